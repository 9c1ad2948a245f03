//! Forces and accelerations of the assembled model.
//!
//! Stages of one evaluation, in order:
//! 1. applied loads (gravity, torques) — depend on time only;
//! 2. joint forces of the declared joints — depend on poses and velocities;
//! 3. contact forces of the declared pairs — depend on poses and velocities;
//! 4. accelerations: Newton for translation, Euler's equations with the
//!    gyroscopic term for rotation (body frame), projected onto the spin axis
//!    for `spin` bodies.

use crate::force::friction_force;
use crate::force::joint::twist_axis;
use crate::geometry::{CentreMotion, ContactPoint, PointSink, Rim, Slide};
use crate::math::{Mat3, Vec3};
use crate::model::{ContactPair, Joint, Model, Motion, State};
pub use impulse::{Impulses, PairTotals};
use nalgebra::Vector6;
use table::{ContactTable, PairSlots};

mod impulse;
pub mod quasistatic;
mod table;

/// Accelerations of every body (zero for bodies that are not integrated).
#[derive(Debug, Clone, PartialEq)]
pub struct Accel {
    /// Linear accelerations [m/s²], world frame.
    pub lin: Vec<Vec3>,
    /// Angular accelerations [rad/s²], body frame.
    pub ang: Vec<Vec3>,
}

impl Accel {
    /// Zero accelerations for `n` bodies.
    pub fn zeros(n: usize) -> Self {
        Self {
            lin: vec![Vec3::zeros(); n],
            ang: vec![Vec3::zeros(); n],
        }
    }
}

/// Whether an evaluation may update per-contact memory (latched approach
/// speeds). Only evaluations at accepted states commit; trial stages do not.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    /// At the start of a step: contact onsets are latched.
    Commit,
    /// Intermediate stage: memory is read only.
    Trial,
}

/// Everything known about one contact point after its laws are evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactEval {
    /// The geometric point (convention of [`crate::geometry`]).
    pub point: ContactPoint,
    /// Penetration rate δ̇ [m/s], positive approaching.
    pub depth_rate: f64,
    /// Normal force [N] along the normal: ≥ 0, except at a point of
    /// weight −1 (a level-set minimum of a line contact, where the point
    /// law is subtracted from its pair's): the law times the point's weight.
    pub normal_force: f64,
    /// Tangential (friction) force on body b [N], world frame.
    pub tangential_force: Vec3,
    /// Slip speed |v_t| [m/s].
    pub slip_speed: f64,
}

impl ContactEval {
    /// The point's contact force on body b [N], world frame: F_n·n + F_t
    /// (body a takes the opposite).
    #[inline]
    pub fn force(&self) -> Vec3 {
        self.point.normal * self.normal_force + self.tangential_force
    }

    fn new(point: ContactPoint, law: &PointLaw) -> Self {
        Self {
            point,
            depth_rate: law.depth_rate,
            normal_force: law.normal_force,
            tangential_force: law.tangential_force,
            slip_speed: law.slip_speed,
        }
    }
}

/// Whether the contact points at the end of a step the integrator kept
/// are to be read from the last evaluation ([`Dynamics::last_contact_points`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Evaluated {
    /// The last evaluation was Newton's last iterate of the step's last
    /// stage: the step's end to Newton's tolerance (adaptive steps; no
    /// further evaluation).
    LastIterate,
    /// Not known to be at the step's end: evaluate there (a fixed step, or
    /// an adaptive step taken by the first-order fallback).
    No,
}

/// What the laws of one contact point give: [`ContactEval`] without its
/// point, so that an evaluation does not copy the points (the fields as
/// there).
#[derive(Debug, Clone, Copy, PartialEq)]
struct PointLaw {
    depth_rate: f64,
    normal_force: f64,
    tangential_force: Vec3,
    slip_speed: f64,
}

impl PointLaw {
    /// The point's contact force on body b [N], world frame.
    #[inline]
    fn force(&self, p: &ContactPoint) -> Vec3 {
        p.normal * self.normal_force + self.tangential_force
    }
}

/// Torque of all contact forces on `body` about its centre of mass [N·m],
/// world frame, from the points `evals[k]` of every pair k evaluated at
/// `state` (e.g. by [`Dynamics::contact_points`]).
pub fn contact_torque(
    model: &Model,
    state: &State,
    evals: &[Vec<ContactEval>],
    body: usize,
) -> Vec3 {
    pairs_torque(model, state, evals, 0..model.pairs.len(), body)
}

/// Torque of the contact forces of the pairs `pairs` on `body` about its
/// centre of mass [N·m], world frame, as [`contact_torque`].
pub fn pairs_torque(
    model: &Model,
    state: &State,
    evals: &[Vec<ContactEval>],
    pairs: impl IntoIterator<Item = usize>,
    body: usize,
) -> Vec3 {
    let mut tau = Vec3::zeros();
    for k in pairs {
        let (pair, ev) = (&model.pairs[k], &evals[k]);
        let sign = if pair.b == body {
            1.0
        } else if pair.a == body {
            -1.0
        } else {
            continue;
        };
        for e in ev {
            tau += sign * (e.point.point - state.pos[body]).cross(&e.force());
        }
    }
    tau
}

/// Energy of the system at one instant [J].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Energy {
    /// Kinetic energy of the integrated bodies.
    pub kinetic: f64,
    /// Gravitational potential energy of the integrated bodies, zero at the world origin.
    pub potential_gravity: f64,
    /// Elastic energy stored in the contacts.
    pub potential_contact: f64,
}

impl Energy {
    /// Sum of all parts.
    pub fn total(&self) -> f64 {
        self.kinetic + self.potential_gravity + self.potential_contact
    }
}

/// Force evaluator with its scratch space and per-contact memory.
#[derive(Debug, Clone)]
pub struct Dynamics {
    force: Vec<Vec3>,
    torque: Vec<Vec3>,
    points: Vec<ContactPoint>,
    /// Each body's angular velocity in the world frame at the state being
    /// evaluated [rad/s]: rotated once per body, not once per pair.
    omega_world: Vec<Vec3>,
    /// Every pair's points and laws of the current evaluation, and its
    /// latched approach speeds [m/s] (for laws that latch).
    table: ContactTable,
    /// Threads that evaluate the pairs (`None`: this thread alone).
    pool: Option<std::sync::Arc<rayon::ThreadPool>>,
    /// The state of the last evaluation, when [`Dynamics::wrenches_kept`]
    /// made it (any other evaluation clears it): the recorder and the
    /// energy check read its points and laws instead of evaluating again.
    kept: Option<State>,
    kept_valid: bool,
    /// Number of force evaluations so far.
    pub evaluations: u64,
    /// Deepest penetration and stiffest contact since the last reset.
    pub watch: ContactWatch,
    /// Each pair's impulse as the integrator applied it, when a table
    /// records it ([`Dynamics::track_impulses`]).
    impulses: Option<Impulses>,
    /// The quasi-static groups' solutions and scratch (`None`: the model has none).
    groups: Option<Box<quasistatic::Groups>>,
}

