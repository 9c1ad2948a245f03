//! Filling the tables, one frame at a time.
//!
//! Each pair's contact points are evaluated once per frame and shared by
//! every table that needs them; nothing is evaluated for tables the scene
//! did not ask for.

use crate::dynamics::{ContactEval, Dynamics};
use crate::math::Vec3;
use crate::model::{Model, Motion, State};
use crate::record::{Cell, TableBuffer};
use crate::scene::TableKind;

/// Running per-pair force statistics for the `summary` table.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct PairStats {
    frames: u64,
    normal_peak: f64,
    normal_sum: f64,
    normal_sumsq: f64,
    tangential_peak: f64,
    tangential_sum: f64,
    tangential_sumsq: f64,
}

/// Total normal force and friction magnitude of a set of points.
fn totals(evals: &[ContactEval]) -> (f64, f64) {
    let n: f64 = evals.iter().map(|e| e.normal_force).sum();
    let t: Vec3 = evals.iter().map(|e| e.tangential_force).sum();
    (n, t.norm())
}

/// The tables of a run and the scratch to fill them.
#[derive(Debug, Clone)]
pub struct Recorder {
    /// The tables, in the scene's order.
    pub tables: Vec<TableBuffer>,
    evals: Vec<Vec<ContactEval>>,
    stats: Vec<PairStats>,
    needs_pairs: bool,
}

impl Recorder {
    /// Empty tables for the model's recording plan.
    pub fn new(model: &Model) -> Self {
        let kinds = &model.record.tables;
        Self {
            tables: kinds.iter().map(|k| TableBuffer::new(*k)).collect(),
            evals: vec![Vec::new(); model.pairs.len()],
            stats: vec![PairStats::default(); model.pairs.len()],
            needs_pairs: kinds.iter().any(|k| {
                matches!(
                    k,
                    TableKind::Contacts
                        | TableKind::Summary
                        | TableKind::Hinges
                        | TableKind::Keys
                        | TableKind::Drive
                )
            }),
        }
    }

    /// Records the frame of `state` at integrator step `step`.
    pub fn record(&mut self, model: &Model, state: &State, step: u64, dynamics: &mut Dynamics) {
        if self.needs_pairs {
            for (k, out) in self.evals.iter_mut().enumerate() {
                out.clear();
                dynamics.contact_points(model, state, k, out);
            }
        }
        let frame = (Cell::U64(step), Cell::F64(state.t));
        for k in 0..self.tables.len() {
            let kind = self.tables[k].kind;
            let table = &mut self.tables[k];
            match kind {
                TableKind::Bodies => bodies(table, model, state, frame),
                TableKind::Contacts => contacts(table, model, &self.evals, frame),
                TableKind::Energy => {
                    let e = dynamics.energy(model, state);
                    table.push(&[
                        frame.0,
                        frame.1,
                        Cell::F64(e.kinetic),
                        Cell::F64(e.potential_gravity),
                        Cell::F64(e.potential_contact),
                        Cell::F64(e.total()),
                    ]);
                }
                TableKind::Summary => {
                    let (start, end) = model.record.summary_window;
                    if state.t >= start - 1e-12 && state.t <= end + 1e-12 {
                        for (s, ev) in self.stats.iter_mut().zip(&self.evals) {
                            let (n, t) = totals(ev);
                            s.frames += 1;
                            s.normal_peak = s.normal_peak.max(n);
                            s.normal_sum += n;
                            s.normal_sumsq += n * n;
                            s.tangential_peak = s.tangential_peak.max(t);
                            s.tangential_sum += t;
                            s.tangential_sumsq += t * t;
                        }
                    }
                }
                TableKind::Links => links(table, model, state, frame),
                TableKind::Hinges => hinges(table, model, state, &self.evals, frame),
                TableKind::Keys => keys(table, model, &self.evals, frame),
                TableKind::Drive => drive(table, model, state, &self.evals, frame),
            }
        }
    }

