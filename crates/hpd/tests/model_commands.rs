//! The drive model's parameters and commands (manual 3.2–3.4, 3.6, 3.8.1): what serial writes
//! it takes, the command bits, the save image and power cycles. One scenario per rule, named
//! by its requirement ID.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_hpd::model::{Alarms, Drive, DriveConfig};
use drivespec_hpd::{Data, Message};
use model_util::*;

/// Alarm codes whose entry in the 3.3 table has the given flags.
fn alarm_where(checksum: bool) -> u8 {
    protocol()
        .alarms
        .iter()
        .find(|a| a.code != 0 && a.save_refused == checksum && a.reset_refused == checksum)
        .unwrap()
        .code
}

#[test]
fn hpd_par_018_writes_are_working_values_until_saved() {
    let mut d = drive(0);
    assert_eq!(exchange(&mut d, 10, &write(0, "Pr5", 100)), [ack(0)]);
    assert_eq!(value(&d, "Pr5"), 100);
    assert_eq!(d.saved_value(&target("Pr5")).unwrap(), 0);
    d.power_cycle(1_000);
    assert_eq!(value(&d, "Pr5"), 0, "lost at power-down");
    exchange(&mut d, 2_000, &write(0, "Pr5", 100));
    // HPD-CMD-012: b99.15 stores all parameters.
    assert_eq!(exchange(&mut d, 3_000, &bit(0, "b99.15", true)), [ack(0)]);
    assert_eq!(d.saved_value(&target("Pr5")).unwrap(), 100);
    exchange(&mut d, 4_000, &write(0, "Pr5", -5));
    d.power_cycle(5_000);
    assert_eq!(value(&d, "Pr5"), 100, "the saved value comes back");
}

#[test]
fn hpd_cmd_011_b99_14_saves_the_plc_program_apart_from_parameters() {
    // Also HPD-PAR-018.
    let mut d = drive(0);
    let code = program_bytes(&["LD 90.6", "OUT 91.5", "END"]);
    load_program(&mut d, 10, 0, &code);
    assert_eq!(&d.plc_area()[..code.len()], code.as_slice());
    assert_ne!(&d.saved_plc_area()[..code.len()], code.as_slice());
    // b99.15 does not store the program.
    exchange(&mut d, 20, &bit(0, "b99.15", true));
    assert_ne!(&d.saved_plc_area()[..code.len()], code.as_slice());
    exchange(&mut d, 30, &bit(0, "b99.14", true));
    assert_eq!(d.saved_plc_area(), d.plc_area());
    d.power_cycle(1_000);
    assert_eq!(&d.plc_area()[..code.len()], code.as_slice());
}

#[test]
fn hpd_cmd_self_clear_command_bits_clear_themselves() {
    let mut d = drive(0);
    exchange(&mut d, 10, &bit(0, "b99.15", true));
    assert_eq!(value(&d, "b99.15"), 0);
    // The `latched` reading of HPD-ERRATUM-012: the bit stays 1 and runs once per 0 → 1.
    let mut d = drive_with(0, "command-self-clear", "latched");
    exchange(&mut d, 10, &write(0, "Pr5", 1));
    exchange(&mut d, 20, &bit(0, "b99.15", true));
    assert_eq!(value(&d, "b99.15"), 1);
    assert_eq!(d.saved_value(&target("Pr5")).unwrap(), 1);
    exchange(&mut d, 30, &write(0, "Pr5", 2));
    exchange(&mut d, 40, &bit(0, "b99.15", true));
    assert_eq!(
        d.saved_value(&target("Pr5")).unwrap(),
        1,
        "no new 0 → 1 change"
    );
    exchange(&mut d, 50, &bit(0, "b99.15", false));
    exchange(&mut d, 60, &bit(0, "b99.15", true));
    assert_eq!(d.saved_value(&target("Pr5")).unwrap(), 2);
    // Command bits are never stored as 1.
    assert_eq!(d.saved_value(&target("b99.15")).unwrap(), 0);
}