/// What the contact points evaluated since the last
/// [`ContactWatch::reset`] say about divergence and the stable step.
///
/// Each point is linearized (stiffness k = ∂F/∂δ, damping c = ∂F/∂δ̇ plus
/// the friction slope, bounded by the trace of its Jacobian, m the pair's
/// reduced mass); the watch keeps the largest ω² = k/m and ζω = c/2m, so
/// that the per-point cost stays a few multiplications. The step estimates
/// combine the two maxima, which is exact for one dominant contact and
/// conservative otherwise.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactWatch {
    /// The deepest penetration relative to its pair's limit:
    /// (pair, depth [m], depth / limit).
    pub deepest: Option<(usize, f64, f64)>,
    /// The largest ω² = k/m over the points [1/s²], with its pair.
    pub stiffest: (f64, usize),
    /// The largest ζω = c/2m over the points [1/s], with its pair.
    pub dampest: (f64, usize),
}

impl Default for ContactWatch {
    fn default() -> Self {
        Self {
            deepest: None,
            stiffest: (0.0, usize::MAX),
            dampest: (0.0, usize::MAX),
        }
    }
}

impl ContactWatch {
    /// Forgets everything seen.
    pub fn reset(&mut self) {
        *self = Self::default();
    }

    /// Whether a loaded contact point was seen.
    pub fn saw_contact(&self) -> bool {
        self.stiffest.1 != usize::MAX || self.dampest.1 != usize::MAX
    }

    /// Symplectic Euler's stable step h = 2 / (ζω + √(ζ²ω² + ω²)) [s], and
    /// the pair whose term dominates.
    pub fn explicit_step(&self) -> (f64, usize) {
        let (w2, a) = (self.stiffest.0, self.dampest.0);
        let pair = if a * a > w2 {
            self.dampest.1
        } else {
            self.stiffest.1
        };
        (2.0 / (a + (a * a + w2).sqrt()), pair)
    }

    /// The elastic limit 2/ω alone [s] (an integrator implicit in the
    /// damping only), with its pair.
    pub fn elastic_step(&self) -> (f64, usize) {
        (2.0 / self.stiffest.0.sqrt(), self.stiffest.1)
    }

    /// The shortest contact period 2π/ω [s], with its pair.
    pub fn period(&self) -> (f64, usize) {
        (
            std::f64::consts::TAU / self.stiffest.0.sqrt(),
            self.stiffest.1,
        )
    }

    /// Notes a point of pair `k` at penetration `depth` [m] for
    /// [`ContactWatch::deepest`]; geometry only, no force law.
    pub fn see_depth(&mut self, k: usize, pair: &ContactPair, depth: f64) {
        let ratio = depth / pair.depth_limit;
        if ratio > self.deepest.map_or(0.0, |(_, _, r)| r) {
            self.deepest = Some((k, depth, ratio));
        }
    }

    fn see(
        &mut self,
        k: usize,
        pair: &ContactPair,
        depth: f64,
        e: &PointLaw,
        d: &PointDerivatives,
    ) {
        self.see_depth(k, pair, depth);
        if e.normal_force <= 0.0 || !pair.reduced_mass.is_finite() {
            return;
        }
        let inv = 1.0 / pair.reduced_mass;
        let w2 = d.d_depth * inv;
        if w2 > self.stiffest.0 {
            self.stiffest = (w2, k);
        }
        let half_rate = 0.5 * (d.d_rate.max(0.0) + d.friction.trace().abs()) * inv;
        if half_rate > self.dampest.0 {
            self.dampest = (half_rate, k);
        }
    }
}

