//! Analytic tube centrelines: straight and circular-arc segments.
//!
//! A faceted (meshed) tube wall tilts the contact normal at every facet edge and
//! changes the penetration by the chord error, which under a stiff penalty law
//! is tens of percent of the force. Here the wall is exact: distance to the
//! centreline minus the inner radius.

use crate::math::Vec3;

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
        /// Turned angle [rad].
        angle: f64,
        /// Direction toward the arc's centre (tube frame); only its part
        /// across the current direction is used.
        bend: Vec3,
    },
}

/// One centreline piece, placed.
#[derive(Debug, Clone, PartialEq)]
enum Segment {
    /// `start + s·dir`, s ∈ [0, length].
    Straight { start: Vec3, dir: Vec3, length: f64 },
    /// `center + radius(cos θ·u + sin θ·t)`, θ ∈ [0, angle]; u points from the
    /// centre to the start, t is the start tangent; `end` = (cos, sin) of
    /// `angle`, so that the nearest-point query needs no trigonometry.
    Arc {
        center: Vec3,
        radius: f64,
        u: Vec3,
        t: Vec3,
        angle: f64,
        end: (f64, f64),
    },
}

/// The nearest centreline point to a query point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CentrelinePoint {
    /// Point on the centreline [m], tube frame.
    pub point: Vec3,
    /// Unit tangent there.
    pub tangent: Vec3,
}

/// A tube centreline with its inner radius, in the tube's body frame.
#[derive(Debug, Clone, PartialEq)]
pub struct TubePath {
    /// Inner (lumen) radius [m].
    pub inner_radius: f64,
    segments: Vec<Segment>,
    start: Vec3,
    start_dir: Vec3,
    end: Vec3,
    end_dir: Vec3,
    length: f64,
}

impl TubePath {
    /// Builds the path of `specs` from `start` along `direction` (both tube
    /// frame); lengths, radii and angles positive, `bend` not along the
    /// direction it turns.
    pub fn new(inner_radius: f64, start: Vec3, direction: Vec3, specs: &[TubeSegment]) -> Self {
        let mut p = start;
        let mut d = direction.normalize();
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
                    let b = (b - b.dot(&d) * d).normalize();
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
            start_dir: direction.normalize(),
            end: p,
            end_dir: d,
            length,
        }
    }

    /// Centreline length [m].
    pub fn length(&self) -> f64 {
        self.length
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
                        return CentrelinePoint {
                            point: center + radius * (th.cos() * u + th.sin() * t),
                            tangent: -th.sin() * u + th.cos() * t,
                        };
                    }
                    rest -= seg_len;
                }
            }
        }
        CentrelinePoint {
            point: self.end,
            tangent: self.end_dir,
        }
    }

    /// Nearest centreline point to `q`, or `None` when `q` lies beyond either
    /// open end of the tube (past the end planes), where there is no wall.
    pub fn nearest(&self, q: &Vec3) -> Option<CentrelinePoint> {
        if (q - self.start).dot(&self.start_dir) < 0.0 && self.closer_to_end(q, &self.start) {
            return None;
        }
        if (q - self.end).dot(&self.end_dir) > 0.0 && self.closer_to_end(q, &self.end) {
            return None;
        }
        let mut best: Option<(f64, CentrelinePoint)> = None;
        for seg in &self.segments {
            let c = nearest_on_segment(seg, q);
            let d2 = (q - c.point).norm_squared();
            if best.as_ref().is_none_or(|(b, _)| d2 < *b) {
                best = Some((d2, c));
            }
        }
        best.map(|(_, c)| c)
    }

    /// Whether the nearest centreline point of `q` is the end point `e`.
    fn closer_to_end(&self, q: &Vec3, e: &Vec3) -> bool {
        let de = (q - e).norm_squared();
        self.segments
            .iter()
            .all(|s| (q - nearest_on_segment(s, q).point).norm_squared() >= de - 1e-18)
    }
}

