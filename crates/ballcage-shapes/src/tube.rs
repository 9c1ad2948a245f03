//! The inside of a tube whose centreline is a chain of straight and
//! circular-arc segments.
//!
//! A faceted (meshed) tube wall tilts the contact normal at every facet edge
//! and changes the penetration by the chord error, which under a stiff
//! penalty law is tens of percent of the force. Here the wall is exact: the
//! distance to the centreline minus the inner radius.

use parry3d_f64::bounding_volume::Aabb;
use parry3d_f64::math::Vector;

use crate::centreline::{Centreline, CentrelinePoint, CircularArc};
use crate::contact::{LocalContact, unit};

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
        /// Turned angle [rad], in (0, 2π).
        angle: f64,
        /// Direction toward the arc's centre (tube frame); only its part
        /// across the current direction is used.
        bend: Vector,
    },
}

/// One centreline piece, placed.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Segment {
    /// `start + s·dir`, s ∈ [0, length].
    Straight {
        start: Vector,
        dir: Vector,
        length: f64,
    },
    /// `center + radius(cos θ·u + sin θ·t)`, θ ∈ [0, angle]; u points from the
    /// centre to the start, t is the start tangent; `end` = (cos, sin) of
    /// `angle`, so that the nearest-point query needs no trigonometry.
    Arc {
        center: Vector,
        radius: f64,
        u: Vector,
        t: Vector,
        angle: f64,
        end: (f64, f64),
    },
}

/// The inside of a tube: a centreline of straight and arc segments with an
/// inner radius, in the tube's frame. The solid is everything farther than
/// the inner radius from the centreline, between the two end planes: beyond
/// the open ends there is no wall.
#[derive(Debug, Clone, PartialEq)]
pub struct TubeInterior {
    inner_radius: f64,
    pub(crate) segments: Vec<Segment>,
    start: Vector,
    start_dir: Vector,
    end: Vector,
    end_dir: Vector,
    length: f64,
}

impl TubeInterior {
    /// The tube of `inner_radius` [m] around the centreline of `specs` from
    /// `start` along `direction` (both tube frame); lengths, radii and angles
    /// positive, `bend` not along the direction it turns.
    pub fn new(inner_radius: f64, start: Vector, direction: Vector, specs: &[TubeSegment]) -> Self {
        let mut p = start;
        let mut d = unit(direction);
        let mut segments = Vec::with_capacity(specs.len());
        let mut length = 0.0;
        for s in specs {
            match *s {
                TubeSegment::Straight { length: l } => {
                    segments.push(Segment::Straight {
                        start: p,
                        dir: d,
                        length: l,
                    });
                    p += l * d;
                    length += l;
                }
                TubeSegment::Arc {
                    radius,
                    angle,
                    bend: b,
                } => {
                    let b = unit(b - b.dot(d) * d);
                    let center = p + radius * b;
                    let (u, t) = (-b, d);
                    segments.push(Segment::Arc {
                        center,
                        radius,
                        u,
                        t,
                        angle,
                        end: (angle.cos(), angle.sin()),
                    });
                    p = center + radius * (angle.cos() * u + angle.sin() * t);
                    d = -angle.sin() * u + angle.cos() * t;
                    length += radius * angle;
                }
            }
        }
        Self {
            inner_radius,
            segments,
            start,
            start_dir: unit(direction),
            end: p,
            end_dir: d,
            length,
        }
    }

    /// Inner (lumen) radius [m].
    pub fn inner_radius(&self) -> f64 {
        self.inner_radius
    }

    /// Centreline length [m].
    pub fn length(&self) -> f64 {
        self.length
    }

    /// The open ends: (point, unit direction out of the tube) at the start
    /// and at the end of the centreline.
    pub fn ends(&self) -> [(Vector, Vector); 2] {
        [(self.start, -self.start_dir), (self.end, self.end_dir)]
    }

    /// The open end of [`Self::ends`] whose point is nearer `q`.
    pub fn nearer_end(&self, q: Vector) -> (Vector, Vector) {
        let [start, end] = self.ends();
        if (q - start.0).length_squared() < (q - end.0).length_squared() {
            start
        } else {
            end
        }
    }

