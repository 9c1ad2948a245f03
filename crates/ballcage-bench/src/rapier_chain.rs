//! A rapier3d-f64 baseline of ballcage's `ideal-cv` drill pipe (issue 12).
//!
//! [`RapierChain::from_scene`] builds a rapier world from a ballcage
//! [`Scene`], so both engines simulate the same bodies: every mass, principal
//! inertia, initial pose, hinge point, the tube centreline, gravity, the
//! drive's speed ramp and the resisting moment are read from the built scene,
//! none is retyped. The intended scene is the paper's drill pipe with
//! `pipe.hinge = "ideal-cv"` (docs/model.md §3–4); [`paper_ideal_cv`] builds
//! it. Units are SI throughout (m, kg, s, N, rad).
//!
//! # What maps to what
//!
//! | ballcage (scene) | rapier |
//! |---|---|
//! | `dynamic` body (links) | dynamic body, mass and principal inertia from the scene (`additional_mass_properties`, colliders of zero density), gyroscopic forces on |
//! | `kinematic-spin` body (upper connector, the drive) | position-based kinematic body whose next rotation is set before each step to the scene's spin angle θ(t + h) = ω₀t_r(τ³ − τ⁴/2), τ = t/t_r, then ω₀(t − t_r/2): the same prescribed motion |
//! | `spin` body (lower connector) | dynamic body held to a fixed ground body by a revolute impulse joint about the scene's spin axis through its centre of mass |
//! | `torque` load (resisting moment) | `reset_torques` + `add_torque(M·STEP(t, 0, 0, t_T, 1)·axis)` on the body before each step, t the step's start |
//! | `cv` joint (penalty, 1e9 N/m and 1.1e5 N·m/rad) | rigid impulse joint, see below |
//! | neck–mouth contact pair (`ring-cylinder`) | a cone limit on the joint's bend, see below |
//! | `tube` shape (analytic wall) and link–tube pairs (IMPACT + Adams friction) | triangle mesh of the same wall, rigid (velocity-level) contact with one Coulomb coefficient, see below |
//! | no other pair is ever tested | collision groups: link colliders meet only the bore; connectors carry no collider |
//!
//! # The constant-velocity hinge in rapier
//!
//! Each `cv` joint becomes an impulse [`GenericJoint`] between the same two
//! bodies, with both joint frames at the scene's hinge anchors and aligned
//! with their bodies' axes (x along the body). It locks the three linear axes
//! (a spherical joint: the hinge points coincide) **and `ANG_X`** (the twist
//! lock). Rapier's locked angular axis `i` drives component `i` of the vector
//! part of the relative rotation q₁⁻¹q₂ (frame 1 to frame 2) to zero; the
//! x component of a unit quaternion is zero exactly when its swing–twist
//! decomposition about x has no twist (q = swing·twist with twist =
//! (w, x, 0, 0)/‖·‖, and the x component of swing·twist is s₀t₁ whichever the
//! order). ballcage's `cv` joint penalizes that same twist φ_tw of q_a⁻¹q_b
//! about a's x axis, zero twist being the constant-velocity condition. So the
//! rapier hinge is the ideal CV constraint itself, enforced rigidly (rapier's
//! joint softness, 1e6 Hz), where ballcage's is a stiff penalty: 1.2 µm of
//! hinge-point gap under the 1.2 kN hinge shear and 1800/1.1e5 = 0.94° of
//! twist per hinge at the full moment. The two bend axes (`ANG_Y`, `ANG_Z`)
//! are free and coupled under one cone limit on the angle between the two
//! body axes, at the bend where ballcage's neck–mouth contact closes
//! ([`articulation_limit`]). The limit differs in kind: rapier's is a rigid
//! one-sided constraint on the bend angle, ballcage's an IMPACT contact
//! between the neck's cylinder and the mouth's ring, which sinks in under
//! load. Contacts between the two jointed bodies are off, as in ballcage
//! (which tests declared pairs only).
//!
//! Why impulse joints, not multibody joints: the chain is held at both ends
//! (the driven upper connector and the lower connector's bearing), a closed
//! loop through the ground, which rapier's reduced-coordinate multibodies
//! cannot represent without an impulse joint anyway.
//!
//! # The bore mesh
//!
//! The scene's tube (a centreline of straight and arc segments and an inner
//! radius r) becomes a triangle mesh of its wall: rings of
//! [`BoreMesh::around`] vertices on the exact wall (an inscribed polygon),
//! one ring every [`BoreMesh::arc_step_deg`] of arc (and every
//! [`BoreMesh::straight_step`] of straight), two triangles per quad, faces
//! oriented toward the centreline (the solid is outside). Default: 64 facets
//! around and one ring per 0.5° of arc, i.e. 180 rings along the paper's 90°
//! arc, 23 040 triangles. Chord errors ([`BoreMesh::chord_errors`]): around,
//! the facet's middle lies r(1 − cos(π/N)) inside the wall, 0.070 mm for
//! r = 58 mm and N = 64; along, the wall at distance R ± r from the arc's
//! centre is cut by chords with sagitta (R ± r)(1 − cos(Δα/2)), 0.015 mm
//! for R = 1.5 m and Δα = 0.5°, which narrow the bore on the outside of the
//! bend and widen it on the inside. The mesh wall is thus within
//! −0.085 mm/+0.015 mm of the analytic one (negative: into the lumen),
//! against ballcage's link–tube penetrations of 0.1–0.3 mm. Like ballcage's
//! tube, the mesh exists on the centreline's segments only: beyond the end
//! planes there is no wall.
//!
//! # The exact bore
//!
//! With [`Bore::Exact`] the bore is instead ballcage's own tube, the parry
//! shape `ballcage_shapes::TubeInterior` taken from the assembled model
//! (the same object ballcage's contact evaluation uses), and the narrow
//! phase is built with `ballcage_shapes::ShapeDispatcher` chained before
//! parry's default dispatcher. The wall is then exact, and each link's
//! contact with it is one manifold per sample along the link in contact (and
//! per exact depth maximum between two samples), each with its own exact
//! depth and normal: the line contact of ballcage's model without its
//! one-force-per-patch reduction, which belongs to the penalty law. The
//! difference between the two rapier runs is the faceted wall; between the
//! exact-bore run and ballcage, rapier's solver (rigid contacts and joints,
//! one Coulomb μ) against ballcage's model.
//!
//! rapier's contact clustering (merging a pair's manifolds of nearly parallel
//! normals into at most four solver points per plane, `contact_clustering`)
//! is off for the exact bore: it serves composite shapes with hundreds of
//! manifolds, and with the few one-point manifolds of the exact bore the
//! impulses rapier 0.35.3 writes back to the merged points did not add up to
//! the load they carry (one link resting in a straight exact bore: 15 N
//! summed against its 78.4 N weight, held all the same), whereas the plain
//! manifolds' impulses sum to 78.39 N (the test
//! `a_link_resting_in_a_straight_exact_bore_weighs_m_g`). The mesh keeps
//! rapier's default (on), under which its own resting test gives m·g.
//!
//! # Contact and friction
//!
//! rapier's contacts are rigid, solved at velocity level with its soft-
//! constraint regularization (contact and static-contact softness at their
//! defaults, 30 and 60 Hz, ζ = 10) and one Coulomb coefficient; ballcage's
//! are the paper's penalty IMPACT law (K = 1e5 N/mm^2.2, c = 10 N·s/mm) with
//! the Adams friction law (μs 0.3 at 100 mm/s, μd 0.1 at 1000 mm/s). The
//! rapier coefficient is the scene's link–tube friction law evaluated at a
//! nominal slip speed, by default the spin of a link's surface at the drive
//! speed, ω₀·r_link (0.45 m/s, μ = 0.233 for the paper's scene); see
//! [`RapierOptions::friction`]. The tube normal force of a link in rapier is
//! the sum of the normal impulses of all its contact manifolds with the bore
//! over a step, divided by the step.
//!
//! # Solver settings
//!
//! `length_unit` is 0.1 m (the links are 86 mm × 200 mm), which scales
//! rapier's tolerances (prediction distance 2 mm, largest corrective velocity
//! 0.3 m/s); contact recycling is off (it keeps a pair's contact points while
//! the pair moves less than 5 mm, and a link spinning in the wall would keep
//! stale points); the other parameters are rapier's defaults (4 substeps).

