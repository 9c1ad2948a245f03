//! A parry query dispatcher for the container shapes.
//!
//! [`ShapeDispatcher`] answers the queries between one of this crate's
//! containers and a parry `Ball`, `Cylinder` or `Capsule` (either order) and
//! returns `Unsupported` for every other pair, so that chained in front of
//! parry's default dispatcher it adds these pairs and changes nothing else:
//!
//! ```
//! use ballcage_shapes::ShapeDispatcher;
//! use parry3d_f64::query::{DefaultQueryDispatcher, QueryDispatcher};
//! let dispatcher = ShapeDispatcher::default().chain(DefaultQueryDispatcher);
//! ```
//!
//! rapier takes it as `NarrowPhase::with_query_dispatcher(dispatcher)`.

use parry3d_f64::math::{Pose, Real, Vector};
use parry3d_f64::query::details::NormalConstraints;
use parry3d_f64::query::details::ShapeCastOptions;
use parry3d_f64::query::{
    ClosestPoints, Contact, ContactManifold, ContactManifoldsWorkspace, NonlinearRigidMotion,
    PersistentQueryDispatcher, QueryDispatcher, ShapeCastHit, TrackedContact, Unsupported,
};
use parry3d_f64::shape::{PackedFeatureId, Shape};

use crate::contact::{Body, LocalContact};
use crate::container::{Container, LineOptions, Reduction, as_container};

/// Queries between the container shapes of this crate and balls, cylinders
/// and capsules; `Unsupported` for any other pair (chain it with parry's
/// `DefaultQueryDispatcher`).
///
/// `contact` reports the deepest point (exact: for a line contact, the
/// deepest sample or the exact maximum between two samples);
/// `contact_manifolds` one manifold of one point per contact that
/// [`Container::body_contacts`] reports with `line` (by default every sample
/// of a cylinder or capsule in contact, each with its own normal).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ShapeDispatcher {
    /// How line contacts (a cylinder or capsule in a tube or groove) are
    /// sampled and reported.
    pub line: LineOptions,
}

impl ShapeDispatcher {
    /// A dispatcher sampling line contacts at `samples` points (≥ 2) along
    /// the axis, reported per sample.
    pub fn with_samples(samples: u32) -> Self {
        Self {
            line: LineOptions {
                samples,
                reduction: Reduction::Stations,
            },
        }
    }
}

/// A container and a body of a query pair.
struct Pair<'a> {
    container: &'a dyn Container,
    body: Body,
    /// The body's frame in the container's frame.
    pose: Pose,
    /// Whether the container is the pair's second shape.
    flipped: bool,
}

impl<'a> Pair<'a> {
    /// The pair of `g1` and `g2` (`g2` at `pos12` in `g1`'s frame), if one is
    /// a container and the other a ball, cylinder or capsule.
    fn of(pos12: &Pose, g1: &'a dyn Shape, g2: &'a dyn Shape) -> Result<Self, Unsupported> {
        if let Some(container) = as_container(g1) {
            let body = Body::from_parry(g2, pos12).ok_or(Unsupported)?;
            return Ok(Self {
                container,
                body,
                pose: *pos12,
                flipped: false,
            });
        }
        let container = as_container(g2).ok_or(Unsupported)?;
        let pose = pos12.inverse();
        let body = Body::from_parry(g1, &pose).ok_or(Unsupported)?;
        Ok(Self {
            container,
            body,
            pose,
            flipped: true,
        })
    }

    /// A local contact as parry's contact of the pair, in the pair's order:
    /// points and normals in each shape's frame, `dist` = −δ.
    fn contact(&self, c: &LocalContact) -> Contact {
        let inverse = self.pose.rotation.inverse();
        let contact = Contact::new(
            c.wall_point(),
            self.pose.inverse_transform_point(c.body_point()),
            c.normal,
            inverse * -c.normal,
            -c.depth,
        );
        if self.flipped {
            contact.flipped()
        } else {
            contact
        }
    }

