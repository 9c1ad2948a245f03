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
use crate::scene::{
    Scene, TableKind, apply_override, deserialize_with_path, lookup, merge, parse_toml,
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
                Ok(Self::from_parts(Source::Generic, scene, model, state))
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
        Ok(Self::from_parts(Source::Generic, scene, model, state))
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
        Ok(Self::from_parts(source, expansion.scene, model, state))
    }

    fn from_parts(source: Source, scene: Scene, model: Model, state: State) -> Self {
        Self {
            source,
            scene,
            model,
            state,
        }
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
                    layout.as_ref().clone(),
                    &spec.record.tables,
                ))]
            }
        }
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
