//! One flank of a Gothic-arch groove: the inside of the tube of a torus.
//!
//! A Gothic-arch race is two circular arcs of section radius ρ larger than
//! the ball's, their centres offset to either side of the groove's middle;
//! the ball touches each arc from inside, at the contact angle. Swept round
//! the race's axis, each arc is a torus: core circle (centre, axis, radius
//! R₀) and section radius ρ. A ball of radius r centred at p sits in it at
//! distance d from the core circle's nearest point q, and reaches δ = d + r − ρ
//! into the flank, pushed back along (q − p)/d. One [`GrooveFlank`] is one
//! torus; a groove is two of them (the ball meets both from inside).

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;

use crate::centreline::{Centreline, CentrelinePoint};
use crate::contact::{LocalContact, unit};

/// The inside of the tube of a torus, in its frame: the solid is everything
/// farther than `tube_radius` from the core circle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GrooveFlank {
    /// Core-circle centre [m].
    pub centre: Vector,
    /// Unit normal of the core circle's plane (the race's axis).
    pub axis: Vector,
    /// Core-circle radius R₀ [m].
    pub core_radius: f64,
    /// Section radius ρ [m].
    pub tube_radius: f64,
}

impl GrooveFlank {
    /// The flank of core circle (`centre`, `axis` normalized here,
    /// `core_radius`) and section radius `tube_radius` [m].
    pub fn new(centre: Vector, axis: Vector, core_radius: f64, tube_radius: f64) -> Self {
        Self {
            centre,
            axis: unit(axis),
            core_radius,
            tube_radius,
        }
    }

    /// A ball of `ball_radius` [m] centred at `p` against the flank:
    /// δ = |q − p| + r − ρ, the normal (q − p)/|q − p| toward the core circle.
    /// `None` on the race's axis (no nearest core point) or on the core circle.
    pub fn ball_contact(&self, p: Vector, ball_radius: f64) -> Option<LocalContact> {
        let r = p - self.centre;
        let in_plane = r - r.dot(self.axis) * self.axis;
        let len = in_plane.length();
        if len < 1e-15 {
            return None;
        }
        let q = self.centre + self.core_radius * in_plane / len;
        let to_core = q - p;
        let d = to_core.length();
        let depth = d + ball_radius - self.tube_radius;
        if d < 1e-15 {
            return None;
        }
        // The wall pushes the ball back toward the core circle.
        let n = to_core / d;
        let ball_surface = p - ball_radius * n;
        Some(LocalContact {
            point: ball_surface + 0.5 * depth * n,
            normal: n,
            depth,
            feature: 0,
        })
    }

    /// The lumen's bounding box: the torus.
    pub fn lumen_aabb(&self) -> Aabb {
        // The core circle reaches R₀·√(1 − a_i²) along axis i.
        let a = self.axis;
        let reach = Vector::new(
            (1.0 - a.x * a.x).max(0.0).sqrt(),
            (1.0 - a.y * a.y).max(0.0).sqrt(),
            (1.0 - a.z * a.z).max(0.0).sqrt(),
        ) * self.core_radius
            + Vector::splat(self.tube_radius);
        Aabb::new(self.centre - reach, self.centre + reach)
    }
}

impl Centreline for GrooveFlank {
    /// The core circle's point nearest `q`: `None` on the race's axis.
    #[inline]
    fn nearest(&self, q: Vector) -> Option<CentrelinePoint> {
        let r = q - self.centre;
        let in_plane = r - r.dot(self.axis) * self.axis;
        let len = in_plane.length();
        if len < 1e-15 {
            return None;
        }
        let dir = in_plane / len;
        Some(CentrelinePoint {
            point: self.centre + self.core_radius * dir,
            tangent: self.axis.cross(dir),
            curvature: -dir / self.core_radius,
        })
    }

    #[inline]
    fn wall_radius(&self) -> f64 {
        self.tube_radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ball centre at distance e from the core circle, in the meridian plane
    /// at azimuth φ, at angle β from the race's plane: the nearest core point
    /// is R₀(cos φ, sin φ, 0), so δ = e + r − ρ and the normal is
    /// −(cos β·(cos φ, sin φ, 0) + sin β·z).
    #[test]
    fn a_ball_off_the_core_circle_is_pushed_back_toward_it() {
        let f = GrooveFlank::new(Vector::ZERO, Vector::Z, 0.03, 0.0078);
        let (r, e) = (0.0075, 0.0004);
        for (phi, beta) in [(0.0_f64, 0.0_f64), (1.0, 0.6), (-2.0, -1.1), (3.0, 1.5)] {
            let radial = Vector::new(phi.cos(), phi.sin(), 0.0);
            let dir = beta.cos() * radial + beta.sin() * Vector::Z;
            let c = f
                .ball_contact(0.03 * radial + e * dir, r)
                .expect("off the axis");
            assert!((c.depth - (e + r - 0.0078)).abs() < 1e-15);
            assert!((c.normal + dir).length() < 1e-12);
        }
        assert!(f.ball_contact(Vector::new(0.0, 0.0, 0.01), r).is_none());
    }

    #[test]
    fn the_lumen_box_of_a_flat_torus() {
        let b = GrooveFlank::new(Vector::new(1.0, 0.0, 0.0), Vector::Z, 0.03, 0.008).lumen_aabb();
        assert!((b.mins - Vector::new(0.962, -0.038, -0.008)).length() < 1e-15);
        assert!((b.maxs - Vector::new(1.038, 0.038, 0.008)).length() < 1e-15);
    }
}
