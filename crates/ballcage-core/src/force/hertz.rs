//! Hertz contact patches: semi-axes, peak pressure and approach from a normal force.
//!
//! These are pure functions of the contact geometry, the materials and the
//! normal force F \[N\]; they feed the peak-pressure output, not the force law
//! (the force comes from the engine's normal law). SI units: m, N, Pa.
//!
//! # Conventions
//!
//! * A curvature is 1/radius \[1/m\] of a body's surface at the contact point,
//!   in one principal plane: positive where the surface is convex (a ball),
//!   negative where it is concave (a groove or a bore), 0 where it is flat.
//! * [`Elliptical`] takes four curvatures `[ρ1₁, ρ1₂, ρ2₁, ρ2₂]`: body 1's in
//!   planes 1 and 2, then body 2's in the same two planes. The two bodies'
//!   principal planes must coincide, as for a ball in a groove (plane 1 = the
//!   groove cross-section, plane 2 = along the track).
//! * The curvature sum of a plane, Σ₁ = ρ1₁ + ρ2₁ or Σ₂ = ρ1₂ + ρ2₂, is the
//!   relative curvature of the two surfaces there. Both must be positive
//!   for a point contact; a sum ≤ 0 means the surfaces conform beyond
//!   contact (a groove tighter than the ball) or touch along a line.
//! * The semi-major axis a of the ellipse lies in the plane with the smaller
//!   curvature sum, the semi-minor axis b in the other.
//!
//! # Elliptical contact (Johnson, *Contact Mechanics*, §4.2)
//!
//! The gap is h = A x² + B y² with A = Σ_min/2, B = Σ_max/2. The pressure
//! p = p0 √(1 − x²/a² − y²/b²) with b/a = k′ and e² = 1 − k′² closes it when
//!
//! ```text
//! B/A = (E/k′² − K) / (K − E)       K = K(e), E = E(e): complete elliptic integrals
//! a³  = 3 F D / (π E* Σ_min)         D = (K − E)/e²   (D → π/4 for a circle)
//! p0  = 3 F / (2π a b)               δ = p0 b K / E*
//! ```
//!
//! so a, b ∝ F^(1/3), p0 ∝ F^(1/3) and δ ∝ F^(2/3). [`Elliptical::new`] solves
//! the first equation for k′ by bisection, once per geometry; K and D come
//! from the arithmetic-geometric mean. For Σ₁ = Σ₂ = 2/R the patch is a circle
//! and the formulas reduce to a = (3FR/(4E*))^(1/3), δ = a²/R.
//!
//! # Line contact
//!
//! [`Line`]: two cylinders with parallel axes over a length L, each given by
//! its curvature in the plane normal to the axes. With R′ = 1/(ρ1 + ρ2),
//! b = √(4 F R′/(π L E*)) and p0 = 2F/(π b L). The approach of a line contact
//! depends on the bodies' dimensions, not only on the contact, so it is
//! reported as 0.
//!
//! # Which model for which drill-pipe contact
//!
//! * Ball key in a Gothic-arch groove: [`Elliptical`] with the ball's
//!   `[1/r_b, 1/r_b]` and the groove's `[−1/ρ_g, ±1/ρ_t]` (arc radius ρ_g;
//!   track radius ρ_t, + on an inner race, which is convex along the track,
//!   − on an outer race).
//! * Link envelope lying along the bore (axes parallel): [`Line`] with
//!   `[1/r_link, −1/r_bore]` and the length in contact.
//! * Link end rim on the bore (tilted link): a rim rounded with edge radius
//!   r_e is a point contact, [`Elliptical`] with `[1/r_e, 1/r_link, 0,
//!   −1/r_bore]` (plane 1 = the link's axial plane, plane 2 = around the
//!   rim; the tilt misaligns the planes only to second order). A perfectly
//!   sharp edge has no Hertz solution (the pressure is singular there), so
//!   an edge radius must be given.
//!
//! Hertz assumes that the patch is small against the radii (a ≪ ρ): a
//! conforming groove at high load can leave that range, and the result is
//! then an estimate.

use std::f64::consts::PI;

