//! The drive model on the serial line (manual chapter 4, 4.1, 3.4 b42.3, 3.8.2 example 10):
//! one scenario per rule, named by its requirement ID.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_hpd::model::{Drive, DriveConfig, Output};
use drivespec_hpd::{parse, Data, Message, MessageKind, Micros};
use model_util::*;

/// Time-out and answer delay of Pr26 code `code` from the spec (µs).
fn baud(code: u8) -> (Micros, Micros) {
    let b = protocol().baud_rate(code).unwrap();
    (
        Micros::from(b.timeout_ms) * 1000,
        Micros::from(b.answer_delay_ms.unwrap_or(0)) * 1000,
    )
}

#[test]
fn hpd_serial_003_only_its_own_address_is_answered() {
    let mut d = drive(3);
    assert!(exchange(&mut d, 10, &read(4, "Pr31")).is_empty());
    assert!(exchange(&mut d, 20, &write(4, "Pr5", 77)).is_empty());
    assert_eq!(
        value(&d, "Pr5"),
        0,
        "a write to another drive is not executed"
    );
    let answer = exchange(&mut d, 30, &read(3, "Pr31"));
    assert!(matches!(answer[..], [Message::Response { addr: 3, .. }]));
    // HPD-SERIAL-001: answers of other drives on the line are not acted on.
    assert!(exchange(&mut d, 40, &ack(3)).is_empty());
    let other = Message::Response {
        addr: 3,
        par: slot("Pr5").0,
        data: Data::from_value(5, 2).unwrap(),
    };
    assert!(exchange(&mut d, 50, &other).is_empty());
    assert_eq!(value(&d, "Pr5"), 0);
}

#[test]
fn hpd_serial_012_messages_with_errors_get_no_answer() {
    let mut d = drive(0);
    let good = bytes(&read(0, "Pr31"));
    let mut bad_checksum = good.clone();
    *bad_checksum.last_mut().unwrap() ^= 1;
    let cases: Vec<Vec<u8>> = vec![
        bad_checksum,
        // CMD+ADDR = 0 (HPD-FRAME-021).
        vec![0x7E, 0x00, 0x01, 0x54, 0x55],
        // LUN 0 and LUN 5 (HPD-FRAME-007).
        vec![0x7E, 0x80, 0x00, 0x54, 0xD4],
        vec![0x7E, 0x80, 0x05, 0x54, 0xD9],
        // A $7E field not followed by $00 (HPD-FRAME-003).
        vec![0x7E, 0xA0, 0x02, 0x3E, 0x7E, 0x01, 0x00, 0x5F],
        // A bit change with LUN 1 (HPD-FRAME-016).
        vec![0x7E, 0xC0, 0x01, 0x5D, 0xFD, 0x1B],
    ];
    for (i, c) in cases.iter().enumerate() {
        let t = 1_000_000 * (i as u64 + 1);
        d.handle_rx(t, c);
        d.advance(t + 600_000);
        assert!(transmits(&drain(&mut d)).is_empty(), "case {i}: {c:02X?}");
    }
    // The line is not stuck: a correct message is answered afterwards.
    assert_eq!(exchange(&mut d, 50_000_000, &read(0, "Pr31")).len(), 1);
}

#[test]
fn hpd_serial_013_a_broadcast_is_executed_and_never_answered() {
    let mut d = drive(5);
    let (par, lun) = slot("Pr5");
    let msg = Message::Broadcast {
        par,
        data: Data::from_value(-1234, lun).unwrap(),
    };
    assert!(exchange(&mut d, 100, &msg).is_empty());
    assert_eq!(value(&d, "Pr5"), -1234);
}

#[test]
fn hpd_serial_017_a_read_answer_repeats_lun_and_par() {
    let mut d = drive(2);
    set(&mut d, 0, "Pr80", -2);
    let (par, _) = slot("Pr80");
    // HPD-FRAME-010, HPD-SERIAL-016: data least significant byte first.
    let answer = exchange(
        &mut d,
        10,
        &Message::ReadParam {
            addr: 2,
            lun: 2,
            par,
        },
    );
    assert_eq!(
        answer,
        [Message::Response {
            addr: 2,
            par,
            data: Data::new(&[0xFE, 0xFF]).unwrap()
        }]
    );
    // Four bytes from Pr80 give Pr80 and Pr81 (flat serial memory).
    set(&mut d, 20, "Pr81", 0x0102);
    let answer = exchange(
        &mut d,
        30,
        &Message::ReadParam {
            addr: 2,
            lun: 4,
            par,
        },
    );
    assert_eq!(
        answer,
        [Message::Response {
            addr: 2,
            par,
            data: Data::new(&[0xFE, 0xFF, 0x02, 0x01]).unwrap()
        }]
    );
}

