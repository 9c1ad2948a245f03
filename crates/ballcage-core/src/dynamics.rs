//! Forces and accelerations of the assembled model.
//!
//! Stages of one evaluation, in order:
//! 1. applied loads (gravity, torques) — depend on time only;
//! 2. contact forces of the declared pairs — depend on poses and velocities;
//! 3. accelerations: Newton for translation, Euler's equations with the
//!    gyroscopic term for rotation (body frame), projected onto the spin axis
//!    for `spin` bodies.

use crate::force::friction_force;
use crate::geometry::ContactPoint;
use crate::math::Vec3;
use crate::model::{ContactPair, Model, Motion, State};

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
    /// Normal force magnitude [N] (≥ 0).
    pub normal_force: f64,
    /// Tangential (friction) force on body b [N], world frame.
    pub tangential_force: Vec3,
    /// Slip speed |v_t| [m/s].
    pub slip_speed: f64,
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
    /// Latched approach speed per pair and slot [m/s]; empty for laws that do not latch.
    latched: Vec<Vec<Option<f64>>>,
    /// Number of force evaluations so far.
    pub evaluations: u64,
}

impl Dynamics {
    /// Scratch and memory sized for `model`.
    pub fn new(model: &Model) -> Self {
        let n = model.bodies.len();
        Self {
            force: vec![Vec3::zeros(); n],
            torque: vec![Vec3::zeros(); n],
            points: Vec::with_capacity(16),
            latched: model
                .pairs
                .iter()
                .map(|p| {
                    if p.normal.latches_approach_speed() {
                        vec![None; p.geometry.slots()]
                    } else {
                        vec![]
                    }
                })
                .collect(),
            evaluations: 0,
        }
    }

    /// Accelerations of all bodies at `state`.
    pub fn accelerations(&mut self, model: &Model, state: &State, mode: Mode, acc: &mut Accel) {
        self.evaluations += 1;
        // 1. applied loads
        for &i in &model.integrated {
            self.force[i] = model.gravity * model.bodies[i].mass;
            self.torque[i] = Vec3::zeros();
        }
        for l in &model.torques {
            self.torque[l.body] += l.torque(state.t);
        }
        // 2. contacts
        for k in 0..model.pairs.len() {
            let pair = &model.pairs[k];
            let mut points = std::mem::take(&mut self.points);
            find_points(model, pair, state, &mut points);
            let latched = &mut self.latched[k];
            if mode == Mode::Commit && !latched.is_empty() {
                let mut seen = [false; 64];
                for p in &points {
                    let rate = depth_rate(state, pair, p);
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
            for p in &points {
                let e = evaluate_point(state, pair, p, &self.latched[k]);
                let f = e.point.normal * e.normal_force + e.tangential_force;
                let (a, b) = (pair.a, pair.b);
                self.force[b] += f;
                self.torque[b] += (p.point - state.pos[b]).cross(&f);
                self.force[a] -= f;
                self.torque[a] -= (p.point - state.pos[a]).cross(&f);
            }
            self.points = points;
        }
        // 3. accelerations
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
                } => {
                    acc.lin[i] = Vec3::zeros();
                    acc.ang[i] = axis_body * (self.torque[i].dot(&axis) / inertia);
                }
                Motion::Fixed | Motion::KinematicSpin(_) => {}
            }
        }
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
                .map(|p| evaluate_point(state, pair, p, &self.latched[k])),
        );
        self.points = points;
    }

    /// Kinetic, gravitational and elastic contact energy at `state`.
    pub fn energy(&mut self, model: &Model, state: &State) -> Energy {
        let mut kinetic = 0.0;
        let mut potential_gravity = 0.0;
        for &i in &model.integrated {
            let b = &model.bodies[i];
            let w = state.omega[i];
            kinetic += 0.5 * b.mass * state.vel[i].norm_squared()
                + 0.5 * w.dot(&b.inertia.component_mul(&w));
            potential_gravity -= b.mass * model.gravity.dot(&state.pos[i]);
        }
        let mut potential_contact = 0.0;
        let mut points = std::mem::take(&mut self.points);
        for pair in &model.pairs {
            find_points(model, pair, state, &mut points);
            potential_contact += points
                .iter()
                .map(|p| pair.normal.elastic_energy(p.depth))
                .sum::<f64>();
        }
        self.points = points;
        Energy {
            kinetic,
            potential_gravity,
            potential_contact,
        }
    }
}

/// Contact points of a pair in the (a, b) convention.
fn find_points(model: &Model, pair: &ContactPair, state: &State, out: &mut Vec<ContactPoint>) {
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
        for p in out.iter_mut() {
            p.normal = -p.normal;
        }
    }
}

fn relative_velocity(state: &State, pair: &ContactPair, p: &ContactPoint) -> Vec3 {
    state.point_velocity(pair.b, &p.point) - state.point_velocity(pair.a, &p.point)
}

fn depth_rate(state: &State, pair: &ContactPair, p: &ContactPoint) -> f64 {
    -relative_velocity(state, pair, p).dot(&p.normal)
}

fn evaluate_point(
    state: &State,
    pair: &ContactPair,
    p: &ContactPoint,
    latched: &[Option<f64>],
) -> ContactEval {
    let rel = relative_velocity(state, pair, p);
    let rate = -rel.dot(&p.normal);
    let approach = latched
        .get(p.slot as usize)
        .copied()
        .flatten()
        .unwrap_or(rate);
    let fnormal = pair.normal.evaluate(p.depth, rate, approach).force;
    let slip = rel + rate * p.normal;
    let slip_speed = slip.norm();
    let tangential = match &pair.friction {
        Some(law) if fnormal > 0.0 => {
            let (f, _) = friction_force([slip.x, slip.y, slip.z], fnormal, |s| law.coefficient(s));
            Vec3::from(f)
        }
        _ => Vec3::zeros(),
    };
    ContactEval {
        point: *p,
        depth_rate: rate,
        normal_force: fnormal,
        tangential_force: tangential,
        slip_speed,
    }
}