    /// Centreline point at arc length `s` [m] from the start (clamped), with its tangent.
    pub fn point_at(&self, s: f64) -> CentrelinePoint {
        let mut rest = s.clamp(0.0, self.length);
        for (i, seg) in self.segments.iter().enumerate() {
            let last = i + 1 == self.segments.len();
            match *seg {
                Segment::Straight { start, dir, length } => {
                    if rest <= length || last {
                        return CentrelinePoint {
                            point: start + rest.min(length) * dir,
                            tangent: dir,
                            curvature: Vector::ZERO,
                        };
                    }
                    rest -= length;
                }
                Segment::Arc {
                    center,
                    radius,
                    u,
                    t,
                    angle,
                    ..
                } => {
                    let seg_len = radius * angle;
                    if rest <= seg_len || last {
                        let th = (rest / radius).min(angle);
                        let out = th.cos() * u + th.sin() * t;
                        return CentrelinePoint {
                            point: center + radius * out,
                            tangent: -th.sin() * u + th.cos() * t,
                            curvature: -out / radius,
                        };
                    }
                    rest -= seg_len;
                }
            }
        }
        CentrelinePoint {
            point: self.end,
            tangent: self.end_dir,
            curvature: Vector::ZERO,
        }
    }

    /// Nearest centreline point to `q`, or `None` when `q` lies beyond either
    /// open end of the tube (past the end planes), where there is no wall.
    pub fn nearest(&self, q: Vector) -> Option<CentrelinePoint> {
        if (q - self.start).dot(self.start_dir) < 0.0 && self.closer_to_end(q, self.start) {
            return None;
        }
        if (q - self.end).dot(self.end_dir) > 0.0 && self.closer_to_end(q, self.end) {
            return None;
        }
        // One segment (a plain bend): no comparison, nothing copied.
        if let [seg] = self.segments.as_slice() {
            return Some(nearest_on_segment(seg, q));
        }
        let mut best: Option<(f64, CentrelinePoint)> = None;
        for seg in &self.segments {
            let c = nearest_on_segment(seg, q);
            let d2 = (q - c.point).length_squared();
            if best.as_ref().is_none_or(|(b, _)| d2 < *b) {
                best = Some((d2, c));
            }
        }
        best.map(|(_, c)| c)
    }

    /// The index of the segment [`Self::nearest`] lies on (the same
    /// comparison; `None` where it is `None`).
    pub(crate) fn nearest_segment(&self, q: Vector) -> Option<usize> {
        let c = self.nearest(q)?;
        self.segments
            .iter()
            .position(|seg| nearest_on_segment(seg, q).point == c.point)
    }

    /// Whether the nearest centreline point of `q` is the end point `e`.
    fn closer_to_end(&self, q: Vector, e: Vector) -> bool {
        let de = (q - e).length_squared();
        self.segments
            .iter()
            .all(|s| (q - nearest_on_segment(s, q).point).length_squared() >= de - 1e-18)
    }

    /// A ball of `radius` [m] centred at `centre` (tube frame) against the
    /// wall: its surface point farthest from the centreline, w, and the wall
    /// there. δ = |w − c(w)| − R_tube, which is |centre − c| + r − R_tube.
    /// `None` where the centre is on the centreline or past an open end.
    pub fn ball_contact(&self, centre: Vector, radius: f64) -> Option<LocalContact> {
        let c = self.nearest(centre)?;
        let r = centre - c.point;
        let d = r.length();
        if d < 1e-15 {
            return None;
        }
        let w = centre + radius * r / d;
        self.wall_contact(w)
    }

    /// The wall against a surface point `w` (tube frame) of a body: the
    /// normal from the wall toward the body (inward), δ = |w − c(w)| − R.
    pub fn wall_contact(&self, w: Vector) -> Option<LocalContact> {
        let c = self.nearest(w)?;
        let r = w - c.point;
        let d = r.length();
        if d < 1e-15 {
            return None;
        }
        let depth = d - self.inner_radius;
        let out = r / d;
        Some(LocalContact {
            point: w - 0.5 * depth * out,
            normal: -out,
            depth,
            feature: 0,
        })
    }