#[test]
fn hpd_frame_011_writes_bit_changes_and_plc_writes_get_the_short_acknowledge() {
    // Also HPD-FRAME-013.
    let mut d = drive(7);
    assert_eq!(exchange(&mut d, 10, &write(7, "Pr5", 10)), [ack(7)]);
    assert_eq!(exchange(&mut d, 20, &bit(7, "b90.9", true)), [ack(7)]);
    let plc = Message::WritePlc {
        addr: 7,
        par: 0,
        data: Data::new(&[0x40, 0x5A]).unwrap(),
    };
    assert_eq!(exchange(&mut d, 30, &plc), [ack(7)]);
    // The acknowledge is [STX][001+ADDR] on the line.
    d.handle_rx(40, &bytes(&write(7, "Pr5", 11)));
    assert_eq!(transmits(&drain(&mut d)), [vec![0x7E, 0x27]]);
}

#[test]
fn hpd_frame_018_a_bit_change_acts_on_the_addressed_byte() {
    let mut d = drive(0);
    // HPD-FRAME-017: only the bits with 0 in the mask change.
    set(&mut d, 0, "Pb90", 0x0500);
    let (addr, _) = slot("Pb90");
    let msg = Message::BitChange {
        addr: 0,
        par: addr + 1,
        mask: 0b1111_1001,
        value: 0b0000_0010,
    };
    assert_eq!(exchange(&mut d, 10, &msg), [ack(0)]);
    // b90.9 set, b90.10 cleared, b90.8 untouched (bits 8–15 at PAR + 1).
    assert_eq!(value(&d, "Pb90") & 0xFF00, 0x0300);
    assert_eq!(exchange(&mut d, 20, &bit(0, "b90.12", true)), [ack(0)]);
    assert_eq!(value(&d, "b90.12"), 1);
}

#[test]
fn hpd_bit_40_14_a_drive_as_delivered_is_silent_until_enabled_and_initialised() {
    let mut d = Drive::new(spec(), DriveConfig::factory()).unwrap();
    assert_eq!(value(&d, "b40.14"), 0);
    assert!(exchange(&mut d, 10, &read(0, "Pr31")).is_empty());
    // b40.14 = 1 takes effect with the next initialisation (b42.3).
    set(&mut d, 20, "b40.14", 1);
    assert!(exchange(&mut d, 30, &read(0, "Pr31")).is_empty());
    set(&mut d, 40, "b99.6", 1);
    set(&mut d, 50, "b42.3", 1);
    assert_eq!(exchange(&mut d, 60, &read(0, "Pr31")).len(), 1);
    // HPD-SERIAL-009: without b99.15 the set-up is lost at the next power-up.
    d.power_cycle(1_000_000);
    assert!(exchange(&mut d, 1_000_010, &read(0, "Pr31")).is_empty());
}

#[test]
fn hpd_bit_40_14_clearing_the_enable_silences_the_drive_at_once() {
    let mut d = drive(0);
    // The request that disables the line is still acknowledged.
    assert_eq!(exchange(&mut d, 10, &bit(0, "b40.14", false)), [ack(0)]);
    assert!(exchange(&mut d, 20, &read(0, "Pr31")).is_empty());
    assert!(exchange(&mut d, 30, &bit(0, "b40.14", true)).is_empty());
    // Set again by the keypad, it works again: the line was initialised enabled.
    set(&mut d, 40, "b40.14", 1);
    assert_eq!(exchange(&mut d, 50, &read(0, "Pr31")).len(), 1);
}

