//! Filling the tables, one frame at a time.
//!
//! Each pair's contact points are evaluated once per frame and shared by
//! every table that needs them, the observers' included; nothing is
//! evaluated for tables the scene did not ask for.

use std::ops::Range;

use super::{BodyParts, Cell, Frame, Observer, Step, TableBuffer, contact_totals, table_def};
use crate::dynamics::{ContactEval, Dynamics, Energy, Evaluated, PairTotals};
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
    /// The pair's integrals at the first and the last frame of the window:
    /// (t [s], impulses [normal, friction] [N·s], ∫F² dt of both [N²·s]).
    first: Option<(f64, PairTotals, PairTotals)>,
    last: (f64, PairTotals, PairTotals),
}

impl PairStats {
    /// The time means of the normal force and of the friction force's
    /// magnitude [N]: the impulses' growth between the window's first and
    /// last frames over their distance ([`Frame::impulses`]); the mean over
    /// the frames for a window of one frame.
    fn means(&self) -> (f64, f64) {
        match self.first {
            Some((t0, i0, _)) if self.last.0 > t0 => {
                let (t1, i1, _) = self.last;
                let span = t1 - t0;
                ((i1[0] - i0[0]) / span, (i1[1] - i0[1]) / span)
            }
            _ => {
                let f = self.frames.max(1) as f64;
                (self.normal_sum / f, self.tangential_sum / f)
            }
        }
    }

    /// The root mean squares over time of the normal force and of the
    /// friction force's magnitude [N]: √(growth of ∫F² dt / length) between
    /// the window's first and last frames. Over the frames instead for a
    /// window of one frame, and where ∫F² dt is not finite (forces beyond
    /// about 1e150 N, whose squares overflow; the frames' sum is scaled).
    fn rms(&self) -> (f64, f64) {
        let f = self.frames.max(1) as f64;
        let frames = (self.normal_squares.rms(f), self.tangential_squares.rms(f));
        match self.first {
            Some((t0, _, q0)) if self.last.0 > t0 => {
                let (t1, _, q1) = self.last;
                let over_time = |i: usize, fallback: f64| {
                    let growth = q1[i] - q0[i];
                    if growth.is_finite() {
                        (growth.max(0.0) / (t1 - t0)).sqrt()
                    } else {
                        fallback
                    }
                };
                (over_time(0, frames.0), over_time(1, frames.1))
            }
            _ => frames,
        }
    }

    /// Adds a frame at `at` [s] with the pair's totals (n, t) [N], its
    /// impulses and ∫F² dt and its largest totals since the previous frame
    /// ([`Frame::peaks`]; both `None` when the simulation does not track
    /// them). The peaks are those of the integrator's stages, the window's
    /// first frame counting with its own totals: the largest over the
    /// steps that start within the window, whatever the output interval.
    fn add(
        &mut self,
        (n, t): (f64, f64),
        at: f64,
        integrals: Option<(PairTotals, PairTotals)>,
        peak: Option<PairTotals>,
    ) {
        if let Some((impulse, squares)) = integrals {
            self.first.get_or_insert((at, impulse, squares));
            self.last = (at, impulse, squares);
        }
        let [peak_n, peak_t] = peak.filter(|_| self.frames > 0).unwrap_or([n, t]);
        self.frames += 1;
        self.normal_peak = self.normal_peak.max(peak_n);
        self.normal_sum += n;
        self.normal_squares.add(n);
        self.tangential_peak = self.tangential_peak.max(peak_t);
        self.tangential_sum += t;
        self.tangential_squares.add(t);
    }
}

