//! Narrow phase: where declared pairs touch.
//!
//! # Sign convention (the only place it is defined)
//! A [`ContactPoint`] of the pair `(a, b)`:
//! - `depth` δ [m] is positive when the surfaces overlap;
//! - `normal` is a unit world vector pointing **from a toward b**: the normal
//!   force on b is `+F_n·normal`, on a `−F_n·normal`;
//! - `point` [m] is midway between the two surface points;
//! - the penetration rate δ̇ = −(v_b(p) − v_a(p))·normal is positive while approaching.
//!
//! # Pair table
//! | pair | method |
//! |---|---|
//! | half-space–ball, ball–ball, ball–cuboid | parry3d `query::contact` (exact for these convex pairs) |
//! | cuboid–half-space | analytic: each vertex below the plane is a point |
//! | cylinder–tube | analytic line contact (`line.rs`): one point per contact patch at its deepest penetration; `points` samples along the axis locate the patches |
//! | ball–tube | analytic: distance to the centreline |
//! | declared features (groove flank, window, spherical cavity, ring–cylinder) | analytic, in the bodies' frames (`ring.rs` for a neck through a ring) |
//!
//! The tube, the groove flank (`TorusBall`), the window (`SlotBall`) and the
//! cavity (`CavitySphere`) are computed by the crate `ballcage-shapes`
//! (`TubeInterior`, `GrooveFlank`, `WindowSlot`, `SphericalCavity`), whose
//! types are also parry shapes with a query dispatcher for rapier: one
//! geometry code path for ballcage, parry and rapier. Here the bodies are
//! placed in the feature's frame and the contact mapped back; the engine's
//! nalgebra vectors and parry's glam vectors convert component by component.

mod line;
mod ring;
mod tube;

pub use ring::RingCylinder;

pub use tube::{CentrelinePoint, TubePath, TubeSegment};

use ballcage_shapes::{GrooveFlank, LocalContact, SphericalCavity, WindowSlot};
use parry3d_f64::query;
use parry3d_f64::shape::{Ball, Cuboid, HalfSpace};

use crate::math::{Mat3, Quat, Vec3, from_glam, to_glam, to_glam_pose};

/// A shape ready for queries.
#[derive(Debug, Clone)]
pub enum Shape {
    /// Sphere.
    Ball(Ball),
    /// Box.
    Cuboid(Cuboid),
    /// Half-space (boundary through the body origin).
    HalfSpace(HalfSpace),
    /// Cylinder along the body x axis.
    Cylinder {
        /// Outer radius [m].
        radius: f64,
        /// Half-length [m].
        half_length: f64,
    },
    /// Inside of a tube.
    Tube(TubePath),
}

impl Shape {
    /// Radius of curvature of the shape's surface [m]: ball, cylinder or
    /// tube radius, the smallest half-extent of a cuboid, infinite for a
    /// half-space.
    pub fn radius(&self) -> f64 {
        match self {
            Self::Ball(b) => b.radius,
            Self::Cuboid(c) => c.half_extents.min_element(),
            Self::HalfSpace(_) => f64::INFINITY,
            Self::Cylinder { radius, .. } => *radius,
            Self::Tube(t) => t.inner_radius(),
        }
    }

    /// A sphere of `radius` [m] centred at the body origin.
    pub fn ball(radius: f64) -> Self {
        Self::Ball(Ball::new(radius))
    }

    /// A box of `half_extents` [m] along the body axes.
    pub fn cuboid(half_extents: Vec3) -> Self {
        Self::Cuboid(Cuboid::new(to_glam(&half_extents)))
    }

    /// A half-space with outward boundary `normal` (normalized here), its
    /// plane through the body origin.
    pub fn half_space(normal: Vec3) -> Self {
        Self::HalfSpace(HalfSpace::new(to_glam(&normal.normalize())))
    }
}

/// One point of contact; see the module doc for the sign convention.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    /// Stable index of this point within its pair (vertex, sample), for per-point memory.
    pub slot: u32,
    /// Midpoint between the surfaces [m], world frame.
    pub point: Vec3,
    /// Unit normal from body a toward body b, world frame.
    pub normal: Vec3,
    /// Overlap δ > 0 [m].
    pub depth: f64,
    /// The sign with which this point's law enters its pair: +1, except at
    /// a depth minimum of the level-set line law ([`LineLaw::LevelSets`]),
    /// where the point law is subtracted (−1). Forces, their derivatives
    /// and the elastic energy of the point are multiplied by it.
    pub weight: f64,
    /// How the normal turns as the bodies move, for the geometric terms
    /// of the Jacobian: only that reads it, so a query may leave it
    /// [`NormalTurning::plane`] at the point where its sink does not want it
    /// ([`PointSink::wants_turning`]) and it costs a query of its own.
    pub turning: NormalTurning,
}

