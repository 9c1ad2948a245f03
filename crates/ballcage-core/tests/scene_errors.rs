//! Bad scenes are rejected with an error that names the field, the value and
//! the reason; overrides address fields by dotted path.

use ballcage_core::{Scene, SceneError, Simulation};

const GOOD: &str = r#"
[simulation]
duration = 0.01
dt = 1e-4
output_interval = 1e-3
[[bodies]]
name = "ground"
motion = "fixed"
shape = { type = "half-space", normal = [0.0, 0.0, 1.0] }
[[bodies]]
name = "ball"
shape = { type = "ball", radius = 0.05 }
mass = 1.0
position = [0.0, 0.0, 0.05]
[[contacts]]
bodies = ["ground", "ball"]
normal = { law = "hertz", stiffness = 1e8 }
"#;

/// The error of reading, validating or assembling the scene (a geometry
/// that does not fit the bodies' shapes is found at assembly).
fn error_of(toml: &str, overrides: &[&str]) -> SceneError {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    match Scene::from_toml_str(toml, &o).and_then(|s| Simulation::new(&s)) {
        Ok(_) => panic!("scene was accepted"),
        Err(e) => e,
    }
}

#[test]
fn the_reference_scene_is_valid() {
    let scene = Scene::from_toml_str(GOOD, &[]).unwrap();
    Simulation::new(&scene).unwrap();
}

#[test]
fn missing_field_is_named() {
    let e = error_of(&GOOD.replace("dt = 1e-4\n", ""), &[]);
    assert_eq!(e.path, "simulation.dt");
    assert!(e.reason.contains("missing field `dt`"), "{e}");
}

#[test]
fn an_override_takes_the_path_an_error_prints() {
    // `--set` accepts `bodies[1].mass`, the path errors name, as well as `bodies.1.mass`.
    let e = error_of(GOOD, &["bodies[1].mass=-2"]);
    assert_eq!(e.path, "bodies[1].mass");
    assert_eq!(e.value, "-2");
    let e = error_of(GOOD, &["bodies[7].mass=2"]);
    assert_eq!(e.path, "bodies.7");
    assert!(e.reason.contains("index out of range"), "{e}");
}

#[test]
fn negative_mass_is_named_with_its_value() {
    let e = error_of(GOOD, &["bodies.1.mass=-2"]);
    assert_eq!(e.path, "bodies[1].mass");
    assert_eq!(e.value, "-2");
    assert!(e.reason.contains("positive"), "{e}");
    assert_eq!(
        e.to_string(),
        "scene field `bodies[1].mass` = -2: must be positive"
    );
}

#[test]
fn unknown_contact_law_is_named() {
    let e = error_of(&GOOD.replace("law = \"hertz\"", "law = \"hookean\""), &[]);
    assert!(e.path.starts_with("contacts[0].normal"), "{e}");
    assert!(e.reason.contains("hookean"), "{e}");
}

#[test]
fn nan_is_rejected_where_it_is_written() {
    let e = error_of(&GOOD.replace("radius = 0.05", "radius = nan"), &[]);
    assert_eq!(e.path, "bodies[1].shape.radius");
    assert!(e.reason.contains("finite"), "{e}");
    let e = error_of(GOOD, &["world.gravity=[0.0, nan, -9.8]"]);
    assert_eq!(e.path, "world.gravity[1]");
}

#[test]
fn unknown_fields_are_typos_not_silently_ignored() {
    let e = error_of(&GOOD.replace("mass = 1.0", "mas = 1.0"), &[]);
    assert!(e.path.starts_with("bodies[1]"), "{e}");
    assert!(e.reason.contains("mas"), "{e}");
}

#[test]
fn references_to_missing_bodies_and_unsupported_pairs_are_named() {
    let e = error_of(
        &GOOD.replace(
            "bodies = [\"ground\", \"ball\"]",
            "bodies = [\"ground\", \"bal\"]",
        ),
        &[],
    );
    assert_eq!(e.path, "contacts[0].bodies[1]");
    let e = error_of(
        GOOD,
        &["bodies.1.shape={ type = \"cylinder\", radius = 0.1, half_length = 0.2 }"],
    );
    assert_eq!(e.path, "contacts[0].bodies");
    assert!(
        e.reason.contains("half-space–cylinder") || e.reason.contains("no contact geometry"),
        "{e}"
    );
}

#[test]
fn output_interval_must_be_a_whole_number_of_steps() {
    let e = error_of(GOOD, &["simulation.output_interval=1.5e-4"]);
    assert_eq!(e.path, "simulation.output_interval");
}

#[test]
fn overrides_set_nested_and_indexed_fields() {
    let s = Scene::from_toml_str(
        GOOD,
        &[
            "simulation.integrator=symplectic-euler".into(),
            "bodies.1.position.2=0.2".into(),
        ],
    )
    .unwrap();
    assert_eq!(s.simulation.integrator.name(), "symplectic-euler");
    assert_eq!(s.bodies[1].position[2], 0.2);
    let e = error_of(GOOD, &["bodies.7.mass=1"]);
    assert_eq!(e.path, "bodies.7");
    let e = error_of(GOOD, &["simulation.dt"]);
    assert!(e.reason.contains("key=value"), "{e}");
}

#[test]
fn resolved_scene_round_trips_through_toml() {
    let s = Scene::from_toml_str(GOOD, &[]).unwrap();
    let again = Scene::from_toml_str(&s.to_toml(), &[]).unwrap();
    assert_eq!(s, again);
}

#[test]
fn a_wrong_type_is_named_in_words_not_rust_types() {
    let e = error_of(GOOD, &["simulation.duration=\"abc\""]);
    assert_eq!(e.path, "simulation.duration");
    assert!(e.reason.contains("expected a number"), "{e}");
    assert!(!e.reason.contains("f64"), "{e}");
}
