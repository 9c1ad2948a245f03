//! Body declarations: shape, mass, initial state and how the body may move.

use serde::{Deserialize, Serialize};

use super::fields::FieldDoc;
use super::{Scene, direction, finite_vec, non_negative, positive};
use crate::error::SceneError;

/// How a body moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum MotionKind {
    /// Never moves.
    Fixed,
    /// Six degrees of freedom.
    #[default]
    Dynamic,
    /// Prescribed spin about `spin_axis` through its centre of mass, at
    /// `spin_speed` reached by an Adams STEP ramp over `spin_ramp` (a drive).
    KinematicSpin,
    /// Dynamic, but free only to spin about `spin_axis` through its fixed
    /// centre of mass (a connector on a rotating pair).
    Spin,
    /// Dynamic, free to spin about `spin_axis` and to slide along it (a
    /// cylindrical joint to the ground: a connector whose centre of mass
    /// moves only along the axis, e.g. to carry an axial force).
    SpinSlide,
    /// Not integrated: at every force evaluation its pose is solved for
    /// static equilibrium with the bodies outside its group held (a group:
    /// quasi-static bodies joined by contact pairs), and it moves with the
    /// mean of their rigid motions; it acts on them as a force element
    /// (issue 28's quasi-static hinge: the cage).
    QuasiStatic,
    /// As `quasi-static`, its position only solved for, its orientation
    /// kept (a ball, whose turn carries no load without friction: a key).
    QuasiStaticPosition,
}

/// A body's shape, in its body frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum ShapeSpec {
    /// Solid sphere centred at the body origin.
    Ball {
        /// Radius [m].
        radius: f64,
    },
    /// Box centred at the body origin.
    Cuboid {
        /// Half-extents along the body x, y, z axes [m].
        half_extents: [f64; 3],
    },
    /// Half-space whose boundary plane passes through the body origin.
    HalfSpace {
        /// Outward normal of the boundary (pointing out of the solid), body frame.
        normal: [f64; 3],
    },
    /// Cylinder along the body x axis, centred at the body origin. Contact
    /// uses the outer surface; `inner_radius` only hollows the mass.
    Cylinder {
        /// Outer radius [m].
        radius: f64,
        /// Half of the length [m].
        half_length: f64,
        /// Bore radius for mass properties [m]; 0 for a solid cylinder.
        #[serde(default)]
        inner_radius: f64,
    },
    /// The inside of a tube around a centreline of straight and circular-arc
    /// segments (body frame). Contacts are analytic: no mesh.
    Tube {
        /// Inner (lumen) radius [m].
        inner_radius: f64,
        /// Centreline start point [m].
        start: [f64; 3],
        /// Centreline direction at the start.
        direction: [f64; 3],
        /// Centreline segments, in order from the start.
        segments: Vec<TubeSegmentSpec>,
        /// Length [m] of a body's part inside over which its wall contact
        /// is taken up where it crosses an open end (0: at once, a jump as
        /// its last section leaves the tube while pressing the wall).
        #[serde(default = "default_end_engagement")]
        end_engagement: f64,
    },
}

/// [`ShapeSpec::Tube`]'s `end_engagement` when not given [m]
/// (docs/model.md §4, "The tube's open ends").
pub const DEFAULT_END_ENGAGEMENT: f64 = 0.002;

fn default_end_engagement() -> f64 {
    DEFAULT_END_ENGAGEMENT
}

/// One piece of a tube centreline.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "kebab-case", deny_unknown_fields)]
pub enum TubeSegmentSpec {
    /// Straight piece along the current direction.
    Straight {
        /// Length [m].
        length: f64,
    },
    /// Circular arc turning the current direction toward `bend`.
    Arc {
        /// Centreline curvature radius [m].
        radius: f64,
        /// Turned angle [deg].
        angle_deg: f64,
        /// Direction toward the arc's centre; its part across the current
        /// direction is used.
        bend: [f64; 3],
    },
}

