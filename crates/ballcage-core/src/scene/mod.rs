//! What the user asks for: plain serde data, no physics.
//!
//! A scene is read from TOML text or from any serde value (the Python binding
//! passes a dict), optionally patched with `dotted.key=value` overrides, then
//! validated here, in one place. Every error names the field
//! ([`SceneError::path`]). All quantities are SI unless a field says otherwise;
//! the only non-SI input is a normal law declared with `units = "N-mm-s"`
//! (the paper's field units), converted once in [`NormalLawSpec::to_law`].

mod body;
mod contact;
mod joint;
mod load;
mod overrides;

pub use body::{BodySpec, MotionKind, ShapeSpec, TubeSegmentSpec};
pub use contact::{ContactSpec, FeatureSpec, FieldUnits, FrictionLawSpec, NormalLawSpec};
pub use joint::JointSpec;
pub use load::LoadSpec;
pub use overrides::apply_override;

use serde::{Deserialize, Serialize};

use crate::error::SceneError;

/// Which fixed-step integrator advances the state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum IntegratorKind {
    /// Semi-implicit (symplectic) Euler: velocities first, then positions
    /// with the new velocities; quaternions by the exact exponential map.
    /// First order, one force evaluation per step.
    SymplecticEuler,
    /// Classical fourth-order Runge–Kutta; rotations by Runge–Kutta–Munthe-Kaas
    /// on the rotation vector, so quaternions stay on the manifold.
    /// Four force evaluations per step.
    #[default]
    Rk4,
    /// Linearly implicit (Rosenbrock–Euler) step, implicit in the
    /// velocity-dependent forces (contact damping, friction, joint dampers)
    /// through their analytic velocity Jacobian, explicit in the elastic and
    /// gyroscopic terms; positions and rotations as in symplectic Euler. One
    /// force evaluation and one sparse LU solve per step.
    LinearlyImplicitEuler,
    /// Two-stage singly diagonally implicit Runge–Kutta (Alexander's SDIRK2,
    /// γ = 1 − 1/√2): second order, L-stable and stiffly accurate; implicit
    /// in every force (elastic, damping, friction, joints), solved per stage
    /// by simplified Newton iterations on the velocity twists with the
    /// analytic Jacobian D + γh·K ([`NewtonSpec`]), its LU factorization
    /// reused across iterations, stages and steps while Newton converges fast.
    Sdirk2,
}

impl IntegratorKind {
    /// The name used in scene files and output metadata.
    pub fn name(self) -> &'static str {
        match self {
            Self::SymplecticEuler => "symplectic-euler",
            Self::Rk4 => "rk4",
            Self::LinearlyImplicitEuler => "linearly-implicit-euler",
            Self::Sdirk2 => "sdirk2",
        }
    }

    /// Every integrator, in the order of the docs.
    pub const ALL: [Self; 4] = [
        Self::SymplecticEuler,
        Self::Rk4,
        Self::LinearlyImplicitEuler,
        Self::Sdirk2,
    ];

    /// Whether the step solves a linear system (the implicit integrators).
    pub fn is_implicit(self) -> bool {
        matches!(self, Self::LinearlyImplicitEuler | Self::Sdirk2)
    }
}

/// Newton iterations of the `sdirk2` integrator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct NewtonSpec {
    /// Convergence tolerance on the velocity-twist increments, relative to
    /// |v| + 1 m/s (rad/s for rotations) [–]: a stage has converged when the
    /// estimated remaining error θ/(1 − θ)·‖Δ‖ of the contracting iteration
    /// is below it (θ the contraction rate). The error left in each step's
    /// velocities acts like a force error of about m·tolerance/h, so it must
    /// stay well below the step's own error. Default 1e-8.
    pub tolerance: f64,
    /// Iterations allowed per stage; a stage that has not converged by then
    /// fails the step with a divergence error. Default 20.
    pub max_iterations: u32,
    /// Keep the factorized Jacobian from step to step while Newton converges
    /// within `reuse_iterations` iterations per stage; re-evaluate it
    /// otherwise (and at once, at the current iterate, when the contraction
    /// rate exceeds 0.3). `false` refreshes it at the start of every step.
    /// Default true.
    pub reuse_jacobian: bool,
    /// See `reuse_jacobian`. Default 3.
    pub reuse_iterations: u32,
}

