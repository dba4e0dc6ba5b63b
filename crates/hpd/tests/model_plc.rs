//! The drive model's pico-PLC on virtual time (manual 3.8.1, appendix F) and the appendix G
//! default program driven by digital inputs. One scenario per rule, named by its requirement
//! ID.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_hpd::model::{Drive, Output};
use drivespec_hpd::{Data, Message, Micros};
use model_util::*;

/// Digital input bit of input `i`.
fn input(i: u8) -> u16 {
    1 << i
}

/// The times of the digital output changes among `outputs`.
fn output_changes(outputs: &[Output]) -> Vec<(Micros, u16)> {
    outputs
        .iter()
        .filter_map(|o| match o {
            Output::DigitalOutputs { at, value } => Some((*at, *value)),
            Output::Transmit { .. } => None,
        })
        .collect()
}

#[test]
fn hpd_plc_004_the_plc_scans_every_6144_us_from_power_up() {
    // Also HPD-TIMER-004, HPD-PAR-057.
    let mut d = drive(0);
    assert_eq!(d.poll_timeout(), Some(scan_us()));
    d.power_cycle(1_000);
    assert_eq!(d.poll_timeout(), Some(1_000 + scan_us()));
    // Pr92 = 100 runs out after 100 scans.
    set(&mut d, 1_000, "Pr92", 100);
    d.advance(1_000 + 99 * scan_us());
    assert_eq!((value(&d, "Pr92"), value(&d, "b99.0")), (1, 0));
    assert_eq!(d.poll_timeout(), Some(1_000 + 100 * scan_us()));
    d.advance(1_000 + 100 * scan_us());
    assert_eq!((value(&d, "Pr92"), value(&d, "b99.0")), (0, 1));
}

#[test]
fn hpd_bit_90_inputs_are_read_at_the_start_of_each_scan() {
    let mut d = drive(0);
    d.set_inputs(100, input(6) | input(7));
    assert_eq!(d.digital_inputs(), input(6) | input(7));
    assert_eq!(value(&d, "b90.6"), 0, "not before the scan");
    d.advance(scan_us() - 1);
    assert_eq!(value(&d, "b90.6"), 0);
    d.advance(scan_us());
    assert_eq!((value(&d, "b90.6"), value(&d, "b90.7")), (1, 1));
    // An input change at the very time of a scan is seen by the next one.
    d.set_inputs(2 * scan_us(), 0);
    d.advance(2 * scan_us());
    assert_eq!(value(&d, "b90.6"), 1);
    d.advance(3 * scan_us());
    assert_eq!(value(&d, "b90.6"), 0);
}

#[test]
fn hpd_io_003_outputs_are_written_at_the_end_of_each_scan() {
    // Also HPD-PLC-006.
    let mut d = drive(0);
    d.advance(scan_us());
    let first = d.digital_outputs();
    exchange(&mut d, scan_us() + 10, &bit(0, "b91.5", true));
    assert_eq!(d.digital_outputs(), first, "not before the scan");
    d.advance(2 * scan_us());
    assert_eq!(d.digital_outputs(), first | 1 << 5);
    assert_eq!(
        output_changes(&drain(&mut d)).last(),
        Some(&(2 * scan_us(), first | 1 << 5))
    );
}

#[test]
fn hpd_bit_99_13_instructions_change_only_while_the_plc_is_stopped() {
    let mut d = drive(0);
    let before = d.plc_area().to_vec();
    let msg = Message::WritePlc {
        addr: 0,
        par: 0,
        data: Data::new(&[0x40, 0x5A]).unwrap(),
    };
    assert_eq!(exchange(&mut d, 10, &msg), [ack(0)]);
    assert_eq!(d.plc_area(), before.as_slice(), "ignored while running");
    // A stopped PLC does not run its program: b40.0 no longer follows input 4.
    exchange(&mut d, 20, &bit(0, "b99.13", false));
    d.set_inputs(30, input(4));
    d.advance(scan_us());
    assert_eq!(value(&d, "b40.0"), 0);
    assert_eq!(value(&d, "b90.4"), 1, "inputs are still read");
    assert_eq!(exchange(&mut d, scan_us() + 10, &msg), [ack(0)]);
    assert_eq!(&d.plc_area()[..2], &[0x40, 0x5A]);
    // The program is decoded again from the area.
    let code = program_bytes(&["LD 90.4", "OUT 91.3", "END"]);
    load_program(&mut d, scan_us() + 20, 0, &code);
    assert_eq!(d.program().unwrap().instrs.len(), 3);
    d.advance(2 * scan_us());
    assert_eq!(value(&d, "b91.3"), 1);
}

#[test]
fn hpd_plc_029_fin_copies_its_input_every_512_us() {
    // Also HPD-PLC-030, HPD-PLC-031.
    let mut d = drive(0);
    let code = program_bytes(&["FIN 3,0", "END"]);
    load_program(&mut d, 10, 0, &code);
    let t = 2 * scan_us() + 100;
    d.advance(t);
    assert_eq!(value(&d, "b40.3"), 0);
    // While a FIN runs the drive wakes up every FIN period.
    let next = d.poll_timeout().unwrap();
    assert_eq!(next % fin_us(), 0);
    assert!(next - t <= fin_us());
    d.set_inputs(t, input(1));
    d.advance(next - 1);
    assert_eq!(value(&d, "b40.3"), 0);
    d.advance(next);
    assert_eq!(
        value(&d, "b40.3"),
        1,
        "copied at the FIN slot, before the scan"
    );
    assert!(next < 3 * scan_us());
    // HPD-PLC-033: b94.5 = 1 disables the first FIN.
    exchange(&mut d, next + 1, &bit(0, "b94.5", true));
    d.set_inputs(next + 2, 0);
    d.advance(next + 3 * fin_us());
    assert_eq!(value(&d, "b40.3"), 1);
    // A FIN after another instruction is ignored: no FIN wake-ups then.
    let late = program_bytes(&["LD 90.6", "FIN 3,0", "END"]);
    load_program(&mut d, next + 4 * fin_us(), 0, &late);
    let now = d.now();
    assert_eq!(
        d.poll_timeout().unwrap() % scan_us(),
        0,
        "only scans: {now}"
    );
}