    /// Writes the end-of-run rows (the summary) and hands over the tables.
    pub fn finish(mut self, model: &Model, end_time: f64) -> Vec<TableBuffer> {
        let (start, end) = model.record.summary_window;
        for table in &mut self.tables {
            if table.kind != TableKind::Summary {
                continue;
            }
            for (k, s) in self.stats.iter().enumerate() {
                let f = s.frames.max(1) as f64;
                table.push(&[
                    Cell::U32(k as u32),
                    Cell::U32(k as u32),
                    Cell::F64(start),
                    Cell::F64(end.min(end_time)),
                    Cell::U64(s.frames),
                    Cell::F64(s.normal_peak),
                    Cell::F64(s.normal_sum / f),
                    Cell::F64((s.normal_sumsq / f).sqrt()),
                    Cell::F64(s.tangential_peak),
                    Cell::F64(s.tangential_sum / f),
                    Cell::F64((s.tangential_sumsq / f).sqrt()),
                ]);
            }
        }
        self.tables
    }
}

fn bodies(table: &mut TableBuffer, model: &Model, s: &State, (step, t): (Cell, Cell)) {
    for &i in &model.record.bodies {
        let (p, q, v, w) = (s.pos[i], s.rot[i], s.vel[i], s.omega_world(i));
        table.push(&[
            step,
            t,
            Cell::U32(i as u32),
            Cell::U32(i as u32),
            Cell::F64(p.x),
            Cell::F64(p.y),
            Cell::F64(p.z),
            Cell::F64(q.w),
            Cell::F64(q.i),
            Cell::F64(q.j),
            Cell::F64(q.k),
            Cell::F64(v.x),
            Cell::F64(v.y),
            Cell::F64(v.z),
            Cell::F64(w.x),
            Cell::F64(w.y),
            Cell::F64(w.z),
        ]);
    }
}

fn contacts(
    table: &mut TableBuffer,
    model: &Model,
    evals: &[Vec<ContactEval>],
    (step, t): (Cell, Cell),
) {
    for &k in &model.record.pairs {
        let pair = &model.pairs[k];
        for e in &evals[k] {
            let (f, p, n) = (e.tangential_force, e.point.point, e.point.normal);
            table.push(&[
                step,
                t,
                Cell::U32(k as u32),
                Cell::U32(k as u32),
                Cell::U32(pair.a as u32),
                Cell::U32(pair.b as u32),
                Cell::U32(e.point.slot),
                Cell::F64(e.point.depth),
                Cell::F64(e.depth_rate),
                Cell::F64(e.normal_force),
                Cell::F64(f.x),
                Cell::F64(f.y),
                Cell::F64(f.z),
                Cell::F64(e.slip_speed),
                Cell::F64(p.x),
                Cell::F64(p.y),
                Cell::F64(p.z),
                Cell::F64(n.x),
                Cell::F64(n.y),
                Cell::F64(n.z),
            ]);
        }
    }
}

/// World axis (body x) of body `i`.
fn axis(s: &State, i: usize) -> Vec3 {
    s.rot[i] * Vec3::x()
}

/// Angle between two unit vectors [deg], robust near 0 and 180.
fn angle_deg(a: &Vec3, b: &Vec3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b)).to_degrees()
}

fn links(table: &mut TableBuffer, model: &Model, s: &State, (step, t): (Cell, Cell)) {
    let Some(layout) = &model.drill_pipe else {
        return;
    };
    let chain = &layout.chain;
    for k in 1..chain.len().saturating_sub(1) {
        let i = chain[k];
        let d = axis(s, i);
        let (phi, theta) = crate::drillpipe::chain::eq4_angles(&d);
        let (inclination, azimuth) = (phi.to_degrees(), theta.to_degrees());
        let c = s.pos[i];
        let offset = layout.centreline.nearest(&c).map_or_else(
            || (c - layout.centreline.point_at(0.0).point).norm(),
            |n| (c - n.point).norm(),
        );
        let included = 180.0 - angle_deg(&d, &axis(s, chain[k + 1]));
        table.push(&[
            step,
            t,
            Cell::U32(k as u32),
            Cell::U32(i as u32),
            Cell::F64(inclination),
            Cell::F64(azimuth),
            Cell::F64(c.x),
            Cell::F64(c.y),
            Cell::F64(c.z),
            Cell::F64(offset),
            Cell::F64(included),
        ]);
    }
}

