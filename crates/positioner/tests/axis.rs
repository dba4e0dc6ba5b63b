//! Position arithmetic of the shared core (PSD4xx manual 4.7, 4.8; PSx3xx 5.5–5.7) with both
//! families' numbers: the same code, configured differently (PSD4xx: 4,026 rotations; PSx3xx:
//! 256-rotation encoder, 250 usable).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod common;

use common::*;
use drivespec_positioner::axis::{
    rescale, scale, Axis, AxisError, LimitsAfterMappingEnd, Rounding,
};
use proptest::prelude::*;
use std::sync::Arc;

fn psd() -> Axis {
    Axis::new(Arc::new(psd_axis()))
}

fn psx() -> Axis {
    Axis::new(Arc::new(psx_axis()))
}

/// Delivery state: ±2,013 rotations around 0 (PSD-MAP-003, PSD-MAP-006, PSD-MAP-008,
/// PSD-MAP-009, PSD-MAP-001).
#[test]
fn psd_delivery_range() {
    let a = psd();
    assert_eq!(a.position_range(), (-805_200, 805_200));
    assert_eq!(a.increments_per_rotation(), 400.0);
    assert_eq!(a.mapping_end_window(0), (1200, 1_611_600));
    let (lo, hi) = a.position_range();
    assert_eq!((hi - lo) / 400, 4026);
}

/// PSx3xx 5.6.1: delivery 51,200 in the middle, limits 1,200 … 101,200; 5.6.4: mapping end
/// between actual + 1,200 and actual + 101,200; the worked example with a 5 mm spindle.
#[test]
fn psx_numbers_on_the_same_core() {
    let mut a = psx();
    assert_eq!(a.position_range(), (1200, 101_200));
    assert_eq!(a.mapping_end_window(51_200), (52_400, 152_400));
    a.set_mapping_end(152_400, 51_200).unwrap();
    assert_eq!(
        (a.values().lower_limit, a.values().upper_limit),
        (51_200, 151_200)
    );
    a.set_mapping_end(52_400, 51_200).unwrap();
    assert_eq!(
        (a.values().lower_limit, a.values().upper_limit),
        (-48_800, 51_200)
    );
    // 5.6.4: numerator 400, denominator 5,000; referencing value 300,000; end 1,215,000.
    let mut a = psx();
    a.set_scaling(400, 5000).unwrap();
    a.load(drivespec_positioner::AxisValues {
        reference: 300_000,
        ..a.values()
    });
    a.set_mapping_end(1_215_000, 0).unwrap();
    assert_eq!(
        (a.values().lower_limit, a.values().upper_limit),
        (-50_000, 1_200_000)
    );
}

/// Scaling by denominator / numerator, both roundings (PSD-MAP-024, PSD-MAP-028; PSx3xx 5.6.4).
#[test]
fn scaling_and_rounding() {
    assert_eq!(scale(1200, 400, 100, Rounding::TowardZero), 300);
    assert_eq!(scale(1_611_600, 400, 100, Rounding::TowardZero), 402_900);
    assert_eq!(scale(1000, 300, 400, Rounding::TowardZero), 1333);
    assert_eq!(scale(1000, 600, 400, Rounding::Nearest), 667);
    assert_eq!(scale(-1000, 600, 400, Rounding::Nearest), -667);
    assert_eq!(scale(-1000, 600, 400, Rounding::TowardZero), -666);
    assert_eq!(
        rescale(4000, 400, 400, 400, 100, Rounding::TowardZero),
        1000
    );
    assert_eq!(scale(i64::MAX, 1, 10_000, Rounding::Nearest), i64::MAX);
}

/// 4.7 notes 3–6: the cascades (PSD-MAP-012, PSD-MAP-013, PSD-MAP-014, PSD-MAP-015,
/// PSD-MAP-021, PSD-MAP-022).
#[test]
fn cascades() {
    let mut a = psd();
    a.set_target(Some(4000));
    a.set_reference(100);
    assert_eq!(a.target(), Some(4100));
    assert_eq!(a.values().mapping_end, 806_500);
    assert_eq!(a.actual(0.0), 100);
    a.set_actual(1000, 0.0);
    assert_eq!(a.values().reference, 1000);
    a.set_scaling(400, 200).unwrap();
    assert_eq!(a.values().reference, 500);
    assert_eq!(a.target(), Some(2500));
    assert_eq!(a.values().loop_length, 125);
    assert_eq!(a.values().window, 1);
    let rot = a.set_direction(1, 2.0).unwrap();
    assert_eq!(rot, -2.0);
    assert_eq!(a.values().reference, 0);
    assert_eq!(a.values().mapping_end, 403_200);
    assert_eq!(
        a.set_scaling(0, 400),
        Err(AxisError::OutOfRange {
            value: 0,
            min: 1,
            max: 10_000
        })
    );
}

