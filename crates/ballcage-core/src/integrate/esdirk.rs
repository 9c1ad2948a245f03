//! The ESDIRK pairs, one code for two [`Tableau`]s:
//! - ESDIRK3(2)4L[2]SA of Kennedy & Carpenter ("Diagonally implicit
//!   Runge–Kutta methods for ordinary differential equations. A review",
//!   NASA/TM-2016-219173, 2016): four stages, the first explicit, γ =
//!   0.4358665; third order, L-stable, stiffly accurate, stage order 2, with
//!   an embedded second-order solution for the error estimate. The
//!   coefficients are those of SUNDIALS ARKODE's `ARKODE_ESDIRK324L2SA_4_2_3`
//!   (src/arkode/arkode_butcher_dirk.def, LLNL/sundials; A and b are those of
//!   the implicit table of ARK3(2)4L[2]SA, the embedding d is the method's
//!   own).
//! - TR-BDF2 as Hosea & Shampine's ESDIRK2(3) ([`TRBDF2`]): three stages,
//!   γ = 1 − 1/√2, second order, L-stable, stiffly accurate, stage order 2,
//!   with an embedded third-order solution.
//!
//! Applied to x' = v, M v' = f as SDIRK2 is ([`super`]): stage 1 is the
//! start, V_1 = v_n with A_1 = M⁻¹(f − ω×I_wω)(x_n, v_n); each later stage i
//! solves, for its twists V_i,
//!
//! M(x_i)·(V_i − v_n − h·Σ_{j<i} a_ij·A_j) − γh·(f − ω×I_wω)(x_i, V_i) = 0
//!
//! with the shared Newton iterations, matrix M − γh·(D + γh·K) and linear
//! solver, and A_i = (V_i − v_n − h·Σ_{j<i} a_ij·A_j)/(γh). The stage poses are
//! x_i = x_n + h·Σ_j a_ij·v_j and R_i = Exp(ξ_i)·R_n with ξ_i = h·Σ_j a_ij·K_j,
//! K_j = dexp⁻¹_{−ξ_j}(ω_j) (Runge–Kutta–Munthe-Kaas: without the dexp
//! correction a rotation about a turning axis is second order only); K_i is
//! solved with ξ_i by a few fixed-point iterations per body. The step ends
//! at the last stage (stiffly accurate). Its error estimate is the difference to
//! the embedded solution, h·Σ_j (b_j − d_j)·(K_j, A_j) on the displacements
//! [m, rad] and velocities [m/s, rad/s].
//!
//! With `simulation.rtol` the steps are chosen by a PI controller
//! (Gustafsson; Hairer & Wanner, Solving ODEs II, §IV.8) on the weighted RMS
//! norm of the estimate, ‖e/(atol + rtol·|y|)‖ ≤ 1, up to
//! `simulation.max_step`; a rejected step is retried smaller. The steps do
//! not stop at the recorded frames: each call advances the run by one output
//! interval, and a frame that falls within a step is interpolated from the
//! step's ends (cubic Hermite, [`Implicit::interpolate`]) while the
//! integrator keeps its own state ahead. Each stage's Newton iterations start
//! from A_i extrapolated from the stages before ([`Implicit::predict`]).

use super::{Basis, Implicit, Scheme, StageFailure};
use crate::dynamics::{Dynamics, Evaluated, Mode};
use crate::integrate::Accepted;
use crate::math::{Vec3, dexp_inv};
use crate::model::{Model, Motion, State};
use crate::scene::{IntegratorKind, Tolerance};

/// An ESDIRK pair with at most four stages, the first explicit, stiffly
/// accurate (the last row of A is b, so the step ends at the last stage and
/// the next step's first stage is it); the entries past `stages` are zero.
#[derive(Debug)]
pub(super) struct Tableau {
    /// The name in error messages.
    pub(super) name: &'static str,
    /// The stages, the explicit first one included.
    stages: usize,
    /// γ = a_ii of the implicit stages.
    pub(super) gamma: f64,
    /// The Butcher matrix A (row i: the stage's a_ij, j ≤ i).
    a: [[f64; 4]; 4],
    /// The weights b of the solution the step goes on with (= the last row
    /// of A), and each stage's, for [`Dynamics::note_accepted`].
    b: [f64; 4],
    weights: [(usize, f64); 4],
    /// The weights d of the embedded solution: the estimate is h·Σ (b − d)·f.
    d: [f64; 4],
    /// The stage times c (row sums of A).
    c: [f64; 4],
}

impl Tableau {
    /// The last stage, the step's end.
    fn last(&self) -> usize {
        self.stages - 1
    }

    fn weights(&self) -> &[(usize, f64)] {
        &self.weights[..self.stages]
    }
}

const ESDIRK32_GAMMA: f64 = 0.435_866_521_508_459;
const ESDIRK32_B: [f64; 4] = [
    0.187_641_024_346_723_83,
    -0.595_297_473_576_955,
    0.971_789_927_721_772_1,
    ESDIRK32_GAMMA,
];

