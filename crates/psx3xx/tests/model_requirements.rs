//! The remaining `must` requirements of the PSx3xx manual the reference model expresses: the
//! LEDs (2.6, 3.3.1), the idle period before a reversal (ISDU 162), entry ranges and fixed
//! entries of 3.1, guard entries, the clear-error edge of control bit 14, limit bits, the
//! status word layout, the process-data assignments (3.3), time-stamp sequences (4.4),
//! torque phases (5.2, 5.3) and readjustment (5.4). Each test names its requirement IDs.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

mod model_util;

use drivespec_positioner::EnvChange;
use drivespec_psx3xx::isdu::{Response, Value};
use drivespec_psx3xx::model::{DriveConfig, LedLight, LinkEvent, RunState};
use drivespec_psx3xx::Output;
use model_util::*;

const MODEL: &str = "PSE312-8";

fn format(f: i64) -> Sim {
    let mut s = Sim::new(MODEL);
    s.write_ok(116, f);
    s.write_ok(193, 1);
    s.write_ok(2, 128);
    assert_eq!(i64::from(s.drive.active_format()), f);
    s
}

fn text(s: &Sim, index: u16) -> String {
    match s.drive.read(index, 0).unwrap() {
        Value::Text(t) => t,
        other => panic!("ISDU {index} reads {other:?}"),
    }
}

// ------------------------------------------------------------------ LEDs (2.6, 3.3.1)

#[test]
fn psx_led_001_002_004_green_and_yellow() {
    let mut s = Sim::new(MODEL);
    // PSX-LED-002: communication available.
    assert_eq!(s.drive.leds().green, LedLight::On90Percent);
    // PSX-LED-004: motor voltage present.
    assert_eq!(s.drive.leds().yellow, LedLight::On);
    // PSX-LED-001.
    s.link(LinkEvent::Lost);
    assert_eq!(s.drive.leds().green, LedLight::Off);
    s.link(LinkEvent::Connected);
    assert_eq!(s.drive.leds().green, LedLight::On90Percent);
    s.env(EnvChange::MotorVoltage { dv: 0 });
    assert_eq!(s.drive.leds().yellow, LedLight::Off);
}

#[test]
fn psx_led_003_005_006_orange_shows_the_time_stamp_function() {
    // PSX-LED-003: dark in format 1 with C/Q open.
    let mut s = Sim::new(MODEL);
    s.link(LinkEvent::Lost);
    assert_eq!(s.drive.leds().orange, LedLight::Off);
    // Lit in format 0 with C/Q open.
    let mut s = format(0);
    s.link(LinkEvent::Lost);
    assert_eq!(s.drive.leds().orange, LedLight::On);
    s.link(LinkEvent::Connected);
    s.f0(0, 0x3FFF);
    assert_eq!(s.drive.leds().orange, LedLight::On);
    s.write_ok(112, 60000);
    // PSX-LED-006: dark while valid stamps arrive.
    s.f0(3, 10000);
    s.run_ms(100);
    assert_eq!(s.drive.leds().orange, LedLight::Off);
    // PSX-LED-005: the stamp fires 40 ms after it; a 250 ms dark phase acknowledges it.
    s.f0(3, 0x3FFF);
    let fired = s.until(100, |d| d.run_state() != RunState::Idle);
    assert_eq!(
        s.drive.leds().orange,
        LedLight::Off,
        "fired after {fired} ms"
    );
    let at = s.now;
    s.until(400, |d| d.leds().orange == LedLight::On);
    assert_eq!(s.now - at, 250 * MS);
}

// ------------------------------------------------------------------ reversal (ISDU 162)

/// The time the drive stands at the reversal of a loop run.
fn reversal_stand_ms(idle_ms: i64) -> u64 {
    let mut s = Sim::new(MODEL);
    s.write_ok(162, idle_ms);
    // Downwards with the forward loop: overrun below the target, stop, reverse.
    s.f1(0x14, 50000);
    s.until(60_000, |d| d.core().kinematics().vel < 0.0);
    s.until(60_000, |d| d.core().kinematics().vel == 0.0);
    let stopped = s.now;
    s.until(60_000, |d| {
        d.core().kinematics().vel != 0.0 || d.run_state() == RunState::Idle
    });
    assert_eq!(s.run(), "positioning");
    let stood = (s.now - stopped) / MS;
    s.settle(60_000);
    assert_eq!(s.actual(), 50000);
    stood
}

