//! A lumen around a centreline: what the line contact (module `line`)
//! walks along, and what the tube and the groove are. They name this
//! module, and the tube never names the line contact.

use parry3d_f64::math::Vector;

/// The nearest centreline point to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentrelinePoint {
    /// Point on the centreline [m], tube frame.
    pub point: Vector,
    /// Unit tangent there.
    pub tangent: Vector,
    /// Curvature vector κ·N̂ [1/m]: toward the centre of the osculating
    /// circle, 1/radius long; zero on a straight segment.
    pub curvature: Vector,
}

/// A circular arc of centreline: `centre + radius·(cos θ·u + sin θ·t)` for
/// θ ∈ [0, angle], u and t orthonormal, `end` = (cos, sin) of `angle`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CircularArc {
    /// Centre of the circle [m].
    pub centre: Vector,
    /// Radius [m].
    pub radius: f64,
    /// Unit vector from the centre to the arc's start.
    pub u: Vector,
    /// Unit tangent at the start.
    pub t: Vector,
    /// (cos, sin) of the turned angle, which is at most π.
    pub end: (f64, f64),
}

/// A lumen around a centreline: the wall is `wall_radius` from it.
pub trait Centreline {
    /// Nearest centreline point to `q`, or `None` where there is no wall
    /// (past an open end, or on a torus's axis).
    fn nearest(&self, q: Vector) -> Option<CentrelinePoint>;
    /// Distance from the centreline to the wall [m].
    fn wall_radius(&self) -> f64;

    /// How far `q` lies past the plane of the lumen's open end nearer it
    /// [m], negative before it: a function linear along a straight line,
    /// zero where [`Centreline::nearest`] stops finding a wall there. `None`
    /// for a lumen without open ends.
    fn past_end(&self, _q: Vector) -> Option<f64> {
        None
    }

    /// The whole centreline as one circular arc of at most π, where it is
    /// one (a plain bend), such that [`Centreline::nearest`] of a point
    /// whose direction from the centre lies within the arc's angle is the
    /// arc's point in that direction: the line contact then follows a
    /// straight axis in closed form. `None` by default.
    fn arc(&self) -> Option<CircularArc> {
        None
    }
}