impl Default for NewtonSpec {
    fn default() -> Self {
        Self {
            tolerance: 1e-8,
            max_iterations: 20,
            reuse_jacobian: true,
            reuse_iterations: 3,
        }
    }
}

/// When a run is stopped as diverged (besides a non-finite state).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DivergenceSpec {
    /// Largest allowed penetration as a fraction of the pair's smallest
    /// contacting radius (ball, cylinder or groove radius, smallest cuboid
    /// half-extent) [–]. PROPOSAL: 0.25; the paper's most loaded ball key
    /// reaches about 0.05.
    pub penetration_fraction: f64,
    /// Largest allowed penetration [m], replacing `penetration_fraction` for
    /// every pair when set.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_penetration: Option<f64>,
    /// Largest allowed energy created by the integrator: the run stops when
    /// E(t) − E(0) − W_in(t) (mechanical energy gained beyond the work of the
    /// drives and applied torques) exceeds this fraction of the energy scale
    /// KE(0) + E_contact(0) + max|ΔPE_gravity| + ∫|P_in| dt (the most the
    /// system could hold), checked at every recorded frame [–]. PROPOSAL:
    /// 1.0 — the integrator has made as much energy again as the system
    /// holds or was given; a diverging run passes that within a few steps,
    /// while a stable explicit run near its step limit (symplectic Euler's
    /// energy swings by up to 1/(1 − (hω/2)²)) does not.
    pub energy_growth: f64,
}

impl Default for DivergenceSpec {
    fn default() -> Self {
        Self {
            penetration_fraction: 0.25,
            max_penetration: None,
            energy_growth: 1.0,
        }
    }
}

/// Time stepping.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    /// Simulated duration [s].
    pub duration: f64,
    /// Integrator step [s].
    pub dt: f64,
    /// Interval between recorded frames [s]; an integer multiple of `dt`.
    pub output_interval: f64,
    /// Integrator.
    #[serde(default)]
    pub integrator: IntegratorKind,
    /// Newton iterations of the `sdirk2` integrator.
    #[serde(default)]
    pub newton: NewtonSpec,
    /// Divergence detection.
    #[serde(default)]
    pub divergence: DivergenceSpec,
}

/// Global fields.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// Gravitational acceleration [m/s²], world frame.
    #[serde(default)]
    pub gravity: [f64; 3],
}

impl Default for WorldSpec {
    fn default() -> Self {
        Self { gravity: [0.0; 3] }
    }
}

/// Output tables a scene can ask for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TableKind {
    /// Body poses and velocities, one row per recorded body per frame.
    Bodies,
    /// Contact points in contact, one row per point per frame.
    Contacts,
    /// Energy balance per frame.
    Energy,
    /// Per-pair peak, mean and RMS of normal and tangential force over `record.summary_window`.
    Summary,
    /// Drill pipe: per link per frame, the paper's eq. (4) angles and position.
    Links,
    /// Drill pipe: per hinge per frame, bend angle and cage forces.
    Hinges,
    /// Drill pipe: per ball key per frame, race and window forces.
    Keys,
    /// Drill pipe: per frame, input/output torque, speed, power and efficiency.
    Drive,
}

impl TableKind {
    /// Table name, also the Parquet file stem.
    pub fn name(self) -> &'static str {
        match self {
            Self::Bodies => "bodies",
            Self::Contacts => "contacts",
            Self::Energy => "energy",
            Self::Summary => "summary",
            Self::Links => "links",
            Self::Hinges => "hinges",
            Self::Keys => "keys",
            Self::Drive => "drive",
        }
    }

    /// Every table kind.
    pub const ALL: [TableKind; 8] = [
        Self::Bodies,
        Self::Contacts,
        Self::Energy,
        Self::Summary,
        Self::Links,
        Self::Hinges,
        Self::Keys,
        Self::Drive,
    ];

    /// The kind named `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// Whether only drill-pipe scenes can record it.
    pub fn needs_drill_pipe(self) -> bool {
        matches!(self, Self::Links | Self::Hinges | Self::Keys | Self::Drive)
    }
}

