//! Static equilibrium of some bodies among held ones: the local solve of a
//! quasi-static hinge (issue 28's `ball-keys-qs`, whose cage and keys are
//! solved for given poses of head and seat, as a ball bearing's balls are
//! between given rings in the quasi-static models of Jones and Harris).
//!
//! In a run, the model's quasi-static groups ([`crate::model::StaticGroup`])
//! are solved at every force evaluation ([`Groups`], `Dynamics::solve_groups`:
//! Newton on the group's pairs alone with their exact stiffness, a trust
//! region, a centring spring toward each body's kinematic pose, and the
//! free bodies moving with the mean of the held ones), and hand the global
//! Newton iterations the implicit function theorem's stiffness and damping
//! (`condensed_correction`); docs/engine.md, "Quasi-static bodies".
//!
//! [`equilibrium`] (a standalone solve over every pair, for tests) moves the free bodies of a state, the others held, until
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

use crate::dynamics::{
    CouplingJacobian, Dynamics, Mat6, Mode, VelocityJacobian, Weights, evaluate_pair,
};
use crate::math::{Quat, Vec3};
pub use crate::model::StaticDofs;
use crate::model::{Model, State, StaticGroup};

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

/// What the quasi-static groups' solves did over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct GroupStats {
    /// Group solves: one per group per force evaluation, and per handed-out state.
    pub solves: u64,
    /// Their Newton iterations.
    pub iterations: u64,
    /// Solves that did not reach [`GROUP_TOLERANCE`] from the last solution
    /// and were started again from the evaluated state's own poses.
    pub restarts: u64,
    /// Solves that did not reach it from either start (the last iterate kept).
    pub failures: u64,
}

/// When a group's solve within a force evaluation stops: at a net force
/// within 1e-4 N and torque within 3e-6 N·m (the force at a 30 mm arm) on
/// every free body, both scaled up with 1e-8 of the group's largest contact
/// force where that is larger ([`LOAD_FRACTION`]: 1.35e-4 N at the 13.5 kN
/// of a ball key in the paper's hinge), or after a full Newton step (not
/// shortened by the line search) within 1e-11 m and 1e-9 rad; 20 steps.
pub const GROUP_TOLERANCE: StaticTolerance = StaticTolerance {
    translation: 1e-11,
    rotation: 1e-9,
    force: 1e-4,
    torque: 3e-6,
    max_iterations: 20,
};

/// The stiffness [N/m] of a spring that pulls each quasi-static body
/// toward its kinematic pose ([`StaticGroup::kinematic_pose`]; for a
/// body's turn, CENTRING·ARM² N·m/rad). It makes the equilibrium unique
/// where the contacts leave a body free (a key in its clearance, a cage
/// free to turn within its windows' clearance, contacts just touching under
/// the Adams law's δ^2.2, whose stiffness vanishes at contact), so that the
/// forces on the held bodies are a smooth function of their poses, not of
/// where the last solve ended. 1e3 N/m: a key's 0.14 N weight moves it
/// 0.14 mm in its clearance; 1e-5 of the races' stiffness under the paper's
/// 13.5 kN key load (about 1e8 N/m), so a loaded hinge's forces move by
/// about that fraction (measured 7e-6 against the dynamic keys:
/// tests/hinge_closed_forms.rs).
pub const CENTRING: f64 = 1e3;

/// The arm [m] that turns [`CENTRING`] into a rotational stiffness: a
/// cage's radius.
const ARM: f64 = 0.03;

/// The longest move of a free body in one Newton step of its group's
/// solve [m] (a turn: at [`ARM`]): about a key's clearance in its grooves.
/// A body out of contact (or just touching, where the Adams law's δ^2.2
/// gives no stiffness) sees only the centring spring, whose step would
/// carry it far into its contacts; the step is scaled down to this reach.
const REACH: f64 = 2e-5;

/// The fraction of a group's largest contact force its solve's force
/// tolerance grows to, where that exceeds [`GROUP_TOLERANCE`]'s (and the
/// torque tolerance with it): 1e-8.
const LOAD_FRACTION: f64 = 1e-8;

/// The Jacobian blocks a group's solve uses: K alone.
const ONLY_K: Weights = Weights {
    damping: 0.0,
    stiffness: 1.0,
};

