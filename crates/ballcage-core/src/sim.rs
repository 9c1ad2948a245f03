//! A running simulation: model, state, integrator scratch and recorder.

use std::time::{Duration, Instant};

use crate::assembly::assemble;
use crate::dynamics::{ContactEval, Dynamics, Energy};
use crate::error::{SceneError, SimulationError};
use crate::integrate::{self, Workspace};
use crate::math::Vec3;
use crate::model::{Model, State};
use crate::record::{Recorder, Recording};
use crate::scene::Scene;

/// A simulation of one scene.
#[derive(Debug, Clone)]
pub struct Simulation {
    model: Model,
    state: State,
    dynamics: Dynamics,
    workspace: Workspace,
    recorder: Recorder,
    scene_toml: String,
    step: u64,
    wall: Duration,
}

impl Simulation {
    /// Validates and assembles `scene`, and records the frame at t = 0.
    pub fn new(scene: &Scene) -> Result<Self, SceneError> {
        let (model, state) = assemble(scene)?;
        let mut dynamics = Dynamics::new(&model);
        let workspace = Workspace::new(&state);
        let mut recorder = Recorder::new(&model);
        recorder.record(&model, &state, 0, &mut dynamics);
        Ok(Self {
            model,
            state,
            dynamics,
            workspace,
            recorder,
            scene_toml: scene.to_toml(),
            step: 0,
            wall: Duration::ZERO,
        })
    }

    /// The assembled model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The current state.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// Simulated time [s].
    pub fn time(&self) -> f64 {
        self.state.t
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.step
    }

    /// Force evaluations so far.
    pub fn force_evaluations(&self) -> u64 {
        self.dynamics.evaluations
    }

    /// Sparse linear solves so far (zero for the explicit integrators).
    pub fn linear_solves(&self) -> u64 {
        self.workspace.linear_solves()
    }

    /// Whether the scene's duration has been reached.
    pub fn is_done(&self) -> bool {
        self.step >= self.model.total_steps
    }

    /// Position of the named body's centre of mass [m].
    pub fn position(&self, body: &str) -> Option<Vec3> {
        self.model
            .bodies
            .iter()
            .position(|b| b.name == body)
            .map(|i| self.state.pos[i])
    }

    /// Contact points of pair `k` at the current state, with their forces.
    pub fn pair_contacts(&mut self, k: usize) -> Vec<ContactEval> {
        let mut out = Vec::new();
        self.dynamics
            .contact_points(&self.model, &self.state, k, &mut out);
        out
    }

    /// Index of the contact pair named `name`.
    pub fn pair_index(&self, name: &str) -> Option<usize> {
        self.model.pairs.iter().position(|p| p.name == name)
    }

    /// Takes one integrator step and records a frame when one is due.
    pub fn step(&mut self) -> Result<(), SimulationError> {
        let h = self.model.dt;
        integrate::step(
            self.model.integrator,
            &self.model,
            &mut self.dynamics,
            &mut self.workspace,
            &mut self.state,
            h,
        );
        self.step += 1;
        self.state.t = self.step as f64 * h;
        self.check_finite()?;
        if self.step.is_multiple_of(self.model.steps_per_output) {
            self.recorder
                .record(&self.model, &self.state, self.step, &mut self.dynamics);
        }
        Ok(())
    }

    /// Steps until the time reaches at least `t_end` [s], or the scene's duration.
    pub fn advance_to(&mut self, t_end: f64) -> Result<(), SimulationError> {
        let start = Instant::now();
        // The first step at or after t_end (a t_end within round-off of a step counts as reached).
        let target =
            ((t_end / self.model.dt - 1e-9).ceil().max(0.0) as u64).min(self.model.total_steps);
        let mut result = Ok(());
        while self.step < target {
            if let Err(e) = self.step() {
                result = Err(e);
                break;
            }
        }
        self.wall += start.elapsed();
        result
    }

    /// Runs to the end of the scene's duration.
    pub fn run(&mut self) -> Result<(), SimulationError> {
        self.advance_to(self.model.duration())
    }

    /// Energy at the current state.
    pub fn energy(&mut self) -> Energy {
        self.dynamics.energy(&self.model, &self.state)
    }

    /// Ends the run and hands over the recorded tables with run metadata.
    pub fn finish(self) -> Recording {
        let complete = self.is_done();
        let metadata = vec![
            ("ballcage.scene".to_string(), self.scene_toml),
            ("ballcage.version".to_string(), crate::VERSION.to_string()),
            (
                "ballcage.integrator".to_string(),
                self.model.integrator.name().to_string(),
            ),
            ("ballcage.dt_s".to_string(), format!("{:e}", self.model.dt)),
            ("ballcage.steps".to_string(), self.step.to_string()),
            (
                "ballcage.force_evaluations".to_string(),
                self.dynamics.evaluations.to_string(),
            ),
            (
                "ballcage.wall_time_s".to_string(),
                format!("{:.6}", self.wall.as_secs_f64()),
            ),
            ("ballcage.complete".to_string(), complete.to_string()),
        ];
        let tables = self.recorder.finish(&self.model, self.state.t);
        Recording {
            tables,
            body_names: self.model.bodies.iter().map(|b| b.name.clone()).collect(),
            pair_names: self.model.pairs.iter().map(|p| p.name.clone()).collect(),
            metadata,
        }
    }

    fn check_finite(&self) -> Result<(), SimulationError> {
        for &i in &self.model.integrated {
            let s = &self.state;
            let ok = s.pos[i]
                .iter()
                .chain(s.vel[i].iter())
                .chain(s.omega[i].iter())
                .all(|x| x.is_finite())
                && s.rot[i].coords.iter().all(|x| x.is_finite());
            if !ok {
                return Err(SimulationError {
                    time: self.state.t,
                    step: self.step,
                    reason: format!(
                        "the state of body `{}` is not finite",
                        self.model.bodies[i].name
                    ),
                });
            }
        }
        Ok(())
    }
}
