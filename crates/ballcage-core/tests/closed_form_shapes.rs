//! The exact container shapes against hand-derived closed forms, through
//! both paths that use them (issue 16): ballcage's own contact evaluation
//! (`PairGeometry::contacts`) and parry's query API with
//! `ballcage_shapes::ShapeDispatcher` chained before parry's default
//! dispatcher. Both must give the same depth and normal, in the world frame,
//! for bodies placed with a non-trivial pose (every container here sits on a
//! translated, rotated body).
//!
//! Conventions: δ > 0 into the wall; the normal points from the container
//! (body a) toward the body it holds (b).

use approx::assert_relative_eq;
use ballcage_core::geometry::{
    ContactPoint, LineContact, LineLaw, PairGeometry, Shape, TubePath, TubeSegment,
};
use ballcage_core::math::{Quat, Vec3};
use ballcage_shapes::{GrooveFlank, ShapeDispatcher, SphericalCavity, TubeInterior, WindowSlot};
use parry3d_f64::math::{Pose, Rotation, Vector};
use parry3d_f64::query::{
    ContactManifold, DefaultQueryDispatcher, PersistentQueryDispatcher, QueryDispatcher,
};
use parry3d_f64::shape::{Ball, Cylinder};

/// Depths are ~0.1 mm: 1e-12 m is eight orders below what they guard.
const DEPTH_TOL: f64 = 1e-12;
/// Normals are built from offsets of ~10 mm: round-off ~1e-14.
const NORMAL_TOL: f64 = 1e-10;

/// The pose of the container's body in every test: off the origin, turned
/// about a skew axis, so a frame mistake shows.
fn container_pose() -> (Vec3, Quat) {
    let axis = nalgebra::Unit::new_normalize(Vec3::new(0.3, -0.5, 0.8));
    (Vec3::new(0.2, -0.7, 1.1), Quat::from_axis_angle(&axis, 0.9))
}

fn glam(v: &Vec3) -> Vector {
    Vector::new(v.x, v.y, v.z)
}

fn nalg(v: Vector) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

fn glam_pose(p: &(Vec3, Quat)) -> Pose {
    let q = p.1;
    Pose::from_parts(glam(&p.0), Rotation::from_xyzw(q.i, q.j, q.k, q.w))
}

/// A world-frame contact: depth and unit normal (container toward body).
#[derive(Debug, Clone, Copy)]
struct World {
    depth: f64,
    normal: Vec3,
}

/// ballcage's path: the pair's contact points.
fn ballcage(
    g: PairGeometry,
    s1: &Shape,
    p1: &(Vec3, Quat),
    s2: &Shape,
    p2: &(Vec3, Quat),
) -> Vec<World> {
    let mut out: Vec<ContactPoint> = vec![];
    g.contacts(s1, (&p1.0, &p1.1), s2, (&p2.0, &p2.1), &mut out);
    out.iter()
        .map(|c| World {
            depth: c.depth,
            normal: c.normal,
        })
        .collect()
}

fn dispatcher() -> impl PersistentQueryDispatcher<(), ()> {
    ShapeDispatcher::default().chain(DefaultQueryDispatcher)
}

/// parry's path, `contact`: the deepest point, both shape orders (the
/// reversed order's normal1 belongs to the body and points at the container).
fn parry_contact(
    container: &dyn parry3d_f64::shape::Shape,
    pa: &Pose,
    body: &dyn parry3d_f64::shape::Shape,
    pb: &Pose,
) -> Option<World> {
    let d = dispatcher();
    let c = d
        .contact(&pa.inv_mul(pb), container, body, 0.0)
        .expect("supported")?;
    let r = d
        .contact(&pb.inv_mul(pa), body, container, 0.0)
        .expect("supported")?;
    assert!((c.dist - r.dist).abs() < DEPTH_TOL);
    let (n, m) = (pa.rotation * c.normal1, pb.rotation * r.normal1);
    assert!(
        (n + m).length() < NORMAL_TOL,
        "reversed order: {n} against {m}"
    );
    // normal1 is the container's outward normal, into the lumen: toward the body.
    Some(World {
        depth: -c.dist,
        normal: nalg(n),
    })
}

