//! The drill pipe's own output tables, filled by an [`Observer`] the
//! drill-pipe layer registers with the simulation: `links`, `hinges`,
//! `keys`, `drive`, `pairs` and `wear` (defined in [`super::wear`]). Parts
//! are identified by integer columns (`link`, `hinge`, `key`), never by
//! names.

use super::ids::{FEATURE, HINGE, KEY, LINK, PAIR, PAIR_ID, pair_cells};
use super::layout::{Feature, HingeLayout, KeyLayout, Layout, Part};
use super::spec::{DrillPipeSpec, PipeTable};
use super::stress::{PairStress, pair_stresses};
use super::wear::{PairWear, WEAR, wear_rows};
use crate::math::{Vec3, angle_between};
use crate::model::{Model, Motion, State};
use crate::record::{
    BodyParts, Cell, ColumnDef, ColumnKind, Dictionary, Frame, Observer, PartIds, STEP, Step, TIME,
    TableBuffer, TableDef, col, contact_totals,
};

use ColumnKind::{F64, Name, OptF64, OptU32, U32};

/// Columns of the `links` table (drill pipe): one row per link per frame.
const LINKS_COLUMNS: &[ColumnDef] = &[
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
    col(
        "offset_outward",
        F64,
        "m",
        "centre-of-mass offset from the tube centreline in the bend plane, + toward the outer wall of the bend",
    ),
    col(
        "offset_lateral",
        F64,
        "m",
        "centre-of-mass offset from the tube centreline out of the bend plane",
    ),
    col(
        "tube_normal",
        F64,
        "N",
        "total normal force of the link's contact with the tube",
    ),
    col(
        "tube_tangential",
        F64,
        "N",
        "magnitude of the summed friction force of the link's contact with the tube",
    ),
    col(
        "tube_pressure",
        F64,
        "Pa",
        "Hertz peak pressure p₀ of the link's most loaded tube contact: a line along the wall, an elliptical patch at a rim rounded to pipe.link_edge_radius; 0 without contact",
    ),
    col(
        "tube_normal_max",
        F64,
        "N",
        "largest tube_normal since the previous frame, at every stage of the integrator's steps accepted since then (this frame's own value at the first frame, or where a step spans several frames): the largest over a window of frames, whatever the output interval, is the largest of this column after the window's first frame and that frame's tube_normal",
    ),
    col(
        "tube_tangential_max",
        F64,
        "N",
        "largest tube_tangential since the previous frame, as tube_normal_max",
    ),
    col(
        "tube_normal_impulse",
        F64,
        "N*s",
        "integral of tube_normal from t = 0 to the frame, as the integrator applied it over its own steps (interpolated within an adaptive step); a mean over [a, b] is the difference over b - a",
    ),
    col(
        "tube_tangential_impulse",
        F64,
        "N*s",
        "integral of tube_tangential from t = 0 to the frame, as tube_normal_impulse",
    ),
];

/// Columns of the `hinges` table (drill pipe): one row per hinge per frame.
const HINGES_COLUMNS: &[ColumnDef] = &[
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
    col(
        "neck_normal",
        F64,
        "N",
        "normal force of the head's neck on the seat's mouth, the articulation limit (0 below it)",
    ),
    col(
        "neck_tangential",
        F64,
        "N",
        "friction force magnitude between the head's neck and the seat's mouth",
    ),
    col(
        "cage_head_pressure",
        F64,
        "Pa",
        "Hertz peak pressure p₀ between cage and ball head (sphere in a conforming cavity: an estimate once the patch nears the radius); 0 without contact",
    ),
    col(
        "cage_seat_pressure",
        F64,
        "Pa",
        "Hertz peak pressure p₀ between cage and ball seat, as cage_head_pressure",
    ),
    col(
        "torque_in",
        F64,
        "N*m",
        "spin torque the upper body hands to the hinge: minus the axial moment of the hinge's contacts and joint on it, about its own axis",
    ),
    col(
        "torque_out",
        F64,
        "N*m",
        "spin torque the hinge hands to the lower body: the axial moment of the hinge's contacts and joint on it, about its own axis",
    ),
    col(
        "power_in",
        F64,
        "W",
        "torque_in × the upper body's spin speed",
    ),
    col(
        "power_out",
        F64,
        "W",
        "torque_out × the lower body's spin speed; power_in − power_out is lost in the hinge (friction, damping) or stored in its cage and keys",
    ),
];

