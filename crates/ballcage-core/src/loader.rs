//! Reading a scene document of any kind: the one place where the kind is
//! chosen, and the one place that knows every kind.
//!
//! A document is TOML text or a table (from any serde source). Its `kind`
//! key picks the reader: `"generic"` (bodies, pairs, loads: [`Scene`]) or
//! `"drill-pipe"` ([`DrillPipeSpec`], expanded into a generic scene). A
//! document without `kind` is a drill pipe when it has no `bodies` but a
//! `pipe`, `borehole` or `drive` section, and generic otherwise. Sections and
//! fields a drill-pipe document leaves out take the paper's values.
//!
//! Loading validates, expands and assembles once: a [`Document`] holds the
//! assembled model, and every simulation of it starts from a copy.

use std::collections::HashMap;

use crate::assembly::{assemble, assemble_validated};
use crate::drillpipe::{self, DrillPipeSpec, Layout, PipeTables};
use crate::error::SceneError;
use crate::model::{Model, State};
use crate::record::{Observer, TableDef, table_def};
use crate::scene::{
    FieldUnits, Scene, TableKind, apply_override, deserialize_with_path, lookup, merge, parse_toml,
};
use crate::sim::Simulation;

/// The kinds of scene document.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Bodies, contact pairs, joints and loads, declared one by one.
    Generic,
    /// The ball-cage drill pipe, declared by its engineering parameters.
    DrillPipe,
}

impl Kind {
    /// Every kind.
    pub const ALL: [Kind; 2] = [Kind::Generic, Kind::DrillPipe];

    /// The `kind` key's value.
    pub fn name(self) -> &'static str {
        match self {
            Kind::Generic => "generic",
            Kind::DrillPipe => drillpipe::KIND,
        }
    }

    /// The kind a document table declares (or implies, without `kind`).
    fn of(table: &toml::Table) -> Result<Self, SceneError> {
        match table.get("kind") {
            Some(toml::Value::String(k)) => Self::ALL
                .into_iter()
                .find(|kind| kind.name() == k)
                .ok_or_else(|| unknown_kind(k)),
            Some(other) => Err(unknown_kind(other)),
            None if !table.contains_key("bodies")
                && ["pipe", "borehole", "drive"]
                    .iter()
                    .any(|k| table.contains_key(*k)) =>
            {
                Ok(Kind::DrillPipe)
            }
            None => Ok(Kind::Generic),
        }
    }
}

fn unknown_kind(value: impl std::fmt::Display) -> SceneError {
    let kinds: Vec<String> = Kind::ALL
        .iter()
        .map(|k| format!("\"{}\"", k.name()))
        .collect();
    SceneError::new(
        "kind",
        value,
        format!("unknown scene kind (kinds: {})", kinds.join(", ")),
    )
}

/// What a document was written as.
#[derive(Debug, Clone)]
enum Source {
    Generic,
    DrillPipe {
        spec: Box<DrillPipeSpec>,
        layout: Box<Layout>,
    },
}

/// A validated, expanded and assembled scene document.
#[derive(Debug, Clone)]
pub struct Document {
    source: Source,
    scene: Scene,
    model: Model,
    state: State,
}

impl Document {
    /// Parses TOML text, applies `dotted.key=value` overrides, validates,
    /// expands and assembles.
    pub fn from_toml_str(text: &str, overrides: &[String]) -> Result<Self, SceneError> {
        Self::from_table(parse_toml(text)?, overrides)
    }

    /// Reads a document table (see the module doc), applies overrides,
    /// validates, expands and assembles.
    pub fn from_table(mut table: toml::Table, overrides: &[String]) -> Result<Self, SceneError> {
        match Kind::of(&table)? {
            Kind::Generic => {
                table.remove("kind");
                // The reader validates; assembly does not do it again.
                let scene = Scene::from_table(table, overrides)?;
                let (model, state) = assemble_validated(&scene)?;
                Self::from_parts(Source::Generic, scene, model, state)
            }
            Kind::DrillPipe => {
                // Sections and fields left out take the paper's values.
                let mut root = toml::Value::try_from(DrillPipeSpec::default()).map_err(|e| {
                    SceneError::new("", "", format!("default drill-pipe scene: {e}"))
                })?;
                merge(&mut root, toml::Value::Table(table));
                for o in overrides {
                    apply_override(&mut root, o)?;
                }
                Self::drill_pipe(deserialize_with_path(root)?)
            }
        }
    }

