//! What the user asks for: plain serde data, no physics.
//!
//! A scene is read from TOML text or from any serde value (the Python binding
//! passes a dict), optionally patched with `dotted.key=value` overrides, then
//! validated here, in one place. Every error names the field
//! ([`SceneError::path`]). All quantities are SI unless a field says otherwise;
//! the only non-SI input is a normal law declared with `units = "N-mm-s"`
//! (the paper's field units), converted once when the scene is assembled.

mod body;
mod contact;
mod fields;
mod joint;
mod load;
mod overrides;
pub mod provenance;
mod suggest;

pub use body::{BodySpec, DEFAULT_END_ENGAGEMENT, MotionKind, ShapeSpec, TubeSegmentSpec};
pub use contact::{
    ContactSpec, FeatureSpec, FieldUnits, FrictionLawSpec, LineLawSpec, NormalLawSpec, law_field,
    scale_from,
};
pub use fields::{FieldDoc, FieldInfo, Fields, LawRule, annotate, describe, flatten, numeric_keys};
pub use joint::JointSpec;
pub use load::LoadSpec;
pub use overrides::{apply_override, lookup};
pub use provenance::{FieldOrigin, Proposal, Provenance, Source};

use serde::{Deserialize, Serialize};

use crate::error::SceneError;

/// Which fixed-step integrator advances the state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorKind {
    /// Semi-implicit (symplectic) Euler: velocities first, then positions
    /// with the new velocities; quaternions by the exact exponential map.
    /// First order, one force evaluation per step.
    SymplecticEuler,
    /// Classical fourth-order Runge–Kutta; rotations by Runge–Kutta–Munthe-Kaas
    /// on the rotation vector, so quaternions stay on the manifold.
    /// Four force evaluations per step.
    #[default]
    Rk4,
    /// Linearly implicit (Rosenbrock–Euler) step, implicit in the
    /// velocity-dependent forces (contact damping, friction, joint dampers)
    /// through their analytic velocity Jacobian, explicit in the elastic and
    /// gyroscopic terms; positions and rotations as in symplectic Euler. One
    /// force evaluation and one sparse LU solve per step.
    LinearlyImplicitEuler,
    /// Two-stage singly diagonally implicit Runge–Kutta (Alexander's SDIRK2,
    /// γ = 1 − 1/√2): second order (formally, for smooth problems; on contact
    /// scenes the observed order can be lower and erratic, docs/accuracy.md),
    /// L-stable and stiffly accurate; implicit
    /// in every force (elastic, damping, friction, joints), solved per stage
    /// by simplified Newton iterations on the velocity twists with the
    /// analytic Jacobian D + γh·K ([`NewtonSpec`]), its LU factorization
    /// reused across iterations, stages and steps while Newton converges fast.
    Sdirk2,
    /// Kennedy–Carpenter ESDIRK3(2)4L[2]SA (NASA/TM-2016-219173): four
    /// stages, the first explicit, γ = 0.4358665; third order, L-stable,
    /// stiffly accurate, stage order 2, with an embedded second-order
    /// estimate. The implicit stages are solved as SDIRK2's (same Newton
    /// iterations, Jacobian and linear solver); rotations by
    /// Runge–Kutta–Munthe-Kaas. Adaptive steps when `simulation.rtol` is
    /// positive (the drill pipe's default, rtol = 1e-4), else fixed steps of
    /// `simulation.dt`. Not among [`IntegratorKind::ALL`], the fixed-step
    /// ladders of the studies; `ballcage accuracy` runs it as its second
    /// method.
    Esdirk32,
    /// TR-BDF2 (Bank et al. 1985) as the ESDIRK2(3) of Hosea & Shampine
    /// (Appl. Numer. Math. 20, 1996): three stages, the first explicit, γ =
    /// 1 − 1/√2 (SDIRK2's); a trapezoidal stage to t + 2γh, then BDF2 to
    /// t + h. Second order, L-stable, stiffly accurate, stage order 2, with
    /// an embedded third-order solution that estimates the error of the
    /// second-order one the step goes on with. Adaptive or fixed steps as
    /// [`IntegratorKind::Esdirk32`], whose stages and controller it shares;
    /// two implicit stages per step at γh = 0.29·h against ESDIRK3(2)'s
    /// three at 0.44·h, so where Newton's convergence limits γh it takes
    /// steps 1.5 times longer with two thirds of the stages
    /// (docs/performance.md). Not among [`IntegratorKind::ALL`].
    Trbdf2,
}

