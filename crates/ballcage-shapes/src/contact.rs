//! The frame-local contact every shape of this crate reports, and the
//! convex bodies it reports it for.

use parry3d_f64::math::{Pose, Vector};
use parry3d_f64::shape::Shape;

/// One contact between a container shape (its solid surrounds a lumen) and
/// a body inside it, in the container's frame.
///
/// Sign convention (the crate's, and ballcage's `geometry::ContactPoint`):
/// - `depth` δ [m] is positive when the body reaches into the solid, negative
///   for a gap (only reported within a caller's threshold);
/// - `normal` is a unit vector **from the container toward the body** (into
///   the lumen): the normal force on the body is `+F_n·normal`;
/// - `point` [m] is midway between the two surface points: the container's
///   wall point is `point + δ/2·normal`, the body's deepest point
///   `point − δ/2·normal`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LocalContact {
    /// Midpoint between the surfaces [m], container frame.
    pub point: Vector,
    /// Unit normal from the container toward the body, container frame.
    pub normal: Vector,
    /// Penetration δ [m]; negative for a gap.
    pub depth: f64,
    /// Which sample of the body this is (line contacts: the sample index
    /// along the axis; otherwise 0): a stable id for per-point memory.
    pub feature: u32,
}

impl LocalContact {
    /// The container's surface point [m], container frame.
    pub fn wall_point(&self) -> Vector {
        self.point + 0.5 * self.depth * self.normal
    }

    /// The body's deepest surface point [m], container frame.
    pub fn body_point(&self) -> Vector {
        self.point - 0.5 * self.depth * self.normal
    }
}

/// A cylinder or capsule about a straight axis, in the container's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rod {
    /// Centre of the axis segment [m].
    pub centre: Vector,
    /// Unit direction of the axis.
    pub axis: Vector,
    /// Half-length of the axis segment [m] (a capsule's caps extend beyond it).
    pub half_length: f64,
    /// Radius [m].
    pub radius: f64,
}

impl Rod {
    /// The axis point at `s` [m] from the centre.
    #[inline]
    pub fn at(&self, s: f64) -> Vector {
        self.centre + s * self.axis
    }
}

/// A convex body inside a container, placed in the container's frame: the
/// bodies the pair functions of this crate answer for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Body {
    /// Sphere.
    Ball {
        /// Centre [m].
        centre: Vector,
        /// Radius [m].
        radius: f64,
    },
    /// Cylinder with flat ends.
    Cylinder(Rod),
    /// Capsule: the axis segment swept by a sphere.
    Capsule(Rod),
}

impl Body {
    /// The body of a parry `shape` whose frame is at `pose` in the
    /// container's frame: a `Ball`, a `Cylinder` (axis along its local y)
    /// or a `Capsule`; `None` for any other shape.
    pub fn from_parry(shape: &dyn Shape, pose: &Pose) -> Option<Self> {
        if let Some(b) = shape.as_ball() {
            return Some(Self::Ball {
                centre: pose.translation,
                radius: b.radius,
            });
        }
        if let Some(c) = shape.as_cylinder() {
            return Some(Self::Cylinder(Rod {
                centre: pose.translation,
                axis: pose.rotation * Vector::Y,
                half_length: c.half_height,
                radius: c.radius,
            }));
        }
        let c = shape.as_capsule()?;
        let (a, b) = (pose * c.segment.a, pose * c.segment.b);
        let length = (b - a).length();
        let centre = 0.5 * (a + b);
        if length < 1e-15 {
            return Some(Self::Ball {
                centre,
                radius: c.radius,
            });
        }
        Some(Self::Capsule(Rod {
            centre,
            axis: (b - a) / length,
            half_length: 0.5 * length,
            radius: c.radius,
        }))
    }
}

/// `v / |v|`: the same rounding as nalgebra's `normalize` (a division, not
/// a multiplication by the reciprocal), so ballcage's results do not move by
/// an ulp when its geometry calls this crate.
#[inline]
pub(crate) fn unit(v: Vector) -> Vector {
    v / v.length()
}

/// A unit vector perpendicular to the unit vector `n`.
pub(crate) fn perpendicular(n: Vector) -> Vector {
    let a = if n.x.abs() < 0.6 {
        Vector::X
    } else {
        Vector::Y
    };
    unit(a - a.dot(n) * n)
}

#[cfg(test)]
mod tests {
    use super::*;
    use parry3d_f64::shape::{Ball, Capsule, Cylinder};

    #[test]
    fn parry_bodies_are_placed_in_the_container_frame() {
        // A cylinder turned 90° about z: its local y axis is the container's −x.
        let pose = Pose::from_parts(
            Vector::new(1.0, 2.0, 3.0),
            parry3d_f64::math::Rotation::from_rotation_z(std::f64::consts::FRAC_PI_2),
        );
        let Some(Body::Cylinder(rod)) = Body::from_parry(&Cylinder::new(0.1, 0.04), &pose) else {
            panic!("a cylinder")
        };
        assert!((rod.axis - Vector::new(-1.0, 0.0, 0.0)).length() < 1e-15);
        assert_eq!((rod.half_length, rod.radius), (0.1, 0.04));
        // A capsule from (0, −1, 0) to (0, 1, 0) in its frame: centre at the
        // translation, half-length 1 along −x.
        let cap = Capsule::new_y(1.0, 0.2);
        let Some(Body::Capsule(rod)) = Body::from_parry(&cap, &pose) else {
            panic!("a capsule")
        };
        assert!((rod.centre - pose.translation).length() < 1e-15);
        assert!((rod.half_length - 1.0).abs() < 1e-15);
        assert!(Body::from_parry(&Ball::new(0.3), &pose).is_some());
    }

    #[test]
    fn surface_points_lie_half_the_depth_either_side_of_the_midpoint() {
        let c = LocalContact {
            point: Vector::ZERO,
            normal: Vector::Z,
            depth: 2e-4,
            feature: 0,
        };
        // The wall point is δ further along the normal than the body's deepest point.
        assert!((c.wall_point() - c.body_point() - 2e-4 * Vector::Z).length() < 1e-18);
    }
}
