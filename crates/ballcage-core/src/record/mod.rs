//! What gets kept: the column definitions of the engine's output tables
//! (the one schema of the project), columnar buffers filled once per frame,
//! and the [`Observer`] interface through which a layer above the engine
//! (the drill pipe) adds tables of its own.
//!
//! A table is a [`TableDef`]: a name and its columns, each with type, unit and
//! meaning. The engine's own tables are [`BODIES`], [`CONTACTS`], [`ENERGY`]
//! and [`SUMMARY`]; the output stage turns any `TableDef` into an Arrow
//! schema, so a table is defined once, wherever it is produced.

mod budget;
mod frame;
mod observer;

pub use budget::{TableEstimate, bytes_text, check_budget, estimate, frames};
pub use frame::Recorder;
pub(crate) use frame::within_step;
pub use observer::{BodyParts, Frame, Observer, PartIds, Step, contact_totals};

use crate::scene::TableKind;

/// Physical type of a column.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnKind {
    /// Unsigned 64-bit integer.
    U64,
    /// Unsigned 32-bit integer.
    U32,
    /// 64-bit float.
    F64,
    /// Unsigned 32-bit integer, or null where the column does not apply to
    /// the row (an id of a part the row has none of).
    OptU32,
    /// 64-bit float, or null where the quantity does not exist in the row
    /// (an angle of a contact that is not touching).
    OptF64,
    /// A name, dictionary-encoded with u32 keys into a [`Dictionary`].
    Name(Dictionary),
    /// A name as [`ColumnKind::Name`], or null where the column does not
    /// apply to the row.
    OptName(Dictionary),
}

/// Which list of names a name column indexes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dictionary {
    /// Body names, indexed by body id.
    Bodies,
    /// Contact pair names, indexed by pair id.
    Pairs,
    /// A fixed list of labels, indexed by position.
    Labels(&'static [&'static str]),
    /// The part labels of the layer that built the scene
    /// ([`BodyParts::labels`], [`Recording::part_labels`]), indexed by position.
    Parts,
}

/// One column: name, type, unit, meaning.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ColumnDef {
    /// Column name.
    pub name: &'static str,
    /// Type.
    pub kind: ColumnKind,
    /// Unit (`1` for dimensionless, empty for identifiers).
    pub unit: &'static str,
    /// Meaning.
    pub description: &'static str,
}

/// An output table: its name (also the Parquet file stem) and its columns.
#[derive(Debug, PartialEq, Eq)]
pub struct TableDef {
    /// Table name.
    pub name: &'static str,
    /// What one row is.
    pub row: &'static str,
    /// Columns, in order.
    pub columns: &'static [ColumnDef],
}

/// A column definition (for `const` tables).
pub const fn col(
    name: &'static str,
    kind: ColumnKind,
    unit: &'static str,
    description: &'static str,
) -> ColumnDef {
    ColumnDef {
        name,
        kind,
        unit,
        description,
    }
}

use ColumnKind::{F64, Name, OptF64, OptName, OptU32, U32, U64};

/// The frame's integrator step index, first column of every per-frame table.
pub const STEP: ColumnDef = col("step", U64, "", "integrator step index of the frame");
/// The frame's simulated time, second column of every per-frame table.
pub const TIME: ColumnDef = col("t", F64, "s", "simulated time");