#[test]
fn psx_isdu_162_reverse_idle_period_before_a_reversal() {
    // PSX-ISDU-162-REVERSE: the drive waits ISDU 162 ms before it turns the other way.
    for idle in [10, 500, 2000] {
        let stood = reversal_stand_ms(idle);
        assert!(
            stood.abs_diff(idle as u64) <= 2,
            "ISDU 162 = {idle}: stood {stood} ms"
        );
    }
    // A manual run turned round waits as well.
    let mut s = Sim::new(MODEL);
    s.write_ok(162, 700);
    s.f1(0x11, 0);
    s.run_ms(1000);
    s.f1(0x12, 0);
    s.until(10_000, |d| d.core().kinematics().vel == 0.0);
    let stopped = s.now;
    s.until(10_000, |d| d.core().kinematics().vel < 0.0);
    assert!(
        ((s.now - stopped) / MS).abs_diff(700) <= 2,
        "stood {} ms",
        (s.now - stopped) / MS
    );
    // No drag error from the wait (PSX-STS-1-SET-2).
    let mut s = Sim::new(MODEL);
    s.write_ok(162, 3000);
    s.f1(0x14, 50000);
    s.settle(60_000);
    assert!(!s.bit(1) && s.bit(0), "status {:#06x}", s.status());
}

// ------------------------------------------------------------------ ranges (3.1, 3.2)

/// Entries whose range the ISDU server checks against the spec's range for the model.
const RANGES: &[&str] = &[
    "PSX-ISDU-12-RANGE",
    "PSX-ISDU-116-RANGE",
    "PSX-ISDU-118-RANGE",
    "PSX-ISDU-119-RANGE",
    "PSX-ISDU-123-RANGE",
    "PSX-ISDU-124-RANGE",
    "PSX-ISDU-125-RANGE",
    "PSX-ISDU-132-RANGE",
    "PSX-ISDU-133-RANGE",
    "PSX-ISDU-134-RANGE",
    "PSX-ISDU-135-RANGE",
    "PSX-ISDU-136-RANGE",
    "PSX-ISDU-143-RANGE",
    "PSX-ISDU-144-RANGE",
    "PSX-ISDU-145-RANGE",
    "PSX-ISDU-146-RANGE",
    "PSX-ISDU-147-RANGE",
    "PSX-ISDU-148-RANGE",
    "PSX-ISDU-152-RANGE",
    "PSX-ISDU-153-RANGE",
    "PSX-ISDU-154-RANGE",
    "PSX-ISDU-155-RANGE",
    "PSX-ISDU-159-RANGE",
    "PSX-ISDU-160-RANGE",
    "PSX-ISDU-161-RANGE",
    "PSX-ISDU-162-RANGE",
    "PSX-ISDU-163-RANGE",
    "PSX-ISDU-164-RANGE",
    "PSX-ISDU-165-RANGE",
    "PSX-ISDU-166-RANGE",
    "PSX-ISDU-181-RANGE",
    "PSX-ISDU-182-RANGE",
];

/// A fresh drive; for ISDU 153 the speeds are at their maxima, where the table range holds
/// (PSX-ERRATUM-015).
fn fresh_for(index: u16) -> Sim {
    let mut s = Sim::new(MODEL);
    if index == 153 {
        let model = family().model(MODEL).unwrap();
        for id in ["142", "145"] {
            let p = family().parameter(id).unwrap();
            let max = family()
                .resolve(p, Some(model))
                .range
                .unwrap()
                .max()
                .unwrap();
            s.write_ok(id.parse().unwrap(), max);
        }
    }
    s
}

#[test]
fn isdu_ranges_of_3_1_and_3_2_are_enforced() {
    let model = family().model(MODEL).unwrap();
    for id in RANGES {
        let number = id.split('-').nth(2).unwrap();
        let index: u16 = number.parse().unwrap();
        let p = family().parameter(number).unwrap();
        let range = family().resolve(p, Some(model)).range.unwrap();
        for [lo, hi] in range.intervals().iter().copied() {
            for v in [lo, hi] {
                let mut s = fresh_for(index);
                assert_eq!(s.write(index, v), Response::Write, "{id}: {v}");
                assert_eq!(s.read(index), v, "{id}: {v}");
            }
            for v in [lo - 1, hi + 1] {
                if range.contains(v) {
                    continue;
                }
                let mut s = fresh_for(index);
                let before = s.read(index);
                assert_ne!(s.write(index, v), Response::Write, "{id}: {v} accepted");
                assert_eq!(s.read(index), before, "{id}: {v} changed the value");
            }
        }
    }
}

