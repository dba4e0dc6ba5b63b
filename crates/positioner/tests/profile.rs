//! The motion profile (PSD4xx manual 4.3): for any speeds, ramps and goals the drive arrives
//! exactly, never exceeds the maximum speed and never changes speed faster than its ramps
//! (PSD-VEL-001, PSD-VEL-002, PSD-VEL-003, PSD-VEL-004, PSD-VEL-005).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_positioner::profile::{approach, approach_speed, brake, rps, Kinematics, Ramps};
use proptest::prelude::*;

/// Seconds within which an approach from speed `v0` to `goal` arrives, twice over: braking
/// from `v0`, the trapezoid over the farthest distance, and the harmonious end, whose speed
/// falls with the distance left (time constant vmax / decel · √(blend / 2)) down to the creep
/// speed of one step's deceleration.
fn time_bound(r: &Ramps, v0: f64, goal: f64, dt: f64) -> f64 {
    let brake = v0.abs() / r.decel;
    let distance = goal.abs() + v0 * v0 / (2.0 * r.decel);
    let travel = distance / r.vmax + r.vmax / r.accel + r.vmax / r.decel;
    let tau = r.vmax / r.decel * (r.blend / 2.0).sqrt();
    let creep = r.decel * dt;
    let end = tau * ((distance / (tau * creep)).max(1.0).ln() + 2.0);
    2.0 * (brake + travel + end) + 1.0
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn arrives_within_limits(
        vmax in 10.0f64..1000.0,
        accel in 1.0f64..5000.0,
        decel in 1.0f64..5000.0,
        goal in -5.0f64..5.0,
        v0 in -1.0f64..1.0,
    ) {
        let r = Ramps { vmax: rps(vmax), accel: rps(accel), decel: rps(decel), blend: 0.5 };
        let dt = 0.001;
        let mut k = Kinematics { pos: 0.0, vel: v0 * r.vmax };
        let mut arrived = false;
        let steps = (time_bound(&r, k.vel, goal, dt) / dt).ceil() as u64;
        for _ in 0..steps {
            let s = approach(k, goal, &r, dt);
            let dv = s.kin.vel - k.vel;
            let speeding_up = s.kin.vel.abs() > k.vel.abs() && s.kin.vel * k.vel >= 0.0;
            let limit = if speeding_up { r.accel } else { r.decel.max(r.accel) };
            prop_assert!(dv.abs() <= limit * dt * (1.0 + 1e-9) + 1e-12, "dv {dv}");
            prop_assert!(s.kin.vel.abs() <= r.vmax.max(k.vel.abs()) * (1.0 + 1e-12));
            k = s.kin;
            if s.arrived {
                arrived = true;
                break;
            }
        }
        prop_assert!(arrived);
        prop_assert_eq!(k.pos, goal);
        prop_assert_eq!(k.vel, 0.0);
    }

    /// The approach curve never asks more than the deceleration (4.3: harmonious end).
    #[test]
    fn curve_deceleration_bounded(vmax in 1.0f64..1000.0, decel in 1.0f64..5000.0, s in 0.0001f64..10.0) {
        let r = Ramps { vmax: rps(vmax), accel: 1.0, decel: rps(decel), blend: 0.5 };
        let ds = 1e-6;
        let v1 = approach_speed(s, &r);
        let v2 = approach_speed(s + ds, &r);
        // a = v dv/ds
        let a = v1 * (v2 - v1) / ds;
        prop_assert!(a <= r.decel * (1.0 + 1e-3) + 1e-9, "{a} > {}", r.decel);
    }
}

#[test]
fn braking_stops_with_the_rate() {
    let mut k = Kinematics {
        pos: 0.0,
        vel: rps(200.0),
    };
    let mut n = 0;
    while k.vel != 0.0 {
        k = brake(k, rps(2000.0), 0.001).kin;
        n += 1;
    }
    assert!((100..=101).contains(&n), "{n}");
    assert!((k.pos - 0.1667 * 1.0).abs() < 0.01, "{}", k.pos);
}