impl Dynamics {
    /// Scratch and memory sized for `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.bodies.len();
        Self {
            force: vec![Vec3::zeros(); n],
            torque: vec![Vec3::zeros(); n],
            points: Vec::with_capacity(16),
            omega_world: vec![Vec3::zeros(); n],
            // Room for as many points as each pair can report: no
            // allocation when a pair first comes into contact.
            table: ContactTable::new(model),
            // A pool that cannot start leaves the evaluation on this thread:
            // the same results, only slower.
            pool: (model.threads > 1)
                .then(|| {
                    rayon::ThreadPoolBuilder::new()
                        .num_threads(model.threads)
                        .build()
                        .ok()
                })
                .flatten()
                .map(std::sync::Arc::new),
            kept: None,
            kept_valid: false,
            evaluations: 0,
            watch: ContactWatch::default(),
            impulses: None,
            groups: quasistatic::Groups::new(model),
        }
    }

    /// Accelerations of all bodies at `state`.
    pub fn accelerations(&mut self, model: &Model, state: &State, mode: Mode, acc: &mut Accel) {
        self.loads_joints_contacts(model, state, mode, None);
        // 4. accelerations
        for &i in &model.integrated {
            let b = &model.bodies[i];
            let w = state.omega[i];
            match b.motion {
                Motion::Dynamic => {
                    acc.lin[i] = self.force[i] / b.mass;
                    let tau_b = state.rot[i].inverse() * self.torque[i];
                    let iw = b.inertia.component_mul(&w);
                    acc.ang[i] = (tau_b - w.cross(&iw)).component_div(&b.inertia);
                }
                Motion::Spin {
                    axis,
                    axis_body,
                    inertia,
                    slides,
                } => {
                    acc.lin[i] = if slides {
                        axis * (self.force[i].dot(&axis) / b.mass)
                    } else {
                        Vec3::zeros()
                    };
                    acc.ang[i] = axis_body * (self.torque[i].dot(&axis) / inertia);
                }
                Motion::Fixed | Motion::KinematicSpin(_) | Motion::QuasiStatic(_) => {}
            }
        }
    }

    /// Stages 1–3 of an evaluation: net force and torque on every integrated
    /// body (world frame, torques about the centres of mass, no gyroscopic
    /// term); with `jac`, also their velocity Jacobian.
    fn loads_joints_contacts(
        &mut self,
        model: &Model,
        state: &State,
        mode: Mode,
        jac: Option<&mut VelocityJacobian>,
    ) {
        match self.groups.take() {
            None => self.loads_at(model, state, mode, jac),
            Some(groups) => self.loads_with_groups(model, state, mode, jac, groups),
        }
    }

    /// [`Self::loads_joints_contacts`] at `state` as it is (its
    /// quasi-static bodies, if any, where `state` has them).
    fn loads_at(
        &mut self,
        model: &Model,
        state: &State,
        mode: Mode,
        mut jac: Option<&mut VelocityJacobian>,
    ) {
        if let Some(jac) = jac.as_deref_mut() {
            jac.clear();
        }
        self.evaluations += 1;
        self.kept_valid = false;
        // 1. applied loads (prescribed bodies collect only what joints and
        // contacts apply to them: the reaction on a drive)
        for (i, b) in model.bodies.iter().enumerate() {
            self.force[i] = if b.is_integrated() {
                model.gravity * b.mass
            } else {
                Vec3::zeros()
            };
            self.torque[i] = Vec3::zeros();
            self.omega_world[i] = state.omega_world(i);
        }
        for l in &model.torques {
            self.torque[l.body] += l.torque(state.t);
        }
        for l in &model.forces {
            self.force[l.body] += l.force(state.t);
        }
        // 2. joints
        for (n, j) in model.joints.iter().enumerate() {
            let (a, b) = (j.a, j.b);
            let (w, ra, rb) = j.evaluate(state);
            self.force[b] += w.force;
            self.torque[b] += rb.cross(&w.force) + w.torque;
            self.force[a] -= w.force;
            self.torque[a] -= ra.cross(&w.force) + w.torque;
            if let Some(jac) = jac.as_deref_mut() {
                jac.add_joint(model.pairs.len() + n, j, state, (&ra, &rb), &w.force);
            }
        }
        // 3. contacts
        self.contacts(model, state, mode, jac);
    }

    /// Stage 3: each pair on its own (in parallel with a pool), then summed
    /// in the pairs' order, so that the result does not depend on the
    /// number of threads.
    fn contacts(
        &mut self,
        model: &Model,
        state: &State,
        mode: Mode,
        jac: Option<&mut VelocityJacobian>,
    ) {
        let n = model.pairs.len();
        let scale = Weights {
            damping: 1.0,
            stiffness: jac.as_ref().map_or(0.0, |j| j.stiffness_scale),
        };
        let omega = &self.omega_world;
        // A few tasks per thread: enough to balance, few enough to be cheap.
        let chunk = n.div_ceil(4 * self.threads());
        self.table.for_each_pair(
            jac.map(|j| &mut j.couplings[..]),
            self.pool.as_deref(),
            chunk,
            |k, slots| evaluate_pair(model, (state, omega), mode, k, slots, scale),
        );
        for (k, pair) in model.pairs.iter().enumerate() {
            let (points, laws) = self.table.pair(k);
            for (point, (e, d)) in points.iter().zip(laws) {
                self.watch.see(k, pair, point.depth, e, d);
                let (f, p) = (e.force(point), point.point);
                let (a, b) = (pair.a, pair.b);
                self.force[b] += f;
                self.torque[b] += (p - state.pos[b]).cross(&f);
                self.force[a] -= f;
                self.torque[a] -= (p - state.pos[a]).cross(&f);
            }
        }
    }

    /// Threads evaluating the contact pairs (1 without a pool).
    pub fn threads(&self) -> usize {
        self.pool.as_ref().map_or(1, |p| p.current_num_threads())
    }

    /// Whether some pair keeps per-contact memory (latched approach speeds),
    /// which only [`Mode::Commit`] evaluations update.
    pub fn has_memory(&self) -> bool {
        self.table.has_memory()
    }

    /// Net force and torque on every body at `state` (world frame, torques
    /// about the centres of mass, no gyroscopic term), left in
    /// [`Dynamics::forces`] and [`Dynamics::torques`]. For a prescribed body
    /// these are what the joints and contacts apply to it.
    pub fn wrenches(&mut self, model: &Model, state: &State, mode: Mode) {
        self.loads_joints_contacts(model, state, mode, None);
    }

    /// [`Dynamics::wrenches`] at a state that is handed out as a frame, its
    /// points and laws kept for [`Dynamics::all_contact_points`] and
    /// [`Dynamics::energy`] at that state (until the next evaluation).
    pub fn wrenches_kept(&mut self, model: &Model, state: &State) {
        self.wrenches(model, state, Mode::Trial);
        state.copy_into(&mut self.kept);
        self.kept_valid = true;
    }

    /// Integrates each pair's impulse from now on ([`Impulses`]): the
    /// integrators then keep every stage's pair totals.
    pub fn track_impulses(&mut self, model: &Model) {
        self.impulses = Some(Impulses::new(model.pairs.len()));
    }

    /// Each pair's cumulative impulse [N·s] at `t` [s] into `out`
    /// ([`Impulses::at`]); empty when not tracked.
    pub fn impulses_at(&self, t: f64, out: &mut Vec<PairTotals>) {
        match &self.impulses {
            Some(i) => i.at(t, out),
            None => out.clear(),
        }
    }

    /// Each pair's ∫F² dt of both totals since t = 0 [N²·s] at `t`
    /// ([`Impulses::squares_at`]; empty when impulses are not tracked).
    pub fn squares_at(&self, t: f64, out: &mut Vec<PairTotals>) {
        match &self.impulses {
            Some(i) => i.squares_at(t, out),
            None => out.clear(),
        }
    }

    /// Each pair's largest totals [N] at any stage of the steps accepted
    /// since the last call ([`Impulses::take_peaks`]; −∞ where none, empty
    /// when impulses are not tracked).
    pub fn take_peaks(&mut self, out: &mut Vec<PairTotals>) {
        match &mut self.impulses {
            Some(i) => i.take_peaks(out),
            None => out.clear(),
        }
    }

    /// The last evaluation was stage `s`'s last ([`Impulses::take_stage`]).
    pub(crate) fn note_stage(&mut self, s: usize) {
        if let Some(i) = &mut self.impulses {
            i.take_stage(s, &self.table);
        }
    }

    /// A step with nothing to integrate (only prescribed bodies move)
    /// starts at `state`: when impulses are tracked, the forces there are
    /// every stage's (the impulse is the start's force times the step).
    pub(crate) fn note_unintegrated(&mut self, model: &Model, state: &State) {
        if self.impulses.is_some() {
            self.wrenches(model, state, Mode::Trial);
            for s in 0..impulse::STAGES {
                self.note_stage(s);
            }
        }
    }

    /// Stage `to` has stage `from`'s forces ([`Impulses::copy_stage`]).
    pub(crate) fn note_same_stage(&mut self, from: usize, to: usize) {
        if let Some(i) = &mut self.impulses {
            i.copy_stage(from, to);
        }
    }

    /// A step of `h` [s] from `t0` [s] was accepted ([`Impulses::accept`]).
    pub(crate) fn note_accepted(&mut self, t0: f64, h: f64, weights: &[(usize, f64)], last: usize) {
        if let Some(i) = &mut self.impulses {
            i.accept(t0, h, weights, last);
        }
    }

    /// Whether the last evaluation was [`Dynamics::wrenches_kept`] at
    /// `state` (its time rounded by the caller: the points and laws do not
    /// depend on the time).
    fn kept_at(&self, state: &State) -> bool {
        self.kept_valid
            && self
                .kept
                .as_ref()
                .is_some_and(|k| k.is_at(state, 1e-12 * state.t.abs().max(1.0)))
    }

    /// Forces and their velocity Jacobian at `state`, for implicit integrators.
    ///
    /// One force evaluation through the same path as
    /// [`Dynamics::accelerations`] (same loads, joints, contact points and
    /// laws, same latching in [`Mode::Commit`]); it leaves the net force and
    /// torque on every integrated body in [`Dynamics::forces`] and
    /// [`Dynamics::torques`] (no gyroscopic term) and fills `jac` with
    /// D = ∂(wrench)/∂(twist) of the velocity-dependent joint and contact
    /// forces, the geometry (points, normals, depths, joint axes) and latched
    /// approach speeds held fixed. See [`VelocityJacobian`] for the layout.
    ///
    /// With `stiffness_scale` s > 0 the blocks hold D + s·K instead, K the
    /// stiffness (position Jacobian) of the same forces: the Jacobian with
    /// respect to the velocities when the positions move with them as
    /// x = x₀ + s·v (an implicit stage of weight s). K holds the normal
    /// stiffness of each contact point (∂F_n/∂δ along the normal, with the
    /// friction it carries), the joint springs, and the geometric terms of
    /// the normal forces and the joint springs: normals turning across the
    /// curved surfaces and with the bodies, lever arms turning with the
    /// bodies, contact points sliding along a link, a ring or a rim, or
    /// with a link's section across a tube's end plane
    /// ([`crate::geometry::NormalTurning`]). Left out: the friction force's
    /// turning, the damping and slip's dependence on the pose (both vanish
    /// at rest) and the twist spring's axis turning (tests/jacobian.rs:
    /// every pair kind within 6e-8 of finite differences at rest, the
    /// ideal-CV joints within 1.2e-4).
    pub fn forces_and_jacobian(
        &mut self,
        model: &Model,
        state: &State,
        mode: Mode,
        stiffness_scale: f64,
        jac: &mut VelocityJacobian,
    ) {
        jac.stiffness_scale = stiffness_scale;
        self.loads_joints_contacts(model, state, mode, Some(jac));
    }

    /// Net force on each body [N], world frame, from the last evaluation.
    /// Only the entries of integrated bodies are meaningful.
    pub fn forces(&self) -> &[Vec3] {
        &self.force
    }

    /// Net torque on each body about its centre of mass [N·m], world frame,
    /// from the last evaluation; see [`Dynamics::forces`].
    pub fn torques(&self) -> &[Vec3] {
        &self.torque
    }

    /// Evaluates the contact points of pair `k` at `state` without touching
    /// the memory, for recording.
    pub fn contact_points(
        &mut self,
        model: &Model,
        state: &State,
        k: usize,
        out: &mut Vec<ContactEval>,
    ) {
        let pair = &model.pairs[k];
        self.points.clear();
        let mut points = std::mem::take(&mut self.points);
        find_points(model, pair, state, &mut points);
        out.extend(
            points
                .iter()
                .map(|p| evaluate_point(state, pair, p, self.table.latched(k))),
        );
        self.points = points;
    }

    /// Every pair's contact points at `state` (`out[k]` for pair k, each
    /// cleared first), as [`Dynamics::contact_points`] gives them: read from
    /// the last evaluation where it was kept at `state`, the same to the bit.
    pub fn all_contact_points(
        &mut self,
        model: &Model,
        state: &State,
        out: &mut [Vec<ContactEval>],
    ) {
        if self.kept_at(state) {
            self.last_contact_points(out);
            return;
        }
        for (k, out) in out.iter_mut().enumerate() {
            out.clear();
            self.contact_points(model, state, k, out);
        }
    }

    /// Every pair's contact points as the last evaluation found them, at
    /// whatever state that was (`out[k]` for pair k, each cleared first).
    pub fn last_contact_points(&self, out: &mut [Vec<ContactEval>]) {
        for (k, out) in out.iter_mut().enumerate() {
            out.clear();
            let (points, laws) = self.table.pair(k);
            out.extend(
                points
                    .iter()
                    .zip(laws)
                    .map(|(p, (law, _))| ContactEval::new(*p, law)),
            );
        }
    }

    /// Kinetic, gravitational and elastic contact energy at `state` (the
    /// contact points read from the last evaluation where it was kept at
    /// `state`).
    pub fn energy(&mut self, model: &Model, state: &State) -> Energy {
        if !self.kept_at(state) {
            return energy_of(model, state, &mut self.points);
        }
        let mut e = bodies_energy(model, state);
        for (k, pair) in model.pairs.iter().enumerate() {
            e.potential_contact += elastic_energy(pair, self.table.pair(k).0);
        }
        e
    }
}

