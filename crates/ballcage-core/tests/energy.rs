//! Energy conservation of elastic (restitution-free) contacts, docs/model.md §7.11.
//!
//! With no damping, friction, gravity or drive, the total energy (kinetic +
//! elastic contact energy) of colliding bodies is a constant of the motion;
//! what the integrator changes is its truncation error, which shrinks with dt.

mod common;

use ballcage_core::{Scene, Simulation};

/// One steel ball (r = 40 mm, ρ = 7850: m = 2.1044 kg) flying at 1 m/s
/// against a fixed half-space, Hertz law F = K·δ^1.5 with K = 1e9 N/m^1.5,
/// no gravity, RK4 at step `dt`. Returns (largest relative energy error over
/// the run, largest normal force [N], its depth [m], contact duration [s]
/// from the first to the last step with F > 0, rebound velocity [m/s]).
fn single_hertz_impact(dt: f64) -> (f64, f64, f64, f64, f64) {
    let toml = format!(
        r#"
        [simulation]
        duration = 0.015
        dt = {dt}
        output_interval = 0.005
        integrator = "rk4"
        [record]
        tables = []
        [[bodies]]
        name = "wall"
        motion = "fixed"
        shape = {{ type = "half-space", normal = [1.0, 0.0, 0.0] }}
        [[bodies]]
        name = "ball"
        shape = {{ type = "ball", radius = 0.04 }}
        density = 7850.0
        position = [0.045, 0.0, 0.0]
        velocity = [-1.0, 0.0, 0.0]
        [[contacts]]
        bodies = ["wall", "ball"]
        normal = {{ law = "hertz", stiffness = 1e9 }}
        "#
    );
    let mut sim = common::sim(&toml);
    let ball = common::body(&sim, "ball");
    let e0 = sim.energy().total();
    let (mut worst, mut f_max, mut d_max) = (0.0_f64, 0.0_f64, 0.0_f64);
    let (mut first, mut last) = (f64::NAN, f64::NAN);
    while !sim.is_done() {
        sim.step().unwrap();
        worst = worst.max(((sim.energy().total() - e0) / e0).abs());
        if let Some(c) = sim.pair_contacts(0).first()
            && c.normal_force > 0.0
        {
            if first.is_nan() {
                first = sim.time();
            }
            last = sim.time();
            if c.normal_force > f_max {
                f_max = c.normal_force;
                d_max = c.point.depth;
            }
        }
    }
    (worst, f_max, d_max, last - first, sim.state().vel[ball].x)
}

