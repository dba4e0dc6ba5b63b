//! Events of a PROFINET capture on hand-made frames: alarm notifications and ERR-RTA-PDUs,
//! a cyclic stream that stops while the capture goes on, DCP name conflicts, Sets without
//! answer and a rename during a running AR.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_capture::profinet::Events;
use drivespec_capture::write::PcapWriter;
use drivespec_capture::{CaptureReader, LinkType};
use drivespec_check::profinet::{check, PnOptions};
use drivespec_check::synth::profinet::{
    ethernet, psd_capture, rt_cyclic, PsdScenario, CONTROLLER_MAC, DEVICE_MAC,
};
use drivespec_check::Report;
use drivespec_spec::Spec;

const T0: u64 = 1_700_000_000_000_000;
const OTHER_MAC: [u8; 6] = [0x00, 0x1b, 0x1b, 0x0d, 0x0e, 0x0f];

/// A frame: time µs after T0, destination, source, RT payload with FrameID.
type Frame = (u64, [u8; 6], [u8; 6], Vec<u8>);

fn capture(frames: &[Frame]) -> Vec<u8> {
    let mut w = PcapWriter::new(Vec::new(), LinkType::ETHERNET, 65535).unwrap();
    for (t, dst, src, payload) in frames {
        w.write_packet(T0 + t, &ethernet(*dst, *src, 0x8892, payload))
            .unwrap();
    }
    w.into_inner().unwrap()
}

fn run(bytes: &[u8]) -> Report {
    let spec = Spec::builtin().unwrap();
    check(
        &spec,
        PnOptions::default(),
        Events::new(CaptureReader::new(bytes).unwrap()),
    )
    .unwrap()
}

/// An RTA-PDU on the low-priority alarm FrameID.
fn rta(pdu_type: u8, var_part: &[u8]) -> Vec<u8> {
    let mut p = vec![0xFE, 0x01, 0x80, 0x01, 0x80, 0x01, 0x10 | pdu_type, 0x01];
    p.extend_from_slice(&[0xff, 0xff, 0xff, 0xfe]);
    p.extend_from_slice(&(var_part.len() as u16).to_be_bytes());
    p.extend_from_slice(var_part);
    p
}

/// A DCP PDU: FrameID, ServiceID, ServiceType, Xid, ResponseDelay, blocks.
fn dcp(frame_id: u16, service: u8, kind: u8, xid: u32, blocks: &[u8]) -> Vec<u8> {
    let mut p = frame_id.to_be_bytes().to_vec();
    p.extend_from_slice(&[service, kind]);
    p.extend_from_slice(&xid.to_be_bytes());
    p.extend_from_slice(&[0, 0]);
    p.extend_from_slice(&(blocks.len() as u16).to_be_bytes());
    p.extend_from_slice(blocks);
    p
}

/// A NameOfStation block (option 2.2) with its BlockInfo/BlockQualifier word.
fn name_block(name: &str) -> Vec<u8> {
    let mut b = vec![2, 2];
    b.extend_from_slice(&((name.len() + 2) as u16).to_be_bytes());
    b.extend_from_slice(&[0, 0]);
    b.extend_from_slice(name.as_bytes());
    if name.len() % 2 == 1 {
        b.push(0);
    }
    b
}

fn cyclic(frame_id: u16, i: u16) -> Vec<u8> {
    rt_cyclic(frame_id, &[0x80; 4], 40, i.wrapping_mul(32), 0x35)
}

fn ids(r: &Report) -> Vec<&str> {
    r.violations
        .iter()
        .map(|v| v.requirement.as_str())
        .collect()
}

