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

#[test]
fn every_unknown_key_and_wrong_type_is_listed_in_one_error() {
    let e = error_of(
        GOOD,
        &[
            "simulation.duraton=1",
            "bodies[1].mas=2",
            "bodies[1].position=\"up\"",
        ],
    );
    let mut paths: Vec<&str> = e.each().map(|x| x.path.as_str()).collect();
    paths.sort_unstable();
    assert_eq!(
        paths,
        ["bodies[1].mas", "bodies[1].position", "simulation.duraton"],
        "{e}"
    );
    let mas = e.each().find(|x| x.path == "bodies[1].mas").unwrap();
    assert!(mas.reason.ends_with("did you mean `mass`?"), "{e}");
    // one message, every error in it, separated by "; "
    assert_eq!(e.to_string().matches("scene field `").count(), 3, "{e}");
}

#[test]
fn a_key_taken_out_after_its_own_error_is_not_reported_missing_as_well() {
    // `dt` is required: its wrong type is one error, not also "missing field `dt`"
    let e = error_of(GOOD, &["simulation.dt=\"fast\""]);
    assert_eq!(e.path, "simulation.dt");
    assert!(e.more.is_empty(), "{e}");
}

#[test]
fn range_errors_of_independent_bodies_and_sections_are_all_listed() {
    let e = error_of(
        GOOD,
        &[
            "bodies[1].mass=-2",
            "world.gravity=[0.0, 0.0, nan]",
            "simulation.duration=-1",
        ],
    );
    let mut paths: Vec<&str> = e.each().map(|x| x.path.as_str()).collect();
    paths.sort_unstable();
    assert_eq!(
        paths,
        ["bodies[1].mass", "simulation.duration", "world.gravity[2]"],
        "{e}"
    );
}