/// Columns of the `bodies` table: one row per recorded body per frame. The
/// part columns (`part` … `key`) are the ids a scene kind gives the bodies
/// it builds ([`Observer::body_parts`]); null for a generic scene's bodies.
const BODIES_COLUMNS: &[ColumnDef] = &[
    STEP,
    TIME,
    col("body_id", U32, "", "body index in the scene's body list"),
    col("body", Name(Dictionary::Bodies), "", "body name"),
    col(
        "part",
        OptName(Dictionary::Parts),
        "",
        "what the body is in the assembly its scene kind built (e.g. link, key: the kind's labels); null for a body of a generic scene",
    ),
    col(
        "link",
        OptU32,
        "",
        "link number in the chain its scene kind built, 1 at the top (links; null otherwise)",
    ),
    col(
        "hinge",
        OptU32,
        "",
        "hinge number in that chain, 0 above link 1 (the parts inside a hinge: cage, ball keys; null otherwise)",
    ),
    col(
        "key",
        OptU32,
        "",
        "ball key number within its hinge, 0-5 (ball keys; null otherwise)",
    ),
    col("pos_x", F64, "m", "centre-of-mass position x, world frame"),
    col("pos_y", F64, "m", "centre-of-mass position y, world frame"),
    col("pos_z", F64, "m", "centre-of-mass position z, world frame"),
    col(
        "quat_w",
        F64,
        "1",
        "orientation quaternion w (body to world)",
    ),
    col("quat_x", F64, "1", "orientation quaternion x"),
    col("quat_y", F64, "1", "orientation quaternion y"),
    col("quat_z", F64, "1", "orientation quaternion z"),
    col(
        "vel_x",
        F64,
        "m/s",
        "centre-of-mass velocity x, world frame",
    ),
    col(
        "vel_y",
        F64,
        "m/s",
        "centre-of-mass velocity y, world frame",
    ),
    col(
        "vel_z",
        F64,
        "m/s",
        "centre-of-mass velocity z, world frame",
    ),
    col("angvel_x", F64, "rad/s", "angular velocity x, world frame"),
    col("angvel_y", F64, "rad/s", "angular velocity y, world frame"),
    col("angvel_z", F64, "rad/s", "angular velocity z, world frame"),
];

/// Columns of the `contacts` table: one row per contact point in contact per frame.
const CONTACTS_COLUMNS: &[ColumnDef] = &[
    STEP,
    TIME,
    col(
        "pair_id",
        U32,
        "",
        "contact pair index in the scene's contact list",
    ),
    col("pair", Name(Dictionary::Pairs), "", "contact pair name"),
    col(
        "body_a",
        Name(Dictionary::Bodies),
        "",
        "first body of the pair (normals point from a to b)",
    ),
    col(
        "body_b",
        Name(Dictionary::Bodies),
        "",
        "second body of the pair (forces reported on b)",
    ),
    col(
        "point_index",
        U32,
        "",
        "point slot within the pair (vertex or axial sample)",
    ),
    col("depth", F64, "m", "penetration, positive when overlapping"),
    col(
        "depth_rate",
        F64,
        "m/s",
        "penetration rate, positive while approaching",
    ),
    col(
        "normal_force",
        F64,
        "N",
        "normal force along the normal on b (pushes b; negative at a depth minimum of the level-set \
         line law, which takes back part of its neighbours' force: docs/model.md §4)",
    ),
    col(
        "tangential_force_x",
        F64,
        "N",
        "friction force on body b, x, world frame",
    ),
    col(
        "tangential_force_y",
        F64,
        "N",
        "friction force on body b, y, world frame",
    ),
    col(
        "tangential_force_z",
        F64,
        "N",
        "friction force on body b, z, world frame",
    ),
    col(
        "slip_speed",
        F64,
        "m/s",
        "tangential relative speed of b over a",
    ),
    col(
        "point_x",
        F64,
        "m",
        "contact point x (midway between surfaces), world frame",
    ),
    col("point_y", F64, "m", "contact point y, world frame"),
    col("point_z", F64, "m", "contact point z, world frame"),
    col(
        "normal_x",
        F64,
        "1",
        "unit normal from a toward b, x, world frame",
    ),
    col(
        "normal_y",
        F64,
        "1",
        "unit normal from a toward b, y, world frame",
    ),
    col(
        "normal_z",
        F64,
        "1",
        "unit normal from a toward b, z, world frame",
    ),
];

