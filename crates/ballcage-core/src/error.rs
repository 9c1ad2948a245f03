//! Errors: every one names where the problem is.

use thiserror::Error;

/// A scene that cannot be read, validated or assembled.
///
/// `path` is the dotted location of the offending value in the scene
/// (`bodies[1].mass`), `value` the value as written (empty if missing) and
/// `reason` what is wrong with it. An error of the document as a whole (a
/// TOML syntax error) has an empty path and displays its reason alone.
/// Further problems found in the same pass are in `more` and displayed
/// after the first, separated by "; ".
#[derive(Debug, Clone, PartialEq)]
pub struct SceneError {
    /// Dotted path of the offending field, e.g. `contacts[0].normal.stiffness`.
    pub path: String,
    /// The offending value as text; empty when the field is missing.
    pub value: String,
    /// Why the value is rejected.
    pub reason: String,
    /// Other errors of the same scene, found in the same pass (each with an empty `more`).
    pub more: Vec<SceneError>,
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
            more: Vec::new(),
        }
    }

    /// Every failed check of `checks` as one error (the first, the others in
    /// `more`), or `Ok` when none failed. Every check has already run: pass
    /// only checks that do not depend on each other.
    pub fn all(checks: impl IntoIterator<Item = Result<(), SceneError>>) -> Result<(), SceneError> {
        Self::combine(checks.into_iter().filter_map(Result::err)).map_or(Ok(()), Err)
    }

    /// `errors` (each possibly with its own `more`) as one error; `None` when there are none.
    pub fn combine(errors: impl IntoIterator<Item = SceneError>) -> Option<SceneError> {
        let mut flat = errors.into_iter().flat_map(SceneError::into_each);
        let mut first = flat.next()?;
        first.more.extend(flat);
        Some(first)
    }

    /// This error and those in `more`, each alone.
    pub fn each(&self) -> impl Iterator<Item = &SceneError> {
        std::iter::once(self).chain(self.more.iter())
    }

    fn into_each(mut self) -> impl Iterator<Item = SceneError> {
        let more = std::mem::take(&mut self.more);
        std::iter::once(self).chain(more)
    }

    /// The first error alone, as displayed: "scene field `path` = value: reason".
    pub fn one(&self) -> String {
        if self.path.is_empty() {
            self.reason.clone()
        } else if self.value.is_empty() {
            format!("scene field `{}`: {}", self.path, self.reason)
        } else {
            format!(
                "scene field `{}` = {}: {}",
                self.path, self.value, self.reason
            )
        }
    }
}

impl std::fmt::Display for SceneError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let all: Vec<String> = self.each().map(SceneError::one).collect();
        f.write_str(&all.join("; "))
    }
}

impl std::error::Error for SceneError {}

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
