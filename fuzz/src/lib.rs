//! What every fuzz input must satisfy, shared by the fuzz targets
//! (`fuzz_targets/`) and the replay tests (`tests/replay.rs`).
//!
//! A scene document, with overrides, either fails to load with a
//! [`SceneError`] that says why, or loads, round-trips through its TOML,
//! runs a few steps (stopping, at worst, with a [`SimulationError`]) and
//! hands over tables whose every number is finite and which convert to
//! Arrow. Anything else is a panic here, which libFuzzer reports as a crash.
//!
//! Work per input is capped ([`LIMITS`]) so that one execution takes
//! milliseconds and a hang stands out: a scene over a cap is loaded and
//! validated but not run.

use ballcage_core::record::{ColumnData, Recording};
use ballcage_core::{Document, SceneError, SimulationError};

/// Caps on the work of one input.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Integrator steps run at most.
    pub steps: u64,
    /// Bodies of a scene that is run.
    pub bodies: usize,
    /// Contact pairs of a scene that is run.
    pub pairs: usize,
    /// `simulation.threads` of a scene that is run (each run starts a pool).
    pub threads: usize,
    /// `simulation.newton.max_iterations` of a scene that is run.
    pub newton_iterations: u32,
}

/// The caps of the fuzz targets.
pub const LIMITS: Limits = Limits {
    steps: 6,
    bodies: 48,
    pairs: 160,
    threads: 2,
    newton_iterations: 50,
};

/// What became of one input.
#[derive(Debug)]
pub enum Outcome {
    /// The document was rejected.
    Rejected(SceneError),
    /// The document loaded but is over a cap of [`LIMITS`]; not run.
    Skipped(&'static str),
    /// The run stopped with a divergence.
    Diverged(SimulationError),
    /// The run took its steps.
    Ran,
}

/// The overrides written in `text` as comment lines `#set key=value` (at
/// most 8), the form of a saved regression input.
pub fn set_lines(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.strip_prefix("#set "))
        .take(8)
        .map(str::to_string)
        .collect()
}

/// Loads `text` with `overrides` and, when it loads, checks it ([`check_document`]).
pub fn check_text(text: &str, overrides: &[String]) -> Outcome {
    match Document::from_toml_str(text, overrides) {
        Ok(doc) => check_document(&doc, LIMITS),
        Err(e) => {
            check_scene_error(&e);
            Outcome::Rejected(e)
        }
    }
}

/// A scene error must say what is wrong; one that names a field names it
/// in its message.
pub fn check_scene_error(e: &SceneError) {
    assert!(
        !e.reason.trim().is_empty(),
        "scene error without a reason: {e:?}"
    );
    let shown = e.to_string();
    assert!(
        !shown.trim().is_empty(),
        "scene error that displays empty: {e:?}"
    );
    if !e.path.is_empty() {
        assert!(
            shown.contains(&e.path),
            "scene error `{shown}` does not name {}",
            e.path
        );
    }
}

/// Round-trips a loaded document through its TOML, runs up to
/// `limits.steps` steps and checks the tables.
pub fn check_document(doc: &Document, limits: Limits) -> Outcome {
    if let Some(why) = over_limits(doc, limits) {
        return Outcome::Skipped(why);
    }
    check_round_trip(doc);
    let _ = doc.table_names();
    let mut sim = doc.simulation();
    let steps = doc.model().total_steps.min(limits.steps);
    let mut outcome = Outcome::Ran;
    for _ in 0..steps {
        if let Err(e) = sim.step() {
            assert!(
                !e.reason.trim().is_empty(),
                "divergence without a reason: {e:?}"
            );
            assert!(sim.failure().is_some(), "a failed step left no failure");
            assert!(sim.step().is_err(), "a step after a failure succeeded");
            outcome = Outcome::Diverged(e);
            break;
        }
    }
    let recording = sim.finish();
    check_recording(&recording);
    if let Err(e) = ballcage_core::output::record_batches(recording) {
        panic!("the tables do not convert to Arrow: {e}");
    }
    outcome
}