/// Where a pair's contact query puts the points it finds: a `Vec`, or the
/// pair's fixed range of slots in the engine's flat per-contact arrays
/// ([`SlotSink`]).
pub trait PointSink {
    /// Appends one point.
    fn push(&mut self, point: ContactPoint);

    /// Forgets every point.
    fn clear(&mut self);

    /// The points appended since the last [`PointSink::clear`].
    fn filled(&mut self) -> &mut [ContactPoint];

    /// Whether the points' [`ContactPoint::turning`] will be read (by the
    /// Jacobian); true unless the sink says otherwise.
    #[inline]
    fn wants_turning(&self) -> bool {
        true
    }

    /// Appends `point` if there is one.
    #[inline]
    fn push_some(&mut self, point: Option<ContactPoint>) {
        if let Some(p) = point {
            self.push(p);
        }
    }
}

impl PointSink for Vec<ContactPoint> {
    #[inline]
    fn push(&mut self, point: ContactPoint) {
        Vec::push(self, point);
    }

    fn clear(&mut self) {
        Vec::clear(self);
    }

    fn filled(&mut self) -> &mut [ContactPoint] {
        self
    }
}

/// A pair's range of slots in a flat array, filled from its start: it holds
/// as many points as [`PairGeometry::slots`] says the pair can report.
#[derive(Debug)]
pub struct SlotSink<'a> {
    /// The pair's slots.
    pub slots: &'a mut [ContactPoint],
    /// How many are filled.
    pub len: usize,
    /// Whether the points' turning is wanted (a Jacobian evaluation).
    pub turning: bool,
}

impl PointSink for SlotSink<'_> {
    #[inline]
    fn push(&mut self, point: ContactPoint) {
        // Every query reports at most `PairGeometry::slots` points, each in
        // a slot of its own (a straight link crosses each of the tube's end
        // planes once). Were one to report more, the extra points would be
        // dropped rather than the run stopped by a panic.
        if let Some(slot) = self.slots.get_mut(self.len) {
            *slot = point;
            self.len += 1;
        }
    }

    fn clear(&mut self) {
        self.len = 0;
    }

    fn filled(&mut self) -> &mut [ContactPoint] {
        &mut self.slots[..self.len]
    }

    #[inline]
    fn wants_turning(&self) -> bool {
        self.turning
    }
}

impl ContactPoint {
    /// A slot not in use (all zeros): what flat per-contact arrays are
    /// filled with before any evaluation.
    pub const UNUSED: Self = Self {
        slot: 0,
        point: Vec3::new(0.0, 0.0, 0.0),
        normal: Vec3::new(0.0, 0.0, 0.0),
        depth: 0.0,
        weight: 0.0,
        turning: NormalTurning {
            centre: Vec3::new(0.0, 0.0, 0.0),
            curvature: Mat3::new(0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
            centre_on_b: true,
            motion: CentreMotion::Fixed,
        },
    };
}

/// How a contact point's normal turns as the bodies move: the data of the
/// geometric terms of the force Jacobian (`dynamics::CouplingJacobian`).
///
/// The normal force acts along the normal through `centre`, a point c fixed
/// in one body (a ball's centre, a cuboid's vertex, the axis point of a
/// link's section, a ring's point); the normal is a field n(c) carried by
/// the other body. With that body held, `curvature` is ∂n/∂c. For c inside
/// a lumen at distance ρ from its core curve (nearest point P, unit tangent
/// t̂, curvature vector κ): n = −(c − P)/ρ and
/// ∂n/∂c = −(I − n·nᵀ − β·t̂·t̂ᵀ)/ρ with β = 1/(1 − (c − P)·κ) (β = 0 for
/// a spherical cavity, β = R/|c⊥| for a torus of core radius R); zero for
/// a plane. Where c also moves on its body as the bodies move (a link's
/// interior depth extremum along the link's axis, the ring point nearest a
/// neck's axis along the ring, a link's rim point), `motion` says how.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormalTurning {
    /// The point c [m], world frame.
    pub centre: Vec3,
    /// ∂n/∂c [1/m], world frame, the body carrying the field held.
    pub curvature: Mat3,
    /// Whether c is carried by body b (and the field by a); else by a.
    pub centre_on_b: bool,
    /// How c moves on its body beyond moving with it.
    pub motion: CentreMotion,
}

