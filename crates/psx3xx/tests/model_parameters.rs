//! The ISDU server of the PSx3xx reference model (manual 3.1, 3.2, 5.5–5.7): ErrorTypes, the
//! state-dependent ranges, guard entries, ISDU 2 / 193 with the EEPROM image apart from the
//! working values, the process-data format switch and device ID, identification entries, and
//! the status bits of supply, temperature and limits (3.4). Each test names its requirement IDs.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

mod model_util;

use drivespec_positioner::EnvChange;
use drivespec_psx3xx::isdu::{Request, Response, Value};
use drivespec_psx3xx::model::DriveConfig;
use drivespec_psx3xx::ErrorType;
use model_util::*;

fn error(r: Response) -> u16 {
    match r {
        Response::Error {
            error: ErrorType(e),
        } => e,
        other => panic!("expected an error, got {other:?}"),
    }
}

fn raw(s: &mut Sim, index: u16, subindex: u8, data: &[u8]) -> Response {
    s.drive.handle_isdu(
        s.now,
        Request::Write {
            index,
            subindex,
            data: data.to_vec(),
        },
    );
    let mut last = None;
    while let Some(a) = s.drive.poll_isdu() {
        last = Some(a.response);
    }
    last.unwrap()
}

#[test]
fn psx_dp_err_001_to_007_error_types() {
    let mut s = Sim::new("PSE312-8");
    // PSX-DP-ERR-001.
    assert_eq!(error(raw(&mut s, 1, 0, &[0])), 0x8011);
    // PSX-DP-ERR-002.
    assert_eq!(error(raw(&mut s, 0, 17, &[0])), 0x8012);
    // PSX-DP-ERR-003: read-only, nothing changes.
    assert_eq!(error(s.write(64, 0)), 0x8023);
    // PSX-DP-ERR-004: out of range, the value is kept (PSX-ISDU-131-RANGE).
    assert_eq!(error(s.write(131, 0)), 0x8030);
    assert_eq!(s.read(131), 2);
    // PSX-DP-ERR-005.
    assert_eq!(error(s.write(2, 129)), 0x8035);
    // PSX-DP-ERR-006.
    assert_eq!(error(raw(&mut s, 131, 0, &[0, 0, 5])), 0x8033);
    assert_eq!(error(raw(&mut s, 131, 0, &[5])), 0x8034);
    // PSX-DP-ERR-007: ISDU 2 is write-only.
    while s.drive.poll_isdu().is_some() {}
    s.drive.handle_isdu(
        s.now,
        Request::Read {
            index: 2,
            subindex: 0,
        },
    );
    assert_eq!(error(s.drive.poll_isdu().unwrap().response), 0x8023);
    // PSX-ISDU-193-RANGE, PSX-ISDU-137-RANGE (PSX-TIMEOUT-007: 0 reserved).
    assert_eq!(error(s.write(193, 4)), 0x8030);
    assert_eq!(error(s.write(137, 0)), 0x8030);
}

#[test]
fn psx_dp_err_008_write_lock() {
    let mut s = Sim::new("PSE312-8");
    s.write_ok(12, 1);
    assert_eq!(error(s.write(131, 3)), 0x8023);
    // ISDU 12 itself stays writable.
    s.write_ok(12, 0);
    s.write_ok(131, 3);
}

#[test]
fn psx_map_002_003_004_005_mapping_end_and_limits_depend_on_the_state() {
    let mut s = Sim::new("PSE312-8");
    // value-inconsistent: 0x8030 adopted.
    assert_eq!(error(s.write(128, 152_500)), 0x8030);
    assert_eq!(s.read(129), 101_200);
    s.write_ok(128, 152_400);
    // PSX-POS-006: the limits follow the mapping end.
    assert_eq!((s.read(130), s.read(129)), (51_200, 151_200));
    // PSX-MAP-005: limits can only be narrowed.
    assert_eq!(error(s.write(129, 151_201)), 0x8030);
    s.write_ok(129, 100_000);
    assert_eq!(s.read(129), 100_000);
}