// ------------------------------------------------------------------ fixed entries (3.1)

#[test]
fn psx_isdu_16_17_20_fixed_texts() {
    let s = Sim::new(MODEL);
    // PSX-ISDU-16-TEXT, PSX-ISDU-17-TEXT, PSX-ISDU-20-TEXT: as the spec's delivery texts.
    for (id, want) in [
        ("16", "halstrup-walcher GmbH"),
        ("17", "www.hwg.eu"),
        ("20", "Positioning system"),
    ] {
        let p = family().parameter(id).unwrap();
        assert_eq!(p.default_text.as_deref(), Some(want), "spec of ISDU {id}");
        assert_eq!(text(&s, id.parse().unwrap()), want);
    }
}

#[test]
fn psx_isdu_77_format_78_range_identification_numbers() {
    let mut cfg = DriveConfig::new(MODEL);
    cfg.production_date = 2437;
    cfg.serial_number = u16::MAX;
    let s = Sim::with(cfg);
    // PSX-ISDU-77-FORMAT: year 24, week 37 as YYWW.
    assert_eq!(s.read(77), 2437);
    // PSX-ISDU-78-RANGE: 0..65535, the largest read unchanged.
    assert_eq!(s.read(78), 65535);
    assert_eq!(text(&s, 21), "65535");
}

#[test]
fn psx_isdu_12_bits_locks_are_saved() {
    let mut s = Sim::new(MODEL);
    // PSX-ISDU-12-BITS: delivery 0, secured (saved), bit 0 locks parameter writes.
    assert_eq!(s.read(12), 0);
    s.write_ok(12, 0b1110);
    s.write_ok(131, 3);
    s.write_ok(193, 1);
    s.write_ok(2, 128);
    assert_eq!(s.read(12), 0b1110);
    s.write_ok(12, 0b0001);
    assert_ne!(s.write(131, 4), Response::Write);
    assert_eq!(s.read(131), 3);
}

#[test]
fn psx_isdu_171_free_registers() {
    let mut s = Sim::new(MODEL);
    // PSX-ISDU-171-FREE: ten 16-bit registers, delivery 0, kept over a restart when saved.
    for (k, index) in (171..=180).enumerate() {
        assert_eq!(s.read(index), 0);
        s.write_ok(index, 1000 + k as i64);
    }
    s.write_ok(180, 65535);
    s.write_ok(193, 1);
    s.write_ok(2, 128);
    assert_eq!(s.read(171), 1000);
    assert_eq!(s.read(180), 65535);
    assert_ne!(s.write(171, 65536), Response::Write);
}

#[test]
fn psx_isdu_182_bit7_threshold_of_the_over_temperature_bit() {
    let mut s = Sim::new(MODEL);
    // PSX-ISDU-182-BIT7.
    s.write_ok(182, 40);
    s.env(EnvChange::Temperature { celsius: 40 });
    assert!(!s.bit(7));
    s.env(EnvChange::Temperature { celsius: 41 });
    assert!(s.bit(7));
}

// ------------------------------------------------------------------ guard entries (3.1)

#[test]
fn psx_guard_allow_and_volatile() {
    // (guard, guarded, a value the guarded entry takes)
    for (guard, guarded, value) in [
        (66, 67, 52_000),
        (109, 110, 0x10),
        (111, 112, 60_000),
        (126, 127, 100),
    ] {
        let mut s = Sim::new(MODEL);
        // PSX-GUARD-66-VOLATILE, PSX-GUARD-109-VOLATILE, PSX-GUARD-111-VOLATILE,
        // PSX-GUARD-126-VOLATILE: 0..1, delivery 0, not saved.
        assert_eq!(s.read(guard), 0);
        assert_ne!(s.write(guard, 2), Response::Write, "ISDU {guard}");
        s.write_ok(guard, 1);
        s.write_ok(193, 1);
        assert_eq!(
            s.drive.saved_value(&guard.to_string()),
            None,
            "ISDU {guard}"
        );
        s.write_ok(2, 128);
        assert_eq!(s.read(guard), 0, "ISDU {guard} after a restart");
        // PSX-GUARD-66-ALLOW, PSX-GUARD-109-ALLOW, PSX-GUARD-111-ALLOW, PSX-GUARD-126-ALLOW:
        // a write not directly after a 0 to the guard is executed.
        s.write_ok(guard, 0);
        s.write_ok(131, 3);
        s.write_ok(guarded, value);
        assert_eq!(s.read(guarded), value, "ISDU {guarded}");
    }
}