/// Body `i`'s kinetic and gravitational potential energy [J] at `state`.
pub fn body_energy(model: &Model, state: &State, i: usize) -> (f64, f64) {
    let (b, w) = (&model.bodies[i], state.omega[i]);
    let kinetic =
        0.5 * b.mass * state.vel[i].norm_squared() + 0.5 * w.dot(&b.inertia.component_mul(&w));
    (kinetic, -b.mass * model.gravity.dot(&state.pos[i]))
}

/// The first contact pair whose elastic energy at `state` is not finite.
pub fn pair_with_infinite_energy<'m>(model: &'m Model, state: &State) -> Option<&'m ContactPair> {
    let mut points = Vec::new();
    model.pairs.iter().find(|pair| {
        find_points(model, pair, state, &mut points);
        !points
            .iter()
            .map(|p| p.weight * pair.normal.elastic_energy(p.depth))
            .sum::<f64>()
            .is_finite()
    })
}

/// The energy of `state` (see [`Dynamics::energy`]), with `points` as the
/// contact points' scratch buffer: no [`Dynamics`] (and no thread pool) needed.
pub fn energy_of(model: &Model, state: &State, points: &mut Vec<ContactPoint>) -> Energy {
    let mut e = bodies_energy(model, state);
    for pair in &model.pairs {
        find_points(model, pair, state, points);
        e.potential_contact += elastic_energy(pair, points);
    }
    e
}

/// The bodies' kinetic and gravitational energy at `state`, no contact
/// energy yet.
fn bodies_energy(model: &Model, state: &State) -> Energy {
    let mut kinetic = 0.0;
    let mut potential_gravity = 0.0;
    for &i in &model.integrated {
        let (k, g) = body_energy(model, state, i);
        kinetic += k;
        potential_gravity += g;
    }
    // Quasi-static bodies: no inertia in the dynamics, but their weight.
    for group in &model.static_groups {
        for &(i, _) in &group.free {
            potential_gravity += body_energy(model, state, i).1;
        }
    }
    Energy {
        kinetic,
        potential_gravity,
        potential_contact: 0.0,
    }
}

/// The elastic energy of `pair`'s contact `points` [J].
fn elastic_energy(pair: &ContactPair, points: &[ContactPoint]) -> f64 {
    points
        .iter()
        .map(|p| p.weight * pair.normal.elastic_energy(p.depth))
        .sum()
}

/// Stage 3 for pair `k`, on its own: finds its points into its `slots`,
/// latches onsets in [`Mode::Commit`], evaluates the laws and, with the
/// slots' coupling, fills the pair's Jacobian blocks (their damping and
/// stiffness weighted by `scale`).
#[inline]
fn evaluate_pair(
    model: &Model,
    (state, omega_world): (&State, &[Vec3]),
    mode: Mode,
    k: usize,
    slots: &mut PairSlots,
    scale: Weights,
) {
    let pair = &model.pairs[k];
    find_points(model, pair, state, &mut slots.points);
    let points = &slots.points.slots[..slots.points.len];
    let latched = &mut *slots.latched;
    if points.is_empty() {
        // Most pairs, most of the time: nothing to evaluate, and nothing latched.
        if mode == Mode::Commit {
            latched.fill(None);
        }
        return;
    }
    let motion = PairMotion::of(state, pair, |i| omega_world[i]);
    if mode == Mode::Commit {
        latch(latched, &motion, points);
    }
    for (p, law) in points.iter().zip(slots.laws.iter_mut()) {
        let (l, d) = evaluate_point_full(&motion, pair, p, latched);
        if let Some(c) = slots.coupling.as_deref_mut() {
            c.add_contact_point(state, pair, p, &l, &d, scale);
        }
        *law = (l, d);
    }
}

