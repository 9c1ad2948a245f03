//! Fixed-step integrators. They see only states and accelerations, never contacts.
//!
//! Translation is integrated in the world frame. Rotation is integrated on the
//! manifold: the body-frame angular velocity drives a rotation vector ξ with
//! `R = R₀·Exp(ξ)` (Runge–Kutta–Munthe-Kaas), so quaternions never leave the
//! unit sphere by more than round-off.
//!
//! [`IntegratorKind::LinearlyImplicitEuler`], [`IntegratorKind::Sdirk2`] and
//! [`IntegratorKind::Esdirk32`] and [`IntegratorKind::Trbdf2`] ([`implicit`], `esdirk.rs`) also see the
//! Jacobian of the forces, through
//! [`Dynamics::forces_and_jacobian`].

mod blocklu;
mod implicit;
mod sparselu;

pub(crate) use implicit::MIN_STEP_FRACTION;
pub use implicit::{ErrorStats, Stats};

use crate::dynamics::{Accel, Dynamics, Evaluated, Mode};
use crate::math::{Vec3, dexp_inv, exp_map};
use crate::model::{Model, State};
use crate::scene::IntegratorKind;

/// Scratch space of an integrator; allocate once per simulation.
#[derive(Debug, Clone)]
pub struct Workspace {
    acc: [Accel; 4],
    /// Position rates of the stages (velocities) [m/s].
    kx: [Vec<Vec3>; 4],
    /// Rotation-vector rates of the stages [rad/s].
    kq: [Vec<Vec3>; 4],
    stage: State,
    /// The implicit steps' pattern and factorization, built at the first step.
    implicit: Option<Box<implicit::Implicit>>,
}

impl Workspace {
    /// Workspace for `state`'s body count.
    pub fn new(state: &State) -> Self {
        let n = state.pos.len();
        let z = vec![Vec3::zeros(); n];
        Self {
            acc: [
                Accel::zeros(n),
                Accel::zeros(n),
                Accel::zeros(n),
                Accel::zeros(n),
            ],
            kx: [z.clone(), z.clone(), z.clone(), z.clone()],
            kq: [z.clone(), z.clone(), z.clone(), z],
            stage: state.clone(),
            implicit: None,
        }
    }

    /// Linear solves, factorizations and Newton iterations so far (zero for
    /// the explicit integrators).
    pub fn stats(&self) -> Stats {
        self.implicit
            .as_ref()
            .map_or_else(Stats::default, |w| w.stats)
    }

    /// ESDIRK3(2)'s own state at the end of its last step, when the frame
    /// it last handed out was interpolated within that step (`None` for the
    /// other integrators, or when the frame was a step's end).
    pub fn state_ahead_of_frame(&self) -> Option<&State> {
        self.implicit
            .as_ref()
            .and_then(|w| w.state_ahead_of_frame())
    }

    /// What ESDIRK3(2)'s steps and error estimate did so far (`None` for
    /// the other integrators, or before its first step).
    pub fn error_stats(&self) -> Option<ErrorStats> {
        self.implicit.as_ref().and_then(|w| w.error_stats())
    }
}

/// Takes step `n` of the run: advances `state` from t_n = n·dt to
/// t_{n+1} = (n + 1)·dt with the model's integrator and step dt. The
/// integrators own time: a step that succeeds ends with `state.t` set to
/// (n + 1)·dt exactly, so that time does not drift by round-off over a run
/// (the prescribed motions inside the step are evaluated at t_n + dt).
///
/// With adaptive steps, `accepted` sees each step the controller keeps on
/// the way to the frame, at its end: the state there, the step's length
/// [s] and the dynamics ([`Accepted`]). Those steps do not end on the
/// frames, so integrals over the run (work, wear) are summed there, over
/// the integrator's steps, and not over the frames a user chose. A fixed
/// step is itself the one step kept: the caller integrates over it.
///
/// An error says why an implicit step could not be solved (the state is then
/// left at the start of the step, or for SDIRK2 at the end of the last part
/// step that converged). A state that became non-finite is for the caller to
/// detect.
pub fn step(
    model: &Model,
    dynamics: &mut Dynamics,
    ws: &mut Workspace,
    state: &mut State,
    n: u64,
    accepted: &mut Accepted<'_>,
) -> Result<(), String> {
    fn implicit<'a>(ws: &'a mut Workspace, model: &Model) -> &'a mut implicit::Implicit {
        ws.implicit
            .get_or_insert_with(|| Box::new(implicit::Implicit::new(model)))
    }
    let h = model.dt;
    match model.integrator {
        IntegratorKind::SymplecticEuler => symplectic_euler(model, dynamics, ws, state, h),
        IntegratorKind::Rk4 => rk4(model, dynamics, ws, state, h),
        IntegratorKind::LinearlyImplicitEuler => {
            implicit(ws, model).step(model, dynamics, state, h)
        }
        IntegratorKind::Sdirk2 => implicit(ws, model).sdirk2_step(model, dynamics, state, h)?,
        IntegratorKind::Esdirk32 | IntegratorKind::Trbdf2 => {
            implicit(ws, model).esdirk_step(model, dynamics, state, h, accepted)?
        }
    }
    state.t = (n + 1) as f64 * h;
    Ok(())
}