// ------------------------------------------------------------------ clear errors (3.5 bit 14)

/// A drive with a status bit set, and the target in force.
fn with_bit(n: u32) -> (Sim, i32) {
    let mut s = Sim::new(MODEL);
    let target = 60_000;
    match n {
        5 => {
            s.f1(0x14, target);
            s.run_ms(300);
            s.f1(0x00, target);
        }
        10 => {
            s.f1(0x14, target);
            s.run_ms(300);
            s.env(EnvChange::Jam { on: true });
            s.until(2000, |d| d.status_word() >> 10 & 1 == 1);
            s.env(EnvChange::Jam { on: false });
        }
        11 => {
            s.f1(0x14, target);
            s.settle(60_000);
            s.env(EnvChange::Displace { by: -10 });
        }
        12 => s.f1(0x14, 500_000),
        13 => {
            s.env(EnvChange::MotorVoltage { dv: 100 });
            s.run_ms(2000);
            s.f1(0x14, target);
        }
        _ => unreachable!(),
    }
    s.settle(60_000);
    assert!(s.bit(n), "bit {n} not set: {:#06x}", s.status());
    (s, target)
}

#[test]
fn psx_sts_5_10_11_12_13_reset_by_clear_error_edge() {
    // PSX-STS-5-RESET-2, PSX-STS-10-RESET-3, PSX-STS-11-RESET-3, PSX-STS-12-RESET-2,
    // PSX-STS-13-RESET-2: the 0->1 edge of control bit 14 clears them.
    for n in [5, 10, 11, 12, 13] {
        let (mut s, target) = with_bit(n);
        s.f1(0x4000, target);
        assert!(!s.bit(n), "bit {n} after the edge: {:#06x}", s.status());
        assert_eq!(s.run(), "none");
    }
}

// ------------------------------------------------------------------ bits 0, 10, 13, 14, 15

#[test]
fn psx_sts_0_reset_3_4_invalid_target_and_turning() {
    let mut s = Sim::new(MODEL);
    s.f1(0x14, 60_000);
    s.settle(60_000);
    assert!(s.bit(0));
    // PSX-STS-0-RESET-3.
    s.f1(0x04, 60_000);
    s.f1(0x14, 500_000);
    assert!(!s.bit(0) && s.bit(12));
    let mut s = Sim::new(MODEL);
    s.f1(0x14, 60_000);
    s.settle(60_000);
    // PSX-STS-0-RESET-4 (PSX-ERRATUM-027): within the window bit 0 stays, beyond it resets.
    s.env(EnvChange::Displace { by: 2 });
    assert!(s.bit(0));
    s.env(EnvChange::Displace { by: 1 });
    assert!(!s.bit(0));
}

#[test]
fn psx_sts_10_set_2_13_set_3_adj_007_readjust_without_motor_power() {
    let mut s = Sim::new(MODEL);
    s.f1(0x0414, 60_000);
    s.settle(60_000);
    s.env(EnvChange::MotorVoltage { dv: 0 });
    s.run_ms(2000);
    s.env(EnvChange::Displace { by: -10 });
    // PSX-STS-10-SET-2, PSX-STS-13-SET-3.
    assert!(s.bit(10) && s.bit(13), "status {:#06x}", s.status());
    assert_eq!(s.run(), "none");
    // PSX-ADJ-007: the voltage returning starts no readjustment.
    s.env(EnvChange::MotorVoltage { dv: 240 });
    s.run_ms(2000);
    assert_eq!(s.run(), "none");
    assert_eq!(s.actual(), 59_990);
}

