//! Contact pair declarations and their force laws.

use serde::{Deserialize, Serialize};

use super::{Scene, ShapeSpec, direction, finite_vec, non_negative, positive};
use crate::error::SceneError;
use crate::force::{
    AdamsFrictionParams, DissipativeLaw, DissipativeParams, FrictionLaw, HertzParams, ImpactParams,
    LinearParams, NormalLaw, TanhFrictionParams,
};
use crate::geometry::PairGeometry;
use crate::math::Vec3;

/// Units in which a law's parameters are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum FieldUnits {
    /// SI: stiffness N/m^n, damping N·s/m, lengths m, speeds m/s.
    #[default]
    #[serde(rename = "SI")]
    Si,
    /// The paper's (and MSC Adams') field units: stiffness N/mm^n, damping
    /// N·s/mm, lengths mm, speeds mm/s. Converted to SI once, on reading.
    #[serde(rename = "N-mm-s")]
    NMmS,
}

impl FieldUnits {
    /// Metres per length unit.
    fn length(self) -> f64 {
        match self {
            Self::Si => 1.0,
            Self::NMmS => 1e-3,
        }
    }
}

fn default_exponent_hertzian() -> f64 {
    1.5
}

fn default_min_approach_speed() -> f64 {
    1e-3
}

/// Normal force law of a pair. `law` selects the variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "law", rename_all = "kebab-case", deny_unknown_fields)]
pub enum NormalLawSpec {
    /// MSC Adams IMPACT (the paper's "L-N" law): F = Kδⁿ + STEP(δ,0,0,d_max,c_max)·δ̇, never pulling.
    Impact {
        /// K [N/m^n] (or N/mm^n with `units = "N-mm-s"`).
        stiffness: f64,
        /// n [-].
        exponent: f64,
        /// c_max [N·s/m] (or N·s/mm).
        damping: f64,
        /// d_max, the depth of full damping [m] (or mm).
        depth_max: f64,
        /// Parameter units.
        #[serde(default)]
        units: FieldUnits,
    },
    /// Lankarani–Nikravesh: F = Kδⁿ[1 + 3(1−e²)/4 · δ̇/δ̇⁻], δ̇⁻ latched at contact onset.
    LankaraniNikravesh {
        /// K [N/m^n] (or N/mm^n).
        stiffness: f64,
        /// n [-], 1.5 (Hertzian) by default.
        #[serde(default = "default_exponent_hertzian")]
        exponent: f64,
        /// Coefficient of restitution e ∈ (0, 1].
        restitution: f64,
        /// Lower clamp of the latched approach speed [m/s] (or mm/s).
        #[serde(default = "default_min_approach_speed")]
        min_approach_speed: f64,
        /// Parameter units.
        #[serde(default)]
        units: FieldUnits,
    },
    /// Hunt–Crossley: F = Kδⁿ[1 + 3(1−e)/2 · δ̇/δ̇⁻].
    HuntCrossley {
        /// K [N/m^n] (or N/mm^n).
        stiffness: f64,
        /// n [-], 1.5 by default.
        #[serde(default = "default_exponent_hertzian")]
        exponent: f64,
        /// Coefficient of restitution e ∈ (0, 1].
        restitution: f64,
        /// Lower clamp of the latched approach speed [m/s] (or mm/s).
        #[serde(default = "default_min_approach_speed")]
        min_approach_speed: f64,
        /// Parameter units.
        #[serde(default)]
        units: FieldUnits,
    },
    /// Flores et al. (2011): F = Kδⁿ[1 + 8(1−e)/(5e) · δ̇/δ̇⁻].
    Flores {
        /// K [N/m^n] (or N/mm^n).
        stiffness: f64,
        /// n [-], 1.5 by default.
        #[serde(default = "default_exponent_hertzian")]
        exponent: f64,
        /// Coefficient of restitution e ∈ (0, 1].
        restitution: f64,
        /// Lower clamp of the latched approach speed [m/s] (or mm/s).
        #[serde(default = "default_min_approach_speed")]
        min_approach_speed: f64,
        /// Parameter units.
        #[serde(default)]
        units: FieldUnits,
    },
    /// Hertz: F = K_H δ^1.5, no dissipation.
    Hertz {
        /// K_H [N/m^1.5] (or N/mm^1.5).
        stiffness: f64,
        /// Parameter units.
        #[serde(default)]
        units: FieldUnits,
    },
    /// Linear spring-dashpot (Kelvin–Voigt): F = kδ + cδ̇, never pulling.
    Linear {
        /// k [N/m] (or N/mm).
        stiffness: f64,
        /// c [N·s/m] (or N·s/mm).
        #[serde(default)]
        damping: f64,
        /// Parameter units.
        #[serde(default)]
        units: FieldUnits,
    },
}

