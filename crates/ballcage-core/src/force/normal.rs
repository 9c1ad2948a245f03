//! Normal contact force laws.
//!
//! # Conventions
//!
//! * SI units throughout: metres, seconds, newtons.
//! * `depth` δ \[m\] is the penetration depth; it is positive while the two
//!   shapes overlap and `<= 0` when they are separated.
//! * `rate` δ̇ \[m/s\] is the time derivative of the depth; it is positive
//!   while the bodies approach (penetration grows) and negative while they
//!   separate.
//! * A normal law returns the *magnitude* of the force pushing the bodies
//!   apart. It never pulls: the result is clamped at 0. When the clamp is
//!   active the force and both derivatives are exactly 0.
//! * Separated shapes (δ <= 0) give exactly 0 force and 0 derivatives.
//! * Every law returns its partial derivatives with respect to δ and δ̇
//!   ([`NormalForce`]), because an implicit integrator assembles its
//!   Jacobians from them.
//! * Dissipative laws that depend on the approach speed at first impact
//!   (v⁻) take it as a latched constant: it does not contribute to the
//!   derivatives.

/// Value and partial derivatives of a normal contact force.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct NormalForce {
    /// Force magnitude pushing the bodies apart, F \[N\] (always `>= 0`).
    pub force: f64,
    /// Partial derivative ∂F/∂δ \[N/m\].
    pub d_depth: f64,
    /// Partial derivative ∂F/∂δ̇ \[N·s/m\].
    pub d_rate: f64,
}

impl NormalForce {
    /// Builds the result of a law from the unclamped force and its
    /// derivatives, applying the no-pull clamp: if `force <= 0` (or is NaN)
    /// everything is 0.
    fn clamped(force: f64, d_depth: f64, d_rate: f64) -> Self {
        if force > 0.0 {
            Self {
                force,
                d_depth,
                d_rate,
            }
        } else {
            Self::default()
        }
    }
}

pub use crate::math::step;

/// Parameters of the MSC Adams IMPACT law (penetration form).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactParams {
    /// Stiffness K \[N/mⁿ\].
    pub stiffness: f64,
    /// Force exponent n \[-\].
    pub exponent: f64,
    /// Maximum damping coefficient c_max \[N·s/m\], reached at `depth_max`.
    pub damping: f64,
    /// Penetration d_max \[m\] at which full damping is reached.
    pub depth_max: f64,
}

/// Parameters of the restitution-based dissipative laws
/// (Lankarani–Nikravesh, Hunt–Crossley, Flores).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DissipativeParams {
    /// Stiffness K \[N/mⁿ\].
    pub stiffness: f64,
    /// Force exponent n \[-\] (1.5 for Hertzian contact).
    pub exponent: f64,
    /// Coefficient of restitution e \[-\], in (0, 1].
    pub restitution: f64,
    /// Lower clamp \[m/s\] of the latched approach speed v⁻ (e.g. 1e-3), so
    /// that a grazing contact does not produce unbounded damping.
    pub min_approach_speed: f64,
}

/// Parameters of the elastic Hertz law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HertzParams {
    /// Hertz stiffness K_H \[N/m^1.5\] (see [`hertz_stiffness`]).
    pub stiffness: f64,
}

/// Parameters of the linear spring–damper (Kelvin–Voigt) law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearParams {
    /// Spring stiffness k \[N/m\].
    pub stiffness: f64,
    /// Damping coefficient c \[N·s/m\].
    pub damping: f64,
}

/// Restitution-based dissipative contact laws of the form
/// F = K δⁿ \[1 + χ δ̇ / v⁻\].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DissipativeLaw {
    /// Lankarani–Nikravesh: χ = 3(1 − e²)/4.
    LankaraniNikravesh,
    /// Hunt–Crossley: χ = 3(1 − e)/2.
    HuntCrossley,
    /// Flores et al.: χ = 8(1 − e)/(5e).
    Flores,
}

/// Hysteresis damping factor χ \[-\] of a dissipative law for the
/// coefficient of restitution `restitution` (e in (0, 1]).
pub fn restitution_chi(law: DissipativeLaw, restitution: f64) -> f64 {
    let e = restitution;
    match law {
        DissipativeLaw::LankaraniNikravesh => 0.75 * (1.0 - e * e),
        DissipativeLaw::HuntCrossley => 1.5 * (1.0 - e),
        DissipativeLaw::Flores => 8.0 * (1.0 - e) / (5.0 * e),
    }
}