/// How a contact's centre c moves on the body carrying it, beyond moving
/// with that body.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum CentreMotion {
    /// c is a material point of its body.
    #[default]
    Fixed,
    /// c slides along a curve where the normal is perpendicular to it.
    Slides(Slide),
    /// c is a flat rod end's rim point in a lumen.
    Rim(Rim),
    /// c is the axis point of the rod's section in an open end's plane.
    Crosses(Crossing),
}

/// A flat rod end's rim point in a lumen (`ballcage_shapes::line`): with q
/// the end's axis point, â the axis, u = q − P(q) its offset from the
/// core curve and d the unit part of u across â, the rim point is
/// w = q + r·d. As the bodies move, d turns on the rod's end face:
/// δd = (I − d·dᵀ)/|Π·u| · δ(Π·u), Π = I − â·âᵀ, with
/// δu = (I − β·t̂·t̂ᵀ)·δq_rel + δθ_lumen × u and δâ = δθ_rod × â.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rim {
    /// The end's axis point q [m], world frame.
    pub end: Vec3,
    /// The rod's unit axis â, world frame.
    pub axis: Vec3,
    /// The rod's radius r [m].
    pub radius: f64,
    /// u = q − P(q) [m], world frame.
    pub offset: Vec3,
    /// Unit tangent t̂ of the core curve at P(q), world frame.
    pub core_tangent: Vec3,
    /// β = 1/(1 − u·κ) at P(q), κ the core's curvature vector.
    pub beta: f64,
}

/// The section of a flat rod in the plane of a lumen's open end (the last
/// one with a wall, `ballcage_shapes::line`): its deepest point c is a rim
/// point of that section ([`Rim`], `rim.end` the section's axis point q),
/// and the section slides along the rod's axis â so that its point p on the
/// plane (q, or c where c reaches the plane first) stays on it. With t̂ the
/// plane's normal, carried by the lumen's body, the slide δs follows from
/// t̂·δp = 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    /// The section as a rim.
    pub rim: Rim,
    /// The plane's unit normal t̂, world frame.
    pub plane_normal: Vec3,
    /// Whether the deepest point c, not the axis point q, is the one on the
    /// plane.
    pub rim_on_plane: bool,
}

/// The curve on its body along which a contact's centre c slides: c stays
/// where the normal is perpendicular to the curve, n·â = 0, so a pose
/// change moves c along â by
/// δs = −(âᵀH·δu + (â × n)·(δθ_c − δθ_field)) / (âᵀH·â + n·κ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slide {
    /// Unit tangent â of the curve at c, world frame.
    pub direction: Vec3,
    /// Curvature vector κ of the curve at c [1/m], world frame (zero for a
    /// straight axis).
    pub curvature: Vec3,
}

impl NormalTurning {
    /// c carried by b with a constant normal field (a plane of a).
    pub fn plane(centre: Vec3) -> Self {
        Self {
            centre,
            curvature: Mat3::zeros(),
            centre_on_b: true,
            motion: CentreMotion::Fixed,
        }
    }

    /// c carried by b inside a lumen of a: at distance `rho` [m] from the
    /// core's nearest point, whose unit tangent is `tangent` and curvature
    /// vector `kappa` [1/m] (zero tangent for a spherical cavity); `normal`
    /// = −(c − P)/ρ.
    pub fn lumen(centre: Vec3, normal: &Vec3, rho: f64, tangent: &Vec3, kappa: &Vec3) -> Self {
        let beta = 1.0 / (1.0 + rho * normal.dot(kappa));
        let across =
            Mat3::identity() - normal * normal.transpose() - beta * tangent * tangent.transpose();
        Self {
            centre,
            curvature: -across / rho,
            centre_on_b: true,
            motion: CentreMotion::Fixed,
        }
    }

    /// The same turning seen from the pair in the other order (normal reversed).
    pub fn swapped(self) -> Self {
        Self {
            centre: self.centre,
            curvature: -self.curvature,
            centre_on_b: !self.centre_on_b,
            motion: self.motion,
        }
    }
}

/// How a cylinder–tube pair turns its line contact into points
/// (docs/model.md §4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LineLaw {
    /// The point law at every depth maximum minus the point law at every
    /// interior depth minimum: the energy Σ Φ(δ_max) − Σ Φ(δ_min) counts the
    /// connected pieces of the contact at each depth, so force, moment and
    /// energy are continuous when pieces appear, merge or split, and the
    /// elastic force is the energy's gradient.
    #[default]
    LevelSets,
    /// One point law per contact patch at its largest penetration, acting
    /// at the patch's depth-weighted centroid (MSC Adams' solid contact;
    /// the earlier default, kept for comparison): it jumps when patches
    /// merge or split.
    Patches,
}

