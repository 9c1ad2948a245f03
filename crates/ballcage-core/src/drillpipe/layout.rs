//! Where the drill pipe's parts sit in an assembled model, for the derived tables.

use super::DrillPipeSpec;
use crate::geometry::TubePath;
use crate::model::{Body, ContactPair};

/// Pair indices of one ball key.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct KeyLayout {
    /// Inner-race (head) flanks.
    pub inner: Vec<usize>,
    /// Outer-race (seat) flanks.
    pub outer: Vec<usize>,
    /// Cage window faces.
    pub window: Vec<usize>,
}

/// Pair indices of one hinge.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct HingeLayout {
    /// Cage–head pair.
    pub cage_head: Option<usize>,
    /// Cage–seat pair.
    pub cage_seat: Option<usize>,
    /// The ball keys.
    pub keys: Vec<KeyLayout>,
}

/// Body and pair indices of a drill pipe in its model.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// Bodies in chain order: upper connector, links 1…N, lower connector.
    pub chain: Vec<usize>,
    /// Hinges 0…N (without ball keys: no cage pairs and no keys).
    pub hinges: Vec<HingeLayout>,
    /// The tube centreline extended straight past the arc [m].
    pub centreline: TubePath,
}

impl Layout {
    /// Finds the parts by the names [`DrillPipeSpec::expand`] gives them.
    pub fn new(spec: &DrillPipeSpec, bodies: &[Body], pairs: &[ContactPair]) -> Self {
        let n = spec.pipe.joints;
        let body = |name: &str| bodies.iter().position(|b| b.name == name);
        let pair = |name: &str| pairs.iter().position(|p| p.name == name);
        let chain = std::iter::once("upper".to_string())
            .chain((1..=n).map(|k| format!("link{k:02}")))
            .chain(std::iter::once("lower".to_string()))
            .filter_map(|name| body(&name))
            .collect();
        let hinges = (0..=n)
            .map(|h| HingeLayout {
                cage_head: pair(&format!("h{h:02}.cage/head")),
                cage_seat: pair(&format!("h{h:02}.cage/seat")),
                keys: (0..6)
                    .map(|j| {
                        let find = |tags: &[&str]| {
                            tags.iter()
                                .filter_map(|t| pair(&format!("h{h:02}.key{j}/{t}")))
                                .collect()
                        };
                        KeyLayout {
                            inner: find(&["head+", "head-"]),
                            outer: find(&["seat+", "seat-"]),
                            window: find(&["window-axial", "window-side"]),
                        }
                    })
                    .filter(|k| !k.inner.is_empty())
                    .collect(),
            })
            .collect();
        Self {
            chain,
            hinges,
            centreline: spec.centreline(2.0 * n as f64 * spec.pipe.pitch),
        }
    }
}
