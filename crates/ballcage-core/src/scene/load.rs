//! Applied loads.

use serde::{Deserialize, Serialize};

use super::fields::FieldDoc;
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
    /// A force `force · axis` [N] at a body's centre of mass, ramped in by
    /// an Adams STEP from 0 at t = 0 to full at t = `ramp`. On a
    /// `spin-slide` body only its part along the spin axis moves the body;
    /// the rest is carried by the body's restraint.
    Force {
        /// Body name.
        body: String,
        /// Force direction, world frame.
        axis: [f64; 3],
        /// Signed magnitude along `axis` [N].
        force: f64,
        /// STEP ramp duration [s]; 0 applies the full force from t = 0.
        #[serde(default)]
        ramp: f64,
    },
}

impl LoadSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::text("type", "the load: torque or force"),
        FieldDoc::text("body", "the body loaded"),
        FieldDoc::number("axis", "-", "torque axis, or force direction, world frame"),
        FieldDoc::number("magnitude", "N·m", "signed torque about axis"),
        FieldDoc::number(
            "force",
            "N",
            "signed force along axis, at the centre of mass",
        ),
        FieldDoc::number(
            "ramp",
            "s",
            "STEP ramp from 0 to the full load; 0 applies it at once",
        ),
    ];

    /// Checks the body (existing and integrated, and for a force one whose
    /// centre of mass can move) and the load.
    pub(super) fn validate(&self, path: &str, scene: &Scene) -> Result<(), SceneError> {
        let (body, axis, value, ramp, field) = match self {
            Self::Torque {
                body,
                axis,
                magnitude,
                ramp,
            } => (body, axis, *magnitude, *ramp, "magnitude"),
            Self::Force {
                body,
                axis,
                force,
                ramp,
            } => (body, axis, *force, *ramp, "force"),
        };
        let i = scene.body_id(&format!("{path}.body"), body)?;
        let motion = scene.bodies[i].motion;
        if !scene.bodies[i].is_integrated() {
            return Err(SceneError::new(
                format!("{path}.body"),
                body,
                format!("a load on a {motion:?} body has no effect").to_lowercase(),
            ));
        }
        if matches!(self, Self::Force { .. }) && motion == MotionKind::Spin {
            return Err(SceneError::new(
                format!("{path}.body"),
                body,
                "a force on a spin body has no effect: its centre of mass is held \
                 (make it spin-slide to let it move along its axis)",
            ));
        }
        if matches!(motion, MotionKind::Spin | MotionKind::SpinSlide)
            && axis.iter().all(|x| *x == 0.0)
        {
            return Err(SceneError::new(
                format!("{path}.axis"),
                "[0, 0, 0]",
                "must be a direction",
            ));
        }
        direction(&format!("{path}.axis"), axis)?;
        finite(&format!("{path}.{field}"), value)?;
        non_negative(&format!("{path}.ramp"), ramp)?;
        Ok(())
    }
}
