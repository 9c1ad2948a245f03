//! The ball-key hinge against hand calculations (docs/model.md §7.9,
//! §7.10): its secondary couple T·tan(β/2), the window thrust
//! 2F·cos α·c/ρ, its torsional stiffness, its operating contact angles and
//! its backlash.
//!
//! Every scene is one link between the two connectors (hinges 0 and 1),
//! drive held, the torque ramped onto the lower connector over 40 ms, no
//! gravity, run to 0.24 s with the default SDIRK2 at 100 µs. Settled: from
//! 0.24 to 0.96 s the key force and the turn change by less than 1e-4 on a
//! straight bore (by 2e-3 and 1e-3 between 0.12 and 0.24 s).

mod common;

use ballcage_core::dynamics::quasistatic::{
    StaticDofs, StaticTolerance, condensed_stiffness, equilibrium,
};
use ballcage_core::dynamics::{Dynamics, Mode, VelocityJacobian};
use ballcage_core::math::{Quat, Vec3};
use ballcage_core::{Document, Simulation, State};

const PCR: f64 = 0.0315; // pitch radius [m]
const C: f64 = 0.004; // groove-centre offset per race [m]
const R_B: f64 = 0.0075; // ball radius [m]
const K_SI: f64 = 1e5 * 3.981_071_705_534_972e6; // 1e5 N/mm^2.2 in N/m^2.2
const N: f64 = 2.2; // IMPACT exponent
const ALPHA: f64 = std::f64::consts::FRAC_PI_4; // design contact angle
const RHO_G: f64 = 0.030; // default flank radius [m]
/// Contacts 1e4 times stiffer than the paper's (1e9 N/mm^2.2): a key at
/// 13.47 kN sinks 6 µm, so the 45° contact angle holds (45.02°).
const STIFF: &str = "materials.internal.normal.stiffness=1e9";
const K_STIFF: f64 = 1e4 * K_SI;

/// One key of a loaded hinge: the race normal forces [N], the operating
/// contact angles [rad] (as the `keys` table defines them: the contact
/// normal's angle from the groove's radial direction, in each race's own
/// groove section) and the window's axial push [N].
#[derive(Debug, Clone, Copy)]
struct KeyObs {
    f_head: f64,
    f_seat: f64,
    alpha_head: f64,
    alpha_seat: f64,
    window: f64,
}

/// A one-link pipe (hinges 0 and 1 between the held connectors) on a bore
/// of radius `r` [m], drive held, `torque` [N·m] ramped onto the lower
/// connector over 40 ms, no gravity, run to 0.24 s with `extra` overrides.
/// Returns the chain's body indices, the simulation and the lower
/// connector's turn about its axis since t = 0 [rad] (two hinges in
/// series; positive with the torque).
fn loaded_link(r: f64, torque: f64, extra: &[&str]) -> (Vec<usize>, Simulation, f64) {
    let mut o: Vec<String> = vec![
        "pipe.joints=1".into(),
        format!("borehole.curvature_radius={r}"),
        "drive.speed_rpm=0".into(),
        format!("load.resisting_moment={torque}"),
        "load.ramp=0.04".into(),
        "world.gravity=0".into(),
        "simulation.duration=0.24".into(),
        "record.tables=[]".into(),
    ];
    o.extend(extra.iter().map(|s| s.to_string()));
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &o).unwrap();
    let chain = doc.drill_pipe_parts().unwrap().1.chain.clone();
    let mut sim = doc.simulation();
    let q0 = sim.state().rot[chain[2]];
    sim.run().unwrap();
    let (q, axis) = (
        sim.state().rot[chain[2]],
        sim.state().rot[chain[2]] * Vec3::x(),
    );
    let turn = -(q * q0.inverse()).scaled_axis().dot(&axis);
    (chain, sim, turn)
}

/// Σ over the pair's points of the contact force on `body` [N] and its
/// moment about `about` [N·m], world frame; zero if `body` is not in the pair.
fn pair_wrench(sim: &mut Simulation, k: usize, body: usize, about: Vec3) -> (Vec3, Vec3) {
    let pair = &sim.model().pairs[k];
    let sign = if pair.b == body {
        1.0
    } else if pair.a == body {
        -1.0
    } else {
        return (Vec3::zeros(), Vec3::zeros());
    };
    let (mut f, mut m) = (Vec3::zeros(), Vec3::zeros());
    for e in sim.pair_contacts(k) {
        let force = sign * e.force();
        f += force;
        m += (e.point.point - about).cross(&force);
    }
    (f, m)
}

