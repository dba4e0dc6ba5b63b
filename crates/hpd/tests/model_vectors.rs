//! The manual's serial examples (4.1 cases 1–8 and the derived vectors of
//! `spec/hpd/vectors/serial.toml`) run against the drive model: the drive at the vector's
//! address answers exactly `expect.response`, or stays silent.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_hpd::model::{Drive, DriveConfig};
use drivespec_hpd::{parse, Message};
use drivespec_spec::hex::parse_hex;
use drivespec_spec::VectorKind;
use model_util::*;

/// Whether bit `name` (`b99.14`) is a command the drive executes (bits.toml rules).
fn is_command(name: &str) -> bool {
    let (n, y) = name.trim_start_matches('b').split_once('.').unwrap();
    let p = family().parameter(n).unwrap();
    family().bitfields_of(&p.id).any(|bf| {
        bf.bit(y.parse().unwrap())
            .is_some_and(|b| b.rules.iter().any(|r| r.trigger == "command-executed"))
    })
}

#[test]
fn serial_vectors_run_against_the_model() {
    let rules = rules();
    let mut cases = 0;
    for v in family()
        .vectors
        .iter()
        .filter(|v| v.kind == VectorKind::HpdFrame)
    {
        if v.id.starts_with("serial-case-") {
            cases += 1;
        }
        let b = v.hpd_frame().unwrap();
        let at = b.input.drive_addr.or(b.input.addr).unwrap();
        let mut d = Drive::new(spec(), DriveConfig::commissioned(u8::try_from(at).unwrap()))
            .unwrap_or_else(|e| panic!("{}: {e}", v.id));
        let request = parse_hex(&b.input.request).unwrap();
        let msg = parse(&rules, &request).ok();
        let name = b.input.param.as_deref().or(b.input.target.as_deref());
        let want = b.expect.value.or(b.input.value);
        // What the example reads is put into the drive first (Pr7 is a measurement).
        if let (Some(Message::ReadParam { .. }), Some(name), Some(want)) = (msg, name, want) {
            set(&mut d, 0, name, want);
        }
        // Case 7 writes the PLC area, which takes instructions only while stopped.
        if let Some(Message::WritePlc { .. }) = msg {
            set(&mut d, 0, "b99.13", 0);
        }
        let before = name.map(|n| value(&d, n));
        d.handle_rx(1_000, &request);
        // Let the time-out of a half-received frame pass too.
        d.advance(1_000 + 600_000);
        let sent = transmits(&drain(&mut d));
        match &b.expect.response {
            Some(hex) => assert_eq!(sent, [parse_hex(hex).unwrap()], "{}", v.id),
            None => assert!(sent.is_empty(), "{}: the drive must stay silent", v.id),
        }
        // The effect of writes: in-range values are taken, others ignored.
        match (msg, name, want) {
            (Some(Message::WriteParam { .. } | Message::Broadcast { .. }), Some(n), Some(w)) => {
                let p = target(n).param();
                let in_range = family()
                    .resolve(p, None)
                    .range
                    .is_none_or(|r| r.contains(w));
                let expect = if in_range { w } else { before.unwrap() };
                assert_eq!(value(&d, n), expect, "{}: {n}", v.id);
            }
            (Some(Message::BitChange { .. }), Some(n), Some(w)) => {
                // HPD-CMD-SELF-CLEAR: a command bit reads 0 once executed.
                let expect = if is_command(n) { 0 } else { w };
                assert_eq!(value(&d, n), expect, "{}: {n}", v.id);
            }
            (Some(Message::WritePlc { par, data, .. }), _, _) => {
                let at = usize::from(par);
                assert_eq!(
                    &d.plc_area()[at..at + usize::from(data.len())],
                    data.as_slice(),
                    "{}",
                    v.id
                );
            }
            _ => {}
        }
    }
    assert_eq!(cases, 8, "the eight examples of manual 4.1");
}

#[test]
fn case_8_reads_the_appendix_g_program_of_a_drive_as_delivered() {
    // HPD-PLC-002: the default program is in the PLC area from the start.
    let d = drive(0);
    let listing: Vec<&str> = protocol()
        .default_program
        .iter()
        .map(|l| l.listing.as_str())
        .collect();
    let code = program_bytes(&listing);
    assert_eq!(&d.plc_area()[..code.len()], code.as_slice());
    assert_eq!(d.saved_plc_area(), d.plc_area());
}