use std::collections::HashMap;
use std::f64::consts::PI;

use ballcage_core::Document;
use ballcage_core::Simulation;
use ballcage_core::geometry::Shape;
use ballcage_core::model::SpinProfile;
use ballcage_core::scene::{
    BodySpec, FeatureSpec, JointSpec, LoadSpec, MotionKind, ShapeSpec, TubeSegmentSpec,
};
use ballcage_core::{Model, Scene, SceneError};
use ballcage_shapes::ShapeDispatcher;
use rapier3d_f64::parry::query::{DefaultQueryDispatcher, QueryDispatcher};
use rapier3d_f64::prelude::*;

/// Collision group of the link colliders.
const LINKS: Group = Group::GROUP_1;
/// Collision group of the bore mesh.
const BORE: Group = Group::GROUP_2;

/// Builds the paper's drill pipe with the ideal-CV hinge at SDIRK2's fixed
/// steps (as the peer comparison was measured; `dt` is rapier's step too),
/// plus `overrides` (`dotted.key=value`, as on ballcage's command line),
/// with no recorded tables (the comparison reads forces directly).
pub fn paper_ideal_cv(overrides: &[String]) -> Result<Document, SceneError> {
    let mut all = vec![
        "pipe.hinge=\"ideal-cv\"".to_string(),
        "simulation.integrator=\"sdirk2\"".to_string(),
        "simulation.rtol=0".to_string(),
        "record.tables=[]".to_string(),
    ];
    all.extend(overrides.iter().cloned());
    Document::from_toml_str("kind = \"drill-pipe\"\n", &all)
}

/// Resolution of the bore's triangle mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoreMesh {
    /// Facets around the circumference [–].
    pub around: usize,
    /// Largest arc angle between two rings along an arc segment [deg].
    pub arc_step_deg: f64,
    /// Largest distance between two rings along a straight segment [m].
    pub straight_step: f64,
}

impl Default for BoreMesh {
    fn default() -> Self {
        Self {
            around: 64,
            arc_step_deg: 0.5,
            straight_step: 0.01,
        }
    }
}

impl BoreMesh {
    /// Chord errors [m] of this resolution on a tube of inner radius `r` [m]
    /// whose tightest arc has centreline radius `big_r` [m]: (around, along).
    /// Around: r(1 − cos(π/N)), the facet's middle inside the wall. Along:
    /// (R + r)(1 − cos(Δα/2)), the sagitta of the outer wall's chord.
    pub fn chord_errors(&self, r: f64, big_r: f64) -> (f64, f64) {
        let around = r * (1.0 - (PI / self.around as f64).cos());
        let along = (big_r + r) * (1.0 - (0.5 * self.arc_step_deg.to_radians()).cos());
        (around, along)
    }
}

/// What the bore is in rapier.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Bore {
    /// A triangle mesh of the wall ([`RapierOptions::mesh`]), rapier's own
    /// contacts: faceted.
    Mesh,
    /// The exact tube (`ballcage_shapes::TubeInterior`) through
    /// `ballcage_shapes::ShapeDispatcher`, `samples` points along each link
    /// (≥ 2, rims included) locating its line contacts.
    Exact {
        /// Samples along a link's axis.
        samples: u32,
    },
}

/// How the rapier world is set up beyond what the scene says.
#[derive(Debug, Clone, PartialEq)]
pub struct RapierOptions {
    /// The bore: mesh or exact.
    pub bore: Bore,
    /// The bore mesh (with [`Bore::Mesh`]).
    pub mesh: BoreMesh,
    /// Coulomb coefficient of the link–bore contacts [–]; `None` takes the
    /// scene's link–tube friction law at the slip speed ω₀·r_link (the drive
    /// speed times the link radius).
    pub friction: Option<f64>,
    /// rapier's solver substeps (`num_solver_iterations`, default 4).
    pub substeps: usize,
    /// rapier's `length_unit` [m]: the scale of its tolerances.
    pub length_unit: f64,
}

impl Default for RapierOptions {
    fn default() -> Self {
        Self {
            bore: Bore::Mesh,
            mesh: BoreMesh::default(),
            friction: None,
            substeps: 4,
            length_unit: 0.1,
        }
    }
}

/// The bend [rad] at which a cylinder of radius `neck` about one body's axis
/// meets a ring of radius `ring` centred `offset` from the hinge on the other
/// body's axis: the ring's nearest point is ρ·cos β − d·sin β from the
/// cylinder's axis, so β = acos(r/√(ρ² + d²)) − asin(d/√(ρ² + d²)).
pub fn articulation_limit(neck: f64, ring: f64, offset: f64) -> f64 {
    let r = ring.hypot(offset);
    (neck / r).acos() - (offset / r).asin()
}

