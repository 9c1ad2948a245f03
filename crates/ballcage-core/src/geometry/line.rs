//! A cylinder (a drill-pipe link) inside a tube: a line contact as points.
//!
//! MSC Adams, and so the paper, applies its IMPACT law once per contact
//! patch at the patch's largest penetration. That force jumps when patches
//! merge or split (two patches of depth δ each carry 2·Kδⁿ, one merged patch
//! Kδⁿ), and a point at the patch's sampled centroid moves its moment with
//! the sample count. ballcage's default, the level-set law
//! ([`LineLaw::LevelSets`], docs/model.md §4), keeps what Adams gets
//! right and removes both defects:
//! - a link pressed uniformly into the wall at depth δ gets the single-point
//!   law at δ, and a link touching at one rim the single-point law at that
//!   rim (one depth maximum, no minimum);
//! - two separate patches get one point law each, as in Adams;
//! - between those, the energy Σ Φ(δ_max) − Σ Φ(δ_min) over the exact depth
//!   extrema (Φ the point law's elastic energy) counts the connected pieces
//!   of the contact at each depth, so force, moment and energy are
//!   continuous in the link's pose, and the elastic force is the gradient
//!   of that energy: each maximum carries the point law along its normal,
//!   each interior minimum the point law with the sign reversed
//!   ([`ContactPoint::weight`] = −1).
//!
//! The extrema are found exactly (`ballcage_shapes::line::line_extrema`):
//! the samples only bracket them, so the answer does not depend on the
//! sample count once each extremum has its own bracket. The earlier law
//! stays as [`LineLaw::Patches`] for comparison
//! (`ballcage_shapes::line::line_patches`).

use ballcage_shapes::line::{Ends, line_extrema, line_patches};
use ballcage_shapes::{Rod, TubeInterior};
use parry3d_f64::math::Vector;

use super::{
    CentreMotion, ContactPoint, Crossing, LineContact, LineLaw, NormalTurning, PointSink, Rim,
    Slide, TubePath,
};
use crate::math::{Quat, Vec3, from_glam, to_glam};
use ballcage_shapes::line::Extremum;

/// Contact points of a cylinder (`radius`, `half_length`, axis along its
/// body x) at pose `pc` inside tube `t` at pose `pt`, by the `line`
/// contact's law, from its samples along the axis (rims included).
#[allow(clippy::too_many_arguments)]
pub(super) fn cylinder_tube(
    t: &TubePath,
    pt: (&Vec3, &Quat),
    radius: f64,
    half_length: f64,
    line: LineContact,
    pc: (&Vec3, &Quat),
    out: &mut dyn PointSink,
) {
    let inv = pt.1.inverse();
    let rod = Rod {
        centre: to_glam(&(inv * (pc.0 - pt.0))),
        axis: to_glam(&(inv * (pc.1 * Vec3::x()))),
        half_length,
        radius,
    };
    let inside = t.interior();
    // The turning costs nearest-point queries of its own: only for a Jacobian.
    let wants_turning = out.wants_turning();
    let mut push = |c: ballcage_shapes::LocalContact, kind: Option<Extremum>| {
        let weight = kind.map_or(1.0, Extremum::weight);
        let normal = pt.1 * from_glam(c.normal);
        let point = pt.0 + pt.1 * from_glam(c.point);
        let turning = if wants_turning {
            turning(&c, kind, &rod, inside, pt)
        } else {
            NormalTurning::plane(point)
        };
        out.push(ContactPoint {
            slot: c.feature,
            point,
            normal,
            depth: c.depth,
            weight,
            turning,
        })
    };
    let inside_length = match line.law {
        LineLaw::LevelSets => line_extrema(
            t.interior(),
            &rod,
            Ends::Flat,
            line.points,
            (0.0, t.end_engagement()),
            &mut |c, kind| push(c, Some(kind)),
        ),
        LineLaw::Patches => {
            line_patches(t.interior(), &rod, Ends::Flat, line.points, 0.0, &mut |c| {
                push(c, None)
            });
            None
        }
    };
    // A link crossing an open end carries its wall contact in proportion to
    // how much of it is inside (docs/model.md §4, "The tube's open ends").
    if let Some(length) = inside_length {
        let w = t.engagement(length);
        if w < 1.0 {
            for p in out.filled() {
                p.weight *= w;
            }
        }
    }
}

