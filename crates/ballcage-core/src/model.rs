//! The assembled, read-only model and the mutable state it acts on.

use crate::force::{FrictionLaw, NormalLaw, step};
use crate::geometry::{PairGeometry, Shape};
use crate::math::{Quat, Vec3};
use crate::scene::{IntegratorKind, TableKind};

/// How an assembled body moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// Never moves.
    Fixed,
    /// Six degrees of freedom.
    Dynamic,
    /// Prescribed spin about a world axis through the centre of mass.
    KinematicSpin(SpinProfile),
    /// One degree of freedom: spin about a world axis through the fixed
    /// centre of mass; with `slides`, two: the centre of mass also slides
    /// along that axis (a cylindrical joint to the ground).
    Spin {
        /// Unit spin axis, world frame.
        axis: Vec3,
        /// The same axis in the body frame (fixed in the body as it spins).
        axis_body: Vec3,
        /// Moment of inertia about the axis [kg·m²].
        inertia: f64,
        /// Whether the centre of mass is free to slide along `axis`.
        slides: bool,
    },
    /// Not integrated: at every force evaluation its pose (or position)
    /// is solved for static equilibrium among the bodies it touches,
    /// which are held ([`StaticGroup`]; a quasi-static hinge's cage and
    /// keys, issue 28).
    QuasiStatic(StaticDofs),
}

/// Which of a quasi-static body's pose coordinates its equilibrium solves for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StaticDofs {
    /// Position and orientation: 6 coordinates.
    Pose,
    /// Position only (a ball, whose turn carries no load without friction):
    /// 3 coordinates.
    Position,
}

impl StaticDofs {
    /// Coordinates solved for.
    pub fn dim(self) -> usize {
        match self {
            Self::Pose => 6,
            Self::Position => 3,
        }
    }
}

/// Quasi-static bodies connected by contact pairs, solved together for
/// equilibrium with the bodies they touch outside the group held.
#[derive(Debug, Clone, PartialEq)]
pub struct StaticGroup {
    /// The group's bodies and the coordinates solved for, in body order.
    pub free: Vec<(usize, StaticDofs)>,
    /// The bodies outside the group that its pairs touch, in body order:
    /// what the group acts on as a force element.
    pub held: Vec<usize>,
    /// Every contact pair with a body of the group, in pair order.
    pub pairs: Vec<usize>,
    /// Per free body, per held body: the free body's pose in the held
    /// body's frame in the initial state (position [m], rotation). The mean
    /// of the poses the held bodies carry it to is its kinematic pose
    /// ([`StaticGroup::kinematic_pose`]).
    pub carried: Vec<Vec<(Vec3, Quat)>>,
}

impl StaticGroup {
    /// Free body `f`'s (its index in `free`) kinematic pose at `state`: the
    /// mean of the poses each held body carries it to from the initial
    /// state (for a hinge's two links, the cage on the bisecting plane).
    pub fn kinematic_pose(&self, f: usize, state: &State) -> (Vec3, Quat) {
        let n = self.held.len() as f64;
        let (mut x, mut q) = (Vec3::zeros(), nalgebra::Quaternion::new(0.0, 0.0, 0.0, 0.0));
        for (&h, (p, r)) in self.held.iter().zip(&self.carried[f]) {
            x += state.pos[h] + state.rot[h] * p;
            let carried = (state.rot[h] * r).into_inner();
            // The same hemisphere as the first, so that the sum is a mean.
            q += if q.dot(&carried) < 0.0 {
                -carried
            } else {
                carried
            };
        }
        (x / n, Quat::from_quaternion(q))
    }
}

/// A spin drive: speed ramped by an Adams STEP from 0 to `speed` over `ramp`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpinProfile {
    /// Unit spin axis, world frame.
    pub axis: Vec3,
    /// Final speed [rad/s].
    pub speed: f64,
    /// Ramp duration [s].
    pub ramp: f64,
}

