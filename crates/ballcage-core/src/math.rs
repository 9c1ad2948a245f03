//! Scalar and small dense types used throughout the engine.
//!
//! The engine computes in nalgebra types (`Vec3`, `Quat`, `Mat3`); parry's
//! glam types appear only inside `geometry`, converted at the call.

/// Scalar type: every quantity is an `f64` in SI units.
pub type Real = f64;
/// A 3-vector (position [m], velocity [m/s], force [N], ...).
pub type Vec3 = nalgebra::Vector3<Real>;
/// A unit quaternion: body orientation, body frame → world frame.
pub type Quat = nalgebra::UnitQuaternion<Real>;
/// A 3×3 matrix (inertia tensors [kg·m²], Jacobian blocks).
pub type Mat3 = nalgebra::Matrix3<Real>;

/// Converts to parry's vector type.
#[inline]
pub(crate) fn to_glam(v: &Vec3) -> parry3d_f64::math::Vector {
    parry3d_f64::math::Vector::new(v.x, v.y, v.z)
}

/// Converts from parry's vector type.
#[inline]
pub(crate) fn from_glam(v: parry3d_f64::math::Vector) -> Vec3 {
    Vec3::new(v.x, v.y, v.z)
}

/// Converts a pose to parry's pose type.
#[inline]
pub(crate) fn to_glam_pose(p: &Vec3, q: &Quat) -> parry3d_f64::math::Pose {
    let r = parry3d_f64::math::Rotation::from_xyzw(q.i, q.j, q.k, q.w);
    parry3d_f64::math::Pose::from_parts(to_glam(p), r)
}

/// Rotation vector (axis × angle [rad]) to unit quaternion, exact.
#[inline]
pub fn exp_map(rotation_vector: &Vec3) -> Quat {
    Quat::from_scaled_axis(*rotation_vector)
}

/// Inverse of the right Jacobian of SO(3) applied to `w`: the rate ξ̇ of the
/// rotation vector ξ in `R = R0·Exp(ξ)` when the body-frame angular velocity is `w`.
///
/// ξ̇ = w + ½ ξ×w + (1/θ² − (1+cos θ)/(2θ sin θ)) ξ×(ξ×w), θ = |ξ|; the last
/// coefficient tends to 1/12 as θ → 0. Below θ² = 0.1 it is taken from its
/// Taylor series, 1/12 + θ²/720 + θ⁴/30240 + θ⁶/1209600 + θ⁸/47900160
/// (from the series of cot θ/2; the next term is below 1e-15 there), which
/// needs no sine or cosine: the implicit integrators call this for every
/// body at every Newton iteration.
#[inline]
pub fn dexp_inv(xi: &Vec3, w: &Vec3) -> Vec3 {
    let th2 = xi.norm_squared();
    let c = if th2 < 0.1 {
        1.0 / 12.0
            + th2
                * (1.0 / 720.0
                    + th2 * (1.0 / 30240.0 + th2 * (1.0 / 1_209_600.0 + th2 / 47_900_160.0)))
    } else {
        let th = th2.sqrt();
        1.0 / th2 - (1.0 + th.cos()) / (2.0 * th * th.sin())
    };
    let xw = xi.cross(w);
    w + 0.5 * xw + c * xi.cross(&xw)
}

/// Angle between two vectors [rad], in [0, π]: atan2(|a × b|, a · b), accurate
/// near 0 and π where acos is not. The one bend-angle formula of the engine.
#[inline]
pub fn angle_between(a: &Vec3, b: &Vec3) -> Real {
    a.cross(b).norm().atan2(a.dot(b))
}

/// Adams STEP cubic: returns (value, d value / dx). The contact laws' ramps
/// (`force`) and the tube ends' engagement (`geometry`) both use it.
///
/// `STEP(x, x0, h0, x1, h1)` equals `h0` for `x <= x0`, `h1` for `x >= x1`
/// and `h0 + (h1 - h0) Δ² (3 - 2Δ)` with `Δ = (x - x0) / (x1 - x0)` in
/// between. It is C¹: the slope vanishes at both ends. Requires `x0 <= x1`
/// (with `x0 == x1` it is a plain jump at `x0`).
pub fn step(x: f64, x0: f64, h0: f64, x1: f64, h1: f64) -> (f64, f64) {
    if x <= x0 {
        (h0, 0.0)
    } else if x >= x1 {
        (h1, 0.0)
    } else {
        let width = x1 - x0;
        let d = (x - x0) / width;
        let dh = h1 - h0;
        let value = h0 + dh * d * d * (3.0 - 2.0 * d);
        let slope = dh * 6.0 * d * (1.0 - d) / width;
        (value, slope)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form of dexp_inv's last coefficient.
    fn coefficient(th: f64) -> f64 {
        1.0 / (th * th) - (1.0 + th.cos()) / (2.0 * th * th.sin())
    }

    #[test]
    fn the_series_of_dexp_inv_matches_its_closed_form() {
        let w = Vec3::new(0.3, -1.2, 2.0);
        let axis = Vec3::new(1.0, 2.0, -0.5).normalize();
        // Where the closed form is still accurate (it cancels as θ → 0),
        // up to the switch at θ² = 0.1 and just past it.
        for th in [0.02, 0.05, 0.1, 0.2, 0.3, 0.316, 0.317, 0.4] {
            let xi = th * axis;
            let xw = xi.cross(&w);
            let exact = w + 0.5 * xw + coefficient(th) * xi.cross(&xw);
            let got = dexp_inv(&xi, &w);
            assert!(
                (got - exact).norm() <= 1e-13 * w.norm(),
                "θ = {th}: {got} against {exact}"
            );
        }
        // The series differs from its first term by θ²/720 at θ = 0.3: the
        // comparison above would see a series cut after one term.
        let th: f64 = 0.3;
        assert!((coefficient(th) - 1.0 / 12.0) * th * th > 1e-5);
    }
}