#[test]
fn hpd_bit_42_3_pr26_and_pr27_take_effect_with_b42_3() {
    // Also HPD-PAR-038.
    let mut d = drive(0);
    let (timeout_8, _) = baud(8);
    let (timeout_3, _) = baud(3);
    assert_eq!(d.line().unwrap().timeout_us, timeout_8);
    assert_eq!(exchange(&mut d, 10, &write(0, "Pr27", 5)), [ack(0)]);
    assert_eq!(exchange(&mut d, 20, &write(0, "Pr26", 3)), [ack(0)]);
    // Nothing changes before the re-initialisation.
    assert_eq!(d.line().unwrap().address, 0);
    assert_eq!(d.line().unwrap().timeout_us, timeout_8);
    assert!(exchange(&mut d, 30, &read(5, "Pr31")).is_empty());
    assert_eq!(exchange(&mut d, 40, &bit(0, "b99.6", true)), [ack(0)]);
    // The b42.3 message is acknowledged under the address it was sent to.
    assert_eq!(exchange(&mut d, 50, &bit(0, "b42.3", true)), [ack(0)]);
    let line = d.line().unwrap();
    assert_eq!(
        (line.address, line.baud_code, line.timeout_us),
        (5, 3, timeout_3)
    );
    assert!(exchange(&mut d, 60, &read(0, "Pr31")).is_empty());
    assert_eq!(exchange(&mut d, 70, &read(5, "Pr31")).len(), 1);
}

#[test]
fn hpd_cmd_002_b42_3_needs_b99_6() {
    let mut d = drive(0);
    assert_eq!(value(&d, "b99.6"), 0);
    exchange(&mut d, 10, &write(0, "Pr27", 9));
    assert_eq!(exchange(&mut d, 20, &bit(0, "b42.3", true)), [ack(0)]);
    assert_eq!(d.line().unwrap().address, 0, "refused without b99.6");
    assert_eq!(value(&d, "b42.3"), 0, "the refused command is dropped");
    assert_eq!(exchange(&mut d, 30, &read(0, "Pr27")).len(), 1);
}

#[test]
fn hpd_bit_42_3_the_line_is_initialised_at_power_up() {
    let mut d = drive(0);
    exchange(&mut d, 10, &write(0, "Pr27", 7));
    exchange(&mut d, 20, &bit(0, "b99.15", true));
    d.power_cycle(1_000);
    assert_eq!(d.line().unwrap().address, 7);
    assert_eq!(exchange(&mut d, 2_000, &read(7, "Pr31")).len(), 1);
}

#[test]
fn hpd_baud_002_a_message_split_across_the_time_out_is_dropped() {
    // Also HPD-BAUD-003, HPD-FRAME-020: the time-out counts from STX, per Pr26 code.
    for code in [8, 0, 9] {
        let (timeout, _) = baud(code);
        let request = bytes(&read(1, "Pr31"));
        let (head, tail) = request.split_at(2);
        let mut d = Drive::new(spec(), DriveConfig::commissioned_at(code, 1)).unwrap();
        d.handle_rx(1_000, head);
        d.handle_rx(1_000 + timeout, tail);
        assert_eq!(
            transmits(&drain(&mut d)).len(),
            1,
            "code {code}: just in time"
        );
        let t = 10_000_000;
        d.handle_rx(t, head);
        d.handle_rx(t + timeout + 1, tail);
        assert!(
            transmits(&drain(&mut d)).is_empty(),
            "code {code}: too late"
        );
        // The drive waits for a new STX and answers the next message.
        d.handle_rx(t + timeout + 2, &request);
        assert_eq!(
            transmits(&drain(&mut d)).len(),
            1,
            "code {code}: next message"
        );
    }
}

#[test]
fn hpd_baud_004_code_4_delays_every_answer_by_25_ms() {
    let (_, delay) = baud(4);
    assert!(delay > 0);
    let mut d = Drive::new(spec(), DriveConfig::commissioned_at(4, 1)).unwrap();
    d.handle_rx(1_000, &bytes(&read(1, "Pr31")));
    assert!(transmits(&drain(&mut d)).is_empty(), "not before the delay");
    // poll_timeout leads to the answer through the PLC scans before it.
    while d.poll_timeout().unwrap() < 1_000 + delay {
        d.advance(d.poll_timeout().unwrap());
        assert!(transmits(&drain(&mut d)).is_empty());
    }
    assert_eq!(d.poll_timeout(), Some(1_000 + delay));
    d.advance(1_000 + delay);
    let out = drain(&mut d);
    assert!(
        matches!(&out[..], [Output::Transmit { at, .. }] if *at == 1_000 + delay),
        "{out:?}"
    );
    // Code 5 has the same rate without the delay.
    let mut d = Drive::new(spec(), DriveConfig::commissioned_at(5, 1)).unwrap();
    d.handle_rx(1_000, &bytes(&read(1, "Pr31")));
    assert!(matches!(
        &drain(&mut d)[..],
        [Output::Transmit { at: 1_000, .. }]
    ));
}

