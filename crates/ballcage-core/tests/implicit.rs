//! The linearly implicit Euler integrator: its velocity Jacobian against
//! finite differences, and its steps against closed forms and against
//! symplectic Euler where the latter fails.

mod common;

use ballcage_core::Simulation;
use ballcage_core::dynamics::{Dynamics, Mode, VelocityJacobian};
use ballcage_core::math::Vec3;
use ballcage_core::model::{Model, State};

/// The wrenches [F; τ] (world frame) of every body of `ids`, stacked.
fn wrenches(dynamics: &mut Dynamics, model: &Model, state: &State, ids: &[usize]) -> Vec<f64> {
    let mut jac = VelocityJacobian::new(model);
    dynamics.forces_and_jacobian(model, state, Mode::Trial, 0.0, &mut jac);
    let mut out = vec![];
    for &i in ids {
        out.extend(dynamics.forces()[i].iter());
        out.extend(dynamics.torques()[i].iter());
    }
    out
}

/// Perturbs component k of body i's world twist [v; ω] by `e`.
fn perturb(state: &mut State, i: usize, k: usize, e: f64) {
    if k < 3 {
        state.vel[i][k] += e;
    } else {
        let mut w = state.omega_world(i);
        w[k - 3] += e;
        state.omega[i] = state.rot[i].inverse() * w;
    }
}

/// Checks the assembled D against central differences of the wrenches with
/// respect to every integrated body's twist; every 3×3 sub-block must agree
/// to `rtol` of its largest entry. Returns the number of non-zero sub-blocks
/// compared.
fn check_jacobian(sim: &Simulation, rtol: f64) -> usize {
    let model = sim.model();
    let state = sim.state().clone();
    let ids = model.integrated.clone();
    let mut dynamics = Dynamics::new(model);
    let mut jac = VelocityJacobian::new(model);
    // Latch the approach speeds at this state, then hold them.
    dynamics.forces_and_jacobian(model, &state, Mode::Commit, 0.0, &mut jac);
    let dense = jac.to_dense(model.bodies.len());
    let n = 6 * ids.len();
    let mut fd = nalgebra::DMatrix::<f64>::zeros(n, n);
    for (cj, &j) in ids.iter().enumerate() {
        for k in 0..6 {
            let e = if k < 3 { 1e-7 } else { 1e-6 };
            let mut plus = state.clone();
            perturb(&mut plus, j, k, e);
            let mut minus = state.clone();
            perturb(&mut minus, j, k, -e);
            let fp = wrenches(&mut dynamics, model, &plus, &ids);
            let fm = wrenches(&mut dynamics, model, &minus, &ids);
            for r in 0..n {
                fd[(r, 6 * cj + k)] = (fp[r] - fm[r]) / (2.0 * e);
            }
        }
    }
    let mut compared = 0;
    let mut worst = 0.0_f64;
    for (ri, &i) in ids.iter().enumerate() {
        for (cj, &j) in ids.iter().enumerate() {
            for (hr, hc) in [(0, 0), (0, 3), (3, 0), (3, 3)] {
                let sub = |m: &dyn Fn(usize, usize) -> f64| {
                    nalgebra::Matrix3::from_fn(|r, c| m(r + hr, c + hc))
                };
                let analytic = sub(&|r, c| dense[(6 * i + r, 6 * j + c)]);
                let numeric = sub(&|r, c| fd[(6 * ri + r, 6 * cj + c)]);
                let scale = analytic.amax().max(numeric.amax());
                if scale == 0.0 {
                    continue;
                }
                compared += 1;
                let err = (analytic - numeric).amax();
                worst = worst.max(err / scale);
                assert!(
                    err <= rtol * scale,
                    "bodies {} ← {} rows {hr} cols {hc}: error {err:.3e} of {scale:.3e}\n\
                     analytic {analytic}\nfinite differences {numeric}",
                    model.bodies[i].name,
                    model.bodies[j].name,
                );
            }
        }
    }
    eprintln!("{compared} sub-blocks, worst relative error {worst:.2e}");
    compared
}