#[test]
fn psx_isdu_131_scale_window_and_loop_ranges_follow_the_resolution() {
    let mut s = Sim::new("PSE312-8");
    // PSX-ISDU-131-SCALE.
    assert_eq!(error(s.write(131, 101)), 0x8030);
    s.write_ok(125, 5000);
    // PSX-POS-007: window 2 -> 25, loop 250 -> 3125.
    assert_eq!((s.read(131), s.read(132)), (25, 3125));
    s.write_ok(131, 1250);
    assert_eq!(error(s.write(131, 1251)), 0x8030);
    s.write_ok(132, 5000);
    assert_eq!(error(s.write(132, 5001)), 0x8030);
    // PSX-ISDU-132-ZERO.
    s.write_ok(132, 0);
}

#[test]
fn psx_trq_003_running_torque_above_the_table_at_reduced_speed() {
    let mut s = Sim::new("PSE335-14");
    let table_max = 400;
    // At the model's top speed (100 rpm) the table holds.
    s.write_ok(142, 100);
    assert_eq!(error(s.write(153, table_max + 1)), 0x8030);
    s.write_ok(142, 85);
    // PSX-ERRATUM-063 "truncate": 400 x 100 / 85 = 470.
    s.write_ok(153, 470);
    assert_eq!(error(s.write(153, 471)), 0x8030);
    // PSX-ERRATUM-015 reading "table".
    let cfg = DriveConfig::new("PSE335-14")
        .with_readings(readings(&[("psx-torque-speed-extension", "table")]));
    let mut t = Sim::with(cfg);
    assert_eq!(error(t.write(153, 401)), 0x8030);
}

#[test]
fn psx_model_table_per_model_ranges_and_defaults() {
    let s = Sim::new("PSE335-14");
    assert_eq!((s.read(142), s.read(145)), (85, 40));
    let mut w = Sim::new("PSE301-8");
    assert_eq!(w.read(142), 230);
    // PSX-ISDU-142-RANGE.
    assert_eq!(error(w.write(142, 231)), 0x8030);
    assert_eq!(error(w.write(142, 14)), 0x8030);
    // PSX-MODEL-146.
    assert_eq!(Sim::new("PSE3110-14").read(146), 60);
    assert_eq!(w.read(146), 30);
}

#[test]
fn psx_pd_010_dp_005_007_008_format_switch_after_save_and_reset() {
    let mut s = Sim::new("PSE312-8");
    assert_eq!(s.drive.device_id(), Some(3_120_802));
    assert_eq!(s.drive.read(0, 7).unwrap(), Value::Int(0x85));
    s.write_ok(116, 0);
    // Not active yet, and a reset without a save loses it (PSX-CMD-018).
    s.write_ok(2, 128);
    assert_eq!(s.drive.active_format(), 1);
    assert_eq!(s.read(116), 1);
    s.write_ok(116, 0);
    s.write_ok(2, 161);
    assert_eq!(s.drive.active_format(), 1);
    s.write_ok(2, 128);
    assert_eq!(s.drive.active_format(), 0);
    assert_eq!(s.drive.device_id(), Some(3_120_801));
    assert_eq!(s.drive.read(0, 7).unwrap(), Value::Int(0x10));
    // A format 1 image is now refused.
    assert!(s
        .drive
        .handle_output(
            s.now,
            &drivespec_psx3xx::Output::ControlTarget {
                control_word: 0x14,
                target: 0
            }
        )
        .is_err());
}

#[test]
fn psx_pd_005_format_2_needs_software_249() {
    let mut s = Sim::with(DriveConfig::new("PSE312-8").with_software(248));
    assert_eq!(error(s.write(116, 2)), 0x8030);
    // PSX-VER-CLEAR: bit 14 is reserved before 249.
    assert_eq!(error(s.write(110, 0x4000)), 0x8030);
    s.write_ok(116, 0);
}

