//! The level-set law of a link in a tube (docs/model.md §4) against what
//! it promises, each checked so that it can fail:
//! - pushed through patch merges and splits in the paper's bend in 1 µm
//!   steps, the elastic force and moment change no faster than the point
//!   law's own slope allows (the patch law, run over the same window,
//!   breaks that bound, and its patch count changes inside the window);
//! - force and moment do not depend on the sample count once each depth
//!   extremum has a bracket of its own;
//! - one rim touching is the single-point law at that rim.
//!
//! The elastic point law is written out here, F = K·δⁿ with the paper's
//! K = 1e5 N/mm^2.2 and n = 2.2, not taken from the engine.

use ballcage_core::geometry::{
    ContactPoint, LineContact, LineLaw, PairGeometry, Shape, TubePath, TubeSegment,
};
use ballcage_core::math::{Quat, Vec3};

/// K [N/m^2.2] of the paper's IMPACT law (1e5 N/mm^2.2) and its exponent.
const K: f64 = 1e5 * 3_981_071.705534972; // 1000^2.2
const N: f64 = 2.2;
/// The paper's link: radius 43 mm, length 200 mm.
const RADIUS: f64 = 0.043;
const HALF: f64 = 0.1;

/// The paper's guide tube: bore radius 58 mm, an arc of R = 1.5 m in the
/// x–z plane starting at the origin going down −z, bending toward +x.
fn paper_tube() -> Shape {
    Shape::Tube(TubePath::new(
        0.058,
        Vec3::zeros(),
        -Vec3::z(),
        &[TubeSegment::Arc {
            radius: 1.5,
            angle: std::f64::consts::FRAC_PI_2,
            bend: Vec3::x(),
        }],
    ))
}

/// Centreline point, outward radial and tangent of the arc at angle α.
fn arc(alpha: f64) -> (Vec3, Vec3, Vec3) {
    let e_r = Vec3::new(-alpha.cos(), 0.0, -alpha.sin());
    let t = Vec3::new(alpha.sin(), 0.0, -alpha.cos());
    (Vec3::new(1.5, 0.0, 0.0) + 1.5 * e_r, e_r, t)
}

fn points(tube: &Shape, law: LineLaw, samples: u32, pose: &(Vec3, Quat)) -> Vec<ContactPoint> {
    let cyl = Shape::Cylinder {
        radius: RADIUS,
        half_length: HALF,
    };
    let mut out = vec![];
    PairGeometry::CylinderTube(LineContact {
        points: samples,
        law,
    })
    .contacts(
        tube,
        (&Vec3::zeros(), &Quat::identity()),
        &cyl,
        (&pose.0, &pose.1),
        &mut out,
    );
    out
}

/// Elastic force [N] on the link and its moment [N·m] about the link's centre.
fn wrench(pts: &[ContactPoint], centre: &Vec3) -> (Vec3, Vec3) {
    let mut f = Vec3::zeros();
    let mut m = Vec3::zeros();
    for p in pts {
        let fi = p.weight * K * p.depth.max(0.0).powf(N) * p.normal;
        f += fi;
        m += (p.point - centre).cross(&fi);
    }
    (f, m)
}

/// Σ K·n·δ^(n−1) over the points: how fast the point laws can change per
/// metre of push.
fn slope(pts: &[ContactPoint]) -> f64 {
    pts.iter()
        .map(|p| K * N * p.depth.max(0.0).powf(N - 1.0))
        .sum()
}

/// A link whose axis lies along the arc's tangent at α = 45°, its centre
/// `rho` from the centreline in the direction `phi` from the outward radial
/// toward +y, turned about its own offset direction by `tilt` [rad].
fn pose(rho: f64, phi: f64, tilt: f64) -> (Vec3, Quat) {
    let (c, e_r, t) = arc(std::f64::consts::FRAC_PI_4);
    let dir = phi.cos() * e_r + phi.sin() * Vec3::y();
    let axis =
        nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(dir), tilt) * t;
    let to_axis = nalgebra::UnitQuaternion::rotation_between(&Vec3::x(), &axis).expect("turn");
    (c + rho * dir, to_axis)
}