/// Columns of the `energy` table: one row per frame.
const ENERGY_COLUMNS: &[ColumnDef] = &[
    STEP,
    TIME,
    col(
        "kinetic",
        F64,
        "J",
        "kinetic energy of the integrated bodies",
    ),
    col(
        "potential_gravity",
        F64,
        "J",
        "gravitational potential energy of the integrated bodies (zero at the origin)",
    ),
    col(
        "potential_contact",
        F64,
        "J",
        "elastic energy stored in the contacts",
    ),
    col(
        "total",
        F64,
        "J",
        "kinetic + potential_gravity + potential_contact",
    ),
    col(
        "drive_work",
        F64,
        "J",
        "work the prescribed motions (drives) have done on the bodies since t = 0",
    ),
    col(
        "load_work",
        F64,
        "J",
        "work the applied torques and forces have done since t = 0 (negative for a resisting moment)",
    ),
    col(
        "friction_work",
        F64,
        "J",
        "energy dissipated by contact friction since t = 0",
    ),
    col(
        "damping_work",
        F64,
        "J",
        "energy dissipated by the normal laws' damping since t = 0",
    ),
    col(
        "joint_work",
        F64,
        "J",
        "energy the penalty joints have taken since t = 0 (stored and dissipated)",
    ),
    col(
        "balance_error",
        F64,
        "J",
        "drive_work + load_work − (total − total at t = 0) − friction_work − damping_work − joint_work: \
         the energy the integrator made (+) or lost (−)",
    ),
];

/// Columns of the `summary` table: one row per contact pair.
const SUMMARY_COLUMNS: &[ColumnDef] = &[
    col(
        "pair_id",
        U32,
        "",
        "contact pair index in the scene's contact list",
    ),
    col("pair", Name(Dictionary::Pairs), "", "contact pair name"),
    col("window_start", F64, "s", "start of the summary window"),
    col("window_end", F64, "s", "end of the summary window"),
    col("frames", U64, "", "recorded frames in the window"),
    col(
        "normal_peak",
        F64,
        "N",
        "largest total normal force of the pair in the window: at the window's first frame and at every stage of the integrator's steps accepted after it (the frame's own value where a step spans several frames), so a peak between frames counts and the output interval does not move it",
    ),
    col(
        "normal_mean",
        F64,
        "N",
        "time mean of the total normal force over the window's frames: its impulse, as the integrator applied it over its own steps, between the first and the last frame over their distance (the frame's value for a window of one frame)",
    ),
    col(
        "normal_rms",
        F64,
        "N",
        "root mean square over time of the total normal force in the window: the growth of its integrated square, as the integrator applied the force over its own steps, between the first and the last frame, over their distance (over the frames for a window of one frame)",
    ),
    col(
        "tangential_peak",
        F64,
        "N",
        "largest magnitude of the summed friction force in the window, as normal_peak",
    ),
    col(
        "tangential_mean",
        F64,
        "N",
        "time mean of the magnitude of the summed friction force, as normal_mean",
    ),
    col(
        "tangential_rms",
        F64,
        "N",
        "root mean square over time of the magnitude of the summed friction force, as normal_rms",
    ),
];

/// The `bodies` table.
pub const BODIES: TableDef = TableDef {
    name: "bodies",
    row: "one row per recorded body per frame",
    columns: BODIES_COLUMNS,
};
/// The `contacts` table.
pub const CONTACTS: TableDef = TableDef {
    name: "contacts",
    row: "one row per contact point in contact per frame",
    columns: CONTACTS_COLUMNS,
};
/// The `energy` table.
pub const ENERGY: TableDef = TableDef {
    name: "energy",
    row: "one row per frame",
    columns: ENERGY_COLUMNS,
};
/// The `summary` table.
pub const SUMMARY: TableDef = TableDef {
    name: "summary",
    row: "one row per contact pair",
    columns: SUMMARY_COLUMNS,
};

/// The definition of an engine table.
pub fn table_def(kind: TableKind) -> &'static TableDef {
    match kind {
        TableKind::Bodies => &BODIES,
        TableKind::Contacts => &CONTACTS,
        TableKind::Energy => &ENERGY,
        TableKind::Summary => &SUMMARY,
    }
}

/// One value of a row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cell {
    /// For `U64` columns.
    U64(u64),
    /// For `U32` and `Name` columns.
    U32(u32),
    /// For `F64` columns.
    F64(f64),
    /// For `OptU32` and `OptName` columns.
    OptU32(Option<u32>),
    /// For `OptF64` columns.
    OptF64(Option<f64>),
}