const JACOBIAN_SCENE: &str = r#"
    [simulation]
    duration = 1e-3
    dt = 1e-5
    output_interval = 1e-3
    integrator = "linearly-implicit-euler"
    [world]
    gravity = [0.0, 0.0, -9.81]
    [record]
    tables = []

    # A tilted cuboid sliding and spinning on a half-space, Adams friction.
    [[bodies]]
    name = "ground"
    motion = "fixed"
    shape = { type = "half-space", normal = [0.0, 0.0, 1.0] }
    [[bodies]]
    name = "block"
    shape = { type = "cuboid", half_extents = [0.05, 0.04, 0.02] }
    mass = 1.0
    position = [0.0, 0.0, 0.0196]
    orientation = [0.99999932, 0.001, -0.0006, 0.0]
    velocity = [0.3, 0.12, -0.02]
    angular_velocity = [0.2, -0.1, 1.5]

    # A ball pressed against the wall of a moving tube, Hunt–Crossley (latched) and tanh friction.
    [[bodies]]
    name = "pipe"
    shape = { type = "tube", inner_radius = 0.0105, start = [-0.5, 1.0, 0.0], direction = [1.0, 0.0, 0.0], segments = [{ type = "straight", length = 1.0 }] }
    mass = 2.0
    inertia = [0.01, 0.02, 0.02]
    position = [0.0, 0.0, 0.0]
    velocity = [0.01, -0.02, 0.005]
    angular_velocity = [-0.1, 0.1, -0.2]
    [[bodies]]
    name = "ball"
    shape = { type = "ball", radius = 0.01 }
    mass = 0.03
    position = [0.1, 1.0006, 0.0005]
    velocity = [0.2, 0.03, -0.05]
    angular_velocity = [3.0, -2.0, 7.0]

    # A ball key in a torus groove of a free race: the paper's IMPACT law, Adams friction in N-mm-s.
    [[bodies]]
    name = "race"
    shape = { type = "cuboid", half_extents = [0.02, 0.04, 0.04] }
    mass = 0.5
    position = [1.0, 0.0, 0.0]
    orientation = [0.9998, 0.02, 0.0, 0.0]
    velocity = [0.0, 0.01, 0.02]
    angular_velocity = [2.0, 0.3, -0.1]
    [[bodies]]
    name = "key"
    shape = { type = "ball", radius = 0.006 }
    mass = 0.014
    position = [1.0, 0.0305, 0.0012]
    velocity = [0.1, -0.02, 0.15]
    angular_velocity = [-5.0, 10.0, 4.0]

    [[contacts]]
    bodies = ["ground", "block"]
    normal = { law = "impact", stiffness = 1e9, exponent = 1.5, damping = 2000.0, depth_max = 1e-3 }
    friction = { law = "adams", mu_static = 0.3, mu_dynamic = 0.1, v_static = 0.1, v_dynamic = 1.0 }
    [[contacts]]
    bodies = ["pipe", "ball"]
    normal = { law = "hunt-crossley", stiffness = 1e9, restitution = 0.7 }
    friction = { law = "tanh", mu = 0.2, v_ref = 0.05 }
    [[contacts]]
    bodies = ["race", "key"]
    geometry = { type = "torus-ball", centre = [0.0, 0.0, 0.0], axis = [1.0, 0.0, 0.0], core_radius = 0.03, tube_radius = 0.0062 }
    normal = { law = "impact", stiffness = 1e5, exponent = 2.2, damping = 10.0, depth_max = 0.1, units = "N-mm-s" }
    friction = { law = "adams", mu_static = 0.1, mu_dynamic = 0.05, v_static = 100.0, v_dynamic = 1000.0, units = "N-mm-s" }
"#;

