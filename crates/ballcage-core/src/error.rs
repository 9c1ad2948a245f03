//! Errors: every one names where the problem is.

use thiserror::Error;

/// A scene that cannot be read, validated or assembled.
///
/// `path` is the dotted location of the offending value in the scene
/// (`bodies[1].mass`), `value` the value as written (empty if missing) and
/// `reason` what is wrong with it. An error of the document as a whole (a
/// TOML syntax error) has an empty path and displays its reason alone.
#[derive(Debug, Clone, Error, PartialEq)]
#[error("{}{reason}", if path.is_empty() { String::new() } else if value.is_empty() { format!("scene field `{path}`: ") } else { format!("scene field `{path}` = {value}: ") })]
pub struct SceneError {
    /// Dotted path of the offending field, e.g. `contacts[0].normal.stiffness`.
    pub path: String,
    /// The offending value as text; empty when the field is missing.
    pub value: String,
    /// Why the value is rejected.
    pub reason: String,
}

impl SceneError {
    /// Builds an error for `path` with the offending `value` and a `reason`.
    pub fn new(
        path: impl Into<String>,
        value: impl std::fmt::Display,
        reason: impl Into<String>,
    ) -> Self {
        Self {
            path: path.into(),
            value: value.to_string(),
            reason: reason.into(),
        }
    }
}

/// A run that had to stop: the state stopped being physical.
#[derive(Debug, Clone, Error, PartialEq)]
#[error("simulation diverged at t = {time:.6e} s (step {step}): {reason}")]
pub struct SimulationError {
    /// Simulated time of the failure [s].
    pub time: f64,
    /// Integrator step index at the failure.
    pub step: u64,
    /// What went wrong, naming the bodies or the contact pair.
    pub reason: String,
}