/// parry's path, `contact_manifolds`: every manifold's point.
fn parry_manifolds(
    container: &dyn parry3d_f64::shape::Shape,
    pa: &Pose,
    body: &dyn parry3d_f64::shape::Shape,
    pb: &Pose,
) -> Vec<World> {
    let mut manifolds: Vec<ContactManifold<(), ()>> = vec![];
    dispatcher()
        .contact_manifolds(
            &pa.inv_mul(pb),
            container,
            body,
            0.0,
            &mut manifolds,
            &mut None,
        )
        .expect("supported");
    manifolds
        .iter()
        .flat_map(|m| {
            m.points.iter().map(|p| World {
                depth: -p.dist,
                normal: nalg(pa.rotation * m.local_n1),
            })
        })
        .collect()
}

fn assert_world(got: &World, depth: f64, normal: &Vec3, what: &str) {
    assert!(
        (got.depth - depth).abs() < DEPTH_TOL,
        "{what}: depth {} against {depth}",
        got.depth
    );
    assert!(
        (got.normal - normal).norm() < NORMAL_TOL,
        "{what}: normal {} against {normal}",
        got.normal
    );
}

/// A ball in tube `t` (its own frame: `local` centre) checked through both
/// paths against δ and the tube-frame normal `n`.
fn check_ball_in_tube(t: &TubePath, radius: f64, local: Vec3, depth: f64, n: Vec3, what: &str) {
    let pa = container_pose();
    let pb = (pa.0 + pa.1 * local, Quat::identity());
    let world_n = pa.1 * n;
    let got = ballcage(
        PairGeometry::BallTube,
        &Shape::Tube(t.clone()),
        &pa,
        &Shape::ball(radius),
        &pb,
    );
    assert_eq!(got.len(), 1, "{what}: ballcage");
    assert_world(&got[0], depth, &world_n, &format!("{what}, ballcage"));
    let tube: &TubeInterior = t.interior();
    let got =
        parry_contact(tube, &glam_pose(&pa), &Ball::new(radius), &glam_pose(&pb)).expect("contact");
    assert_world(&got, depth, &world_n, &format!("{what}, parry"));
}

/// The paper's guide tube: from the origin down (−z), a 90° arc of R = 1.5 m
/// bending toward +x (centre O = (1.5, 0, 0)); inner radius 58 mm.
fn paper_tube() -> TubePath {
    TubePath::new(
        0.058,
        Vec3::zeros(),
        -Vec3::z(),
        &[TubeSegment::Arc {
            radius: 1.5,
            angle: std::f64::consts::FRAC_PI_2,
            bend: Vec3::x(),
        }],
    )
}

/// The centreline point C(α) = O + 1.5·(−cos α, 0, −sin α) and the outward
/// radial e_r = (−cos α, 0, −sin α) of the paper's arc at angle α.
fn paper_arc(alpha: f64) -> (Vec3, Vec3) {
    let e_r = Vec3::new(-alpha.cos(), 0.0, -alpha.sin());
    (Vec3::new(1.5, 0.0, 0.0) + 1.5 * e_r, e_r)
}

/// A ball of r = 43 mm centred C(α) + a·e_r + b·y, with √(a² + b²) = 15.1 mm:
/// the nearest centreline point is C(α) (the offset is perpendicular to the
/// tangent), so δ = 15.1 + 43 − 58 = 0.1 mm, normal −(a·e_r + b·y)/15.1 mm.
/// Off the bend plane (b ≠ 0), on its outer (a > 0) and inner (a < 0) side.
#[test]
fn a_ball_off_the_bend_plane_of_the_arc() {
    let t = paper_tube();
    for deg in [10.0_f64, 45.0, 80.0] {
        let (c, e_r) = paper_arc(deg.to_radians());
        for phi in [90.0_f64, 40.0, -70.0, 200.0] {
            let off = 0.0151 * (phi.to_radians().cos() * e_r + phi.to_radians().sin() * Vec3::y());
            let what = format!("α = {deg}°, offset at {phi}° from the bend plane");
            check_ball_in_tube(&t, 0.043, c + off, 1e-4, -off / 0.0151, &what);
        }
    }
}

