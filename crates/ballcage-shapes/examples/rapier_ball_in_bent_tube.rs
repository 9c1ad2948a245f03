//! A ball dropped into a bent tube, in rapier3d-f64, against the exact tube
//! wall of `ballcage_shapes::TubeInterior`: a program a rapier user can copy.
//!
//! The tube (inner radius 58 mm) runs down from the origin, turns through a
//! quarter circle of radius 1.5 m to the horizontal, runs 1 m straight and
//! turns back up: a J. A ball of 43 mm dropped in at the top falls, runs
//! round the bend and, slowed by a little damping, comes to rest on the
//! bottom of the straight, where the wall is R − r = 15 mm below the
//! centreline: its centre settles at z = −1.5 − 0.015 m. Nothing is meshed:
//! the contact depth and normal are the closed forms, smooth round the bends.
//!
//! What it takes, beside an ordinary rapier world:
//! 1. the tube as a collider: `ColliderBuilder::new(SharedShape::new(tube))`
//!    on a fixed body (the tube has no mass of its own);
//! 2. a narrow phase that knows the shape:
//!    `NarrowPhase::with_query_dispatcher(ShapeDispatcher::default().chain(DefaultQueryDispatcher))`;
//!    every other pair still goes to parry's default dispatcher.
//!
//! Run: `cargo run --release -p ballcage-shapes --example rapier_ball_in_bent_tube`.

use ballcage_shapes::{ShapeDispatcher, TubeInterior, TubeSegment};
use rapier3d_f64::parry::query::{DefaultQueryDispatcher, QueryDispatcher};
use rapier3d_f64::prelude::*;

/// Tube radius and ball radius [m].
const INNER_RADIUS: f64 = 0.058;
const BALL_RADIUS: f64 = 0.043;

/// The J-shaped tube on a fixed body and the ball above its bottom: the
/// bodies, the colliders and the ball's handle.
fn scene() -> (RigidBodySet, ColliderSet, RigidBodyHandle) {
    let quarter = std::f64::consts::FRAC_PI_2;
    let tube = TubeInterior::new(
        INNER_RADIUS,
        Vector::ZERO,
        -Vector::Z,
        &[
            TubeSegment::Arc {
                radius: 1.5,
                angle: quarter,
                bend: Vector::X,
            },
            TubeSegment::Straight { length: 1.0 },
            TubeSegment::Arc {
                radius: 1.5,
                angle: quarter,
                bend: Vector::Z,
            },
        ],
    );
    let mut bodies = RigidBodySet::new();
    let mut colliders = ColliderSet::new();
    let ground = bodies.insert(RigidBodyBuilder::fixed());
    colliders.insert_with_parent(
        ColliderBuilder::new(SharedShape::new(tube)).density(0.0),
        ground,
        &mut bodies,
    );
    let ball = bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(Vector::new(0.0, 0.0, -0.2))
            .linear_damping(0.5)
            .angular_damping(0.5),
    );
    colliders.insert_with_parent(
        ColliderBuilder::ball(BALL_RADIUS).friction(0.3),
        ball,
        &mut bodies,
    );
    (bodies, colliders, ball)
}

fn main() {
    let (mut bodies, mut colliders, ball) = scene();
    let params = IntegrationParameters {
        dt: 1e-3,
        length_unit: 0.1,
        ..IntegrationParameters::default()
    };
    let mut pipeline = PhysicsPipeline::new();
    let mut islands = IslandManager::new();
    let mut broad_phase = BroadPhaseBvh::new();
    // The one line that makes rapier see the exact tube.
    let mut narrow_phase = NarrowPhase::with_query_dispatcher(
        ShapeDispatcher::default().chain(DefaultQueryDispatcher),
    );
    let mut impulse_joints = ImpulseJointSet::new();
    let mut multibody_joints = MultibodyJointSet::new();
    let mut ccd = CCDSolver::new();
    let gravity = Vector::new(0.0, 0.0, -9.81);

    for step in 0..=20_000 {
        pipeline.step(
            gravity,
            &params,
            &mut islands,
            &mut broad_phase,
            &mut narrow_phase,
            &mut bodies,
            &mut colliders,
            &mut impulse_joints,
            &mut multibody_joints,
            &mut ccd,
            &(),
            &(),
        );
        if step % 2_000 == 0 {
            let p = bodies[ball].translation();
            let v = bodies[ball].linvel();
            println!(
                "t = {:5.1} s: ball at ({:+.4}, {:+.4}, {:+.4}) m, speed {:.4} m/s",
                step as f64 * params.dt,
                p.x,
                p.y,
                p.z,
                v.length()
            );
        }
    }
    let z = bodies[ball].translation().z;
    let rest = -1.5 - (INNER_RADIUS - BALL_RADIUS);
    println!("rests at z = {z:.5} m; the wall's closed form puts it at {rest:.5} m");
    // rapier lets a resting contact sink by its allowed error, 0.001 × length_unit.
    assert!((z - rest).abs() < 2e-4, "{z} against {rest}");
}
