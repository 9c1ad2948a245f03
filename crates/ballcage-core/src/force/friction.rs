//! Tangential (friction) contact force laws.
//!
//! # Conventions
//!
//! * SI units, as in the [normal-force module](super::normal).
//! * The slip velocity v_t \[m/s\] is the tangential part of the velocity of
//!   body b relative to body a at the contact point; the slip speed is
//!   s = |v_t| \[m/s\] `>= 0` and û = v_t / s is the slip direction.
//! * The friction force on body b is −μ̂(s)·F_n·û, where F_n \[N\] `>= 0` is
//!   the normal force magnitude (body a receives the opposite force).
//! * A friction law returns the coefficient μ̂(s) \[-\] and its slope
//!   dμ̂/ds \[s/m\] ([`FrictionCoefficient`]), from which [`friction_force`]
//!   builds the force and its Jacobian for an implicit integrator.
//! * Laws are regularized: μ̂(0) = 0 and μ̂ rises with a finite slope, so
//!   the force is continuous in v_t.

use super::normal::step;

/// Friction coefficient and its slope with respect to slip speed.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FrictionCoefficient {
    /// Friction coefficient μ̂(s) \[-\].
    pub mu: f64,
    /// Slope dμ̂/ds \[s/m\].
    pub d_slip: f64,
}

/// Parameters of the MSC Adams friction law (static/dynamic with STEP
/// transitions). Requires 0 < `v_static` <= `v_dynamic`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AdamsFrictionParams {
    /// Static friction coefficient μs \[-\], reached at `v_static`.
    pub mu_static: f64,
    /// Dynamic friction coefficient μd \[-\], reached at `v_dynamic`.
    pub mu_dynamic: f64,
    /// Stiction transition speed v_s \[m/s\].
    pub v_static: f64,
    /// Dynamic transition speed v_d \[m/s\].
    pub v_dynamic: f64,
}

/// Parameters of the hyperbolic-tangent regularized Coulomb law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TanhFrictionParams {
    /// Coulomb friction coefficient μ \[-\].
    pub mu: f64,
    /// Regularization speed v_ref \[m/s\] (μ̂ reaches 76 % of μ at v_ref).
    pub v_ref: f64,
}

/// MSC Adams friction law.
///
/// With u = s/v_s:
/// * μ̂(s) = μs·u(3 − u²)/2 for s < v_s (C¹ stiction ramp, slope 1.5 μs/v_s
///   at 0 and 0 at v_s);
/// * μ̂(s) = STEP(s, v_s, μs, v_d, μd) for v_s <= s <= v_d;
/// * μ̂(s) = μd for s > v_d.
///
/// `slip` is a speed (>= 0); a negative value is treated as 0.
pub fn adams_friction_coefficient(slip: f64, p: &AdamsFrictionParams) -> FrictionCoefficient {
    let s = slip.max(0.0);
    if s < p.v_static {
        let u = s / p.v_static;
        FrictionCoefficient {
            mu: 0.5 * p.mu_static * u * (3.0 - u * u),
            d_slip: 1.5 * p.mu_static * (1.0 - u * u) / p.v_static,
        }
    } else {
        let (mu, d_slip) = step(s, p.v_static, p.mu_static, p.v_dynamic, p.mu_dynamic);
        FrictionCoefficient { mu, d_slip }
    }
}

/// Hyperbolic-tangent regularized Coulomb law: μ̂(s) = μ·tanh(s/v_ref).
///
/// `slip` is a speed (>= 0); a negative value is treated as 0.
pub fn tanh_friction_coefficient(slip: f64, p: &TanhFrictionParams) -> FrictionCoefficient {
    let t = (slip.max(0.0) / p.v_ref).tanh();
    FrictionCoefficient {
        mu: p.mu * t,
        d_slip: p.mu * (1.0 - t * t) / p.v_ref,
    }
}

/// Slip speeds \[m/s\] below which [`friction_force`] uses the s → 0 limit.
const TINY_SLIP: f64 = 1e-12;

