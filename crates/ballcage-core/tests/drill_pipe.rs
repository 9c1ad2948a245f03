//! The drill pipe's parts against hand calculations (docs/model.md §7.4, §7.5, §7.6, §7.9, §7.10).

mod common;

use ballcage_core::force::joint::twist_angle;
use ballcage_core::math::Vec3;
use ballcage_core::record::ColumnData;
use ballcage_core::{Document, Simulation};

const K_SI: f64 = 1e5 * 3.981_071_705_534_972e6; // 1e5 N/mm^2.2 in N/m^2.2 (1000^2.2 = 10^6.6)

/// A link resting in a straight horizontal tube; returns (Σ normal force [N], depth per point [m], speed [m/s]).
fn resting_link(points: u32, law: &str) -> (f64, f64, f64) {
    let toml = format!(
        r#"
        [simulation]
        duration = 0.3
        dt = 1e-5
        output_interval = 1e-2
        integrator = "rk4"
        [world]
        gravity = [0.0, 0.0, -9.8]
        [[bodies]]
        name = "tube"
        motion = "fixed"
        shape = {{ type = "tube", inner_radius = 0.058, start = [-1.0, 0.0, 0.0], direction = [1.0, 0.0, 0.0], segments = [{{ type = "straight", length = 2.0 }}] }}
        [[bodies]]
        name = "link"
        shape = {{ type = "cylinder", radius = 0.043, half_length = 0.1 }}
        mass = 8.010
        inertia = [8.306e-3, 3.085e-2, 3.085e-2]
        position = [0.0, 0.0, -0.015]
        [[contacts]]
        bodies = ["tube", "link"]
        points = {points}
        line_law = "{law}"
        normal = {{ law = "impact", stiffness = 1e5, exponent = 2.2, damping = 10.0, depth_max = 0.1, units = "N-mm-s" }}
        friction = {{ law = "adams", mu_static = 0.3, mu_dynamic = 0.1, v_static = 100.0, v_dynamic = 1000.0, units = "N-mm-s" }}
        "#
    );
    let mut sim = common::sim(&toml);
    sim.run().unwrap();
    let c = sim.pair_contacts(0);
    assert_eq!(c.len(), 1, "a link lying flat is one contact piece");
    assert_eq!(c[0].point.weight, 1.0);
    (
        c[0].normal_force,
        c[0].point.depth,
        sim.state().vel[1].norm(),
    )
}

#[test]
fn a_link_resting_in_a_horizontal_tube_carries_its_weight() {
    // docs/model.md §7.6: one IMPACT force per contact piece, so Σ F_n = m g =
    // 78.50 N and the resting depth δ = (m g / K)^(1/2.2) = 0.0388 mm whatever
    // the sampling. (A force per sample gave δ = (m g / (N K))^(1/2.2): 0.0283 mm
    // for 2 samples, 0.0186 mm for 9; the tolerance is far below that spread.)
    let mg = 8.010 * 9.8;
    let expect = (mg / K_SI).powf(1.0 / 2.2);
    assert!(
        (expect * 1e3 - 0.0388).abs() < 5e-5,
        "hand value {expect} m"
    );
    // The level-set law (the default) and the patch law both give a flat
    // link the single-point law at its depth. In a straight tube the
    // level-set law's maximum moves from one rim to the other as the link
    // tilts through level (docs/model.md §4), so the link rocks by about
    // 1e-3 rad/s and its force at an instant is within 1.5 % of m g; the
    // patch law, acting at the centroid, holds it still.
    for (law, force_tolerance) in [("level-sets", 1.5e-2), ("patches", 1e-3)] {
        for points in [2, 5, 9, 17] {
            check_resting(law, points, force_tolerance, mg, expect);
        }
    }
}

fn check_resting(law: &str, points: u32, force_tolerance: f64, mg: f64, expect: f64) {
    {
        let (total, depth, speed) = resting_link(points, law);
        assert!(
            ((total - mg) / mg).abs() < force_tolerance,
            "{law}, {points} points: F_n = {total} N, m g = {mg} N"
        );
        assert!(
            ((depth - expect) / expect).abs() < 1e-3,
            "{law}, {points} points: δ = {depth}, expected {expect}"
        );
        assert!(speed < 1e-6, "{law}: still moving at {speed} m/s");
    }
}

#[test]
fn the_paper_scene_expands_to_its_bodies_and_pairs_and_starts_without_contact() {
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &[]).unwrap();
    let scene = doc.scene();
    // 1 tube + 2 connectors + 12 links + 13 cages + 78 keys.
    assert_eq!(scene.bodies.len(), 106);
    // 12 link–tube pairs; per hinge 2 cage spheres + the neck–mouth pair
    // + 6 keys × (2 + 2 flanks + 2 window pairs).
    assert_eq!(scene.contacts.len(), 12 + 13 * (3 + 6 * 6));
    let mut sim = doc.simulation();
    for k in 0..scene.contacts.len() {
        assert!(
            sim.pair_contacts(k).is_empty(),
            "pair {} touches at t = 0",
            scene.contacts[k].pair_name()
        );
    }
    // The default is the paper's: printing and reading back gives the same scene,
    // and what is printed is the short drill-pipe form, not the expansion.
    let text = doc.to_toml();
    assert!(
        text.starts_with("kind = \"drill-pipe\""),
        "{}",
        &text[..200.min(text.len())]
    );
    assert!(text.len() < 10_000, "{} bytes", text.len());
    let again = Document::from_toml_str(&text, &[]).unwrap();
    assert_eq!(again.scene().bodies, scene.bodies);
    assert_eq!(again.scene().contacts, scene.contacts);
}

#[test]
fn dotted_keys_of_the_drill_pipe_scene_take_effect() {
    let o = |s: &[&str]| s.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    let doc = Document::from_toml_str(
        "kind = \"drill-pipe\"\n",
        &o(&[
            "pipe.joints=4",
            "borehole.curvature_radius=2.5",
            "drive.speed_rpm=60",
            "load.resisting_moment=900",
        ]),
    )
    .unwrap();
    let scene = doc.scene();
    assert_eq!(
        scene
            .bodies
            .iter()
            .filter(|b| b.name.starts_with("link"))
            .count(),
        4
    );
    let (spec, _) = doc.drill_pipe_parts().unwrap();
    assert_eq!(spec.borehole.curvature_radius, 2.5);
    // The name follows the scene, and says the paper's only when it is.
    assert_eq!(scene.name, "4 ball-cage joints, R 2.5 m, 60 rpm, 0.9 kN·m");
    let paper = Document::from_toml_str("kind = \"drill-pipe\"\n", &[]).unwrap();
    assert_eq!(
        paper.scene().name,
        "Zhu et al. 2023: 12 ball-cage joints, R 1.5 m, 100 rpm, 1.8 kN·m"
    );
    let cv = Document::from_toml_str("kind = \"drill-pipe\"\n", &o(&["pipe.hinge=\"ideal-cv\""]));
    assert!(cv.unwrap().scene().name.starts_with("12 ideal-CV joints"));
    let upper = scene.bodies.iter().find(|b| b.name == "upper").unwrap();
    assert!(
        (upper.spin_speed - 2.0 * std::f64::consts::PI).abs() < 1e-12,
        "60 rpm = 2π rad/s"
    );
    let e = Document::from_toml_str("kind = \"drill-pipe\"\n", &o(&["pipe.joints=0"])).unwrap_err();
    assert_eq!(e.path, "pipe.joints");
    let e = Document::from_toml_str(
        "kind = \"drill-pipe\"\n",
        &o(&["borehole.curvature_radius=-1"]),
    )
    .unwrap_err();
    assert_eq!(e.path, "borehole.curvature_radius");
}