/// Why a loaded document is not run, if it is over a cap.
fn over_limits(doc: &Document, limits: Limits) -> Option<&'static str> {
    let m = doc.model();
    if m.bodies.len() > limits.bodies {
        Some("bodies")
    } else if m.pairs.len() > limits.pairs {
        Some("pairs")
    } else if m.threads > limits.threads {
        Some("threads")
    } else if m.integrator.is_implicit() && m.newton.max_iterations > limits.newton_iterations {
        Some("newton iterations")
    } else {
        None
    }
}

/// The document's TOML (as saved with every run) loads again, to the same
/// document, and its annotated form (`to_toml_with_units`) parses to the
/// same values.
fn check_round_trip(doc: &Document) {
    let text = doc.to_toml();
    let again = match Document::from_toml_str(&text, &[]) {
        Ok(d) => d,
        Err(e) => panic!("the document's own TOML does not load again: {e}\n--- TOML ---\n{text}"),
    };
    assert_eq!(
        again.to_toml(),
        text,
        "the document's TOML changes on reloading"
    );
    let plain: toml::Table = text.parse().expect("to_toml parses");
    let with_units = doc.to_toml_with_units();
    let annotated: toml::Table = match with_units.parse() {
        Ok(t) => t,
        Err(e) => panic!("to_toml_with_units does not parse: {e}\n{with_units}"),
    };
    assert!(
        same(&toml::Value::Table(annotated), &toml::Value::Table(plain)),
        "to_toml_with_units parses to other values:\n{with_units}"
    );
    let whole = doc.value("").expect("the whole document as a value");
    if let Some(path) = non_finite_at(&whole, "") {
        panic!("the loaded document holds a non-finite number at `{path}`:\n{text}");
    }
}

/// Equal values, a NaN equal to a NaN.
fn same(a: &toml::Value, b: &toml::Value) -> bool {
    use toml::Value::{Array, Float, Table};
    match (a, b) {
        (Float(x), Float(y)) => x == y || (x.is_nan() && y.is_nan()),
        (Array(x), Array(y)) => x.len() == y.len() && x.iter().zip(y).all(|(x, y)| same(x, y)),
        (Table(x), Table(y)) => {
            x.len() == y.len() && x.iter().all(|(k, v)| y.get(k).is_some_and(|w| same(v, w)))
        }
        _ => a == b,
    }
}

/// The dotted path of the first NaN or infinity in `v`: every field of a
/// loaded scene is validated, so none may hold one (it would be written
/// into every run's `ballcage.scene` metadata).
fn non_finite_at(v: &toml::Value, path: &str) -> Option<String> {
    let join = |k: &str| {
        if path.is_empty() {
            k.to_string()
        } else {
            format!("{path}.{k}")
        }
    };
    match v {
        toml::Value::Float(x) if !x.is_finite() => Some(path.to_string()),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| non_finite_at(x, &join(&i.to_string()))),
        toml::Value::Table(t) => t.iter().find_map(|(k, x)| non_finite_at(x, &join(k))),
        _ => None,
    }
}

/// Every column has one value per row, and every number is finite (a
/// nullable column holds nulls, not NaN, where it does not apply).
pub fn check_recording(rec: &Recording) {
    for table in &rec.tables {
        assert_eq!(
            table.data.len(),
            table.def.columns.len(),
            "table {}",
            table.def.name
        );
        for (col, data) in table.def.columns.iter().zip(&table.data) {
            let (len, bad) = match data {
                ColumnData::F64(v) => (v.len(), v.iter().position(|x| !x.is_finite())),
                ColumnData::OptF64(v) => (
                    v.len(),
                    v.iter().position(|x| x.is_some_and(|x| !x.is_finite())),
                ),
                ColumnData::U64(v) => (v.len(), None),
                ColumnData::U32(v) => (v.len(), None),
                ColumnData::OptU32(v) => (v.len(), None),
            };
            assert_eq!(
                len, table.rows,
                "column {}.{} length",
                table.def.name, col.name
            );
            if let Some(row) = bad {
                panic!(
                    "non-finite value in table {} column {} row {row}: {:?}",
                    table.def.name,
                    col.name,
                    cell(data, row)
                );
            }
        }
    }
}

fn cell(data: &ColumnData, row: usize) -> String {
    match data {
        ColumnData::F64(v) => format!("{}", v[row]),
        ColumnData::OptF64(v) => format!("{:?}", v[row]),
        _ => String::new(),
    }
}

pub mod overrides;
