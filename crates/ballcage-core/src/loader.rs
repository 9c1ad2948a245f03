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

use crate::assembly::{assemble, assemble_validated};
use crate::drillpipe::{self, DrillPipeSpec, Layout, PipeTables};
use crate::error::SceneError;
use crate::model::{Model, State};
use crate::record::{Observer, TableDef, table_def};
use crate::scene::provenance::{self, FieldOrigin, Proposal, Provenance};
use crate::scene::{
    FieldDoc, FieldInfo, FieldUnits, Scene, TableKind, annotate, apply_override, describe,
    deserialize_with_path, lookup, merge, parse_toml,
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

    /// The kind whose `kind` key is `name` (`"generic"`, `"drill-pipe"`).
    pub fn named(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|kind| kind.name() == name)
    }

    /// The unit and meaning of every field of a document of this kind.
    pub fn field_docs(self) -> &'static [FieldDoc] {
        match self {
            Kind::Generic => Scene::FIELDS,
            Kind::DrillPipe => DrillPipeSpec::FIELDS,
        }
    }

    /// Where the defaults of a document of this kind come from: the lists
    /// of [`FieldOrigin`]s that classify them, each with the kind whose
    /// registry holds its PROPOSALs (the engine's sections, which every kind
    /// shares, are the generic kind's).
    pub fn provenance(self) -> [(Kind, &'static [FieldOrigin]); 2] {
        let engine = (Kind::Generic, provenance::ENGINE);
        match self {
            Kind::Generic => [engine, (Kind::Generic, provenance::GENERIC)],
            Kind::DrillPipe => [engine, (Kind::DrillPipe, drillpipe::PROVENANCE)],
        }
    }

    /// The default document of this kind as a TOML value, every default
    /// filled in: the paper's drill pipe, or for a generic scene the
    /// smallest one ([`provenance::MINIMAL_GENERIC_SCENE`], one body).
    pub fn default_value(self) -> Result<toml::Value, SceneError> {
        let value = match self {
            Kind::DrillPipe => toml::Value::try_from(DrillPipeSpec::default()),
            Kind::Generic => toml::Value::try_from(Scene::from_toml_str(
                provenance::MINIMAL_GENERIC_SCENE,
                &[],
            )?),
        };
        value.map_err(|e| SceneError::new("", "", format!("default {} scene: {e}", self.name())))
    }

    /// The kind a document table declares (or implies, without `kind`).
    fn of(table: &toml::Table) -> Result<Self, SceneError> {
        match table.get("kind") {
            Some(toml::Value::String(k)) => Self::named(k).ok_or_else(|| unknown_kind(k)),
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
    /// law's fields in its own `units`, e.g. `# N/mm^2.2`), from the
    /// table of its kind's fields ([`Self::field`]). The text parses to the
    /// same values.
    ///
    /// Each field of the registry of unstated parameters ([`proposals`])
    /// gets a comment line above it with its plausible range and source,
    /// `# PROPOSAL, 17.5–21 mm: not in the paper`, when the document writes
    /// it in the registry's unit (a contact law rewritten in other units or
    /// as another law is not marked).
    pub fn to_toml_with_units(&self) -> String {
        // the tests keep the registry resolvable; were it not, the text would only lack its marks
        let registry = registry(self.kind(), Lists::Applying).unwrap_or_default();
        let mark = |key: &str, unit: &str| {
            registry
                .iter()
                .find(|e| e.key == key && e.unit == unit)
                .map(|e| e.proposal.mark(unit))
        };
        annotate(
            &self.to_toml(),
            self.field_docs(),
            &self.source_value(),
            &mark,
        )
    }

    /// The unit and meaning of every field of the document's kind
    /// ([`Scene::FIELDS`], [`DrillPipeSpec::FIELDS`]).
    pub fn field_docs(&self) -> &'static [FieldDoc] {
        self.kind().field_docs()
    }

    /// Where the default of the field at a dotted key of the document's
    /// kind comes from (the paper, a rule, a PROPOSAL, a setting); `None`
    /// for a key no list classifies (a generic scene's bodies and pairs).
    pub fn provenance(&self, key: &str) -> Option<&'static Provenance> {
        provenance_of(self.kind(), key)
    }

    /// The unit and meaning of the field at a dotted key (`pipe.pitch`,
    /// `bodies[1].mass` or `bodies.1.mass`); a contact law's field answers
    /// in the law's own `units`. An error names a key the document does not
    /// have.
    pub fn field(&self, key: &str) -> Result<FieldInfo, SceneError> {
        describe(self.field_docs(), &self.source_value(), key)
    }

    /// The factor that turns a value of the contact-law field at `key`,
    /// written in `from` units, into the units the document writes it in
    /// ([`crate::scene::scale_from`]); an error names a key that is not a
    /// number of a contact law.
    pub fn scale_from(&self, key: &str, from: FieldUnits) -> Result<f64, SceneError> {
        let root = self.source_value();
        lookup(&root, key)?;
        let (law_key, field) = key.rsplit_once('.').unwrap_or(("", key));
        lookup(&root, law_key)
            .ok()
            .and_then(toml::Value::as_table)
            .filter(|t| t.contains_key("law"))
            .and_then(|law| crate::scene::scale_from(field, law, from))
            .ok_or_else(|| SceneError::new(key, "", "is not a number of a contact law"))
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

    /// A digest of everything a run of the document computes from: the
    /// generic scene the engine runs (for a drill pipe, its expansion, with
    /// the time stepping, recording and divergence checks), the state at
    /// t = 0 and the set-up of the document's own tables (each pair's Hertz
    /// and wear model). The engine is deterministic, so two documents with
    /// the same digest record bitwise the same tables: whatever they differ
    /// in enters only what is computed from those tables afterwards (the
    /// fatigue outputs, `fatigue.*`), or nothing this scene builds
    /// (`pipe.ideal_cv.*` with ball-key hinges). Sweeps run such documents
    /// once. A hex string, stable within one build of ballcage.
    pub fn engine_digest(&self) -> String {
        use std::hash::{Hash, Hasher};
        let mut hasher = std::collections::hash_map::DefaultHasher::new();
        format!("{:?}", self.scene).hash(&mut hasher);
        format!("{:?}", self.state).hash(&mut hasher);
        if let Source::DrillPipe { spec, layout } = &self.source {
            let tables = PipeTables::new(spec, layout.as_ref().clone(), &self.model, &self.state);
            format!("{tables:?}").hash(&mut hasher);
        }
        format!("{:016x}", hasher.finish())
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

/// The embedded default document: the paper's drill pipe.
pub fn default_document() -> DrillPipeSpec {
    DrillPipeSpec::default()
}

/// Where the default at a dotted key of a document of `kind` comes from;
/// `None` for a key no list of the kind classifies.
pub fn provenance_of(kind: Kind, key: &str) -> Option<&'static Provenance> {
    let lists = kind.provenance().map(|(_, list)| list);
    provenance::origin_of(&lists, key).map(|o| &o.provenance)
}

/// One entry of the registry of unstated parameters, with what the
/// registry does not hold itself: the default (from the kind's default
/// document), the unit and the meaning (from its table of fields).
#[derive(Debug, Clone)]
pub struct ProposalEntry {
    /// Dotted key, as `--set key=value` takes it.
    pub key: &'static str,
    /// The kind whose registry holds it; the generic kind's (the engine's
    /// `simulation` section) apply to every kind.
    pub kind: Kind,
    /// The default, in `unit`.
    pub default: f64,
    /// The field's unit in the default document (`-` for a pure number).
    pub unit: String,
    /// One line on what the field is.
    pub meaning: &'static str,
    /// Source, reference, range (in `unit`) and why.
    pub proposal: &'static Proposal,
}

/// The registry of unstated parameters: every PROPOSAL default of every
/// kind (or of `kind` only), the drill pipe's first, each in its list's
/// order. An error (a bug: the tests keep every key resolvable) names a
/// key that is not a number of its kind's default document.
pub fn proposals(kind: Option<Kind>) -> Result<Vec<ProposalEntry>, SceneError> {
    let mut out = Vec::new();
    for owner in [Kind::DrillPipe, Kind::Generic] {
        if kind.is_none_or(|k| k == owner) {
            out.extend(registry(owner, Lists::Own)?);
        }
    }
    Ok(out)
}

/// Which of a kind's provenance lists [`registry`] reads.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Lists {
    /// Those whose PROPOSALs the kind's registry holds.
    Own,
    /// Every list that classifies a document of the kind (the engine's too).
    Applying,
}

/// The PROPOSALs of `kind`'s `lists`, resolved against its default document.
fn registry(kind: Kind, lists: Lists) -> Result<Vec<ProposalEntry>, SceneError> {
    let root = kind.default_value()?;
    let mut out = Vec::new();
    for (owner, list) in kind.provenance() {
        if lists == Lists::Applying || owner == kind {
            for origin in list.iter().filter(|o| o.proposal_entry().is_some()) {
                out.push(entry(owner, kind, origin, &root)?);
            }
        }
    }
    Ok(out)
}

/// The registry entry of `origin` (a PROPOSAL of `owner`'s registry) with
/// its default, unit and meaning from `root`, a default document of `kind`.
fn entry(
    owner: Kind,
    kind: Kind,
    origin: &'static FieldOrigin,
    root: &toml::Value,
) -> Result<ProposalEntry, SceneError> {
    let key = origin.key;
    let proposal = origin
        .proposal_entry()
        .ok_or_else(|| SceneError::new(key, "", "is not a PROPOSAL"))?;
    let default = match lookup(root, key)? {
        toml::Value::Float(x) => *x,
        toml::Value::Integer(i) => *i as f64,
        other => {
            return Err(SceneError::new(
                key,
                other,
                format!(
                    "a PROPOSAL must be a number of the default {} document",
                    kind.name()
                ),
            ));
        }
    };
    let info = describe(kind.field_docs(), root, key)?;
    Ok(ProposalEntry {
        key,
        kind: owner,
        default,
        unit: info.unit,
        meaning: info.meaning,
        proposal,
    })
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

    /// A ball on the ground: a generic scene with two bodies and a Hertz pair.
    const BALL_ON_GROUND: &str = r#"
        [simulation]
        duration = 0.1
        dt = 1e-4
        output_interval = 1e-3
        [[bodies]]
        name = "ground"
        motion = "fixed"
        shape = { type = "half-space", normal = [0.0, 0.0, 1.0] }
        [[bodies]]
        name = "ball"
        mass = 1.0
        shape = { type = "ball", radius = 0.05 }
        [[contacts]]
        bodies = ["ground", "ball"]
        normal = { law = "hertz", stiffness = 1e8 }
    "#;

    #[test]
    fn each_element_of_an_array_of_tables_gets_its_own_units() {
        let annotated = Document::from_toml_str(BALL_ON_GROUND, &[])
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
        let again = r#"
            [[contacts]]
            name = "again"
            bodies = ["ground", "ball"]
            normal = { law = "linear", stiffness = 1e5, damping = 1, units = "N-mm-s" }
        "#;
        let text = format!("{BALL_ON_GROUND}{again}");
        let doc = Document::from_toml_str(&text, &[]).unwrap();
        let unit = |key: &str| doc.field(key).map(|f| f.unit);
        assert_eq!(unit("contacts[0].normal.stiffness").unwrap(), "N/m^1.5");
        assert_eq!(unit("contacts.1.normal.stiffness").unwrap(), "N/mm");
        assert_eq!(unit("contacts[1].normal.damping").unwrap(), "N·s/mm");
        assert_eq!(unit("contacts[1].normal.units").unwrap(), "");
        assert_eq!(unit("world.gravity").unwrap(), "m/s²");
        assert_eq!(unit("world.gravity[2]").unwrap(), "m/s²");
        assert_eq!(unit("bodies[1].mass").unwrap(), "kg");
        assert_eq!(unit("bodies.1.shape.radius").unwrap(), "m");
        assert_eq!(unit("bodies[0].name").unwrap(), "");
        assert_eq!(
            doc.field("bodies[1].mass").unwrap().meaning,
            "mass; alternative to density"
        );
        for missing in ["bodies[1].whatever", "bodies[7].mass", "nope", ""] {
            assert!(doc.field(missing).is_err(), "{missing}");
        }
        let pipe = Document::from_toml_str("kind = \"drill-pipe\"", &[]).unwrap();
        assert_eq!(pipe.field("pipe.neck_radius").unwrap().unit, "m");
        assert_eq!(
            pipe.field("materials.tube.normal.stiffness").unwrap().unit,
            "N/mm^2.2"
        );
        let e = pipe.field("pipe.neck_radiu").unwrap_err();
        assert_eq!(e.path, "pipe.neck_radiu");
    }

    #[test]
    fn a_law_value_converts_from_other_field_units_to_the_laws_own() {
        let key = "materials.internal.normal";
        let si = [format!("{key}.units=\"SI\"")];
        let paper = Document::from_toml_str("kind = \"drill-pipe\"", &[]).unwrap();
        let si = Document::from_toml_str("kind = \"drill-pipe\"", &si).unwrap();
        let scale = |doc: &Document, field: &str, from| {
            doc.scale_from(&format!("{key}.{field}"), from).unwrap()
        };
        assert_eq!(scale(&paper, "stiffness", FieldUnits::NMmS), 1.0);
        assert_eq!(scale(&si, "stiffness", FieldUnits::NMmS), 1000f64.powf(2.2));
        assert_eq!(scale(&si, "damping", FieldUnits::NMmS), 1000.0);
        assert_eq!(scale(&si, "depth_max", FieldUnits::NMmS), 1e-3);
        assert_eq!(scale(&paper, "depth_max", FieldUnits::Si), 1000.0);
        assert_eq!(scale(&si, "exponent", FieldUnits::NMmS), 1.0);
        assert!(si.scale_from("pipe.pitch", FieldUnits::NMmS).is_err());
        assert!(
            si.scale_from(&format!("{key}.law"), FieldUnits::NMmS)
                .is_err()
        );
        assert!(
            si.scale_from(&format!("{key}.nope"), FieldUnits::NMmS)
                .is_err()
        );
    }

    /// The documents `scene show` prints in the tests: the default drill
    /// pipe under either hinge model and every scene of examples/scenes/.
    fn shown_documents() -> Vec<(String, Document)> {
        let mut docs: Vec<(String, Document)> = ["ball-keys", "ideal-cv"]
            .iter()
            .map(|hinge| {
                let overrides = [format!("pipe.hinge=\"{hinge}\"")];
                let doc = Document::from_toml_str("kind = \"drill-pipe\"", &overrides).unwrap();
                (format!("drill pipe, {hinge}"), doc)
            })
            .collect();
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/scenes");
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                let text = std::fs::read_to_string(&path).unwrap();
                docs.push((
                    path.display().to_string(),
                    Document::from_toml_str(&text, &[]).unwrap(),
                ));
            }
        }
        assert!(docs.len() >= 4, "{} documents", docs.len());
        docs
    }

    /// Every number `scene show` prints has an entry in its kind's table of
    /// fields (a new field without one fails here), every other key has a
    /// meaning, and every numeric line of the printed text carries its unit.
    #[test]
    fn every_number_scene_show_prints_has_a_documented_unit() {
        for (name, doc) in shown_documents() {
            let root = doc.source_value();
            for key in crate::scene::numeric_keys(&root, "") {
                let field = doc
                    .field(&key)
                    .unwrap_or_else(|e| panic!("{name}: {key}: {e}"));
                assert!(!field.unit.is_empty(), "{name}: {key} has no unit");
                assert!(!field.meaning.is_empty(), "{name}: {key} has no meaning");
            }
            let text = doc.to_toml_with_units();
            let lines: Vec<&str> = text.lines().collect();
            let number = |v: &str| v.starts_with(|c: char| c.is_ascii_digit() || c == '-');
            for (i, line) in lines.iter().enumerate() {
                let Some((_, value)) = line.split_once(" = ").filter(|_| !line.starts_with(' '))
                else {
                    continue;
                };
                let value = value.split("  # ").next().unwrap_or("");
                let next = lines.get(i + 1).map_or("", |l| l.trim());
                if number(value) || (value == "[" && number(next)) {
                    assert!(line.contains("  # "), "{name}: no unit on `{line}`");
                }
            }
        }
    }

    /// Each table of fields names a key once, with a meaning and a unit
    /// only where it holds numbers; every key of a shown document is in it.
    #[test]
    fn the_tables_of_fields_are_complete_and_unique() {
        for docs in [Scene::FIELDS, DrillPipeSpec::FIELDS] {
            let flat = crate::scene::flatten(docs);
            for (i, (key, doc)) in flat.iter().enumerate() {
                assert!(flat[..i].iter().all(|(k, _)| k != key), "{key} twice");
                assert!(!doc.meaning.is_empty(), "{key} has no meaning");
            }
        }
        fn keys(v: &toml::Value, path: &str, out: &mut Vec<String>) {
            let join = |k: &str| {
                if path.is_empty() {
                    k.to_string()
                } else {
                    format!("{path}.{k}")
                }
            };
            match v {
                toml::Value::Table(t) => t.iter().for_each(|(k, x)| {
                    out.push(join(k));
                    keys(x, &join(k), out);
                }),
                toml::Value::Array(a) => a
                    .iter()
                    .enumerate()
                    .for_each(|(i, x)| keys(x, &join(&i.to_string()), out)),
                _ => {}
            }
        }
        for (name, doc) in shown_documents() {
            let mut all = Vec::new();
            keys(&doc.source_value(), "", &mut all);
            for key in all {
                doc.field(&key)
                    .unwrap_or_else(|e| panic!("{name}: {key}: {e}"));
            }
        }
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