/// Section model of one loaded key (docs/model.md §3 geometry): the loaded head
/// flank centre sits at +a(cos α, sin α) and the seat flank centre at
/// −a(cos α, sin α) from the ball (radial, circumferential), a = ρ_g − r_b − s.
/// Turning the seat by u = PCR·θ moves its flank centre by u around; the ball,
/// pressed equally by both, lies midway, each contact penetrating δ with
/// |C_head − C_seat| = 2(a + s + δ). So cos α′ = a·cos α/(a + s + δ) and
/// T = 6·K·δⁿ·PCR·sin α′. Returns (per-key force [N], wind-up per hinge [rad]).
/// With s = 0 and δ ≪ a this is docs/model.md §7.9: T/(6·PCR·sin 45°) = 13.47 kN.
/// `rho_g` is the Gothic arch's flank radius [m] (a = ρ_g − r_b − s).
fn section_model(torque: f64, k: f64, n: f64, s: f64, rho_g: f64) -> (f64, f64) {
    let (pcr, alpha, r_b) = (0.0315, std::f64::consts::FRAC_PI_4, 0.0075);
    let a = rho_g - r_b - s;
    let t_of =
        |d: f64| 6.0 * k * d.powf(n) * pcr * (1.0 - (a * alpha.cos() / (a + s + d)).powi(2)).sqrt();
    let (mut lo, mut hi) = (0.0, 1e-2);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if t_of(mid) < torque {
            lo = mid
        } else {
            hi = mid
        }
    }
    let d = 0.5 * (lo + hi);
    let u = (4.0 * (a + s + d).powi(2) - (2.0 * a * alpha.cos()).powi(2)).sqrt()
        - 2.0 * a * alpha.sin();
    (k * d.powf(n), u / pcr)
}

/// Per key of both hinges, (inner race, outer race) values.
type PerKey = Vec<(f64, f64)>;

