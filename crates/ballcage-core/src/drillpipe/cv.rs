//! Exact ball-cage (Rzeppa) constant-velocity geometry (docs/model.md §1.1).
//!
//! Hinge frame: origin at the joint centre O, x̂ the head-body axis (downhole),
//! bending by β about ẑ, so the seat-body axis is e_s = R_z(β)x̂. The head
//! (inner-race) grooves are circles of radius ρ = √(PCR² + c²) about
//! G_h = −c·x̂, the seat (outer-race) grooves circles of radius ρ about
//! G_s = +c·e_s, each in its body's meridian plane at angle ψ_j from the
//! body's ŷ. A ball equidistant from G_h and G_s lies in the bisector plane
//! (normal R_z(β/2)x̂); its meridian angle about e_h equals the one about
//! e_s, which is the constant-velocity property.

use crate::math::Vec3;

/// Ball-cage joint dimensions [m, rad].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CvGeometry {
    /// Pitch radius of the ball set, PCR [m].
    pub pitch_radius: f64,
    /// Groove-centre offset per race, c [m].
    pub groove_offset: f64,
}

impl CvGeometry {
    /// Track radius ρ = √(PCR² + c²) [m].
    pub fn track_radius(&self) -> f64 {
        self.pitch_radius.hypot(self.groove_offset)
    }

    /// Head groove centre G_h in the hinge frame.
    pub fn head_groove_centre(&self) -> Vec3 {
        -self.groove_offset * Vec3::x()
    }

    /// Seat groove centre G_s for bend β, hinge frame.
    pub fn seat_groove_centre(&self, beta: f64) -> Vec3 {
        self.groove_offset * Vec3::new(beta.cos(), beta.sin(), 0.0)
    }

    /// Ball centre parametrized by its angle ψ in the bisector plane
    /// (docs/model.md §1.1): p = c·sin(β/2)·t + r_c(cos ψ·t + sin ψ·ẑ).
    pub fn ball_centre_at(&self, beta: f64, psi: f64) -> Vec3 {
        let c = self.groove_offset;
        let rho = self.track_radius();
        let h = 0.5 * beta;
        let rc = (rho * rho - c * c * h.cos().powi(2)).sqrt();
        let t = Vec3::new(-h.sin(), h.cos(), 0.0);
        c * h.sin() * t + rc * (psi.cos() * t + psi.sin() * Vec3::z())
    }

    /// Meridian angle of point p about the head axis x̂, from ŷ [rad].
    pub fn head_meridian_angle(p: &Vec3) -> f64 {
        p.z.atan2(p.y)
    }

    /// Meridian angle of point p about the seat axis e_s, from R_z(β)ŷ [rad].
    pub fn seat_meridian_angle(p: &Vec3, beta: f64) -> f64 {
        let ys = Vec3::new(-beta.sin(), beta.cos(), 0.0);
        p.z.atan2(p.dot(&ys))
    }

    /// Centre of the ball held by the grooves at meridian angle `groove_angle`
    /// (the same in both bodies' frames when the seat body is the head body
    /// turned by R_z(β)): the ψ whose head meridian angle is `groove_angle`.
    pub fn ball_centre_in_groove(&self, beta: f64, groove_angle: f64) -> Vec3 {
        // The head meridian angle is a monotone function of ψ; solve by Newton
        // from ψ = groove_angle, with a finite-difference slope.
        let g = self.head_groove_centre();
        let f = |psi: f64| {
            let d = Self::head_meridian_angle(&(self.ball_centre_at(beta, psi) - g)) - groove_angle;
            (d + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI) - std::f64::consts::PI
        };
        let mut psi = groove_angle;
        for _ in 0..50 {
            let r = f(psi);
            if r.abs() < 1e-15 {
                break;
            }
            let h = 1e-7;
            let slope = (f(psi + h) - f(psi - h)) / (2.0 * h);
            psi -= r / slope;
        }
        self.ball_centre_at(beta, psi)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PAPER: CvGeometry = CvGeometry {
        pitch_radius: 0.0315,
        groove_offset: 0.004,
    };

    #[test]
    fn balls_are_equidistant_from_both_groove_centres_and_in_the_bisector_plane() {
        // docs/model.md §7.4: to 1e-9 mm = 1e-12 m, for bends 0–20°.
        let rho = PAPER.track_radius();
        for deg in [0.0, 1.0, 3.82, 7.645, 12.0, 15.0, 20.0] {
            let beta = f64::to_radians(deg);
            let bisector = Vec3::new((beta / 2.0).cos(), (beta / 2.0).sin(), 0.0);
            for j in 0..6 {
                let groove = j as f64 * std::f64::consts::FRAC_PI_3 + 0.1;
                let p = PAPER.ball_centre_in_groove(beta, groove);
                assert!(((p - PAPER.head_groove_centre()).norm() - rho).abs() < 1e-12);
                assert!(((p - PAPER.seat_groove_centre(beta)).norm() - rho).abs() < 1e-12);
                assert!(
                    p.dot(&bisector).abs() < 1e-12,
                    "β = {deg}°: off the bisector plane by {}",
                    p.dot(&bisector)
                );
                let head = CvGeometry::head_meridian_angle(&(p - PAPER.head_groove_centre()));
                let seat =
                    CvGeometry::seat_meridian_angle(&(p - PAPER.seat_groove_centre(beta)), beta);
                let wrap = |x: f64| {
                    (x + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
                        - std::f64::consts::PI
                };
                assert!(
                    wrap(head - groove).abs() < 1e-12,
                    "β = {deg}°, j = {j}: head angle {head} vs {groove}"
                );
                assert!(
                    wrap(seat - groove).abs() < 1e-12,
                    "β = {deg}°: seat angle {seat} vs head {head}"
                );
            }
        }
    }

    #[test]
    fn output_angle_equals_input_angle_for_every_rotation() {
        // Turning the head by φ moves each ball to the groove angle ψ + φ; the
        // seat sees the same angle, so it turns by exactly φ (a Cardan joint would not).
        for deg in [0.0, 7.645, 20.0] {
            let beta = f64::to_radians(deg);
            for k in 0..360 {
                let phi = f64::to_radians(k as f64);
                let p = PAPER.ball_centre_in_groove(beta, phi);
                let out =
                    CvGeometry::seat_meridian_angle(&(p - PAPER.seat_groove_centre(beta)), beta);
                let d = (out - phi + std::f64::consts::PI).rem_euclid(2.0 * std::f64::consts::PI)
                    - std::f64::consts::PI;
                assert!(
                    d.abs() < 1e-12,
                    "β = {deg}°, φ = {k}°: output differs by {d}"
                );
            }
        }
    }

    #[test]
    fn straight_joint_puts_balls_on_the_pitch_circle() {
        for j in 0..6 {
            let g = j as f64 * std::f64::consts::FRAC_PI_3;
            let p = PAPER.ball_centre_in_groove(0.0, g);
            assert!((p - 0.0315 * Vec3::new(0.0, g.cos(), g.sin())).norm() < 1e-15);
        }
    }
}