/// Pushes the link outward from `rho0` in 1 µm steps over `steps` steps;
/// returns the largest ratio of |ΔF| (and of |ΔM|/(h + r)) to the bound the
/// point laws' slopes allow, and how many times the patch count changed.
fn sweep(law: LineLaw, phi: f64, tilt: f64, rho0: f64, steps: usize) -> (f64, usize) {
    let tube = paper_tube();
    let step = 1e-6;
    let arm = HALF + RADIUS;
    let mut worst: f64 = 0.0;
    let mut changes = 0;
    let at = |k: usize| {
        let p = pose(rho0 + step * k as f64, phi, tilt);
        let pts = points(&tube, law, 5, &p);
        let patches = points(&tube, LineLaw::Patches, 5, &p).len();
        (wrench(&pts, &p.0), slope(&pts), patches)
    };
    let mut before = at(0);
    for k in 1..=steps {
        let now = at(k);
        // The depth of any surface point changes by at most the push; the
        // normals turn by a negligible angle over 1 µm (the 5 % margin).
        let bound = 1.05 * before.1.max(now.1) * step + 1e-9;
        let df = (now.0.0 - before.0.0).norm();
        let dm = (now.0.1 - before.0.1).norm() / arm;
        worst = worst.max(df / bound).max(dm / bound);
        if now.2 != before.2 {
            changes += 1;
        }
        before = now;
    }
    (worst, changes)
}

/// Offset directions φ [rad from the outward radial toward +y] and tilts
/// [rad] whose depth profiles change shape inside the window: at φ = 1.3
/// the bend makes the ends deeper than the middle and the tilted link's
/// upper rim comes into contact (a patch appears); near φ = 1.7 a middle
/// maximum between two dips joins the rims' patches and leaves them again
/// (merges and splits).
const CASES: [(f64, f64); 5] = [
    (1.3, 0.001),
    (1.66, 0.0),
    (1.7, 0.0),
    (1.7, 0.001),
    (1.7, 0.003),
];

#[test]
fn pushed_through_merges_the_level_set_law_changes_no_faster_than_its_slope() {
    for (phi, tilt) in CASES {
        // Start with the deepest point 5 µm into the wall and push 120 µm.
        let rho0 = start_offset(phi, tilt, 5e-6);
        let (worst, changes) = sweep(LineLaw::LevelSets, phi, tilt, rho0, 120);
        assert!(
            changes > 0,
            "φ = {phi}, tilt = {tilt}: no patch merged or split inside the window"
        );
        assert!(
            worst <= 1.0,
            "φ = {phi}, tilt = {tilt}: the level-set law changed {worst:.2}× faster than its slope"
        );
        // Where patches merge (all but the first case, where one appears),
        // the same window breaks the bound under the patch law: the test can fail.
        let (patch_worst, _) = sweep(LineLaw::Patches, phi, tilt, rho0, 120);
        if phi > 1.5 {
            assert!(
                patch_worst > 1.5,
                "φ = {phi}, tilt = {tilt}: the patch law stayed within {patch_worst:.2}× of the bound"
            );
        }
    }
}

