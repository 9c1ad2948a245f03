//! The contact pairs of a force evaluation may run on several threads
//! (`simulation.threads`); each pair is evaluated on its own and the forces
//! are summed in the pairs' order, so a run is bitwise identical for any
//! thread count: states, recorded tables and solver counts.

use ballcage_core::Document;

/// The paper scene (`overrides` on top) stepped `steps` times on `threads`
/// threads: the final state and the recorded tables, printed exactly
/// (`{:?}` of an f64 round-trips its bits, −0 included), and the solver
/// counts.
fn run(threads: u32, overrides: &[&str], steps: u32) -> (String, String, String) {
    let mut all = vec![
        "simulation.duration=1.0".to_string(),
        format!("simulation.threads={threads}"),
    ];
    all.extend(overrides.iter().map(|s| s.to_string()));
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &all).expect("valid scene");
    let mut sim = doc.simulation();
    assert_eq!(sim.threads(), threads as usize, "the pool was not built");
    for _ in 0..steps {
        sim.step().expect("stable");
    }
    let state = format!("{:?}", sim.state());
    let counts = format!(
        "{:?} {} {}",
        sim.solver_stats(),
        sim.force_evaluations(),
        sim.steps()
    );
    let rec = sim.finish();
    let tables = format!("{:?}", rec.tables);
    (state, tables, counts)
}

#[test]
fn two_threads_give_the_single_threaded_run_bit_for_bit() {
    for overrides in [
        &["simulation.output_interval=1e-3"][..],
        &["pipe.hinge=\"ideal-cv\"", "simulation.dt=1e-3"][..],
    ] {
        let steps = 60;
        let one = run(1, overrides, steps);
        let two = run(2, overrides, steps);
        // The run did something: the chain moved from its start.
        let start = run(1, overrides, 0);
        assert_ne!(one.0, start.0, "{overrides:?}: nothing moved");
        assert_eq!(one.2, two.2, "{overrides:?}: solver counts");
        assert!(one.0 == two.0, "{overrides:?}: final states differ");
        assert!(one.1 == two.1, "{overrides:?}: recorded tables differ");
    }
}