/// What sees each step the integrator keeps ([`step`]): its end state, its
/// length h [s], the dynamics, and whether the dynamics' last evaluation
/// is the one to read for the step's end.
pub type Accepted<'a> = dyn FnMut(&State, f64, &mut Dynamics, Evaluated) + 'a;

/// v ← v + h·a(x, v); x ← x + h·v; R ← R·Exp(h·ω).
fn symplectic_euler(
    model: &Model,
    dynamics: &mut Dynamics,
    ws: &mut Workspace,
    state: &mut State,
    h: f64,
) {
    let acc = &mut ws.acc[0];
    dynamics.accelerations(model, state, Mode::Commit, acc);
    dynamics.note_stage(0);
    dynamics.note_accepted(state.t, h, &[(0, 1.0)], 0);
    for &i in &model.integrated {
        state.vel[i] += h * acc.lin[i];
        state.omega[i] += h * acc.ang[i];
        state.pos[i] += h * state.vel[i];
        state.rot[i] *= exp_map(&(h * state.omega[i]));
        state.rot[i].renormalize_fast();
    }
    state.t += h;
    model.prescribe(state.t, state);
}

/// Classical RK4 in (x, v, ω) with RKMK4 for the rotation vector.
fn rk4(model: &Model, dynamics: &mut Dynamics, ws: &mut Workspace, state: &mut State, h: f64) {
    const C: [f64; 4] = [0.0, 0.5, 0.5, 1.0];
    const W: [f64; 4] = [1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0];
    let Workspace {
        acc, kx, kq, stage, ..
    } = ws;
    for s in 0..4 {
        if s == 0 {
            stage.clone_from(state);
        } else {
            let c = C[s] * h;
            stage.t = state.t + c;
            for &i in &model.integrated {
                stage.pos[i] = state.pos[i] + c * kx[s - 1][i];
                stage.vel[i] = state.vel[i] + c * acc[s - 1].lin[i];
                stage.omega[i] = state.omega[i] + c * acc[s - 1].ang[i];
                let xi = c * kq[s - 1][i];
                stage.rot[i] = state.rot[i] * exp_map(&xi);
                kq[s][i] = dexp_inv(&xi, &stage.omega[i]);
                kx[s][i] = stage.vel[i];
            }
            model.prescribe(stage.t, stage);
        }
        if s == 0 {
            for &i in &model.integrated {
                kx[0][i] = state.vel[i];
                kq[0][i] = state.omega[i];
            }
        }
        let mode = if s == 0 { Mode::Commit } else { Mode::Trial };
        dynamics.accelerations(model, stage, mode, &mut acc[s]);
        dynamics.note_stage(s);
    }
    dynamics.note_accepted(state.t, h, &[(0, W[0]), (1, W[1]), (2, W[2]), (3, W[3])], 3);
    for &i in &model.integrated {
        let mut dx = Vec3::zeros();
        let mut dv = Vec3::zeros();
        let mut dw = Vec3::zeros();
        let mut xi = Vec3::zeros();
        for s in 0..4 {
            dx += W[s] * kx[s][i];
            dv += W[s] * acc[s].lin[i];
            dw += W[s] * acc[s].ang[i];
            xi += W[s] * kq[s][i];
        }
        state.pos[i] += h * dx;
        state.vel[i] += h * dv;
        state.omega[i] += h * dw;
        state.rot[i] *= exp_map(&(h * xi));
        state.rot[i].renormalize_fast();
    }
    state.t += h;
    model.prescribe(state.t, state);
}
