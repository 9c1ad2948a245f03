//! A cylinder or capsule inside a lumen around a centreline (a tube, or the
//! tube of a torus): a line contact, found exactly at its deepest points.
//!
//! At axial position s the rod's surface point deepest in the wall is, for a
//! cylinder, the rim point farthest from the centreline; for a capsule, the
//! point of the sphere at the axis point along the offset from the
//! centreline. So the depth profile is d(s) = |u(s)| + r − R_wall to first
//! order (a capsule: exactly), u the axis point's offset from the
//! centreline. Its maxima are the ends and the interior points where |u|
//! stops growing: since u is perpendicular to the centreline at the nearest
//! point, d|u|²/ds = 2 u·â exactly (â the rod axis), so a maximum lies between
//! two samples where u·â changes from positive to negative. There Newton's
//! method on u·â, with the exact slope d(u·â)/ds and kept in its bracket by
//! regula falsi (Illinois), finds it to round-off, so the largest
//! penetration is exact, and a contact lying wholly between two samples (a
//! straight link against the convex inner wall of a bend) is not missed.
//! Between the rod's ends the samples and the root finding need only the
//! axis point ([`Axis`]: one nearest-point query); a flat rod's rim point,
//! a second query, is found only where a contact is reported.
//!
//! Three reductions of the depth along the axis:
//! - [`line_extrema`]: every depth maximum (ends included) and every
//!   interior depth minimum, found exactly, for the level-set law whose
//!   energy is Σ Φ(δ_max) − Σ Φ(δ_min): continuous in the rod's pose, the
//!   gradient of that energy, independent of the sampling once each
//!   extremum has a bracket of its own (ballcage's default);
//! - [`line_patches`]: one contact per patch (a run of samples in contact,
//!   or such a hidden maximum) at its largest penetration, acting at the
//!   patch's centre of pressure: MSC Adams' convention (the force does not
//!   depend on the sampling, but it jumps when patches merge or split);
//! - [`line_stations`]: every sample in contact and every hidden maximum,
//!   each with its own exact depth and normal: what a rigid-contact solver
//!   (rapier) wants for a line contact.

use parry3d_f64::math::Vector;

use crate::centreline::{Centreline, CircularArc};
use crate::contact::{LocalContact, Rod, unit};

/// The ends of a rod.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ends {
    /// A cylinder: flat ends, sharp rims.
    Flat,
    /// A capsule: hemispherical caps.
    Round,
}

/// A rod's surface in a lumen, in the lumen's frame.
struct RodInLumen<'a, L: ?Sized> {
    lumen: &'a L,
    rod: Rod,
    ends: Ends,
    /// Whether brackets that cannot reach the threshold are skipped
    /// ([`Self::clear_between`]); always, but in the test that shows it
    /// changes nothing.
    cull: bool,
    /// The rod's axis against the lumen's centreline in closed form, where
    /// that is one circular arc ([`Centreline::arc`]).
    on_arc: Option<AxisOnArc>,
}

impl<'a, L: Centreline + ?Sized> RodInLumen<'a, L> {
    fn new(lumen: &'a L, rod: Rod, ends: Ends, cull: bool) -> Self {
        let on_arc = lumen.arc().map(|arc| AxisOnArc::new(&arc, &rod));
        Self {
            lumen,
            rod,
            ends,
            cull,
            on_arc,
        }
    }
}

/// A straight axis q(s) = p + s·â against a circular-arc centreline (centre
/// o, radius R, start direction û, start tangent t̂, plane normal n̂ = û × t̂).
/// With r = q − o, the coordinates x = r·û, y = r·t̂, z = r·n̂ are linear in
/// s, and where the direction (x, y)/ρ (ρ = √(x² + y²)) lies within the arc
/// its nearest point is o + R·(x·û + y·t̂)/ρ. Then, with ĉ = (x·û + y·t̂)/ρ
/// and the tangent t̂(s) = (x·t̂ − y·û)/ρ:
/// - u·â = r·â − R·ĉ·â, r·â = r(0)·â + s;
/// - the slope 1 − β·(t̂(s)·â)² with β = 1/(1 − u·κ) = R/ρ (κ = −ĉ/R and
///   u·ĉ = ρ − R);
/// - |u| = √((ρ − R)² + z²).
///
/// That is [`Axis`] for a few multiplications and two square roots, where the
/// nearest-point query would build the centreline point first.
#[derive(Clone, Copy)]
struct AxisOnArc {
    arc: CircularArc,
    /// x, y, z and r·â at s = 0 [m].
    at_centre: [f64; 4],
    /// â·û, â·t̂, â·n̂.
    along: [f64; 3],
}

impl AxisOnArc {
    fn new(arc: &CircularArc, rod: &Rod) -> Self {
        let n = arc.u.cross(arc.t);
        let r = rod.centre - arc.centre;
        let a = rod.axis;
        Self {
            arc: *arc,
            at_centre: [r.dot(arc.u), r.dot(arc.t), r.dot(n), r.dot(a)],
            along: [a.dot(arc.u), a.dot(arc.t), a.dot(n)],
        }
    }

    /// The axis point at `s` [m]: its (cos, sin) direction ĉ in the arc's
    /// plane and [`Axis`]; `None` where that direction is not within the
    /// arc's angle or the point is on the circle's axis (the caller then
    /// asks the lumen).
    #[inline]
    fn at(&self, s: f64) -> Option<((f64, f64), Axis)> {
        let [x0, y0, z0, g0] = self.at_centre;
        let [au, at, an] = self.along;
        let (x, y, z) = (x0 + s * au, y0 + s * at, z0 + s * an);
        let rho = (x * x + y * y).sqrt();
        if rho.is_nan() || rho == 0.0 {
            return None;
        }
        let (c, sn) = (x / rho, y / rho);
        let (ca, sa) = self.arc.end;
        // Within [0, angle] (angle ≤ π): past the start, up to the end.
        if !(sn >= 0.0 && ca * sn - sa * c <= 0.0) {
            return None;
        }
        let big_r = self.arc.radius;
        let tangent = c * at - sn * au;
        let radial = rho - big_r;
        Some((
            (c, sn),
            Axis {
                growth: g0 + s - big_r * (c * au + sn * at),
                slope: 1.0 - (big_r / rho) * tangent * tangent,
                offset: (radial * radial + z * z).sqrt(),
            },
        ))
    }
}

/// The rod's axis point at one axial position against the centreline:
/// what brackets and finds the extrema of the depth (one nearest-point
/// query, where the [`Station`] needs a second for a flat rod's rim).
#[derive(Clone, Copy)]
struct Axis {
    /// u·â: positive while the offset from the centreline grows along the axis [m].
    growth: f64,
    /// d(u·â)/ds = 1 − β·(t̂·â)² [–], t̂ the centreline's tangent at the
    /// nearest point and β = 1/(1 − u·κ) (κ its curvature vector): where it
    /// changes sign, u·â has an extremum, and a depth maximum and minimum
    /// can be born there as a pair.
    slope: f64,
    /// |u|, the axis point's distance from the centreline [m].
    offset: f64,
}

/// The deepest surface point of one axial station.
#[derive(Clone, Copy)]
struct Station {
    /// Midpoint between the surfaces [m].
    point: Vector,
    /// Unit normal from the wall toward the rod.
    normal: Vector,
    /// Penetration [m]; negative for a gap.
    depth: f64,
    /// The axis point there.
    axis: Axis,
}

impl Station {
    fn contact(&self, feature: usize) -> LocalContact {
        LocalContact {
            point: self.point,
            normal: self.normal,
            depth: self.depth,
            feature: feature as u32,
        }
    }
}