/// The sampling and law of a cylinder–tube line contact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LineContact {
    /// Samples along the axis (rims included) that locate the contact.
    pub points: u32,
    /// How the line contact becomes points.
    pub law: LineLaw,
}

/// How a pair's contact points are found; chosen once, at assembly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PairGeometry {
    /// parry's convex–convex query, one deepest point (ball–half-space, ball–ball, ball–cuboid).
    ParryConvex,
    /// Cuboid vertices against a half-space, up to 8 points.
    CuboidHalfSpace,
    /// Cylinder inside a tube: a line contact, as points by its [`LineLaw`].
    CylinderTube(LineContact),
    /// Ball inside a tube.
    BallTube,
    /// Ball (b) inside the tube of a torus on body a (a groove flank); vectors in a's frame.
    TorusBall {
        /// Core-circle centre [m].
        centre: Vec3,
        /// Unit normal of the core circle's plane.
        axis: Vec3,
        /// Core-circle radius [m].
        core_radius: f64,
        /// Section radius [m].
        tube_radius: f64,
        /// Radius of ball b [m].
        ball_radius: f64,
    },
    /// Ball (b) between two parallel planes of body a; vectors in a's frame.
    SlotBall {
        /// Mid-plane point [m].
        centre: Vec3,
        /// Unit plane normal.
        normal: Vec3,
        /// Half-gap [m].
        half_width: f64,
        /// Radius of ball b [m].
        ball_radius: f64,
    },
    /// Sphere on body b inside a spherical cavity of body a.
    CavitySphere {
        /// Cavity centre, a's frame [m].
        cavity_centre: Vec3,
        /// Cavity radius [m].
        cavity_radius: f64,
        /// Sphere centre, b's frame [m].
        sphere_centre: Vec3,
        /// Sphere radius [m].
        sphere_radius: f64,
    },
    /// Cylinder on body b through a ring of body a (a neck through an opening).
    RingCylinder(RingCylinder),
}

impl PairGeometry {
    /// Supported pairs, for messages.
    pub const SUPPORTED: &'static str =
        "ball–half-space, ball–ball, ball–cuboid, cuboid–half-space, cylinder–tube, ball–tube";

    /// The method for a pair of shapes in either order (with the
    /// cylinder–tube line contact's sampling and law), or `None` if
    /// unsupported. The returned flag is true when the canonical order is (b, a).
    pub fn select(a: &Shape, b: &Shape, line: LineContact) -> Option<(Self, bool)> {
        use Shape as S;
        let canonical = |x: &Shape, y: &Shape| -> Option<Self> {
            match (x, y) {
                // Half-space first: parry 0.30's support-map–half-space order
                // applies the relative pose uninverted (wrong depth); the
                // half-space–support-map order is correct.
                (S::HalfSpace(_), S::Ball(_)) => Some(Self::ParryConvex),
                (S::Ball(_), S::Ball(_) | S::Cuboid(_)) => Some(Self::ParryConvex),
                (S::Cuboid(_), S::HalfSpace(_)) => Some(Self::CuboidHalfSpace),
                (S::Tube(_), S::Cylinder { .. }) => Some(Self::CylinderTube(line)),
                (S::Tube(_), S::Ball(_)) => Some(Self::BallTube),
                _ => None,
            }
        };
        canonical(a, b)
            .map(|g| (g, false))
            .or_else(|| canonical(b, a).map(|g| (g, true)))
    }

    /// The smallest radius of curvature that takes part in the contact [m]
    /// (ball, cylinder, groove or tube radius, smallest cuboid half-extent;
    /// a half-space has none), the scale of the penetration limit.
    pub fn contact_radius(self, s1: &Shape, s2: &Shape) -> f64 {
        match self {
            Self::TorusBall {
                tube_radius,
                ball_radius,
                ..
            } => tube_radius.min(ball_radius),
            Self::SlotBall { ball_radius, .. } => ball_radius,
            Self::CavitySphere {
                cavity_radius,
                sphere_radius,
                ..
            } => cavity_radius.min(sphere_radius),
            Self::RingCylinder(r) => r.cylinder_radius,
            _ => s1.radius().min(s2.radius()),
        }
    }

    /// Number of point slots a pair of this kind can report.
    pub fn slots(self) -> usize {
        match self {
            Self::ParryConvex
            | Self::BallTube
            | Self::TorusBall { .. }
            | Self::SlotBall { .. }
            | Self::CavitySphere { .. }
            | Self::RingCylinder(_) => 1,
            Self::CuboidHalfSpace => 8,
            // Level sets: maxima at 0..n, interior minima at n..2n − 1,
            // the open ends of the tube at 2n and 2n + 1.
            Self::CylinderTube(LineContact {
                points,
                law: LineLaw::LevelSets,
            }) => 2 * points as usize + 2,
            Self::CylinderTube(LineContact { points, .. }) => points as usize,
        }
    }