/// Halvings of a group's Newton step that made its residual grow.
const GROUP_HALVINGS: u32 = 12;

/// The quasi-static groups of a model as a force evaluation solves them:
/// the last solution (each evaluation starts from it), the state
/// evaluated, and each group's stiffness blocks and condensed Jacobian.
#[derive(Debug, Clone)]
pub(crate) struct Groups {
    /// Each body's last solved pose relative to its kinematic pose (the
    /// offset [m] and the turn; meaningful for quasi-static bodies): the
    /// next solve starts from its kinematic pose there, moved by this.
    solved: Vec<(Vec3, Quat)>,
    /// Whether `solved` holds a solution yet.
    started: bool,
    /// The state evaluated: the caller's, with the groups solved.
    work: Option<Box<State>>,
    /// Per group: one coupling per group pair, K only.
    k: Vec<Vec<CouplingJacobian>>,
    /// Per group: one coupling per group pair, D only.
    d: Vec<Vec<CouplingJacobian>>,
    /// Per group: what its free bodies add to its held bodies' stiffness
    /// and damping ([`condensed_correction`]) at its last solution, when a
    /// Jacobian was asked for.
    condensed: Vec<(DMatrix<f64>, DMatrix<f64>)>,
    pub stats: GroupStats,
}

impl Groups {
    /// Scratch for `model`'s groups; `None` where it has none.
    pub fn new(model: &Model) -> Option<Box<Self>> {
        if model.static_groups.is_empty() {
            return None;
        }
        let coupling = |k: usize| {
            let p = &model.pairs[k];
            CouplingJacobian::zeros(p.a, p.b)
        };
        Some(Box::new(Self {
            solved: vec![(Vec3::zeros(), Quat::identity()); model.bodies.len()],
            started: false,
            work: None,
            k: model
                .static_groups
                .iter()
                .map(|g| g.pairs.iter().map(|&k| coupling(k)).collect())
                .collect(),
            d: model
                .static_groups
                .iter()
                .map(|g| g.pairs.iter().map(|&k| coupling(k)).collect())
                .collect(),
            condensed: model
                .static_groups
                .iter()
                .map(|g| {
                    let n = 6 * g.held.len();
                    (DMatrix::zeros(n, n), DMatrix::zeros(n, n))
                })
                .collect(),
            stats: GroupStats::default(),
        }))
    }
}

/// The couplings a model's groups add to its velocity Jacobian, after its
/// pairs and joints: per group, one per two of its held bodies (one on the
/// body itself where it holds only one), each (a, b).
pub(crate) fn group_couplings(model: &Model) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for g in &model.static_groups {
        let h = &g.held;
        if h.len() == 1 {
            out.push((h[0], h[0]));
        }
        for i in 0..h.len() {
            for j in i + 1..h.len() {
                out.push((h[i], h[j]));
            }
        }
    }
    out
}

impl Dynamics {
    /// Stages 1–3 at `state` with the quasi-static groups solved first
    /// (their bodies' poses from the last solution, solved again for the
    /// held bodies' poses at `state`, their velocities the mean of the held
    /// bodies' rigid motions), and their centring springs' reactions on the
    /// held bodies; with `jac`, what each group adds to its held bodies'
    /// Jacobian, C_D + s·C_K ([`condensed_correction`]), joins its couplings.
    pub(super) fn loads_with_groups(
        &mut self,
        model: &Model,
        state: &State,
        mode: Mode,
        mut jac: Option<&mut VelocityJacobian>,
        mut groups: Box<Groups>,
    ) {
        let mut work = groups
            .work
            .take()
            .unwrap_or_else(|| Box::new(state.clone()));
        (*work).clone_from(state);
        self.solve_groups(model, &mut groups, &mut work, jac.is_some());
        self.loads_at(model, &work, mode, jac.as_deref_mut());
        self.centring_reactions(model, &work);
        if let Some(jac) = jac {
            add_condensed(model, &groups, jac);
        }
        groups.work = Some(work);
        self.groups = Some(groups);
    }

