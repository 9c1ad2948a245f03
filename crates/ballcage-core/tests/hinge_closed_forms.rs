//! The ball-key hinge against hand calculations (docs/model.md §7.9,
//! §7.10): its secondary couple T·tan(β/2), the window thrust
//! 2F·cos α·c/ρ, its torsional stiffness and its backlash.

mod common;

use ballcage_core::math::Vec3;
use ballcage_core::{Document, Simulation};

const PCR: f64 = 0.0315; // pitch radius [m]
const C: f64 = 0.004; // groove-centre offset per race [m]
const R_B: f64 = 0.0075; // ball radius [m]
const K_SI: f64 = 1e5 * 3.981_071_705_534_972e6; // 1e5 N/mm^2.2 in N/m^2.2

/// One key of a loaded hinge: the race forces on the key (world, [N]), their
/// normal magnitudes [N], the operating contact angles [rad] and the
/// window's axial push [N].
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
/// connector over 40 ms, no gravity, run to 0.12 s with `extra` overrides.
fn loaded_link(r: f64, torque: f64, extra: &[String]) -> (Document, Simulation) {
    let mut o: Vec<String> = vec![
        "pipe.joints=1".into(),
        format!("borehole.curvature_radius={r}"),
        "drive.speed_rpm=0".into(),
        format!("load.resisting_moment={torque}"),
        "load.ramp=0.04".into(),
        "world.gravity=0".into(),
        "simulation.duration=0.12".into(),
        "record.tables=[]".into(),
    ];
    o.extend(extra.iter().cloned());
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &o).unwrap();
    let mut sim = doc.simulation();
    sim.run().unwrap();
    (doc, sim)
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
        let e_t = s.rot[head] * Vec3::new(0.0, -psi.sin(), psi.cos());
        let g_head = s.pos[head] + s.rot[head] * Vec3::new(0.1 - C, 0.0, 0.0);
        let g_seat = s.pos[seat] + s.rot[seat] * Vec3::new(-0.1 + C, 0.0, 0.0);
        let mut race = |name: &str, g: Vec3| -> (f64, f64) {
            let (mut force, mut angle) = (0.0, 0.0);
            for t in ["+", "-"] {
                let k = sim.pair_index(&format!("h{h:02}.key{j}/{name}{t}")).unwrap();
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
        let (f_head, alpha_head) = race("head", g_head);
        let (f_seat, alpha_seat) = race("seat", g_seat);
        let k = sim.pair_index(&format!("h{h:02}.key{j}/window-axial")).unwrap();
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
    (bend, m.dot(&x), m.dot(&normal), m.dot(&third), f.dot(&normal))
}

#[test]
fn explore_couple() {
    let r0 = 0.1 / 7.645_f64.to_radians().sin();
    for (hinge, t, r, extra) in [("ball-keys", 1800.0, r0, vec!["materials.internal.friction.mu_dynamic=0", "materials.internal.friction.mu_static=0"]), ("ball-keys", 1800.0, r0, vec!["materials.internal.normal.stiffness=1e9", "pipe.ball_keys.flank_clearance=0"]), ("ball-keys", 1800.0, r0, vec!["pipe.ball_keys.groove_offset=0.001"])] {
        let mut o = vec![format!("pipe.hinge=\"{hinge}\"")];
        o.extend(extra.iter().map(|s| s.to_string()));
        let (doc, mut sim) = loaded_link(r, t, &o);
        println!("{extra:?} T {t} R {r}");
        let chain = doc.drill_pipe_parts().unwrap().1.chain.clone();
        for h in 0..2 {
            let (b, ax, bm, sec, shear) = link_wrench(&mut sim, &chain, h);
            println!("{hinge} {h}: bend {:.4} axial {ax:.2} bending {bm:.3} secondary {sec:.3} (T tan b/2 = {:.3}) shear {shear:.2} (2T tan/l {:.2})",
                b.to_degrees(), t * (b / 2.0).tan(), 2.0 * t * (b / 2.0).tan() / 0.2);
        }
    }
}

#[test]
fn explore() {
    let (doc, mut sim) = loaded_link(1000.0, 1800.0, &[]);
    let chain = doc.drill_pipe_parts().unwrap().1.chain.clone();
    for h in 0..2 {
        for k in keys_of(&mut sim, h, chain[h], chain[h + 1]) {
            let hand = (k.f_head * k.alpha_head.cos() + k.f_seat * k.alpha_seat.cos()) * C
                / (PCR * PCR + C * C).sqrt();
            println!(
                "{h} {:.1} {:.1} {:.3} {:.3} window {:.1} hand {:.1}",
                k.f_head,
                k.f_seat,
                k.alpha_head.to_degrees(),
                k.alpha_seat.to_degrees(),
                k.window,
                hand
            );
        }
    }
    let _ = (R_B, K_SI);
    for h in 0..2 {
        for j in 0..2 {
            for name in ["head+", "head-", "seat+", "seat-", "window-axial", "window-side"] {
                let k = sim.pair_index(&format!("h{h:02}.key{j}/{name}")).unwrap();
                for e in sim.pair_contacts(k) {
                    println!("{h} {j} {name} depth {:.4} mm F {:.1}", e.point.depth * 1e3, e.normal_force);
                }
            }
        }
    }
    let (lower, upper) = (chain[2], chain[0]);
    let s = sim.state();
    println!("turn lower {:.4} deg link {:.4}", (s.rot[lower]).angle().to_degrees(), (s.rot[chain[1]] * s.rot[upper].inverse()).angle().to_degrees());
    for b in 0..3 { println!("body {} pos {:?}", b, s.pos[chain[b]]); }
    let cage = common::body(&sim, "h00.cage");
    println!("cage {:?}", s.pos[cage]);
}
