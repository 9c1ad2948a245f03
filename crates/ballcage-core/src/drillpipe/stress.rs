//! Contact pressure and wear of the drill pipe's contacts: a Hertz model per
//! contact pair, set once from the pair's geometry and the solids'
//! elasticity (docs/model.md, "Contact pressure and wear"), and the per-pair
//! integrals of the `wear` table.
//!
//! | pair | Hertz model (body 1, body 2 principal curvatures [1/m]) |
//! |---|---|
//! | key–race flank | elliptical: ball `[1/r_b, 1/r_b]`, flank `[−1/ρ_g, κ_track]`, κ_track of the torus at the key's designed seat |
//! | key–window face | elliptical: ball on a flat |
//! | cage–head, cage–seat | elliptical: sphere in a spherical cavity (so conforming that a ≪ R fails at kN: an estimate) |
//! | link–tube, along the wall | line: `[1/r_link, −1/r_bore]` over the link's length |
//! | link–tube, at an end rim | elliptical: rim rounded to `pipe.link_edge_radius` r_e, `[1/r_e, 1/r_link]` on `[0, −1/r_bore]` |
//! | neck–mouth | none: a sharp edge has no Hertz solution |

use super::layout::{Feature, Layout};
use super::spec::{DrillPipeSpec, SolidSpec};
use super::tables::{FEATURE, HINGE, KEY, LINK, PAIR, PAIR_ID, pair_cells};
use crate::dynamics::ContactEval;
use crate::force::hertz::{Elliptical, HertzContact, Line, effective_modulus};
use crate::geometry::{PairGeometry, Shape};
use crate::math::Vec3;
use crate::model::{ContactPair, Model, State};
use crate::record::{Cell, ColumnDef, ColumnKind, TableBuffer, TableDef, col};

use ColumnKind::{F64, OptF64};

/// How a pair's Hertz patch is found.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Patch {
    /// One elliptical model for every point.
    Point(Elliptical),
    /// A link in the tube: `rim` for a point within the edge radius of an
    /// end of the link (body `link`, half-length `half_length` [m]), `line`
    /// elsewhere.
    Tube {
        link: usize,
        half_length: f64,
        edge: f64,
        line: Line,
        rim: Elliptical,
    },
    /// No Hertz solution.
    None,
}

/// The pressure and wear model of one contact pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairStress {
    patch: Patch,
    /// Allowable peak pressure [Pa]: the weaker surface's.
    pub allowable: f64,
    /// Hardness of the softer surface [Pa], the one that wears (Archard).
    pub hardness: f64,
    /// Archard wear coefficient k [–].
    pub wear_coefficient: f64,
}

impl PairStress {
    /// The Hertz patch of point `e` of the pair at `state`, and its mean
    /// pressure [Pa] (F over the patch's area); zeros without a model.
    pub fn patch(&self, state: &State, e: &ContactEval) -> (HertzContact, f64) {
        let f = e.normal_force;
        let ellipse = |m: &Elliptical| {
            let c = m.at(f);
            // p_mean = F/(π a b) = (2/3)·p₀
            (c, 2.0 / 3.0 * c.peak_pressure)
        };
        match &self.patch {
            Patch::Point(m) => ellipse(m),
            Patch::Tube {
                link,
                half_length,
                edge,
                line,
                rim,
            } => {
                let x = (state.rot[*link].inverse() * (e.point.point - state.pos[*link])).x;
                if x.abs() > half_length - edge {
                    ellipse(rim)
                } else {
                    let c = line.at(f);
                    // p_mean = F/(2b·L) = (π/4)·p₀
                    (c, std::f64::consts::FRAC_PI_4 * c.peak_pressure)
                }
            }
            Patch::None => (HertzContact::default(), 0.0),
        }
    }

    /// Whether the pair has a Hertz model at all.
    pub fn has_model(&self) -> bool {
        self.patch != Patch::None
    }
}

/// The model of every contact pair of the pipe, by pair id.
pub fn pair_stresses(
    spec: &DrillPipeSpec,
    layout: &Layout,
    model: &Model,
    state: &State,
) -> Vec<PairStress> {
    let (pipe, key) = (&spec.materials.pipe_steel, &spec.materials.key_steel);
    layout
        .pairs
        .iter()
        .zip(&model.pairs)
        .map(|(part, pair)| {
            let keyed = matches!(
                part.feature,
                Feature::InnerRace | Feature::OuterRace | Feature::Window
            );
            let other = if keyed { key } else { pipe };
            let wear_coefficient = if part.feature == Feature::Tube {
                spec.wear.tube_coefficient
            } else {
                spec.wear.internal_coefficient
            };
            PairStress {
                patch: patch_of(spec, model, state, pair, e_star(pipe, other)),
                allowable: pipe.allowable_pressure.min(other.allowable_pressure),
                hardness: pipe.hardness.min(other.hardness),
                wear_coefficient,
            }
        })
        .collect()
}

