//! A cylinder passing through a circular opening: a shaft's neck through the
//! end ring of a cage or the mouth of a seat, the surfaces that bind when a
//! joint articulates as far as it can.
//!
//! The cylinder (radius r, axis through P along â) touches the ring (centre O,
//! plane normal ê, radius ρ) where the ring comes nearest the axis. With
//! c(φ) = O + ρ(cos φ ê₁ + sin φ ê₂) and w = c − P, the squared distance from
//! the ring point to the axis is g(φ) = |w|² − (w·â)²; the contact is at the
//! minimiser φ*, with δ = r − √g(φ*).
//!
//! For an axis through the ring's axis at distance h from the ring's plane,
//! tilted by t from ê, the nearest ring point lies in the plane of the tilt
//! and √g = ρ·cos t − h·sin t (docs/model.md §3): the
//! closed form the tests check.

use super::{CentreMotion, ContactPoint, NormalTurning, PointSink, Slide};
use crate::math::{Mat3, Quat, Vec3};

/// The ring (on body a) and the cylinder (on body b) in their bodies' frames.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RingCylinder {
    /// Ring centre, a's frame [m].
    pub ring_centre: Vec3,
    /// Unit normal of the ring's plane, a's frame.
    pub ring_axis: Vec3,
    /// Ring radius [m].
    pub ring_radius: f64,
    /// A point of the cylinder's axis, b's frame [m].
    pub axis_point: Vec3,
    /// Unit direction of the cylinder's axis, b's frame.
    pub axis_direction: Vec3,
    /// Cylinder radius [m], smaller than the ring's.
    pub cylinder_radius: f64,
}

impl RingCylinder {
    /// Appends the contact of the cylinder (body b) with the ring (body a),
    /// if they overlap. The normal points from the ring toward the axis,
    /// pushing the cylinder away from the ring.
    pub fn contacts(&self, pa: (&Vec3, &Quat), pb: (&Vec3, &Quat), out: &mut dyn PointSink) {
        let o = pa.0 + pa.1 * self.ring_centre;
        let e = pa.1 * self.ring_axis;
        let p = pb.0 + pb.1 * self.axis_point;
        let a = pb.1 * self.axis_direction;
        if !self.clear(&o, &e, &p, &a) {
            self.search(&o, &e, &p, &a, out);
        }
    }

    /// Whether no ring point can come within the cylinder's radius of its
    /// axis, by a bound far cheaper than [`Self::search`]: a ring point
    /// o + ρ·u (u ⟂ ê, |u| = 1) lies at |(o − P) × â + ρ·u × â| ≥
    /// ρ·|u × â| − |(o − P) × â| from the axis, and |u × â| ≥ |â·ê| for every
    /// such u (|u·â| ≤ √(1 − (â·ê)²)). For an axis through the ring's axis
    /// this is the closed form ρ·cos t − h·sin t of the module's doc, so the
    /// bound is sharp where the pair matters. With a margin of 1e-9·ρ for
    /// rounding, a clear pair has no point for the search to report: skipping
    /// it changes no output (test `culled_rings_change_no_contact_bit_for_bit`).
    fn clear(&self, o: &Vec3, e: &Vec3, p: &Vec3, a: &Vec3) -> bool {
        let bound = self.ring_radius * a.dot(e).abs() - (o - p).cross(a).norm();
        bound > self.cylinder_radius + 1e-9 * self.ring_radius
    }

    /// The search of [`Self::contacts`] at the world poses: ring centre `o`
    /// and normal `e`, cylinder axis point `p` and direction `a`.
    fn search(&self, o: &Vec3, e: &Vec3, p: &Vec3, a: &Vec3, out: &mut dyn PointSink) {
        let (o, e, p, a) = (*o, *e, *p, *a);
        let (e1, e2) = plane_basis(&e);
        let ring = |phi: f64| o + self.ring_radius * (phi.cos() * e1 + phi.sin() * e2);
        let phi = nearest_to_axis(&o, &e1, &e2, self.ring_radius, &p, &a);
        let c = ring(phi);
        let w = c - p;
        let foot = p + w.dot(&a) * a;
        let to_axis = foot - c;
        let d = to_axis.norm();
        let depth = self.cylinder_radius - d;
        if depth <= 0.0 || d < 1e-15 {
            return;
        }
        let normal = to_axis / d;
        // The ring point (on a) in the neck's field (b): the normal toward
        // the axis turns as c moves across it, by −(I − n·nᵀ − â·âᵀ)/d.
        let across = Mat3::identity() - normal * normal.transpose() - a * a.transpose();
        // c is the ring point nearest the axis, (c − foot)·t̂ = 0: it slides
        // along the ring (tangent t̂, curvature −(c − O)/ρ²).
        let radial = (c - o) / self.ring_radius;
        out.push(ContactPoint {
            slot: 0,
            point: c - 0.5 * depth * normal,
            normal,
            depth,
            weight: 1.0,
            turning: NormalTurning {
                centre: c,
                curvature: -across / d,
                centre_on_b: false,
                motion: CentreMotion::Slides(Slide {
                    direction: e.cross(&radial),
                    curvature: -radial / self.ring_radius,
                }),
            },
        });
    }
}