impl NormalLawSpec {
    /// Validates and converts to the SI law the engine evaluates.
    pub fn to_law(&self, path: &str) -> Result<NormalLaw, SceneError> {
        let exponent_ok = |n: f64| -> Result<(), SceneError> {
            positive(&format!("{path}.exponent"), n)?;
            if n < 1.0 {
                return Err(SceneError::new(
                    format!("{path}.exponent"),
                    n,
                    "must be at least 1 (the force must start at zero slope or higher)",
                ));
            }
            Ok(())
        };
        let restitution_ok = |e: f64| -> Result<(), SceneError> {
            positive(&format!("{path}.restitution"), e)?;
            if e > 1.0 {
                return Err(SceneError::new(
                    format!("{path}.restitution"),
                    e,
                    "must lie in (0, 1]",
                ));
            }
            Ok(())
        };
        let stiff = |k: f64, n: f64, u: FieldUnits| -> Result<f64, SceneError> {
            positive(&format!("{path}.stiffness"), k)?;
            // N/mm^n → N/m^n: F = K δ_mm^n = K (δ_m / L)^n with L the unit length in m.
            Ok(k * u.length().powf(-n))
        };
        let dissipative =
            |law, k: f64, n: f64, e: f64, v: f64, u: FieldUnits| -> Result<NormalLaw, SceneError> {
                exponent_ok(n)?;
                restitution_ok(e)?;
                positive(&format!("{path}.min_approach_speed"), v)?;
                Ok(NormalLaw::Dissipative(
                    law,
                    DissipativeParams {
                        stiffness: stiff(k, n, u)?,
                        exponent: n,
                        restitution: e,
                        min_approach_speed: v * u.length(),
                    },
                ))
            };
        match *self {
            Self::Impact {
                stiffness,
                exponent,
                damping,
                depth_max,
                units,
            } => {
                exponent_ok(exponent)?;
                non_negative(&format!("{path}.damping"), damping)?;
                positive(&format!("{path}.depth_max"), depth_max)?;
                Ok(NormalLaw::Impact(ImpactParams {
                    stiffness: stiff(stiffness, exponent, units)?,
                    exponent,
                    damping: damping / units.length(),
                    depth_max: depth_max * units.length(),
                }))
            }
            Self::LankaraniNikravesh {
                stiffness,
                exponent,
                restitution,
                min_approach_speed,
                units,
            } => dissipative(
                DissipativeLaw::LankaraniNikravesh,
                stiffness,
                exponent,
                restitution,
                min_approach_speed,
                units,
            ),
            Self::HuntCrossley {
                stiffness,
                exponent,
                restitution,
                min_approach_speed,
                units,
            } => dissipative(
                DissipativeLaw::HuntCrossley,
                stiffness,
                exponent,
                restitution,
                min_approach_speed,
                units,
            ),
            Self::Flores {
                stiffness,
                exponent,
                restitution,
                min_approach_speed,
                units,
            } => dissipative(
                DissipativeLaw::Flores,
                stiffness,
                exponent,
                restitution,
                min_approach_speed,
                units,
            ),
            Self::Hertz { stiffness, units } => Ok(NormalLaw::Hertz(HertzParams {
                stiffness: stiff(stiffness, 1.5, units)?,
            })),
            Self::Linear {
                stiffness,
                damping,
                units,
            } => {
                non_negative(&format!("{path}.damping"), damping)?;
                Ok(NormalLaw::Linear(LinearParams {
                    stiffness: stiff(stiffness, 1.0, units)?,
                    damping: damping / units.length(),
                }))
            }
        }
    }
}

/// Friction law of a pair. `law` selects the variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "law", rename_all = "kebab-case", deny_unknown_fields)]
pub enum FrictionLawSpec {
    /// MSC Adams static/dynamic law (physics.md §2.2), no true stiction.
    Adams {
        /// μs [-].
        mu_static: f64,
        /// μd [-].
        mu_dynamic: f64,
        /// Stiction transition speed v_s [m/s] (or mm/s).
        v_static: f64,
        /// Friction transition speed v_d > v_s [m/s] (or mm/s).
        v_dynamic: f64,
        /// Parameter units.
        #[serde(default)]
        units: FieldUnits,
    },
    /// Regularized Coulomb: μ·tanh(s / v_ref).
    Tanh {
        /// μ [-].
        mu: f64,
        /// Regularization speed [m/s] (or mm/s).
        v_ref: f64,
        /// Parameter units.
        #[serde(default)]
        units: FieldUnits,
    },
}