/// Kennedy & Carpenter's ESDIRK3(2)4L[2]SA: third order, the embedded
/// solution second.
pub(super) const ESDIRK32: Tableau = Tableau {
    name: "ESDIRK3(2)",
    stages: 4,
    gamma: ESDIRK32_GAMMA,
    a: [
        [0.0, 0.0, 0.0, 0.0],
        [ESDIRK32_GAMMA, ESDIRK32_GAMMA, 0.0, 0.0],
        [
            0.257_648_246_066_427_2,
            -0.093_514_767_574_886_25,
            ESDIRK32_GAMMA,
            0.0,
        ],
        ESDIRK32_B,
    ],
    b: ESDIRK32_B,
    weights: [
        (0, ESDIRK32_B[0]),
        (1, ESDIRK32_B[1]),
        (2, ESDIRK32_B[2]),
        (3, ESDIRK32_B[3]),
    ],
    d: [
        0.108_896_617_615_864_46,
        -0.915_325_811_870_712_7,
        1.271_273_597_302_152,
        0.535_155_596_952_696_1,
    ],
    c: [0.0, 0.871_733_043_016_918, 0.6, 1.0],
};

/// TR-BDF2's γ = 1 − 1/√2 (SDIRK2's) and w = √2/4.
const TRBDF2_GAMMA: f64 = 0.292_893_218_813_452_4;
const TRBDF2_W: f64 = 0.353_553_390_593_273_8;

/// TR-BDF2 as the ESDIRK2(3) of Hosea & Shampine ("Analysis and
/// implementation of TR-BDF2", Appl. Numer. Math. 20, 1996): a trapezoidal
/// stage to t + 2γh, then BDF2 to t + h. Second order, L-stable, stiffly
/// accurate, stage order 2; the embedded solution b̂ = ((1 − w)/3,
/// (3w + 1)/3, γ/3) is third order, and the estimate is the error of the
/// second-order solution the step goes on with (no local extrapolation:
/// the third-order solution is not L-stable). Two implicit stages at γh =
/// 0.29·h, against ESDIRK3(2)'s three at 0.44·h.
pub(super) const TRBDF2: Tableau = Tableau {
    name: "TR-BDF2",
    stages: 3,
    gamma: TRBDF2_GAMMA,
    a: [
        [0.0, 0.0, 0.0, 0.0],
        [TRBDF2_GAMMA, TRBDF2_GAMMA, 0.0, 0.0],
        [TRBDF2_W, TRBDF2_W, TRBDF2_GAMMA, 0.0],
        [0.0; 4],
    ],
    b: [TRBDF2_W, TRBDF2_W, TRBDF2_GAMMA, 0.0],
    weights: [(0, TRBDF2_W), (1, TRBDF2_W), (2, TRBDF2_GAMMA), (3, 0.0)],
    d: [
        (1.0 - TRBDF2_W) / 3.0,
        (3.0 * TRBDF2_W + 1.0) / 3.0,
        TRBDF2_GAMMA / 3.0,
        0.0,
    ],
    c: [0.0, 2.0 * TRBDF2_GAMMA, 1.0, 0.0],
};

/// Fixed-point iterations of ξ_i = h·(Σ_{j<i} a_ij·K_j + γ·dexp⁻¹_{−ξ_i}(ω_i)):
/// each gains a factor γh|ω|/2.
const DEXP_ITERATIONS: usize = 4;

/// The PI controller: safety factor, exponents on the present and the last
/// accepted error (Gustafsson's 0.7/k and 0.4/k, k = 3 the lower order of
/// the pair + 1, for both pairs), and the bounds of one step's change.
const SAFETY: f64 = 0.9;
const K_PRESENT: f64 = 0.7 / 3.0;
const K_LAST: f64 = 0.4 / 3.0;
const SHRINK_MIN: f64 = 0.2;
const GROW_MAX: f64 = 5.0;

/// The smallest adaptive step, as a fraction of the largest
/// (`simulation.max_step`): 1/1024 until 2026-11-26, where the 100× stiffer
/// contact of docs/performance.md at rtol 1e-5 needs 1/2262; a step
/// whose Newton iterations fail below it is taken by the fallback.
pub(crate) const MIN_STEP_FRACTION: f64 = 1.0 / 16384.0;

/// What the adaptive steps and the error estimate did over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ErrorStats {
    /// Steps accepted (adaptive mode; fixed mode: every step and part step).
    pub accepted: u64,
    /// Steps rejected and retried smaller: the error estimate above the
    /// tolerance, or Newton not converging.
    pub rejected: u64,
    /// The smallest step accepted [s] (infinite before the first).
    pub smallest_step: f64,
    /// Σ over accepted steps of the largest estimated local error of a
    /// position component [m]: a bound on the global position error when
    /// errors add up without damping.
    pub position_error: f64,
    /// The same for the velocities [m/s].
    pub velocity_error: f64,
    /// Σ over accepted steps of the weighted norm of the estimate
    /// (adaptive mode; 1 = one tolerance) [–].
    pub weighted_error: f64,
}

/// The last accepted adaptive step, for the frames within it
/// ([`Implicit::interpolate`]); in unknown coordinates.
#[derive(Debug, Clone)]
struct Dense {
    /// The step's start and length [s].
    start: State,
    h: f64,
    /// A fallback step: interpolated linearly.
    linear: bool,
    /// The displacement over the step [m, rad].
    disp: Vec<f64>,
    /// The displacement rates at both ends [m/s, rad/s].
    rate0: Vec<f64>,
    rate1: Vec<f64>,
    /// The velocities [m/s, rad/s] and accelerations [m/s², rad/s²] at
    /// both ends.
    v0: Vec<f64>,
    v1: Vec<f64>,
    a0: Vec<f64>,
    a1: Vec<f64>,
}