    /// A generic scene: validated and assembled.
    pub fn generic(scene: Scene) -> Result<Self, SceneError> {
        let (model, state) = assemble(&scene)?;
        Self::from_parts(Source::Generic, scene, model, state)
    }

    /// A drill-pipe scene: validated, expanded (which validates the
    /// expansion) and assembled.
    pub fn drill_pipe(spec: DrillPipeSpec) -> Result<Self, SceneError> {
        let expansion = spec.expand()?;
        let (model, state) = assemble_validated(&expansion.scene)?;
        let source = Source::DrillPipe {
            spec: Box::new(spec),
            layout: Box::new(expansion.layout),
        };
        Self::from_parts(source, expansion.scene, model, state)
    }

    /// The document of assembled parts; refuses a start whose energy is not finite.
    fn from_parts(
        source: Source,
        scene: Scene,
        model: Model,
        state: State,
    ) -> Result<Self, SceneError> {
        crate::sim::initial_energy_is_finite(&model, &state)?;
        let doc = Self {
            source,
            scene,
            model,
            state,
        };
        crate::record::check_budget(&doc.model, &doc.observers())?;
        Ok(doc)
    }

    /// The document's kind.
    pub fn kind(&self) -> Kind {
        match self.source {
            Source::Generic => Kind::Generic,
            Source::DrillPipe { .. } => Kind::DrillPipe,
        }
    }

    /// The generic scene the engine runs (for a drill pipe, its expansion).
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The assembled model.
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// The state at t = 0.
    pub fn initial_state(&self) -> &State {
        &self.state
    }

    /// The drill-pipe document and the layout of its parts, for drill pipes.
    pub fn drill_pipe_parts(&self) -> Option<(&DrillPipeSpec, &Layout)> {
        match &self.source {
            Source::Generic => None,
            Source::DrillPipe { spec, layout } => Some((spec, layout)),
        }
    }

    /// The document as written, every default filled in, as a TOML value.
    fn source_value(&self) -> toml::Value {
        let value = match &self.source {
            Source::Generic => toml::Value::try_from(&self.scene),
            Source::DrillPipe { spec, .. } => toml::Value::try_from(spec.as_ref()),
        };
        // Serializing plain data with finite numbers cannot fail.
        value.unwrap_or_else(|_| toml::Value::Table(toml::Table::new()))
    }

    /// The document as TOML, every default written out (a drill pipe as its
    /// drill-pipe document, not its expansion).
    pub fn to_toml(&self) -> String {
        match &self.source {
            Source::Generic => self.scene.to_toml(),
            Source::DrillPipe { spec, .. } => spec.to_toml(),
        }
    }

    /// The document as [`Self::to_toml`] writes it, with the unit of every
    /// number as a comment at the end of its line (`pitch = 0.2  # m`; a
    /// law's fields in its own `units`, e.g. `# N/mm^2.2`); see
    /// [`field_unit`]. The text parses to the same values.
    pub fn to_toml_with_units(&self) -> String {
        with_units(&self.to_toml(), &self.source_value())
    }

    /// The resolved value at a dotted key (the syntax of overrides); the
    /// empty key gives the whole document.
    pub fn value(&self, key: &str) -> Result<toml::Value, SceneError> {
        let root = self.source_value();
        if key.trim().is_empty() {
            return Ok(root);
        }
        lookup(&root, key).cloned()
    }

    /// Names of the tables a run of this document records, in order.
    pub fn table_names(&self) -> Vec<&'static str> {
        let engine = self.scene.record.tables.iter().map(|k| k.name());
        let own: &[drillpipe::PipeTable] = match &self.source {
            Source::Generic => &[],
            Source::DrillPipe { spec, .. } => &spec.record.tables,
        };
        let own = own.iter().filter_map(|t| drillpipe::tables::table_def(*t));
        engine.chain(own.map(|t| t.name)).collect()
    }

    /// The observers of the document's own tables.
    fn observers(&self) -> Vec<Box<dyn Observer>> {
        match &self.source {
            Source::Generic => vec![],
            Source::DrillPipe { spec, layout } => {
                vec![Box::new(PipeTables::new(
                    spec,
                    layout.as_ref().clone(),
                    &self.model,
                    &self.state,
                ))]
            }
        }
    }

    /// The estimated size of every table a run of the document records (at
    /// most; checked against `record.max_bytes` when the document was made).
    pub fn memory_estimate(&self) -> Vec<crate::record::TableEstimate> {
        crate::record::estimate(&self.model, &self.observers())
    }

    /// A new simulation of the document, at t = 0 with its first frame recorded.
    pub fn simulation(&self) -> Simulation {
        Simulation::from_model(
            self.model.clone(),
            self.state.clone(),
            self.observers(),
            self.to_toml(),
        )
    }
}

