//! A running simulation: model, state, integrator scratch and recorder.

use std::time::{Duration, Instant};

use crate::assembly::assemble;
use crate::dynamics::{ContactEval, ContactWatch, Dynamics, Energy};
use crate::error::{SceneError, SimulationError};
use crate::integrate::{self, Stats, Workspace};
use crate::math::Vec3;
use crate::model::{Model, Motion, State};
use crate::record::{Observer, Recorder, Recording};
use crate::scene::{IntegratorKind, Scene};

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
    /// The divergence that stopped the run, if any.
    failed: Option<SimulationError>,
    /// Energy bookkeeping of the divergence check.
    balance: EnergyBalance,
    /// The contact watch of the last accepted step (stable-step estimate).
    last_watch: ContactWatch,
}

/// What stopped a run, for the advice in its error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Failure {
    /// A penetration beyond its pair's limit (possibly physical).
    Penetration,
    /// Anything else (non-finite state, energy created, Newton failure).
    Numerical,
}

/// Energy put in by drives and applied torques, against which the
/// mechanical energy may not grow ([`crate::scene::DivergenceSpec::energy_growth`]).
#[derive(Debug, Clone, Default)]
struct EnergyBalance {
    /// Mechanical energy at t = 0 [J].
    initial: f64,
    /// Gravitational potential at t = 0 [J].
    initial_gravity: f64,
    /// Kinetic and contact energy at t = 0 [J].
    initial_free: f64,
    /// Net work of the drives and applied torques so far [J].
    work_in: f64,
    /// ∫|P| of each input so far [J].
    work_abs: f64,
    /// Largest gravitational energy released or stored so far, |ΔPE_g| [J].
    gravity_swing: f64,
}

impl Simulation {
    /// Assembles a generic `scene` and records the frame at t = 0. Scene
    /// documents of any kind start simulations through the loader's
    /// `Document::simulation`, a layer above, with their observers.
    pub fn new(scene: &Scene) -> Result<Self, SceneError> {
        let (model, state) = assemble(scene)?;
        Ok(Self::from_model(model, state, vec![], scene.to_toml()))
    }

    /// A simulation of an assembled model from `state`, with `observers`
    /// filling tables of their own; `scene_toml` goes into the output
    /// metadata. Records the frame at `state`.
    pub fn from_model(
        model: Model,
        state: State,
        observers: Vec<Box<dyn Observer>>,
        scene_toml: String,
    ) -> Self {
        let mut dynamics = Dynamics::new(&model);
        let workspace = Workspace::new(&state);
        let mut recorder = Recorder::new(&model, observers);
        recorder.record(&model, &state, 0, &mut dynamics);
        let e0 = dynamics.energy(&model, &state);
        let balance = EnergyBalance {
            initial: e0.total(),
            initial_gravity: e0.potential_gravity,
            initial_free: e0.kinetic + e0.potential_contact,
            ..EnergyBalance::default()
        };
        Self {
            model,
            state,
            dynamics,
            workspace,
            recorder,
            scene_toml,
            step: 0,
            wall: Duration::ZERO,
            failed: None,
            balance,
            last_watch: ContactWatch::default(),
        }
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
        self.workspace.stats().solves
    }

    /// Linear solves, LU factorizations and Newton iterations so far.
    pub fn solver_stats(&self) -> Stats {
        self.workspace.stats()
    }