/// Columns of the `keys` table (drill pipe): one row per ball key per frame.
/// Race forces add both Gothic-arch flanks; window forces both window pairs.
const KEYS_COLUMNS: &[ColumnDef] = &[
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
    col(
        "inner_contact_angle_deg",
        OptF64,
        "deg",
        "operating contact angle on the inner race: the angle of the contact normal from the groove's radial direction, in the groove's cross-section, force-weighted over the flanks in contact (45 as designed); null without contact",
    ),
    col(
        "outer_contact_angle_deg",
        OptF64,
        "deg",
        "operating contact angle on the outer race, as inner_contact_angle_deg; null without contact",
    ),
    col(
        "inner_pressure",
        F64,
        "Pa",
        "Hertz peak pressure p₀ on the inner race: ball in the torus-section flank, the more loaded flank; 0 without contact",
    ),
    col(
        "outer_pressure",
        F64,
        "Pa",
        "Hertz peak pressure p₀ on the outer race, as inner_pressure",
    ),
    col(
        "window_pressure",
        F64,
        "Pa",
        "Hertz peak pressure p₀ on the cage window faces (ball on a flat); 0 without contact",
    ),
];

/// Columns of the `drive` table (drill pipe): one row per frame.
const DRIVE_COLUMNS: &[ColumnDef] = &[
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
    col(
        "friction_tube",
        F64,
        "W",
        "power friction dissipates between the links and the tube, Σ|F_t|·v_slip",
    ),
    col(
        "friction_key_race",
        F64,
        "W",
        "power friction dissipates between the ball keys and their races",
    ),
    col(
        "friction_key_window",
        F64,
        "W",
        "power friction dissipates between the ball keys and the cage windows",
    ),
    col(
        "friction_cage",
        F64,
        "W",
        "power friction dissipates between the cages and the ball heads and seats",
    ),
    col(
        "friction_neck",
        F64,
        "W",
        "power friction dissipates between the necks and the seats' mouths",
    ),
];

/// Columns of the `pairs` table (drill pipe): one row per contact pair, written once.
const PAIRS_COLUMNS: &[ColumnDef] = &[
    PAIR_ID,
    PAIR,
    FEATURE,
    LINK,
    HINGE,
    KEY,
    col(
        "face",
        OptU32,
        "",
        "race flank (0 the + flank, 1 the - flank) or window faces (0 axial, 1 side); null otherwise",
    ),
];

/// The `links` table.
pub const LINKS: TableDef = TableDef {
    name: "links",
    row: "one row per link per frame",
    columns: LINKS_COLUMNS,
};
/// The `hinges` table.
pub const HINGES: TableDef = TableDef {
    name: "hinges",
    row: "one row per hinge per frame",
    columns: HINGES_COLUMNS,
};
/// The `keys` table.
pub const KEYS: TableDef = TableDef {
    name: "keys",
    row: "one row per ball key per frame",
    columns: KEYS_COLUMNS,
};
/// The `drive` table.
pub const DRIVE: TableDef = TableDef {
    name: "drive",
    row: "one row per frame",
    columns: DRIVE_COLUMNS,
};

/// The `pairs` table.
pub const PAIRS: TableDef = TableDef {
    name: "pairs",
    row: "one row per contact pair, written with the first frame",
    columns: PAIRS_COLUMNS,
};

/// The drill pipe's tables, in the order `ballcage schema` lists them.
pub const TABLES: [&TableDef; 6] = [&LINKS, &HINGES, &KEYS, &DRIVE, &PAIRS, &WEAR];

/// The drill pipe's own table of a `record.tables` entry, if it is one.
pub fn table_def(table: PipeTable) -> Option<&'static TableDef> {
    match table {
        PipeTable::Links => Some(&LINKS),
        PipeTable::Hinges => Some(&HINGES),
        PipeTable::Keys => Some(&KEYS),
        PipeTable::Drive => Some(&DRIVE),
        PipeTable::Pairs => Some(&PAIRS),
        PipeTable::Wear => Some(&WEAR),
        PipeTable::Bodies | PipeTable::Contacts | PipeTable::Energy | PipeTable::Summary => None,
    }
}

