//! Expansion of a drill-pipe document into a generic [`Scene`] and the
//! [`Layout`] of its parts, one job per function.
//!
//! Body and pair ids are positions in the scene's `bodies` and `contacts`
//! lists, so the layout records each part's id as the part is pushed; no
//! part is ever found again by its name. Order: the tube, the upper
//! connector, links 1…n, the lower connector, then per hinge its cage and
//! six keys (ball-key hinges only). Pairs: each link with the tube, then per
//! hinge cage–head and cage–seat (ball keys), the neck–mouth articulation
//! pair (both hinge models, unless `pipe.neck_radius` is 0), and per key the
//! four race flanks and two window faces.

use super::cv::CvGeometry;
use super::layout::{BodyPart, Feature, HingeLayout, KeyLayout, Layout, PairPart, Part};
use super::spec::{DrillPipeSpec, HingeModel, LowerEnd, MaterialSpec};
use super::{chain, names};
use crate::error::SceneError;
use crate::geometry::{TubePath, TubeSegment};
use crate::math::{Mat3, Quat, Vec3};
use crate::scene::{
    BodySpec, ContactSpec, FeatureSpec, JointSpec, LineLawSpec, LoadSpec, MotionKind, RecordSpec,
    Scene, ShapeSpec, TubeSegmentSpec, WorldSpec,
};

/// A drill pipe expanded into the engine's terms.
#[derive(Debug, Clone)]
pub struct Expansion {
    /// The generic scene the engine runs.
    pub scene: Scene,
    /// Where each part of the pipe is in that scene.
    pub layout: Layout,
}

/// Every body's z axis: the normal of the bend plane (world −y).
const BEND_NORMAL: Vec3 = Vec3::new(0.0, -1.0, 0.0);
/// The tube's entry direction (world −z, downhole) and the direction it bends toward (+x).
const TUBE_DIRECTION: Vec3 = Vec3::new(0.0, 0.0, -1.0);
const TUBE_BEND: [f64; 3] = [1.0, 0.0, 0.0];

impl DrillPipeSpec {
    /// Validates the document and expands it into a generic scene.
    pub fn expand(&self) -> Result<Expansion, SceneError> {
        self.validate()?;
        let placement = Placement::new(self);
        placement.check_fit(self)?;
        let mut b = Builder::new(self, &placement);
        b.chain_bodies();
        b.tube_contacts();
        for h in 0..=self.pipe.joints {
            match self.pipe.hinge {
                HingeModel::IdealCv => b.ideal_cv_hinge(h),
                HingeModel::BallKeys | HingeModel::BallKeysQs => b.ball_key_hinge(h),
            }
        }
        let expansion = b.finish();
        expansion.scene.validate()?;
        Ok(expansion)
    }

    /// The tube's centreline from the start of the arc, extended straight
    /// past the arc's end by `extension` [m].
    pub fn centreline(&self, extension: f64) -> TubePath {
        let b = &self.borehole;
        let mut segs = vec![TubeSegment::Arc {
            radius: b.curvature_radius,
            angle: b.build_angle_deg.to_radians(),
            bend: Vec3::from(TUBE_BEND),
        }];
        if extension > 0.0 {
            segs.push(TubeSegment::Straight { length: extension });
        }
        TubePath::new(b.inner_diameter / 2.0, Vec3::zeros(), TUBE_DIRECTION, &segs)
    }

    /// The centreline the chain is placed on and measured against: extended
    /// past the arc by twice the chain's length.
    pub fn extended_centreline(&self) -> TubePath {
        self.centreline(2.0 * self.pipe.joints as f64 * self.pipe.pitch)
    }

    /// Hinge centres in world coordinates (docs/model.md §4, Option A) [m].
    pub fn hinge_positions(&self) -> Vec<Vec3> {
        self.hinges_on(&self.extended_centreline())
    }

