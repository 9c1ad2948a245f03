//! A running simulation: model, state, integrator scratch and recorder.

use std::time::{Duration, Instant};

use crate::assembly::assemble;
use crate::dynamics::{ContactEval, ContactWatch, Dynamics, Energy, Evaluated};
use crate::error::{SceneError, SimulationError};
use crate::integrate::{self, ErrorStats, Stats, Workspace};
use crate::math::Vec3;
use crate::model::{Model, Motion, State};
use crate::record::{Observer, Recorder, Recording, within_step};
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
    /// Halvings of SDIRK2 steps before the current step (divergence advice).
    halvings_before_step: u64,
    /// The deepest penetration at t = 0 relative to its pair's limit:
    /// (pair, depth [m], depth / limit) (divergence advice).
    initial_deepest: Option<(usize, f64, f64)>,
    /// How close the run has come to the limits of its divergence checks.
    closest: Closest,
}

/// How close a run has come to the limits of its divergence checks, for
/// its metadata: the deepest penetration relative to its pair's limit
/// (pair, depth / limit, time [s]), at the end of each step, and the
/// largest energy created relative to what the check allows, at each
/// recorded frame (where the check runs).
#[derive(Debug, Clone, Copy, Default)]
struct Closest {
    penetration: Option<(usize, f64, f64)>,
    energy: f64,
}

impl Closest {
    /// Takes in the deepest penetration `deepest` (pair, depth [m],
    /// depth / limit) seen at time `t` [s].
    fn see_penetration(&mut self, deepest: Option<(usize, f64, f64)>, t: f64) {
        if let Some((k, _, ratio)) = deepest
            && self.penetration.is_none_or(|(_, r, _)| ratio > r)
        {
            self.penetration = Some((k, ratio, t));
        }
    }
}

/// What stopped a run, for the advice in its error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Failure {
    /// The integrator could not take its step (Newton, or with adaptive
    /// steps the error estimate at the smallest step).
    Integrator,
    /// A penetration beyond its pair's limit (possibly physical).
    Penetration,
    /// The mechanical energy grew beyond the input work.
    Energy,
    /// A non-finite state.
    NotFinite,
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
    /// The input work up to the end of the last step the integrator kept.
    work: InputWork,
    /// The same at that step's start, and the step's span [s]: a frame
    /// within the step takes the work interpolated to its time.
    before: InputWork,
    span: (f64, f64),
    /// The drives', the loads' and the summed absolute input power [W] at
    /// the end of the last step (`None` before the first step).
    power: Option<[f64; 3]>,
    /// Largest gravitational energy released or stored so far, |ΔPE_g| [J].
    gravity_swing: f64,
}

/// Work of the drives and applied torques since t = 0 [J], summed over the
/// integrator's steps.
#[derive(Debug, Clone, Copy, Default)]
struct InputWork {
    /// Net work of the drives and applied torques [J].
    net: f64,
    /// Of it, the drives' (prescribed motions') [J].
    drive: f64,
    /// Of it, the applied torques' and forces' [J].
    load: f64,
    /// ∫|P| of each input [J].
    abs: f64,
}

impl Simulation {
    /// Assembles a generic `scene` and records the frame at t = 0. Scene
    /// documents of any kind start simulations through the loader's
    /// `Document::simulation`, a layer above, with their observers.
    pub fn new(scene: &Scene) -> Result<Self, SceneError> {
        let (model, state) = assemble(scene)?;
        initial_energy_is_finite(&model, &state)?;
        crate::record::check_budget(&model, &[])?;
        Ok(Self::from_model(model, state, vec![], scene.to_toml()))
    }