#[test]
fn hpd_cmd_005_alarm_reset_clears_pr23_and_pr24() {
    // Also HPD-ALARM-001, HPD-ALARM-003.
    let mut d = drive(0);
    let code = alarm_where(false);
    d.raise_alarm(10, code).unwrap();
    assert_eq!(
        d.alarms(),
        Alarms {
            active: code,
            last: code
        }
    );
    assert_eq!(value(&d, "Pr23"), i64::from(code));
    exchange(&mut d, 20, &bit(0, "b99.10", true));
    assert_eq!(d.alarms(), Alarms { active: 0, last: 0 });
    assert!(d.raise_alarm(30, 0).is_err());
    assert!(d.raise_alarm(30, 200).is_err());
}

#[test]
fn hpd_cmd_006_no_alarm_reset_on_a_checksum_alarm() {
    let mut d = drive(0);
    let code = alarm_where(true);
    d.raise_alarm(10, code).unwrap();
    exchange(&mut d, 20, &bit(0, "b99.10", true));
    assert_eq!(d.alarms().active, code);
}

#[test]
fn hpd_cmd_013_no_parameter_save_on_a_checksum_alarm() {
    let mut d = drive(0);
    d.raise_alarm(10, alarm_where(true)).unwrap();
    exchange(&mut d, 20, &write(0, "Pr5", 9));
    exchange(&mut d, 30, &bit(0, "b99.15", true));
    assert_eq!(d.saved_value(&target("Pr5")).unwrap(), 0);
    // Other alarms do not stop the save.
    let mut d = drive(0);
    d.raise_alarm(10, alarm_where(false)).unwrap();
    exchange(&mut d, 20, &write(0, "Pr5", 9));
    exchange(&mut d, 30, &bit(0, "b99.15", true));
    assert_eq!(d.saved_value(&target("Pr5")).unwrap(), 9);
}

#[test]
fn hpd_cmd_015_b99_14_and_checksum_alarms_follow_the_erratum_reading() {
    // The two readings of HPD-ERRATUM-013.
    let code = program_bytes(&["LD 90.6", "OUT 91.5", "END"]);
    for (reading, saved) in [("b99-15-only", true), ("both", false)] {
        let mut d = drive_with(0, "b99-14-checksum", reading);
        d.raise_alarm(0, alarm_where(true)).unwrap();
        load_program(&mut d, 10, 0, &code);
        exchange(&mut d, 20, &bit(0, "b99.14", true));
        assert_eq!(d.saved_plc_area() == d.plc_area(), saved, "{reading}");
    }
}

#[test]
fn hpd_cmd_007_mode_defaults_only_with_b40_2_zero() {
    // Also HPD-MODE-005, HPD-MODE-004: the defaults come from `[[parameter.mode]]`.
    let mode = 9;
    let expected: Vec<(String, i64)> = family()
        .parameters
        .iter()
        .filter(|p| p.address.is_some())
        .filter_map(|p| {
            let m = p.modes.iter().find(|m| m.modes.contains(&mode))?;
            Some((p.id.clone(), m.default?))
        })
        .collect();
    assert!(expected.len() >= 4);
    let mut d = drive(0);
    exchange(&mut d, 10, &write(0, "Pr31", mode.into()));
    exchange(&mut d, 20, &bit(0, "b40.2", true));
    exchange(&mut d, 30, &bit(0, "b99.11", true));
    assert!(
        expected.iter().any(|(id, v)| value(&d, id) != *v),
        "refused"
    );
    exchange(&mut d, 40, &bit(0, "b40.2", false));
    exchange(&mut d, 50, &bit(0, "b99.11", true));
    for (id, v) in &expected {
        assert_eq!(value(&d, id), *v, "{id} in mode {mode}");
    }
}