/// At the arc's two ends (α = 0 at the origin, α = 90° at (1.5, 0, −1.5)),
/// 0.1 µm inside the end planes (on a plane itself, whether a point is in
/// the tube is decided by round-off): the nearest point is C(α), the same
/// closed form as inside. 1 mm past either end plane there is no wall: no
/// contact on either path, though the ball still reaches 0.1 mm beyond the
/// wall's radius there.
#[test]
fn a_ball_at_the_arc_ends_and_past_them() {
    let t = paper_tube();
    for (deg, out_of_tube) in [(0.0_f64, Vec3::z()), (90.0, Vec3::x())] {
        let inside = if deg == 0.0 { 1e-7 / 1.5 } else { -1e-7 / 1.5 };
        let (c, e_r) = paper_arc(deg.to_radians() + inside);
        let off = 0.0151 * (0.6 * e_r + 0.8 * Vec3::y());
        check_ball_in_tube(
            &t,
            0.043,
            c + off,
            1e-4,
            -off / 0.0151,
            &format!("end at {deg}°"),
        );
        let pa = container_pose();
        let pb = (
            pa.0 + pa.1 * (c + off + 1e-3 * out_of_tube),
            Quat::identity(),
        );
        let tube = Shape::Tube(t.clone());
        assert!(ballcage(PairGeometry::BallTube, &tube, &pa, &Shape::ball(0.043), &pb).is_empty());
        let d = dispatcher();
        let pos12 = glam_pose(&pa).inv_mul(&glam_pose(&pb));
        assert!(
            d.contact(&pos12, t.interior(), &Ball::new(0.043), 0.0)
                .expect("supported")
                .is_none()
        );
    }
}

/// A tube from the origin along +x: straight 1 m, an arc of R = 2 m over 30°
/// bending toward +y (centre O = (1, 2, 0)), straight 0.5 m; inner radius
/// 58 mm, ball 43 mm, out-of-plane offset z₀ = 6 mm.
///
/// At the first join (x = 1): 10 mm before it, on the straight, the nearest
/// point is (0.99, 0, 0): offset (0, y₀, z₀), δ = √(y₀² + z₀²) + r − R.
/// 10 mm after it, on the arc, the point's distance from O in the bend plane
/// is ρ = √(0.01² + (2 − y₀)²), its offset from the arc ρ − 2 radially (away
/// from O) and z₀ across: δ = √((ρ − 2)² + z₀²) + r − R.
/// At the second join E = O + 2·(sin 30°, −cos 30°, 0) = (2, 2 − √3, 0),
/// tangent T = (cos 30°, sin 30°, 0), outward radial e = (sin 30°, −cos 30°, 0):
/// E + 10 mm·T + a·e + z₀·z is on the straight, δ = √(a² + z₀²) + r − R;
/// E − 10 mm·T + a·e is on the arc at ρ = √((2 + a)² + 0.01²) from O.
#[test]
fn a_ball_across_the_straight_joins() {
    let t = TubePath::new(
        0.058,
        Vec3::zeros(),
        Vec3::x(),
        &[
            TubeSegment::Straight { length: 1.0 },
            TubeSegment::Arc {
                radius: 2.0,
                angle: 30f64.to_radians(),
                bend: Vec3::y(),
            },
            TubeSegment::Straight { length: 0.5 },
        ],
    );
    let (r, big_r, z0, eps) = (0.043, 0.058, 0.006, 0.01);
    let o = Vec3::new(1.0, 2.0, 0.0);
    for y0 in [-0.014, 0.014] {
        // Before the first join, on the straight.
        let off = Vec3::new(0.0, y0, z0);
        let q = Vec3::new(1.0 - eps, 0.0, 0.0) + off;
        check_ball_in_tube(
            &t,
            r,
            q,
            off.norm() + r - big_r,
            -off / off.norm(),
            "before join 1",
        );
        // After it, on the arc.
        let q = Vec3::new(1.0 + eps, y0, z0);
        let in_plane = Vec3::new(q.x, q.y, 0.0) - o;
        let rho = in_plane.norm();
        let u = (rho - 2.0) * in_plane / rho + z0 * Vec3::z();
        check_ball_in_tube(
            &t,
            r,
            q,
            u.norm() + r - big_r,
            -u / u.norm(),
            "after join 1",
        );
    }
    let (s30, c30) = (0.5_f64, 3f64.sqrt() / 2.0);
    let e_pt = Vec3::new(2.0, 2.0 - 3f64.sqrt(), 0.0);
    let (tan, e) = (Vec3::new(c30, s30, 0.0), Vec3::new(s30, -c30, 0.0));
    for a in [-0.014, 0.014] {
        let off = a * e + z0 * Vec3::z();
        let q = e_pt + eps * tan + off;
        check_ball_in_tube(
            &t,
            r,
            q,
            off.norm() + r - big_r,
            -off / off.norm(),
            "after join 2",
        );
        let q = e_pt - eps * tan + off;
        let in_plane = Vec3::new(q.x, q.y, 0.0) - o;
        let rho = in_plane.norm();
        assert!((rho - ((2.0 + a) * (2.0 + a) + eps * eps).sqrt()).abs() < 1e-15);
        let u = (rho - 2.0) * in_plane / rho + z0 * Vec3::z();
        check_ball_in_tube(
            &t,
            r,
            q,
            u.norm() + r - big_r,
            -u / u.norm(),
            "before join 2",
        );
    }
}

