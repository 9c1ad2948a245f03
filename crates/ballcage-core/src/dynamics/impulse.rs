//! The contact impulse each pair took over the run, as the integrator
//! applied it.
//!
//! A step of a Runge–Kutta method changes the velocities by h·Σ_j b_j·A_j:
//! the force the step applies is the stage forces weighted by b. So each
//! pair's impulse over a step is h·Σ_j b_j·F_j, with F_j the pair's total
//! at stage j's last evaluation (for a stage solved by Newton, its last
//! iterate). Summed over the accepted steps this is the integrator's own
//! quadrature of the force, of the method's order (third for ESDIRK3(2)),
//! and it does not depend on which frames are recorded. A mean force over a
//! window is then the difference of the cumulative impulse over the
//! window's length. For a frame within an adaptive step, the cumulative
//! impulse is interpolated (cubic Hermite, its slopes the pair's totals at
//! the step's ends, limited so that it never decreases).
//!
//! Per pair two scalars are integrated: the total normal force and the
//! magnitude of the summed friction force [N], the quantities of the
//! drill pipe's `links.tube_normal` and `links.tube_tangential`.

use super::table::ContactTable;

/// A pair's normal force total and the magnitude of its summed friction
/// force [N], or their impulses [N·s].
pub type PairTotals = [f64; 2];

/// Stages a step may have (ESDIRK3(2) and RK4 have four).
pub(super) const STAGES: usize = 4;

/// The cumulative impulses of every pair and the stage totals of the step
/// being taken.
#[derive(Debug, Clone)]
pub struct Impulses {
    /// Per stage, per pair: the totals of the stage's last evaluation [N].
    stage: [Vec<PairTotals>; STAGES],
    /// The cumulative impulses since t = 0 at the last accepted step's
    /// start and end [N·s].
    start: Vec<PairTotals>,
    end: Vec<PairTotals>,
    /// The totals at those two times [N]: the interpolation's slopes.
    rate_start: Vec<PairTotals>,
    rate_end: Vec<PairTotals>,
    /// The last accepted step's start and end [s].
    t_start: f64,
    t_end: f64,
    /// Whether a step was accepted yet (`rate_end` is then the force at
    /// the next step's start).
    any: bool,
    /// The largest totals at any stage of the steps accepted since the
    /// last [`Self::take_peaks`] [N] (−∞ before any).
    peak: Vec<PairTotals>,
    /// ∫F² dt of both totals since t = 0 at the last accepted step's start
    /// and end [N²·s], by the same weights: a root mean square over a
    /// window is √(growth / length).
    squares_start: Vec<PairTotals>,
    squares_end: Vec<PairTotals>,
}

impl Impulses {
    /// Zero impulses of `pairs` pairs at t = 0.
    pub fn new(pairs: usize) -> Self {
        let z = vec![[0.0; 2]; pairs];
        Self {
            stage: [z.clone(), z.clone(), z.clone(), z.clone()],
            start: z.clone(),
            end: z.clone(),
            rate_start: z.clone(),
            rate_end: z.clone(),
            t_start: 0.0,
            t_end: 0.0,
            any: false,
            peak: vec![[f64::NEG_INFINITY; 2]; pairs],
            squares_start: z.clone(),
            squares_end: z,
        }
    }

    /// Keeps the pair totals of the evaluation in `table` as stage `s`'s.
    pub(super) fn take_stage(&mut self, s: usize, table: &ContactTable) {
        for (k, out) in self.stage[s].iter_mut().enumerate() {
            let (_, laws) = table.pair(k);
            let mut normal = 0.0;
            let mut friction = crate::math::Vec3::zeros();
            for (law, _) in laws {
                normal += law.normal_force;
                friction += law.tangential_force;
            }
            *out = [normal, friction.norm()];
        }
    }

    /// Stage `to` takes stage `from`'s totals (a first stage known from
    /// the step before).
    pub(super) fn copy_stage(&mut self, from: usize, to: usize) {
        let source = std::mem::take(&mut self.stage[from]);
        self.stage[to].copy_from_slice(&source);
        self.stage[from] = source;
    }

