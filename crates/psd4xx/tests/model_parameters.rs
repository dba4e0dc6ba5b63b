//! Parameters, the PKW server, records and par. 96 on the reference model (manual 3.2.2, 3.3,
//! 3.4, 3.8, 4.7, 4.8): ranges per model, write conditions, the recalculation cascades of 4.7,
//! the EEPROM image apart from the working values, and the commands of par. 96. Each test
//! names the requirements it covers.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_positioner::machine::{CoreEvent, RunKind};
use drivespec_psd4xx::model::{DriveConfig, Event, RecordAnswer, RecordFailure, RecordRequest};
use drivespec_psd4xx::{PkwRequest, Request, Width};
use drivespec_spec::{Access, DataType};
use model_util::*;

const MODEL: &str = "PSD401-5V";

fn go(s: &mut Sim, target: i32) {
    s.send(0x14, target);
    s.wait_idle();
}

// ---------------------------------------------------------------- ranges and access

/// Every writable parameter with a static range accepts its ends and refuses one beyond, with
/// the model's own ranges, and reads its delivery value after power-up (PSD-PAR-RANGE-001,
/// PSD-PKW-025, PSD-PAR-MODEL-001, PSD-MODEL-P53, PSD-MODEL-P56, PSD-MODEL-P58,
/// PSD-MODEL-P59, PSD-MODEL-P63, PSD-MODEL-P64, PSD-MODEL-P65, PSD-MODEL-P66,
/// PSD-MODEL-P41, PSD-MODEL-P42, PSD-MODEL-P43, PSD-PAR-DELIVERY-001, PSD-PAR-41-003,
/// PSD-PAR-44-002, PSD-PAR-53-001, PSD-PAR-56-001, PSD-PAR-58-001, PSD-PAR-59-001,
/// PSD-PAR-63-001, PSD-PAR-80-001).
#[test]
fn ranges_and_delivery_values_per_model() {
    let skip = [
        "3", "37", "38", "39", "40", "41", "42", "43", "44", "45", "96", "92",
    ];
    for model in &family().models {
        let mut s = Sim::new(&model.id);
        for p in &family().parameters {
            let pnu = p.number as u16;
            let resolved = family().resolve(p, Some(model));
            if let Some(d) = resolved.default {
                if p.access != Access::Pd {
                    assert_eq!(s.par(pnu), d, "{} par {}: delivery", model.id, p.id);
                }
            }
            if !p.access.writable() || skip.contains(&p.id.as_str()) {
                continue;
            }
            let r = resolved.range.unwrap();
            let (lo, hi) = (r.min().unwrap(), r.max().unwrap());
            let at = |what: &str| format!("{} par {} {what}", model.id, p.id);
            assert_eq!(s.try_write(pnu, lo), Ok(()), "{}", at("min"));
            assert_eq!(s.try_write(pnu, hi), Ok(()), "{}", at("max"));
            if p.data_type.bounds().is_some_and(|(b, _)| b < lo) {
                assert_eq!(s.try_write(pnu, lo - 1), Err(2), "{}", at("below"));
            }
            if p.data_type.bounds().is_some_and(|(_, b)| b > hi) {
                assert_eq!(s.try_write(pnu, hi + 1), Err(2), "{}", at("above"));
            }
            if let Some(d) = resolved.default {
                s.write(pnu, d);
            }
        }
    }
}

/// Read-only and process-data parameters refuse writes with error 1; unknown numbers give
/// error 0 (PSD-PAR-READONLY-001, PSD-PD-009, PSD-PKW-023, PSD-PKW-024, PSD-PAR-1-001,
/// PSD-PAR-32-002, PSD-PAR-33-002).
#[test]
fn access_rules() {
    let mut s = Sim::new(MODEL);
    for p in &family().parameters {
        if !p.access.writable() {
            assert_eq!(s.try_write(p.number as u16, 0), Err(1), "par {}", p.id);
        }
    }
    assert_eq!(s.try_write(20, 0), Err(0));
    assert_eq!(s.par(32), 0);
    s.send(0x2014, 4000);
    assert_eq!(s.par(32), 0x2014);
    assert_eq!(s.par(33), 4000);
    assert_eq!(s.par(1), i64::from(s.status()));
}

