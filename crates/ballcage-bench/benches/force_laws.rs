//! Micro-benchmarks of the force laws over 128 seeded inputs.

use std::hint::black_box;

use ballcage_core::force::{
    AdamsFrictionParams, ImpactParams, adams_friction_coefficient, friction_force,
    impact_normal_force,
};
use criterion::{Criterion, criterion_group, criterion_main};

/// Deterministic inputs (a 64-bit LCG, seed 0).
fn inputs(n: usize) -> Vec<(f64, f64, [f64; 3])> {
    let mut x: u64 = 0;
    let mut next = || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| {
            (
                next() * 6e-4,
                (next() - 0.5) * 0.2,
                [next() - 0.5, next() - 0.5, 0.0],
            )
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let impact = ImpactParams {
        stiffness: 1e5 * 1000f64.powf(2.2),
        exponent: 2.2,
        damping: 1e4,
        depth_max: 1e-4,
    };
    let adams = AdamsFrictionParams {
        mu_static: 0.3,
        mu_dynamic: 0.1,
        v_static: 0.1,
        v_dynamic: 1.0,
    };
    let data = inputs(128);
    c.bench_function("impact_normal_force x128", |b| {
        b.iter(|| {
            data.iter()
                .map(|(d, r, _)| impact_normal_force(black_box(*d), black_box(*r), &impact).force)
                .sum::<f64>()
        })
    });
    c.bench_function("adams friction_force x128", |b| {
        b.iter(|| {
            data.iter()
                .map(|(_, _, v)| {
                    friction_force(black_box(*v), 600.0, |s| {
                        adams_friction_coefficient(s, &adams)
                    })
                    .0[0]
                })
                .sum::<f64>()
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
