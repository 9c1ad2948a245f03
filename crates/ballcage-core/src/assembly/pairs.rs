//! Contact specs → contact pairs: each pair's geometry and laws resolved once.

use super::laws::{friction_law, normal_law};
use crate::error::SceneError;
use crate::geometry::{LineContact, LineLaw, PairGeometry, RingCylinder, Shape};
use crate::math::Vec3;
use crate::model::{Body, ContactPair, Motion};
use crate::scene::{ContactSpec, FeatureSpec, LineLawSpec, Scene, ShapeSpec};

/// Every declared contact pair, in order (index = pair id).
pub(super) fn contact_pairs(
    scene: &Scene,
    bodies: &[Body],
) -> Result<Vec<ContactPair>, SceneError> {
    scene
        .contacts
        .iter()
        .enumerate()
        .map(|(i, c)| contact_pair(scene, bodies, c, &format!("contacts[{i}]")))
        .collect()
}

/// One pair: its bodies, point finder, laws, penetration limit and reduced mass.
fn contact_pair(
    scene: &Scene,
    bodies: &[Body],
    c: &ContactSpec,
    path: &str,
) -> Result<ContactPair, SceneError> {
    let a = scene.body_id(&format!("{path}.bodies[0]"), &c.bodies[0])?;
    let b = scene.body_id(&format!("{path}.bodies[1]"), &c.bodies[1])?;
    let specs = [&scene.bodies[a].shape, &scene.bodies[b].shape];
    let (geometry, swapped) = pair_geometry(c, path, specs, [&bodies[a].shape, &bodies[b].shape])?;
    let (first, second) = if swapped { (b, a) } else { (a, b) };
    let divergence = &scene.simulation.divergence;
    let depth_limit = divergence.max_penetration.unwrap_or_else(|| {
        divergence.penetration_fraction
            * geometry.contact_radius(&bodies[first].shape, &bodies[second].shape)
    });
    // Only free bodies translate; the others count as infinitely heavy.
    let inverse_mass = |i: usize| {
        let body: &Body = &bodies[i];
        if body.motion == Motion::Dynamic {
            1.0 / body.mass
        } else {
            0.0
        }
    };
    Ok(ContactPair {
        name: c.pair_name(),
        a,
        b,
        geometry,
        swapped,
        normal: normal_law(&c.normal),
        friction: c.friction.as_ref().map(friction_law),
        depth_limit,
        reduced_mass: 1.0 / (inverse_mass(a) + inverse_mass(b)),
    })
}

/// The point finder of pair `c` between shapes a and b (`specs` as written,
/// `shapes` built from them), and whether its canonical order is (b, a).
/// Fails when no finder applies to the two shapes.
pub(super) fn pair_geometry(
    c: &ContactSpec,
    path: &str,
    specs: [&ShapeSpec; 2],
    shapes: [&Shape; 2],
) -> Result<(PairGeometry, bool), SceneError> {
    let Some(feature) = &c.geometry else {
        let line = LineContact {
            points: c.points,
            law: match c.line_law {
                LineLawSpec::LevelSets => LineLaw::LevelSets,
                LineLawSpec::Patches => LineLaw::Patches,
            },
        };
        return PairGeometry::select(shapes[0], shapes[1], line).ok_or_else(|| {
            SceneError::new(
                format!("{path}.bodies"),
                format!("{:?}", c.bodies),
                format!(
                    "no contact geometry for a {}–{} pair (supported: {}; or give `geometry`)",
                    specs[0].kind_name(),
                    specs[1].kind_name(),
                    PairGeometry::SUPPORTED
                ),
            )
        });
    };
    Ok((feature_geometry(c, feature, path, specs[1])?, false))
}

/// The radius of pair `c`'s body b, of shape `b`, which a ball feature needs to be a ball.
fn ball_radius(c: &ContactSpec, path: &str, b: &ShapeSpec) -> Result<f64, SceneError> {
    match b {
        ShapeSpec::Ball { radius } => Ok(*radius),
        other => Err(SceneError::new(
            format!("{path}.bodies[1]"),
            &c.bodies[1],
            format!(
                "this geometry needs body b to be a ball, not a {}",
                other.kind_name()
            ),
        )),
    }
}