/// Size, peak pressure and approach of a Hertz contact patch.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct HertzContact {
    /// Semi-major axis a \[m\] (half the length, for a line contact).
    pub semi_major: f64,
    /// Semi-minor axis b \[m\] (the half-width, for a line contact).
    pub semi_minor: f64,
    /// Peak (central) contact pressure p0 \[Pa\].
    pub peak_pressure: f64,
    /// Approach δ \[m\] of distant points of the two bodies; 0 for a line
    /// contact (see [`Line`]).
    pub approach: f64,
}

/// Effective (contact) modulus E* \[Pa\] = 1/((1 − ν1²)/E1 + (1 − ν2²)/E2)
/// from Young's moduli E \[Pa\] and Poisson's ratios ν \[-\].
///
/// Steel on steel (210 GPa, 0.3) gives 115 385 MPa. The inputs are not
/// checked: [`Elliptical::new`] and [`Line::new`] reject a non-finite or
/// non-positive result.
pub fn effective_modulus(e1: f64, nu1: f64, e2: f64, nu2: f64) -> f64 {
    1.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2)
}

/// An elliptical (point) Hertz contact, solved once per geometry; see the
/// module doc for the curvature convention and the equations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Elliptical {
    /// a = `major` · F^(1/3) \[m/N^(1/3)\].
    major: f64,
    /// b = `minor` · F^(1/3) \[m/N^(1/3)\].
    minor: f64,
    /// p0 = `pressure` · F^(1/3) \[Pa/N^(1/3)\].
    pressure: f64,
    /// δ = `approach` · F^(2/3) \[m/N^(2/3)\].
    approach: f64,
}

impl Elliptical {
    /// Solves the contact of two bodies with principal curvatures
    /// `curvatures` = `[ρ1₁, ρ1₂, ρ2₁, ρ2₂]` \[1/m\] (body 1 in planes 1 and 2,
    /// then body 2) and effective modulus `e_star` E* \[Pa\].
    ///
    /// Returns `None` for a non-finite input, E* ≤ 0, or a curvature sum
    /// ≤ 0 in either plane (conforming beyond contact, or a line contact).
    pub fn new(curvatures: [f64; 4], e_star: f64) -> Option<Self> {
        if !curvatures.iter().all(|c| c.is_finite()) || !finite_positive(e_star) {
            return None;
        }
        let [r11, r12, r21, r22] = curvatures;
        let (sum1, sum2) = (r11 + r21, r12 + r22);
        let (small, large) = (sum1.min(sum2), sum1.max(sum2));
        if !finite_positive(small) || !(large / small).is_finite() {
            return None;
        }
        let axis_ratio = solve_axis_ratio(large / small)?;
        let (k, d) = elliptic_k_and_d(axis_ratio);
        // a³ = 3 F D / (π E* Σ_min); b = k′ a; p0 = 3F/(2π a b); δ = p0 b K/E*.
        let major = (3.0 * d / (PI * e_star * small)).cbrt();
        let minor = axis_ratio * major;
        let pressure = 3.0 / (2.0 * PI * major * minor);
        let approach = pressure * minor * k / e_star;
        Some(Self {
            major,
            minor,
            pressure,
            approach,
        })
    }

    /// The contact patch under a normal force `force` F \[N\]; F ≤ 0 (or NaN)
    /// gives all zeros.
    pub fn at(&self, force: f64) -> HertzContact {
        if force.is_nan() || force <= 0.0 {
            return HertzContact::default();
        }
        let c = force.cbrt();
        HertzContact {
            semi_major: self.major * c,
            semi_minor: self.minor * c,
            peak_pressure: self.pressure * c,
            approach: self.approach * c * c,
        }
    }
}

/// A line Hertz contact between two cylinders with parallel axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Line {
    /// Contact length L \[m\].
    length: f64,
    /// b = `half_width` · F^(1/2) \[m/N^(1/2)\].
    half_width: f64,
    /// p0 = `pressure` · F^(1/2) \[Pa/N^(1/2)\].
    pressure: f64,
}

