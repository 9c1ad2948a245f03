//! The implicit integrators: linearly implicit Euler, SDIRK2 and (in
//! [`esdirk`], on SDIRK2's Newton iterations) ESDIRK3(2), all on the
//! rotation manifold, sharing one sparse matrix pattern and factorization.
//!
//! # Linearly implicit Euler
//! The unknowns are the twist increments of the integrated bodies in the
//! world frame: a dynamic body has Δv (3) and Δω (3), a `spin` body the one
//! spin-rate increment about its axis, a `spin-slide` body that and the
//! speed increment along the axis. Per body a basis B maps them to a world
//! twist [v; ω] (B = I₆, B = [0; axis] or [axis, 0; 0, axis]); fixed and kinematic bodies
//! carry no unknowns (their velocities are prescribed). One step of `h`:
//!
//! 1. one force evaluation at (x_n, v_n) giving the wrenches f (gravity,
//!    torques, joints, contacts; the gyroscopic term ω × I_w ω is subtracted
//!    explicitly) and D = ∂f/∂twist, the analytic velocity Jacobian of the
//!    joint and contact forces at fixed geometry
//!    ([`Dynamics::forces_and_jacobian`]);
//! 2. the sparse linear solve Bᵀ(M − h·D)B · Δq̇ = h·Bᵀf, M the block-diagonal
//!    mass (m·I, I_w = R·I_b·Rᵀ);
//! 3. v_{n+1} = v_n + Δv, ω_{n+1} = ω_n + Δω (stored back in the body frame),
//!    x_{n+1} = x_n + h·v_{n+1}, R_{n+1} = R_n·Exp(h·ω_body,n+1) as in
//!    symplectic Euler; then the prescribed bodies are set at t + h.
//!
//! With D = 0 this is exactly symplectic Euler. Contact damping and friction
//! (the stiff, overdamped modes, docs/model.md §5) are integrated with the
//! L-stable backward-Euler amplification; the elastic and gyroscopic terms
//! stay explicit.
//!
//! # SDIRK2
//! Alexander's two-stage, L-stable, stiffly accurate SDIRK (γ = 1 − 1/√2,
//! a₁₁ = γ, a₂₁ = 1 − γ, a₂₂ = γ, c = (γ, 1)) applied to x' = v, M v' = f.
//! The unknowns of stage i are its twists V_i (world frame, as above); the
//! stage poses follow from them, x_i = x_n + h·Σ_j a_ij·v_j and
//! R_i = Exp(h·Σ_j a_ij·ω_j)·R_n (second order on the manifold without a
//! dexp correction). Each stage solves
//!
//! r(V_i) = M(x_i)·(V_i − v_n − h·Σ_{j<i} a_ij·A_j) − h·γ·(f − ω×I_wω)(x_i, V_i) = 0
//!
//! by simplified Newton iterations with the matrix Bᵀ(M − γh·(D + γh·K))B,
//! D + γh·K from [`Dynamics::forces_and_jacobian`] with stiffness scale γh
//! (every force implicit: elastic, damping, friction, joints). ‖Δ‖ is the
//! largest increment relative to |V| + 1 (m/s or rad/s) and θ = ‖Δ_k‖/‖Δ_{k−1}‖
//! the contraction rate. A stage has converged when θ < 1 and
//! θ/(1 − θ)·‖Δ‖ ≤ `newton.tolerance` (the estimated distance to the
//! solution), or at once when ‖Δ‖ ≤ tolerance/100. The converged stage
//! gives A_1 = (V_1 − v_n)/(γh); the step ends at stage 2 (stiffly
//! accurate). The factorization is kept across iterations, stages and
//! steps: it is re-evaluated at the current iterate when the contraction
//! is slow (θ > 0.3), and at the next step when a stage took more than
//! `newton.reuse_iterations`. An increment that makes the residual (in
//! velocity units, relative to |v_n| + 1) grow — Newton overshooting across a
//! contact onset or release — is halved, up to 8 times, each halving an
//! iteration with a fresh Jacobian. A stage that has not converged within
//! `newton.max_iterations` fails the step, which is then retried as two
//! half steps, down to a sixteenth (many contacts switching within one
//! step); the run fails only when that does not converge either.
//!
//! # Linear algebra
//! The sparsity pattern of Bᵀ(M − h·D)B is fixed by the model: a diagonal
//! block per integrated body and a pair of off-diagonal blocks per declared
//! contact pair or joint between two integrated bodies. It is analysed
//! once, at the first step; each step only refills the values and factors
//! numerically (the matrix is not symmetric once friction acts). The solver
//! is `simulation.newton.linear_solver`: block elimination along the
//! bodies' graph ([`super::blocklu`], the default) or a general sparse LU
//! with pivoting ([`super::sparselu`]).

use crate::dynamics::{Dynamics, Mat6, Mode, VelocityJacobian};
use crate::math::{Mat3, Vec3, exp_map};
use crate::model::{Model, Motion, State};
use crate::scene::LinearSolver;

use super::blocklu::BlockLu;
use super::sparselu::SparseLu;

#[path = "esdirk.rs"]
mod esdirk;

pub use esdirk::ErrorStats;
pub(crate) use esdirk::MIN_STEP_FRACTION;

/// Which diagonally implicit scheme the Newton iterations solve the stages
/// of: they share the iterations, the Newton matrix and the linear solver,
/// and differ in γ and in what each stage already knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Scheme {
    /// Alexander's SDIRK2 (this module).
    Sdirk2,
    /// Kennedy–Carpenter ESDIRK3(2)4L[2]SA ([`esdirk`]).
    Esdirk32,
    /// TR-BDF2 as Hosea and Shampine's ESDIRK2(3) ([`esdirk`]).
    Trbdf2,
}

