//! A body with no contacts falls as z(t) = z0 − g t²/2; RK4 integrates a
//! quadratic exactly, so only round-off remains.

mod common;

#[test]
fn free_fall_matches_the_parabola_to_round_off() {
    let mut sim = common::sim(
        r#"
        [simulation]
        duration = 1.0
        dt = 1e-3
        output_interval = 1e-2
        integrator = "rk4"
        [world]
        gravity = [0.0, 0.0, -9.81]
        [[bodies]]
        name = "ball"
        shape = { type = "ball", radius = 0.05 }
        mass = 1.0
        position = [0.0, 0.0, 10.0]
        "#,
    );
    let i = common::body(&sim, "ball");
    for k in 1..=100 {
        sim.advance_to(k as f64 * 0.01).unwrap();
        let t = sim.time();
        let expect = 10.0 - 0.5 * 9.81 * t * t;
        let z = sim.state().pos[i].z;
        assert!(
            ((z - expect) / expect).abs() < 1e-9,
            "t = {t}: z = {z}, expected {expect}"
        );
        assert!((sim.state().vel[i].z + 9.81 * t).abs() < 1e-9 * 9.81 * t.max(1.0));
    }
}

#[test]
fn symplectic_euler_free_fall_has_its_known_first_order_error() {
    // x_{n+1} = x_n + h v_{n+1}: z_n = z0 − g h² n(n+1)/2 exactly.
    let mut sim = common::sim(
        r#"
        [simulation]
        duration = 0.1
        dt = 1e-2
        output_interval = 1e-2
        integrator = "symplectic-euler"
        [world]
        gravity = [0.0, 0.0, -9.81]
        [[bodies]]
        name = "ball"
        shape = { type = "ball", radius = 0.05 }
        mass = 1.0
        "#,
    );
    sim.run().unwrap();
    let n = 10.0;
    let expect = -9.81 * 1e-4 * n * (n + 1.0) / 2.0;
    assert!((sim.state().pos[0].z - expect).abs() < 1e-12);
}