/// The default drive with its appendix G program, run for one scan with `inputs`.
fn appendix_g(inputs: u16, b90_10: bool, b90_11: bool) -> Drive {
    let mut d = drive(0);
    set(&mut d, 0, "b90.10", i64::from(b90_10));
    set(&mut d, 0, "b90.11", i64::from(b90_11));
    d.set_inputs(0, inputs);
    d.advance(scan_us());
    d
}

#[test]
fn hpd_io_007_limit_switches_and_emergency_stop_act_only_with_b90_10() {
    // Also HPD-PLC-048. Normally closed: an open input (0) is active.
    let all = input(1) | input(2) | input(3);
    let stops = |d: &Drive| [value(d, "b40.4"), value(d, "b40.5"), value(d, "b40.6")];
    assert_eq!(stops(&appendix_g(0, false, false)), [0, 0, 0]);
    assert_eq!(stops(&appendix_g(all, true, false)), [0, 0, 0]);
    assert_eq!(stops(&appendix_g(0, true, false)), [1, 1, 1]);
    assert_eq!(stops(&appendix_g(all & !input(2), true, false)), [0, 1, 0]);
    // Over time: opening input 3 stops the motor at the next scan.
    let mut d = appendix_g(all, true, false);
    d.set_inputs(scan_us() + 1, all & !input(3));
    d.advance(2 * scan_us());
    assert_eq!(value(&d, "b40.6"), 1);
}

#[test]
fn hpd_plc_048_input_4_selects_the_full_scale_and_input_5_the_zeroed_pr5() {
    assert_eq!(value(&appendix_g(input(4), false, false), "b40.0"), 1);
    assert_eq!(value(&appendix_g(0, false, false), "b40.0"), 0);
    let mut d = drive(0);
    set(&mut d, 0, "Pr5", 500);
    d.advance(scan_us());
    assert_eq!((value(&d, "Pr5"), value(&d, "b40.12")), (500, 0));
    d.set_inputs(scan_us() + 1, input(5));
    d.advance(2 * scan_us());
    assert_eq!((value(&d, "Pr5"), value(&d, "b40.12")), (0, 1));
    d.set_inputs(2 * scan_us() + 1, 0);
    d.advance(3 * scan_us());
    assert_eq!(value(&d, "b40.12"), 0);
}

#[test]
fn hpd_plc_049_b90_11_reverses_pr5_every_1024_scans() {
    // Also HPD-TIMER-007: timer 1 reloaded with the constant Pr78.
    let period = u64::try_from(protocol().plc.constant("Pr78").unwrap()).unwrap();
    let mut d = drive(0);
    set(&mut d, 0, "Pr5", 300);
    set(&mut d, 0, "b90.11", 1);
    let mut flips = Vec::new();
    let mut last = value(&d, "Pr5");
    while let Some(t) = d.poll_timeout().filter(|t| *t <= 20_000_000) {
        d.advance(t);
        let now = value(&d, "Pr5");
        if now != last {
            flips.push((t, now));
            last = now;
        }
    }
    assert!(flips.len() >= 3, "{flips:?}");
    assert_eq!(
        flips[0],
        (scan_us(), -300),
        "first reversal at the first scan"
    );
    for w in flips.windows(2) {
        assert_eq!(w[1].0 - w[0].0, period * scan_us(), "about 6.3 s apart");
        assert_eq!(w[1].1, -w[0].1);
    }
    // b40.12 stays on while b90.11 = 1, whatever input 5 does.
    assert_eq!(value(&d, "b40.12"), 1);
}

#[test]
fn hpd_bit_41_4_appendix_g_puts_drive_healthy_on_output_6() {
    // Also HPD-IO-003, HPD-IO-006.
    let healthy = protocol()
        .io
        .outputs
        .iter()
        .find(|o| o.function.as_deref().is_some_and(|f| f.contains("healthy")))
        .unwrap()
        .index;
    // Outputs 1 and 2 show b41.1 and b41.2: at standstill the speed error 0 lies inside
    // the Pr15..Pr14 window and Pr0 = 0.
    let standstill = 1 << 1 | 1 << 2;
    let mut d = drive(0);
    d.advance(scan_us());
    let changes = output_changes(&drain(&mut d));
    assert_eq!(changes, [(scan_us(), 1 << healthy | standstill)]);
    d.raise_alarm(scan_us() + 5, 3).unwrap();
    d.advance(2 * scan_us());
    assert_eq!(
        output_changes(&drain(&mut d)),
        [(2 * scan_us(), standstill)]
    );
    // Outputs drop at power-down and come back with the first scan.
    set(&mut d, 2 * scan_us() + 1, "b99.10", 1);
    d.advance(3 * scan_us());
    d.power_cycle(3 * scan_us() + 7);
    d.advance(4 * scan_us() + 7);
    assert_eq!(
        output_changes(&drain(&mut d)),
        [
            (3 * scan_us(), 1 << healthy | standstill),
            (3 * scan_us() + 7, 0),
            (4 * scan_us() + 7, 1 << healthy | standstill)
        ]
    );
}