    /// Hinge centres [m] for the chain in the tube whose extended centreline
    /// is `centreline`: on it, or where a link's chord on it would cut into
    /// the bend's inner wall, on the path [`Self::placement_offset`] outside
    /// it.
    fn hinges_on(&self, centreline: &TubePath) -> Vec<Vec3> {
        let offset = self.placement_offset();
        let count = self.pipe.joints + 1;
        if offset == 0.0 {
            return chain::place_hinges(centreline, self.pipe.pitch, count);
        }
        let b = &self.borehole;
        let extension = 2.0 * self.pipe.joints as f64 * self.pipe.pitch;
        let outward = -Vec3::from(TUBE_BEND);
        let path = TubePath::new(
            b.inner_diameter / 2.0,
            offset * outward,
            TUBE_DIRECTION,
            &[
                TubeSegment::Arc {
                    radius: b.curvature_radius + offset,
                    angle: b.build_angle_deg.to_radians(),
                    bend: Vec3::from(TUBE_BEND),
                },
                TubeSegment::Straight { length: extension },
            ],
        );
        chain::place_hinges(&path, self.pipe.pitch, count)
    }

    /// How far outside the tube's centreline the hinges are placed [m]
    /// (docs/model.md §4): by how much a link's chord between two hinges on
    /// the centreline arc would cut into the bend's inner wall, its sagitta
    /// R − √(R² − (L/2)²) plus the link's radius r beyond the tube's
    /// D/2; 0 where it clears it, as in the paper's scene. Placed on the
    /// concentric arc of radius R + δ, the chord's middle clears the inner
    /// wall and its ends stay within the wall while δ ≤ (D − d)/2, which
    /// eq. (9) ensures to first order.
    pub fn placement_offset(&self) -> f64 {
        let (b, p) = (&self.borehole, &self.pipe);
        let (radius, half) = (b.curvature_radius, p.pitch / 2.0);
        if half >= radius {
            return 0.0;
        }
        let sagitta = radius - (radius * radius - half * half).sqrt();
        (sagitta + p.link_diameter / 2.0 - b.inner_diameter / 2.0).max(0.0)
    }

    /// The chain as placed at t = 0: hinge centres 0…n [m] and unit body
    /// axes in chain order (upper connector, links 1…n, lower connector),
    /// world frame.
    pub fn placed_chain(&self) -> (Vec<Vec3>, Vec<Vec3>) {
        let p = Placement::new(self);
        (p.hinges, p.axes)
    }
}

/// The chain's initial placement: hinge centres, body axes and orientations.
struct Placement {
    /// Hinge centres 0…n [m].
    hinges: Vec<Vec3>,
    /// Body axes in chain order: upper, links 1…n, lower.
    axes: Vec<Vec3>,
    /// Body orientations in chain order (x along the axis, z the bend normal).
    rotations: Vec<Quat>,
    /// The extended centreline.
    centreline: TubePath,
}

impl Placement {
    /// The placement of `spec`'s chain; builds the extended centreline, the
    /// one of the whole load ([`Layout::centreline`] is it).
    fn new(spec: &DrillPipeSpec) -> Self {
        let n = spec.pipe.joints;
        let centreline = spec.extended_centreline();
        let hinges = spec.hinges_on(&centreline);
        let mut axes = vec![TUBE_DIRECTION];
        for k in 1..=n {
            axes.push((hinges[k] - hinges[k - 1]).normalize());
        }
        axes.push(tangent_at(&centreline, &hinges[n]));
        let rotations = axes
            .iter()
            .map(|x| rotation_from_axes(*x, BEND_NORMAL))
            .collect();
        Self {
            hinges,
            axes,
            rotations,
            centreline,
        }
    }
}

impl Placement {
    /// Refuses a tube the chain cannot be placed in: a link longer than
    /// eq. (9) allows, or a hinge bent beyond its articulation limit.
    fn check_fit(&self, spec: &DrillPipeSpec) -> Result<(), SceneError> {
        let (p, r) = (&spec.pipe, spec.borehole.curvature_radius);
        let fit = super::sizing::tightest_radius_for_link(
            p.pitch,
            spec.borehole.inner_diameter,
            p.link_diameter,
        );
        if r < fit {
            let (d, tube) = (p.link_diameter, spec.borehole.inner_diameter);
            let longest = super::sizing::longest_link(r, tube, d);
            return Err(SceneError::new(
                "borehole.curvature_radius",
                r,
                format!(
                    "a {} m link of Ø{d} m does not fit a Ø{tube} m tube bent this tightly: \
                     eq. (9) needs R ≥ {fit:.4} m, {:.4} m more; at this R the longest \
                     link that fits is {longest:.4} m, pipe.pitch is {:.4} m too long \
                     (`ballcage size`)",
                    p.pitch,
                    fit - r,
                    p.pitch - longest
                ),
            ));
        }
        let Some(limit) = spec.articulation_limit().map(f64::to_degrees) else {
            return Ok(());
        };
        let (h, bend) = (0..self.axes.len() - 1)
            .map(|h| {
                (
                    h,
                    crate::math::angle_between(&self.axes[h], &self.axes[h + 1]).to_degrees(),
                )
            })
            .fold((0, 0.0), |m, x| if x.1 > m.1 { x } else { m });
        if bend > limit * (1.0 + 1e-9) {
            return Err(SceneError::new(
                "borehole.curvature_radius",
                r,
                format!(
                    "placed on this arc, hinge {h} bends {bend:.2}°, {:.2}° beyond the hinge's \
                     articulation limit of {limit:.2}° (where the head's neck, pipe.neck_radius, \
                     meets the seat's mouth); chains of two or more links need R ≥ {:.4} m, \
                     {:.4} m more",
                    bend - limit,
                    spec.tightest_radius(),
                    spec.tightest_radius() - r
                ),
            ));
        }
        Ok(())
    }
}

