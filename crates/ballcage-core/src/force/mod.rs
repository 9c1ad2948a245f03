//! Force laws: pure functions of contact kinematics and parameters.
//!
//! | law | module | formula |
//! |---|---|---|
//! | Adams IMPACT | [`normal`] | Kδⁿ + STEP(δ,0,0,d_max,c_max)·δ̇ |
//! | Lankarani–Nikravesh | [`normal`] | Kδⁿ[1 + 3(1−e²)/4 · δ̇/δ̇⁻] |
//! | Hunt–Crossley | [`normal`] | Kδⁿ[1 + 3(1−e)/2 · δ̇/δ̇⁻] |
//! | Flores | [`normal`] | Kδⁿ[1 + 8(1−e)/(5e) · δ̇/δ̇⁻] |
//! | Hertz | [`normal`] | K_H δ^1.5 |
//! | linear | [`normal`] | kδ + cδ̇ |
//! | Adams friction | [`friction`] | μ̂(s): cubic below v_s, STEP to μd at v_d |
//! | tanh friction | [`friction`] | μ tanh(s/v_ref) |
//!
//! Every law returns its derivatives (∂F/∂δ, ∂F/∂δ̇, dμ̂/ds) for Jacobians.
//! [`NormalLaw`] and [`FrictionLaw`] are the closed sets the engine dispatches on.

pub mod friction;
pub mod hertz;
pub mod joint;
pub mod normal;

pub use friction::{
    AdamsFrictionParams, FrictionCoefficient, TanhFrictionParams, adams_friction_coefficient,
    friction_force, tanh_friction_coefficient,
};
pub use normal::{
    DissipativeLaw, DissipativeParams, HertzParams, ImpactParams, LinearParams, NormalForce,
    effective_restitution, flores_normal_force, hertz_normal_force, hertz_stiffness,
    hunt_crossley_normal_force, impact_normal_force, lankarani_nikravesh_normal_force,
    linear_normal_force, restitution_chi, step,
};

/// A normal force law with SI parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NormalLaw {
    /// MSC Adams IMPACT.
    Impact(ImpactParams),
    /// Lankarani–Nikravesh, Hunt–Crossley or Flores: needs the approach speed latched at onset.
    Dissipative(DissipativeLaw, DissipativeParams),
    /// Hertz.
    Hertz(HertzParams),
    /// Linear spring-dashpot.
    Linear(LinearParams),
}

impl NormalLaw {
    /// Force and derivatives at depth δ [m], rate δ̇ [m/s]; `approach_speed`
    /// [m/s] is the latched δ̇⁻, read only by the dissipative laws.
    #[inline]
    pub fn evaluate(&self, depth: f64, rate: f64, approach_speed: f64) -> NormalForce {
        match self {
            Self::Impact(p) => impact_normal_force(depth, rate, p),
            Self::Dissipative(DissipativeLaw::LankaraniNikravesh, p) => {
                lankarani_nikravesh_normal_force(depth, rate, approach_speed, p)
            }
            Self::Dissipative(DissipativeLaw::HuntCrossley, p) => {
                hunt_crossley_normal_force(depth, rate, approach_speed, p)
            }
            Self::Dissipative(DissipativeLaw::Flores, p) => {
                flores_normal_force(depth, rate, approach_speed, p)
            }
            Self::Hertz(p) => hertz_normal_force(depth, p),
            Self::Linear(p) => linear_normal_force(depth, rate, p),
        }
    }

    /// Whether the law reads an approach speed latched at contact onset.
    pub fn latches_approach_speed(&self) -> bool {
        matches!(self, Self::Dissipative(..))
    }

    /// Stiffness K and exponent n of the rate-independent part Kδⁿ.
    fn spring(&self) -> (f64, f64) {
        match self {
            Self::Impact(p) => (p.stiffness, p.exponent),
            Self::Dissipative(_, p) => (p.stiffness, p.exponent),
            Self::Hertz(p) => (p.stiffness, 1.5),
            Self::Linear(p) => (p.stiffness, 1.0),
        }
    }

    /// Elastic energy stored at depth δ [J]: ∫₀^δ of the rate-independent part.
    pub fn elastic_energy(&self, depth: f64) -> f64 {
        if depth <= 0.0 {
            return 0.0;
        }
        let (k, n) = self.spring();
        k * depth.powf(n + 1.0) / (n + 1.0)
    }

    /// The rate-independent part Kδⁿ at depth δ [N]: the force minus it,
    /// times δ̇, is the power the law's damping dissipates.
    pub fn elastic_force(&self, depth: f64) -> f64 {
        if depth <= 0.0 {
            return 0.0;
        }
        let (k, n) = self.spring();
        k * depth.powf(n)
    }
}

/// A friction law with SI parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrictionLaw {
    /// MSC Adams static/dynamic law.
    Adams(AdamsFrictionParams),
    /// tanh-regularized Coulomb.
    Tanh(TanhFrictionParams),
}

impl FrictionLaw {
    /// Coefficient μ̂ and slope dμ̂/ds at slip speed s [m/s].
    #[inline]
    pub fn coefficient(&self, slip: f64) -> FrictionCoefficient {
        match self {
            Self::Adams(p) => adams_friction_coefficient(slip, p),
            Self::Tanh(p) => tanh_friction_coefficient(slip, p),
        }
    }
}
