//! ballcage against rapier3d-f64 on the paper's drill pipe with the ideal-CV
//! hinge: wall time of each engine's stepping loop, real-time factors, their
//! ratio, and each link's mean tube normal force in both.
//!
//! Usage (release build):
//!
//! ```sh
//! cargo run --release -p ballcage-bench --example rapier_forces -- \
//!     [--joints N] [--dt S] [--duration S] [--window-start S] \
//!     [--mu MU] [--around N] [--arc-step DEG] [--substeps N] [--set KEY=VALUE ...] \
//!     [--ballcage-only]
//! ```
//!
//! Defaults: the paper's 12 joints, dt = 1 ms for both engines (ballcage's
//! default integrator, SDIRK2), 1.8 s, forces averaged from 0.5 s (after
//! both 0.3 s ramps) to the end. `--set` passes any other ballcage override.
//! Only the `step` calls are timed; reading the forces is not.
//! `--ballcage-only` skips rapier (for ballcage's own step sensitivity).

use std::time::{Duration, Instant};

use ballcage_bench::rapier_chain::{
    BallcageTubeForces, BoreMesh, RapierChain, RapierOptions, WindowMean, paper_ideal_cv,
};
use ballcage_core::{Document, Scene};

struct Args {
    joints: Option<usize>,
    dt: f64,
    duration: f64,
    window_start: f64,
    options: RapierOptions,
    extra: Vec<String>,
    ballcage_only: bool,
}

fn parse() -> Args {
    let mut a = Args {
        joints: None,
        dt: 1e-3,
        duration: 1.8,
        window_start: 0.5,
        options: RapierOptions::default(),
        extra: vec![],
        ballcage_only: false,
    };
    let mut mesh = BoreMesh::default();
    let mut it = std::env::args().skip(1);
    while let Some(flag) = it.next() {
        let mut value = || it.next().unwrap_or_else(|| panic!("{flag} needs a value"));
        match flag.as_str() {
            "--joints" => a.joints = Some(value().parse().expect("--joints N")),
            "--dt" => a.dt = value().parse().expect("--dt seconds"),
            "--duration" => a.duration = value().parse().expect("--duration seconds"),
            "--window-start" => a.window_start = value().parse().expect("--window-start seconds"),
            "--mu" => a.options.friction = Some(value().parse().expect("--mu coefficient")),
            "--around" => mesh.around = value().parse().expect("--around facets"),
            "--arc-step" => mesh.arc_step_deg = value().parse().expect("--arc-step degrees"),
            "--substeps" => a.options.substeps = value().parse().expect("--substeps N"),
            "--set" => a.extra.push(value()),
            "--ballcage-only" => a.ballcage_only = true,
            other => panic!("unknown argument {other}"),
        }
    }
    a.options.mesh = mesh;
    a
}

fn main() {
    let args = parse();
    let overrides = overrides(&args);
    let doc = paper_ideal_cv(&overrides).unwrap_or_else(|e| panic!("{e}"));
    let scene = doc.scene();
    let window = (args.window_start, args.duration);
    print_header(scene, &args, &overrides, window);
    let bc = run_ballcage(&doc, window);
    if args.ballcage_only {
        print_ballcage_only(&bc);
        return;
    }
    let ra = run_rapier(scene, &args, window);
    print_rapier_world(scene, &args, &ra);
    print_timing(&bc, &ra);
    print_forces(&bc, &ra, window);
}

/// ballcage's overrides: the step, the duration, an output interval that
/// keeps no frame (ballcage records at whole multiples of the step), the
/// number of joints and the `--set` ones.
fn overrides(args: &Args) -> Vec<String> {
    let output = args.dt * (1e-3 / args.dt).ceil().max(1.0);
    let mut overrides = vec![
        format!("simulation.dt={}", args.dt),
        format!("simulation.duration={}", args.duration),
        format!("simulation.output_interval={output}"),
    ];
    if let Some(n) = args.joints {
        overrides.push(format!("pipe.joints={n}"));
    }
    overrides.extend(args.extra.iter().cloned());
    overrides
}