#[test]
fn an_alarm_notification_is_listed_and_an_abort_is_reported_in_words() {
    // AlarmNotification (low): BlockType 0x0002, length, version; AlarmType 3 (Pull),
    // API 0, slot 1, subslot 0x0001, module and submodule ident, AlarmSpecifier.
    let mut note = vec![0x00, 0x02, 0x00, 0x14, 0x01, 0x00, 0x00, 0x03];
    note.extend_from_slice(&[0, 0, 0, 0, 0x00, 0x01, 0x00, 0x01]);
    note.extend_from_slice(&[0, 0, 0, 0x2a, 0, 0, 0, 0x01, 0x00, 0x00]);
    let bytes = capture(&[
        (0, CONTROLLER_MAC, DEVICE_MAC, rta(1, &note)),
        (
            1000,
            DEVICE_MAC,
            CONTROLLER_MAC,
            rta(4, &[0xcf, 0x81, 0xfd, 0x05]),
        ),
    ]);
    let r = run(&bytes);
    let alarm = r
        .allowed
        .iter()
        .find(|o| o.requirement == "PN-ALARM-001")
        .expect("alarm listed");
    assert!(
        alarm
            .message
            .contains("alarm Pull (0x0003) (low priority) for API 0, slot 1, subslot 0x0001"),
        "{}",
        alarm.message
    );
    assert_eq!(alarm.start.frame, Some(1));
    assert_eq!(ids(&r), ["PN-ALARM-002"]);
    let abort = &r.violations[0];
    assert_eq!(abort.at.frame, Some(2));
    assert!(
        abort
            .message
            .contains("ErrorCode2 0x05 (AR consumer DHT/WDT expired (RTA_ERR_ABORT))"),
        "{}",
        abort.message
    );
    assert!(r.passed(), "an abort is a warning, not a failure");
}

#[test]
fn a_stream_that_stops_while_the_capture_goes_on_is_a_connection_abort() {
    let mut frames = Vec::new();
    for i in 0..100u16 {
        let t = u64::from(i) * 1000;
        if i < 30 {
            frames.push((t, CONTROLLER_MAC, DEVICE_MAC, cyclic(0x8001, i)));
        }
        frames.push((t + 500, DEVICE_MAC, CONTROLLER_MAC, cyclic(0x8002, i)));
    }
    let r = run(&capture(&frames));
    assert_eq!(ids(&r), ["PN-AR-001"], "{:#?}", r.violations);
    let v = &r.violations[0];
    assert!(v.subject.starts_with("0x8001"), "{}", v.subject);
    assert_eq!(v.at.frame, Some(59), "the stream's last frame");
    assert!(v.message.contains("no frame for 70 ms"), "{}", v.message);
    assert!(v.message.contains("bound 3 ms"), "{}", v.message);
}

#[test]
fn dcp_name_conflicts_and_unanswered_sets_are_reported() {
    let set = {
        let mut b = vec![1, 2, 0, 14, 0, 1];
        b.extend_from_slice(&[192, 168, 0, 9, 255, 255, 255, 0, 0, 0, 0, 0]);
        b
    };
    let bytes = capture(&[
        (0, DEVICE_MAC, CONTROLLER_MAC, dcp(0xfefe, 5, 0, 7, &[])),
        (
            10,
            CONTROLLER_MAC,
            DEVICE_MAC,
            dcp(0xfeff, 5, 1, 7, &name_block("drive-1")),
        ),
        (
            20,
            CONTROLLER_MAC,
            OTHER_MAC,
            dcp(0xfeff, 5, 1, 7, &name_block("drive-1")),
        ),
        // Answered Set, then a Set nobody answers, then 2 s of capture.
        (100, DEVICE_MAC, CONTROLLER_MAC, dcp(0xfefd, 4, 0, 8, &set)),
        (200, CONTROLLER_MAC, DEVICE_MAC, dcp(0xfefd, 4, 1, 8, &[])),
        (300, OTHER_MAC, CONTROLLER_MAC, dcp(0xfefd, 4, 0, 9, &set)),
        (
            2_000_300,
            DEVICE_MAC,
            CONTROLLER_MAC,
            dcp(0xfefe, 5, 0, 10, &[]),
        ),
    ]);
    let r = run(&bytes);
    assert_eq!(ids(&r), ["PN-DCP-001", "PN-DCP-002"], "{:#?}", r.violations);
    assert_eq!(r.violations[0].at.frame, Some(3));
    assert!(r.violations[0].message.contains("\"drive-1\""));
    assert_eq!(r.violations[1].at.frame, Some(6));
    assert!(r.passed());
}

#[test]
fn a_rename_during_a_running_ar_is_reported() {
    let spec = Spec::builtin().unwrap();
    let mut bytes = psd_capture(&spec, &PsdScenario::default()).unwrap();
    let end = drivespec_check::synth::profinet::START + 60_000_000;
    let rename = capture(&[(
        end - T0,
        DEVICE_MAC,
        OTHER_MAC,
        dcp(0xfefd, 4, 0, 11, &name_block("intruder")),
    )]);
    bytes.extend_from_slice(&rename[24..]);
    let r = run(&bytes);
    let v = r
        .violations
        .iter()
        .find(|v| v.requirement == "PN-DCP-003")
        .expect("rename reported");
    assert!(
        v.message.contains("to \"intruder\" while its AR runs"),
        "{}",
        v.message
    );
}