impl Dense {
    fn new(n: usize) -> Self {
        let z = vec![0.0; n];
        Self {
            start: State {
                t: 0.0,
                pos: Vec::new(),
                rot: Vec::new(),
                vel: Vec::new(),
                omega: Vec::new(),
            },
            h: 0.0,
            linear: true,
            disp: z.clone(),
            rate0: z.clone(),
            rate1: z.clone(),
            v0: z.clone(),
            v1: z.clone(),
            a0: z.clone(),
            a1: z,
        }
    }
}

/// An ESDIRK pair's stage data and step control.
#[derive(Debug, Clone)]
pub(super) struct Stages {
    /// The pair.
    tab: &'static Tableau,
    /// A_j per stage, in unknown coordinates [m/s², rad/s²].
    acc: [Vec<f64>; 4],
    /// The displacement rates per stage: V_j, or K_j for a free body's
    /// rotation [m/s, rad/s].
    rate: [Vec<f64>; 4],
    /// Σ_{j<i} a_ij·rate_j of the stage being solved, and its index.
    known_disp: Vec<f64>,
    solving: usize,
    /// The error estimates of the last step: displacements [m, rad] and
    /// velocities [m/s, rad/s].
    err_x: Vec<f64>,
    err_v: Vec<f64>,
    /// The state at the start of an adaptive step, for a retry.
    saved: Option<State>,
    /// The integrator's own state when its last step went past the frame
    /// last handed out, and that frame (interpolated; valid while
    /// `handed_valid`, its memory kept so that no step allocates).
    ahead: Option<State>,
    handed: Option<State>,
    handed_valid: bool,
    /// The last accepted step, for the frames within it.
    dense: Dense,
    /// Stage 1's A_1 known without a force evaluation ([`Implicit::first_stage`]):
    /// the state whose A_1 `acc[0]` holds (the last step's start), and the
    /// end of the last step taken with its A_4.
    known_start: Option<State>,
    known_end: Option<State>,
    end_acc: Vec<f64>,
    /// The step the controller proposes next [s] (0 before the first).
    h_next: f64,
    /// The last accepted step's error norm, and whether the last attempt
    /// was rejected.
    err_last: f64,
    rejected_last: bool,
    pub(super) stats: ErrorStats,
}

impl Stages {
    fn new(n: usize, tab: &'static Tableau) -> Self {
        let z = vec![0.0; n];
        let z_end = z.clone();
        Self {
            tab,
            acc: [z.clone(), z.clone(), z.clone(), z.clone()],
            rate: [z.clone(), z.clone(), z.clone(), z.clone()],
            known_disp: z.clone(),
            solving: 1,
            err_x: z.clone(),
            err_v: z,
            saved: None,
            ahead: None,
            handed: None,
            handed_valid: false,
            dense: Dense::new(n),
            known_start: None,
            known_end: None,
            end_acc: z_end,
            h_next: 0.0,
            err_last: 1.0,
            rejected_last: false,
            stats: ErrorStats {
                smallest_step: f64::INFINITY,
                ..ErrorStats::default()
            },
        }
    }
}

impl Implicit {
    /// See [`super::super::Workspace::state_ahead_of_frame`].
    pub(crate) fn state_ahead_of_frame(&self) -> Option<&State> {
        let es = self.esdirk.as_ref()?;
        es.ahead.as_ref().filter(|_| es.handed_valid)
    }

    /// What the ESDIRK pair has done so far (`None` for the other schemes).
    pub(crate) fn error_stats(&self) -> Option<ErrorStats> {
        self.esdirk.as_ref().map(|es| es.stats)
    }

    /// One step of `h` seconds: fixed (split in halves when Newton fails,
    /// as SDIRK2's) without tolerances, else adaptive steps that land on
    /// t + h.
    pub(crate) fn esdirk_step(
        &mut self,
        model: &Model,
        dynamics: &mut Dynamics,
        state: &mut State,
        h: f64,
        accepted: &mut Accepted<'_>,
    ) -> Result<(), String> {
        self.scheme = match model.integrator {
            IntegratorKind::Trbdf2 => Scheme::Trbdf2,
            _ => Scheme::Esdirk32,
        };
        let (n, tab) = (self.n, self.scheme.tableau().expect("an ESDIRK pair"));
        self.esdirk
            .get_or_insert_with(|| Box::new(Stages::new(n, tab)));
        match model.tolerance {
            None => self.sdirk2_split(model, dynamics, state, h, 0),
            Some(tol) => self.esdirk_adaptive(model, dynamics, state, (h, &tol), accepted),
        }
    }