/// The six keys of hinge `h` (head body `head`, seat body `seat`, both
/// 0.2 m long so the hinge centre sits 0.1 m from each centre of mass).
fn keys_of(sim: &mut Simulation, h: usize, head: usize, seat: usize) -> Vec<KeyObs> {
    let mut keys = vec![];
    for j in 0..6 {
        let key = common::body(sim, &format!("h{h:02}.key{j}"));
        let (p, s) = (sim.state().pos[key], sim.state().clone());
        let psi = j as f64 * std::f64::consts::FRAC_PI_3;
        let tangent = Vec3::new(0.0, -psi.sin(), psi.cos());
        let g_head = s.pos[head] + s.rot[head] * Vec3::new(0.1 - C, 0.0, 0.0);
        let g_seat = s.pos[seat] + s.rot[seat] * Vec3::new(-0.1 + C, 0.0, 0.0);
        let mut race = |name: &str, g: Vec3, e_t: Vec3| -> (f64, f64) {
            let (mut force, mut angle) = (0.0, 0.0);
            for t in ["+", "-"] {
                let k = sim
                    .pair_index(&format!("h{h:02}.key{j}/{name}{t}"))
                    .unwrap();
                for e in sim.pair_contacts(k) {
                    let radial = (p - g) - e_t * (p - g).dot(&e_t);
                    let n = e.point.normal;
                    let a = n.dot(&e_t).abs().atan2(n.dot(&radial.normalize()).abs());
                    force += e.normal_force;
                    angle += e.normal_force * a;
                }
            }
            (force, angle / force)
        };
        let (f_head, alpha_head) = race("head", g_head, s.rot[head] * tangent);
        let (f_seat, alpha_seat) = race("seat", g_seat, s.rot[seat] * tangent);
        let k = sim
            .pair_index(&format!("h{h:02}.key{j}/window-axial"))
            .unwrap();
        let window = sim.pair_contacts(k).iter().map(|e| e.normal_force).sum();
        keys.push(KeyObs {
            f_head,
            f_seat,
            alpha_head,
            alpha_seat,
            window,
        });
    }
    keys
}

/// The wrench of hinge `h`'s contacts on the link (`chain[1]`) about the
/// link's hinge centre (0.1 m from its centre of mass, uphole for hinge 0,
/// downhole for hinge 1), split along the link axis, the hinge's bend-plane
/// normal and the third axis (in the bend plane, square to the link):
/// (bend β [rad], axial moment, bending moment, secondary couple [N·m],
/// out-of-plane force [N]).
fn link_wrench(sim: &mut Simulation, chain: &[usize], h: usize) -> (f64, f64, f64, f64, f64) {
    let link = chain[1];
    let s = sim.state().clone();
    let axis = |b: usize| s.rot[b] * Vec3::x();
    let (head, seat) = (axis(chain[h]), axis(chain[h + 1]));
    let bend = head.angle(&seat);
    let normal = head.cross(&seat).normalize();
    let x = axis(link);
    let centre = s.pos[link] + x * if h == 0 { -0.1 } else { 0.1 };
    let prefix = format!("h{h:02}.");
    let (mut f, mut m) = (Vec3::zeros(), Vec3::zeros());
    for k in 0..sim.model().pairs.len() {
        if sim.model().pairs[k].name.starts_with(&prefix) {
            let (fk, mk) = pair_wrench(sim, k, link, centre);
            f += fk;
            m += mk;
        }
    }
    let third = normal.cross(&x);
    (
        bend,
        m.dot(&x),
        m.dot(&normal),
        m.dot(&third),
        f.dot(&normal),
    )
}

/// The lower connector's turn [rad] and hinge 0's keys on a straight bore
/// under `torque` [N·m] ([`loaded_link`]).
fn turn_under(torque: f64, extra: &[&str]) -> (f64, Vec<KeyObs>) {
    let (chain, mut sim, turn) = loaded_link(1000.0, torque, extra);
    (turn, keys_of(&mut sim, 0, chain[0], chain[1]))
}

/// One key's groove section as the seat turns (docs/model.md §7.9, "the
/// rotating section"), for a groove offset c → 0 so that head and seat
/// grooves share one cross-section. Coordinates (radial, circumferential)
/// about the pipe axis, the key at (PCR, 0). The loaded head flank's
/// centre of curvature is C_h = (PCR + a·cos α, a·sin α), the seat's
/// C_s = R(−φ)·(PCR − a·cos α, −a·sin α) with the seat turned by φ, a =
/// ρ_g − r_b − s. The key, pulled equally toward both (it sinks δ into
/// each), sits midway, M = (C_h + C_s)/2, with |C_h − C_s| = 2(a + s + δ);
/// each flank pushes F = Kδⁿ along d = (C_h − C_s)/|C_h − C_s|, whose
/// moment about the axis is F·|M × d|, so T = 6·F·|M × d|.
/// The operating angle of a race is d's angle from that race's own radial
/// direction: ŷ for the head, R(−φ)ŷ for the seat, which has turned.
/// Returns (φ per hinge [rad], F [N], α_head, α_seat [rad], δ [m]).
fn rotating_section(torque: f64, k: f64, s: f64) -> (f64, f64, f64, f64, f64) {
    let a = RHO_G - R_B - s;
    let rot = |(y, z): (f64, f64), t: f64| (y * t.cos() - z * t.sin(), y * t.sin() + z * t.cos());
    let c_h = (PCR + a * ALPHA.cos(), a * ALPHA.sin());
    let at = |phi: f64| {
        let c_s = rot((PCR - a * ALPHA.cos(), -a * ALPHA.sin()), -phi);
        let (dy, dz) = (c_h.0 - c_s.0, c_h.1 - c_s.1);
        let len = dy.hypot(dz);
        let (m_y, m_z) = (0.5 * (c_h.0 + c_s.0), 0.5 * (c_h.1 + c_s.1));
        let delta = (0.5 * len - a - s).max(0.0);
        let f = k * delta.powf(N);
        let t = 6.0 * f * (m_y * dz - m_z * dy).abs() / len;
        let head = dz.abs().atan2(dy.abs());
        let (ry, rz) = rot((1.0, 0.0), -phi);
        let seat = (-rz * dy + ry * dz).abs().atan2((ry * dy + rz * dz).abs());
        (t, f, head, seat, delta)
    };
    let (mut lo, mut hi) = (0.0, 0.2);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if at(mid).0 < torque {
            lo = mid
        } else {
            hi = mid
        }
    }
    let phi = 0.5 * (lo + hi);
    let (_, f, head, seat, delta) = at(phi);
    (phi, f, head, seat, delta)
}