    /// Adds the step of `h` [s] from `t0` [s] just accepted: h·Σ w·F over
    /// its stages `weights` (stage, b), `last` the stage at its end.
    pub(super) fn accept(&mut self, t0: f64, h: f64, weights: &[(usize, f64)], last: usize) {
        for k in 0..self.end.len() {
            let (mut step, mut squares) = ([0.0; 2], [0.0; 2]);
            let peak = &mut self.peak[k];
            for &(s, w) in weights {
                let f = self.stage[s][k];
                for i in 0..2 {
                    step[i] += w * f[i];
                    squares[i] += w * f[i] * f[i];
                }
                *peak = [peak[0].max(f[0]), peak[1].max(f[1])];
            }
            let f = self.stage[last][k];
            *peak = [peak[0].max(f[0]), peak[1].max(f[1])];
            self.start[k] = self.end[k];
            self.end[k] = [self.end[k][0] + h * step[0], self.end[k][1] + h * step[1]];
            let q = self.squares_end[k];
            self.squares_start[k] = q;
            self.squares_end[k] = [q[0] + h * squares[0], q[1] + h * squares[1]];
        }
        let first = weights.first().map_or(last, |&(s, _)| s);
        if self.any {
            std::mem::swap(&mut self.rate_start, &mut self.rate_end);
        } else {
            self.rate_start.copy_from_slice(&self.stage[first]);
        }
        self.rate_end.copy_from_slice(&self.stage[last]);
        (self.t_start, self.t_end, self.any) = (t0, t0 + h, true);
    }

    /// Each pair's largest totals [N] at any stage of the steps accepted
    /// since the last call, into `out` (−∞ where no step was accepted);
    /// starts the next interval. The stages are the integrator's own
    /// samples of the force, so a peak between two frames is seen, and
    /// the largest over a window of frames is the same for any output
    /// interval: it covers the steps that start within the window.
    pub fn take_peaks(&mut self, out: &mut Vec<PairTotals>) {
        out.clear();
        out.extend_from_slice(&self.peak);
        self.peak.fill([f64::NEG_INFINITY; 2]);
    }

    /// The cumulative impulses [N·s] at `t` [s], into `out`: at the last
    /// accepted step's end, or interpolated within that step.
    pub fn at(&self, t: f64, out: &mut Vec<PairTotals>) {
        self.interpolate(t, (&self.start[..], &self.end[..]), |f| f, out);
    }

    /// The cumulative ∫F² dt of both totals [N²·s] at `t` [s], into `out`,
    /// as [`Self::at`] (the slopes the squared totals at the step's ends).
    pub fn squares_at(&self, t: f64, out: &mut Vec<PairTotals>) {
        let ends = (&self.squares_start[..], &self.squares_end[..]);
        self.interpolate(t, ends, |f| f * f, out);
    }

    /// The integral `ends` (at the last accepted step's start and end) at
    /// `t` [s], into `out`; `rate` maps a total at a step's end to the
    /// integrand there.
    fn interpolate(
        &self,
        t: f64,
        (start, end): (&[PairTotals], &[PairTotals]),
        rate: impl Fn(f64) -> f64,
        out: &mut Vec<PairTotals>,
    ) {
        out.clear();
        let h = self.t_end - self.t_start;
        if !self.any || h <= 0.0 || t >= self.t_end - 1e-12 * h {
            out.extend_from_slice(end);
            return;
        }
        let th = ((t - self.t_start) / h).clamp(0.0, 1.0);
        out.extend((0..end.len()).map(|k| {
            let f = |i: usize| {
                let (m0, m1) = (rate(self.rate_start[k][i]), rate(self.rate_end[k][i]));
                monotone_hermite(start[k][i], end[k][i], h * m0, h * m1, th)
            };
            [f(0), f(1)]
        }));
    }
}

/// The cubic Hermite interpolant at θ ∈ [0, 1] of a non-decreasing
/// integral from `i0` to `i1` with the slopes `m0`, `m1` (per unit θ),
/// limited so that it does not decrease (Fritsch & Carlson, "Monotone
/// piecewise cubic interpolation", SIAM J. Numer. Anal. 17, 1980: slopes of
/// the secant's sign, and α² + β² ≤ 9 for α, β the slopes over the
/// secant). Third order where the limit does not act, as the step; at a
/// contact's onset or release within the step it acts, and the integral
/// cannot dip.
fn monotone_hermite(i0: f64, i1: f64, m0: f64, m1: f64, th: f64) -> f64 {
    let delta = i1 - i0;
    let (mut m0, mut m1) = if delta > 0.0 {
        (m0.max(0.0), m1.max(0.0))
    } else {
        (0.0, 0.0)
    };
    let s = (m0 * m0 + m1 * m1) / (delta * delta);
    if s > 9.0 {
        let tau = 3.0 / s.sqrt();
        (m0, m1) = (tau * m0, tau * m1);
    }
    let (t2, t3) = (th * th, th * th * th);
    (2.0 * t3 - 3.0 * t2 + 1.0) * i0
        + (3.0 * t2 - 2.0 * t3) * i1
        + (t3 - 2.0 * t2 + th) * m0
        + (t3 - t2) * m1
}