    /// Adaptive steps, none longer than `simulation.max_step`, until the
    /// frame `big` [s] after `state.t` is reached or passed; `state` is then
    /// that frame (interpolated when a step passed it). `accepted` sees the
    /// end of each step kept, before the frame is handed out.
    fn esdirk_adaptive(
        &mut self,
        model: &Model,
        dynamics: &mut Dynamics,
        state: &mut State,
        (big, tol): (f64, &Tolerance),
        accepted: &mut Accepted<'_>,
    ) -> Result<(), String> {
        let t_end = state.t + big;
        let mut cur = self.own_state(state, big);
        // The smallest step, relative to the largest (`simulation.max_step`,
        // by default the output interval `big`).
        let largest = model.max_step;
        let floor = MIN_STEP_FRACTION * largest;
        while t_end - cur.t > 1e-12 * big {
            let es = self.esdirk.as_mut().expect("made by esdirk_step");
            // The first step: `max_step`.
            let proposed = if es.h_next > 0.0 {
                es.h_next
            } else {
                model.max_step
            };
            let h = proposed.min(model.max_step);
            let mut saved = es.saved.take().unwrap_or_else(|| cur.clone());
            saved.clone_from(&cur);
            self.give_up_early = h > floor;
            let outcome = self.esdirk_single(model, dynamics, &mut cur, h);
            self.give_up_early = false;
            let result = match outcome {
                Ok(()) => {
                    let err = self.error_norm(model, &saved, &cur, tol);
                    if self.control(h, proposed, err) {
                        self.keep_dense(&saved, h, false);
                        let tab = self.esdirk.as_ref().expect("made").tab;
                        dynamics.note_accepted(saved.t, h, tab.weights(), tab.last());
                        accepted(&cur, h, dynamics, Evaluated::LastIterate);
                        Ok(())
                    } else {
                        cur.clone_from(&saved);
                        let name = self.scheme.name();
                        too_small(h, largest).map_or(Ok(()), |why| {
                            Err(format!(
                                "the error estimate of {name} is {err:.3e} times \
                                 simulation.rtol/atol {why}"
                            ))
                        })
                    }
                }
                // Newton did not converge: a rejected step, retried at a quarter.
                Err(_) if h > floor => {
                    let es = self.esdirk.as_mut().expect("made by esdirk_step");
                    es.stats.rejected += 1;
                    es.rejected_last = true;
                    es.h_next = h / 4.0;
                    Ok(())
                }
                Err(_) if model.newton.fallback => {
                    // First order, without an estimate: counted apart.
                    self.stats.fallbacks += 1;
                    self.step(model, dynamics, &mut cur, h);
                    self.refresh = true;
                    self.keep_dense(&saved, h, true);
                    let es = self.esdirk.as_mut().expect("made by esdirk_step");
                    es.stats.smallest_step = es.stats.smallest_step.min(h);
                    accepted(&cur, h, dynamics, Evaluated::No);
                    Ok(())
                }
                Err(e) => Err(format!("{e} {}", too_small(h, largest).unwrap_or_default())),
            };
            self.esdirk.as_mut().expect("made").saved = Some(saved);
            result?;
        }
        self.hand_out(model, dynamics, cur, state, t_end, big);
        Ok(())
    }

    /// The state the integrator goes on from towards the frame `big` [s]
    /// after `state`: its own, past `state`, when its last step crossed the
    /// frame that `state` was interpolated at and `state` is still that
    /// frame (nothing changed it since); else `state`.
    fn own_state(&mut self, state: &State, big: f64) -> State {
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        let unchanged = |handed: &State| handed.is_at(state, 1e-9 * big);
        let handed = es.handed.get_or_insert_with(|| state.clone());
        match es.ahead.take() {
            Some(ahead) if es.handed_valid && unchanged(handed) => ahead,
            ahead => {
                let mut fresh = ahead.unwrap_or_else(|| state.clone());
                fresh.clone_from(state);
                fresh
            }
        }
    }

    /// Sets `state` to the frame at `t_end` [s]: the integrator's state
    /// `cur` if it ends there, else interpolated within the last step, with
    /// the forces evaluated there (as after a step that ends there: the
    /// run's drive work reads them); keeps `cur` to go on from.
    fn hand_out(
        &mut self,
        model: &Model,
        dynamics: &mut Dynamics,
        cur: State,
        state: &mut State,
        t_end: f64,
        big: f64,
    ) {
        let exact = (cur.t - t_end).abs() <= 1e-12 * big;
        if exact {
            state.clone_from(&cur);
        } else {
            self.interpolate(model, t_end, state);
            dynamics.wrenches_kept(model, state);
        }
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        es.ahead = Some(cur);
        es.handed_valid = !exact;
        if let Some(handed) = es.handed.as_mut().filter(|_| !exact) {
            handed.clone_from(state);
        }
    }

    /// Keeps what [`Self::interpolate`] needs of the step of `h` [s] just
    /// accepted from `start`: the displacement h·Σ b_j·rate_j, the rates and
    /// accelerations at both ends (`linear`: a fallback step, which has no
    /// stages, interpolated linearly).
    fn keep_dense(&mut self, start: &State, h: f64, linear: bool) {
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        let d = &mut es.dense;
        d.h = h;
        d.linear = linear;
        d.start.clone_from(start);
        for k in 0..self.n {
            d.disp[k] = h * self.base[k];
            d.v0[k] = self.v_n[k];
            d.v1[k] = self.v[k];
        }
        if !linear {
            let last = es.tab.last();
            d.rate0.copy_from_slice(&es.rate[0]);
            d.rate1.copy_from_slice(&es.rate[last]);
            d.a0.copy_from_slice(&es.acc[0]);
            d.a1.copy_from_slice(&es.acc[last]);
        }
    }