#[test]
fn psx_cmd_014_017_018_par_saved_eeprom_apart_from_working_values() {
    let mut s = Sim::new("PSE312-8");
    s.write_ok(131, 5);
    s.write_ok(171, 1234);
    assert_eq!(s.drive.saved_value("131"), Some(2));
    // PSX-PAR-SAVED.
    s.write_ok(193, 1);
    // PSX-CMD-017 (DECISION: the save takes no virtual time).
    assert_eq!(s.read(193), 0);
    assert_eq!(s.drive.saved_value("131"), Some(5));
    s.write_ok(131, 7);
    s.write_ok(110, 0x04);
    s.write_ok(112, 60000);
    s.drive.power_cycle(s.now);
    assert_eq!((s.read(131), s.read(171)), (5, 1234));
    // PSX-CMD-016: 0 after booting with a correct EEPROM; PSX-ISDU-112-DEFAULT.
    assert_eq!((s.read(193), s.read(110), s.read(112)), (0, 0, 0));
    // PSX-PAR-NOT-SAVED.
    for id in ["66", "67", "109", "110", "111", "112", "126", "193"] {
        assert_eq!(s.drive.saved_value(id), None, "ISDU {id}");
    }
}

#[test]
fn psx_cmd_011_015_delivery_state_commands() {
    let mut s = Sim::new("PSE312-8");
    s.write_ok(116, 0);
    s.write_ok(131, 5);
    s.write_ok(193, 1);
    s.write_ok(2, 128);
    // 193 = 3: defaults keeping the format (PSX-PAR-DEFAULTS).
    s.write_ok(131, 5);
    s.write_ok(193, 3);
    assert_eq!((s.read(131), s.read(116)), (2, 0));
    assert_eq!(s.drive.saved_value("131"), Some(2));
    // 160: the same through ISDU 2.
    s.write_ok(131, 5);
    s.write_ok(2, 160);
    assert_eq!((s.read(131), s.read(116)), (2, 0));
    // 130 (PSX-ERRATUM-059 "like-193-2"): format 1 too, no movement.
    s.write_ok(2, 130);
    assert_eq!(s.read(116), 1);
    assert_eq!(s.run(), "none");
    assert_eq!(s.drive.active_format(), 0);
    // 193 = 2.
    s.write_ok(131, 5);
    s.write_ok(193, 2);
    assert_eq!((s.read(131), s.drive.saved_value("116")), (2, Some(1)));
}

#[test]
fn psx_cmd_012_013_isdu_193_midrange_after_reference_loop() {
    let mut s = Sim::with(DriveConfig::new("PSE312-8").with_start_position(30_000));
    s.write_ok(131, 5);
    s.f1(0x10, 0);
    s.write_ok(193, -1);
    assert_eq!(s.read(131), 2);
    assert_eq!(s.run(), "reference-loop");
    s.until(60_000, |d| d.run_state().name() == "centre");
    s.settle(120_000);
    // PSX-ISDU-193-MIDRANGE.
    assert_eq!(s.actual(), 51_200);
}

