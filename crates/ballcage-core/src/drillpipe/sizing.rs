//! Geometric limits of a drill pipe in a curved tube: the paper's eq. (9)
//! and the hinge's articulation limit.

use super::spec::{DrillPipeSpec, HingeModel};

/// The paper's eq. (9): the longest rigid link [m] of radius `link_radius`
/// that fits a tube of inner diameter `tube_diameter` bent to centreline
/// radius `curvature_radius` [m]: L = 2·√(2(D − 2r)(R + r)).
pub fn longest_link(curvature_radius: f64, tube_diameter: f64, link_radius: f64) -> f64 {
    2.0 * (2.0 * (tube_diameter - 2.0 * link_radius) * (curvature_radius + link_radius)).sqrt()
}

/// Eq. (9) solved for R: the tightest centreline radius [m] a rigid link of
/// length `length` fits, R = (L/2)² / (2(D − 2r)) − r; infinite when the
/// link does not fit the straight tube.
pub fn tightest_radius_for_link(length: f64, tube_diameter: f64, link_radius: f64) -> f64 {
    let gap = tube_diameter - 2.0 * link_radius;
    if gap <= 0.0 {
        return f64::INFINITY;
    }
    (length / 2.0).powi(2) / (2.0 * gap) - link_radius
}

/// The tightest radius [m] at which links of pitch `pitch` bend by
/// `bend_limit` [rad] at each joint: on an arc of radius R the bend is
/// 2·asin(p / 2R), so R = p / (2 sin(β_max / 2)).
pub fn tightest_radius_for_bend(pitch: f64, bend_limit: f64) -> f64 {
    pitch / (2.0 * (bend_limit / 2.0).sin())
}

impl DrillPipeSpec {
    /// The hinge model's articulation limit [deg].
    pub fn bend_limit_deg(&self) -> f64 {
        match self.pipe.hinge {
            HingeModel::BallKeys => self.pipe.ball_keys.bend_limit_deg,
            HingeModel::IdealCv => self.pipe.ideal_cv.bend_limit_deg,
        }
    }

    /// The tightest tube curvature radius [m] this pipe allows: whichever
    /// binds first of the articulation limit and eq. (9). For the paper's
    /// pipe the limit binds: 0.766 m against 0.124 m.
    pub fn tightest_radius(&self) -> f64 {
        let p = &self.pipe;
        let bend = tightest_radius_for_bend(p.pitch, self.bend_limit_deg().to_radians());
        let fit =
            tightest_radius_for_link(p.pitch, self.borehole.inner_diameter, p.link_diameter / 2.0);
        bend.max(fit)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn eq9_round_trips_and_matches_the_paper_pipe() {
        // R = 1.5 m, D = 116 mm, r = 43 mm: L = 2·√(2·0.030·1.543) = 0.60854 m.
        let l = longest_link(1.5, 0.116, 0.043);
        assert_relative_eq!(
            l,
            2.0 * (2.0 * 0.030 * 1.543_f64).sqrt(),
            max_relative = 1e-12
        );
        assert_relative_eq!(l, 0.60854, max_relative = 1e-4);
        assert_relative_eq!(
            tightest_radius_for_link(l, 0.116, 0.043),
            1.5,
            max_relative = 1e-12
        );
    }

    #[test]
    fn the_paper_pipe_is_bounded_by_its_articulation_limit() {
        let spec = DrillPipeSpec::default();
        // 0.2 / (2 sin 7.5°) = 0.76613 m; eq. (9): 0.01 / 0.06 − 0.043 = 0.12367 m.
        assert_relative_eq!(
            spec.tightest_radius(),
            0.2 / (2.0 * 7.5_f64.to_radians().sin()),
            max_relative = 1e-12
        );
        assert_relative_eq!(
            tightest_radius_for_link(0.2, 0.116, 0.043),
            0.01 / 0.06 - 0.043,
            max_relative = 1e-12
        );
    }
}