/// The scene, the overrides, the step and the averaging window [s].
fn print_header(scene: &Scene, args: &Args, overrides: &[String], window: (f64, f64)) {
    println!("scene: {}", scene.name);
    println!("overrides: pipe.hinge=\"ideal-cv\" {}", overrides.join(" "));
    println!(
        "step {} s, duration {} s, integrator {} (ballcage), forces averaged over [{}, {}] s",
        args.dt,
        args.duration,
        scene.simulation.integrator.name(),
        window.0,
        window.1
    );
}

/// ballcage's run: the window means (each link's tube normal force, then
/// the magnitude sum of its friction forces [N]), the wall time of its
/// `step` calls, the error that stopped it if any, and where it got to.
struct BallcageRun {
    mean: WindowMean,
    wall: Duration,
    error: Option<String>,
    time: f64,
    steps: u64,
}

/// Runs ballcage on `doc` to its end (or its first error), sampling the
/// tube forces in `window` [s].
fn run_ballcage(doc: &Document, window: (f64, f64)) -> BallcageRun {
    let tube = BallcageTubeForces::new(doc.scene());
    let mut sim = doc.simulation();
    let mut mean = WindowMean::new(window.0, window.1);
    let mut wall = Duration::ZERO;
    let mut error = None;
    while !sim.is_done() {
        let t0 = Instant::now();
        let r = sim.step();
        wall += t0.elapsed();
        if let Err(e) = r {
            error = Some(e.to_string());
            break;
        }
        if mean.wants(sim.time()) {
            let (normal, tangential) = tube.sample_with_friction(&mut sim);
            let mut s = normal;
            s.extend(tangential);
            mean.add(sim.time(), &s);
        }
    }
    BallcageRun {
        mean,
        wall,
        error,
        time: sim.time(),
        steps: sim.steps(),
    }
}

/// With `--ballcage-only`: ballcage's timing and its per-link forces.
fn print_ballcage_only(bc: &BallcageRun) {
    let bc_time = bc.time;
    if let Some(e) = &bc.error {
        println!("ballcage STOPPED at t = {bc_time:.4} s: {e}");
    }
    println!(
        "ballcage: {:.3} s wall for {bc_time:.3} s simulated, real-time factor {:.3}",
        bc.wall.as_secs_f64(),
        bc_time / bc.wall.as_secs_f64()
    );
    let b = bc.mean.means();
    let n = b.len() / 2;
    println!("| link | ballcage [N] | ballcage μ_eff |\n|---|---:|---:|");
    for k in 0..n {
        println!(
            "| link{:02} | {:.1} | {:.3} |",
            k + 1,
            b[k],
            b[n + k] / b[k]
        );
    }
    println!("| sum | {:.1} | |", b[..n].iter().sum::<f64>());
}

/// rapier's run: the world, its build time, the window means (each link's
/// tube normal force, then the magnitude of its resultant [N]) and the wall
/// time of its `step` calls.
struct RapierRun {
    chain: RapierChain,
    build: Duration,
    mean: WindowMean,
    wall: Duration,
}