/// A cylinder (r = 10 mm, half-length h = 30 mm) across the bend plane: its
/// axis along y through C(α) + a·e_r. Every axis point q(s) = C + a·e_r + s·y
/// has C as its nearest centreline point; the rim point farthest out is
/// q + r·e_r, at √((a + r)² + s²) from C. So the depth is smallest mid-link
/// and largest at the rims: δ = √((a + r)² + h²) − R there, normals
/// −((a + r)·e_r ± h·y)/√(…), off the bend plane by atan(h/(a + r)). With
/// a = √((R + 0.1 mm)² − h²) − r, δ = 0.1 mm; the samples at ±h/2 are
/// √((a + r)² + h²/4) − R < 0 from the wall: two patches, one rim each.
#[test]
fn a_cylinder_across_the_bend_touches_off_plane_at_both_rims() {
    let (r, h, big_r, delta): (f64, f64, f64, f64) = (0.01, 0.03, 0.058, 1e-4);
    let a = ((big_r + delta) * (big_r + delta) - h * h).sqrt() - r;
    assert!(((a + r) * (a + r) + h * h / 4.0).sqrt() < big_r);
    let t = paper_tube();
    let pa = container_pose();
    for deg in [20.0_f64, 55.0] {
        let (c, e_r) = paper_arc(deg.to_radians());
        let centre = pa.0 + pa.1 * (c + a * e_r);
        let norm = ((a + r) * (a + r) + h * h).sqrt();
        let rims = [-h, h].map(|s| pa.1 * (-((a + r) * e_r + s * Vec3::y()) / norm));
        // ballcage: the link's axis is its body x; turn x onto the tube's y.
        let q = pa.1 * Quat::from_axis_angle(&Vec3::z_axis(), std::f64::consts::FRAC_PI_2);
        let cyl = Shape::Cylinder {
            radius: r,
            half_length: h,
        };
        // Both line laws: two separate patches, one point law at each rim.
        for law in [LineLaw::LevelSets, LineLaw::Patches] {
            let got = ballcage(
                PairGeometry::CylinderTube(LineContact { points: 5, law }),
                &Shape::Tube(t.clone()),
                &pa,
                &cyl,
                &(centre, q),
            );
            assert_eq!(got.len(), 2, "ballcage at {deg}°, {law:?}");
            for (g, n) in got.iter().zip(&rims) {
                assert_world(g, delta, n, &format!("ballcage, rim at {deg}°, {law:?}"));
            }
        }
        // parry: its cylinder's axis is its local y, already along the tube's y.
        let pb = glam_pose(&(centre, pa.1));
        let parry_cyl = Cylinder::new(h, r);
        let got = parry_manifolds(t.interior(), &glam_pose(&pa), &parry_cyl, &pb);
        assert_eq!(got.len(), 2, "parry at {deg}°");
        for (g, n) in got.iter().zip(&rims) {
            assert_world(g, delta, n, &format!("parry, rim at {deg}°"));
        }
        let deepest =
            parry_contact(t.interior(), &glam_pose(&pa), &parry_cyl, &pb).expect("contact");
        assert!((deepest.depth - delta).abs() < DEPTH_TOL);
    }
}

