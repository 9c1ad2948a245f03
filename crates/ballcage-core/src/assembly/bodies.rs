//! Body specs → assembled bodies, their query shapes and the initial state.

use crate::error::SceneError;
use crate::geometry::{Shape, TubePath, TubeSegment};
use crate::math::{Quat, Vec3};
use crate::model::{Body, Motion, SpinProfile, State, StaticDofs};
use crate::scene::{BodySpec, MotionKind, Scene, ShapeSpec, TubeSegmentSpec};

/// Every body of the scene, in order (index = body id).
pub(super) fn bodies(scene: &Scene) -> Result<Vec<Body>, SceneError> {
    scene
        .bodies
        .iter()
        .enumerate()
        .map(|(i, b)| body(b, &format!("bodies[{i}]")))
        .collect()
}

/// One body: mass properties, motion, query shape and initial orientation.
fn body(b: &BodySpec, path: &str) -> Result<Body, SceneError> {
    let q0 = b.orientation;
    let rot = Quat::from_quaternion(nalgebra::Quaternion::new(q0[0], q0[1], q0[2], q0[3]));
    let (mass, inertia) = match b.mass_properties() {
        Some((m, i3)) => (m, Vec3::from(i3)),
        None if b.needs_mass() => {
            return Err(SceneError::new(format!("{path}.mass"), "", "missing"));
        }
        None => (0.0, Vec3::zeros()),
    };
    Ok(Body {
        name: b.name.clone(),
        motion: motion(b, &rot, &inertia),
        mass,
        inertia,
        shape: shape(&b.shape),
        initial_rotation: rot,
    })
}

/// How the body moves; a spin body's axis and moment of inertia about it
/// are fixed in its initial orientation `rot`.
fn motion(b: &BodySpec, rot: &Quat, inertia: &Vec3) -> Motion {
    let axis = b
        .spin_axis
        .map(|a| Vec3::from(a).normalize())
        .unwrap_or_else(Vec3::z);
    match b.motion {
        MotionKind::Fixed => Motion::Fixed,
        MotionKind::Dynamic => Motion::Dynamic,
        MotionKind::QuasiStatic => Motion::QuasiStatic(StaticDofs::Pose),
        MotionKind::QuasiStaticPosition => Motion::QuasiStatic(StaticDofs::Position),
        MotionKind::KinematicSpin => Motion::KinematicSpin(SpinProfile {
            axis,
            speed: b.spin_speed,
            ramp: b.spin_ramp,
        }),
        MotionKind::Spin | MotionKind::SpinSlide => {
            let axis_body = rot.inverse() * axis;
            let i_axis = axis_body.dot(&inertia.component_mul(&axis_body));
            Motion::Spin {
                axis,
                axis_body,
                inertia: i_axis,
                slides: b.motion == MotionKind::SpinSlide,
            }
        }
    }
}

/// The query shape of a validated shape spec.
pub fn shape(spec: &ShapeSpec) -> Shape {
    match spec {
        ShapeSpec::Ball { radius } => Shape::ball(*radius),
        ShapeSpec::Cuboid { half_extents } => Shape::cuboid(Vec3::from(*half_extents)),
        ShapeSpec::HalfSpace { normal } => Shape::half_space(Vec3::from(*normal)),
        ShapeSpec::Cylinder {
            radius,
            half_length,
            ..
        } => Shape::Cylinder {
            radius: *radius,
            half_length: *half_length,
        },
        ShapeSpec::Tube {
            inner_radius,
            start,
            direction,
            segments,
            end_engagement,
        } => Shape::Tube(
            TubePath::new(
                *inner_radius,
                Vec3::from(*start),
                Vec3::from(*direction),
                &segments.iter().map(tube_segment).collect::<Vec<_>>(),
            )
            .with_end_engagement(*end_engagement),
        ),
    }
}

/// A centreline piece as written → the geometry's (angles in radians).
pub fn tube_segment(spec: &TubeSegmentSpec) -> TubeSegment {
    match *spec {
        TubeSegmentSpec::Straight { length } => TubeSegment::Straight { length },
        TubeSegmentSpec::Arc {
            radius,
            angle_deg,
            bend,
        } => TubeSegment::Arc {
            radius,
            angle: angle_deg.to_radians(),
            bend: Vec3::from(bend),
        },
    }
}

/// The initial state of the scene's bodies (angular velocities to the body
/// frame; a spin body keeps only its spin about the axis, and its velocity
/// along it if it slides), before the
/// prescribed bodies are placed.
pub(super) fn initial_state(scene: &Scene, bodies: &[Body]) -> State {
    let mut state = State {
        t: 0.0,
        pos: scene
            .bodies
            .iter()
            .map(|b| Vec3::from(b.position))
            .collect(),
        rot: bodies.iter().map(|b| b.initial_rotation).collect(),
        vel: scene
            .bodies
            .iter()
            .map(|b| Vec3::from(b.velocity))
            .collect(),
        omega: scene
            .bodies
            .iter()
            .zip(bodies)
            .map(|(s, b)| b.initial_rotation.inverse() * Vec3::from(s.angular_velocity))
            .collect(),
    };
    for (i, b) in bodies.iter().enumerate() {
        if let Motion::Spin {
            axis,
            axis_body,
            slides,
            ..
        } = b.motion
        {
            state.vel[i] = if slides {
                axis * state.vel[i].dot(&axis)
            } else {
                Vec3::zeros()
            };
            state.omega[i] = axis_body * state.omega[i].dot(&axis_body);
        }
    }
    state
}
