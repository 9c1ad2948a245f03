//! Where the drill pipe's parts sit in its expanded scene: body and pair ids
//! recorded by [`DrillPipeSpec::expand`](super::DrillPipeSpec::expand) as it
//! builds each part.

use crate::geometry::{CentrelinePoint, TubePath};
use crate::math::Vec3;

/// Pair ids of one ball key.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct KeyLayout {
    /// Inner-race (head) flanks.
    pub inner: Vec<usize>,
    /// Outer-race (seat) flanks.
    pub outer: Vec<usize>,
    /// Cage window faces.
    pub window: Vec<usize>,
}

/// Pair ids of one hinge; empty for an ideal-CV hinge (no cage, no keys).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct HingeLayout {
    /// Cage–head pair.
    pub cage_head: Option<usize>,
    /// Cage–seat pair.
    pub cage_seat: Option<usize>,
    /// The ball keys, 0–5 around the joint.
    pub keys: Vec<KeyLayout>,
}

/// Body and pair ids of a drill pipe in its scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Body ids in chain order: upper connector, links 1…n, lower connector.
    pub chain: Vec<usize>,
    /// Pair id of link k's contact with the tube at index k − 1.
    pub tube_pairs: Vec<usize>,
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