/// One rapier link: its body, its collider and its name in the scene.
#[derive(Debug, Clone)]
struct Link {
    name: String,
    body: RigidBodyHandle,
    collider: ColliderHandle,
}

/// The rapier world of a ballcage drill-pipe scene, stepped at the scene's
/// step [s].
pub struct RapierChain {
    gravity: Vector,
    params: IntegrationParameters,
    pipeline: PhysicsPipeline,
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    ccd: CCDSolver,
    bore: ColliderHandle,
    links: Vec<Link>,
    drives: Vec<(RigidBodyHandle, SpinProfile, Rotation)>,
    torques: Vec<(RigidBodyHandle, Vector, f64, f64)>,
    friction: f64,
    triangles: usize,
    bend_limit: Option<f64>,
    steps: u64,
}

fn v3(a: [f64; 3]) -> Vector {
    Vector::new(a[0], a[1], a[2])
}

fn quat(q: [f64; 4]) -> Rotation {
    Rotation::from_xyzw(q[1], q[2], q[3], q[0]).normalize()
}

fn err(path: &str, reason: impl Into<String>) -> SceneError {
    SceneError::new(path, "", reason.into())
}

/// The index of the scene's tube body (the bore).
fn tube_body(scene: &Scene) -> Result<usize, SceneError> {
    scene
        .bodies
        .iter()
        .position(|b| matches!(b.shape, ShapeSpec::Tube { .. }))
        .ok_or_else(|| err("bodies", "the scene has no tube body"))
}

/// The links, the bodies in declared pairs with the tube `tube_id`, and
/// those pairs, both in pair order: (link body indices, pair indices).
fn tube_links(scene: &Scene, tube_id: usize) -> Result<(Vec<usize>, Vec<usize>), SceneError> {
    let mut link_ids = Vec::new();
    let mut tube_pairs = Vec::new();
    for (k, c) in scene.contacts.iter().enumerate() {
        let tube = &scene.bodies[tube_id].name;
        if c.bodies[0] == *tube || c.bodies[1] == *tube {
            let other = if c.bodies[0] == *tube {
                &c.bodies[1]
            } else {
                &c.bodies[0]
            };
            let id = scene
                .body_index(other)
                .ok_or_else(|| err("contacts", "unknown body"))?;
            link_ids.push(id);
            tube_pairs.push(k);
        }
    }
    Ok((link_ids, tube_pairs))
}

/// The Coulomb coefficient of the link–bore contacts [–]: the options' own,
/// or the first tube pair's friction law at the slip speed ω₀·r_link (the
/// fastest drive's speed times the largest link radius).
fn link_friction(
    scene: &Scene,
    model: &Model,
    options: &RapierOptions,
    link_ids: &[usize],
    tube_pairs: &[usize],
) -> f64 {
    let drive_speed = scene
        .bodies
        .iter()
        .filter(|b| b.motion == MotionKind::KinematicSpin)
        .map(|b| b.spin_speed.abs())
        .fold(0.0, f64::max);
    let link_radius = link_ids
        .iter()
        .map(|&i| match scene.bodies[i].shape {
            ShapeSpec::Cylinder { radius, .. } => radius,
            _ => 0.0,
        })
        .fold(0.0, f64::max);
    match options.friction {
        Some(mu) => mu,
        None => tube_pairs
            .first()
            .and_then(|&k| model.pairs[k].friction)
            .map_or(0.0, |law| law.coefficient(drive_speed * link_radius).mu),
    }
}

/// The unit spin axis [–] of body `i`, or an error with `reason` if it has none.
fn spin_axis(i: usize, b: &BodySpec, reason: &str) -> Result<Vector, SceneError> {
    let axis = b
        .spin_axis
        .ok_or_else(|| err(&format!("bodies[{i}].spin_axis"), reason))?;
    Ok(v3(axis).normalize())
}

/// Mass [kg] and principal inertia [kg·m²] about the centre of mass.
fn mass_properties(mass: f64, inertia: [f64; 3]) -> MassProperties {
    MassProperties::new(Vector::ZERO, mass, v3(inertia))
}

/// Refuses feature pairs other than the neck–mouth ones: the ball keys have
/// no rapier model here.
fn reject_ball_keys(scene: &Scene) -> Result<(), SceneError> {
    match scene.contacts.iter().position(|c| {
        c.geometry.is_some() && !matches!(c.geometry, Some(FeatureSpec::RingCylinder { .. }))
    }) {
        Some(j) => Err(err(
            &format!("contacts[{j}]"),
            "the rapier baseline models the ideal-CV hinge only (no ball keys)",
        )),
        None => Ok(()),
    }
}

/// The hinge of `cv` joint `joint`: a spherical joint with the twist locked,
/// its bend under the neck–mouth cone limit [rad] if the scene declares one.
fn hinge(scene: &Scene, joint: &JointSpec) -> (GenericJoint, Option<f64>) {
    let JointSpec::Cv {
        bodies: names,
        anchors,
        ..
    } = joint;
    let mut builder = GenericJointBuilder::new(JointAxesMask::LIN_AXES | JointAxesMask::ANG_X)
        .local_anchor1(v3(anchors[0]))
        .local_anchor2(v3(anchors[1]))
        .contacts_enabled(false);
    let limit = neck_limit(scene, names, anchors);
    if let Some(limit) = limit {
        builder = builder
            .coupled_axes(JointAxesMask::ANG_Y | JointAxesMask::ANG_Z)
            .limits(JointAxis::AngY, [-limit, limit]);
    }
    (builder.build(), limit)
}

/// rapier's integration parameters for `scene`'s step [s] and the options.
fn integration_parameters(scene: &Scene, options: &RapierOptions) -> IntegrationParameters {
    IntegrationParameters {
        dt: scene.simulation.dt,
        length_unit: options.length_unit,
        contact_recycling: false,
        // See "The exact bore" in the module doc.
        contact_clustering: options.bore == Bore::Mesh,
        num_solver_iterations: options.substeps,
        ..IntegrationParameters::default()
    }
}

/// The narrow phase of the bore: rapier's own for the mesh, ballcage's
/// shapes chained before it for the exact tube.
fn narrow_phase(options: &RapierOptions) -> NarrowPhase {
    match options.bore {
        Bore::Mesh => NarrowPhase::new(),
        Bore::Exact { samples } => NarrowPhase::with_query_dispatcher(
            ShapeDispatcher::with_samples(samples).chain(DefaultQueryDispatcher),
        ),
    }
}

