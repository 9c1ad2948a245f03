//! Joint declarations.

use serde::{Deserialize, Serialize};

use super::fields::FieldDoc;
use super::{Scene, finite_vec, non_negative, positive};
use crate::error::SceneError;

/// A penalty joint. `type` selects the variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum JointSpec {
    /// Ideal constant-velocity joint: the hinge points coincide (spring-damper),
    /// no relative twist about the bodies' x axes (torsional spring-damper).
    /// It bends freely: an articulation limit is a contact between the
    /// surfaces that bind (e.g. a `ring-cylinder` contact geometry).
    Cv {
        /// Name in messages.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        name: Option<String>,
        /// The two bodies `[a, b]`.
        bodies: [String; 2],
        /// Hinge point in each body's frame [m].
        anchors: [[f64; 3]; 2],
        /// Hinge-point spring [N/m].
        stiffness: f64,
        /// Hinge-point damper [N·s/m].
        damping: f64,
        /// Twist spring [N·m/rad].
        twist_stiffness: f64,
        /// Twist damper [N·m·s/rad].
        twist_damping: f64,
    },
}

impl JointSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::text("type", "the joint: cv (ideal constant-velocity)"),
        FieldDoc::text("name", "name in messages"),
        FieldDoc::text("bodies", "the two bodies [a, b]"),
        FieldDoc::number("anchors", "m", "hinge point in each body's frame"),
        FieldDoc::number("stiffness", "N/m", "hinge-point spring"),
        FieldDoc::number("damping", "N·s/m", "hinge-point damper"),
        FieldDoc::number("twist_stiffness", "N·m/rad", "twist spring"),
        FieldDoc::number("twist_damping", "N·m·s/rad", "twist damper"),
    ];

    /// The two bodies `[a, b]`.
    pub fn bodies(&self) -> &[String; 2] {
        match self {
            Self::Cv { bodies, .. } => bodies,
        }
    }

    /// Checks the bodies (two, existing, one of them moving) and the parameters.
    pub(super) fn validate(&self, path: &str, scene: &Scene) -> Result<(), SceneError> {
        let bodies = self.bodies();
        let mut idx = [0usize; 2];
        for (k, name) in bodies.iter().enumerate() {
            idx[k] = scene.body_id(&format!("{path}.bodies[{k}]"), name)?;
        }
        if idx[0] == idx[1] {
            return Err(SceneError::new(
                format!("{path}.bodies"),
                format!("{bodies:?}"),
                "a joint needs two bodies",
            ));
        }
        if let Some(k) = (0..2).find(|&k| scene.bodies[idx[k]].is_quasi_static()) {
            return Err(SceneError::new(
                format!("{path}.bodies[{k}]"),
                bodies[k].clone(),
                "is quasi-static: its equilibrium is solved over contact pairs only, so it takes no joint",
            ));
        }
        if !scene.bodies[idx[0]].is_integrated() && !scene.bodies[idx[1]].is_integrated() {
            return Err(SceneError::new(
                format!("{path}.bodies"),
                format!("{bodies:?}"),
                "neither body can move",
            ));
        }
        match self {
            Self::Cv {
                anchors,
                stiffness,
                damping,
                twist_stiffness,
                twist_damping,
                ..
            } => {
                for (k, a) in anchors.iter().enumerate() {
                    finite_vec(&format!("{path}.anchors[{k}]"), a)?;
                }
                positive(&format!("{path}.stiffness"), *stiffness)?;
                non_negative(&format!("{path}.damping"), *damping)?;
                positive(&format!("{path}.twist_stiffness"), *twist_stiffness)?;
                non_negative(&format!("{path}.twist_damping"), *twist_damping)?;
            }
        }
        Ok(())
    }
}