/// Standstill-only parameters refuse writes while running with error 17 (PSD-PKW-030,
/// PSD-PAR-3-003, PSD-PAR-37-003, PSD-PAR-38-002, PSD-PAR-40-002, PSD-PAR-41-002); with the
/// reading "par-39-only" the numerator may change while running (erratum PSD-ERRATUM-016).
#[test]
fn standstill_conditions() {
    let mut s = Sim::new(MODEL);
    s.send(0x14, 400_000);
    s.step(100);
    for (pnu, v) in [
        (3, 0),
        (37, 1),
        (38, 400),
        (39, 400),
        (40, 0),
        (41, 806_400),
    ] {
        assert_eq!(s.try_write(pnu, v), Err(17), "par {pnu}");
    }
    assert_eq!(s.try_write(44, 5), Ok(()), "no condition on par 44");
    let mut s = Sim::with(
        DriveConfig::new(MODEL).with_readings(readings(&[("par38-standstill", "par-39-only")])),
    );
    s.send(0x14, 400_000);
    s.step(100);
    assert_eq!(s.try_write(38, 400), Ok(()));
    assert_eq!(s.try_write(39, 400), Err(17));
}

// ---------------------------------------------------------------- 4.7 cascades

/// Changing the direction resets referencing value, mapping end and limits; the position
/// counts the other way (PSD-MAP-012, PSD-PAR-37-001, PSD-PAR-37-002).
#[test]
fn direction_change_cascade() {
    let mut s = Sim::new(MODEL);
    go(&mut s, 4000);
    s.write(40, 100);
    s.write(42, 500_000);
    assert_eq!(s.actual(), 4100);
    s.write(37, 1);
    assert_eq!(
        (s.par(40), s.par(41), s.par(42), s.par(43)),
        (0, 806_400, 805_200, -805_200)
    );
    assert_eq!(s.actual(), -4000);
    assert_eq!(s.try_write(37, 2), Err(2));
}

/// Changing the mapping end sets the limits to the full new range (PSD-MAP-013, erratum
/// PSD-ERRATUM-057), or to the delivery values with the other reading; par. 41 outside
/// actual + 3 … + 4,029 rotations is refused (PSD-MAP-007, PSD-MAP-002, PSD-MAP-006).
#[test]
fn mapping_end_cascade() {
    let mut s = Sim::new(MODEL);
    s.write(42, 1000);
    s.write(41, 1_611_600);
    assert_eq!((s.par(42), s.par(43)), (1_610_400, 0));
    assert_eq!(s.try_write(41, 1_611_601), Err(2));
    assert_eq!(s.try_write(41, 1199), Err(2));
    let mut s = Sim::with(DriveConfig::new(MODEL).with_readings(readings(&[(
        "psd-limits-after-mapping-end",
        "absolute-delivery-values",
    )])));
    s.write(41, 1_611_600);
    assert_eq!((s.par(42), s.par(43)), (805_200, -805_200));
}

/// The limits are permitted between mapping end − 4,029 and − 3 rotations, scaled by the
/// denominator / numerator (PSD-MAP-028, PSD-MAP-008, PSD-MAP-009, erratum PSD-ERRATUM-007).
#[test]
fn limit_windows() {
    let mut s = Sim::new(MODEL);
    assert_eq!(s.try_write(42, 805_201), Err(2));
    assert_eq!(s.try_write(43, -805_201), Err(2));
    s.write(38, 400);
    s.write(39, 100);
    assert_eq!(s.try_write(42, 201_300), Ok(()));
    assert_eq!(s.try_write(42, 201_301), Err(2));
    assert_eq!(s.try_write(43, 201_600 - 402_900), Ok(()));
    assert_eq!(s.try_write(43, 201_600 - 402_901), Err(2));
}