impl Line {
    /// Solves the contact of two parallel cylinders with curvatures
    /// `curvatures` = `[ρ1, ρ2]` \[1/m\] in the plane normal to their axes
    /// (1/radius; negative for a concave bore, 0 for a flat), touching over
    /// `length` L \[m\], with effective modulus `e_star` E* \[Pa\].
    ///
    /// Returns `None` for a non-finite input, L ≤ 0, E* ≤ 0, or ρ1 + ρ2 ≤ 0
    /// (a bore as tight as the cylinder or tighter).
    pub fn new(curvatures: [f64; 2], length: f64, e_star: f64) -> Option<Self> {
        let finite = curvatures.iter().all(|c| c.is_finite());
        let sum = curvatures[0] + curvatures[1];
        if !finite || !finite_positive(length) || !finite_positive(e_star) || !finite_positive(sum)
        {
            return None;
        }
        // b = √(4 F R′/(π L E*)) with R′ = 1/Σ; p0 = 2F/(π b L).
        let half_width = (4.0 / (PI * length * e_star * sum)).sqrt();
        let pressure = 2.0 / (PI * half_width * length);
        Some(Self {
            length,
            half_width,
            pressure,
        })
    }

    /// The contact strip under a normal force `force` F \[N\]: semi-major
    /// axis L/2, semi-minor axis the half-width b, and approach 0 (not
    /// modelled: it depends on the bodies' dimensions). F ≤ 0 (or NaN) gives
    /// all zeros.
    pub fn at(&self, force: f64) -> HertzContact {
        if force.is_nan() || force <= 0.0 {
            return HertzContact::default();
        }
        let s = force.sqrt();
        HertzContact {
            semi_major: 0.5 * self.length,
            semi_minor: self.half_width * s,
            peak_pressure: self.pressure * s,
            approach: 0.0,
        }
    }
}

/// Whether `x` is finite and > 0 (false for NaN).
fn finite_positive(x: f64) -> bool {
    x.is_finite() && x > 0.0
}

/// K(e) and D(e) = (K(e) − E(e))/e² for the ellipse with axis ratio
/// `axis_ratio` k′ = b/a ∈ (0, 1] (eccentricity e = √(1 − k′²)).
///
/// Arithmetic-geometric mean from a₀ = 1, b₀ = k′, c₀ = e (Abramowitz &
/// Stegun 17.6): K = π/(2 a_N) and K − E = K Σₙ 2ⁿ⁻¹ cₙ². Dividing by e²
/// term by term avoids the cancellation of K − E near the circle:
/// c₁²/e² = (1 − k′)/(4(1 + k′)), and cₙ₊₁ = cₙ²/(4 aₙ₊₁) is used instead of
/// the cancelling (aₙ − bₙ)/2.
fn elliptic_k_and_d(axis_ratio: f64) -> (f64, f64) {
    let kp = axis_ratio;
    let (mut a, mut b) = (0.5 * (1.0 + kp), kp.sqrt());
    let mut c = 0.5 * (1.0 - kp);
    let mut scaled = (1.0 - kp) / (4.0 * (1.0 + kp)); // cₙ²/e², n = 1
    let mut weight = 1.0; // 2ⁿ⁻¹
    let mut series = 0.5 + scaled; // Σₙ 2ⁿ⁻¹ cₙ²/e², n = 0, 1
    for _ in 0..64 {
        if weight * scaled <= f64::EPSILON * 1e-3 * series {
            break;
        }
        let next_a = 0.5 * (a + b);
        scaled *= c * c / (16.0 * next_a * next_a);
        c = c * c / (4.0 * next_a);
        b = (a * b).sqrt();
        a = next_a;
        weight *= 2.0;
        series += weight * scaled;
    }
    let k = PI / (2.0 * a);
    (k, k * series)
}

/// The curvature-sum ratio B/A = (E/k′² − K)/(K − E) produced by the axis
/// ratio k′ = b/a, written as (K − D)/(k′² D) to avoid cancellation. It falls
/// from +∞ at k′ → 0 to 1 at k′ = 1.
fn curvature_ratio(axis_ratio: f64) -> f64 {
    let (k, d) = elliptic_k_and_d(axis_ratio);
    (k - d) / (axis_ratio * axis_ratio * d)
}