/// How the normal of contact `c` (tube frame, an extremum of `kind`, or
/// the patch law's point) of `rod` in the tube `inside` at pose `pt` turns.
fn turning(
    c: &ballcage_shapes::LocalContact,
    kind: Option<Extremum>,
    rod: &Rod,
    inside: &TubeInterior,
    pt: (&Vec3, &Quat),
) -> NormalTurning {
    // The lumen's normal field at the point (tube frame) through which the
    // normal force acts.
    let normal = pt.1 * from_glam(c.normal);
    let field = |centre: Vector| match inside.nearest(centre) {
        Some(core) => NormalTurning::lumen(
            pt.0 + pt.1 * from_glam(centre),
            &normal,
            (centre - core.point).length(),
            &(pt.1 * from_glam(core.tangent)),
            &(pt.1 * from_glam(core.curvature)),
        ),
        None => NormalTurning::plane(pt.0 + pt.1 * from_glam(centre)),
    };
    match kind {
        // A rim: the force acts through the rim point w, δ/2 behind the
        // midpoint, which moves around the rim.
        Some(Extremum::End) => {
            let mut turning = field(c.point - 0.5 * c.depth * c.normal);
            let s = if c.feature == 0 {
                -rod.half_length
            } else {
                rod.half_length
            };
            turning.motion = rim(rod, s, inside, pt);
            turning
        }
        // The section in an open end's plane: like a rim, through its
        // deepest point w, which moves around the section and, with the
        // section, along the axis to keep the section on the plane.
        Some(Extremum::Mouth) => {
            let deepest = c.point - 0.5 * c.depth * c.normal;
            let mut turning = field(deepest);
            // w − q is across the axis: the section's axial position.
            let s = (deepest - rod.centre).dot(rod.axis);
            let q = rod.at(s);
            let (end, out) = inside.nearer_end(q);
            turning.motion = match rim(rod, s, inside, pt) {
                CentreMotion::Rim(section) => CentreMotion::Crosses(Crossing {
                    rim: section,
                    plane_normal: pt.1 * from_glam(out),
                    rim_on_plane: (deepest - end).dot(out) > (q - end).dot(out),
                }),
                other => other,
            };
            turning
        }
        // Otherwise through the axis point, (r − δ/2) beyond the midpoint
        // along n (for the patch law's centroid, the link's section there
        // taken as a ball); an interior extremum slides along the axis.
        _ => {
            let mut turning = field(c.point + (rod.radius - 0.5 * c.depth) * c.normal);
            if kind.is_some() {
                turning.motion = CentreMotion::Slides(Slide {
                    direction: pt.1 * from_glam(rod.axis),
                    curvature: Vec3::zeros(),
                });
            }
            turning
        }
    }
}

/// The rim of `rod`'s end at `s` [m] in the tube `inside` (pose `pt`).
fn rim(rod: &Rod, s: f64, inside: &TubeInterior, pt: (&Vec3, &Quat)) -> CentreMotion {
    let q = rod.at(s);
    let Some(core) = inside.nearest(q) else {
        return CentreMotion::Fixed;
    };
    let u = q - core.point;
    CentreMotion::Rim(Rim {
        end: pt.0 + pt.1 * from_glam(q),
        axis: pt.1 * from_glam(rod.axis),
        radius: rod.radius,
        offset: pt.1 * from_glam(u),
        core_tangent: pt.1 * from_glam(core.tangent),
        beta: 1.0 / (1.0 - u.dot(core.curvature)),
    })
}

#[cfg(test)]
mod tests {
    use super::super::{PairGeometry, Shape, TubeSegment};
    use super::*;
    use approx::assert_relative_eq;

    fn contacts(
        tube: &Shape,
        half_length: f64,
        points: u32,
        pc: (Vec3, Quat),
    ) -> Vec<ContactPoint> {
        let cyl = Shape::Cylinder {
            radius: 0.043,
            half_length,
        };
        let mut out = vec![];
        PairGeometry::CylinderTube(LineContact {
            points,
            law: LineLaw::Patches,
        })
        .contacts(
            tube,
            (&Vec3::zeros(), &Quat::identity()),
            &cyl,
            (&pc.0, &pc.1),
            &mut out,
        );
        out
    }

    fn straight() -> Shape {
        Shape::Tube(TubePath::new(
            0.058,
            Vec3::new(-1.0, 0.0, 0.0),
            Vec3::x(),
            &[TubeSegment::Straight { length: 2.0 }],
        ))
    }

    #[test]
    fn a_link_pressed_uniformly_gets_one_point_at_its_depth_for_any_sampling() {
        // Centre 15.1 mm below the axis: 43 + 15.1 − 58 = 0.1 mm into the wall all along.
        for points in [2, 5, 9, 17] {
            let out = contacts(
                &straight(),
                0.1,
                points,
                (Vec3::new(0.0, 0.0, -0.0151), Quat::identity()),
            );
            assert_eq!(out.len(), 1, "{points} samples");
            assert_relative_eq!(out[0].depth, 1e-4, epsilon = 1e-12);
            assert_relative_eq!(out[0].normal, Vec3::z(), epsilon = 1e-12);
            // The centre of pressure of a uniform patch is the link's middle.
            assert_relative_eq!(out[0].point.x, 0.0, epsilon = 1e-12);
        }
    }

