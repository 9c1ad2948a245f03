//! Applied loads.

use serde::{Deserialize, Serialize};

use super::{MotionKind, Scene, direction, finite, non_negative};
use crate::error::SceneError;

/// An applied load. `type` selects the variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum LoadSpec {
    /// A torque `magnitude · axis` [N·m] on a body, ramped in by an Adams STEP
    /// from 0 at t = 0 to full at t = `ramp` (a negative magnitude about a
    /// spin axis resists the spin).
    Torque {
        /// Body name.
        body: String,
        /// Torque axis, world frame.
        axis: [f64; 3],
        /// Signed magnitude about `axis` [N·m].
        magnitude: f64,
        /// STEP ramp duration [s]; 0 applies the full torque from t = 0.
        #[serde(default)]
        ramp: f64,
    },
}

impl LoadSpec {
    /// Checks the body (existing and integrated) and the torque.
    pub(super) fn validate(&self, path: &str, scene: &Scene) -> Result<(), SceneError> {
        match self {
            Self::Torque {
                body,
                axis,
                magnitude,
                ramp,
            } => {
                let i = scene.body_id(&format!("{path}.body"), body)?;
                if !scene.bodies[i].is_integrated() {
                    return Err(SceneError::new(
                        format!("{path}.body"),
                        body,
                        format!(
                            "a load on a {:?} body has no effect",
                            scene.bodies[i].motion
                        )
                        .to_lowercase(),
                    ));
                }
                if scene.bodies[i].motion == MotionKind::Spin && axis.iter().all(|x| *x == 0.0) {
                    return Err(SceneError::new(
                        format!("{path}.axis"),
                        "[0, 0, 0]",
                        "must be a direction",
                    ));
                }
                direction(&format!("{path}.axis"), axis)?;
                finite(&format!("{path}.magnitude"), *magnitude)?;
                non_negative(&format!("{path}.ramp"), *ramp)?;
                Ok(())
            }
        }
    }
}
