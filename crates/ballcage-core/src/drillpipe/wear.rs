//! The `wear` table: per contact pair, the friction work, sliding and
//! Archard wear over the summary window and the largest Hertz pressure of
//! the run, integrated every step from each pair's model ([`super::stress`]).

use super::ids::{FEATURE, HINGE, KEY, LINK, PAIR, PAIR_ID, pair_cells};
use super::layout::Layout;
use super::stress::PairStress;
use crate::dynamics::ContactEval;
use crate::model::State;
use crate::record::{Cell, ColumnDef, ColumnKind, TableBuffer, TableDef, col};

use ColumnKind::{F64, OptF64};

/// A pair's integrals for the `wear` table.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PairWear {
    /// ∫|F_t|·v dt over the window [J].
    pub friction_work: f64,
    /// ∫v dt over the window, summed over the pair's points [m].
    pub sliding: f64,
    /// ∫F_n·v dt over the window [N·m] (Archard's load × distance).
    pub normal_sliding: f64,
    /// ∫p_mean·v dt over the window [Pa·m] (local Archard depth ÷ (k/H)).
    pub pressure_sliding: f64,
    /// The largest peak pressure over the run.
    pub peak: Option<Peak>,
    /// The four integrands above at the end of the last step (`None`
    /// before the first), for the trapezoidal rule.
    pub rates: Option<[f64; 4]>,
}

/// The largest Hertz peak pressure of a pair over a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Peak {
    /// Peak pressure p₀ [Pa].
    pub pressure: f64,
    /// When [s].
    pub t: f64,
    /// The point's normal force then [N].
    pub force: f64,
    /// The patch's semi-axes a, b then [m].
    pub semi_axes: (f64, f64),
}

impl PairWear {
    /// Adds the step that ended at `state` (time `t`), points `points`: its
    /// pressure to the peak, and its rates to the window's integrals over
    /// `h` [s], the part of the step inside the window (0 for a step
    /// outside it), by the trapezoidal rule (the rates at the step's two
    /// ends; the first step has only its end), as the `energy` table's work.
    pub fn add(&mut self, stress: &PairStress, state: &State, points: &[ContactEval], h: f64) {
        // [friction power, slip speed, F_n·v, p_mean·v]
        let mut rates = [0.0; 4];
        for e in points {
            let (c, mean) = stress.patch(state, e);
            if c.peak_pressure > self.peak.map_or(0.0, |p| p.pressure) {
                self.peak = Some(Peak {
                    pressure: c.peak_pressure,
                    t: state.t,
                    force: e.normal_force,
                    semi_axes: (c.semi_major, c.semi_minor),
                });
            }
            let v = e.slip_speed;
            // Signed by the point's weight: a level-set minimum (−1)
            // takes back its share of its neighbours' friction work.
            rates[0] += e.point.weight * e.tangential_force.norm() * v;
            if e.point.weight > 0.0 {
                rates[1] += v;
            }
            rates[2] += e.normal_force * v;
            rates[3] += mean * v;
        }
        let before = self.rates.replace(rates).unwrap_or(rates);
        if h > 0.0 {
            let integral = |k: usize| 0.5 * (before[k] + rates[k]) * h;
            self.friction_work += integral(0);
            self.sliding += integral(1);
            self.normal_sliding += integral(2);
            self.pressure_sliding += integral(3);
        }
    }
}