/// Latches the approach speed of every point of `points` that has none
/// (a contact onset) and forgets those of slots not in contact; `latched`
/// is empty for laws that do not latch.
fn latch(latched: &mut [Option<f64>], motion: &PairMotion, points: &[ContactPoint]) {
    if latched.is_empty() {
        return;
    }
    // Slots of a pair stay below 130: 64 samples, and 2·64 + 2 for the
    // level-set line law (its extrema and the tube's two open ends).
    let mut seen = [false; 130];
    for p in points {
        let rate = -motion.relative_velocity(&p.point).dot(&p.normal);
        let slot = p.slot as usize;
        if latched[slot].is_none() {
            latched[slot] = Some(rate);
        }
        if slot < seen.len() {
            seen[slot] = true;
        }
    }
    for (s, l) in latched.iter_mut().enumerate() {
        if s < seen.len() && !seen[s] {
            *l = None;
        }
    }
}

/// Contact points of a pair in the (a, b) convention.
fn find_points(model: &Model, pair: &ContactPair, state: &State, out: &mut dyn PointSink) {
    out.clear();
    let (first, second) = if pair.swapped {
        (pair.b, pair.a)
    } else {
        (pair.a, pair.b)
    };
    pair.geometry.contacts(
        &model.bodies[first].shape,
        (&state.pos[first], &state.rot[first]),
        &model.bodies[second].shape,
        (&state.pos[second], &state.rot[second]),
        out,
    );
    if pair.swapped {
        for p in out.filled() {
            p.normal = -p.normal;
            p.turning = p.turning.swapped();
        }
    }
}

/// A pair's two bodies as they move, read once for all its points: each
/// body's velocity [m/s], angular velocity [rad/s] (world frame) and centre
/// of mass [m], a's then b's.
struct PairMotion {
    a: (Vec3, Vec3, Vec3),
    b: (Vec3, Vec3, Vec3),
}

impl PairMotion {
    /// The motion of `pair`'s bodies at `state`, `omega_world` giving body
    /// i's angular velocity in the world frame.
    fn of(state: &State, pair: &ContactPair, omega_world: impl Fn(usize) -> Vec3) -> Self {
        let body = |i: usize| (state.vel[i], omega_world(i), state.pos[i]);
        Self {
            a: body(pair.a),
            b: body(pair.b),
        }
    }

    /// The velocity of b's material point at `p` relative to a's [m/s]
    /// (as [`State::point_velocity`]).
    #[inline]
    fn relative_velocity(&self, p: &Vec3) -> Vec3 {
        let at = |(v, w, x): &(Vec3, Vec3, Vec3)| v + w.cross(&(p - x));
        at(&self.b) - at(&self.a)
    }
}

fn evaluate_point(
    state: &State,
    pair: &ContactPair,
    p: &ContactPoint,
    latched: &[Option<f64>],
) -> ContactEval {
    let motion = PairMotion::of(state, pair, |i| state.omega_world(i));
    ContactEval::new(*p, &evaluate_point_full(&motion, pair, p, latched).0)
}

/// Derivatives of one contact point's forces.
#[derive(Debug, Clone, Copy, PartialEq)]
struct PointDerivatives {
    /// ∂F_n/∂δ [N/m] of the normal law.
    d_depth: f64,
    /// ∂F_n/∂δ̇ [N·s/m] of the normal law.
    d_rate: f64,
    /// ∂F_t/∂v_t [N·s/m] of the friction law at fixed F_n.
    friction: Mat3,
}

/// The per-point laws: forces and their velocity derivatives.
#[inline]
fn evaluate_point_full(
    motion: &PairMotion,
    pair: &ContactPair,
    p: &ContactPoint,
    latched: &[Option<f64>],
) -> (PointLaw, PointDerivatives) {
    let rel = motion.relative_velocity(&p.point);
    let rate = -rel.dot(&p.normal);
    let approach = latched
        .get(p.slot as usize)
        .copied()
        .flatten()
        .unwrap_or(rate);
    let normal = pair.normal.evaluate(p.depth, rate, approach);
    let fnormal = normal.force;
    // A point entering its pair with weight w (−1 at a level-set minimum,
    // geometry::LineLaw) carries w times its laws: forces and derivatives.
    let w = p.weight;
    let slip = rel + rate * p.normal;
    let slip_speed = slip.norm();
    let (tangential, friction) = match &pair.friction {
        Some(law) if fnormal > 0.0 => {
            let (f, j) = friction_force([slip.x, slip.y, slip.z], fnormal, |s| law.coefficient(s));
            (Vec3::from(f), Mat3::from_fn(|r, c| j[r][c]))
        }
        _ => (Vec3::zeros(), Mat3::zeros()),
    };
    (
        PointLaw {
            depth_rate: rate,
            normal_force: w * fnormal,
            tangential_force: w * tangential,
            slip_speed,
        },
        PointDerivatives {
            d_depth: w * normal.d_depth,
            d_rate: w * normal.d_rate,
            friction: w * friction,
        },
    )
}

/// How a contact's Jacobian blocks weigh its two parts: D (damping and
/// friction, ∂F/∂twist) and K (stiffness, ∂F/∂pose): D·`damping` + K·`stiffness`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Weights {
    damping: f64,
    stiffness: f64,
}

/// A 6×6 block of a velocity Jacobian.
pub type Mat6 = nalgebra::Matrix6<f64>;

/// Velocity Jacobian of the forces between two bodies a and b (a contact
/// pair or a joint): `xy` = ∂(wrench on x)/∂(twist of y).
///
/// A twist is [v; ω] (centre-of-mass velocity [m/s], angular velocity
/// [rad/s], both world frame) and a wrench [F; τ] (force [N], torque about
/// the centre of mass [N·m], both world frame).
#[derive(Debug, Clone, PartialEq)]
pub struct CouplingJacobian {
    /// Body a.
    pub a: usize,
    /// Body b.
    pub b: usize,
    /// Whether any velocity-dependent force acted at the last evaluation
    /// (the blocks are zero otherwise).
    pub active: bool,
    /// ∂(wrench on a)/∂(twist of a).
    pub aa: Mat6,
    /// ∂(wrench on a)/∂(twist of b).
    pub ab: Mat6,
    /// ∂(wrench on b)/∂(twist of a).
    pub ba: Mat6,
    /// ∂(wrench on b)/∂(twist of b).
    pub bb: Mat6,
}

impl CouplingJacobian {
    /// Zero blocks between bodies `a` and `b`.
    pub fn zeros(a: usize, b: usize) -> Self {
        Self {
            a,
            b,
            active: false,
            aa: Mat6::zeros(),
            ab: Mat6::zeros(),
            ba: Mat6::zeros(),
            bb: Mat6::zeros(),
        }
    }