/// Effective coefficient of restitution e* \[-\] actually produced by a law
/// F = K δⁿ \[1 + χ δ̇ / v⁻\] with damping factor `chi` (χ).
///
/// Solves χe* + ln(1 − χe*) = ln(1 + χ) − χ for e* in (0, 1] by bisection on
/// x = χe* in (0, 1) (to machine precision, well below 1e-12). Returns 1 for
/// `chi <= 0` (no damping).
pub fn effective_restitution(chi: f64) -> f64 {
    if chi <= 0.0 {
        return 1.0;
    }
    let target = chi.ln_1p() - chi;
    // g(x) = x + ln(1 - x) - target is strictly decreasing on [0, 1):
    // g(0) = -target > 0 and g -> -inf as x -> 1. The root also satisfies
    // x < chi, hence e* = x / chi < 1.
    let g = |x: f64| x + (-x).ln_1p() - target;
    let mut lo = 0.0_f64;
    let mut hi = chi.min(1.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if g(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    (0.5 * (lo + hi) / chi).min(1.0)
}

/// Hertz stiffness K_H = (4/3) E* √R* \[N/m^1.5\] for two bodies of the same
/// material.
///
/// * `youngs_modulus` E \[Pa\], `poisson` ν \[-\]: 1/E* = 2(1 − ν²)/E.
/// * `radius1`, `radius2_or_inf` \[m\]: 1/R* = 1/R1 + 1/R2; pass
///   `f64::INFINITY` as R2 for a flat.
pub fn hertz_stiffness(
    youngs_modulus: f64,
    poisson: f64,
    radius1: f64,
    radius2_or_inf: f64,
) -> f64 {
    let e_star = youngs_modulus / (2.0 * (1.0 - poisson * poisson));
    let r_star = 1.0 / (1.0 / radius1 + 1.0 / radius2_or_inf);
    4.0 / 3.0 * e_star * r_star.sqrt()
}

/// K·δⁿ and its slope n·K·δⁿ⁻¹, δ > 0, from one power.
#[inline]
fn power_law(stiffness: f64, depth: f64, n: f64) -> (f64, f64) {
    let slope = stiffness * depth.powf(n - 1.0);
    (slope * depth, n * slope)
}

/// MSC Adams IMPACT law (penetration form):
/// F = max(0, K δⁿ + STEP(δ, 0, 0, d_max, c_max) δ̇).
pub fn impact_normal_force(depth: f64, rate: f64, p: &ImpactParams) -> NormalForce {
    if depth <= 0.0 {
        return NormalForce::default();
    }
    let n = p.exponent;
    let (elastic, d_elastic) = power_law(p.stiffness, depth, n);
    let (c, dc) = step(depth, 0.0, 0.0, p.depth_max, p.damping);
    NormalForce::clamped(elastic + c * rate, d_elastic + dc * rate, c)
}

/// Shared form of the restitution-based laws:
/// F = max(0, K δⁿ \[1 + χ δ̇ / v⁻\]), v⁻ = max(approach_speed, min).
fn dissipative_normal_force(
    depth: f64,
    rate: f64,
    approach_speed: f64,
    chi: f64,
    p: &DissipativeParams,
) -> NormalForce {
    if depth <= 0.0 {
        return NormalForce::default();
    }
    let n = p.exponent;
    let v_minus = approach_speed.max(p.min_approach_speed);
    let (elastic, d_elastic) = power_law(p.stiffness, depth, n);
    let damping_ratio = chi / v_minus;
    let factor = 1.0 + damping_ratio * rate;
    NormalForce::clamped(
        elastic * factor,
        d_elastic * factor,
        elastic * damping_ratio,
    )
}

/// Lankarani–Nikravesh law: F = max(0, K δⁿ \[1 + χ δ̇ / v⁻\]),
/// χ = 3(1 − e²)/4, v⁻ = max(`approach_speed`, `p.min_approach_speed`).
///
/// `approach_speed` \[m/s\] is the depth rate latched at first contact; it is
/// treated as a constant in the derivatives.
pub fn lankarani_nikravesh_normal_force(
    depth: f64,
    rate: f64,
    approach_speed: f64,
    p: &DissipativeParams,
) -> NormalForce {
    let chi = restitution_chi(DissipativeLaw::LankaraniNikravesh, p.restitution);
    dissipative_normal_force(depth, rate, approach_speed, chi, p)
}

/// Hunt–Crossley law: F = max(0, K δⁿ \[1 + χ δ̇ / v⁻\]), χ = 3(1 − e)/2,
/// v⁻ = max(`approach_speed`, `p.min_approach_speed`).
///
/// `approach_speed` \[m/s\] is the depth rate latched at first contact; it is
/// treated as a constant in the derivatives.
pub fn hunt_crossley_normal_force(
    depth: f64,
    rate: f64,
    approach_speed: f64,
    p: &DissipativeParams,
) -> NormalForce {
    let chi = restitution_chi(DissipativeLaw::HuntCrossley, p.restitution);
    dissipative_normal_force(depth, rate, approach_speed, chi, p)
}

/// Flores law: F = max(0, K δⁿ \[1 + χ δ̇ / v⁻\]), χ = 8(1 − e)/(5e),
/// v⁻ = max(`approach_speed`, `p.min_approach_speed`).
///
/// `approach_speed` \[m/s\] is the depth rate latched at first contact; it is
/// treated as a constant in the derivatives.
pub fn flores_normal_force(
    depth: f64,
    rate: f64,
    approach_speed: f64,
    p: &DissipativeParams,
) -> NormalForce {
    let chi = restitution_chi(DissipativeLaw::Flores, p.restitution);
    dissipative_normal_force(depth, rate, approach_speed, chi, p)
}

/// Elastic Hertz law: F = K_H δ^1.5 (no rate dependence, `d_rate` = 0).
pub fn hertz_normal_force(depth: f64, p: &HertzParams) -> NormalForce {
    if depth <= 0.0 {
        return NormalForce::default();
    }
    let root = depth.sqrt();
    NormalForce::clamped(p.stiffness * depth * root, 1.5 * p.stiffness * root, 0.0)
}

/// Linear spring–damper law: F = max(0, k δ + c δ̇).
pub fn linear_normal_force(depth: f64, rate: f64, p: &LinearParams) -> NormalForce {
    if depth <= 0.0 {
        return NormalForce::default();
    }
    NormalForce::clamped(
        p.stiffness * depth + p.damping * rate,
        p.stiffness,
        p.damping,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// Paper parameters K = 1e5 N/mm^2.2, n = 2.2, c_max = 10 N·s/mm,
    /// d_max = 0.1 mm, in SI (the scene converts field units; see
    /// tests/resting_contact.rs::paper_field_units_convert_once_to_si).
    fn paper_impact() -> ImpactParams {
        ImpactParams {
            stiffness: 1e5 * 1000f64.powf(2.2),
            exponent: 2.2,
            damping: 1e4,
            depth_max: 1e-4,
        }
    }

    fn dissipative(restitution: f64) -> DissipativeParams {
        DissipativeParams {
            stiffness: 4.2e11,
            exponent: 1.5,
            restitution,
            min_approach_speed: 1e-3,
        }
    }

    const DEPTHS: [f64; 9] = [-1e-3, -1e-6, 0.0, 1e-7, 1e-6, 3e-5, 7e-5, 2e-4, 1e-3];
    const RATES: [f64; 11] = [
        -1e3, -10.0, -1.0, -0.1, -1e-3, 0.0, 1e-3, 0.1, 1.0, 10.0, 1e3,
    ];

    /// A law under test as a closure of (depth, rate).
    type Law = Box<dyn Fn(f64, f64) -> NormalForce>;

    /// All laws under test, named.
    fn all_laws() -> Vec<(&'static str, Law)> {
        let impact = paper_impact();
        let d = dissipative(0.7);
        let hertz = HertzParams {
            stiffness: hertz_stiffness(210e9, 0.3, 7.5e-3, f64::INFINITY),
        };
        let linear = LinearParams {
            stiffness: 1e8,
            damping: 1e4,
        };
        vec![
            (
                "impact",
                Box::new(move |x, v| impact_normal_force(x, v, &impact)),
            ),
            (
                "lankarani_nikravesh",
                Box::new(move |x, v| lankarani_nikravesh_normal_force(x, v, 0.5, &d)),
            ),
            (
                "hunt_crossley",
                Box::new(move |x, v| hunt_crossley_normal_force(x, v, 0.5, &d)),
            ),
            (
                "flores",
                Box::new(move |x, v| flores_normal_force(x, v, 0.5, &d)),
            ),
            (
                "flores_tiny_approach",
                Box::new(move |x, v| flores_normal_force(x, v, 0.0, &d)),
            ),
            ("hertz", Box::new(move |x, _| hertz_normal_force(x, &hertz))),
            (
                "linear",
                Box::new(move |x, v| linear_normal_force(x, v, &linear)),
            ),
        ]
    }

    /// Asserts `a ≈ b` to relative `rel`, with an absolute floor `abs`.
    fn assert_close(name: &str, what: &str, a: f64, b: f64, rel: f64, abs: f64) {
        let tol = rel * a.abs().max(b.abs()) + abs;
        assert!(
            (a - b).abs() <= tol,
            "{name}: {what}: analytic {a} vs numeric {b} (tol {tol})"
        );
    }

    #[test]
    fn step_reference_values() {
        assert_relative_eq!(step(0.25, 0.0, 0.0, 1.0, 1.0).0, 0.15625, epsilon = 1e-15);
        assert_relative_eq!(step(0.5, 0.0, 0.0, 1.0, 1.0).0, 0.5, epsilon = 1e-15);
        assert_eq!(step(-1.0, 0.0, 2.0, 1.0, 5.0), (2.0, 0.0));
        assert_eq!(step(2.0, 0.0, 2.0, 1.0, 5.0), (5.0, 0.0));
        // Degenerate interval: a jump, no division by zero.
        assert_eq!(step(1.0, 1.0, 2.0, 1.0, 5.0), (2.0, 0.0));
        assert_eq!(step(1.5, 1.0, 2.0, 1.0, 5.0), (5.0, 0.0));
    }

    #[test]
    fn step_derivative_matches_finite_differences() {
        let (x0, h0, x1, h1) = (0.3, 2.0, 1.7, -1.5);
        for i in 1..40 {
            let x = x0 + (x1 - x0) * f64::from(i) / 40.0;
            let h = 1e-6;
            let fd = (step(x + h, x0, h0, x1, h1).0 - step(x - h, x0, h0, x1, h1).0) / (2.0 * h);
            assert_close("step", "slope", step(x, x0, h0, x1, h1).1, fd, 1e-6, 1e-9);
        }
    }

    #[test]
    fn step_is_c1_at_ends() {
        let (x0, h0, x1, h1) = (0.3, 2.0, 1.7, -1.5);
        let eps = 1e-9;
        let (a, da) = step(x0 + eps, x0, h0, x1, h1);
        let (b, db) = step(x1 - eps, x0, h0, x1, h1);
        assert_relative_eq!(a, h0, epsilon = 1e-12);
        assert_relative_eq!(b, h1, epsilon = 1e-12);
        assert!(da.abs() < 1e-7 && db.abs() < 1e-7, "{da} {db}");
        assert_eq!(step(x0, x0, h0, x1, h1), (h0, 0.0));
        assert_eq!(step(x1, x0, h0, x1, h1), (h1, 0.0));
    }

    #[test]
    fn impact_field_units_conversion() {
        let p = paper_impact();
        assert_relative_eq!(p.stiffness, 3.981e11, max_relative = 1e-3);
        assert_relative_eq!(p.exponent, 2.2);
        assert_relative_eq!(p.damping, 1e4, max_relative = 1e-12);
        assert_relative_eq!(p.depth_max, 1e-4, max_relative = 1e-12);
        let f = impact_normal_force(1e-4, 0.0, &p);
        assert!((f.force - 630.96).abs() < 0.01, "{}", f.force);
        assert!((f.force - 630.957).abs() < 1e-3, "{}", f.force);
    }

    #[test]
    fn impact_reference_values() {
        let p = paper_impact();
        // 0.05 mm at +100 mm/s: 137.32 N elastic + 5 N·s/mm · 100 mm/s.
        let f = impact_normal_force(0.05e-3, 0.1, &p);
        assert!((f.force - 637.32).abs() < 0.01, "{}", f.force);
        assert_relative_eq!(f.d_rate, 5e3, max_relative = 1e-12);
        let elastic = impact_normal_force(0.05e-3, 0.0, &p);
        assert!((elastic.force - 137.32).abs() < 0.01, "{}", elastic.force);
        // Separating fast: the damping term would pull; clamped to 0.
        assert_eq!(
            impact_normal_force(0.05e-3, -0.1, &p),
            NormalForce::default()
        );
    }

    #[test]
    fn dissipative_reference_values() {
        let p = dissipative(0.5);
        let (depth, rate, v) = (1e-5_f64, 0.2, 0.4);
        let elastic = p.stiffness * depth.powf(1.5);
        let cases = [
            (DissipativeLaw::LankaraniNikravesh, 0.5625),
            (DissipativeLaw::HuntCrossley, 0.75),
            (DissipativeLaw::Flores, 1.6),
        ];
        for (law, chi) in cases {
            assert_relative_eq!(restitution_chi(law, 0.5), chi, max_relative = 1e-14);
            let f = match law {
                DissipativeLaw::LankaraniNikravesh => {
                    lankarani_nikravesh_normal_force(depth, rate, v, &p)
                }
                DissipativeLaw::HuntCrossley => hunt_crossley_normal_force(depth, rate, v, &p),
                DissipativeLaw::Flores => flores_normal_force(depth, rate, v, &p),
            };
            assert_relative_eq!(
                f.force,
                elastic * (1.0 + chi * rate / v),
                max_relative = 1e-12
            );
        }
        // Perfectly elastic: no damping at all.
        for law in [
            DissipativeLaw::LankaraniNikravesh,
            DissipativeLaw::HuntCrossley,
            DissipativeLaw::Flores,
        ] {
            assert_eq!(restitution_chi(law, 1.0), 0.0);
        }
        // The approach speed is clamped from below.
        let low = flores_normal_force(depth, 1e-4, 1e-9, &p);
        let clamped = flores_normal_force(depth, 1e-4, p.min_approach_speed, &p);
        assert_eq!(low, clamped);
        assert_relative_eq!(
            low.force,
            elastic * (1.0 + 1.6 * 1e-4 / 1e-3),
            max_relative = 1e-12
        );
    }

    #[test]
    fn effective_restitution_table() {
        let table = [
            (0.3, 0.684, 0.581, 0.256),
            (0.5, 0.725, 0.663, 0.470),
            (0.7, 0.796, 0.768, 0.683),
            (0.9, 0.913, 0.909, 0.894),
        ];
        for (e, ln, hc, fl) in table {
            let got = [
                DissipativeLaw::LankaraniNikravesh,
                DissipativeLaw::HuntCrossley,
                DissipativeLaw::Flores,
            ]
            .map(|law| effective_restitution(restitution_chi(law, e)));
            assert!((got[0] - ln).abs() < 1e-3, "LN e={e}: {}", got[0]);
            assert!((got[1] - hc).abs() < 1e-3, "HC e={e}: {}", got[1]);
            assert!((got[2] - fl).abs() < 1e-3, "Flores e={e}: {}", got[2]);
        }
    }

    #[test]
    fn effective_restitution_solves_equation() {
        for chi in [1e-4, 0.01, 0.3, 0.9, 1.0, 2.5, 10.0, 100.0] {
            let e = effective_restitution(chi);
            assert!(e > 0.0 && e < 1.0, "chi={chi}: e*={e}");
            // The root is bracketed to 1e-12 in e*.
            let g = |e: f64| chi * e + (-chi * e).ln_1p() - (chi.ln_1p() - chi);
            assert!(g(e - 1e-12) >= 0.0 || (e - 1e-12) * chi <= 0.0, "chi={chi}");
            assert!(g(e + 1e-12) <= 0.0 || (e + 1e-12) * chi >= 1.0, "chi={chi}");
        }
        assert_eq!(effective_restitution(0.0), 1.0);
        assert_eq!(effective_restitution(-1.0), 1.0);
        assert!(effective_restitution(1e-4) > 0.9999);
    }

    #[test]
    fn hertz_stiffness_steel_ball_on_flat() {
        let (e, nu) = (210e9, 0.3);
        let e_star = e / (2.0 * (1.0 - nu * nu));
        assert_relative_eq!(e_star / 1e6, 115_385.0, max_relative = 1e-5);
        let k = hertz_stiffness(e, nu, 7.5e-3, f64::INFINITY);
        assert_relative_eq!(k, 4.213e5 * 1000f64.powf(1.5), max_relative = 1e-3);
        // Two equal balls: R* halves.
        let k2 = hertz_stiffness(e, nu, 7.5e-3, 7.5e-3);
        assert_relative_eq!(k2, k * 0.5f64.sqrt(), max_relative = 1e-12);
        let f = hertz_normal_force(1e-5, &HertzParams { stiffness: k });
        assert_relative_eq!(f.force, k * 1e-5 * 1e-5f64.sqrt(), max_relative = 1e-12);
        assert_eq!(f.d_rate, 0.0);
    }

    #[test]
    fn linear_reference_values() {
        let p = LinearParams {
            stiffness: 1e8,
            damping: 1e4,
        };
        let f = linear_normal_force(1e-5, 0.05, &p);
        assert_relative_eq!(f.force, 1500.0, max_relative = 1e-12);
        assert_eq!((f.d_depth, f.d_rate), (1e8, 1e4));
        assert_eq!(linear_normal_force(1e-5, -0.2, &p), NormalForce::default());
    }

    #[test]
    fn separated_gives_exactly_zero() {
        for (name, law) in all_laws() {
            for depth in [0.0, -0.0, -1e-12, -1e-3, -1.0] {
                for rate in RATES {
                    assert_eq!(
                        law(depth, rate),
                        NormalForce::default(),
                        "{name} at ({depth}, {rate})"
                    );
                }
            }
        }
    }

    #[test]
    fn never_pulls() {
        for (name, law) in all_laws() {
            for depth in DEPTHS {
                for rate in RATES {
                    let f = law(depth, rate);
                    assert!(f.force >= 0.0, "{name} pulls at ({depth}, {rate})");
                    assert!(f.force.is_finite(), "{name} at ({depth}, {rate})");
                    if f.force == 0.0 {
                        assert_eq!(f, NormalForce::default(), "{name} at ({depth}, {rate})");
                    }
                }
            }
        }
    }

    #[test]
    fn derivatives_match_finite_differences() {
        // Avoids depth_max = 1e-4 (kink of the IMPACT damping STEP).
        let depths = [1e-7, 3e-6, 2.5e-5, 6e-5, 9.9e-5, 1.3e-4, 8e-4];
        let rates = [-3.0, -0.4, -0.02, 0.0, 0.02, 0.4, 3.0];
        let mut checked = 0;
        for (name, law) in all_laws() {
            for depth in depths {
                for rate in rates {
                    let f = law(depth, rate);
                    let hx = 1e-6 * depth;
                    let hv = 1e-6 * rate.abs().max(1e-3);
                    let samples = [
                        law(depth + hx, rate),
                        law(depth - hx, rate),
                        law(depth, rate + hv),
                        law(depth, rate - hv),
                    ];
                    // Skip points next to the no-pull kink.
                    if f.force == 0.0 || samples.iter().any(|s| s.force == 0.0) {
                        continue;
                    }
                    let fd_x = (samples[0].force - samples[1].force) / (2.0 * hx);
                    let fd_v = (samples[2].force - samples[3].force) / (2.0 * hv);
                    // Absolute floor: a tiny fraction of the natural scales.
                    let floor_x = 1e-9 * f.force / depth;
                    let floor_v = 1e-9 * f.force / rate.abs().max(1e-3);
                    assert_close(name, "d_depth", f.d_depth, fd_x, 1e-6, floor_x);
                    assert_close(name, "d_rate", f.d_rate, fd_v, 1e-6, floor_v);
                    checked += 1;
                }
            }
        }
        assert!(checked > 200, "only {checked} points checked");
    }
}