/// Changing numerator or denominator recalculates target, actual, referencing value, mapping
/// end, limits, window and loop (PSD-MAP-014, PSD-MAP-024, PSD-MAP-025, PSD-PAR-38-001,
/// PSD-PAR-44-003, PSD-PAR-45-003, erratum PSD-ERRATUM-024).
#[test]
fn scaling_cascade() {
    let mut s = Sim::new(MODEL);
    go(&mut s, 4000);
    s.write(40, 400);
    s.write(44, 8);
    s.write(45, 400);
    assert_eq!(s.actual(), 4400);
    s.write(39, 100);
    assert_eq!(s.drive.core().axis().increments_per_rotation(), 100.0);
    assert_eq!(
        (
            s.par(3),
            s.par(33),
            s.par(40),
            s.par(41),
            s.par(42),
            s.par(43)
        ),
        (1100, 1100, 100, 201_700, 201_400, -201_200)
    );
    assert_eq!((s.par(44), s.par(45)), (2, 100));
    // The window's maximum scales: 100 × 100 / 400 = 25.
    assert_eq!(s.try_write(44, 25), Ok(()));
    assert_eq!(s.try_write(44, 26), Err(2));
    assert_eq!(s.try_write(45, 1000), Ok(()));
    assert_eq!(s.try_write(45, 1001), Err(2));
    assert_eq!(s.try_write(38, 0), Err(2));
    assert_eq!(s.try_write(39, 10_001), Err(2));
    // A run in the new unit.
    go(&mut s, 1200);
    assert_eq!(s.actual(), 1200);
}

/// The referencing value shifts target, actual, mapping end and limits, whether written
/// directly or through the actual value (PSD-MAP-015, PSD-MAP-019, PSD-MAP-020, PSD-MAP-021,
/// PSD-MAP-022, PSD-PAR-40-001, PSD-PAR-3-001).
#[test]
fn reference_cascade() {
    let mut s = Sim::new(MODEL);
    go(&mut s, 1000);
    s.write(40, 500);
    assert_eq!(
        (s.par(3), s.par(33), s.par(41), s.par(42), s.par(43)),
        (1500, 1500, 806_900, 805_700, -804_700)
    );
    s.write(3, 5000);
    assert_eq!(s.par(40), 4000);
    assert_eq!((s.par(3), s.par(33), s.par(41)), (5000, 5000, 810_400));
    // A target shifted by the referencing value can fall outside the limits (bit 12).
    s.send(0x14, 900_000);
    assert!(s.bit(12));
}

/// Written in the order of 4.7 note 7 no value is adjusted afterwards (PSD-MAP-016,
/// PSD-MAP-010, PSD-MAP-011).
#[test]
fn recommended_write_order() {
    let mut s = Sim::new(MODEL);
    let order = &family().psd4xx().unwrap().positioning.write_order;
    let values = [
        ("37", 0),
        ("38", 400),
        ("39", 200),
        ("40", 1000),
        ("41", 403_800),
        ("44", 4),
        ("45", -100),
    ];
    for group in order {
        for id in group {
            let (_, v) = values.iter().find(|(k, _)| k == id).unwrap();
            s.write(id.parse().unwrap(), *v);
        }
    }
    for (id, v) in values {
        assert_eq!(s.par(id.parse().unwrap()), v, "par {id}");
    }
    // The limits then follow par. 41 (3 rotations = 600 increments at 200 per rotation).
    assert_eq!(s.par(42), 403_800 - 600);
}

// ---------------------------------------------------------------- par. 96 and EEPROM