/// A Gothic-arch groove: ball radius r = 7.5 mm, flank section radius
/// ρ = 7.8 mm, ball centre nominally at P = R_p·e_φ (R_p = 30 mm, e_φ the
/// radial at azimuth φ) about the race axis z. Flank k touches the ball at
/// contact angle β_k (n_k = cos β_k·e_φ + sin β_k·z, from the ball's centre
/// to its contact point): its section centre is c_k = P − (ρ − r)·n_k, so the
/// torus has core radius R_p − (ρ − r)·cos β_k at height −(ρ − r)·sin β_k.
/// Pushed by δ along n₁ the ball centre is p = P + δ·n₁:
/// - flank 1: p − c₁ = (ρ − r + δ)·n₁, so δ₁ = δ, normal −n₁;
/// - flank 2: p − c₂ = (ρ − r)·n₂ + δ·n₁, so
///   δ₂ = √((ρ − r)² + δ² + 2(ρ − r)δ·cos(β₁ − β₂)) − (ρ − r),
///   normal −(p − c₂)/|p − c₂|
///
/// (both nearest core points are at azimuth φ: p lies in that meridian plane).
#[test]
fn a_ball_in_a_gothic_arch_at_several_contact_angles() {
    let (r, rho, rp, delta) = (0.0075, 0.0078, 0.03, 1e-4);
    let g = rho - r;
    let pa = container_pose();
    let phi = 25f64.to_radians();
    let e_phi = Vec3::new(phi.cos(), phi.sin(), 0.0);
    for beta in [30.0_f64, 40.0, 45.0, 60.0] {
        let (b1, b2) = (beta.to_radians(), -beta.to_radians());
        let n = |b: f64| b.cos() * e_phi + b.sin() * Vec3::z();
        let p = rp * e_phi + delta * n(b1);
        let expected = [
            (delta, -n(b1)),
            (
                (g * g + delta * delta + 2.0 * g * delta * (b1 - b2).cos()).sqrt() - g,
                -(g * n(b2) + delta * n(b1)) / (g * n(b2) + delta * n(b1)).norm(),
            ),
        ];
        for (k, b) in [b1, b2].into_iter().enumerate() {
            let (depth, normal) = expected[k];
            let flank = PairGeometry::TorusBall {
                centre: Vec3::new(0.0, 0.0, -g * b.sin()),
                axis: Vec3::z(),
                core_radius: rp - g * b.cos(),
                tube_radius: rho,
                ball_radius: r,
            };
            let none = Shape::ball(1.0);
            let pb = (pa.0 + pa.1 * p, Quat::identity());
            let what = format!("β = {beta}°, flank {}", k + 1);
            let got = ballcage(flank, &none, &pa, &none, &pb);
            let shape = GrooveFlank::new(
                Vector::new(0.0, 0.0, -g * b.sin()),
                Vector::Z,
                rp - g * b.cos(),
                rho,
            );
            let parry = parry_contact(&shape, &glam_pose(&pa), &Ball::new(r), &glam_pose(&pb));
            // At β = 60° flank 2 is clear: δ₂ = √7e-8 − 3e-4 < 0.
            if depth <= 0.0 {
                assert!(got.is_empty() && parry.is_none(), "{what}: clear");
                continue;
            }
            assert_eq!(got.len(), 1, "{what}");
            let n = pa.1 * normal;
            assert_world(&got[0], depth, &n, &format!("{what}, ballcage"));
            assert_world(
                &parry.expect("contact"),
                depth,
                &n,
                &format!("{what}, parry"),
            );
        }
    }
}

