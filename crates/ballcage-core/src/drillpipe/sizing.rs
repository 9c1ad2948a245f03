//! Geometric limits of a drill pipe in a curved tube: the paper's eq. (9)
//! both ways (`ballcage size`) and the hinge's articulation limit.
//!
//! Eq. (8) is the right triangle of Figure 14, (L/2)² + (R − D/2 + 2r)² =
//! (R + D/2)²: the link's corners on the tube's outer wall, its inner face
//! on the inner wall. Eq. (9) is that triangle solved for L; expanded, its
//! 2RD − 4Rr + 2Dr − 4r² is 2(D − 2r)(R + r), the form used here.
//!
//! The three eq. (9) functions share one vocabulary with `ballcage.sizing`
//! and `ballcage size`: a rigid *link* of length L and outer diameter d
//! (r = d/2 in the formulas) in a tube of inner diameter D bent to
//! centreline radius R, all in metres.

use super::spec::{BallKeySpec, DrillPipeSpec};

/// The paper's eq. (9): the longest rigid link [m] of outer diameter
/// `link_outer_diameter` d that fits a tube of inner diameter
/// `tube_inner_diameter` D bent to centreline radius `curvature_radius` R
/// [m]: L = 2·√(2(D − 2r)(R + r)), r = d/2.
pub fn longest_link(
    curvature_radius: f64,
    tube_inner_diameter: f64,
    link_outer_diameter: f64,
) -> f64 {
    let r = link_outer_diameter / 2.0;
    2.0 * (2.0 * (tube_inner_diameter - 2.0 * r) * (curvature_radius + r)).sqrt()
}

/// Eq. (9) solved for R: the tightest centreline radius [m] a rigid link of
/// length `link_length` and outer diameter `link_outer_diameter` fits in a
/// tube of inner diameter `tube_inner_diameter` [m],
/// R = (L/2)² / (2(D − 2r)) − r; infinite when the link does not fit the
/// straight tube.
pub fn tightest_radius_for_link(
    link_length: f64,
    tube_inner_diameter: f64,
    link_outer_diameter: f64,
) -> f64 {
    let r = link_outer_diameter / 2.0;
    let gap = tube_inner_diameter - 2.0 * r;
    if gap <= 0.0 {
        return f64::INFINITY;
    }
    (link_length / 2.0).powi(2) / (2.0 * gap) - r
}

/// Eq. (9) solved for d: the largest outer diameter [m] of a rigid link of
/// length `link_length` that fits a tube of inner diameter
/// `tube_inner_diameter` bent to centreline radius `curvature_radius` [m];
/// `None` when even a link of no diameter does not fit, L > 2·√(2RD).
///
/// (L/2)² = 2(D − 2r)(R + r) is 2r² + (2R − D)r + L²/8 − RD = 0, whose
/// larger root is r = (D − 2R + √((2R + D)² − L²)) / 4 (the smaller one is
/// negative). For R > D/2 the same root is written without the cancellation
/// of D − 2R against the square root: r = (8RD − L²) / (4(√((2R + D)² − L²) + 2R − D)).
/// The diameter is 2r.
pub fn largest_link_diameter(
    link_length: f64,
    curvature_radius: f64,
    tube_inner_diameter: f64,
) -> Option<f64> {
    let (l, r, d) = (link_length, curvature_radius, tube_inner_diameter);
    let room = 8.0 * r * d - l * l;
    if room < 0.0 {
        return None;
    }
    let root = ((2.0 * r + d).powi(2) - l * l).sqrt();
    let radius = if 2.0 * r > d {
        room / (4.0 * (root + 2.0 * r - d))
    } else {
        (d - 2.0 * r + root) / 4.0
    };
    Some(2.0 * radius)
}

/// The tightest radius [m] at which links of pitch `pitch` bend by
/// `bend_limit` [rad] at each joint: on an arc of radius R the bend is
/// 2·asin(p / 2R), so R = p / (2 sin(β_max / 2)).
pub fn tightest_radius_for_bend(pitch: f64, bend_limit: f64) -> f64 {
    pitch / (2.0 * (bend_limit / 2.0).sin())
}

