//! # ballcage-core
//!
//! Rigid-body penalty-contact dynamics for ball-cage flexible drill pipes.
//!
//! The pipeline: a [`Scene`] (plain data, from TOML or any serde source) is
//! validated, then [`assembly`] builds a read-only [`Model`] and a mutable
//! [`State`] holding only what the scene declares (bodies, declared contact
//! pairs, loads, recorded channels). A [`Simulation`] advances the state with a
//! fixed-step integrator ([`integrate`]); each step evaluates the declared
//! contacts ([`geometry`]) and their force laws ([`force`]) in
//! [`dynamics`]. A [`Recorder`](record::Recorder) keeps the asked-for
//! channels in columnar buffers, which [`output`] turns into Arrow tables with
//! the one schema of the project.
//!
//! Units are SI throughout; the paper's field units ([`scene::FieldUnits`])
//! are converted once, at assembly ([`assembly::normal_law`]).
//!
//! The drill pipe ([`drillpipe`]) is a layer above the engine: it expands
//! its document into a generic scene and adds its tables through a
//! [`record::Observer`]. [`loader`] reads a document of either kind. See
//! docs/architecture.md for the map of the stages and what each may import.

pub mod assembly;
pub mod drillpipe;
pub mod dynamics;
pub mod error;
pub mod force;
pub mod geometry;
pub mod integrate;
pub mod loader;
pub mod math;
pub mod model;
#[cfg(feature = "arrow")]
pub mod output;
pub mod record;
pub mod scene;
pub mod sim;

pub use error::{SceneError, SimulationError};
pub use loader::Document;
pub use model::{Model, State};
pub use scene::Scene;
pub use sim::Simulation;

/// Package version, written into every output's metadata.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
