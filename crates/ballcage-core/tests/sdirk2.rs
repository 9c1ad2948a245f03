//! The SDIRK2 integrator: its stiffness Jacobian against finite
//! differences, its order against closed forms, its Newton iterations, and
//! stiff contacts at steps where the other integrators fail.

mod common;

use ballcage_core::Simulation;
use ballcage_core::dynamics::{Dynamics, Mode, VelocityJacobian};
use ballcage_core::math::Vec3;

/// A ball pressed into a half-space (IMPACT law, Adams friction, sliding)
/// and a ball key pressed into a torus groove (the paper's law).
const PRESSED: &str = r#"
    [simulation]
    duration = 1e-3
    dt = 1e-5
    output_interval = 1e-3
    integrator = "sdirk2"
    [record]
    tables = []
    [[bodies]]
    name = "ground"
    motion = "fixed"
    shape = { type = "half-space", normal = [0.0, 0.0, 1.0] }
    [[bodies]]
    name = "ball"
    shape = { type = "ball", radius = 0.01 }
    mass = 0.03
    position = [0.0, 0.0, 0.0098]
    velocity = [0.2, 0.05, -0.01]
    [[bodies]]
    name = "race"
    motion = "fixed"
    shape = { type = "cuboid", half_extents = [0.02, 0.04, 0.04] }
    position = [1.0, 0.0, 0.0]
    [[bodies]]
    name = "key"
    shape = { type = "ball", radius = 0.006 }
    mass = 0.014
    position = [1.0, 0.0305, 0.0012]
    velocity = [0.1, -0.02, 0.15]
    angular_velocity = [-5.0, 10.0, 4.0]
    [[contacts]]
    bodies = ["ground", "ball"]
    normal = { law = "impact", stiffness = 1e9, exponent = 1.5, damping = 2000.0, depth_max = 1e-3 }
    friction = { law = "adams", mu_static = 0.3, mu_dynamic = 0.1, v_static = 0.1, v_dynamic = 1.0 }
    [[contacts]]
    bodies = ["race", "key"]
    geometry = { type = "torus-ball", centre = [0.0, 0.0, 0.0], axis = [1.0, 0.0, 0.0], core_radius = 0.03, tube_radius = 0.0062 }
    normal = { law = "impact", stiffness = 1e5, exponent = 2.2, damping = 10.0, depth_max = 0.1, units = "N-mm-s" }
    friction = { law = "adams", mu_static = 0.1, mu_dynamic = 0.05, v_static = 100.0, v_dynamic = 1000.0, units = "N-mm-s" }
"#;

#[test]
fn stiffness_jacobian_matches_finite_differences() {
    // K = (J(s) − J(0))/s against central differences of the force on each
    // ball with respect to its translation. On the half-space the normal
    // does not move with the ball, and without spin the slip does not depend
    // on the arm, so the whole translational block is exact. The key in the
    // groove is moving: the pose dependence of its damping and slip, which
    // K leaves out, shows in the sideways entries (about 1 % here), so only
    // the normal–normal entry is exact. tests/jacobian.rs checks every pair
    // kind at rest, where K is exact with its geometric terms.
    let sim = common::sim(PRESSED);
    let model = sim.model();
    let state = sim.state().clone();
    let mut dynamics = Dynamics::new(model);
    let (mut j0, mut j1) = (VelocityJacobian::new(model), VelocityJacobian::new(model));
    let s = 1e-3;
    dynamics.forces_and_jacobian(model, &state, Mode::Commit, 0.0, &mut j0);
    dynamics.forces_and_jacobian(model, &state, Mode::Trial, s, &mut j1);
    let k = (j1.to_dense(model.bodies.len()) - j0.to_dense(model.bodies.len())) / s;
    let mut force = |state: &ballcage_core::State, i: usize| {
        dynamics.wrenches(model, state, Mode::Trial);
        dynamics.forces()[i]
    };
    let fd = |i: usize, dir: Vec3, force: &mut dyn FnMut(&ballcage_core::State, usize) -> Vec3| {
        let e = 1e-9;
        let (mut plus, mut minus) = (state.clone(), state.clone());
        plus.pos[i] += e * dir;
        minus.pos[i] -= e * dir;
        (force(&plus, i) - force(&minus, i)) / (2.0 * e)
    };
    let ball = common::body(&sim, "ball");
    for c in 0..3 {
        let numeric = fd(ball, Vec3::ith(c, 1.0), &mut force);
        let analytic = Vec3::from_fn(|r, _| k[(6 * ball + r, 6 * ball + c)]);
        assert!(
            (analytic - numeric).norm() <= 1e-6 * numeric.norm().max(1.0),
            "ball column {c}: {analytic} vs {numeric}"
        );
    }
    // The stiffness is that of the law: dF/dδ = 1.5·k·δ^0.5 (+ the damping ramp's slope · δ̇).
    assert!(k[(6 * ball + 2, 6 * ball + 2)] < -1e5);
    let key = common::body(&sim, "key");
    let points = common::sim(PRESSED).pair_contacts(1);
    assert_eq!(points.len(), 1, "the key must touch its groove");
    let n = points[0].point.normal;
    let numeric = n.dot(&fd(key, n, &mut force));
    let block = nalgebra::Matrix3::from_fn(|r, c| k[(6 * key + r, 6 * key + c)]);
    let analytic = n.dot(&(block * n));
    assert!(
        ((analytic - numeric) / numeric).abs() < 1e-6,
        "key nᵀKn {analytic:e} vs {numeric:e}"
    );
}

