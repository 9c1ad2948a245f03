//! Scene → model and initial state, keeping only what the scene declares.

use crate::error::SceneError;
use crate::force::joint::CvJointParams;
use crate::geometry::Shape;
use crate::math::{Quat, Vec3};
use crate::model::{
    Body, ContactPair, Joint, Model, Motion, RecordPlan, SpinProfile, State, TorqueLoad,
};
use crate::scene::{JointSpec, LoadSpec, MotionKind, Scene};

/// Builds the model and initial state of a scene (validating it first).
pub fn assemble(scene: &Scene) -> Result<(Model, State), SceneError> {
    scene.validate()?;
    let mut bodies = Vec::with_capacity(scene.bodies.len());
    for (i, b) in scene.bodies.iter().enumerate() {
        let q0 = b.orientation;
        let rot = Quat::from_quaternion(nalgebra::Quaternion::new(q0[0], q0[1], q0[2], q0[3]));
        let (mass, inertia) = match b.mass_properties() {
            Some((m, i3)) => (m, Vec3::from(i3)),
            None if b.is_integrated() => {
                return Err(SceneError::new(format!("bodies[{i}].mass"), "", "missing"));
            }
            None => (0.0, Vec3::zeros()),
        };
        let axis = b
            .spin_axis
            .map(|a| Vec3::from(a).normalize())
            .unwrap_or_else(Vec3::z);
        let motion = match b.motion {
            MotionKind::Fixed => Motion::Fixed,
            MotionKind::Dynamic => Motion::Dynamic,
            MotionKind::KinematicSpin => Motion::KinematicSpin(SpinProfile {
                axis,
                speed: b.spin_speed,
                ramp: b.spin_ramp,
            }),
            MotionKind::Spin => {
                let axis_body = rot.inverse() * axis;
                let i_axis = axis_body.dot(&inertia.component_mul(&axis_body));
                Motion::Spin {
                    axis,
                    axis_body,
                    inertia: i_axis,
                }
            }
        };
        bodies.push(Body {
            name: b.name.clone(),
            motion,
            mass,
            inertia,
            shape: Shape::from_spec(&b.shape),
            initial_rotation: rot,
        });
    }

    let mut pairs = Vec::with_capacity(scene.contacts.len());
    for (i, c) in scene.contacts.iter().enumerate() {
        let path = format!("contacts[{i}]");
        let a = scene.body_index(&c.bodies[0]).ok_or_else(|| {
            SceneError::new(
                format!("{path}.bodies[0]"),
                &c.bodies[0],
                "no body of that name",
            )
        })?;
        let b = scene.body_index(&c.bodies[1]).ok_or_else(|| {
            SceneError::new(
                format!("{path}.bodies[1]"),
                &c.bodies[1],
                "no body of that name",
            )
        })?;
        let (geometry, swapped) = c.resolve_geometry(&path, scene)?;
        let (first, second) = if swapped { (b, a) } else { (a, b) };
        let divergence = &scene.simulation.divergence;
        let depth_limit = divergence.max_penetration.unwrap_or_else(|| {
            divergence.penetration_fraction
                * geometry.contact_radius(&bodies[first].shape, &bodies[second].shape)
        });
        // Only free bodies translate; the others count as infinitely heavy.
        let inverse_mass = |i: usize| {
            let body: &Body = &bodies[i];
            if body.motion == Motion::Dynamic {
                1.0 / body.mass
            } else {
                0.0
            }
        };
        let reduced_mass = 1.0 / (inverse_mass(a) + inverse_mass(b));
        pairs.push(ContactPair {
            name: c.pair_name(),
            a,
            b,
            geometry,
            swapped,
            normal: c.normal.to_law(&format!("{path}.normal"))?,
            friction: c
                .friction
                .as_ref()
                .map(|f| f.to_law(&format!("{path}.friction")))
                .transpose()?,
            depth_limit,
            reduced_mass,
        });
    }

    let torques = scene
        .loads
        .iter()
        .map(|l| match l {
            LoadSpec::Torque {
                body,
                axis,
                magnitude,
                ramp,
            } => TorqueLoad {
                body: scene.body_index(body).unwrap_or_default(),
                axis: Vec3::from(*axis).normalize(),
                magnitude: *magnitude,
                ramp: *ramp,
            },
        })
        .collect();

    let joints = scene
        .joints
        .iter()
        .enumerate()
        .map(|(i, j)| match j {
            JointSpec::Cv {
                name,
                bodies: names,
                anchors,
                stiffness,
                damping,
                twist_stiffness,
                twist_damping,
                bend_limit_deg,
                stop_stiffness,
            } => Joint {
                name: name.clone().unwrap_or_else(|| format!("joints[{i}]")),
                a: scene.body_index(&names[0]).unwrap_or_default(),
                b: scene.body_index(&names[1]).unwrap_or_default(),
                anchor_a: Vec3::from(anchors[0]),
                anchor_b: Vec3::from(anchors[1]),
                params: CvJointParams {
                    stiffness: *stiffness,
                    damping: *damping,
                    twist_stiffness: *twist_stiffness,
                    twist_damping: *twist_damping,
                    bend_limit: bend_limit_deg.to_radians(),
                    stop_stiffness: *stop_stiffness,
                },
            },
            JointSpec::BendStop {
                name,
                bodies: names,
                bend_limit_deg,
                stop_stiffness,
            } => Joint {
                name: name.clone().unwrap_or_else(|| format!("joints[{i}]")),
                a: scene.body_index(&names[0]).unwrap_or_default(),
                b: scene.body_index(&names[1]).unwrap_or_default(),
                anchor_a: Vec3::zeros(),
                anchor_b: Vec3::zeros(),
                params: CvJointParams {
                    stiffness: 0.0,
                    damping: 0.0,
                    twist_stiffness: 0.0,
                    twist_damping: 0.0,
                    bend_limit: bend_limit_deg.to_radians(),
                    stop_stiffness: *stop_stiffness,
                },
            },
        })
        .collect();

    let record = RecordPlan {
        tables: scene.record.tables.clone(),
        bodies: if scene.record.bodies.is_empty() {
            (0..bodies.len())
                .filter(|&i| !matches!(bodies[i].motion, Motion::Fixed))
                .collect()
        } else {
            scene
                .record
                .bodies
                .iter()
                .filter_map(|n| scene.body_index(n))
                .collect()
        },
        summary_window: match scene.record.summary_window.as_slice() {
            [a, b] => (*a, *b),
            _ => (0.0, f64::INFINITY),
        },
        pairs: if scene.record.contacts.is_empty() {
            (0..pairs.len()).collect()
        } else {
            scene
                .record
                .contacts
                .iter()
                .filter_map(|n| pairs.iter().position(|p| &p.name == n))
                .collect()
        },
    };

    let state = State {
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
            .zip(&bodies)
            .map(|(s, b)| b.initial_rotation.inverse() * Vec3::from(s.angular_velocity))
            .collect(),
    };
    let integrated = (0..bodies.len())
        .filter(|&i| bodies[i].is_integrated())
        .collect();
    let mut model = Model {
        bodies,
        integrated,
        pairs,
        torques,
        joints,
        gravity: Vec3::from(scene.world.gravity),
        integrator: scene.simulation.integrator,
        dt: scene.simulation.dt,
        newton: scene.simulation.newton.clone(),
        energy_growth: scene.simulation.divergence.energy_growth,
        steps_per_output: scene.steps_per_output(),
        total_steps: scene.total_steps(),
        record,
        name: scene.name.clone(),
        drill_pipe: None,
    };
    let mut state = state;
    // A spin body's velocity is only its spin about the axis.
    for i in 0..model.bodies.len() {
        if let Motion::Spin { axis_body, .. } = model.bodies[i].motion {
            state.vel[i] = Vec3::zeros();
            state.omega[i] = axis_body * state.omega[i].dot(&axis_body);
        }
    }
    model.drill_pipe = scene
        .origin
        .as_ref()
        .map(|spec| crate::drillpipe::Layout::new(spec, &model.bodies, &model.pairs));
    model.prescribe(0.0, &mut state);
    Ok((model, state))
}