#[test]
fn velocity_jacobian_matches_finite_differences() {
    let mut sim = common::sim(JACOBIAN_SCENE);
    // Every pair is in contact with positive normal force and smooth slip
    // (block: 4 vertices sliding at 0.25–0.41 m/s; ball: 0.083 m/s; key: 0.080 m/s).
    for k in 0..sim.model().pairs.len() {
        let points = sim.pair_contacts(k);
        assert!(!points.is_empty(), "pair {k} is not in contact");
        for p in &points {
            assert!(p.normal_force > 0.0, "pair {k}: {p:?}");
            assert!(p.slip_speed > 1e-3, "pair {k}: {p:?}");
        }
    }
    let compared = check_jacobian(&sim, 1e-5);
    assert!(compared >= 12, "only {compared} non-zero sub-blocks");
}

#[test]
fn joint_damper_jacobian_matches_finite_differences() {
    let sim = common::sim(
        r#"
        [simulation]
        duration = 1e-3
        dt = 1e-5
        output_interval = 1e-3
        integrator = "linearly-implicit-euler"
        [record]
        tables = []
        [[bodies]]
        name = "head"
        shape = { type = "cylinder", radius = 0.03, half_length = 0.1 }
        mass = 2.0
        velocity = [0.1, -0.2, 0.05]
        angular_velocity = [3.0, 0.4, -0.2]
        [[bodies]]
        name = "seat"
        shape = { type = "cylinder", radius = 0.03, half_length = 0.1 }
        mass = 1.5
        position = [0.2, 0.01, 0.0]
        orientation = [0.99875, 0.0, 0.0, 0.04998]
        velocity = [0.12, -0.1, 0.0]
        angular_velocity = [2.5, -0.3, 0.6]
        [[joints]]
        type = "cv"
        bodies = ["head", "seat"]
        anchors = [[0.1, 0.0, 0.0], [-0.1, 0.0, 0.0]]
        stiffness = 1e8
        damping = 2e3
        twist_stiffness = 1e5
        twist_damping = 50.0
        "#,
    );
    let compared = check_jacobian(&sim, 1e-5);
    assert!(compared >= 8, "only {compared} non-zero sub-blocks");
}

fn free_body(integrator: &str) -> Simulation {
    common::sim(&format!(
        r#"
        [simulation]
        duration = 0.5
        dt = 1e-3
        output_interval = 0.1
        integrator = "{integrator}"
        [world]
        gravity = [0.0, 0.0, -9.81]
        [record]
        tables = []
        [[bodies]]
        name = "box"
        shape = {{ type = "cuboid", half_extents = [0.1, 0.05, 0.02] }}
        mass = 1.0
        position = [0.0, 0.0, 2.0]
        velocity = [0.3, 0.0, 0.0]
        angular_velocity = [0.5, 4.0, 0.2]
        "#
    ))
}

#[test]
fn free_fall_follows_the_closed_form_of_the_scheme() {
    let mut sim = free_body("linearly-implicit-euler");
    let (h, g, z0) = (1e-3, 9.81, 2.0);
    let i = common::body(&sim, "box");
    for n in 1..=500u64 {
        sim.step().unwrap();
        let nf = n as f64;
        // v_n = −g·h·n, z_n = z0 − g·h²·n(n+1)/2 (positions from the new velocities).
        let s = sim.state();
        let z = z0 - g * h * h * nf * (nf + 1.0) / 2.0;
        assert!(
            (s.pos[i].z - z).abs() <= 1e-13 * z0,
            "step {n}: {} vs {z}",
            s.pos[i].z
        );
        assert!((s.vel[i].z + g * h * nf).abs() <= 1e-13 * g * h * nf);
        assert!((s.pos[i].x - 0.3 * h * nf).abs() <= 1e-14);
    }
    assert_eq!(sim.steps(), 500);
    assert_eq!(sim.linear_solves(), 500);
    assert_eq!(sim.force_evaluations(), 500);
}