#[test]
fn psx_isdu_16_to_24_identification() {
    let mut cfg = DriveConfig::new("PSS335-14");
    cfg.serial_number = 42;
    cfg.production_date = 2412;
    let mut s = Sim::with(cfg);
    let text = |s: &Sim, i: u16| match s.drive.read(i, 0).unwrap() {
        Value::Text(t) => t,
        v => panic!("{v:?}"),
    };
    assert_eq!(text(&s, 16), "halstrup-walcher GmbH");
    assert_eq!(text(&s, 17), "www.hwg.eu");
    // PSX-ISDU-18-TEXT.
    assert_eq!(text(&s, 18), "PSS335-14-IO");
    // PSX-ISDU-19-TEXT (PSX-ERRATUM-022 "series").
    assert_eq!(text(&s, 19), "PSS");
    assert_eq!(text(&s, 20), "Positioning system");
    // PSX-ISDU-21-TEXT.
    assert_eq!(text(&s, 21), "00042");
    // PSX-ISDU-24-DEFAULT, PSX-ISDU-24-LENGTH.
    assert_eq!(text(&s, 24), "");
    assert_eq!(
        s.drive
            .write(s.now, 24, 0, &Value::Text("axis 7".into()))
            .unwrap(),
        Response::Write
    );
    assert_eq!(text(&s, 24), "axis 7");
    assert_ne!(
        s.drive
            .write(s.now, 24, 0, &Value::Text("x".repeat(17)))
            .unwrap(),
        Response::Write
    );
    assert_eq!((s.read(77), s.read(78)), (2412, 42));
    // PSX-ISDU-79-CODES, PSX-ISDU-80-VERSION.
    assert_eq!(s.read(79), 335);
    assert_eq!(s.read(80), 249);
}

#[test]
fn psx_guard_persistent_reading() {
    let cfg = DriveConfig::new("PSE312-8")
        .with_readings(readings(&[("psx-guard-semantics", "persistent")]));
    let mut s = Sim::with(cfg);
    s.write_ok(126, 0);
    s.write_ok(131, 3);
    s.write_ok(127, 1000);
    assert_eq!(s.read(127), 0);
    s.write_ok(126, 1);
    s.write_ok(127, 1000);
    assert_eq!(s.read(127), 1000);
}

#[test]
fn psx_sts_4_13_motor_voltage_bits() {
    let mut s = Sim::new("PSE312-8");
    // PSX-STS-4-SET-1: 24 V lies between ISDU 181 and 30 V.
    assert!(s.bit(4));
    s.env(EnvChange::MotorVoltage { dv: 170 });
    s.run_ms(1000);
    // PSX-STS-4-RESET-1, PSX-ISDU-181-BIT4.
    assert!(!s.bit(4));
    // PSX-STS-13-SET-1: a positioning ordered without motor power.
    s.f1(0x14, 60000);
    assert!(s.bit(13));
    assert_eq!(s.run(), "none");
    s.env(EnvChange::MotorVoltage { dv: 240 });
    s.run_ms(1000);
    s.f1(0x00, 60000);
    s.f1(0x14, 60000);
    // PSX-STS-13-RESET-1.
    assert!(!s.bit(13));
    s.run_ms(500);
    // PSX-STS-13-SET-2: the voltage leaves the corridor during the run.
    s.env(EnvChange::MotorVoltage { dv: 310 });
    s.run_ms(1000);
    assert!(s.bit(13));
    assert_eq!(s.run(), "none");
}

#[test]
fn psx_sts_7_temperature_with_hysteresis() {
    let mut s = Sim::new("PSE312-8");
    let limit = s.read(182) as i16;
    s.env(EnvChange::Temperature { celsius: limit + 1 });
    // PSX-STS-7-SET-1, PSX-ISDU-72-UNIT.
    assert!(s.bit(7));
    assert_eq!(s.read(72), i64::from(limit + 1));
    // PSX-STS-7-RESET-1 (PSX-ERRATUM-001): only 5 °C below the limit.
    s.env(EnvChange::Temperature { celsius: limit - 5 });
    assert!(s.bit(7));
    s.env(EnvChange::Temperature { celsius: limit - 6 });
    assert!(!s.bit(7));
}