/// A 1-link pipe in a straight bore (two hinges in series), drive held at
/// rest, 1.8 kN·m ramped onto the lower connector, no gravity; returns each
/// key's (head-race, seat-race) normal force [N], the lower connector's turn
/// [rad], and every key's (inner, outer) operating contact angle [deg] from
/// the last frame of the `keys` table.
fn quasi_static_hinges(extra: &[&str]) -> (PerKey, f64, PerKey) {
    let mut o: Vec<String> = [
        "pipe.joints=1",
        "borehole.curvature_radius=1000",
        "drive.speed_rpm=0",
        "load.ramp=0.04",
        "world.gravity=0",
        "simulation.duration=0.12",
        "simulation.dt=2e-7",
        "simulation.integrator=\"symplectic-euler\"",
        "simulation.rtol=0",
        "simulation.output_interval=0.01",
        "record.tables=[\"keys\"]",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    o.extend(extra.iter().map(|s| s.to_string()));
    let mut sim = Document::from_toml_str("kind = \"drill-pipe\"\n", &o)
        .unwrap()
        .simulation();
    let lower = common::body(&sim, "lower");
    let q0 = sim.state().rot[lower];
    sim.run().unwrap();
    let mut forces = vec![];
    for h in 0..2 {
        for j in 0..6 {
            let mut race = |name: &str| -> f64 {
                ["+", "-"]
                    .iter()
                    .map(|t| {
                        let k = sim
                            .pair_index(&format!("h{h:02}.key{j}/{name}{t}"))
                            .unwrap();
                        sim.pair_contacts(k)
                            .iter()
                            .map(|e| e.normal_force)
                            .sum::<f64>()
                    })
                    .sum()
            };
            let head = race("head");
            forces.push((head, race("seat")));
        }
    }
    let turned = (sim.state().rot[lower] * q0.inverse()).angle();
    let rec = sim.finish();
    let keys = rec.tables.iter().find(|t| t.def.name == "keys").unwrap();
    let angle = |name: &str| -> Vec<f64> {
        match keys.column(name) {
            Some(ColumnData::OptF64(v)) => v[v.len() - 12..]
                .iter()
                .map(|a| a.expect("every key touches its race"))
                .collect(),
            other => panic!("{name}: {other:?}"),
        }
    };
    let angles = angle("inner_contact_angle_deg")
        .into_iter()
        .zip(angle("outer_contact_angle_deg"))
        .collect();
    (forces, turned, angles)
}

#[test]
fn one_hinge_under_quasi_static_torque_carries_13_47_kn_per_key() {
    // docs/model.md §7.9's assumptions: no flank clearance, contacts stiff enough
    // that the 45° contact angle holds (K = 1e12 N/mm^2.2: δ ≈ 0.3 µm ≪ a = 7.5 mm).
    let (forces, _, angles) = quasi_static_hinges(&[
        "pipe.ball_keys.flank_clearance=0",
        "materials.internal.normal.stiffness=1e12",
    ]);
    // δ ≈ 0.3 µm against a = 7.5 mm: the contact angle holds its 45° (the
    // section model: acos(a cos 45° / (a + δ)) = 45.002°; the full model's ball
    // also shifts in its groove under the cage's push), far from the ~72° a
    // close groove opens to under the paper's law (next test).
    for (i, (inner, outer)) in angles.iter().enumerate() {
        for a in [inner, outer] {
            assert!((a - 45.0).abs() < 1.5, "key {i}: contact angle {a}°");
        }
    }
    let hand = 1800.0 / (6.0 * 0.0315 * std::f64::consts::FRAC_PI_4.sin());
    assert!((hand - 13_468.7).abs() < 1.0);
    let mean = forces.iter().map(|(h, s)| h + s).sum::<f64>() / (2.0 * forces.len() as f64);
    for (i, (head, seat)) in forces.iter().enumerate() {
        for f in [head, seat] {
            assert!(
                ((f - hand) / hand).abs() < 0.02,
                "key {i}: {f} N vs the hand value {hand} N"
            );
            assert!(
                ((f - mean) / mean).abs() < 0.005,
                "key {i}: {f} N vs the mean {mean} N: unequal sharing"
            );
        }
    }
    // The elastic wind-up here (2·2δ/(PCR·sin α) ≈ 0.05 mrad) is below the slack the cage and
    // window clearances allow, so §7.9's wind-up is checked with the paper's law below.
}

#[test]
fn with_the_paper_law_a_close_groove_opens_its_contact_angle_and_keys_carry_less() {
    // The paper's law is soft: at ~10 kN a key penetrates ~0.35 mm, more than the
    // 0.29 mm flank offset of a close Gothic arch (ρ_g = 7.8 mm, f = 1.04), so the
    // contact angle opens from 45° toward 72° and each key carries ~10 kN, not 13.47 kN.
    let k = 1e5 * 1000f64.powf(2.2);
    let (forces, turned, angles) = quasi_static_hinges(&["pipe.ball_keys.groove_radius=0.0078"]);
    let (model, per_hinge) = section_model(1800.0, k, 2.2, 1e-5, 0.0078);
    // The section model's operating angle: cos α′ = a cos 45° / (a + s + δ), δ = (F/K)^(1/n).
    let (a, s) = (0.0078 - 0.0075 - 1e-5, 1e-5);
    let delta = (model / k).powf(1.0 / 2.2);
    let opened = (a * std::f64::consts::FRAC_PI_4.cos() / (a + s + delta))
        .acos()
        .to_degrees();
    assert!(opened > 65.0, "section model α′ = {opened}°");
    for (i, (inner, outer)) in angles.iter().enumerate() {
        for angle in [inner, outer] {
            // As for the force, the 2-D section ignores the ball's radial shift
            // and the 7.2° track offset: measured 74.2° on the inner race and
            // 75.8° on the outer against 71.7°, while the angle opened by 27°.
            assert!(
                (angle - opened).abs() < 5.0,
                "key {i}: contact angle {angle}° vs the section model's {opened}°"
            );
        }
    }
    assert!(model < 10_100.0 && model > 9_900.0, "section model {model}");
    let mean = forces.iter().map(|(h, s)| h + s).sum::<f64>() / (2.0 * forces.len() as f64);
    for (i, (head, seat)) in forces.iter().enumerate() {
        for f in [head, seat] {
            assert!(
                ((f - mean) / mean).abs() < 0.01,
                "key {i}: {f} N, mean {mean} N: unequal sharing"
            );
        }
    }
    // The 2-D section ignores the ball's radial shift and the 7.2° track offset: 3 %.
    assert!(
        ((mean - model) / model).abs() < 0.03,
        "mean key force {mean} N vs section model {model} N"
    );
    assert!(
        ((turned - 2.0 * per_hinge) / (2.0 * per_hinge)).abs() < 0.05,
        "turned {turned} rad vs {}",
        2.0 * per_hinge
    );
}

/// docs/model.md §3 (groove conformity): with the default open arch
/// (ρ_g = 30 mm, a = ρ_g − r_b − s = 22.49 mm) the contact angle holds 45°
/// up to the paper's peak key load of 33.5 kN under its own law.
/// 4.47 kN·m through one hinge gives T/(6·PCR·sin 45°) = 33.5 kN per key at
/// 45°; the section model then sinks a key δ = (F/K)^(1/2.2) = 0.61 mm and
/// opens the angle to acos(a cos 45°/(a + s + δ)) = 46.5°. That section
/// translates the seat; turned about the axis instead (docs/model.md §7.9,
/// the rotating section, tests/hinge_closed_forms.rs) its flank centre also
/// moves outward, and the contact line stays at 44.9° from the head race's
/// radial direction, while the seat race's own groove section has turned
/// with the seat by φ, half the two hinges' turn, so its angle reads φ more
/// (48.1° by hand). Checked: head race within 0.3° of 45°, seat race within
/// 0.3° of the head race's angle + φ; 0.3° covers the 4 mm groove offset
/// the c → 0 section leaves out (measured: head 45.04°, seat 0.13° above
/// the head's + φ, φ = 3.53°), and is 10× below the seat race's opening.
/// The close arch (ρ_g = 7.8 mm) opens to 76° under the same load (section
/// model).
#[test]
fn with_the_default_groove_the_contact_angle_holds_at_the_papers_peak_key_load() {
    let torque = 33_500.0 * 6.0 * 0.0315 * std::f64::consts::FRAC_PI_4.sin();
    let (forces, turned, angles) =
        quasi_static_hinges(&[&format!("load.resisting_moment={torque}")]);
    let k = 1e5 * 1000f64.powf(2.2);
    let (model, _) = section_model(torque, k, 2.2, 1e-5, 0.030);
    let (a, s) = (0.030 - 0.0075 - 1e-5, 1e-5);
    let opened = |rho_a: f64| {
        let delta = (model / k).powf(1.0 / 2.2);
        (rho_a * std::f64::consts::FRAC_PI_4.cos() / (rho_a + s + delta))
            .acos()
            .to_degrees()
    };
    assert!(
        (opened(a) - 46.5).abs() < 0.1,
        "section model α′ = {}°",
        opened(a)
    );
    assert!(opened(0.0078 - 0.0075 - 1e-5) > 70.0);
    let (phi, tol) = ((0.5 * turned).to_degrees(), 0.3);
    assert!(phi > 10.0 * tol, "turn per hinge {phi}°");
    for (i, (inner, outer)) in angles.iter().enumerate() {
        assert!(
            (inner - 45.0).abs() < tol,
            "key {i}: head-race contact angle {inner}°"
        );
        assert!(
            (outer - (inner + phi)).abs() < tol,
            "key {i}: seat-race contact angle {outer}° vs {inner}° + {phi}°"
        );
    }
    let mean = forces.iter().map(|(h, s)| h + s).sum::<f64>() / (2.0 * forces.len() as f64);
    assert!(
        ((mean - model) / model).abs() < 0.03,
        "mean key force {mean} N vs section model {model} N"
    );
}

#[test]
fn a_ball_key_hinge_passes_spin_at_constant_velocity() {
    // docs/model.md §7.4: full contact model, light load, β = 7.6°: |ω_out/ω_in − 1| < 1e-3
    // (a Cardan joint at 7.645° would swing between 0.99111 and 1.00897).
    // One link on R = 0.75 m: both hinges bend 2·asin(0.1/0.75)/2 = 7.66°.
    let o: Vec<String> = [
        "pipe.joints=1",
        "borehole.curvature_radius=0.75",
        "drive.speed_rpm=600",
        "drive.ramp=0.05",
        "load.resisting_moment=5",
        "load.ramp=0.05",
        "world.gravity=0",
        "simulation.duration=0.5",
        "simulation.dt=1e-6",
        "simulation.integrator=\"symplectic-euler\"",
        "simulation.rtol=0",
        "simulation.output_interval=0.001",
        "record.tables=[]",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let mut sim = Document::from_toml_str("kind = \"drill-pipe\"\n", &o)
        .unwrap()
        .simulation();
    let (upper, link) = (common::body(&sim, "upper"), common::body(&sim, "link01"));
    let bend = {
        let s = sim.state();
        let (a, b) = (
            s.rot[upper] * ballcage_core::math::Vec3::x(),
            s.rot[link] * ballcage_core::math::Vec3::x(),
        );
        a.cross(&b).norm().atan2(a.dot(&b)).to_degrees()
    };
    assert!((bend - 7.66).abs() < 0.01, "hinge 0 bends {bend}°");
    // The output turns by the input angle plus the relative twist (zero for an
    // ideal CV joint; ±(β²/4)·sin 2φ ≈ ±4.5 mrad for a Cardan joint). The speed
    // ratio over each 10 ms window (36° of input) is 1 + Δtwist/Δφ_in.
    // The spin-up leaves a lightly damped 37 Hz torsional oscillation: let it
    // decay, then watch one revolution (0.1 s). Light load: 1 µs is stable.
    sim.advance_to(0.4).unwrap();
    let twist = |sim: &Simulation| twist_angle(&sim.state().rot[upper], &sim.state().rot[link]);
    let mut samples = vec![];
    while sim.time() < 0.5 - 1e-9 {
        sim.advance_to(sim.time() + 0.001).unwrap();
        samples.push(twist(&sim));
    }
    let input_step = 600.0 * std::f64::consts::TAU / 60.0 * 0.01;
    let worst = samples
        .windows(11)
        .map(|w| ((w[10] - w[0]) / input_step).abs())
        .fold(0.0, f64::max);
    assert!(
        worst < 1e-3,
        "output/input spin speed deviates by {worst:.2e}"
    );
}

/// Included angles [deg] between adjacent bodies of the chain (upper, links, lower).
fn included_angles(doc: &Document, sim: &Simulation) -> Vec<f64> {
    let chain = &doc.drill_pipe_parts().expect("a drill pipe").1.chain;
    let s = sim.state();
    chain
        .windows(2)
        .map(|w| {
            let (a, b) = (
                s.rot[w[0]] * ballcage_core::math::Vec3::x(),
                s.rot[w[1]] * ballcage_core::math::Vec3::x(),
            );
            180.0 - a.cross(&b).norm().atan2(a.dot(&b)).to_degrees()
        })
        .collect()
}

/// A two-link chain (hinges 0–2, connectors fixed in the tube on R = 1.5 m,
/// drive held, 1.8 kN·m ramped over 50 ms, gravity along the well) with
/// `hinge`, run to 0.3 s. Returns the mean bend [deg] of each hinge over
/// 0.15–0.3 s and, at 0.3 s, the distance [m] from each hinge's centre
/// (midway between the two bodies' hinge points) to the next.
fn two_link_chain(hinge: &str) -> (Vec<f64>, Vec<f64>) {
    let o: Vec<String> = [
        format!("pipe.hinge=\"{hinge}\""),
        "pipe.joints=2".into(),
        "drive.speed_rpm=0".into(),
        "load.ramp=0.05".into(),
        "simulation.duration=0.3".into(),
        "record.tables=[]".into(),
    ]
    .to_vec();
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &o).unwrap();
    let chain = doc.drill_pipe_parts().unwrap().1.chain.clone();
    let mut sim = doc.simulation();
    let (mut sum, mut frames) = (vec![0.0; 3], 0);
    while !sim.is_done() {
        sim.advance_to(sim.time() + 0.005).unwrap();
        if sim.time() > 0.15 - 1e-9 {
            for (m, b) in sum.iter_mut().zip(included_angles(&doc, &sim)) {
                *m += 180.0 - b;
            }
            frames += 1;
        }
    }
    // Sides of the triangle h0–h1–h2: from the upper connector's hinge point
    // to hinge 1's centre (midway between the links' hinge points) and on to
    // the lower connector's; the hinge points sit ±pitch/2 along each body's
    // x axis (the ideal-CV anchors). Both connectors are fixed.
    let s = sim.state();
    let x = ballcage_core::math::Vec3::x();
    let end = |i: usize, sign: f64| s.pos[i] + s.rot[i] * x * (0.1 * sign);
    let (h0, h2) = (end(chain[0], 1.0), end(chain[3], -1.0));
    let h1 = 0.5 * (end(chain[1], 1.0) + end(chain[2], -1.0));
    let spans = vec![(h1 - h0).norm(), (h2 - h1).norm(), (h2 - h0).norm()];
    (sum.iter().map(|m| m / frames as f64).collect(), spans)
}

/// The two hinge models on the same two-link chain, statically loaded: they
/// genuinely differ, and the difference is the ball-key hinge's axial play.
///
/// Two links between connectors fixed in position and direction form a
/// one-degree-of-freedom pendulum about the line through hinges 0 and 2;
/// here it hangs at its lowest point (gravity is along the well), so with
/// rigid hinge points nothing moves: the ideal-CV chain keeps the chord
/// geometry, asin(0.1/1.5) = 3.8226° at the connectors and twice that,
/// 7.6451°, at hinge 1 (docs/model.md §7.5), within 0.01° (measured 1e-3°).
///
/// The ball-key hinges are not rigid axially: under 1.8 kN·m and the links'
/// weight the head and seat of each hinge separate by 0.08–0.17 mm (key
/// penetration and flank clearance), lengthening the sides h0–h1 and h1–h2
/// by 0.21 and 0.18 mm (measured). The chain is nearly straight (hinge 1 only
/// d = 13.3 mm off the line h0–h2), so lengthening its sides by ε opens the
/// bend at hinge 1 by about ε/d: 1.5° measured (7.65° → 9.15°), the end hinges
/// closing to 3.1°.
///
/// The test checks (1) this is a real difference (> 1°; the old comparison at
/// a 0.5° tolerance would fail here) and (2) it is explained: the bend at
/// hinge 1 predicted by the law of cosines on the triangle h0–h1–h2, from the
/// ball-key chain's measured sides and the fixed connectors' h0–h2 distance,
/// matches its mean bend within 0.2° (measured with the close 7.8 mm groove
/// 9.18° vs 9.15°; with the default open groove 8.94° vs 8.80°). The 0.2°
/// covers the lateral hinge offsets (≤ 0.2 mm over 200 mm: 0.06°), the
/// drift of the bend within the 0.15 s averaging window and the hinge
/// centre taken midway between the two bodies' hinge points; it is 6×
/// below the 1.3° being explained: without the lengthening the prediction is
/// the ideal-CV bend.
#[test]
fn ideal_cv_and_ball_keys_differ_on_a_short_chain_by_the_hinges_axial_play() {
    let (cv, cv_spans) = two_link_chain("ideal-cv");
    let (keys, key_spans) = two_link_chain("ball-keys");
    let half = (0.1_f64 / 1.5).asin().to_degrees();
    for (k, (b, hand)) in cv.iter().zip([half, 2.0 * half, half]).enumerate() {
        assert!(
            (b - hand).abs() < 0.01,
            "ideal-cv hinge {k}: {b}° vs {hand}°"
        );
    }
    assert!(
        keys[1] - cv[1] > 1.0,
        "ball-key hinge 1 bends {}°, ideal-cv {}°: no difference left to explain",
        keys[1],
        cv[1]
    );
    // Triangle h0–h1–h2: the h0–h2 side is the connectors' (fixed); the other
    // two are the ball-key chain's centre-to-centre spans. The interior angle at h1
    // is 180° − bend (planar chain).
    let (a, b, base) = (key_spans[0], key_spans[1], key_spans[2]);
    assert!((base - cv_spans[2]).abs() < 1e-6, "the connectors moved");
    let predicted = 180.0
        - ((a * a + b * b - base * base) / (2.0 * a * b))
            .acos()
            .to_degrees();
    assert!(
        (predicted - keys[1]).abs() < 0.2,
        "hinge 1: {}° measured, {predicted}° from the hinge spans",
        keys[1]
    );
}

/// Last value of column `name` of the recorded table `table`.
fn last_value(rec: &ballcage_core::record::Recording, table: &str, name: &str) -> f64 {
    let t = rec
        .tables
        .iter()
        .find(|t| t.def.name == table)
        .expect("table recorded");
    match t.column(name).expect("column") {
        ballcage_core::record::ColumnData::F64(v) => *v.last().expect("rows"),
        other => panic!("{name} is not a float column: {other:?}"),
    }
}

/// Torque [N·m] that the hinge parts (every contact pair and joint touching
/// `body`) apply to `body` about its centre of mass, world frame: computed
/// from the contact forces and joint wrenches, not from any applied load.
fn hinge_torque_on(sim: &mut Simulation, body: usize) -> ballcage_core::math::Vec3 {
    let evals: Vec<_> = (0..sim.model().pairs.len())
        .map(|k| sim.pair_contacts(k))
        .collect();
    let (model, state) = (sim.model(), sim.state());
    let joints: ballcage_core::math::Vec3 =
        model.joints.iter().map(|j| j.torque_on(state, body)).sum();
    ballcage_core::dynamics::contact_torque(model, state, &evals, body) + joints
}

/// Statics of the drive with the drive held still and 1.8 kN·m ramped onto the
/// lower connector (one link, straight bore, no gravity), through either hinge
/// model. Two moment balances, each on one connector:
///
/// - upper: the drive's `input_torque` (what the contacts and joints take from
///   the upper connector) equals the 1.8 kN·m at the far end;
/// - lower: the torque the hinge's own forces (key contacts, or the CV joint's
///   wrench) exert on the lower connector about its axis balances the applied
///   −1.8 kN·m. The `drive` table's `output_torque` is the applied load by
///   definition, so it is not checked against 1800; this sum is independent
///   of it (computed from contact points and joint states).
///
/// Tolerance 0.1 % (1.8 N·m) on both: at t = 0.12 s, 80 ms after the ramp
/// ended, the measured residuals are below 1e-3 relative (ideal-cv and
/// ball-keys; with the default open groove the ball-key lower connector still
/// turns at 2.3e-3 rad/s, a twist vibration of about 2e-6 rad). A hinge that
/// lost one of six keys or mis-signed a twist spring would be off by ≥ 1/6
/// or 2×; a connector still swinging at the 0.1 % level (1.8 N·m over the
/// hinges' ~5e4 N·m/rad secant twist stiffness, 3.6e-5 rad, at their
/// ~1.2e3 rad/s twist frequency: 0.04 rad/s) would be caught here and by the
/// rest check (|ω| < 1e-2 rad/s).
#[test]
fn at_rest_the_drive_and_the_hinge_both_balance_the_resisting_moment() {
    for (hinge, dt) in [("ideal-cv", "1e-5"), ("ball-keys", "2e-7")] {
        let o: Vec<String> = [
            format!("pipe.hinge=\"{hinge}\""),
            "pipe.joints=1".into(),
            "borehole.curvature_radius=1000".into(),
            "drive.speed_rpm=0".into(),
            "load.ramp=0.04".into(),
            "world.gravity=0".into(),
            "simulation.duration=0.12".into(),
            format!("simulation.dt={dt}"),
            "simulation.integrator=\"symplectic-euler\"".into(),
            "simulation.rtol=0".into(),
            "simulation.rtol=0".into(),
            "simulation.output_interval=0.01".into(),
            "record.tables=[\"drive\"]".into(),
        ]
        .to_vec();
        let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &o).unwrap();
        let lower = *doc.drill_pipe_parts().unwrap().1.chain.last().unwrap();
        let mut sim = doc.simulation();
        sim.run().unwrap();
        let ballcage_core::model::Motion::Spin { axis, .. } = sim.model().bodies[lower].motion
        else {
            panic!("the lower connector is a spin body")
        };
        let applied: f64 = sim
            .model()
            .torques
            .iter()
            .filter(|l| l.body == lower)
            .map(|l| l.torque(sim.time()).dot(&axis))
            .sum();
        let from_hinge = hinge_torque_on(&mut sim, lower).dot(&axis);
        let spin = sim.state().omega_world(lower).dot(&axis);
        let rec = sim.finish();
        let input = last_value(&rec, "drive", "input_torque");
        assert!(
            (applied + 1800.0).abs() < 1e-9,
            "{hinge}: the load is not the full −1.8 kN·m: {applied}"
        );
        assert!(
            ((from_hinge - 1800.0) / 1800.0).abs() < 1e-3,
            "{hinge}: the hinge exerts {from_hinge} N·m on the lower connector"
        );
        assert!(
            spin.abs() < 1e-2,
            "{hinge}: the lower connector turns at {spin} rad/s"
        );
        assert!(
            ((input - 1800.0) / 1800.0).abs() < 1e-3,
            "{hinge}: input torque {input} N·m"
        );
    }
}