/// Fills the drill pipe's tables the scene asked for.
#[derive(Debug, Clone)]
pub struct PipeTables {
    layout: Layout,
    tables: Vec<PipeTable>,
    /// The Hertz and wear model of each pair, by pair id.
    stress: Vec<PairStress>,
    /// The `wear` table's integrals, by pair id (empty unless it is recorded).
    wear: Vec<PairWear>,
    /// Window `[start, end]` of the wear integrals [s] (`record.summary_window`).
    window: (f64, f64),
}

impl PipeTables {
    /// An observer of the pipe `spec` laid out as `layout` in `model`,
    /// starting from `state`, for the drill-pipe entries of its
    /// `record.tables` (engine tables are skipped).
    pub fn new(spec: &DrillPipeSpec, layout: Layout, model: &Model, state: &State) -> Self {
        let tables: Vec<PipeTable> = spec
            .record
            .tables
            .iter()
            .copied()
            .filter(|t| table_def(*t).is_some())
            .collect();
        let stress = pair_stresses(spec, &layout, model, state);
        let wear = if tables.contains(&PipeTable::Wear) {
            vec![PairWear::default(); layout.pairs.len()]
        } else {
            vec![]
        };
        Self {
            layout,
            tables,
            stress,
            wear,
            window: model.record.summary_window,
        }
    }
}

impl Observer for PipeTables {
    fn tables(&self) -> Vec<&'static TableDef> {
        self.tables.iter().filter_map(|t| table_def(*t)).collect()
    }

    fn rows(&self, frames: u64) -> Vec<u64> {
        let l = &self.layout;
        let per_frame = |n: usize| frames.saturating_mul(n as u64);
        self.tables
            .iter()
            .map(|t| match t {
                PipeTable::Links => per_frame(l.chain.len().saturating_sub(2)),
                PipeTable::Hinges => per_frame(l.hinges.len()),
                PipeTable::Keys => per_frame(l.hinges.iter().map(|h| h.keys.len()).sum()),
                PipeTable::Drive => frames,
                PipeTable::Pairs | PipeTable::Wear => l.pairs.len() as u64,
                _ => 0,
            })
            .collect()
    }

    fn needs_contacts(&self) -> bool {
        self.tables.iter().any(|t| *t != PipeTable::Pairs)
    }

    fn record(&mut self, frame: &Frame<'_>, out: &mut [TableBuffer]) {
        let (layout, stress) = (&self.layout, &self.stress[..]);
        for (table, kind) in out.iter_mut().zip(&self.tables) {
            match kind {
                PipeTable::Links => links(table, layout, stress, frame),
                PipeTable::Hinges => hinges(table, layout, stress, frame),
                PipeTable::Keys => keys(table, layout, stress, frame),
                PipeTable::Drive => drive(table, layout, frame),
                PipeTable::Pairs => pairs(table, layout),
                _ => {}
            }
        }
    }

    fn needs_steps(&self) -> bool {
        !self.wear.is_empty()
    }

    fn needs_impulses(&self) -> bool {
        self.tables.contains(&PipeTable::Links)
    }

    fn step(&mut self, step: &Step<'_>) {
        let t = step.state.t;
        let (start, end) = self.window;
        // The part of the step (t − h, t] inside the window and the run
        // (an adaptive step may end past a window's edge, or the run's).
        let model = step.model;
        let end = end.min(model.total_steps as f64 * model.dt);
        let inside = (t.min(end) - (t - step.h).max(start)).max(0.0);
        // Round-off of a step that ends on an edge counts as outside.
        let inside = if inside <= 1e-12 * step.h {
            0.0
        } else {
            inside
        };
        for ((w, s), points) in self.wear.iter_mut().zip(&self.stress).zip(step.contacts) {
            w.add(s, step.state, points, inside);
        }
    }

    fn finish(&mut self, _model: &Model, end_time: f64, out: &mut [TableBuffer]) {
        let (start, end) = self.window;
        for (table, kind) in out.iter_mut().zip(&self.tables) {
            if *kind == PipeTable::Wear {
                let window = (start, end.min(end_time));
                wear_rows(table, &self.layout, &self.stress, &self.wear, window);
            }
        }
    }

    fn body_parts(&self) -> Option<BodyParts> {
        let ids = self.layout.bodies.iter().map(|b| PartIds {
            part: Some(b.part.code()),
            link: b.link,
            hinge: b.hinge,
            key: b.key,
        });
        Some(BodyParts {
            labels: Part::LABELS,
            ids: ids.collect(),
        })
    }

    fn clone_box(&self) -> Box<dyn Observer> {
        Box::new(self.clone())
    }
}

