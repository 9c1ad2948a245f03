//! Contact pair declarations and their force laws, as written: the laws
//! and geometry the engine evaluates are built from them at assembly,
//! which also converts the field units.

use serde::{Deserialize, Serialize};

use super::fields::{FieldDoc, FieldInfo};
use super::{Scene, direction, finite_vec, non_negative, positive};
use crate::error::SceneError;

/// Units in which a law's parameters are written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum FieldUnits {
    /// SI: stiffness N/m^n, damping N·s/m, lengths m, speeds m/s.
    #[default]
    #[serde(rename = "SI")]
    Si,
    /// The paper's (and MSC Adams') field units: stiffness N/mm^n, damping
    /// N·s/mm, lengths mm, speeds mm/s. Converted to SI once, at assembly.
    #[serde(rename = "N-mm-s")]
    NMmS,
}

impl FieldUnits {
    /// Millimetres per length unit.
    fn millimetres(self) -> f64 {
        match self {
            Self::Si => 1000.0,
            Self::NMmS => 1.0,
        }
    }
}

/// The fields of the contact laws (normal and friction). Their units are
/// written for the law's own `units`: `{L}` is its length (m or mm) and
/// `^n` its stiffness exponent ([`law_field`]).
pub const LAW_FIELDS: &[FieldDoc] = &[
    FieldDoc::text(
        "law",
        "the law: impact, lankarani-nikravesh, hunt-crossley, flores, hertz or linear (normal); adams or tanh (friction)",
    ),
    FieldDoc::text(
        "units",
        "the units the law's fields are written in: SI, or N-mm-s (the paper's)",
    ),
    FieldDoc::number(
        "stiffness",
        "N/{L}^n",
        "stiffness K of the elastic force K·δⁿ",
    ),
    FieldDoc::number("exponent", "-", "force exponent n"),
    FieldDoc::number(
        "damping",
        "N·s/{L}",
        "damping: IMPACT's c_max, or the linear law's c",
    ),
    FieldDoc::number(
        "depth_max",
        "{L}",
        "IMPACT's d_max, the depth of full damping",
    ),
    FieldDoc::number("restitution", "-", "coefficient of restitution e"),
    FieldDoc::number(
        "min_approach_speed",
        "{L}/s",
        "lower clamp of the approach speed latched at contact onset",
    ),
    FieldDoc::number("mu_static", "-", "static friction coefficient μs"),
    FieldDoc::number("mu_dynamic", "-", "dynamic friction coefficient μd"),
    FieldDoc::number("v_static", "{L}/s", "stiction transition speed v_s"),
    FieldDoc::number(
        "v_dynamic",
        "{L}/s",
        "friction transition speed v_d, above v_static",
    ),
    FieldDoc::number("mu", "-", "friction coefficient μ"),
    FieldDoc::number("v_ref", "{L}/s", "regularization speed"),
];

/// A law table's `units` and stiffness exponent n: `exponent`, else 1.5
/// for `hertz` and 1 for the others (`linear`; friction has no stiffness).
fn law_units(law: &toml::Table) -> Option<(FieldUnits, f64)> {
    let units: FieldUnits = law
        .get("units")
        .and_then(|u| u.clone().try_into().ok())
        .unwrap_or_default();
    let n = match (
        law.get("law").and_then(toml::Value::as_str),
        law.get("exponent"),
    ) {
        (_, Some(n)) => n.as_float().or_else(|| n.as_integer().map(|i| i as f64))?,
        (Some("hertz"), None) => 1.5,
        _ => 1.0,
    };
    Some((units, n))
}

/// The unit and meaning of field `key` of the contact law table `law`
/// ([`LAW_FIELDS`]): lengths in the law's `units`, a stiffness in N/m^n
/// (or N/mm^n) for its exponent n, `N/m` for n = 1. A [`LawRule`](super::LawRule).
pub fn law_field(key: &str, law: &toml::Table) -> Option<FieldInfo> {
    let doc = LAW_FIELDS.iter().find(|d| d.key == key)?;
    let (units, n) = law_units(law)?;
    let length = match units {
        FieldUnits::Si => "m",
        FieldUnits::NMmS => "mm",
    };
    let power = if n == 1.0 {
        String::new()
    } else {
        format!("^{n}")
    };
    Some(FieldInfo {
        unit: doc.unit.replace("^n", &power).replace("{L}", length),
        meaning: doc.meaning,
    })
}