impl<L: Centreline + ?Sized> RodInLumen<'_, L> {
    /// The axis point at axial position `s` [m]: the point q, its offset u
    /// from the centreline, and what they give. `None` past the lumen's
    /// open ends.
    fn axis_at(&self, s: f64) -> Option<(Vector, Vector, Axis)> {
        let q = self.rod.at(s);
        if let Some(on) = &self.on_arc
            && let Some(((c, sn), axis)) = on.at(s)
        {
            let arc = &on.arc;
            let u = q - (arc.centre + arc.radius * (c * arc.u + sn * arc.t));
            return Some((q, u, axis));
        }
        let c = self.lumen.nearest(q)?;
        let u = q - c.point;
        let beta = 1.0 / (1.0 - u.dot(c.curvature));
        let axis = Axis {
            growth: u.dot(self.rod.axis),
            slope: 1.0 - beta * c.tangent.dot(self.rod.axis).powi(2),
            offset: u.length(),
        };
        Some((q, u, axis))
    }

    /// [`Self::axis_at`] without the points.
    fn axis(&self, s: f64) -> Option<Axis> {
        if let Some((_, axis)) = self.on_arc.as_ref().and_then(|on| on.at(s)) {
            return Some(axis);
        }
        self.axis_at(s).map(|(.., axis)| axis)
    }

    /// The station at axial position `s` [m]. `None` where the axis is on
    /// the centreline or the station is past the lumen's open ends.
    fn station(&self, s: f64) -> Option<Station> {
        let (q, u, axis) = self.axis_at(s)?;
        if self.ends == Ends::Round {
            return self.ball_station(q, u, axis);
        }
        let across = u - axis.growth * self.rod.axis;
        let len = across.length();
        if len < 1e-15 {
            return None;
        }
        let w = q + self.rod.radius * across / len;
        let cw = self.lumen.nearest(w)?;
        let rw = w - cw.point;
        let d = rw.length();
        if d < 1e-15 {
            return None;
        }
        let depth = d - self.lumen.wall_radius();
        let out = rw / d;
        Some(Station {
            point: w - 0.5 * depth * out,
            normal: -out,
            depth,
            axis,
        })
    }

    /// Whether nothing between two stations (positions [m] and stations)
    /// can be deeper than `threshold` [m], so that no extremum there need
    /// be looked for. The axis point's distance from the centreline is
    /// 1-Lipschitz along the unit axis, so between the stations it is at
    /// most (|u_a| + |u_b| + (s_b − s_a))/2, and a station's depth is at
    /// most that plus r − R (exactly that for round ends; for flat ends the
    /// rim point lies within r of the axis point). The bound is exact
    /// arithmetic on quantities the stations already hold; 1e-12 m covers
    /// their round-off. Skipping such a bracket leaves every contact
    /// reported unchanged, bit for bit: it only spares the root finding
    /// whose result the threshold would drop.
    fn clear_between(&self, (sa, a): (f64, &Axis), (sb, b): (f64, &Axis), threshold: f64) -> bool {
        if !self.cull {
            return false;
        }
        let farthest = 0.5 * (a.offset + b.offset + (sb - sa));
        farthest + self.rod.radius - self.lumen.wall_radius() < threshold - 1e-12
    }

    /// A capsule's station: the sphere about the axis point `q` whose offset
    /// from the centreline is `u`: δ = |u| + r − R.
    fn ball_station(&self, q: Vector, u: Vector, axis: Axis) -> Option<Station> {
        let len = axis.offset;
        if len < 1e-15 {
            return None;
        }
        let out = u / len;
        let depth = len + self.rod.radius - self.lumen.wall_radius();
        let w = q + self.rod.radius * out;
        Some(Station {
            point: w - 0.5 * depth * out,
            normal: -out,
            depth,
            axis,
        })
    }

    /// A depth maximum and minimum born between two samples (positions [m]
    /// and stations) whose growths u·â have the same sign, if u·â changes
    /// sign twice between them: where the slope d(u·â)/ds goes from −
    /// to + under positive growths (u·â dips below zero), or from + to −
    /// under negative ones. The turn is approached by regula falsi
    /// (Illinois) on the slope, which keeps a bracket where the slope jumps
    /// with the centreline's curvature, until u·â has crossed zero, then
    /// each root of u·â on its side is
    /// found by [`Self::stationary`]. Returns the maximum's and the
    /// minimum's positions [m].
    fn hidden_pair(&self, (sa, a): (f64, &Axis), (sb, b): (f64, &Axis)) -> Option<(f64, f64)> {
        let up = a.growth > 0.0;
        if up != (b.growth > 0.0) {
            return None;
        }
        // Under positive growths a dip needs the slope − then +.
        let sign = if up { 1.0 } else { -1.0 };
        if !(sign * a.slope < 0.0 && sign * b.slope > 0.0) {
            return None;
        }
        // Toward the turn (the slope's zero) by the Illinois variant of
        // regula falsi on the slope, stopping at the first point where u·â
        // has crossed zero: the roots then lie on either side of it.
        let (mut lo, mut hi) = (sa, sb);
        let (mut slo, mut shi) = (sign * a.slope, sign * b.slope);
        let tolerance = 1e-12 * (1.0 + sa.abs().max(sb.abs()));
        let mut turn = None;
        // Which end moved last: +1 for lo, −1 for hi.
        let mut side = 0;
        for _ in 0..200 {
            if hi - lo <= tolerance {
                break;
            }
            let x = (lo * shi - hi * slo) / (shi - slo);
            let mid = if x > lo && x < hi { x } else { 0.5 * (lo + hi) };
            let st = self.axis(mid)?;
            if sign * st.growth < 0.0 {
                turn = Some((mid, st));
                break;
            }
            if sign * st.slope < 0.0 {
                (lo, slo) = (mid, sign * st.slope);
                if side == 1 {
                    shi *= 0.5;
                }
                side = 1;
            } else {
                (hi, shi) = (mid, sign * st.slope);
                if side == -1 {
                    slo *= 0.5;
                }
                side = -1;
            }
        }
        let (lo, turn) = match turn {
            Some(found) => found,
            None => (lo, self.axis(lo)?),
        };
        if sign * turn.growth >= 0.0 {
            return None;
        }
        if up {
            // + → − (a maximum) then − → + (a minimum).
            let max = self.stationary((sa, a), (lo, &turn), 1.0)?;
            let min = self.stationary((lo, &turn), (sb, b), -1.0)?;
            Some((max, min))
        } else {
            let min = self.stationary((sa, a), (lo, &turn), -1.0)?;
            let max = self.stationary((lo, &turn), (sb, b), 1.0)?;
            Some((max, min))
        }
    }

    /// The axial position in `[a, b]` where the offset from the centreline
    /// stops growing (u·â = 0, the depth's maximum), given u·â > 0 at `a`
    /// and ≤ 0 at `b` ([`Self::stationary`]). `None` if a station on the way
    /// does not exist.
    fn deepest(&self, a: (f64, &Axis), b: (f64, &Axis)) -> Option<f64> {
        self.stationary(a, b, 1.0)
    }

    /// The axial position in `[a, b]` where u·â changes sign: with
    /// `sign` = 1 from positive at `a` to non-positive at `b` (a depth
    /// maximum, see [`Self::deepest`]); with `sign` = −1 from non-positive
    /// to positive (a depth minimum). Both ends' axis points are given; the
    /// search works on sign·u·â, positive at `a` and non-positive at `b`
    /// either way.
    ///
    /// Newton's method on u·â with its exact slope d(u·â)/ds, which each
    /// axis point computes, kept inside the bracket, which every axis point
    /// narrows. The first estimate is the root of the cubic that matches
    /// u·â and its slope at both ends ([`hermite_root`]); a Newton step that
    /// leaves the bracket, or does not halve the step before it, is replaced
    /// by the Illinois variant of regula falsi (the slope jumps where the
    /// centreline's curvature does). Newton converges quadratically here,
    /// so a step c after a step c₋ lands within |c|³/c₋² of the root: once
    /// that is within 1e-12 of the positions and |c| ≤ 1e-3·|c₋| (the
    /// iteration plainly quadratic, not crossing a jump of the slope), the
    /// position after that step is returned without an axis point of its
    /// own (the caller's station there is the one query it needs). Stops too
    /// when the bracket or the last step is within 1e-12 of the positions.
    fn stationary(&self, (a, at): (f64, &Axis), (b, bt): (f64, &Axis), sign: f64) -> Option<f64> {
        let (mut a, mut ga, mut b, mut gb) = (a, sign * at.growth, b, sign * bt.growth);
        if ga == 0.0 {
            return Some(a);
        }
        let tolerance = 1e-12 * (1.0 + b.abs().max(a.abs()));
        let mut first = hermite_root((a, ga, sign * at.slope), (b, gb, sign * bt.slope));
        // Which end moved last: +1 for a, −1 for b.
        let mut side = 0;
        // The last axis point: its position, sign·u·â, sign·slope, and the step to it.
        let mut last: Option<(f64, f64, f64, f64)> = None;
        for _ in 0..100 {
            if b - a <= tolerance {
                break;
            }
            let newton =
                last.and_then(|(x, g, slope, step)| newton_step(x, g, slope, step, (a, b)));
            let first = first.take().filter(|&x| x > a && x < b);
            let x = newton.or(first).unwrap_or_else(|| {
                let x = (a * gb - b * ga) / (gb - ga);
                if x > a && x < b { x } else { 0.5 * (a + b) }
            });
            let st = self.axis(x)?;
            let (gx, slope) = (sign * st.growth, sign * st.slope);
            let step = last.map_or(b - a, |(prev, ..)| (x - prev).abs());
            if gx == 0.0 || (newton.is_some() && step <= tolerance) {
                return Some(x);
            }
            if gx > 0.0 {
                (a, ga) = (x, gx);
                if side == 1 && newton.is_none() {
                    gb *= 0.5;
                }
                side = 1;
            } else {
                (b, gb) = (x, gx);
                if side == -1 && newton.is_none() {
                    ga *= 0.5;
                }
                side = -1;
            }
            if newton.is_some()
                && let Some(next) = newton_step(x, gx, slope, step, (a, b))
                && converged(next - x, step, tolerance)
            {
                return Some(next);
            }
            last = Some((x, gx, slope, step));
        }
        Some(if ga.abs() < gb.abs() { a } else { b })
    }

    /// The interior depth maximum between two neighbouring samples (axial
    /// position [m] and station each), if one lies there and is deeper than
    /// `threshold`: its position [m] and station.
    fn interior_maximum(
        &self,
        (sa, a): (f64, &Option<Station>),
        (sb, b): (f64, &Option<Station>),
        threshold: f64,
    ) -> Option<(f64, Station)> {
        let (a, b) = (&a.as_ref()?.axis, &b.as_ref()?.axis);
        if !(a.growth > 0.0 && b.growth <= 0.0) || self.clear_between((sa, a), (sb, b), threshold) {
            return None;
        }
        let x = self.deepest((sa, a), (sb, b))?;
        self.station(x)
            .filter(|st| st.depth > threshold)
            .map(|st| (x, st))
    }
}