/// How far the key's axial travel x [m] toward the line between its two
/// flank centres brings it closer to each [m]: the key sits d_x = a·cos α·c/ρ
/// off that line (the groove offset c tilts each race's radial direction
/// by c/ρ out of the section, in opposite senses), so its distance to
/// each centre drops from a to √(a² − 2·d_x·x + x²).
fn axial_give(x: f64, c: f64, s: f64) -> f64 {
    let a = RHO_G - R_B - s;
    let d_x = a * ALPHA.cos() * c / (PCR * PCR + c * c).sqrt();
    a - (a * a - 2.0 * d_x * x + x * x).sqrt()
}

/// The key's axial travel [m] under race force F [N] with groove offset c:
/// the window pushes back 2F·cos α·c/ρ (per key) after 15 µm of slack
/// (window 15.03 mm, ball 15 mm) and sinks into the window face; the six
/// keys push the cage, whose head and seat contacts (10 µm clearance each)
/// take 3 such thrusts each. All with the paper's law, stiffness `k`.
fn key_axial_travel(f: f64, c: f64, k: f64) -> f64 {
    let thrust = 2.0 * f * ALPHA.cos() * c / (PCR * PCR + c * c).sqrt();
    let sink = |load: f64| (load / k).powf(1.0 / N);
    0.015e-3 + sink(thrust) + 10e-6 + sink(3.0 * thrust)
}

/// docs/model.md §7.10 for the ball-key hinge: one link bent β = 7.645° at
/// each hinge (R = 0.7517 m) carrying T = 1.8 kN·m. A frictionless CV joint
/// with a fixed centre passes its torque about the bisector of the two
/// axes (the virtual power of the zero-twist swings vanishes), so on each
/// body T along its own axis and T·tan(β/2) square to it in the bend plane:
/// the secondary couple; the link's moment balance then needs the
/// out-of-plane hinge shear T·(tan(β₀/2) + tan(β₁/2))/l. The ball-key hinge
/// is such a joint in the limit of stiff contacts and no flank clearance
/// (1e9 N/mm^2.2, s = 0): measured, each hinge's couple within 0.26 % of
/// T·tan(β/2), their mean within 1e-4, the bending moment about the bend
/// normal 1.3 % of the couple, the shear within 4e-5 (unchanged from 0.12
/// to 0.24 s to 1e-5).
///
/// Tolerances: 0.1 % on the mean couple and on the shear, half the
/// difference between tan(β/2) and sin(β/2) at 3.82° (0.22 %): a couple
/// T·sin(β/2), none, or T·tan β (one body's axis instead of the bisector)
/// fails. 0.5 % on each hinge alone, 2 % of the couple for the bending moment.
///
/// Under the paper's soft law the hinge is not this joint: settled (1 s) it
/// carries a bending moment of 95–100 N·m about its bend normal, the bends
/// are 7.98° and 7.32°, the couples 7 % above and 12 % below T·tan(β/2) and
/// the shear 5 % below (docs/model.md §7.10); not asserted here.
#[test]
fn a_ball_key_hinge_passes_the_secondary_couple_t_tan_half_beta() {
    let (t, l) = (1800.0, 0.2);
    let r = 0.1 / 7.645_f64.to_radians().sin();
    let (chain, mut sim, _) = loaded_link(r, t, &[STIFF, "pipe.ball_keys.flank_clearance=0"]);
    let w: Vec<_> = (0..2).map(|h| link_wrench(&mut sim, &chain, h)).collect();
    let (mut measured, mut hand) = (0.0, 0.0);
    for (h, &(bend, axial, bending, couple, _)) in w.iter().enumerate() {
        let expected = t * (bend / 2.0).tan();
        assert!(
            (axial.abs() - t).abs() < 1e-3 * t,
            "hinge {h}: axial moment {axial} N·m"
        );
        assert!(
            ((couple.abs() - expected) / expected).abs() < 5e-3,
            "hinge {h}: couple {couple} N·m vs T·tan(β/2) = {expected} (β = {}°)",
            bend.to_degrees()
        );
        assert!(
            bending.abs() < 0.02 * expected,
            "hinge {h}: bending moment {bending} N·m"
        );
        measured += couple.abs();
        hand += expected;
    }
    assert!(
        ((measured - hand) / hand).abs() < 1e-3,
        "mean couple {} N·m vs {} N·m",
        measured / 2.0,
        hand / 2.0
    );
    // The hand value differs from T·sin(β/2) by more than the tolerance.
    let sin_form = t * ((w[0].0 / 2.0).sin() + (w[1].0 / 2.0).sin());
    assert!((hand - sin_form) / hand > 2e-3);
    for (h, x) in w.iter().enumerate() {
        let shear = hand / l;
        assert!(
            ((x.4.abs() - shear) / shear).abs() < 1e-3,
            "hinge {h}: shear {} N vs {shear} N",
            x.4
        );
    }
}