/// Builds rapier's world of `scene` and runs it for the duration, sampling
/// the tube forces in `window` [s].
fn run_rapier(scene: &Scene, args: &Args, window: (f64, f64)) -> RapierRun {
    let t_build = Instant::now();
    let mut chain = RapierChain::from_scene(scene, &args.options).unwrap_or_else(|e| panic!("{e}"));
    let build = t_build.elapsed();
    let mut mean = WindowMean::new(window.0, window.1);
    let mut wall = Duration::ZERO;
    while chain.time() < args.duration - 1e-9 {
        let t0 = Instant::now();
        chain.step();
        wall += t0.elapsed();
        if mean.wants(chain.time()) {
            let mut s = chain.tube_normal_forces();
            s.extend(
                chain
                    .tube_force_resultants()
                    .iter()
                    .map(|f| (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt()),
            );
            mean.add(chain.time(), &s);
        }
    }
    RapierRun {
        chain,
        build,
        mean,
        wall,
    }
}

/// rapier's world: the mesh, its chord errors, μ, the bend limit, substeps.
fn print_rapier_world(scene: &Scene, args: &Args, ra: &RapierRun) {
    let chain = &ra.chain;
    let (r, big_r) = tube_size(scene);
    let (e_around, e_along) = args.options.mesh.chord_errors(r, big_r);
    println!(
        "rapier: {} triangles ({} around, one ring per {}° of arc; chord errors {:.3} mm around, {:.3} mm along), \
         μ = {:.3}, bend limit {:.2}°, {} substeps, world built in {:.3} s",
        chain.triangles(),
        args.options.mesh.around,
        args.options.mesh.arc_step_deg,
        e_around * 1e3,
        e_along * 1e3,
        chain.friction(),
        chain.bend_limit().unwrap_or(f64::NAN).to_degrees(),
        args.options.substeps,
        ra.build.as_secs_f64()
    );
}

/// Each engine's wall time, real-time factor and their ratio.
fn print_timing(bc: &BallcageRun, ra: &RapierRun) {
    let (bc_time, chain) = (bc.time, &ra.chain);
    if let Some(e) = &bc.error {
        println!("ballcage STOPPED at t = {bc_time:.4} s: {e}");
    }
    let rtf = |sim_t: f64, wall: Duration| sim_t / wall.as_secs_f64();
    let (bw, rw) = (bc.wall.as_secs_f64(), ra.wall.as_secs_f64());
    println!(
        "ballcage: {:>8.3} s wall for {:.3} s simulated ({} steps), real-time factor {:.3}",
        bw,
        bc_time,
        bc.steps,
        rtf(bc_time, bc.wall)
    );
    println!(
        "rapier:   {:>8.3} s wall for {:.3} s simulated ({} steps), real-time factor {:.3}",
        rw,
        chain.time(),
        chain.steps(),
        rtf(chain.time(), ra.wall)
    );
    let ratio = (bw / bc_time) / (rw / chain.time());
    println!(
        "ratio ballcage/rapier, wall time per simulated second: {ratio:.3} ({})",
        if ratio > 1.0 {
            format!("rapier {ratio:.2}x faster")
        } else {
            format!("ballcage {:.2}x faster", 1.0 / ratio)
        }
    );
}

/// The table of each link's mean tube normal force in both engines over
/// `window` [s].
fn print_forces(bc: &BallcageRun, ra: &RapierRun, window: (f64, f64)) {
    let names = ra.chain.link_names();
    let n = names.len();
    let (b, r) = (bc.mean.means(), ra.mean.means());
    if b.is_empty() || r.is_empty() {
        println!("no samples in the window");
        return;
    }
    println!(
        "\nmean tube normal force per link over [{}, {}] s ({} ballcage and {} rapier samples):",
        window.0,
        window.1,
        bc.mean.count(),
        ra.mean.count()
    );
    println!(
        "| link | ballcage [N] | rapier [N] | rapier/ballcage − 1 | rapier resultant [N] | ballcage μ_eff |"
    );
    println!("|---|---:|---:|---:|---:|---:|");
    let (mut sb, mut sr) = (0.0, 0.0);
    for k in 0..n {
        let mu = if b[k] > 0.0 {
            b[n + k] / b[k]
        } else {
            f64::NAN
        };
        println!(
            "| {} | {:.1} | {:.1} | {:+.1} % | {:.1} | {:.3} |",
            names[k],
            b[k],
            r[k],
            (r[k] / b[k] - 1.0) * 100.0,
            r[n + k],
            mu
        );
        sb += b[k];
        sr += r[k];
    }
    println!(
        "| sum | {:.1} | {:.1} | {:+.1} % | | {:.3} |",
        sb,
        sr,
        (sr / sb - 1.0) * 100.0,
        b[n..].iter().sum::<f64>() / sb
    );
}

/// The tube's inner radius and its tightest arc radius [m].
fn tube_size(scene: &Scene) -> (f64, f64) {
    use ballcage_core::scene::{ShapeSpec, TubeSegmentSpec};
    for b in &scene.bodies {
        if let ShapeSpec::Tube {
            inner_radius,
            segments,
            ..
        } = &b.shape
        {
            let big_r = segments
                .iter()
                .filter_map(|s| match s {
                    TubeSegmentSpec::Arc { radius, .. } => Some(*radius),
                    TubeSegmentSpec::Straight { .. } => None,
                })
                .fold(f64::INFINITY, f64::min);
            return (*inner_radius, big_r);
        }
    }
    (f64::NAN, f64::NAN)
}
