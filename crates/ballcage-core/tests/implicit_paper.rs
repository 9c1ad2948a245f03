//! The linearly implicit Euler step on the paper's drill-pipe scene, against
//! symplectic Euler at 0.2 µs (its stable step) as the reference. Slow: run
//! with `cargo test --release --test implicit_paper -- --ignored --nocapture`.

use ballcage_core::{Scene, Simulation};

/// Runs the default drill-pipe scene for `duration` and returns, per contact
/// pair, the summed normal and tangential force magnitudes at the end [N].
fn run(integrator: &str, dt: f64, duration: f64) -> (Simulation, Vec<(f64, f64)>) {
    let overrides = [
        format!("simulation.dt={dt}"),
        format!("simulation.integrator=\"{integrator}\""),
        format!("simulation.duration={duration}"),
        "record.tables=[]".into(),
    ];
    let scene = Scene::from_toml_str("kind = \"drill-pipe\"\n", &overrides).unwrap();
    let mut sim = Simulation::new(&scene).unwrap();
    let start = std::time::Instant::now();
    sim.run().unwrap();
    let wall = start.elapsed().as_secs_f64();
    eprintln!(
        "{integrator} dt = {dt:e}: {} steps, {:.2} s wall, {:.1} s per simulated second, {} linear solves",
        sim.steps(),
        wall,
        wall / duration,
        sim.linear_solves()
    );
    let forces = (0..sim.model().pairs.len())
        .map(|k| {
            sim.pair_contacts(k).iter().fold((0.0, 0.0), |(n, t), p| {
                (n + p.normal_force, t + p.tangential_force.norm())
            })
        })
        .collect();
    (sim, forces)
}

#[test]
#[ignore = "slow: about 20 s in release"]
fn paper_scene_matches_the_fine_explicit_reference() {
    let duration = 0.05;
    let (reference, f_ref) = run("symplectic-euler", 2e-7, duration);
    for dt in [1e-5, 2e-5] {
        let (sim, f) = run("linearly-implicit-euler", dt, duration);
        // Per group of pairs: largest and summed normal force, and the
        // largest error of a pair against the reference.
        for group in ["/tube", ".cage/", ".key", ".stop"] {
            let mut sum = (0.0, 0.0);
            let mut tangential = (0.0, 0.0);
            let mut worst: (f64, String) = (0.0, String::new());
            let mut peak: f64 = 0.0;
            for (k, pair) in reference.model().pairs.iter().enumerate() {
                if !pair.name.contains(group) {
                    continue;
                }
                sum.0 += f_ref[k].0;
                sum.1 += f[k].0;
                tangential.0 += f_ref[k].1;
                tangential.1 += f[k].1;
                peak = peak.max(f_ref[k].0);
                let err = (f[k].0 - f_ref[k].0).abs();
                if err > worst.0 {
                    worst = (err, pair.name.clone());
                }
            }
            eprintln!(
                "  dt = {dt:e} {group:>6}: ΣF_n {:.1} N (reference {:.1} N), ΣF_t {:.2} N \
                 (reference {:.2} N), peak F_n {peak:.1} N, worst pair F_n error {:.2} N at {}",
                sum.1, sum.0, tangential.1, tangential.0, worst.0, worst.1
            );
        }
        // The links' poses.
        let mut worst_pos: f64 = 0.0;
        let mut worst_vel: f64 = 0.0;
        for &i in &reference.model().integrated {
            worst_pos = worst_pos.max((sim.state().pos[i] - reference.state().pos[i]).norm());
            worst_vel = worst_vel.max((sim.state().vel[i] - reference.state().vel[i]).norm());
        }
        eprintln!(
            "  dt = {dt:e}: largest position difference {worst_pos:.3e} m, velocity {worst_vel:.3e} m/s"
        );
        let total = |f: &[(f64, f64)]| f.iter().map(|x| x.0).sum::<f64>();
        assert!(
            (total(&f) - total(&f_ref)).abs() < 0.02 * total(&f_ref),
            "total normal force {} vs {}",
            total(&f),
            total(&f_ref)
        );
    }
}