/// The rapier sets of a world being built from a scene, in the order the
/// scene declares its parts (rapier's results depend on insertion order).
struct WorldBuilder {
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    /// The fixed body the bearings hold on to.
    ground: RigidBodyHandle,
    /// Each scene body's rapier body, by name.
    handles: HashMap<String, RigidBodyHandle>,
    /// The drives: body, prescribed spin and initial rotation.
    drives: Vec<(RigidBodyHandle, SpinProfile, Rotation)>,
}

impl WorldBuilder {
    /// Empty sets but for the ground.
    fn new() -> Self {
        let mut bodies = RigidBodySet::new();
        let ground = bodies.insert(RigidBodyBuilder::fixed().build());
        Self {
            bodies,
            colliders: ColliderSet::new(),
            impulse_joints: ImpulseJointSet::new(),
            ground,
            handles: HashMap::new(),
            drives: Vec::new(),
        }
    }

    /// Adds every scene body, and a collider of `friction` to each of the
    /// links `link_ids`; returns the links in `link_ids` order.
    fn add_bodies(
        &mut self,
        scene: &Scene,
        link_ids: &[usize],
        friction: f64,
    ) -> Result<Vec<Link>, SceneError> {
        let mut links = Vec::new();
        for (i, b) in scene.bodies.iter().enumerate() {
            let handle = self.add_body(i, b)?;
            self.handles.insert(b.name.clone(), handle);
            if let Some(pos) = link_ids.iter().position(|&l| l == i) {
                links.push((pos, self.add_link_collider(i, b, handle, friction)?));
            }
        }
        links.sort_by_key(|(pos, _)| *pos);
        Ok(links.into_iter().map(|(_, l)| l).collect())
    }

    /// Adds scene body `i` as a fixed, a drive or a moving rapier body.
    fn add_body(&mut self, i: usize, b: &BodySpec) -> Result<RigidBodyHandle, SceneError> {
        let pose = Pose::from_parts(v3(b.position), quat(b.orientation));
        match b.motion {
            MotionKind::Fixed => Ok(self
                .bodies
                .insert(RigidBodyBuilder::fixed().pose(pose).build())),
            MotionKind::KinematicSpin => self.add_drive(i, b, pose),
            MotionKind::Dynamic | MotionKind::Spin => self.add_moving(i, b, pose),
            MotionKind::SpinSlide => Err(err(
                &format!("bodies[{i}].motion"),
                "a spin-slide body has no rapier model here",
            )),
            MotionKind::QuasiStatic | MotionKind::QuasiStaticPosition => Err(err(
                &format!("bodies[{i}].motion"),
                "a quasi-static body has no rapier model here",
            )),
        }
    }

    /// A `kinematic-spin` body: position-based kinematic, its spin profile
    /// kept for [`RapierChain::step`].
    fn add_drive(
        &mut self,
        i: usize,
        b: &BodySpec,
        pose: Pose,
    ) -> Result<RigidBodyHandle, SceneError> {
        let axis = spin_axis(i, b, "a drive needs a spin axis")?;
        let (m, inertia) = b.mass_properties().unwrap_or((1.0, [1.0; 3]));
        let h = self.bodies.insert(
            RigidBodyBuilder::kinematic_position_based()
                .pose(pose)
                .additional_mass_properties(mass_properties(m, inertia))
                .can_sleep(false)
                .build(),
        );
        let profile = SpinProfile {
            axis: ballcage_core::math::Vec3::new(axis.x, axis.y, axis.z),
            speed: b.spin_speed,
            ramp: b.spin_ramp,
        };
        self.drives.push((h, profile, pose.rotation));
        Ok(h)
    }

    /// A `dynamic` or `spin` body: dynamic, a `spin` body held to the ground
    /// by a revolute bearing about its spin axis through its centre of mass.
    fn add_moving(
        &mut self,
        i: usize,
        b: &BodySpec,
        pose: Pose,
    ) -> Result<RigidBodyHandle, SceneError> {
        let (m, inertia) = b.mass_properties().ok_or_else(|| {
            err(
                &format!("bodies[{i}]"),
                "a moving body needs mass properties",
            )
        })?;
        let h = self.bodies.insert(
            RigidBodyBuilder::dynamic()
                .pose(pose)
                .additional_mass_properties(mass_properties(m, inertia))
                .linvel(v3(b.velocity))
                .angvel(v3(b.angular_velocity))
                .can_sleep(false)
                .build(),
        );
        if b.motion == MotionKind::Spin {
            let axis = spin_axis(i, b, "a spin body needs an axis")?;
            let bearing = GenericJointBuilder::new(JointAxesMask::LOCKED_REVOLUTE_AXES)
                .local_axis1(axis)
                .local_axis2(pose.rotation.inverse() * axis)
                .local_anchor1(pose.translation)
                .local_anchor2(Vector::ZERO)
                .contacts_enabled(false)
                .build();
            self.impulse_joints.insert(self.ground, h, bearing, true);
        }
        Ok(h)
    }

    /// The cylinder collider of link body `i` (rapier's cylinder runs along
    /// its y axis, ballcage's along x), meeting the bore only.
    fn add_link_collider(
        &mut self,
        i: usize,
        b: &BodySpec,
        handle: RigidBodyHandle,
        friction: f64,
    ) -> Result<Link, SceneError> {
        let ShapeSpec::Cylinder {
            radius,
            half_length,
            ..
        } = b.shape
        else {
            return Err(err(
                &format!("bodies[{i}].shape"),
                "a link in contact with the tube must be a cylinder",
            ));
        };
        let collider = ColliderBuilder::cylinder(half_length, radius)
            .rotation(Vector::new(0.0, 0.0, -0.5 * PI))
            .density(0.0)
            .friction(friction)
            .collision_groups(InteractionGroups::new(
                LINKS,
                BORE,
                InteractionTestMode::And,
            ))
            .build();
        let c = self
            .colliders
            .insert_with_parent(collider, handle, &mut self.bodies);
        Ok(Link {
            name: b.name.clone(),
            body: handle,
            collider: c,
        })
    }

    /// The bore's collider on the `tube` body, whose assembled shape is
    /// `shape`, meeting the links only: (collider, mesh triangles).
    fn add_bore(
        &mut self,
        tube: &BodySpec,
        shape: &Shape,
        options: &RapierOptions,
        friction: f64,
    ) -> Result<(ColliderHandle, usize), SceneError> {
        let (collider, triangles) = bore_collider(tube, shape, options)?;
        let collider = collider
            .friction(friction)
            .collision_groups(InteractionGroups::new(
                BORE,
                LINKS,
                InteractionTestMode::And,
            ))
            .build();
        let bore =
            self.colliders
                .insert_with_parent(collider, self.handles[&tube.name], &mut self.bodies);
        Ok((bore, triangles))
    }