#[test]
fn without_velocity_dependent_forces_it_is_symplectic_euler() {
    // A tumbling box (gyroscopic terms explicit in both): the same state to round-off.
    let mut implicit = free_body("linearly-implicit-euler");
    let mut explicit = free_body("symplectic-euler");
    implicit.run().unwrap();
    explicit.run().unwrap();
    let (a, b) = (implicit.state(), explicit.state());
    let i = common::body(&implicit, "box");
    assert!(
        (a.omega[i] - b.omega[i]).norm() < 1e-12,
        "{} vs {}",
        a.omega[i],
        b.omega[i]
    );
    assert!(a.rot[i].angle_to(&b.rot[i]) < 1e-12);
    assert!((a.pos[i] - b.pos[i]).norm() < 1e-12);
    assert_eq!(explicit.linear_solves(), 0);
}

/// A 14 g ball key on a half-space under the paper's IMPACT law, loaded by
/// `g` (gravity scaled to stand for the squeeze of the races), starting
/// `d0` deep at rest.
fn loaded_ball(integrator: &str, g: f64, d0: f64, duration: f64) -> Simulation {
    common::ball_on_floor(
        &format!(
            "duration = {duration}\ndt = 1e-5\noutput_interval = 1e-3\nintegrator = \"{integrator}\""
        ),
        g,
        &format!(
            "shape = {{ type = \"ball\", radius = 0.0075 }}\nmass = 0.014\nposition = [0.0, 0.0, {z0}]",
            z0 = 0.0075 - d0
        ),
        PAPER_IMPACT,
    )
}

/// The paper's IMPACT law for the ball keys, as a contact's `normal` key.
const PAPER_IMPACT: &str = "normal = { law = \"impact\", stiffness = 1e5, exponent = 2.2, \
     damping = 10.0, depth_max = 0.1, units = \"N-mm-s\" }";

/// Runs to the end (or the first error); returns the result, the final
/// depth [m] and the largest speed seen at 1 ms samples [m/s].
fn run_ball(sim: &mut Simulation) -> (Result<(), ballcage_core::SimulationError>, f64, f64) {
    let i = common::body(sim, "ball");
    let mut vmax = 0.0_f64;
    while !sim.is_done() {
        let r = sim.advance_to(sim.time() + 1e-3);
        vmax = vmax.max(sim.state().vel[i].norm());
        if r.is_err() {
            return (r, f64::NAN, vmax);
        }
    }
    (Ok(()), 0.0075 - sim.state().pos[i].z, vmax)
}

#[test]
fn stiff_damped_contact_settles_where_symplectic_euler_diverges() {
    // 6 kN on the key (docs/model.md §5: δ = 0.278 mm, c/m = 7.1e5 1/s, so
    // h·c/m = 7 at h = 10 µs, far past symplectic Euler's limit of about 2).
    let (m, k, n) = (0.014, 1e5 * 1000f64.powf(2.2), 2.2);
    let g = 6000.0 / m;
    let expect = (m * g / k).powf(1.0 / n);
    for d0 in [0.0, 2e-4] {
        let (r, _, vmax) = run_ball(&mut loaded_ball("symplectic-euler", g, d0, 0.05));
        // It cannot go non-finite (the no-pull clamp ejects the ball at each
        // overshoot), but every impact returns it faster: it diverges.
        assert!(
            r.is_err() || vmax > 100.0,
            "symplectic Euler stayed bounded: {vmax} m/s"
        );
        let (r, depth, vmax) = run_ball(&mut loaded_ball("linearly-implicit-euler", g, d0, 0.05));
        r.unwrap();
        assert!(vmax < 0.1, "{vmax}");
        assert!(
            ((depth - expect) / expect).abs() < 5e-3,
            "δ = {depth:e} m, expected {expect:e} m"
        );
    }
    // The ball resting under its own weight (δ = 2.2 µm, light damping): the
    // implicit step settles too (symplectic Euler is stable here as well).
    let g = 9.81;
    let expect = (m * g / k).powf(1.0 / n);
    let (r, depth, _) = run_ball(&mut loaded_ball("linearly-implicit-euler", g, 1e-4, 0.2));
    r.unwrap();
    assert!(
        ((depth - expect) / expect).abs() < 5e-3,
        "δ = {depth:e}, expected {expect:e}"
    );
}