impl IntegratorKind {
    /// The name used in scene files and output metadata.
    pub fn name(self) -> &'static str {
        match self {
            Self::SymplecticEuler => "symplectic-euler",
            Self::Rk4 => "rk4",
            Self::LinearlyImplicitEuler => "linearly-implicit-euler",
            Self::Sdirk2 => "sdirk2",
            Self::Esdirk32 => "esdirk32",
            Self::Trbdf2 => "trbdf2",
        }
    }

    /// Every established integrator, in the order of the docs: the ones the
    /// studies (`ballcage accuracy`, `stability`) run at fixed steps by
    /// default. [`IntegratorKind::Esdirk32`], whose point is its adaptive
    /// steps, is left out of the ladders.
    pub const ALL: [Self; 4] = [
        Self::SymplecticEuler,
        Self::Rk4,
        Self::LinearlyImplicitEuler,
        Self::Sdirk2,
    ];

    /// Every integrator: [`IntegratorKind::ALL`] and the two adaptive pairs.
    pub const EVERY: [Self; 6] = [
        Self::SymplecticEuler,
        Self::Rk4,
        Self::LinearlyImplicitEuler,
        Self::Sdirk2,
        Self::Esdirk32,
        Self::Trbdf2,
    ];

    /// The implicit stages a step solves by Newton iterations to
    /// `simulation.newton.tolerance` (`None`: no Newton iterations). The
    /// pairs' counts are their tableaus' (a test in `integrate/esdirk.rs`).
    pub fn newton_stages(self) -> Option<u32> {
        match self {
            Self::Sdirk2 | Self::Trbdf2 => Some(2),
            Self::Esdirk32 => Some(3),
            Self::SymplecticEuler | Self::Rk4 | Self::LinearlyImplicitEuler => None,
        }
    }

    /// Whether the step solves a linear system (the implicit integrators);
    /// an explicit integrator's step must resolve the stiffest contact.
    pub fn is_implicit(self) -> bool {
        matches!(
            self,
            Self::LinearlyImplicitEuler | Self::Sdirk2 | Self::Esdirk32 | Self::Trbdf2
        )
    }

    /// Formal order of accuracy of the global error in the step, for smooth
    /// problems. Penalty contacts that begin and release during a run are not
    /// smooth: there the observed order can be lower and erratic
    /// (docs/accuracy.md, "What a run's accuracy is today").
    pub fn order(self) -> u32 {
        match self {
            Self::SymplecticEuler | Self::LinearlyImplicitEuler => 1,
            Self::Sdirk2 | Self::Trbdf2 => 2,
            Self::Esdirk32 => 3,
            Self::Rk4 => 4,
        }
    }

    /// One line on what the integrator is.
    pub fn description(self) -> &'static str {
        match self {
            Self::SymplecticEuler => "semi-implicit (symplectic) Euler: explicit, first order",
            Self::Rk4 => "classical Runge-Kutta with Munthe-Kaas rotations: explicit, fourth order",
            Self::LinearlyImplicitEuler => {
                "Rosenbrock-Euler, implicit in the velocity-dependent forces: first order"
            }
            Self::Sdirk2 => {
                "two-stage L-stable SDIRK with Newton iterations, implicit in every force: second order"
            }
            Self::Esdirk32 => {
                "four-stage L-stable ESDIRK3(2) with an embedded error estimate, fixed or adaptive \
                 steps: third order"
            }
            Self::Trbdf2 => {
                "three-stage L-stable TR-BDF2 with an embedded third-order estimate, fixed or \
                 adaptive steps: second order"
            }
        }
    }
}

/// `interval / step` when it is a whole number ≥ 1 to within 1e-6 relative,
/// else `None`: the one test of "a whole multiple of the step".
pub fn whole_multiple(interval: f64, step: f64) -> Option<u64> {
    let ratio = interval / step;
    if !ratio.is_finite() || ratio.round() < 1.0 {
        return None;
    }
    ((ratio - ratio.round()).abs() <= 1e-6 * ratio.max(1.0)).then(|| ratio.round() as u64)
}

/// Newton iterations of the `sdirk2` integrator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NewtonSpec {
    /// Convergence tolerance on the velocity-twist increments, relative to
    /// |v| + 1 m/s (rad/s for rotations) [–]: a stage has converged when the
    /// estimated remaining error θ/(1 − θ)·‖Δ‖ of the contracting iteration
    /// is below it (θ the contraction rate). The error left in each step's
    /// velocities acts like a force error of about m·tolerance/h, so it must
    /// stay well below the step's own error. Default 1e-5: on the paper
    /// scene every quantity of `ballcage accuracy` is the same to three
    /// digits at 1e-8, 1e-6 and 1e-5, with 2.9 Newton iterations per stage
    /// instead of 5.6 (docs/performance.md).
    pub tolerance: f64,
    /// Iterations allowed per stage; a stage that has not converged by then
    /// fails the step with a divergence error. Default 20.
    pub max_iterations: u32,
    /// Keep the factorized Jacobian from step to step while Newton converges
    /// within `reuse_iterations` iterations per stage; re-evaluate it
    /// otherwise (and at once, at the current iterate, when the contraction
    /// rate exceeds 0.3). `false` refreshes it at the start of every step.
    /// Default true.
    pub reuse_jacobian: bool,
    /// See `reuse_jacobian`. Default 3.
    pub reuse_iterations: u32,
    /// When a step's Newton iterations still fail after halving it four
    /// times, take that h/16 part step with the linearly implicit Euler step
    /// (first order, one linear solve) and go on, instead of stopping the
    /// run. The run's metadata counts such steps (`ballcage.fallback_steps`).
    /// Default true: the friction of the light ball keys leaves SDIRK2's
    /// Newton without a solution it can reach in a few steps of a paper run
    /// (docs/accuracy.md).
    pub fallback: bool,
    /// The linear solver of both implicit integrators' steps. Default
    /// `"block-elimination"`.
    pub linear_solver: LinearSolver,
}

/// How the implicit steps solve their linear systems.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LinearSolver {
    /// Block elimination along the graph of bodies and declared pairs
    /// (minimum-degree order, dense 6 × 6 blocks, pivoting within each
    /// body's block): each hinge's balls and cage are condensed onto its
    /// links, and the links are solved as a banded system. No allocation
    /// per step.
    #[default]
    BlockElimination,
    /// General sparse LU with partial pivoting (faer, COLAMD ordering),
    /// for comparison and for matrices whose body blocks cannot serve as
    /// pivots.
    SparseLu,
}