    /// Adds to each held body the reaction of its groups' centring springs
    /// at `state` (a spring pulls a free body toward the mean of the poses
    /// its held bodies carry it to, so each of the n held bodies takes 1/n
    /// of the reverse force, at the point where it carries the free body,
    /// and of the reverse torque): the springs are internal forces, and the
    /// held bodies' momentum balances with them. (Their stiffness, 1e-5 of
    /// the contacts', is left out of the Jacobian.)
    fn centring_reactions(&mut self, model: &Model, state: &State) {
        for group in &model.static_groups {
            let share = 1.0 / group.held.len() as f64;
            for (f, &(i, _)) in group.free.iter().enumerate() {
                let (x, q) = group.kinematic_pose(f, state);
                let pull = CENTRING * (state.pos[i] - x) * share;
                let twist =
                    CENTRING * ARM * ARM * (state.rot[i] * q.inverse()).scaled_axis() * share;
                for (&h, (p, _)) in group.held.iter().zip(&group.carried[f]) {
                    self.force[h] += pull;
                    self.torque[h] += (state.rot[h] * p).cross(&pull) + twist;
                }
            }
        }
    }

    /// Solves the quasi-static groups of `model` at `state` in place (the
    /// held bodies as they are): what a handed-out state carries. The net
    /// wrenches of the last evaluation are left as they were (the drive's
    /// work reads them); its contact points are no longer the kept ones.
    pub fn settle_groups(&mut self, model: &Model, state: &mut State) {
        if let Some(mut groups) = self.groups.take() {
            let wrenches = (self.force.clone(), self.torque.clone());
            self.solve_groups(model, &mut groups, state, false);
            (self.force, self.torque) = wrenches;
            self.kept_valid = false;
            self.groups = Some(groups);
        }
    }

    /// What the groups' solves did so far (`None`: the model has none).
    pub fn group_stats(&self) -> Option<GroupStats> {
        self.groups.as_ref().map(|g| g.stats)
    }

    /// Every group solved in `state`, from the last solution where there is
    /// one, else (and where that fails) from `state`'s own poses; with
    /// `jacobian`, each group's condensed stiffness at its solution.
    fn solve_groups(
        &mut self,
        model: &Model,
        groups: &mut Groups,
        state: &mut State,
        jacobian: bool,
    ) {
        for (g, group) in model.static_groups.iter().enumerate() {
            let own: Vec<(Vec3, Quat)> = group
                .free
                .iter()
                .map(|&(i, _)| (state.pos[i], state.rot[i]))
                .collect();
            if groups.started {
                for (f, &(i, _)) in group.free.iter().enumerate() {
                    let (x, q) = group.kinematic_pose(f, state);
                    let (dx, dq) = groups.solved[i];
                    (state.pos[i], state.rot[i]) = (x + dx, dq * q);
                }
            }
            mean_motion(group, state);
            groups.stats.solves += 1;
            let mut outcome = self.solve_group(model, group, &mut groups.k[g], state);
            if outcome.is_err() && groups.started {
                groups.stats.restarts += 1;
                for (&(i, _), &(p, r)) in group.free.iter().zip(&own) {
                    (state.pos[i], state.rot[i]) = (p, r);
                }
                outcome = self.solve_group(model, group, &mut groups.k[g], state);
            }
            match outcome {
                Ok(n) => groups.stats.iterations += u64::from(n),
                Err(n) => {
                    groups.stats.iterations += u64::from(n);
                    groups.stats.failures += 1;
                }
            }
            for (f, &(i, _)) in group.free.iter().enumerate() {
                let (x, q) = group.kinematic_pose(f, state);
                groups.solved[i] = (state.pos[i] - x, state.rot[i] * q.inverse());
            }
            if jacobian {
                let n: usize = group.free.iter().map(|(_, d)| d.dim()).sum();
                let only_d = Weights {
                    damping: 1.0,
                    stiffness: 0.0,
                };
                self.group_residual(model, group, &mut groups.d[g], state, n, only_d);
                groups.condensed[g] =
                    condensed_correction(group, &groups.k[g], &groups.d[g], state);
            }
        }
        groups.started = true;
    }