/// Float column `name` of the recorded table `table`.
fn float_column<'a>(
    rec: &'a ballcage_core::record::Recording,
    table: &str,
    name: &str,
) -> &'a [f64] {
    let t = rec
        .tables
        .iter()
        .find(|t| t.def.name == table)
        .expect("table recorded");
    match t.column(name).expect("column") {
        ballcage_core::record::ColumnData::F64(v) => v,
        other => panic!("{name} is not a float column: {other:?}"),
    }
}

#[test]
fn links_placed_on_chords_sit_one_sagitta_inside_the_arc() {
    // Option A placement: hinges on the centreline, links on the chords. A
    // chord of length p on a circle of radius R has its midpoint the sagitta
    // s = R − √(R² − (p/2)²) inside the circle: toward the inner wall, in the
    // bend plane. R = 1.5 m, p = 0.2 m: s = 3.337 mm. Hinges 0–11 lie on the
    // arc, so links 1–11 are chords of it.
    let o: Vec<String> = ["simulation.duration=1e-4", "record.tables=[\"links\"]"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &o).unwrap();
    let rec = doc.simulation().finish();
    let sagitta = 1.5 - (1.5_f64.powi(2) - 0.1_f64.powi(2)).sqrt();
    let outward = float_column(&rec, "links", "offset_outward");
    let lateral = float_column(&rec, "links", "offset_lateral");
    let distance = float_column(&rec, "links", "radial_offset");
    for k in 0..11 {
        assert!(
            (outward[k] + sagitta).abs() < 1e-9,
            "link {}: outward offset {} m, expected −{sagitta} m",
            k + 1,
            outward[k]
        );
        assert!(
            lateral[k].abs() < 1e-12,
            "link {}: lateral {}",
            k + 1,
            lateral[k]
        );
        assert!((distance[k] - sagitta).abs() < 1e-9, "link {}", k + 1);
    }
}