    /// The lumen's bounding box: every point within the inner radius of
    /// the centreline.
    pub fn lumen_aabb(&self) -> Aabb {
        let (mut lo, mut hi) = (Vector::splat(f64::MAX), Vector::splat(f64::MIN));
        for seg in &self.segments {
            let (a, b) = segment_aabb(seg);
            lo = lo.min(a);
            hi = hi.max(b);
        }
        let r = Vector::splat(self.inner_radius);
        Aabb::new(lo - r, hi + r)
    }
}

impl Centreline for TubeInterior {
    #[inline]
    fn nearest(&self, q: Vector) -> Option<CentrelinePoint> {
        TubeInterior::nearest(self, q)
    }

    #[inline]
    fn wall_radius(&self) -> f64 {
        self.inner_radius
    }

    /// (q − e)·ô for the open end (e, ô) of [`TubeInterior::ends`] whose
    /// point e is nearer `q`.
    fn past_end(&self, q: Vector) -> Option<f64> {
        let (e, out) = self.nearer_end(q);
        Some((q - e).dot(out))
    }

    /// A tube of one arc segment of at most π (the paper's bend). Its end
    /// planes pass through the circle's centre, so a point whose direction
    /// lies within the angle is before both, and its nearest point is the
    /// arc's ([`TubeInterior::nearest`]).
    fn arc(&self) -> Option<CircularArc> {
        match self.segments.as_slice() {
            [
                Segment::Arc {
                    center,
                    radius,
                    u,
                    t,
                    angle,
                    end,
                },
            ] if *angle <= std::f64::consts::PI => Some(CircularArc {
                centre: *center,
                radius: *radius,
                u: *u,
                t: *t,
                end: *end,
            }),
            _ => None,
        }
    }
}

/// The bounding box of one centreline segment: its end points and, for an
/// arc, the points where a coordinate is extreme on its circle, if they lie
/// within its angle.
fn segment_aabb(seg: &Segment) -> (Vector, Vector) {
    match *seg {
        Segment::Straight { start, dir, length } => {
            let end = start + length * dir;
            (start.min(end), start.max(end))
        }
        Segment::Arc {
            center,
            radius,
            u,
            t,
            angle,
            ..
        } => {
            let at = |th: f64| center + radius * (th.cos() * u + th.sin() * t);
            let (a, b) = (at(0.0), at(angle));
            let (mut lo, mut hi) = (a.min(b), a.max(b));
            for axis in [Vector::X, Vector::Y, Vector::Z] {
                // x_i(θ) = c_i + R(cos θ u_i + sin θ t_i) is extreme at
                // θ = atan2(t_i, u_i) and that plus π.
                let th0 = axis.dot(t).atan2(axis.dot(u));
                for th in [th0, th0 + std::f64::consts::PI] {
                    let th = th.rem_euclid(std::f64::consts::TAU);
                    if th <= angle {
                        lo = lo.min(at(th));
                        hi = hi.max(at(th));
                    }
                }
            }
            (lo, hi)
        }
    }
}

