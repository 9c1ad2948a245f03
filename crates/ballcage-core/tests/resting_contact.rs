//! A ball resting on a half-space settles where the contact spring carries
//! its weight: K δⁿ = m g, so δ = (m g / K)^(1/n). Damping drops out at rest.

mod common;

fn rest_depth(law: &str, m: f64, g: f64) -> f64 {
    let r = 0.0075;
    let toml = format!(
        r#"
        [simulation]
        duration = 0.4
        dt = 2e-6
        output_interval = 1e-3
        integrator = "rk4"
        [world]
        gravity = [0.0, 0.0, {neg_g}]
        [[bodies]]
        name = "ground"
        motion = "fixed"
        shape = {{ type = "half-space", normal = [0.0, 0.0, 1.0] }}
        [[bodies]]
        name = "ball"
        shape = {{ type = "ball", radius = {r} }}
        mass = {m}
        position = [0.0, 0.0, {r}]
        [[contacts]]
        bodies = ["ground", "ball"]
        normal = {law}
        "#,
        neg_g = -g
    );
    let mut sim = common::sim(&toml);
    sim.run().unwrap();
    let i = common::body(&sim, "ball");
    assert!(
        sim.state().vel[i].norm() < 1e-6,
        "ball still moving: {}",
        sim.state().vel[i]
    );
    r - sim.state().pos[i].z
}

#[test]
fn ball_on_half_space_settles_at_the_adams_law_equilibrium() {
    // The paper's law in its field units: K = 1e5 N/mm^2.2, n = 2.2, c = 10 N·s/mm, d = 0.1 mm.
    let (m, g) = (0.013872, 9.8);
    let depth = rest_depth(
        r#"{ law = "impact", stiffness = 1e5, exponent = 2.2, damping = 10.0, depth_max = 0.1, units = "N-mm-s" }"#,
        m,
        g,
    );
    let k_si = 1e5 * 1000f64.powf(2.2);
    let expect = (m * g / k_si).powf(1.0 / 2.2);
    assert!(
        ((depth - expect) / expect).abs() < 1e-3,
        "depth {depth} vs {expect}"
    );
}

#[test]
fn heavier_ball_on_a_linear_spring_settles_at_mg_over_k() {
    let (m, g) = (2.0, 9.81);
    let depth = rest_depth(
        r#"{ law = "linear", stiffness = 1e6, damping = 3000.0 }"#,
        m,
        g,
    );
    let expect = m * g / 1e6;
    assert!(
        ((depth - expect) / expect).abs() < 1e-3,
        "depth {depth} vs {expect}"
    );
}

#[test]
fn paper_field_units_convert_once_to_si() {
    // K = 1e5 N/mm^2.2 at δ = 0.1 mm gives 630.96 N.
    let scene = ballcage_core::Scene::from_toml_str(
        r#"
        [simulation]
        duration = 1e-3
        dt = 1e-3
        output_interval = 1e-3
        [[bodies]]
        name = "ground"
        motion = "fixed"
        shape = { type = "half-space", normal = [0.0, 0.0, 1.0] }
        [[bodies]]
        name = "ball"
        shape = { type = "ball", radius = 0.01 }
        mass = 1.0
        [[contacts]]
        bodies = ["ground", "ball"]
        normal = { law = "impact", stiffness = 1e5, exponent = 2.2, damping = 10.0, depth_max = 0.1, units = "N-mm-s" }
        "#,
        &[],
    )
    .unwrap();
    let law = ballcage_core::assembly::normal_law(&scene.contacts[0].normal);
    let f = law.evaluate(1e-4, 0.0, 0.0).force;
    assert!((f - 630.957).abs() < 0.01, "F(0.1 mm) = {f} N");
    // Full damping 10 N·s/mm = 1e4 N·s/m beyond d_max: 100 mm/s adds 1000 N.
    let f2 = law.evaluate(2e-4, 0.1, 0.0).force - law.evaluate(2e-4, 0.0, 0.0).force;
    assert!((f2 - 1000.0).abs() < 1e-6, "damping part {f2} N");
}