/// The Newton step from `x` (where the function is `g` and its slope
/// `slope`) if it stays strictly inside the bracket and is at most half the
/// `step` before it (otherwise the search falls back to regula falsi).
fn newton_step(x: f64, g: f64, slope: f64, step: f64, (a, b): (f64, f64)) -> Option<f64> {
    let next = x - g / slope;
    let fine = slope != 0.0 && next > a && next < b && (next - x).abs() <= 0.5 * step;
    fine.then_some(next)
}

/// Whether Newton's step `c` after a step of length `step`, both [m], ends
/// within `tolerance` [m] of the root by quadratic convergence
/// ([`RodInLumen::stationary`]).
fn converged(c: f64, step: f64, tolerance: f64) -> bool {
    let c = c.abs();
    c <= 1e-3 * step && c * c * c <= tolerance * step * step
}

/// The root in (a, b) of the cubic that takes the values `ga`, `gb` and
/// the slopes `sa`, `sb` at a and b (Hermite), found by Newton's method on
/// the cubic from the regula falsi point: a first estimate for
/// [`RodInLumen::stationary`] that costs no query. Exact where the function
/// is a cubic; `None` where the iteration leaves the bracket or does not
/// settle (the search then starts from regula falsi).
fn hermite_root((a, ga, sa): (f64, f64, f64), (b, gb, sb): (f64, f64, f64)) -> Option<f64> {
    let h = b - a;
    if h.is_nan() || h <= 0.0 || ga == gb {
        return None;
    }
    let (ma, mb) = (sa * h, sb * h);
    let mut t = ga / (ga - gb);
    for _ in 0..8 {
        let (t2, t3) = (t * t, t * t * t);
        let p = (2.0 * t3 - 3.0 * t2 + 1.0) * ga
            + (t3 - 2.0 * t2 + t) * ma
            + (3.0 * t2 - 2.0 * t3) * gb
            + (t3 - t2) * mb;
        let dp = (6.0 * t2 - 6.0 * t) * (ga - gb)
            + (3.0 * t2 - 4.0 * t + 1.0) * ma
            + (3.0 * t2 - 2.0 * t) * mb;
        if dp == 0.0 {
            return None;
        }
        let next = t - p / dp;
        if !(next > 0.0 && next < 1.0) {
            return None;
        }
        let settled = (next - t).abs() <= 1e-10;
        t = next;
        if settled {
            return Some(a + t * h);
        }
    }
    None
}

/// What the walk along the axis finds, in order.
enum Event<'a> {
    /// Sample `k`, in contact (deeper than the threshold) or not.
    Sample(usize, Option<&'a Station>),
    /// A hidden maximum between samples `k` and `k + 1`, nearest to sample
    /// `j`; whether sample `k + 1` is in contact; the deeper of the two
    /// samples' depths [m] (−∞ where a station does not exist).
    Peak {
        k: usize,
        j: usize,
        station: Station,
        next_touching: bool,
        neighbours: f64,
    },
}