    /// Zeroes the blocks.
    pub fn clear(&mut self) {
        if self.active {
            self.active = false;
            self.aa.fill(0.0);
            self.ab.fill(0.0);
            self.ba.fill(0.0);
            self.bb.fill(0.0);
        }
    }

    /// Adds the blocks of force G·v_rel acting on b at arm `r_b` (and its
    /// reaction on a at arm `r_a`), v_rel the velocity of b's point relative
    /// to a's.
    fn add_gradient(&mut self, g: &Mat3, r_a: &Vec3, r_b: &Vec3) {
        self.active = true;
        let [bb, ba, ab, aa] = wrench_twist_blocks(r_b, g, r_a);
        self.bb += bb;
        self.ba -= ba;
        self.ab -= ab;
        self.aa += aa;
    }

    /// Adds contact point `e` of `pair` (its damping and stiffness
    /// weighted by `w`).
    fn add_contact_point(
        &mut self,
        state: &State,
        pair: &ContactPair,
        point: &ContactPoint,
        e: &PointLaw,
        d: &PointDerivatives,
        w: Weights,
    ) {
        let g = contact_velocity_gradient(&point.normal, e, d, w);
        if g != Mat3::zeros() {
            let p = point.point;
            self.add_gradient(&g, &(p - state.pos[pair.a]), &(p - state.pos[pair.b]));
        }
        let s = w.stiffness;
        if s != 0.0 && e.normal_force != 0.0 {
            self.add_turning(state, pair, (point, e), s, s * d.d_depth);
        }
    }

    /// Adds s times the geometric stiffness of point `e`'s normal force
    /// F·n̂ ([`crate::geometry::NormalTurning`]): the normal turning as the centre c moves
    /// across the field (curvature H) and with the field's body, and the
    /// lever arms c − x turning with the bodies.
    ///
    /// With P the body carrying c (force F_P = σ·F·n̂ on it, σ = +1 for b)
    /// and Q the field's, a pose change [δx; δθ] (world) gives
    /// δn̂ = −[n̂]×·δθ_Q + H·(J_P(c)·δq_P − J_Q(c)·δq_Q), and besides
    /// σF·δn̂ at the arms r_i = c − x_i the torques gain
    /// δτ_P = [F_P]×[r_P]×·δθ_P and δτ_Q = [F_P]×·(δx_P − [r_P]×·δθ_P − δx_Q).
    /// The friction force's turning is left out (it is μ times smaller and
    /// vanishes at rest). `k` = s·∂F_n/∂δ, for a centre that moves on its
    /// body into or out of the wall ([`CentreMotion::Rim`],
    /// [`CentreMotion::Crosses`]).
    fn add_turning(
        &mut self,
        state: &State,
        pair: &ContactPair,
        (point, e): (&ContactPoint, &PointLaw),
        s: f64,
        k: f64,
    ) {
        let t = &point.turning;
        let n = point.normal;
        let (p, q, sigma) = if t.centre_on_b {
            (pair.b, pair.a, 1.0)
        } else {
            (pair.a, pair.b, -1.0)
        };
        let f = s * sigma * e.normal_force;
        let (rp, rq) = (t.centre - state.pos[p], t.centre - state.pos[q]);
        let g = f * t.curvature;
        let [mut pp, pq, qp, mut qq] = wrench_twist_blocks(&rp, &g, &rq);
        let (mut pq, mut qp) = (-pq, -qp);
        // The field turning with Q: δF_P = −f·[n̂]×·δθ_Q.
        let turn = -f * n.cross_matrix();
        let (rpx, rqx) = (rp.cross_matrix(), rq.cross_matrix());
        add3(&mut pq, 0, 3, &turn);
        add3(&mut pq, 3, 3, &(rpx * turn));
        add3(&mut qq, 0, 3, &(-turn));
        add3(&mut qq, 3, 3, &(-(rqx * turn)));
        // The arms.
        let fx = (f * n).cross_matrix();
        add3(&mut pp, 3, 3, &(fx * rpx));
        add3(&mut qq, 3, 0, &(-fx));
        add3(&mut qp, 3, 0, &fx);
        add3(&mut qp, 3, 3, &(-(fx * rpx)));
        let blocks = [&mut pp, &mut pq, &mut qp, &mut qq];
        match &t.motion {
            CentreMotion::Fixed => {}
            CentreMotion::Slides(slide) => {
                add_slide(blocks, slide, &t.curvature, &n, f, (&rp, &rq));
            }
            CentreMotion::Rim(_) | CentreMotion::Crosses(_) => {
                // ∂F_P/∂(c's own motion): the normal turning, and the depth
                // with the friction it carries.
                let along = if e.normal_force != 0.0 {
                    n + e.tangential_force / e.normal_force
                } else {
                    n
                };
                let g = f * t.curvature - k * along * n.transpose();
                let (xp, xq) = (state.pos[p], state.pos[q]);
                let moves = match &t.motion {
                    CentreMotion::Rim(rim) => {
                        rim_motion(rim, (&(rim.end - xp), &(rim.end - xq))).map(|m| m.0)
                    }
                    CentreMotion::Crosses(cr) => crossing_motion(cr, &t.centre, (&xp, &xq)),
                    _ => None,
                };
                if let Some(moves) = moves {
                    add_centre_motion(blocks, moves, &g, &(f * n), (&rp, &rq));
                }
            }
        }
        self.active = true;
        let (on_p, on_q) = if t.centre_on_b {
            ([&mut self.bb, &mut self.ba], [&mut self.ab, &mut self.aa])
        } else {
            ([&mut self.aa, &mut self.ab], [&mut self.ba, &mut self.bb])
        };
        *on_p[0] += pp;
        *on_p[1] += pq;
        *on_q[0] += qp;
        *on_q[1] += qq;
    }
}

/// D = ∂f/∂(twist): the velocity Jacobian of all joint and contact forces,
/// in 6×6 blocks. The sparsity pattern is fixed by the model: entry `k` of
/// [`VelocityJacobian::couplings`] is contact pair `k` for
/// `k < model.pairs.len()`, then joint `k − model.pairs.len()`.
///
/// A contact point p between a and b with arms r_i = p − x_i has the 3×3
/// gradient G = ∂F_b/∂v_rel of the force on b with respect to the relative
/// point velocity v_rel = (v_b + ω_b × r_b) − (v_a + ω_a × r_a); with the
/// point-velocity map `J_i = [I, −[r_i]×]` and the wrench map
/// `W_i = [I; [r_i]×]` it adds `D_bb += W_b G J_b`, `D_ba −= W_b G J_a`,
/// `D_ab −= W_a G J_b`, `D_aa += W_a G J_a`.
#[derive(Debug, Clone, PartialEq)]
pub struct VelocityJacobian {
    /// One entry per contact pair, then one per joint.
    pub couplings: Vec<CouplingJacobian>,
    /// s of the last [`Dynamics::forces_and_jacobian`]: the blocks hold D + s·K.
    pub stiffness_scale: f64,
}