impl ShapeSpec {
    /// The unit and meaning of each field, of every shape type.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::text(
            "type",
            "the shape: ball, cuboid, half-space, cylinder or tube",
        ),
        FieldDoc::number(
            "radius",
            "m",
            "radius of a ball; outer radius of a cylinder",
        ),
        FieldDoc::number(
            "half_extents",
            "m",
            "half-extents of a cuboid along the body x, y, z axes",
        ),
        FieldDoc::number(
            "normal",
            "-",
            "outward normal of a half-space's boundary, body frame",
        ),
        FieldDoc::number("half_length", "m", "half of a cylinder's length"),
        FieldDoc::number(
            "inner_radius",
            "m",
            "bore radius of a cylinder (mass only); lumen radius of a tube",
        ),
        FieldDoc::number("start", "m", "a tube centreline's start point, body frame"),
        FieldDoc::number(
            "direction",
            "-",
            "a tube centreline's direction at its start, body frame",
        ),
        FieldDoc::tables(
            "segments",
            "a tube centreline's segments, in order from its start",
            TubeSegmentSpec::FIELDS,
        ),
        FieldDoc::number(
            "end_engagement",
            "m",
            "a tube's open ends: length of a body's part inside over which its wall contact is \
             taken up (an Adams STEP from 0; 0 = at once, a jump)",
        ),
    ];

    /// Short name for messages.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Self::Ball { .. } => "ball",
            Self::Cuboid { .. } => "cuboid",
            Self::HalfSpace { .. } => "half-space",
            Self::Cylinder { .. } => "cylinder",
            Self::Tube { .. } => "tube",
        }
    }

    /// Whether the shape has a finite volume (and so a mass from a density).
    pub fn is_solid(&self) -> bool {
        matches!(
            self,
            Self::Ball { .. } | Self::Cuboid { .. } | Self::Cylinder { .. }
        )
    }

    /// Mass [kg] and principal body-frame inertia [kg·m²] at unit density.
    pub fn unit_density_mass_properties(&self) -> Option<(f64, [f64; 3])> {
        use std::f64::consts::PI;
        match *self {
            Self::Ball { radius: r } => {
                let m = 4.0 / 3.0 * PI * r.powi(3);
                let i = 0.4 * m * r * r;
                Some((m, [i; 3]))
            }
            Self::Cuboid {
                half_extents: [a, b, c],
            } => {
                let m = 8.0 * a * b * c;
                Some((
                    m,
                    [
                        m / 3.0 * (b * b + c * c),
                        m / 3.0 * (a * a + c * c),
                        m / 3.0 * (a * a + b * b),
                    ],
                ))
            }
            Self::Cylinder {
                radius: r,
                half_length: h,
                inner_radius: ri,
            } => {
                let m = PI * (r * r - ri * ri) * 2.0 * h;
                let axial = 0.5 * m * (r * r + ri * ri);
                let transverse = m / 12.0 * (3.0 * (r * r + ri * ri) + 4.0 * h * h);
                Some((m, [axial, transverse, transverse]))
            }
            Self::HalfSpace { .. } | Self::Tube { .. } => None,
        }
    }

    fn validate(&self, path: &str) -> Result<(), SceneError> {
        match self {
            Self::Ball { radius } => positive(&format!("{path}.radius"), *radius),
            Self::Cuboid { half_extents } => {
                for (i, h) in half_extents.iter().enumerate() {
                    positive(&format!("{path}.half_extents[{i}]"), *h)?;
                }
                Ok(())
            }
            Self::HalfSpace { normal } => direction(&format!("{path}.normal"), normal),
            Self::Cylinder {
                radius,
                half_length,
                inner_radius,
            } => {
                positive(&format!("{path}.radius"), *radius)?;
                positive(&format!("{path}.half_length"), *half_length)?;
                non_negative(&format!("{path}.inner_radius"), *inner_radius)?;
                if inner_radius >= radius {
                    return Err(SceneError::new(
                        format!("{path}.inner_radius"),
                        inner_radius,
                        "must be smaller than radius",
                    ));
                }
                Ok(())
            }
            Self::Tube {
                inner_radius,
                start,
                direction: dir,
                segments,
                end_engagement,
            } => {
                positive(&format!("{path}.inner_radius"), *inner_radius)?;
                non_negative(&format!("{path}.end_engagement"), *end_engagement)?;
                finite_vec(&format!("{path}.start"), start)?;
                direction(&format!("{path}.direction"), dir)?;
                if segments.is_empty() {
                    return Err(SceneError::new(
                        format!("{path}.segments"),
                        "[]",
                        "a tube needs at least one segment",
                    ));
                }
                for (i, s) in segments.iter().enumerate() {
                    s.validate(&format!("{path}.segments[{i}]"))?;
                }
                Ok(())
            }
        }
    }
}