/// E* of two solids [Pa].
fn e_star(a: &SolidSpec, b: &SolidSpec) -> f64 {
    effective_modulus(
        a.youngs_modulus,
        a.poisson_ratio,
        b.youngs_modulus,
        b.poisson_ratio,
    )
}

/// The Hertz model of `pair` from its geometry (`None` where Hertz has no solution).
fn patch_of(
    spec: &DrillPipeSpec,
    model: &Model,
    state: &State,
    pair: &ContactPair,
    e_star: f64,
) -> Patch {
    let point = |c: [f64; 4]| Elliptical::new(c, e_star).map_or(Patch::None, Patch::Point);
    match pair.geometry {
        PairGeometry::TorusBall {
            tube_radius,
            ball_radius,
            ..
        } => {
            let track = track_curvature(state, pair);
            let ball = 1.0 / ball_radius;
            point([ball, ball, -1.0 / tube_radius, track])
        }
        PairGeometry::SlotBall { ball_radius, .. } => {
            point([1.0 / ball_radius, 1.0 / ball_radius, 0.0, 0.0])
        }
        PairGeometry::CavitySphere {
            cavity_radius,
            sphere_radius,
            ..
        } => {
            let (s, c) = (1.0 / sphere_radius, -1.0 / cavity_radius);
            point([s, s, c, c])
        }
        PairGeometry::CylinderTube { .. } => tube_patch(spec, model, pair, e_star),
        _ => Patch::None,
    }
}

/// The link–tube model: a line along the wall, an elliptical rim at the ends.
fn tube_patch(spec: &DrillPipeSpec, model: &Model, pair: &ContactPair, e_star: f64) -> Patch {
    let (a, b) = (&model.bodies[pair.a].shape, &model.bodies[pair.b].shape);
    let (link, (radius, half_length), bore) = match (a, b) {
        (
            Shape::Tube(_),
            Shape::Cylinder {
                radius,
                half_length,
            },
        ) => (pair.b, (*radius, *half_length), a.radius()),
        (
            Shape::Cylinder {
                radius,
                half_length,
            },
            Shape::Tube(_),
        ) => (pair.a, (*radius, *half_length), b.radius()),
        _ => return Patch::None,
    };
    let edge = spec.pipe.link_edge_radius;
    let line = Line::new([1.0 / radius, -1.0 / bore], 2.0 * half_length, e_star);
    let rim = Elliptical::new([1.0 / edge, 1.0 / radius, 0.0, -1.0 / bore], e_star);
    match (line, rim) {
        (Some(line), Some(rim)) => Patch::Tube {
            link,
            half_length,
            edge,
            line,
            rim,
        },
        _ => Patch::None,
    }
}

/// Curvature [1/m] along the track of a groove flank (a torus section on the
/// race body) where the key sits at `state` (its designed seat at t = 0):
/// by Meusnier, n·ê_r/r at the wall point nearest the ball, with n the
/// race's surface normal toward the ball and ê_r, r the direction and
/// distance from the torus axis: + where the race is convex along the track
/// (a head), − where it is concave (a seat).
pub fn track_curvature(state: &State, pair: &ContactPair) -> f64 {
    let PairGeometry::TorusBall {
        centre,
        axis,
        core_radius,
        ball_radius,
        ..
    } = pair.geometry
    else {
        return 0.0;
    };
    let (race, ball) = if pair.swapped {
        (pair.b, pair.a)
    } else {
        (pair.a, pair.b)
    };
    let in_plane = |v: Vec3| v - v.dot(&axis) * axis;
    let p = state.rot[race].inverse() * (state.pos[ball] - state.pos[race]);
    let Some(radial) = in_plane(p - centre).try_normalize(1e-15) else {
        return 0.0;
    };
    let core = centre + core_radius * radial;
    let Some(n) = (core - p).try_normalize(1e-15) else {
        return 0.0;
    };
    let wall = in_plane(p - ball_radius * n - centre);
    let r = wall.norm();
    if r < 1e-15 {
        return 0.0;
    }
    n.dot(&(wall / r)) / r
}

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
    /// Adds one step of length `h` [s] at `state` (time `t`), points `points`;
    /// `in_window` says whether the step counts toward the window's integrals.
    pub fn add(
        &mut self,
        stress: &PairStress,
        state: &State,
        points: &[ContactEval],
        h: f64,
        in_window: bool,
    ) {
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
            if in_window {
                let v = e.slip_speed;
                self.friction_work += e.tangential_force.norm() * v * h;
                self.sliding += v * h;
                self.normal_sliding += e.normal_force * v * h;
                self.pressure_sliding += mean * v * h;
            }
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
        "Archard depth rate at a spot that stays under the contact, k/H · mean of p_mean·v_slip over the window (p_mean from Hertz); an upper bound for a surface the contact moves over; null without a Hertz model",
    ),
    col(
        "hours_per_100um",
        OptF64,
        "h",
        "hours of this duty to wear 0.1 mm at wear_depth_rate; null where nothing wears",
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
