//! Static equilibrium of some bodies among held ones: the local solve of a
//! quasi-static hinge (issue 28's `ball-keys-qs`, whose cage and keys are
//! solved for given poses of head and seat, as a ball bearing's balls are
//! between given rings in the quasi-static models of Jones and Harris).
//!
//! [`equilibrium`] moves the free bodies of a state, the others held, until
//! the net force and torque on each vanish: Newton's method on the elastic
//! forces, with the stiffness K = ∂(wrench)/∂(pose) that
//! [`Dynamics::forces_and_jacobian`] gives for the implicit integrators (the
//! difference of its blocks at stiffness scales 1 and 0, D + K and D). The
//! free bodies are at rest: their velocities are set to zero, so a
//! regularized friction law carries nothing and the damping only what the
//! held bodies' motion gives it (the hinge's slip from its kinematics is the
//! next step of issue 28, not this one). A ball's turn carries no load
//! without friction, so a body may be free in position only
//! ([`StaticDofs::Position`]).
//!
//! [`condensed_stiffness`] gives what the held bodies feel of the free
//! ones' equilibrium as they move: the Schur complement of the free bodies'
//! stiffness (the implicit function theorem), the Jacobian a quasi-static
//! hinge hands to the global Newton iterations.
//!
//! Each Newton step solves (K_ff − λ·I)·Δ = −f over the free coordinates
//! (K is negative where a force restores, so −λ adds stiffness), λ a 1e-9
//! of K_ff's largest diagonal entry: a direction with no stiffness (a cage
//! free to turn within its windows' clearance) takes a bounded step instead
//! of a singular one. A step that makes the residual (the Euclidean norm of
//! the free bodies' forces and torques) grow is halved, up to
//! `MAX_HALVINGS` times.

use nalgebra::{DMatrix, DVector};

use crate::dynamics::{Dynamics, Mode, VelocityJacobian};
use crate::math::{Quat, Vec3};
use crate::model::{Model, State};

/// Which of a free body's pose coordinates [`equilibrium`] solves for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StaticDofs {
    /// Position and orientation: 6 coordinates.
    Pose,
    /// Position only (a ball, whose turn carries no load without friction):
    /// 3 coordinates.
    Position,
}

impl StaticDofs {
    fn dim(self) -> usize {
        match self {
            Self::Pose => 6,
            Self::Position => 3,
        }
    }
}

/// When [`equilibrium`] stops: after a Newton step within `translation`
/// and `rotation`, or at a residual within `force` and `torque`, whichever
/// comes first. A body whose equilibrium has a contact just touching (a
/// cage free to turn within its windows' clearance comes to rest where the
/// window contacts stop pushing) converges only linearly there: on F = Kδⁿ
/// toward δ = 0 each Newton step leaves (n − 1)/n of δ, 0.55 for the Adams
/// law's n = 2.2, and (0.55)ⁿ ≈ 0.27 of the force, so the residual is the
/// test that ends it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticTolerance {
    /// The largest translation of a Newton step [m].
    pub translation: f64,
    /// The largest rotation of a Newton step [rad].
    pub rotation: f64,
    /// The largest net force on a free body [N].
    pub force: f64,
    /// The largest net torque on a free body [N·m].
    pub torque: f64,
    /// Newton steps allowed.
    pub max_iterations: u32,
}

impl Default for StaticTolerance {
    /// 1e-12 m and 1e-10 rad (a 1e-12 m turn at a 10 mm arm); 1e-4 N and
    /// 1e-6 N·m (1e-4 N at a 10 mm arm): 1e-8 of a ball key's load in the
    /// paper's hinge, and above the evaluation's own noise (a contact of
    /// 3e8 N/m whose geometry is resolved to 1e-12 m); 50 steps.
    fn default() -> Self {
        Self {
            translation: 1e-12,
            rotation: 1e-10,
            force: 1e-4,
            torque: 1e-6,
            max_iterations: 50,
        }
    }
}

/// What [`equilibrium`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticSolve {
    /// Newton steps taken.
    pub iterations: u32,
    /// The largest net force on a free body at the end [N].
    pub force: f64,
    /// The largest net torque on a free body at the end [N·m] (bodies free
    /// in orientation).
    pub torque: f64,
}

/// Halvings of a Newton step that made the residual grow.
const MAX_HALVINGS: u32 = 30;