/// docs/model.md §7.9, the window thrust. A key pressed by its head flank
/// and its seat flank with F each at the contact angle α: each flank
/// pushes F·cos α along its race's radial direction from the groove centre
/// (G_h = −c·x̂ for the head, G_s = +c·x̂ for the seat, the key at (0, PCR,
/// 0) on the pitch circle of a straight hinge), r̂_h = (c, PCR, 0)/ρ and
/// −r̂_s = (c, −PCR, 0)/ρ; the circumferential parts cancel (they carry the
/// torque), the radial parts leave 2F·cos α·c/ρ along +x̂, which the window
/// takes: 2.40 kN at 13.47 kN and 45°. Checked with stiff contacts (the
/// 45° holds) within 0.5 %: measured −0.03 %. Using PCR for ρ (0.8 % more)
/// or one flank (half) fails.
#[test]
fn the_window_takes_the_axial_thrust_2f_cos_alpha_c_over_rho() {
    let rho = (PCR * PCR + C * C).sqrt();
    let hand = 2.0 * 1800.0 / (6.0 * PCR * ALPHA.sin()) * ALPHA.cos() * C / rho;
    assert!((hand - 2400.0).abs() < 1.0, "{hand}");
    let (_, keys) = turn_under(1800.0, &[STIFF, "pipe.ball_keys.flank_clearance=0"]);
    for (j, k) in keys.iter().enumerate() {
        let f = 0.5 * (k.f_head + k.f_seat);
        let expected = 2.0 * f * ALPHA.cos() * C / rho;
        assert!(
            ((k.window - expected) / expected).abs() < 5e-3,
            "key {j}: window {} N vs 2F·cos α·c/ρ = {expected} N",
            k.window
        );
        assert!(((k.window - hand) / hand).abs() < 5e-3, "key {j}");
        assert!((C / PCR - C / rho) / (C / rho) > 5e-3);
    }
}

/// The turn per hinge [rad] the rotating section predicts under `torque`,
/// with the key's axial give for groove offset `c` (docs/model.md §7.9):
/// the give brings the key closer to both flank centres by g, which the
/// turn must make up, 2g/(PCR·sin α) more.
fn predicted_turn(torque: f64, k: f64, s: f64, c: f64) -> f64 {
    let (phi, f, ..) = rotating_section(torque, k, s);
    let give = axial_give(key_axial_travel(f, c, k), c, s);
    phi + 2.0 * give / (PCR * ALPHA.sin())
}

/// docs/model.md §7.9: a hinge under the paper's law on the default open
/// groove (ρ_g = 30 mm), against the rotating section
/// ([`rotating_section`]): key force, turn, both races' operating angles
/// and the tangent torsional stiffness, at 1.71–1.89 kN·m and at the
/// paper's 33.5 kN key peak (4.467 kN·m). First with c = 0.5 mm, where the
/// c → 0 section holds, then at the default c = 4 mm, where the key's axial
/// give (window thrust into the window face and the cage into the head and
/// seat, [`key_axial_travel`]: 0.51 mm at 1.8 kN·m) adds 10 % to the turn.
///
/// Hand values at 1.8 kN·m: F = 13.48 kN, 2.121° per hinge, α 44.97° on the
/// head race and 47.09° on the seat race (measured in the seat's own, turned
/// groove section); k_t = dT/dφ = 1.094e5 N·m/rad, against the closed form
/// 3·PCR²·sin²α·n·F/δ = 1.097e5 at a held 45°.
///
/// Tolerances: force 0.5 %, turn 0.5 % (c = 0.5 mm) and 2.5 % (c = 4 mm, where
/// the give is 10 % of the turn), stiffness 1 %. Angles within 0.4° (c = 0.5
/// mm) and 0.75° (4 mm, for the groove offset the section leaves out): the
/// seat race opens 2.1–3.2° from the head's, and the translating section of
/// the earlier note (cos α′ = a·cos α/(a + s + δ) on both races: 46.0° and
/// 46.5°) misses the head race by 0.8–1.4°.
/// Measured (c = 0.5 mm): force within 0.013 %, turn +0.24 to +0.35 %,
/// angles +0.18 to +0.19° (head) and +0.20° (seat), stiffness 1.0885e5
/// (−0.5 %); (c = 4 mm) force −0.07 %, turn +1.1 to +1.7 %, angles +0.05 to
/// +0.08° (head) and +0.39 to +0.59° (seat).
#[test]
fn a_loaded_hinge_turns_and_opens_as_the_rotating_section() {
    let peak = 33_500.0 * 6.0 * PCR * ALPHA.sin();
    for (c, turn_tol, angle_tol) in [(0.0005, 5e-3, 0.4), (C, 2.5e-2, 0.75)] {
        let offset = format!("pipe.ball_keys.groove_offset={c}");
        let mut turns = vec![];
        for t in [1710.0, 1800.0, 1890.0, peak] {
            let (turn, keys) = turn_under(t, &[&offset]);
            let (_, f, head, seat, delta) = rotating_section(t, K_SI, 1e-5);
            let expected = 2.0 * predicted_turn(t, K_SI, 1e-5, c);
            let case = format!("c = {c} m, T = {t} N·m");
            assert!(
                ((turn - expected) / expected).abs() < turn_tol,
                "{case}: turned {turn} rad vs {expected}"
            );
            if c == C {
                let no_give = 2.0 * rotating_section(t, K_SI, 1e-5).0;
                assert!((expected - no_give) / expected > 0.05, "{case}");
            }
            let a = RHO_G - R_B - 1e-5;
            let translating = (a * ALPHA.cos() / (a + 1e-5 + delta)).acos();
            for (j, k) in keys.iter().enumerate() {
                let mean = 0.5 * (k.f_head + k.f_seat);
                assert!(
                    ((mean - f) / f).abs() < 5e-3,
                    "{case} key {j}: {mean} N vs {f} N"
                );
                for (race, got, want) in
                    [("head", k.alpha_head, head), ("seat", k.alpha_seat, seat)]
                {
                    assert!(
                        (got - want).to_degrees().abs() < angle_tol,
                        "{case} key {j}: {race} angle {}° vs {}°",
                        got.to_degrees(),
                        want.to_degrees()
                    );
                }
                assert!((k.alpha_seat - k.alpha_head).to_degrees() > 1.5, "{case}");
                assert!(
                    (translating - k.alpha_head).to_degrees() > angle_tol,
                    "{case}"
                );
            }
            turns.push(turn);
        }
        if c < C {
            // Tangent stiffness per hinge: the two hinges turn in series.
            let measured = 180.0 / (0.5 * (turns[2] - turns[0]));
            let model = 180.0
                / (rotating_section(1890.0, K_SI, 1e-5).0 - rotating_section(1710.0, K_SI, 1e-5).0);
            let f = 1800.0 / (6.0 * PCR * ALPHA.sin());
            let delta = (f / K_SI).powf(1.0 / N);
            let closed = 3.0 * PCR * PCR * ALPHA.sin().powi(2) * N * f / delta;
            assert!((closed - 1.097e5).abs() < 1e2, "{closed}");
            assert!(
                ((model - closed) / closed).abs() < 5e-3,
                "{model} vs {closed}"
            );
            assert!(
                ((measured - model) / model).abs() < 1e-2,
                "k_t = {measured} N·m/rad vs {model}"
            );
        }
    }
}

