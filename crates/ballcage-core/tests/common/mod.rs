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
