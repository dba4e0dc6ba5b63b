//! Every selectable erratum reading of the PSx3xx spec (`[[erratum]]` with an `option`) on
//! the reference model: the adopted reading gives the adopted behaviour, each other reading
//! its own. The last test checks that no option of the spec is left without a test here.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

mod model_util;

use drivespec_positioner::{ByteOrder, EnvChange};
use drivespec_psx3xx::isdu::Value;
use drivespec_psx3xx::model::{BrakeKind, DriveConfig, JogKeys, LinkEvent, RunState};
use model_util::*;

fn with(model: &str, option: &str, reading: &str) -> Sim {
    Sim::with(DriveConfig::new(model).with_readings(readings(&[(option, reading)])))
}

/// A drive of `model` under `reading` of `option`, switched to process-data format `f`.
fn in_format(model: &str, option: &str, reading: &str, f: i64) -> Sim {
    let mut s = with(model, option, reading);
    s.write_ok(116, f);
    s.write_ok(193, 1);
    s.write_ok(2, 128);
    assert_eq!(i64::from(s.drive.active_format()), f);
    s
}

/// The readings of an option as the spec lists them, the adopted one first.
fn readings_of(option: &str) -> Vec<String> {
    let e = family()
        .errata
        .iter()
        .find(|e| e.option.as_deref() == Some(option))
        .unwrap_or_else(|| panic!("no erratum option {option}"));
    let mut out = vec![e.adopted.clone()];
    out.extend(
        e.readings
            .iter()
            .map(|r| r.id.clone())
            .filter(|r| *r != e.adopted),
    );
    out
}

// ------------------------------------------------------------------ position arithmetic

/// PSX-ERRATUM-056, PSX-POS-009: the 5.6.4 example (5 mm spindle, 0.01 mm resolution): at
/// actual 300,000 the actual value is set to 0. Adopted: ISDU 127 = 0 − 300,000; the other
/// reading prints the manual's +300,000. The user values (actual 0, the example's limits)
/// are the same under both.
#[test]
fn psx_pos_009_erratum_056_referencing_value_sign() {
    for (reading, want) in [
        ("written-minus-physical", -300_000),
        ("physical-minus-written", 300_000),
    ] {
        // 300,000 steps at 400/5000 are 24,000 base steps.
        let cfg = DriveConfig::new("PSE312-8")
            .with_start_position(24_000)
            .with_readings(readings(&[("psx-ref-sign", reading)]));
        let mut s = Sim::with(cfg);
        s.write_ok(124, 400);
        s.write_ok(125, 5000);
        assert_eq!(s.read(67), 300_000, "{reading}");
        s.write_ok(67, 0);
        assert_eq!((s.read(67), s.read(127)), (0, want), "{reading}");
        // 5.6.4: 10 revolutions below and 240 above the new zero.
        s.write_ok(128, 1_215_000);
        s.write_ok(130, -50_000);
        s.write_ok(129, 1_200_000);
        assert_eq!(
            (s.read(129), s.read(130)),
            (1_200_000, -50_000),
            "{reading}"
        );
        // Writing the value read back changes nothing; writing 0 undoes the shift.
        s.write_ok(127, want);
        assert_eq!(s.read(67), 0, "{reading}");
        s.write_ok(127, 0);
        assert_eq!(s.read(67), 300_000, "{reading}");
        // The EEPROM keeps ISDU 127 as read, and a restart shows it again.
        s.write_ok(127, want);
        s.write_ok(193, 1);
        s.write_ok(2, 128);
        assert_eq!(s.drive.saved_value("127"), Some(want), "{reading}");
        assert_eq!((s.read(127), s.read(67)), (want, 0), "{reading}");
    }
}

// ------------------------------------------------------------------ measurements