/// Saving keeps the backed-up parameters over a power cycle; the others are lost
/// (PSD-PAR-SAVE-001, PSD-PAR-SAVE-002, PSD-PAR-96-007, PSD-PAR-96-009).
#[test]
fn save_and_power_cycle() {
    let mut s = Sim::new(MODEL);
    s.write(44, 10);
    s.write(80, 123_456);
    s.drive.power_cycle(s.now);
    assert_eq!((s.par(44), s.par(80)), (2, 0), "not saved: lost");
    s.write(44, 10);
    s.write(80, 123_456);
    s.write(96, 1);
    assert_eq!(s.drive.saved_value(44), Some(10));
    for pnu in [3, 32, 33, 96] {
        assert_eq!(s.drive.saved_value(pnu), None, "par {pnu} is not backed up");
    }
    s.write(44, 20);
    s.drive.power_cycle(s.now);
    assert_eq!((s.par(44), s.par(80)), (10, 123_456));
    assert!(s.events().contains(&Event::Saved));
}

/// -1 delivery state without saving, -2 back to the saved values, -3 delivery state saved
/// and the station name deleted (PSD-PAR-96-004, PSD-PAR-96-005, PSD-PAR-96-006,
/// PSD-PAR-96-008).
#[test]
fn delivery_and_user_states() {
    let mut config = DriveConfig::new(MODEL);
    config.station_name = "press-7".into();
    let mut s = Sim::with(config);
    s.write(44, 10);
    s.write(96, 1);
    s.write(44, 20);
    s.write(96, -1);
    assert_eq!(s.par(44), 2);
    assert_eq!(s.drive.saved_value(44), Some(10));
    s.write(96, -2);
    assert_eq!(s.par(44), 10);
    s.write(96, -3);
    assert_eq!((s.par(44), s.drive.saved_value(44)), (2, Some(2)));
    assert_eq!(s.drive.station_name(), "");
    for bad in [0, 2, -7] {
        assert_eq!(s.try_write(96, bad), Err(2), "{bad}");
    }
    assert_eq!(s.par(96), 0);
}

/// -5 and -4 end with a run to the middle of the range; the unchanged control word is
/// ignored, a changed one aborts it, and the old run command is not restarted after
/// (PSD-PAR-96-002, PSD-PAR-96-003, PSD-PAR-96-010, PSD-PAR-96-011, PSD-PAR-96-012).
#[test]
fn delivery_state_and_centre_run() {
    let mut s = Sim::new(MODEL);
    go(&mut s, 40_000);
    s.write(44, 10);
    s.write(96, -5);
    assert_eq!((s.par(44), s.drive.saved_value(44)), (2, Some(2)));
    s.step(1);
    assert!(s.running());
    assert_eq!(s.drive.core().run_kind(), Some(RunKind::Centre));
    s.wait_idle();
    assert_eq!(s.actual(), 0, "the middle of -805,200 … 805,200");
    s.step(500);
    assert_eq!(s.actual(), 0, "0x14 with the old target is not restarted");
    // -4 from the user's image; a changed control word aborts the run.
    go(&mut s, 0);
    s.control(0x00);
    go(&mut s, 30_000);
    s.write(96, -4);
    s.step(300);
    s.control(0x2014);
    assert!(!s.bit(5), "aborted by a changed word, the release stays");
    s.wait_idle();
    assert!(s.actual() > 0 && s.actual() < 30_000);
    // Withdrawing the release aborts it with bit 5.
    s.write(96, -4);
    s.step(300);
    s.control(0x0000);
    assert!(s.bit(5));
    s.wait_idle();
    assert!(s.actual() > 0);
    // Not while running.
    s.send(0x14, 400_000);
    s.step(100);
    assert_eq!(s.try_write(96, -5), Err(17));
}

