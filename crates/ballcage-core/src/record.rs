//! What gets kept: the column definitions of every output table (the one
//! schema of the project) and columnar buffers filled once per frame.

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
    /// A name, dictionary-encoded with u32 keys into [`TableBuffer::dictionaries`].
    Name(Dictionary),
}

/// Which list of names a name column indexes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dictionary {
    /// Body names, indexed by body id.
    Bodies,
    /// Contact pair names, indexed by pair id.
    Pairs,
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

const fn col(
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

use ColumnKind::{F64, Name, U32, U64};

const STEP: ColumnDef = col("step", U64, "", "integrator step index of the frame");
const TIME: ColumnDef = col("t", F64, "s", "simulated time");

/// Columns of the `bodies` table: one row per recorded body per frame.
pub const BODIES: &[ColumnDef] = &[
    STEP,
    TIME,
    col("body_id", U32, "", "body index in the scene's body list"),
    col("body", Name(Dictionary::Bodies), "", "body name"),
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
pub const CONTACTS: &[ColumnDef] = &[
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
        "normal force magnitude (pushes b along the normal)",
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
pub const ENERGY: &[ColumnDef] = &[
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
];

/// The columns of a table.
pub fn columns(table: TableKind) -> &'static [ColumnDef] {
    match table {
        TableKind::Bodies => BODIES,
        TableKind::Contacts => CONTACTS,
        TableKind::Energy => ENERGY,
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
}

/// Columnar buffers of one table.
#[derive(Debug, Clone, PartialEq)]
pub struct TableBuffer {
    /// Which table.
    pub kind: TableKind,
    /// One buffer per column of [`columns`]`(kind)`, in order.
    pub data: Vec<ColumnData>,
    /// Number of rows.
    pub rows: usize,
}

impl TableBuffer {
    /// Empty buffers for `kind`.
    pub fn new(kind: TableKind) -> Self {
        let data = columns(kind)
            .iter()
            .map(|c| match c.kind {
                U64 => ColumnData::U64(Vec::new()),
                U32 | Name(_) => ColumnData::U32(Vec::new()),
                F64 => ColumnData::F64(Vec::new()),
            })
            .collect();
        Self {
            kind,
            data,
            rows: 0,
        }
    }

    /// Appends a row; `row` follows the column order of the table.
    pub fn push(&mut self, row: &[Cell]) {
        debug_assert_eq!(
            row.len(),
            self.data.len(),
            "row width of table {:?}",
            self.kind
        );
        for (d, v) in self.data.iter_mut().zip(row) {
            match (d, v) {
                (ColumnData::U64(d), Cell::U64(v)) => d.push(*v),
                (ColumnData::U32(d), Cell::U32(v)) => d.push(*v),
                (ColumnData::F64(d), Cell::F64(v)) => d.push(*v),
                (d, v) => panic!(
                    "cell {v:?} does not fit column {d:?} of table {:?}",
                    self.kind
                ),
            }
        }
        self.rows += 1;
    }
}

/// All tables of a run plus the names the dictionary columns index.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Recorded tables, in the scene's order.
    pub tables: Vec<TableBuffer>,
    /// Body names by id.
    pub body_names: Vec<String>,
    /// Pair names by id.
    pub pair_names: Vec<String>,
    /// Run metadata (key → value), written into the schema metadata.
    pub metadata: Vec<(String, String)>,
}

impl Recording {
    /// Names for a dictionary.
    pub fn dictionary(&self, d: Dictionary) -> &[String] {
        match d {
            Dictionary::Bodies => &self.body_names,
            Dictionary::Pairs => &self.pair_names,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn column_names_are_unique_within_each_table() {
        for t in [TableKind::Bodies, TableKind::Contacts, TableKind::Energy] {
            let cols = columns(t);
            for (i, c) in cols.iter().enumerate() {
                assert!(
                    cols[..i].iter().all(|o| o.name != c.name),
                    "{} repeated in {t:?}",
                    c.name
                );
            }
        }
    }

    #[test]
    fn every_float_column_states_a_unit() {
        for t in [TableKind::Bodies, TableKind::Contacts, TableKind::Energy] {
            for c in columns(t) {
                if c.kind == F64 {
                    assert!(!c.unit.is_empty(), "{} has no unit", c.name);
                }
            }
        }
    }
}