/// A ball of r = 7.5 mm in a window of half-width 8 mm, 0.7 mm below the
/// mid-plane: δ = 7.5 + 0.7 − 8 = 0.2 mm against the lower face, pushed up.
/// A sphere of 31 mm in a cavity of 32 mm, 1.1 mm off centre along −y:
/// δ = 1.1 + 31 − 32 = 0.1 mm, pushed along +y.
#[test]
fn a_ball_in_a_window_and_a_sphere_in_a_cavity() {
    let pa = container_pose();
    let none = Shape::ball(1.0);
    let c = Vec3::new(0.01, 0.02, -0.03);
    let window = PairGeometry::SlotBall {
        centre: c,
        normal: Vec3::y(),
        half_width: 0.008,
        ball_radius: 0.0075,
    };
    let pb = (
        pa.0 + pa.1 * (c + Vec3::new(0.003, -0.0007, 0.002)),
        Quat::identity(),
    );
    let n = pa.1 * Vec3::y();
    assert_world(
        &ballcage(window, &none, &pa, &none, &pb)[0],
        2e-4,
        &n,
        "window, ballcage",
    );
    let slot = WindowSlot::new(glam(&c), Vector::Y, 0.008);
    let got = parry_contact(&slot, &glam_pose(&pa), &Ball::new(0.0075), &glam_pose(&pb))
        .expect("contact");
    assert_world(&got, 2e-4, &n, "window, parry");

    let cavity = PairGeometry::CavitySphere {
        cavity_centre: c,
        cavity_radius: 0.032,
        sphere_centre: Vec3::zeros(),
        sphere_radius: 0.031,
    };
    let pb = (pa.0 + pa.1 * (c - 0.0011 * Vec3::y()), Quat::identity());
    assert_world(
        &ballcage(cavity, &none, &pa, &none, &pb)[0],
        1e-4,
        &n,
        "cavity, ballcage",
    );
    let shape = SphericalCavity::new(glam(&c), 0.032);
    let got = parry_contact(&shape, &glam_pose(&pa), &Ball::new(0.031), &glam_pose(&pb))
        .expect("contact");
    assert_world(&got, 1e-4, &n, "cavity, parry");
}

/// A ball pressing the wall 0.1 mm deep as its centre nears the arc's
/// downhole end plane, in a tube whose open ends take contact up over
/// 2 mm (docs/model.md §4): its point carries the share
/// w = 3x² − 2x³, x = e / 2 mm (the Adams STEP) of its law, e the centre's
/// distance before the plane, and 1 from 2 mm in; the depth and normal are
/// those of the wall inside. Past the plane there is no contact, where the
/// share has already reached 0, so the force does not jump. With sharp ends
/// the share is 1 up to the plane.
#[test]
fn a_ball_nearing_an_open_end_takes_its_share_of_the_wall() {
    let pa = container_pose();
    let ball = Shape::ball(0.043);
    let rounded = Shape::Tube(paper_tube().with_end_engagement(2e-3));
    let sharp = Shape::Tube(paper_tube());
    // The end: centreline (1.5, 0, −1.5), tangent +x; offset 15.1 mm
    // outward (−z) in the end plane: δ = 0.1 mm near it.
    let end = Vec3::new(1.5, 0.0, -1.5);
    let at = |e: f64| {
        let centre = end - e * Vec3::x() - 0.0151 * Vec3::z();
        (pa.0 + pa.1 * centre, Quat::identity())
    };
    for e in [3e-3, 2e-3, 1.5e-3, 1e-3, 0.5e-3, 0.1e-3, 1e-6] {
        let mut out: Vec<ContactPoint> = vec![];
        let pb = at(e);
        PairGeometry::BallTube.contacts(&rounded, (&pa.0, &pa.1), &ball, (&pb.0, &pb.1), &mut out);
        let x = (e / 2e-3).min(1.0);
        assert_eq!(out.len(), 1, "e = {e} m");
        assert_relative_eq!(out[0].weight, x * x * (3.0 - 2.0 * x), epsilon = 1e-9);
        // The wall's depth near the end: the centreline bends away by e²/2R.
        assert_relative_eq!(out[0].depth, 1e-4, epsilon = 1e-5);
        let mut plain: Vec<ContactPoint> = vec![];
        PairGeometry::BallTube.contacts(&sharp, (&pa.0, &pa.1), &ball, (&pb.0, &pb.1), &mut plain);
        assert_eq!(plain[0].weight, 1.0, "sharp ends, e = {e} m");
        assert_eq!(plain[0].depth, out[0].depth, "e = {e} m");
    }
    let past = at(-1e-6);
    assert!(ballcage(PairGeometry::BallTube, &rounded, &pa, &ball, &past).is_empty());
}
