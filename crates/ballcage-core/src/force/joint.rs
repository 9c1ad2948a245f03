//! Penalty joints: force elements that hold two bodies together.
//!
//! The ideal constant-velocity (CV) joint keeps the two hinge points together
//! with a stiff spring-damper, forbids relative twist about the body x axes
//! (a CV joint passes spin through unchanged) with a torsional spring-damper,
//! and lets the bend free: an articulation limit is a contact between the
//! surfaces that bind, not a joint term. Zero twist in the swing–twist
//! decomposition of the relative rotation is exactly the CV condition: a head
//! spun by φ about its axis and a seat spun by φ about its own give a relative
//! rotation about an axis perpendicular to x.

use crate::math::{Quat, Vec3, angle_between};

/// Parameters of an ideal CV joint (SI).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CvJointParams {
    /// Hinge-point spring [N/m].
    pub stiffness: f64,
    /// Hinge-point damper [N·s/m].
    pub damping: f64,
    /// Twist spring [N·m/rad].
    pub twist_stiffness: f64,
    /// Twist damper [N·m·s/rad].
    pub twist_damping: f64,
}

/// Wrench of a joint on body b (body a gets the opposite force at its own
/// hinge point and the opposite torque).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointWrench {
    /// Force on b at its hinge point [N], world frame.
    pub force: Vec3,
    /// Pure torque on b [N·m], world frame (twist).
    pub torque: Vec3,
    /// Twist angle [rad].
    pub twist: f64,
}

/// Relative twist of `qb` against `qa` about a's x axis [rad], in (−π, π].
pub fn twist_angle(qa: &Quat, qb: &Quat) -> f64 {
    let r = qa.inverse() * qb;
    let t = 2.0 * r.i.atan2(r.w);
    (t + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI
}

/// Axis of the twist spring and damper: the bisector of the two body x axes
/// (world frame), or a's axis when they are opposite.
pub fn twist_axis(qa: &Quat, qb: &Quat) -> Vec3 {
    let (ea, eb) = (qa * Vec3::x(), qb * Vec3::x());
    (ea + eb).try_normalize(1e-12).unwrap_or(ea)
}

/// Bend β between the two body x axes [rad].
pub fn bend(qa: &Quat, qb: &Quat) -> f64 {
    angle_between(&(qa * Vec3::x()), &(qb * Vec3::x()))
}

/// Wrench of a CV joint. `pa`, `pb`: hinge points [m]; `va`, `vb`: their
/// velocities [m/s]; `wa`, `wb`: angular velocities [rad/s]; all world frame.
#[allow(clippy::too_many_arguments)]
pub fn cv_joint_wrench(
    qa: &Quat,
    qb: &Quat,
    pa: &Vec3,
    pb: &Vec3,
    va: &Vec3,
    vb: &Vec3,
    wa: &Vec3,
    wb: &Vec3,
    p: &CvJointParams,
) -> JointWrench {
    let force = -p.stiffness * (pb - pa) - p.damping * (vb - va);
    let axis = twist_axis(qa, qb);
    let twist = twist_angle(qa, qb);
    let torque = -(p.twist_stiffness * twist + p.twist_damping * (wb - wa).dot(&axis)) * axis;
    JointWrench {
        force,
        torque,
        twist,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equal_spins_about_each_axis_have_no_twist() {
        // Head spun by φ about x, seat bent by β about z then spun by φ about its own x.
        for deg in [0.0f64, 7.645, 15.0] {
            let bend = Quat::from_axis_angle(&Vec3::z_axis(), deg.to_radians());
            for k in 0..12 {
                let phi = k as f64 * 0.5;
                let qa = Quat::from_axis_angle(&Vec3::x_axis(), phi);
                let qb = bend * Quat::from_axis_angle(&Vec3::x_axis(), phi);
                assert!(twist_angle(&qa, &qb).abs() < 1e-12, "β = {deg}°, φ = {phi}");
                let extra = Quat::from_axis_angle(&Vec3::x_axis(), 0.01);
                assert!((twist_angle(&qa, &(qb * extra)) - 0.01).abs() < 1e-12);
            }
        }
    }
}