/// Column data.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnData {
    /// u64 values.
    U64(Vec<u64>),
    /// u32 values (also dictionary keys).
    U32(Vec<u32>),
    /// f64 values.
    F64(Vec<f64>),
    /// u32 values or nulls.
    OptU32(Vec<Option<u32>>),
    /// f64 values or nulls.
    OptF64(Vec<Option<f64>>),
}

/// Columnar buffers of one table.
#[derive(Debug, Clone, PartialEq)]
pub struct TableBuffer {
    /// Which table.
    pub def: &'static TableDef,
    /// One buffer per column of `def.columns`, in order.
    pub data: Vec<ColumnData>,
    /// Number of rows.
    pub rows: usize,
}

impl TableBuffer {
    /// Empty buffers for the table `def`.
    pub fn new(def: &'static TableDef) -> Self {
        let data = def
            .columns
            .iter()
            .map(|c| match c.kind {
                U64 => ColumnData::U64(Vec::new()),
                U32 | Name(_) => ColumnData::U32(Vec::new()),
                F64 => ColumnData::F64(Vec::new()),
                OptU32 | OptName(_) => ColumnData::OptU32(Vec::new()),
                OptF64 => ColumnData::OptF64(Vec::new()),
            })
            .collect();
        Self { def, data, rows: 0 }
    }

    /// The buffer of the column named `name`, if the table has one.
    pub fn column(&self, name: &str) -> Option<&ColumnData> {
        let i = self.def.columns.iter().position(|c| c.name == name)?;
        self.data.get(i)
    }

    /// Appends a row; `row` follows the column order of the table.
    pub fn push(&mut self, row: &[Cell]) {
        debug_assert_eq!(
            row.len(),
            self.data.len(),
            "row width of table {}",
            self.def.name
        );
        for (d, v) in self.data.iter_mut().zip(row) {
            match (d, v) {
                (ColumnData::U64(d), Cell::U64(v)) => d.push(*v),
                (ColumnData::U32(d), Cell::U32(v)) => d.push(*v),
                (ColumnData::F64(d), Cell::F64(v)) => d.push(*v),
                (ColumnData::OptU32(d), Cell::OptU32(v)) => d.push(*v),
                (ColumnData::OptF64(d), Cell::OptF64(v)) => d.push(*v),
                (d, v) => panic!(
                    "cell {v:?} does not fit column {d:?} of table {}",
                    self.def.name
                ),
            }
        }
        self.rows += 1;
    }
}

/// All tables of a run plus the names the dictionary columns index.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Recorded tables: the engine's in the scene's order, then the observers'.
    pub tables: Vec<TableBuffer>,
    /// Body names by id.
    pub body_names: Vec<String>,
    /// Pair names by id.
    pub pair_names: Vec<String>,
    /// Labels of the bodies' parts ([`Dictionary::Parts`]); empty for a generic scene.
    pub part_labels: &'static [&'static str],
    /// Run metadata (key → value), written into the schema metadata.
    pub metadata: Vec<(String, String)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    const ENGINE: [&TableDef; 4] = [&BODIES, &CONTACTS, &ENERGY, &SUMMARY];

    #[test]
    fn column_names_are_unique_within_each_table() {
        for t in ENGINE {
            let cols = t.columns;
            for (i, c) in cols.iter().enumerate() {
                assert!(
                    cols[..i].iter().all(|o| o.name != c.name),
                    "{} repeated in {}",
                    c.name,
                    t.name
                );
            }
        }
    }

    #[test]
    fn every_float_column_states_a_unit() {
        for t in ENGINE {
            for c in t.columns {
                if c.kind == F64 {
                    assert!(!c.unit.is_empty(), "{} has no unit", c.name);
                }
            }
        }
    }

    #[test]
    fn every_engine_table_kind_has_its_definition() {
        for k in TableKind::ALL {
            assert_eq!(table_def(k).name, k.name());
        }
    }
}