    #[test]
    fn a_tilted_link_touches_at_its_lower_rim_only() {
        // Tilted by 0.01 rad about y, centre 14.1 mm down: the rim at x = +0.1 m
        // sits 0.1·sin(0.01) lower, its surface point 43·cos(0.01) mm below the
        // axis: depth = 0.0141 + 0.1 sin θ + 0.043 cos θ − 0.058 = 0.098 mm, and
        // the wall is reached only within 9.8 mm of the rim, less than the
        // 12.5 mm between 17 samples: one patch at the rim, the single-point law.
        let th: f64 = 0.01;
        let q = Quat::from_axis_angle(&Vec3::y_axis(), th);
        for points in [5, 17] {
            let out = contacts(&straight(), 0.1, points, (Vec3::new(0.0, 0.0, -0.0141), q));
            assert_eq!(out.len(), 1, "{points} samples");
            let expect = 0.0141 + 0.1 * th.sin() + 0.043 * th.cos() - 0.058;
            assert_relative_eq!(out[0].depth, expect, epsilon = 1e-12);
            assert_eq!(out[0].slot, points - 1);
            // The patch acts at the rim: its surface point, 0.1 m along the axis.
            let rim = q * Vec3::new(0.1, 0.0, -0.043) + Vec3::new(0.0, 0.0, -0.0141);
            assert_relative_eq!(out[0].point.x, rim.x, epsilon = 1e-9);
        }
    }

    #[test]
    fn a_chord_against_the_inner_wall_is_found_between_samples() {
        // An arc of centreline radius 0.5 m about O = (0.5, 0, 0) (tube starting at
        // the origin along −z, bending toward +x). A straight link of half-length
        // 0.2 m on the chord at distance h from O, perpendicular to the radius
        // through the arc's midpoint: its axis points are √(h² + s²) from O, so
        // the surface point nearest O penetrates the inner wall by
        // 0.5 − √(h² + s²) + 0.043 − 0.058, largest at s = 0. With h chosen for a
        // 0.1 mm penetration there, the samples at ±0.2/3 m are out of contact.
        let tube = Shape::Tube(TubePath::new(
            0.058,
            Vec3::zeros(),
            -Vec3::z(),
            &[TubeSegment::Arc {
                radius: 0.5,
                angle: std::f64::consts::FRAC_PI_2,
                bend: Vec3::x(),
            }],
        ));
        let o = Vec3::new(0.5, 0.0, 0.0);
        let mid = std::f64::consts::FRAC_PI_4;
        let radial = Vec3::new(-mid.cos(), 0.0, -mid.sin()); // from O toward the arc's midpoint
        let h = 0.5 + 0.043 - 0.058 - 1e-4;
        let centre = o + h * radial;
        // The link's x axis along the chord (perpendicular to `radial` in the bend plane).
        let q = Quat::rotation_between(&Vec3::x(), &Vec3::new(-radial.z, 0.0, radial.x)).unwrap();
        let side = 0.5 - (h * h + (0.2_f64 / 3.0).powi(2)).sqrt() + 0.043 - 0.058;
        assert!(
            side < 0.0,
            "the samples beside the middle must be out of contact"
        );
        for points in [4, 5, 17] {
            let out = contacts(&tube, 0.2, points, (centre, q));
            // The rims touch the outer wall; the middle, alone, the inner wall.
            assert_eq!(out.len(), 3, "{points} samples");
            let middle = &out[1];
            assert_relative_eq!(middle.depth, 1e-4, epsilon = 1e-9);
            // The normal pushes the link away from O (from the inner wall outward).
            assert_relative_eq!(middle.normal, radial, epsilon = 1e-6);
            // Each rim: its surface point farthest out lies 43 mm beyond the
            // axis, perpendicular to it, so (h + 0.043, ±0.2) from O in the bend plane.
            let rim = ((h + 0.043).powi(2) + 0.04_f64).sqrt() - 0.5 - 0.058;
            assert_relative_eq!(out[0].depth, rim, epsilon = 1e-9);
            assert_relative_eq!(out[2].depth, rim, epsilon = 1e-9);
        }
        // The same chord slid 10 mm along its axis: the deepest point stays at
        // the foot of the perpendicular from O, now off the middle of the
        // samples bracketing it, and is still found exactly, where it is.
        let along = Vec3::new(-radial.z, 0.0, radial.x);
        for points in [4, 6] {
            let out = contacts(&tube, 0.2, points, (centre + 0.01 * along, q));
            let middle = out
                .iter()
                .find(|c| c.normal.dot(&radial) > 0.99)
                .expect("the inner-wall patch");
            assert_relative_eq!(middle.depth, 1e-4, epsilon = 1e-9);
            assert_relative_eq!((middle.point - centre).dot(&along), 0.0, epsilon = 1e-6);
        }
    }
}