/// What to record. Nothing else is computed for output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordSpec {
    /// Tables to produce.
    #[serde(default = "default_tables")]
    pub tables: Vec<TableKind>,
    /// Bodies recorded in `bodies`; empty means every non-fixed body.
    #[serde(default)]
    pub bodies: Vec<String>,
    /// Contact pairs recorded in `contacts`; empty means every pair.
    #[serde(default)]
    pub contacts: Vec<String>,
    /// Time window `[start, end]` of the `summary` table [s]; empty means the whole run.
    #[serde(default)]
    pub summary_window: Vec<f64>,
}

fn default_tables() -> Vec<TableKind> {
    vec![TableKind::Bodies, TableKind::Contacts]
}

impl Default for RecordSpec {
    fn default() -> Self {
        Self {
            tables: default_tables(),
            bodies: vec![],
            contacts: vec![],
            summary_window: vec![],
        }
    }
}

/// A complete scene: bodies, contacts, loads, time stepping and recording.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// Free-form scene name, copied into the output metadata.
    #[serde(default)]
    pub name: String,
    /// Time stepping.
    pub simulation: SimulationSpec,
    /// Gravity.
    #[serde(default)]
    pub world: WorldSpec,
    /// What to record.
    #[serde(default)]
    pub record: RecordSpec,
    /// Bodies, in order; the order fixes body ids.
    pub bodies: Vec<BodySpec>,
    /// Declared contact pairs; no other pair is ever tested.
    #[serde(default)]
    pub contacts: Vec<ContactSpec>,
    /// Applied loads.
    #[serde(default)]
    pub loads: Vec<LoadSpec>,
    /// Penalty joints.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joints: Vec<JointSpec>,
    /// The higher-level spec this scene was expanded from, if any; it is what
    /// [`Scene::to_toml`] writes back.
    #[serde(skip)]
    pub origin: Option<Box<crate::drillpipe::DrillPipeSpec>>,
}

impl Scene {
    /// Parses TOML text, applies `dotted.key=value` overrides, and validates.
    pub fn from_toml_str(text: &str, overrides: &[String]) -> Result<Self, SceneError> {
        let table: toml::Table = text.parse().map_err(|e: toml::de::Error| {
            SceneError::new(toml_error_path(&e, text), "", first_line(e.message()))
        })?;
        Self::from_table(table, overrides)
    }

    /// Builds a scene from a TOML table (any serde source converts to one),
    /// applies overrides, deserializes with field paths, and validates.
    ///
    /// A table with `kind = "drill-pipe"` (or, without `kind` and without
    /// `bodies`, with a `pipe`, `borehole` or `drive` section) is a
    /// [`DrillPipeSpec`](crate::drillpipe::DrillPipeSpec), expanded here.
    pub fn from_table(table: toml::Table, overrides: &[String]) -> Result<Self, SceneError> {
        let drill_pipe = match table.get("kind") {
            Some(toml::Value::String(k)) if k == crate::drillpipe::KIND => true,
            Some(toml::Value::String(k)) if k == "generic" => false,
            Some(other) => {
                return Err(SceneError::new(
                    "kind",
                    other,
                    format!(
                        "unknown scene kind (kinds: \"generic\", \"{}\")",
                        crate::drillpipe::KIND
                    ),
                ));
            }
            None => {
                !table.contains_key("bodies")
                    && ["pipe", "borehole", "drive"]
                        .iter()
                        .any(|k| table.contains_key(*k))
            }
        };
        let mut root = if drill_pipe {
            // Sections and fields left out take the paper's values.
            let mut base = toml::Value::try_from(crate::drillpipe::DrillPipeSpec::default())
                .map_err(|e| SceneError::new("", "", format!("default drill-pipe scene: {e}")))?;
            merge(&mut base, toml::Value::Table(table));
            base
        } else {
            let mut t = table;
            t.remove("kind");
            toml::Value::Table(t)
        };
        for o in overrides {
            apply_override(&mut root, o)?;
        }
        if drill_pipe {
            let spec: crate::drillpipe::DrillPipeSpec = deserialize_with_path(root)?;
            return spec.expand();
        }
        let scene: Scene = deserialize_with_path(root)?;
        scene.validate()?;
        Ok(scene)
    }