/// The `pairs` rows, once: with the first frame recorded.
fn pairs(table: &mut TableBuffer, layout: &Layout) {
    if table.rows > 0 {
        return;
    }
    for (k, p) in layout.pairs.iter().enumerate() {
        let [id, name, feature, link, hinge, key] = pair_cells(k, p);
        table.push(&[id, name, feature, link, hinge, key, Cell::OptU32(p.face)]);
    }
}

/// The step and time cells of a frame.
fn stamp(f: &Frame<'_>) -> (Cell, Cell) {
    (Cell::U64(f.step), Cell::F64(f.state.t))
}

/// World axis (body x) of body `i`.
fn axis(f: &Frame<'_>, i: usize) -> Vec3 {
    f.state.rot[i] * Vec3::x()
}

/// The largest Hertz peak pressure [Pa] of the points of `pairs` (0 without contact).
fn peak_pressure(stress: &[PairStress], f: &Frame<'_>, pairs: &[usize]) -> f64 {
    pairs
        .iter()
        .flat_map(|&k| f.contacts[k].iter().map(move |e| (k, e)))
        .map(|(k, e)| stress[k].patch(f.state, e).0.peak_pressure)
        .fold(0.0, f64::max)
}

fn links(table: &mut TableBuffer, layout: &Layout, stress: &[PairStress], f: &Frame<'_>) {
    let (step, t) = stamp(f);
    let chain = &layout.chain;
    for k in 1..chain.len().saturating_sub(1) {
        let i = chain[k];
        let d = axis(f, i);
        let (phi, theta) = super::chain::eq4_angles(&d);
        let c = f.state.pos[i];
        let (offset, outward, lateral) = layout.offsets(&c);
        let included = 180.0 - angle_between(&d, &axis(f, chain[k + 1])).to_degrees();
        let tube = &layout.tube_pairs[k - 1..k];
        let (tube_n, tube_t) = contact_totals(f.contacts, tube);
        let since = f.peak(layout.tube_pairs[k - 1]);
        table.push(&[
            step,
            t,
            Cell::U32(k as u32),
            Cell::U32(i as u32),
            Cell::F64(phi.to_degrees()),
            Cell::F64(theta.to_degrees()),
            Cell::F64(c.x),
            Cell::F64(c.y),
            Cell::F64(c.z),
            Cell::F64(offset),
            Cell::F64(included),
            Cell::F64(outward),
            Cell::F64(lateral),
            Cell::F64(tube_n),
            Cell::F64(tube_t),
            Cell::F64(peak_pressure(stress, f, tube)),
            Cell::F64(since[0]),
            Cell::F64(since[1]),
            Cell::F64(impulse(f, tube, 0)),
            Cell::F64(impulse(f, tube, 1)),
        ]);
    }
}

/// The summed impulse [N·s] of the pairs `pairs`: normal (`i` = 0) or
/// friction (`i` = 1), [`Frame::impulses`].
fn impulse(f: &Frame<'_>, pairs: &[usize], i: usize) -> f64 {
    pairs.iter().map(|&k| f.impulses[k][i]).sum()
}

