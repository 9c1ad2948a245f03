//! Filling the tables, one frame at a time.
//!
//! Each pair's contact points are evaluated once per frame and shared by
//! every table that needs them, the observers' included; nothing is
//! evaluated for tables the scene did not ask for.

use std::ops::Range;

use super::{Cell, Frame, Observer, TableBuffer, contact_totals, table_def};
use crate::dynamics::{ContactEval, Dynamics};
use crate::model::{Model, State};
use crate::scene::TableKind;

/// Running per-pair force statistics for the `summary` table.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct PairStats {
    frames: u64,
    normal_peak: f64,
    normal_sum: f64,
    normal_squares: SumOfSquares,
    tangential_peak: f64,
    tangential_sum: f64,
    tangential_squares: SumOfSquares,
}

impl PairStats {
    fn add(&mut self, (n, t): (f64, f64)) {
        self.frames += 1;
        self.normal_peak = self.normal_peak.max(n);
        self.normal_sum += n;
        self.normal_squares.add(n);
        self.tangential_peak = self.tangential_peak.max(t);
        self.tangential_sum += t;
        self.tangential_squares.add(t);
    }
}

/// Σx² kept as `scale`²·`ssq` (as LAPACK's dnrm2), so that forces above
/// 1e154 N, whose squares overflow f64, still give a finite RMS (found by
/// fuzzing).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct SumOfSquares {
    scale: f64,
    ssq: f64,
}

impl SumOfSquares {
    fn add(&mut self, x: f64) {
        let a = x.abs();
        if a == 0.0 || a.is_nan() {
            return;
        }
        if a > self.scale {
            self.ssq = 1.0 + self.ssq * (self.scale / a) * (self.scale / a);
            self.scale = a;
        } else {
            self.ssq += (a / self.scale) * (a / self.scale);
        }
    }

    /// √(Σx² / n).
    fn rms(&self, n: f64) -> f64 {
        self.scale * (self.ssq / n).sqrt()
    }
}

/// An observer and the range of [`Recorder::tables`] it fills.
#[derive(Debug, Clone)]
struct Registered {
    observer: Box<dyn Observer>,
    tables: Range<usize>,
}

/// The tables of a run and the scratch to fill them.
#[derive(Debug, Clone)]
pub struct Recorder {
    /// The engine's tables in the scene's order, then each observer's.
    tables: Vec<TableBuffer>,
    /// The engine's tables, the first `engine.len()` of `tables`.
    engine: Vec<TableKind>,
    observers: Vec<Registered>,
    evals: Vec<Vec<ContactEval>>,
    stats: Vec<PairStats>,
    needs_pairs: bool,
}

impl Recorder {
    /// Empty tables for the model's recording plan and for each observer.
    pub fn new(model: &Model, observers: Vec<Box<dyn Observer>>) -> Self {
        let mut tables: Vec<TableBuffer> = model
            .record
            .tables
            .iter()
            .map(|k| TableBuffer::new(table_def(*k)))
            .collect();
        let engine = model.record.tables.clone();
        let needs_pairs = model
            .record
            .tables
            .iter()
            .any(|k| matches!(k, TableKind::Contacts | TableKind::Summary))
            || observers.iter().any(|o| o.needs_contacts());
        let observers = observers
            .into_iter()
            .map(|observer| {
                let start = tables.len();
                tables.extend(observer.tables().into_iter().map(TableBuffer::new));
                Registered {
                    observer,
                    tables: start..tables.len(),
                }
            })
            .collect();
        Self {
            tables,
            engine,
            observers,
            evals: vec![Vec::new(); model.pairs.len()],
            stats: vec![PairStats::default(); model.pairs.len()],
            needs_pairs,
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
        for (table, kind) in self.tables.iter_mut().zip(&self.engine) {
            match kind {
                TableKind::Bodies => bodies(table, model, state, frame),
                TableKind::Contacts => contacts(table, model, &self.evals, frame),
                TableKind::Energy => energy(table, model, state, dynamics, frame),
                TableKind::Summary => {
                    let (start, end) = model.record.summary_window;
                    if state.t >= start - 1e-12 && state.t <= end + 1e-12 {
                        for (k, s) in self.stats.iter_mut().enumerate() {
                            s.add(contact_totals(&self.evals, &[k]));
                        }
                    }
                }
            }
        }
        let view = Frame {
            model,
            state,
            step,
            contacts: &self.evals,
        };
        for r in &mut self.observers {
            r.observer.record(&view, &mut self.tables[r.tables.clone()]);
        }
    }

    /// Writes the end-of-run rows (the summary) and hands over the tables.
    pub fn finish(mut self, model: &Model, end_time: f64) -> Vec<TableBuffer> {
        let (start, end) = model.record.summary_window;
        for (table, kind) in self.tables.iter_mut().zip(&self.engine) {
            if *kind != TableKind::Summary {
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
                    Cell::F64(s.normal_squares.rms(f)),
                    Cell::F64(s.tangential_peak),
                    Cell::F64(s.tangential_sum / f),
                    Cell::F64(s.tangential_squares.rms(f)),
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

fn energy(
    table: &mut TableBuffer,
    model: &Model,
    state: &State,
    dynamics: &mut Dynamics,
    (step, t): (Cell, Cell),
) {
    let e = dynamics.energy(model, state);
    table.push(&[
        step,
        t,
        Cell::F64(e.kinetic),
        Cell::F64(e.potential_gravity),
        Cell::F64(e.potential_contact),
        Cell::F64(e.total()),
    ]);
}

#[cfg(test)]
mod tests {
    use super::SumOfSquares;

    #[test]
    fn rms_by_hand_and_beyond_the_square_overflow() {
        let mut s = SumOfSquares::default();
        for x in [3.0, 4.0, 0.0, -12.0] {
            s.add(x);
        }
        // (9 + 16 + 0 + 144) / 4 = 42.25
        assert!((s.rms(4.0) - 6.5).abs() < 1e-12);
        let mut big = SumOfSquares::default();
        big.add(2e220);
        big.add(2e220);
        assert!((big.rms(2.0) / 2e220 - 1.0).abs() < 1e-12);
    }
}