impl NewtonSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number(
            "tolerance",
            "-",
            "convergence tolerance on the velocity-twist increments, relative to |v| + 1 m/s",
        ),
        FieldDoc::number("max_iterations", "-", "Newton iterations allowed per stage"),
        FieldDoc::text(
            "reuse_jacobian",
            "keep the factorized Jacobian from step to step while Newton converges fast",
        ),
        FieldDoc::number(
            "reuse_iterations",
            "-",
            "iterations per stage within which the Jacobian is kept",
        ),
        FieldDoc::text(
            "fallback",
            "take a failing h/16 part step with the linearly implicit Euler step instead of stopping",
        ),
        FieldDoc::text("linear_solver", "the implicit steps' linear solver"),
    ];
}

impl Default for NewtonSpec {
    fn default() -> Self {
        Self {
            tolerance: 1e-5,
            max_iterations: 20,
            reuse_jacobian: true,
            reuse_iterations: 3,
            fallback: true,
            linear_solver: LinearSolver::default(),
        }
    }
}

/// When a run is stopped as diverged (besides a non-finite state).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DivergenceSpec {
    /// Largest allowed penetration as a fraction of the pair's smallest
    /// contacting radius (ball, cylinder or groove radius, smallest cuboid
    /// half-extent) [–]. PROPOSAL: 0.25; the paper's most loaded ball key
    /// reaches about 0.05.
    pub penetration_fraction: f64,
    /// Largest allowed penetration [m], replacing `penetration_fraction` for
    /// every pair when set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_penetration: Option<f64>,
    /// Largest allowed energy created by the integrator: the run stops when
    /// E(t) − E(0) − W_in(t) (mechanical energy gained beyond the work of the
    /// drives and applied torques) exceeds this fraction of the energy scale
    /// KE(0) + E_contact(0) + max|ΔPE_gravity| + ∫|P_in| dt (the most the
    /// system could hold), checked at every recorded frame [–]. PROPOSAL:
    /// 1.0 — the integrator has made as much energy again as the system
    /// holds or was given; a diverging run passes that within a few steps,
    /// while a stable explicit run near its step limit (symplectic Euler's
    /// energy swings by up to 1/(1 − (hω/2)²)) does not.
    pub energy_growth: f64,
}

impl DivergenceSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number(
            "penetration_fraction",
            "-",
            "largest allowed penetration, as a fraction of the pair's smallest contacting radius",
        ),
        FieldDoc::number(
            "max_penetration",
            "m",
            "largest allowed penetration, for every pair (replaces penetration_fraction)",
        ),
        FieldDoc::number(
            "energy_growth",
            "-",
            "largest energy the integrator may create, as a fraction of the system's energy scale",
        ),
    ];
}

impl Default for DivergenceSpec {
    fn default() -> Self {
        Self {
            penetration_fraction: 0.25,
            max_penetration: None,
            energy_growth: 1.0,
        }
    }
}

/// Time stepping.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    /// Simulated duration [s].
    pub duration: f64,
    /// Fixed integrator step [s] (with adaptive steps, see `rtol`, unused).
    pub dt: f64,
    /// Interval between recorded frames [s]; an integer multiple of the
    /// step ([`SimulationSpec::step`]).
    pub output_interval: f64,
    /// Integrator.
    #[serde(default)]
    pub integrator: IntegratorKind,
    /// Newton iterations of the `sdirk2` integrator.
    #[serde(default)]
    pub newton: NewtonSpec,
    /// Divergence detection.
    #[serde(default)]
    pub divergence: DivergenceSpec,
    /// Threads that evaluate the contact pairs of one force evaluation in
    /// parallel [–]. Each pair's points, laws and Jacobian blocks are
    /// computed on their own and summed in the pairs' order, so results are
    /// bitwise identical for any count. Default 1; 0 takes one per core.
    #[serde(default = "one_thread")]
    pub threads: u32,
    /// Most integrator steps a run may take [–]: a scene whose duration / dt
    /// exceeds it is refused before it starts, with the count (a 1 ns step,
    /// a typo in the duration). Raise it to run longer. Default 1e8.
    #[serde(default = "default_max_steps")]
    pub max_steps: u64,
    /// Relative tolerance of the adaptive steps of `esdirk32` and `trbdf2`
    /// [–]. Absent or
    /// 0: fixed steps of `dt` (every integrator). Positive: each step's
    /// embedded error estimate e is held to ‖e / (atol + rtol·|y|)‖_rms ≤ 1
    /// over the integrated bodies' positions [m], rotations [rad],
    /// velocities [m/s] and angular velocities [rad/s], |y| the larger
    /// magnitude of the component at the step's two ends (1 rad for
    /// rotations); the steps are at most `max_step` and do not stop at the
    /// recorded frames: a frame within a step is interpolated from the
    /// step's ends (cubic Hermite, third order). The stages'
    /// Newton iterations then stop at min(`newton.tolerance`, rtol/10).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rtol: Option<f64>,
    /// Largest adaptive step [s] (only with a positive `rtol`). Default: the
    /// output interval, so that every frame lies within one step of a solved
    /// state: the forces at an interpolated frame are not held to the
    /// dynamics as a step's end is, and on a stiff contact held still they
    /// drift with the step (a chain held at the wall of a 1e9 N/mm^2.2 tube:
    /// its wall force 3.7 % low at steps of up to 50 ms between 10 ms
    /// frames, within 0.2 % at steps of at most 10 ms; tests/test_buckling.py).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_step: Option<f64>,
    /// Absolute tolerance of the adaptive steps [SI unit of each quantity]:
    /// one number, read as metres for positions, radians for rotations, m/s
    /// for velocities and rad/s for angular velocities, the default of the
    /// four per-quantity tolerances below. Default: `rtol` (errors of
    /// quantities near zero held to rtol·1 m, 1 rad, 1 m/s, 1 rad/s). Only
    /// with `rtol`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atol: Option<f64>,
    /// Absolute tolerance of the adaptive steps on positions [m]. Default:
    /// `atol`. Only with `rtol`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atol_position: Option<f64>,
    /// The same on rotations [rad]. Default: `atol`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atol_rotation: Option<f64>,
    /// The same on velocities [m/s]. Default: `atol`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atol_velocity: Option<f64>,
    /// The same on angular velocities [rad/s]. Default: `atol`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub atol_angular_velocity: Option<f64>,
}