    /// Appends the contact points of shapes 1 and 2 at the given poses, with
    /// normals from shape 1 toward shape 2 (canonical order).
    pub fn contacts(
        &self,
        s1: &Shape,
        p1: (&Vec3, &Quat),
        s2: &Shape,
        p2: (&Vec3, &Quat),
        out: &mut dyn PointSink,
    ) {
        match (self, s1, s2) {
            (Self::ParryConvex, _, _) => parry_convex(s1, p1, s2, p2, out),
            (Self::CuboidHalfSpace, Shape::Cuboid(c), Shape::HalfSpace(h)) => {
                cuboid_half_space(c, p1, h, p2, out)
            }
            (
                Self::CylinderTube(line),
                Shape::Tube(t),
                Shape::Cylinder {
                    radius,
                    half_length,
                },
            ) => line::cylinder_tube(t, p1, *radius, *half_length, *line, p2, out),
            (Self::BallTube, Shape::Tube(t), Shape::Ball(b)) => ball_tube(t, p1, b.radius, p2, out),
            (
                Self::TorusBall {
                    centre,
                    axis,
                    core_radius,
                    tube_radius,
                    ball_radius,
                },
                _,
                _,
            ) => torus_ball(
                centre,
                axis,
                *core_radius,
                *tube_radius,
                *ball_radius,
                p1,
                p2,
                out,
            ),
            (
                Self::SlotBall {
                    centre,
                    normal,
                    half_width,
                    ball_radius,
                },
                _,
                _,
            ) => slot_ball(centre, normal, *half_width, *ball_radius, p1, p2, out),
            (
                Self::CavitySphere {
                    cavity_centre,
                    cavity_radius,
                    sphere_centre,
                    sphere_radius,
                },
                _,
                _,
            ) => {
                let oa = p1.0 + p1.1 * cavity_centre;
                let ob = p2.0 + p2.1 * sphere_centre;
                cavity_sphere(&oa, *cavity_radius, &ob, *sphere_radius, out)
            }
            (Self::RingCylinder(r), _, _) => r.contacts(p1, p2, out),
            _ => {}
        }
    }
}

fn parry_convex(
    s1: &Shape,
    p1: (&Vec3, &Quat),
    s2: &Shape,
    p2: (&Vec3, &Quat),
    out: &mut dyn PointSink,
) {
    let (Some(g1), Some(g2)) = (parry_shape(s1), parry_shape(s2)) else {
        return;
    };
    let pose1 = to_glam_pose(p1.0, p1.1);
    let pose2 = to_glam_pose(p2.0, p2.1);
    if let Ok(Some(c)) = query::contact(&pose1, g1, &pose2, g2, 0.0)
        && c.dist < 0.0
    {
        let normal = from_glam(c.normal1);
        out.push(ContactPoint {
            slot: 0,
            point: 0.5 * (from_glam(c.point1) + from_glam(c.point2)),
            normal,
            depth: -c.dist,
            weight: 1.0,
            turning: parry_turning(s1, p1, s2, p2, &normal),
        });
    }
}

/// The turning of a parry pair's normal: about ball 1's centre for two
/// balls; a plane's, or a cuboid face's, is constant (a cuboid's edge or
/// vertex against a ball is left flat).
fn parry_turning(
    s1: &Shape,
    p1: (&Vec3, &Quat),
    s2: &Shape,
    p2: (&Vec3, &Quat),
    normal: &Vec3,
) -> NormalTurning {
    match (s1, s2) {
        (Shape::Ball(_), Shape::Ball(_)) => {
            let rho = (p2.0 - p1.0).norm();
            let across = Mat3::identity() - normal * normal.transpose();
            NormalTurning {
                centre: *p2.0,
                curvature: across / rho,
                centre_on_b: true,
                motion: CentreMotion::Fixed,
            }
        }
        (Shape::Ball(_), _) => NormalTurning::plane(*p1.0).swapped(),
        _ => NormalTurning::plane(*p2.0),
    }
}

fn parry_shape(s: &Shape) -> Option<&dyn parry3d_f64::shape::Shape> {
    match s {
        Shape::Ball(b) => Some(b),
        Shape::Cuboid(c) => Some(c),
        Shape::HalfSpace(h) => Some(h),
        _ => None,
    }
}