/// docs/model.md §7.9, the flank backlash. A centred key has s of
/// clearance to each of its four flanks; the seat must turn until the
/// distance between the head flank centre and the opposite seat flank
/// centre, 2a along the line at α, has grown by 2s: φ = 2s/(PCR·sin α) =
/// 0.0514° per hinge from centred to engaged (first order; 0.103° between
/// the two senses). Stiff contacts (1e9 N/mm^2.2), ±2 N·m, c = 0.5 mm, with
/// s = 10 and 20 µm. The full hand value adds the sink δ = (F/K)^(1/n) under
/// the 15 N key load (0.28 µm, 2.8 %) and the key's 25 µm axial give
/// (window slack and cage clearance, 2.6 %): 0.05425°; measured 0.05419°
/// (−0.12 %; −0.13 % at s = 20 µm). Tolerance 1 %, below either term; the
/// clearance's share, the difference between s = 20 and 10 µm, is
/// 2Δs/(PCR·sin α) within 1 % (measured −0.15 %).
#[test]
fn the_flank_backlash_is_2s_over_pcr_sin_alpha_per_hinge() {
    let c = "pipe.ball_keys.groove_offset=0.0005";
    let mut play = vec![];
    for s in [1e-5, 2e-5] {
        let clearance = format!("pipe.ball_keys.flank_clearance={s}");
        let o = [STIFF, c, &clearance];
        let (plus, _) = turn_under(2.0, &o);
        let (minus, _) = turn_under(-2.0, &o);
        let per_hinge = 0.25 * (plus - minus);
        let expected = predicted_turn(2.0, K_STIFF, s, 0.0005);
        let bare = 2.0 * s / (PCR * ALPHA.sin());
        assert!(
            ((per_hinge - expected) / expected).abs() < 1e-2,
            "s = {s}: play {}° per hinge vs {}°",
            per_hinge.to_degrees(),
            expected.to_degrees()
        );
        assert!((expected - bare) / bare > 1e-2 * 2.0);
        play.push(per_hinge);
    }
    let share = 2.0 * 1e-5 / (PCR * ALPHA.sin());
    assert!((share.to_degrees() - 0.0514).abs() < 1e-4);
    assert!(
        ((play[1] - play[0] - share) / share).abs() < 1e-2,
        "10 µm of clearance turns {}°, expected {}°",
        (play[1] - play[0]).to_degrees(),
        share.to_degrees()
    );
}