fn incline(integrator: &str, alpha_deg: f64, dt: f64, duration: f64) -> Simulation {
    common::sim(&common::incline_scene(
        alpha_deg, integrator, dt, dt, duration,
    ))
}

#[test]
fn incline_creep_where_symplectic_euler_chatters() {
    // The scene of incline_creep.rs at 25 times its step: symplectic Euler
    // rocks on the vertex springs and tumbles; the implicit step creeps at
    // v = u·v_s, u(3 − u²)/2 = cot α/μs (docs/model.md §7.7: 72.0 mm/s at 75°).
    let dt = 5e-4;
    let mut explicit = incline("symplectic-euler", 75.0, dt, 0.6);
    let i = common::body(&explicit, "block");
    let r = explicit.run();
    let v = explicit.state().vel[i];
    assert!(
        r.is_err() || ((v.x * 1e3 - 72.0) / 72.0).abs() > 0.5 || v.z.abs() > 1e-2,
        "symplectic Euler did not chatter: {v}"
    );
    let mut implicit = incline("linearly-implicit-euler", 75.0, dt, 0.6);
    implicit.run().unwrap();
    let v = implicit.state().vel[i];
    let creep = v.x * 1e3;
    assert!(
        ((creep - 72.0) / 72.0).abs() < 0.02,
        "creep {creep:.3} mm/s"
    );
    assert!(v.z.abs() < 1e-6 && v.y.abs() < 1e-9, "{v}");
    assert!(implicit.state().omega[i].norm() < 1e-6);
}

fn wheel_and_roller(integrator: &str, dt: f64) -> Simulation {
    common::sim(&format!(
        r#"
        [simulation]
        duration = 0.1
        dt = {dt}
        output_interval = 0.01
        integrator = "{integrator}"
        [world]
        gravity = [9.81, 0.0, 0.0]
        [record]
        tables = []
        [[bodies]]
        name = "wheel"
        motion = "spin"
        spin_axis = [0.0, 0.0, 1.0]
        shape = {{ type = "ball", radius = 0.05 }}
        mass = 1.0
        angular_velocity = [0.0, 0.0, 4.0]
        [[bodies]]
        name = "roller"
        shape = {{ type = "ball", radius = 0.02 }}
        mass = 0.1
        position = [-0.06999, 0.0, 0.0]
        [[contacts]]
        bodies = ["wheel", "roller"]
        normal = {{ law = "linear", stiffness = 1e5, damping = 50.0 }}
        friction = {{ law = "adams", mu_static = 0.5, mu_dynamic = 0.3, v_static = 1e-3, v_dynamic = 1e-2 }}
        [[loads]]
        type = "torque"
        body = "wheel"
        axis = [0.0, 0.0, 1.0]
        magnitude = -0.002
        "#
    ))
}

#[test]
fn spin_body_coupled_by_stiff_friction_matches_a_fine_reference() {
    // A braked spin wheel drags a ball pressed against it from sliding into
    // rolling; near zero slip the friction rate is about 2.6e4 1/s.
    let mut reference = wheel_and_roller("rk4", 1e-6);
    let mut implicit = wheel_and_roller("linearly-implicit-euler", 1e-4);
    reference.run().unwrap();
    implicit.run().unwrap();
    let (w, r) = (
        common::body(&implicit, "wheel"),
        common::body(&implicit, "roller"),
    );
    let (a, b) = (implicit.state(), reference.state());
    let close = |x: Vec3, y: Vec3, what: &str| {
        assert!((x - y).norm() <= 1e-4 * y.norm(), "{what}: {x} vs {y}");
    };
    close(a.omega_world(w), b.omega_world(w), "wheel spin");
    close(a.vel[r], b.vel[r], "roller velocity");
    close(a.omega_world(r), b.omega_world(r), "roller spin");
    close(a.pos[r], b.pos[r], "roller position");
    assert_eq!(a.omega_world(w).xy(), nalgebra::Vector2::zeros());
    assert_eq!(implicit.linear_solves(), 1000);
}