#[test]
fn psx_sts_14_15_limits() {
    let mut s = Sim::new("PSE312-8");
    // PSX-STS-14-SET-2: the limit moved past the position.
    s.write_ok(129, 50_000);
    assert!(s.bit(14));
    s.write_ok(129, 101_200);
    // PSX-STS-15-SET-3: pushed beyond the lower limit at standstill.
    s.write_ok(130, 51_100);
    s.env(EnvChange::Displace { by: -200 });
    assert!(s.bit(15));
    // PSX-STS-15-RESET-1: a positioning run starts.
    s.f1(0x54, 60_000);
    assert!(!s.bit(15));
    s.settle(60_000);
    // PSX-STS-15-SET-1: a manual run reaches the lower limit; PSX-STS-14-RESET-1 at the
    // start of a positioning run.
    s.f1(0x12, 60_000);
    s.until(120_000, |d| {
        d.core().kinematics().vel == 0.0 && d.core().actual() == 51_100
    });
    assert!(s.bit(15));
    s.f1(0x10, 60_000);
    s.write_ok(129, 51_100);
    assert!(!s.bit(14));
    s.write_ok(129, 51_000);
    assert!(s.bit(14));
    s.write_ok(129, 101_200);
    s.f1(0x14, 60_500);
    assert_eq!(s.run(), "positioning");
    assert!(!s.bit(14) && !s.bit(15));
}

#[test]
fn psx_isdu_measurements() {
    let mut s = Sim::new("PSE312-8");
    // PSX-ISDU-70-UNIT: 0.1 V.
    assert_eq!((s.read(70), s.read(71)), (240, 240));
    // PSX-ISDU-166-FILTER: averaged over ISDU 166 x 5 ms (PSX-ERRATUM-017).
    s.write_ok(166, 200);
    s.run_ms(2000);
    s.env(EnvChange::MotorVoltage { dv: 200 });
    s.run_ms(500);
    let mid = s.read(71);
    assert!(mid > 200 && mid < 240, "{mid}");
    s.run_ms(600);
    assert_eq!(s.read(71), 200);
    // PSX-ISDU-65-UNIT, PSX-ISDU-68-UNIT, PSX-ISDU-69-PHASES.
    s.env(EnvChange::LoadTorque { cnm: 20 });
    s.f1(0x14, 70_000);
    s.run_ms(2000);
    assert_eq!(s.read(65), s.drive.core().speed_rpm());
    assert!(s.read(65) > 0);
    assert_eq!(s.read(68), 20);
    assert_eq!(s.read(69), 20);
}

#[test]
fn psx_sts_9_set_2_missed_target_is_an_encoder_deviation() {
    let mut s = Sim::new("PSE312-8");
    s.env(EnvChange::MissSteps { by: 30 });
    s.f1(0x14, 60_000);
    s.settle(60_000);
    assert!(s.bit(9) && !s.bit(0) && !s.bit(10));
}

#[test]
fn psx_ctl_13_15_reserved_control_bits() {
    let mut s = Sim::new("PSE312-8");
    // PSX-CTL-13-1, PSX-CTL-15-1.
    // ISDU 110 with bit 13: reserved-bits-set, 0x8030 adopted.
    assert_eq!(error(s.write(110, 0x2010)), 0x8030);
    // In the process data: an invalid combination cancels the run (bit 5).
    s.f1(0x14, 60_000);
    s.run_ms(200);
    s.f1(0x8014, 60_000);
    assert!(s.bit(5));
    assert_eq!(s.run(), "none");
}

#[test]
fn psx_dp_009_direct_parameters_through_isdu_0() {
    let mut s = Sim::new("PSE312-8");
    // PSX-DP-001 … PSX-DP-006 (PSX-DP-002 sub 4, PSX-DP-003 sub 5, PSX-DP-004 sub 6),
    // PSX-ISDU-0-RESERVED.
    for (sub, want) in [
        (3, 0x44),
        (4, 0x2B),
        (5, 0x11),
        (6, 0x87),
        (8, 0x02),
        (9, 0xD8),
        (13, 0),
    ] {
        assert_eq!(s.drive.read(0, sub).unwrap(), Value::Int(want), "sub {sub}");
    }
    // Sub 16 takes the standard commands (PSX-DP-ERR-005).
    assert_eq!(error(raw(&mut s, 0, 16, &[129])), 0x8035);
    assert_eq!(raw(&mut s, 0, 16, &[161]), Response::Write);
}