impl TubeSegmentSpec {
    /// The unit and meaning of each field, of both segment types.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::text("type", "the segment: straight or arc"),
        FieldDoc::number("length", "m", "length of a straight segment"),
        FieldDoc::number("radius", "m", "centreline curvature radius of an arc"),
        FieldDoc::number("angle_deg", "deg", "angle an arc turns"),
        FieldDoc::number(
            "bend",
            "-",
            "direction toward an arc's centre (its part across the current direction)",
        ),
    ];

    /// Checks lengths, radii and angles.
    fn validate(&self, p: &str) -> Result<(), SceneError> {
        match self {
            Self::Straight { length } => positive(&format!("{p}.length"), *length),
            Self::Arc {
                radius,
                angle_deg,
                bend,
            } => {
                positive(&format!("{p}.radius"), *radius)?;
                positive(&format!("{p}.angle_deg"), *angle_deg)?;
                if *angle_deg >= 360.0 {
                    return Err(SceneError::new(
                        format!("{p}.angle_deg"),
                        angle_deg,
                        "must be below 360",
                    ));
                }
                direction(&format!("{p}.bend"), bend)
            }
        }
    }
}

fn default_orientation() -> [f64; 4] {
    [1.0, 0.0, 0.0, 0.0]
}

fn is_zero3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| *x == 0.0)
}

/// A body: shape, mass properties, initial state, motion.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    /// Unique name.
    pub name: String,
    /// How the body moves.
    #[serde(default)]
    pub motion: MotionKind,
    /// Shape in the body frame (the body frame is the principal inertia frame,
    /// centred at the centre of mass).
    pub shape: ShapeSpec,
    /// Mass [kg]; alternative to `density`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mass: Option<f64>,
    /// Density [kg/m³]; mass and inertia follow from the shape.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// Principal moments of inertia about the body x, y, z axes [kg·m²];
    /// needs `mass`. Without it the shape's uniform-density inertia is scaled to `mass`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inertia: Option<[f64; 3]>,
    /// Initial position of the centre of mass [m], world frame.
    #[serde(default)]
    pub position: [f64; 3],
    /// Initial orientation, unit quaternion `[w, x, y, z]`, body → world.
    #[serde(default = "default_orientation")]
    pub orientation: [f64; 4],
    /// Initial velocity [m/s], world frame.
    #[serde(default, skip_serializing_if = "is_zero3")]
    pub velocity: [f64; 3],
    /// Initial angular velocity [rad/s], world frame.
    #[serde(default, skip_serializing_if = "is_zero3")]
    pub angular_velocity: [f64; 3],
    /// Spin axis (world frame, through the centre of mass) for the
    /// `kinematic-spin`, `spin` and `spin-slide` motions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spin_axis: Option<[f64; 3]>,
    /// Final spin speed of a `kinematic-spin` body [rad/s], positive about `spin_axis`.
    #[serde(default)]
    pub spin_speed: f64,
    /// Duration of the STEP ramp from rest to `spin_speed` [s]; 0 starts at full speed.
    #[serde(default)]
    pub spin_ramp: f64,
}