/// The offset [m] at which the link's deepest point is `depth` into the wall
/// (bisection on the level-set maxima, 17 samples).
fn start_offset(phi: f64, tilt: f64, depth: f64) -> f64 {
    let tube = paper_tube();
    let deepest = |rho: f64| {
        points(&tube, LineLaw::LevelSets, 17, &pose(rho, phi, tilt))
            .iter()
            .filter(|p| p.weight > 0.0)
            .map(|p| p.depth)
            .fold(-1.0, f64::max)
    };
    let (mut lo, mut hi) = (0.005, 0.02);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if deepest(mid) > depth {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn force_and_moment_do_not_depend_on_the_sample_count() {
    let tube = paper_tube();
    for (phi, tilt) in CASES {
        for push in [20e-6, 60e-6, 110e-6] {
            let p = pose(start_offset(phi, tilt, 5e-6) + push, phi, tilt);
            let reference = wrench(&points(&tube, LineLaw::LevelSets, 33, &p), &p.0);
            let scale_f = reference.0.norm();
            let scale_m = reference.1.norm().max(scale_f * 1e-3);
            for samples in [5, 9, 17] {
                let (f, m) = wrench(&points(&tube, LineLaw::LevelSets, samples, &p), &p.0);
                let what = format!("φ = {phi}, tilt = {tilt}, push {push:e} m, {samples} samples");
                assert!((f - reference.0).norm() <= 5e-3 * scale_f, "force, {what}");
                assert!((m - reference.1).norm() <= 5e-3 * scale_m, "moment, {what}");
            }
        }
    }
}

#[test]
fn one_rim_touching_is_the_single_point_law_at_that_rim() {
    // A straight tube along x; the link tilted by 0.01 rad about y with its
    // centre 14.1 mm below the axis: only the rim at x = +0.1 m reaches the
    // wall, 0.0141 + 0.1·sin θ + 0.043·cos θ − 0.058 deep.
    let tube = Shape::Tube(TubePath::new(
        0.058,
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::x(),
        &[TubeSegment::Straight { length: 2.0 }],
    ));
    let th: f64 = 0.01;
    let q = Quat::from_axis_angle(&Vec3::y_axis(), th);
    let expect = 0.0141 + 0.1 * th.sin() + 0.043 * th.cos() - 0.058;
    for samples in [5, 17] {
        let pts = points(
            &tube,
            LineLaw::LevelSets,
            samples,
            &(Vec3::new(0.0, 0.0, -0.0141), q),
        );
        assert_eq!(pts.len(), 1, "{samples} samples");
        assert_eq!(pts[0].weight, 1.0);
        assert!((pts[0].depth - expect).abs() < 1e-12, "{}", pts[0].depth);
        assert_eq!(pts[0].slot, samples - 1);
    }
}

/// A measurement, not a check (`cargo test -p ballcage-core --test
/// line_law -- --ignored --nocapture flat`): a link lying 0.1 mm into a
/// straight wall, tilted by ±1 µrad and ±0.1 mrad about the centre. The
/// level-set law puts its one maximum at the lower rim, so its moment about
/// the centre flips from +F·L/2 to −F·L/2 as the tilt passes zero; the
/// patch law's centroid moves smoothly through the middle
/// (docs/accuracy.md, "What stops adaptive steps").
#[test]
#[ignore = "a measurement: prints the moment of a flat link through zero tilt"]
fn flat_link_moment_through_zero_tilt() {
    let tube = Shape::Tube(TubePath::new(
        0.058,
        Vec3::new(-1.0, 0.0, 0.0),
        Vec3::x(),
        &[TubeSegment::Straight { length: 2.0 }],
    ));
    let centre = Vec3::new(0.0, 0.0, -0.0151);
    println!("law | tilt [rad] | points | F_z [N] | M_y about the centre [N·m]");
    for law in [LineLaw::LevelSets, LineLaw::Patches] {
        for tilt in [-1e-4, -1e-6, 1e-6, 1e-4] {
            let pose = (centre, Quat::from_axis_angle(&Vec3::y_axis(), tilt));
            let pts = points(&tube, law, 33, &pose);
            let (f, m) = wrench(&pts, &centre);
            println!(
                "{law:?} | {tilt:e} | {} | {:.3} | {:.4}",
                pts.len(),
                f.z,
                m.y
            );
        }
    }
}

/// A link of the paper's run at t = 0.628 s: centre and axis [m, world =
/// the tube's frame], its rim 176.8 µm deep with a depth minimum and
/// maximum just born 6–7 mm from it (`ballcage_shapes::line` tests).
fn newborn_pair(tilt: f64) -> (Vec3, Quat) {
    let centre = Vec3::new(
        0.6977892573515972,
        0.0029811545930089603,
        -1.2502401472390159,
    );
    let axis = Vec3::new(0.8231828986692482, 0.0906732953784629, -0.5604893119799024).normalize();
    let turn = nalgebra::Unit::new_normalize(axis.cross(&Vec3::y()));
    let q = nalgebra::UnitQuaternion::from_axis_angle(&turn, tilt)
        * nalgebra::UnitQuaternion::rotation_between(&Vec3::x(), &axis).expect("turn");
    (centre, q)
}

/// The largest change of the elastic force [N] and moment [N·m] between
/// neighbouring tilts `step` [rad] apart over ±0.4 mrad about the pose of
/// [`newborn_pair`], and how many tilts show the pair.
fn largest_changes(samples: u32, step: f64) -> (f64, f64, usize) {
    let tube = paper_tube();
    let n = (4e-5 / step).round() as i32;
    let at = |i: i32| {
        let pose = newborn_pair(step * i as f64);
        let pts = points(&tube, LineLaw::LevelSets, samples, &pose);
        (wrench(&pts, &pose.0), pts.len())
    };
    let (mut df, mut dm, mut with_pair) = (0.0_f64, 0.0_f64, 0);
    let mut before = at(-n);
    for i in -n + 1..=n {
        let now = at(i);
        df = df.max((now.0.0 - before.0.0).norm());
        dm = dm.max((now.0.1 - before.0.1).norm());
        with_pair += usize::from(now.1 == 3);
        before = now;
    }
    (df, dm, with_pair)
}

/// Tilted through the birth and death of a depth maximum–minimum pair
/// between two samples, the link's force and moment are continuous: the
/// largest change between neighbouring tilts falls at least 2.5-fold when
/// the tilt step is cut 16-fold (a jump would not fall; the moment's √
/// cusp at the fold, where the pair's two points separate as the square
/// root of the tilt, falls 4-fold). Without the pair's detection from
/// d(u·â)/ds, 33 samples see the pair only when it reaches a sample, and
/// the moment jumps there (measured: it fell 1.05-fold).
#[test]
fn a_pair_born_between_samples_enters_continuously() {
    for samples in [5, 33] {
        let (df, dm, with_pair) = largest_changes(samples, 2e-7);
        let (df_fine, dm_fine, _) = largest_changes(samples, 2e-7 / 16.0);
        assert!(
            with_pair > 0,
            "{samples} samples: the pair never shows in the window"
        );
        assert!(
            dm_fine <= dm / 2.5 && df_fine <= df / 2.5,
            "{samples} samples: |ΔM| {dm:.3e} → {dm_fine:.3e} N·m, |ΔF| {df:.3e} → {df_fine:.3e} N"
        );
    }
}

/// The paper's tube with the given `end_engagement` [m] at its open ends.
fn paper_tube_engaging(length: f64) -> Shape {
    let Shape::Tube(t) = paper_tube() else {
        unreachable!("a tube")
    };
    Shape::Tube(t.with_end_engagement(length))
}

/// A link crossing the tube's downhole end plane with `inside` [m] of its
/// axis inside, tilted 0.02 rad outward so that it presses the outer wall
/// hardest at the plane, 50 µm deep there.
fn leaving(inside: f64) -> (Vec3, Quat) {
    // The arc's end: centreline (1.5, 0, −1.5), tangent +x, outer wall −z.
    let (end, e_r, t) = arc(std::f64::consts::FRAC_PI_2);
    let tilt: f64 = 0.02;
    let axis = tilt.cos() * t + tilt.sin() * e_r;
    let crossing = end + (0.058 - RADIUS + 50e-6) * e_r;
    let to_axis = nalgebra::UnitQuaternion::rotation_between(&Vec3::x(), &axis).expect("turn");
    (crossing + (HALF - inside) * axis, to_axis)
}

/// The largest change of the link's elastic force [N] between neighbouring
/// positions `step` [m] apart as it slides out of the tube along its axis,
/// from 3 mm of it inside to none, and the force at 3 mm.
fn leaving_changes(tube: &Shape, step: f64) -> (f64, f64) {
    let at = |inside: f64| {
        let pose = leaving(inside);
        wrench(&points(tube, LineLaw::LevelSets, 9, &pose), &pose.0).0
    };
    let n = (3e-3 / step).round() as i32;
    let mut before = at(3e-3);
    let start = before.norm();
    let mut largest: f64 = 0.0;
    for i in (-2..n).rev() {
        let now = at(step * i as f64);
        largest = largest.max((now - before).norm());
        before = now;
    }
    (largest, start)
}

/// A link sliding out of the tube through an open end while it presses the
/// wall there (docs/model.md §4, "The tube's open ends"). With sharp ends
/// its contact vanishes at once when its last section inside leaves: a
/// jump of the whole contact (92 N here; the point law at 50 µm is 137 N),
/// at any step. With the ends taking the contact up over 2 mm of the part
/// inside, the force is continuous: the largest change between
/// neighbouring positions falls with the step (measured: 0.69 N at 10 µm,
/// 0.043 N at a 16th of it). Where 2 mm or more is inside, nothing changes.
#[test]
fn a_link_leaving_the_tube_sheds_its_wall_contact_continuously() {
    let law = K * (50e-6_f64).powf(N);
    let sharp = paper_tube();
    let (jump, start) = leaving_changes(&sharp, 1e-5);
    let (jump_fine, _) = leaving_changes(&sharp, 1e-5 / 16.0);
    assert!(
        start > 0.5 * law && jump > 0.5 * law && jump_fine > 0.5 * law,
        "sharp ends: force {start:.1} N, largest changes {jump:.1} and {jump_fine:.1} N against \
         the law's {law:.1} N"
    );
    let rounded = paper_tube_engaging(2e-3);
    let (change, start_rounded) = leaving_changes(&rounded, 1e-5);
    let (change_fine, _) = leaving_changes(&rounded, 1e-5 / 16.0);
    assert!(
        change < 0.05 * law && change_fine <= change / 8.0,
        "2 mm engagement: largest changes {change:.3} N, then {change_fine:.4} N at a 16th of the step"
    );
    assert_eq!(
        start_rounded, start,
        "3 mm inside: the engagement changed the force"
    );
}
