//! Tube centrelines: straight and circular-arc segments.
//!
//! The geometry itself is `ballcage_shapes::TubeInterior`, the same code
//! parry and rapier use through `ballcage_shapes::ShapeDispatcher`: the
//! wall is exact, the distance to the centreline minus the inner radius (a
//! meshed wall tilts the normal at every facet edge and changes the
//! penetration by the chord error). This module is its face in the
//! engine's nalgebra types; the conversions copy components, so no result
//! moves by an ulp.

use ballcage_shapes::TubeInterior;

use crate::math::{Vec3, from_glam, to_glam};

/// One piece of a tube centreline as declared: it continues from where the
/// previous piece ends, along the current direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TubeSegment {
    /// Straight piece along the current direction.
    Straight {
        /// Length [m].
        length: f64,
    },
    /// Circular arc turning the current direction toward `bend`.
    Arc {
        /// Centreline curvature radius [m].
        radius: f64,
        /// Turned angle [rad].
        angle: f64,
        /// Direction toward the arc's centre (tube frame); only its part
        /// across the current direction is used.
        bend: Vec3,
    },
}

/// The nearest centreline point to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentrelinePoint {
    /// Point on the centreline [m], tube frame.
    pub point: Vec3,
    /// Unit tangent there.
    pub tangent: Vec3,
}

impl From<ballcage_shapes::CentrelinePoint> for CentrelinePoint {
    fn from(c: ballcage_shapes::CentrelinePoint) -> Self {
        Self {
            point: from_glam(c.point),
            tangent: from_glam(c.tangent),
        }
    }
}

/// A tube centreline with its inner radius, in the tube's body frame.
#[derive(Debug, Clone, PartialEq)]
pub struct TubePath {
    interior: TubeInterior,
    /// Length [m] of a body's part inside over which its wall contact is
    /// taken up where it crosses an open end ([`TubePath::engagement`]); 0:
    /// at once.
    end_engagement: f64,
}

impl TubePath {
    /// Builds the path of `specs` from `start` along `direction` (both tube
    /// frame); lengths, radii and angles positive, `bend` not along the
    /// direction it turns.
    pub fn new(inner_radius: f64, start: Vec3, direction: Vec3, specs: &[TubeSegment]) -> Self {
        let specs: Vec<ballcage_shapes::TubeSegment> = specs
            .iter()
            .map(|s| match *s {
                TubeSegment::Straight { length } => {
                    ballcage_shapes::TubeSegment::Straight { length }
                }
                TubeSegment::Arc {
                    radius,
                    angle,
                    bend,
                } => ballcage_shapes::TubeSegment::Arc {
                    radius,
                    angle,
                    bend: to_glam(&bend),
                },
            })
            .collect();
        Self {
            interior: TubeInterior::new(inner_radius, to_glam(&start), to_glam(&direction), &specs),
            end_engagement: 0.0,
        }
    }

    /// The same tube whose open ends take up a crossing body's wall
    /// contact over `length` [m] of its part inside ([`TubePath::engagement`]).
    pub fn with_end_engagement(mut self, length: f64) -> Self {
        self.end_engagement = length;
        self
    }

    /// Length [m] over which a crossing body's wall contact is taken up.
    pub fn end_engagement(&self) -> f64 {
        self.end_engagement
    }

    /// The share of its wall contact that a body crossing an open end
    /// carries when `inside` [m] of it lies inside the tube: an Adams STEP
    /// from 0 at nothing inside to 1 at [`TubePath::end_engagement`]. The
    /// contact would otherwise vanish at once, a jump, when the body's last
    /// section inside leaves the tube while pressing the wall; with the
    /// share it fades to zero with the part inside. 1 when the length is 0.
    pub fn engagement(&self, inside: f64) -> f64 {
        if self.end_engagement <= 0.0 {
            return 1.0;
        }
        crate::math::step(inside, 0.0, 0.0, self.end_engagement, 1.0).0
    }

    /// The exact tube, as the parry shape `ballcage_shapes::TubeInterior`.
    pub fn interior(&self) -> &TubeInterior {
        &self.interior
    }

    /// Inner (lumen) radius [m].
    pub fn inner_radius(&self) -> f64 {
        self.interior.inner_radius()
    }