    /// The state at `t` [s] within the last accepted step, into `out`: cubic
    /// Hermite interpolation of the displacements (from the rates at both
    /// ends; rotations as the rotation vector from the step's start) and of
    /// the velocities (from the accelerations at both ends, the first and
    /// last stages' — the pairs are stiffly accurate, so the last stage's is
    /// the end's), third order in h; the prescribed bodies exactly.
    fn interpolate(&mut self, model: &Model, t: f64, out: &mut State) {
        let es = self.esdirk.take().expect("made by esdirk_step");
        let d = &es.dense;
        let th = ((t - d.start.t) / d.h).clamp(0.0, 1.0);
        let (h00, h10, h01, h11) = if d.linear {
            (1.0 - th, 0.0, th, 0.0)
        } else {
            let (t2, t3) = (th * th, th * th * th);
            (
                2.0 * t3 - 3.0 * t2 + 1.0,
                t3 - 2.0 * t2 + th,
                3.0 * t2 - 2.0 * t3,
                t3 - t2,
            )
        };
        let h = d.h;
        for k in 0..self.n {
            let (mut disp, mut v) = (h01 * d.disp[k], h00 * d.v0[k] + h01 * d.v1[k]);
            if !d.linear {
                disp += h * (h10 * d.rate0[k] + h11 * d.rate1[k]);
                v += h * (h10 * d.a0[k] + h11 * d.a1[k]);
            }
            self.base[k] = disp / h;
            self.v[k] = v;
        }
        self.place_stage(model, &es.dense.start, out, t, h);
        self.esdirk = Some(es);
    }

    /// Whether the step of `h` [s] just taken with error norm `err` is
    /// accepted (counted); proposes the next step by the PI controller
    /// (`proposed`: the step the controller had asked for before
    /// `simulation.max_step` shortened it).
    fn control(&mut self, h: f64, proposed: f64, err: f64) -> bool {
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        let err_floor = err.max(1e-10);
        if err <= 1.0 {
            let mut factor = SAFETY * err_floor.powf(-K_PRESENT) * es.err_last.powf(K_LAST);
            factor = factor.clamp(SHRINK_MIN, GROW_MAX);
            if es.rejected_last {
                factor = factor.min(1.0);
            }
            // A step shortened to `max_step`, and still growing, keeps the
            // pace the controller had set.
            es.h_next = if h < proposed && factor >= 1.0 {
                (h * factor).max(proposed)
            } else {
                h * factor
            };
            es.err_last = err.max(1e-4);
            es.rejected_last = false;
            es.stats.weighted_error += err;
            self.note_accepted(h);
            true
        } else {
            es.stats.rejected += 1;
            es.rejected_last = true;
            es.h_next = h * (SAFETY * err.powf(-1.0 / 3.0)).max(SHRINK_MIN);
            false
        }
    }

    /// Counts an accepted step of `h` [s] and adds its error estimate.
    fn note_accepted(&mut self, h: f64) {
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        es.stats.accepted += 1;
        es.stats.smallest_step = es.stats.smallest_step.min(h);
        let largest = |e: &[f64]| e.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        es.stats.position_error += largest(&es.err_x);
        es.stats.velocity_error += largest(&es.err_v);
    }