#[test]
fn hpd_frame_022_plc_requests_stay_inside_0x00_to_0x7f() {
    // Also HPD-PLC-038.
    let mut d = drive(0);
    let last = protocol().plc.last_address;
    let ok = Message::ReadPlc {
        addr: 0,
        lun: 2,
        par: last - 1,
    };
    assert_eq!(exchange(&mut d, 10, &ok).len(), 1);
    for (lun, par) in [(2, last), (1, last + 1), (4, 0xFE)] {
        let msg = Message::ReadPlc { addr: 0, lun, par };
        assert!(exchange(&mut d, 20, &msg).is_empty(), "{msg:?}");
    }
    let beyond = Message::WritePlc {
        addr: 0,
        par: last,
        data: Data::new(&[0, 0]).unwrap(),
    };
    assert!(exchange(&mut d, 30, &beyond).is_empty());
}

/// Two drives in IDC mode (Pr26 = 10) whose Pr80 names the serial address of Pr82.
fn idc_pair() -> (Drive, Drive) {
    let code = protocol().idc.baud_code;
    let (pr82, _) = slot("Pr82");
    let mut a = Drive::new(spec(), DriveConfig::commissioned_at(code, 1)).unwrap();
    let mut b = Drive::new(spec(), DriveConfig::commissioned_at(code, 2)).unwrap();
    for (d, v) in [(&mut a, 111), (&mut b, 222)] {
        set(d, 0, "Pr80", i64::from(pr82));
        set(d, 0, "Pr81", v);
    }
    (a, b)
}

#[test]
fn hpd_bit_99_5_b99_5_broadcasts_pr81_to_the_address_in_pr80() {
    // Also HPD-BAUD-005.
    let (mut a, _) = idc_pair();
    assert!(a.line().unwrap().idc);
    let out = exchange(&mut a, 10, &bit(1, "b99.5", true));
    let (pr82, _) = slot("Pr82");
    assert_eq!(out.len(), 2, "{out:?}");
    assert_eq!(out[0], ack(1));
    assert_eq!(out[1].kind(), MessageKind::Broadcast);
    assert_eq!(
        out[1],
        Message::Broadcast {
            par: pr82,
            data: Data::from_value(111, protocol().idc.lun).unwrap()
        }
    );
    assert_eq!(value(&a, "b99.5"), 0, "one broadcast per b99.5");
    // Without IDC, b99.5 sends nothing.
    let mut d = drive(1);
    assert_eq!(exchange(&mut d, 10, &bit(1, "b99.5", true)), [ack(1)]);
}

#[test]
fn hpd_bit_99_5_a_broadcast_received_in_idc_mode_is_passed_on() {
    // The receiver sets b99.5 and sends its own Pr81.
    let (mut a, mut b) = idc_pair();
    a.set_value(10, &target("b99.5"), 1).unwrap();
    let mut t = 10;
    let mut frame = transmits(&drain(&mut a)).pop().unwrap();
    for hop in 0..4 {
        t += 1_000;
        let receiver = if hop % 2 == 0 { &mut b } else { &mut a };
        receiver.handle_rx(t, &frame);
        frame = transmits(&drain(receiver)).pop().expect("passed on");
        assert!(matches!(
            parse(&rules(), &frame).unwrap(),
            Message::Broadcast { .. }
        ));
    }
    assert_eq!(value(&b, "Pr82"), 111);
    assert_eq!(value(&a, "Pr82"), 222);
    // A drive not in IDC mode executes the broadcast but does not answer it.
    let mut d = drive(3);
    d.handle_rx(t + 1_000, &frame);
    assert!(transmits(&drain(&mut d)).is_empty());
    assert_eq!(value(&d, "b99.5"), 0);
}
