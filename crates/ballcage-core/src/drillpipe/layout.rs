//! Where the drill pipe's parts sit in its expanded scene: body and pair ids
//! recorded by [`DrillPipeSpec::expand`](super::DrillPipeSpec::expand) as it
//! builds each part.

use crate::geometry::{CentrelinePoint, TubePath};
use crate::math::Vec3;

/// What a contact pair of the drill pipe touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    /// A link against the guide tube.
    Tube,
    /// The cage's inner sphere on the ball head.
    CageHead,
    /// The cage's outer sphere in the ball seat.
    CageSeat,
    /// A ball key on a flank of its groove in the ball head (inner race).
    InnerRace,
    /// A ball key on a flank of its groove in the ball seat (outer race).
    OuterRace,
    /// A ball key on a face of its cage window.
    Window,
    /// The ball head's neck against the seat's mouth (the articulation limit).
    NeckMouth,
}

impl Feature {
    /// Labels in the order of the variants (the `pairs.feature` dictionary).
    pub const LABELS: &'static [&'static str] = &[
        "tube",
        "cage-head",
        "cage-seat",
        "inner-race",
        "outer-race",
        "window",
        "neck-mouth",
    ];

    /// Index into [`Feature::LABELS`].
    pub fn code(self) -> u32 {
        self as u32
    }
}

/// Which part of the pipe a contact pair belongs to; ids that do not apply are `None`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PairPart {
    /// What it touches.
    pub feature: Feature,
    /// Link number, 1 at the top (tube pairs).
    pub link: Option<u32>,
    /// Hinge number, 0 above link 1 (joint pairs).
    pub hinge: Option<u32>,
    /// Ball key number, 0–5 (key pairs).
    pub key: Option<u32>,
    /// Which face of the feature: for a race 0 the `+` flank and 1 the `−`
    /// flank; for a window 0 the axial faces and 1 the side faces.
    pub face: Option<u32>,
}

impl PairPart {
    /// A pair of feature `feature` with no ids set.
    pub fn of(feature: Feature) -> Self {
        Self {
            feature,
            link: None,
            hinge: None,
            key: None,
            face: None,
        }
    }
}

/// What a body of the drill pipe is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// The fixed guide tube.
    Tube,
    /// The driven upper connector.
    Upper,
    /// A link.
    Link,
    /// The lower connector, loaded by the resisting moment.
    Lower,
    /// The cage of a ball-key hinge.
    Cage,
    /// A ball key.
    Key,
}

impl Part {
    /// Labels in the order of the variants (the `bodies.part` dictionary).
    pub const LABELS: &'static [&'static str] = &["tube", "upper", "link", "lower", "cage", "key"];

    /// Index into [`Part::LABELS`].
    pub fn code(self) -> u32 {
        self as u32
    }
}

/// Which part of the pipe a body is; ids that do not apply are `None`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BodyPart {
    /// What it is.
    pub part: Part,
    /// Link number, 1 at the top (links).
    pub link: Option<u32>,
    /// Hinge number, 0 above link 1 (cages and keys).
    pub hinge: Option<u32>,
    /// Ball key number, 0–5 (keys).
    pub key: Option<u32>,
}

impl BodyPart {
    /// A body of part `part` with no ids set.
    pub fn of(part: Part) -> Self {
        Self {
            part,
            link: None,
            hinge: None,
            key: None,
        }
    }
}

/// One ball key: its body, its pairs, and its grooves' geometry.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct KeyLayout {
    /// Body id of the key.
    pub body: usize,
    /// Normal of the key's meridian plane (the grooves' cross-section
    /// tangential direction), in the head body's and the seat body's frames
    /// alike (they coincide when the hinge is straight).
    pub tangent: Vec3,
    /// Centre of the head groove's circle, head body frame [m].
    pub head_groove: Vec3,
    /// Centre of the seat groove's circle, seat body frame [m].
    pub seat_groove: Vec3,
    /// Inner-race (head) flanks.
    pub inner: Vec<usize>,
    /// Outer-race (seat) flanks.
    pub outer: Vec<usize>,
    /// Cage window faces.
    pub window: Vec<usize>,
}

/// Pair ids of one hinge; empty for an ideal-CV hinge (no cage, no keys).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HingeLayout {
    /// Cage–head pair.
    pub cage_head: Option<usize>,
    /// Cage–seat pair.
    pub cage_seat: Option<usize>,
    /// Neck–mouth pair (the articulation limit), if `pipe.neck_radius` > 0.
    pub neck: Option<usize>,
    /// The ball keys, 0–5 around the joint.
    pub keys: Vec<KeyLayout>,
}

/// Body and pair ids of a drill pipe in its scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// What each body is, indexed by body id.
    pub bodies: Vec<BodyPart>,
    /// Body ids in chain order: upper connector, links 1…n, lower connector.
    pub chain: Vec<usize>,
    /// Pair id of link k's contact with the tube at index k − 1.
    pub tube_pairs: Vec<usize>,
    /// What each contact pair is, indexed by pair id.
    pub pairs: Vec<PairPart>,
    /// Hinges 0…n; hinge k joins chain bodies k and k + 1.
    pub hinges: Vec<HingeLayout>,
    /// The tube centreline, extended straight past the arc [m].
    pub centreline: TubePath,
    /// Unit normal of the bend plane, world frame: the lateral direction of
    /// [`Layout::offsets`].
    pub lateral: Vec3,
}

impl Layout {
    /// Offsets of point `p` [m] from the extended centreline: total distance,
    /// in-plane (+ toward the outer wall of the bend) and lateral (along
    /// [`Layout::lateral`]). Points before the tube's start are measured from it.
    pub fn offsets(&self, p: &Vec3) -> (f64, f64, f64) {
        let (c, distance) = match self.centreline.nearest(p) {
            Some(c) => {
                let d = (p - c.point).norm();
                (c, d)
            }
            None => {
                let c: CentrelinePoint = self.centreline.point_at(0.0);
                let d = (p - c.point).norm();
                (c, d)
            }
        };
        let outward = self.lateral.cross(&c.tangent);
        let r = p - c.point;
        (distance, r.dot(&outward), r.dot(&self.lateral))
    }
}