    /// A simulation of an assembled model from `state`, with `observers`
    /// filling tables of their own; `scene_toml` goes into the output
    /// metadata. Records the frame at `state`.
    pub fn from_model(
        model: Model,
        mut state: State,
        observers: Vec<Box<dyn Observer>>,
        scene_toml: String,
    ) -> Self {
        let mut dynamics = Dynamics::new(&model);
        dynamics.settle_groups(&model, &mut state);
        let workspace = Workspace::new(&state);
        let mut recorder = Recorder::new(&model, observers);
        if recorder.needs_impulses() {
            dynamics.track_impulses(&model);
        }
        recorder.record(&model, &state, 0, &mut dynamics, (0.0, 0.0));
        let initial_deepest = deepest_penetration(&model, &state, &mut dynamics);
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
            halvings_before_step: 0,
            initial_deepest,
            closest: {
                let mut c = Closest::default();
                c.see_penetration(initial_deepest, 0.0);
                c
            },
        }
    }

    /// Threads evaluating the contact pairs (`simulation.threads`).
    pub fn threads(&self) -> usize {
        self.dynamics.threads()
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

    /// What the error-estimating integrators (`esdirk32`, `trbdf2`) did: accepted and
    /// rejected steps, the smallest step, the accumulated error estimate;
    /// `None` for the other integrators.
    pub fn error_stats(&self) -> Option<ErrorStats> {
        self.workspace.error_stats()
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
    /// hold, or, when a smaller step would probably not help (an initial
    /// overlap, a step already retried in halves, a step already within the
    /// estimate), what to check instead; the frames recorded so far stay
    /// available to [`Self::finish`].
    pub fn step(&mut self) -> Result<(), SimulationError> {
        if let Some(e) = &self.failed {
            return Err(e.clone());
        }
        let h = self.model.dt;
        self.dynamics.watch.reset();
        self.halvings_before_step = self.workspace.stats().halvings;
        let (model, balance, recorder) = (&self.model, &mut self.balance, &mut self.recorder);
        let mut accepted = |state: &State, h: f64, dynamics: &mut Dynamics, evaluated| {
            balance.add_step(model, state, h, dynamics);
            recorder.after_step(model, state, h, dynamics, evaluated);
        };
        if let Err(reason) = integrate::step(
            model,
            &mut self.dynamics,
            &mut self.workspace,
            &mut self.state,
            self.step,
            &mut accepted,
        ) {
            return self.fail_with(reason, Failure::Integrator);
        }
        self.step += 1;
        // The quasi-static bodies where the held ones are now (the
        // integrator moves only the integrated bodies).
        self.dynamics.settle_groups(&self.model, &mut self.state);
        if let Some(reason) = self.non_finite() {
            return self.fail_with(reason, Failure::NotFinite);
        }
        self.closest
            .see_penetration(self.dynamics.watch.deepest, self.state.t);
        if let Some(reason) = self.too_deep() {
            return self.fail_with(reason, Failure::Penetration);
        }
        if self.model.tolerance.is_none() {
            let (model, state) = (&self.model, &self.state);
            self.balance.add_step(model, state, h, &self.dynamics);
            (self.recorder).after_step(model, state, h, &mut self.dynamics, Evaluated::No);
        }
        if self.step.is_multiple_of(self.model.steps_per_output) {
            if let Some(reason) = self.energy_created() {
                return self.fail_with(reason, Failure::Energy);
            }
            let work = self.balance.work_at(self.state.t);
            self.recorder.record(
                &self.model,
                &self.state,
                self.step,
                &mut self.dynamics,
                (work.drive, work.load),
            );
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
        let (smallest, error_metadata) = (self.smallest_step(), self.error_metadata());
        let closest_metadata = self.closest_metadata();
        let group_metadata = self.group_metadata();
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
                "ballcage.fallback_steps".to_string(),
                stats.fallbacks.to_string(),
            ),
            (
                "ballcage.smallest_step_s".to_string(),
                format!("{smallest:e}"),
            ),
            (
                "ballcage.wall_time_s".to_string(),
                format!("{:.6}", self.wall.as_secs_f64()),
            ),
            (
                "ballcage.real_time_factor".to_string(),
                format!("{:.6}", self.state.t / self.wall.as_secs_f64().max(1e-9)),
            ),
            ("ballcage.complete".to_string(), complete.to_string()),
        ];
        metadata.extend(error_metadata);
        metadata.extend(closest_metadata);
        metadata.extend(group_metadata);
        if let Some(e) = &self.failed {
            metadata.push(("ballcage.error".to_string(), e.to_string()));
        }
        let part_labels = self.recorder.part_labels();
        let tables = self.recorder.finish(&self.model, self.state.t);
        Recording {
            tables,
            body_names: self.model.bodies.iter().map(|b| b.name.clone()).collect(),
            pair_names: self.model.pairs.iter().map(|p| p.name.clone()).collect(),
            part_labels,
            metadata,
        }
    }

    /// What the quasi-static groups' solves did (`ballcage.static_*`;
    /// nothing for a model without quasi-static bodies).
    fn group_metadata(&self) -> Vec<(String, String)> {
        let Some(g) = self.dynamics.group_stats() else {
            return vec![];
        };
        [
            ("solves", g.solves),
            ("iterations", g.iterations),
            ("restarts", g.restarts),
            ("failures", g.failures),
        ]
        .into_iter()
        .map(|(k, v)| (format!("ballcage.static_{k}"), v.to_string()))
        .collect()
    }

    /// The smallest step or part step taken [s]: `simulation.dt` halved as
    /// often as any step was, or the smallest adaptive step.
    pub fn smallest_step(&self) -> f64 {
        let halved = self.model.dt / f64::from(1u32 << self.workspace.stats().deepest_halving);
        self.workspace
            .error_stats()
            .map_or(halved, |e| halved.min(e.smallest_step))
    }

    /// How close the run came to the limits of its divergence checks
    /// (`simulation.divergence`): the deepest penetration over its pair's
    /// limit, with the pair and the time, at the end of the steps; the
    /// largest energy created over what the check allows, at the frames.
    /// 1 is the limit; a completed run stayed below it in both.
    fn closest_metadata(&self) -> Vec<(String, String)> {
        let mut out = vec![(
            "ballcage.energy_of_limit".to_string(),
            format!("{:.6e}", self.closest.energy),
        )];
        let (ratio, pair, t) = match self.closest.penetration {
            Some((k, ratio, t)) => (ratio, self.model.pairs[k].name.clone(), t),
            None => (0.0, String::new(), 0.0),
        };
        out.push((
            "ballcage.penetration_of_limit".to_string(),
            format!("{ratio:.6e}"),
        ));
        if !pair.is_empty() {
            out.push(("ballcage.penetration_of_limit_pair".to_string(), pair));
            out.push((
                "ballcage.penetration_of_limit_t_s".to_string(),
                format!("{t:e}"),
            ));
        }
        out
    }

    /// The metadata of an integrator with an error estimate (`esdirk32`, `trbdf2`):
    /// accepted and rejected steps, the accumulated estimate of the global
    /// error (the sums of each step's largest local error on a position
    /// [m] and on a velocity [m/s]) and the tolerances; empty otherwise.
    fn error_metadata(&self) -> Vec<(String, String)> {
        let Some(e) = self.workspace.error_stats() else {
            return vec![];
        };
        let mut out = vec![
            ("ballcage.accepted_steps", e.accepted.to_string()),
            ("ballcage.rejected_steps", e.rejected.to_string()),
            (
                "ballcage.error_estimate",
                format!("{:e} m, {:e} m/s", e.position_error, e.velocity_error),
            ),
            (
                "ballcage.error_estimate_position_m",
                format!("{:e}", e.position_error),
            ),
            (
                "ballcage.error_estimate_velocity_m_s",
                format!("{:e}", e.velocity_error),
            ),
        ];
        if let Some(tol) = self.model.tolerance {
            out.push(("ballcage.rtol", format!("{:e}", tol.rtol)));
            out.push(("ballcage.atol_position_m", format!("{:e}", tol.position)));
            out.push(("ballcage.atol_rotation_rad", format!("{:e}", tol.rotation)));
            out.push(("ballcage.atol_velocity_m_s", format!("{:e}", tol.velocity)));
            out.push((
                "ballcage.atol_angular_velocity_rad_s",
                format!("{:e}", tol.angular_velocity),
            ));
        }
        out.into_iter().map(|(k, v)| (k.to_string(), v)).collect()
    }

    /// Records the failure and returns it, with the stable-step advice.
    fn fail_with(&mut self, reason: String, kind: Failure) -> Result<(), SimulationError> {
        let e = SimulationError {
            time: self.state.t,
            step: self.step,
            reason: format!("{reason}; {}", self.step_advice(kind)),
        };
        self.failed = Some(e.clone());
        Err(e)
    }

    /// What to change after a failure: the step the stability estimate of
    /// the last accepted step asks for, or, when the step is probably not
    /// the cause (see [`Self::not_the_step`]), what to check instead.
    fn step_advice(&self, failure: Failure) -> String {
        let kind = self.model.integrator;
        let dt = self.model.dt;
        let (estimate, pair, what) = self.stable_step();
        let stiffest = self.model.pairs.get(pair).filter(|_| estimate.is_finite());
        if let Some(advice) = self.adaptive_check_advice(failure) {
            return advice;
        }
        if let Some((why, names_a_pair)) = self.not_the_step(estimate, stiffest.is_some()) {
            let at = stiffest
                .filter(|_| !names_a_pair)
                .map_or(String::new(), |p| {
                    format!(
                        "; the stiffest contact was pair `{}` (bodies `{}` and `{}`)",
                        p.name, self.model.bodies[p.a].name, self.model.bodies[p.b].name
                    )
                });
            return format!(
                "{why}, so the step ({dt:.3e} s with {}) is probably not the cause: {}{at}",
                kind.name(),
                what_to_check(failure)
            );
        }
        let Some(p) = stiffest else {
            return format!(
                "no contact was active, so there is no stable-step estimate; try \
                 simulation.dt = {:.3e} s, and if the run fails at the same time \
                 again, the step is not the cause: {}",
                dt / 4.0,
                what_to_check(failure)
            );
        };
        format!(
            "{what} asks for simulation.dt ≤ {estimate:.3e} s with {} (pair `{}`, bodies \
             `{}` and `{}`; the step is {dt:.3e} s)",
            kind.name(),
            p.name,
            self.model.bodies[p.a].name,
            self.model.bodies[p.b].name
        )
    }

    /// The stable step the contact watch of the last accepted step gives
    /// for the integrator [s] (infinite without a contact), the pair that
    /// sets it, and what the estimate is, in words.
    fn stable_step(&self) -> (f64, usize, &'static str) {
        let w = if self.last_watch.saw_contact() {
            self.last_watch
        } else {
            self.dynamics.watch
        };
        let explicit = "the stability estimate of the stiffest contact";
        match self.model.integrator {
            IntegratorKind::SymplecticEuler => {
                let (h, pair) = w.explicit_step();
                (h, pair, explicit)
            }
            // RK4's stability interval on the real and imaginary axes is
            // about 2.8 against symplectic Euler's 2.
            IntegratorKind::Rk4 => {
                let (h, pair) = w.explicit_step();
                (1.4 * h, pair, explicit)
            }
            IntegratorKind::LinearlyImplicitEuler => {
                let (h, pair) = w.elastic_step();
                (h, pair, explicit)
            }
            // No stability limit on the linearized contacts: resolve the
            // stiffest contact's period instead.
            IntegratorKind::Sdirk2 | IntegratorKind::Esdirk32 | IntegratorKind::Trbdf2 => {
                let (period, pair) = w.period();
                (
                    period / 10.0,
                    pair,
                    "a tenth of the stiffest contact's period",
                )
            }
        }
    }

    /// With adaptive steps, the advice after a check that failed at the
    /// end of steps the integrator accepted (energy created, a penetration
    /// beyond its limit, a non-finite state): each step met the error
    /// tolerance, so no step was shortened for it; `None` for a step the
    /// integrator could not take, or with fixed steps.
    fn adaptive_check_advice(&self, failure: Failure) -> Option<String> {
        let tol = self.model.tolerance.as_ref()?;
        // An overlap at t = 0 is the likelier cause ([`Self::not_the_step`]).
        if self.initial_deepest.is_some_and(|d| d.2 > 1.0) {
            return None;
        }
        let met = format!(
            "every step met its error estimate's tolerance (simulation.rtol = {}, atol {} m, \
             {} rad, {} m/s, {} rad/s)",
            tol.rtol, tol.position, tol.rotation, tol.velocity, tol.angular_velocity
        );
        match failure {
            Failure::Integrator => None,
            // The energy a step may create grows with the error it is allowed.
            Failure::Energy | Failure::NotFinite => Some(format!(
                "{met}, and a tolerance loose against the energy the system holds lets the \
                 integrator create energy: lower simulation.rtol (and simulation.atol, if \
                 set); if the run fails at the same time with a tenth of it, the tolerance \
                 is not the cause: {}",
                what_to_check(failure)
            )),
            Failure::Penetration => Some(format!(
                "{met}, so the depth is the model's rather than the step's: {}",
                what_to_check(failure)
            )),
        }
    }

    /// Why a smaller step would probably not cure the failure, if it would
    /// not: a pair already penetrated beyond its limit at t = 0; the
    /// failing step was already retried in halves (SDIRK2); or the step is
    /// already within the stability estimate `estimate` [s] (`estimated`:
    /// a contact gave one). The flag says whether the reason names a pair.
    fn not_the_step(&self, estimate: f64, estimated: bool) -> Option<(String, bool)> {
        if let Some((k, depth, ratio)) = self.initial_deepest.filter(|d| d.2 > 1.0) {
            let p = &self.model.pairs[k];
            let why = format!(
                "pair `{}` already penetrates {:.4} mm at t = 0, {ratio:.1} times its limit of \
                 {:.4} mm (an initial overlap)",
                p.name,
                depth * 1e3,
                p.depth_limit * 1e3
            );
            return Some((why, true));
        }
        if self.model.tolerance.is_some() {
            // Adaptive steps: the integrator only gives up at MIN_STEP_FRACTION of the
            // largest step, so a smaller step is not the cure.
            let why = format!(
                "the adaptive steps went down to {:.3e} s (1/{} of the largest) without curing it",
                self.model.max_step * crate::integrate::MIN_STEP_FRACTION,
                (1.0 / crate::integrate::MIN_STEP_FRACTION).round()
            );
            return Some((why, false));
        }
        let halvings = self.workspace.stats().halvings - self.halvings_before_step;
        if halvings > 0 {
            let why = format!(
                "the failing step was already retried in halves ({halvings} times) without \
                 curing it"
            );
            return Some((why, false));
        }
        let (dt, what) = (self.model.dt, self.stable_step().2);
        (estimated && estimate >= dt).then(|| {
            (
                format!("the step is already within {what} ({estimate:.3e} s)"),
                false,
            )
        })
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
        let work = self.balance.work_at(self.state.t);
        let (created, scale) = self.balance.excess(&e, &work);
        let limit = self.model.energy_growth * scale;
        let share = if created <= 1e-12 {
            0.0
        } else if created <= limit {
            created / limit
        } else {
            // The frame failed; its step's own end decides (or the frame).
            self.own_state_share().unwrap_or(created / limit)
        };
        if !share.is_nan() {
            self.closest.energy = self.closest.energy.max(share);
        }
        if share <= 1.0 {
            return None;
        }
        let b = &self.balance;
        Some(format!(
            "the integrator created {created:.4e} J of energy (mechanical energy {:.4e} J, \
             {:.4e} J at the start, input work {:.4e} J), more than \
             simulation.divergence.energy_growth = {} of the energy scale {scale:.4e} J",
            e.total(),
            b.initial,
            b.work_at(self.state.t).net,
            self.model.energy_growth
        ))
    }

    /// For a frame interpolated within an adaptive step that failed the
    /// energy balance, the balance at the integrator's own state at the
    /// step's end ([`Self::energy_created`], with the input work summed to
    /// that end): the run stops only if that fails too. The
    /// interpolant's error is not controlled: within a step over which a
    /// stiff transient settles, its velocities, cubic Hermite from the
    /// accelerations at the step's ends, overshoot (three ideal-CV links at
    /// rtol 1e-3 with steps of up to 5 ms: 5.0e-4 J of kinetic energy at the
    /// 1 ms frame against 4.3e-5 J with 1 ms steps, and an energy scale of
    /// 3e-4 J). The run goes on from the step's end, so that is the state a
    /// divergence would show in.
    ///
    /// Returns the energy created there as a share of what the check
    /// allows, 1 at the limit (`None` without such a state).
    fn own_state_share(&mut self) -> Option<f64> {
        let own = self.workspace.state_ahead_of_frame()?;
        let e = self.dynamics.energy(&self.model, own);
        let (created, scale) = self.balance.excess(&e, &self.balance.work);
        let limit = self.model.energy_growth * scale;
        Some(if created <= 1e-12 {
            0.0
        } else {
            created / limit
        })
    }
}