    /// Adds the hinge of every `cv` joint; returns the bend limit [rad] of
    /// the last one with a neck–mouth pair, if any.
    fn add_hinges(&mut self, scene: &Scene) -> Result<Option<f64>, SceneError> {
        let mut bend_limit = None;
        for (j, joint) in scene.joints.iter().enumerate() {
            let (hinge, limit) = hinge(scene, joint);
            bend_limit = limit.or(bend_limit);
            let JointSpec::Cv { bodies: names, .. } = joint;
            let body = |name: &String| {
                self.handles
                    .get(name)
                    .copied()
                    .ok_or_else(|| err(&format!("joints[{j}]"), "unknown body"))
            };
            let (a, b) = (body(&names[0])?, body(&names[1])?);
            self.impulse_joints.insert(a, b, hinge, true);
        }
        Ok(bend_limit)
    }

    /// Each `torque` load: body, unit axis, magnitude [N·m] and ramp [s].
    fn torques(&self, scene: &Scene) -> Vec<(RigidBodyHandle, Vector, f64, f64)> {
        scene
            .loads
            .iter()
            .filter_map(|load| match load {
                LoadSpec::Torque {
                    body,
                    axis,
                    magnitude,
                    ramp,
                } => Some((self.handles[body], v3(*axis).normalize(), *magnitude, *ramp)),
                // refused by from_scene
                LoadSpec::Force { .. } => None,
            })
            .collect()
    }
}

impl RapierChain {
    /// Builds the rapier world of `scene` (a drill pipe with the ideal-CV
    /// hinge, or any scene of the same parts: one fixed `tube` body, links
    /// in declared pairs with it, `cv` joints, `kinematic-spin` and `spin`
    /// bodies, `torque` loads). Refuses parts it has no rapier model for.
    pub fn from_scene(scene: &Scene, options: &RapierOptions) -> Result<Self, SceneError> {
        let (model, _) = ballcage_core::assembly::assemble(scene)?;
        let tube_id = tube_body(scene)?;
        let (link_ids, tube_pairs) = tube_links(scene, tube_id)?;
        let friction = link_friction(scene, &model, options, &link_ids, &tube_pairs);
        let mut world = WorldBuilder::new();
        let links = world.add_bodies(scene, &link_ids, friction)?;
        let tube = &scene.bodies[tube_id];
        let (bore, triangles) =
            world.add_bore(tube, &model.bodies[tube_id].shape, options, friction)?;
        let bend_limit = world.add_hinges(scene)?;
        reject_ball_keys(scene)?;
        if let Some(i) = (scene.loads.iter()).position(|l| matches!(l, LoadSpec::Force { .. })) {
            return Err(err(
                &format!("loads[{i}]"),
                "a force load has no rapier model here",
            ));
        }
        let torques = world.torques(scene);
        for (_, b) in world.bodies.iter_mut() {
            b.recompute_mass_properties_from_colliders(&world.colliders);
        }
        Ok(Self {
            gravity: v3(scene.world.gravity),
            params: integration_parameters(scene, options),
            pipeline: PhysicsPipeline::new(),
            islands: IslandManager::new(),
            broad_phase: BroadPhaseBvh::new(),
            narrow_phase: narrow_phase(options),
            bodies: world.bodies,
            colliders: world.colliders,
            impulse_joints: world.impulse_joints,
            multibody_joints: MultibodyJointSet::new(),
            ccd: CCDSolver::new(),
            bore,
            links,
            drives: world.drives,
            torques,
            friction,
            triangles,
            bend_limit,
            steps: 0,
        })
    }

    /// The step [s].
    pub fn dt(&self) -> f64 {
        self.params.dt
    }

    /// Simulated time [s].
    pub fn time(&self) -> f64 {
        self.steps as f64 * self.params.dt
    }

    /// Steps taken.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The Coulomb coefficient of the link–bore contacts [–].
    pub fn friction(&self) -> f64 {
        self.friction
    }

    /// Triangles of the bore mesh.
    pub fn triangles(&self) -> usize {
        self.triangles
    }

    /// The hinges' bend limit [rad], if the scene declares neck–mouth pairs.
    pub fn bend_limit(&self) -> Option<f64> {
        self.bend_limit
    }

    /// The links' names, in the order of [`Self::tube_normal_forces`].
    pub fn link_names(&self) -> Vec<String> {
        self.links.iter().map(|l| l.name.clone()).collect()
    }

    /// Total mass of the moving (dynamic) bodies [kg].
    pub fn moving_mass(&self) -> f64 {
        self.bodies
            .iter()
            .filter(|(_, b)| b.is_dynamic())
            .map(|(_, b)| b.mass())
            .sum()
    }

    /// Centre of mass of link `k` (in [`Self::link_names`] order) [m].
    pub fn link_position(&self, k: usize) -> [f64; 3] {
        let t = self.bodies[self.links[k].body].translation();
        [t.x, t.y, t.z]
    }

    /// Takes one step: sets the drive's next pose and the resisting moment
    /// at the step's start, then steps the pipeline.
    pub fn step(&mut self) {
        let t = self.time();
        let h = self.params.dt;
        for (handle, profile, q0) in &self.drives {
            let a = profile.axis;
            let axis = Vector::new(a.x, a.y, a.z);
            let q = Rotation::from_axis_angle(axis, profile.angle(t + h)) * *q0;
            self.bodies[*handle].set_next_kinematic_rotation(q);
        }
        for (handle, axis, magnitude, ramp) in &self.torques {
            let s = ballcage_core::force::step(t, 0.0, 0.0, *ramp, 1.0).0;
            let b = &mut self.bodies[*handle];
            b.reset_torques(false);
            b.add_torque(*axis * (*magnitude * s), true);
        }
        self.pipeline.step(
            self.gravity,
            &self.params,
            &mut self.islands,
            &mut self.broad_phase,
            &mut self.narrow_phase,
            &mut self.bodies,
            &mut self.colliders,
            &mut self.impulse_joints,
            &mut self.multibody_joints,
            &mut self.ccd,
            &(),
            &(),
        );
        self.steps += 1;
    }

    /// Steps until the time reaches at least `t_end` [s].
    pub fn advance_to(&mut self, t_end: f64) {
        let target = (t_end / self.params.dt - 1e-9).ceil().max(0.0) as u64;
        while self.steps < target {
            self.step();
        }
    }

