//! A cylinder (a drill-pipe link) inside a tube: a line contact reduced to
//! one point per contact patch.
//!
//! MSC Adams, and so the paper, applies its IMPACT law once per contact
//! patch, with the patch's largest penetration. ballcage does the same: the
//! force a link gets does not depend on how finely it is sampled. A link
//! pressed uniformly into the wall at depth δ gets the single-point law at δ
//! for any sample count, and a link touching at one rim gets the
//! single-point law at that rim (docs/model.md §7.6). The force acts at the
//! patch's centre of pressure, the depth-weighted centroid of its sampled
//! surface points (PROPOSAL: a link lying along the wall then feels no
//! torque from where round-off puts its deepest sample, and a tilting link
//! feels its centre of pressure move continuously toward the deeper end).
//!
//! At axial position s the link's surface point deepest in the wall is the
//! rim point farthest from the centreline, so the depth profile is
//! d(s) = |u(s)| + r − R_tube, u the axis point's offset from the centreline.
//! Its maxima are the rims and the interior points where |u| stops growing:
//! since u is perpendicular to the centreline at the nearest point,
//! d|u|²/ds = 2 u·â exactly (â the link axis), so a maximum lies between two
//! samples where u·â changes from positive to negative. There regula falsi
//! (Illinois) on u·â finds it to round-off, so the largest penetration
//! of a patch is exact, and a patch lying wholly between two samples (a
//! straight link against the convex inner wall of a bend) is not missed.
//! The `points` samples along the axis (rims included) locate the patches: a
//! patch is a run of samples in contact, or such a hidden maximum.

use super::{ContactPoint, TubePath};
use crate::math::{Quat, Vec3};

/// A cylinder's surface in a tube, in the tube's frame.
struct LinkInTube<'a> {
    tube: &'a TubePath,
    /// Centre of the cylinder [m].
    centre: Vec3,
    /// Unit axis.
    axis: Vec3,
    /// Cylinder radius [m].
    radius: f64,
}

/// The deepest surface point of one axial station.
struct Station {
    /// Midpoint between the surfaces [m], tube frame.
    point: Vec3,
    /// Unit normal from the tube toward the link, tube frame.
    normal: Vec3,
    /// Penetration [m]; negative for a gap.
    depth: f64,
    /// u·â: positive while the offset from the centreline grows along the axis [m].
    growth: f64,
}

impl LinkInTube<'_> {
    /// The station at axial position `s` [m]. `None` where the axis is on
    /// the centreline or the station is past the tube's open ends.
    fn station(&self, s: f64) -> Option<Station> {
        let q = self.centre + s * self.axis;
        let c = self.tube.nearest(&q)?;
        let u = q - c.point;
        let across = u - u.dot(&self.axis) * self.axis;
        let len = across.norm();
        if len < 1e-15 {
            return None;
        }
        let w = q + self.radius * across / len;
        let cw = self.tube.nearest(&w)?;
        let rw = w - cw.point;
        let d = rw.norm();
        if d < 1e-15 {
            return None;
        }
        let depth = d - self.tube.inner_radius;
        let out = rw / d;
        Some(Station {
            point: w - 0.5 * depth * out,
            normal: -out,
            depth,
            growth: u.dot(&self.axis),
        })
    }

    /// The axial position in `[a, b]` where the offset from the centreline
    /// stops growing (u·â = 0, the depth's maximum), given u·â = `ga` > 0 at
    /// `a` and `gb` ≤ 0 at `b`: the Illinois variant of regula falsi, which
    /// converges superlinearly on this smooth root, to 1e-12 of the
    /// positions. `None` if a station on the way does not exist.
    fn deepest(&self, (mut a, mut ga): (f64, f64), (mut b, mut gb): (f64, f64)) -> Option<f64> {
        let tolerance = 1e-12 * (1.0 + b.abs().max(a.abs()));
        // Which end moved last: +1 for a, −1 for b.
        let mut side = 0;
        for _ in 0..100 {
            if b - a <= tolerance {
                break;
            }
            let x = (a * gb - b * ga) / (gb - ga);
            let x = if x > a && x < b { x } else { 0.5 * (a + b) };
            let gx = self.station(x)?.growth;
            if gx > 0.0 {
                (a, ga) = (x, gx);
                if side == 1 {
                    gb *= 0.5;
                }
                side = 1;
            } else {
                (b, gb) = (x, gx);
                if side == -1 {
                    ga *= 0.5;
                }
                side = -1;
            }
            if gx == 0.0 {
                return Some(x);
            }
        }
        Some(if ga.abs() < gb.abs() { a } else { b })
    }
}