impl SimulationSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::number("duration", "s", "simulated duration"),
        FieldDoc::number(
            "dt",
            "s",
            "fixed integrator step (unused with adaptive steps, rtol > 0)",
        ),
        FieldDoc::number(
            "output_interval",
            "s",
            "interval between recorded frames, a whole multiple of dt",
        ),
        FieldDoc::text(
            "integrator",
            "the integrator (esdirk32 and trbdf2 take adaptive steps when rtol is set)",
        ),
        FieldDoc::table(
            "newton",
            "Newton iterations of the implicit integrators",
            NewtonSpec::FIELDS,
        ),
        FieldDoc::table(
            "divergence",
            "when a run is stopped as diverged",
            DivergenceSpec::FIELDS,
        ),
        FieldDoc::number(
            "threads",
            "-",
            "threads that evaluate the contact pairs in parallel (0: one per core)",
        ),
        FieldDoc::number("max_steps", "-", "most integrator steps a run may take"),
        FieldDoc::optional(
            "rtol",
            "-",
            "relative tolerance of esdirk32's and trbdf2's adaptive steps (absent or 0: fixed \
             steps of dt)",
        ),
        FieldDoc::optional(
            "max_step",
            "s",
            "largest adaptive step (default: the output interval)",
        ),
        FieldDoc::optional(
            "atol",
            "m, rad, m/s, rad/s",
            "absolute tolerance of the adaptive steps, in the SI unit of each quantity \
             (positions, rotations, velocities, angular velocities); default rtol",
        ),
        FieldDoc::optional(
            "atol_position",
            "m",
            "absolute tolerance of the adaptive steps on positions (default: atol)",
        ),
        FieldDoc::optional(
            "atol_rotation",
            "rad",
            "absolute tolerance of the adaptive steps on rotations (default: atol)",
        ),
        FieldDoc::optional(
            "atol_velocity",
            "m/s",
            "absolute tolerance of the adaptive steps on velocities (default: atol)",
        ),
        FieldDoc::optional(
            "atol_angular_velocity",
            "rad/s",
            "absolute tolerance of the adaptive steps on angular velocities (default: atol)",
        ),
    ];
}

/// Most threads `simulation.threads` may ask for: each simulation starts
/// its own pool, and thousands of threads only thrash (found by fuzzing).
const MAX_THREADS: u32 = 256;

fn one_thread() -> u32 {
    1
}

/// `simulation.max_steps` unless a scene sets it: 1e8 steps, about a day of the paper's scene at 1 ms a step.
pub(crate) fn default_max_steps() -> u64 {
    100_000_000
}

impl SimulationSpec {
    /// Checks the stepping, Newton and divergence settings.
    fn validate(&self) -> Result<(), SceneError> {
        positive("simulation.duration", self.duration)?;
        positive("simulation.dt", self.dt)?;
        positive("simulation.output_interval", self.output_interval)?;
        if self.dt > self.duration {
            return Err(SceneError::new(
                "simulation.dt",
                self.dt,
                format!("step longer than the duration {} s", self.duration),
            ));
        }
        if self.threads > MAX_THREADS {
            return Err(SceneError::new(
                "simulation.threads",
                self.threads,
                format!("must be at most {MAX_THREADS} (0 takes one per core)"),
            ));
        }
        // The step (and so the step count) needs the tolerances checked first.
        self.validate_tolerances()?;
        let steps = (self.duration / self.step()).ceil();
        if self.max_steps == 0 {
            return Err(SceneError::new(
                "simulation.max_steps",
                0,
                "must be at least 1",
            ));
        }
        if steps > self.max_steps as f64 {
            return Err(SceneError::new(
                "simulation.dt",
                self.dt,
                format!(
                    "{steps:.3e} steps for simulation.duration = {} s, more than simulation.max_steps = {:.3e}; \
                     raise simulation.max_steps to run this long",
                    self.duration, self.max_steps as f64
                ),
            ));
        }
        if !self.adaptive() && whole_multiple(self.output_interval, self.dt).is_none() {
            return Err(SceneError::new(
                "simulation.output_interval",
                self.output_interval,
                format!(
                    "must be a whole multiple (≥ 1) of simulation.dt = {} s",
                    self.dt
                ),
            ));
        }
        positive("simulation.newton.tolerance", self.newton.tolerance)?;
        if self.newton.max_iterations == 0 {
            return Err(SceneError::new(
                "simulation.newton.max_iterations",
                0,
                "must be at least 1",
            ));
        }
        let d = &self.divergence;
        positive(
            "simulation.divergence.penetration_fraction",
            d.penetration_fraction,
        )?;
        if let Some(m) = d.max_penetration {
            positive("simulation.divergence.max_penetration", m)?;
        }
        positive("simulation.divergence.energy_growth", d.energy_growth)
    }
}