/// Every output table any kind of document can record, in the order
/// `ballcage schema` lists them: the engine's, then the drill pipe's.
pub fn tables() -> Vec<&'static TableDef> {
    TableKind::ALL
        .iter()
        .map(|k| table_def(*k))
        .chain(drillpipe::tables::TABLES)
        .collect()
}

/// The table named `name`, of any kind.
pub fn table(name: &str) -> Option<&'static TableDef> {
    tables().into_iter().find(|t| t.name == name)
}

/// `text`, TOML as [`Document::to_toml`] writes it (table headers and
/// `key = value` lines at the start of a line, arrays over several lines),
/// with `  # unit` after each line that sets a number or an array of
/// numbers whose unit [`field_unit`] knows; `root` is the parsed document.
fn with_units(text: &str, root: &toml::Value) -> String {
    let mut section: Option<&toml::Table> = root.as_table();
    let mut section_name = String::new();
    // Elements seen so far of each array of tables (`[[bodies]]`), by its dotted name.
    let mut seen: HashMap<String, usize> = HashMap::new();
    let mut out = String::with_capacity(text.len() + text.len() / 4);
    for line in text.lines() {
        out.push_str(line);
        if let Some(header) = line.strip_prefix('[') {
            section_name = header.trim_matches(|c| c == '[' || c == ']').to_string();
            if header.starts_with('[') {
                *seen.entry(section_name.clone()).or_default() += 1;
            }
            section = table_at(root, &section_name, &seen);
        } else if let Some((key, _)) = line.split_once(" = ")
            && !line.starts_with(' ')
            && let Some(table) = section
            && table.get(key).is_some_and(is_numeric)
            && let Some(unit) = field_unit(&section_name, key, table)
        {
            out.push_str("  # ");
            out.push_str(&unit);
        }
        out.push('\n');
    }
    out
}

/// The table at the dotted header `name` of `root`; in an array of tables,
/// the element `seen` counts up to (its last one so far).
fn table_at<'a>(
    root: &'a toml::Value,
    name: &str,
    seen: &HashMap<String, usize>,
) -> Option<&'a toml::Table> {
    let mut v = root;
    let mut prefix = String::new();
    for seg in name.split('.').filter(|s| !s.is_empty()) {
        if !prefix.is_empty() {
            prefix.push('.');
        }
        prefix.push_str(seg);
        v = v.get(seg)?;
        if let toml::Value::Array(items) = v {
            v = items.get(seen.get(&prefix)?.checked_sub(1)?)?;
        }
    }
    v.as_table()
}

/// A number, or a non-empty array of numbers.
fn is_numeric(v: &toml::Value) -> bool {
    match v {
        toml::Value::Integer(_) | toml::Value::Float(_) => true,
        toml::Value::Array(a) => !a.is_empty() && a.iter().all(is_numeric),
        _ => false,
    }
}

/// The unit of the number `key` in the table `table` at the dotted
/// `section` of a scene document of any kind (`"-"` for a pure number),
/// or `None` when it is not known. Scene fields are SI (the drill pipe's
/// `_deg` and `_rpm` fields say their unit in their name); a contact law's
/// fields are in its `units` ([`FieldUnits`]), its stiffness in N/m^n (or
/// N/mm^n) for its exponent n.
pub fn field_unit(section: &str, key: &str, table: &toml::Table) -> Option<String> {
    if let Some(law) = table.get("law").and_then(toml::Value::as_str) {
        return law_field_unit(law, key, table);
    }
    let exact = match (section.rsplit('.').next().unwrap_or(""), key) {
        ("world", "gravity") => Some("m/s²"),
        ("newton", _) | ("divergence", "penetration_fraction" | "energy_growth") => Some("-"),
        ("record", "summary_window") => Some("s"),
        ("record", "max_bytes") => Some("B"),
        _ => None,
    };
    exact.or_else(|| named_unit(key)).map(str::to_string)
}

