//! Runs the paper scene for a short time and prints stability and cost figures.
//! Usage: cargo run --release --example probe -- DT INTEGRATOR DURATION
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
        format!("simulation.duration={dur}"),
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
    let t0 = Instant::now();
    let dur: f64 = dur.parse().unwrap();
    let mut k = 0;
    while !sim.is_done() {
        k += 1;
        let r = sim.advance_to(dur * k as f64 / 10.0);
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
        if sim.time() < dur * k as f64 / 10.0 - 1e-9 {
            break;
        }
    }
    let st = sim.solver_stats();
    println!(
        "force evaluations {} factorizations {} solves {} newton iterations {} halvings {}",
        sim.force_evaluations(),
        st.factorizations,
        st.solves,
        st.newton_iterations,
        st.halvings
    );
}