#[test]
fn a_drill_pipe_lists_the_errors_of_its_independent_sections() {
    use ballcage_core::loader::Document;
    let text = ballcage_core::loader::default_document().to_toml();
    let overrides: Vec<String> = [
        "drive.ramp=-1",
        "load.resisting_moment=nan",
        "pipe.joints=0",
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    let e = match Document::from_toml_str(&text, &overrides) {
        Ok(_) => panic!("scene was accepted"),
        Err(e) => e,
    };
    let mut paths: Vec<&str> = e.each().map(|x| x.path.as_str()).collect();
    paths.sort_unstable();
    assert_eq!(
        paths,
        ["drive.ramp", "load.resisting_moment", "pipe.joints"],
        "{e}"
    );
}

/// The drill-pipe error of the default document with `overrides`.
fn pipe_error_of(overrides: &[&str]) -> SceneError {
    let text = ballcage_core::loader::default_document().to_toml();
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    match ballcage_core::loader::Document::from_toml_str(&text, &o) {
        Ok(_) => panic!("scene was accepted"),
        Err(e) => e,
    }
}

#[test]
fn a_summary_window_past_the_run_is_refused() {
    // GOOD runs 0.01 s: a window ending at 0.01 s is the whole run, 0.02 s reaches past it
    assert!(Scene::from_toml_str(GOOD, &["record.summary_window=[0.0, 0.01]".into()]).is_ok());
    let e = error_of(GOOD, &["record.summary_window=[0.0, 0.02]"]);
    assert_eq!(e.path, "record.summary_window[1]");
    assert!(e.reason.contains("simulation.duration = 0.01 s"), "{e}");
}

#[test]
fn dynamic_friction_above_static_friction_is_refused() {
    // the paper's tube friction: mu_static 0.3; 0.3 is allowed, 0.31 is not
    let text = ballcage_core::loader::default_document().to_toml();
    let ok: Vec<String> = vec!["materials.tube.friction.mu_dynamic=0.3".into()];
    assert!(ballcage_core::loader::Document::from_toml_str(&text, &ok).is_ok());
    let e = pipe_error_of(&["materials.tube.friction.mu_dynamic=0.31"]);
    assert!(e.path.ends_with("friction.mu_dynamic"), "{e}");
    assert!(e.reason.contains("mu_static = 0.3"), "{e}");
}

#[test]
fn a_race_contact_angle_of_90_degrees_or_more_is_refused() {
    let e = pipe_error_of(&["pipe.ball_keys.contact_angle_deg=90"]);
    assert_eq!(e.path, "pipe.ball_keys.contact_angle_deg");
    let text = ballcage_core::loader::default_document().to_toml();
    let ok: Vec<String> = vec!["pipe.ball_keys.contact_angle_deg=60".into()];
    assert!(ballcage_core::loader::Document::from_toml_str(&text, &ok).is_ok());
}

#[test]
fn a_run_of_more_steps_than_max_steps_is_refused_with_the_count() {
    // 0.01 s at 1e-4 s is 100 steps: a limit of 100 runs, 99 does not
    assert!(Scene::from_toml_str(GOOD, &["simulation.max_steps=100".into()]).is_ok());
    let e = error_of(GOOD, &["simulation.max_steps=99"]);
    assert_eq!(e.path, "simulation.dt");
    assert!(e.reason.starts_with("1.000e2 steps"), "{e}");
    // the issue's example: a 1 ns step for an hour, 3.6e12 steps against the default 1e8
    let e = error_of(
        GOOD,
        &[
            "simulation.dt=1e-9",
            "simulation.duration=3600",
            "simulation.output_interval=1.0",
        ],
    );
    assert!(e.reason.starts_with("3.600e12 steps"), "{e}");
    assert!(e.reason.contains("simulation.max_steps = 1.000e8"), "{e}");
}

#[test]
fn a_ball_too_small_for_its_mass_properties_is_refused_not_nan() {
    // fuzz/regressions/ball-radius-underflow-nan-inertia.toml: r³·4π/3 underflows to 0 at r = 1e-200 m,
    // so the inertia m·i₁/m₁ would be 0/0
    let e = error_of(GOOD, &["bodies[1].shape.radius=1e-200"]);
    assert_eq!(e.path, "bodies[1].inertia", "{e}");
    assert!(Scene::from_toml_str(GOOD, &["bodies[1].shape.radius=1e-3".into()]).is_ok());
}

#[test]
fn a_spin_speed_on_a_body_that_does_not_spin_is_refused() {
    // fuzz/regressions/dynamic-body-nan-spin-speed.toml
    let e = error_of(GOOD, &["bodies[1].spin_speed=nan"]);
    assert_eq!(e.path, "bodies[1].spin_speed", "{e}");
    let e = error_of(GOOD, &["bodies[1].spin_ramp=-inf"]);
    assert_eq!(e.path, "bodies[1].spin_ramp", "{e}");
}

#[test]
fn a_start_whose_energy_overflows_is_refused_naming_the_body() {
    // fuzz/regressions/huge-velocity-infinite-kinetic-energy.toml: ½·m·v² overflows above ~1.3e154 m/s
    let e = error_of(GOOD, &["bodies[1].velocity=[1e200, 0.0, 0.0]"]);
    assert!(e.reason.contains("body `ball`"), "{e}");
    assert!(e.reason.contains("kinetic inf J"), "{e}");
    assert!(Scene::from_toml_str(GOOD, &["bodies[1].velocity=[1e3, 0.0, 0.0]".into()]).is_ok());
}

#[test]
fn a_cage_inertia_and_a_pitch_radius_outside_the_cage_are_refused() {
    // fuzz/regressions/ideal-cv-nan-cage-inertia.toml and summary-rms-overflow.toml
    let e = pipe_error_of(&[
        "pipe.hinge=\"ideal-cv\"",
        "pipe.ball_keys.cage_inertia[1]=nan",
    ]);
    assert_eq!(e.path, "pipe.ball_keys.cage_inertia[1]", "{e}");
    let e = pipe_error_of(&["pipe.ball_keys.pitch_radius=3.15e98"]);
    assert_eq!(e.path, "pipe.ball_keys.pitch_radius", "{e}");
    // the paper's keys sit at 31.5 mm, in the 31-32 mm cage wall; 40 mm is beyond 32 + 7.5 mm
    let e = pipe_error_of(&["pipe.ball_keys.pitch_radius=0.040"]);
    assert_eq!(e.path, "pipe.ball_keys.pitch_radius", "{e}");
}

#[test]
fn thousands_of_threads_are_refused() {
    // found by fuzzing: simulation.threads = 5000 started a 5000-thread pool per run
    assert!(Scene::from_toml_str(GOOD, &["simulation.threads=256".into()]).is_ok());
    let e = error_of(GOOD, &["simulation.threads=5000"]);
    assert_eq!(e.path, "simulation.threads", "{e}");
}

#[test]
fn a_curvature_radius_beyond_100_km_is_refused() {
    // fuzz/regressions/huge-curvature-radius-infinite-depth.toml: 1e308 m overflowed the tube's geometry
    let e = pipe_error_of(&["borehole.curvature_radius=1e308"]);
    assert_eq!(e.path, "borehole.curvature_radius", "{e}");
    let e = pipe_error_of(&["borehole.curvature_radius=1.1e5"]);
    assert_eq!(e.path, "borehole.curvature_radius", "{e}");
}

#[test]
fn a_start_with_an_overlap_whose_energy_overflows_names_the_pair() {
    // fuzz/regressions/huge-overlap-infinite-contact-energy.toml: a 1e200 m ball sunk into the ground
    let e = error_of(
        GOOD,
        &[
            "bodies[1].shape.radius=1e200",
            "bodies[1].inertia=[1.0, 1.0, 1.0]",
        ],
    );
    assert!(e.reason.contains("the overlap of contact pair `"), "{e}");
}

#[test]
fn a_hardness_below_1_mpa_and_a_wear_coefficient_above_1_are_refused() {
    // fuzz/regressions/tiny-hardness-nan-wear.toml: 3e-319 Pa made the wear NaN.
    let text = ballcage_core::loader::default_document().to_toml();
    let ok: Vec<String> = vec![
        "materials.pipe_steel.hardness=1e6".into(),
        "wear.tube_coefficient=1".into(),
    ];
    assert!(ballcage_core::loader::Document::from_toml_str(&text, &ok).is_ok());
    let e = pipe_error_of(&["materials.pipe_steel.hardness=3.22986e-319"]);
    assert_eq!(e.path, "materials.pipe_steel.hardness");
    assert!(e.reason.contains("at least 1e6 Pa"), "{e}");
    let e = pipe_error_of(&["wear.tube_coefficient=1.5"]);
    assert_eq!(e.path, "wear.tube_coefficient");
    assert!(e.reason.contains("must not exceed 1"), "{e}");
}

#[test]
fn the_adaptive_steps_settings_are_checked_by_name() {
    // The paper scene is adaptive (rtol 1e-4): a largest step must be positive (it need not
    // divide the output interval: frames within a step are interpolated); rtol = 0 gives fixed
    // steps, with which max_step and atol have no meaning, and dt must divide the interval.
    let e = pipe_error_of(&["simulation.max_step=-1"]);
    assert_eq!(e.path, "simulation.max_step");
    assert!(e.reason.contains("positive"), "{}", e.reason);
    let e = pipe_error_of(&["simulation.rtol=0", "simulation.dt=3e-4"]);
    assert_eq!(e.path, "simulation.output_interval");
    assert!(e.reason.contains("simulation.dt"), "{}", e.reason);
    for key in ["simulation.max_step=1e-3", "simulation.atol=1e-6"] {
        let e = pipe_error_of(&["simulation.rtol=0", key]);
        assert_eq!(e.path, key.split('=').next().unwrap());
        assert!(
            e.reason.contains("positive simulation.rtol"),
            "{}",
            e.reason
        );
    }
    let e = pipe_error_of(&["simulation.rtol=-1e-4"]);
    assert_eq!(e.path, "simulation.rtol");
    let e = pipe_error_of(&["simulation.integrator=\"sdirk2\""]);
    assert_eq!(e.path, "simulation.rtol");
    assert!(e.reason.contains("set simulation.rtol = 0"), "{}", e.reason);
    // Fixed steps of dt with rtol = 0 load, and so do largest steps that do or do not divide
    // the interval.
    for ok in [
        &["simulation.integrator=\"sdirk2\"", "simulation.rtol=0"][..],
        &["simulation.max_step=5e-4"][..],
        &["simulation.max_step=3e-4"][..],
        &["simulation.max_step=2.5e-3"][..],
    ] {
        let overrides: Vec<String> = ok.iter().map(|s| s.to_string()).collect();
        let doc =
            ballcage_core::loader::Document::from_toml_str("kind = \"drill-pipe\"\n", &overrides);
        assert!(doc.is_ok(), "{ok:?}: {:?}", doc.err());
    }
}