    /// The divergence that stopped the run, if any.
    pub fn failure(&self) -> Option<&SimulationError> {
        self.failed.as_ref()
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
    ///
    /// The step fails, and every later one with it, when it diverges: a
    /// non-finite state, a penetration beyond its pair's limit, energy
    /// created beyond the divergence tolerance (checked at recorded frames),
    /// or an implicit step that cannot be solved. The error names the time,
    /// the bodies or pair, and the step the stability estimate says would
    /// hold; the frames recorded so far stay available to [`Self::finish`].
    pub fn step(&mut self) -> Result<(), SimulationError> {
        if let Some(e) = &self.failed {
            return Err(e.clone());
        }
        let h = self.model.dt;
        self.dynamics.watch.reset();
        if let Err(reason) = integrate::step(
            &self.model,
            &mut self.dynamics,
            &mut self.workspace,
            &mut self.state,
            self.step,
        ) {
            return self.fail(reason);
        }
        self.step += 1;
        if let Some(reason) = self.non_finite() {
            return self.fail(reason);
        }
        if let Some(reason) = self.too_deep() {
            return self.fail_with(reason, Failure::Penetration);
        }
        self.add_input_work(h);
        if self.step.is_multiple_of(self.model.steps_per_output) {
            if let Some(reason) = self.energy_created() {
                return self.fail(reason);
            }
            self.recorder
                .record(&self.model, &self.state, self.step, &mut self.dynamics);
        }
        if self.dynamics.watch.saw_contact() {
            self.last_watch = self.dynamics.watch;
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

    /// Ends the run and hands over the recorded tables with run metadata
    /// (`ballcage.complete` is false, and `ballcage.error` says why, when
    /// the run stopped early).
    pub fn finish(self) -> Recording {
        let complete = self.is_done() && self.failed.is_none();
        let stats = self.workspace.stats();
        let mut metadata = vec![
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
                "ballcage.linear_solves".to_string(),
                stats.solves.to_string(),
            ),
            (
                "ballcage.factorizations".to_string(),
                stats.factorizations.to_string(),
            ),
            (
                "ballcage.newton_iterations".to_string(),
                stats.newton_iterations.to_string(),
            ),
            (
                "ballcage.step_halvings".to_string(),
                stats.halvings.to_string(),
            ),
            (
                "ballcage.wall_time_s".to_string(),
                format!("{:.6}", self.wall.as_secs_f64()),
            ),
            ("ballcage.complete".to_string(), complete.to_string()),
        ];
        if let Some(e) = &self.failed {
            metadata.push(("ballcage.error".to_string(), e.to_string()));
        }
        let tables = self.recorder.finish(&self.model, self.state.t);
        Recording {
            tables,
            body_names: self.model.bodies.iter().map(|b| b.name.clone()).collect(),
            pair_names: self.model.pairs.iter().map(|p| p.name.clone()).collect(),
            metadata,
        }
    }

    /// Records the failure and returns it, with the stable-step advice.
    fn fail(&mut self, reason: String) -> Result<(), SimulationError> {
        self.fail_with(reason, Failure::Numerical)
    }

    fn fail_with(&mut self, reason: String, kind: Failure) -> Result<(), SimulationError> {
        let e = SimulationError {
            time: self.state.t,
            step: self.step,
            reason: format!("{reason}; {}", self.step_advice(kind)),
        };
        self.failed = Some(e.clone());
        Err(e)
    }

    /// What the stability estimate of the last accepted step says about dt.
    fn step_advice(&self, failure: Failure) -> String {
        let w = if self.last_watch.saw_contact() {
            self.last_watch
        } else {
            self.dynamics.watch
        };
        let kind = self.model.integrator;
        let dt = self.model.dt;
        let (estimate, pair) = match kind {
            IntegratorKind::SymplecticEuler => w.explicit_step(),
            // RK4's stability interval on the real and imaginary axes is
            // about 2.8 against symplectic Euler's 2.
            IntegratorKind::Rk4 => {
                let (h, pair) = w.explicit_step();
                (1.4 * h, pair)
            }
            IntegratorKind::LinearlyImplicitEuler => w.elastic_step(),
            // No stability limit on the linearized contacts: resolve the
            // stiffest contact's period instead.
            IntegratorKind::Sdirk2 => {
                let (period, pair) = w.period();
                (period / 10.0, pair)
            }
        };
        let Some(p) = self.model.pairs.get(pair).filter(|_| estimate.is_finite()) else {
            return format!(
                "no contact was active, so there is no stable-step estimate; \
                 try simulation.dt = {:.3e} s",
                dt / 4.0
            );
        };
        let what = if kind == IntegratorKind::Sdirk2 {
            "a tenth of the stiffest contact's period"
        } else {
            "the stability estimate of the stiffest contact"
        };
        let advice = if estimate < dt {
            format!("{what} asks for simulation.dt ≤ {estimate:.3e} s")
        } else if failure == Failure::Penetration {
            format!(
                "{what} ({estimate:.3e} s) is above the step, so the penetration may be \
                 physical (a contact too soft for its load): if it is, raise \
                 simulation.divergence.penetration_fraction or set max_penetration; \
                 otherwise try simulation.dt = {:.3e} s",
                dt / 4.0
            )
        } else {
            format!(
                "{what} ({estimate:.3e} s) is above the step, so the instability is \
                 elsewhere (joints, gyroscopic terms); try simulation.dt = {:.3e} s",
                dt / 4.0
            )
        };
        format!(
            "{advice} with {} (pair `{}`, bodies `{}` and `{}`; the step is {dt:.3e} s)",
            kind.name(),
            p.name,
            self.model.bodies[p.a].name,
            self.model.bodies[p.b].name
        )
    }

    fn non_finite(&self) -> Option<String> {
        let s = &self.state;
        self.model
            .integrated
            .iter()
            .find(|&&i| {
                !(s.pos[i]
                    .iter()
                    .chain(s.vel[i].iter())
                    .chain(s.omega[i].iter())
                    .all(|x| x.is_finite())
                    && s.rot[i].coords.iter().all(|x| x.is_finite()))
            })
            .map(|&i| {
                format!(
                    "the state of body `{}` is not finite",
                    self.model.bodies[i].name
                )
            })
    }

    fn too_deep(&self) -> Option<String> {
        let (k, depth, ratio) = self.dynamics.watch.deepest?;
        if ratio <= 1.0 {
            return None;
        }
        let p = &self.model.pairs[k];
        Some(format!(
            "pair `{}` (bodies `{}` and `{}`) penetrates {:.4} mm, beyond its limit of {:.4} mm \
             (simulation.divergence)",
            p.name,
            self.model.bodies[p.a].name,
            self.model.bodies[p.b].name,
            depth * 1e3,
            p.depth_limit * 1e3
        ))
    }

    /// Adds the work of the applied torques and of the prescribed bodies
    /// (minus what the joints and contacts do on them) over the step, from
    /// the last force evaluation and the new velocities.
    fn add_input_work(&mut self, h: f64) {
        let (model, state) = (&self.model, &self.state);
        let mut add = |p: f64| {
            self.balance.work_in += p * h;
            self.balance.work_abs += p.abs() * h;
        };
        for l in &model.torques {
            add(l.torque(state.t).dot(&state.omega_world(l.body)));
        }
        let (force, torque) = (self.dynamics.forces(), self.dynamics.torques());
        for (i, b) in model.bodies.iter().enumerate() {
            if matches!(b.motion, Motion::KinematicSpin(_)) {
                add(-(force[i].dot(&state.vel[i]) + torque[i].dot(&state.omega_world(i))));
            }
        }
    }

    /// Checks that the mechanical energy has not grown beyond the input
    /// work by more than the divergence tolerance. Physically
    /// E(t) − E(0) − W_in(t) ≤ 0 (the contacts and joints only dissipate);
    /// the tolerance is relative to the most energy the system could hold:
    /// its initial kinetic and contact energy, the gravitational energy
    /// released, and the absolute input work.
    fn energy_created(&mut self) -> Option<String> {
        let e = self.dynamics.energy(&self.model, &self.state);
        let b = &mut self.balance;
        b.gravity_swing = b
            .gravity_swing
            .max((e.potential_gravity - b.initial_gravity).abs());
        let created = e.total() - b.initial - b.work_in;
        let scale = b.initial_free + b.gravity_swing + b.work_abs;
        let limit = self.model.energy_growth * scale;
        (created > limit && created > 1e-12).then(|| {
            format!(
                "the integrator created {created:.4e} J of energy (mechanical energy {:.4e} J, \
                 {:.4e} J at the start, input work {:.4e} J), more than \
                 simulation.divergence.energy_growth = {} of the energy scale {scale:.4e} J",
                e.total(),
                b.initial,
                b.work_in,
                self.model.energy_growth
            )
        })
    }
}