/// Moves the `free` bodies of `state` (body index and the coordinates
/// solved for) to static equilibrium with the others held, their
/// velocities set to zero. Returns the steps taken and the residual, or
/// why it failed: not converged within `tol.max_iterations`, or a residual
/// that is not finite.
pub fn equilibrium(
    model: &Model,
    dynamics: &mut Dynamics,
    state: &mut State,
    free: &[(usize, StaticDofs)],
    tol: StaticTolerance,
) -> Result<StaticSolve, String> {
    let mut offset = vec![None; model.bodies.len()];
    let mut n = 0;
    for &(body, dofs) in free {
        offset[body] = Some((n, dofs));
        n += dofs.dim();
    }
    for &(body, _) in free {
        state.vel[body] = Vec3::zeros();
        state.omega[body] = Vec3::zeros();
    }
    let mut f = residual(model, dynamics, state, free, n)?;
    for iteration in 1..=tol.max_iterations {
        let (k, _) = partitioned(model, dynamics, state, free, &[]);
        let largest = k.diagonal().iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let damped = &k - DMatrix::identity(n, n) * (1e-9 * largest);
        // K·Δ = −f with K = ∂f/∂q: Δ = −K⁻¹·f.
        let Some(step) = damped.lu().solve(&(-&f)) else {
            return Err(format!(
                "the stiffness of the {} free bodies is singular at Newton step {iteration}",
                free.len()
            ));
        };
        let before = state.clone();
        let mut scale = 1.0;
        let mut halvings = 0;
        let mut next = loop {
            state.clone_from(&before);
            displace(state, free, &offset, &(scale * &step));
            let next = residual(model, dynamics, state, free, n)?;
            if next.norm() <= f.norm() || halvings == MAX_HALVINGS {
                break next;
            }
            scale *= 0.5;
            halvings += 1;
        };
        std::mem::swap(&mut f, &mut next);
        let (moved, turned) = largest_parts(free, &offset, &(scale * &step));
        let (force, torque) = largest_parts(free, &offset, &f);
        if (moved <= tol.translation && turned <= tol.rotation)
            || (force <= tol.force && torque <= tol.torque)
        {
            return Ok(StaticSolve {
                iterations: iteration,
                force,
                torque,
            });
        }
    }
    Err(format!(
        "the {} free bodies did not reach equilibrium within {} Newton steps (net force {:.3e} N)",
        free.len(),
        tol.max_iterations,
        largest_parts(free, &offset, &f).0
    ))
}

/// The stiffness of the `held` bodies' net wrenches against their own
/// poses (world δx and δθ, six coordinates per held body in their order;
/// N/m, N/rad, N·m/m, N·m/rad) with the `free` bodies kept in equilibrium
/// as the held ones move: a quasi-static hinge's Jacobian for the global
/// Newton iterations. By the implicit function theorem, as f_f(q_f, q_h) =
/// 0 holds, δq_f = −K_ff⁻¹·K_fh·δq_h and
///
/// K_c = K_hh − K_hf·K_ff⁻¹·K_fh,
///
/// the Schur complement of the free bodies' stiffness, each block of K over
/// every force on its bodies. `state` should be an equilibrium of the free
/// bodies ([`equilibrium`]); an error where their stiffness is singular.
pub fn condensed_stiffness(
    model: &Model,
    dynamics: &mut Dynamics,
    state: &State,
    free: &[(usize, StaticDofs)],
    held: &[usize],
) -> Result<DMatrix<f64>, String> {
    let (k, n_free) = partitioned(model, dynamics, state, free, held);
    let n_held = k.nrows() - n_free;
    if n_free == 0 {
        return Ok(k);
    }
    let k_fh = k.view((0, n_free), (n_free, n_held)).into_owned();
    let moved = solve_free(&k, n_free, free.len(), k_fh)?;
    Ok(k.view((n_free, n_free), (n_held, n_held)) - k.view((n_free, 0), (n_held, n_free)) * moved)
}

/// K over the `free` bodies' coordinates and then the `held` bodies' poses
/// (6 each) at `state`, and the number of free coordinates.
fn partitioned(
    model: &Model,
    dynamics: &mut Dynamics,
    state: &State,
    free: &[(usize, StaticDofs)],
    held: &[usize],
) -> (DMatrix<f64>, usize) {
    let mut offset = vec![None; model.bodies.len()];
    let mut n = 0;
    let held_poses: Vec<(usize, StaticDofs)> =
        held.iter().map(|&b| (b, StaticDofs::Pose)).collect();
    for &(body, dofs) in free.iter().chain(&held_poses) {
        offset[body] = Some((n, dofs));
        n += dofs.dim();
    }
    let (mut with_k, mut without_k) = (VelocityJacobian::new(model), VelocityJacobian::new(model));
    dynamics.forces_and_jacobian(model, state, Mode::Trial, 0.0, &mut without_k);
    dynamics.forces_and_jacobian(model, state, Mode::Trial, 1.0, &mut with_k);
    (
        stiffness(&with_k, &without_k, &offset, n),
        n - 6 * held.len(),
    )
}