#[test]
fn psx_adj_001_003_readjust_only_against_the_loop() {
    // PSX-ADJ-003: turned in the loop direction (upwards for ISDU 134 = 0): no
    // readjustment, bit 11 set, bit 0 reset.
    let mut s = Sim::new(MODEL);
    s.f1(0x0414, 60_000);
    s.settle(60_000);
    s.env(EnvChange::Displace { by: 10 });
    assert_eq!(s.run(), "none");
    assert!(s.bit(11) && !s.bit(0));
    // PSX-ADJ-001: against the loop direction with bits 4 and 10 the target is approached
    // again.
    let mut s = Sim::new(MODEL);
    s.f1(0x0414, 60_000);
    s.settle(60_000);
    s.env(EnvChange::Displace { by: -10 });
    assert_eq!(s.run(), "positioning");
    s.settle(60_000);
    assert_eq!(s.actual(), 60_000);
    assert!(s.bit(0));
}

#[test]
fn psx_sts_14_15_set_and_reset_by_turning_limits_and_runs() {
    let mut s = Sim::new(MODEL);
    // PSX-STS-15-SET-2: the lower limit is set above the position.
    s.write_ok(130, 52_000);
    assert!(s.bit(15));
    // PSX-STS-15-RESET-3: a manual run starts.
    s.f1(0x11, 0);
    assert!(!s.bit(15));
    s.f1(0x10, 0);
    s.settle(10_000);
    // PSX-STS-14-SET-3: turned beyond the upper limit at standstill.
    let mut s = Sim::new(MODEL);
    s.write_ok(129, 51_300);
    s.env(EnvChange::Displace { by: 200 });
    assert!(s.bit(14));
    // PSX-STS-14-RESET-3: a manual run starts.
    s.f1(0x12, 0);
    assert!(!s.bit(14));
    s.f1(0x10, 0);
    s.settle(10_000);
    // PSX-STS-14-RESET-2, PSX-STS-15-RESET-2: the initial reference loop starts.
    let mut s = Sim::new(MODEL);
    s.write_ok(129, 51_300);
    s.env(EnvChange::Displace { by: 200 });
    s.write_ok(130, 51_250);
    assert!(s.bit(14));
    s.f1(0x90, 0);
    assert_eq!(s.run(), "reference-loop");
    assert!(!s.bit(14) && !s.bit(15));
    let mut s = Sim::new(MODEL);
    s.write_ok(130, 52_000);
    assert!(s.bit(15));
    s.f1(0x90, 0);
    assert_eq!(s.run(), "reference-loop");
    assert!(!s.bit(15));
}

#[test]
fn psx_sts_layout_isdu_64_is_the_status_word() {
    let status = family().bitfield("status").unwrap();
    // PSX-STS-LAYOUT: 16 bits, bit 0 target reached … bit 15 the lower range limit.
    assert_eq!(status.bits.len(), 16);
    let rule_bit = |req: &str| {
        status
            .bits
            .iter()
            .find(|b| b.rules.iter().any(|r| r.requirement == req))
            .map(|b| b.bit)
            .unwrap()
    };
    assert_eq!(rule_bit("PSX-STS-0-SET-1"), 0);
    assert_eq!(rule_bit("PSX-STS-15-SET-1"), 15);
    let mut s = Sim::new(MODEL);
    s.write_ok(130, 52_000);
    s.f1(0x14, 60_000);
    s.settle(60_000);
    let word = s.status();
    assert!(bit(word, 0) && !bit(word, 15));
    assert_eq!(s.read(64), i64::from(word));
    assert_eq!(s.drive.input().status, word);
    s.write_ok(130, 61_000);
    assert!(bit(s.status(), 15));
    assert_eq!(s.read(64), i64::from(s.status()));
}

// ------------------------------------------------------------------ process data (3.3)

#[test]
fn psx_pd_003_004_output_assignments() {
    // PSX-PD-003: format 1, bytes 0-1 control word, bytes 2-5 target.
    let mut s = Sim::new(MODEL);
    s.drive
        .handle_image(s.now, &[0x00, 0x14, 0x00, 0x00, 0xEA, 0x60])
        .unwrap();
    assert_eq!((s.read(110), s.read(112)), (0x14, 60_000));
    assert_eq!(
        s.drive.run_state(),
        RunState::Positioning { target: 60_000 }
    );
    // PSX-PD-004: format 2, bytes 0-1 speed, 2-3 control word, 4-7 target.
    let mut s = format(2);
    let image = [0x00, 0x28, 0x00, 0x14, 0x00, 0x00, 0xEA, 0x60];
    s.drive.handle_image(s.now, &image).unwrap();
    assert_eq!((s.read(110), s.read(112)), (0x14, 60_000));
    for _ in 0..300 {
        s.now += MS;
        s.drive.handle_image(s.now, &image).unwrap();
    }
    assert_eq!(s.drive.core().speed_rpm(), 40);
}