/// PSX-ERRATUM-011, PSX-ISDU-65-UNIT, PSX-ISDU-72-UNIT: speed toward smaller values and a
/// temperature below 0 °C are negative under the adopted "signed" reading; "unsigned" gives
/// the speed's magnitude (ISDU 65 and the input image) and 0 °C.
#[test]
fn psx_isdu_65_72_erratum_011_signed_measurements() {
    for (reading, signed) in [("signed", true), ("unsigned", false)] {
        let mut s = with("PSE312-8", "psx-signed-measurements", reading);
        s.f1(0x14, 30_000);
        s.run_ms(1500);
        let rpm = s.drive.core().speed_rpm();
        assert!(rpm < 0, "runs toward smaller values");
        let want = if signed { rpm } else { -rpm };
        assert_eq!(s.read(65), want, "{reading}");
        assert_eq!(i64::from(s.drive.input().rpm), want, "{reading}");
        s.env(EnvChange::Temperature { celsius: -12 });
        assert_eq!(s.read(72), if signed { -12 } else { 0 }, "{reading}");
        s.env(EnvChange::Temperature { celsius: 31 });
        assert_eq!(s.read(72), 31, "{reading}: positive values read the same");
    }
}

/// PSX-ERRATUM-010, PSX-STS-1-SET-1, PSX-STS-1-SET-2: a short jam after the top speed was
/// reached leaves the run behind its computed position. "both" and "position" set bit 1;
/// "speed" only looks at the top speed, which was reached, and does not. A jam during the
/// acceleration tells "position" apart.
#[test]
fn psx_sts_1_erratum_010_drag_error_rule() {
    for reading in readings_of("psx-drag-error-rule") {
        let mut s = with("PSE312-8", "psx-drag-error-rule", &reading);
        s.f1(0x14, 90000);
        s.run_ms(1000);
        s.env(EnvChange::Jam { on: true });
        s.run_ms(60);
        s.env(EnvChange::Jam { on: false });
        assert_eq!(s.bit(1), reading != "speed", "{reading}");
        // A short jam during the acceleration with the largest ISDU 133: the top speed is
        // missed, the position difference stays small. "both" and "speed" set bit 1,
        // "position" does not.
        let mut s = with("PSE312-8", "psx-drag-error-rule", &reading);
        s.write_ok(133, 1000);
        s.f1(0x14, 90000);
        s.run_ms(40);
        s.env(EnvChange::Jam { on: true });
        s.run_ms(30);
        s.env(EnvChange::Jam { on: false });
        s.run_ms(2000);
        assert_eq!(
            s.bit(1),
            reading != "position",
            "{reading}: during acceleration"
        );
    }
}

/// PSX-ERRATUM-015, PSX-ERRATUM-063, PSX-TRQ-003: the 5.2 example on a PSE335: at 85 rpm
/// ISDU 153 may reach 400 × 100 / 85 = 470.6, truncated (adopted) or rounded.
#[test]
fn psx_trq_003_erratum_063_torque_rounding() {
    for (reading, bound) in [("truncate", 470), ("round", 471)] {
        let mut s = with("PSE335-14", "psx-torque-rounding", reading);
        s.write_ok(142, 85);
        s.write_ok(145, 85);
        s.write_ok(153, bound);
        assert_ne!(
            s.write(153, bound + 1),
            drivespec_psx3xx::isdu::Response::Write,
            "{reading}"
        );
    }
}

// ------------------------------------------------------------------ process data

/// PSX-ERRATUM-050, PSX-PD-008: big-endian (adopted) puts status bits 8–15 into byte 0;
/// "little-endian" bits 0–7.
#[test]
fn psx_pd_008_erratum_050_byte_order() {
    for (reading, order) in [
        ("big-endian", ByteOrder::BigEndian),
        ("little-endian", ByteOrder::LittleEndian),
    ] {
        let s = with("PSE312-8", "psx-pd-byte-order", reading);
        assert_eq!(s.drive.byte_order(), order);
        let status = s.status().to_be_bytes();
        let image = s.drive.input_image();
        let want = match order {
            ByteOrder::BigEndian => [status[0], status[1]],
            ByteOrder::LittleEndian => [status[1], status[0]],
        };
        assert_eq!(&image[..2], &want, "{reading}");
    }
}

/// The format 0 word with `code` and `stamp` placed as `reading` of PSX-ERRATUM-051 says.
fn stamp_word(reading: &str, code: u16, stamp: u16) -> [u8; 2] {
    let word = if reading == "high-bits" {
        code << 14 | stamp
    } else {
        stamp << 2 | code
    };
    word.to_be_bytes()
}