/// Friction force vector on body b given relative slip velocity (b relative
/// to a, tangential part) and normal force magnitude; zero when slip speed is
/// 0 or F_n is 0. Also returns the 3x3 Jacobian dF_t/dv_t as a row-major
/// `[[f64; 3]; 3]` (`jac[i][j]` = ∂F_i/∂v_j).
///
/// * `slip_velocity` v_t \[m/s\]: tangential velocity of b relative to a.
/// * `normal_force` F_n \[N\]: a value `<= 0` (or NaN) gives zero force and a
///   zero Jacobian.
/// * `coefficient`: the friction law, μ̂ and dμ̂/ds as functions of s.
///
/// The force is F_t = −μ̂(s)·F_n·û \[N\] and the Jacobian \[N·s/m\] is
/// dF_t/dv_t = −F_n\[μ̂'(s)·ûûᵀ + (μ̂(s)/s)(I − ûûᵀ)\]. For s below 1e-12 m/s
/// the law is linearized at 0: F_t = −F_n·μ̂'(0)·v_t (exactly 0 at s = 0)
/// and dF_t/dv_t = −F_n·μ̂'(0)·I, so no NaN appears.
pub fn friction_force(
    slip_velocity: [f64; 3],
    normal_force: f64,
    coefficient: impl Fn(f64) -> FrictionCoefficient,
) -> ([f64; 3], [[f64; 3]; 3]) {
    let zero = ([0.0; 3], [[0.0; 3]; 3]);
    if normal_force.is_nan() || normal_force <= 0.0 {
        return zero;
    }
    let [x, y, z] = slip_velocity;
    let s = (x * x + y * y + z * z).sqrt();
    if s < TINY_SLIP {
        let gain = -normal_force * coefficient(0.0).d_slip;
        let force = slip_velocity.map(|v| gain * v);
        let mut jac = [[0.0; 3]; 3];
        for (i, row) in jac.iter_mut().enumerate() {
            row[i] = gain;
        }
        return (force, jac);
    }
    let c = coefficient(s);
    let u = slip_velocity.map(|v| v / s);
    let force = u.map(|ui| -c.mu * normal_force * ui);
    let mu_over_s = c.mu / s;
    let mut jac = [[0.0; 3]; 3];
    for (i, row) in jac.iter_mut().enumerate() {
        for (j, entry) in row.iter_mut().enumerate() {
            let uu = u[i] * u[j];
            let identity = if i == j { 1.0 } else { 0.0 };
            *entry = -normal_force * (c.d_slip * uu + mu_over_s * (identity - uu));
        }
    }
    (force, jac)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn adams() -> AdamsFrictionParams {
        AdamsFrictionParams {
            mu_static: 0.3,
            mu_dynamic: 0.1,
            v_static: 0.1,
            v_dynamic: 1.0,
        }
    }

    fn tanh_params() -> TanhFrictionParams {
        TanhFrictionParams {
            mu: 0.25,
            v_ref: 0.05,
        }
    }

    #[test]
    fn adams_reference_values() {
        let p = adams();
        let table = [
            (0.010, 0.0449),
            (0.050, 0.2062),
            (0.100, 0.3000),
            (0.300, 0.2748),
            (0.450, 0.2328),
            (0.550, 0.2000),
            (1.000, 0.1000),
            (1.500, 0.1000),
            (100.0, 0.1000),
        ];
        for (s, mu) in table {
            let c = adams_friction_coefficient(s, &p);
            assert!((c.mu - mu).abs() < 1e-4, "s={s}: {} vs {mu}", c.mu);
        }
        assert_eq!(adams_friction_coefficient(0.0, &p).mu, 0.0);
        assert_eq!(adams_friction_coefficient(2.0, &p).d_slip, 0.0);
    }

    #[test]
    fn adams_slope_at_zero() {
        let p = adams();
        let c = adams_friction_coefficient(0.0, &p);
        assert_relative_eq!(c.d_slip, 1.5 * 0.3 / 0.1, max_relative = 1e-14);
        // Negative input is treated as zero slip.
        assert_eq!(adams_friction_coefficient(-1.0, &p), c);
    }

    #[test]
    fn adams_is_c1_at_transitions() {
        let p = adams();
        for v in [p.v_static, p.v_dynamic] {
            let below = adams_friction_coefficient(v - 1e-12, &p);
            let above = adams_friction_coefficient(v + 1e-12, &p);
            assert!((below.mu - above.mu).abs() < 1e-10, "v={v}");
            assert!((below.d_slip - above.d_slip).abs() < 1e-9, "v={v}");
        }
    }

    fn check_slope(name: &str, law: impl Fn(f64) -> FrictionCoefficient, speeds: &[f64]) {
        for &s in speeds {
            let h = 1e-6 * s;
            let fd = (law(s + h).mu - law(s - h).mu) / (2.0 * h);
            let c = law(s);
            let tol = 1e-6 * c.d_slip.abs().max(fd.abs()) + 1e-9 * c.mu / s;
            assert!(
                (c.d_slip - fd).abs() <= tol,
                "{name} s={s}: {} vs {fd}",
                c.d_slip
            );
        }
    }

    #[test]
    fn slopes_match_finite_differences() {
        let p = adams();
        let speeds = [
            1e-4, 0.01, 0.05, 0.099, 0.13, 0.3, 0.45, 0.55, 0.98, 1.2, 5.0,
        ];
        check_slope("adams", |s| adams_friction_coefficient(s, &p), &speeds);
        let t = tanh_params();
        check_slope("tanh", |s| tanh_friction_coefficient(s, &t), &speeds);
    }

    #[test]
    fn tanh_reference_values() {
        let t = tanh_params();
        assert_eq!(tanh_friction_coefficient(0.0, &t).mu, 0.0);
        assert_relative_eq!(
            tanh_friction_coefficient(0.0, &t).d_slip,
            0.25 / 0.05,
            max_relative = 1e-14
        );
        assert_relative_eq!(
            tanh_friction_coefficient(0.05, &t).mu,
            0.25 * 1f64.tanh(),
            max_relative = 1e-14
        );
        assert_relative_eq!(
            tanh_friction_coefficient(10.0, &t).mu,
            0.25,
            max_relative = 1e-14
        );
    }

    #[test]
    fn force_opposes_slip_with_coulomb_magnitude() {
        let p = adams();
        let v = [0.2, -0.3, 0.6]; // |v| = 0.7 m/s
        let (f, _) = friction_force(v, 500.0, |s| adams_friction_coefficient(s, &p));
        let mu = adams_friction_coefficient(0.7, &p).mu;
        for (fi, vi) in f.iter().zip(v) {
            assert_relative_eq!(*fi, -mu * 500.0 * vi / 0.7, max_relative = 1e-12);
        }
    }

    #[test]
    fn zero_cases_have_no_nan() {
        let p = adams();
        let law = |s| adams_friction_coefficient(s, &p);
        // No normal force: nothing at all.
        for fn_ in [0.0, -10.0, f64::NAN] {
            assert_eq!(
                friction_force([0.3, 0.0, 0.1], fn_, law),
                ([0.0; 3], [[0.0; 3]; 3])
            );
        }
        // No slip: zero force, Jacobian is the s -> 0 limit.
        let gain = -100.0 * 1.5 * 0.3 / 0.1;
        for v in [[0.0; 3], [1e-14, -3e-14, 2e-14]] {
            let (f, j) = friction_force(v, 100.0, law);
            assert!(f.iter().all(|x| x.is_finite()));
            for (i, row) in j.iter().enumerate() {
                for (k, &entry) in row.iter().enumerate() {
                    let expect = if i == k { gain } else { 0.0 };
                    assert_relative_eq!(entry, expect, max_relative = 1e-14);
                }
            }
        }
        assert_eq!(friction_force([0.0; 3], 100.0, law).0, [0.0; 3]);
        // Continuity across the tiny-slip threshold.
        let (below, _) = friction_force([0.999e-12, 0.0, 0.0], 100.0, law);
        let (above, _) = friction_force([1.001e-12, 0.0, 0.0], 100.0, law);
        assert_relative_eq!(below[0], above[0], max_relative = 1e-2);
    }

    fn check_jacobian(name: &str, law: impl Fn(f64) -> FrictionCoefficient + Copy, v: [f64; 3]) {
        let fn_ = 750.0;
        let (_, jac) = friction_force(v, fn_, law);
        let speed = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        let h = 1e-6 * speed;
        let scale = jac.iter().flatten().fold(0.0_f64, |m, x| m.max(x.abs()));
        for k in 0..3 {
            let mut plus = v;
            let mut minus = v;
            plus[k] += h;
            minus[k] -= h;
            let (fp, _) = friction_force(plus, fn_, law);
            let (fm, _) = friction_force(minus, fn_, law);
            for i in 0..3 {
                let fd = (fp[i] - fm[i]) / (2.0 * h);
                let tol = 1e-6 * scale;
                assert!(
                    (jac[i][k] - fd).abs() <= tol,
                    "{name} v={v:?} J[{i}][{k}] = {} vs {fd}",
                    jac[i][k]
                );
            }
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let p = adams();
        let adams_law = |s| adams_friction_coefficient(s, &p);
        let t = tanh_params();
        let tanh_law = |s| tanh_friction_coefficient(s, &t);
        let slips = [
            [0.01, 0.0, 0.0],
            [0.02, -0.03, 0.01],
            [0.0, 0.05, 0.06],
            [0.2, -0.1, 0.15],
            [0.3, 0.4, -0.2],
            [-0.9, 0.5, 0.6],
            [2.0, -1.0, 0.5],
        ];
        for v in slips {
            check_jacobian("adams", adams_law, v);
            check_jacobian("tanh", tanh_law, v);
        }
    }
}
