//! A block on an incline under the Adams friction law: there is no true
//! stiction, so below tan⁻¹ the block creeps at the speed where the friction
//! coefficient balances the slope, μ̂(v) = cot α (α measured from vertical):
//! v = u·v_s with u(3 − u²)/2 = cot α / μs (docs/model.md §7.7).
//!
//! The incline is modelled by tilting gravity: g = 9.8·(cos α, 0, −sin α) on a
//! horizontal plane.

mod common;

fn block_on_incline(alpha_deg: f64, duration: f64) -> common::Probe {
    common::Probe::run(
        &common::incline_scene(alpha_deg, "rk4", 2e-5, 1e-2, duration),
        "block",
    )
}

#[test]
fn creep_speeds_match_the_closed_form() {
    for (alpha, expect_mm_s) in [(75.0, 72.0), (80.0, 41.6), (85.0, 19.7)] {
        let p = block_on_incline(alpha, 0.6);
        let v = p.final_velocity.x * 1e3;
        assert!(
            ((v - expect_mm_s) / expect_mm_s).abs() < 1e-2,
            "α = {alpha}°: creep {v:.2} mm/s, expected {expect_mm_s}"
        );
        assert!(p.final_velocity.z.abs() < 1e-6 && p.final_velocity.y.abs() < 1e-9);
    }
}

#[test]
fn steep_incline_accelerates_at_the_dynamic_friction_rate() {
    // α = 60°: cot α = 0.577 > μs, so the block accelerates; past v_d,
    // a = g(cos α − μd sin α) = 4.05 m/s².
    let a = 60f64.to_radians();
    let expect = 9.8 * (a.cos() - 0.1 * a.sin());
    let p = block_on_incline(60.0, 0.8);
    let (t0, v0) = p.velocity_at(0.6);
    let (t1, v1) = p.velocity_at(0.8);
    assert!(v0 > 1.0, "still below v_d at 0.6 s: {v0}");
    let acc = (v1 - v0) / (t1 - t0);
    assert!(
        ((acc - expect) / expect).abs() < 1e-2,
        "a = {acc}, expected {expect}"
    );
}