/// The bend [rad] at which a neck of radius `neck` through a ring of radius
/// ρ at axial distance h from the hinge centre touches the ring when the
/// ring tilts against the neck: the ring's nearest point is
/// ρ·cos t − h·sin t = R·cos(t + asin(h/R)) from the neck's axis,
/// R = √(ρ² + h²), so t = acos(r/R) − asin(h/R).
pub fn neck_limit(neck: f64, ring_radius: f64, ring_offset: f64) -> f64 {
    let r = ring_radius.hypot(ring_offset);
    (neck / r).acos() - (ring_offset / r).asin()
}

impl BallKeySpec {
    /// Radius of the seat's mouth [m]: the seat sphere cut at `mouth_offset`.
    pub fn mouth_radius(&self) -> f64 {
        (self.seat_radius.powi(2) - self.mouth_offset.powi(2))
            .max(0.0)
            .sqrt()
    }

    /// Radius of the cage's end openings [m]: its inner sphere cut at
    /// ±cage_length/2.
    pub fn rim_radius(&self) -> f64 {
        let h = self.cage_length / 2.0;
        (self.cage_inner_radius.powi(2) - h * h).max(0.0).sqrt()
    }

    /// The bend [rad] at which a neck of radius `neck` meets the seat's mouth:
    /// acos(r/R_s) − asin(d_m/R_s).
    pub fn mouth_limit(&self, neck: f64) -> f64 {
        neck_limit(neck, self.mouth_radius(), self.mouth_offset)
    }

    /// The bend [rad] at which a neck of radius `neck` would meet the cage's
    /// end rim, which turns by half the bend: 2·(acos(r/R_ci) − asin(L_c/2R_ci)).
    pub fn cage_rim_limit(&self, neck: f64) -> f64 {
        2.0 * neck_limit(neck, self.rim_radius(), self.cage_length / 2.0)
    }
}

impl DrillPipeSpec {
    /// The articulation limit [rad]: where the head's neck meets the seat's
    /// mouth, β_max = acos(r_neck/R_s) − asin(d_m/R_s); `None` without a
    /// neck contact (`pipe.neck_radius = 0`). Both hinge models share it.
    pub fn articulation_limit(&self) -> Option<f64> {
        let r = self.pipe.neck_radius;
        (r > 0.0).then(|| self.pipe.ball_keys.mouth_limit(r))
    }

