//! Whole-simulation benchmarks: small scenes, and the paper scene per step and per 0.1 s run.

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

/// The paper's scene with `hinge` and `integrator` (ball keys at the
/// scene's default step, ideal CV at 1 ms with SDIRK2 and 0.2 ms with the
/// linearly implicit Euler step), `solver` and `duration` [s].
fn paper_scene(hinge: &str, integrator: &str, solver: &str, duration: f64) -> (Document, f64) {
    let mut set = vec![
        format!("pipe.hinge=\"{hinge}\""),
        format!("simulation.integrator=\"{integrator}\""),
        "simulation.rtol=0".to_string(),
        format!("simulation.newton.linear_solver=\"{solver}\""),
        format!("simulation.duration={duration}"),
        "record.tables=[]".to_string(),
    ];
    if hinge == "ideal-cv" {
        // The linearly implicit Euler step keeps the 1e9 N/m hinge springs'
        // elastic part explicit: it diverges at 1 ms and runs at 0.2 ms.
        let dt = if integrator == "sdirk2" { 1e-3 } else { 2e-4 };
        set.push(format!("simulation.dt={dt}"));
    }
    let doc = Document::from_toml_str("kind = \"drill-pipe\"\n", &set).expect("valid paper scene");
    let dt = doc.scene().simulation.dt;
    (doc, dt)
}

const HINGES: [&str; 2] = ["ball-keys", "ideal-cv"];
const INTEGRATORS: [&str; 2] = ["linearly-implicit-euler", "sdirk2"];

/// The paper's drill pipe (12 joints; ball keys: 106 bodies, 519 pairs;
/// ideal CV: 15 bodies) for 0.1 s from rest, with each implicit integrator
/// and each linear solver: block elimination along the bodies' graph (the
/// default) against faer's general sparse LU.
fn paper_run(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper scene, 0.1 s from rest");
    g.sample_size(10);
    for hinge in HINGES {
        for integrator in INTEGRATORS {
            for solver in ["block-elimination", "sparse-lu"] {
                let (doc, dt) = paper_scene(hinge, integrator, solver, 0.1);
                g.bench_function(format!("{hinge}, {integrator} at {dt} s, {solver}"), |b| {
                    b.iter(|| {
                        let mut sim = doc.simulation();
                        sim.run().expect("stable");
                        sim.steps()
                    })
                });
            }
        }
    }
    g.finish();
}

/// One step of the same scenes in the loaded phase: each iteration steps
/// on from t = 0.5 s (the chain folded, the drive at speed and loaded).
fn paper_step(c: &mut Criterion) {
    let mut g = c.benchmark_group("paper scene, one step from t = 0.5 s");
    for hinge in HINGES {
        for integrator in INTEGRATORS {
            let (doc, dt) = paper_scene(hinge, integrator, "block-elimination", 100.0);
            let mut sim = doc.simulation();
            sim.advance_to(0.5).expect("stable warm-up");
            g.bench_function(format!("{hinge}, {integrator} at {dt} s"), |b| {
                b.iter(|| sim.step().expect("stable"))
            });
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

criterion_group!(benches, bench, paper_step, paper_run);
criterion_main!(benches);