/// Each key's race normal forces (head, seat) and window push [N] of hinge
/// `h` at `state`, by a fresh evaluation of its pairs.
fn key_forces(sim: &Simulation, state: &State, h: usize) -> Vec<(f64, f64, f64)> {
    let model = sim.model();
    let mut dynamics = Dynamics::new(model);
    let mut sum = |names: &[String]| -> f64 {
        let mut total = 0.0;
        for name in names {
            let k = sim.pair_index(name).unwrap();
            let mut out = vec![];
            dynamics.contact_points(model, state, k, &mut out);
            total += out.iter().map(|e| e.normal_force).sum::<f64>();
        }
        total
    };
    (0..6)
        .map(|j| {
            let pair = |race: &str| -> Vec<String> {
                ["+", "-"]
                    .iter()
                    .map(|t| format!("h{h:02}.key{j}/{race}{t}"))
                    .collect()
            };
            (
                sum(&pair("head")),
                sum(&pair("seat")),
                sum(&[format!("h{h:02}.key{j}/window-axial")]),
            )
        })
        .collect()
}

/// Hinge `h`'s cage (free in its pose, first) and six keys (free in their
/// positions) for `dynamics::quasistatic`, and the state of `sim` at rest, as
/// the hand statics are (the settled links still creep by µm/s).
fn hinge_at_rest(sim: &Simulation, h: usize) -> (Vec<(usize, StaticDofs)>, State) {
    let mut free = vec![(
        common::body(sim, &format!("h{h:02}.cage")),
        StaticDofs::Pose,
    )];
    free.extend((0..6).map(|j| {
        let key = common::body(sim, &format!("h{h:02}.key{j}"));
        (key, StaticDofs::Position)
    }));
    let mut state = sim.state().clone();
    state.vel.fill(Vec3::zeros());
    state.omega.fill(Vec3::zeros());
    (free, state)
}

/// Issue 28's local solve (`dynamics::quasistatic::equilibrium`): hinge 0's
/// cage (its pose) and keys (their positions) moved off the settled state of
/// the dynamic model (the cage by 4 µm and 0.01° about the pipe axis, each
/// key by 3–5 µm; ten times that with the paper's softer contacts) and solved for equilibrium with the links held come back
/// to the settled forces: each key's race forces and window push within 1 %
/// of the dynamic model's (settled to 1e-4, module doc), and with contacts
/// stiff enough that 45° holds, within 1 % of the hand statics, F =
/// T/(6·PCR·sin α) = 13.47 kN per key on both races and 2F·cos α·c/ρ on the
/// window (docs/model.md §7.9). Moved, the forces are more than 5 % off, so
/// the 1 % catches a solve that stopped short.
#[test]
fn the_cage_and_keys_solved_for_equilibrium_carry_the_settled_forces_and_the_hand_statics() {
    let torque = 1800.0;
    let f_hand = torque / (6.0 * PCR * ALPHA.sin());
    let rho = (PCR * PCR + C * C).sqrt();
    // The paper's contacts sink 0.35 mm at this load: the start is moved ten times as far.
    for (extra, stiff, far) in [(&[STIFF][..], true, 1.0), (&[][..], false, 10.0)] {
        let (chain, sim, _) = loaded_link(1000.0, torque, extra);
        let settled = key_forces(&sim, sim.state(), 0);
        let (free, mut state) = hinge_at_rest(&sim, 0);
        let (cage, keys) = (free[0].0, &free[1..]);
        state.pos[cage] += far * Vec3::new(4e-6, -3e-6, 2e-6);
        let axis = state.rot[chain[0]] * Vec3::x();
        state.rot[cage] = Quat::from_scaled_axis(axis * 1.7e-4 * far) * state.rot[cage];
        for (j, &(key, _)) in keys.iter().enumerate() {
            let psi = j as f64 * std::f64::consts::FRAC_PI_3;
            state.pos[key] += far * Vec3::new(3e-6, 5e-6 * psi.cos(), -4e-6 * psi.sin());
        }
        let moved = key_forces(&sim, &state, 0);
        let off = |a: &[(f64, f64, f64)]| {
            a.iter()
                .zip(&settled)
                .map(|(x, y)| ((x.0 - y.0) / y.0).abs().max(((x.1 - y.1) / y.1).abs()))
                .fold(0.0f64, f64::max)
        };
        assert!(
            off(&moved) > 0.05,
            "the start is off the settled forces: {}",
            off(&moved)
        );
        let model = sim.model();
        let mut dynamics = Dynamics::new(model);
        let solve = equilibrium(
            model,
            &mut dynamics,
            &mut state,
            &free,
            StaticTolerance::default(),
        )
        .unwrap_or_else(|e| panic!("stiff = {stiff}: {e}"));
        let solved = key_forces(&sim, &state, 0);
        println!("stiff = {stiff}: {solve:?}, settled {settled:?}, solved {solved:?}");
        assert!(solve.force < 1e-3 * f_hand, "{solve:?}");
        assert!(off(&solved) < 0.01, "stiff = {stiff}: {}", off(&solved));
        for ((head, seat, window), (_, _, w0)) in solved.iter().zip(&settled) {
            assert!(
                ((window - w0) / w0).abs() < 0.01,
                "window {window} against {w0}"
            );
            if stiff {
                for f in [head, seat] {
                    assert!((f / f_hand - 1.0).abs() < 0.01, "{f} against {f_hand}");
                }
                let thrust = 2.0 * head * ALPHA.cos() * C / rho;
                assert!(
                    (window / thrust - 1.0).abs() < 0.01,
                    "{window} against {thrust}"
                );
            }
        }
    }
}