#[test]
fn psx_pd_007_input_assignment_is_the_same_in_every_format() {
    for f in [0, 1, 2] {
        let s = format(f);
        let image = s.drive.input_image();
        let input = s.drive.input();
        // PSX-PD-007: status, speed, actual value at bytes 0-1, 2-3, 4-7.
        assert_eq!(image.len(), 8);
        assert_eq!(u16::from_be_bytes([image[0], image[1]]), input.status);
        assert_eq!(i16::from_be_bytes([image[2], image[3]]), input.rpm);
        assert_eq!(
            i32::from_be_bytes([image[4], image[5], image[6], image[7]]),
            input.actual
        );
        assert_eq!(input.actual, 51_200, "format {f}");
    }
}

#[test]
fn psx_pd_013_time_stamp_format_controlled_through_isdu() {
    // PSX-PD-013: with the stamp inactive, ISDU 110 and 112 control the drive.
    let mut s = format(0);
    s.f0(0, 0x3FFF);
    s.write_ok(110, 0x14);
    s.write_ok(112, 60_000);
    assert_eq!(s.run(), "positioning");
    s.settle(60_000);
    assert_eq!(s.actual(), 60_000);
    s.write_ok(110, 0x11);
    s.run_ms(300);
    assert_eq!(s.run(), "manual-forward");
    s.write_ok(110, 0x10);
    s.settle(10_000);
    assert_eq!(s.run(), "none");
}

// ------------------------------------------------------------------ time stamps (4.4)

#[test]
fn psx_ts_002_010_inactive_stamp_then_positioning_sequence() {
    let mut s = format(0);
    s.f0(0, 0x3FFF);
    s.write_ok(112, 60_000);
    // PSX-TS-002: 0x3FFF is no new stamp: the code alone does nothing.
    s.f0(3, 0x3FFF);
    s.run_ms(200);
    assert_eq!(s.run(), "none");
    // PSX-TS-010: code 3 with a stamp, then inactive: the run starts after the delay.
    s.f0(3, 10_000);
    let sent = s.now;
    s.f0(3, 0x3FFF);
    s.until(100, |d| d.run_state() != RunState::Idle);
    assert_eq!(s.now - sent, 40 * MS);
    s.settle(60_000);
    assert_eq!(s.actual(), 60_000);
}

#[test]
fn psx_obst_005_same_target_after_block_in_time_stamp_mode() {
    let mut s = format(0);
    s.f0(0, 0x3FFF);
    s.write_ok(112, 70_000);
    s.f0(3, 0);
    s.f0(3, 0x3FFF);
    s.run_ms(300);
    s.env(EnvChange::Jam { on: true });
    s.until(2000, |d| d.status_word() >> 10 & 1 == 1);
    s.env(EnvChange::Jam { on: false });
    // PSX-OBST-005: code 0 with stamp, inactive, code 3 with stamp, inactive.
    s.f0(0, 0);
    s.f0(0, 0x3FFF);
    s.f0(3, 0);
    s.f0(3, 0x3FFF);
    assert_eq!(s.run(), "positioning");
    s.settle(60_000);
    assert_eq!(s.actual(), 70_000);
}

// ------------------------------------------------------------------ commands (3.1, 4.6)

#[test]
fn psx_cmd_014_isdu_193_zero_and_one() {
    let mut s = Sim::new(MODEL);
    s.write_ok(131, 5);
    // PSX-CMD-014: 0 does nothing, 1 saves.
    s.write_ok(193, 0);
    assert_eq!(s.drive.saved_value("131"), Some(2));
    assert_eq!(s.read(131), 5);
    s.write_ok(193, 1);
    assert_eq!(s.drive.saved_value("131"), Some(5));
}

