//! Three-way tube forces on the paper's drill pipe with the ideal-CV hinge
//! (issue 16): ballcage, rapier with the triangle-mesh bore, and rapier with
//! the exact bore (`ballcage_shapes::TubeInterior` through
//! `ballcage_shapes::ShapeDispatcher`). For each link, the mean and the peak
//! of its tube normal force over a window, and the differences that split
//! rapier's departure from ballcage into the faceted wall's part (mesh
//! against exact, both rapier) and the solver's (rapier exact against
//! ballcage).
//!
//! Usage (release build):
//!
//! ```sh
//! cargo run --release -p ballcage-bench --example rapier_exact_bore -- \
//!     [--dt S] [--duration S] [--window-start S] [--samples N] [--mu MU] [--set KEY=VALUE ...]
//! ```
//!
//! Defaults: dt = 1 ms for all three, 1.8 s, window [0.5, 1.8] s (after both
//! 0.3 s ramps), 5 samples along each link for the exact bore (ballcage's
//! `pipe.tube_contact_points`), rapier's μ from the scene's friction law at
//! the drive's surface speed. Only the `step` calls are timed.

use std::time::{Duration, Instant};

use ballcage_bench::rapier_chain::{
    BallcageTubeForces, Bore, RapierChain, RapierOptions, WindowMean, paper_ideal_cv,
};
use ballcage_core::Scene;

struct Args {
    dt: f64,
    duration: f64,
    window_start: f64,
    samples: u32,
    mu: Option<f64>,
    extra: Vec<String>,
}

fn parse() -> Args {
    let mut a = Args {
        dt: 1e-3,
        duration: 1.8,
        window_start: 0.5,
        samples: 5,
        mu: None,
        extra: vec![],
    };
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().unwrap_or_else(|| panic!("{flag} needs a value"));
        match flag.as_str() {
            "--dt" => a.dt = value().parse().expect("--dt seconds"),
            "--duration" => a.duration = value().parse().expect("--duration seconds"),
            "--window-start" => a.window_start = value().parse().expect("--window-start seconds"),
            "--samples" => a.samples = value().parse().expect("--samples N"),
            "--mu" => a.mu = Some(value().parse().expect("--mu coefficient")),
            "--set" => a.extra.push(value()),
            other => panic!("unknown argument {other}"),
        }
    }
    a
}

/// Per-link means and peaks over the window, and the stepping's wall time.
struct Run {
    name: &'static str,
    /// rapier's Coulomb coefficient (0 for ballcage).
    mu: f64,
    mean: Vec<f64>,
    peak: Vec<f64>,
    wall: Duration,
    simulated: f64,
}

/// Adds a sample to the running peaks.
fn raise(peak: &mut Vec<f64>, sample: &[f64]) {
    if peak.is_empty() {
        *peak = vec![0.0; sample.len()];
    }
    for (p, s) in peak.iter_mut().zip(sample) {
        *p = p.max(*s);
    }
}

fn run_ballcage(doc: &ballcage_core::Document, window: (f64, f64)) -> Run {
    let tube = BallcageTubeForces::new(doc.scene());
    let mut sim = doc.simulation();
    let (mut mean, mut peak) = (WindowMean::new(window.0, window.1), vec![]);
    let mut wall = Duration::ZERO;
    while !sim.is_done() {
        let t0 = Instant::now();
        let r = sim.step();
        wall += t0.elapsed();
        if let Err(e) = r {
            println!("ballcage STOPPED at t = {:.4} s: {e}", sim.time());
            break;
        }
        if mean.wants(sim.time()) {
            let f = tube.sample(&mut sim);
            mean.add(sim.time(), &f);
            raise(&mut peak, &f);
        }
    }
    Run {
        name: "ballcage",
        mu: 0.0,
        mean: mean.means(),
        peak,
        wall,
        simulated: sim.time(),
    }
}

fn run_rapier(scene: &Scene, options: &RapierOptions, duration: f64, window: (f64, f64)) -> Run {
    let mut chain = RapierChain::from_scene(scene, options).unwrap_or_else(|e| panic!("{e}"));
    let (mut mean, mut peak) = (WindowMean::new(window.0, window.1), vec![]);
    let mut wall = Duration::ZERO;
    while chain.time() < duration - 1e-9 {
        let t0 = Instant::now();
        chain.step();
        wall += t0.elapsed();
        if mean.wants(chain.time()) {
            let f = chain.tube_normal_forces();
            mean.add(chain.time(), &f);
            raise(&mut peak, &f);
        }
    }
    let name = match options.bore {
        Bore::Mesh => "rapier, mesh bore",
        Bore::Exact { .. } => "rapier, exact bore",
    };
    println!(
        "{name}: {} triangles, μ = {:.3}, {} substeps",
        chain.triangles(),
        chain.friction(),
        options.substeps
    );
    Run {
        name,
        mu: chain.friction(),
        mean: mean.means(),
        peak,
        wall,
        simulated: chain.time(),
    }
}