/// Issue 28's Jacobian of a quasi-static hinge (`condensed_stiffness`, by
/// the implicit function theorem) against central differences of its
/// equilibria: hinge 0 of the loaded link at rest, its cage and keys in
/// equilibrium; each of the connector's and the link's 12 pose coordinates
/// moved by ±ε (10 nm, or 10 nm at a 30 mm arm for a turn), the cage and
/// keys solved for equilibrium again, and the change of the two bodies' net
/// wrenches over 2ε; with contacts stiff enough that 45° holds (6 µm deep,
/// so ε/δ ≈ 2e-3 and the differences' own error is about (ε/δ)²) and with
/// the paper's law (0.35 mm deep; measured 1.3e-6 and 2.1e-5, the latter
/// set by the solves' 1e-4 N residual). Without the free bodies' response
/// (K_hh alone) the error is of order one (1.4 and 1.3), so the bound of
/// 1e-4 catches a Schur complement left out or wrong.
#[test]
fn the_condensed_stiffness_of_a_hinge_matches_finite_differences_of_its_equilibria() {
    for extra in [&[STIFF][..], &[][..]] {
        condensed_against_differences(extra);
    }
}

/// [`the_condensed_stiffness_of_a_hinge_matches_finite_differences_of_its_equilibria`]
/// with the scene overrides `extra`.
fn condensed_against_differences(extra: &[&str]) {
    let (chain, sim, _) = loaded_link(1000.0, 1800.0, extra);
    let model = sim.model();
    let (free, mut rest) = hinge_at_rest(&sim, 0);
    let held = [chain[0], chain[1]];
    let mut dynamics = Dynamics::new(model);
    equilibrium(
        model,
        &mut dynamics,
        &mut rest,
        &free,
        StaticTolerance::default(),
    )
    .unwrap();
    let analytic = condensed_stiffness(model, &mut dynamics, &rest, &free, &held).unwrap();
    // K_hh alone: the free bodies left where they are.
    let k_hh = condensed_stiffness(model, &mut dynamics, &rest, &[], &held).unwrap();
    // The held bodies' net wrenches with the free bodies in equilibrium.
    let wrenches = |b: usize, c: usize, d: f64| -> Vec<f64> {
        let mut state = moved(&rest, &held, b, c, d);
        equilibrium(
            model,
            &mut dynamics,
            &mut state,
            &free,
            StaticTolerance::default(),
        )
        .unwrap();
        dynamics.wrenches(model, &state, Mode::Trial);
        held_wrenches(&dynamics, &held)
    };
    let (err, without) =
        against_differences(|r, c| analytic[(r, c)], |r, c| k_hh[(r, c)], wrenches);
    println!("{extra:?}: condensed against differences {err:.3e}, K_hh alone {without:.3e}");
    assert!(err < 1e-4, "{err:e}");
    assert!(without > 1e-2, "{without:e}");
}

/// Issue 28's quasi-static hinge (`pipe.hinge = "ball-keys-qs"`): the
/// loaded link of [`loaded_link`] at 1.8 kN·m with contacts stiff enough
/// that 45° holds, its cages and keys solved for equilibrium at every
/// evaluation instead of integrated. Each key's race forces and window push
/// are within 1 % of the dynamic model's settled ones and of the hand
/// statics (F = T/(6·PCR·sin α) = 13.47 kN, 2F·cos α·c/ρ on the window;
/// docs/model.md §7.9). A hinge that passed half the torque, or none of
/// the window's thrust, would be 50 % or 100 % off.
#[test]
fn the_quasi_static_hinge_carries_the_settled_forces_and_the_hand_statics() {
    let torque = 1800.0;
    let f_hand = torque / (6.0 * PCR * ALPHA.sin());
    let rho = (PCR * PCR + C * C).sqrt();
    let (_, dynamic, _) = loaded_link(1000.0, torque, &[STIFF]);
    let settled = key_forces(&dynamic, dynamic.state(), 0);
    let (_, qs, _) = loaded_link(1000.0, torque, &[STIFF, "pipe.hinge=\"ball-keys-qs\""]);
    let solved = key_forces(&qs, qs.state(), 0);
    let meta = qs.finish().metadata;
    let count = |key: &str| -> f64 {
        meta.iter()
            .find(|(k, _)| k == key)
            .map(|(_, v)| v.parse().unwrap())
            .unwrap_or_else(|| panic!("no {key}"))
    };
    let (solves, failures) = (
        count("ballcage.static_solves"),
        count("ballcage.static_failures"),
    );
    println!("settled {settled:?}\nsolved {solved:?}\n{failures} of {solves} solves failed");
    // The solves that fail are at the start of the torque ramp, where the
    // keys are barely loaded (docs/engine.md, "Quasi-static bodies").
    assert!(failures < 0.02 * solves, "{failures} of {solves}");
    for ((head, seat, window), (h0, s0, w0)) in solved.iter().zip(&settled) {
        for (f, f0) in [(head, h0), (seat, s0), (window, w0)] {
            assert!(((f - f0) / f0).abs() < 0.01, "{f} against the dynamic {f0}");
        }
        for f in [head, seat] {
            assert!((f / f_hand - 1.0).abs() < 0.01, "{f} against {f_hand}");
        }
        let thrust = 2.0 * head * ALPHA.cos() * C / rho;
        assert!(
            (window / thrust - 1.0).abs() < 0.01,
            "{window} against {thrust}"
        );
    }
}