/// A single elastic impact, checked against its closed form (docs/model.md
/// §2.1 "Undamped impact", §7.2) and for energy conservation.
///
/// Hand calculation: m = 7850·(4/3)π·0.04³ = 2.1044 kg, v = 1 m/s, n = 1.5,
/// δ_max = ((n+1)·m·v²/(2K))^(1/(n+1)) = (2.5·2.1044/2e9)^0.4 = 0.3698 mm,
/// F_max = K·δ_max^1.5 = 7113 N, t_c = 2.9433·δ_max/v = 1.089 ms, and with
/// no loss the ball leaves at +1 m/s.
///
/// First the test checks the collision happened (a positive normal force at
/// some step, the velocity reversed), so the energy check is not vacuous.
/// Invariant: the total energy is constant; the rebound speed equals the
/// approach speed (e = 1).
///
/// Tolerances, at dt = 10 µs (109 steps per contact): the largest relative
/// energy error, measured 7.4e-7, and |1 − v_out/v_in|, measured 1e-8, must
/// stay below 1e-5. That is 200× below the loss of the weakest dissipation
/// one would ever add (Hunt–Crossley with e = 0.999 loses 1 − e² = 2e-3) and
/// 1e5× below a lost contact energy (all of E_0 is elastic at δ_max). The
/// error is the integrator's: at 4× the step (40 µs) it is 5.8e-5, 77× more
/// (RK4 is of order 3 through the δ^1.5 onset; where the separation falls
/// within a step scatters the error by up to 10× between neighbouring steps,
/// hence the required ratio of only 16 = order 2). δ_max and F_max are read
/// at steps: within 0.1 % and 0.2 % (measured 0.008 %, 0.013 %); t_c is the span
/// from the first to the last step with F > 0, so t_c − 2·dt ≤ span ≤ t_c.
#[test]
fn a_single_elastic_impact_rebounds_at_its_speed_and_keeps_its_energy() {
    let m = 7850.0 * 4.0 / 3.0 * std::f64::consts::PI * 0.04_f64.powi(3);
    let d_hand = (2.5 * m / 2e9).powf(0.4);
    let f_hand = 1e9 * d_hand.powf(1.5);
    let tc_hand = 2.9433 * d_hand;
    assert!((d_hand * 1e3 - 0.3698).abs() < 1e-4, "{d_hand}");
    assert!((f_hand - 7112.6).abs() < 0.1, "{f_hand}");

    let dt = 1e-5;
    let (drift, f_max, d_max, span, v_out) = single_hertz_impact(dt);
    // The collision happened: a force, and the velocity reversed.
    assert!(f_max > 0.5 * f_hand, "largest contact force {f_max} N");
    assert!(v_out > 0.0, "ball did not rebound: v = {v_out} m/s");
    // Closed form.
    assert!(
        ((d_max - d_hand) / d_hand).abs() < 1e-3,
        "δ_max {d_max} vs {d_hand}"
    );
    assert!(
        ((f_max - f_hand) / f_hand).abs() < 2e-3,
        "F_max {f_max} vs {f_hand}"
    );
    assert!(
        span <= tc_hand * (1.0 + 2e-3) && span >= tc_hand * (1.0 - 2e-3) - 2.0 * dt,
        "contact span {span} s vs t_c {tc_hand} s"
    );
    assert!((v_out - 1.0).abs() < 1e-5, "rebound {v_out} m/s: e ≠ 1");
    assert!(drift < 1e-5, "relative energy error {drift:.2e}");
    // It is truncation error: it shrinks with the step.
    let (coarse, ..) = single_hertz_impact(4.0 * dt);
    assert!(
        coarse > 16.0 * drift,
        "energy error {coarse:.2e} at 40 µs, {drift:.2e} at 10 µs: not truncation error"
    );
}

