//! Benchmarks live in `benches/`; this library holds what they share with
//! the examples: [`rapier_chain`], the rapier3d-f64 baseline of the
//! `ideal-cv` drill pipe (issue 12). rapier is a dependency of this crate
//! only, never of ballcage-core or of the wheel.

pub mod rapier_chain;