impl EnergyBalance {
    /// The energy created at a state of energy `e` [J], against the input
    /// work `work`, and the energy scale it is measured against: the most
    /// the system could hold (initial kinetic and contact energy,
    /// gravitational energy released, ∫|P_in| dt) [J].
    fn excess(&self, e: &Energy, work: &InputWork) -> (f64, f64) {
        let swing = self
            .gravity_swing
            .max((e.potential_gravity - self.initial_gravity).abs());
        let created = e.total() - self.initial - work.net;
        (created, self.initial_free + swing + work.abs)
    }

    /// Adds the work of the applied torques and forces and of the
    /// prescribed bodies (minus what the joints and contacts do on them)
    /// over a step of `h` [s] that ended at `state`, by the trapezoidal rule
    /// as the dissipated energies (the powers at the step's end from the
    /// last force evaluation and the end's velocities; the first step has
    /// only its end).
    fn add_step(&mut self, model: &Model, state: &State, h: f64, dynamics: &Dynamics) {
        // [drive, load, Σ|P|] [W]
        let mut p = [0.0; 3];
        let mut add = |w: f64, k: usize| {
            p[k] += w;
            p[2] += w.abs();
        };
        for l in &model.torques {
            add(l.torque(state.t).dot(&state.omega_world(l.body)), 1);
        }
        for l in &model.forces {
            add(l.force(state.t).dot(&state.vel[l.body]), 1);
        }
        let (force, torque) = (dynamics.forces(), dynamics.torques());
        for (i, body) in model.bodies.iter().enumerate() {
            if matches!(body.motion, Motion::KinematicSpin(_)) {
                add(
                    -(force[i].dot(&state.vel[i]) + torque[i].dot(&state.omega_world(i))),
                    0,
                );
            }
        }
        let before = self.power.replace(p).unwrap_or(p);
        let work = |k: usize| 0.5 * (before[k] + p[k]) * h;
        self.before = self.work;
        self.span = (state.t - h, state.t);
        let w = &mut self.work;
        w.drive += work(0);
        w.load += work(1);
        w.net += work(0) + work(1);
        w.abs += work(2);
    }