impl SimulationSpec {
    /// Whether the steps are adaptive: a positive `rtol`.
    pub fn adaptive(&self) -> bool {
        self.rtol.is_some_and(|r| r > 0.0)
    }

    /// The tolerances of the adaptive steps (`None`: fixed steps), each
    /// absolute tolerance resolved: its own field, else `atol`, else `rtol`.
    pub fn tolerance(&self) -> Option<Tolerance> {
        let rtol = self.rtol.filter(|_| self.adaptive())?;
        let atol = self.atol.unwrap_or(rtol);
        Some(Tolerance {
            rtol,
            position: self.atol_position.unwrap_or(atol),
            rotation: self.atol_rotation.unwrap_or(atol),
            velocity: self.atol_velocity.unwrap_or(atol),
            angular_velocity: self.atol_angular_velocity.unwrap_or(atol),
        })
    }

    /// The step the run advances by between the integrator's calls [s]:
    /// `dt`, or with adaptive steps the output interval, to which the
    /// integrator takes (or interpolates) its own steps.
    pub fn step(&self) -> f64 {
        if self.adaptive() {
            self.output_interval
        } else {
            self.dt
        }
    }

    /// Checks `rtol`, `atol` and `max_step`: `rtol` ≥ 0 (0: fixed steps),
    /// `atol` and `max_step` positive and only with a positive `rtol`, and
    /// adaptive steps only for the integrator that has an error estimate.
    fn validate_tolerances(&self) -> Result<(), SceneError> {
        let needs = |key: &str, value: f64| {
            SceneError::new(
                key,
                value,
                "needs a positive simulation.rtol (adaptive steps); without it the steps are fixed",
            )
        };
        for (key, value) in [
            ("simulation.atol", self.atol),
            ("simulation.atol_position", self.atol_position),
            ("simulation.atol_rotation", self.atol_rotation),
            ("simulation.atol_velocity", self.atol_velocity),
            (
                "simulation.atol_angular_velocity",
                self.atol_angular_velocity,
            ),
            ("simulation.max_step", self.max_step),
        ] {
            if let Some(v) = value {
                positive(key, v)?;
                if !self.adaptive() {
                    return Err(needs(key, v));
                }
            }
        }
        let Some(rtol) = self.rtol else {
            return Ok(());
        };
        if !(rtol.is_finite() && rtol >= 0.0) {
            return Err(SceneError::new(
                "simulation.rtol",
                rtol,
                "must be a finite number ≥ 0 (0: fixed steps of simulation.dt)",
            ));
        }
        let estimating = [IntegratorKind::Esdirk32, IntegratorKind::Trbdf2];
        if rtol > 0.0 && !estimating.contains(&self.integrator) {
            return Err(SceneError::new(
                "simulation.rtol",
                rtol,
                format!(
                    "adaptive steps need an error estimate: only simulation.integrator = \
                     \"esdirk32\" and \"trbdf2\" have one (it is \"{}\"); for fixed steps \
                     of simulation.dt set simulation.rtol = 0",
                    self.integrator.name()
                ),
            ));
        }
        Ok(())
    }
}

/// The tolerances of adaptive steps: relative, and absolute per quantity
/// ([`crate::scene::SimulationSpec::atol`] and its per-quantity fields).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// Relative tolerance [–].
    pub rtol: f64,
    /// Absolute tolerance on positions [m].
    pub position: f64,
    /// Absolute tolerance on rotations [rad].
    pub rotation: f64,
    /// Absolute tolerance on velocities [m/s].
    pub velocity: f64,
    /// Absolute tolerance on angular velocities [rad/s].
    pub angular_velocity: f64,
}

/// Global fields.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// Gravitational acceleration [m/s²], world frame.
    #[serde(default)]
    pub gravity: [f64; 3],
}

impl WorldSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[FieldDoc::number(
        "gravity",
        "m/s²",
        "gravitational acceleration, world frame",
    )];
}

impl Default for WorldSpec {
    fn default() -> Self {
        Self { gravity: [0.0; 3] }
    }
}

/// The engine's output tables a scene can ask for (a scene kind built on
/// top of the engine may add its own through the recorder's observers).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TableKind {
    /// Body poses and velocities, one row per recorded body per frame.
    Bodies,
    /// Contact points in contact, one row per point per frame.
    Contacts,
    /// Energy balance per frame.
    Energy,
    /// Per-pair peak, mean and RMS of normal and tangential force over `record.summary_window`.
    Summary,
}

impl TableKind {
    /// Table name, also the Parquet file stem.
    pub fn name(self) -> &'static str {
        match self {
            Self::Bodies => "bodies",
            Self::Contacts => "contacts",
            Self::Energy => "energy",
            Self::Summary => "summary",
        }
    }

    /// Every engine table.
    pub const ALL: [TableKind; 4] = [Self::Bodies, Self::Contacts, Self::Energy, Self::Summary];
}

/// A table a scene can list in `record.tables`: the engine's
/// ([`TableKind`]), or a set that a scene kind built on the engine extends.
pub trait TableChoice: Copy + PartialEq + std::fmt::Debug {
    /// The tables recorded when `record.tables` is left out.
    fn defaults() -> Vec<Self>;
    /// The table's name, also the Parquet file stem.
    fn table_name(self) -> &'static str;
}

impl TableChoice for TableKind {
    fn defaults() -> Vec<Self> {
        vec![TableKind::Bodies, TableKind::Contacts]
    }

    fn table_name(self) -> &'static str {
        self.name()
    }
}

