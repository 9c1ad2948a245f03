//! What gets kept: the column definitions of every output table (the one
//! schema of the project) and columnar buffers filled once per frame.

mod frame;

pub use frame::Recorder;

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

/// Columns of the `summary` table: one row per contact pair.
pub const SUMMARY: &[ColumnDef] = &[
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
        "largest per-frame total normal force of the pair",
    ),
    col(
        "normal_mean",
        F64,
        "N",
        "mean per-frame total normal force (frames without contact count as 0)",
    ),
    col(
        "normal_rms",
        F64,
        "N",
        "root mean square of the per-frame total normal force",
    ),
    col(
        "tangential_peak",
        F64,
        "N",
        "largest per-frame magnitude of the summed friction force",
    ),
    col(
        "tangential_mean",
        F64,
        "N",
        "mean per-frame magnitude of the summed friction force",
    ),
    col(
        "tangential_rms",
        F64,
        "N",
        "root mean square of the per-frame friction force magnitude",
    ),
];

/// Columns of the `links` table (drill pipe): one row per link per frame.
pub const LINKS: &[ColumnDef] = &[
    STEP,
    TIME,
    col(
        "link",
        U32,
        "",
        "link number, 1 at the top (the paper's joint number)",
    ),
    col("body", Name(Dictionary::Bodies), "", "body name"),
    col(
        "inclination_deg",
        F64,
        "deg",
        "eq. (4) φ: angle of the link axis from the downward vertical",
    ),
    col(
        "azimuth_deg",
        F64,
        "deg",
        "eq. (4) θ: azimuth of the link axis about the vertical, from the bend direction (+x)",
    ),
    col("com_x", F64, "m", "centre of mass x, world frame"),
    col("com_y", F64, "m", "centre of mass y, world frame"),
    col("com_z", F64, "m", "centre of mass z, world frame"),
    col(
        "radial_offset",
        F64,
        "m",
        "distance of the centre of mass from the tube centreline (extended straight past the arc)",
    ),
    col(
        "included_angle_deg",
        F64,
        "deg",
        "angle between this link's axis and the next body's, 180 when straight",
    ),
];

/// Columns of the `hinges` table (drill pipe): one row per hinge per frame.
pub const HINGES: &[ColumnDef] = &[
    STEP,
    TIME,
    col(
        "hinge",
        U32,
        "",
        "hinge number, 0 between the upper connector and link 1",
    ),
    col("bend_deg", F64, "deg", "angle between the two bodies' axes"),
    col(
        "cage_head_normal",
        F64,
        "N",
        "normal force between cage and ball head",
    ),
    col(
        "cage_head_tangential",
        F64,
        "N",
        "friction force magnitude between cage and ball head",
    ),
    col(
        "cage_seat_normal",
        F64,
        "N",
        "normal force between cage and ball seat",
    ),
    col(
        "cage_seat_tangential",
        F64,
        "N",
        "friction force magnitude between cage and ball seat",
    ),
];

/// Columns of the `keys` table (drill pipe): one row per ball key per frame.
/// Race forces add both Gothic-arch flanks; window forces both window pairs.
pub const KEYS: &[ColumnDef] = &[
    STEP,
    TIME,
    col("hinge", U32, "", "hinge number"),
    col("key", U32, "", "ball key number, 0–5 around the joint"),
    col(
        "inner_normal",
        F64,
        "N",
        "normal force on the inner race (ball head grooves), both flanks",
    ),
    col(
        "inner_tangential",
        F64,
        "N",
        "friction force magnitude on the inner race",
    ),
    col(
        "outer_normal",
        F64,
        "N",
        "normal force on the outer race (ball seat grooves), both flanks",
    ),
    col(
        "outer_tangential",
        F64,
        "N",
        "friction force magnitude on the outer race",
    ),
    col(
        "window_normal",
        F64,
        "N",
        "normal force on the cage window faces",
    ),
    col(
        "window_tangential",
        F64,
        "N",
        "friction force magnitude on the cage window faces",
    ),
];

/// Columns of the `drive` table (drill pipe): one row per frame.
pub const DRIVE: &[ColumnDef] = &[
    STEP,
    TIME,
    col(
        "input_speed",
        F64,
        "rad/s",
        "prescribed spin speed of the upper connector",
    ),
    col(
        "input_torque",
        F64,
        "N*m",
        "torque the drive applies to the upper connector about its axis",
    ),
    col(
        "output_speed",
        F64,
        "rad/s",
        "spin speed of the lower connector",
    ),
    col(
        "output_torque",
        F64,
        "N*m",
        "resisting moment applied to the lower connector (opposing its spin)",
    ),
    col("input_power", F64, "W", "input_torque × input_speed"),
    col("output_power", F64, "W", "output_torque × output_speed"),
    col(
        "efficiency",
        F64,
        "1",
        "output_power / input_power; 0 while the input power is not positive",
    ),
];

/// The columns of a table.
pub fn columns(table: TableKind) -> &'static [ColumnDef] {
    match table {
        TableKind::Bodies => BODIES,
        TableKind::Contacts => CONTACTS,
        TableKind::Energy => ENERGY,
        TableKind::Summary => SUMMARY,
        TableKind::Links => LINKS,
        TableKind::Hinges => HINGES,
        TableKind::Keys => KEYS,
        TableKind::Drive => DRIVE,
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
        for t in TableKind::ALL {
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
        for t in TableKind::ALL {
            for c in columns(t) {
                if c.kind == F64 {
                    assert!(!c.unit.is_empty(), "{} has no unit", c.name);
                }
            }
        }
    }
}
