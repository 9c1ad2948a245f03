//! Exact parry3d-f64 shapes for bodies held inside a container: the inside
//! of a bent tube, one flank of a Gothic-arch groove, a window slot and a
//! spherical cavity.
//!
//! parry's shapes are convex pieces, meshes and height fields; none is the
//! inside of a curved tube. Meshed, a bore is faceted: the contact normal
//! jumps at every edge, and at 64 facets around a 58 mm radius the wall is
//! off by the 70 µm chord error, tens of percent of the force under a stiff
//! penalty law. These shapes are the closed forms instead: the depth and the
//! normal are exact (to round-off, or to 1e-12 of the positions where a root
//! is solved for), and smooth as a body slides along the wall.
//!
//! | shape | the lumen | the solid |
//! |---|---|---|
//! | [`TubeInterior`] | within `inner_radius` of a centreline of straight and circular-arc segments ([`TubeSegment`]) | the rest, between the two end planes (open ends) |
//! | [`GrooveFlank`] | within `tube_radius` of a core circle: the tube of a torus | the rest |
//! | [`WindowSlot`] | between two parallel planes | the two half-spaces beyond |
//! | [`SphericalCavity`] | within `radius` of a centre | the rest |
//!
//! Each implements parry's `Shape`, `PointQuery` and `RayCast`, and
//! [`Container::body_contacts`] against a ball, a cylinder and a capsule
//! (the table in [`container`]). [`ShapeDispatcher`] answers parry's
//! `contact` and `contact_manifolds` for those pairs; chained in front of
//! parry's `DefaultQueryDispatcher`, it leaves every other pair to parry.
//! The crate depends on parry alone.
//!
//! # Sign convention
//! A [`LocalContact`] is in the container's frame: `depth` δ > 0 when the
//! body reaches into the solid; `normal` is unit, from the container toward
//! the body (into the lumen); `point` lies midway between the surfaces.
//! Through parry, the container's `Contact` has `dist` = −δ, `normal1` the
//! same normal when the container is shape 1, `point1` on its wall.
//!
//! # Example: a ball in a bent tube through parry's query API
//! ```
//! use ballcage_shapes::{ShapeDispatcher, TubeInterior, TubeSegment};
//! use parry3d_f64::math::{Pose, Vector};
//! use parry3d_f64::query::{DefaultQueryDispatcher, QueryDispatcher};
//! use parry3d_f64::shape::Ball;
//!
//! // Down from the origin, then a quarter turn of radius 1.5 m toward +x;
//! // inner radius 58 mm.
//! let tube = TubeInterior::new(
//!     0.058,
//!     Vector::ZERO,
//!     -Vector::Z,
//!     &[TubeSegment::Arc { radius: 1.5, angle: std::f64::consts::FRAC_PI_2, bend: Vector::X }],
//! );
//! // A ball of 43 mm, 15.1 mm off the centreline across the bend plane
//! // (along y), at 30° round the arc: δ = 15.1 + 43 − 58 = 0.1 mm.
//! let a = 30f64.to_radians();
//! let centre = Vector::new(1.5 * (1.0 - a.cos()), 0.0151, -1.5 * a.sin());
//! let dispatcher = ShapeDispatcher::default().chain(DefaultQueryDispatcher);
//! let c = dispatcher
//!     .contact(&Pose::from_translation(centre), &tube, &Ball::new(0.043), 0.0)
//!     .expect("a supported pair")
//!     .expect("in contact");
//! assert!((c.dist + 1e-4).abs() < 1e-12);
//! assert!((c.normal1 + Vector::Y).length() < 1e-12);
//! ```
//!
//! With rapier, give the container to a fixed body's collider as
//! `SharedShape::new(tube)` and build the narrow phase with
//! `NarrowPhase::with_query_dispatcher(ShapeDispatcher::default().chain(DefaultQueryDispatcher))`;
//! `examples/rapier_ball_in_bent_tube.rs` is a whole program.

mod cavity;
mod centreline;
mod contact;
pub mod container;
mod dispatcher;
mod groove;
pub mod line;
mod query;
mod shape;
mod slot;
mod tube;

pub use cavity::SphericalCavity;
pub use centreline::{Centreline, CentrelinePoint};
pub use contact::{Body, LocalContact, Rod};
pub use container::{Container, LineOptions, Reduction, as_container};
pub use dispatcher::ShapeDispatcher;
pub use groove::GrooveFlank;
pub use line::Ends;
pub use slot::WindowSlot;
pub use tube::{TubeInterior, TubeSegment};
