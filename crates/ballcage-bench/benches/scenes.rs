//! Whole-simulation benchmarks: integrator steps of small scenes.

use ballcage_core::{Document, Scene, Simulation};
use criterion::{Criterion, criterion_group, criterion_main};

const BALLS_ON_PLANE: &str = r#"
[simulation]
duration = 0.01
dt = 1e-5
output_interval = 1e-3
integrator = "rk4"
[world]
gravity = [0.0, 0.0, -9.81]
[record]
tables = []
[[bodies]]
name = "ground"
motion = "fixed"
shape = { type = "half-space", normal = [0.0, 0.0, 1.0] }
"#;

fn scene(n: usize) -> Scene {
    let mut toml = BALLS_ON_PLANE.to_string();
    for i in 0..n {
        toml += &format!(
            "[[bodies]]\nname = \"b{i}\"\nshape = {{ type = \"ball\", radius = 0.0075 }}\ndensity = 7850.0\nposition = [{x}, 0.0, 0.0075]\n[[contacts]]\nbodies = [\"ground\", \"b{i}\"]\nnormal = {{ law = \"impact\", stiffness = 1e5, exponent = 2.2, damping = 10.0, depth_max = 0.1, units = \"N-mm-s\" }}\nfriction = {{ law = \"adams\", mu_static = 0.1, mu_dynamic = 0.01, v_static = 100.0, v_dynamic = 1000.0, units = \"N-mm-s\" }}\n",
            x = 0.02 * i as f64
        );
    }
    Scene::from_toml_str(&toml, &[]).expect("valid bench scene")
}

/// The paper's drill pipe (12 joints; ball keys: 106 bodies, 519 pairs;
/// ideal CV: 15 bodies) for 20 ms from rest, with each implicit integrator
/// at its step and each linear solver: block elimination along the bodies'
/// graph (the default) against faer's general sparse LU.
fn paper(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper scene, first 20 ms");
    g.sample_size(10);
    for hinge in ["ball-keys", "ideal-cv"] {
        for (integrator, dt) in [("linearly-implicit-euler", 1e-4), ("sdirk2", 1e-4)] {
            for solver in ["block-elimination", "sparse-lu"] {
                let s = Document::from_toml_str(
                    "kind = \"drill-pipe\"\n",
                    &[
                        format!("pipe.hinge=\"{hinge}\""),
                        format!("simulation.integrator=\"{integrator}\""),
                        format!("simulation.dt={dt}"),
                        format!("simulation.newton.linear_solver=\"{solver}\""),
                        "simulation.duration=0.02".to_string(),
                        "record.tables=[]".to_string(),
                    ],
                )
                .expect("valid paper scene");
                g.bench_function(format!("{hinge}, {integrator} at {dt} s, {solver}"), |b| {
                    b.iter(|| {
                        let mut sim = s.simulation();
                        sim.run().expect("stable");
                        sim.steps()
                    })
                });
            }
        }
    }
    g.finish();
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("rk4 1000 steps, keys resting on a plane");
    g.sample_size(10);
    for n in [1usize, 78] {
        let s = scene(n);
        g.bench_function(format!("{n} keys"), |b| {
            b.iter(|| {
                let mut sim = Simulation::new(&s).expect("assembles");
                sim.run().expect("stable");
                sim.steps()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench, paper);
criterion_main!(benches);