    /// Each link's resultant tube normal force over the last step [N], the
    /// vector sum of its contacts' normal forces on the link, world frame.
    /// Its magnitude is at most [`Self::tube_normal_forces`]: in a faceted
    /// bore a link pressing into the groove between two facets takes two
    /// inclined normals, and rapier's rigid contacts may carry any
    /// self-equilibrated wedge force between them (statically indeterminate).
    pub fn tube_force_resultants(&self) -> Vec<[f64; 3]> {
        self.links
            .iter()
            .map(|l| {
                let mut f = self
                    .narrow_phase
                    .contact_pair(l.collider, self.bore)
                    .map_or(Vector::ZERO, |p| {
                        // Normals point from collider 1 to collider 2: the
                        // force on the link points the other way when it is
                        // collider 1.
                        let v = solved_normal_impulse_vector(p);
                        if p.collider1 == l.collider { -v } else { v }
                    });
                f /= self.params.dt;
                [f.x, f.y, f.z]
            })
            .collect()
    }

    /// Each link's tube normal force over the last step [N]: the sum of the
    /// normal impulses of its contact manifolds with the bore, over the step.
    pub fn tube_normal_forces(&self) -> Vec<f64> {
        self.links
            .iter()
            .map(|l| {
                self.narrow_phase
                    .contact_pair(l.collider, self.bore)
                    .map_or(0.0, solved_normal_impulse)
                    / self.params.dt
            })
            .collect()
    }
}

/// The normal impulses [N·s] the solver applied over the last step between
/// the pair's colliders, summed as vectors (from collider 1 toward 2); see
/// [`solved_normal_impulse`].
fn solved_normal_impulse_vector(pair: &ContactPair) -> Vector {
    pair.solver_manifolds()
        .iter()
        .map(|m| {
            m.data.normal
                * m.data
                    .solver_contacts
                    .iter()
                    .map(|sc| m.points[sc.contact_indices()[0] as usize].data.impulse)
                    .sum::<f64>()
        })
        .sum()
}

/// The normal impulse [N·s] the solver applied over the last step between
/// the pair's colliders: the sum over the solver contacts of every manifold
/// the solver saw (the clusters when rapier clusters the manifolds of a
/// mesh). The impulses are read through the solver contacts' indices: a
/// point of a manifold that was not a solver contact in this step keeps the
/// impulse of an earlier step, so `ContactPair::total_impulse_magnitude`,
/// which sums every point, over-counts on a mesh (by 6.7 times for a link
/// resting in a straight bore).
fn solved_normal_impulse(pair: &ContactPair) -> f64 {
    pair.solver_manifolds()
        .iter()
        .map(|m| {
            m.data
                .solver_contacts
                .iter()
                .map(|sc| m.points[sc.contact_indices()[0] as usize].data.impulse)
                .sum::<f64>()
        })
        .sum()
}

/// The bend limit of the neck–mouth pair of the hinge between `names` with
/// `anchors`, if the scene declares one: the ring on one body, the cylinder
/// on the other, the ring's offset measured from the ring body's anchor.
fn neck_limit(scene: &Scene, names: &[String; 2], anchors: &[[f64; 3]; 2]) -> Option<f64> {
    scene.contacts.iter().find_map(|c| {
        let Some(FeatureSpec::RingCylinder {
            ring_centre,
            ring_radius,
            cylinder_radius,
            ..
        }) = &c.geometry
        else {
            return None;
        };
        let ring_side = names.iter().position(|n| *n == c.bodies[0])?;
        if !names.contains(&c.bodies[1]) || c.bodies[0] == c.bodies[1] {
            return None;
        }
        let offset = (v3(*ring_centre) - v3(anchors[ring_side])).length();
        Some(articulation_limit(*cylinder_radius, *ring_radius, offset))
    })
}

/// The bore's collider (without friction and groups) and its triangle
/// count (0 for the exact tube): the mesh of `tube`'s wall, or the exact
/// tube of ballcage's assembled `shape` of it.
fn bore_collider(
    tube: &BodySpec,
    shape: &Shape,
    options: &RapierOptions,
) -> Result<(ColliderBuilder, usize), SceneError> {
    let ShapeSpec::Tube {
        inner_radius,
        start,
        direction,
        segments,
        ..
    } = &tube.shape
    else {
        return Err(err("bodies", "the bore must be a tube"));
    };
    match (options.bore, shape) {
        (Bore::Exact { .. }, Shape::Tube(path)) => Ok((
            ColliderBuilder::new(SharedShape::new(path.interior().clone())).density(0.0),
            0,
        )),
        (Bore::Exact { .. }, _) => Err(err("bodies", "the bore must be a tube")),
        (Bore::Mesh, _) => {
            let (vertices, indices) = bore_mesh(
                *inner_radius,
                v3(*start),
                v3(*direction),
                segments,
                &options.mesh,
            );
            let triangles = indices.len();
            let mesh =
                ColliderBuilder::trimesh_with_flags(vertices, indices, TriMeshFlags::ORIENTED)
                    .map_err(|e| err("bodies.tube", format!("bore mesh: {e:?}")))?;
            Ok((mesh, triangles))
        }
    }
}

/// Vertices and triangles of the wall of a tube of inner radius `r` around
/// the centreline from `start` along `direction` through `segments`, faces
/// toward the centreline.
fn bore_mesh(
    r: f64,
    start: Vector,
    direction: Vector,
    segments: &[TubeSegmentSpec],
    res: &BoreMesh,
) -> (Vec<Vector>, Vec<[u32; 3]>) {
    let mut t = direction.normalize();
    // A frame (u, w) across the centreline, carried along without twist.
    let mut u = t.any_orthonormal_vector();
    let mut p = start;
    let mut rings: Vec<(Vector, Vector, Vector)> = vec![(p, u, t.cross(u))];
    for s in segments {
        match *s {
            TubeSegmentSpec::Straight { length } => {
                let n = (length / res.straight_step).ceil().max(1.0) as usize;
                for k in 1..=n {
                    rings.push((p + t * (length * k as f64 / n as f64), u, t.cross(u)));
                }
                p += t * length;
            }
            TubeSegmentSpec::Arc {
                radius,
                angle_deg,
                bend,
            } => {
                let b = v3(bend);
                let b = (b - t * b.dot(t)).normalize();
                let centre = p + b * radius;
                let axis = t.cross(b);
                let n = (angle_deg / res.arc_step_deg).ceil().max(1.0) as usize;
                let (p0, t0, u0) = (p, t, u);
                for k in 1..=n {
                    let a = angle_deg.to_radians() * k as f64 / n as f64;
                    let rot = Rotation::from_axis_angle(axis, a);
                    p = centre + rot * (p0 - centre);
                    t = rot * t0;
                    u = rot * u0;
                    rings.push((p, u, t.cross(u)));
                }
            }
        }
    }
    let m = res.around;
    let mut vertices = Vec::with_capacity(rings.len() * m);
    for (c, u, w) in &rings {
        for j in 0..m {
            let phi = 2.0 * PI * j as f64 / m as f64;
            vertices.push(*c + (*u * phi.cos() + *w * phi.sin()) * r);
        }
    }
    let mut indices = Vec::with_capacity(2 * (rings.len() - 1) * m);
    for i in 0..rings.len() - 1 {
        for j in 0..m {
            let a = (i * m + j) as u32;
            let b = (i * m + (j + 1) % m) as u32;
            let c = ((i + 1) * m + j) as u32;
            let d = ((i + 1) * m + (j + 1) % m) as u32;
            // (b − a) runs around (+φ), (c − a) along (+t): (w·…)×t points
            // outward, so the order a, c, b faces the centreline.
            indices.push([a, c, b]);
            indices.push([b, c, d]);
        }
    }
    (vertices, indices)
}