#[test]
fn link_tube_forces_are_the_sums_of_each_links_contact_rows() {
    // The links table finds each link's tube contact by the pair id the
    // expansion recorded; its per-frame total must equal the sum of the
    // contacts rows between the tube (body 0) and that link's body.
    let o: Vec<String> = [
        "pipe.hinge=\"ideal-cv\"",
        "simulation.duration=0.3",
        "record.tables=[\"links\", \"contacts\"]",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &o).unwrap();
    let mut sim = doc.simulation();
    sim.run().unwrap();
    let rec = sim.finish();
    let u32s = |table: &str, name: &str| -> Vec<u32> {
        let t = rec.tables.iter().find(|t| t.def.name == table).unwrap();
        match t.column(name) {
            Some(ballcage_core::record::ColumnData::U32(v)) => v.clone(),
            other => panic!("{table}.{name}: {other:?}"),
        }
    };
    let (link_body, body_a, body_b) = (
        u32s("links", "body"),
        u32s("contacts", "body_a"),
        u32s("contacts", "body_b"),
    );
    let (link_t, contact_t) = (
        float_column(&rec, "links", "t"),
        float_column(&rec, "contacts", "t"),
    );
    let tube = float_column(&rec, "links", "tube_normal");
    let force = float_column(&rec, "contacts", "normal_force");
    let end = *link_t.last().unwrap();
    let mut touching = 0;
    for r in (0..tube.len()).filter(|&r| link_t[r] == end) {
        let sum: f64 = (0..force.len())
            .filter(|&c| contact_t[c] == end && body_a[c] == 0 && body_b[c] == link_body[r])
            .map(|c| force[c])
            .sum();
        assert!(
            (tube[r] - sum).abs() <= 1e-9 * sum.abs().max(1.0),
            "body {}: links.tube_normal {} N, contacts {} N",
            link_body[r],
            tube[r],
            sum
        );
        touching += usize::from(sum > 0.0);
    }
    assert!(
        touching > 0,
        "no link touches the tube: the check would be empty"
    );
}