/// Tangent of `path` at the point of it nearest `p`, by bisection along it.
fn tangent_at(path: &TubePath, p: &Vec3) -> Vec3 {
    let (mut lo, mut hi) = (0.0, path.length());
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let c = path.point_at(mid);
        if (c.point - p).dot(&c.tangent) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    path.point_at(0.5 * (lo + hi)).tangent
}

fn rotation_from_axes(x: Vec3, z: Vec3) -> Quat {
    let y = z.cross(&x);
    Quat::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(
        Mat3::from_columns(&[x, y, z]),
    ))
}

fn quat_array(q: &Quat) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

fn arr(v: &Vec3) -> [f64; 3] {
    [v.x, v.y, v.z]
}

/// The scene under construction and the layout of what is in it so far.
struct Builder<'a> {
    spec: &'a DrillPipeSpec,
    place: &'a Placement,
    bodies: Vec<BodySpec>,
    contacts: Vec<ContactSpec>,
    joints: Vec<JointSpec>,
    layout: Layout,
}

impl<'a> Builder<'a> {
    fn new(spec: &'a DrillPipeSpec, place: &'a Placement) -> Self {
        let tube = BodySpec {
            name: names::TUBE.into(),
            motion: MotionKind::Fixed,
            shape: ShapeSpec::Tube {
                inner_radius: spec.borehole.inner_diameter / 2.0,
                start: [0.0; 3],
                direction: arr(&TUBE_DIRECTION),
                segments: vec![TubeSegmentSpec::Arc {
                    radius: spec.borehole.curvature_radius,
                    angle_deg: spec.borehole.build_angle_deg,
                    bend: TUBE_BEND,
                }],
                end_engagement: spec.borehole.end_engagement,
            },
            ..blank_body()
        };
        Self {
            spec,
            place,
            bodies: vec![tube],
            contacts: vec![],
            joints: vec![],
            layout: Layout {
                bodies: vec![BodyPart::of(Part::Tube)],
                chain: vec![],
                tube_pairs: vec![],
                pairs: vec![],
                hinges: vec![],
                centreline: place.centreline.clone(),
                lateral: -BEND_NORMAL,
            },
        }
    }

    fn n(&self) -> usize {
        self.spec.pipe.joints
    }

    /// Name of the body in chain position `k`.
    fn chain_name(&self, k: usize) -> String {
        names::chain_body(k, self.n())
    }

    fn push_body(&mut self, body: BodySpec, part: BodyPart) -> usize {
        self.bodies.push(body);
        self.layout.bodies.push(part);
        self.bodies.len() - 1
    }

    fn push_contact(&mut self, contact: ContactSpec, part: PairPart) -> usize {
        self.contacts.push(contact);
        self.layout.pairs.push(part);
        self.contacts.len() - 1
    }