impl VelocityJacobian {
    /// Zero blocks shaped for `model`: its pairs', its joints', then its
    /// quasi-static groups' ([`quasistatic::group_couplings`]).
    pub fn new(model: &Model) -> Self {
        let ends = model
            .pairs
            .iter()
            .map(|p| (p.a, p.b))
            .chain(model.joints.iter().map(|j| (j.a, j.b)))
            .chain(quasistatic::group_couplings(model));
        Self {
            couplings: ends.map(|(a, b)| CouplingJacobian::zeros(a, b)).collect(),
            stiffness_scale: 0.0,
        }
    }

    /// Zeroes every block.
    pub fn clear(&mut self) {
        for c in &mut self.couplings {
            c.clear();
        }
    }

    /// The dense 6n × 6n matrix over all `n_bodies` bodies' twists (body i
    /// at rows and columns 6i..6i+6), for tests and inspection.
    pub fn to_dense(&self, n_bodies: usize) -> nalgebra::DMatrix<f64> {
        let mut d = nalgebra::DMatrix::zeros(6 * n_bodies, 6 * n_bodies);
        for c in self.couplings.iter().filter(|c| c.active) {
            for (i, j, m) in [
                (c.a, c.a, &c.aa),
                (c.a, c.b, &c.ab),
                (c.b, c.a, &c.ba),
                (c.b, c.b, &c.bb),
            ] {
                let mut v = d.view_mut((6 * i, 6 * j), (6, 6));
                v += m;
            }
        }
        d
    }

    /// [`CouplingJacobian::add_gradient`] of coupling `k`.
    fn add_gradient(&mut self, k: usize, g: &Mat3, r_a: &Vec3, r_b: &Vec3) {
        self.couplings[k].add_gradient(g, r_a, r_b);
    }

    /// The joint's dampers: −c·(v_b(p_b) − v_a(p_a)) at the hinge points
    /// (arms `ra`, `rb`) and −c_t·(ê·(ω_b − ω_a))·ê on b about the mean x
    /// axis ê ([`twist_axis`]).
    ///
    /// With a stiffness scale s the springs add s·k in the same places, and
    /// the arms of the joint's force F on b (−F on a) turn with the bodies:
    /// δτ_b = [F]×[r_b]×·δθ_b, δτ_a = −[F]×[r_a]×·δθ_a.
    fn add_joint(
        &mut self,
        k: usize,
        j: &Joint,
        state: &State,
        arms: (&Vec3, &Vec3),
        force: &Vec3,
    ) {
        let (ra, rb) = arms;
        let p = &j.params;
        let s = self.stiffness_scale;
        let linear = p.damping + s * p.stiffness;
        if linear != 0.0 {
            self.add_gradient(k, &(-linear * Mat3::identity()), ra, rb);
        }
        if s != 0.0 && *force != Vec3::zeros() {
            let fx = (s * force).cross_matrix();
            let c = &mut self.couplings[k];
            c.active = true;
            add3(&mut c.bb, 3, 3, &(fx * rb.cross_matrix()));
            add3(&mut c.aa, 3, 3, &(-(fx * ra.cross_matrix())));
        }
        let twist = p.twist_damping + s * p.twist_stiffness;
        if twist != 0.0 {
            let axis = twist_axis(&state.rot[j.a], &state.rot[j.b]);
            let t = twist * axis * axis.transpose();
            let c = &mut self.couplings[k];
            c.active = true;
            let add = |m: &mut Mat6, sign: f64| {
                let mut v = m.fixed_view_mut::<3, 3>(3, 3);
                v += sign * t;
            };
            add(&mut c.bb, -1.0);
            add(&mut c.ba, 1.0);
            add(&mut c.ab, 1.0);
            add(&mut c.aa, -1.0);
        }
    }
}

/// G = ∂F_b/∂v_rel [N·s/m] of the total force on b (F_n·n + F_t) at fixed
/// geometry: the normal law through δ̇ = −n·v_rel, the friction law through
/// the slip v_t = (I − nnᵀ)·v_rel and through F_n (F_t is proportional to
/// F_n, so ∂F_t/∂F_n = F_t/F_n).
///
/// With a stiffness scale s the normal stiffness joins the damping: the
/// point's relative displacement s·v_rel deepens the contact by −s·n·v_rel,
/// so ∂F_n/∂δ̇ becomes ∂F_n/∂δ̇ + s·∂F_n/∂δ. With a damping weight 0
/// only that stiffness is left (a quasi-static group's K).
fn contact_velocity_gradient(n: &Vec3, e: &PointLaw, d: &PointDerivatives, w: Weights) -> Mat3 {
    let n = *n;
    let mut g = w.damping * d.friction * (Mat3::identity() - n * n.transpose());
    let normal = w.damping * d.d_rate + w.stiffness * d.d_depth;
    if e.normal_force != 0.0 && normal != 0.0 {
        let along = n + e.tangential_force / e.normal_force;
        g -= normal * along * n.transpose();
    }
    g
}

/// Adds to the blocks [PP, PQ, QP, QQ] of [`CouplingJacobian::add_turning`]
/// the sliding of the centre c along `slide` (its [`Slide`]): c moves by
/// â·δs, which turns the normal by H·â·δs and moves both arms by â·δs, a
/// rank-one term (wrench per unit slide) ⊗ (∂s/∂pose). `f` is the scaled,
/// signed force on P along `n`, `arms` (r_P, r_Q). A slide along which the
/// normal does not turn (âᵀH·â + n·κ = 0: a link parallel to a straight
/// wall) has no definite position and adds nothing.
fn add_slide(
    blocks: [&mut Mat6; 4],
    slide: &Slide,
    h: &Mat3,
    n: &Vec3,
    f: f64,
    (rp, rq): (&Vec3, &Vec3),
) {
    let a = slide.direction;
    let ha = h * a;
    let den = a.dot(&ha) + n.dot(&slide.curvature);
    if den.abs() <= 1e-12 * (h.norm() + slide.curvature.norm()) {
        return;
    }
    let hta = h.transpose() * a;
    let axn = a.cross(n);
    let row = |r: &Vec3, sign: f64| {
        let (x, th) = (sign * hta, sign * (r.cross(&hta) + axn));
        Vector6::new(x.x, x.y, x.z, th.x, th.y, th.z) / -den
    };
    let (g, fp) = (f * ha, f * n);
    let wrench = |r: &Vec3, sign: f64| {
        let t = sign * (r.cross(&g) - fp.cross(&a));
        Vector6::new(sign * g.x, sign * g.y, sign * g.z, t.x, t.y, t.z)
    };
    let (row_p, row_q) = (row(rp, 1.0), row(rq, -1.0));
    let (w_p, w_q) = (wrench(rp, 1.0), wrench(rq, -1.0));
    let [pp, pq, qp, qq] = blocks;
    *pp += w_p * row_p.transpose();
    *pq += w_p * row_q.transpose();
    *qp += w_q * row_p.transpose();
    *qq += w_q * row_q.transpose();
}