/// -6 resets: working values from the EEPROM image, bit 8 set (PSD-PAR-96-001,
/// PSD-STS-8-SET-2); par. 92 takes effect only after saving and a restart
/// (PSD-PAR-92-002).
#[test]
fn reset_and_address() {
    let mut s = Sim::new(MODEL);
    go(&mut s, 4000);
    assert!(!s.bit(8));
    s.write(92, 17);
    assert_eq!(s.drive.address_in_force(), 0);
    s.write(96, 1);
    assert_eq!(s.drive.address_in_force(), 0);
    s.write(44, 30);
    s.write(96, -6);
    assert_eq!(s.par(44), 2);
    assert!(s.bit(8));
    assert_eq!(s.drive.address_in_force(), 17);
    assert_eq!(
        s.actual(),
        4000,
        "the measuring system is absolute (PSD-MAP-023)"
    );
}

/// The status queries read what the drive measures and what it is (PSD-PAR-2-001,
/// PSD-PAR-6-001, PSD-PAR-7-001, PSD-PAR-8-001, PSD-PAR-9-001, PSD-PAR-10-001,
/// PSD-PAR-11-001, PSD-PAR-12-001, PSD-PAR-14-001). Motor currents (par. 4, 5) are not
/// modelled and read 0.
#[test]
fn status_queries() {
    let mut config = DriveConfig::new(MODEL);
    config.address_switch = 12;
    config.production_date = 2417;
    config.serial_number = 4711;
    config.model_number = 401;
    config.version = 0x0102_0304;
    let mut s = Sim::with(config);
    s.env(drivespec_positioner::EnvChange::ControlVoltage { dv: 235 });
    s.env(drivespec_positioner::EnvChange::MotorVoltage { dv: 228 });
    s.env(drivespec_positioner::EnvChange::Temperature { celsius: -5 });
    s.step(200);
    assert_eq!((s.par(6), s.par(7), s.par(8)), (235, 228, -5));
    assert_eq!(
        (s.par(9), s.par(10), s.par(11), s.par(12), s.par(14)),
        (12, 2417, 4711, 401, 0x0102_0304)
    );
    assert_eq!((s.par(4), s.par(5)), (0, 0));
    s.control(0x12);
    s.step(1000);
    assert_eq!(s.par(2), -70);
    assert_eq!(s.par(2), i64::from(s.drive.input().speed));
}

/// The end-of-run holding torque applies for par. 72, then the holding torque
/// (PSD-PAR-65-001, PSD-PAR-66-001, PSD-PAR-72-001).
#[test]
fn holding_torques() {
    let mut s = Sim::new(MODEL);
    s.write(72, 300);
    s.send(0x14, 4000);
    s.step(10);
    assert_eq!(s.drive.core().holding_torque(), None, "running");
    s.wait_idle();
    assert_eq!(s.drive.core().holding_torque(), Some(s.par(65)));
    s.step(305);
    assert_eq!(s.drive.core().holding_torque(), Some(s.par(66)));
}

// ---------------------------------------------------------------- PKW server

/// Sends a PKW request, kept in every following cycle as a controller repeats it (3.8).
fn pkw(s: &mut Sim, req: Request) -> drivespec_psd4xx::Reply {
    let rules = s.rules().clone();
    let block: PkwRequest = rules.pkw().encode_request(&req).unwrap();
    s.pkw = Some(block);
    s.cycle();
    rules.pkw().reply(&s.drive.input().pkw).unwrap()
}

/// The response to a read holds the value at the time of the command; repeating the command
/// does not refresh it; after command 0 and response 0 the same read gives the new value
/// (PSD-PKW-002, PSD-PKW-003, PSD-PKW-004, PSD-PKW-005, PSD-PKW-006, PSD-PKW-007,
/// PSD-PKW-010, PSD-PKW-012).
#[test]
fn pkw_response_is_held() {
    let mut s = Sim::new(MODEL);
    s.send(0x14, 400_000);
    s.step(500);
    let read = Request::Read {
        pnu: 3,
        index: None,
    };
    let first = pkw(&mut s, read);
    s.step(200);
    assert_eq!(pkw(&mut s, read), first, "held");
    assert_eq!(pkw(&mut s, Request::None), drivespec_psd4xx::Reply::None);
    let again = pkw(&mut s, read);
    assert_ne!(again, first);
    let drivespec_psd4xx::Reply::Value { value, width, .. } = again else {
        panic!("{again:?}")
    };
    assert_eq!((value, width), (s.actual(), Width::Dword));
    let (_, input) = (s.now, s.drive.input());
    assert!(!input.pkw.spm);
}