fn cuboid_half_space(
    c: &Cuboid,
    pc: (&Vec3, &Quat),
    h: &HalfSpace,
    ph: (&Vec3, &Quat),
    out: &mut dyn PointSink,
) {
    let n = ph.1 * from_glam(h.normal);
    let he = from_glam(c.half_extents);
    for k in 0..8u32 {
        let local = Vec3::new(
            if k & 1 == 0 { -he.x } else { he.x },
            if k & 2 == 0 { -he.y } else { he.y },
            if k & 4 == 0 { -he.z } else { he.z },
        );
        let v = pc.0 + pc.1 * local;
        let d = (v - ph.0).dot(&n);
        if d < 0.0 {
            // Normal from the cuboid (1) toward the half-space (2) is −n.
            out.push(ContactPoint {
                slot: k,
                point: v - 0.5 * d * n,
                normal: -n,
                depth: -d,
                weight: 1.0,
                // The vertex (on the cuboid, 1) against the plane of 2.
                turning: NormalTurning::plane(v).swapped(),
            });
        }
    }
}

/// A contact in the frame of body a (pose `pa`) as a world contact point,
/// if the surfaces overlap, with the turning `turning(normal)` of its world
/// normal.
fn placed(
    c: LocalContact,
    pa: (&Vec3, &Quat),
    turning: impl FnOnce(&Vec3) -> NormalTurning,
) -> Option<ContactPoint> {
    (c.depth > 0.0).then(|| {
        let normal = pa.1 * from_glam(c.normal);
        ContactPoint {
            slot: c.feature,
            point: pa.0 + pa.1 * from_glam(c.point),
            normal,
            depth: c.depth,
            weight: 1.0,
            turning: turning(&normal),
        }
    })
}

fn ball_tube(
    t: &TubePath,
    pt: (&Vec3, &Quat),
    radius: f64,
    pb: (&Vec3, &Quat),
    out: &mut dyn PointSink,
) {
    let inside = t.interior();
    let centre = to_glam(&(pt.1.inverse() * (pb.0 - pt.0)));
    if let (Some(c), Some(core)) = (inside.ball_contact(centre, radius), inside.nearest(centre)) {
        let rho = (centre - core.point).length();
        let (tangent, kappa) = (
            pt.1 * from_glam(core.tangent),
            pt.1 * from_glam(core.curvature),
        );
        // Taken up as the centre passes the nearer end plane, as a link's
        // contact with its part inside (line.rs).
        let (end, out_of_tube) = inside.nearer_end(centre);
        let share = t.engagement((end - centre).dot(out_of_tube));
        out.push_some(
            placed(c, pt, |n| {
                NormalTurning::lumen(*pb.0, n, rho, &tangent, &kappa)
            })
            .map(|mut p| {
                p.weight = share;
                p
            }),
        );
    }
}

/// Ball (centre p, world) in the tube of a torus on body a.
#[allow(clippy::too_many_arguments)]
fn torus_ball(
    centre: &Vec3,
    axis: &Vec3,
    core_radius: f64,
    tube_radius: f64,
    ball_radius: f64,
    pa: (&Vec3, &Quat),
    pb: (&Vec3, &Quat),
    out: &mut dyn PointSink,
) {
    let flank = GrooveFlank {
        centre: to_glam(centre),
        axis: to_glam(axis),
        core_radius,
        tube_radius,
    };
    let p = pa.1.inverse() * (pb.0 - pa.0);
    if let Some(c) = flank.ball_contact(to_glam(&p), ball_radius) {
        // The core circle's tangent and curvature at the nearest point.
        let r = p - centre;
        let dir = (r - r.dot(axis) * axis).normalize();
        let rho = c.depth + flank.tube_radius - ball_radius;
        let (tangent, kappa) = (pa.1 * axis.cross(&dir), pa.1 * (-dir / core_radius));
        out.push_some(placed(c, pa, |n| {
            NormalTurning::lumen(*pb.0, n, rho, &tangent, &kappa)
        }));
    }
}

/// Ball (centre p, world) between two parallel planes of body a.
fn slot_ball(
    centre: &Vec3,
    normal: &Vec3,
    half_width: f64,
    ball_radius: f64,
    pa: (&Vec3, &Quat),
    pb: (&Vec3, &Quat),
    out: &mut dyn PointSink,
) {
    let slot = WindowSlot {
        centre: to_glam(centre),
        normal: to_glam(normal),
        half_width,
    };
    let p = pa.1.inverse() * (pb.0 - pa.0);
    out.push_some(placed(
        slot.ball_contact(to_glam(&p), ball_radius),
        pa,
        |_| NormalTurning::plane(*pb.0),
    ));
}