impl Scheme {
    /// γ, the diagonal of the Butcher matrix.
    fn gamma(self) -> f64 {
        match self {
            Self::Sdirk2 => GAMMA,
            Self::Esdirk32 | Self::Trbdf2 => self.tableau().expect("an ESDIRK pair").gamma,
        }
    }

    /// The tableau of an ESDIRK pair (`None`: SDIRK2).
    fn tableau(self) -> Option<&'static esdirk::Tableau> {
        match self {
            Self::Sdirk2 => None,
            Self::Esdirk32 => Some(&esdirk::ESDIRK32),
            Self::Trbdf2 => Some(&esdirk::TRBDF2),
        }
    }

    /// The tolerance of the stages' Newton iterations:
    /// `simulation.newton.tolerance`, and with adaptive steps at most a
    /// tenth of `simulation.rtol` (the iterations' error well below the
    /// step's).
    fn newton_tolerance(self, model: &Model) -> f64 {
        match (self, model.tolerance) {
            (Self::Esdirk32 | Self::Trbdf2, Some(tol)) => {
                model.newton.tolerance.min(0.1 * tol.rtol)
            }
            _ => model.newton.tolerance,
        }
    }

    /// The name in error messages.
    fn name(self) -> &'static str {
        match self {
            Self::Sdirk2 => "SDIRK2",
            Self::Esdirk32 | Self::Trbdf2 => self.tableau().expect("an ESDIRK pair").name,
        }
    }
}

/// Why the Newton iterations of an implicit stage (`stage`, counted from 0)
/// failed. Formatted only when a failure is reported: an adaptive step that
/// fails and is retried smaller must not allocate.
#[derive(Debug, Clone, Copy)]
pub(crate) enum StageFailure {
    /// Not within `max` iterations; the last increment, relative.
    NotConverged {
        scheme: Scheme,
        stage: usize,
        max: u32,
        last: f64,
        tolerance: f64,
    },
    /// Diverging, or too slow to converge within `max` iterations, at this
    /// contraction rate on a fresh Jacobian (adaptive steps).
    TooSlow {
        scheme: Scheme,
        stage: usize,
        theta: f64,
        norm: f64,
        max: u32,
    },
    /// A singular Newton matrix.
    Singular { scheme: Scheme, stage: usize },
    /// A non-finite increment.
    NotFinite { scheme: Scheme, stage: usize },
}

impl std::fmt::Display for StageFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Self::NotConverged {
                scheme,
                stage,
                max,
                last,
                tolerance,
            } => write!(
                f,
                "Newton iterations of {} stage {} did not converge within \
                 simulation.newton.max_iterations = {max} (last increment {last:.3e} relative, \
                 simulation.newton.tolerance = {tolerance:e})",
                scheme.name(),
                stage + 1
            ),
            Self::TooSlow {
                scheme,
                stage,
                theta,
                norm,
                max,
            } => write!(
                f,
                "Newton iterations of {} stage {} contract at {theta:.3} per iteration \
                 (increment {norm:.3e} relative): too slowly to converge within \
                 simulation.newton.max_iterations = {max}",
                scheme.name(),
                stage + 1
            ),
            Self::Singular { scheme, stage } => write!(
                f,
                "the Newton matrix of {} stage {} is singular",
                scheme.name(),
                stage + 1
            ),
            Self::NotFinite { scheme, stage } => write!(
                f,
                "the Newton increment of {} stage {} is not finite",
                scheme.name(),
                stage + 1
            ),
        }
    }
}

/// How a body's unknowns map to its world twist [v; ω].
#[derive(Debug, Clone, Copy, PartialEq)]
enum Basis {
    /// Six unknowns (Δv, Δω), B = I₆.
    Full,
    /// One unknown, the spin rate about this world axis: B = [0; axis].
    Axis(Vec3),
    /// Two unknowns, the speed along and the spin rate about this world
    /// axis (a `spin-slide` body): B = [axis, 0; 0, axis].
    Slide(Vec3),
}

impl Basis {
    fn dim(self) -> usize {
        match self {
            Self::Full => 6,
            Self::Axis(_) => 1,
            Self::Slide(_) => 2,
        }
    }

    /// Per unknown of a reduced basis: where its axis sits in the twist
    /// [v; ω] (0 for v, 3 for ω) and the axis. Empty for `Full`.
    fn columns(self) -> [Option<(usize, Vec3)>; 2] {
        match self {
            Self::Full => [None, None],
            Self::Axis(u) => [Some((3, u)), None],
            Self::Slide(u) => [Some((0, u)), Some((3, u))],
        }
    }
}

/// The linear solver of the Newton matrix, one interface over both kinds.
#[derive(Debug, Clone)]
// One per simulation, inside the boxed workspace: the size does not matter.
#[allow(clippy::large_enum_variant)]
enum Linear {
    Block(BlockLu),
    Sparse(SparseLu),
}

impl Linear {
    fn new(kind: LinearSolver, offsets: Vec<(usize, usize)>, edges: &[(usize, usize)]) -> Self {
        match kind {
            LinearSolver::BlockElimination => Self::Block(BlockLu::new(offsets, edges)),
            LinearSolver::SparseLu => Self::Sparse(SparseLu::new(&offsets, edges)),
        }
    }

    fn block(&self, i: usize, j: usize) -> Option<usize> {
        match self {
            Self::Block(lu) => lu.block(i, j),
            Self::Sparse(lu) => lu.block(i, j),
        }
    }