/// Error codes of the server (PSD-PKW-019, PSD-PKW-022, PSD-PKW-026, PSD-PKW-027,
/// PSD-PKW-028, PSD-PKW-030, PSD-PKW-031, PSD-PKW-038); error 6 has no parameter that could
/// cause it in the PSD4xx table. No PSD4xx array parameter is writable, so the array writes
/// (commands 7 and 8) end in error 1 or 4, never in responses 4 or 5 (PSD-PKW-016,
/// PSD-PKW-017).
#[test]
fn pkw_error_codes() {
    let mut s = Sim::new(MODEL);
    let err = |r: drivespec_psd4xx::Reply| match r {
        drivespec_psd4xx::Reply::Error { error, .. } => error.0,
        other => panic!("{other:?}"),
    };
    let ask = |s: &mut Sim, r: Request| {
        pkw(s, Request::None);
        err(pkw(s, r))
    };
    assert_eq!(
        ask(
            &mut s,
            Request::Read {
                pnu: 44,
                index: Some(0)
            }
        ),
        4
    );
    assert_eq!(
        ask(
            &mut s,
            Request::Read {
                pnu: 13,
                index: Some(5)
            }
        ),
        3
    );
    assert_eq!(
        ask(
            &mut s,
            Request::Read {
                pnu: 13,
                index: None
            }
        ),
        5
    );
    assert_eq!(
        ask(
            &mut s,
            Request::Write {
                pnu: 42,
                index: None,
                width: Width::Word,
                value: 5
            }
        ),
        5
    );
    assert_eq!(
        ask(
            &mut s,
            Request::Write {
                pnu: 44,
                index: None,
                width: Width::Word,
                value: 0
            }
        ),
        2
    );
    assert_eq!(
        ask(
            &mut s,
            Request::Write {
                pnu: 13,
                index: Some(0),
                width: Width::Dword,
                value: 0
            }
        ),
        1
    );
    assert_eq!(
        ask(
            &mut s,
            Request::Write {
                pnu: 44,
                index: Some(0),
                width: Width::Word,
                value: 5
            }
        ),
        4
    );
    s.send(0x14, 400_000);
    s.step(50);
    assert_eq!(
        ask(
            &mut s,
            Request::Write {
                pnu: 40,
                index: None,
                width: Width::Dword,
                value: 0
            }
        ),
        17
    );
    // A command code the table does not list: error 18.
    let rules = s.rules().clone();
    let mut block: PkwRequest = rules
        .pkw()
        .encode_request(&Request::Read {
            pnu: 44,
            index: None,
        })
        .unwrap();
    block.ak = drivespec_psd4xx::CommandCode(12);
    s.pkw = Some(block);
    s.cycle();
    assert_eq!(s.drive.input().pkw.pwe, 18);
}