    /// The scene as TOML, with every default written out; a scene expanded
    /// from a drill-pipe spec is written as that spec.
    pub fn to_toml(&self) -> String {
        if let Some(origin) = &self.origin {
            return origin.to_toml();
        }
        // Serializing plain data with finite numbers cannot fail.
        toml::to_string_pretty(self)
            .unwrap_or_else(|e| format!("# scene could not be written: {e}\n"))
    }

    /// Index of the body named `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// Checks every value; the first problem found is returned with its path.
    pub fn validate(&self) -> Result<(), SceneError> {
        let s = &self.simulation;
        positive("simulation.duration", s.duration)?;
        positive("simulation.dt", s.dt)?;
        positive("simulation.output_interval", s.output_interval)?;
        if s.dt > s.duration {
            return Err(SceneError::new(
                "simulation.dt",
                s.dt,
                format!("step longer than the duration {} s", s.duration),
            ));
        }
        let ratio = s.output_interval / s.dt;
        if (ratio - ratio.round()).abs() > 1e-6 * ratio.max(1.0) || ratio.round() < 1.0 {
            return Err(SceneError::new(
                "simulation.output_interval",
                s.output_interval,
                format!(
                    "must be a whole multiple (≥ 1) of simulation.dt = {} s",
                    s.dt
                ),
            ));
        }
        positive("simulation.newton.tolerance", s.newton.tolerance)?;
        if s.newton.max_iterations == 0 {
            return Err(SceneError::new(
                "simulation.newton.max_iterations",
                0,
                "must be at least 1",
            ));
        }
        positive(
            "simulation.divergence.penetration_fraction",
            s.divergence.penetration_fraction,
        )?;
        if let Some(d) = s.divergence.max_penetration {
            positive("simulation.divergence.max_penetration", d)?;
        }
        positive(
            "simulation.divergence.energy_growth",
            s.divergence.energy_growth,
        )?;
        finite_vec("world.gravity", &self.world.gravity)?;
        if self.bodies.is_empty() {
            return Err(SceneError::new(
                "bodies",
                "[]",
                "a scene needs at least one body",
            ));
        }
        for (i, b) in self.bodies.iter().enumerate() {
            b.validate(&format!("bodies[{i}]"))?;
            if self.bodies[..i].iter().any(|o| o.name == b.name) {
                return Err(SceneError::new(
                    format!("bodies[{i}].name"),
                    &b.name,
                    "duplicate body name",
                ));
            }
        }
        for (i, c) in self.contacts.iter().enumerate() {
            c.validate(&format!("contacts[{i}]"), self)?;
        }
        let names: Vec<String> = self.contacts.iter().map(|c| c.pair_name()).collect();
        for (i, n) in names.iter().enumerate() {
            if names[..i].contains(n) {
                return Err(SceneError::new(
                    format!("contacts[{i}].name"),
                    n,
                    "duplicate contact pair name",
                ));
            }
        }
        for (i, l) in self.loads.iter().enumerate() {
            l.validate(&format!("loads[{i}]"), self)?;
        }
        for (i, j) in self.joints.iter().enumerate() {
            j.validate(&format!("joints[{i}]"), self)?;
        }
        for (i, t) in self.record.tables.iter().enumerate() {
            if t.needs_drill_pipe() && self.origin.is_none() {
                return Err(SceneError::new(
                    format!("record.tables[{i}]"),
                    t.name(),
                    "only drill-pipe scenes (kind = \"drill-pipe\") have this table",
                ));
            }
            if self.record.tables[..i].contains(t) {
                return Err(SceneError::new(
                    format!("record.tables[{i}]"),
                    t.name(),
                    "listed twice",
                ));
            }
        }
        let w = &self.record.summary_window;
        if !w.is_empty() {
            if w.len() != 2 {
                return Err(SceneError::new(
                    "record.summary_window",
                    format!("{w:?}"),
                    "give [start, end] in seconds",
                ));
            }
            non_negative("record.summary_window[0]", w[0])?;
            finite("record.summary_window[1]", w[1])?;
            if w[1] <= w[0] {
                return Err(SceneError::new(
                    "record.summary_window[1]",
                    w[1],
                    format!("must exceed the start {} s", w[0]),
                ));
            }
        }
        for (i, n) in self.record.bodies.iter().enumerate() {
            if self.body_index(n).is_none() {
                return Err(SceneError::new(
                    format!("record.bodies[{i}]"),
                    n,
                    "no body of that name",
                ));
            }
        }
        for (i, n) in self.record.contacts.iter().enumerate() {
            if !names.contains(n) {
                return Err(SceneError::new(
                    format!("record.contacts[{i}]"),
                    n,
                    "no contact pair of that name",
                ));
            }
        }
        Ok(())
    }