#[test]
fn psx_cmd_019_format_2_manual_run_with_speed() {
    let mut s = format(2);
    // PSX-CMD-019.
    s.f2(40, 0x11, 0);
    s.run_ms(2000);
    assert_eq!(s.run(), "manual-forward");
    assert_eq!(s.drive.core().speed_rpm(), 40);
    s.f2(40, 0x12, 0);
    s.run_ms(3000);
    assert_eq!(s.run(), "manual-reverse");
    assert_eq!(s.drive.core().speed_rpm(), -40);
}

#[test]
fn psx_start_004_process_data_needs_operate() {
    let mut cfg = DriveConfig::new(MODEL);
    cfg.connected = false;
    let mut s = Sim::with(cfg);
    // PSX-START-004: before OPERATE the process data does not reach the drive.
    s.f1(0x14, 60_000);
    s.run_ms(100);
    assert_eq!(s.run(), "none");
    s.link(LinkEvent::Connected);
    s.f1(0x14, 60_000);
    assert_eq!(s.run(), "positioning");
}

// ------------------------------------------------------------------ torque (5.2, 5.3)

#[test]
fn psx_trq_001_005_torque_phases() {
    let mut s = Sim::new(MODEL);
    let (start, running, stop, hold) = (s.read(152), s.read(153), s.read(154), s.read(155));
    let (start_ms, stop_ms) = (s.read(160) as u64, s.read(161) as u64);
    // PSX-TRQ-005: at standstill the holding torque ISDU 155.
    assert_eq!(s.drive.core().holding_torque(), Some(hold));
    // PSX-TRQ-001: ISDU 152 for ISDU 160 ms after the start, then ISDU 153.
    s.f1(0x14, 90_000);
    s.run_ms(start_ms - 2);
    assert_eq!(s.drive.core().torque_limit(), start);
    s.run_ms(4);
    assert_eq!(s.drive.core().torque_limit(), running);
    // ISDU 154 for ISDU 161 ms after the end of the run.
    s.until(120_000, |d| d.run_state() == RunState::Idle);
    assert_eq!(s.drive.core().holding_torque(), Some(stop));
    s.run_ms(stop_ms + 2);
    assert_eq!(s.drive.core().holding_torque(), Some(hold));
}

#[test]
fn psx_brake_008_no_brake_release_without_a_run() {
    let mut s = Sim::with(
        DriveConfig::new("PSE322-14").with_brake(drivespec_psx3xx::model::BrakeKind::Snap),
    );
    // PSX-BRAKE-008: control words without a run order and ISDU writes leave it closed.
    for word in [0x10, 0x04, 0x0800, 0x0400, 0x4000] {
        s.f1(word, 52_000);
        s.run_ms(100);
        assert!(!s.drive.brake_open(), "control word {word:#06x}");
    }
    s.write_ok(164, 100);
    s.write_ok(136, 5);
    assert!(!s.drive.brake_open());
    s.f1(0x14, 52_000);
    s.run_ms(200);
    assert!(s.drive.brake_open());
}

/// Output images built from the typed form and sent as bytes reach the drive alike.
#[test]
fn typed_and_byte_images_agree() {
    let mut a = Sim::new(MODEL);
    let mut b = Sim::new(MODEL);
    let out = Output::ControlTarget {
        control_word: 0x14,
        target: 55_000,
    };
    a.send(out);
    let bytes = out.to_bytes(a.rules(), a.drive.byte_order()).unwrap();
    b.drive.handle_image(b.now, &bytes).unwrap();
    assert_eq!(a.drive.run_state(), b.drive.run_state());
}

#[test]
fn psx_model_table_delivery_values_per_gearbox_type() {
    // PSX-MODEL-TABLE: ISDU 136, 142-145, 147, 148 and 152-155 take the delivery value of
    // the gearbox type, on every model of the spec.
    for model in &family().models {
        let mut cfg = DriveConfig::new(&model.id);
        if model.attribute("device_model_code").is_none() {
            // PSX-ERRATUM-016: the ISDU 79 code of this type is undocumented.
            cfg.model_code = Some(0);
        }
        let s = Sim::with(cfg);
        for id in [
            "136", "142", "143", "144", "145", "147", "148", "152", "153", "154", "155",
        ] {
            let p = family().parameter(id).unwrap();
            let want = family().resolve(p, Some(model)).default.unwrap();
            assert_eq!(s.read(id.parse().unwrap()), want, "{} ISDU {id}", model.id);
        }
    }
}