    /// The upper connector (driven), links 1…n and the lower connector (loaded).
    fn chain_bodies(&mut self) {
        let (p, n) = (&self.spec.pipe, self.n());
        let half_c = p.connector_length / 2.0;
        let upper = self.connector(0, self.place.hinges[0] - half_c * self.place.axes[0]);
        let id = self.push_body(upper, BodyPart::of(Part::Upper));
        self.layout.chain.push(id);
        // The reduced model keeps the chain's mass: each link carries one hinge's
        // cage and keys (half of each of its two hinges).
        let hinge_parts = if p.hinge == HingeModel::IdealCv {
            p.ball_keys.cage_mass + 6.0 * p.ball_keys.ball_mass
        } else {
            0.0
        };
        for k in 1..=n {
            let h = &self.place.hinges;
            let link = BodySpec {
                name: self.chain_name(k),
                motion: MotionKind::Dynamic,
                shape: ShapeSpec::Cylinder {
                    radius: p.link_diameter / 2.0,
                    half_length: p.pitch / 2.0,
                    inner_radius: 0.0,
                },
                mass: Some(p.link_mass + hinge_parts),
                inertia: Some(p.link_inertia),
                position: arr(&(0.5 * (h[k - 1] + h[k]))),
                orientation: quat_array(&self.place.rotations[k]),
                ..blank_body()
            };
            let part = BodyPart {
                link: Some(k as u32),
                ..BodyPart::of(Part::Link)
            };
            let id = self.push_body(link, part);
            self.layout.chain.push(id);
        }
        let lower = self.connector(
            n + 1,
            self.place.hinges[n] + half_c * self.place.axes[n + 1],
        );
        let id = self.push_body(lower, BodyPart::of(Part::Lower));
        self.layout.chain.push(id);
    }

    /// A connector at chain position `k` (0 upper, n + 1 lower) centred at `centre`.
    fn connector(&self, k: usize, centre: Vec3) -> BodySpec {
        let p = &self.spec.pipe;
        let drive = &self.spec.drive;
        let driven = k == 0;
        let omega = drive.speed_rpm * std::f64::consts::TAU / 60.0;
        BodySpec {
            name: self.chain_name(k),
            motion: match (driven, p.lower_end) {
                (true, _) => MotionKind::KinematicSpin,
                (false, LowerEnd::Fixed) => MotionKind::Spin,
                (false, LowerEnd::AxiallyFree) => MotionKind::SpinSlide,
            },
            shape: ShapeSpec::Cylinder {
                radius: p.connector_diameter / 2.0,
                half_length: p.connector_length / 2.0,
                inner_radius: 0.0,
            },
            mass: Some(p.connector_mass),
            inertia: Some(p.connector_inertia),
            position: arr(&centre),
            orientation: quat_array(&self.place.rotations[k]),
            spin_axis: Some(arr(&self.place.axes[k])),
            spin_speed: if driven { omega } else { 0.0 },
            spin_ramp: if driven { drive.ramp } else { 0.0 },
            ..blank_body()
        }
    }

    /// Each link against the tube wall, sampled along its length.
    fn tube_contacts(&mut self) {
        let m = &self.spec.materials.tube;
        for k in 1..=self.n() {
            let contact = ContactSpec {
                name: Some(names::tube_pair(k)),
                bodies: [names::TUBE.into(), self.chain_name(k)],
                normal: m.normal.clone(),
                friction: Some(m.friction.clone()),
                geometry: None,
                points: self.spec.pipe.tube_contact_points,
                line_law: self.spec.pipe.tube_contact_law,
            };
            let part = PairPart {
                link: Some(k as u32),
                ..PairPart::of(Feature::Tube)
            };
            let id = self.push_contact(contact, part);
            self.layout.tube_pairs.push(id);
        }
    }

    /// Hinge centre in the head body's and the seat body's frames [m]: the
    /// head end is downhole (+x), the seat end uphole (−x).
    fn hinge_anchors(&self, h: usize) -> (Vec3, Vec3) {
        let p = &self.spec.pipe;
        let half_c = p.connector_length / 2.0;
        let head_half = if h == 0 { half_c } else { p.pitch / 2.0 };
        let seat_half = if h == self.n() { half_c } else { p.pitch / 2.0 };
        (
            Vec3::new(head_half, 0.0, 0.0),
            Vec3::new(-seat_half, 0.0, 0.0),
        )
    }