#[test]
fn hpd_cmd_008_defaults_restore_parameters_and_the_appendix_g_program() {
    // Also HPD-PLC-002, HPD-BIT-40-14-DEFAULT.
    let mut d = drive(0);
    let delivered = Drive::new(spec(), DriveConfig::factory()).unwrap();
    load_program(
        &mut d,
        10,
        0,
        &program_bytes(&["LD 90.6", "OUT 91.5", "END"]),
    );
    for (name, v) in [("Pr2", 1234), ("Pr5", 55), ("Pr31", 9), ("Pr50", 7)] {
        exchange(&mut d, 20, &write(0, name, v));
    }
    // HPD-CMD-009: refused while the PLC runs.
    assert_eq!(value(&d, "b99.13"), 1);
    exchange(&mut d, 30, &bit(0, "b99.12", true));
    assert_eq!(value(&d, "Pr2"), 1234);
    exchange(&mut d, 40, &bit(0, "b99.13", false));
    // The command is acknowledged, then the line is lost: b40.14 is 0 by default.
    assert_eq!(exchange(&mut d, 50, &bit(0, "b99.12", true)), [ack(0)]);
    for name in ["Pr2", "Pr5", "Pr31", "Pr50", "Pb40", "Pr26", "Pr27", "Pb99"] {
        assert_eq!(value(&d, name), value(&delivered, name), "{name}");
    }
    assert_eq!(d.plc_area(), delivered.plc_area());
    assert!(exchange(&mut d, 60, &read(0, "Pr31")).is_empty());
}

#[test]
fn hpd_cmd_010_defaults_clear_a_checksum_alarm() {
    let mut d = drive(0);
    d.raise_alarm(10, alarm_where(true)).unwrap();
    set(&mut d, 20, "b99.13", 0);
    set(&mut d, 30, "b99.12", 1);
    assert_eq!(d.alarms(), Alarms { active: 0, last: 0 });
}

#[test]
fn hpd_bit_99_7_security_blocks_writes_and_commands() {
    // Also HPD-BIT-99-7-SELF, HPD-CMD-001 (HPD-ERRATUM-011 reading `all-writes`).
    let mut d = drive(0);
    exchange(&mut d, 10, &bit(0, "b99.7", true));
    assert_eq!(exchange(&mut d, 20, &write(0, "Pr5", 5)), [ack(0)]);
    assert_eq!(value(&d, "Pr5"), 0, "refused, still acknowledged");
    let code = alarm_where(false);
    d.raise_alarm(30, code).unwrap();
    set(&mut d, 40, "b99.10", 1);
    assert_eq!(d.alarms().active, code, "commands refused");
    // A Pb99 write takes b99.7 only.
    exchange(&mut d, 50, &write(0, "Pb99", 0x0040));
    assert_eq!(value(&d, "b99.7"), 0);
    assert_eq!(value(&d, "b99.6"), 0);
    exchange(&mut d, 60, &write(0, "Pr5", 5));
    assert_eq!(value(&d, "Pr5"), 5);
    // Reading `keypad-only`: serial writes are not blocked.
    let mut d = drive_with(0, "b99-7-scope", "keypad-only");
    exchange(&mut d, 10, &bit(0, "b99.7", true));
    exchange(&mut d, 20, &write(0, "Pr5", 5));
    assert_eq!(value(&d, "Pr5"), 5);
}

#[test]
fn hpd_par_009_values_outside_the_range_are_ignored() {
    let mut d = drive(0);
    let r = family()
        .resolve(target("Pr33").param(), None)
        .range
        .unwrap();
    let (lo, hi) = (r.min().unwrap(), r.max().unwrap());
    for (v, taken) in [(lo, true), (hi, true), (lo - 1, false), (hi + 1, false)] {
        let before = value(&d, "Pr33");
        assert_eq!(exchange(&mut d, 10, &write(0, "Pr33", v)), [ack(0)]);
        assert_eq!(value(&d, "Pr33"), if taken { v } else { before }, "{v}");
    }
}

#[test]
fn hpd_mode_001_pr31_range_follows_the_erratum_reading() {
    // The two readings of HPD-ERRATUM-014.
    let undocumented = (0..=255)
        .find(|v| !target("Pr31").param().values.iter().any(|x| x.value == *v))
        .unwrap();
    let mut d = drive(0);
    exchange(&mut d, 10, &write(0, "Pr31", undocumented));
    assert_eq!(value(&d, "Pr31"), 0);
    let mut d = drive_with(0, "pr31-range", "byte");
    exchange(&mut d, 10, &write(0, "Pr31", undocumented));
    assert_eq!(value(&d, "Pr31"), undocumented);
}