#[inline]
pub(crate) fn nearest_on_segment(seg: &Segment, q: Vector) -> CentrelinePoint {
    match *seg {
        Segment::Straight { start, dir, length } => {
            let s = (q - start).dot(dir).clamp(0.0, length);
            CentrelinePoint {
                point: start + s * dir,
                tangent: dir,
                curvature: Vector::ZERO,
            }
        }
        Segment::Arc {
            center,
            radius,
            u,
            t,
            angle,
            end: (ca, sa),
        } => {
            // The direction of q from the centre in the arc's plane, (x, y) =
            // ρ(cos θ, sin θ); θ ∈ [0, angle] tested by signs, not by atan2.
            let r = q - center;
            let (x, y) = (r.dot(u), r.dot(t));
            let rho = (x * x + y * y).sqrt();
            let (c, s) = if rho > 0.0 {
                (x / rho, y / rho)
            } else {
                (1.0, 0.0)
            };
            // sin(θ − angle) = ca·sin θ − sa·cos θ ≤ 0 past the start, up to the end.
            let before_end = ca * s - sa * c <= 0.0;
            let inside = if angle <= std::f64::consts::PI {
                s >= 0.0 && before_end
            } else {
                s >= 0.0 || before_end
            };
            let (c, s) = if inside {
                (c, s)
            } else {
                // Outside the swept range: the nearer end point.
                let at = |c: f64, s: f64| center + radius * (c * u + s * t);
                if (q - at(1.0, 0.0)).length_squared() <= (q - at(ca, sa)).length_squared() {
                    (1.0, 0.0)
                } else {
                    (ca, sa)
                }
            };
            CentrelinePoint {
                point: center + radius * (c * u + s * t),
                tangent: -s * u + c * t,
                curvature: -(c * u + s * t) / radius,
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    fn close(a: Vector, b: Vector, tol: f64) -> bool {
        (a - b).length() <= tol
    }

    /// The paper's guide tube: down from the origin, bending toward +x at R = 1.5 m over 90°.
    pub(crate) fn paper_tube() -> TubeInterior {
        TubeInterior::new(
            0.058,
            Vector::ZERO,
            Vector::new(0.0, 0.0, -1.0),
            &[TubeSegment::Arc {
                radius: 1.5,
                angle: 90f64.to_radians(),
                bend: Vector::X,
            }],
        )
    }

    #[test]
    fn arc_follows_the_paper_parametrization() {
        let t = paper_tube();
        assert!((t.length() - 0.75 * std::f64::consts::PI).abs() < 1e-14);
        for deg in [0.0_f64, 7.6451, 45.0, 87.0, 90.0] {
            let a = deg.to_radians();
            let c = t.point_at(1.5 * a);
            let expect = Vector::new(1.5 * (1.0 - a.cos()), 0.0, -1.5 * a.sin());
            assert!(close(c.point, expect, 1e-12));
            // The inclination of the tangent from the downward vertical equals the arc angle.
            assert!((c.tangent.dot(Vector::new(0.0, 0.0, -1.0)).acos() - a).abs() < 1e-7);
        }
    }

    /// The nearest point of an arc, found by signs instead of atan2, is the
    /// nearest of 200 001 points sampled along it, for arcs shorter and
    /// longer than a half turn and for query points on either side of their
    /// ends (checked against the distance, which has one minimiser here).
    #[test]
    fn nearest_point_on_an_arc_matches_dense_sampling() {
        for deg in [30.0_f64, 90.0, 179.0, 200.0, 300.0] {
            let angle = deg.to_radians();
            let t = TubeInterior::new(
                0.05,
                Vector::ZERO,
                Vector::X,
                &[TubeSegment::Arc {
                    radius: 1.0,
                    angle,
                    bend: Vector::Y,
                }],
            );
            let seg = &t.segments[0];
            let samples: Vec<Vector> = (0..=200_000)
                .map(|i| t.point_at(t.length() * i as f64 / 200_000.0).point)
                .collect();
            for k in 0..72 {
                let phi = (5.0 * k as f64 + 2.5).to_radians();
                for (rho, z) in [(0.7, 0.0), (1.3, 0.2), (0.2, -0.1)] {
                    // Centre at (0, 1, 0); the arc starts at the origin, θ = 0 along −y.
                    let q = Vector::new(rho * phi.sin(), 1.0 - rho * phi.cos(), z);
                    let got = (q - nearest_on_segment(seg, q).point).length();
                    let best = samples
                        .iter()
                        .map(|p| (q - *p).length())
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        (got - best).abs() < 1e-9,
                        "{deg}° arc: {got} against {best}"
                    );
                }
            }
        }
    }

    #[test]
    fn points_beyond_the_open_ends_have_no_wall() {
        let t = paper_tube();
        assert!(t.nearest(Vector::new(0.0, 0.0, 0.05)).is_none());
        assert!(t.nearest(Vector::new(1.6, 0.0, -1.5)).is_none());
        assert!(t.nearest(Vector::new(1.45, 0.0, -1.5)).is_some());
    }

    /// The paper's arc spans x ∈ [0, 1.5], z ∈ [−1.5, 0] on its centreline
    /// (its quarter circle about (1.5, 0, 0)); the lumen adds 58 mm all round.
    #[test]
    fn the_lumen_box_holds_the_arc_and_the_radius() {
        let b = paper_tube().lumen_aabb();
        assert!(close(b.mins, Vector::new(-0.058, -0.058, -1.558), 1e-12));
        assert!(close(b.maxs, Vector::new(1.558, 0.058, 0.058), 1e-12));
    }
}
