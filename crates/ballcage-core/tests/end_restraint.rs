//! The chain's end restraint (issue 25, item 2): an axially free lower
//! connector (`pipe.lower_end = "axially-free"`) carrying `load.axial_force`,
//! against hand calculations (docs/paper.md, "The chain's end restraint").

use ballcage_core::Document;
use ballcage_core::math::Vec3;
use ballcage_core::model::Motion;

/// A straight, weightless chain of `joints` ideal-CV links with no torque,
/// its lower end free along the tube and pulled with `force` [N] (ramped
/// over 0.05 s), run for 0.15 s with SDIRK2 at 100 µs.
fn pulled_chain(joints: usize, force: f64, extra: &[&str]) -> Document {
    let mut o: Vec<String> = vec![
        "pipe.hinge=\"ideal-cv\"".into(),
        format!("pipe.joints={joints}"),
        "pipe.lower_end=\"axially-free\"".into(),
        format!("load.axial_force={force}"),
        "load.resisting_moment=0".into(),
        "load.ramp=0.05".into(),
        // R = 100 km: the chain's chords bend 2e-6 rad, so it is straight to 1e-12 m
        "borehole.curvature_radius=1e5".into(),
        "drive.speed_rpm=0".into(),
        "world.gravity=0".into(),
        "simulation.duration=0.15".into(),
        "simulation.output_interval=0.01".into(),
        // The balance sums the work every fixed step of 100 µs.
        "simulation.integrator=\"sdirk2\"".into(),
        "simulation.rtol=0".into(),
        "record.tables=[\"drive\"]".into(),
    ];
    o.extend(extra.iter().map(|s| s.to_string()));
    Document::from_toml_str("kind = \"drill-pipe\"\n", &o).unwrap_or_else(|e| panic!("{e}"))
}

/// Pulled with F, the ideal-CV chain's n + 1 hinge springs (stiffness k, in
/// series) stretch by F/k each, so the free lower connector moves (n + 1)·F/k
/// along the tube's end tangent, and at rest the hinge's axial force on it
/// balances F (the chain's force balance along the axis). With F = ±2 kN,
/// k = 1e9 N/m and three links: 8 µm. Tolerance 0.5 % on the displacement
/// (a hinge missing from the series, or the force doubled or lost, is off by
/// 25 % or more) and 1e-3 relative on the reaction. Tension moves the
/// connector downhole (+), compression uphole (−): the sign convention of
/// `load.axial_force`.
#[test]
fn a_pulled_chain_stretches_its_hinge_springs_in_series_and_its_end_carries_the_force() {
    let (n, k) = (3usize, 1e9);
    for force in [2000.0, -2000.0] {
        let doc = pulled_chain(n, force, &[]);
        let lower = *doc.drill_pipe_parts().unwrap().1.chain.last().unwrap();
        let mut sim = doc.simulation();
        let Motion::Spin {
            axis, slides: true, ..
        } = sim.model().bodies[lower].motion
        else {
            panic!("the axially free lower connector is a sliding spin body")
        };
        let start = sim.state().pos[lower];
        sim.run().unwrap();
        let (model, state) = (sim.model(), sim.state());
        let moved = (state.pos[lower] - start).dot(&axis);
        let expected = (n + 1) as f64 * force / k;
        assert!(
            ((moved - expected) / expected).abs() < 5e-3,
            "F = {force} N: the lower connector moved {moved:e} m along the axis, \
             the hinge springs in series give {expected:e} m"
        );
        let off_axis = (state.pos[lower] - start) - axis * moved;
        assert!(
            off_axis.norm() < 1e-12,
            "F = {force} N: the connector left its axis by {:e} m",
            off_axis.norm()
        );
        // The joints' force on the lower connector along the axis: −F at rest.
        let reaction: f64 = model
            .joints
            .iter()
            .filter(|j| j.b == lower || j.a == lower)
            .map(|j| {
                let (w, _, _) = j.evaluate(state);
                let sign = if j.b == lower { 1.0 } else { -1.0 };
                sign * w.force.dot(&axis)
            })
            .sum();
        assert!(
            ((reaction + force) / force).abs() < 1e-3,
            "F = {force} N: the hinge pulls the connector with {reaction} N along the axis"
        );
        assert!(
            state.vel[lower].norm() < 1e-4,
            "F = {force} N: the connector still moves at {:e} m/s",
            state.vel[lower].norm()
        );
    }
}

