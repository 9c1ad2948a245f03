//! Shared helpers: build a simulation from TOML text.

#![allow(dead_code)]

use ballcage_core::{Scene, Simulation};

/// Parses, validates and assembles a TOML scene; panics with the scene error.
pub fn sim(toml: &str) -> Simulation {
    let scene = Scene::from_toml_str(toml, &[]).unwrap_or_else(|e| panic!("bad test scene: {e}"));
    Simulation::new(&scene).unwrap_or_else(|e| panic!("assembly failed: {e}"))
}

/// Index of a body by name.
pub fn body(sim: &Simulation, name: &str) -> usize {
    sim.model()
        .bodies
        .iter()
        .position(|b| b.name == name)
        .expect("body exists")
}

/// Time history of one body's velocity, sampled every output frame.
pub struct Probe {
    /// (t, v_x) samples.
    pub samples: Vec<(f64, f64)>,
    /// Velocity at the end [m/s].
    pub final_velocity: ballcage_core::math::Vec3,
}

impl Probe {
    /// Runs `toml` to the end, sampling body `name` every output interval.
    pub fn run(toml: &str, name: &str) -> Self {
        let mut s = sim(toml);
        let i = body(&s, name);
        let every = s.model().dt * s.model().steps_per_output as f64;
        let mut samples = vec![];
        while !s.is_done() {
            s.advance_to(s.time() + every).unwrap();
            samples.push((s.time(), s.state().vel[i].x));
        }
        Self {
            samples,
            final_velocity: s.state().vel[i],
        }
    }

    /// The sample nearest to time `t`.
    pub fn velocity_at(&self, t: f64) -> (f64, f64) {
        *self
            .samples
            .iter()
            .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
            .expect("samples")
    }
}

/// The incline of docs/model.md §7.7: a 1 kg block on a horizontal plane with
/// gravity tilted to α from vertical, g = 9.8·(cos α, 0, −sin α), a linear
/// normal law and the Adams friction law (μs 0.3, μd 0.1, v_s 0.1, v_d 1 m/s).
pub fn incline_scene(
    alpha_deg: f64,
    integrator: &str,
    dt: f64,
    output_interval: f64,
    duration: f64,
) -> String {
    let a = alpha_deg.to_radians();
    let (gx, gz) = (9.8 * a.cos(), -9.8 * a.sin());
    format!(
        r#"
        [simulation]
        duration = {duration}
        dt = {dt}
        output_interval = {output_interval}
        integrator = "{integrator}"
        [world]
        gravity = [{gx}, 0.0, {gz}]
        [record]
        tables = []
        [[bodies]]
        name = "incline"
        motion = "fixed"
        shape = {{ type = "half-space", normal = [0.0, 0.0, 1.0] }}
        [[bodies]]
        name = "block"
        shape = {{ type = "cuboid", half_extents = [0.05, 0.05, 0.02] }}
        mass = 1.0
        position = [0.0, 0.0, 0.02]
        [[contacts]]
        bodies = ["incline", "block"]
        normal = {{ law = "linear", stiffness = 1e6, damping = 1000.0 }}
        friction = {{ law = "adams", mu_static = 0.3, mu_dynamic = 0.1, v_static = 0.1, v_dynamic = 1.0 }}
        "#
    )
}

/// A 1 kg ball on a linear spring-dashpot contact (k = 1e4 N/m, c = 20
/// N·s/m: ω₀ = 100 rad/s, ζ = 0.1) under gravity, starting at its rest depth
/// moving up at 0.05 m/s: it rings down about rest, never leaving the floor
/// ([`oscillator_exact`]). `simulation`: the `[simulation]` keys besides
/// the duration (0.1 s).
pub fn oscillator(simulation: &str) -> Simulation {
    ball_on_floor(
        &format!("duration = 0.1\n{simulation}"),
        9.81,
        &format!(
            "shape = {{ type = \"ball\", radius = 0.05 }}\nmass = 1.0\n\
             position = [0.0, 0.0, {z0}]\nvelocity = [0.0, 0.0, 0.05]",
            z0 = 0.05 - 9.81e-4
        ),
        "normal = { law = \"linear\", stiffness = 1e4, damping = 20.0 }",
    )
}

/// A body named "ball" on a fixed floor (the half-space z ≤ 0, body
/// "floor") under gravity `g` [m/s²] along −z, no tables recorded:
/// `simulation` the `[simulation]` keys, `ball` the ball's keys besides its
/// name (shape, mass, position, velocity), `contact` the floor–ball
/// contact's keys besides its bodies (its laws).
pub fn ball_on_floor(simulation: &str, g: f64, ball: &str, contact: &str) -> Simulation {
    sim(&ball_on_floor_toml(simulation, g, ball, contact))
}

/// The scene document of [`ball_on_floor`].
pub fn ball_on_floor_toml(simulation: &str, g: f64, ball: &str, contact: &str) -> String {
    format!(
        r#"
        [simulation]
        {simulation}
        [world]
        gravity = [0.0, 0.0, {neg_g}]
        [record]
        tables = []
        [[bodies]]
        name = "floor"
        motion = "fixed"
        shape = {{ type = "half-space", normal = [0.0, 0.0, 1.0] }}
        [[bodies]]
        name = "ball"
        {ball}
        [[contacts]]
        bodies = ["floor", "ball"]
        {contact}
        "#,
        neg_g = -g,
    )
}

/// The [`oscillator`]'s exact height [m] and vertical velocity [m/s] at `t`
/// [s]: z(t) = z_s + (v₀/ω_d)·e^(−ζω₀t)·sin(ω_d·t), ω_d = ω₀·√(1 − ζ²).
pub fn oscillator_exact(t: f64) -> (f64, f64) {
    let (w0, zeta) = (100.0, 0.1);
    let wd = w0 * (1.0f64 - zeta * zeta).sqrt();
    let decay = (-zeta * w0 * t).exp();
    let z = 0.05 - 9.81e-4 + 0.05 / wd * decay * (wd * t).sin();
    let v = 0.05 / wd * decay * (wd * (wd * t).cos() - zeta * w0 * (wd * t).sin());
    (z, v)
}

/// A tumbling asymmetric box without forces: the gyroscopic term alone
/// turns the rotation axis; 0.4 s at steps of `dt` with `integrator`, its
/// Newton iterations (implicit integrators) to `newton_tolerance`.
pub fn tumbling(integrator: &str, dt: f64, newton_tolerance: f64) -> Simulation {
    sim(&format!(
        r#"
        [simulation]
        duration = 0.4
        dt = {dt}
        output_interval = 0.4
        integrator = "{integrator}"
        newton = {{ tolerance = {newton_tolerance:e} }}
        [record]
        tables = []
        [[bodies]]
        name = "box"
        shape = {{ type = "cuboid", half_extents = [0.1, 0.05, 0.02] }}
        mass = 1.0
        angular_velocity = [0.5, 4.0, 0.2]
        "#
    ))
}