/// What to record. Nothing else is computed for output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordSpec<T: TableChoice = TableKind> {
    /// Tables to produce.
    #[serde(default = "T::defaults")]
    pub tables: Vec<T>,
    /// Bodies recorded in `bodies`; empty means every non-fixed body.
    #[serde(default)]
    pub bodies: Vec<String>,
    /// Contact pairs recorded in `contacts`; empty means every pair.
    #[serde(default)]
    pub contacts: Vec<String>,
    /// Time window `[start, end]` of the `summary` table [s]; empty means the whole run.
    #[serde(default)]
    pub summary_window: Vec<f64>,
    /// Most memory the recorded tables may take [B]: before a run starts,
    /// frames × rows × columns of every recorded table is estimated (an
    /// upper bound: every contact point slot of every recorded pair in every
    /// frame), and a scene over it is refused with the estimate. Default 4e9
    /// (4 GB).
    #[serde(default = "default_max_bytes")]
    pub max_bytes: u64,
}

/// `record.max_bytes` unless a scene sets it: 4 GB, a sixth of a 24 GiB machine.
pub(crate) fn default_max_bytes() -> u64 {
    4_000_000_000
}

impl<T: TableChoice> RecordSpec<T> {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::text("tables", "tables to produce"),
        FieldDoc::text(
            "bodies",
            "bodies recorded in the bodies table; empty: every non-fixed body",
        ),
        FieldDoc::text(
            "contacts",
            "contact pairs recorded in the contacts table; empty: every pair",
        ),
        FieldDoc::number(
            "summary_window",
            "s",
            "time window [start, end] of the summary table; empty: the whole run",
        ),
        FieldDoc::number("max_bytes", "B", "most memory the recorded tables may take"),
    ];

    /// Checks the table list and the summary window against the run's
    /// `duration` [s] (not the names, which need the scene: [`Scene::validate`]).
    pub fn validate_tables(&self, duration: f64) -> Result<(), SceneError> {
        for (i, t) in self.tables.iter().enumerate() {
            if self.tables[..i].contains(t) {
                return Err(SceneError::new(
                    format!("record.tables[{i}]"),
                    t.table_name(),
                    "listed twice",
                ));
            }
        }
        if self.max_bytes == 0 {
            return Err(SceneError::new("record.max_bytes", 0, "must be at least 1"));
        }
        validate_window("record.summary_window", &self.summary_window, duration)
    }
}

impl RecordSpec {
    /// Checks the tables, the summary window and the recorded names.
    fn validate(&self, scene: &Scene) -> Result<(), SceneError> {
        self.validate_tables(scene.simulation.duration)?;
        for (i, n) in self.bodies.iter().enumerate() {
            scene.body_id(&format!("record.bodies[{i}]"), n)?;
        }
        let names = scene.pair_names();
        for (i, n) in self.contacts.iter().enumerate() {
            if !names.contains(n) {
                return Err(SceneError::new(
                    format!("record.contacts[{i}]"),
                    n,
                    "no contact pair of that name",
                ));
            }
        }
        Ok(())
    }
}

/// Checks a time window `[start, end]` [s]; empty means the whole run.
fn validate_window(path: &str, w: &[f64], duration: f64) -> Result<(), SceneError> {
    if w.is_empty() {
        return Ok(());
    }
    if w.len() != 2 {
        return Err(SceneError::new(
            path,
            format!("{w:?}"),
            "give [start, end] in seconds",
        ));
    }
    non_negative(&format!("{path}[0]"), w[0])?;
    finite(&format!("{path}[1]"), w[1])?;
    if w[1] <= w[0] {
        return Err(SceneError::new(
            format!("{path}[1]"),
            w[1],
            format!("must exceed the start {} s", w[0]),
        ));
    }
    // the run's last frame is at `duration`; allow its rounding
    if w[1] > duration * (1.0 + 1e-9) {
        return Err(SceneError::new(
            format!("{path}[1]"),
            w[1],
            format!(
                "must not exceed simulation.duration = {duration} s (the window would reach past the run)"
            ),
        ));
    }
    Ok(())
}

impl<T: TableChoice> Default for RecordSpec<T> {
    fn default() -> Self {
        Self {
            tables: T::defaults(),
            bodies: vec![],
            contacts: vec![],
            summary_window: vec![],
            max_bytes: default_max_bytes(),
        }
    }
}

/// A complete scene: bodies, contacts, loads, time stepping and recording.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Free-form scene name, copied into the output metadata.
    #[serde(default)]
    pub name: String,
    /// Time stepping.
    pub simulation: SimulationSpec,
    /// Gravity.
    #[serde(default)]
    pub world: WorldSpec,
    /// What to record.
    #[serde(default)]
    pub record: RecordSpec,
    /// Bodies, in order; the order fixes body ids.
    pub bodies: Vec<BodySpec>,
    /// Declared contact pairs; no other pair is ever tested.
    #[serde(default)]
    pub contacts: Vec<ContactSpec>,
    /// Applied loads.
    #[serde(default)]
    pub loads: Vec<LoadSpec>,
    /// Penalty joints.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joints: Vec<JointSpec>,
}