    /// The input work at time `t` [s]: the sum to the last step's end,
    /// interpolated linearly within that step for a frame inside it.
    fn work_at(&self, t: f64) -> InputWork {
        let Some(s) = within_step(self.span, t) else {
            return self.work;
        };
        let (a, b) = (&self.before, &self.work);
        let mix = |x: f64, y: f64| x + s * (y - x);
        InputWork {
            net: mix(a.net, b.net),
            drive: mix(a.drive, b.drive),
            load: mix(a.load, b.load),
            abs: mix(a.abs, b.abs),
        }
    }
}

/// What to check when the step is not the cause of a failure.
fn what_to_check(failure: Failure) -> &'static str {
    match failure {
        Failure::Penetration => {
            "the penetration may be physical or set up; check that the pair's geometry \
             fits (parts that do not fit, an initial overlap), that its contact law is \
             not too soft for the load (raise its stiffness, or \
             simulation.divergence.penetration_fraction / max_penetration if the depth is \
             real) nor too stiff, and that no load (drive, moment, gravity) is too large"
        }
        Failure::Integrator | Failure::Energy | Failure::NotFinite => {
            "check for an initial overlap or geometry that does not fit (a penetration \
             beyond a pair's limit), a contact law too stiff or too soft, a load (drive, \
             moment, gravity) too large, the joints' stiffness, and for SDIRK2 \
             simulation.newton.max_iterations"
        }
    }
}