impl BodySpec {
    /// The unit and meaning of each field.
    pub const FIELDS: &'static [FieldDoc] = &[
        FieldDoc::text("name", "unique body name"),
        FieldDoc::text(
            "motion",
            "how the body moves: fixed, dynamic, kinematic-spin, spin, spin-slide, quasi-static or quasi-static-position",
        ),
        FieldDoc::table(
            "shape",
            "shape in the body frame (principal axes, centred at the centre of mass)",
            ShapeSpec::FIELDS,
        ),
        FieldDoc::number("mass", "kg", "mass; alternative to density"),
        FieldDoc::number(
            "density",
            "kg/m³",
            "density; mass and inertia follow from the shape",
        ),
        FieldDoc::number(
            "inertia",
            "kg·m²",
            "principal moments of inertia about the body x, y, z axes",
        ),
        FieldDoc::number(
            "position",
            "m",
            "initial position of the centre of mass, world frame",
        ),
        FieldDoc::number(
            "orientation",
            "-",
            "initial orientation, unit quaternion [w, x, y, z], body to world",
        ),
        FieldDoc::number("velocity", "m/s", "initial velocity, world frame"),
        FieldDoc::number(
            "angular_velocity",
            "rad/s",
            "initial angular velocity, world frame",
        ),
        FieldDoc::number(
            "spin_axis",
            "-",
            "spin axis through the centre of mass (kinematic-spin, spin and spin-slide motions), world frame",
        ),
        FieldDoc::number(
            "spin_speed",
            "rad/s",
            "final spin speed of a kinematic-spin body about spin_axis",
        ),
        FieldDoc::number(
            "spin_ramp",
            "s",
            "duration of the STEP ramp from rest to spin_speed",
        ),
    ];

    /// Whether the body carries integrated state.
    pub fn is_integrated(&self) -> bool {
        matches!(
            self.motion,
            MotionKind::Dynamic | MotionKind::Spin | MotionKind::SpinSlide
        )
    }

    /// Mass [kg] and principal inertia [kg·m²], for bodies that need them.
    pub fn mass_properties(&self) -> Option<(f64, [f64; 3])> {
        if let Some(rho) = self.density {
            let (m, i) = self.shape.unit_density_mass_properties()?;
            return Some((rho * m, i.map(|x| x * rho)));
        }
        let m = self.mass?;
        if let Some(i) = self.inertia {
            return Some((m, i));
        }
        let (m1, i1) = self.shape.unit_density_mass_properties()?;
        // a shape so small that its unit-density mass underflows has no inertia to scale
        (m1 > 0.0 && m1.is_finite()).then(|| (m, i1.map(|x| x * m / m1)))
    }

    /// Checks every field; the first problem found is returned with its path.
    pub(super) fn validate(&self, path: &str) -> Result<(), SceneError> {
        if self.name.trim().is_empty() {
            return Err(SceneError::new(
                format!("{path}.name"),
                "\"\"",
                "must not be empty",
            ));
        }
        self.shape.validate(&format!("{path}.shape"))?;
        self.validate_initial_state(path)?;
        self.validate_mass(path)?;
        self.validate_motion(path)
    }

    /// Initial pose and velocities: finite, the orientation a unit quaternion.
    fn validate_initial_state(&self, path: &str) -> Result<(), SceneError> {
        finite_vec(&format!("{path}.position"), &self.position)?;
        finite_vec(&format!("{path}.orientation"), &self.orientation)?;
        let qn = self.orientation.iter().map(|x| x * x).sum::<f64>().sqrt();
        if (qn - 1.0).abs() > 1e-6 {
            return Err(SceneError::new(
                format!("{path}.orientation"),
                format!("{:?}", self.orientation),
                format!("must be a unit quaternion [w, x, y, z] (norm is {qn})"),
            ));
        }
        finite_vec(&format!("{path}.velocity"), &self.velocity)?;
        finite_vec(&format!("{path}.angular_velocity"), &self.angular_velocity)
    }

    /// Mass, density and inertia: positive, consistent with each other and
    /// with the shape.
    fn validate_mass(&self, path: &str) -> Result<(), SceneError> {
        if let Some(m) = self.mass {
            positive(&format!("{path}.mass"), m)?;
        }
        if let Some(rho) = self.density {
            positive(&format!("{path}.density"), rho)?;
            if self.mass.is_some() {
                return Err(SceneError::new(
                    format!("{path}.density"),
                    rho,
                    "give either mass or density, not both",
                ));
            }
            if !self.shape.is_solid() {
                return Err(SceneError::new(
                    format!("{path}.density"),
                    rho,
                    format!(
                        "a {} has no volume: give mass and inertia",
                        self.shape.kind_name()
                    ),
                ));
            }
        }
        if let Some(i) = self.inertia {
            for (k, x) in i.iter().enumerate() {
                positive(&format!("{path}.inertia[{k}]"), *x)?;
            }
            if self.mass.is_none() {
                return Err(SceneError::new(
                    format!("{path}.inertia"),
                    format!("{i:?}"),
                    "needs `mass` too",
                ));
            }
            // Triangle inequality of principal moments.
            let [a, b, c] = i;
            if a > b + c + 1e-12 * (a + b + c)
                || b > a + c + 1e-12 * (a + b + c)
                || c > a + b + 1e-12 * (a + b + c)
            {
                return Err(SceneError::new(
                    format!("{path}.inertia"),
                    format!("{i:?}"),
                    "principal moments violate the triangle inequality (no real body has them)",
                ));
            }
        }
        Ok(())
    }

    /// Whether the body is solved for static equilibrium at every evaluation.
    pub fn is_quasi_static(&self) -> bool {
        matches!(
            self.motion,
            MotionKind::QuasiStatic | MotionKind::QuasiStaticPosition
        )
    }

    /// Whether the body needs mass properties: integrated, or quasi-static
    /// (its weight is part of its equilibrium).
    pub fn needs_mass(&self) -> bool {
        self.is_integrated() || self.is_quasi_static()
    }

    /// What the motion needs: mass properties and no initial velocity
    /// unless integrated, a spin axis (and only then) for the spin motions.
    fn validate_motion(&self, path: &str) -> Result<(), SceneError> {
        if self.needs_mass() {
            if self.mass.is_none() && self.density.is_none() {
                return Err(SceneError::new(
                    format!("{path}.mass"),
                    "",
                    "missing: a moving body needs `mass` or `density`",
                ));
            }
            let Some((mass, inertia)) = self.mass_properties() else {
                return Err(SceneError::new(
                    format!("{path}.inertia"),
                    "",
                    format!(
                        "missing: a {} has no volume to derive inertia from (or one too small to compute)",
                        self.shape.kind_name()
                    ),
                ));
            };
            if !(mass > 0.0
                && mass.is_finite()
                && inertia.iter().all(|i| *i > 0.0 && i.is_finite()))
            {
                return Err(SceneError::new(
                    format!("{path}.shape"),
                    "",
                    format!(
                        "gives mass {mass:e} kg and inertia {inertia:?} kg·m²: not positive and finite (a shape \
                         too small or too large for its mass or density); give `inertia` or resize it"
                    ),
                ));
            }
        }
        if !self.is_integrated() && (!is_zero3(&self.velocity) || !is_zero3(&self.angular_velocity))
        {
            return Err(SceneError::new(
                format!("{path}.velocity"),
                format!("{:?}", self.velocity),
                "only dynamic bodies take an initial velocity",
            ));
        }
        match self.motion {
            MotionKind::KinematicSpin | MotionKind::Spin | MotionKind::SpinSlide => {
                let Some(axis) = &self.spin_axis else {
                    return Err(SceneError::new(
                        format!("{path}.spin_axis"),
                        "",
                        "missing: required by this motion",
                    ));
                };
                direction(&format!("{path}.spin_axis"), axis)?;
                super::finite(&format!("{path}.spin_speed"), self.spin_speed)?;
                non_negative(&format!("{path}.spin_ramp"), self.spin_ramp)
            }
            _ if self.spin_axis.is_some() => Err(SceneError::new(
                format!("{path}.spin_axis"),
                format!("{:?}", self.spin_axis.unwrap_or_default()),
                "only `kinematic-spin`, `spin` and `spin-slide` bodies take a spin axis",
            )),
            // NaN != 0 too: a stray value is refused, not kept in the scene unused
            _ if self.spin_speed != 0.0 || self.spin_ramp != 0.0 => Err(SceneError::new(
                format!(
                    "{path}.{}",
                    if self.spin_speed != 0.0 {
                        "spin_speed"
                    } else {
                        "spin_ramp"
                    }
                ),
                if self.spin_speed != 0.0 {
                    self.spin_speed
                } else {
                    self.spin_ramp
                },
                "only `kinematic-spin`, `spin` and `spin-slide` bodies take a spin speed and ramp",
            )),
            _ => Ok(()),
        }
    }
}

impl Scene {
    /// Id of the body named `name`; else the error "no body of that name"
    /// at `path`, the field that names it. The one name lookup of scenes
    /// and assembly.
    pub fn body_id(&self, path: &str, name: &str) -> Result<usize, SceneError> {
        self.body_index(name)
            .ok_or_else(|| SceneError::new(path, name, "no body of that name"))
    }
}
