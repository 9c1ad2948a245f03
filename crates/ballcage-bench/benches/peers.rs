//! ballcage against a rapier3d-f64 baseline (issue 12): the paper's drill pipe
//! with the ideal-CV hinge, the same bodies, drive, load and gravity in both
//! engines (rapier's world is built from ballcage's scene, see
//! `ballcage_bench::rapier_chain`), stepped at the same step for the same
//! simulated time from rest:
//!
//! - dt = 1 ms for 0.1 s (100 steps);
//! - dt = 0.1 ms for 0.02 s (200 steps; rapier's mesh contacts make a longer
//!   window too slow for a bench).
//!
//! ballcage runs SDIRK2 at fixed steps (`paper_ideal_cv`; the default until
//! 2026-11-26, when it became adaptive ESDIRK3(2)); rapier its default solver
//! (4 substeps) against a 64 × 180 facet bore mesh, and again against the
//! exact tube (`Bore::Exact`: ballcage's `TubeInterior` through
//! `ballcage_shapes::ShapeDispatcher`, 5 samples per link; issue 16). Only
//! the stepping is timed, not building either world. Criterion reports each
//! time; after each pair the bench prints the ratio of the mean times it
//! measured.

use std::cell::Cell;
use std::hint::black_box;
use std::time::{Duration, Instant};

use ballcage_bench::rapier_chain::{Bore, RapierChain, RapierOptions, paper_ideal_cv};
use criterion::{Criterion, criterion_group, criterion_main};

/// Total time and iterations measured by one benchmark.
#[derive(Default)]
struct Tally {
    total: Cell<Duration>,
    iters: Cell<u64>,
}

impl Tally {
    fn add(&self, d: Duration, n: u64) {
        self.total.set(self.total.get() + d);
        self.iters.set(self.iters.get() + n);
    }

    fn mean(&self) -> f64 {
        self.total.get().as_secs_f64() / self.iters.get().max(1) as f64
    }
}

fn peers(c: &mut Criterion) {
    let mut g = c.benchmark_group("ideal-cv drill pipe from rest");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    g.measurement_time(Duration::from_secs(3));
    for (dt, duration) in [(1e-3, 0.1), (1e-4, 0.02)] {
        let doc = paper_ideal_cv(&[
            format!("simulation.dt={dt}"),
            format!("simulation.duration={duration}"),
        ])
        .expect("valid paper scene");
        let options = RapierOptions::default();
        let (ours, theirs) = (Tally::default(), Tally::default());
        g.bench_function(format!("ballcage, dt {dt} s, {duration} s"), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let mut sim = doc.simulation();
                    let t0 = Instant::now();
                    sim.run().expect("stable");
                    total += t0.elapsed();
                    black_box(sim.steps());
                }
                ours.add(total, iters);
                total
            })
        });
        g.bench_function(format!("rapier, dt {dt} s, {duration} s"), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let mut chain = RapierChain::from_scene(doc.scene(), &options).expect("builds");
                    let t0 = Instant::now();
                    chain.advance_to(duration);
                    total += t0.elapsed();
                    black_box(chain.tube_normal_forces());
                }
                theirs.add(total, iters);
                total
            })
        });
        let exact = RapierOptions {
            bore: Bore::Exact { samples: 5 },
            ..RapierOptions::default()
        };
        g.bench_function(format!("rapier exact bore, dt {dt} s, {duration} s"), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for _ in 0..iters {
                    let mut chain = RapierChain::from_scene(doc.scene(), &exact).expect("builds");
                    let t0 = Instant::now();
                    chain.advance_to(duration);
                    total += t0.elapsed();
                    black_box(chain.tube_normal_forces());
                }
                total
            })
        });
        println!(
            "ratio, dt {dt} s, {duration} s simulated: ballcage {:.4} s, rapier {:.4} s, \
             ballcage/rapier = {:.4} (rapier takes {:.1}x ballcage's time)",
            ours.mean(),
            theirs.mean(),
            ours.mean() / theirs.mean(),
            theirs.mean() / ours.mean()
        );
    }
    g.finish();
}

criterion_group!(benches, peers);
criterion_main!(benches);