/// The limits after a mapping end change, both readings (PSD-MAP-013, erratum
/// PSD-ERRATUM-057); refused mapping ends (PSD-MAP-007).
#[test]
fn mapping_end_and_limits() {
    let mut a = psd();
    assert!(a.set_mapping_end(1_611_601, 0).is_err());
    a.set_mapping_end(1_611_600, 0).unwrap();
    assert_eq!(
        (a.values().lower_limit, a.values().upper_limit),
        (0, 1_610_400)
    );
    let mut cfg = psd_axis();
    cfg.limits_after_mapping_end = LimitsAfterMappingEnd::Delivery;
    let mut a = Axis::new(Arc::new(cfg));
    a.set_mapping_end(1_611_600, 0).unwrap();
    assert_eq!(
        (a.values().lower_limit, a.values().upper_limit),
        (-805_200, 805_200)
    );
    assert!(a.set_upper_limit(1_610_401).is_err());
    assert!(a.set_lower_limit(-1).is_err());
}

/// A direction change wraps the mirrored position into the new measuring range (PSD-MAP-012).
#[test]
fn direction_flip_wraps() {
    let mut a = psd();
    a.set_mapping_end(1_611_600, 0).unwrap();
    // At 1,000,000 increments = 2,500 rotations; mirrored: -2,500, inside -2,013 … 2,013 after
    // wrapping by the 4,026-rotation span: 1,526.
    let rot = a.set_direction(1, 2500.0).unwrap();
    assert_eq!(rot, 1526.0);
}

/// Window and loop ranges scale with the resolution (PSD-PAR-44-003, PSD-PAR-45-003,
/// erratum PSD-ERRATUM-024).
#[test]
fn scaled_ranges() {
    let mut a = psd();
    a.set_scaling(400, 100).unwrap();
    assert_eq!(a.window_range(), (1, 25));
    assert_eq!(a.loop_intervals(), vec![[-1000, -2], [0, 0], [2, 1000]]);
    assert!(a.set_window(26).is_err());
    assert!(a.set_loop_length(1).is_err());
    a.set_loop_length(-2).unwrap();
}

proptest! {
    /// Scaling and scaling back keeps a position within the rounding error (PSD-MAP-014), and
    /// the shaft position maps to the same user value after any scaling (PSD-MAP-024).
    #[test]
    fn rescaling_round_trip(v in -2_000_000i64..2_000_000, n in 1i64..=10_000, d in 1i64..=10_000) {
        let there = rescale(v, 400, 400, n, d, Rounding::Nearest);
        let back = rescale(there, n, d, 400, 400, Rounding::Nearest);
        let err = (400.0 * n as f64 / d as f64).ceil() as i64;
        prop_assert!((back - v).abs() <= err.max(1));
        let mut a = psd();
        a.set_scaling(n, d).unwrap();
        let rot = v as f64 / 400.0;
        let user = a.actual(rot);
        prop_assert!((a.to_rot(user) - rot).abs() <= 0.5 / a.increments_per_rotation() + 1e-9);
    }

    /// The mapping end window always contains an accepted end, and the limits it implies
    /// always contain the actual position (PSD-MAP-007, PSD-MAP-013).
    #[test]
    fn mapping_end_keeps_the_position_inside(actual in -3_000_000i64..3_000_000, f in 0.0f64..=1.0) {
        let mut a = psd();
        let (lo, hi) = a.mapping_end_window(actual);
        let end = lo + ((hi - lo) as f64 * f) as i64;
        a.set_mapping_end(end, actual).unwrap();
        let v = a.values();
        prop_assert!(v.lower_limit <= actual && actual <= v.upper_limit);
    }
}