impl Scene {
    /// The unit and meaning of every field of a generic scene document.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::text(
            "name",
            "free-form scene name, copied into the output metadata",
        ),
        FieldDoc::table("simulation", "time stepping", SimulationSpec::FIELDS),
        FieldDoc::table("world", "gravity", WorldSpec::FIELDS),
        FieldDoc::table("record", "what to record", RecordSpec::<TableKind>::FIELDS),
        FieldDoc::tables(
            "bodies",
            "bodies, in order; the order fixes body ids",
            BodySpec::FIELDS,
        ),
        FieldDoc::tables(
            "contacts",
            "declared contact pairs; no other pair is ever tested",
            ContactSpec::FIELDS,
        ),
        FieldDoc::tables("loads", "applied loads", LoadSpec::FIELDS),
        FieldDoc::tables("joints", "penalty joints", JointSpec::FIELDS),
    ];

    /// Parses a generic scene from TOML text, applies `dotted.key=value`
    /// overrides, and validates. Documents that may be of another kind (a
    /// `kind` key) are read by the loader, a layer above.
    pub fn from_toml_str(text: &str, overrides: &[String]) -> Result<Self, SceneError> {
        Self::from_table(parse_toml(text)?, overrides)
    }

    /// Builds a generic scene from a TOML table (any serde source converts to
    /// one), applies overrides, deserializes with field paths, and validates.
    pub fn from_table(table: toml::Table, overrides: &[String]) -> Result<Self, SceneError> {
        let mut root = toml::Value::Table(table);
        for o in overrides {
            apply_override(&mut root, o)?;
        }
        let scene: Scene = deserialize_with_path(root)?;
        scene.validate()?;
        Ok(scene)
    }

    /// The scene as TOML, with every default written out.
    pub fn to_toml(&self) -> String {
        to_toml_text(self)
    }

    /// Index of the body named `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Checks every value; the first problem of each independent section
    /// (each body, then the pairs, loads and joints once the bodies are
    /// valid) is returned with its path, the others in the error's `more`.
    pub fn validate(&self) -> Result<(), SceneError> {
        SceneError::all([
            self.simulation.validate(),
            finite_vec("world.gravity", &self.world.gravity),
            self.validate_parts()
                .and_then(|()| self.record.validate(self)),
        ])
    }

    /// Bodies, contacts, loads and joints.
    fn validate_parts(&self) -> Result<(), SceneError> {
        if self.bodies.is_empty() {
            return Err(SceneError::new(
                "bodies",
                "[]",
                "a scene needs at least one body",
            ));
        }
        SceneError::all(self.bodies.iter().enumerate().map(|(i, b)| {
            b.validate(&format!("bodies[{i}]"))?;
            if self.bodies[..i].iter().any(|o| o.name == b.name) {
                return Err(SceneError::new(
                    format!("bodies[{i}].name"),
                    &b.name,
                    "duplicate body name",
                ));
            }
            Ok(())
        }))?;
        for (i, c) in self.contacts.iter().enumerate() {
            c.validate(&format!("contacts[{i}]"), self)?;
        }
        let names = self.pair_names();
        for (i, n) in names.iter().enumerate() {
            if names[..i].contains(n) {
                return Err(SceneError::new(
                    format!("contacts[{i}].name"),
                    n,
                    "duplicate contact pair name",
                ));
            }
        }
        for (i, l) in self.loads.iter().enumerate() {
            l.validate(&format!("loads[{i}]"), self)?;
        }
        for (i, j) in self.joints.iter().enumerate() {
            j.validate(&format!("joints[{i}]"), self)?;
        }
        Ok(())
    }

    /// Names of the contact pairs, in order (pair ids).
    pub fn pair_names(&self) -> Vec<String> {
        self.contacts.iter().map(|c| c.pair_name()).collect()
    }

    /// Number of integrator steps per recorded frame.
    pub fn steps_per_output(&self) -> u64 {
        (self.simulation.output_interval / self.simulation.step()).round() as u64
    }

    /// Total number of integrator steps.
    pub fn total_steps(&self) -> u64 {
        let n = (self.simulation.duration / self.simulation.step()).round() as u64;
        n.max(1)
    }
}

/// Writes `over` onto `base`: tables merge key by key, anything else
/// replaces. A table whose tag (`law` or `type`) differs replaces whole, so a
/// different law does not inherit the old law's parameters.
pub(crate) fn merge(base: &mut toml::Value, over: toml::Value) {
    match (base, over) {
        (toml::Value::Table(b), toml::Value::Table(o)) => {
            let retagged = ["law", "type"]
                .iter()
                .any(|tag| matches!((b.get(*tag), o.get(*tag)), (Some(x), Some(y)) if x != y));
            if retagged {
                *b = o;
                return;
            }
            for (k, v) in o {
                match b.get_mut(&k) {
                    Some(slot) => merge(slot, v),
                    None => {
                        b.insert(k, v);
                    }
                }
            }
        }
        (b, o) => *b = o,
    }
}

/// Most errors one deserialization reports (`deserialize_with_path`).
const MAX_ERRORS: usize = 20;

/// Deserializes with the path of the offending field in the error.
///
/// After an unknown key or a value of the wrong type, the key is taken out
/// and the document read again, so one error lists every such problem (up
/// to `MAX_ERRORS`): the first in the error, the others in `more`.
pub(crate) fn deserialize_with_path<T: serde::de::DeserializeOwned>(
    root: toml::Value,
) -> Result<T, SceneError> {
    let mut value = root;
    let mut errors: Vec<SceneError> = Vec::new();
    let mut removed: Vec<String> = Vec::new();
    loop {
        let error = match serde_path_to_error::deserialize::<_, T>(value.clone()) {
            Ok(parsed) if errors.is_empty() => return Ok(parsed),
            Ok(_) => break,
            Err(e) => path_error(e),
        };
        if removed.contains(&error.path) {
            break; // a key taken out after an error of its own is missing now: not another error
        }
        let retry = errors.len() + 1 < MAX_ERRORS
            && !error.reason.starts_with("missing field")
            && remove_key(&mut value, &error.path);
        removed.push(error.path.clone());
        errors.push(error);
        if !retry {
            break;
        }
    }
    Err(SceneError::combine(errors).unwrap_or_else(|| SceneError::new("", "", "invalid scene")))
}

