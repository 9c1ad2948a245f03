//! After warm-up, a step allocates nothing: `allocation-counter` counts
//! every allocation made while the paper's scene steps (both hinge models;
//! the default adaptive ESDIRK3(2), and SDIRK2 and linearly implicit Euler
//! at fixed steps) with the default block-elimination solver.
//! (The `sparse-lu` solver allocates inside faer's numeric LU, about 20
//! times per step; it is there for comparison.)

use ballcage_core::Document;

/// Allocations during `steps` steps of the paper scene with `overrides`,
/// after 20 steps of warm-up (first factorization, contact buffers grown).
fn allocations(overrides: &[&str], steps: u32) -> u64 {
    let mut all = vec![
        "simulation.duration=1.0".to_string(),
        "record.tables=[]".to_string(),
    ];
    all.extend(overrides.iter().map(|s| s.to_string()));
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &all).expect("valid scene");
    let mut sim = doc.simulation();
    for _ in 0..20 {
        sim.step().expect("stable warm-up");
    }
    let info = allocation_counter::measure(|| {
        for _ in 0..steps {
            sim.step().expect("stable");
        }
    });
    info.count_total
}

#[test]
fn the_counter_sees_an_allocation() {
    let info = allocation_counter::measure(|| {
        std::hint::black_box(vec![1u8; 10]);
    });
    assert_eq!(info.count_total, 1);
}

#[test]
fn steps_after_warm_up_allocate_nothing() {
    for overrides in [
        &[][..],
        &["simulation.integrator=\"sdirk2\"", "simulation.rtol=0"][..],
        &[
            "simulation.integrator=\"linearly-implicit-euler\"",
            "simulation.rtol=0",
        ][..],
        &[
            "pipe.hinge=\"ideal-cv\"",
            "simulation.integrator=\"sdirk2\"",
            "simulation.rtol=0",
            "simulation.dt=1e-3",
        ][..],
    ] {
        assert_eq!(
            allocations(overrides, 30),
            0,
            "allocations with {overrides:?}"
        );
    }
}