fn hinges(table: &mut TableBuffer, layout: &Layout, stress: &[PairStress], f: &Frame<'_>) {
    let (step, t) = stamp(f);
    for (h, hinge) in layout.hinges.iter().enumerate() {
        let (upper, lower) = (layout.chain[h], layout.chain[h + 1]);
        let bend = angle_between(&axis(f, upper), &axis(f, lower));
        let (hn, ht) = contact_totals(f.contacts, hinge.cage_head.as_slice());
        let (sn, st) = contact_totals(f.contacts, hinge.cage_seat.as_slice());
        let (nn, nt) = contact_totals(f.contacts, hinge.neck.as_slice());
        let (torque_in, speed_in) = hinge_torque(f, hinge, upper, lower, upper);
        let (torque_out, speed_out) = hinge_torque(f, hinge, upper, lower, lower);
        table.push(&[
            step,
            t,
            Cell::U32(h as u32),
            Cell::F64(bend.to_degrees()),
            Cell::F64(hn),
            Cell::F64(ht),
            Cell::F64(sn),
            Cell::F64(st),
            Cell::F64(nn),
            Cell::F64(nt),
            Cell::F64(peak_pressure(stress, f, hinge.cage_head.as_slice())),
            Cell::F64(peak_pressure(stress, f, hinge.cage_seat.as_slice())),
            Cell::F64(-torque_in),
            Cell::F64(torque_out),
            Cell::F64(-torque_in * speed_in),
            Cell::F64(torque_out * speed_out),
        ]);
    }
}

/// The axial moment [N·m] of hinge `hinge`'s contacts (head, seat and neck
/// pairs of its keys and cage) and of its joint on `body` (its `upper` or
/// `lower` chain body), about that body's own axis (body x) through its
/// centre of mass, and the body's spin speed about that axis [rad/s].
fn hinge_torque(
    f: &Frame<'_>,
    hinge: &HingeLayout,
    upper: usize,
    lower: usize,
    body: usize,
) -> (f64, f64) {
    let (model, s) = (f.model, f.state);
    let pairs = hinge
        .cage_head
        .iter()
        .chain(&hinge.cage_seat)
        .chain(&hinge.neck)
        .chain(
            hinge
                .keys
                .iter()
                .flat_map(|k| k.inner.iter().chain(&k.outer)),
        )
        .copied();
    let contacts = crate::dynamics::pairs_torque(model, s, f.contacts, pairs, body);
    let joints: Vec3 = model
        .joints
        .iter()
        .filter(|j| (j.a, j.b) == (upper, lower) || (j.a, j.b) == (lower, upper))
        .map(|j| j.torque_on(s, body))
        .sum();
    let e = axis(f, body);
    ((contacts + joints).dot(&e), s.omega_world(body).dot(&e))
}

/// The operating contact angle [deg] of key `key` on the race of body
/// `race` (groove circle centred at `groove`, race body frame): for each
/// flank point in contact, the angle of its normal from the groove's radial
/// direction (ball centre away from the groove circle's centre, out of the
/// meridian plane) in the groove's cross-section; force-weighted over the
/// points of `pairs`. `None` without contact.
fn contact_angle(
    f: &Frame<'_>,
    key: &KeyLayout,
    race: usize,
    groove: &Vec3,
    pairs: &[usize],
) -> Option<f64> {
    let (s, q) = (f.state, f.state.rot[race]);
    let e_t = q * key.tangent;
    let r = s.pos[key.body] - (s.pos[race] + q * groove);
    let e_r = (r - r.dot(&e_t) * e_t).try_normalize(1e-15)?;
    let (mut sum, mut weight) = (0.0, 0.0);
    for &k in pairs {
        for e in &f.contacts[k] {
            let n = e.point.normal;
            sum += e.normal_force * n.dot(&e_t).abs().atan2(n.dot(&e_r).abs());
            weight += e.normal_force;
        }
    }
    (weight > 0.0).then(|| (sum / weight).to_degrees())
}