    /// Newton's method on the net wrenches of `group`'s free bodies, in
    /// `state`; the steps taken, `Err` where it did not converge. `k` ends
    /// with the stiffness blocks at the last iterate.
    fn solve_group(
        &mut self,
        model: &Model,
        group: &StaticGroup,
        k: &mut [CouplingJacobian],
        state: &mut State,
    ) -> Result<u32, u32> {
        let tol = GROUP_TOLERANCE;
        let (offset, n) = offsets(model, &group.free);
        let mut f = self.group_residual(model, group, k, state, n, ONLY_K);
        for iteration in 0..tol.max_iterations {
            let Some((r, load)) = f.as_ref() else {
                return Err(iteration);
            };
            // The tolerance grows with the group's largest contact force.
            let scale = (load * LOAD_FRACTION / tol.force).max(1.0);
            let (force, torque) = largest_parts(&group.free, &offset, r);
            let (force, torque) = (force / scale, torque / scale);
            if force <= tol.force && torque <= tol.torque {
                return Ok(iteration);
            }
            let kff = gather(group, k, false).0 + centring(&group.free);
            let Some(mut step) = kff.lu().solve(&(-r)) else {
                return Err(iteration);
            };
            // A trust region: no body moves more than REACH in one step.
            let (reach, turn) = largest_parts(&group.free, &offset, &step);
            let longest = reach.max(turn * ARM);
            if longest > REACH {
                step *= REACH / longest;
            }
            let start: Vec<(Vec3, Quat)> = group
                .free
                .iter()
                .map(|&(i, _)| (state.pos[i], state.rot[i]))
                .collect();
            let norm = r.norm();
            let mut scale = 1.0;
            let mut halvings = 0;
            let next = loop {
                for (&(i, _), &(p, q)) in group.free.iter().zip(&start) {
                    (state.pos[i], state.rot[i]) = (p, q);
                }
                displace(state, &group.free, &offset, &(scale * &step));
                let next = self.group_residual(model, group, k, state, n, ONLY_K);
                let better = next.as_ref().is_some_and(|(x, _)| x.norm() <= norm);
                if better || halvings == GROUP_HALVINGS {
                    break next;
                }
                scale *= 0.5;
                halvings += 1;
            };
            f = next;
            let (moved, turned) = largest_parts(&group.free, &offset, &(scale * &step));
            if halvings == 0 && moved <= tol.translation && turned <= tol.rotation && f.is_some() {
                return Ok(iteration + 1);
            }
        }
        Err(tol.max_iterations)
    }

    /// The net wrenches on `group`'s free bodies at `state` (weight and the
    /// group's pairs), stacked as their coordinates are, with the largest
    /// contact force among those pairs [N], and each pair's stiffness into
    /// `k`; `None` if not finite.
    fn group_residual(
        &mut self,
        model: &Model,
        group: &StaticGroup,
        k: &mut [CouplingJacobian],
        state: &State,
        n: usize,
        weights: Weights,
    ) -> Option<(DVector<f64>, f64)> {
        for &(i, _) in &group.free {
            self.force[i] = model.gravity * model.bodies[i].mass;
            self.torque[i] = Vec3::zeros();
        }
        for &i in group.free.iter().map(|(i, _)| i).chain(&group.held) {
            self.omega_world[i] = state.omega_world(i);
        }
        for c in k.iter_mut() {
            c.clear();
        }
        let omega = &self.omega_world;
        self.table.each_listed(&group.pairs, Some(k), |p, slots| {
            evaluate_pair(model, (state, omega), Mode::Trial, p, slots, weights)
        });
        let mut load = 0.0f64;
        for &p in &group.pairs {
            let pair = &model.pairs[p];
            let (points, laws) = self.table.pair(p);
            for (point, (e, _)) in points.iter().zip(laws) {
                let (f, at) = (e.force(point), point.point);
                load = load.max(e.normal_force.abs());
                self.force[pair.b] += f;
                self.torque[pair.b] += (at - state.pos[pair.b]).cross(&f);
                self.force[pair.a] -= f;
                self.torque[pair.a] -= (at - state.pos[pair.a]).cross(&f);
            }
        }
        for (f, &(i, _)) in group.free.iter().enumerate() {
            let (x, q) = group.kinematic_pose(f, state);
            self.force[i] -= CENTRING * (state.pos[i] - x);
            self.torque[i] -= CENTRING * ARM * ARM * (state.rot[i] * q.inverse()).scaled_axis();
        }
        let mut f = DVector::zeros(n);
        let mut at = 0;
        for &(i, dofs) in &group.free {
            let parts = [self.force[i], self.torque[i]];
            for c in 0..dofs.dim() {
                f[at + c] = parts[c / 3][c % 3];
            }
            at += dofs.dim();
        }
        f.iter().all(|x| x.is_finite()).then_some((f, load))
    }
}