    /// One step of the ESDIRK pair of `h` seconds, not split; on success
    /// `state` is the last stage's state and the error estimates are set.
    pub(super) fn esdirk_single(
        &mut self,
        model: &Model,
        dynamics: &mut Dynamics,
        state: &mut State,
        h: f64,
    ) -> Result<(), StageFailure> {
        let tab = self.esdirk.as_ref().expect("made by esdirk_step").tab;
        if self.n == 0 {
            dynamics.note_unintegrated(model, state);
            if model.tolerance.is_none() {
                dynamics.note_accepted(state.t, h, tab.weights(), tab.last());
            }
            state.t += h;
            model.prescribe(state.t, state);
            return Ok(());
        }
        self.first_stage(model, dynamics, state, h);
        // A rate measured in an earlier step (or attempt) is no longer this step's.
        self.theta_step = None;
        let mut stage = self.stage.take().unwrap_or_else(|| state.clone());
        self.v.copy_from_slice(&self.v_n);
        if !model.newton.reuse_jacobian {
            self.refresh = true;
        }
        let mut worst = 0;
        let mut result = Ok(());
        for (s, c) in tab.c.iter().enumerate().take(tab.stages).skip(1) {
            self.known_parts(s, h);
            self.predict(s, h);
            let t_stage = state.t + c * h;
            match self.newton(model, dynamics, state, &mut stage, s, t_stage, h) {
                Ok(iterations) => worst = worst.max(iterations),
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
            dynamics.note_stage(s);
            self.finish_stage(s, h);
        }
        self.refresh = result.is_err() || worst > model.newton.reuse_iterations;
        if result.is_ok() {
            self.estimate(h);
            std::mem::swap(state, &mut stage);
            state.t = stage.t + h;
            model.prescribe(state.t, state);
            stage.clone_from(state);
            let es = self.esdirk.as_mut().expect("made by esdirk_step");
            es.end_acc.copy_from_slice(&es.acc[tab.last()]);
            state.copy_into(&mut es.known_end);
            if model.tolerance.is_none() {
                self.note_accepted(h);
                dynamics.note_accepted(state.t - h, h, tab.weights(), tab.last());
            }
        }
        self.stage = Some(stage);
        result
    }

    /// Stage 1: v_n, and A_1 = M⁻¹(f − ω×I_wω) at the start, from a force
    /// evaluation only where it is not known already (first same as last):
    /// at the end of the step just taken, A_1 is that step's last stage's
    /// (the pairs are stiffly accurate: the last stage is the new start, and
    /// its A solves its stage equation, M·A = f − ω×I_wω there, to Newton's
    /// tolerance);
    /// at the start of a step retried smaller, it is the A_1 of the attempt
    /// before. Laws with memory latch their onsets at every start
    /// ([`Mode::Commit`]), so those scenes evaluate at every start.
    fn first_stage(&mut self, model: &Model, dynamics: &mut Dynamics, state: &State, h: f64) {
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        let memory = dynamics.has_memory();
        let at = |kept: &Option<State>| kept.as_ref().is_some_and(|k| k.is_at(state, 1e-9 * h));
        if !memory && at(&es.known_end) {
            es.acc[0].copy_from_slice(&es.end_acc);
            dynamics.note_same_stage(es.tab.last(), 0);
        } else if memory || !at(&es.known_start) {
            self.explicit_stage(model, dynamics, state);
            dynamics.note_stage(0);
        }
        self.gather(model, state);
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        es.rate[0].copy_from_slice(&self.v_n);
        state.copy_into(&mut es.known_start);
    }

    fn explicit_stage(&mut self, model: &Model, dynamics: &mut Dynamics, state: &State) {
        dynamics.wrenches(model, state, Mode::Commit);
        self.gather(model, state);
        self.euler_rhs(model, dynamics, state, 1.0);
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        for &i in &model.integrated {
            let (off, basis) = self.dofs[i].expect("integrated");
            let body = &model.bodies[i];
            match (basis, body.motion) {
                (Basis::Axis(_), Motion::Spin { inertia, .. }) => {
                    es.acc[0][off] = self.rhs[off] / inertia;
                }
                (Basis::Slide(_), Motion::Spin { inertia, .. }) => {
                    es.acc[0][off] = self.rhs[off] / body.mass;
                    es.acc[0][off + 1] = self.rhs[off + 1] / inertia;
                }
                (Basis::Axis(_) | Basis::Slide(_), _) => {
                    unreachable!("only spin bodies have an axis basis")
                }
                (Basis::Full, _) => {
                    let r = state.rot[i].to_rotation_matrix();
                    let inv = r.matrix()
                        * crate::math::Mat3::from_diagonal(&body.inertia.map(|x| 1.0 / x))
                        * r.matrix().transpose();
                    let tau = Vec3::new(self.rhs[off + 3], self.rhs[off + 4], self.rhs[off + 5]);
                    let alpha = inv * tau;
                    for c in 0..3 {
                        es.acc[0][off + c] = self.rhs[off + c] / body.mass;
                        es.acc[0][off + 3 + c] = alpha[c];
                    }
                }
            }
        }
    }

    /// The known parts of stage `s`: h·Σ_{j<s} a_sj·A_j and Σ_{j<s} a_sj·rate_j.
    fn known_parts(&mut self, s: usize, h: f64) {
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        es.solving = s;
        for k in 0..self.n {
            let (mut dv, mut dx) = (0.0, 0.0);
            for (j, a) in es.tab.a[s].iter().enumerate().take(s) {
                dv += a * es.acc[j][k];
                dx += a * es.rate[j][k];
            }
            self.known_dv[k] = h * dv;
            es.known_disp[k] = dx;
        }
    }

    /// The first Newton iterate of stage `s`: V_s = v_n + known_dv +
    /// γh·A_s, A_s extrapolated linearly in time from the last two stages
    /// (stage 2: A_1). Starting from the last stage's V instead costs about
    /// 0.4 more iterations per stage on the paper's scene (2.53 against
    /// 2.14 over 0.6 s; docs/performance.md).
    fn predict(&mut self, s: usize, h: f64) {
        let es = self.esdirk.as_ref().expect("made by esdirk_step");
        let (c, gh) = (&es.tab.c, es.tab.gamma * h);
        let (w_last, w_before) = if s == 1 {
            (1.0, 0.0)
        } else {
            let slope = (c[s] - c[s - 1]) / (c[s - 1] - c[s - 2]);
            (1.0 + slope, -slope)
        };
        for k in 0..self.n {
            let a = if s == 1 {
                es.acc[0][k]
            } else {
                w_last * es.acc[s - 1][k] + w_before * es.acc[s - 2][k]
            };
            self.v[k] = self.v_n[k] + self.known_dv[k] + gh * a;
        }
    }

    /// A_s and rate_s of the converged stage `s` (its rates were left in
    /// `rate[s]` by the last [`Self::esdirk_base`]).
    fn finish_stage(&mut self, s: usize, h: f64) {
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        let gh = es.tab.gamma * h;
        for k in 0..self.n {
            es.acc[s][k] = (self.v[k] - self.v_n[k] - self.known_dv[k]) / gh;
        }
    }

    /// The error estimates h·Σ_j (b_j − d_j)·(rate_j, A_j).
    fn estimate(&mut self, h: f64) {
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        let tab = es.tab;
        for k in 0..self.n {
            let (mut ex, mut ev) = (0.0, 0.0);
            for j in 0..tab.stages {
                ex += (tab.b[j] - tab.d[j]) * es.rate[j][k];
                ev += (tab.b[j] - tab.d[j]) * es.acc[j][k];
            }
            es.err_x[k] = h * ex;
            es.err_v[k] = h * ev;
        }
    }

    /// The displacement weights of the stage being solved, into `base`:
    /// Σ_{j<i} a_ij·rate_j + γ·rate_i, rate_i = V_i, or for a free body's
    /// rotation K_i = dexp⁻¹_{−ξ_i}(ω_i) with ξ_i = h·base (fixed point).
    pub(super) fn esdirk_base(&mut self, model: &Model, h: f64) {
        let es = self.esdirk.as_mut().expect("made by esdirk_step");
        let (s, gamma) = (es.solving, es.tab.gamma);
        for k in 0..self.n {
            es.rate[s][k] = self.v[k];
            self.base[k] = es.known_disp[k] + gamma * self.v[k];
        }
        for &i in &model.integrated {
            let (off, basis) = self.dofs[i].expect("integrated");
            if basis != Basis::Full {
                continue;
            }
            let w = Vec3::new(self.v[off + 3], self.v[off + 4], self.v[off + 5]);
            let known = Vec3::new(
                es.known_disp[off + 3],
                es.known_disp[off + 4],
                es.known_disp[off + 5],
            );
            let mut rate = w;
            for _ in 0..DEXP_ITERATIONS {
                let xi = h * (known + gamma * rate);
                rate = dexp_inv(&-xi, &w);
            }
            for c in 0..3 {
                es.rate[s][off + 3 + c] = rate[c];
                self.base[off + 3 + c] = known[c] + gamma * rate[c];
            }
        }
    }

    /// The weighted RMS norm of the last step's error estimate,
    /// ‖e/(atol + rtol·|y|)‖ over positions [m], rotations [rad, |y| = 1],
    /// velocities [m/s] and angular velocities [rad/s], each with its own
    /// atol, |y| the larger of the component's magnitudes at `start` and
    /// `end`.
    fn error_norm(&self, model: &Model, start: &State, end: &State, tol: &Tolerance) -> f64 {
        let es = self.esdirk.as_ref().expect("made by esdirk_step");
        let (mut sum, mut count) = (0.0, 0usize);
        let mut add = |e: f64, atol: f64, y: f64| {
            let w = e / (atol + tol.rtol * y);
            sum += w * w;
            count += 1;
        };
        let larger = |k: usize| self.v_n[k].abs().max(self.v[k].abs());
        for &i in &model.integrated {
            let (off, basis) = self.dofs[i].expect("integrated");
            let (x0, x1) = (start.pos[i], end.pos[i]);
            match basis {
                Basis::Axis(_) => {
                    add(es.err_x[off], tol.rotation, 1.0);
                    add(es.err_v[off], tol.angular_velocity, larger(off));
                }
                Basis::Slide(axis) => {
                    let y = x0.dot(&axis).abs().max(x1.dot(&axis).abs());
                    add(es.err_x[off], tol.position, y);
                    add(es.err_x[off + 1], tol.rotation, 1.0);
                    add(es.err_v[off], tol.velocity, larger(off));
                    add(es.err_v[off + 1], tol.angular_velocity, larger(off + 1));
                }
                Basis::Full => {
                    for c in 0..3 {
                        add(
                            es.err_x[off + c],
                            tol.position,
                            x0[c].abs().max(x1[c].abs()),
                        );
                        add(es.err_x[off + 3 + c], tol.rotation, 1.0);
                        add(es.err_v[off + c], tol.velocity, larger(off + c));
                        let k = off + 3 + c;
                        add(es.err_v[k], tol.angular_velocity, larger(k));
                    }
                }
            }
        }
        if count == 0 {
            0.0
        } else {
            (sum / count as f64).sqrt()
        }
    }
}

/// Why a step of `h` [s] cannot be made smaller within the largest step
/// `big` [s], if it cannot.
fn too_small(h: f64, big: f64) -> Option<String> {
    (h <= MIN_STEP_FRACTION * big).then(|| {
        format!(
            "(with the adaptive step reduced to {h:.3e} s, 1/{} of the largest step or less)",
            (1.0 / MIN_STEP_FRACTION) as u64
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Σ_j w_j·f(j) over the tableau's stages.
    fn dot(tab: &Tableau, w: &[f64; 4], f: &dyn Fn(usize) -> f64) -> f64 {
        (0..tab.stages).map(|j| w[j] * f(j)).sum()
    }

    /// The order conditions up to 3 that the weights `w` meet: 0 to 3.
    fn order_of(tab: &Tableau, w: &[f64; 4]) -> u32 {
        let c = &tab.c;
        let ac = |j: usize| (0..tab.stages).map(|k| tab.a[j][k] * c[k]).sum::<f64>();
        let conditions = [
            (dot(tab, w, &|_| 1.0), 1.0),
            (dot(tab, w, &|j| c[j]), 0.5),
            (dot(tab, w, &|j| c[j] * c[j]), 1.0 / 3.0),
            (dot(tab, w, &ac), 1.0 / 6.0),
        ];
        let holds: Vec<bool> = conditions
            .iter()
            .map(|(x, want)| (x - want).abs() < 1e-15)
            .collect();
        match holds.as_slice() {
            [true, true, true, true] => 3,
            [true, true, ..] => 2,
            [true, ..] => 1,
            _ => 0,
        }
    }

    #[test]
    fn the_tableaus_are_consistent() {
        // Row sums are c; the order conditions of b and d (ESDIRK3(2): 3
        // and 2; TR-BDF2: 2 and 3); stage order 2; stiffly accurate (the
        // last row of A is b); TR-BDF2's γ is SDIRK2's.
        let pairs = [
            (&ESDIRK32, IntegratorKind::Esdirk32, 3, 2),
            (&TRBDF2, IntegratorKind::Trbdf2, 2, 3),
        ];
        for (tab, kind, order_b, order_d) in pairs {
            let name = tab.name;
            // What the scene reports of it: its order and implicit stages.
            assert_eq!(kind.order(), order_b, "{name}");
            assert_eq!(kind.newton_stages(), Some(tab.last() as u32), "{name}");
            for s in 0..tab.stages {
                let row: f64 = tab.a[s].iter().sum();
                assert!((row - tab.c[s]).abs() < 1e-15, "{name} row {s}: {row}");
                let ac: f64 = (0..tab.stages).map(|k| tab.a[s][k] * tab.c[k]).sum();
                let c = tab.c[s];
                assert!((ac - c * c / 2.0).abs() < 1e-15, "{name} stage {s}");
            }
            assert_eq!(order_of(tab, &tab.b), order_b, "{name}: b");
            assert_eq!(order_of(tab, &tab.d), order_d, "{name}: d");
            assert_eq!(tab.a[tab.last()], tab.b, "{name}");
            for (j, &(stage, w)) in tab.weights().iter().enumerate() {
                assert_eq!((stage, w), (j, tab.b[j]), "{name}");
            }
            assert_eq!(tab.a[1][1], tab.gamma, "{name}");
        }
        let sdirk2 = 1.0 - std::f64::consts::FRAC_1_SQRT_2;
        assert!((TRBDF2.gamma - sdirk2).abs() < 1e-16);
        assert!((TRBDF2_W - 2f64.sqrt() / 4.0).abs() < 1e-16);
    }

    /// The tableau on the Prothero–Robinson problem y' = λ(y − φ) + φ',
    /// φ = sin t, y(0) = 0 (exact y = sin t), from t = 0 to 1 with `steps`
    /// steps: the error |y(1) − sin 1| and the summed embedded estimate.
    /// Each stage as the engine solves it: A_i = (Y_i − y_n − h·Σ_{j<i} a_ij·A_j)/(γh).
    fn prothero_robinson(tab: &Tableau, lambda: f64, steps: u32) -> (f64, f64) {
        let h = 1.0 / f64::from(steps);
        let (mut y, mut estimate) = (0.0f64, 0.0f64);
        for n in 0..steps {
            let t = f64::from(n) * h;
            let mut f = [0.0; 4];
            f[0] = lambda * (y - t.sin()) + t.cos();
            for s in 1..tab.stages {
                let ts = t + tab.c[s] * h;
                let known = y + h * (0..s).map(|j| tab.a[s][j] * f[j]).sum::<f64>();
                let gh = tab.gamma * h;
                let stage = (known + gh * (-lambda * ts.sin() + ts.cos())) / (1.0 - gh * lambda);
                f[s] = (stage - known) / gh;
            }
            y += h * dot(tab, &tab.b, &|j| f[j]);
            estimate += h * dot(tab, &tab.b, &|j| f[j]) - h * dot(tab, &tab.d, &|j| f[j]);
        }
        ((y - 1f64.sin()).abs(), estimate.abs())
    }

    #[test]
    fn prothero_robinson_converges_where_the_stiff_scale_is_not_resolved() {
        // λ = −1e6 and hλ from −1e4 to −1.25e3: the stiff scale is never
        // resolved. Stiff accuracy and stage order 2 give an error of order
        // h²/|λ| there (ESDIRK3(2): measured 4.2e-12 at h = 0.01, then
        // order 2.00): tiny and converging, ESDIRK3(2)'s order reduced from
        // 3 to 2 (the stage order) and damped by 1/|λ|. The non-stiff
        // problem (λ = −1) shows the classical orders, 3 and 2.
        let cases = [
            (&ESDIRK32, -1e6, 2.0, 1e-10),
            (&ESDIRK32, -1.0, 3.0, 1e-6),
            (&TRBDF2, -1e6, 2.0, 1e-10),
            (&TRBDF2, -1.0, 2.0, 1e-4),
        ];
        for (tab, lambda, order, bound) in cases {
            let errors: Vec<f64> = [100, 200, 400, 800]
                .iter()
                .map(|&n| prothero_robinson(tab, lambda, n).0)
                .collect();
            let p: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
            let name = tab.name;
            eprintln!("{name}, λ = {lambda}: errors {errors:?}, orders {p:?}");
            assert!(errors[0] < bound, "{name}, λ = {lambda}: {errors:?}");
            for p in &p {
                assert!(
                    (p - order).abs() < 0.2,
                    "{name}, λ = {lambda}: order {p:.3} ({errors:?})"
                );
            }
        }
    }

    #[test]
    fn trbdf2_estimates_the_error_of_the_solution_it_goes_on_with() {
        // λ = 0 (y' = cos t, a quadrature: the global error is the sum of
        // the local ones): with a third-order embedded solution the summed
        // estimate is the second-order solution's error up to O(h): within
        // 0.1 % at 800 steps (measured 0.004 %), and closer as h falls.
        let ratio = |n| {
            let (err, est) = prothero_robinson(&TRBDF2, 0.0, n);
            est / err
        };
        let (coarse, fine) = (ratio(200), ratio(800));
        eprintln!("estimate / error: {coarse} at 200 steps, {fine} at 800");
        assert!((fine - 1.0).abs() < 1e-3, "{fine}");
        assert!(
            (fine - 1.0).abs() < (coarse - 1.0).abs(),
            "{coarse} → {fine}"
        );
    }
}
