//! Contact pressure and wear of the drill pipe's contacts: a Hertz model per
//! contact pair, set once from the pair's geometry and the solids'
//! elasticity (docs/model.md, "Contact pressure and wear"); the `wear`
//! table (module `wear`, above this one) integrates it.
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
use crate::dynamics::ContactEval;
use crate::force::hertz::{Elliptical, HertzContact, Line, effective_modulus};
use crate::geometry::{PairGeometry, Shape};
use crate::math::Vec3;
use crate::model::{ContactPair, Model, State};

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
    /// pressure [Pa] (F over the patch's area); zeros without a model, and
    /// at a point that carries no pressure of its own: a level-set minimum
    /// of the link–tube law (weight −1), which only takes back part of its
    /// neighbouring maxima's force (docs/model.md §4).
    pub fn patch(&self, state: &State, e: &ContactEval) -> (HertzContact, f64) {
        let f = e.normal_force;
        if e.point.weight < 0.0 || f <= 0.0 {
            return (HertzContact::default(), 0.0);
        }
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
        PairGeometry::CylinderTube(_) => tube_patch(spec, model, pair, e_star),
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