fn keys(table: &mut TableBuffer, layout: &Layout, stress: &[PairStress], f: &Frame<'_>) {
    let (step, t) = stamp(f);
    for (h, hinge) in layout.hinges.iter().enumerate() {
        let (head, seat) = (layout.chain[h], layout.chain[h + 1]);
        for (j, key) in hinge.keys.iter().enumerate() {
            let (i_n, i_t) = contact_totals(f.contacts, &key.inner);
            let (o_n, o_t) = contact_totals(f.contacts, &key.outer);
            let (w_n, w_t) = contact_totals(f.contacts, &key.window);
            let inner = contact_angle(f, key, head, &key.head_groove, &key.inner);
            let outer = contact_angle(f, key, seat, &key.seat_groove, &key.outer);
            table.push(&[
                step,
                t,
                Cell::U32(h as u32),
                Cell::U32(j as u32),
                Cell::F64(i_n),
                Cell::F64(i_t),
                Cell::F64(o_n),
                Cell::F64(o_t),
                Cell::F64(w_n),
                Cell::F64(w_t),
                Cell::OptF64(inner),
                Cell::OptF64(outer),
                Cell::F64(peak_pressure(stress, f, &key.inner)),
                Cell::F64(peak_pressure(stress, f, &key.outer)),
                Cell::F64(peak_pressure(stress, f, &key.window)),
            ]);
        }
    }
}

/// Speed [rad/s] and torque [N·m] of the drive on the upper connector: what
/// the contacts and joints take, plus what spins up the connector.
fn input(layout: &Layout, f: &Frame<'_>) -> (f64, f64) {
    let (model, s) = (f.model, f.state);
    let upper = layout.chain[0];
    let Motion::KinematicSpin(p) = model.bodies[upper].motion else {
        return (0.0, 0.0);
    };
    let joints: Vec3 = model.joints.iter().map(|j| j.torque_on(s, upper)).sum();
    let contact =
        (crate::dynamics::contact_torque(model, s, f.contacts, upper) + joints).dot(&p.axis);
    let inertia = p.axis.dot(
        &(s.rot[upper]
            * model.bodies[upper]
                .inertia
                .component_mul(&(s.rot[upper].inverse() * p.axis))),
    );
    (p.speed_at(s.t), inertia * p.acceleration_at(s.t) - contact)
}

/// Speed [rad/s] of the lower connector and the resisting moment on it [N·m].
fn output(layout: &Layout, f: &Frame<'_>) -> (f64, f64) {
    let (model, s) = (f.model, f.state);
    let lower = layout.chain[layout.chain.len() - 1];
    let Motion::Spin { axis, .. } = model.bodies[lower].motion else {
        return (0.0, 0.0);
    };
    let applied: f64 = model
        .torques
        .iter()
        .filter(|l| l.body == lower)
        .map(|l| l.torque(s.t).dot(&axis))
        .sum();
    (s.omega_world(lower).dot(&axis), -applied)
}

fn drive(table: &mut TableBuffer, layout: &Layout, f: &Frame<'_>) {
    let (step, t) = stamp(f);
    let (input_speed, input_torque) = input(layout, f);
    let (output_speed, output_torque) = output(layout, f);
    let p_in = input_torque * input_speed;
    let p_out = output_torque * output_speed;
    let efficiency = if p_in > 1e-9 { p_out / p_in } else { 0.0 };
    let friction = friction_by_feature(layout, f);
    table.push(&[
        step,
        t,
        Cell::F64(input_speed),
        Cell::F64(input_torque),
        Cell::F64(output_speed),
        Cell::F64(output_torque),
        Cell::F64(p_in),
        Cell::F64(p_out),
        Cell::F64(efficiency),
        Cell::F64(friction[0]),
        Cell::F64(friction[1]),
        Cell::F64(friction[2]),
        Cell::F64(friction[3]),
        Cell::F64(friction[4]),
    ]);
}

/// Power friction dissipates [W], Σ|F_t|·v_slip, in the tube, key–race,
/// key–window, cage (head and seat) and neck contacts.
fn friction_by_feature(layout: &Layout, f: &Frame<'_>) -> [f64; 5] {
    let mut out = [0.0; 5];
    for (part, points) in layout.pairs.iter().zip(f.contacts) {
        let i = match part.feature {
            Feature::Tube => 0,
            Feature::InnerRace | Feature::OuterRace => 1,
            Feature::Window => 2,
            Feature::CageHead | Feature::CageSeat => 3,
            Feature::NeckMouth => 4,
        };
        out[i] += points
            .iter()
            .map(|e| e.tangential_force.norm() * e.slip_speed)
            .sum::<f64>();
    }
    out
}
