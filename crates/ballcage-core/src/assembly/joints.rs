//! Joint and load specs → penalty joints and torque loads.

use crate::error::SceneError;
use crate::force::joint::CvJointParams;
use crate::math::Vec3;
use crate::model::{ForceLoad, Joint, TorqueLoad};
use crate::scene::{JointSpec, LoadSpec, Scene};

/// Every declared joint, in order.
pub(super) fn joints(scene: &Scene) -> Result<Vec<Joint>, SceneError> {
    scene
        .joints
        .iter()
        .enumerate()
        .map(|(i, j)| joint(scene, j, i))
        .collect()
}

/// Joint `i`: a constant-velocity joint.
fn joint(scene: &Scene, j: &JointSpec, i: usize) -> Result<Joint, SceneError> {
    let path = format!("joints[{i}]");
    let ids = |names: &[String; 2]| -> Result<(usize, usize), SceneError> {
        Ok((
            scene.body_id(&format!("{path}.bodies[0]"), &names[0])?,
            scene.body_id(&format!("{path}.bodies[1]"), &names[1])?,
        ))
    };
    let default_name = |name: &Option<String>| name.clone().unwrap_or_else(|| path.clone());
    Ok(match j {
        JointSpec::Cv {
            name,
            bodies: names,
            anchors,
            stiffness,
            damping,
            twist_stiffness,
            twist_damping,
        } => {
            let (a, b) = ids(names)?;
            Joint {
                name: default_name(name),
                a,
                b,
                anchor_a: Vec3::from(anchors[0]),
                anchor_b: Vec3::from(anchors[1]),
                params: CvJointParams {
                    stiffness: *stiffness,
                    damping: *damping,
                    twist_stiffness: *twist_stiffness,
                    twist_damping: *twist_damping,
                },
            }
        }
    })
}

/// Every applied torque, in order.
pub(super) fn torque_loads(scene: &Scene) -> Result<Vec<TorqueLoad>, SceneError> {
    scene
        .loads
        .iter()
        .enumerate()
        .filter_map(|(i, l)| match l {
            LoadSpec::Torque {
                body,
                axis,
                magnitude,
                ramp,
            } => Some(
                scene
                    .body_id(&format!("loads[{i}].body"), body)
                    .map(|body| TorqueLoad {
                        body,
                        axis: Vec3::from(*axis).normalize(),
                        magnitude: *magnitude,
                        ramp: *ramp,
                    }),
            ),
            LoadSpec::Force { .. } => None,
        })
        .collect()
}

/// Every applied force, in order.
pub(super) fn force_loads(scene: &Scene) -> Result<Vec<ForceLoad>, SceneError> {
    scene
        .loads
        .iter()
        .enumerate()
        .filter_map(|(i, l)| match l {
            LoadSpec::Force {
                body,
                axis,
                force,
                ramp,
            } => Some(
                scene
                    .body_id(&format!("loads[{i}].body"), body)
                    .map(|body| ForceLoad {
                        body,
                        axis: Vec3::from(*axis).normalize(),
                        magnitude: *force,
                        ramp: *ramp,
                    }),
            ),
            LoadSpec::Torque { .. } => None,
        })
        .collect()
}