/// The deepest penetration of any pair at `state` relative to its pair's
/// limit, (pair, depth [m], depth / limit), from the contact geometry alone
/// (no force evaluation); `None` without contact.
fn deepest_penetration(
    model: &Model,
    state: &State,
    dynamics: &mut Dynamics,
) -> Option<(usize, f64, f64)> {
    let (mut points, mut watch) = (Vec::new(), ContactWatch::default());
    for (k, pair) in model.pairs.iter().enumerate() {
        points.clear();
        dynamics.contact_points(model, state, k, &mut points);
        for e in &points {
            watch.see_depth(k, pair, e.point.depth);
        }
    }
    watch.deepest
}

/// Refuses a start whose energy overflows f64 (found by fuzzing: a
/// velocity of 1e200 m/s, a ball overlapping the ground by 1e200 m): the
/// frame at t = 0 would hold infinities, and no step could follow. Names
/// the first body or pair whose energy is not finite.
pub(crate) fn initial_energy_is_finite(model: &Model, state: &State) -> Result<(), SceneError> {
    let energy = crate::dynamics::energy_of(model, state, &mut Vec::new());
    if energy.total().is_finite() {
        return Ok(());
    }
    let body = model.integrated.iter().find(|&&i| {
        let (kinetic, gravity) = crate::dynamics::body_energy(model, state, i);
        !(kinetic.is_finite() && gravity.is_finite())
    });
    let culprit = match body {
        Some(&i) => format!(
            "body `{}` (its mass, velocity or position)",
            model.bodies[i].name
        ),
        None => match crate::dynamics::pair_with_infinite_energy(model, state) {
            Some(pair) => format!(
                "the overlap of contact pair `{}` (a body placed far inside another)",
                pair.name
            ),
            None => "a body's mass or position".to_string(),
        },
    };
    Err(SceneError::new(
        "",
        "",
        format!(
            "the state at t = 0 has no finite energy (kinetic {:e} J, gravitational {:e} J, contact {:e} J): \
             {culprit} is too large to compute with",
            energy.kinetic, energy.potential_gravity, energy.potential_contact
        ),
    ))
}
