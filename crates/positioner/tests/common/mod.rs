//! A PSD4xx-like and a PSx3xx-like family description built from the spec's numbers, for
//! testing the shared core without a family crate.
#![allow(dead_code)]

use drivespec_positioner::axis::{
    AxisConfig, Delivery, LimitRatio, LimitsAfterMappingEnd, Rounding,
};
use drivespec_positioner::config::{Backoff, LoopRules, Ramp, VoltageRules};
use drivespec_positioner::machine::{DriveSettings, Settings};
use drivespec_positioner::{AxisValues, BitMap, CoreConfig, Flag};
use drivespec_spec::{FamilyId, Spec};
use std::sync::{Arc, OnceLock};

pub fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

/// PSD4xx 4.7/4.8 numbers from `spec/psd4xx/protocol.toml`.
pub fn psd_axis() -> AxisConfig {
    let p = spec().family(FamilyId::Psd4xx).psd4xx().unwrap();
    let m = &p.positioning.mapping;
    let s = &p.positioning.scaling;
    AxisConfig {
        base_increments: s.base_increments_per_rotation,
        upper_margin: m.upper_margin,
        lower_offset: m.lower_offset,
        factor_range: [s.factor_min, s.factor_max],
        rounding: Rounding::TowardZero,
        delivery: Delivery {
            mapping_end: m.default_mapping_end,
            upper_limit: m.default_upper_limit,
            lower_limit: m.default_lower_limit,
            reference: 0,
            window: 2,
            loop_length: p.positioning.reference_loop.default_length,
            numerator: s.default_numerator,
            denominator: s.default_denominator,
            direction: 0,
        },
        window_range: [1, 100],
        scale_window_range: true,
        loop_range: vec![[-4000, -10], [0, 0], [10, 4000]],
        scale_loop_range: true,
        upper_limit_ratio: LimitRatio::DenOverNum,
        limits_after_mapping_end: LimitsAfterMappingEnd::FullNewRange,
    }
}

/// PSx3xx 5.5–5.6 numbers from `spec/psx3xx/protocol.toml` (256-rotation encoder, 250 usable).
pub fn psx_axis() -> AxisConfig {
    let p = spec().family(FamilyId::Psx3xx).psx3xx().unwrap();
    let c = &p.constants;
    let m = &p.mapping;
    AxisConfig {
        base_increments: i64::from(m.scaling_base),
        upper_margin: i64::from(m.upper_margin_steps),
        lower_offset: i64::from(m.lower_offset_steps),
        factor_range: c.scaling_factor_range.map(i64::from),
        rounding: Rounding::Nearest,
        delivery: Delivery {
            mapping_end: c.delivery_upper_mapping_end,
            upper_limit: c.delivery_upper_limit,
            lower_limit: c.delivery_lower_limit,
            reference: 0,
            window: 2,
            loop_length: i64::from(c.delivery_loop_steps),
            numerator: 400,
            denominator: 400,
            direction: 0,
        },
        window_range: [1, 100],
        scale_window_range: true,
        loop_range: vec![[-4000, -10], [0, 0], [10, 4000]],
        scale_loop_range: true,
        upper_limit_ratio: LimitRatio::DenOverNum,
        limits_after_mapping_end: LimitsAfterMappingEnd::FullNewRange,
    }
}

/// A PSD4xx-like core configuration with the PSD status bits (3.6).
pub fn psd_core() -> Arc<CoreConfig> {
    let family = spec().family(FamilyId::Psd4xx);
    let bits = BitMap::from_bitfield(
        family.bitfield("status").unwrap(),
        &[
            (Flag::Reached, "PSD-STS-0-SET-1"),
            (Flag::Toggle, "PSD-STS-2-SET-1"),
            (Flag::MotorOk, "PSD-STS-4-SET-1"),
            (Flag::Aborted, "PSD-STS-5-SET-1"),
            (Flag::Running, "PSD-STS-6-SET-1"),
            (Flag::OverTemp, "PSD-STS-7-SET-1"),
            (Flag::AgainstLoop, "PSD-STS-8-SET-1"),
            (Flag::Error, "PSD-STS-9-SET-1"),
            (Flag::Obstruction, "PSD-STS-10-SET-1"),
            (Flag::ManualRotation, "PSD-STS-11-SET-1"),
            (Flag::BadTarget, "PSD-STS-12-SET-1"),
            (Flag::VoltageMissing, "PSD-STS-13-SET-1"),
            (Flag::UpperLimit, "PSD-STS-14-SET-1"),
            (Flag::LowerLimit, "PSD-STS-15-SET-1"),
        ],
    )
    .unwrap();
    Arc::new(CoreConfig {
        axis: Arc::new(psd_axis()),
        bits,
        priority_exclusive: true,
        loop_rules: LoopRules {
            overshoot_is_loop_length: true,
            positive_approaches_up: true,
            backoff: Backoff::LoopLength,
            fixed_rotations: [5, 8],
            attempts: 2,
        },
        stop_ramp: Ramp::Parameter,
        emergency_ramp: Ramp::Maximum,
        max_deceleration: 5000.0,
        voltage: VoltageRules {
            upper: 300,
            run_minimum: Some(175),
        },
        temperature_hysteresis: 5,
        aborted_on_manual_stop: false,
        manual_rotation_always: true,
        both_manual_invalid: true,
        adjust_both_without_loop: true,
        tick_us: 1000,
        blend: 0.5,
        start_position: 0,
    })
}

/// Settings of a PSD 401/411-5V at delivery (3.3, 3.4).
pub fn psd_settings() -> Settings {
    let a = psd_axis().delivery;
    Settings {
        axis: AxisValues {
            direction: a.direction,
            numerator: a.numerator,
            denominator: a.denominator,
            reference: a.reference,
            mapping_end: a.mapping_end,
            upper_limit: a.upper_limit,
            lower_limit: a.lower_limit,
            window: a.window,
            loop_length: a.loop_length,
        },
        drive: DriveSettings {
            readjust: 0,
            positioning_speed: 200,
            manual_speed: 70,
            block_speed_percent: 30,
            acceleration: 1000,
            deceleration: 2000,
            startup_torque: 50,
            operating_torque: 40,
            end_hold_torque: 30,
            hold_torque: 20,
            block_time_ms: 200,
            startup_time_ms: 200,
            end_hold_time_ms: 200,
            umot_filter_ms: 100,
            umot_limit: 185,
            temp_limit: 80,
        },
    }
}