/// The oscillator of tests/common at steps of `dt` with `integrator`.
fn oscillator(integrator: &str, dt: f64) -> Simulation {
    common::oscillator(&format!(
        "dt = {dt}\noutput_interval = 0.1\nintegrator = \"{integrator}\""
    ))
}

/// |z(T) − exact| of the oscillator at `dt`.
fn oscillator_error(integrator: &str, dt: f64) -> f64 {
    let mut sim = oscillator(integrator, dt);
    sim.run().unwrap();
    let i = common::body(&sim, "ball");
    (sim.state().pos[i].z - common::oscillator_exact(sim.time()).0).abs()
}

#[test]
fn sdirk2_is_second_order_and_linearly_implicit_euler_first() {
    // Halving the step divides the error by 2^p.
    for (integrator, order, dts) in [
        ("sdirk2", 2.0, [2e-3, 1e-3, 5e-4]),
        ("linearly-implicit-euler", 1.0, [2e-4, 1e-4, 5e-5]),
    ] {
        let e: Vec<f64> = dts
            .iter()
            .map(|&dt| oscillator_error(integrator, dt))
            .collect();
        for w in e.windows(2) {
            let p = (w[0] / w[1]).log2();
            assert!(
                (p - order).abs() < 0.15,
                "{integrator}: observed order {p:.3} (errors {e:?})"
            );
        }
    }
}

/// The tumbling box of tests/common, Newton to 1e-13.
fn tumbling(integrator: &str, dt: f64) -> Simulation {
    common::tumbling(integrator, dt, 1e-13)
}

#[test]
fn sdirk2_rotations_are_second_order_on_the_manifold() {
    let mut reference = tumbling("rk4", 1e-5);
    reference.run().unwrap();
    let i = common::body(&reference, "box");
    let r = reference.state().rot[i];
    let errors: Vec<f64> = [4e-3, 2e-3, 1e-3]
        .iter()
        .map(|&dt| {
            let mut sim = tumbling("sdirk2", dt);
            sim.run().unwrap();
            let q = sim.state().rot[i];
            assert!((q.norm() - 1.0).abs() < 1e-12);
            q.angle_to(&r)
        })
        .collect();
    for w in errors.windows(2) {
        let p = (w[0] / w[1]).log2();
        assert!((p - 2.0).abs() < 0.2, "observed order {p:.3} ({errors:?})");
    }
}

/// The 14 g ball key of implicit.rs loaded by 6 kN (gravity scaled), with
/// the paper's IMPACT law or without damping.
fn loaded_key(dt: f64, damping: f64, extra: &str) -> Simulation {
    common::ball_on_floor(
        &format!(
            "duration = 0.05\ndt = {dt}\noutput_interval = 1e-3\nintegrator = \"sdirk2\"\n{extra}"
        ),
        6000.0 / 0.014,
        "shape = { type = \"ball\", radius = 0.0075 }\nmass = 0.014\nposition = [0.0, 0.0, 0.0075]",
        &format!(
            "normal = {{ law = \"impact\", stiffness = 1e5, exponent = 2.2, damping = {damping}, \
             depth_max = 0.1, units = \"N-mm-s\" }}"
        ),
    )
}

