//! Chain placement along the borehole centreline (physics.md §4, Option A).
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::TubeSegmentSpec;

    fn paper_centreline(r: f64) -> TubePath {
        TubePath::new(
            0.058,
            Vec3::zeros(),
            Vec3::new(0.0, 0.0, -1.0),
            &[
                TubeSegmentSpec::Arc {
                    radius: r,
                    angle_deg: 90.0,
                    bend: [1.0, 0.0, 0.0],
                },
                TubeSegmentSpec::Straight { length: 5.0 },
            ],
        )
    }

    #[test]
    fn option_a_hinges_of_the_paper_chain() {
        // physics.md §4: Δα = 2·asin(100/1500) = 7.6451°, hinges 1–11 on the arc,
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
    fn adjacent_links_include_172_355_degrees() {
        // physics.md §7.5: 180° − 7.645° for a 200 mm pitch on R = 1.5 m.
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