/// Each free body's place among the coordinates, by body index, and their number.
fn offsets(
    model: &Model,
    free: &[(usize, StaticDofs)],
) -> (Vec<Option<(usize, StaticDofs)>>, usize) {
    let mut offset = vec![None; model.bodies.len()];
    let mut n = 0;
    for &(body, dofs) in free {
        offset[body] = Some((n, dofs));
        n += dofs.dim();
    }
    (offset, n)
}

/// The centring springs' stiffness over the free coordinates: −CENTRING
/// on each translation, −CENTRING·ARM² on each turn (its dependence on the
/// held bodies, through the kinematic pose, is left out of the Jacobian:
/// 1e-5 of the contacts').
fn centring(free: &[(usize, StaticDofs)]) -> DMatrix<f64> {
    let turns = CENTRING * ARM * ARM;
    let diagonal: Vec<f64> = free
        .iter()
        .flat_map(|&(_, dofs)| (0..dofs.dim()).map(move |c| if c < 3 { -CENTRING } else { -turns }))
        .collect();
    DMatrix::from_diagonal(&DVector::from_vec(diagonal))
}

/// Sets each free body's velocity and angular velocity to the mean of the
/// held bodies' rigid motions at its centre (for a hinge's two links: the
/// cage and keys turn with the bisecting plane, and their slip on each race
/// is half the links' relative motion there).
fn mean_motion(group: &StaticGroup, state: &mut State) {
    let count = group.held.len() as f64;
    for &(i, _) in &group.free {
        let (mut v, mut w) = (Vec3::zeros(), Vec3::zeros());
        for &h in &group.held {
            let wh = state.omega_world(h);
            v += state.vel[h] + wh.cross(&(state.pos[i] - state.pos[h]));
            w += wh;
        }
        state.vel[i] = v / count;
        state.omega[i] = state.rot[i].inverse() * (w / count);
    }
}

/// The blocks of `group`'s pair couplings `c` between its free and held
/// bodies: (ff, fh, hf), the free bodies' rows over their solved
/// coordinates, their columns too, or with `full_columns` over all six of
/// each twist; the held bodies' rows and columns six each, in
/// `group.held`'s order.
fn gather(
    group: &StaticGroup,
    c: &[CouplingJacobian],
    full_columns: bool,
) -> (DMatrix<f64>, DMatrix<f64>, DMatrix<f64>) {
    let (mut rows, mut cols) = (vec![], vec![]);
    let (mut nr, mut nc) = (0, 0);
    for &(i, d) in &group.free {
        let dc = if full_columns { 6 } else { d.dim() };
        rows.push((i, nr, d.dim()));
        cols.push((i, nc, dc));
        nr += d.dim();
        nc += dc;
    }
    let free_row = |b: usize| rows.iter().find(|r| r.0 == b).map(|r| (r.1, r.2));
    let free_col = |b: usize| cols.iter().find(|r| r.0 == b).map(|r| (r.1, r.2));
    let held = |b: usize| group.held.iter().position(|&h| h == b).map(|h| (6 * h, 6));
    let n_held = 6 * group.held.len();
    let (mut ff, mut fh, mut hf) = (
        DMatrix::zeros(nr, nc),
        DMatrix::zeros(nr, n_held),
        DMatrix::zeros(n_held, nc),
    );
    let put = |target: &mut DMatrix<f64>,
               (r0, dr): (usize, usize),
               (c0, dc): (usize, usize),
               m: &Mat6| {
        for r in 0..dr {
            for col in 0..dc {
                target[(r0 + r, c0 + col)] += m[(r, col)];
            }
        }
    };
    for c in c.iter().filter(|c| c.active) {
        for (i, j, m) in [
            (c.a, c.a, &c.aa),
            (c.a, c.b, &c.ab),
            (c.b, c.a, &c.ba),
            (c.b, c.b, &c.bb),
        ] {
            match (free_row(i), free_col(j), held(i), held(j)) {
                (Some(r), Some(col), _, _) => put(&mut ff, r, col, m),
                (Some(r), None, _, Some(col)) => put(&mut fh, r, col, m),
                (None, Some(col), Some(r), _) => put(&mut hf, r, col, m),
                _ => {}
            }
        }
    }
    (ff, fh, hf)
}