/// PSX-ERRATUM-051, PSX-PD-002: code 3 with a stamp below 2000 starts the run on reception
/// when the bytes carry it where the reading puts it; the other layout means something else.
#[test]
fn psx_pd_002_erratum_051_time_stamp_bit_layout() {
    for reading in ["low-bits", "high-bits"] {
        let mut s = in_format("PSE312-8", "psx-ts-bit-layout", reading, 0);
        let inactive = stamp_word(reading, 0, 0x3FFF);
        s.drive.handle_image(s.now, &inactive).unwrap();
        s.write_ok(112, 60000);
        s.drive
            .handle_image(s.now, &stamp_word(reading, 3, 100))
            .unwrap();
        assert_eq!(s.run(), "positioning", "{reading}");
        s.drive.handle_image(s.now, &inactive).unwrap();
        s.settle(60_000);
        assert_eq!(s.actual(), 60000, "{reading}");
        // The same bytes read with the other layout: code 0 (no run) with another stamp.
        let other = if reading == "low-bits" {
            "high-bits"
        } else {
            "low-bits"
        };
        s.drive
            .handle_image(s.now, &stamp_word(other, 3, 100))
            .unwrap();
        s.run_ms(100);
        assert_eq!(s.run(), "none", "{reading}");
    }
}

/// PSX-ERRATUM-009, PSX-DP-005: ProcessDataOut (ISDU 0 sub 7) follows the active format
/// (adopted) or always reads 16.
#[test]
fn psx_dp_005_erratum_009_process_data_out_length() {
    for (reading, want) in [("format-dependent", 0x85), ("fixed-16", 16)] {
        let s = with("PSE312-8", "psx-pd-out-length", reading);
        assert_eq!(s.drive.active_format(), 1);
        assert_eq!(s.drive.read(0, 7).unwrap(), Value::Int(want), "{reading}");
    }
}

// ------------------------------------------------------------------ time stamps

/// PSX-ERRATUM-054, PSX-PD-011: code 3 stands for control word 0x14 (adopted) or for the
/// release bit 4 alone, the target being taken from the ISDU 112 write (4.4.4). The
/// control word the drive acts on (ISDU 110) shows which.
#[test]
fn psx_pd_011_erratum_054_control_code_3() {
    for (reading, bits) in [("release-and-transfer", 0x14), ("release-only", 0x10)] {
        let mut s = in_format("PSE312-8", "psx-ts-code3", reading, 0);
        s.f0(0, 0x3FFF);
        s.write_ok(112, 60000);
        s.f0(3, 0);
        assert_eq!(s.read(110) & 0x14, bits, "{reading}");
        s.settle(60_000);
        assert_eq!(s.actual(), 60000, "{reading}");
    }
}

/// PSX-ERRATUM-061, PSX-TS-009: a reserved stamp value (16370) after a pending stamp:
/// ignored (adopted), fires it as the inactive marker, or replaces it as 16368.
#[test]
fn psx_ts_009_erratum_061_reserved_stamp_values() {
    for reading in readings_of("psx-ts-reserved") {
        let mut s = in_format("PSE312-8", "psx-ts-reserved", &reading, 0);
        s.f0(0, 0x3FFF);
        s.write_ok(112, 60000);
        s.f0(3, 10000);
        let sent = s.now;
        s.f0(3, 16370);
        // The master sends each telegram once.
        s.out = None;
        s.run_ms(50);
        let started = s.run() == "positioning";
        assert_eq!(started, reading == "as-inactive", "{reading}");
        if !started {
            s.f0(3, 0x3FFF);
            let t = s.until(200, |d| d.run_state() != RunState::Idle);
            // "clamped": the reserved value replaced the stamp by 16368 × 4 µs, from its
            // own reception (checked to the millisecond the test steps by); "ignored": the
            // 40 ms of the pending stamp are over.
            if reading == "clamped" {
                let want = (16368 * 4u64).div_ceil(MS) * MS;
                assert_eq!(s.now - sent, want, "{reading}: after {t} ms");
            } else {
                assert_eq!(t, 0, "{reading}");
            }
        }
    }
}