/// The factor that turns a value of field `key` of the contact law table
/// `law`, written in `from` units, into the law's own units (those
/// [`law_field`] names): (mm per own length / mm per `from` length)^n for
/// a stiffness, that ratio for a damping, its inverse for a length or a
/// speed, 1 for a pure number; `None` for a field that is not a number.
pub fn scale_from(key: &str, law: &toml::Table, from: FieldUnits) -> Option<f64> {
    let doc = LAW_FIELDS.iter().find(|d| d.key == key)?;
    let (units, n) = law_units(law)?;
    let ratio = units.millimetres() / from.millimetres();
    match doc.unit {
        "-" => Some(1.0),
        u if u.ends_with("^n") => Some(ratio.powf(n)),
        u if u.starts_with("N·s/") => Some(ratio),
        u if u.starts_with("{L}") => Some(from.millimetres() / units.millimetres()),
        _ => None,
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
    /// Checks the parameters' ranges (in the units written).
    pub fn validate(&self, path: &str) -> Result<(), SceneError> {
        let exponent = |n: f64| exponent_at_least_one(&format!("{path}.exponent"), n);
        let stiffness = |k: f64| positive(&format!("{path}.stiffness"), k);
        match *self {
            Self::Impact {
                stiffness: k,
                exponent: n,
                damping,
                depth_max,
                ..
            } => {
                exponent(n)?;
                non_negative(&format!("{path}.damping"), damping)?;
                positive(&format!("{path}.depth_max"), depth_max)?;
                stiffness(k)
            }
            Self::LankaraniNikravesh {
                stiffness: k,
                exponent: n,
                restitution,
                min_approach_speed,
                ..
            }
            | Self::HuntCrossley {
                stiffness: k,
                exponent: n,
                restitution,
                min_approach_speed,
                ..
            }
            | Self::Flores {
                stiffness: k,
                exponent: n,
                restitution,
                min_approach_speed,
                ..
            } => {
                exponent(n)?;
                restitution_in_range(&format!("{path}.restitution"), restitution)?;
                positive(&format!("{path}.min_approach_speed"), min_approach_speed)?;
                stiffness(k)
            }
            Self::Hertz { stiffness: k, .. } => stiffness(k),
            Self::Linear {
                stiffness: k,
                damping,
                ..
            } => {
                non_negative(&format!("{path}.damping"), damping)?;
                stiffness(k)
            }
        }
    }
}

/// A force exponent: positive and at least 1.
fn exponent_at_least_one(path: &str, n: f64) -> Result<(), SceneError> {
    positive(path, n)?;
    if n < 1.0 {
        return Err(SceneError::new(
            path,
            n,
            "must be at least 1 (the force must start at zero slope or higher)",
        ));
    }
    Ok(())
}

/// A coefficient of restitution: in (0, 1].
fn restitution_in_range(path: &str, e: f64) -> Result<(), SceneError> {
    positive(path, e)?;
    if e > 1.0 {
        return Err(SceneError::new(path, e, "must lie in (0, 1]"));
    }
    Ok(())
}

/// Friction law of a pair. `law` selects the variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "law", rename_all = "kebab-case", deny_unknown_fields)]
pub enum FrictionLawSpec {
    /// MSC Adams static/dynamic law (docs/model.md §2.2), no true stiction.
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
    /// Checks the parameters' ranges (in the units written).
    pub fn validate(&self, path: &str) -> Result<(), SceneError> {
        match *self {
            Self::Adams {
                mu_static,
                mu_dynamic,
                v_static,
                v_dynamic,
                ..
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
                if mu_dynamic > mu_static {
                    return Err(SceneError::new(
                        format!("{path}.mu_dynamic"),
                        mu_dynamic,
                        format!(
                            "must not exceed mu_static = {mu_static} (the Adams law falls from static to \
                             dynamic friction as the slip grows)"
                        ),
                    ));
                }
                Ok(())
            }
            Self::Tanh { mu, v_ref, .. } => {
                non_negative(&format!("{path}.mu"), mu)?;
                positive(&format!("{path}.v_ref"), v_ref)
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
    /// A cylinder of body b through a ring of body a (a shaft's neck through
    /// an opening): δ = cylinder_radius − d, d the distance from the ring to
    /// the cylinder's axis at the ring point nearest the axis.
    RingCylinder {
        /// Ring centre, body a frame.
        ring_centre: [f64; 3],
        /// Normal of the ring's plane, body a frame.
        ring_axis: [f64; 3],
        /// Ring radius [m].
        ring_radius: f64,
        /// A point of the cylinder's axis, body b frame.
        axis_point: [f64; 3],
        /// Direction of the cylinder's axis, body b frame.
        axis_direction: [f64; 3],
        /// Cylinder radius [m], smaller than the ring's.
        cylinder_radius: f64,
    },
}

impl FeatureSpec {
    /// The unit and meaning of each field, of every geometry type.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::text(
            "type",
            "the geometry: torus-ball, slot-ball, cavity-sphere or ring-cylinder",
        ),
        FieldDoc::number(
            "centre",
            "m",
            "core-circle centre (torus-ball) or mid-plane point (slot-ball), body a frame",
        ),
        FieldDoc::number(
            "axis",
            "-",
            "normal of the core circle's plane (torus-ball), body a frame",
        ),
        FieldDoc::number("core_radius", "m", "radius of the torus' core circle"),
        FieldDoc::number(
            "tube_radius",
            "m",
            "radius of the torus' section, larger than the ball's",
        ),
        FieldDoc::number("normal", "-", "normal of a slot's planes, body a frame"),
        FieldDoc::number("half_width", "m", "half of the gap between a slot's planes"),
        FieldDoc::number(
            "cavity_centre",
            "m",
            "centre of the spherical cavity, body a frame",
        ),
        FieldDoc::number("cavity_radius", "m", "radius of the spherical cavity"),
        FieldDoc::number(
            "sphere_centre",
            "m",
            "centre of the sphere in the cavity, body b frame",
        ),
        FieldDoc::number(
            "sphere_radius",
            "m",
            "radius of the sphere in the cavity, smaller than the cavity's",
        ),
        FieldDoc::number("ring_centre", "m", "centre of the ring, body a frame"),
        FieldDoc::number("ring_axis", "-", "normal of the ring's plane, body a frame"),
        FieldDoc::number("ring_radius", "m", "radius of the ring"),
        FieldDoc::number(
            "axis_point",
            "m",
            "a point of the cylinder's axis, body b frame",
        ),
        FieldDoc::number(
            "axis_direction",
            "-",
            "direction of the cylinder's axis, body b frame",
        ),
        FieldDoc::number(
            "cylinder_radius",
            "m",
            "radius of the cylinder through the ring, smaller than the ring's",
        ),
    ];

    /// Checks the feature's own dimensions; whether it fits the pair's
    /// shapes is checked at assembly.
    pub fn validate(&self, g: &str) -> Result<(), SceneError> {
        match self {
            Self::TorusBall {
                centre,
                axis,
                core_radius,
                tube_radius,
            } => {
                finite_vec(&format!("{g}.centre"), centre)?;
                direction(&format!("{g}.axis"), axis)?;
                positive(&format!("{g}.core_radius"), *core_radius)?;
                positive(&format!("{g}.tube_radius"), *tube_radius)
            }
            Self::SlotBall {
                centre,
                normal,
                half_width,
            } => {
                finite_vec(&format!("{g}.centre"), centre)?;
                direction(&format!("{g}.normal"), normal)?;
                positive(&format!("{g}.half_width"), *half_width)
            }
            Self::CavitySphere {
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
                Ok(())
            }
            Self::RingCylinder {
                ring_centre,
                ring_axis,
                ring_radius,
                axis_point,
                axis_direction,
                cylinder_radius,
            } => {
                finite_vec(&format!("{g}.ring_centre"), ring_centre)?;
                direction(&format!("{g}.ring_axis"), ring_axis)?;
                finite_vec(&format!("{g}.axis_point"), axis_point)?;
                direction(&format!("{g}.axis_direction"), axis_direction)?;
                positive(&format!("{g}.ring_radius"), *ring_radius)?;
                positive(&format!("{g}.cylinder_radius"), *cylinder_radius)?;
                if cylinder_radius >= ring_radius {
                    return Err(SceneError::new(
                        format!("{g}.cylinder_radius"),
                        cylinder_radius,
                        format!(
                            "must be smaller than ring_radius = {ring_radius}: \
                             a wider cylinder cannot pass through the ring"
                        ),
                    ));
                }
                Ok(())
            }
        }
    }
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
    /// How a cylinder–tube line contact becomes points (other pairs ignore
    /// it): `"level-sets"` (default) or `"patches"` (docs/model.md §4).
    #[serde(default)]
    pub line_law: LineLawSpec,
}

fn default_points() -> u32 {
    5
}

/// How a cylinder–tube pair turns its line contact into point laws
/// (docs/model.md §4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LineLawSpec {
    /// The point law at every depth maximum minus the point law at every
    /// interior depth minimum: continuous in the pose, the gradient of an
    /// energy, independent of the sample count.
    #[default]
    LevelSets,
    /// One point law per contact patch at its deepest point, acting at the
    /// patch's sampled centroid (MSC Adams' solid contact; jumps when
    /// patches merge or split). For comparison.
    Patches,
}

impl ContactSpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::text("name", "pair name in the output; default \"<a>/<b>\""),
        FieldDoc::text("bodies", "the two bodies [a, b]; normals point from a to b"),
        FieldDoc::law("normal", "normal force law", law_field),
        FieldDoc::law("friction", "friction law; none: frictionless", law_field),
        FieldDoc::table(
            "geometry",
            "explicit contact geometry; none: the bodies' shapes decide",
            FeatureSpec::FIELDS,
        ),
        FieldDoc::number(
            "points",
            "-",
            "sample points along a cylinder's axis for cylinder-tube contact",
        ),
        FieldDoc::text(
            "line_law",
            "cylinder-tube line contact as points: level-sets (continuous) or patches (Adams, jumps)",
        ),
    ];

    /// The pair's name in outputs.
    pub fn pair_name(&self) -> String {
        self.name
            .clone()
            .unwrap_or_else(|| format!("{}/{}", self.bodies[0], self.bodies[1]))
    }

    /// Checks the sample count, the bodies (existing, two), the feature's
    /// dimensions and the laws' parameters. Whether the geometry fits the
    /// bodies' shapes is checked at assembly.
    pub(super) fn validate(&self, path: &str, scene: &Scene) -> Result<(), SceneError> {
        if !(2..=64).contains(&self.points) {
            return Err(SceneError::new(
                format!("{path}.points"),
                self.points,
                "must lie in 2..=64 (2 = both end rims)",
            ));
        }
        let mut idx = [0usize; 2];
        for (k, name) in self.bodies.iter().enumerate() {
            idx[k] = scene.body_id(&format!("{path}.bodies[{k}]"), name)?;
        }
        if idx[0] == idx[1] {
            return Err(SceneError::new(
                format!("{path}.bodies"),
                format!("{:?}", self.bodies),
                "a body cannot touch itself",
            ));
        }
        if let Some(feature) = &self.geometry {
            feature.validate(&format!("{path}.geometry"))?;
        }
        self.normal.validate(&format!("{path}.normal"))?;
        if let Some(f) = &self.friction {
            f.validate(&format!("{path}.friction"))?;
        }
        Ok(())
    }
}
