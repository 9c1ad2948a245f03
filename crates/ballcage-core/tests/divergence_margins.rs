//! Every run's metadata says how close it came to the limits of its
//! divergence checks (`simulation.divergence`): `ballcage.penetration_of_limit`,
//! the deepest penetration over its pair's limit (penetration_fraction ×
//! the pair's contact radius), with the pair and the time, and
//! `ballcage.energy_of_limit`, the most energy created over what the
//! energy check allows. Checked on a ball resting on a linear spring, where
//! the depth is m·g/k, and on a run the penetration check stops (a run the
//! energy check stops: `divergence.rs`).

mod common;

/// A 2 kg ball of radius 10 mm placed at rest `depth` [m] deep on a
/// linear contact spring of k [N/m], 0.2 s, with the given penetration
/// fraction; the run's metadata.
fn placed(k: f64, fraction: f64, depth: f64) -> Vec<(String, String)> {
    let r = 0.01;
    let mut sim = common::ball_on_floor(
        &format!(
            "duration = 0.2\ndt = 1e-4\noutput_interval = 1e-3\nintegrator = \"sdirk2\"\n\
             divergence = {{ penetration_fraction = {fraction} }}"
        ),
        9.81,
        &format!(
            "shape = {{ type = \"ball\", radius = {r} }}\nmass = 2.0\nposition = [0.0, 0.0, {z}]",
            z = r - depth
        ),
        &format!("normal = {{ law = \"linear\", stiffness = {k}, damping = 3000.0 }}"),
    );
    let _ = sim.run();
    sim.finish().metadata
}

/// [`placed`] at the depth m·g/k where the spring carries the ball.
fn resting(k: f64, fraction: f64) -> Vec<(String, String)> {
    placed(k, fraction, 2.0 * 9.81 / k)
}

fn value<'a>(meta: &'a [(String, String)], key: &str) -> &'a str {
    meta.iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
        .unwrap_or_else(|| panic!("no {key} in the metadata"))
}

fn number(meta: &[(String, String)], key: &str) -> f64 {
    value(meta, key).parse().expect("a number")
}

/// At rest at δ = m·g/k the deepest penetration is δ all along, so the
/// share of the limit is δ / (fraction · r): 1.962e-5 / (0.25 · 0.01) =
/// 7.848e-3 at k = 1e6 N/m, and it scales with 1/k and 1/fraction. The
/// resting ball creates no energy.
#[test]
fn a_resting_ball_reports_its_depth_over_the_limit() {
    let expect = |k: f64, fraction: f64| 2.0 * 9.81 / k / (fraction * 0.01);
    for (k, fraction) in [(1e6, 0.25), (1e5, 0.25), (1e6, 0.1)] {
        let meta = resting(k, fraction);
        let share = number(&meta, "ballcage.penetration_of_limit");
        assert!(
            (share / expect(k, fraction) - 1.0).abs() < 1e-3,
            "k {k}, fraction {fraction}: {share} against {}",
            expect(k, fraction)
        );
        assert_eq!(
            value(&meta, "ballcage.penetration_of_limit_pair"),
            "floor/ball"
        );
        let energy = number(&meta, "ballcage.energy_of_limit");
        assert!((0.0..1e-3).contains(&energy), "energy share {energy}");
    }
}

/// A run the penetration check stops reports the share that stopped it,
/// just above 1: the ball placed at rest 1 mm deep on a spring too soft to
/// hold it (m·g/k = 19.6 mm) sinks, at most m·g/c = 6.5 mm/s on its
/// damper, past the limit of 0.15 · 10 mm = 1.5 mm.
#[test]
fn a_run_stopped_by_the_penetration_check_reports_more_than_the_limit() {
    let meta = placed(1e3, 0.15, 1e-3);
    assert_eq!(value(&meta, "ballcage.complete"), "false");
    let share = number(&meta, "ballcage.penetration_of_limit");
    assert!(share > 1.0 && share < 1.1, "share {share}");
}