    /// Hinge `h` as an ideal constant-velocity penalty joint.
    fn ideal_cv_hinge(&mut self, h: usize) {
        let (c_head, c_seat) = self.hinge_anchors(h);
        let c = &self.spec.pipe.ideal_cv;
        self.joints.push(JointSpec::Cv {
            name: Some(names::hinge(h)),
            bodies: [self.chain_name(h), self.chain_name(h + 1)],
            anchors: [arr(&c_head), arr(&c_seat)],
            stiffness: c.stiffness,
            damping: c.damping,
            twist_stiffness: c.twist_stiffness,
            twist_damping: c.twist_damping,
        });
        let neck = self.neck_contact(h);
        self.layout.hinges.push(HingeLayout {
            neck,
            ..HingeLayout::default()
        });
    }

    /// The articulation limit of hinge `h`: the head's neck against the
    /// seat's mouth, a contact of the joint's internal material; None when
    /// `pipe.neck_radius` is 0.
    fn neck_contact(&mut self, h: usize) -> Option<usize> {
        self.spec.articulation_limit()?;
        let (r_neck, kb) = (self.spec.pipe.neck_radius, &self.spec.pipe.ball_keys);
        let (c_head, c_seat) = self.hinge_anchors(h);
        let geometry = FeatureSpec::RingCylinder {
            ring_centre: arr(&(c_seat - kb.mouth_offset * Vec3::x())),
            ring_axis: [1.0, 0.0, 0.0],
            ring_radius: kb.mouth_radius(),
            axis_point: arr(&c_head),
            axis_direction: [1.0, 0.0, 0.0],
            cylinder_radius: r_neck,
        };
        let part = PairPart {
            hinge: Some(h as u32),
            ..PairPart::of(Feature::NeckMouth)
        };
        let (head, seat) = (self.chain_name(h), self.chain_name(h + 1));
        Some(self.internal_contact(names::neck(h), [&seat, &head], geometry, part))
    }

    /// Hinge `h` as the paper's ball-cage joint: cage, neck–mouth
    /// articulation contact, and six ball keys with their race and window
    /// contacts.
    fn ball_key_hinge(&mut self, h: usize) {
        let kb = &self.spec.pipe.ball_keys;
        let (head, seat) = (self.chain_name(h), self.chain_name(h + 1));
        let beta = chain::bend_angle(&self.place.axes[h], &self.place.axes[h + 1], &BEND_NORMAL);
        let r_cage = self.place.rotations[h] * Quat::from_axis_angle(&Vec3::z_axis(), beta / 2.0);
        let quasi_static = self.spec.pipe.hinge == HingeModel::BallKeysQs;
        let cage = BodySpec {
            name: names::cage(h),
            motion: if quasi_static {
                MotionKind::QuasiStatic
            } else {
                MotionKind::Dynamic
            },
            shape: ShapeSpec::Ball {
                radius: kb.cage_outer_radius,
            },
            mass: Some(kb.cage_mass),
            inertia: Some(kb.cage_inertia),
            position: arr(&self.place.hinges[h]),
            orientation: quat_array(&r_cage),
            ..blank_body()
        };
        let part = BodyPart {
            hinge: Some(h as u32),
            ..BodyPart::of(Part::Cage)
        };
        self.push_body(cage, part);
        let mut layout = self.cage_contacts(h, &head, &seat);
        layout.neck = self.neck_contact(h);
        for j in 0..6 {
            layout.keys.push(self.ball_key(h, j, beta, &head, &seat));
        }
        self.layout.hinges.push(layout);
    }

    /// A contact of the joint's internal material between two parts.
    fn internal_contact(
        &mut self,
        name: String,
        [a, b]: [&str; 2],
        geometry: FeatureSpec,
        part: PairPart,
    ) -> usize {
        let MaterialSpec { normal, friction } = &self.spec.materials.internal;
        let contact = ContactSpec {
            name: Some(name),
            bodies: [a.into(), b.into()],
            normal: normal.clone(),
            friction: Some(friction.clone()),
            geometry: Some(geometry),
            points: 5,
            line_law: LineLawSpec::default(),
        };
        self.push_contact(contact, part)
    }