/// One contact patch under construction (tube frame).
#[derive(Default)]
struct Patch {
    /// Largest penetration [m] and the sample nearest where it is.
    depth: f64,
    slot: usize,
    /// Σ δ_k, Σ δ_k·p_k [m²] and Σ δ_k·n_k [m] over the patch's samples.
    weight: f64,
    point: Vec3,
    normal: Vec3,
}

impl Patch {
    /// Adds a sampled surface point of the patch.
    fn add(&mut self, k: usize, st: &Station) {
        self.deepen(k, st.depth);
        self.weight += st.depth;
        self.point += st.depth * st.point;
        self.normal += st.depth * st.normal;
    }

    /// Raises the patch's largest penetration to `depth` if deeper.
    fn deepen(&mut self, k: usize, depth: f64) {
        if depth > self.depth {
            self.depth = depth;
            self.slot = k;
        }
    }

    /// The patch's contact point, body frames mapped by the tube pose `pt`.
    fn contact(&self, pt: (&Vec3, &Quat)) -> ContactPoint {
        ContactPoint {
            slot: self.slot as u32,
            point: pt.0 + pt.1 * (self.point / self.weight),
            normal: pt.1 * self.normal.normalize(),
            depth: self.depth,
        }
    }
}

/// Contact points of a cylinder (`radius`, `half_length`, axis along its
/// body x) at pose `pc` inside tube `t` at pose `pt`: one per patch.
#[allow(clippy::too_many_arguments)]
pub(super) fn cylinder_tube(
    t: &TubePath,
    pt: (&Vec3, &Quat),
    radius: f64,
    half_length: f64,
    points: u32,
    pc: (&Vec3, &Quat),
    out: &mut Vec<ContactPoint>,
) {
    let inv = pt.1.inverse();
    let link = LinkInTube {
        tube: t,
        centre: inv * (pc.0 - pt.0),
        axis: inv * (pc.1 * Vec3::x()),
        radius,
    };
    let n = points.max(2) as usize;
    let s = |k: usize| -half_length + 2.0 * half_length * k as f64 / (n - 1) as f64;
    let touching = |st: &Option<Station>| st.as_ref().is_some_and(|st| st.depth > 0.0);
    let mut open: Option<Patch> = None;
    // A hidden maximum just before a patch opens belongs to it.
    let mut pending: Option<(usize, f64)> = None;
    // Stations k and k + 1 only: no allocation per evaluation.
    let mut here = link.station(s(0));
    for k in 0..n {
        let next = if k + 1 < n {
            link.station(s(k + 1))
        } else {
            None
        };
        match &here {
            Some(st) if st.depth > 0.0 => {
                let p = open.get_or_insert_with(Patch::default);
                if let Some((j, d)) = pending.take() {
                    p.deepen(j, d);
                }
                p.add(k, st);
            }
            _ => {
                if let Some(p) = open.take() {
                    out.push(p.contact(pt));
                }
            }
        }
        if let Some((x, peak)) = interior_maximum(&link, (s(k), &here), (s(k + 1), &next)) {
            let j = if x - s(k) < s(k + 1) - x { k } else { k + 1 };
            match (&mut open, touching(&next)) {
                (Some(p), _) => p.deepen(j, peak.depth),
                (None, true) => pending = Some((j, peak.depth)),
                (None, false) => {
                    let mut p = Patch::default();
                    p.add(j, &peak);
                    out.push(p.contact(pt));
                }
            }
        }
        here = next;
    }
    if let Some(p) = open {
        out.push(p.contact(pt));
    }
}

/// The interior depth maximum between two neighbouring samples (axial
/// position [m] and station each), if one lies there and is in contact:
/// its position [m] and station.
fn interior_maximum(
    link: &LinkInTube<'_>,
    (sa, a): (f64, &Option<Station>),
    (sb, b): (f64, &Option<Station>),
) -> Option<(f64, Station)> {
    let (a, b) = (a.as_ref()?, b.as_ref()?);
    if !(a.growth > 0.0 && b.growth <= 0.0) {
        return None;
    }
    let x = link.deepest((sa, a.growth), (sb, b.growth))?;
    link.station(x)
        .filter(|st| st.depth > 0.0)
        .map(|st| (x, st))
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
        PairGeometry::CylinderTube { points }.contacts(
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