    /// The deepest contact deeper than −`prediction`.
    fn deepest(&self, prediction: Real, line: LineOptions) -> Option<Contact> {
        let mut best: Option<LocalContact> = None;
        let line = LineOptions {
            reduction: Reduction::Stations,
            ..line
        };
        self.container
            .body_contacts(&self.body, -prediction, line, &mut |c| {
                if best.is_none_or(|b| c.depth > b.depth) {
                    best = Some(c);
                }
            });
        best.map(|c| self.contact(&c))
    }
}

impl QueryDispatcher for ShapeDispatcher {
    fn intersection_test(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
    ) -> Result<bool, Unsupported> {
        Ok(self
            .contact(pos12, g1, g2, 0.0)?
            .is_some_and(|c| c.dist <= 0.0))
    }

    /// The gap between the body and the wall, 0 when they touch;
    /// `Real::MAX` where the body sees no wall (past an open end).
    fn distance(&self, pos12: &Pose, g1: &dyn Shape, g2: &dyn Shape) -> Result<Real, Unsupported> {
        Ok(self
            .contact(pos12, g1, g2, Real::MAX)?
            .map_or(Real::MAX, |c| c.dist.max(0.0)))
    }

    fn contact(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        prediction: Real,
    ) -> Result<Option<Contact>, Unsupported> {
        Ok(Pair::of(pos12, g1, g2)?.deepest(prediction, self.line))
    }

    fn closest_points(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        max_dist: Real,
    ) -> Result<ClosestPoints, Unsupported> {
        Ok(match self.contact(pos12, g1, g2, max_dist)? {
            None => ClosestPoints::Disjoint,
            Some(c) if c.dist <= 0.0 => ClosestPoints::Intersecting,
            Some(c) => ClosestPoints::WithinMargin(c.point1, c.point2),
        })
    }

    /// Not supported.
    fn cast_shapes(
        &self,
        _pos12: &Pose,
        _local_vel12: Vector,
        _g1: &dyn Shape,
        _g2: &dyn Shape,
        _options: ShapeCastOptions,
    ) -> Result<Option<ShapeCastHit>, Unsupported> {
        Err(Unsupported)
    }

    /// Not supported.
    fn cast_shapes_nonlinear(
        &self,
        _motion1: &NonlinearRigidMotion,
        _g1: &dyn Shape,
        _motion2: &NonlinearRigidMotion,
        _g2: &dyn Shape,
        _start_time: Real,
        _end_time: Real,
        _stop_at_penetration: bool,
    ) -> Result<Option<ShapeCastHit>, Unsupported> {
        Err(Unsupported)
    }
}

impl<ManifoldData, ContactData> PersistentQueryDispatcher<ManifoldData, ContactData>
    for ShapeDispatcher