/// K_ff⁻¹·`rhs`, K_ff the leading `n_free` block of `k` (of `bodies` free
/// bodies); an error where it is singular.
fn solve_free(
    k: &DMatrix<f64>,
    n_free: usize,
    bodies: usize,
    rhs: DMatrix<f64>,
) -> Result<DMatrix<f64>, String> {
    k.view((0, 0), (n_free, n_free))
        .into_owned()
        .lu()
        .solve(&rhs)
        .filter(|x| x.iter().all(|v| v.is_finite()))
        .ok_or_else(|| format!("the stiffness of the {bodies} free bodies is singular"))
}

/// The net wrenches on the free bodies at `state`, stacked as their
/// coordinates are (forces [N], then torques [N·m] for a `Pose` body).
fn residual(
    model: &Model,
    dynamics: &mut Dynamics,
    state: &State,
    free: &[(usize, StaticDofs)],
    n: usize,
) -> Result<DVector<f64>, String> {
    dynamics.wrenches(model, state, Mode::Trial);
    let mut f = DVector::zeros(n);
    let mut at = 0;
    for &(body, dofs) in free {
        let parts = [dynamics.forces()[body], dynamics.torques()[body]];
        for c in 0..dofs.dim() {
            f[at + c] = parts[c / 3][c % 3];
        }
        at += dofs.dim();
    }
    if f.iter().all(|x| x.is_finite()) {
        Ok(f)
    } else {
        Err("the net force on a free body is not finite".to_string())
    }
}

/// K over the free coordinates: the blocks of `with_k` (D + K) less those
/// of `without_k` (D), each coupling's four blocks where both ends are free.
fn stiffness(
    with_k: &VelocityJacobian,
    without_k: &VelocityJacobian,
    offset: &[Option<(usize, StaticDofs)>],
    n: usize,
) -> DMatrix<f64> {
    let mut k = DMatrix::zeros(n, n);
    for (c1, c0) in with_k.couplings.iter().zip(&without_k.couplings) {
        let ends = [
            (c1.a, c1.a, c1.aa - c0.aa),
            (c1.a, c1.b, c1.ab - c0.ab),
            (c1.b, c1.a, c1.ba - c0.ba),
            (c1.b, c1.b, c1.bb - c0.bb),
        ];
        for (i, j, block) in ends {
            if let (Some((ri, di)), Some((cj, dj))) = (offset[i], offset[j]) {
                for r in 0..di.dim() {
                    for c in 0..dj.dim() {
                        k[(ri + r, cj + c)] += block[(r, c)];
                    }
                }
            }
        }
    }
    k
}

/// Moves each free body by its part of `step`: its position by the first
/// three, its orientation by the rotation vector of the next three (world
/// frame, R ← Exp(δθ)·R).
fn displace(
    state: &mut State,
    free: &[(usize, StaticDofs)],
    offset: &[Option<(usize, StaticDofs)>],
    step: &DVector<f64>,
) {
    for &(body, dofs) in free {
        let (at, _) = offset[body].expect("a free body");
        state.pos[body] += Vec3::new(step[at], step[at + 1], step[at + 2]);
        if dofs == StaticDofs::Pose {
            let turn = Vec3::new(step[at + 3], step[at + 4], step[at + 5]);
            state.rot[body] = Quat::from_scaled_axis(turn) * state.rot[body];
        }
    }
}

/// The largest translational and rotational parts of `v` over the free
/// bodies (the largest force and torque, for a residual).
fn largest_parts(
    free: &[(usize, StaticDofs)],
    offset: &[Option<(usize, StaticDofs)>],
    v: &DVector<f64>,
) -> (f64, f64) {
    let (mut linear, mut angular) = (0.0f64, 0.0f64);
    for &(body, dofs) in free {
        let (at, _) = offset[body].expect("a free body");
        for c in 0..dofs.dim() {
            if c < 3 {
                linear = linear.max(v[at + c].abs());
            } else {
                angular = angular.max(v[at + c].abs());
            }
        }
    }
    (linear, angular)
}
