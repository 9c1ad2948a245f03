//! Runs the paper scene for a short time and prints stability and cost figures.
//! Usage: [PROBE_WARM=T] cargo run --release --example probe -- DT INTEGRATOR DURATION [KEY=VALUE ...]
//! (PROBE_WARM: run to T s first, then DURATION s inside `window`, for callgrind)
use ballcage_core::Document;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dt = args.get(1).map(|s| s.as_str()).unwrap_or("2e-7");
    let integ = args
        .get(2)
        .map(|s| s.as_str())
        .unwrap_or("symplectic-euler");
    let dur = args.get(3).map(|s| s.as_str()).unwrap_or("0.002");
    let overrides: Vec<String> = vec![
        format!("simulation.dt={dt}"),
        format!("simulation.integrator=\"{integ}\""),
        // Fixed steps of DT (the drill pipe's default is adaptive).
        "simulation.rtol=0".to_string(),
        "simulation.duration=100".to_string(),
        // Nothing recorded: 100 s of frames would pass the memory budget.
        "record.tables=[]".to_string(),
    ];
    let mut all = overrides.clone();
    all.extend(args.iter().skip(4).cloned());
    let doc =
        Document::from_toml_str("kind = \"drill-pipe\"\n", &all).unwrap_or_else(|e| panic!("{e}"));
    let scene = doc.scene();
    println!(
        "bodies {} contacts {}",
        scene.bodies.len(),
        scene.contacts.len()
    );
    let mut sim = doc.simulation();
    // PROBE_WARM=T: run to T first; the rest runs inside `window` (for
    // callgrind --toggle-collect=*window*).
    if let Ok(warm) = std::env::var("PROBE_WARM") {
        let warm: f64 = warm.parse().expect("PROBE_WARM in seconds");
        sim.advance_to(warm).expect("warm-up");
        println!("warm to {warm} s: steps {}", sim.steps());
    }
    window(&mut sim, dur.parse().unwrap());
}

#[inline(never)]
fn window(sim: &mut ballcage_core::Simulation, dur: f64) {
    let t_start = sim.time();
    let t0 = Instant::now();
    let st0 = sim.solver_stats();
    let ev0 = sim.force_evaluations();
    let steps0 = sim.steps();
    let mut k = 0;
    while k < 10 {
        k += 1;
        let r = sim.advance_to(t_start + dur * k as f64 / 10.0);
        let e = sim.energy();
        println!(
            "t={:.5} steps={} wall={:.2}s KE={:.4e} Ec={:.4e} {:?}",
            sim.time(),
            sim.steps(),
            t0.elapsed().as_secs_f64(),
            e.kinetic,
            e.potential_contact,
            r.err()
        );
        if sim.time() < t_start + dur * k as f64 / 10.0 - 1e-9 {
            break;
        }
    }
    let st = sim.solver_stats();
    println!(
        "window: steps {} force evaluations {} factorizations {} solves {} newton iterations {} halvings {} fallbacks {} wall {:.3} s",
        sim.steps() - steps0,
        sim.force_evaluations() - ev0,
        st.factorizations - st0.factorizations,
        st.solves - st0.solves,
        st.newton_iterations - st0.newton_iterations,
        st.halvings - st0.halvings,
        st.fallbacks - st0.fallbacks,
        t0.elapsed().as_secs_f64()
    );
}
