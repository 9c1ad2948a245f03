//! How much memory a run's tables will take, estimated before it starts,
//! against the scene's budget `record.max_bytes`.
//!
//! The estimate counts the bytes the recorder's buffers hold per row
//! ([`TableDef::row_bytes`]) times the rows each table will have after the
//! last frame: every engine table from the recording plan, every layer
//! table from its observer ([`Observer::rows`]). It is an upper bound: the
//! `contacts` table is counted with every point slot of every recorded pair
//! in every frame, though only the points in contact are written.

use super::{ColumnKind, Observer, TableDef, table_def};
use crate::error::SceneError;
use crate::model::Model;
use crate::scene::TableKind;

/// One table's estimated size.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TableEstimate {
    /// Table name.
    pub name: &'static str,
    /// Rows after the last frame (at most).
    pub rows: u64,
    /// Bytes of the recorder's buffers (at most).
    pub bytes: u64,
}

impl TableDef {
    /// Bytes one row takes in the recorder's buffers: 8 per u64 or f64,
    /// 4 per u32 or name, 8 per nullable u32 or name and 16 per nullable f64
    /// (Rust's `Option` layout).
    pub fn row_bytes(&self) -> u64 {
        self.columns
            .iter()
            .map(|c| match c.kind {
                ColumnKind::U64 | ColumnKind::F64 | ColumnKind::OptU32 | ColumnKind::OptName(_) => {
                    8
                }
                ColumnKind::U32 | ColumnKind::Name(_) => 4,
                ColumnKind::OptF64 => 16,
            })
            .sum()
    }
}

/// Frames a run of `model` records: t = 0 and every `steps_per_output` steps.
pub fn frames(model: &Model) -> u64 {
    model.total_steps / model.steps_per_output.max(1) + 1
}

/// The estimated size of every table a run of `model` with `observers`
/// records: the engine's in the scene's order, then each observer's.
pub fn estimate(model: &Model, observers: &[Box<dyn Observer>]) -> Vec<TableEstimate> {
    let n = frames(model);
    let r = &model.record;
    let slots: u64 = r
        .pairs
        .iter()
        .map(|&k| model.pairs[k].geometry.slots() as u64)
        .sum();
    let engine = r.tables.iter().map(|&kind| {
        let rows = match kind {
            TableKind::Bodies => n.saturating_mul(r.bodies.len() as u64),
            TableKind::Contacts => n.saturating_mul(slots),
            TableKind::Energy => n,
            TableKind::Summary => model.pairs.len() as u64,
        };
        (table_def(kind), rows)
    });
    let layers = observers
        .iter()
        .flat_map(|o| o.tables().into_iter().zip(o.rows(n)));
    engine
        .chain(layers)
        .map(|(def, rows)| TableEstimate {
            name: def.name,
            rows,
            bytes: rows.saturating_mul(def.row_bytes()),
        })
        .collect()
}

/// Refuses a run whose tables would take more than `record.max_bytes`,
/// naming the estimate, its largest tables and what to change; returns the
/// estimate otherwise.
pub fn check_budget(
    model: &Model,
    observers: &[Box<dyn Observer>],
) -> Result<Vec<TableEstimate>, SceneError> {
    let tables = estimate(model, observers);
    let total = tables.iter().fold(0u64, |s, t| s.saturating_add(t.bytes));
    let budget = model.record.max_bytes;
    if total <= budget {
        return Ok(tables);
    }
    let mut largest: Vec<&TableEstimate> = tables.iter().collect();
    largest.sort_by_key(|t| std::cmp::Reverse(t.bytes));
    let parts: Vec<String> = largest
        .iter()
        .take(3)
        .map(|t| {
            format!(
                "{} {} in {:.3e} rows",
                t.name,
                bytes_text(t.bytes),
                t.rows as f64
            )
        })
        .collect();
    Err(SceneError::new(
        "record.max_bytes",
        budget,
        format!(
            "the recorded tables would take up to {} over {} frames ({}), more than the budget of {}; \
             record fewer tables, bodies or contact pairs, raise simulation.output_interval, \
             or raise record.max_bytes",
            bytes_text(total),
            frames(model),
            parts.join(", "),
            bytes_text(budget),
        ),
    ))
}

/// `bytes` in B, kB, MB, GB or TB (powers of 1000), three significant digits.
pub fn bytes_text(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "kB", "MB", "GB", "TB"];
    let mut v = bytes as f64;
    let mut u = 0;
    while v >= 1000.0 && u + 1 < UNITS.len() {
        v /= 1000.0;
        u += 1;
    }
    if u == 0 {
        format!("{bytes} B")
    } else {
        format!("{v:.3} {}", UNITS[u])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::record::{BODIES, CONTACTS};

    #[test]
    fn row_bytes_counts_each_column_by_its_type() {
        // bodies: step (u64), t (f64), body_id (u32), body (name), part
        // (nullable name), link, hinge, key (nullable u32), then 13 f64
        assert_eq!(BODIES.row_bytes(), 8 + 8 + 4 + 4 + 4 * 8 + 13 * 8);
        // contacts: step, t; pair_id, pair, body_a, body_b, point_index (u32/name); 13 f64
        assert_eq!(CONTACTS.row_bytes(), 8 + 8 + 5 * 4 + 13 * 8);
    }

    #[test]
    fn bytes_are_written_in_decimal_units() {
        assert_eq!(bytes_text(999), "999 B");
        assert_eq!(bytes_text(1_500), "1.500 kB");
        assert_eq!(bytes_text(4_000_000_000), "4.000 GB");
        assert_eq!(bytes_text(u64::MAX), "18446744.074 TB");
    }
}
