//! Divergence detection: a penetration beyond the scene's limit, energy
//! created by the integrator, the stable step named in the error against
//! its closed form, and the partial recording marked incomplete.

mod common;

use std::collections::HashMap;

use ballcage_core::Simulation;

/// A 1 kg ball of radius 50 mm on a linear spring-dashpot floor
/// (k [N/m], c [N·s/m]) under gravity, starting at rest depth moving
/// down at `v0` [m/s].
fn ball_on_spring(integrator: &str, dt: f64, k: f64, c: f64, v0: f64, extra: &str) -> Simulation {
    common::sim(&format!(
        r#"
        [simulation]
        duration = 0.2
        dt = {dt}
        output_interval = {dt}
        integrator = "{integrator}"
        {extra}
        [world]
        gravity = [0.0, 0.0, -9.81]
        [record]
        tables = ["bodies"]
        [[bodies]]
        name = "floor"
        motion = "fixed"
        shape = {{ type = "half-space", normal = [0.0, 0.0, 1.0] }}
        [[bodies]]
        name = "ball"
        shape = {{ type = "ball", radius = 0.05 }}
        mass = 1.0
        position = [0.0, 0.0, {z0}]
        velocity = [0.0, 0.0, {vz}]
        [[contacts]]
        bodies = ["floor", "ball"]
        normal = {{ law = "linear", stiffness = {k}, damping = {c} }}
        "#,
        z0 = 0.05 - 9.81 / k,
        vz = -v0,
    ))
}

fn metadata(sim: Simulation) -> (HashMap<String, String>, usize) {
    let rec = sim.finish();
    let rows = rec.tables.iter().map(|t| t.rows).sum();
    (rec.metadata.into_iter().collect(), rows)
}

#[test]
fn penetration_beyond_the_limit_stops_the_run() {
    // A soft floor (ω = 100 rad/s) hit at 5 m/s at its rest depth
    // δ_s = mg/k = 0.98 mm: the ball would sink to δ_s + v0/ω = 51 mm, past
    // the default limit of 0.25 × 50 mm = 12.5 mm, which it crosses at
    // t = asin((12.5 mm − δ_s)/(v0/ω))/ω = 2.32 ms.
    let mut sim = ball_on_spring("rk4", 1e-5, 1e4, 0.0, 5.0, "");
    let e = sim.run().unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("pair `floor/ball` (bodies `floor` and `ball`) penetrates"),
        "{text}"
    );
    assert!(text.contains("beyond its limit of 12.5000 mm"), "{text}");
    // RK4's stable step on this contact, 1.4 × 2/ω = 28 ms, is far above the
    // 10 µs step: the message says the penetration may be physical.
    assert!(text.contains("the penetration may be physical"), "{text}");
    assert!(text.contains("2.800e-2 s"), "{text}");
    let t_cross = ((12.5e-3 - 9.81e-4) / 0.05f64).asin() / 100.0;
    assert!(
        (e.time - t_cross).abs() <= 1e-5,
        "stopped at {} s, expected about {t_cross} s",
        e.time
    );
    // The frames up to the failure are kept, marked incomplete.
    let steps = e.step as usize;
    let (meta, rows) = metadata(sim);
    assert_eq!(meta["ballcage.complete"], "false");
    assert_eq!(meta["ballcage.error"], text);
    // Frames 0 to the last full step before the failing one, every step.
    assert!(
        rows > 0 && rows % steps == 0,
        "{rows} rows for {steps} steps"
    );

    // A limit set in the scene lets the same impact through.
    let mut sim = ball_on_spring(
        "rk4",
        1e-5,
        1e4,
        0.0,
        5.0,
        "divergence = { max_penetration = 0.06 }",
    );
    sim.run().unwrap();
}

#[test]
fn the_advised_step_is_the_closed_form_stability_limit() {
    // Symplectic Euler on m·x'' = −k·x − c·x' is stable for
    // h < 2 / (c/2m + √((c/2m)² + k/m)): 1.9025e-3 s for k = 1e6, c = 100.
    let (k, c): (f64, f64) = (1e6, 100.0);
    let limit = 2.0 / (c / 2.0 + (c * c / 4.0 + k).sqrt());
    let mut sim = ball_on_spring("symplectic-euler", 2.2e-3, k, c, 0.01, "");
    let e = sim.run().unwrap_err();
    let text = e.to_string();
    let advised: f64 = text
        .split("simulation.dt ≤ ")
        .nth(1)
        .and_then(|t| t.split(' ').next())
        .and_then(|t| t.parse().ok())
        .unwrap_or_else(|| panic!("no advised step in {text}"));
    assert!(
        ((advised - limit) / limit).abs() < 1e-3,
        "advised {advised} s, closed form {limit} s"
    );
    assert!(
        text.contains("with symplectic-euler (pair `floor/ball`"),
        "{text}"
    );
    // At half the limit it runs to the end, its energy bounded (closer to
    // the limit the energy symplectic Euler shows swings by up to
    // 1/(1 − (hω/2)²), which the balance check takes for divergence).
    let mut sim = ball_on_spring("symplectic-euler", 0.5 * limit, k, c, 0.01, "");
    sim.run().unwrap();
    let i = common::body(&sim, "ball");
    assert!(sim.state().vel[i].norm() < 0.01);
}

#[test]
fn energy_created_without_contact_stops_the_run() {
    // Two 1 kg bodies on a stiff joint spring (relative ω = √(2k/m) =
    // 1414 rad/s): symplectic Euler at h·ω = 2.8 > 2 gains energy every
    // step; the balance check at each frame stops it long before the state
    // overflows, and no contact gives a stable-step estimate.
    let mut sim = common::sim(
        r#"
        [simulation]
        duration = 1.0
        dt = 2e-3
        output_interval = 2e-2
        integrator = "symplectic-euler"
        [record]
        tables = ["energy"]
        [[bodies]]
        name = "a"
        shape = { type = "ball", radius = 0.05 }
        mass = 1.0
        inertia = [0.001, 0.001, 0.001]
        [[bodies]]
        name = "b"
        shape = { type = "ball", radius = 0.05 }
        mass = 1.0
        inertia = [0.001, 0.001, 0.001]
        position = [0.2, 0.0, 0.0]
        velocity = [0.01, 0.0, 0.0]
        [[joints]]
        type = "cv"
        bodies = ["a", "b"]
        anchors = [[0.1, 0.0, 0.0], [-0.1, 0.0, 0.0]]
        stiffness = 1e6
        damping = 0.0
        twist_stiffness = 1.0
        twist_damping = 0.0
        "#,
    );
    let e = sim.run().unwrap_err();
    let text = e.to_string();
    assert!(text.contains("the integrator created"), "{text}");
    assert!(
        text.contains("simulation.divergence.energy_growth"),
        "{text}"
    );
    assert!(text.contains("no contact was active"), "{text}");
    assert!(e.time <= 0.1, "caught late, at {} s", e.time);
    assert!(sim.state().vel.iter().all(|v| v.norm().is_finite()));
    // The metadata reports the share of the energy limit that stopped it,
    // above 1, and, without contact, no penetration and no pair.
    let meta = sim.finish().metadata;
    let value = |key: &str| meta.iter().find(|(k, _)| k == key).map(|(_, v)| v.clone());
    let share: f64 = value("ballcage.energy_of_limit")
        .expect("reported")
        .parse()
        .unwrap();
    assert!(share > 1.0, "energy share {share}");
    assert_eq!(
        value("ballcage.penetration_of_limit").as_deref(),
        Some("0.000000e0")
    );
    assert_eq!(value("ballcage.penetration_of_limit_pair"), None);
}
