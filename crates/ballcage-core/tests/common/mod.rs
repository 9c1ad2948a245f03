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