/// PSX-ERRATUM-064, PSX-TS-005: the delay of a stamp counts from the telegram carrying it
/// (adopted) or from the first inactive marker.
#[test]
fn psx_ts_005_erratum_064_delay_reference() {
    for (reading, from_stamp) in [("last-stamp", true), ("inactive-marker", false)] {
        let mut s = in_format("PSE312-8", "psx-ts-reference", reading, 0);
        s.f0(0, 0x3FFF);
        s.write_ok(112, 60000);
        s.f0(3, 10000);
        let stamped = s.now;
        // The master sends the stamp once, then nothing until the marker.
        s.out = None;
        s.run_ms(24);
        let marker = s.now;
        s.f0(3, 0x3FFF);
        s.until(100, |d| d.run_state() != RunState::Idle);
        let from = if from_stamp { stamped } else { marker };
        assert_eq!(s.now - from, 40 * MS, "{reading}");
    }
}

// ------------------------------------------------------------------ status bits, commands

/// PSX-ERRATUM-024, PSX-STS-5-SET-1: withdrawing the release of a manual run sets bit 5
/// under "any-run" (adopted), not under "positioning-only".
#[test]
fn psx_sts_5_erratum_024_manual_run_abort() {
    for (reading, set) in [("any-run", true), ("positioning-only", false)] {
        let mut s = with("PSE312-8", "psx-sts5-manual-abort", reading);
        s.f1(0x11, 0);
        s.run_ms(500);
        assert_eq!(s.run(), "manual-forward");
        s.f1(0x00, 0);
        s.settle(10_000);
        assert_eq!(s.bit(5), set, "{reading}");
    }
}

/// PSX-ERRATUM-059, PSX-CMD-011: ISDU 2 = 130 restores the delivery state without moving
/// (adopted "like-193-2") or with the initial reference loop and the run to mid-range.
#[test]
fn psx_cmd_011_erratum_059_restore_factory_command() {
    for (reading, moves) in [("like-193-2", false), ("like-193-minus-2", true)] {
        let cfg = DriveConfig::new("PSE312-8")
            .with_start_position(30_000)
            .with_readings(readings(&[("psx-cmd-130", reading)]));
        let mut s = Sim::with(cfg);
        s.write_ok(131, 5);
        s.f1(0x10, 0);
        s.write_ok(2, 130);
        assert_eq!((s.read(131), s.read(116)), (2, 1), "{reading}");
        if moves {
            assert_eq!(s.run(), "reference-loop", "{reading}");
            s.settle(120_000);
            assert_eq!(s.actual(), 51_200, "{reading}");
        } else {
            s.run_ms(500);
            assert_eq!((s.run(), s.actual()), ("none", 30_000), "{reading}");
        }
    }
}

/// PSX-ERRATUM-022, PSX-ISDU-19-TEXT: ISDU 19 of a PSS names its series (adopted) or reads
/// "PSE".
#[test]
fn psx_isdu_19_erratum_022_product_id() {
    for (reading, want) in [("series", "PSS"), ("literal", "PSE")] {
        let s = with("PSS335-14", "psx-product-id", reading);
        assert_eq!(
            s.drive.read(19, 0).unwrap(),
            Value::Text(want.to_owned()),
            "{reading}"
        );
    }
}

/// PSX-ERRATUM-017, PSX-JOG-006: the continuous jog starts ISDU 163 × 5 ms after the key
/// (adopted) or ISDU 163 ms after it.
#[test]
fn psx_jog_006_erratum_017_five_ms_steps() {
    for (reading, factor) in [("5ms-steps", 5), ("ms", 1)] {
        let mut s = with("PSE312-8", "psx-5ms-steps", reading);
        s.link(LinkEvent::Lost);
        let wait = s.read(163) as u64 * factor;
        s.keys(JogKeys::FORWARD);
        let t = s.until(wait + 100, |d| d.run_state().name() == "jog-continuous");
        assert!(t.abs_diff(wait) <= 8, "{reading}: {t} ms, want {wait}");
    }
}