    fn clear(&mut self) {
        match self {
            Self::Block(lu) => lu.clear(),
            Self::Sparse(lu) => lu.clear(),
        }
    }

    fn add(&mut self, b: usize, m: &Mat6, scale: f64) {
        match self {
            Self::Block(lu) => lu.add(b, m, scale),
            Self::Sparse(lu) => lu.add(b, m, scale),
        }
    }

    fn factor(&mut self) -> bool {
        match self {
            Self::Block(lu) => lu.factor(),
            Self::Sparse(lu) => lu.factor(),
        }
    }

    fn solve(&mut self, rhs: &mut [f64]) {
        match self {
            Self::Block(lu) => lu.solve(rhs),
            Self::Sparse(lu) => lu.solve(rhs),
        }
    }
}

/// Workspace of the implicit steps: the fixed sparsity pattern, its symbolic
/// factorization and the per-step buffers.
#[derive(Debug, Clone)]
pub(crate) struct Implicit {
    /// Per body: first unknown and basis, `None` if not integrated.
    dofs: Vec<Option<(usize, Basis)>>,
    /// Number of unknowns.
    n: usize,
    /// Diagonal block of every integrated body.
    diag: Vec<(usize, usize)>,
    /// Per coupling of [`VelocityJacobian`]: the blocks (aa, ab, ba, bb),
    /// `None` where a body is not integrated.
    couplings: Vec<[Option<usize>; 4]>,
    jac: VelocityJacobian,
    /// Right-hand side, then the solution Δq̇.
    rhs: Vec<f64>,
    /// `None` when there are no unknowns.
    linear: Option<Linear>,
    /// Whether `lu` holds a numeric factorization.
    factored: bool,
    /// SDIRK2: whether the next step starts with a fresh Jacobian.
    refresh: bool,
    /// SDIRK2: the γh the factorized matrix was built with.
    factored_gh: f64,
    /// SDIRK2 stage data, in unknown coordinates: v_n, the iterate V, the
    /// stage displacement weights Σ a_ij V_j (without h) and A_1.
    v_n: Vec<f64>,
    v: Vec<f64>,
    base: Vec<f64>,
    a1: Vec<f64>,
    /// The velocity increment a stage already knows from the earlier
    /// stages, h·Σ_{j<i} a_ij·A_j (SDIRK2: h(1 − γ)·A_1 at stage 2).
    known_dv: Vec<f64>,
    /// The scheme whose stages `newton` solves.
    scheme: Scheme,
    /// ESDIRK3(2)'s stage data and step control, made at its first step.
    esdirk: Option<Box<esdirk::Stages>>,
    /// The last Newton increment, and the mass scale of each unknown
    /// (m, the largest principal inertia, or the spin inertia).
    step: Vec<f64>,
    mass_scale: Vec<f64>,
    stage: Option<State>,
    /// The last contraction rate of the Newton iterations measured (∞
    /// before the first).
    theta_last: f64,
    /// The last one measured in the current step (ESDIRK3(2); `None` at
    /// each step's start).
    pub(super) theta_step: Option<f64>,
    /// Whether a stage whose Newton iterations contract too slowly fails at
    /// once (an adaptive step above the smallest, which a smaller step can
    /// retry) rather than after `newton.max_iterations`.
    give_up_early: bool,
    /// Statistics.
    pub(crate) stats: Stats,
}

/// Work done by an implicit integrator.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    /// Triangular solves with a factorized matrix.
    pub solves: u64,
    /// Numeric LU factorizations (each follows a Jacobian evaluation).
    pub factorizations: u64,
    /// Newton iterations (SDIRK2).
    pub newton_iterations: u64,
    /// Steps (or part steps) retried as two halves because Newton did not
    /// converge (SDIRK2).
    pub halvings: u64,
    /// Part steps of h/16 that SDIRK2's Newton could not solve and that
    /// were taken by the linearly implicit Euler step instead.
    pub fallbacks: u64,
    /// The most halvings any step needed (SDIRK2): the smallest part step
    /// taken is h/2^this.
    pub deepest_halving: u32,
}

/// γ of SDIRK2.
const GAMMA: f64 = 1.0 - std::f64::consts::FRAC_1_SQRT_2;

/// Halvings of a step whose Newton iterations do not converge.
const MAX_HALVINGS: u32 = 4;

/// Halvings of one Newton increment before it is taken as it is.
const MAX_BACKTRACKS: u32 = 8;

/// The least contraction rate an iteration without a measured rate of its
/// own is judged by (ESDIRK3(2)) when the last rate measured is an earlier
/// step's: with none, stages taken after one iteration at a tiny earlier
/// rate spoil the error estimate (531 rejected steps against 67 over the
/// paper's first 0.6 s).
const RATE_FLOOR: f64 = 0.1;

/// The same when a rate was measured earlier in the same step (at the same
/// step size, with this step's Jacobian or a fresher one), which the stage
/// is judged by instead: the rates of one step's stages agree far better
/// than a step's with the last. On the paper's scene over 1.8 s, 1.85
/// Newton iterations per stage against 2.19 with `RATE_FLOOR` alone, the
/// steps within 2 % (3 653 against 3 599) and 14 % less CPU time, every
/// compared quantity within 0.11 % of the reference (docs/performance.md,
/// change 12). Without a floor, 1.71 iterations per
/// stage and 0.37 % over the first 0.6 s.
const RATE_FLOOR_IN_STEP: f64 = 0.01;

/// Contraction rate above which Newton re-evaluates its Jacobian: at 0.3
/// each iteration gains half a digit; slower is cheaper with a fresh one.
const REFRESH_CONTRACTION: f64 = 0.3;