/// ballcage's side of the comparison: the tube pairs of a drill-pipe scene
/// and their per-step normal forces.
pub struct BallcageTubeForces {
    pairs: Vec<usize>,
}

impl BallcageTubeForces {
    /// The link–tube pairs of `scene`, in declared order (links 1…n).
    pub fn new(scene: &Scene) -> Self {
        let tube = scene
            .bodies
            .iter()
            .find(|b| matches!(b.shape, ShapeSpec::Tube { .. }))
            .map(|b| b.name.clone())
            .unwrap_or_default();
        let pairs = scene
            .contacts
            .iter()
            .enumerate()
            .filter(|(_, c)| c.bodies.contains(&tube))
            .map(|(k, _)| k)
            .collect();
        Self { pairs }
    }

    /// Each link's tube normal force at the simulation's current state [N]:
    /// the sum of the normal forces of the pair's contact patches.
    pub fn sample(&self, sim: &mut Simulation) -> Vec<f64> {
        self.pairs
            .iter()
            .map(|&k| sim.pair_contacts(k).iter().map(|c| c.normal_force).sum())
            .collect()
    }

    /// Each link's tube normal force and the magnitude sum of its friction
    /// forces at the simulation's current state [N]: (normal, tangential).
    pub fn sample_with_friction(&self, sim: &mut Simulation) -> (Vec<f64>, Vec<f64>) {
        let mut normal = Vec::with_capacity(self.pairs.len());
        let mut tangential = Vec::with_capacity(self.pairs.len());
        for &k in &self.pairs {
            let points = sim.pair_contacts(k);
            normal.push(points.iter().map(|c| c.normal_force).sum());
            tangential.push(points.iter().map(|c| c.tangential_force.norm()).sum());
        }
        (normal, tangential)
    }
}

/// Time averages of per-step samples over a window `[start, end]` [s].
#[derive(Debug, Clone, Default)]
pub struct WindowMean {
    start: f64,
    end: f64,
    sums: Vec<f64>,
    count: u64,
}

impl WindowMean {
    /// An empty average over `[start, end]` [s].
    pub fn new(start: f64, end: f64) -> Self {
        Self {
            start,
            end,
            sums: vec![],
            count: 0,
        }
    }

    /// Whether a sample at time `t` [s] falls in the window.
    pub fn wants(&self, t: f64) -> bool {
        t >= self.start - 1e-12 && t <= self.end + 1e-12
    }

    /// Adds the sample `values` taken at the end of a step at time `t` [s].
    pub fn add(&mut self, t: f64, values: &[f64]) {
        if !self.wants(t) {
            return;
        }
        if self.sums.is_empty() {
            self.sums = vec![0.0; values.len()];
        }
        for (s, v) in self.sums.iter_mut().zip(values) {
            *s += v;
        }
        self.count += 1;
    }

    /// The means, one per sampled value (empty without samples).
    pub fn means(&self) -> Vec<f64> {
        self.sums.iter().map(|s| s / self.count as f64).collect()
    }