#[test]
fn the_pairs_table_says_what_each_pair_touches() {
    // 12 tube pairs; per hinge (13) one cage–head and one cage–seat pair and
    // per key (6) two flanks on each race and two window pairs.
    let o: Vec<String> = ["simulation.duration=1e-4", "record.tables=[\"pairs\"]"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &o).unwrap();
    let rec = doc.simulation().finish();
    let t = rec.tables.iter().find(|t| t.def.name == "pairs").unwrap();
    assert_eq!(t.rows, doc.scene().contacts.len());
    let (feature, link, hinge, key) = match (
        t.column("feature"),
        t.column("link"),
        t.column("hinge"),
        t.column("key"),
    ) {
        (
            Some(ColumnData::U32(f)),
            Some(ColumnData::OptU32(l)),
            Some(ColumnData::OptU32(h)),
            Some(ColumnData::OptU32(k)),
        ) => (f, l, h, k),
        other => panic!("pairs columns: {other:?}"),
    };
    let labels = ballcage_core::drillpipe::Feature::LABELS;
    let count = |label: &str| {
        feature
            .iter()
            .filter(|&&f| labels[f as usize] == label)
            .count()
    };
    assert_eq!(count("tube"), 12);
    assert_eq!((count("cage-head"), count("cage-seat")), (13, 13));
    assert_eq!(
        (count("inner-race"), count("outer-race")),
        (13 * 12, 13 * 12)
    );
    assert_eq!(count("window"), 13 * 12);
    // A tube pair's link is the chain position of its body b; joint pairs
    // name a hinge and no link; key pairs a key 0–5.
    let (_, layout) = doc.drill_pipe_parts().unwrap();
    for (k, pair) in doc.model().pairs.iter().enumerate() {
        match labels[feature[k] as usize] {
            "tube" => {
                let link = link[k].expect("tube pair has a link") as usize;
                assert_eq!(layout.chain[link], pair.b, "pair {k}");
                assert_eq!(hinge[k], None);
            }
            label => {
                assert_eq!(link[k], None, "pair {k}");
                assert!(hinge[k].is_some_and(|h| h <= 12), "pair {k}");
                let keyed = ["inner-race", "outer-race", "window"].contains(&label);
                assert_eq!(key[k].is_some_and(|j| j < 6), keyed, "pair {k}");
            }
        }
    }
}

/// One ideal-CV link between the two connectors on an arc of radius `r`, no
/// gravity, drive held, `torque` ramped onto the lower connector over 40 ms,
/// run to 0.12 s. Returns per joint (bend [rad], force on b [N], torque on b
/// [N·m]) and the bend-plane normal (unit, world).
fn ideal_cv_link_under_torque(
    r: f64,
    torque: f64,
) -> (
    Vec<(f64, ballcage_core::math::Vec3, ballcage_core::math::Vec3)>,
    ballcage_core::math::Vec3,
) {
    let o: Vec<String> = [
        "pipe.hinge=\"ideal-cv\"".to_string(),
        "pipe.joints=1".into(),
        format!("borehole.curvature_radius={r}"),
        "drive.speed_rpm=0".into(),
        format!("load.resisting_moment={torque}"),
        "load.ramp=0.04".into(),
        "world.gravity=0".into(),
        "simulation.duration=0.12".into(),
        "simulation.dt=1e-5".into(),
        "simulation.integrator=\"symplectic-euler\"".into(),
        "simulation.rtol=0".into(),
        "simulation.output_interval=0.01".into(),
        "record.tables=[]".into(),
    ]
    .to_vec();
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &o).unwrap();
    let chain = doc.drill_pipe_parts().unwrap().1.chain.clone();
    let mut sim = doc.simulation();
    sim.run().unwrap();
    let (model, s) = (sim.model(), sim.state());
    assert_eq!(model.joints.len(), 2, "two hinges");
    let x = ballcage_core::math::Vec3::x();
    let plane = (s.rot[chain[0]] * x)
        .cross(&(s.rot[chain[2]] * x))
        .normalize();
    let joints = model
        .joints
        .iter()
        .map(|j| {
            let (w, _, _) = j.evaluate(s);
            let bend = ballcage_core::force::joint::bend(&s.rot[j.a], &s.rot[j.b]);
            (bend, w.force, w.torque)
        })
        .collect();
    (joints, plane)
}