/// The point finder of an explicit feature; the ball features hold ball b, of
/// shape `b`, whose radius must fit the feature.
fn feature_geometry(
    c: &ContactSpec,
    feature: &FeatureSpec,
    path: &str,
    b: &ShapeSpec,
) -> Result<PairGeometry, SceneError> {
    let g = format!("{path}.geometry");
    let ball_radius = || ball_radius(c, path, b);
    let narrower = |field: &str, width: f64, r: f64| {
        SceneError::new(
            format!("{g}.{field}"),
            width,
            format!("must exceed the ball radius {r}"),
        )
    };
    Ok(match feature {
        FeatureSpec::TorusBall {
            centre,
            axis,
            core_radius,
            tube_radius,
        } => {
            let r = ball_radius()?;
            if r >= *tube_radius {
                return Err(narrower("tube_radius", *tube_radius, r));
            }
            PairGeometry::TorusBall {
                centre: Vec3::from(*centre),
                axis: Vec3::from(*axis).normalize(),
                core_radius: *core_radius,
                tube_radius: *tube_radius,
                ball_radius: r,
            }
        }
        FeatureSpec::SlotBall {
            centre,
            normal,
            half_width,
        } => {
            let r = ball_radius()?;
            if r >= *half_width {
                return Err(narrower("half_width", *half_width, r));
            }
            PairGeometry::SlotBall {
                centre: Vec3::from(*centre),
                normal: Vec3::from(*normal).normalize(),
                half_width: *half_width,
                ball_radius: r,
            }
        }
        FeatureSpec::CavitySphere {
            cavity_centre,
            cavity_radius,
            sphere_centre,
            sphere_radius,
        } => PairGeometry::CavitySphere {
            cavity_centre: Vec3::from(*cavity_centre),
            cavity_radius: *cavity_radius,
            sphere_centre: Vec3::from(*sphere_centre),
            sphere_radius: *sphere_radius,
        },
        FeatureSpec::RingCylinder {
            ring_centre,
            ring_axis,
            ring_radius,
            axis_point,
            axis_direction,
            cylinder_radius,
        } => PairGeometry::RingCylinder(RingCylinder {
            ring_centre: Vec3::from(*ring_centre),
            ring_axis: Vec3::from(*ring_axis).normalize(),
            ring_radius: *ring_radius,
            axis_point: Vec3::from(*axis_point),
            axis_direction: Vec3::from(*axis_direction).normalize(),
            cylinder_radius: *cylinder_radius,
        }),
    })
}

#[cfg(test)]
mod tests {
    use crate::scene::Scene;

    /// A race (cylinder) and a ball in its torus groove.
    const GROOVE: &str = r#"
        [simulation]
        duration = 0.01
        dt = 1e-4
        output_interval = 1e-3
        [[bodies]]
        name = "race"
        shape = { type = "cylinder", radius = 0.2, half_length = 0.1 }
        mass = 1.0
        [[bodies]]
        name = "ball"
        shape = { type = "ball", radius = 0.05 }
        mass = 1.0
        position = [0.0, 0.0, 1.0]
        [[contacts]]
        bodies = ["race", "ball"]
        normal = { law = "hertz", stiffness = 1e8 }
        geometry = { type = "torus-ball", centre = [0.0, 0.0, 0.0], axis = [1.0, 0.0, 0.0], core_radius = 0.1, tube_radius = 0.06 }
    "#;

    fn error_of(text: &str) -> crate::error::SceneError {
        let scene = Scene::from_toml_str(text, &[]).expect("valid data");
        super::super::assemble(&scene).expect_err("geometry does not fit")
    }

    #[test]
    fn a_groove_needs_a_ball_narrower_than_its_section() {
        let scene = Scene::from_toml_str(GROOVE, &[]).unwrap();
        let (model, _) = super::super::assemble(&scene).unwrap();
        assert_eq!(model.pairs.len(), 1);
        let e = error_of(&GROOVE.replace("tube_radius = 0.06", "tube_radius = 0.04"));
        assert_eq!(e.path, "contacts[0].geometry.tube_radius");
        assert_eq!(e.reason, "must exceed the ball radius 0.05");
        let e = error_of(&GROOVE.replace(r#"["race", "ball"]"#, r#"["ball", "race"]"#));
        assert_eq!(e.path, "contacts[0].bodies[1]");
        assert_eq!(e.value, "race");
        assert_eq!(
            e.reason,
            "this geometry needs body b to be a ball, not a cylinder"
        );
    }
}