fn sum_pairs(evals: &[Vec<ContactEval>], pairs: &[usize]) -> (f64, f64) {
    let mut n = 0.0;
    let mut f = Vec3::zeros();
    for &k in pairs {
        for e in &evals[k] {
            n += e.normal_force;
            f += e.tangential_force;
        }
    }
    (n, f.norm())
}

fn hinges(
    table: &mut TableBuffer,
    model: &Model,
    s: &State,
    evals: &[Vec<ContactEval>],
    (step, t): (Cell, Cell),
) {
    let Some(layout) = &model.drill_pipe else {
        return;
    };
    for (h, hinge) in layout.hinges.iter().enumerate() {
        let bend = angle_deg(&axis(s, layout.chain[h]), &axis(s, layout.chain[h + 1]));
        let (hn, ht) = sum_pairs(evals, hinge.cage_head.as_slice());
        let (sn, st) = sum_pairs(evals, hinge.cage_seat.as_slice());
        table.push(&[
            step,
            t,
            Cell::U32(h as u32),
            Cell::F64(bend),
            Cell::F64(hn),
            Cell::F64(ht),
            Cell::F64(sn),
            Cell::F64(st),
        ]);
    }
}

fn keys(
    table: &mut TableBuffer,
    model: &Model,
    evals: &[Vec<ContactEval>],
    (step, t): (Cell, Cell),
) {
    let Some(layout) = &model.drill_pipe else {
        return;
    };
    for (h, hinge) in layout.hinges.iter().enumerate() {
        for (j, key) in hinge.keys.iter().enumerate() {
            let (i_n, i_t) = sum_pairs(evals, &key.inner);
            let (o_n, o_t) = sum_pairs(evals, &key.outer);
            let (w_n, w_t) = sum_pairs(evals, &key.window);
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
            ]);
        }
    }
}

fn drive(
    table: &mut TableBuffer,
    model: &Model,
    s: &State,
    evals: &[Vec<ContactEval>],
    (step, t): (Cell, Cell),
) {
    let Some(layout) = &model.drill_pipe else {
        return;
    };
    let (Some(&upper), Some(&lower)) = (layout.chain.first(), layout.chain.last()) else {
        return;
    };
    let (input_speed, input_torque) = match model.bodies[upper].motion {
        Motion::KinematicSpin(p) => {
            // The drive supplies what the contacts and joints take plus what spins up the connector.
            let joints: Vec3 = model.joints.iter().map(|j| j.torque_on(s, upper)).sum();
            let contact = (contact_torque(model, s, evals, upper) + joints).dot(&p.axis);
            let inertia = p.axis.dot(
                &(s.rot[upper]
                    * model.bodies[upper]
                        .inertia
                        .component_mul(&(s.rot[upper].inverse() * p.axis))),
            );
            (p.speed_at(s.t), inertia * p.acceleration_at(s.t) - contact)
        }
        _ => (0.0, 0.0),
    };
    let (output_speed, output_torque) = match model.bodies[lower].motion {
        Motion::Spin { axis, .. } => {
            let applied: f64 = model
                .torques
                .iter()
                .filter(|l| l.body == lower)
                .map(|l| l.torque(s.t).dot(&axis))
                .sum();
            (s.omega_world(lower).dot(&axis), -applied)
        }
        _ => (0.0, 0.0),
    };
    let p_in = input_torque * input_speed;
    let p_out = output_torque * output_speed;
    let efficiency = if p_in > 1e-9 { p_out / p_in } else { 0.0 };
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
    ]);
}

/// Torque of all contact forces on body `i` about its centre of mass [N·m], world frame.
fn contact_torque(model: &Model, s: &State, evals: &[Vec<ContactEval>], i: usize) -> Vec3 {
    let mut tau = Vec3::zeros();
    for (pair, ev) in model.pairs.iter().zip(evals) {
        let sign = if pair.b == i {
            1.0
        } else if pair.a == i {
            -1.0
        } else {
            continue;
        };
        for e in ev {
            let f = e.point.normal * e.normal_force + e.tangential_force;
            tau += sign * (e.point.point - s.pos[i]).cross(&f);
        }
    }
    tau
}