/// docs/model.md §7.10 on the smallest statically determinate ideal-CV
/// chain: one link (hinge pitch l = 0.2 m) whose two hinge points are held
/// by the connectors, bent on an arc of radius R, carrying T = 1.8 kN·m, no
/// gravity, no tube contact (the link floats on its chord, 15 mm off the wall).
///
/// Hand calculation. The CV joint passes torque about the bisector of its two
/// axes, so a hinge bent by β carries τ = T/cos(β/2) to have T along each
/// body's own axis, and τ·sin(β/2) = T·tan(β/2) across it: the secondary
/// couple. Both hinges of the link bend in one plane and their couples on the
/// link add, a couple about an in-plane axis normal to the link that only a
/// pair of out-of-plane hinge forces ±F can balance: F·l = T·(tan(β₀/2) +
/// tan(β₁/2)). With the connectors tangent to the arc at the hinges, each
/// hinge bends β = asin(l/(2R)):
///
/// - R = 1.5 m: β = 3.8226°, F = 2·1800·tan(1.9113°)/0.2 = 600.7 N;
/// - R = 0.7517 m (β = 7.645°, the paper's hinge bend on R = 1.5 m):
///   F = 2·1800·tan(3.8226°)/0.2 = 1202.7 N, the §7.10 value;
///
/// and each twist spring carries τ = T/cos(β/2) (1800.9 and 1804.0 N·m).
///
/// Measured: F and τ equal the hand values to 1e-10, the in-plane force is
/// 6e-6·F, β matches to 1e-7°.
///
/// Tolerances: F and τ within 1e-4, the in-plane force below 1e-4·F, β within
/// 0.001°. The static solution is exact up to the hinge-point gap (F/k =
/// 1.2 µm against l = 0.2 m: 6e-6) and what is left of the settling 80 ms
/// after the ramp. 1e-4 is 5× and 22× below the difference between tan(β/2)
/// and sin(β/2) (1/cos(β/2) − 1 = 5.6e-4 at 3.82°, 2.2e-3 at 7.645°), so a
/// shear formula with the wrong trigonometry fails, and so does a twist
/// torque about one body's axis instead of the bisector (the link's couple
/// becomes T·tan β, 0.45 % more than 2T·tan(β/2) at 7.645°).
#[test]
fn an_ideal_cv_link_under_torque_carries_the_hinge_shear_2t_tan_half_beta_over_l() {
    let t = 1800.0;
    for (r, f_hand) in [(1.5, 600.7), (0.1 / 7.645_f64.to_radians().sin(), 1202.7)] {
        let beta = (0.1 / r).asin();
        let f_exact = 2.0 * t * (beta / 2.0).tan() / 0.2;
        assert!(
            (f_exact - f_hand).abs() < 0.1,
            "hand value {f_exact} vs {f_hand}"
        );
        let (joints, plane) = ideal_cv_link_under_torque(r, t);
        for (k, (bend, force, torque)) in joints.iter().enumerate() {
            let out = force.dot(&plane).abs();
            let in_plane = (force - plane * force.dot(&plane)).norm();
            let tau_hand = t / (bend / 2.0).cos();
            assert!(
                (bend - beta).abs().to_degrees() < 1e-3,
                "R = {r}: joint {k} bends {}°, expected {}°",
                bend.to_degrees(),
                beta.to_degrees()
            );
            assert!(
                ((out - f_exact) / f_exact).abs() < 1e-4,
                "R = {r}: joint {k}: out-of-plane shear {out} N vs {f_exact} N"
            );
            assert!(
                in_plane < 1e-4 * f_exact,
                "R = {r}: joint {k}: in-plane hinge force {in_plane} N"
            );
            assert!(
                ((torque.norm() - tau_hand) / tau_hand).abs() < 1e-4,
                "R = {r}: joint {k}: twist torque {} N·m vs {tau_hand}",
                torque.norm()
            );
        }
    }
}

#[test]
fn a_tube_bent_tighter_than_the_hinges_allow_is_refused_with_the_limit() {
    // On an arc of radius R, links of pitch p bend 2·asin(p / 2R) at each
    // interior hinge: at R = 0.7 m, 16.43° > the 14.92° limit where the
    // neck meets the seat's mouth, β = acos(19/32.01) − asin(20/32.01); the
    // tightest radius is p / (2 sin(β/2)) = 0.7701 m, which is accepted.
    let load = |r: &str| {
        Document::from_toml_str(
            "kind = \"drill-pipe\"\n",
            &[format!("borehole.curvature_radius={r}")],
        )
    };
    let e = load("0.7").unwrap_err();
    assert_eq!(e.path, "borehole.curvature_radius");
    let expect = 2.0 * (0.1_f64 / 0.7).asin().to_degrees();
    assert!(e.reason.contains(&format!("{expect:.2}°")), "{e}");
    assert!(e.reason.contains("0.7701 m"), "{e}");
    assert!(load("0.7702").is_ok());
    assert!(load("0.7700").is_err());
    // Eq. (9): a 0.6 m link of Ø86 mm in the Ø116 mm tube needs R ≥ 0.3^2/0.06 − 0.043 = 1.457 m.
    let e = Document::from_toml_str(
        "kind = \"drill-pipe\"\n",
        &[
            "pipe.pitch=0.6".to_string(),
            "borehole.curvature_radius=1.4".to_string(),
            "pipe.neck_radius=0".to_string(),
        ],
    )
    .unwrap_err();
    assert!(e.reason.contains("eq. (9) needs R ≥ 1.4570 m"), "{e}");
}

/// The `bodies` table's part columns of a run: (body id, part label, link, hinge, key) per row.
type PartRow = (u32, Option<String>, Option<u32>, Option<u32>, Option<u32>);

fn body_parts(rec: &ballcage_core::record::Recording) -> Vec<PartRow> {
    let t = rec.tables.iter().find(|t| t.def.name == "bodies").unwrap();
    match (
        t.column("body_id"),
        t.column("part"),
        t.column("link"),
        t.column("hinge"),
        t.column("key"),
    ) {
        (
            Some(ColumnData::U32(id)),
            Some(ColumnData::OptU32(part)),
            Some(ColumnData::OptU32(link)),
            Some(ColumnData::OptU32(hinge)),
            Some(ColumnData::OptU32(key)),
        ) => (0..t.rows)
            .map(|r| {
                let label = part[r].map(|p| rec.part_labels[p as usize].to_string());
                (id[r], label, link[r], hinge[r], key[r])
            })
            .collect(),
        other => panic!("bodies part columns: {other:?}"),
    }
}