fn nearest_on_segment(seg: &Segment, q: &Vec3) -> CentrelinePoint {
    match *seg {
        Segment::Straight { start, dir, length } => {
            let s = (q - start).dot(&dir).clamp(0.0, length);
            CentrelinePoint {
                point: start + s * dir,
                tangent: dir,
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
            let (x, y) = (r.dot(&u), r.dot(&t));
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
                if (q - at(1.0, 0.0)).norm_squared() <= (q - at(ca, sa)).norm_squared() {
                    (1.0, 0.0)
                } else {
                    (ca, sa)
                }
            };
            CentrelinePoint {
                point: center + radius * (c * u + s * t),
                tangent: -s * u + c * t,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// The paper's guide tube: down from the origin, bending toward +x at R = 1.5 m over 90°.
    fn paper_tube() -> TubePath {
        TubePath::new(
            0.058,
            Vec3::zeros(),
            Vec3::new(0.0, 0.0, -1.0),
            &[TubeSegment::Arc {
                radius: 1.5,
                angle: 90f64.to_radians(),
                bend: Vec3::x(),
            }],
        )
    }

    #[test]
    fn arc_follows_the_paper_parametrization() {
        let t = paper_tube();
        assert_relative_eq!(
            t.length(),
            0.75 * std::f64::consts::PI,
            max_relative = 1e-14
        );
        for deg in [0.0_f64, 7.6451, 45.0, 87.0, 90.0] {
            let a = deg.to_radians();
            let c = t.point_at(1.5 * a);
            let expect = Vec3::new(1.5 * (1.0 - a.cos()), 0.0, -1.5 * a.sin());
            assert_relative_eq!(c.point, expect, epsilon = 1e-12);
            // The inclination of the tangent from the downward vertical equals the arc angle.
            assert_relative_eq!(
                c.tangent.dot(&Vec3::new(0.0, 0.0, -1.0)).acos(),
                a,
                epsilon = 1e-7
            );
        }
    }

    #[test]
    fn nearest_point_of_an_offset_point_is_radially_inward() {
        let t = paper_tube();
        let a = 30.0_f64.to_radians();
        let on = Vec3::new(1.5 * (1.0 - a.cos()), 0.0, -1.5 * a.sin());
        let radial = Vec3::new(-a.cos(), 0.0, -a.sin()); // away from the arc centre (1.5, 0, 0)
        let q = on + 0.02 * radial + Vec3::new(0.0, 0.01, 0.0);
        let c = t.nearest(&q).expect("inside the tube span");
        assert_relative_eq!(c.point, on, epsilon = 1e-12);
        assert_relative_eq!(
            (q - c.point).norm(),
            (0.02_f64.powi(2) + 0.01_f64.powi(2)).sqrt(),
            epsilon = 1e-12
        );
    }

    /// The nearest point of an arc, found by signs instead of atan2, is the
    /// nearest of 200 001 points sampled along it, for arcs shorter and
    /// longer than a half turn and for query points on either side of their
    /// ends (checked against the distance, which has one minimiser here).
    #[test]
    fn nearest_point_on_an_arc_matches_dense_sampling() {
        for deg in [30.0_f64, 90.0, 179.0, 200.0, 300.0] {
            let angle = deg.to_radians();
            let t = TubePath::new(
                0.05,
                Vec3::zeros(),
                Vec3::x(),
                &[TubeSegment::Arc {
                    radius: 1.0,
                    angle,
                    bend: Vec3::y(),
                }],
            );
            let seg = &t.segments[0];
            for k in 0..72 {
                let phi = (5.0 * k as f64 + 2.5).to_radians();
                for (rho, z) in [(0.7, 0.0), (1.3, 0.2), (0.2, -0.1)] {
                    // Centre at (0, 1, 0); the arc starts at the origin, θ = 0 along −y.
                    let q = Vec3::new(rho * phi.sin(), 1.0 - rho * phi.cos(), z);
                    let got = (q - nearest_on_segment(seg, &q).point).norm();
                    let best = (0..=200_000)
                        .map(|i| t.point_at(t.length() * i as f64 / 200_000.0).point)
                        .map(|p| (q - p).norm())
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        (got - best).abs() < 1e-9,
                        "{deg}° arc, query at {:.1}°: {got} against {best}",
                        phi.to_degrees()
                    );
                }
            }
        }
    }

    #[test]
    fn points_beyond_the_open_ends_have_no_wall() {
        let t = paper_tube();
        assert!(t.nearest(&Vec3::new(0.0, 0.0, 0.05)).is_none());
        assert!(t.nearest(&Vec3::new(1.6, 0.0, -1.5)).is_none());
        assert!(t.nearest(&Vec3::new(1.45, 0.0, -1.5)).is_some());
    }

    #[test]
    fn straight_then_arc_joins_smoothly() {
        let t = TubePath::new(
            0.05,
            Vec3::zeros(),
            Vec3::new(1.0, 0.0, 0.0),
            &[
                TubeSegment::Straight { length: 1.0 },
                TubeSegment::Arc {
                    radius: 2.0,
                    angle: 30f64.to_radians(),
                    bend: Vec3::y(),
                },
            ],
        );
        let a = t.point_at(1.0 - 1e-9);
        let b = t.point_at(1.0 + 1e-9);
        assert_relative_eq!(a.point, b.point, epsilon = 1e-8);
        assert_relative_eq!(a.tangent, b.tangent, epsilon = 1e-8);
        let end = t.point_at(t.length());
        let th = 30.0_f64.to_radians();
        assert_relative_eq!(
            end.point,
            Vec3::new(1.0 + 2.0 * th.sin(), 2.0 * (1.0 - th.cos()), 0.0),
            epsilon = 1e-12
        );
    }
}