/// Two unit vectors completing `e` to a right-handed orthonormal basis.
fn plane_basis(e: &Vec3) -> (Vec3, Vec3) {
    let helper = if e.x.abs() < 0.9 {
        Vec3::x()
    } else {
        Vec3::y()
    };
    let e1 = e.cross(&helper).normalize();
    (e1, e.cross(&e1))
}

/// (cos, sin) of k·30°, k = 0‥11.
const TWELFTHS: [(f64, f64); 12] = {
    const H: f64 = 0.866_025_403_784_438_6; // √3/2
    [
        (1.0, 0.0),
        (H, 0.5),
        (0.5, H),
        (0.0, 1.0),
        (-0.5, H),
        (-H, 0.5),
        (-1.0, 0.0),
        (-H, -0.5),
        (-0.5, -H),
        (0.0, -1.0),
        (0.5, -H),
        (H, -0.5),
    ]
};

/// The ring angle φ* whose point is nearest the axis (P, â): Newton on
/// g′(φ) = 0 from the best of 12 samples, so that the start lies in the
/// basin of the global minimum.
fn nearest_to_axis(o: &Vec3, e1: &Vec3, e2: &Vec3, rho: f64, p: &Vec3, a: &Vec3) -> f64 {
    // The samples at k·30° from a table of (cos, sin), not from sin_cos.
    let sample = |(c, s): (f64, f64)| {
        let w = o + rho * (c * e1 + s * e2) - p;
        w.norm_squared() - w.dot(a).powi(2)
    };
    let k = (0..12)
        .min_by(|&i, &j| sample(TWELFTHS[i]).total_cmp(&sample(TWELFTHS[j])))
        .unwrap_or(0);
    let mut phi = k as f64 * std::f64::consts::TAU / 12.0;
    for _ in 0..20 {
        let (s, c) = phi.sin_cos();
        let w = o + rho * (c * e1 + s * e2) - p;
        let dc = rho * (-s * e1 + c * e2);
        let ddc = -rho * (c * e1 + s * e2);
        let (wa, da) = (w.dot(a), dc.dot(a));
        let g1 = 2.0 * (w.dot(&dc) - wa * da);
        let g2 = 2.0 * (dc.norm_squared() + w.dot(&ddc) - da * da - wa * ddc.dot(a));
        if g2 <= 0.0 {
            break;
        }
        let step = g1 / g2;
        phi -= step;
        // Quadratic convergence: the next step would be ~1e-20 rad, and the
        // depth's error is second order in φ's at the minimum.
        if step.abs() < 1e-10 {
            break;
        }
    }
    phi
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// A ring of radius ρ at height h on the z axis; the cylinder's axis
    /// through the origin, tilted by t toward +x about y.
    fn touch(rho: f64, h: f64, r: f64, t: f64, spin: f64) -> Option<ContactPoint> {
        let g = RingCylinder {
            ring_centre: Vec3::new(0.0, 0.0, h),
            ring_axis: Vec3::z(),
            ring_radius: rho,
            axis_point: Vec3::zeros(),
            axis_direction: Vec3::z(),
            cylinder_radius: r,
        };
        let tilt = Quat::from_axis_angle(&Vec3::y_axis(), t);
        let about = Quat::from_axis_angle(&Vec3::z_axis(), spin);
        let mut out = vec![];
        g.contacts(
            (&Vec3::zeros(), &about),
            (&Vec3::zeros(), &(about * tilt)),
            &mut out,
        );
        out.first().copied()
    }

    #[test]
    fn a_tilted_neck_touches_the_ring_where_the_closed_form_says() {
        let (rho, h, r) = (0.0237, 0.020, 0.021);
        for deg in [2.0f64, 5.0, 7.5, 10.0] {
            for spin in [0.0, 1.0, 2.5] {
                let t = deg.to_radians();
                let closed = r - (rho * t.cos() - h * t.sin());
                match touch(rho, h, r, t, spin) {
                    Some(c) => {
                        assert_relative_eq!(c.depth, closed, epsilon = 1e-12);
                        // The ring point on the side the neck tilts toward,
                        // pushing the neck back toward the ring's axis.
                        let toward = Quat::from_axis_angle(&Vec3::z_axis(), spin) * Vec3::x();
                        assert!(c.normal.dot(&toward) < -0.9, "{:?}", c.normal);
                    }
                    None => assert!(closed <= 0.0, "missed a contact of {closed} m at {deg}°"),
                }
            }
        }
    }

    #[test]
    fn the_contact_starts_at_the_angle_where_the_neck_meets_the_ring() {
        // ρ cos t − h sin t = r  ⇔  t = acos(r/R) − asin(h/R), R = √(ρ² + h²).
        let (rho, h, r): (f64, f64, f64) = (0.0237, 0.020, 0.021);
        let big_r = (rho * rho + h * h).sqrt();
        let t0 = (r / big_r).acos() - (h / big_r).asin();
        assert!(touch(rho, h, r, t0 - 1e-4, 0.3).is_none());
        let c = touch(rho, h, r, t0 + 1e-4, 0.3).expect("in contact past the limit");
        assert!(c.depth > 0.0 && c.depth < 1e-5);
    }

    /// The cull of [`RingCylinder::clear`] changes no reported contact by a
    /// single bit, on 20 000 poses of the test's neck and ring (tilted 0–12°
    /// about any direction, its axis point up to 2 mm off, turned about
    /// anything), 46 % of them touching; and it does skip the search, for
    /// all but 1.4 % of the poses that do not touch. Without the offset term
    /// of the bound it fails.
    #[test]
    fn culled_rings_change_no_contact_bit_for_bit() {
        let g = RingCylinder {
            ring_centre: Vec3::new(0.0, 0.0, 0.020),
            ring_axis: Vec3::z(),
            ring_radius: 0.0237,
            axis_point: Vec3::zeros(),
            axis_direction: Vec3::z(),
            cylinder_radius: 0.021,
        };
        let mut seed = 0x9e37_79b9_7f4a_7c15_u64;
        let mut uniform = || {
            seed = seed
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut culled, mut touching) = (0, 0);
        for case in 0..20_000 {
            let u: [f64; 8] = std::array::from_fn(|_| uniform() - 0.5);
            let turn = Quat::from_scaled_axis(6.0 * Vec3::new(u[0], u[1], u[2]));
            let tilt_axis = Vec3::new(u[3], u[4], 0.0).normalize();
            let tilt = Quat::from_scaled_axis(tilt_axis * (12.0f64.to_radians() * uniform()));
            let offset = 0.004 * Vec3::new(u[5], u[6], u[7]);
            let (pa, pb) = ((Vec3::zeros(), turn), (turn * offset, turn * tilt));
            let (mut with, mut without) = (vec![], vec![]);
            g.contacts((&pa.0, &pa.1), (&pb.0, &pb.1), &mut with);
            let (o, e) = (pa.0 + pa.1 * g.ring_centre, pa.1 * g.ring_axis);
            let (p, a) = (pb.0 + pb.1 * g.axis_point, pb.1 * g.axis_direction);
            g.search(&o, &e, &p, &a, &mut without);
            assert_eq!(with, without, "case {case}");
            culled += usize::from(g.clear(&o, &e, &p, &a));
            touching += usize::from(!without.is_empty());
        }
        assert!(
            touching > 4000 && touching < 16_000,
            "{touching} of 20 000 poses touch"
        );
        // Sharp where it matters: nearly every clear pose is culled (98.6 % here).
        let clear = 20_000 - touching;
        assert!(
            culled as f64 > 0.9 * clear as f64,
            "{culled} of {clear} clear poses culled"
        );
    }

    #[test]
    fn an_offset_axis_is_measured_exactly() {
        // Axis parallel to the ring's, offset by e toward +x: the nearest ring
        // point is at +x, at distance ρ − e.
        let g = RingCylinder {
            ring_centre: Vec3::zeros(),
            ring_axis: Vec3::z(),
            ring_radius: 0.03,
            axis_point: Vec3::new(0.0, 0.0, 0.0),
            axis_direction: Vec3::z(),
            cylinder_radius: 0.025,
        };
        let mut out = vec![];
        let pb = Vec3::new(0.007, 0.0, 0.5);
        g.contacts(
            (&Vec3::zeros(), &Quat::identity()),
            (&pb, &Quat::identity()),
            &mut out,
        );
        assert_eq!(out.len(), 1);
        assert_relative_eq!(out[0].depth, 0.025 - (0.03 - 0.007), epsilon = 1e-12);
        assert_relative_eq!(out[0].normal, -Vec3::x(), epsilon = 1e-9);
    }
}