    /// The tightest tube curvature radius [m] this pipe allows: whichever
    /// binds first of the articulation limit and eq. (9). For the paper's
    /// pipe the limit binds: 0.770 m against 0.124 m.
    pub fn tightest_radius(&self) -> f64 {
        let p = &self.pipe;
        let bend = self
            .articulation_limit()
            .map_or(0.0, |b| tightest_radius_for_bend(p.pitch, b));
        let fit = tightest_radius_for_link(p.pitch, self.borehole.inner_diameter, p.link_diameter);
        bend.max(fit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn eq9_round_trips_and_matches_the_paper_pipe() {
        // R = 1.5 m, D = 116 mm, d = 86 mm (r = 43 mm): L = 2·√(2·0.030·1.543) = 0.60854 m.
        let l = longest_link(1.5, 0.116, 0.086);
        assert_relative_eq!(
            l,
            2.0 * (2.0 * 0.030 * 1.543_f64).sqrt(),
            max_relative = 1e-12
        );
        assert_relative_eq!(l, 0.60854, max_relative = 1e-4);
        assert_relative_eq!(
            tightest_radius_for_link(l, 0.116, 0.086),
            1.5,
            max_relative = 1e-12
        );
    }

    #[test]
    fn eq9_solved_for_the_link_diameter() {
        // R = 1 m, D = 0.1 m, L = √0.41 m: (2R + D)² − L² = 4.41 − 0.41 = 4,
        // r = (0.1 − 2 + 2) / 4 = 0.025 m, d = 0.05 m; forward, 2·√(2·0.05·1.025) = √0.41.
        let l = 0.41_f64.sqrt();
        assert_relative_eq!(longest_link(1.0, 0.1, 0.05), l, max_relative = 1e-14);
        let d = largest_link_diameter(l, 1.0, 0.1).unwrap();
        assert_relative_eq!(d, 0.05, max_relative = 1e-12);
        // The paper's pipe: the 608.54 mm link of R = 1.5 m is Ø86 mm.
        let d = largest_link_diameter(longest_link(1.5, 0.116, 0.086), 1.5, 0.116).unwrap();
        assert_relative_eq!(d, 0.086, max_relative = 1e-12);
        // A link of no length may be as wide as the bore; one longer than
        // 2·√(2RD) = 2·√0.2 = 0.89443 m fits at no diameter; just below it, a thin one.
        assert_relative_eq!(
            largest_link_diameter(0.0, 1.0, 0.1).unwrap(),
            0.1,
            max_relative = 1e-14
        );
        assert_eq!(largest_link_diameter(0.9, 1.0, 0.1), None);
        let thin = largest_link_diameter(0.894, 1.0, 0.1).unwrap();
        assert!(thin > 0.0 && thin < 4e-4, "{thin}");
        // Below R = D/2 the direct form is used: R = 0.04, D = 0.1, d = 0.02 round-trips.
        let l = longest_link(0.04, 0.1, 0.02);
        assert_relative_eq!(
            largest_link_diameter(l, 0.04, 0.1).unwrap(),
            0.02,
            max_relative = 1e-12
        );
        // Round trips over a range of radii, to 1e-12 relative.
        for k in 1..=20 {
            let (big_r, d) = (0.2 * f64::from(k), 0.004 * f64::from(k));
            let l = longest_link(big_r, 0.116, d);
            let back = largest_link_diameter(l, big_r, 0.116).unwrap();
            assert_relative_eq!(back, d, max_relative = 1e-12);
            assert_relative_eq!(
                tightest_radius_for_link(l, 0.116, d),
                big_r,
                max_relative = 1e-12
            );
        }
    }

    #[test]
    fn the_articulation_limit_is_where_the_neck_meets_the_seat_mouth() {
        // R_s = 32.01 mm, d_m = 20 mm, r_neck = 19 mm:
        // acos(19/32.01) − asin(20/32.01) = 53.590° − 38.668° = 14.922°;
        // the cage rim (R_ci = 31, L_c = 40) would bind only at
        // 2·(acos(19/31) − asin(20/31)) = 2·(52.200° − 40.178°) = 24.05°.
        let spec = DrillPipeSpec::default();
        let limit = spec.articulation_limit().unwrap().to_degrees();
        let expected = ((19.0f64 / 32.01).acos() - (20.0f64 / 32.01).asin()).to_degrees();
        assert_relative_eq!(limit, expected, max_relative = 1e-12);
        assert!((limit - 14.922).abs() < 0.001, "{limit}");
        let rim = spec.pipe.ball_keys.cage_rim_limit(0.019).to_degrees();
        assert!((rim - 24.045).abs() < 0.001, "{rim}");
        let mut free = spec.clone();
        free.pipe.neck_radius = 0.0;
        assert_eq!(free.articulation_limit(), None);
    }

    #[test]
    fn the_paper_pipe_is_bounded_by_its_articulation_limit() {
        let spec = DrillPipeSpec::default();
        // 0.2 / (2 sin(β_max/2)); eq. (9): 0.01 / 0.06 − 0.043 = 0.12367 m.
        let beta = spec.articulation_limit().unwrap();
        assert_relative_eq!(
            spec.tightest_radius(),
            0.2 / (2.0 * (beta / 2.0).sin()),
            max_relative = 1e-12
        );
        assert_relative_eq!(
            tightest_radius_for_link(0.2, 0.116, 0.086),
            0.01 / 0.06 - 0.043,
            max_relative = 1e-12
        );
    }
}