impl SpinProfile {
    /// Spin angle θ(t) [rad]: ω₀t_r(τ³ − τ⁴/2), τ = t/t_r, during the ramp;
    /// ω₀(t − t_r/2) after it.
    pub fn angle(&self, t: f64) -> f64 {
        if self.ramp <= 0.0 || t >= self.ramp {
            self.speed * (t - 0.5 * self.ramp)
        } else if t <= 0.0 {
            0.0
        } else {
            let tau = t / self.ramp;
            self.speed * self.ramp * (tau.powi(3) - 0.5 * tau.powi(4))
        }
    }

    /// Spin acceleration dω/dt [rad/s²].
    pub fn acceleration_at(&self, t: f64) -> f64 {
        if self.ramp <= 0.0 {
            0.0
        } else {
            step(t, 0.0, 0.0, self.ramp, self.speed).1
        }
    }

    /// Spin speed ω(t) = STEP(t, 0, 0, t_r, ω₀) [rad/s].
    pub fn speed_at(&self, t: f64) -> f64 {
        if self.ramp <= 0.0 {
            self.speed
        } else {
            step(t, 0.0, 0.0, self.ramp, self.speed).0
        }
    }
}

/// An assembled body. Indices into [`Model::bodies`] are body ids.
#[derive(Debug, Clone)]
pub struct Body {
    /// Name from the scene.
    pub name: String,
    /// How it moves.
    pub motion: Motion,
    /// Mass [kg]; 0 for bodies without mass properties (half-spaces, tubes).
    pub mass: f64,
    /// Principal inertia about body x, y, z [kg·m²].
    pub inertia: Vec3,
    /// Query shape.
    pub shape: Shape,
    /// Initial orientation (kinematic spin is applied on top of it).
    pub initial_rotation: Quat,
}

impl Body {
    /// Whether the integrator advances this body.
    pub fn is_integrated(&self) -> bool {
        matches!(self.motion, Motion::Dynamic | Motion::Spin { .. })
    }
}

/// A declared contact pair with its laws.
#[derive(Debug, Clone)]
pub struct ContactPair {
    /// Name in outputs.
    pub name: String,
    /// Body a (normals point from a toward b).
    pub a: usize,
    /// Body b.
    pub b: usize,
    /// Point finder.
    pub geometry: PairGeometry,
    /// True when the geometry's canonical order is (b, a).
    pub swapped: bool,
    /// Normal law, SI.
    pub normal: NormalLaw,
    /// Friction law, if any.
    pub friction: Option<FrictionLaw>,
    /// Penetration beyond which the run is stopped as diverged [m].
    pub depth_limit: f64,
    /// Reduced translational mass of the two bodies [kg] (a body that is not
    /// integrated counts as infinitely heavy), for the stable-step estimate.
    pub reduced_mass: f64,
}

/// A torque `magnitude·axis·STEP(t, 0, 0, ramp, 1)` on a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TorqueLoad {
    /// Body index.
    pub body: usize,
    /// Unit axis, world frame.
    pub axis: Vec3,
    /// Signed magnitude [N·m].
    pub magnitude: f64,
    /// Ramp [s].
    pub ramp: f64,
}

impl TorqueLoad {
    /// Torque vector at time t [N·m].
    pub fn torque(&self, t: f64) -> Vec3 {
        let s = if self.ramp <= 0.0 {
            1.0
        } else {
            step(t, 0.0, 0.0, self.ramp, 1.0).0
        };
        self.axis * (self.magnitude * s)
    }
}

/// A force `magnitude·axis·STEP(t, 0, 0, ramp, 1)` at a body's centre of mass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceLoad {
    /// Body index.
    pub body: usize,
    /// Unit direction, world frame.
    pub axis: Vec3,
    /// Signed magnitude along `axis` [N].
    pub magnitude: f64,
    /// Ramp [s].
    pub ramp: f64,
}