#[test]
fn stiff_contact_settles_at_a_hundred_times_the_explicit_step() {
    // docs/model.md §5: δ = (F/K)^(1/2.2) = 0.278 mm; the contact's ω is about
    // 5.8e4 rad/s (k_tan = 2.2·F/δ = 4.7e7 N/m on 14 g) and c/m = 7.1e5 1/s, so symplectic Euler needs h < 2.8 µs.
    // SDIRK2 at 100 µs, with the paper's damping and with none at all
    // (L-stability damps the unresolved oscillation).
    let k = 1e5 * 1000f64.powf(2.2);
    let expect = (6000.0 / k).powf(1.0 / 2.2);
    for damping in [10.0, 0.0] {
        let mut sim = loaded_key(1e-4, damping, "");
        sim.run().unwrap();
        let i = common::body(&sim, "ball");
        let depth = 0.0075 - sim.state().pos[i].z;
        assert!(
            ((depth - expect) / expect).abs() < 1e-3,
            "c = {damping}: δ = {depth:e} m, expected {expect:e} m"
        );
        assert!(sim.state().vel[i].norm() < 1e-3);
    }
}

#[test]
fn the_jacobian_is_reused_while_newton_converges_fast() {
    // Settling under load: after the transient, Newton converges within a
    // few iterations on the reused factorization.
    let mut reused = loaded_key(1e-4, 10.0, "");
    reused.run().unwrap();
    let mut fresh = loaded_key(1e-4, 10.0, "newton = { reuse_jacobian = false }");
    fresh.run().unwrap();
    let (a, b) = (reused.solver_stats(), fresh.solver_stats());
    assert_eq!(reused.steps(), 500);
    assert!(
        b.factorizations >= reused.steps(),
        "{b:?}: a fresh Jacobian per step"
    );
    assert!(
        a.factorizations * 10 < b.factorizations,
        "reuse saved too little: {a:?} vs {b:?}"
    );
    // One force evaluation per iteration; a solve unless the line search
    // halved the last increment instead.
    assert!(a.solves <= a.newton_iterations);
    assert_eq!(reused.force_evaluations(), a.newton_iterations);
    let i = common::body(&reused, "ball");
    let dz = reused.state().pos[i].z - fresh.state().pos[i].z;
    assert!(dz.abs() < 1e-9, "reuse changed the answer by {dz:e} m");
}

#[test]
fn newton_that_cannot_converge_is_a_divergence_error_without_the_fallback() {
    let mut sim = loaded_key(
        1e-4,
        10.0,
        "newton = { tolerance = 1e-300, max_iterations = 3, fallback = false }",
    );
    let e = sim.run().unwrap_err();
    let text = e.to_string();
    assert!(
        text.contains("Newton iterations of SDIRK2 stage 1 did not converge"),
        "{text}"
    );
    assert!(text.contains("simulation.newton.tolerance"), "{text}");
    assert_eq!(e.step, 0);
    // The run stays stopped.
    assert!(sim.step().is_err());
}

/// With the fallback (the default) a step whose Newton iterations cannot
/// converge (tolerance 1e-300) is halved four times and each h/16 part step
/// that still fails is taken by the linearly implicit Euler step, so the run
/// completes: every fallback is an h/16 part step (15 halvings per 16), and
/// the key settles where the IMPACT law carries its weight,
/// δ = (m·g/K)^(1/2.2) = (6000 N / 1e5 N/mm^2.2)^(1/2.2) = 0.2781 mm.
#[test]
fn newton_that_cannot_converge_falls_back_to_linearly_implicit_euler_at_h_over_16() {
    let mut sim = loaded_key(
        1e-4,
        10.0,
        "newton = { tolerance = 1e-300, max_iterations = 3 }",
    );
    sim.run().unwrap();
    let stats = sim.solver_stats();
    assert_eq!(sim.steps(), 500);
    assert!(stats.fallbacks > 500, "{stats:?}");
    assert!(16 * stats.halvings >= 15 * stats.fallbacks, "{stats:?}");
    let i = common::body(&sim, "ball");
    let depth = 0.0075 - sim.state().pos[i].z;
    let hand = (6000.0f64 / 1e5).powf(1.0 / 2.2) * 1e-3;
    assert!((depth - hand).abs() < 1e-3 * hand, "{depth} m vs {hand} m");
}