/// The unit a field's name implies (see [`field_unit`]).
fn named_unit(key: &str) -> Option<&'static str> {
    const BY_NAME: &[(&[&str], &str)] = &[
        (
            &["duration", "dt", "output_interval", "ramp", "spin_ramp"],
            "s",
        ),
        (
            &[
                "joints",
                "tube_contact_points",
                "points",
                "threads",
                "max_steps",
            ],
            "-",
        ),
        (&["twist_stiffness", "stop_stiffness"], "N·m/rad"),
        (&["twist_damping"], "N·m·s/rad"),
        (&["stiffness"], "N/m"),
        (&["damping"], "N·s/m"),
        (&["resisting_moment", "magnitude"], "N·m"),
        (&["velocity"], "m/s"),
        (&["angular_velocity", "spin_speed"], "rad/s"),
        (&["density"], "kg/m³"),
        (&["youngs_modulus", "hardness", "allowable_pressure"], "Pa"),
        (
            &["poisson_ratio", "tube_coefficient", "internal_coefficient"],
            "-",
        ),
        (&["orientation", "normal", "axis", "spin_axis"], "-"),
        (
            &["position", "pitch", "max_penetration", "half_extents"],
            "m",
        ),
    ];
    const BY_SUFFIX: &[(&str, &str)] = &[
        ("_deg", "deg"),
        ("_rpm", "rpm"),
        ("mass", "kg"),
        ("inertia", "kg·m²"),
        ("radius", "m"),
        ("diameter", "m"),
        ("length", "m"),
        ("width", "m"),
        ("offset", "m"),
        ("clearance", "m"),
    ];
    BY_NAME
        .iter()
        .find(|(names, _)| names.contains(&key))
        .map(|(_, unit)| *unit)
        .or_else(|| {
            BY_SUFFIX
                .iter()
                .find(|(suffix, _)| key.ends_with(suffix))
                .map(|(_, unit)| *unit)
        })
}

/// The unit of field `key` of a contact law table `table` whose `law` is `law`.
fn law_field_unit(law: &str, key: &str, table: &toml::Table) -> Option<String> {
    let units: FieldUnits = table
        .get("units")
        .and_then(|u| u.clone().try_into().ok())
        .unwrap_or_default();
    let length = match units {
        FieldUnits::Si => "m",
        FieldUnits::NMmS => "mm",
    };
    let unit = match key {
        "stiffness" => {
            let n = match (law, table.get("exponent")) {
                (_, Some(n)) => n.as_float().or_else(|| n.as_integer().map(|i| i as f64))?,
                ("hertz", None) => 1.5,
                _ => 1.0,
            };
            if n == 1.0 {
                format!("N/{length}")
            } else {
                format!("N/{length}^{n}")
            }
        }
        "damping" => format!("N·s/{length}"),
        "depth_max" => length.to_string(),
        "v_static" | "v_dynamic" | "v_ref" | "min_approach_speed" => format!("{length}/s"),
        "exponent" | "restitution" | "mu" | "mu_static" | "mu_dynamic" => "-".to_string(),
        _ => return None,
    };
    Some(unit)
}