/// The same run with the fixed (paper's) lower end does not move the
/// connector at all, and at zero force the free end stays where it was
/// placed: the option changes nothing until a force or a torque asks it to.
#[test]
fn with_no_force_the_free_end_stays_and_the_fixed_end_never_moves() {
    let doc = pulled_chain(3, 0.0, &[]);
    let lower = *doc.drill_pipe_parts().unwrap().1.chain.last().unwrap();
    let mut sim = doc.simulation();
    let start = sim.state().pos[lower];
    sim.run().unwrap();
    let moved = (sim.state().pos[lower] - start).norm();
    assert!(moved < 1e-12, "free end at 0 N moved {moved:e} m");

    let doc = pulled_chain(3, 0.0, &["pipe.lower_end=\"fixed\""]);
    let lower = *doc.drill_pipe_parts().unwrap().1.chain.last().unwrap();
    let mut sim = doc.simulation();
    assert!(matches!(
        sim.model().bodies[lower].motion,
        Motion::Spin { slides: false, .. }
    ));
    assert!(
        sim.model().forces.is_empty(),
        "a fixed end carries no force load"
    );
    let start = sim.state().pos[lower];
    sim.run().unwrap();
    assert_eq!(sim.state().pos[lower], start);
}

/// The energy table books the axial force's work as load work: pulled with
/// F through the displacement d, the chain stores k·Σ(F/k)²/2 = F·d/2 in its
/// springs and the rest is damped; the balance closes.
#[test]
fn the_axial_force_does_work_that_the_energy_balance_counts() {
    let force = 2000.0;
    let doc = pulled_chain(3, force, &["record.tables=[\"energy\"]"]);
    let mut sim = doc.simulation();
    sim.run().unwrap();
    let rec = sim.finish();
    let t = rec
        .tables
        .iter()
        .find(|t| t.def.name == "energy")
        .expect("energy recorded");
    let column = |name: &str| match t.column(name).expect("column") {
        ballcage_core::record::ColumnData::F64(v) => *v.last().expect("rows"),
        other => panic!("{name}: {other:?}"),
    };
    // F·d with d = 4F/k = 8 µm: 16 mJ; the ramp applies it while the ends move.
    let load = column("load_work");
    let expected_max = force * 4.0 * force / 1e9;
    assert!(
        load > 0.2 * expected_max && load < 1.01 * expected_max,
        "load work {load} J, F·d = {expected_max} J"
    );
    let error = column("balance_error").abs();
    assert!(
        error < 1e-3 * load,
        "balance error {error} J against the load work {load} J"
    );
}

/// The option's errors name the field, its value and the reason.
#[test]
fn an_axial_force_on_a_fixed_end_or_not_finite_is_refused_by_name() {
    let e = Document::from_toml_str(
        "kind = \"drill-pipe\"\n",
        &["load.axial_force=1000".to_string()],
    )
    .expect_err("a force on the fixed end is refused");
    let text = e.to_string();
    assert!(
        text.contains("load.axial_force") && text.contains("1000") && text.contains("axially-free"),
        "{text}"
    );
    let e = Document::from_toml_str(
        "kind = \"drill-pipe\"\n",
        &["pipe.lower_end=\"sliding\"".to_string()],
    )
    .expect_err("an unknown restraint is refused");
    assert!(e.to_string().contains("lower_end"), "{e}");
    let doc = Document::from_toml_str(
        "kind = \"drill-pipe\"\n",
        &["pipe.lower_end=\"axially-free\"".to_string()],
    )
    .expect("the free end at the default 0 N");
    let sim = doc.simulation();
    let f = sim.model().forces.first().expect("one force load");
    assert_eq!(f.magnitude, 0.0);
    assert!(
        (f.axis - Vec3::x()).norm() < 1e-9,
        "along the end tangent +x: {}",
        f.axis
    );
}