#[test]
fn hpd_mode_005_pr50_to_pr69_ranges_depend_on_the_mode() {
    let range = |mode: u32| {
        let p = target("Pr50").param();
        p.modes
            .iter()
            .find(|m| m.modes.contains(&mode))
            .and_then(|m| m.range.clone())
            .unwrap()
    };
    let (narrow, wide) = (12, 1);
    let v = range(narrow).max().unwrap() + 1;
    assert!(range(wide).contains(v));
    let mut d = drive(0);
    exchange(&mut d, 10, &write(0, "Pr31", narrow.into()));
    exchange(&mut d, 20, &write(0, "Pr50", v));
    assert_ne!(value(&d, "Pr50"), v);
    exchange(&mut d, 30, &write(0, "Pr31", wide.into()));
    exchange(&mut d, 40, &write(0, "Pr50", v));
    assert_eq!(value(&d, "Pr50"), v);
}

#[test]
fn hpd_par_053_read_only_parameters_are_not_written() {
    // Also HPD-PAR-024, HPD-PAR-025, HPD-PAR-034.
    let mut d = drive(0);
    for name in ["Pb41", "Pr0", "Pr6", "Pr7", "Pr20"] {
        let before = value(&d, name);
        assert_eq!(
            exchange(&mut d, 10, &write(0, name, 0x55)),
            [ack(0)],
            "{name}"
        );
        assert_eq!(value(&d, name), before, "{name}");
    }
    // Read-only bits of a writable bitfield keep the drive's value (b99.0 timer status).
    d.advance(scan_us());
    let flag = value(&d, "b99.0");
    exchange(&mut d, 20, &bit(0, "b99.0", flag == 0));
    assert_eq!(value(&d, "b99.0"), flag);
}

#[test]
fn hpd_bit_40_15_must_remain_zero() {
    let mut d = drive(0);
    let v = value(&d, "Pb40") | 0x8000 | 0x0001;
    exchange(&mut d, 10, &write(0, "Pb40", v));
    assert_eq!(value(&d, "b40.15"), 0);
    assert_eq!(value(&d, "b40.0"), 1);
}

#[test]
fn writes_must_cover_whole_parameters() {
    // DECISION of the model (manual 4.2 silent): partial writes are ignored, double words and
    // runs of whole parameters are taken (HPD-PAR-006).
    let mut d = drive(0);
    let (pr5, _) = slot("Pr5");
    let one = Message::WriteParam {
        addr: 0,
        par: pr5,
        data: Data::new(&[9]).unwrap(),
    };
    assert_eq!(exchange(&mut d, 10, &one), [ack(0)]);
    let odd = Message::WriteParam {
        addr: 0,
        par: pr5 + 1,
        data: Data::new(&[9]).unwrap(),
    };
    exchange(&mut d, 20, &odd);
    assert_eq!(value(&d, "Pr5"), 0);
    let double = target("Pr64:65").write(family(), 0, "-100000").unwrap();
    exchange(&mut d, 30, &double);
    assert_eq!(d.value(&target("Pr64:65")).unwrap(), -100_000);
}

#[test]
fn hpd_bit_91_power_on_outputs_and_pb94_are_zero_after_power_up() {
    // Also HPD-BIT-94-POWER-ON, HPD-BIT-90-USER.
    let mut d = drive(0);
    for name in ["b91.8", "b94.0", "b94.5", "b90.9"] {
        exchange(&mut d, 10, &bit(0, name, true));
        assert_eq!(value(&d, name), 1, "{name}");
    }
    exchange(&mut d, 20, &bit(0, "b99.15", true));
    d.power_cycle(1_000);
    for name in ["b91.8", "b94.0", "b94.5"] {
        assert_eq!(value(&d, name), 0, "{name}");
    }
    assert_eq!(value(&d, "b90.9"), 1, "b90.8–15 are saved");
}

#[test]
fn hpd_bit_41_4_drive_healthy_follows_the_alarm() {
    let mut d = drive(0);
    assert_eq!(value(&d, "b41.4"), 1);
    d.raise_alarm(10, alarm_where(false)).unwrap();
    assert_eq!(value(&d, "b41.4"), 0);
    set(&mut d, 20, "b99.10", 1);
    assert_eq!(value(&d, "b41.4"), 1);
}
