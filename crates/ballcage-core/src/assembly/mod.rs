//! Scene → read-only model and initial state, keeping only what the scene
//! declares.
//!
//! Every body's shape, every pair's point finder and force laws, every
//! joint and load is resolved here, once; this is also where the checks
//! that need more than one part of the scene at a time live (a contact
//! geometry that does not fit its bodies' shapes), and where the paper's
//! field units are converted ([`normal_law`], [`friction_law`]).
//!
//! | module | job |
//! |---|---|
//! | `bodies` | bodies, their query shapes, the initial state |
//! | `pairs` | contact pairs: geometry, laws, penetration limit |
//! | `laws` | force laws as written → SI laws |
//! | `joints` | joints and torque loads |
//! | `groups` | quasi-static bodies grouped for their equilibrium solves |

mod bodies;
mod groups;
mod joints;
mod laws;
mod pairs;

pub use bodies::{shape, tube_segment};
pub use laws::{friction_law, normal_law};

use crate::error::SceneError;
use crate::math::Vec3;
use crate::model::{Body, ContactPair, Model, Motion, RecordPlan, State};
use crate::scene::Scene;

/// Validates the scene and builds its model and initial state.
pub fn assemble(scene: &Scene) -> Result<(Model, State), SceneError> {
    scene.validate()?;
    assemble_validated(scene)
}

/// Builds the model and initial state of a scene [`Scene::validate`] has
/// accepted (a reader that validated it does not validate it again).
pub fn assemble_validated(scene: &Scene) -> Result<(Model, State), SceneError> {
    let bodies = bodies::bodies(scene)?;
    let pairs = pairs::contact_pairs(scene, &bodies)?;
    let torques = joints::torque_loads(scene)?;
    let forces = joints::force_loads(scene)?;
    let joints = joints::joints(scene)?;
    let record = record_plan(scene, &bodies, &pairs)?;
    let mut state = bodies::initial_state(scene, &bodies);
    let static_groups = groups::static_groups(&bodies, &pairs, &state)?;
    let integrated = (0..bodies.len())
        .filter(|&i| bodies[i].is_integrated())
        .collect();
    let model = Model {
        bodies,
        integrated,
        pairs,
        torques,
        forces,
        joints,
        static_groups,
        gravity: Vec3::from(scene.world.gravity),
        integrator: scene.simulation.integrator,
        dt: scene.simulation.step(),
        newton: scene.simulation.newton.clone(),
        tolerance: scene.simulation.tolerance(),
        max_step: scene
            .simulation
            .max_step
            .unwrap_or(scene.simulation.output_interval),
        threads: match scene.simulation.threads {
            0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
            n => n as usize,
        },
        energy_growth: scene.simulation.divergence.energy_growth,
        steps_per_output: scene.steps_per_output(),
        total_steps: scene.total_steps(),
        record,
        name: scene.name.clone(),
    };
    model.prescribe(0.0, &mut state);
    Ok((model, state))
}

/// What to record: the tables, the recorded bodies (by default every body
/// that is not fixed) and pairs (by default all), the summary window.
fn record_plan(
    scene: &Scene,
    bodies: &[Body],
    pairs: &[ContactPair],
) -> Result<RecordPlan, SceneError> {
    let r = &scene.record;
    let recorded_bodies = if r.bodies.is_empty() {
        (0..bodies.len())
            .filter(|&i| !matches!(bodies[i].motion, Motion::Fixed))
            .collect()
    } else {
        r.bodies
            .iter()
            .enumerate()
            .map(|(i, n)| scene.body_id(&format!("record.bodies[{i}]"), n))
            .collect::<Result<_, _>>()?
    };
    Ok(RecordPlan {
        tables: r.tables.clone(),
        bodies: recorded_bodies,
        summary_window: match r.summary_window.as_slice() {
            [a, b] => (*a, *b),
            _ => (0.0, f64::INFINITY),
        },
        max_bytes: r.max_bytes,
        pairs: if r.contacts.is_empty() {
            (0..pairs.len()).collect()
        } else {
            r.contacts
                .iter()
                .filter_map(|n| pairs.iter().position(|p| &p.name == n))
                .collect()
        },
    })
}