/// Walks `samples` (≥ 2) evenly spaced axial positions of `rod` from end to
/// end, reporting each sample and each interior maximum deeper than
/// `threshold` [m] between two samples. Two stations at a time: no allocation.
fn walk<L: Centreline + ?Sized>(
    lumen: &L,
    (rod, ends): (&Rod, Ends),
    samples: u32,
    threshold: f64,
    cull: bool,
    visit: &mut impl FnMut(Event<'_>),
) {
    let link = RodInLumen::new(lumen, *rod, ends, cull);
    let n = samples.max(2) as usize;
    let h = rod.half_length;
    let s = |k: usize| -h + 2.0 * h * k as f64 / (n - 1) as f64;
    let touching = |st: &Option<Station>| st.as_ref().is_some_and(|st| st.depth > threshold);
    let mut here = link.station(s(0));
    for k in 0..n {
        let next = if k + 1 < n {
            link.station(s(k + 1))
        } else {
            None
        };
        visit(Event::Sample(
            k,
            here.as_ref().filter(|st| st.depth > threshold),
        ));
        if let Some((x, peak)) = link.interior_maximum((s(k), &here), (s(k + 1), &next), threshold)
        {
            let j = if x - s(k) < s(k + 1) - x { k } else { k + 1 };
            let depth = |st: &Option<Station>| st.as_ref().map_or(f64::NEG_INFINITY, |st| st.depth);
            visit(Event::Peak {
                k,
                j,
                station: peak,
                next_touching: touching(&next),
                neighbours: depth(&here).max(depth(&next)),
            });
        }
        here = next;
    }
}

/// One contact patch under construction.
struct Patch {
    /// Largest penetration [m] and the sample nearest where it is.
    depth: f64,
    slot: usize,
    /// Σ w_k, Σ w_k·p_k [m²] and Σ w_k·n_k [m] over the patch's samples, with
    /// weights w_k = δ_k − threshold > 0.
    weight: f64,
    point: Vector,
    normal: Vector,
}

impl Patch {
    fn new() -> Self {
        Self {
            depth: f64::NEG_INFINITY,
            slot: 0,
            weight: 0.0,
            point: Vector::ZERO,
            normal: Vector::ZERO,
        }
    }

    /// Adds a sampled surface point of the patch.
    fn add(&mut self, k: usize, st: &Station, threshold: f64) {
        self.deepen(k, st.depth);
        let w = st.depth - threshold;
        self.weight += w;
        self.point += w * st.point;
        self.normal += w * st.normal;
    }

    /// Raises the patch's largest penetration to `depth` if deeper.
    fn deepen(&mut self, k: usize, depth: f64) {
        if depth > self.depth {
            self.depth = depth;
            self.slot = k;
        }
    }

    /// The patch's contact: its largest penetration at its centre of
    /// pressure, along its weighted mean normal.
    fn contact(&self) -> LocalContact {
        LocalContact {
            point: self.point / self.weight,
            normal: unit(self.normal),
            depth: self.depth,
            feature: self.slot as u32,
        }
    }
}

/// The contacts of `rod` (flat or round `ends`) inside `lumen`, one per
/// contact patch (see the module doc), in the lumen's frame, from the
/// `samples` (≥ 2, ends included) that locate the patches. A point is in
/// contact when deeper than `threshold` [m] (0 for touching only; −p to
/// report gaps up to p). The centre of pressure weights each sample by its
/// depth beyond the threshold. `feature` is the sample nearest the largest
/// penetration.
pub fn line_patches<L: Centreline + ?Sized>(
    lumen: &L,
    rod: &Rod,
    ends: Ends,
    samples: u32,
    threshold: f64,
    emit: &mut impl FnMut(LocalContact),
) {
    patches(lumen, (rod, ends), samples, threshold, true, emit);
}

/// [`line_patches`], with or without culling the brackets that cannot
/// reach the threshold ([`RodInLumen::clear_between`]).
fn patches<L: Centreline + ?Sized>(
    lumen: &L,
    (rod, ends): (&Rod, Ends),
    samples: u32,
    threshold: f64,
    cull: bool,
    emit: &mut impl FnMut(LocalContact),
) {
    let mut open: Option<Patch> = None;
    // A hidden maximum just before a patch opens belongs to it.
    let mut pending: Option<(usize, f64)> = None;
    walk(
        lumen,
        (rod, ends),
        samples,
        threshold,
        cull,
        &mut |e| match e {
            Event::Sample(k, Some(st)) => {
                let p = open.get_or_insert_with(Patch::new);
                if let Some((j, d)) = pending.take() {
                    p.deepen(j, d);
                }
                p.add(k, st, threshold);
            }
            Event::Sample(_, None) => {
                if let Some(p) = open.take() {
                    emit(p.contact());
                }
            }
            Event::Peak {
                j,
                station,
                next_touching,
                ..
            } => match (&mut open, next_touching) {
                (Some(p), _) => p.deepen(j, station.depth),
                (None, true) => pending = Some((j, station.depth)),
                (None, false) => {
                    let mut p = Patch::new();
                    p.add(j, &station, threshold);
                    emit(p.contact());
                }
            },
        },
    );
    if let Some(p) = open {
        emit(p.contact());
    }
}

/// The contacts of `rod` inside `lumen`, one per sample deeper than
/// `threshold` [m] (`feature` = its index k) and one per hidden maximum
/// between samples k and k + 1 (`feature` = `samples` + k), each with its
/// own exact depth and normal, in the lumen's frame. A maximum no deeper
/// than its two samples by 1e-12 m is left out: there the depth is flat (a
/// rod lying along a straight wall, where round-off alone makes the offset
/// "stop growing" between samples) and the samples already carry it.
pub fn line_stations<L: Centreline + ?Sized>(
    lumen: &L,
    rod: &Rod,
    ends: Ends,
    samples: u32,
    threshold: f64,
    emit: &mut impl FnMut(LocalContact),
) {
    let n = samples.max(2) as usize;
    walk(
        lumen,
        (rod, ends),
        samples,
        threshold,
        true,
        &mut |e| match e {
            Event::Sample(k, Some(st)) => emit(st.contact(k)),
            Event::Sample(_, None) => {}
            Event::Peak {
                k,
                station,
                neighbours,
                ..
            } => {
                if station.depth > neighbours + 1e-12 {
                    emit(station.contact(n + k))
                }
            }
        },
    );
}

/// Whether a depth extremum of [`line_extrema`] is a maximum or an
/// interior minimum of the depth along the axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Extremum {
    /// A local maximum of the depth at an end of the rod.
    End,
    /// An interior local maximum of the depth (between two samples), where
    /// u·â = 0: it slides along the axis as the rod moves.
    Maximum,
    /// An interior local minimum of the depth (a dip between two maxima).
    Minimum,
    /// A local maximum of the depth where the rod leaves the lumen through
    /// one of its open ends: the end of the rod's part inside, a boundary
    /// of its depth profile as the rod's own ends are.
    Mouth,
}

impl Extremum {
    /// +1 for a maximum, −1 for a minimum: the sign with which its point
    /// law enters the level-set law (see [`line_extrema`]).
    pub fn weight(self) -> f64 {
        match self {
            Self::End | Self::Maximum | Self::Mouth => 1.0,
            Self::Minimum => -1.0,
        }
    }
}

/// The exact extrema of the depth δ(s) along `rod` inside `lumen` that are
/// deeper than `threshold` [m]: every local maximum (the ends included) and
/// every interior local minimum, each with its own exact depth, point and
/// normal, in the lumen's frame, in axial order.
///
/// This is what the level-set line law needs: the number of connected
/// pieces of the contact deeper than h is N(h) = #{maxima > h} −
/// #{interior minima > h} (passing a maximum downward opens a piece,
/// passing an interior minimum joins two), so the energy
/// E = ∫₀^∞ (dΦ/dh)·N(h) dh of a point law with energy Φ(δ) is
/// Σ_maxima Φ(δ_i) − Σ_minima Φ(δ_m), and its forces are the point law at
/// each maximum minus the point law at each minimum. E and its gradient are
/// continuous when pieces appear, merge, split or vanish: a minimum rising
/// through h = 0 enters with Φ(0) = 0, and a maximum and minimum that meet
/// annihilate with equal and opposite terms.
///
/// The `samples` (≥ 2, ends included) only bracket the extrema: each sign
/// change of u·â between two samples is refined by Newton's method
/// (safeguarded by regula falsi) to 1e-12 of the positions. A maximum and a minimum born together between the same
/// two samples (where u·â turns back across zero) are found from the sign
/// change of d(u·â)/ds at the samples (`RodInLumen::hidden_pair`), so a
/// pair enters with equal depths, as the law needs for continuity. Only
/// two such turns of u·â between one pair of samples go unseen.
/// Where the rod passes an open end of the lumen, its part inside ends
/// there: the section in the end plane is a maximum ([`Extremum::Mouth`])
/// where the depth grows toward it, as the rod's own ends are, and the
/// extrema are sought between it and the samples inside.
/// `feature`: an end maximum is sample 0 or `samples` − 1, an interior
/// maximum between samples k and k + 1 is k, an interior minimum there is
/// `samples` + k, the maximum of a pair born between samples 0 and 1
/// beside an end maximum at sample 0 is 2·`samples` − 1, and an open end's
/// maximum is 2·`samples` where the rod leaves the lumen toward its +s end
/// and 2·`samples` + 1 where it enters at its −s end: unique and stable,
/// below 2·`samples` + 2.
///
/// Returns, where the rod crosses an open end, the length of its part
/// inside [m], from its end inside to the last section inside: every
/// contact above lies on that part, and all vanish together when it shrinks
/// to nothing. A law that takes their load up over a short length of that
/// part stays continuous as the rod leaves the lumen (`ballcage-core`'s
/// tube ends). It is found whether or not a contact lies near the end
/// where it may be shorter than `measure_below` [m]; longer, it is given
/// only where the end's own search found it (`None` otherwise).
pub fn line_extrema<L: Centreline + ?Sized>(
    lumen: &L,
    rod: &Rod,
    ends: Ends,
    samples: u32,
    (threshold, measure_below): (f64, f64),
    emit: &mut impl FnMut(LocalContact, Extremum),
) -> Option<f64> {
    let link = RodInLumen::new(lumen, *rod, ends, true);
    link.extrema(samples, (threshold, measure_below), emit)
}