impl FrictionLawSpec {
    /// Validates and converts to the SI law the engine evaluates.
    pub fn to_law(&self, path: &str) -> Result<FrictionLaw, SceneError> {
        match *self {
            Self::Adams {
                mu_static,
                mu_dynamic,
                v_static,
                v_dynamic,
                units,
            } => {
                non_negative(&format!("{path}.mu_static"), mu_static)?;
                non_negative(&format!("{path}.mu_dynamic"), mu_dynamic)?;
                positive(&format!("{path}.v_static"), v_static)?;
                positive(&format!("{path}.v_dynamic"), v_dynamic)?;
                if v_dynamic <= v_static {
                    return Err(SceneError::new(
                        format!("{path}.v_dynamic"),
                        v_dynamic,
                        format!("must exceed v_static = {v_static}"),
                    ));
                }
                let l = units.length();
                Ok(FrictionLaw::Adams(AdamsFrictionParams {
                    mu_static,
                    mu_dynamic,
                    v_static: v_static * l,
                    v_dynamic: v_dynamic * l,
                }))
            }
            Self::Tanh { mu, v_ref, units } => {
                non_negative(&format!("{path}.mu"), mu)?;
                positive(&format!("{path}.v_ref"), v_ref)?;
                Ok(FrictionLaw::Tanh(TanhFrictionParams {
                    mu,
                    v_ref: v_ref * units.length(),
                }))
            }
        }
    }
}

/// Explicit contact geometry fixed to the pair's bodies, for surfaces that
/// are not a body's main shape (races, windows, spherical seats). All vectors
/// are in the named body's frame [m].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum FeatureSpec {
    /// Ball b inside the tube of a torus on body a: a groove flank of
    /// circular section `tube_radius` swept around a core circle.
    /// δ = |p − q| + r_ball − tube_radius, q the core-circle point nearest the ball centre p.
    TorusBall {
        /// Core-circle centre, body a frame.
        centre: [f64; 3],
        /// Normal of the core circle's plane, body a frame.
        axis: [f64; 3],
        /// Core-circle radius [m].
        core_radius: f64,
        /// Section (tube) radius [m], larger than the ball's.
        tube_radius: f64,
    },
    /// Ball b between two parallel planes of body a (a window):
    /// δ = r_ball − (half_width − |(p − centre)·normal|).
    SlotBall {
        /// Mid-plane point, body a frame.
        centre: [f64; 3],
        /// Plane normal, body a frame.
        normal: [f64; 3],
        /// Half of the gap between the planes [m].
        half_width: f64,
    },
    /// A sphere fixed to body b inside a spherical cavity of body a:
    /// δ = |o_b − o_a| + sphere_radius − cavity_radius.
    CavitySphere {
        /// Cavity centre, body a frame.
        cavity_centre: [f64; 3],
        /// Cavity radius [m].
        cavity_radius: f64,
        /// Sphere centre, body b frame.
        sphere_centre: [f64; 3],
        /// Sphere radius [m], smaller than the cavity's.
        sphere_radius: f64,
    },
}

/// A pair of bodies that may touch, and the laws of their contact.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    /// Pair name in the output; defaults to `"<a>/<b>"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The two bodies `[a, b]`. Normals point from a to b; reported
    /// tangential forces act on b.
    pub bodies: [String; 2],
    /// Normal force law.
    pub normal: NormalLawSpec,
    /// Friction law; none means frictionless (no friction term is built).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub friction: Option<FrictionLawSpec>,
    /// Explicit geometry; without it the bodies' shapes decide.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geometry: Option<FeatureSpec>,
    /// Sample points along a cylinder's axis for cylinder–tube contact (≥ 2:
    /// both end rims and evenly spaced interior points).
    #[serde(default = "default_points")]
    pub points: u32,
}

fn default_points() -> u32 {
    5
}

impl ContactSpec {
    /// The pair's name in outputs.
    pub fn pair_name(&self) -> String {
        self.name
            .clone()
            .unwrap_or_else(|| format!("{}/{}", self.bodies[0], self.bodies[1]))
    }