/// Sphere (centre ob, world) inside a cavity (centre oa, world).
fn cavity_sphere(
    oa: &Vec3,
    cavity_radius: f64,
    ob: &Vec3,
    sphere_radius: f64,
    out: &mut dyn PointSink,
) {
    let cavity = SphericalCavity::new(to_glam(oa), cavity_radius);
    // Already in the world frame.
    if let Some(c) = cavity.sphere_contact(to_glam(ob), sphere_radius)
        && c.depth > 0.0
    {
        let normal = from_glam(c.normal);
        let rho = (ob - oa).norm();
        out.push(ContactPoint {
            slot: c.feature,
            point: from_glam(c.point),
            normal,
            depth: c.depth,
            weight: 1.0,
            turning: NormalTurning::lumen(*ob, &normal, rho, &Vec3::zeros(), &Vec3::zeros()),
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn a_full_slot_sink_drops_further_points_instead_of_panicking() {
        let mut slots = [ContactPoint::UNUSED; 2];
        let mut sink = SlotSink {
            slots: &mut slots,
            len: 0,
            turning: true,
        };
        for depth in [1.0, 2.0, 3.0] {
            let mut p = ContactPoint::UNUSED;
            p.depth = depth;
            sink.push(p);
        }
        assert_eq!(sink.len, 2);
        assert_eq!(
            sink.filled().iter().map(|p| p.depth).collect::<Vec<_>>(),
            [1.0, 2.0]
        );
        sink.clear();
        assert!(sink.filled().is_empty());
    }

    const LINE: LineContact = LineContact {
        points: 5,
        law: LineLaw::LevelSets,
    };

    fn pose(p: [f64; 3]) -> (Vec3, Quat) {
        (Vec3::from(p), Quat::identity())
    }

    #[test]
    fn ball_on_half_space_depth_and_normal_follow_the_convention() {
        let ground = Shape::half_space(Vec3::z());
        let ball = Shape::ball(0.1);
        // Declared either way round, the pair resolves to half-space first.
        assert_eq!(
            PairGeometry::select(&ball, &ground, LINE),
            Some((PairGeometry::ParryConvex, true))
        );
        assert_eq!(
            PairGeometry::select(&ground, &ball, LINE),
            Some((PairGeometry::ParryConvex, false))
        );
        for z in [0.099, 0.0999, 0.05] {
            let (g, b) = (pose([0.3, -0.2, 0.0]), pose([0.0, 0.0, z]));
            let mut out = vec![];
            PairGeometry::ParryConvex.contacts(
                &ground,
                (&g.0, &g.1),
                &ball,
                (&b.0, &b.1),
                &mut out,
            );
            assert_eq!(out.len(), 1);
            assert_relative_eq!(out[0].depth, 0.1 - z, epsilon = 1e-12);
            assert_relative_eq!(out[0].normal, Vec3::z(), epsilon = 1e-12);
            assert_relative_eq!(out[0].point.z, -(0.1 - z) / 2.0, epsilon = 1e-12);
        }
        let b = pose([0.0, 0.0, 0.1001]);
        let g = pose([0.0; 3]);
        let mut out = vec![];
        PairGeometry::ParryConvex.contacts(&ground, (&g.0, &g.1), &ball, (&b.0, &b.1), &mut out);
        assert!(out.is_empty(), "a ball above the plane does not touch it");
    }

    #[test]
    fn ball_against_a_cuboid_face_has_the_face_normal() {
        let ball = Shape::ball(0.05);
        let cube = Shape::cuboid(Vec3::new(0.1, 0.2, 0.3));
        let (pb, pc) = (pose([-0.149, 0.01, 0.02]), pose([0.0; 3]));
        let mut out = vec![];
        PairGeometry::ParryConvex.contacts(&ball, (&pb.0, &pb.1), &cube, (&pc.0, &pc.1), &mut out);
        assert_eq!(out.len(), 1);
        assert_relative_eq!(out[0].depth, 1e-3, epsilon = 1e-12);
        assert_relative_eq!(out[0].normal, Vec3::x(), epsilon = 1e-12);
    }

    #[test]
    fn separated_balls_have_no_contact_and_overlapping_ones_have_one() {
        let a = Shape::ball(0.1);
        let (p1, p2, p3) = (
            pose([0.0; 3]),
            pose([0.21, 0.0, 0.0]),
            pose([0.19, 0.0, 0.0]),
        );
        let mut out = vec![];
        PairGeometry::ParryConvex.contacts(&a, (&p1.0, &p1.1), &a, (&p2.0, &p2.1), &mut out);
        assert!(out.is_empty());
        PairGeometry::ParryConvex.contacts(&a, (&p1.0, &p1.1), &a, (&p3.0, &p3.1), &mut out);
        assert_relative_eq!(out[0].depth, 0.01, epsilon = 1e-12);
        assert_relative_eq!(out[0].normal, Vec3::x(), epsilon = 1e-12);
    }

    #[test]
    fn tilted_cuboid_touches_with_its_lowest_vertices() {
        let c = Shape::cuboid(Vec3::new(0.1, 0.2, 0.3));
        let h = Shape::half_space(Vec3::z());
        let (pc, ph) = (pose([0.0, 0.0, 0.299]), pose([0.0; 3]));
        let mut out = vec![];
        PairGeometry::CuboidHalfSpace.contacts(&c, (&pc.0, &pc.1), &h, (&ph.0, &ph.1), &mut out);
        assert_eq!(out.len(), 4);
        for p in &out {
            assert_relative_eq!(p.depth, 1e-3, epsilon = 1e-12);
            assert_relative_eq!(p.normal, Vec3::new(0.0, 0.0, -1.0), epsilon = 1e-12);
        }
    }

    #[test]
    fn ball_in_a_torus_groove_touches_the_flank_at_the_section_circle() {
        // Core circle radius 0.03 about z in the xy plane; section radius 0.0078; ball 0.0075.
        let g = PairGeometry::TorusBall {
            centre: Vec3::zeros(),
            axis: Vec3::z(),
            core_radius: 0.03,
            tube_radius: 0.0078,
            ball_radius: 0.0075,
        };
        let a = pose([0.1, 0.2, 0.3]);
        let none = Shape::Cylinder {
            radius: 1.0,
            half_length: 1.0,
        };
        // Ball centre 0.0004 from the core circle, outward at 30°: overlap 0.0004 + 0.0075 − 0.0078 = 0.0001.
        let th = 30f64.to_radians();
        let radial = Vec3::new(th.cos(), th.sin(), 0.0);
        let b = (a.0 + radial * 0.0304, Quat::identity());
        let mut out = vec![];
        g.contacts(&none, (&a.0, &a.1), &none, (&b.0, &b.1), &mut out);
        assert_eq!(out.len(), 1);
        assert_relative_eq!(out[0].depth, 1e-4, epsilon = 1e-12);
        assert_relative_eq!(out[0].normal, -radial, epsilon = 1e-12);
        // Inside the clearance there is no contact.
        let b = (a.0 + radial * 0.0302, Quat::identity());
        out.clear();
        g.contacts(&none, (&a.0, &a.1), &none, (&b.0, &b.1), &mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn ball_in_a_slot_is_pushed_back_from_the_face_it_crosses() {
        let g = PairGeometry::SlotBall {
            centre: Vec3::zeros(),
            normal: Vec3::y(),
            half_width: 0.008,
            ball_radius: 0.0075,
        };
        let none = Shape::Cylinder {
            radius: 1.0,
            half_length: 1.0,
        };
        // Body a rotated 90° about z: its y axis is world −x.
        let qa = Quat::from_axis_angle(&Vec3::z_axis(), std::f64::consts::FRAC_PI_2);
        let pa = Vec3::zeros();
        let pb = Vec3::new(-0.0007, 0.0, 0.0);
        let mut out = vec![];
        g.contacts(&none, (&pa, &qa), &none, (&pb, &Quat::identity()), &mut out);
        assert_eq!(out.len(), 1);
        assert_relative_eq!(out[0].depth, 2e-4, epsilon = 1e-12);
        assert_relative_eq!(out[0].normal, Vec3::x(), epsilon = 1e-12);
    }

    #[test]
    fn eccentric_sphere_in_a_cavity_is_pushed_toward_the_cavity_centre() {
        let g = PairGeometry::CavitySphere {
            cavity_centre: Vec3::new(0.0, 0.0, 0.1),
            cavity_radius: 0.032,
            sphere_centre: Vec3::zeros(),
            sphere_radius: 0.031,
        };
        let none = Shape::Cylinder {
            radius: 1.0,
            half_length: 1.0,
        };
        let pa = Vec3::zeros();
        let pb = Vec3::new(0.0, 0.0011, 0.1);
        let mut out = vec![];
        g.contacts(
            &none,
            (&pa, &Quat::identity()),
            &none,
            (&pb, &Quat::identity()),
            &mut out,
        );
        assert_eq!(out.len(), 1);
        assert_relative_eq!(out[0].depth, 1e-4, epsilon = 1e-12);
        assert_relative_eq!(out[0].normal, -Vec3::y(), epsilon = 1e-12);
    }
}