/// Four steel balls (r = 40 mm) in a 0.4 m box of six fixed half-spaces,
/// Hertz contacts (K = 1e9 N/m^1.5), no gravity, RK4 at step `dt` for 1.8 s.
/// Returns (largest relative energy error, number of ball–ball and of
/// ball–wall collisions counted at their onset step by step, kinetic energy
/// each ball gained or lost over the run relative to the total [J/J]).
fn balls_in_a_box(dt: f64) -> (f64, usize, usize, Vec<f64>) {
    let mut toml = format!(
        r#"
        [simulation]
        duration = 1.8
        dt = {dt}
        output_interval = 1e-2
        integrator = "rk4"
        [record]
        tables = []
        "#,
    );
    let walls = [
        ("xlo", [-0.2, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ("xhi", [0.2, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        ("ylo", [0.0, -0.2, 0.0], [0.0, 1.0, 0.0]),
        ("yhi", [0.0, 0.2, 0.0], [0.0, -1.0, 0.0]),
        ("zlo", [0.0, 0.0, -0.2], [0.0, 0.0, 1.0]),
        ("zhi", [0.0, 0.0, 0.2], [0.0, 0.0, -1.0]),
    ];
    for (name, p, n) in walls {
        toml += &format!(
            "[[bodies]]\nname = \"{name}\"\nmotion = \"fixed\"\nposition = {p:?}\nshape = {{ type = \"half-space\", normal = {n:?} }}\n"
        );
    }
    let balls = [
        ("b0", [-0.1, -0.1, 0.0], [1.0, 0.7, 0.2]),
        ("b1", [0.1, -0.1, 0.05], [-0.8, 0.9, -0.3]),
        ("b2", [0.1, 0.1, -0.05], [-0.6, -1.1, 0.4]),
        ("b3", [-0.1, 0.1, 0.0], [0.9, -0.5, -0.6]),
    ];
    for (i, (name, p, v)) in balls.iter().enumerate() {
        toml += &format!(
            "[[bodies]]\nname = \"{name}\"\nshape = {{ type = \"ball\", radius = 0.04 }}\ndensity = 7850.0\nposition = {p:?}\nvelocity = {v:?}\nangular_velocity = [0.0, 0.0, {w}]\n",
            w = i as f64
        );
    }
    let law = r#"{ law = "hertz", stiffness = 1e9 }"#;
    for (b, _, _) in balls {
        for (w, _, _) in walls {
            toml += &format!("[[contacts]]\nbodies = [\"{w}\", \"{b}\"]\nnormal = {law}\n");
        }
    }
    for i in 0..4 {
        for j in i + 1..4 {
            toml += &format!("[[contacts]]\nbodies = [\"b{i}\", \"b{j}\"]\nnormal = {law}\n");
        }
    }
    let scene = Scene::from_toml_str(&toml, &[]).unwrap();
    let mut sim = Simulation::new(&scene).unwrap();
    let ids: Vec<usize> = balls.iter().map(|b| common::body(&sim, b.0)).collect();
    let kinetic = |sim: &Simulation| -> Vec<f64> {
        ids.iter()
            .map(|&i| 0.5 * sim.model().bodies[i].mass * sim.state().vel[i].norm_squared())
            .collect()
    };
    let k0 = kinetic(&sim);
    let e0 = sim.energy().total();
    let mut touching = vec![false; scene.contacts.len()];
    let (mut ball_ball, mut ball_wall, mut worst) = (0, 0, 0.0_f64);
    while !sim.is_done() {
        sim.step().unwrap();
        worst = worst.max(((sim.energy().total() - e0) / e0).abs());
        for (k, was) in touching.iter_mut().enumerate() {
            let now = sim.pair_contacts(k).iter().any(|c| c.normal_force > 0.0);
            if now && !*was {
                // The 24 wall pairs come first.
                if k < 24 {
                    ball_wall += 1
                } else {
                    ball_ball += 1
                }
            }
            *was = now;
        }
    }
    let k1 = kinetic(&sim);
    let exchanged = k0.iter().zip(&k1).map(|(a, b)| (b - a) / e0).collect();
    (worst, ball_ball, ball_wall, exchanged)
}

/// Several bodies colliding with each other and with walls, spinning, over
/// 1.8 s (docs/model.md §7.11).
///
/// First the test checks that collisions happened, counted at the step where
/// a pair's normal force becomes positive: balls against walls and against
/// each other, with kinetic energy passed between balls (a ball–ball impact
/// off the line of centres changes each ball's speed; a wall bounce does not).
/// Invariant: total energy (kinetic + Hertz elastic) constant.
///
/// Measured at dt = 20 µs: 12 ball–ball and 40 ball–wall collisions; each
/// ball's translational kinetic energy changed by 2–9 % of the total.
///
/// Tolerance: the largest relative energy error over the run, measured
/// 2.7e-5 at dt = 20 µs, must stay below 1e-4 and must fall when dt halves
/// (measured 5.5e-6 at 10 µs, 0.2×; required < 0.5×): it is RK4
/// truncation summed over ~50 impacts, not a loss. 1e-4 is 5× below what a
/// single Hunt–Crossley impact with e = 0.999 would lose (1 − e² = 2e-3 of
/// one ball's energy, each ball holding ~1/4 of the total), and 100× below
/// the exchange the test requires as proof of collisions (1e-2).
#[test]
fn elastic_collisions_in_a_box_conserve_energy() {
    let (worst, ball_ball, ball_wall, exchanged) = balls_in_a_box(2e-5);
    assert!(
        ball_ball >= 4 && ball_wall >= 8,
        "{ball_ball} ball–ball and {ball_wall} ball–wall collisions: too few to test anything"
    );
    for (i, x) in exchanged.iter().enumerate() {
        assert!(
            x.abs() > 1e-2,
            "ball {i} kept its kinetic energy ({x:.1e} of the total): no exchange happened"
        );
    }
    assert!(worst < 1e-4, "relative energy error {worst:.2e}");
    let (half, ..) = balls_in_a_box(1e-5);
    assert!(
        half < 0.5 * worst,
        "energy error {worst:.2e} at 20 µs, {half:.2e} at 10 µs: not truncation error"
    );
}