/// ‖a − b‖₂ / ‖b‖₂ over the links.
fn l2(a: &[f64], b: &[f64]) -> f64 {
    let num: f64 = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum();
    (num / b.iter().map(|y| y * y).sum::<f64>()).sqrt()
}

fn pct(a: f64, b: f64) -> String {
    if b > 0.0 {
        format!("{:+.0} %", (a / b - 1.0) * 100.0)
    } else {
        "–".to_string()
    }
}

fn print_table(runs: &[Run; 3], of: fn(&Run) -> &Vec<f64>, what: &str) {
    let [b, m, e] = runs;
    println!("\n{what} tube normal force per link [N]:\n");
    println!(
        "| link | ballcage | rapier mesh | rapier exact | mesh − exact | exact − ballcage | mesh − ballcage |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    let (fb, fm, fe) = (of(b), of(m), of(e));
    for k in 0..fb.len() {
        println!(
            "| link{:02} | {:.1} | {:.1} | {:.1} | {} | {} | {} |",
            k + 1,
            fb[k],
            fm[k],
            fe[k],
            pct(fm[k], fe[k]),
            pct(fe[k], fb[k]),
            pct(fm[k], fb[k])
        );
    }
    let sum = |v: &Vec<f64>| v.iter().sum::<f64>();
    let (sb, sm, se) = (sum(fb), sum(fm), sum(fe));
    println!(
        "| sum | {sb:.1} | {sm:.1} | {se:.1} | {} | {} | {} |",
        pct(sm, se),
        pct(se, sb),
        pct(sm, sb)
    );
    println!(
        "| L2 over the links | | | | {:.3} | {:.3} | {:.3} |",
        l2(fm, fe),
        l2(fe, fb),
        l2(fm, fb)
    );
}

fn main() {
    let args = parse();
    let output = args.dt * (1e-3 / args.dt).ceil().max(1.0);
    let mut overrides = vec![
        format!("simulation.dt={}", args.dt),
        format!("simulation.duration={}", args.duration),
        format!("simulation.output_interval={output}"),
    ];
    overrides.extend(args.extra.iter().cloned());
    let doc = paper_ideal_cv(&overrides).unwrap_or_else(|e| panic!("{e}"));
    let window = (args.window_start, args.duration);
    println!("overrides: pipe.hinge=\"ideal-cv\" {}", overrides.join(" "));
    println!(
        "step {} s, duration {} s, forces over [{}, {}] s",
        args.dt, args.duration, window.0, window.1
    );
    let mesh = RapierOptions {
        friction: args.mu,
        ..RapierOptions::default()
    };
    let exact = RapierOptions {
        bore: Bore::Exact {
            samples: args.samples,
        },
        ..mesh.clone()
    };
    let runs = [
        run_ballcage(&doc, window),
        run_rapier(doc.scene(), &mesh, args.duration, window),
        run_rapier(doc.scene(), &exact, args.duration, window),
    ];
    for r in &runs {
        println!(
            "{}: {:.3} s wall for {:.3} s simulated, real-time factor {:.3}",
            r.name,
            r.wall.as_secs_f64(),
            r.simulated,
            r.simulated / r.wall.as_secs_f64()
        );
    }
    if runs.iter().any(|r| r.mean.is_empty()) {
        println!("no samples in the window");
        return;
    }
    print_table(&runs, |r| &r.mean, "Mean");
    print_table(&runs, |r| &r.peak, "Peak");
    spread(doc.scene(), &exact, &runs[2], args.duration, window);
}

/// rapier's own sensitivity: the exact-bore run again with μ × (1 + 1e-4),
/// against the first. The chain's buckled shape in the tube is chaotic
/// (docs/peers.md), so differences between runs below this spread are not
/// resolved.
fn spread(scene: &Scene, exact: &RapierOptions, first: &Run, duration: f64, window: (f64, f64)) {
    let nudged = RapierOptions {
        friction: Some(first.mu * (1.0 + 1e-4)),
        ..exact.clone()
    };
    let again = run_rapier(scene, &nudged, duration, window);
    let sum = |v: &Vec<f64>| v.iter().sum::<f64>();
    println!(
        "\nrapier exact bore with μ × 1.0001 against μ: means L2 {:.3}, sum {}; peaks L2 {:.3}",
        l2(&again.mean, &first.mean),
        pct(sum(&again.mean), sum(&first.mean)),
        l2(&again.peak, &first.peak)
    );
}
