//! A torque-free asymmetric body keeps its world-frame angular momentum
//! L = R·I·ω and its kinetic energy, while ω itself tumbles (Euler's equations
//! with the gyroscopic term ω × Iω).

mod common;

use ballcage_core::math::Vec3;

#[test]
fn torque_free_asymmetric_body_keeps_its_angular_momentum() {
    let mut sim = common::sim(
        r#"
        [simulation]
        duration = 10.0
        dt = 1e-3
        output_interval = 1e-1
        integrator = "rk4"
        [[bodies]]
        name = "brick"
        shape = { type = "cuboid", half_extents = [0.1, 0.2, 0.3] }
        mass = 2.0
        inertia = [0.1, 0.2, 0.25]
        orientation = [0.9238795325112867, 0.3826834323650898, 0.0, 0.0]
        angular_velocity = [0.3, 2.0, 0.2]
        "#,
    );
    let inertia = Vec3::new(0.1, 0.2, 0.25);
    let momentum = |s: &ballcage_core::State| s.rot[0] * inertia.component_mul(&s.omega[0]);
    let l0 = momentum(sim.state());
    let e0 = sim.energy().kinetic;
    let w0 = sim.state().omega[0];
    let mut max_change = 0.0_f64;
    for _ in 0..10_000 {
        sim.step().unwrap();
        let l = momentum(sim.state());
        max_change = max_change.max((l - l0).norm() / l0.norm());
    }
    assert_eq!(sim.steps(), 10_000);
    assert!(max_change < 1e-8, "|ΔL|/|L| = {max_change:.2e}");
    assert!(((sim.energy().kinetic - e0) / e0).abs() < 1e-8);
    // Near the intermediate axis the body tumbles: body-frame ω changes a lot.
    assert!(
        (sim.state().omega[0] - w0).norm() > 0.5,
        "no tumbling: ω barely changed"
    );
    assert!((sim.state().rot[0].norm() - 1.0).abs() < 1e-12);
}
