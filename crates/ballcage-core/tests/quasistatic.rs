//! The static equilibrium solve (`dynamics::quasistatic::equilibrium`, the
//! local solve of issue 28's quasi-static hinge) against closed forms; the
//! ball-key hinge itself is in `hinge_closed_forms.rs`.

mod common;

use ballcage_core::dynamics::Dynamics;
use ballcage_core::dynamics::quasistatic::{StaticDofs, StaticTolerance, equilibrium};

/// The paper's IMPACT law for the ball keys, as a contact's `normal` key.
const PAPER_IMPACT: &str = "normal = { law = \"impact\", stiffness = 1e5, exponent = 2.2, \
     damping = 10.0, depth_max = 0.1, units = \"N-mm-s\" }";

/// A 14 g ball key on a half-space under the IMPACT law, loaded by 6 kN
/// (gravity scaled), `d0` [m] deep at rest.
fn loaded_ball(d0: f64) -> ballcage_core::Simulation {
    common::ball_on_floor(
        "duration = 0.01\ndt = 1e-5\noutput_interval = 1e-3",
        6000.0 / 0.014,
        &format!(
            "shape = {{ type = \"ball\", radius = 0.0075 }}\nmass = 0.014\nposition = [0.0, 0.0, {}]",
            0.0075 - d0
        ),
        PAPER_IMPACT,
    )
}

/// Pressed by 6 kN, the ball sinks δ = (F/K)^(1/n) = 0.278 mm (K = 1e5
/// N/mm^2.2, n = 2.2; docs/model.md §5), from 10 µm deep or from 1 mm deep;
/// the solve ends within the default tolerance (1e-4 N, so within about
/// 1e-12 m of the closed form at the contact's 4.7e7 N/m) and leaves the
/// ball at rest.
#[test]
fn a_pressed_ball_settles_at_the_closed_form_depth() {
    let (k, n, f) = (1e5 * 1000f64.powf(2.2), 2.2, 6000.0);
    let expect = (f / k).powf(1.0 / n);
    for d0 in [1e-5, 1e-3] {
        let sim = loaded_ball(d0);
        let ball = common::body(&sim, "ball");
        let mut state = sim.state().clone();
        state.vel[ball].z = -0.3; // set to zero by the solve
        let mut dynamics = Dynamics::new(sim.model());
        let solve = equilibrium(
            sim.model(),
            &mut dynamics,
            &mut state,
            &[(ball, StaticDofs::Position)],
            StaticTolerance::default(),
        )
        .unwrap();
        let depth = 0.0075 - state.pos[ball].z;
        assert!(
            (depth / expect - 1.0).abs() < 1e-8,
            "from {d0} m: {depth} against {expect} ({solve:?})"
        );
        assert!(solve.force <= 1e-4, "{solve:?}");
        assert_eq!(state.vel[ball].norm(), 0.0);
        assert!(solve.iterations < 20, "{solve:?}");
    }
}

/// A ball in the air has no equilibrium: nothing holds it against gravity,
/// its stiffness is zero, and the solve says so rather than moving it.
#[test]
fn a_ball_held_by_nothing_is_refused() {
    let sim = loaded_ball(-0.01);
    let ball = common::body(&sim, "ball");
    let mut state = sim.state().clone();
    let mut dynamics = Dynamics::new(sim.model());
    let err = equilibrium(
        sim.model(),
        &mut dynamics,
        &mut state,
        &[(ball, StaticDofs::Pose)],
        StaticTolerance::default(),
    )
    .unwrap_err();
    assert!(err.contains("singular"), "{err}");
}