impl ForceLoad {
    /// Force vector at time t [N].
    pub fn force(&self, t: f64) -> Vec3 {
        let s = if self.ramp <= 0.0 {
            1.0
        } else {
            step(t, 0.0, 0.0, self.ramp, 1.0).0
        };
        self.axis * (self.magnitude * s)
    }
}

/// An ideal constant-velocity joint between bodies a and b.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Name in messages.
    pub name: String,
    /// Body a.
    pub a: usize,
    /// Body b.
    pub b: usize,
    /// Hinge point in a's frame [m].
    pub anchor_a: Vec3,
    /// Hinge point in b's frame [m].
    pub anchor_b: Vec3,
    /// Parameters.
    pub params: crate::force::joint::CvJointParams,
}

impl Joint {
    /// The joint's wrench on body b at `state`, with the arms `(r_a, r_b)` from
    /// each body's centre of mass to its hinge point [m], world frame. Body a
    /// gets the opposite force at its own hinge point and the opposite torque.
    pub fn evaluate(&self, state: &State) -> (crate::force::joint::JointWrench, Vec3, Vec3) {
        let (a, b) = (self.a, self.b);
        let (ra, rb) = (state.rot[a] * self.anchor_a, state.rot[b] * self.anchor_b);
        let (wa, wb) = (state.omega_world(a), state.omega_world(b));
        let w = crate::force::joint::cv_joint_wrench(
            &state.rot[a],
            &state.rot[b],
            &(state.pos[a] + ra),
            &(state.pos[b] + rb),
            &(state.vel[a] + wa.cross(&ra)),
            &(state.vel[b] + wb.cross(&rb)),
            &wa,
            &wb,
            &self.params,
        );
        (w, ra, rb)
    }

    /// Torque of the joint on body `i` about its centre of mass [N·m], world frame (zero if not attached).
    pub fn torque_on(&self, state: &State, i: usize) -> Vec3 {
        if i != self.a && i != self.b {
            return Vec3::zeros();
        }
        let (w, ra, rb) = self.evaluate(state);
        if i == self.b {
            rb.cross(&w.force) + w.torque
        } else {
            -(ra.cross(&w.force) + w.torque)
        }
    }
}

/// What the recorder keeps.
#[derive(Debug, Clone, PartialEq)]
pub struct RecordPlan {
    /// Tables to produce, in order.
    pub tables: Vec<TableKind>,
    /// Body indices recorded in `bodies`.
    pub bodies: Vec<usize>,
    /// Pair indices recorded in `contacts`.
    pub pairs: Vec<usize>,
    /// Window `[start, end]` of the `summary` table [s].
    pub summary_window: (f64, f64),
    /// Most memory the recorded tables may take [B] (`record.max_bytes`).
    pub max_bytes: u64,
}

/// Read-only after assembly.
#[derive(Debug, Clone)]
pub struct Model {
    /// Bodies; index = body id.
    pub bodies: Vec<Body>,
    /// Indices of the integrated bodies.
    pub integrated: Vec<usize>,
    /// Declared contact pairs; no other pair is evaluated.
    pub pairs: Vec<ContactPair>,
    /// Applied torques.
    pub torques: Vec<TorqueLoad>,
    /// Applied forces (at the centres of mass).
    pub forces: Vec<ForceLoad>,
    /// Penalty joints.
    pub joints: Vec<Joint>,
    /// Groups of quasi-static bodies, solved at every force evaluation.
    pub static_groups: Vec<StaticGroup>,
    /// Gravity [m/s²], world frame.
    pub gravity: Vec3,
    /// Integrator.
    pub integrator: IntegratorKind,
    /// Integrator step [s].
    pub dt: f64,
    /// Threads of a force evaluation's contact pairs
    /// ([`crate::scene::SimulationSpec::threads`], 0 resolved to the cores).
    pub threads: usize,
    /// Newton iterations of the `sdirk2` integrator.
    pub newton: crate::scene::NewtonSpec,
    /// Tolerances of adaptive steps; `None`: fixed steps of `dt`
    /// ([`crate::scene::SimulationSpec::rtol`]).
    pub tolerance: Option<crate::scene::Tolerance>,
    /// Largest adaptive step [s] ([`crate::scene::SimulationSpec::max_step`],
    /// default the output interval).
    pub max_step: f64,
    /// Largest energy the integrator may create, as a fraction of the
    /// energy scale ([`crate::scene::DivergenceSpec::energy_growth`]).
    pub energy_growth: f64,
    /// Steps per recorded frame.
    pub steps_per_output: u64,
    /// Total steps.
    pub total_steps: u64,
    /// Recording plan.
    pub record: RecordPlan,
    /// Scene name.
    pub name: String,
}