    /// Number of integrator steps per recorded frame.
    pub fn steps_per_output(&self) -> u64 {
        (self.simulation.output_interval / self.simulation.dt).round() as u64
    }

    /// Total number of integrator steps.
    pub fn total_steps(&self) -> u64 {
        let n = (self.simulation.duration / self.simulation.dt).round() as u64;
        n.max(1)
    }
}

/// Writes `over` onto `base`: tables merge key by key, anything else
/// replaces. A table whose tag (`law` or `type`) differs replaces whole, so a
/// different law does not inherit the old law's parameters.
fn merge(base: &mut toml::Value, over: toml::Value) {
    match (base, over) {
        (toml::Value::Table(b), toml::Value::Table(o)) => {
            let retagged = ["law", "type"]
                .iter()
                .any(|tag| matches!((b.get(*tag), o.get(*tag)), (Some(x), Some(y)) if x != y));
            if retagged {
                *b = o;
                return;
            }
            for (k, v) in o {
                match b.get_mut(&k) {
                    Some(slot) => merge(slot, v),
                    None => {
                        b.insert(k, v);
                    }
                }
            }
        }
        (b, o) => *b = o,
    }
}

/// Deserializes with the path of the offending field in the error.
fn deserialize_with_path<T: serde::de::DeserializeOwned>(
    root: toml::Value,
) -> Result<T, SceneError> {
    serde_path_to_error::deserialize(root).map_err(|e| {
        let mut path = e.path().to_string();
        if path == "." {
            path.clear();
        }
        let reason = first_line(&e.into_inner().to_string());
        // serde reports a missing field at its parent: name the field itself.
        if let Some(field) = reason
            .strip_prefix("missing field `")
            .and_then(|r| r.split('`').next())
        {
            path = if path.is_empty() {
                field.to_string()
            } else {
                format!("{path}.{field}")
            };
        }
        SceneError::new(path, "", reason)
    })
}

fn first_line(s: &str) -> String {
    s.lines().next().unwrap_or("").trim().to_string()
}

fn toml_error_path(e: &toml::de::Error, text: &str) -> String {
    match e.span() {
        Some(span) => {
            let line = text[..span.start.min(text.len())].matches('\n').count() + 1;
            format!("<toml line {line}>")
        }
        None => "<toml>".to_string(),
    }
}

/// Rejects non-finite and non-positive values.
pub(crate) fn positive(path: &str, v: f64) -> Result<(), SceneError> {
    if !v.is_finite() {
        return Err(SceneError::new(path, v, "must be a finite number"));
    }
    if v <= 0.0 {
        return Err(SceneError::new(path, v, "must be positive"));
    }
    Ok(())
}

/// Rejects non-finite and negative values.
pub(crate) fn non_negative(path: &str, v: f64) -> Result<(), SceneError> {
    if !v.is_finite() {
        return Err(SceneError::new(path, v, "must be a finite number"));
    }
    if v < 0.0 {
        return Err(SceneError::new(path, v, "must not be negative"));
    }
    Ok(())
}

/// Rejects non-finite values.
pub(crate) fn finite(path: &str, v: f64) -> Result<(), SceneError> {
    if !v.is_finite() {
        return Err(SceneError::new(path, v, "must be a finite number"));
    }
    Ok(())
}

/// Rejects vectors with a non-finite component.
pub(crate) fn finite_vec(path: &str, v: &[f64]) -> Result<(), SceneError> {
    for (i, x) in v.iter().enumerate() {
        finite(&format!("{path}[{i}]"), *x)?;
    }
    Ok(())
}

/// Rejects vectors that are not finite or have (near) zero length.
pub(crate) fn direction(path: &str, v: &[f64; 3]) -> Result<(), SceneError> {
    finite_vec(path, v)?;
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    if n < 1e-12 {
        return Err(SceneError::new(
            path,
            format!("{v:?}"),
            "must be a non-zero direction",
        ));
    }
    Ok(())
}