/// Where `t` [s] lies within the step `span` (its start and end [s]): the
/// fraction of the step, for a sum kept at both ends to be interpolated
/// linearly; `None` at or past its end (or before the first step), where
/// the sum at the end holds.
pub(crate) fn within_step((t0, t1): (f64, f64), t: f64) -> Option<f64> {
    (t < t1 && t1 > t0).then(|| ((t - t0) / (t1 - t0)).clamp(0.0, 1.0))
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

/// Energy taken out of the bodies since t = 0, integrated step by step by
/// the trapezoidal rule (the powers at both ends of each step; the first
/// step has only its end), for the `energy` table's balance. Second order
/// in the step: the balance then measures the integrator, not the
/// quadrature (docs/model.md §8.5), also with adaptive steps of a
/// millisecond, where the power at the end of each step times its length
/// was 1 % off (a ball sliding into rolling, 1.5e-3 of mv₀²/7 = 0.143 J).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Dissipated {
    /// By contact friction [J].
    friction: f64,
    /// By the normal laws' damping [J].
    damping: f64,
    /// Taken by the penalty joints, stored and dissipated [J].
    joints: f64,
    /// The three powers [W] at the end of the last step (`None` before the
    /// first step).
    power: Option<[f64; 3]>,
}

impl Dissipated {
    /// Adds the step of `h` [s] that ended at `state`, contacts `evals`.
    fn add(&mut self, model: &Model, state: &State, evals: &[Vec<ContactEval>], h: f64) {
        let (mut friction, mut damping) = (0.0, 0.0);
        for (pair, points) in model.pairs.iter().zip(evals) {
            for e in points {
                // Adams and tanh friction oppose the slip: −F_t·v_slip = |F_t|·|v_slip|,
                // times the point's weight (−1 at a level-set minimum, geometry::LineLaw).
                friction += e.point.weight * e.tangential_force.norm() * e.slip_speed;
                let elastic = e.point.weight * pair.normal.elastic_force(e.point.depth);
                damping += (e.normal_force - elastic) * e.depth_rate;
            }
        }
        let mut joints = 0.0;
        for j in &model.joints {
            let (w, ra, rb) = j.evaluate(state);
            let (wa, wb) = (state.omega_world(j.a), state.omega_world(j.b));
            joints -= w.force.dot(&(state.vel[j.b] + wb.cross(&rb))) + w.torque.dot(&wb)
                - w.force.dot(&(state.vel[j.a] + wa.cross(&ra)))
                - w.torque.dot(&wa);
        }
        let power = [friction, damping, joints];
        let before = self.power.replace(power).unwrap_or(power);
        let work = |k: usize| 0.5 * (before[k] + power[k]) * h;
        self.friction += work(0);
        self.damping += work(1);
        self.joints += work(2);
    }