#[test]
fn the_bodies_table_says_what_each_body_is() {
    // The paper's pipe by hand: the tube, the upper connector, 12 links, the
    // lower connector, and per hinge (13) a cage and 6 ball keys: 106 bodies,
    // every one recorded.
    let base = ["simulation.duration=1e-4", "record.tables=[\"bodies\"]"].map(String::from);
    let names: Vec<String> = Document::from_toml_str("kind = \"drill-pipe\"\n", &base)
        .unwrap()
        .scene()
        .bodies
        .iter()
        .map(|b| format!("\"{}\"", b.name))
        .collect();
    assert_eq!(names.len(), 1 + 1 + 12 + 1 + 13 * 7);
    let mut o = base.to_vec();
    o.push(format!("record.bodies=[{}]", names.join(", ")));
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &o).unwrap();
    let rec = doc.simulation().finish();
    let rows = body_parts(&rec);
    let frames = rows.len() / names.len();
    assert!(frames >= 1 && rows.len() == frames * names.len());
    let first = &rows[..names.len()];
    let count = |label: &str| {
        first
            .iter()
            .filter(|r| r.1.as_deref() == Some(label))
            .count()
    };
    let counts = ["tube", "upper", "link", "lower", "cage", "key"].map(count);
    assert_eq!(counts, [1, 1, 12, 1, 13, 78]);
    // Each row's ids name the body its name says (names.rs formats them);
    // ids that do not apply are null.
    use ballcage_core::drillpipe::names;
    let mut keys = std::collections::BTreeSet::new();
    for (id, part, link, hinge, key) in &rows {
        let expected = match (part.as_deref(), link, hinge, key) {
            (Some("tube"), None, None, None) => names::TUBE.to_string(),
            (Some("upper"), None, None, None) => names::UPPER.to_string(),
            (Some("lower"), None, None, None) => names::LOWER.to_string(),
            (Some("link"), Some(k), None, None) if (1..=12).contains(k) => {
                names::chain_body(*k as usize, 12)
            }
            (Some("cage"), None, Some(h), None) if *h <= 12 => names::cage(*h as usize),
            (Some("key"), None, Some(h), Some(j)) if *h <= 12 && *j < 6 => {
                keys.insert((*h, *j));
                names::key(*h as usize, *j as usize)
            }
            other => panic!("body {id}: ids {other:?}"),
        };
        assert_eq!(rec.body_names[*id as usize], expected, "body {id}");
    }
    assert_eq!(keys.len(), 13 * 6, "every key of every hinge once");
}

#[test]
fn a_generic_scene_leaves_the_part_columns_null() {
    let toml = r#"
        [simulation]
        duration = 1e-3
        dt = 1e-4
        output_interval = 1e-4
        [[bodies]]
        name = "ball"
        shape = { type = "ball", radius = 0.05 }
        mass = 1.0
        [record]
        tables = ["bodies"]
    "#;
    let rec = common::sim(toml).finish();
    let rows = body_parts(&rec);
    assert!(!rows.is_empty());
    assert!(rec.part_labels.is_empty());
    for row in rows {
        assert_eq!((row.1, row.2, row.3, row.4), (None, None, None, None));
    }
}

#[test]
fn the_load_places_the_chain_on_the_one_centreline_its_layout_keeps() {
    // The centreline is built once per load (issue 24): the layout's is the
    // spec's extended centreline, and the hinges the scene's bodies sit
    // between are the ones placed on it.
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &[]).unwrap();
    let (spec, layout) = doc.drill_pipe_parts().unwrap();
    assert_eq!(layout.centreline, spec.extended_centreline());
    let (hinges, _) = spec.placed_chain();
    assert_eq!(hinges, spec.hinge_positions());
    let bodies = &doc.scene().bodies;
    for k in 1..=spec.pipe.joints {
        let centre = 0.5 * (hinges[k - 1] + hinges[k]);
        let link = bodies[layout.chain[k]].position;
        assert_eq!(link, [centre.x, centre.y, centre.z], "link {k}");
    }
}

#[test]
fn links_too_long_for_the_centreline_are_placed_outside_it_clear_of_the_inner_wall() {
    // A 0.5 m link of Ø86 mm in a Ø106 mm tube bent to R = 2 m: eq. (9)
    // allows 0.57 m, but its chord between two hinges on the centreline has
    // a sagitta of R − √(R² − 0.25²) = 15.69 mm and cuts 15.69 + 43 − 53 =
    // 5.69 mm into the inner wall (the design chart's cell with
    // `--tube-id 106` started there and stopped at t = 0). Placed on the arc
    // of radius R + δ, δ = 5.69 mm, every link clears the inner wall and
    // stays within the outer one.
    let over = |d: f64| {
        [
            "borehole.curvature_radius=2.0".to_string(),
            "pipe.pitch=0.5".to_string(),
            format!("borehole.inner_diameter={d}"),
        ]
    };
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &over(0.106)).unwrap();
    let (spec, _) = doc.drill_pipe_parts().unwrap();
    let sagitta = 2.0 - (4.0f64 - 0.25 * 0.25).sqrt();
    let delta = sagitta + 0.043 - 0.053;
    assert!(
        (spec.placement_offset() - delta).abs() < 1e-15,
        "{}",
        spec.placement_offset()
    );
    assert!((delta - 5.69e-3).abs() < 1e-5);
    let (hinges, _) = spec.placed_chain();
    // The bend's centre: the arc starts at the origin downward and bends toward +x.
    let centre = Vec3::new(2.0, 0.0, 0.0);
    let (inner, outer) = (2.0 - 0.053, 2.0 + 0.053);
    let arc_end = spec.borehole.build_angle_deg.to_radians();
    let mut on_arc = 0;
    for k in 1..=spec.pipe.joints {
        let (a, b) = (hinges[k - 1] - centre, hinges[k] - centre);
        // Links wholly on the arc (both hinges at angles within it).
        let angle = |p: Vec3| (-p.z).atan2(-p.x);
        if angle(a) > arc_end || angle(b) > arc_end {
            continue;
        }
        on_arc += 1;
        let middle = (0.5 * (a + b)).norm();
        assert!(
            middle - 0.043 >= inner - 1e-12,
            "link {k} cuts {} m into the inner wall",
            inner - (middle - 0.043)
        );
        assert!(
            a.norm() + 0.043 <= outer + 1e-4,
            "link {k}'s end reaches {} m",
            a.norm() + 0.043
        );
    }
    assert!(on_arc >= 5, "{on_arc} links on the quarter arc of π m");
    // The paper's tube (Ø116 mm) with its 0.2 m links needs no offset: the
    // chord cuts nothing, and the chain sits on the centreline as before.
    let paper = Document::from_toml_str("kind = \"drill-pipe\"\n", &[]).unwrap();
    let (spec, _) = paper.drill_pipe_parts().unwrap();
    assert_eq!(spec.placement_offset(), 0.0);
    assert!(
        (spec.hinge_positions()[0]).norm() == 0.0,
        "hinge 0 at the arc's start"
    );
}