/// Columns of the `wear` table (drill pipe): one row per contact pair, at the end of the run.
const WEAR_COLUMNS: &[ColumnDef] = &[
    PAIR_ID,
    PAIR,
    FEATURE,
    LINK,
    HINGE,
    KEY,
    col(
        "window_start",
        F64,
        "s",
        "start of the window of the work, sliding and wear columns (record.summary_window)",
    ),
    col("window_end", F64, "s", "end of that window"),
    col(
        "friction_work",
        F64,
        "J",
        "energy friction dissipated in the window, ∫|F_t|·v_slip dt over the pair's points",
    ),
    col(
        "friction_power",
        F64,
        "W",
        "friction_work / window length: the pair's mean friction loss",
    ),
    col(
        "sliding_distance",
        F64,
        "m",
        "distance slid in the window, ∫v_slip dt summed over the pair's points",
    ),
    col(
        "normal_sliding",
        F64,
        "N*m",
        "Archard's load × distance in the window, ∫F_n·v_slip dt",
    ),
    col(
        "wear_volume",
        F64,
        "m^3",
        "Archard wear volume in the window, k·normal_sliding / H (wear.*_coefficient k, the softer surface's hardness H)",
    ),
    col(
        "wear_depth_rate",
        OptF64,
        "m/s",
        "UPPER BOUND of the Archard depth rate: a spot that stays under the contact, k/H · mean of p_mean·v_slip over the window (p_mean from Hertz); the contacts move over the surfaces, so the wear map (wear_map.parquet, depth per surface cell) gives the depth to use; null without a Hertz model",
    ),
    col(
        "hours_per_100um",
        OptF64,
        "h",
        "LOWER BOUND of the hours of this duty to wear 0.1 mm: at the upper-bound wear_depth_rate (the wear map's hours_to_depth is the figure to use); null where nothing wears",
    ),
    col(
        "pressure_peak",
        OptF64,
        "Pa",
        "largest Hertz peak pressure p₀ over the whole run, checked every step; null without contact or model",
    ),
    col("pressure_peak_t", OptF64, "s", "time of pressure_peak"),
    col(
        "pressure_peak_force",
        OptF64,
        "N",
        "normal force of the point at pressure_peak (p₀ goes as its cube root on a point contact)",
    ),
    col(
        "semi_major",
        OptF64,
        "m",
        "Hertz semi-major axis a at pressure_peak (half the length of a line contact)",
    ),
    col(
        "semi_minor",
        OptF64,
        "m",
        "Hertz semi-minor axis b at pressure_peak",
    ),
    col(
        "allowable_pressure",
        F64,
        "Pa",
        "the weaker surface's materials.*.allowable_pressure",
    ),
    col(
        "pressure_margin",
        OptF64,
        "1",
        "allowable_pressure / pressure_peak: below 1 the static contact-stress limit is exceeded",
    ),
];

/// The `wear` table.
pub const WEAR: TableDef = TableDef {
    name: "wear",
    row: "one row per contact pair, written at the end of the run",
    columns: WEAR_COLUMNS,
};

/// The `wear` rows: one per pair, from the integrals `wear` over `window` [s].
pub fn wear_rows(
    table: &mut TableBuffer,
    layout: &Layout,
    stress: &[PairStress],
    wear: &[PairWear],
    (start, end): (f64, f64),
) {
    let span = (end - start).max(f64::MIN_POSITIVE);
    for (k, ((part, s), w)) in layout.pairs.iter().zip(stress).zip(wear).enumerate() {
        let k_h = s.wear_coefficient / s.hardness;
        let rate = s.has_model().then(|| k_h * w.pressure_sliding / span);
        let hours = rate.filter(|r| *r > 0.0).map(|r| 1e-4 / r / 3600.0);
        let peak = w.peak;
        let [id, name, feature, link, hinge, key] = pair_cells(k, part);
        table.push(&[
            id,
            name,
            feature,
            link,
            hinge,
            key,
            Cell::F64(start),
            Cell::F64(end),
            Cell::F64(w.friction_work),
            Cell::F64(w.friction_work / span),
            Cell::F64(w.sliding),
            Cell::F64(w.normal_sliding),
            Cell::F64(k_h * w.normal_sliding),
            Cell::OptF64(rate),
            Cell::OptF64(hours),
            Cell::OptF64(peak.map(|p| p.pressure)),
            Cell::OptF64(peak.map(|p| p.t)),
            Cell::OptF64(peak.map(|p| p.force)),
            Cell::OptF64(peak.map(|p| p.semi_axes.0)),
            Cell::OptF64(peak.map(|p| p.semi_axes.1)),
            Cell::F64(s.allowable),
            Cell::OptF64(peak.map(|p| s.allowable / p.pressure)),
        ]);
    }
}
