//! A spherical cavity: the inside of a sphere (a cage in its seat, a ball
//! head in its cage).

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;

use crate::contact::{LocalContact, Rod, perpendicular};
use crate::line::Ends;

/// The inside of the sphere of `radius` about `centre`, in its frame: the
/// solid is everything farther than `radius` from the centre.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphericalCavity {
    /// Centre [m].
    pub centre: Vector,
    /// Radius [m].
    pub radius: f64,
}

impl SphericalCavity {
    /// The cavity of `radius` [m] about `centre`.
    pub fn new(centre: Vector, radius: f64) -> Self {
        Self { centre, radius }
    }

    /// A sphere of `sphere_radius` [m] centred at `c` against the wall:
    /// δ = |c − O| + r − R, pushed back toward the centre O. `None` when the
    /// two centres coincide (no direction).
    pub fn sphere_contact(&self, c: Vector, sphere_radius: f64) -> Option<LocalContact> {
        let r = c - self.centre;
        let d = r.length();
        let depth = d + sphere_radius - self.radius;
        if d < 1e-15 {
            return None;
        }
        let u = r / d;
        Some(LocalContact {
            point: c + (sphere_radius - 0.5 * depth) * u,
            normal: -u,
            depth,
            feature: 0,
        })
    }

    /// A rod against the wall: the surface point of each end (s = ∓L/2)
    /// farthest from the centre O — a cylinder's rim point along the part of
    /// e − O across the axis (e the end's centre), at distance
    /// √(a² + (b + r)²) with a, b the axial and across parts; a capsule's end
    /// sphere — deeper than `threshold` [m]. The farthest point of a convex
    /// body from O is on these rims, so the deeper of the two is the body's
    /// deepest point. `feature` = the end (0, 1).
    pub fn rod_contacts(
        &self,
        rod: &Rod,
        ends: Ends,
        threshold: f64,
        emit: &mut impl FnMut(LocalContact),
    ) {
        for (end, s) in [(0u32, -rod.half_length), (1, rod.half_length)] {
            let e = rod.at(s);
            let contact = match ends {
                Ends::Round => self.sphere_contact(e, rod.radius),
                Ends::Flat => {
                    let v = e - self.centre;
                    let across = v - v.dot(rod.axis) * rod.axis;
                    let len = across.length();
                    let dir = if len > 1e-15 {
                        across / len
                    } else {
                        perpendicular(rod.axis)
                    };
                    self.sphere_contact(e + rod.radius * dir, 0.0)
                }
            };
            if let Some(c) = contact.filter(|c| c.depth > threshold) {
                emit(LocalContact { feature: end, ..c });
            }
        }
    }

    /// The lumen's bounding box.
    pub fn lumen_aabb(&self) -> Aabb {
        let r = Vector::splat(self.radius);
        Aabb::new(self.centre - r, self.centre + r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_eccentric_sphere_is_pushed_toward_the_centre() {
        let cav = SphericalCavity::new(Vector::new(0.0, 0.0, 0.1), 0.032);
        let c = cav
            .sphere_contact(Vector::new(0.0, 0.0011, 0.1), 0.031)
            .expect("off centre");
        assert!((c.depth - 1e-4).abs() < 1e-15);
        assert!((c.normal + Vector::Y).length() < 1e-15);
    }

    /// A cylinder of half-length h and radius r along x, centred at the
    /// cavity's centre: both rims are √(h² + r²) from it.
    #[test]
    fn a_centred_cylinder_reaches_the_wall_with_both_rims() {
        let (h, r) = (0.02, 0.015);
        let cav = SphericalCavity::new(Vector::ZERO, 0.0249);
        let rod = Rod {
            centre: Vector::ZERO,
            axis: Vector::X,
            half_length: h,
            radius: r,
        };
        let mut out = vec![];
        cav.rod_contacts(&rod, Ends::Flat, 0.0, &mut |c| out.push(c));
        assert_eq!(out.len(), 2);
        let expect = (h * h + r * r).sqrt() - 0.0249;
        for c in &out {
            assert!((c.depth - expect).abs() < 1e-15);
        }
    }
}