    /// Samples taken.
    pub fn count(&self) -> u64 {
        self.count
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper(overrides: &[&str]) -> Scene {
        let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        paper_ideal_cv(&o).expect("valid scene").scene().clone()
    }

    #[test]
    fn the_rapier_world_moves_the_same_mass_as_the_scene() {
        let scene = paper(&[]);
        let chain = RapierChain::from_scene(&scene, &RapierOptions::default()).expect("builds");
        let expected: f64 = scene
            .bodies
            .iter()
            .filter(|b| b.is_integrated())
            .map(|b| b.mass_properties().expect("mass").0)
            .sum();
        assert!(
            (chain.moving_mass() - expected).abs() < 1e-9 * expected,
            "{} vs {expected}",
            chain.moving_mass()
        );
        assert_eq!(chain.link_names().len(), 12);
    }

    #[test]
    fn the_bend_limit_is_the_drill_pipes_articulation_limit() {
        let doc = paper_ideal_cv(&[]).expect("valid scene");
        let (spec, _) = doc.drill_pipe_parts().expect("a drill pipe");
        let chain =
            RapierChain::from_scene(doc.scene(), &RapierOptions::default()).expect("builds");
        let want = spec.articulation_limit().expect("a neck");
        let got = chain.bend_limit().expect("neck pairs found");
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }

    #[test]
    fn the_mesh_is_narrower_than_the_bore_by_at_most_its_chord_errors() {
        let r = 0.058;
        let res = BoreMesh::default();
        let segs = [TubeSegmentSpec::Arc {
            radius: 1.5,
            angle_deg: 90.0,
            bend: [1.0, 0.0, 0.0],
        }];
        let (v, idx) = bore_mesh(r, Vector::ZERO, Vector::new(0.0, 0.0, -1.0), &segs, &res);
        assert_eq!(idx.len(), 2 * 64 * 180);
        let (around, along) = res.chord_errors(r, 1.5);
        // Every vertex on the wall; every facet centroid off it by less than
        // the chord errors, and its normal toward the centreline.
        let centre = Vector::new(1.5, 0.0, 0.0);
        let wall = |p: Vector| {
            let q = Vector::new(p.x, 0.0, p.z) - centre;
            let c = centre + q.normalize() * 1.5;
            ((p - c).length(), c)
        };
        for p in &v {
            assert!((wall(*p).0 - r).abs() < 1e-12);
        }
        for t in &idx {
            let (a, b, c) = (v[t[0] as usize], v[t[1] as usize], v[t[2] as usize]);
            let g = (a + b + c) / 3.0;
            let (d, axis) = wall(g);
            assert!((r - d).abs() < around + along, "{}", r - d);
            assert!((b - a).cross(c - a).dot(axis - g) > 0.0, "faces inward");
        }
    }

    /// One link (8 kg, r = 43 mm) lying 14.8 mm below the axis of a straight,
    /// horizontal bore of R = 58 mm, 1 m long, under gravity; 0.5 s at 1 ms.
    fn resting_link() -> Scene {
        let text = r#"
[simulation]
duration = 0.5
dt = 1e-3
output_interval = 1e-3
[world]
gravity = [0.0, 0.0, -9.8]
[[bodies]]
name = "tube"
motion = "fixed"
shape = { type = "tube", inner_radius = 0.058, start = [-0.5, 0.0, 0.0], direction = [1.0, 0.0, 0.0], segments = [{ type = "straight", length = 1.0 }] }
[[bodies]]
name = "link"
shape = { type = "cylinder", radius = 0.043, half_length = 0.1 }
mass = 8.0
inertia = [8.3e-3, 3.1e-2, 3.1e-2]
position = [0.0, 0.0, -0.0148]
[[contacts]]
bodies = ["tube", "link"]
normal = { law = "impact", stiffness = 1e5, exponent = 2.2, damping = 10.0, depth_max = 0.1, units = "N-mm-s" }
friction = { law = "adams", mu_static = 0.3, mu_dynamic = 0.1, v_static = 100.0, v_dynamic = 1000.0, units = "N-mm-s" }
"#;
        Scene::from_toml_str(text, &[]).expect("valid scene")
    }

    /// One link lying in a straight, horizontal bore under gravity: the bore
    /// carries its weight, m·g, once the link has settled (mean over
    /// 0.2–0.5 s at 1 ms).
    #[test]
    fn a_link_resting_in_a_straight_bore_weighs_m_g() {
        let scene = resting_link();
        let mut chain = RapierChain::from_scene(&scene, &RapierOptions::default()).expect("builds");
        let mut mean = WindowMean::new(0.2, 0.5);
        while chain.time() < 0.5 - 1e-9 {
            chain.step();
            let mut sample = chain.tube_normal_forces();
            sample.extend(chain.tube_force_resultants()[0]);
            mean.add(chain.time(), &sample);
        }
        // The resultant carries the weight, upward. The sum of the contact
        // forces' magnitudes exceeds it: the link lies in the groove between
        // two facets and rapier's rigid contacts carry a varying wedge force
        // between them (measured: 3.8 % on average, up to 10 % in a step).
        // Summing every manifold point's impulse instead of the solver
        // contacts' gave 6.7 m·g.
        let m = mean.means();
        let w = 8.0 * 9.8;
        assert!(
            (m[3] - w).abs() < 0.005 * w,
            "resultant {m:?} vs weight {w} N"
        );
        assert!(m[1].abs() < 0.005 * w && m[2].abs() < 0.02 * w, "{m:?}");
        assert!(
            m[0] >= m[3] && m[0] < 1.1 * w,
            "sum {} N vs weight {w} N",
            m[0]
        );
        // The link rests on the mesh's bottom: within the chord error of the wall.
        let z = chain.link_position(0)[2];
        let (around, _) = RapierOptions::default().mesh.chord_errors(0.058, 1.0);
        assert!((z + 0.015).abs() < around + 2e-4, "z = {z}");
    }

    /// The same link in the exact bore (ballcage's tube through
    /// `ShapeDispatcher`): each of its five samples along the bottom has the
    /// exact normal, straight up, so the contact forces' sum and resultant
    /// are the same and carry m·g, and the link rests at the wall itself:
    /// its axis R − r = 15 mm below the bore's, within rapier's allowed
    /// penetration (0.001 × length_unit = 0.1 mm) and no chord error.
    #[test]
    fn a_link_resting_in_a_straight_exact_bore_weighs_m_g() {
        let options = RapierOptions {
            bore: Bore::Exact { samples: 5 },
            ..RapierOptions::default()
        };
        let mut chain = RapierChain::from_scene(&resting_link(), &options).expect("builds");
        assert_eq!(chain.triangles(), 0);
        let mut mean = WindowMean::new(0.2, 0.5);
        while chain.time() < 0.5 - 1e-9 {
            chain.step();
            let mut sample = chain.tube_normal_forces();
            sample.extend(chain.tube_force_resultants()[0]);
            mean.add(chain.time(), &sample);
        }
        let m = mean.means();
        let w = 8.0 * 9.8;
        assert!(
            (m[3] - w).abs() < 0.005 * w,
            "resultant {m:?} vs weight {w} N"
        );
        assert!(
            (m[0] - m[3]).abs() < 1e-6 * w,
            "sum {} vs resultant {}",
            m[0],
            m[3]
        );
        let z = chain.link_position(0)[2];
        assert!((z + 0.015).abs() < 1e-4 + 1e-6, "z = {z}");
    }

    /// The paper's chain against the exact bore for 0.1 s from rest (at
    /// 1 ms): rapier steps it through the custom dispatcher, the links
    /// press on the wall, every force is finite and the total is of the
    /// order of the chain's weight (the drive and load ramps have barely
    /// begun: the moment is 1800·STEP(0.1 s) ≈ 0.26 kN·m).
    #[test]
    fn the_chain_in_the_exact_bore_produces_tube_forces() {
        let scene = paper(&["simulation.duration=0.1"]);
        let options = RapierOptions {
            bore: Bore::Exact { samples: 5 },
            ..RapierOptions::default()
        };
        let mut chain = RapierChain::from_scene(&scene, &options).expect("builds");
        let mut mean = WindowMean::new(0.05, 0.1);
        while chain.time() < 0.1 - 1e-9 {
            chain.step();
            mean.add(chain.time(), &chain.tube_normal_forces());
        }
        let f = mean.means();
        assert_eq!(f.len(), 12);
        assert!(f.iter().all(|x| x.is_finite() && *x >= 0.0), "{f:?}");
        let total: f64 = f.iter().sum();
        let weight = chain.moving_mass() * 9.8;
        assert!(
            total > 0.1 * weight && total < 10.0 * weight,
            "{total} N against {weight} N"
        );
    }
}