/// A `quasi-static-position` ball key on a half-space under the IMPACT
/// law, pressed by 6 kN (gravity scaled), placed just touching: solved at
/// assembly and after each step, it rests where its weight is carried by
/// the contact and the centring spring toward where it was placed, m·g =
/// K·δⁿ + c·δ (c = `CENTRING`; docs/engine.md, "Quasi-static bodies"),
/// within 1e-9. The centring spring moves the depth by 2e-5, so the bound
/// sees it.
#[test]
fn a_quasi_static_ball_rests_where_its_weight_is_carried() {
    use ballcage_core::dynamics::quasistatic::CENTRING;
    let (k, n, w) = (1e5 * 1000f64.powf(2.2), 2.2, 6000.0);
    // m·g = K·δⁿ + c·δ by Newton's method from the contact alone.
    let mut depth = (w / k).powf(1.0 / n);
    for _ in 0..50 {
        let r = k * depth.powf(n) + CENTRING * depth - w;
        depth -= r / (n * k * depth.powf(n - 1.0) + CENTRING);
    }
    let contact_alone = (w / k).powf(1.0 / n);
    assert!((depth / contact_alone - 1.0).abs() > 1e-5);
    let mut sim = common::ball_on_floor(
        "duration = 0.002\ndt = 1e-4\noutput_interval = 1e-3",
        w / 0.014,
        "motion = \"quasi-static-position\"\nshape = { type = \"ball\", radius = 0.0075 }\n\
         mass = 0.014\nposition = [0.0, 0.0, 0.0075]",
        PAPER_IMPACT,
    );
    let ball = common::body(&sim, "ball");
    let sunk = |sim: &ballcage_core::Simulation| 0.0075 - sim.state().pos[ball].z;
    assert!(
        (sunk(&sim) / depth - 1.0).abs() < 1e-9,
        "{} against {depth}",
        sunk(&sim)
    );
    sim.run().unwrap();
    assert!(
        (sunk(&sim) / depth - 1.0).abs() < 1e-9,
        "{} against {depth}",
        sunk(&sim)
    );
}

/// A quasi-static body that no contact pair joins to a body that is not
/// quasi-static, and one in a joint, are refused with the field named.
#[test]
fn a_quasi_static_body_unheld_or_in_a_joint_is_refused() {
    let toml = common::ball_on_floor_toml(
        "duration = 0.01\ndt = 1e-4\noutput_interval = 1e-3",
        9.81,
        "motion = \"quasi-static\"\nshape = { type = \"ball\", radius = 0.05 }\nmass = 1.0\n\
         position = [0.0, 0.0, 0.05]",
        "normal = { law = \"hertz\", stiffness = 1e8 }",
    );
    let error = |toml: &str| {
        ballcage_core::Scene::from_toml_str(toml, &[])
            .and_then(|scene| ballcage_core::Simulation::new(&scene))
            .map(|_| ())
            .expect_err("refused")
    };
    let unheld = toml.replace(
        "bodies = [\"floor\", \"ball\"]",
        "bodies = [\"ball\", \"ball2\"]",
    ) + "[[bodies]]\nname = \"ball2\"\nmotion = \"quasi-static\"\n\
           shape = { type = \"ball\", radius = 0.05 }\nmass = 1.0\nposition = [0.0, 0.0, 0.2]\n";
    let e = error(&unheld);
    assert_eq!(
        (e.path.as_str(), e.value.as_str()),
        ("bodies[1].motion", "ball"),
        "{e}"
    );
    assert!(e.reason.contains("nothing holds it"), "{e}");
    let jointed = toml
        + "[[joints]]\ntype = \"cv\"\nbodies = [\"floor\", \"ball\"]\n\
           anchors = [[0.0, 0.0, 0.05], [0.0, 0.0, 0.0]]\nstiffness = 1000.0\ndamping = 0.0\n\
           twist_stiffness = 1.0\ntwist_damping = 0.0\n";
    let e = error(&jointed);
    assert_eq!(
        (e.path.as_str(), e.value.as_str()),
        ("joints[0].bodies[1]", "ball"),
        "{e}"
    );
    assert!(e.reason.contains("takes no joint"), "{e}");
}