/// ∂e/∂(δx, δθ) of bodies P and Q, e the motion of a contact's centre on
/// P beyond moving with P.
type CentreMoves = (nalgebra::Matrix3x6<f64>, nalgebra::Matrix3x6<f64>);

/// The motion of a rim point around its rim ([`Rim`]), with `ends` the arms
/// (q − x_P, q − x_Q) of the end's axis point q, and the rim point's rate
/// along the rod's axis as its section moves along it, â + ∂(r·d)/∂s;
/// `None` where the end's axis lies on the lumen's core (no definite rim
/// point).
fn rim_motion(rim: &Rim, (qp, qq): (&Vec3, &Vec3)) -> Option<(CentreMoves, Vec3)> {
    let (a, u) = (rim.axis, rim.offset);
    let pi = Mat3::identity() - a * a.transpose();
    let across = pi * u;
    let len = across.norm();
    if len <= 1e-15 {
        return None;
    }
    let d = across / len;
    let turn = (rim.radius / len) * (Mat3::identity() - d * d.transpose());
    let pa = pi * (Mat3::identity() - rim.beta * rim.core_tangent * rim.core_tangent.transpose());
    let grow = u.dot(&a);
    let mut mp = nalgebra::Matrix3x6::zeros();
    mp.fixed_view_mut::<3, 3>(0, 0).copy_from(&(turn * pa));
    let rot_p = -(pa * qp.cross_matrix()) + grow * a.cross_matrix() - a * a.cross(&u).transpose();
    mp.fixed_view_mut::<3, 3>(0, 3)
        .copy_from(&(turn * rot_p + rim.radius * d.cross_matrix()));
    let mut mq = nalgebra::Matrix3x6::zeros();
    mq.fixed_view_mut::<3, 3>(0, 0).copy_from(&(-(turn * pa)));
    let rot_q = pa * qq.cross_matrix() - pi * u.cross_matrix();
    mq.fixed_view_mut::<3, 3>(0, 3).copy_from(&(turn * rot_q));
    Some(((mp, mq), a + turn * pa * a))
}

/// The motion of the deepest point c of a section in an open end's plane
/// ([`crate::geometry::Crossing`]): around the section as a rim point,
/// e_rim = M_P·δq_P + M_Q·δq_Q, and with the section along the axis,
/// v·δs, v = â + ∂(r·d)/∂s. The point p on the plane (the axis point q, or
/// c) stays on it: t̂·(δp_P − δp_Q) + t̂·ṗ·δs = 0, with δp_i the motion of
/// p as a point of body i (plus e_rim for c) and ṗ its rate along the axis
/// (â for q, v for c). `centre` is c, `bodies` (x_P, x_Q); `None` where the
/// section has no definite rim point or its axis lies in the plane.
fn crossing_motion(
    cr: &crate::geometry::Crossing,
    centre: &Vec3,
    (xp, xq): (&Vec3, &Vec3),
) -> Option<CentreMoves> {
    let q = cr.rim.end;
    let ((mut mp, mut mq), v) = rim_motion(&cr.rim, (&(q - xp), &(q - xq)))?;
    let t = cr.plane_normal;
    let (p, rate) = if cr.rim_on_plane {
        (*centre, v)
    } else {
        (q, cr.rim.axis)
    };
    let den = t.dot(&rate);
    if den.abs() <= 1e-12 {
        return None;
    }
    let material = |x: &Vec3| {
        let th = (p - x).cross(&t);
        nalgebra::RowVector6::new(t.x, t.y, t.z, th.x, th.y, th.z)
    };
    let (mut row_p, mut row_q) = (material(xp), -material(xq));
    if cr.rim_on_plane {
        row_p += t.transpose() * mp;
        row_q += t.transpose() * mq;
    }
    mp -= v * (row_p / den);
    mq -= v * (row_q / den);
    Some((mp, mq))
}

/// Adds to the blocks [PP, PQ, QP, QQ] of [`CouplingJacobian::add_turning`]
/// the motion e = M_P·δq_P + M_Q·δq_Q (`moves`) of a contact's centre on P
/// beyond moving with P (a rim point around its rim, a section sliding to
/// stay in a plane): the wrenches change by W_P·e (on P) and W_Q·e (on Q),
/// with `g` = ∂F_P/∂e (the normal turning and the depth), `fp` the scaled
/// force on P and `arms` (c − x_P, c − x_Q).
fn add_centre_motion(
    blocks: [&mut Mat6; 4],
    (mp, mq): CentreMoves,
    g: &Mat3,
    fp: &Vec3,
    (rp, rq): (&Vec3, &Vec3),
) {
    let fx = fp.cross_matrix();
    let wrench = |r: &Vec3, sign: f64| {
        let mut w = nalgebra::Matrix6x3::zeros();
        w.fixed_view_mut::<3, 3>(0, 0).copy_from(&(sign * g));
        w.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(sign * (r.cross_matrix() * g - fx)));
        w
    };
    let (w_p, w_q) = (wrench(rp, 1.0), wrench(rq, -1.0));
    let [pp, pq, qp_block, qq_block] = blocks;
    *pp += w_p * mp;
    *pq += w_p * mq;
    *qp_block += w_q * mp;
    *qq_block += w_q * mq;
}

/// Adds `m` to the 3×3 block of `to` at (`row`, `col`).
fn add3(to: &mut Mat6, row: usize, col: usize, m: &Mat3) {
    let mut v = to.fixed_view_mut::<3, 3>(row, col);
    v += m;
}

/// W_i·G·J_j for the four pairs (i, j) of two arms `r_p` and `r_q`,
/// [PP, PQ, QP, QQ]: the wrench on body i (force G·u at arm r_i) per unit
/// twist of body j (u the velocity of j's point at arm r_j). With
/// `R = [r]×`, each is `[[G, −G·R_j], [R_i·G, −R_i·G·R_j]]`; the products
/// G·R and R·G are formed once for the four.
fn wrench_twist_blocks(r_p: &Vec3, g: &Mat3, r_q: &Vec3) -> [Mat6; 4] {
    let (rp, rq) = (r_p.cross_matrix(), r_q.cross_matrix());
    let (g_rp, g_rq) = (g * rp, g * rq);
    let (rp_g, rq_g) = (rp * g, rq * g);
    [
        block(g, &(-g_rp), &rp_g, &(-(rp * g_rp))),
        block(g, &(-g_rq), &rp_g, &(-(rp * g_rq))),
        block(g, &(-g_rp), &rq_g, &(-(rq * g_rp))),
        block(g, &(-g_rq), &rq_g, &(-(rq * g_rq))),
    ]
}

/// The 6×6 block [[a, b], [c, d]] of four 3×3 blocks.
fn block(a: &Mat3, b: &Mat3, c: &Mat3, d: &Mat3) -> Mat6 {
    let mut m = Mat6::zeros();
    m.fixed_view_mut::<3, 3>(0, 0).copy_from(a);
    m.fixed_view_mut::<3, 3>(0, 3).copy_from(b);
    m.fixed_view_mut::<3, 3>(3, 0).copy_from(c);
    m.fixed_view_mut::<3, 3>(3, 3).copy_from(d);
    m
}