    /// The energies a fraction `s` (0 to 1) of the way from `before` to `self`.
    fn between(&self, before: &Self, s: f64) -> Self {
        let mix = |x: f64, y: f64| x + s * (y - x);
        Self {
            friction: mix(before.friction, self.friction),
            damping: mix(before.damping, self.damping),
            joints: mix(before.joints, self.joints),
            power: self.power,
        }
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
    /// The bodies' part ids, from the first observer that has them.
    parts: BodyParts,
    evals: Vec<Vec<ContactEval>>,
    /// Whether `evals` holds the current state's points (evaluated by
    /// [`Self::after_step`] for the step that a frame then records).
    evals_current: bool,
    stats: Vec<PairStats>,
    needs_pairs: bool,
    /// Whether anything reads every step: the `energy` table or an observer.
    needs_steps: bool,
    dissipated: Dissipated,
    /// `dissipated` at the start of the last step, and that step's span
    /// [s]: a frame within the step takes the energies interpolated to its
    /// time.
    dissipated_before: Dissipated,
    step_span: (f64, f64),
    /// Mechanical energy at the first frame [J].
    initial_total: Option<f64>,
    /// Each pair's impulse at the frame being recorded, if the `summary`
    /// table or an observer reads it ([`Frame::impulses`]).
    needs_impulses: bool,
    impulses: Vec<PairTotals>,
    /// Each pair's largest totals since the previous frame ([`Frame::peaks`]).
    peaks: Vec<PairTotals>,
    /// Each pair's ∫F² dt of both totals at the frame [N²·s], for the
    /// `summary` table's RMS.
    squares: Vec<PairTotals>,
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
        let needs_steps = model.record.tables.contains(&TableKind::Energy)
            || observers.iter().any(|o| o.needs_steps());
        let parts = observers
            .iter()
            .find_map(|o| o.body_parts())
            .unwrap_or_default();
        let needs_impulses = model.record.tables.contains(&TableKind::Summary)
            || observers.iter().any(|o| o.needs_impulses());
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
            parts,
            evals: vec![Vec::new(); model.pairs.len()],
            evals_current: false,
            stats: vec![PairStats::default(); model.pairs.len()],
            needs_pairs,
            needs_steps,
            dissipated: Dissipated::default(),
            dissipated_before: Dissipated::default(),
            step_span: (0.0, 0.0),
            initial_total: None,
            needs_impulses,
            impulses: Vec::new(),
            peaks: Vec::new(),
            squares: Vec::new(),
        }
    }

    /// Whether the `summary` table or an observer reads the pairs'
    /// impulses (the simulation then has its [`Dynamics`] track them).
    pub fn needs_impulses(&self) -> bool {
        self.needs_impulses
    }

    /// Every pair's contact points with their forces at `state`, into `evals`.
    fn evaluate(&mut self, model: &Model, state: &State, dynamics: &mut Dynamics) {
        dynamics.all_contact_points(model, state, &mut self.evals);
    }

    /// Integrates what the `energy` table and the observers read every step
    /// over the step of length `h` [s] that ended at `state`, only if
    /// anything reads it. The contact points there are those of the last
    /// evaluation (`evaluated`: Newton's last iterate of an adaptive step),
    /// or evaluated once more at `state` (a fixed step, whose frame then
    /// reuses them).
    pub fn after_step(
        &mut self,
        model: &Model,
        state: &State,
        h: f64,
        dynamics: &mut Dynamics,
        evaluated: Evaluated,
    ) {
        if !self.needs_steps {
            return;
        }
        match evaluated {
            Evaluated::LastIterate => dynamics.last_contact_points(&mut self.evals),
            Evaluated::No => self.evaluate(model, state, dynamics),
        }
        self.evals_current = evaluated == Evaluated::No;
        self.dissipated_before = self.dissipated;
        self.step_span = (state.t - h, state.t);
        self.dissipated.add(model, state, &self.evals, h);
        let view = Step {
            model,
            state,
            h,
            contacts: &self.evals,
        };
        for r in &mut self.observers {
            if r.observer.needs_steps() {
                r.observer.step(&view);
            }
        }
    }

    /// What [`Self::after_step`] dissipated until `t` [s]: to the last
    /// step's end, interpolated linearly within that step.
    fn dissipated_at(&self, t: f64) -> Dissipated {
        match within_step(self.step_span, t) {
            Some(s) => self.dissipated.between(&self.dissipated_before, s),
            None => self.dissipated,
        }
    }

    /// Records the frame of `state` at integrator step `step`; `input_work`
    /// is the work of the drives and of the applied torques since t = 0 [J].
    pub fn record(
        &mut self,
        model: &Model,
        state: &State,
        step: u64,
        dynamics: &mut Dynamics,
        input_work: (f64, f64),
    ) {
        if self.needs_pairs && !self.evals_current {
            self.evaluate(model, state, dynamics);
        }
        self.evals_current = false;
        if self.needs_impulses {
            dynamics.impulses_at(state.t, &mut self.impulses);
            dynamics.squares_at(state.t, &mut self.squares);
            dynamics.take_peaks(&mut self.peaks);
            for (k, p) in self.peaks.iter_mut().enumerate() {
                if p[0] == f64::NEG_INFINITY {
                    let (n, t) = contact_totals(&self.evals, &[k]);
                    *p = [n, t];
                }
            }
        }
        let frame = (Cell::U64(step), Cell::F64(state.t));
        let dissipated = self.dissipated_at(state.t);
        for (table, kind) in self.tables.iter_mut().zip(&self.engine) {
            match kind {
                TableKind::Bodies => bodies(table, model, &self.parts, state, frame),
                TableKind::Contacts => contacts(table, model, &self.evals, frame),
                TableKind::Energy => {
                    let e = dynamics.energy(model, state);
                    let initial = *self.initial_total.get_or_insert(e.total());
                    energy(table, &e, initial, input_work, &dissipated, frame);
                }
                TableKind::Summary => {
                    let (start, end) = model.record.summary_window;
                    if state.t >= start - 1e-12 && state.t <= end + 1e-12 {
                        for (k, s) in self.stats.iter_mut().enumerate() {
                            let impulse = self.impulses.get(k).copied();
                            let integrals = impulse.zip(self.squares.get(k).copied());
                            let peak = self.peaks.get(k).copied();
                            s.add(contact_totals(&self.evals, &[k]), state.t, integrals, peak);
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
            impulses: &self.impulses,
            peaks: &self.peaks,
        };
        for r in &mut self.observers {
            r.observer.record(&view, &mut self.tables[r.tables.clone()]);
        }
    }

    /// Labels of the bodies' parts ([`BodyParts::labels`]).
    pub fn part_labels(&self) -> &'static [&'static str] {
        self.parts.labels
    }

    /// Writes the end-of-run rows (the summary, the observers') and hands
    /// over the tables.
    pub fn finish(mut self, model: &Model, end_time: f64) -> Vec<TableBuffer> {
        for r in &mut self.observers {
            r.observer
                .finish(model, end_time, &mut self.tables[r.tables.clone()]);
        }
        let (start, end) = model.record.summary_window;
        for (table, kind) in self.tables.iter_mut().zip(&self.engine) {
            if *kind != TableKind::Summary {
                continue;
            }
            for (k, s) in self.stats.iter().enumerate() {
                let (normal_mean, tangential_mean) = s.means();
                let (normal_rms, tangential_rms) = s.rms();
                table.push(&[
                    Cell::U32(k as u32),
                    Cell::U32(k as u32),
                    Cell::F64(start),
                    Cell::F64(end.min(end_time)),
                    Cell::U64(s.frames),
                    Cell::F64(s.normal_peak),
                    Cell::F64(normal_mean),
                    Cell::F64(normal_rms),
                    Cell::F64(s.tangential_peak),
                    Cell::F64(tangential_mean),
                    Cell::F64(tangential_rms),
                ]);
            }
        }
        self.tables
    }
}

fn bodies(
    table: &mut TableBuffer,
    model: &Model,
    parts: &BodyParts,
    s: &State,
    (step, t): (Cell, Cell),
) {
    for &i in &model.record.bodies {
        let (p, q, v, w) = (s.pos[i], s.rot[i], s.vel[i], s.omega_world(i));
        let ids = parts.of(i);
        table.push(&[
            step,
            t,
            Cell::U32(i as u32),
            Cell::U32(i as u32),
            Cell::OptU32(ids.part),
            Cell::OptU32(ids.link),
            Cell::OptU32(ids.hinge),
            Cell::OptU32(ids.key),
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
    e: &Energy,
    initial: f64,
    (drive, load): (f64, f64),
    out: &Dissipated,
    (step, t): (Cell, Cell),
) {
    let error = drive + load - (e.total() - initial) - out.friction - out.damping - out.joints;
    table.push(&[
        step,
        t,
        Cell::F64(e.kinetic),
        Cell::F64(e.potential_gravity),
        Cell::F64(e.potential_contact),
        Cell::F64(e.total()),
        Cell::F64(drive),
        Cell::F64(load),
        Cell::F64(out.friction),
        Cell::F64(out.damping),
        Cell::F64(out.joints),
        Cell::F64(error),
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