impl Implicit {
    /// Builds the sparsity pattern of `model` and factors it symbolically.
    pub(crate) fn new(model: &Model) -> Self {
        let (dofs, n) = unknowns(model);
        let mass_scale = mass_scales(model, &dofs, n);
        let jac = VelocityJacobian::new(model);
        // The nodes are the integrated bodies, in the order of their unknowns.
        let mut node = vec![None; model.bodies.len()];
        for (k, &i) in model.integrated.iter().enumerate() {
            node[i] = Some(k);
        }
        let offsets = model
            .integrated
            .iter()
            .map(|&i| {
                dofs[i]
                    .map(|(off, basis)| (off, basis.dim()))
                    .expect("integrated")
            })
            .collect();
        let edges: Vec<(usize, usize)> = jac
            .couplings
            .iter()
            .filter_map(|c| Some((node[c.a]?, node[c.b]?)))
            .filter(|(a, b)| a != b)
            .collect();
        let linear = (n > 0).then(|| Linear::new(model.newton.linear_solver, offsets, &edges));
        let block = |i: usize, j: usize| {
            let lu = linear.as_ref()?;
            lu.block(node[i]?, node[j]?)
        };
        let diag = model
            .integrated
            .iter()
            .map(|&i| (i, block(i, i).expect("diagonal block")))
            .collect();
        let couplings = jac
            .couplings
            .iter()
            .map(|c| {
                [
                    block(c.a, c.a),
                    block(c.a, c.b),
                    block(c.b, c.a),
                    block(c.b, c.b),
                ]
            })
            .collect();
        Self {
            dofs,
            n,
            diag,
            couplings,
            jac,
            rhs: vec![0.0; n],
            linear,
            factored: false,
            refresh: true,
            factored_gh: 0.0,
            v_n: vec![0.0; n],
            v: vec![0.0; n],
            base: vec![0.0; n],
            a1: vec![0.0; n],
            known_dv: vec![0.0; n],
            scheme: Scheme::Sdirk2,
            esdirk: None,
            step: vec![0.0; n],
            mass_scale,
            stage: None,
            theta_last: f64::INFINITY,
            theta_step: None,
            give_up_early: false,
            stats: Stats::default(),
        }
    }

    /// One step of `h` seconds.
    pub(crate) fn step(
        &mut self,
        model: &Model,
        dynamics: &mut Dynamics,
        state: &mut State,
        h: f64,
    ) {
        dynamics.forces_and_jacobian(model, state, Mode::Commit, 0.0, &mut self.jac);
        // The step applies the start's forces plus their linear change,
        // whose share per pair is not known: the impulse counts the start's.
        dynamics.note_stage(0);
        dynamics.note_accepted(state.t, h, &[(0, 1.0)], 0);
        self.assemble_matrix(model, state, h);
        self.euler_rhs(model, dynamics, state, h);
        let solved = self.factor() && self.solve();
        for &i in &model.integrated {
            let (off, basis) = self.dofs[i].expect("integrated");
            if !solved {
                // A singular system: poison the state so the caller reports it.
                state.vel[i] = Vec3::repeat(f64::NAN);
                continue;
            }
            let dq = &self.rhs[off..off + basis.dim()];
            match (basis, model.bodies[i].motion) {
                (Basis::Full, _) => {
                    state.vel[i] += Vec3::new(dq[0], dq[1], dq[2]);
                    state.omega[i] += state.rot[i].inverse() * Vec3::new(dq[3], dq[4], dq[5]);
                }
                (Basis::Axis(_), Motion::Spin { axis_body, .. }) => {
                    state.omega[i] += axis_body * dq[0];
                }
                (Basis::Slide(axis), Motion::Spin { axis_body, .. }) => {
                    state.vel[i] += axis * dq[0];
                    state.omega[i] += axis_body * dq[1];
                }
                (Basis::Axis(_) | Basis::Slide(_), _) => {
                    unreachable!("only spin bodies have an axis basis")
                }
            }
            state.pos[i] += h * state.vel[i];
            state.rot[i] *= exp_map(&(h * state.omega[i]));
            state.rot[i].renormalize_fast();
        }
        state.t += h;
        model.prescribe(state.t, state);
    }

    /// One SDIRK2 step of `h` seconds. A step whose Newton iterations do not
    /// converge is retried as two half steps, down to h/16. A part step of
    /// h/16 that still does not converge is taken by the linearly implicit
    /// Euler step (one linear solve, first order, no iteration to fail) when
    /// `model.newton.fallback` is set, and counted in [`Stats::fallbacks`];
    /// otherwise the error names the stage that did not converge (the state
    /// is then left at the end of the last part step that did).
    pub(crate) fn sdirk2_step(
        &mut self,
        model: &Model,
        dynamics: &mut Dynamics,
        state: &mut State,
        h: f64,
    ) -> Result<(), String> {
        self.sdirk2_split(model, dynamics, state, h, 0)
    }

    fn sdirk2_split(
        &mut self,
        model: &Model,
        dynamics: &mut Dynamics,
        state: &mut State,
        h: f64,
        depth: u32,
    ) -> Result<(), String> {
        self.stats.deepest_halving = self.stats.deepest_halving.max(depth);
        let single = match self.scheme {
            Scheme::Sdirk2 => self.sdirk2_single(model, dynamics, state, h),
            Scheme::Esdirk32 | Scheme::Trbdf2 => self.esdirk_single(model, dynamics, state, h),
        };
        match single {
            Err(_) if depth < MAX_HALVINGS => {
                self.stats.halvings += 1;
                self.sdirk2_split(model, dynamics, state, h / 2.0, depth + 1)?;
                self.sdirk2_split(model, dynamics, state, h / 2.0, depth + 1)
            }
            Err(_) if model.newton.fallback => {
                self.stats.fallbacks += 1;
                self.step(model, dynamics, state, h);
                // The factorization is the Euler step's, not SDIRK2's.
                self.refresh = true;
                Ok(())
            }
            Err(e) => Err(format!(
                "{e} (with the step halved {MAX_HALVINGS} times, to {h:.3e} s)"
            )),
            Ok(()) => Ok(()),
        }
    }

