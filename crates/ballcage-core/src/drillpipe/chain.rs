//! Chain placement along the borehole centreline (docs/model.md §4, Option A).
//!
//! Hinge 0 sits at the start of the guide tube's arc; each next hinge lies on
//! the centreline (the arc, then its straight tangent extension) at one pitch
//! of chord distance from the previous one. Links lie on the chords.

use crate::geometry::TubePath;
use crate::math::Vec3;

/// Hinge centres along `path`, hinge 0 at the start, at chord distance `pitch`.
pub fn place_hinges(path: &TubePath, pitch: f64, count: usize) -> Vec<Vec3> {
    let mut hinges = Vec::with_capacity(count);
    let mut s_prev = 0.0;
    hinges.push(path.point_at(0.0).point);
    for _ in 1..count {
        let prev = *hinges.last().expect("hinge 0 exists");
        // |P(s) − P(s_prev)| grows with s on arcs shorter than a half turn and straights.
        let (mut lo, mut hi) = (s_prev, s_prev + 2.0 * pitch);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if (path.point_at(mid).point - prev).norm() < pitch {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        s_prev = 0.5 * (lo + hi);
        hinges.push(path.point_at(s_prev).point);
    }
    hinges
}

/// Signed bend from axis `a` to axis `b` about `z` [rad].
pub fn bend_angle(a: &Vec3, b: &Vec3, z: &Vec3) -> f64 {
    a.cross(b).dot(z).atan2(a.dot(b))
}

/// The paper's eq. (4): centres of mass of links 0…i from their angles,
/// mapped to the world frame (x = Y_p, y = X_p, z = l − Z_p; docs/model.md §1.2).
/// `angles[k] = (φ_k, θ_k)` [rad]: inclination from the downward vertical and
/// azimuth from the bend direction. Link 0 is the upper connector; every link
/// has length `pitch` [m].
pub fn eq4_centres(pitch: f64, angles: &[(f64, f64)]) -> Vec<Vec3> {
    let l = pitch;
    let mut out = Vec::with_capacity(angles.len());
    let (mut sx, mut sy, mut sz) = (0.0, 0.0, 0.0);
    for &(phi, theta) in angles {
        let xp = sx + 0.5 * l * phi.sin() * theta.sin();
        let yp = sy + 0.5 * l * phi.sin() * theta.cos();
        let zp = sz + 0.5 * l * phi.cos();
        out.push(Vec3::new(yp, xp, l - zp));
        sx += l * phi.sin() * theta.sin();
        sy += l * phi.sin() * theta.cos();
        sz += l * phi.cos();
    }
    out
}

/// The paper's eq. (5): centre-of-mass velocities from angles and rates
/// [rad/s], the exact time derivative of [`eq4_centres`] [m/s], world frame.
pub fn eq5_velocities(pitch: f64, angles: &[(f64, f64)], rates: &[(f64, f64)]) -> Vec<Vec3> {
    let l = pitch;
    let mut out = Vec::with_capacity(angles.len());
    let (mut sx, mut sy, mut sz) = (0.0, 0.0, 0.0);
    for (&(phi, theta), &(dphi, dtheta)) in angles.iter().zip(rates) {
        let vx = phi.cos() * theta.sin() * dphi + phi.sin() * theta.cos() * dtheta;
        let vy = phi.cos() * theta.cos() * dphi - phi.sin() * theta.sin() * dtheta;
        let vz = -phi.sin() * dphi;
        out.push(Vec3::new(
            sy + 0.5 * l * vy,
            sx + 0.5 * l * vx,
            -(sz + 0.5 * l * vz),
        ));
        sx += l * vx;
        sy += l * vy;
        sz += l * vz;
    }
    out
}

/// Eq. (4) angles (φ, θ) [rad] of a link whose axis points along `axis` (world).
pub fn eq4_angles(axis: &Vec3) -> (f64, f64) {
    ((-axis.z).clamp(-1.0, 1.0).acos(), axis.y.atan2(axis.x))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::TubeSegment;

    fn paper_centreline(r: f64) -> TubePath {
        TubePath::new(
            0.058,
            Vec3::zeros(),
            Vec3::new(0.0, 0.0, -1.0),
            &[
                TubeSegment::Arc {
                    radius: r,
                    angle: std::f64::consts::FRAC_PI_2,
                    bend: Vec3::x(),
                },
                TubeSegment::Straight { length: 5.0 },
            ],
        )
    }

    #[test]
    fn option_a_hinges_of_the_paper_chain() {
        // docs/model.md §4: Δα = 2·asin(100/1500) = 7.6451°, hinges 1–11 on the arc,
        // hinge 12 at (1545.55, 0, −1500) mm.
        let h = place_hinges(&paper_centreline(1.5), 0.2, 13);
        let da = 2.0 * (0.1f64 / 1.5).asin();
        assert!((da.to_degrees() - 7.6451).abs() < 1e-4);
        for (k, p) in h.iter().enumerate().take(12) {
            let a = k as f64 * da;
            let expect = Vec3::new(1.5 * (1.0 - a.cos()), 0.0, -1.5 * a.sin());
            assert!((p - expect).norm() < 1e-12, "hinge {k}: {p} vs {expect}");
        }
        assert!(
            (h[12] - Vec3::new(1.54555, 0.0, -1.5)).norm() < 1e-5,
            "hinge 12 at {}",
            h[12]
        );
        for w in h.windows(2) {
            assert!(((w[1] - w[0]).norm() - 0.2).abs() < 1e-12);
        }
    }

    #[test]
    fn eq4_reproduces_the_chord_midpoints() {
        let h = place_hinges(&paper_centreline(1.5), 0.2, 13);
        let mut angles = vec![(0.0, 0.0)]; // link 0: the vertical upper connector
        for k in 1..13 {
            angles.push(eq4_angles(&(h[k] - h[k - 1]).normalize()));
        }
        let c = eq4_centres(0.2, &angles);
        assert!((c[0] - Vec3::new(0.0, 0.0, 0.1)).norm() < 1e-15);
        for k in 1..13 {
            let mid = 0.5 * (h[k - 1] + h[k]);
            assert!((c[k] - mid).norm() < 1e-12, "link {k}: {} vs {mid}", c[k]);
        }
    }

    #[test]
    fn eq5_is_the_time_derivative_of_eq4() {
        // An arbitrary smooth 3-D motion of five links.
        let traj = |t: f64| -> Vec<(f64, f64)> {
            (0..5)
                .map(|k| {
                    (
                        0.3 + 0.1 * k as f64 + 0.2 * (3.0 * t + k as f64).sin(),
                        0.5 * k as f64 + 1.3 * t,
                    )
                })
                .collect()
        };
        let rates = |t: f64| -> Vec<(f64, f64)> {
            (0..5)
                .map(|k| (0.6 * (3.0 * t + k as f64).cos(), 1.3))
                .collect()
        };
        let (t, h) = (0.37, 1e-6);
        let v = eq5_velocities(0.2, &traj(t), &rates(t));
        let plus = eq4_centres(0.2, &traj(t + h));
        let minus = eq4_centres(0.2, &traj(t - h));
        for k in 0..5 {
            let fd = (plus[k] - minus[k]) / (2.0 * h);
            assert!(
                (fd - v[k]).norm() < 1e-8,
                "link {k}: fd {fd} vs eq5 {}",
                v[k]
            );
        }
    }

    #[test]
    fn adjacent_links_include_172_355_degrees() {
        // docs/model.md §7.5: 180° − 7.645° for a 200 mm pitch on R = 1.5 m.
        let h = place_hinges(&paper_centreline(1.5), 0.2, 13);
        let z = Vec3::new(0.0, -1.0, 0.0);
        for k in 1..11 {
            let a = (h[k] - h[k - 1]).normalize();
            let b = (h[k + 1] - h[k]).normalize();
            let included = 180.0 - bend_angle(&a, &b, &z).to_degrees();
            assert!((included - 172.355).abs() < 1e-3, "hinge {k}: {included}");
        }
    }
}