    /// Centreline length [m].
    pub fn length(&self) -> f64 {
        self.interior.length()
    }

    /// Centreline point at arc length `s` [m] from the start (clamped), with its tangent.
    pub fn point_at(&self, s: f64) -> CentrelinePoint {
        self.interior.point_at(s).into()
    }

    /// Nearest centreline point to `q`, or `None` when `q` lies beyond either
    /// open end of the tube (past the end planes), where there is no wall.
    pub fn nearest(&self, q: &Vec3) -> Option<CentrelinePoint> {
        self.interior.nearest(to_glam(q)).map(Into::into)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The paper's guide tube: down from the origin, bending toward +x at R = 1.5 m over 90°.
    fn paper_tube() -> TubePath {
        TubePath::new(
            0.058,
            Vec3::zeros(),
            Vec3::new(0.0, 0.0, -1.0),
            &[TubeSegment::Arc {
                radius: 1.5,
                angle: 90f64.to_radians(),
                bend: Vec3::x(),
            }],
        )
    }

    #[test]
    fn arc_follows_the_paper_parametrization() {
        let t = paper_tube();
        assert_relative_eq!(
            t.length(),
            0.75 * std::f64::consts::PI,
            max_relative = 1e-14
        );
        for deg in [0.0_f64, 7.6451, 45.0, 87.0, 90.0] {
            let a = deg.to_radians();
            let c = t.point_at(1.5 * a);
            let expect = Vec3::new(1.5 * (1.0 - a.cos()), 0.0, -1.5 * a.sin());
            assert_relative_eq!(c.point, expect, epsilon = 1e-12);
            // The inclination of the tangent from the downward vertical equals the arc angle.
            assert_relative_eq!(
                c.tangent.dot(&Vec3::new(0.0, 0.0, -1.0)).acos(),
                a,
                epsilon = 1e-7
            );
        }
    }

    #[test]
    fn nearest_point_of_an_offset_point_is_radially_inward() {
        let t = paper_tube();
        let a = 30.0_f64.to_radians();
        let on = Vec3::new(1.5 * (1.0 - a.cos()), 0.0, -1.5 * a.sin());
        let radial = Vec3::new(-a.cos(), 0.0, -a.sin()); // away from the arc centre (1.5, 0, 0)
        let q = on + 0.02 * radial + Vec3::new(0.0, 0.01, 0.0);
        let c = t.nearest(&q).expect("inside the tube span");
        assert_relative_eq!(c.point, on, epsilon = 1e-12);
        assert_relative_eq!(
            (q - c.point).norm(),
            (0.02_f64.powi(2) + 0.01_f64.powi(2)).sqrt(),
            epsilon = 1e-12
        );
    }

    #[test]
    fn points_beyond_the_open_ends_have_no_wall() {
        let t = paper_tube();
        assert!(t.nearest(&Vec3::new(0.0, 0.0, 0.05)).is_none());
        assert!(t.nearest(&Vec3::new(1.6, 0.0, -1.5)).is_none());
        assert!(t.nearest(&Vec3::new(1.45, 0.0, -1.5)).is_some());
    }

    #[test]
    fn straight_then_arc_joins_smoothly() {
        let t = TubePath::new(
            0.05,
            Vec3::zeros(),
            Vec3::new(1.0, 0.0, 0.0),
            &[
                TubeSegment::Straight { length: 1.0 },
                TubeSegment::Arc {
                    radius: 2.0,
                    angle: 30f64.to_radians(),
                    bend: Vec3::y(),
                },
            ],
        );
        let a = t.point_at(1.0 - 1e-9);
        let b = t.point_at(1.0 + 1e-9);
        assert_relative_eq!(a.point, b.point, epsilon = 1e-8);
        assert_relative_eq!(a.tangent, b.tangent, epsilon = 1e-8);
        let end = t.point_at(t.length());
        let th = 30.0_f64.to_radians();
        assert_relative_eq!(
            end.point,
            Vec3::new(1.0 + 2.0 * th.sin(), 2.0 * (1.0 - th.cos()), 0.0),
            epsilon = 1e-12
        );
    }
}
