//! parry's `Shape` for the container shapes.
//!
//! All four are `ShapeType::Custom`: parry's own dispatcher does not know
//! them, [`crate::ShapeDispatcher`] does. Their bounding box is the lumen's
//! (what a body inside can touch; the slot's planes are unbounded, so its box
//! is parry's half-space box), they have no mass (they are containers, for
//! fixed or kinematic bodies: give their colliders zero density) and are
//! not convex.

use parry3d_f64::bounding_volume::{Aabb, BoundingSphere};
use parry3d_f64::mass_properties::MassProperties;
use parry3d_f64::math::{Real, Vector};
use parry3d_f64::shape::{Shape, ShapeType, TypedShape};

use crate::cavity::SphericalCavity;
use crate::groove::GrooveFlank;
use crate::slot::WindowSlot;
use crate::tube::TubeInterior;

/// The `Shape` methods all four share; `$aabb` is the local box and
/// `$thickness` the CCD thickness [m] (the lumen's radius).
macro_rules! container_shape {
    ($t:ty, |$s:ident| $aabb:expr, $thickness:expr) => {
        impl Shape for $t {
            fn compute_local_aabb(&self) -> Aabb {
                let $s = self;
                $aabb
            }

            fn compute_local_bounding_sphere(&self) -> BoundingSphere {
                self.compute_local_aabb().bounding_sphere()
            }

            fn clone_dyn(&self) -> Box<dyn Shape> {
                Box::new(self.clone())
            }

            /// Not supported: `None`.
            fn scale_dyn(&self, _scale: Vector, _num_subdivisions: u32) -> Option<Box<dyn Shape>> {
                None
            }

            /// A container has no mass of its own: zero.
            fn mass_properties(&self, _density: Real) -> MassProperties {
                MassProperties::new(Vector::ZERO, 0.0, Vector::ZERO)
            }

            fn shape_type(&self) -> ShapeType {
                ShapeType::Custom
            }

            fn as_typed_shape(&self) -> TypedShape<'_> {
                TypedShape::Custom(self)
            }

            fn ccd_thickness(&self) -> Real {
                let $s = self;
                $thickness
            }

            fn ccd_angular_thickness(&self) -> Real {
                std::f64::consts::FRAC_PI_2
            }
        }
    };
}

container_shape!(TubeInterior, |s| s.lumen_aabb(), s.inner_radius());
container_shape!(GrooveFlank, |s| s.lumen_aabb(), s.tube_radius);
container_shape!(SphericalCavity, |s| s.lumen_aabb(), s.radius);
container_shape!(
    WindowSlot,
    |s| {
        let _ = s;
        let max = Vector::splat(Real::MAX * 0.5);
        Aabb::new(-max, max)
    },
    s.half_width
);