    /// The cage's spherical contacts with the ball head and the ball seat.
    fn cage_contacts(&mut self, h: usize, head: &str, seat: &str) -> HingeLayout {
        let kb = &self.spec.pipe.ball_keys;
        let (c_head, c_seat) = self.hinge_anchors(h);
        let cage = names::cage(h);
        let head_geometry = FeatureSpec::CavitySphere {
            cavity_centre: [0.0; 3],
            cavity_radius: kb.cage_inner_radius,
            sphere_centre: arr(&c_head),
            sphere_radius: kb.head_radius,
        };
        let seat_geometry = FeatureSpec::CavitySphere {
            cavity_centre: arr(&c_seat),
            cavity_radius: kb.seat_radius,
            sphere_centre: [0.0; 3],
            sphere_radius: kb.cage_outer_radius,
        };
        let part = |feature| PairPart {
            hinge: Some(h as u32),
            ..PairPart::of(feature)
        };
        let cage_head = self.internal_contact(
            names::feature(&cage, "head"),
            [&cage, head],
            head_geometry,
            part(Feature::CageHead),
        );
        let cage_seat = self.internal_contact(
            names::feature(&cage, "seat"),
            [seat, &cage],
            seat_geometry,
            part(Feature::CageSeat),
        );
        HingeLayout {
            cage_head: Some(cage_head),
            cage_seat: Some(cage_seat),
            ..HingeLayout::default()
        }
    }

    /// Ball key `j` of hinge `h` (bent by `beta` [rad] as placed): its body,
    /// the two flanks of its head and seat grooves, and its cage window.
    fn ball_key(&mut self, h: usize, j: usize, beta: f64, head: &str, seat: &str) -> KeyLayout {
        let kb = &self.spec.pipe.ball_keys;
        let cv = CvGeometry {
            pitch_radius: kb.pitch_radius,
            groove_offset: kb.groove_offset,
        };
        let psi = j as f64 * std::f64::consts::FRAC_PI_3;
        let key_inertia = 0.4 * kb.ball_mass * kb.ball_radius * kb.ball_radius;
        let p_hinge = cv.ball_centre_in_groove(beta, psi);
        let body = BodySpec {
            name: names::key(h, j),
            motion: if self.spec.pipe.hinge == HingeModel::BallKeysQs {
                MotionKind::QuasiStaticPosition
            } else {
                MotionKind::Dynamic
            },
            shape: ShapeSpec::Ball {
                radius: kb.ball_radius,
            },
            mass: Some(kb.ball_mass),
            inertia: Some([key_inertia; 3]),
            position: arr(&(self.place.hinges[h] + self.place.rotations[h] * p_hinge)),
            ..blank_body()
        };
        let (c_head, c_seat) = self.hinge_anchors(h);
        let part = BodyPart {
            hinge: Some(h as u32),
            key: Some(j as u32),
            ..BodyPart::of(Part::Key)
        };
        let mut layout = KeyLayout {
            body: self.push_body(body, part),
            tangent: Self::key_tangent(j),
            head_groove: c_head - kb.groove_offset * Vec3::x(),
            seat_groove: c_seat + kb.groove_offset * Vec3::x(),
            ..KeyLayout::default()
        };
        self.race_flanks(h, j, [head, seat], &mut layout);
        self.window_faces(h, j, &mut layout);
        layout
    }

    /// Key `j`'s tangent direction in the hinge frame: the normal of its
    /// groove's plane and of its window's side faces.
    fn key_tangent(j: usize) -> Vec3 {
        let psi = j as f64 * std::f64::consts::FRAC_PI_3;
        Vec3::new(0.0, -psi.sin(), psi.cos())
    }

    /// The two Gothic-arch flanks of key `j`'s groove in the head and in the seat.
    fn race_flanks(&mut self, h: usize, j: usize, [head, seat]: [&str; 2], layout: &mut KeyLayout) {
        let kb = &self.spec.pipe.ball_keys;
        let cv = CvGeometry {
            pitch_radius: kb.pitch_radius,
            groove_offset: kb.groove_offset,
        };
        let key = names::key(h, j);
        let (c_head, c_seat) = self.hinge_anchors(h);
        let rho = cv.track_radius();
        let alpha = kb.contact_angle_deg.to_radians();
        let a = kb.groove_radius - kb.ball_radius - kb.flank_clearance;
        let e_t = Self::key_tangent(j);
        for (face, sign, tag) in [(0, 1.0, "+"), (1, -1.0, "-")] {
            let head_flank = FeatureSpec::TorusBall {
                centre: arr(&(c_head - kb.groove_offset * Vec3::x() + sign * a * alpha.sin() * e_t)),
                axis: arr(&e_t),
                core_radius: rho + a * alpha.cos(),
                tube_radius: kb.groove_radius,
            };
            let seat_flank = FeatureSpec::TorusBall {
                centre: arr(&(c_seat
                    + kb.groove_offset * Vec3::x()
                    + sign * a * alpha.sin() * e_t)),
                axis: arr(&e_t),
                core_radius: rho - a * alpha.cos(),
                tube_radius: kb.groove_radius,
            };
            let name = names::feature(&key, &format!("head{tag}"));
            let inner = key_part(Feature::InnerRace, h, j, face);
            layout
                .inner
                .push(self.internal_contact(name, [head, &key], head_flank, inner));
            let name = names::feature(&key, &format!("seat{tag}"));
            let outer = key_part(Feature::OuterRace, h, j, face);
            layout
                .outer
                .push(self.internal_contact(name, [seat, &key], seat_flank, outer));
        }
    }