/// What `group`'s free bodies add to its held bodies' Jacobian, by the
/// implicit function theorem, from its pairs' stiffness blocks `k` (K) and
/// damping blocks `d` (D) at its solution in `state`: (C_K, C_D), over the
/// held bodies' six coordinates each in `group.held`'s order.
///
/// - C_K = −K_hf·K_ff⁻¹·K_fh: a held body's move moves the free bodies to
///   their new equilibrium (as [`condensed_stiffness`]); K_ff with the
///   centring springs.
/// - C_D = D_hf·T − K_hf·K_ff⁻¹·(D_fh + D_ff·T): the free bodies' twists
///   follow the held bodies' (T, the mean motion), and the forces that
///   their velocities change on the free bodies move them too.
///
/// Zero where K_ff is singular.
fn condensed_correction(
    group: &StaticGroup,
    k: &[CouplingJacobian],
    d: &[CouplingJacobian],
    state: &State,
) -> (DMatrix<f64>, DMatrix<f64>) {
    let n_held = 6 * group.held.len();
    let (kff, kfh, khf) = gather(group, k, false);
    let kff = kff + centring(&group.free);
    let (dff, dfh, dhf) = gather(group, d, true);
    // T: each free twist against the held twists, the mean of the held
    // bodies' rigid motions (v_f = Σ(v_h + ω_h × (x_f − x_h))/n, ω_f = Σω_h/n).
    let mut t = DMatrix::zeros(6 * group.free.len(), n_held);
    let w = 1.0 / group.held.len() as f64;
    for (f, &(i, _)) in group.free.iter().enumerate() {
        for (h, &j) in group.held.iter().enumerate() {
            let arm = (state.pos[i] - state.pos[j]).cross_matrix();
            for c in 0..3 {
                t[(6 * f + c, 6 * h + c)] = w;
                t[(6 * f + 3 + c, 6 * h + 3 + c)] = w;
            }
            let mut v = t.view_mut((6 * f, 6 * h + 3), (3, 3));
            v -= arm * w;
        }
    }
    let n_free = kff.nrows();
    let mut rhs = DMatrix::zeros(n_free, 2 * n_held);
    rhs.view_mut((0, 0), (n_free, n_held)).copy_from(&kfh);
    rhs.view_mut((0, n_held), (n_free, n_held))
        .copy_from(&(dfh + &dff * &t));
    match kff.lu().solve(&rhs) {
        Some(x) if x.iter().all(|v: &f64| v.is_finite()) => (
            -(&khf * x.view((0, 0), (n_free, n_held))),
            dhf * t - &khf * x.view((0, n_held), (n_free, n_held)),
        ),
        _ => (
            DMatrix::zeros(n_held, n_held),
            DMatrix::zeros(n_held, n_held),
        ),
    }
}

/// Adds each group's condensed stiffness, times the Jacobian's stiffness
/// scale, to its couplings ([`group_couplings`]), which follow the pairs'
/// and joints' in `jac`.
fn add_condensed(model: &Model, groups: &Groups, jac: &mut VelocityJacobian) {
    let s = jac.stiffness_scale;
    let mut at = model.pairs.len() + model.joints.len();
    for (group, (ck, cd)) in model.static_groups.iter().zip(&groups.condensed) {
        let h = group.held.len();
        let block = |i: usize, j: usize| -> Mat6 {
            (cd.fixed_view::<6, 6>(6 * i, 6 * j) + s * ck.fixed_view::<6, 6>(6 * i, 6 * j))
                .into_owned()
        };
        let mut diagonal_done = vec![false; h];
        let mut pairs: Vec<(usize, usize)> = (0..h)
            .flat_map(|i| (i + 1..h).map(move |j| (i, j)))
            .collect();
        if h == 1 {
            pairs.push((0, 0));
        }
        for (i, j) in pairs {
            let coupling = &mut jac.couplings[at];
            at += 1;
            coupling.active = true;
            if !diagonal_done[i] {
                coupling.aa += block(i, i);
                diagonal_done[i] = true;
            }
            if i != j {
                coupling.ab += block(i, j);
                coupling.ba += block(j, i);
                if !diagonal_done[j] {
                    coupling.bb += block(j, j);
                    diagonal_done[j] = true;
                }
            }
        }
    }
}