impl<L: Centreline + ?Sized> RodInLumen<'_, L> {
    /// The extrema between axial positions `sa` < `sb` [m] (the axis
    /// points `a`, `b` there), within the bracket of samples `k` and k + 1
    /// of `n`: a maximum and minimum born together, and where u·â changes
    /// sign, a maximum or a minimum; each put if deeper than `threshold`.
    /// `beside_end`: an end maximum was put at sample 0 (the pair's feature
    /// then moves to 2n − 1).
    #[allow(clippy::too_many_arguments)]
    fn bracket(
        &self,
        k: usize,
        n: usize,
        (sa, a): (f64, &Axis),
        (sb, b): (f64, &Axis),
        threshold: f64,
        beside_end: bool,
        put: &mut impl FnMut(Station, usize, Extremum),
    ) {
        if self.clear_between((sa, a), (sb, b), threshold) {
            return;
        }
        if let Some((max, min)) = self.hidden_pair((sa, a), (sb, b)) {
            let feature = if k == 0 && beside_end { 2 * n - 1 } else { k };
            let mut pair = [
                (max, feature, Extremum::Maximum),
                (min, n + k, Extremum::Minimum),
            ];
            pair.sort_by(|p, q| p.0.total_cmp(&q.0));
            for (x, feature, kind) in pair {
                if let Some(st) = self.station(x) {
                    put(st, feature, kind);
                }
            }
        }
        let found = match (a.growth > 0.0, b.growth > 0.0) {
            (true, false) => self
                .stationary((sa, a), (sb, b), 1.0)
                .map(|x| (x, k, Extremum::Maximum)),
            (false, true) => self
                .stationary((sa, a), (sb, b), -1.0)
                .map(|x| (x, n + k, Extremum::Minimum)),
            _ => None,
        };
        if let Some((x, feature, kind)) = found
            && let Some(st) = self.station(x)
        {
            put(st, feature, kind);
        }
    }

    /// Where the rod passes an open end of the lumen between axial
    /// positions `inside` (the axis point `at` there) and `outside` (no
    /// station) [m]: the last position inside, to 1e-12 of the positions,
    /// and its station, `None` if the rod's part between them cannot reach
    /// `threshold` (the offset from the centreline grows by at most the
    /// distance along the unit axis, as in [`Self::clear_between`]: leaving
    /// that part out changes no contact reported). Where it cannot, the
    /// position is still found with `locate` (it bounds the part of the rod
    /// inside, [`line_extrema`]); without, nothing is searched and the
    /// answer is `None`.
    ///
    /// A station exists while the axis point and the section's deepest
    /// point are both before the end plane: where [`Centreline::past_end`]
    /// of the two, the larger, is ≤ 0. That is linear along the straight
    /// axis where the axis point binds, nearly so where the section's point
    /// does, so the Illinois variant of regula falsi finds it in a few
    /// nearest-point queries, stopping within 1e-12 of the plane or of the
    /// positions; by bisection where the lumen has no end plane.
    fn mouth(
        &self,
        (inside, outside): (f64, f64),
        at: &Axis,
        threshold: f64,
        locate: bool,
    ) -> Option<(f64, Option<Station>)> {
        // The part inside reaches at most as far as the axis point passes
        // the end plane (linear along the axis, no query), or `outside`.
        let plane = |s: f64| self.lumen.past_end(self.rod.at(s));
        let length = match (plane(inside), plane(outside)) {
            (Some(a), Some(b)) if a <= 0.0 && b > 0.0 => (outside - inside).abs() * (-a / (b - a)),
            _ => (outside - inside).abs(),
        };
        let reach = at.offset + length * (1.0 + 1e-12) + self.rod.radius;
        let culled = self.cull && reach - self.lumen.wall_radius() < threshold - 1e-12;
        if culled && !locate {
            return None;
        }
        let tolerance = 1e-12 * (1.0 + inside.abs().max(outside.abs()));
        let (mut lo, mut hi) = (inside, outside);
        if let (Some(mut glo), Some(mut ghi)) = (self.past_end(lo), self.past_end(hi)) {
            // A station missing before the plane (the rod's end on the
            // centreline, where no deepest point is defined) is no open end.
            if !(glo <= 0.0 && ghi > 0.0) {
                return None;
            }
            // Which end moved last: +1 for lo, −1 for hi.
            let mut side = 0;
            for _ in 0..100 {
                if (hi - lo).abs() <= tolerance {
                    break;
                }
                let x = lo + (hi - lo) * (glo / (glo - ghi));
                let x = if (x - lo) * (hi - x) > 0.0 {
                    x
                } else if ghi <= tolerance {
                    // Regula falsi lands on `hi`, past the plane by round-off
                    // only: half a tolerance before it (not ~20 bisections).
                    hi - 0.5 * tolerance * (hi - lo).signum()
                } else {
                    0.5 * (lo + hi)
                };
                let Some(gx) = self.past_end(x) else { break };
                if gx <= 0.0 {
                    (lo, glo) = (x, gx);
                    // Within round-off of the plane: the last station.
                    if gx > -tolerance {
                        break;
                    }
                    if side == 1 {
                        ghi *= 0.5;
                    }
                    side = 1;
                } else {
                    (hi, ghi) = (x, gx);
                    if side == -1 {
                        glo *= 0.5;
                    }
                    side = -1;
                }
            }
            if culled {
                return Some((lo, None));
            }
            if let Some(st) = self.station(lo) {
                return Some((lo, Some(st)));
            }
            (lo, hi) = (inside, outside);
        }
        let mut station = self.station(lo)?;
        while (hi - lo).abs() > tolerance {
            let mid = 0.5 * (lo + hi);
            match self.station(mid) {
                Some(st) => (lo, station) = (mid, st),
                None => hi = mid,
            }
        }
        Some((lo, (!culled).then_some(station)))
    }

    /// How far the station at axial position `s` [m] lies past the lumen's
    /// end plane ([`Centreline::past_end`]): the axis point's distance where
    /// it is past, else the larger of it and the section's deepest point's
    /// (a flat rod's; a round rod's station is about the axis point alone).
    fn past_end(&self, s: f64) -> Option<f64> {
        let q = self.rod.at(s);
        let axis = self.lumen.past_end(q)?;
        if axis > 0.0 || self.ends == Ends::Round {
            return Some(axis);
        }
        let Some((_, u, a)) = self.axis_at(s) else {
            return Some(axis.max(f64::MIN_POSITIVE));
        };
        let across = u - a.growth * self.rod.axis;
        let len = across.length();
        if len < 1e-15 {
            return Some(axis);
        }
        let w = q + self.rod.radius * across / len;
        Some(axis.max(self.lumen.past_end(w)?))
    }

    /// [`line_extrema`] of this rod.
    fn extrema(
        &self,
        samples: u32,
        (threshold, measure_below): (f64, f64),
        emit: &mut impl FnMut(LocalContact, Extremum),
    ) -> Option<f64> {
        let link = self;
        let n = samples.max(2) as usize;
        let h = link.rod.half_length;
        let s = |k: usize| -h + 2.0 * h * k as f64 / (n - 1) as f64;
        let mut put = |st: Station, feature: usize, kind: Extremum| {
            if st.depth > threshold {
                emit(st.contact(feature), kind);
            }
        };
        // The ends' stations in full (an end is a maximum by itself); in
        // between the axis points alone bracket the extrema.
        let first = link.station(s(0));
        let end_zero = first.filter(|st| st.axis.growth <= 0.0);
        if let Some(st) = end_zero {
            put(st, 0, Extremum::End);
        }
        let mut here = first.map(|st| st.axis);
        let mut last = None;
        // The length of the part inside [m], where the rod crosses an open
        // end and it is measured.
        let mut inside = None;
        for k in 0..n - 1 {
            let next = if k + 2 == n {
                last = link.station(s(k + 1));
                last.map(|st| st.axis)
            } else {
                link.axis(s(k + 1))
            };
            // Where the rod leaves or enters the lumen between the samples,
            // its part inside ends at the open end: a maximum there if it
            // deepens toward it, and the extrema are sought up to it.
            let (mut span, mut leaving) = (None, None);
            match (here, next) {
                (Some(a), Some(b)) => span = Some(((s(k), a), (s(k + 1), b))),
                (Some(a), None) => {
                    // The part inside, [−h, x], is at least s(k) + h long.
                    let locate = s(k) + h < measure_below;
                    if let Some((x, st)) = link.mouth((s(k), s(k + 1)), &a, threshold, locate) {
                        inside = Some(inside.map_or(x + h, |l: f64| l.min(x + h)));
                        if let Some(st) = st {
                            span = Some(((s(k), a), (x, st.axis)));
                            leaving = Some(st).filter(|st| st.axis.growth > 0.0);
                        }
                    }
                }
                (None, Some(b)) => {
                    // The part inside, [x, h], is at least h − s(k + 1) long.
                    let locate = h - s(k + 1) < measure_below;
                    if let Some((x, st)) = link.mouth((s(k + 1), s(k)), &b, threshold, locate) {
                        inside = Some(inside.map_or(h - x, |l: f64| l.min(h - x)));
                        if let Some(st) = st {
                            if st.axis.growth <= 0.0 {
                                put(st, 2 * n + 1, Extremum::Mouth);
                            }
                            span = Some(((x, st.axis), (s(k + 1), b)));
                        }
                    }
                }
                (None, None) => {}
            }
            if let Some(((sa, a), (sb, b))) = span {
                let beside_end = end_zero.is_some();
                link.bracket(k, n, (sa, &a), (sb, &b), threshold, beside_end, &mut put);
            }
            if let Some(st) = leaving {
                put(st, 2 * n, Extremum::Mouth);
            }
            here = next;
        }
        if let Some(st) = last.filter(|st| st.axis.growth > 0.0) {
            put(st, n - 1, Extremum::End);
        }
        inside
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tube::{TubeInterior, TubeSegment};

    fn straight() -> TubeInterior {
        TubeInterior::new(
            0.058,
            Vector::new(-1.0, 0.0, 0.0),
            Vector::X,
            &[TubeSegment::Straight { length: 2.0 }],
        )
    }

    /// A seeded generator of uniform numbers in [0, 1) (Knuth's MMIX
    /// constants), so that the random poses of the tests are always the same.
    struct Lcg(u64);

    impl Lcg {
        fn uniform(&mut self) -> f64 {
            self.0 = self
                .0
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (self.0 >> 11) as f64 / (1u64 << 53) as f64
        }

        fn vector(&mut self) -> Vector {
            Vector::new(
                self.uniform() - 0.5,
                self.uniform() - 0.5,
                self.uniform() - 0.5,
            )
        }
    }

    /// A link ([`rod`]) whose centre is up to 17 mm off the centreline
    /// point `along` [m] of `arc` (continued straight past its ends), in a
    /// random direction across it, its axis tilted from the tangent by up
    /// to about 6°.
    fn link_near(arc: &TubeInterior, along: f64, rng: &mut Lcg) -> Rod {
        let on = along.clamp(0.0, arc.length());
        let c = arc.point_at(on);
        let across = unit(c.tangent.cross(rng.vector()));
        let tilt = unit(rng.vector());
        let centre = c.point + (along - on) * c.tangent + (0.017 * rng.uniform()) * across;
        rod(centre, unit(c.tangent + 0.1 * rng.uniform() * tilt))
    }

    fn rod(centre: Vector, axis: Vector) -> Rod {
        Rod {
            centre,
            axis,
            half_length: 0.1,
            radius: 0.043,
        }
    }

    fn all(f: impl FnOnce(&mut dyn FnMut(LocalContact))) -> Vec<LocalContact> {
        let mut out = vec![];
        f(&mut |c| out.push(c));
        out
    }

    #[test]
    fn a_capsule_tilted_in_a_straight_tube_touches_with_its_lower_cap() {
        // Axis (cos θ, 0, −sin θ), centre h = 14.1 mm below the tube's axis
        // (the x axis): the segment end at s = +0.1 m is h + 0.1·sin θ below
        // it, its sphere reaches that + r from the axis, so
        // δ = h + 0.1·sin θ + 0.043 − 0.058 = 0.098 mm, normal +z (toward the
        // axis). The offset grows all along the axis (u·â = |u|·sin θ > 0), so
        // the end is the only maximum, and the sample at s = 0.05 m is
        // 0.5 mm clear: one patch, at the last sample.
        let th: f64 = 0.01;
        let axis = Vector::new(th.cos(), 0.0, -th.sin());
        let r = rod(Vector::new(0.0, 0.0, -0.0141), axis);
        let out = all(|e| line_patches(&straight(), &r, Ends::Round, 5, 0.0, &mut |c| e(c)));
        assert_eq!(out.len(), 1);
        let expect = 0.0141 + 0.1 * th.sin() + 0.043 - 0.058;
        assert!((out[0].depth - expect).abs() < 1e-14, "{}", out[0].depth);
        assert!((out[0].normal - Vector::Z).length() < 1e-12);
        assert_eq!(out[0].feature, 4);
    }

    #[test]
    fn stations_report_every_sample_in_contact_with_its_own_depth() {
        // A cylinder lying 0.1 mm into the bottom all along: five samples,
        // each 0.1 mm deep; with a threshold of −1 mm, also a cylinder lying
        // 0.5 mm clear of the wall reports five points at δ = −0.5 mm.
        for (z, depth) in [(-0.0151, 1e-4), (-0.0145, -5e-4)] {
            let r = rod(Vector::new(0.0, 0.0, z), Vector::X);
            let out = all(|e| line_stations(&straight(), &r, Ends::Flat, 5, -1e-3, &mut |c| e(c)));
            assert_eq!(out.len(), 5);
            for (k, c) in out.iter().enumerate() {
                assert_eq!(c.feature, k as u32);
                assert!((c.depth - depth).abs() < 1e-14);
            }
        }
    }

    /// [`line_extrema`] at `samples`: every contact and its kind, in axial
    /// order, and the length inside an open end (measured below 0.1 m,
    /// which changes no contact).
    fn extrema_inside<L: Centreline>(
        lumen: &L,
        r: &Rod,
        ends: Ends,
        samples: u32,
    ) -> (Vec<(LocalContact, Extremum)>, Option<f64>) {
        let mut out = vec![];
        let inside = line_extrema(lumen, r, ends, samples, (0.0, 0.1), &mut |c, kind| {
            out.push((c, kind))
        });
        (out, inside)
    }

    /// (depth, kind) of every extremum of a flat-ended rod, in axial order.
    fn extrema(lumen: &TubeInterior, r: &Rod, samples: u32) -> Vec<(f64, Extremum)> {
        let (found, _) = extrema_inside(lumen, r, Ends::Flat, samples);
        found.into_iter().map(|(c, kind)| (c.depth, kind)).collect()
    }

    #[test]
    fn a_pair_born_between_two_samples_is_found_with_the_samples_of_the_ends_only() {
        // A link of the paper's run (t = 0.628 s) in its guide tube (an arc
        // of 1.5 m from the origin down −z, bending toward +x): its rim at
        // s = −0.1 m touches 176.8 µm deep, and 6–7 mm from it a depth
        // minimum and maximum 0.26 µm shallower have just been born, both
        // between the rim and the next sample at any sampling up to 33.
        // Found from the sign change of d(u·â)/ds, the pair is the same with
        // 5 samples as with 64: without that, 5–33 samples see the rim
        // alone. (Farther along, u·â turns back a third time, out of
        // contact: with the rims as the only samples, three roots share one
        // bracket, which the law does not resolve.)
        let arc = crate::tube::tests::paper_tube();
        let r = Rod {
            centre: Vector::new(
                0.6977892573515972,
                0.0029811545930089603,
                -1.2502401472390159,
            ),
            axis: Vector::new(0.8231828986692482, 0.0906732953784629, -0.5604893119799024)
                .normalize(),
            half_length: 0.1,
            radius: 0.043,
        };
        let fine = extrema(&arc, &r, 64);
        let kinds: Vec<Extremum> = fine.iter().map(|(_, k)| *k).collect();
        assert_eq!(
            kinds,
            [Extremum::End, Extremum::Minimum, Extremum::Maximum],
            "{fine:?}"
        );
        for samples in [5, 9, 17, 33] {
            let coarse = extrema(&arc, &r, samples);
            assert_eq!(coarse.len(), fine.len(), "{samples} samples: {coarse:?}");
            for ((df, kf), (dc, kc)) in fine.iter().zip(&coarse) {
                assert_eq!(kf, kc);
                assert!((df - dc).abs() < 1e-12, "{samples} samples: {df} vs {dc}");
            }
        }
    }

    #[test]
    fn a_rod_through_an_open_end_of_the_tube_is_held_by_the_end_of_its_part_inside() {
        // The straight tube of `straight` runs from x = −1 to x = +1 m. A
        // flat-ended rod 15.1 mm below its axis, tilted by θ = 0.01 rad so that
        // it sinks deeper toward one open end, slides out through that end.
        // Every section deepens toward the end, so the one maximum of the
        // depth over the part inside is the rod's end while it is inside, then
        // the section in the end plane: at axial distance
        // s* = min(h, (1 − |x_c|)/cos θ) from the centre, the section's
        // deepest point (r below the axis across it) is
        // δ = 15.1 mm + s*·sin θ + r·cos θ − R deep. Before the tube's ends
        // were taken as boundaries, the rod found no contact at all once its
        // end was out, 0.6 mm deep in the wall.
        let (th, z, h, r, wall): (f64, f64, f64, f64, f64) = (0.01, 0.0151, 0.1, 0.043, 0.058);
        let n = 9u32;
        // Toward either end of the tube (x = ±1), the rod's axis pointing out
        // (it leaves the tube at its +s end) or in (it enters at its −s end).
        let cases = [
            (1.0, 1.0, 2 * n),
            (-1.0, 1.0, 2 * n),
            (1.0, -1.0, 2 * n + 1),
            (-1.0, -1.0, 2 * n + 1),
        ];
        for (dir, out, mouth_feature) in cases {
            for step in 0..=40 {
                // The centre from 0.85 to 0.95 m toward the end: the rod's end
                // from 5 cm inside to 5 cm outside.
                let xc = 0.85 + 0.0025 * f64::from(step);
                let axis = out * Vector::new(dir * th.cos(), 0.0, -th.sin());
                let rd = rod(Vector::new(dir * xc, 0.0, -z), axis);
                let found = all_extrema(&straight(), &rd, n);
                let s_star = h.min((1.0 - xc) / th.cos());
                let expect = z + s_star * th.sin() + r * th.cos() - wall;
                assert_eq!(found.len(), 1, "x_c = {xc}, {dir}: {found:?}");
                let (depth, kind, feature) = found[0];
                assert!(
                    (depth - expect).abs() < 1e-12,
                    "x_c = {xc}: {depth} vs {expect}"
                );
                if (1.0 - xc) / th.cos() < h - 1e-9 {
                    assert_eq!(
                        (kind, feature),
                        (Extremum::Mouth, mouth_feature),
                        "x_c = {xc}"
                    );
                } else {
                    assert_eq!(kind, Extremum::End, "x_c = {xc}");
                }
                // The same maximum at any sampling (the samples only bracket).
                for samples in [2, 5, 33] {
                    let other = all_extrema(&straight(), &rd, samples);
                    assert_eq!(other.len(), 1, "{samples} samples");
                    assert!((other[0].0 - depth).abs() < 1e-12, "{samples} samples");
                }
            }
        }
    }

    /// (depth, kind, feature) of every extremum, in axial order.
    fn all_extrema(lumen: &TubeInterior, r: &Rod, samples: u32) -> Vec<(f64, Extremum, u32)> {
        let (found, _) = extrema_inside(lumen, r, Ends::Flat, samples);
        found
            .into_iter()
            .map(|(c, kind)| (c.depth, kind, c.feature))
            .collect()
    }

    /// A centreline that counts its nearest-point queries.
    struct Counting<'a> {
        tube: &'a TubeInterior,
        queries: std::cell::Cell<u64>,
    }

    impl<'a> Counting<'a> {
        fn new(tube: &'a TubeInterior) -> Self {
            Self {
                tube,
                queries: std::cell::Cell::new(0),
            }
        }
    }

    impl Centreline for Counting<'_> {
        fn nearest(&self, q: Vector) -> Option<crate::centreline::CentrelinePoint> {
            self.queries.set(self.queries.get() + 1);
            self.tube.nearest(q)
        }
        fn wall_radius(&self) -> f64 {
            self.tube.wall_radius()
        }
    }

    /// The paper's bend behind the trait's defaults: no closed form along
    /// the arc, every axis point a nearest-point query.
    struct Generic<'a>(&'a TubeInterior);

    impl Centreline for Generic<'_> {
        fn nearest(&self, q: Vector) -> Option<crate::centreline::CentrelinePoint> {
            self.0.nearest(q)
        }
        fn wall_radius(&self) -> f64 {
            self.0.wall_radius()
        }
        fn past_end(&self, q: Vector) -> Option<f64> {
            self.0.past_end(q)
        }
    }

    /// The closed form along an arc ([`AxisOnArc`]) finds the extrema the
    /// nearest-point queries find: the same contacts, kinds and features,
    /// depths within 1e-15 m, points within 1e-11 m, normals within 1e-11,
    /// and the same length inside an open end; on 3000 poses of a link in
    /// the paper's bend and across both its open ends, both end types.
    /// Hand-made axis points check the closed form's three quantities.
    #[test]
    fn the_closed_form_along_an_arc_matches_the_nearest_point_queries() {
        let arc = crate::tube::tests::paper_tube();
        assert!(arc.arc().is_some() && Generic(&arc).arc().is_none());
        let mut rng = Lcg(0x2545_f491_4f6c_dd1d);
        let (mut compared, mut crossing) = (0, 0);
        for case in 0..3000 {
            // Centres from 0.15 m before the entry to 0.15 m past the exit.
            let along = -0.15 + (arc.length() + 0.3) * rng.uniform();
            let r = link_near(&arc, along, &mut rng);
            let ends = if case % 2 == 0 {
                Ends::Flat
            } else {
                Ends::Round
            };
            let (fast, fast_inside) = extrema_inside(&arc, &r, ends, 5);
            let (slow, slow_inside) = extrema_inside(&Generic(&arc), &r, ends, 5);
            assert_eq!(fast.len(), slow.len(), "case {case}");
            assert_eq!(fast_inside.is_some(), slow_inside.is_some(), "case {case}");
            if let (Some(a), Some(b)) = (fast_inside, slow_inside) {
                assert!(
                    (a - b).abs() < 1e-11,
                    "case {case}: {a} against {b} m inside"
                );
                crossing += 1;
            }
            for ((f, fk), (g, gk)) in fast.iter().zip(&slow) {
                assert_eq!((fk, f.feature), (gk, g.feature), "case {case}");
                assert!(
                    (f.depth - g.depth).abs() < 1e-15,
                    "case {case}: {} against {}",
                    f.depth,
                    g.depth
                );
                assert!((f.point - g.point).length() < 1e-11, "case {case}");
                assert!((f.normal - g.normal).length() < 1e-11, "case {case}");
                compared += 1;
            }
        }
        assert!(
            compared > 1000 && crossing > 100,
            "{compared} contacts, {crossing} rods crossing an end"
        );
        // By hand: a rod along the centreline's tangent at the arc's middle,
        // displaced by d toward the circle's centre and by h out of plane, at
        // s along it: r = (R − d)·ĉ + h·n̂ + s·t̂, so u·â = s − R·s/ρ with
        // ρ = √((R − d)² + s²), the slope 1 − R(R − d)²/ρ³ and the offset
        // √((ρ − R)² + h²).
        let (big_r, d, h) = (1.5, 0.01, 0.004);
        let mid = arc.point_at(0.5 * arc.length());
        let toward = mid.curvature / mid.curvature.length();
        let out_of_plane = unit(mid.tangent.cross(toward));
        let r = rod(mid.point + d * toward + h * out_of_plane, mid.tangent);
        let link = RodInLumen::new(&arc, r, Ends::Round, true);
        for s in [-0.1, 0.03, 0.12] {
            let axis = link.axis(s).expect("inside the bend");
            let rho = ((big_r - d) * (big_r - d) + s * s).sqrt();
            let slope = 1.0 - big_r * (big_r - d) * (big_r - d) / rho.powi(3);
            let offset = ((rho - big_r).powi(2) + h * h).sqrt();
            assert!(
                (axis.growth - (s - big_r * s / rho)).abs() < 1e-15,
                "growth at {s}"
            );
            assert!((axis.slope - slope).abs() < 1e-12, "slope at {s}");
            assert!((axis.offset - offset).abs() < 1e-15, "offset at {s}");
        }
    }

    /// The first estimate is exact on a cubic: u·â = (s − r)(s² + 0.3) on
    /// [−0.1, 0.2] has its root r found to 1e-15 from the ends' values and
    /// slopes alone, where regula falsi is 0.01 off.
    #[test]
    fn the_hermite_start_is_exact_on_a_cubic() {
        for r in [-0.07, 0.0, 0.05, 0.18] {
            let g = |s: f64| (s - r) * (s * s + 0.3);
            let slope = |s: f64| (s * s + 0.3) + 2.0 * s * (s - r);
            let (a, b) = (-0.1, 0.2);
            let found = hermite_root((a, g(a), slope(a)), (b, g(b), slope(b))).expect("a root");
            assert!((found - r).abs() < 1e-15, "{found} against {r}");
            let falsi = (a * g(b) - b * g(a)) / (g(b) - g(a));
            assert!((falsi - r).abs() > 1e-3, "regula falsi {falsi} against {r}");
        }
    }

    /// Each root of u·â between two samples is found to round-off (|u·â|
    /// below 2e-15 m where the slope is about 1e-2: the root within about
    /// 1e-13 m) with fewer than 2.5 nearest-point queries on average, on
    /// 2000 poses of a link in the paper's bend (nearest-point queries, not
    /// the closed form along the arc): Newton from the Hermite start,
    /// stopped by the quadratic prediction, 2.11 queries and |u·â| ≤ 4.3e-16
    /// m. From regula falsi with the same stop: 3.12 and 8.5e-15 m; from
    /// regula falsi, stopped by a step below 1e-12 (before 2026-11-27):
    /// 5.04 and 3.6e-16 m.
    #[test]
    fn a_root_between_samples_costs_few_queries_and_is_exact() {
        let arc = crate::tube::tests::paper_tube();
        let lumen = Counting::new(&arc);
        let mut rng = Lcg(0x1234_5678_9abc_def1);
        let (mut roots, mut queries, mut worst) = (0, 0, 0.0_f64);
        for _ in 0..2000 {
            let r = link_near(&arc, 0.2 + 2.0 * rng.uniform(), &mut rng);
            let link = RodInLumen::new(&lumen, r, Ends::Round, false);
            let s = |k: usize| -0.1 + 0.05 * k as f64;
            for k in 0..4 {
                let (Some(a), Some(b)) = (link.axis(s(k)), link.axis(s(k + 1))) else {
                    continue;
                };
                let sign = match (a.growth > 0.0, b.growth > 0.0) {
                    (true, false) => 1.0,
                    (false, true) => -1.0,
                    _ => continue,
                };
                lumen.queries.set(0);
                let x = link
                    .stationary((s(k), &a), (s(k + 1), &b), sign)
                    .expect("a root");
                queries += lumen.queries.get();
                roots += 1;
                worst = worst.max(link.axis(x).expect("inside").growth.abs());
            }
        }
        assert!(roots > 500, "{roots} roots");
        assert!(worst < 2e-15, "|u·â| up to {worst:e} m at a root");
        let mean = queries as f64 / roots as f64;
        assert!(mean < 2.5, "{mean} queries per root");
    }

    /// Every contact the level-set and patch reductions report, as bits.
    fn reported(lumen: &Counting, r: &Rod, ends: Ends, samples: u32, cull: bool) -> Vec<[u64; 8]> {
        let bits = |c: LocalContact, kind: u64| {
            let (p, n) = (c.point, c.normal);
            [
                p.x.to_bits(),
                p.y.to_bits(),
                p.z.to_bits(),
                n.x.to_bits(),
                n.y.to_bits(),
                n.z.to_bits(),
                c.depth.to_bits(),
                (u64::from(c.feature) << 8) | kind,
            ]
        };
        let mut out = vec![];
        let link = RodInLumen::new(lumen, *r, ends, cull);
        link.extrema(samples, (0.0, 0.0), &mut |c, kind| {
            out.push(bits(c, kind as u64))
        });
        patches(lumen, (r, ends), samples, 0.0, cull, &mut |c| {
            out.push(bits(c, 9))
        });
        out
    }

    /// Skipping the brackets whose depth cannot reach the threshold
    /// changes no reported contact by a single bit, on 4000 poses of a link
    /// in the paper's arc, each end type, 5 and 33 samples (links from
    /// touch-free to 2 mm deep, tilted up to 6°); and it does skip work
    /// (3.8 % of the nearest-point queries here; 9 % before the roots took
    /// about two queries each, docs/performance.md change 15).
    #[test]
    fn culled_brackets_change_no_contact_bit_for_bit() {
        let arc = crate::tube::tests::paper_tube();
        let lumen = Counting::new(&arc);
        let mut rng = Lcg(0x9e37_79b9_7f4a_7c15);
        let (mut with, mut without, mut touching) = (0, 0, 0);
        for case in 0..4000 {
            let r = link_near(&arc, 0.2 + 2.0 * rng.uniform(), &mut rng);
            let ends = if case % 2 == 0 {
                Ends::Flat
            } else {
                Ends::Round
            };
            for samples in [5, 33] {
                lumen.queries.set(0);
                let culled = reported(&lumen, &r, ends, samples, true);
                with += lumen.queries.get();
                lumen.queries.set(0);
                let full = reported(&lumen, &r, ends, samples, false);
                without += lumen.queries.get();
                assert_eq!(culled, full, "case {case}, {samples} samples");
                touching += usize::from(!full.is_empty());
            }
        }
        assert!(
            touching > 2000 && touching < 7000,
            "{touching} of 8000 runs touch"
        );
        assert!(
            (with as f64) < 0.98 * without as f64,
            "{with} against {without} queries"
        );
    }
}