impl Model {
    /// Simulated duration [s].
    pub fn duration(&self) -> f64 {
        self.total_steps as f64 * self.dt
    }

    /// Sets the prescribed bodies' pose and velocity at time `t`.
    pub fn prescribe(&self, t: f64, state: &mut State) {
        for (i, b) in self.bodies.iter().enumerate() {
            if let Motion::KinematicSpin(p) = b.motion {
                let q = Quat::from_scaled_axis(p.axis * p.angle(t)) * b.initial_rotation;
                state.rot[i] = q;
                state.omega[i] = q.inverse() * (p.axis * p.speed_at(t));
            }
        }
    }
}

/// Mutable state: cheap to clone, so integrator stages copy it.
///
/// All arrays are indexed by body id; fixed bodies keep their initial values.
#[derive(Debug, PartialEq)]
pub struct State {
    /// Time [s].
    pub t: f64,
    /// Centre-of-mass positions [m], world frame.
    pub pos: Vec<Vec3>,
    /// Orientations, body → world.
    pub rot: Vec<Quat>,
    /// Linear velocities [m/s], world frame.
    pub vel: Vec<Vec3>,
    /// Angular velocities [rad/s], **body frame**.
    pub omega: Vec<Vec3>,
}

impl Clone for State {
    fn clone(&self) -> Self {
        Self {
            t: self.t,
            pos: self.pos.clone(),
            rot: self.rot.clone(),
            vel: self.vel.clone(),
            omega: self.omega.clone(),
        }
    }

    /// Field by field, reusing the arrays' memory: the integrators copy
    /// states every step and must not allocate.
    fn clone_from(&mut self, source: &Self) {
        self.t = source.t;
        self.pos.clone_from(&source.pos);
        self.rot.clone_from(&source.rot);
        self.vel.clone_from(&source.vel);
        self.omega.clone_from(&source.omega);
    }
}

impl State {
    /// Whether `other` is this state: the same poses and velocities to the
    /// bit, its time within `time_tolerance` [s] (callers round the time to
    /// their step count).
    pub fn is_at(&self, other: &State, time_tolerance: f64) -> bool {
        (self.t - other.t).abs() <= time_tolerance
            && (&self.pos, &self.rot, &self.vel, &self.omega)
                == (&other.pos, &other.rot, &other.vel, &other.omega)
    }

    /// Copies this state into `slot`, reusing the memory of the state
    /// already there (no allocation after the first).
    pub fn copy_into(&self, slot: &mut Option<State>) {
        match slot {
            Some(kept) => kept.clone_from(self),
            None => *slot = Some(self.clone()),
        }
    }

    /// Angular velocity of body `i` in the world frame [rad/s].
    pub fn omega_world(&self, i: usize) -> Vec3 {
        self.rot[i] * self.omega[i]
    }

    /// Velocity of the material point of body `i` at world point `p` [m/s].
    pub fn point_velocity(&self, i: usize, p: &Vec3) -> Vec3 {
        self.vel[i] + self.omega_world(i).cross(&(p - self.pos[i]))
    }
}