    fn sdirk2_single(
        &mut self,
        model: &Model,
        dynamics: &mut Dynamics,
        state: &mut State,
        h: f64,
    ) -> Result<(), StageFailure> {
        if self.n == 0 {
            // Nothing to integrate: only the prescribed bodies move.
            dynamics.note_unintegrated(model, state);
            dynamics.note_accepted(state.t, h, &[(0, 1.0 - GAMMA), (1, GAMMA)], 1);
            state.t += h;
            model.prescribe(state.t, state);
            return Ok(());
        }
        if dynamics.has_memory() {
            // Latch contact onsets at the accepted state.
            dynamics.wrenches(model, state, Mode::Commit);
        }
        let mut stage = self.stage.take().unwrap_or_else(|| state.clone());
        self.gather(model, state);
        self.v.copy_from_slice(&self.v_n);
        if !model.newton.reuse_jacobian {
            self.refresh = true;
        }
        let gh = GAMMA * h;
        let mut worst = 0;
        let mut result = Ok(());
        for s in 0..2 {
            // Known part of the stage velocity and of its displacement.
            if s == 0 {
                self.a1.fill(0.0);
            } else {
                for k in 0..self.n {
                    self.a1[k] = (self.v[k] - self.v_n[k]) / gh;
                }
            }
            let t_stage = state.t + if s == 0 { gh } else { h };
            match self.newton(model, dynamics, state, &mut stage, s, t_stage, h) {
                Ok(iterations) => worst = worst.max(iterations),
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
            dynamics.note_stage(s);
        }
        self.refresh = result.is_err() || worst > model.newton.reuse_iterations;
        if result.is_ok() {
            dynamics.note_accepted(state.t, h, &[(0, 1.0 - GAMMA), (1, GAMMA)], 1);
            std::mem::swap(state, &mut stage);
            state.t = stage.t + h;
            model.prescribe(state.t, state);
            stage.clone_from(state);
        }
        self.stage = Some(stage);
        result
    }

    /// Newton iterations of stage `s` (0 or 1) into `self.v`, `stage` left
    /// at the converged stage state; returns the iterations taken.
    #[allow(clippy::too_many_arguments)]
    fn newton(
        &mut self,
        model: &Model,
        dynamics: &mut Dynamics,
        start: &State,
        stage: &mut State,
        s: usize,
        t_stage: f64,
        h: f64,
    ) -> Result<u32, StageFailure> {
        let gh = self.scheme.gamma() * h;
        let settings = &model.newton;
        let mut previous = f64::INFINITY;
        let mut last_residual = f64::INFINITY;
        let mut backtracks = 0;
        // Whether the Jacobian was evaluated within these iterations.
        let mut fresh = false;
        let give_up_early = self.give_up_early;
        for k in 1..=settings.max_iterations {
            self.stats.newton_iterations += 1;
            self.set_stage(model, start, stage, s, t_stage, h);
            // The divergence checks look at the last iterate only: Newton may
            // overshoot deep into a contact on its way to the solution.
            dynamics.watch.reset();
            if self.refresh || !self.factored || self.factored_gh != gh {
                self.refresh_matrix(model, dynamics, stage, s, gh)?;
                previous = f64::INFINITY;
                fresh = true;
            } else {
                dynamics.wrenches(model, stage, Mode::Trial);
            }
            self.residual(model, dynamics, stage, s, h);
            // Line search: an increment that made the residual grow (Newton
            // overshooting across a contact onset or release) is halved.
            let residual = self.residual_norm();
            if residual > last_residual && backtracks < MAX_BACKTRACKS {
                backtracks += 1;
                self.halve_increment();
                continue;
            }
            backtracks = 0;
            last_residual = residual;
            let norm = self.increment(s)?;
            // The contraction rate, unknown at the first iteration of a Jacobian.
            let theta = (previous.is_finite()).then(|| norm / previous);
            if let Some(theta) = theta {
                self.theta_last = theta;
                self.theta_step = Some(theta);
            }
            // SDIRK2 waits for a rate of its own.
            let rate = theta.or((self.scheme != Scheme::Sdirk2).then(|| self.borrowed_rate()));
            previous = norm;
            if converged(norm, rate, self.scheme.newton_tolerance(model)) {
                self.set_stage(model, start, stage, s, t_stage, h);
                return Ok(k);
            }
            if let Some(theta) = theta.filter(|_| fresh && give_up_early)
                && let Some(why) = self.too_slow(model, theta, norm, k, s)
            {
                return Err(why);
            }
            if theta.is_some_and(|theta| theta > REFRESH_CONTRACTION) {
                // Slow or diverging: a Jacobian evaluated at this iterate.
                self.refresh = true;
            }
        }
        Err(StageFailure::NotConverged {
            scheme: self.scheme,
            stage: s,
            max: settings.max_iterations,
            last: previous,
            tolerance: settings.tolerance,
        })
    }

    /// The contraction rate ESDIRK3(2) judges an iteration without a rate
    /// of its own (the first of a stage or of a Jacobian) by: the last rate
    /// measured (Hairer & Wanner, Solving ODEs II, §IV.8, η), this step's at
    /// least `RATE_FLOOR_IN_STEP`, else an earlier step's at least
    /// `RATE_FLOOR`.
    fn borrowed_rate(&self) -> f64 {
        self.theta_step
            .map_or(self.theta_last.max(RATE_FLOOR), |t| {
                t.max(RATE_FLOOR_IN_STEP)
            })
    }

    /// With a fresh Jacobian and adaptive steps: why the iterations of stage
    /// `s`, at contraction rate `theta` with increment `norm` after `k`
    /// iterations, should stop now, if they diverge or will not converge
    /// within the iterations left at this rate; the step is then retried
    /// smaller (Hairer & Wanner, Solving ODEs II, §IV.8).
    fn too_slow(
        &self,
        model: &Model,
        theta: f64,
        norm: f64,
        k: u32,
        s: usize,
    ) -> Option<StageFailure> {
        let max = model.newton.max_iterations;
        let left = (max - k) as i32;
        let tolerance = self.scheme.newton_tolerance(model);
        (theta >= 1.0 || theta.powi(left) / (1.0 - theta) * norm > tolerance).then_some(
            StageFailure::TooSlow {
                scheme: self.scheme,
                stage: s,
                theta,
                norm,
                max,
            },
        )
    }

    /// Evaluates the Jacobian at `stage` and factors the Newton matrix
    /// M − γh·(D + γh·K) of stage `s` (`gh` = γh).
    fn refresh_matrix(
        &mut self,
        model: &Model,
        dynamics: &mut Dynamics,
        stage: &State,
        s: usize,
        gh: f64,
    ) -> Result<(), StageFailure> {
        dynamics.forces_and_jacobian(model, stage, Mode::Trial, gh, &mut self.jac);
        self.assemble_matrix(model, stage, gh);
        if !self.factor() {
            return Err(StageFailure::Singular {
                scheme: self.scheme,
                stage: s,
            });
        }
        self.refresh = false;
        self.factored_gh = gh;
        Ok(())
    }

    /// Takes back half of the last increment, and asks for a fresh Jacobian.
    fn halve_increment(&mut self) {
        for i in 0..self.n {
            self.step[i] *= 0.5;
            self.v[i] -= self.step[i];
        }
        self.refresh = true;
    }

    /// Solves for the Newton increment of stage `s` from the residual in
    /// `rhs` and adds it to the iterate; returns its norm, the largest
    /// increment relative to |V| + 1.
    fn increment(&mut self, s: usize) -> Result<f64, StageFailure> {
        if !self.solve() {
            return Err(StageFailure::NotFinite {
                scheme: self.scheme,
                stage: s,
            });
        }
        let mut norm = 0.0f64;
        for i in 0..self.n {
            self.step[i] = self.rhs[i];
            self.v[i] += self.rhs[i];
            norm = norm.max(self.rhs[i].abs() / (self.v[i].abs() + 1.0));
        }
        Ok(norm)
    }

    /// The largest residual in velocity units (divided by the mass scale),
    /// relative to |v_n| + 1 (a fixed weight within the step, so that the
    /// line search compares like with like).
    fn residual_norm(&self) -> f64 {
        (0..self.n)
            .map(|i| self.rhs[i].abs() / (self.mass_scale[i] * (self.v_n[i].abs() + 1.0)))
            .fold(0.0, f64::max)
    }

    /// v_n in unknown coordinates from `state` (world twists, spin rates).
    fn gather(&mut self, model: &Model, state: &State) {
        for &i in &model.integrated {
            let (off, basis) = self.dofs[i].expect("integrated");
            let w = state.omega_world(i);
            match basis {
                Basis::Axis(axis) => self.v_n[off] = w.dot(&axis),
                Basis::Slide(axis) => {
                    self.v_n[off] = state.vel[i].dot(&axis);
                    self.v_n[off + 1] = w.dot(&axis);
                }
                Basis::Full => {
                    for c in 0..3 {
                        self.v_n[off + c] = state.vel[i][c];
                        self.v_n[off + 3 + c] = w[c];
                    }
                }
            }
        }
    }

    /// Sets `stage` to stage `s` with iterate `self.v`: SDIRK2's
    /// displacement weights γ·V (stage 1) or (1 − γ)·V_1 + γ·V (stage 2,
    /// V_1 = v_n + γh·A_1), or ESDIRK3(2)'s ([`Self::esdirk_base`]).
    fn set_stage(
        &mut self,
        model: &Model,
        start: &State,
        stage: &mut State,
        s: usize,
        t_stage: f64,
        h: f64,
    ) {
        match self.scheme {
            Scheme::Sdirk2 => {
                for k in 0..self.n {
                    self.base[k] = GAMMA * self.v[k];
                    if s == 1 {
                        let v1 = self.v_n[k] + GAMMA * h * self.a1[k];
                        self.base[k] += (1.0 - GAMMA) * v1;
                    }
                }
            }
            Scheme::Esdirk32 | Scheme::Trbdf2 => self.esdirk_base(model, h),
        }
        self.place_stage(model, start, stage, t_stage, h);
    }

    /// Sets `stage` at `t_stage` to the velocities `self.v` and the poses
    /// x_n + h·base, Exp(h·base)·R_n.
    fn place_stage(
        &mut self,
        model: &Model,
        start: &State,
        stage: &mut State,
        t_stage: f64,
        h: f64,
    ) {
        stage.t = t_stage;
        for &i in &model.integrated {
            let (off, basis) = self.dofs[i].expect("integrated");
            let (disp, rotvec, vel, w) = match basis {
                Basis::Axis(axis) => (
                    Vec3::zeros(),
                    axis * self.base[off],
                    start.vel[i],
                    axis * self.v[off],
                ),
                Basis::Slide(axis) => (
                    axis * self.base[off],
                    axis * self.base[off + 1],
                    axis * self.v[off],
                    axis * self.v[off + 1],
                ),
                Basis::Full => (
                    Vec3::new(self.base[off], self.base[off + 1], self.base[off + 2]),
                    Vec3::new(self.base[off + 3], self.base[off + 4], self.base[off + 5]),
                    Vec3::new(self.v[off], self.v[off + 1], self.v[off + 2]),
                    Vec3::new(self.v[off + 3], self.v[off + 4], self.v[off + 5]),
                ),
            };
            stage.pos[i] = start.pos[i] + h * disp;
            let mut rot = exp_map(&(h * rotvec)) * start.rot[i];
            rot.renormalize_fast();
            stage.rot[i] = rot;
            stage.vel[i] = vel;
            stage.omega[i] = rot.inverse() * w;
        }
        model.prescribe(t_stage, stage);
    }

    /// −r(V) into `rhs` from the wrenches last evaluated at `stage`:
    /// r = M·(V − v_n − known_dv) − γh·(f − ω×I_wω), SDIRK2's known_dv
    /// h(1 − γ)·A_1·[s = 1] (ESDIRK3(2) sets its own before each stage).
    fn residual(&mut self, model: &Model, dynamics: &Dynamics, stage: &State, s: usize, h: f64) {
        if self.scheme == Scheme::Sdirk2 {
            let known = if s == 1 { (1.0 - GAMMA) * h } else { 0.0 };
            for k in 0..self.n {
                self.known_dv[k] = known * self.a1[k];
            }
        }
        let gh = self.scheme.gamma() * h;
        let (force, torque) = (dynamics.forces(), dynamics.torques());
        let (v, v_n, known_dv) = (&self.v, &self.v_n, &self.known_dv);
        let dv = |k: usize| v[k] - v_n[k] - known_dv[k];
        for &i in &model.integrated {
            let (off, basis) = self.dofs[i].expect("integrated");
            match (basis, model.bodies[i].motion) {
                (Basis::Axis(axis), Motion::Spin { inertia, .. }) => {
                    self.rhs[off] = -(inertia * dv(off) - gh * torque[i].dot(&axis));
                }
                (Basis::Slide(axis), Motion::Spin { inertia, .. }) => {
                    let m = model.bodies[i].mass;
                    self.rhs[off] = -(m * dv(off) - gh * force[i].dot(&axis));
                    self.rhs[off + 1] = -(inertia * dv(off + 1) - gh * torque[i].dot(&axis));
                }
                (Basis::Axis(_) | Basis::Slide(_), _) => {
                    unreachable!("only spin bodies have an axis basis")
                }
                (Basis::Full, _) => {
                    let m = model.bodies[i].mass;
                    let inertia_w = world_inertia(model, stage, i);
                    let w = stage.omega_world(i);
                    let tau = torque[i] - w.cross(&(inertia_w * w));
                    let dw = Vec3::new(dv(off + 3), dv(off + 4), dv(off + 5));
                    let r_ang = inertia_w * dw - gh * tau;
                    for c in 0..3 {
                        self.rhs[off + c] = -(m * dv(off + c) - gh * force[i][c]);
                        self.rhs[off + 3 + c] = -r_ang[c];
                    }
                }
            }
        }
    }

    /// h·Bᵀ(f − ω×I_wω) into `rhs`: the right-hand side of the linearly
    /// implicit Euler step.
    fn euler_rhs(&mut self, model: &Model, dynamics: &Dynamics, state: &State, h: f64) {
        let (force, torque) = (dynamics.forces(), dynamics.torques());
        for &i in &model.integrated {
            let (off, basis) = self.dofs[i].expect("integrated");
            match basis {
                // ω ∥ axis: the gyroscopic torque has no part along it.
                Basis::Axis(axis) => self.rhs[off] = h * torque[i].dot(&axis),
                Basis::Slide(axis) => {
                    self.rhs[off] = h * force[i].dot(&axis);
                    self.rhs[off + 1] = h * torque[i].dot(&axis);
                }
                Basis::Full => {
                    let inertia_w = world_inertia(model, state, i);
                    let w = state.omega_world(i);
                    let tau = torque[i] - w.cross(&(inertia_w * w));
                    for k in 0..3 {
                        self.rhs[off + k] = h * force[i][k];
                        self.rhs[off + 3 + k] = h * tau[k];
                    }
                }
            }
        }
    }

    /// Fills Bᵀ(M − hh·J)B into the linear solver, J the blocks last
    /// evaluated into `jac` (D, or D + s·K) and M the mass at `state`.
    fn assemble_matrix(&mut self, model: &Model, state: &State, hh: f64) {
        let Some(linear) = &mut self.linear else {
            return;
        };
        linear.clear();
        for &(i, blk) in &self.diag {
            let body = &model.bodies[i];
            let mut mass = Mat6::zeros();
            match (self.dofs[i].expect("integrated").1, body.motion) {
                (Basis::Axis(_), Motion::Spin { inertia, .. }) => mass[(0, 0)] = inertia,
                (Basis::Slide(_), Motion::Spin { inertia, .. }) => {
                    mass[(0, 0)] = body.mass;
                    mass[(1, 1)] = inertia;
                }
                _ => {
                    mass.fixed_view_mut::<3, 3>(0, 0).fill_diagonal(body.mass);
                    mass.fixed_view_mut::<3, 3>(3, 3)
                        .copy_from(&world_inertia(model, state, i));
                }
            }
            linear.add(blk, &mass, 1.0);
        }
        for (c, blocks) in self.jac.couplings.iter().zip(&self.couplings) {
            if !c.active {
                continue;
            }
            let ends = [(c.a, c.a), (c.a, c.b), (c.b, c.a), (c.b, c.b)];
            let mats = [&c.aa, &c.ab, &c.ba, &c.bb];
            for ((blk, (i, j)), m) in blocks.iter().zip(ends).zip(mats) {
                if let Some(blk) = blk {
                    let bi = self.dofs[i].expect("integrated").1;
                    let bj = self.dofs[j].expect("integrated").1;
                    if (bi, bj) == (Basis::Full, Basis::Full) {
                        // Most blocks: no projection, and no copy of the block.
                        linear.add(*blk, m, -hh);
                    } else {
                        linear.add(*blk, &project(bi, bj, m), -hh);
                    }
                }
            }
        }
    }

    /// Factors the assembled matrix; false if the factorization failed.
    fn factor(&mut self) -> bool {
        let Some(linear) = &mut self.linear else {
            return true;
        };
        self.stats.factorizations += 1;
        self.factored = linear.factor();
        self.factored
    }

    /// Overwrites `rhs` with the solution of the factorized system; false
    /// if it is not finite.
    fn solve(&mut self) -> bool {
        let Some(linear) = &mut self.linear else {
            return true;
        };
        if !self.factored {
            return false;
        }
        linear.solve(&mut self.rhs);
        self.stats.solves += 1;
        self.rhs.iter().all(|x| x.is_finite())
    }
}

/// Whether a Newton iteration whose increment has norm `norm` (contraction
/// rate `theta` when known) has converged: at once when the increment is a
/// hundredth of the tolerance, else when the estimated distance to the
/// solution θ/(1 − θ)·‖Δ‖ is within it.
fn converged(norm: f64, theta: Option<f64>, tolerance: f64) -> bool {
    match theta {
        _ if norm <= 0.01 * tolerance => true,
        Some(theta) => theta < 1.0 && theta / (1.0 - theta) * norm <= tolerance,
        None => false,
    }
}

/// Per body its first unknown and basis (`None` if not integrated), and the
/// number of unknowns.
fn unknowns(model: &Model) -> (Vec<Option<(usize, Basis)>>, usize) {
    let mut dofs = vec![None; model.bodies.len()];
    let mut n = 0;
    for &i in &model.integrated {
        let basis = match model.bodies[i].motion {
            Motion::Spin {
                axis, slides: true, ..
            } => Basis::Slide(axis),
            Motion::Spin { axis, .. } => Basis::Axis(axis),
            _ => Basis::Full,
        };
        dofs[i] = Some((n, basis));
        n += basis.dim();
    }
    (dofs, n)
}

/// The mass scale of each unknown: m, the largest principal inertia, or
/// the spin inertia.
fn mass_scales(model: &Model, dofs: &[Option<(usize, Basis)>], n: usize) -> Vec<f64> {
    let mut mass_scale = vec![0.0; n];
    for &i in &model.integrated {
        let (off, basis) = dofs[i].expect("integrated");
        let body = &model.bodies[i];
        match (basis, body.motion) {
            (Basis::Axis(_), Motion::Spin { inertia, .. }) => mass_scale[off] = inertia,
            (Basis::Slide(_), Motion::Spin { inertia, .. }) => {
                mass_scale[off] = body.mass;
                mass_scale[off + 1] = inertia;
            }
            _ => {
                let rot = body.inertia.max();
                mass_scale[off..off + 6]
                    .copy_from_slice(&[body.mass, body.mass, body.mass, rot, rot, rot]);
            }
        }
    }
    mass_scale
}

/// I_w = R·I_b·Rᵀ of body `i` at `state` [kg·m²].
fn world_inertia(model: &Model, state: &State, i: usize) -> Mat3 {
    let r = state.rot[i].to_rotation_matrix();
    r.matrix() * Mat3::from_diagonal(&model.bodies[i].inertia) * r.matrix().transpose()
}

/// B_iᵀ·m·B_j in the leading corner of a 6 × 6 block (the rest zero).
fn project(bi: Basis, bj: Basis, m: &Mat6) -> Mat6 {
    let mut out = Mat6::zeros();
    let (ci, cj) = (bi.columns(), bj.columns());
    match (bi, bj) {
        (Basis::Full, Basis::Full) => out = *m,
        (Basis::Full, _) => {
            for (c, (off, u)) in cj.iter().enumerate().filter_map(|(c, x)| Some((c, (*x)?))) {
                for r in 0..6 {
                    out[(r, c)] = m.fixed_view::<1, 3>(r, off).transpose().dot(&u);
                }
            }
        }
        (_, Basis::Full) => {
            for (r, (off, u)) in ci.iter().enumerate().filter_map(|(r, x)| Some((r, (*x)?))) {
                for c in 0..6 {
                    out[(r, c)] = m.fixed_view::<3, 1>(off, c).dot(&u);
                }
            }
        }
        _ => {
            for (r, (oi, u)) in ci.iter().enumerate().filter_map(|(r, x)| Some((r, (*x)?))) {
                for (c, (oj, w)) in cj.iter().enumerate().filter_map(|(c, x)| Some((c, (*x)?))) {
                    out[(r, c)] = u.dot(&(m.fixed_view::<3, 3>(oi, oj) * w));
                }
            }
        }
    }
    out
}
