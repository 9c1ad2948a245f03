//! The pair table: every container shape against every body.
//!
//! | container | ball | cylinder | capsule |
//! |---|---|---|---|
//! | [`TubeInterior`] | wall at the ball's point farthest from the centreline | line contact ([`crate::line`]) | line contact, round ends |
//! | [`GrooveFlank`] | δ = d + r − ρ to the core circle | line contact about the core circle | line contact, round ends |
//! | [`WindowSlot`] | the face on the ball's side | each end's rim point toward each face | each end's sphere against each face |
//! | [`SphericalCavity`] | δ = \|c − O\| + r − R | each end's rim point farthest from O | each end's sphere |

use parry3d_f64::shape::Shape;

use crate::cavity::SphericalCavity;
use crate::centreline::Centreline;
use crate::contact::{Body, LocalContact, Rod};
use crate::groove::GrooveFlank;
use crate::line::{Ends, line_patches, line_stations};
use crate::slot::WindowSlot;
use crate::tube::TubeInterior;

/// How a line contact (a cylinder or capsule in a tube or groove) is reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reduction {
    /// One contact per patch, at its largest penetration and centre of
    /// pressure ([`line_patches`]): for a penalty law applied once per patch.
    Patches,
    /// Every sample in contact and every hidden maximum between samples,
    /// each exact ([`line_stations`]): for a rigid-contact solver.
    Stations,
}

/// How line contacts are found and reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LineOptions {
    /// Samples along a rod's axis, ends included (≥ 2), that locate the
    /// contacts; the deepest point between two samples is found exactly.
    pub samples: u32,
    /// Per patch or per sample.
    pub reduction: Reduction,
}

impl Default for LineOptions {
    /// Five samples (ballcage's default for a drill-pipe link), per sample.
    fn default() -> Self {
        Self {
            samples: 5,
            reduction: Reduction::Stations,
        }
    }
}

/// A shape whose solid surrounds a lumen, and the bodies it holds.
pub trait Container {
    /// The contacts of `body` (placed in this shape's frame) deeper than
    /// `threshold` [m] (0: touching only; −p: also gaps up to p), in this
    /// shape's frame, passed to `emit`.
    fn body_contacts(
        &self,
        body: &Body,
        threshold: f64,
        line: LineOptions,
        emit: &mut dyn FnMut(LocalContact),
    );
}

/// The container of a parry shape, if it is one of this crate's.
pub fn as_container(shape: &dyn Shape) -> Option<&dyn Container> {
    if let Some(s) = shape.as_shape::<TubeInterior>() {
        return Some(s);
    }
    if let Some(s) = shape.as_shape::<GrooveFlank>() {
        return Some(s);
    }
    if let Some(s) = shape.as_shape::<WindowSlot>() {
        return Some(s);
    }
    shape
        .as_shape::<SphericalCavity>()
        .map(|s| s as &dyn Container)
}

fn emit_if(c: Option<LocalContact>, threshold: f64, emit: &mut dyn FnMut(LocalContact)) {
    if let Some(c) = c.filter(|c| c.depth > threshold) {
        emit(c);
    }
}

/// A rod in a lumen, reduced as `line` says.
fn rod_in_lumen<L: Centreline>(
    lumen: &L,
    rod: &Rod,
    ends: Ends,
    threshold: f64,
    line: LineOptions,
    mut emit: &mut dyn FnMut(LocalContact),
) {
    match line.reduction {
        Reduction::Patches => line_patches(lumen, rod, ends, line.samples, threshold, &mut emit),
        Reduction::Stations => line_stations(lumen, rod, ends, line.samples, threshold, &mut emit),
    }
}

impl Container for TubeInterior {
    fn body_contacts(
        &self,
        body: &Body,
        threshold: f64,
        line: LineOptions,
        emit: &mut dyn FnMut(LocalContact),
    ) {
        match body {
            Body::Ball { centre, radius } => {
                emit_if(self.ball_contact(*centre, *radius), threshold, emit)
            }
            Body::Cylinder(rod) => rod_in_lumen(self, rod, Ends::Flat, threshold, line, emit),
            Body::Capsule(rod) => rod_in_lumen(self, rod, Ends::Round, threshold, line, emit),
        }
    }
}

impl Container for GrooveFlank {
    fn body_contacts(
        &self,
        body: &Body,
        threshold: f64,
        line: LineOptions,
        emit: &mut dyn FnMut(LocalContact),
    ) {
        match body {
            Body::Ball { centre, radius } => {
                emit_if(self.ball_contact(*centre, *radius), threshold, emit)
            }
            Body::Cylinder(rod) => rod_in_lumen(self, rod, Ends::Flat, threshold, line, emit),
            Body::Capsule(rod) => rod_in_lumen(self, rod, Ends::Round, threshold, line, emit),
        }
    }
}

impl Container for WindowSlot {
    fn body_contacts(
        &self,
        body: &Body,
        threshold: f64,
        _line: LineOptions,
        mut emit: &mut dyn FnMut(LocalContact),
    ) {
        match body {
            Body::Ball { centre, radius } => {
                emit_if(Some(self.ball_contact(*centre, *radius)), threshold, emit)
            }
            Body::Cylinder(rod) => self.rod_contacts(rod, Ends::Flat, threshold, &mut emit),
            Body::Capsule(rod) => self.rod_contacts(rod, Ends::Round, threshold, &mut emit),
        }
    }
}

impl Container for SphericalCavity {
    fn body_contacts(
        &self,
        body: &Body,
        threshold: f64,
        _line: LineOptions,
        mut emit: &mut dyn FnMut(LocalContact),
    ) {
        match body {
            Body::Ball { centre, radius } => {
                emit_if(self.sphere_contact(*centre, *radius), threshold, emit)
            }
            Body::Cylinder(rod) => self.rod_contacts(rod, Ends::Flat, threshold, &mut emit),
            Body::Capsule(rod) => self.rod_contacts(rod, Ends::Round, threshold, &mut emit),
        }
    }
}