where
    ManifoldData: Default + Clone,
    ContactData: Default + Copy,
{
    /// One manifold of one point per contact deeper than −`prediction`
    /// (see [`ShapeDispatcher`]). A manifold whose point has the same
    /// feature id (the sample along a rod's axis) as before is reused, so
    /// its contact data (a solver's warm start) carries over.
    fn contact_manifolds(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        prediction: Real,
        manifolds: &mut Vec<ContactManifold<ManifoldData, ContactData>>,
        _workspace: &mut Option<ContactManifoldsWorkspace>,
    ) -> Result<(), Unsupported> {
        let pair = Pair::of(pos12, g1, g2)?;
        let mut old = std::mem::take(manifolds);
        pair.container
            .body_contacts(&pair.body, -prediction, self.line, &mut |c| {
                let contact = pair.contact(&c);
                let fid = PackedFeatureId::face(c.feature);
                let tracked =
                    TrackedContact::new(contact.point1, contact.point2, fid, fid, contact.dist);
                let same = |m: &ContactManifold<ManifoldData, ContactData>| {
                    m.points.len() == 1 && m.points[0].fid1 == fid
                };
                let mut m = match old.iter().position(same) {
                    Some(i) => {
                        let mut m = old.swap_remove(i);
                        m.points[0].copy_geometry_from(tracked);
                        m
                    }
                    None => {
                        let mut m = ContactManifold::with_data(0, 0, ManifoldData::default());
                        m.points.push(tracked);
                        m
                    }
                };
                m.local_n1 = contact.normal1;
                m.local_n2 = contact.normal2;
                manifolds.push(m);
            });
        Ok(())
    }

    /// Not supported: the container shapes are not convex.
    fn contact_manifold_convex_convex(
        &self,
        _pos12: &Pose,
        _g1: &dyn Shape,
        _g2: &dyn Shape,
        _normal_constraints1: Option<&dyn NormalConstraints>,
        _normal_constraints2: Option<&dyn NormalConstraints>,
        _prediction: Real,
        _manifold: &mut ContactManifold<ManifoldData, ContactData>,
    ) -> Result<(), Unsupported> {
        Err(Unsupported)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tube::{TubeInterior, TubeSegment};
    use parry3d_f64::query::DefaultQueryDispatcher;
    use parry3d_f64::shape::{Capsule, Cuboid};

    fn straight() -> TubeInterior {
        TubeInterior::new(
            0.058,
            Vector::new(-1.0, 0.0, 0.0),
            Vector::X,
            &[TubeSegment::Straight { length: 2.0 }],
        )
    }

    /// A capsule along x (segment ±0.1 m, r = 43 mm), its axis 15.1 mm below
    /// the tube's: every station is 15.1 + 43 − 58 = 0.1 mm into the wall.
    /// In either order, `contact` gives δ = 0.1 mm and the container's normal
    /// +z (toward its axis), and `contact_manifolds` one manifold per sample.
    #[test]
    fn a_capsule_lying_in_a_tube_through_the_dispatcher() {
        let d = ShapeDispatcher::default().chain(DefaultQueryDispatcher);
        let tube = straight();
        let cap = Capsule::new_x(0.1, 0.043);
        let pos12 = Pose::from_translation(Vector::new(0.0, 0.0, -0.0151));
        let c = d.contact(&pos12, &tube, &cap, 0.0).unwrap().unwrap();
        assert!((c.dist + 1e-4).abs() < 1e-14);
        assert!((c.normal1 - Vector::Z).length() < 1e-12);
        let r = d
            .contact(&pos12.inverse(), &cap, &tube, 0.0)
            .unwrap()
            .unwrap();
        assert!((r.dist + 1e-4).abs() < 1e-14);
        assert!((r.normal1 + Vector::Z).length() < 1e-12);
        let mut manifolds: Vec<ContactManifold<(), u32>> = vec![];
        d.contact_manifolds(&pos12, &tube, &cap, 0.0, &mut manifolds, &mut None)
            .unwrap();
        assert_eq!(manifolds.len(), 5);
        // A solver's per-point data survives the next update of the same samples.
        manifolds[2].points[0].data = 7;
        let moved = Pose::from_translation(Vector::new(0.001, 0.0, -0.0152));
        d.contact_manifolds(&moved, &tube, &cap, 0.0, &mut manifolds, &mut None)
            .unwrap();
        assert_eq!(manifolds.len(), 5);
        assert_eq!(manifolds[2].points[0].data, 7);
        assert!((manifolds[2].points[0].dist + 2e-4).abs() < 1e-14);
    }

    #[test]
    fn other_pairs_are_left_to_the_next_dispatcher() {
        let tube = straight();
        let cube = Cuboid::new(Vector::splat(0.01));
        assert!(
            ShapeDispatcher::default()
                .contact(&Pose::IDENTITY, &tube, &cube, 0.0)
                .is_err()
        );
        assert!(
            ShapeDispatcher::default()
                .contact(&Pose::IDENTITY, &cube, &cube, 0.0)
                .is_err()
        );
    }
}