/// The axis ratio k′ = b/a ∈ (0, 1] whose [`curvature_ratio`] is `target`
/// (≥ 1): bisection on ln k′ over \[−700, 0\], to full precision. `None` for
/// a target < 1 or NaN.
fn solve_axis_ratio(target: f64) -> Option<f64> {
    if target.is_nan() || target < 1.0 {
        return None;
    }
    if target == 1.0 {
        return Some(1.0);
    }
    // ln k′ = −700 gives k′² = 0 in f64, a ratio of +∞: every finite target
    // lies inside the bracket.
    let (mut lo, mut hi) = (-700.0_f64, 0.0_f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if curvature_ratio(mid.exp()) > target {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some((0.5 * (lo + hi)).exp())
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Steel on steel, E = 210 GPa, ν = 0.3 both: E* = 210e9/(2·0.91) =
    /// 115 384.6 MPa (docs/model.md §2.1: 115 385 MPa).
    fn steel() -> f64 {
        effective_modulus(210e9, 0.3, 210e9, 0.3)
    }

    /// Ø15 ball key: radius 7.5 mm.
    const BALL: f64 = 7.5e-3;

    /// Groove arc radius at conformity f = 1.04: 7.8 mm.
    const GROOVE: f64 = 1.04 * BALL;

    /// Track radius of the requested ball-in-groove case, 31.5 mm.
    const TRACK: f64 = 31.5e-3;

    /// The paper's seat–key peak load, 33.5 kN (docs/model.md §2.1).
    const KEY_LOAD: f64 = 33.5e3;

    /// A Ø15 ball in a 1.04 groove on a track of signed radius `track`
    /// (+ inner race, convex along the track; − outer race).
    fn ball_in_groove(track: f64) -> Elliptical {
        Elliptical::new(
            [1.0 / BALL, 1.0 / BALL, -1.0 / GROOVE, 1.0 / track],
            steel(),
        )
        .unwrap()
    }

    /// Hertz stiffness K_H = F/δ^1.5 in N/mm^1.5, from the approach at F.
    fn stiffness_n_per_mm15(contact: &Elliptical, force: f64) -> f64 {
        force / (contact.at(force).approach * 1e3).powf(1.5)
    }

    #[test]
    fn steel_on_steel_effective_modulus() {
        assert_relative_eq!(steel(), 210e9 / 1.82, max_relative = 1e-15);
        assert_relative_eq!(steel(), 115_385e6, max_relative = 1e-5);
    }

    #[test]
    fn elliptic_integrals_at_the_lemniscatic_modulus() {
        // k = k′ = 1/√2: K = Γ(1/4)²/(4√π) = 1.854074677301372, and
        // Legendre's relation 2EK − K² = π/2 gives E = 1.350643881047676,
        // so D = (K − E)/(1/2) = 1.006861592507393.
        let gamma_quarter = 3.625_609_908_221_908_f64;
        let k_ref = gamma_quarter * gamma_quarter / (4.0 * PI.sqrt());
        let e_ref = (0.5 * PI + k_ref * k_ref) / (2.0 * k_ref);
        let (k, d) = elliptic_k_and_d(0.5_f64.sqrt());
        assert_relative_eq!(k, k_ref, max_relative = 1e-14);
        assert_relative_eq!(d, 2.0 * (k_ref - e_ref), max_relative = 1e-14);
        // circle: K = π/2, D = π/4 exactly in the limit
        let (k, d) = elliptic_k_and_d(1.0);
        assert_relative_eq!(k, 0.5 * PI, max_relative = 1e-15);
        assert_relative_eq!(d, 0.25 * PI, max_relative = 1e-15);
    }

    #[test]
    fn ball_on_flat_matches_the_circular_closed_form() {
        // Ø15 ball on a steel flat at F = 1000 N:
        // a = (3FR/(4E*))^(1/3) = (22.5/4.615e11)^(1/3) = 0.36531 mm,
        // p0 = 3F/(2πa²) = 3577.9 MPa, δ = a²/R = 0.017793 mm.
        let (f, e) = (1000.0, steel());
        let c = Elliptical::new([1.0 / BALL, 1.0 / BALL, 0.0, 0.0], e)
            .unwrap()
            .at(f);
        let a = (3.0 * f * BALL / (4.0 * e)).cbrt();
        assert_relative_eq!(c.semi_major, a, max_relative = 1e-12);
        assert_relative_eq!(c.semi_minor, a, max_relative = 1e-12);
        assert_relative_eq!(
            c.peak_pressure,
            3.0 * f / (2.0 * PI * a * a),
            max_relative = 1e-12
        );
        assert_relative_eq!(c.approach, a * a / BALL, max_relative = 1e-12);
        assert_relative_eq!(c.semi_major, 0.365_307e-3, max_relative = 1e-5);
        assert_relative_eq!(c.peak_pressure, 3577.87e6, max_relative = 1e-5);
        assert_relative_eq!(c.approach, 17.7932e-6, max_relative = 1e-5);
        // docs/model.md §2.1: K_H = (4/3)E*√R = 1.3323e10 N/m^1.5 = 4.213e5 N/mm^1.5,
        // so F = K_H δ^1.5 at any load.
        let flat = Elliptical::new([1.0 / BALL, 1.0 / BALL, 0.0, 0.0], e).unwrap();
        for f in [10.0, 1000.0, KEY_LOAD] {
            assert_relative_eq!(
                stiffness_n_per_mm15(&flat, f),
                4.2133e5,
                max_relative = 1e-4
            );
        }
    }

    #[test]
    fn equal_crossed_cylinders_are_a_sphere_on_a_flat() {
        // Σ₁ = Σ₂ = 1/R in both cases, so the gaps h = (x² + y²)/(2R) agree.
        let (r, f, e) = (0.02, 500.0, steel());
        let crossed = Elliptical::new([1.0 / r, 0.0, 0.0, 1.0 / r], e)
            .unwrap()
            .at(f);
        let sphere = Elliptical::new([1.0 / r, 1.0 / r, 0.0, 0.0], e)
            .unwrap()
            .at(f);
        assert_eq!(crossed, sphere);
        let a = (3.0 * f * r / (4.0 * e)).cbrt();
        assert_relative_eq!(crossed.semi_major, a, max_relative = 1e-12);
        assert_relative_eq!(crossed.semi_minor, a, max_relative = 1e-12);
        assert_relative_eq!(crossed.approach, a * a / r, max_relative = 1e-12);
    }

    /// Hamrock–Brewe (1983) closed forms for the same contact, with
    /// 1/Rx = Σ along the track, 1/Ry = Σ across it (Ry > Rx), E′ = 2E*:
    /// k ≈ 1.0339 (Ry/Rx)^0.636, Ɛ ≈ 1.0003 + 0.5968 Rx/Ry,
    /// F_ell ≈ 1.5277 + 0.6023 ln(Ry/Rx), 1/R = 1/Rx + 1/Ry,
    /// a = (6k²ƐFR/(πE′))^(1/3), b = (6ƐFR/(πkE′))^(1/3), p0 = 3F/(2πab),
    /// δ = F_ell ((9/(2ƐR)) (F/(πkE′))²)^(1/3).
    fn hamrock_brewe(track: f64, force: f64) -> HertzContact {
        let rx = 1.0 / (1.0 / BALL + 1.0 / track);
        let ry = 1.0 / (1.0 / BALL - 1.0 / GROOVE);
        let (r, e2) = (1.0 / (1.0 / rx + 1.0 / ry), 2.0 * steel());
        let k = 1.0339 * (ry / rx).powf(0.636);
        let ell_e = 1.0003 + 0.5968 * rx / ry;
        let ell_f = 1.5277 + 0.6023 * (ry / rx).ln();
        let a = (6.0 * k * k * ell_e * force * r / (PI * e2)).cbrt();
        let b = (6.0 * ell_e * force * r / (PI * k * e2)).cbrt();
        let q = force / (PI * k * e2);
        HertzContact {
            semi_major: a,
            semi_minor: b,
            peak_pressure: 3.0 * force / (2.0 * PI * a * b),
            approach: ell_f * (9.0 / (2.0 * ell_e * r) * q * q).cbrt(),
        }
    }

    #[test]
    fn ball_in_groove_matches_hamrock_brewe_within_their_accuracy() {
        // Hand values of the H-B forms at 33.5 kN (Ry = 195 mm):
        // inner (track +31.5 mm, Rx = 6.058 mm, Ry/Rx = 32.19): k = 9.41,
        // a = 5.28 mm, b = 0.561 mm, p0 = 5406 MPa, δ = 0.0951 mm;
        // outer (track −31.5 mm, Rx = 9.844 mm, Ry/Rx = 19.81): k = 6.91,
        // a = 5.04 mm, b = 0.729 mm, p0 = 4356 MPa, δ = 0.0916 mm.
        let tol = 0.03;
        for track in [TRACK, -TRACK] {
            let exact = ball_in_groove(track).at(KEY_LOAD);
            let hb = hamrock_brewe(track, KEY_LOAD);
            let k_exact = exact.semi_major / exact.semi_minor;
            let k_hb = hb.semi_major / hb.semi_minor;
            assert_relative_eq!(k_exact, k_hb, max_relative = tol);
            assert_relative_eq!(exact.semi_major, hb.semi_major, max_relative = tol);
            assert_relative_eq!(exact.semi_minor, hb.semi_minor, max_relative = tol);
            assert_relative_eq!(exact.peak_pressure, hb.peak_pressure, max_relative = tol);
            assert_relative_eq!(exact.approach, hb.approach, max_relative = tol);
            // the tolerance would catch a flipped track curvature: k moves by ≥ 25 %
            let flipped = ball_in_groove(-track).at(KEY_LOAD);
            let k_flipped = flipped.semi_major / flipped.semi_minor;
            assert!((k_flipped / k_hb - 1.0).abs() > 5.0 * tol);
        }
        // ... and a flipped groove curvature (a ball on a ridge) even more:
        let ridge = Elliptical::new([1.0 / BALL, 1.0 / BALL, 1.0 / GROOVE, 1.0 / TRACK], steel())
            .unwrap()
            .at(KEY_LOAD);
        let k_ridge = ridge.semi_major / ridge.semi_minor;
        let k_hb = hamrock_brewe(TRACK, KEY_LOAD);
        assert!((k_ridge / (k_hb.semi_major / k_hb.semi_minor) - 1.0).abs() > 5.0 * tol);
    }

    #[test]
    fn ball_in_groove_reproduces_the_model_md_stiffnesses() {
        // docs/model.md §2.1 (Hertz): K_H ≈ 1.14e6 (inner) and 1.20e6 N/mm^1.5
        // (outer), from Hamrock–Brewe, track radius not stated. With the
        // assumed ±31.5 mm (the PCR) the exact solution differs by −1.4 %
        // and +0.3 %. (H-B gives 1.138e6 and 1.200e6 with 26.2 mm and
        // −39 mm, the inner contact and outer groove-bottom radii.)
        // A 2 % tolerance still catches swapped signs: inner and outer
        // differ by 7 %.
        let inner = stiffness_n_per_mm15(&ball_in_groove(TRACK), KEY_LOAD);
        let outer = stiffness_n_per_mm15(&ball_in_groove(-TRACK), KEY_LOAD);
        assert_relative_eq!(inner, 1.14e6, max_relative = 0.02);
        assert_relative_eq!(outer, 1.20e6, max_relative = 0.02);
        assert!(outer / inner - 1.0 > 2.0 * 0.02);
        // K_H does not depend on the load: δ ∝ F^(2/3).
        let light = stiffness_n_per_mm15(&ball_in_groove(TRACK), 100.0);
        assert_relative_eq!(light, inner, max_relative = 1e-12);
    }

    #[test]
    fn opening_the_groove_tends_to_ball_on_flat() {
        // Groove arc radius ρ_g → ∞ on a straight track: with ε = r/ρ_g the
        // curvature sums are (1 − ε)/r and 1/r. To first order (Johnson:
        // a/b ≈ (B/A)^(2/3), √(ab) ∝ (Σ₁Σ₂)^(−1/6)) a grows by ε/2, b shrinks
        // by ε/6, p0 by ε/3 and δ by ε/6, so the largest relative change is
        // ≈ ε/2: it must stay below ε and vanish with it.
        let (f, e) = (1000.0, steel());
        let flat = Elliptical::new([1.0 / BALL, 1.0 / BALL, 0.0, 0.0], e)
            .unwrap()
            .at(f);
        let mut previous = f64::INFINITY;
        for groove in [0.1, 1.0, 10.0, 1000.0] {
            let c = Elliptical::new([1.0 / BALL, 1.0 / BALL, -1.0 / groove, 0.0], e)
                .unwrap()
                .at(f);
            let error = (c.semi_major / flat.semi_major - 1.0)
                .abs()
                .max((c.semi_minor / flat.semi_minor - 1.0).abs())
                .max((c.peak_pressure / flat.peak_pressure - 1.0).abs())
                .max((c.approach / flat.approach - 1.0).abs());
            assert!(error < BALL / groove, "ρ_g = {groove}: {error}");
            assert!(error < previous);
            previous = error;
        }
    }

    #[test]
    fn timoshenko_goodier_coefficient_table() {
        // Timoshenko & Goodier, Theory of Elasticity, §140: with
        // cos θ = (B − A)/(B + A), a = m·(3F/(4E*(A + B)))^(1/3) and
        // b = n·(same). The three-decimal table (quoted from memory; the
        // classical tables carry errors up to ~0.002, Cooper 1968) against
        // a tolerance of 0.0025, far below the ≥ 0.05 between neighbours.
        let table = [
            (30.0, 2.731, 0.493),
            (35.0, 2.397, 0.530),
            (40.0, 2.136, 0.567),
            (45.0, 1.926, 0.604),
            (50.0, 1.754, 0.641),
            (55.0, 1.611, 0.678),
            (60.0, 1.486, 0.717),
            (65.0, 1.378, 0.759),
            (70.0, 1.284, 0.802),
            (75.0, 1.202, 0.846),
            (80.0, 1.128, 0.893),
            (85.0, 1.061, 0.944),
            (90.0, 1.000, 1.000),
        ];
        let (f, e, a_plus_b) = (100.0, steel(), 50.0);
        let scale = (3.0 * f / (4.0 * e * a_plus_b)).cbrt();
        for (theta, m, n) in table {
            let cos = f64::to_radians(theta).cos();
            let (a_coef, b_coef) = (a_plus_b * (1.0 - cos) / 2.0, a_plus_b * (1.0 + cos) / 2.0);
            let c = Elliptical::new([2.0 * a_coef, 2.0 * b_coef, 0.0, 0.0], e)
                .unwrap()
                .at(f);
            assert!((c.semi_major / scale - m).abs() < 0.0025, "θ = {theta}°: m");
            assert!((c.semi_minor / scale - n).abs() < 0.0025, "θ = {theta}°: n");
        }
    }

    #[test]
    fn parallel_cylinders_match_the_line_closed_form() {
        // Ø20 steel rollers, L = 20 mm, F = 10 kN: R′ = 5 mm,
        // b = √(4FR′/(πLE*)) = 0.16609 mm, p0 = 2F/(πbL) = √(FE*/(πLR′)) = 1916.5 MPa.
        let (f, l, e, r) = (1e4, 0.02, steel(), 0.01);
        let c = Line::new([1.0 / r, 1.0 / r], l, e).unwrap().at(f);
        let rp = 0.5 * r;
        let b = (4.0 * f * rp / (PI * l * e)).sqrt();
        assert_relative_eq!(c.semi_minor, b, max_relative = 1e-12);
        assert_relative_eq!(
            c.peak_pressure,
            (f * e / (PI * l * rp)).sqrt(),
            max_relative = 1e-12
        );
        assert_relative_eq!(c.semi_minor, 0.166_093e-3, max_relative = 1e-5);
        assert_relative_eq!(c.peak_pressure, 1916.46e6, max_relative = 1e-5);
        assert_eq!(c.semi_major, 0.5 * l);
        assert_eq!(c.approach, 0.0);
    }

    #[test]
    fn a_concave_bore_widens_a_line_contact() {
        // R = 10 mm on a flat: R′ = 10 mm, b = 0.23489 mm, p0 = 1355.1 MPa.
        // In a 50 mm bore: R′ = 1/(1/10 − 1/50) = 12.5 mm, so b grows by
        // √1.25 to 0.26262 mm and p0 falls by the same factor to 1212.1 MPa.
        let (f, l, e) = (1e4, 0.02, steel());
        let flat = Line::new([100.0, 0.0], l, e).unwrap().at(f);
        let bore = Line::new([100.0, -20.0], l, e).unwrap().at(f);
        assert_relative_eq!(flat.semi_minor, 0.234_891e-3, max_relative = 1e-5);
        assert_relative_eq!(bore.semi_minor, 0.262_616e-3, max_relative = 1e-5);
        assert_relative_eq!(
            bore.semi_minor / flat.semi_minor,
            1.25_f64.sqrt(),
            max_relative = 1e-12
        );
        assert_relative_eq!(
            flat.peak_pressure / bore.peak_pressure,
            1.25_f64.sqrt(),
            max_relative = 1e-12
        );
    }

    #[test]
    fn patch_scales_with_the_cube_root_of_the_force() {
        // a, b, p0 ∝ F^(1/3) and δ ∝ F^(2/3): ×8 force doubles a, b, p0 and
        // quadruples δ. Line: b, p0 ∝ F^(1/2). A 1e-14 tolerance is far below
        // the ≥ 26 % (2^(1/3) vs 2^(1/2)) a wrong exponent would give.
        let inner = ball_in_groove(TRACK);
        let (c1, c8) = (inner.at(1000.0), inner.at(8000.0));
        assert_relative_eq!(c8.semi_major, 2.0 * c1.semi_major, max_relative = 1e-14);
        assert_relative_eq!(c8.semi_minor, 2.0 * c1.semi_minor, max_relative = 1e-14);
        assert_relative_eq!(
            c8.peak_pressure,
            2.0 * c1.peak_pressure,
            max_relative = 1e-14
        );
        assert_relative_eq!(c8.approach, 4.0 * c1.approach, max_relative = 1e-14);
        let line = Line::new([100.0, -20.0], 0.02, steel()).unwrap();
        let (l1, l4) = (line.at(1000.0), line.at(4000.0));
        assert_relative_eq!(l4.semi_minor, 2.0 * l1.semi_minor, max_relative = 1e-14);
        assert_relative_eq!(
            l4.peak_pressure,
            2.0 * l1.peak_pressure,
            max_relative = 1e-14
        );
        // p0 = 3F/(2πab) holds at any load
        for f in [1.0, KEY_LOAD] {
            let c = inner.at(f);
            let p0 = 3.0 * f / (2.0 * PI * c.semi_major * c.semi_minor);
            assert_relative_eq!(c.peak_pressure, p0, max_relative = 1e-13);
        }
    }

    #[test]
    fn no_force_gives_an_empty_patch() {
        let inner = ball_in_groove(TRACK);
        let line = Line::new([100.0, 0.0], 0.02, steel()).unwrap();
        for f in [0.0, -5.0, f64::NAN] {
            assert_eq!(inner.at(f), HertzContact::default());
            assert_eq!(line.at(f), HertzContact::default());
        }
    }

    #[test]
    fn impossible_geometries_are_rejected() {
        let e = steel();
        let ball = 1.0 / BALL;
        // a groove tighter than the ball conforms beyond contact; f = 1 exactly is a line
        assert!(Elliptical::new([ball, ball, -1.0 / (0.99 * BALL), 1.0 / TRACK], e).is_none());
        assert!(Elliptical::new([ball, ball, -ball, 1.0 / TRACK], e).is_none());
        assert!(Elliptical::new([ball, ball, 0.0, -ball], e).is_none());
        // a cylinder on a flat, axes parallel: no point contact
        assert!(Elliptical::new([ball, 0.0, 0.0, 0.0], e).is_none());
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert!(Elliptical::new([ball, bad, 0.0, 0.0], e).is_none());
            assert!(Elliptical::new([ball, ball, 0.0, 0.0], bad).is_none());
            assert!(Line::new([bad, 0.0], 0.02, e).is_none());
            assert!(Line::new([ball, 0.0], bad, e).is_none());
            assert!(Line::new([ball, 0.0], 0.02, bad).is_none());
        }
        assert!(Elliptical::new([ball, ball, 0.0, 0.0], 0.0).is_none());
        assert!(Elliptical::new([ball, ball, 0.0, 0.0], -e).is_none());
        assert!(Line::new([100.0, -100.0], 0.02, e).is_none());
        assert!(Line::new([100.0, -150.0], 0.02, e).is_none());
        assert!(Line::new([100.0, 0.0], 0.0, e).is_none());
        assert!(Line::new([100.0, 0.0], 0.02, -e).is_none());
    }

    #[test]
    fn extreme_ellipticity_follows_the_slender_asymptote() {
        // Σ_max/Σ_min = 1e12, a nearly line-like patch. For k′ = b/a → 0,
        // K ≈ ln(4/k′), E ≈ 1, so B/A ≈ 1/(k′² (ln(4/k′) − 1)) with relative
        // error O(k′² ln k′); solving k′² (ln(4/k′) − 1) = 1e-12 by fixed
        // point gives k′ = 2.5341e-7.
        let c = Elliptical::new([1.0, 1e12, 0.0, 0.0], steel())
            .unwrap()
            .at(100.0);
        assert_relative_eq!(c.semi_minor / c.semi_major, 2.5341e-7, max_relative = 1e-4);
        for v in [c.semi_major, c.semi_minor, c.peak_pressure, c.approach] {
            assert!(v.is_finite() && v > 0.0);
        }
    }
}