/// The embedded default document: the paper's drill pipe.
pub fn default_document() -> DrillPipeSpec {
    DrillPipeSpec::default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::ColumnKind;

    #[test]
    fn every_table_has_a_unique_name_and_unique_columns_with_units() {
        let all = tables();
        for (i, t) in all.iter().enumerate() {
            assert!(
                all[..i].iter().all(|o| o.name != t.name),
                "{} twice",
                t.name
            );
            for (j, c) in t.columns.iter().enumerate() {
                assert!(
                    t.columns[..j].iter().all(|o| o.name != c.name),
                    "{}.{} twice",
                    t.name,
                    c.name
                );
                if c.kind == ColumnKind::F64 {
                    assert!(!c.unit.is_empty(), "{}.{} has no unit", t.name, c.name);
                }
            }
        }
        assert_eq!(table("links").map(|t| t.name), Some("links"));
        assert!(table("nonsense").is_none());
    }

    #[test]
    fn a_toml_syntax_error_names_its_line_and_column_and_no_field() {
        let e = parse_toml("[pipe]\njoints = @\n").unwrap_err();
        assert_eq!(e.path, "");
        let expected = "TOML syntax error at line 2, column 10: ";
        assert!(e.reason.starts_with(expected), "{e:?}");
        // Columns count characters, not bytes: `@` is the 10th character, the 12th byte.
        let e = parse_toml("a = 1\nb = \"µµ\" @\n").unwrap_err();
        assert!(e.reason.contains("at line 2, column 10: "), "{e:?}");
    }

    /// Every number of the default drill-pipe document, under either hinge
    /// model, with a unit comment; the annotated text reads back the same.
    #[test]
    fn every_number_of_a_drill_pipe_document_has_a_unit() {
        for hinge in ["ball-keys", "ideal-cv"] {
            let overrides = [format!("pipe.hinge=\"{hinge}\"")];
            let doc = Document::from_toml_str("kind = \"drill-pipe\"", &overrides).unwrap();
            let text = doc.to_toml_with_units();
            let lines: Vec<&str> = text.lines().collect();
            let number = |v: &str| v.starts_with(|c: char| c.is_ascii_digit() || c == '-');
            let mut numeric_lines = 0;
            for (i, line) in lines.iter().enumerate() {
                let Some((_, value)) = line.split_once(" = ").filter(|_| !line.starts_with(' '))
                else {
                    continue;
                };
                let value = value.split("  # ").next().unwrap_or("");
                let next = lines.get(i + 1).map_or("", |l| l.trim());
                if number(value) || (value == "[" && number(next)) {
                    numeric_lines += 1;
                    assert!(line.contains("  # "), "{hinge}: no unit on `{line}`");
                }
            }
            assert!(numeric_lines > 50, "{numeric_lines} numeric lines");
            assert!(text.contains("curvature_radius = 1.5  # m\n"), "{text}");
            assert!(text.contains("speed_rpm = 100.0  # rpm\n"), "{text}");
            assert!(text.contains("link_inertia = [  # kg·m²\n"), "{text}");
            assert!(
                text.contains("stiffness = 100000.0  # N/mm^2.2\n"),
                "{text}"
            );
            assert!(text.contains("damping = 10.0  # N·s/mm\n"), "{text}");
            assert!(text.contains("v_static = 100.0  # mm/s\n"), "{text}");
            assert!(text.contains("stiffness = 1000000000.0  # N/m\n"), "{text}");
            assert!(!text.contains("tables = [  #"), "{text}");
            let back: toml::Table = text.parse().unwrap();
            assert_eq!(toml::Value::Table(back), doc.source_value());
        }
    }

    #[test]
    fn each_element_of_an_array_of_tables_gets_its_own_units() {
        let text = "[simulation]\nduration = 0.1\ndt = 1e-4\noutput_interval = 1e-3\n\
                    [[bodies]]\nname = \"ground\"\nmotion = \"fixed\"\n\
                    shape = { type = \"half-space\", normal = [0.0, 0.0, 1.0] }\n\
                    [[bodies]]\nname = \"ball\"\nmass = 1.0\nshape = { type = \"ball\", radius = 0.05 }\n\
                    [[contacts]]\nbodies = [\"ground\", \"ball\"]\n\
                    normal = { law = \"hertz\", stiffness = 1e8 }\n";
        let annotated = Document::from_toml_str(text, &[])
            .unwrap()
            .to_toml_with_units();
        for expected in [
            "normal = [  # -\n",
            "radius = 0.05  # m\n",
            "mass = 1.0  # kg\n",
            "stiffness = 100000000.0  # N/m^1.5\n",
        ] {
            assert!(annotated.contains(expected), "{expected} in {annotated}");
        }
    }

    #[test]
    fn law_units_follow_the_law_and_its_field_units() {
        let law = |text: &str| text.parse::<toml::Table>().unwrap();
        let si = law("law = \"hertz\"\nstiffness = 1e8");
        assert_eq!(
            field_unit("contacts.normal", "stiffness", &si).unwrap(),
            "N/m^1.5"
        );
        let lin = law("law = \"linear\"\nstiffness = 1e5\ndamping = 1\nunits = \"N-mm-s\"");
        assert_eq!(field_unit("x", "stiffness", &lin).unwrap(), "N/mm");
        assert_eq!(field_unit("x", "damping", &lin).unwrap(), "N·s/mm");
        let none = toml::Table::new();
        assert_eq!(field_unit("world", "gravity", &none).unwrap(), "m/s²");
        assert_eq!(field_unit("bodies", "mass", &none).unwrap(), "kg");
        assert_eq!(field_unit("pipe", "neck_radius", &none).unwrap(), "m");
        assert_eq!(field_unit("bodies", "whatever", &none), None);
    }

    #[test]
    fn the_kind_is_declared_or_implied_by_the_sections() {
        let kind = |text: &str| Kind::of(&parse_toml(text).unwrap());
        assert_eq!(kind("kind = \"drill-pipe\"").unwrap(), Kind::DrillPipe);
        assert_eq!(kind("[pipe]\njoints = 3").unwrap(), Kind::DrillPipe);
        assert_eq!(kind("bodies = []").unwrap(), Kind::Generic);
        assert_eq!(kind("kind = \"generic\"\n[pipe]").unwrap(), Kind::Generic);
        let e = kind("kind = \"crane\"").unwrap_err();
        assert_eq!(e.path, "kind");
        assert!(e.reason.contains("\"drill-pipe\""), "{e}");
    }
}