/// Issue 28's quasi-static hinge as a force element: the velocity
/// Jacobian's stiffness (the blocks at stiffness scale 1 less those at 0,
/// `Dynamics::forces_and_jacobian`) of the loaded link with
/// `pipe.hinge = "ball-keys-qs"`, over hinge 0's two bodies (the upper
/// connector and the link), against central differences of their net
/// wrenches, each evaluation solving the cages and keys again: each of the
/// 12 pose coordinates moved by ±ε (10 nm, or 10 nm at a 30 mm arm for a
/// turn), with contacts stiff enough that 45° holds (measured 8.5e-6).
/// Without the groups' condensed blocks (K_hh alone: the keys held where
/// they are) the error is of order one (measured 23), so the bound catches
/// a Schur complement left out or wrong. (With the paper's law the loaded
/// link does not run yet: docs/engine.md, "Quasi-static bodies".)
#[test]
fn the_quasi_static_hinge_jacobian_matches_finite_differences_of_its_forces() {
    let (chain, sim, _) = loaded_link(1000.0, 1800.0, &[STIFF, "pipe.hinge=\"ball-keys-qs\""]);
    let model = sim.model();
    let rest = sim.state().clone();
    let held = [chain[0], chain[1]];
    let mut dynamics = Dynamics::new(model);
    dynamics.wrenches(model, &rest, Mode::Trial);
    let own = model.pairs.len() + model.joints.len();
    // K over the held bodies' poses, with or without the groups' blocks.
    let mut stiffness = |with_groups: bool| -> Vec<f64> {
        let mut dense = |s: f64| {
            let mut jac = VelocityJacobian::new(model);
            dynamics.forces_and_jacobian(model, &rest, Mode::Trial, s, &mut jac);
            if !with_groups {
                for c in &mut jac.couplings[own..] {
                    c.clear();
                }
            }
            jac.to_dense(model.bodies.len())
        };
        let k = dense(1.0) - dense(0.0);
        let mut out = vec![];
        for r in 0..12 {
            for c in 0..12 {
                out.push(k[(6 * held[r / 6] + r % 6, 6 * held[c / 6] + c % 6)]);
            }
        }
        out
    };
    let (analytic, k_hh) = (stiffness(true), stiffness(false));
    let (err, without) = against_differences(
        |r, c| analytic[12 * r + c],
        |r, c| k_hh[12 * r + c],
        |b, c, d| {
            dynamics.wrenches(model, &moved(&rest, &held, b, c, d), Mode::Trial);
            held_wrenches(&dynamics, &held)
        },
    );
    println!(
        "the force element's stiffness against differences {err:.3e}, K_hh alone {without:.3e}"
    );
    assert!(err < 1e-3, "{err:e}");
    assert!(without > 1e-1, "{without:e}");
}

/// `rest` with held body `held[b]` moved by `d` along coordinate `c` (a
/// translation for c < 3, else a turn) [m, rad].
fn moved(rest: &State, held: &[usize], b: usize, c: usize, d: f64) -> State {
    let mut state = rest.clone();
    let mut v = Vec3::zeros();
    v[c % 3] = d;
    if c < 3 {
        state.pos[held[b]] += v;
    } else {
        state.rot[held[b]] = Quat::from_scaled_axis(v) * state.rot[held[b]];
    }
    state
}

/// The held bodies' net wrenches of the last evaluation, stacked.
fn held_wrenches(dynamics: &Dynamics, held: &[usize]) -> Vec<f64> {
    held.iter()
        .flat_map(|&h| {
            let (f, t) = (dynamics.forces()[h], dynamics.torques()[h]);
            [f.x, f.y, f.z, t.x, t.y, t.z]
        })
        .collect()
}

/// The relative Frobenius errors of a 12 × 12 stiffness `analytic` and of
/// `held_only` (row, column) against central differences of `wrenches`
/// (held body, coordinate, displacement), each coordinate moved by ±10 nm
/// (a turn: 10 nm at a 30 mm arm), rows and columns weighted to forces and
/// translations.
fn against_differences(
    analytic: impl Fn(usize, usize) -> f64,
    held_only: impl Fn(usize, usize) -> f64,
    mut wrenches: impl FnMut(usize, usize, f64) -> Vec<f64>,
) -> (f64, f64) {
    const ARM: f64 = 0.03;
    let scale = |i: usize| if i % 6 < 3 { 1.0 } else { 1.0 / ARM };
    let (mut diff, mut norm, mut without) = (0.0, 0.0, 0.0);
    for col in 0..12 {
        let eps = 1e-8 * scale(col);
        let (plus, minus) = (
            wrenches(col / 6, col % 6, eps),
            wrenches(col / 6, col % 6, -eps),
        );
        for row in 0..12 {
            let w = scale(row) * scale(col);
            let fd = (plus[row] - minus[row]) / (2.0 * eps) * w;
            diff += (analytic(row, col) * w - fd).powi(2);
            without += (held_only(row, col) * w - fd).powi(2);
            norm += fd.powi(2);
        }
    }
    ((diff / norm).sqrt(), (without / norm).sqrt())
}