/// A serde error with the dotted path of the offending field.
fn path_error(e: serde_path_to_error::Error<toml::de::Error>) -> SceneError {
    let mut path = e.path().to_string();
    if path == "." {
        path.clear();
    }
    let reason = suggest::with_suggestion(plain_types(&first_line(&e.into_inner().to_string())));
    // serde reports a missing field at its parent: name the field itself.
    if let Some(field) = reason
        .strip_prefix("missing field `")
        .and_then(|r| r.split('`').next())
    {
        path = if path.is_empty() {
            field.to_string()
        } else {
            format!("{path}.{field}")
        };
    }
    SceneError::new(path, "", reason)
}

/// Takes the table key at the dotted `path` (`a.b[2].c`) out of `root`;
/// `false` when the path does not end in a key of a table (an array item is
/// never removed: the items after it would change their indices).
fn remove_key(root: &mut toml::Value, path: &str) -> bool {
    let mut parts: Vec<&str> = path.split('.').collect();
    let Some(last) = parts.pop() else {
        return false;
    };
    if last.is_empty() || last.contains('[') {
        return false;
    }
    let mut node = root;
    for part in parts {
        let (key, indices) = part
            .split_once('[')
            .map_or((part, ""), |(k, rest)| (k, rest));
        let Some(next) = node.get_mut(key) else {
            return false;
        };
        node = next;
        for index in indices.split('[').filter(|s| !s.is_empty()) {
            let Some(i) = index.trim_end_matches(']').parse::<usize>().ok() else {
                return false;
            };
            let Some(next) = node.get_mut(i) else {
                return false;
            };
            node = next;
        }
    }
    node.as_table_mut()
        .is_some_and(|table| table.remove(last).is_some())
}

/// Parses TOML text into a table. A syntax error names no field (`path`
/// is empty) and says where it is: "TOML syntax error at line 2, column 7:
/// <reason>" (both counted from 1, the column in characters).
pub(crate) fn parse_toml(text: &str) -> Result<toml::Table, SceneError> {
    text.parse().map_err(|e: toml::de::Error| {
        let reason = first_line(e.message());
        SceneError::new(
            "",
            "",
            format!("TOML syntax error{}: {reason}", toml_error_place(&e, text)),
        )
    })
}

/// Serializes a spec as TOML with every default written out.
pub(crate) fn to_toml_text<T: Serialize>(spec: &T) -> String {
    // Serializing plain data with finite numbers cannot fail.
    toml::to_string_pretty(spec).unwrap_or_else(|e| format!("# scene could not be written: {e}\n"))
}

/// serde's Rust type names in a message, in words a scene author knows.
fn plain_types(reason: &str) -> String {
    [
        ("f64", "a number"),
        ("u32", "a whole number ≥ 0"),
        ("u64", "a whole number ≥ 0"),
        ("usize", "a whole number ≥ 0"),
        ("a boolean", "true or false"),
    ]
    .iter()
    .fold(reason.to_string(), |r, (rust, plain)| {
        r.replace(&format!("expected {rust}"), &format!("expected {plain}"))
    })
}

fn first_line(s: &str) -> String {
    s.lines().next().unwrap_or("").trim().to_string()
}

/// " at line L, column C" of a syntax error (1-based; the column counts
/// characters), or nothing when the parser gives no position.
fn toml_error_place(e: &toml::de::Error, text: &str) -> String {
    let Some(span) = e.span() else {
        return String::new();
    };
    let mut start = span.start.min(text.len());
    while !text.is_char_boundary(start) {
        start -= 1;
    }
    let before = &text[..start];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let column = before[line_start..].chars().count() + 1;
    format!(" at line {line}, column {column}")
}

/// Rejects non-finite and non-positive values.
pub(crate) fn positive(path: &str, v: f64) -> Result<(), SceneError> {
    if !v.is_finite() {
        return Err(SceneError::new(path, v, "must be a finite number"));
    }
    if v <= 0.0 {
        return Err(SceneError::new(path, v, "must be positive"));
    }
    Ok(())
}

/// Rejects non-finite and negative values.
pub(crate) fn non_negative(path: &str, v: f64) -> Result<(), SceneError> {
    if !v.is_finite() {
        return Err(SceneError::new(path, v, "must be a finite number"));
    }
    if v < 0.0 {
        return Err(SceneError::new(path, v, "must not be negative"));
    }
    Ok(())
}

/// Rejects non-finite values.
pub(crate) fn finite(path: &str, v: f64) -> Result<(), SceneError> {
    if !v.is_finite() {
        return Err(SceneError::new(path, v, "must be a finite number"));
    }
    Ok(())
}

/// Rejects vectors with a non-finite component.
pub(crate) fn finite_vec(path: &str, v: &[f64]) -> Result<(), SceneError> {
    for (i, x) in v.iter().enumerate() {
        finite(&format!("{path}[{i}]"), *x)?;
    }
    Ok(())
}

/// Rejects vectors that are not finite or have (near) zero length.
pub(crate) fn direction(path: &str, v: &[f64; 3]) -> Result<(), SceneError> {
    finite_vec(path, v)?;
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n < 1e-12 {
        return Err(SceneError::new(
            path,
            format!("{v:?}"),
            "must be a non-zero direction",
        ));
    }
    Ok(())
}