/// PSX-ERRATUM-057, PSX-BRAKE-003, PSX-CTL-11-1: a snap-brake run without control bit 11
/// waits ISDU 164 and runs no breaking-free steps (adopted), or runs them on every run.
#[test]
fn psx_brake_003_erratum_057_breaking_free_run() {
    for (reading, steps) in [("wait-always-steps-with-bit-11", false), ("always", true)] {
        let cfg = DriveConfig::new("PSE322-14")
            .with_brake(BrakeKind::Snap)
            .with_readings(readings(&[("psx-brake-free-run", reading)]));
        let mut s = Sim::with(cfg);
        s.record = true;
        s.f1(0x14, 52000);
        assert_eq!(s.drive.run_state(), RunState::BrakeWait, "{reading}");
        s.settle(60_000);
        let min = s.trace.iter().map(|x| x.actual).min().unwrap();
        let n = s.read(136);
        assert_eq!(min, if steps { 51200 - n } else { 51200 }, "{reading}");
        assert_eq!(s.actual(), 52000, "{reading}");
    }
}

/// PSX-ERRATUM-004, PSX-GUARD-ONESHOT, PSX-GUARD-126-SUPPRESS: after ISDU 126 = 0 and a write
/// of another entry, ISDU 127 is written under "one-shot" (adopted), suppressed under
/// "next-target-write" and "persistent".
#[test]
fn psx_guard_oneshot_erratum_004_guard_semantics() {
    for reading in readings_of("psx-guard-semantics") {
        let mut s = with("PSE312-8", "psx-guard-semantics", &reading);
        s.write_ok(126, 0);
        s.write_ok(131, 3);
        s.write_ok(127, 100);
        let written = s.read(127) == 100;
        assert_eq!(written, reading == "one-shot", "{reading}");
    }
}

/// PSX-ERRATUM-015, PSX-ISDU-153-RANGE: at reduced speed ISDU 153 may exceed the table's
/// maximum (adopted) or never does.
#[test]
fn psx_isdu_153_range_erratum_015_torque_extension() {
    for (reading, extended) in [("speed-dependent", true), ("table", false)] {
        let mut s = with("PSE335-14", "psx-torque-speed-extension", reading);
        s.write_ok(142, 85);
        s.write_ok(145, 85);
        let accepted = s.write(153, 450) == drivespec_psx3xx::isdu::Response::Write;
        assert_eq!(accepted, extended, "{reading}");
    }
}

/// PSX-ERRATUM-052, PSX-TS-006: a stamp below 2000 fires on reception (adopted) or waits for
/// the inactive marker.
#[test]
fn psx_ts_006_erratum_052_immediate_stamps() {
    for (reading, at_once) in [("on-reception", true), ("after-inactive", false)] {
        let mut s = in_format("PSE312-8", "psx-ts-immediate", reading, 0);
        s.f0(0, 0x3FFF);
        s.write_ok(112, 60000);
        s.f0(3, 1999);
        assert_eq!(s.run() == "positioning", at_once, "{reading}");
        s.f0(3, 0x3FFF);
        s.run_ms(9);
        assert_eq!(s.run(), "positioning", "{reading}");
    }
}

/// Every option of the spec's PSx3xx errata has a test in this file, named by its option.
#[test]
fn every_erratum_option_has_a_test_here() {
    let me = include_str!("model_errata.rs");
    let tested = [
        "psx-ref-sign",
        "psx-signed-measurements",
        "psx-drag-error-rule",
        "psx-torque-rounding",
        "psx-pd-byte-order",
        "psx-ts-bit-layout",
        "psx-pd-out-length",
        "psx-ts-code3",
        "psx-ts-reserved",
        "psx-ts-reference",
        "psx-sts5-manual-abort",
        "psx-cmd-130",
        "psx-product-id",
        "psx-5ms-steps",
        "psx-brake-free-run",
        "psx-guard-semantics",
        "psx-torque-speed-extension",
        "psx-ts-immediate",
    ];
    for e in &family().errata {
        let Some(option) = e.option.as_deref() else {
            continue;
        };
        assert!(tested.contains(&option), "option {option} has no test");
        let used = me.matches(&format!("\"{option}\"")).count();
        assert!(used >= 2, "option {option} is not exercised");
        // Each reading of the option can be chosen.
        for r in &e.readings {
            readings(&[(option, r.id.as_str())]);
        }
    }
}