    /// The point finder of this pair, and whether the canonical order is (b, a).
    pub fn resolve_geometry(
        &self,
        path: &str,
        scene: &Scene,
    ) -> Result<(PairGeometry, bool), SceneError> {
        let mut idx = [0usize; 2];
        for (k, name) in self.bodies.iter().enumerate() {
            idx[k] = scene.body_index(name).ok_or_else(|| {
                SceneError::new(format!("{path}.bodies[{k}]"), name, "no body of that name")
            })?;
        }
        if idx[0] == idx[1] {
            return Err(SceneError::new(
                format!("{path}.bodies"),
                format!("{:?}", self.bodies),
                "a body cannot touch itself",
            ));
        }
        let (sa, sb) = (&scene.bodies[idx[0]].shape, &scene.bodies[idx[1]].shape);
        let Some(feature) = &self.geometry else {
            return PairGeometry::select(sa, sb, self.points).ok_or_else(|| {
                SceneError::new(
                    format!("{path}.bodies"),
                    format!("{:?}", self.bodies),
                    format!(
                        "no contact geometry for a {}–{} pair (supported: {}; or give `geometry`)",
                        sa.kind_name(),
                        sb.kind_name(),
                        PairGeometry::SUPPORTED
                    ),
                )
            });
        };
        let g = format!("{path}.geometry");
        let ball_radius = || match sb {
            ShapeSpec::Ball { radius } => Ok(*radius),
            other => Err(SceneError::new(
                format!("{path}.bodies[1]"),
                &self.bodies[1],
                format!(
                    "this geometry needs body b to be a ball, not a {}",
                    other.kind_name()
                ),
            )),
        };
        let geometry = match feature {
            FeatureSpec::TorusBall {
                centre,
                axis,
                core_radius,
                tube_radius,
            } => {
                finite_vec(&format!("{g}.centre"), centre)?;
                direction(&format!("{g}.axis"), axis)?;
                positive(&format!("{g}.core_radius"), *core_radius)?;
                positive(&format!("{g}.tube_radius"), *tube_radius)?;
                let r = ball_radius()?;
                if r >= *tube_radius {
                    return Err(SceneError::new(
                        format!("{g}.tube_radius"),
                        tube_radius,
                        format!("must exceed the ball radius {r}"),
                    ));
                }
                PairGeometry::TorusBall {
                    centre: Vec3::from(*centre),
                    axis: Vec3::from(*axis).normalize(),
                    core_radius: *core_radius,
                    tube_radius: *tube_radius,
                    ball_radius: r,
                }
            }
            FeatureSpec::SlotBall {
                centre,
                normal,
                half_width,
            } => {
                finite_vec(&format!("{g}.centre"), centre)?;
                direction(&format!("{g}.normal"), normal)?;
                positive(&format!("{g}.half_width"), *half_width)?;
                let r = ball_radius()?;
                if r >= *half_width {
                    return Err(SceneError::new(
                        format!("{g}.half_width"),
                        half_width,
                        format!("must exceed the ball radius {r}"),
                    ));
                }
                PairGeometry::SlotBall {
                    centre: Vec3::from(*centre),
                    normal: Vec3::from(*normal).normalize(),
                    half_width: *half_width,
                    ball_radius: r,
                }
            }
            FeatureSpec::CavitySphere {
                cavity_centre,
                cavity_radius,
                sphere_centre,
                sphere_radius,
            } => {
                finite_vec(&format!("{g}.cavity_centre"), cavity_centre)?;
                finite_vec(&format!("{g}.sphere_centre"), sphere_centre)?;
                positive(&format!("{g}.cavity_radius"), *cavity_radius)?;
                positive(&format!("{g}.sphere_radius"), *sphere_radius)?;
                if sphere_radius >= cavity_radius {
                    return Err(SceneError::new(
                        format!("{g}.sphere_radius"),
                        sphere_radius,
                        format!("must be smaller than cavity_radius = {cavity_radius}"),
                    ));
                }
                PairGeometry::CavitySphere {
                    cavity_centre: Vec3::from(*cavity_centre),
                    cavity_radius: *cavity_radius,
                    sphere_centre: Vec3::from(*sphere_centre),
                    sphere_radius: *sphere_radius,
                }
            }
        };
        Ok((geometry, false))
    }

    pub(super) fn validate(&self, path: &str, scene: &Scene) -> Result<(), SceneError> {
        if !(2..=64).contains(&self.points) {
            return Err(SceneError::new(
                format!("{path}.points"),
                self.points,
                "must lie in 2..=64 (2 = both end rims)",
            ));
        }
        self.resolve_geometry(path, scene)?;
        self.normal.to_law(&format!("{path}.normal"))?;
        if let Some(f) = &self.friction {
            f.to_law(&format!("{path}.friction"))?;
        }
        Ok(())
    }
}