    /// The axial and side faces of key `j`'s cage window.
    fn window_faces(&mut self, h: usize, j: usize, layout: &mut KeyLayout) {
        let kb = &self.spec.pipe.ball_keys;
        let (key, cage) = (names::key(h, j), names::cage(h));
        let windows = [
            ("window-axial", [1.0, 0.0, 0.0], kb.window_axial_width / 2.0),
            (
                "window-side",
                arr(&Self::key_tangent(j)),
                kb.window_length / 2.0,
            ),
        ];
        for (face, (tag, normal, half_width)) in (0..).zip(windows) {
            let slot = FeatureSpec::SlotBall {
                centre: [0.0; 3],
                normal,
                half_width,
            };
            let name = names::feature(&key, tag);
            let window = key_part(Feature::Window, h, j, face);
            layout
                .window
                .push(self.internal_contact(name, [&cage, &key], slot, window));
        }
    }

    /// The loads on the lower connector: the resisting moment about its
    /// axis and, with an axially free lower end, the axial force along it
    /// (positive downhole: tension), both ramped by `load.ramp`.
    fn lower_loads(&self) -> Vec<LoadSpec> {
        let (load, axis) = (&self.spec.load, arr(&self.place.axes[self.n() + 1]));
        let mut loads = vec![LoadSpec::Torque {
            body: names::LOWER.into(),
            axis,
            magnitude: -load.resisting_moment,
            ramp: load.ramp,
        }];
        if self.spec.pipe.lower_end == LowerEnd::AxiallyFree {
            loads.push(LoadSpec::Force {
                body: names::LOWER.into(),
                axis,
                force: load.axial_force,
                ramp: load.ramp,
            });
        }
        loads
    }

    /// The generic scene: the parts plus gravity, the loads and recording.
    fn finish(self) -> Expansion {
        let spec = self.spec;
        let n = self.n();
        let r = &spec.record;
        let chain_names: Vec<String> = (0..=n + 1).map(|k| self.chain_name(k)).collect();
        let record = RecordSpec {
            tables: r.tables.iter().filter_map(|t| t.engine()).collect(),
            bodies: if r.bodies.is_empty() {
                chain_names
            } else {
                r.bodies.clone()
            },
            contacts: r.contacts.clone(),
            summary_window: r.summary_window.clone(),
            max_bytes: r.max_bytes,
        };
        let loads = self.lower_loads();
        let scene = Scene {
            name: spec.title(),
            simulation: spec.simulation.clone(),
            world: WorldSpec {
                gravity: [0.0, 0.0, -spec.world.gravity],
            },
            record,
            bodies: self.bodies,
            contacts: self.contacts,
            loads,
            joints: self.joints,
        };
        Expansion {
            scene,
            layout: self.layout,
        }
    }
}

/// A pair of key `j` of hinge `h` on face `face` of `feature`.
fn key_part(feature: Feature, h: usize, j: usize, face: u32) -> PairPart {
    PairPart {
        hinge: Some(h as u32),
        key: Some(j as u32),
        face: Some(face),
        ..PairPart::of(feature)
    }
}

fn blank_body() -> BodySpec {
    BodySpec {
        name: String::new(),
        motion: MotionKind::Dynamic,
        shape: ShapeSpec::Ball { radius: 1.0 },
        mass: None,
        density: None,
        inertia: None,
        position: [0.0; 3],
        orientation: [1.0, 0.0, 0.0, 0.0],
        velocity: [0.0; 3],
        angular_velocity: [0.0; 3],
        spin_axis: None,
        spin_speed: 0.0,
        spin_ramp: 0.0,
    }
}
