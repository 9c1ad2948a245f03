//! Force laws as written → the SI laws the engine evaluates.

use crate::force::{
    AdamsFrictionParams, DissipativeLaw, DissipativeParams, FrictionLaw, HertzParams, ImpactParams,
    LinearParams, NormalLaw, TanhFrictionParams,
};
use crate::scene::{FieldUnits, FrictionLawSpec, NormalLawSpec};

/// The conversion of a law's parameters from the units they are written in
/// to SI: the one place the paper's field units (`units = "N-mm-s"`) are
/// converted.
#[derive(Debug, Clone, Copy)]
struct ToSi {
    /// Metres per length unit.
    metres: f64,
}

impl ToSi {
    fn new(units: FieldUnits) -> Self {
        let metres = match units {
            FieldUnits::Si => 1.0,
            FieldUnits::NMmS => 1e-3,
        };
        Self { metres }
    }

    /// Stiffness of a force K·δⁿ: N/unit^n → N/m^n. F = K δ_u^n = K (δ_m / L)^n.
    fn stiffness(self, k: f64, n: f64) -> f64 {
        k * self.metres.powf(-n)
    }

    /// Damping: N·s/unit → N·s/m.
    fn damping(self, c: f64) -> f64 {
        c / self.metres
    }

    /// Length: unit → m.
    fn length(self, x: f64) -> f64 {
        x * self.metres
    }

    /// Speed: unit/s → m/s.
    fn speed(self, v: f64) -> f64 {
        v * self.metres
    }
}

/// The SI normal law of a validated spec.
pub fn normal_law(spec: &NormalLawSpec) -> NormalLaw {
    let dissipative = |law, k: f64, n: f64, e: f64, v: f64, u: FieldUnits| {
        let si = ToSi::new(u);
        NormalLaw::Dissipative(
            law,
            DissipativeParams {
                stiffness: si.stiffness(k, n),
                exponent: n,
                restitution: e,
                min_approach_speed: si.speed(v),
            },
        )
    };
    match *spec {
        NormalLawSpec::Impact {
            stiffness,
            exponent,
            damping,
            depth_max,
            units,
        } => {
            let si = ToSi::new(units);
            NormalLaw::Impact(ImpactParams {
                stiffness: si.stiffness(stiffness, exponent),
                exponent,
                damping: si.damping(damping),
                depth_max: si.length(depth_max),
            })
        }
        NormalLawSpec::LankaraniNikravesh {
            stiffness: k,
            exponent: n,
            restitution: e,
            min_approach_speed: v,
            units: u,
        } => dissipative(DissipativeLaw::LankaraniNikravesh, k, n, e, v, u),
        NormalLawSpec::HuntCrossley {
            stiffness: k,
            exponent: n,
            restitution: e,
            min_approach_speed: v,
            units: u,
        } => dissipative(DissipativeLaw::HuntCrossley, k, n, e, v, u),
        NormalLawSpec::Flores {
            stiffness: k,
            exponent: n,
            restitution: e,
            min_approach_speed: v,
            units: u,
        } => dissipative(DissipativeLaw::Flores, k, n, e, v, u),
        NormalLawSpec::Hertz { stiffness, units } => NormalLaw::Hertz(HertzParams {
            stiffness: ToSi::new(units).stiffness(stiffness, 1.5),
        }),
        NormalLawSpec::Linear {
            stiffness,
            damping,
            units,
        } => {
            let si = ToSi::new(units);
            NormalLaw::Linear(LinearParams {
                stiffness: si.stiffness(stiffness, 1.0),
                damping: si.damping(damping),
            })
        }
    }
}

/// The SI friction law of a validated spec.
pub fn friction_law(spec: &FrictionLawSpec) -> FrictionLaw {
    match *spec {
        FrictionLawSpec::Adams {
            mu_static,
            mu_dynamic,
            v_static,
            v_dynamic,
            units,
        } => {
            let si = ToSi::new(units);
            FrictionLaw::Adams(AdamsFrictionParams {
                mu_static,
                mu_dynamic,
                v_static: si.speed(v_static),
                v_dynamic: si.speed(v_dynamic),
            })
        }
        FrictionLawSpec::Tanh { mu, v_ref, units } => FrictionLaw::Tanh(TanhFrictionParams {
            mu,
            v_ref: ToSi::new(units).speed(v_ref),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_units_convert_every_parameter_once() {
        let law = normal_law(&NormalLawSpec::Impact {
            stiffness: 1e5,
            exponent: 2.2,
            damping: 10.0,
            depth_max: 0.1,
            units: FieldUnits::NMmS,
        });
        let NormalLaw::Impact(p) = law else {
            panic!("{law:?}")
        };
        assert_eq!(p.stiffness, 1e5 * 1e-3f64.powf(-2.2));
        assert_eq!(p.damping, 10.0 / 1e-3);
        assert_eq!(p.depth_max, 0.1 * 1e-3);
        let f = friction_law(&FrictionLawSpec::Tanh {
            mu: 0.2,
            v_ref: 5.0,
            units: FieldUnits::NMmS,
        });
        assert_eq!(
            f,
            FrictionLaw::Tanh(TanhFrictionParams {
                mu: 0.2,
                v_ref: 5.0 * 1e-3
            })
        );
    }
}