/// A write through PKW answers like a read and is in force at once; par. 96 = -6 through PKW
/// is answered and not executed again while the command stays (PSD-PKW-013, PSD-PKW-014,
/// PSD-PKW-032, PSD-PKW-033, PSD-PKW-034).
#[test]
fn pkw_writes() {
    let mut s = Sim::new(MODEL);
    let w = Request::Write {
        pnu: 45,
        index: None,
        width: Width::Dword,
        value: -300,
    };
    assert_eq!(
        pkw(&mut s, w),
        drivespec_psd4xx::Reply::Value {
            pnu: 45,
            index: None,
            width: Width::Dword,
            value: -300
        }
    );
    assert_eq!(s.par(45), -300);
    pkw(&mut s, Request::None);
    let reset = Request::Write {
        pnu: 96,
        index: None,
        width: Width::Word,
        value: -6,
    };
    s.events();
    let r = pkw(&mut s, reset);
    assert!(
        matches!(r, drivespec_psd4xx::Reply::Value { value: -6, .. }),
        "{r:?}"
    );
    s.step(100);
    let resets = s
        .events()
        .iter()
        .filter(|e| matches!(e, Event::Core(CoreEvent::PowerOn)))
        .count();
    assert_eq!(resets, 1);
}

// ---------------------------------------------------------------- records

/// Records refuse what PKW refuses, check their length and ignore control byte 0
/// (PSD-REC-001, PSD-REC-003, PSD-REC-004, PSD-REC-005, PSD-REC-006, PSD-REC-007).
#[test]
fn record_errors() {
    let mut s = Sim::new(MODEL);
    let r = s.record(RecordRequest::Write {
        index: 11,
        data: vec![1, 0, 5],
    });
    assert_eq!(
        r.result,
        Err(RecordFailure::Refused {
            error: drivespec_psd4xx::ErrorCode(1)
        })
    );
    let r = s.record(RecordRequest::Read { index: 20 });
    assert_eq!(
        r.result,
        Err(RecordFailure::Refused {
            error: drivespec_psd4xx::ErrorCode(0)
        })
    );
    let r = s.record(RecordRequest::Write {
        index: 44,
        data: vec![1, 0, 0, 5],
    });
    assert!(matches!(r.result, Err(RecordFailure::Malformed { .. })));
    let r = s.record(RecordRequest::Write {
        index: 44,
        data: vec![1, 0, 0],
    });
    assert_eq!(
        r.result,
        Err(RecordFailure::Refused {
            error: drivespec_psd4xx::ErrorCode(2)
        })
    );
    let r = s.record(RecordRequest::Write {
        index: 96,
        data: vec![0, 0, 1],
    });
    assert_eq!(r.result, Ok(RecordAnswer::Ignored));
    assert!(!s.events().contains(&Event::Saved));
    let r = s.record(RecordRequest::Write {
        index: 96,
        data: vec![1, 0, 1],
    });
    assert_eq!(r.result, Ok(RecordAnswer::Written));
    // Every numeric parameter reads with the length of its type (PSD-REC-008, PSD-REC-009).
    for p in &family().parameters {
        if p.data_type == DataType::String {
            continue;
        }
        let r = s.record(RecordRequest::Read {
            index: p.number as u16,
        });
        let Ok(RecordAnswer::Data { bytes }) = r.result else {
            panic!("par {}: {:?}", p.id, r.result)
        };
        assert_eq!(
            bytes.len(),
            p.data_type.width().unwrap().max(2) as usize,
            "par {}",
            p.id
        );
    }
}

/// Process images as bytes: a 14-byte output image starts a run, the 16-byte input image
/// reports it (PSD-PD-002, PSD-PD-004, PSD-PD-005, PSD-PD-007, PSD-PD-011, PSD-PD-006).
#[test]
fn images_as_bytes() {
    let mut s = Sim::new(MODEL);
    let bytes =
        drivespec_spec::hex::parse_hex("00 00 00 00 00 00 00 00 14 00 00 00 03 E8").unwrap();
    s.drive.handle_image(s.now, &bytes).unwrap();
    assert!(s.drive.handle_image(s.now, &bytes[..13]).is_err());
    s.control = 0x14;
    s.target = 1000;
    s.wait_idle();
    let image = s.drive.input_image();
    assert_eq!(image.len(), 16);
    assert_eq!(
        image,
        drivespec_spec::hex::parse_hex("00 00 00 00 00 00 00 00 11 00 00 00 00 00 03 E8").unwrap()
    );
}
