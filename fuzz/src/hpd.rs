//! Fuzz harnesses of the HPD codecs (manual 4.1, 3.8.1).

use arbitrary::{Arbitrary, Unstructured};
use drivespec_hpd::plc::PlcCodec;
use drivespec_hpd::{
    decode, parse, AckEnd, Data, FrameRules, LineDecoder, LineEvent, Message, Status,
};
use drivespec_spec::Spec;
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().expect("the built-in spec loads"))
}

fn rules() -> &'static FrameRules {
    static RULES: OnceLock<FrameRules> = OnceLock::new();
    RULES.get_or_init(|| FrameRules::from_spec(spec()).expect("HPD frame rules"))
}

fn codec() -> &'static PlcCodec {
    static CODEC: OnceLock<PlcCodec> = OnceLock::new();
    CODEC.get_or_init(|| PlcCodec::from_spec(spec()).expect("HPD PLC table"))
}

/// Frame decoder: never panics; a complete frame re-encodes to exactly the bytes it used.
pub fn frame(data: &[u8]) {
    for ack in [AckEnd::NextByte, AckEnd::Immediate] {
        match decode(rules(), data, ack) {
            Ok(Status::Complete(d)) => {
                assert!(d.len >= 2 && d.len <= data.len());
                if !cfg!(fuzzing) {
                    assert_eq!(
                        d.message
                            .to_bytes(rules())
                            .expect("a decoded frame re-encodes"),
                        &data[..d.len]
                    );
                }
            }
            Ok(Status::Incomplete { need }) => assert!(need >= 1),
            Err(e) => assert!(e.skip >= 1 && e.skip <= data.len()),
        }
    }
    let _ = parse(rules(), data);
}

/// Line decoder: every byte ends up in exactly one frame or discard, however it is chunked.
pub fn line(data: &[u8]) {
    let Some((&split, rest)) = data.split_first() else {
        return;
    };
    let chunk = usize::from(split % 32) + 1;
    let mut dec = LineDecoder::new(rules().clone()).with_timeout(10_000);
    let mut covered = 0usize;
    let mut sink = |e: LineEvent| {
        covered += match e {
            LineEvent::Frame(f) => f.len,
            LineEvent::Discarded(d) => d.len,
        }
    };
    for (i, piece) in rest.chunks(chunk).enumerate() {
        dec.feed(piece, Some(i as u64 * u64::from(split) * 97), &mut sink);
    }
    dec.finish(&mut sink);
    assert_eq!(covered, rest.len());
}

/// PLC program decoder: a program that decodes re-encodes to the bytes it came from.
pub fn plc(data: &[u8]) {
    let codec = codec();
    if let Ok(program) = codec.decode_program(data) {
        let bytes = codec
            .encode_program(&program)
            .expect("a decoded program re-encodes");
        assert_eq!(&data[..bytes.len()], bytes.as_slice());
        let _ = codec.check(&program);
        let listing = codec.format_program(&program);
        let text: String = listing
            .lines()
            .map(|l| format!("{}\n", l.split_once(": ").map_or(l, |(_, i)| i)))
            .collect();
        let back = codec
            .parse_listing(&text)
            .expect("a printed listing parses");
        // The listing drops the bits the manual leaves unused; it is a fixed point.
        assert_eq!(codec.format_program(&back), listing, "listing round trip");
    }
}

/// A structured message for the round-trip target.
#[derive(Debug, Arbitrary)]
enum FuzzMessage {
    Response(u8, u8, Vec<u8>),
    Ack(u8),
    ReadPlc(u8, u8, u8),
    WritePlc(u8, u8, Vec<u8>),
    ReadParam(u8, u8, u8),
    WriteParam(u8, u8, Vec<u8>),
    BitChange(u8, u8, u8, u8),
    Broadcast(u8, Vec<u8>),
}

impl FuzzMessage {
    fn build(self) -> Option<Message> {
        let data = |d: Vec<u8>| Data::new(d.get(..d.len().clamp(1, 4))?);
        Some(match self {
            FuzzMessage::Response(addr, par, d) => Message::Response {
                addr: addr % 32,
                par,
                data: data(d)?,
            },
            FuzzMessage::Ack(addr) => Message::Ack { addr: addr % 32 },
            FuzzMessage::ReadPlc(addr, lun, par) => Message::ReadPlc {
                addr: addr % 32,
                lun: lun % 4 + 1,
                par,
            },
            FuzzMessage::WritePlc(addr, par, d) => Message::WritePlc {
                addr: addr % 32,
                par,
                data: data(d)?,
            },
            FuzzMessage::ReadParam(addr, lun, par) => Message::ReadParam {
                addr: addr % 32,
                lun: lun % 4 + 1,
                par,
            },
            FuzzMessage::WriteParam(addr, par, d) => Message::WriteParam {
                addr: addr % 32,
                par,
                data: data(d)?,
            },
            FuzzMessage::BitChange(addr, par, mask, value) => Message::BitChange {
                addr: addr % 32,
                par,
                mask,
                value,
            },
            FuzzMessage::Broadcast(par, d) => Message::Broadcast {
                par,
                data: data(d)?,
            },
        })
    }
}

/// Structure-aware round trip: every valid message encodes and decodes to itself.
pub fn roundtrip(data: &[u8]) {
    let mut u = Unstructured::new(data);
    let Ok(m) = FuzzMessage::arbitrary(&mut u) else {
        return;
    };
    let Some(msg) = m.build() else { return };
    let bytes = msg.to_bytes(rules()).expect("a built message encodes");
    assert_eq!(parse(rules(), &bytes), Ok(msg));
}

/// The HPD reference drive fed arbitrary byte chunks, input changes and time steps: it never
/// panics, time never runs backwards in its outputs, and every answer it sends decodes.
pub fn model(data: &[u8]) {
    use drivespec_hpd::model::{Drive, DriveConfig, Output};
    let mut drive = Drive::new(spec(), DriveConfig::commissioned(0)).expect("commissioned drive");
    let mut now = 0u64;
    let mut rest = data;
    while let Some((&op, tail)) = rest.split_first() {
        let n = usize::from(op & 0x0F).min(tail.len());
        let (arg, next) = tail.split_at(n);
        rest = next;
        match op >> 4 {
            0..=9 => drive.handle_rx(now, arg),
            10 | 11 => drive.set_inputs(
                now,
                u16::from_le_bytes([
                    arg.first().copied().unwrap_or(0),
                    arg.get(1).copied().unwrap_or(0),
                ]),
            ),
            12 => drive.power_cycle(now),
            _ => {}
        }
        now += u64::from(op) * 613;
        drive.advance(now);
        let (mut last_tx, mut last_io) = (0, 0);
        while let Some(out) = drive.poll_output() {
            match out {
                Output::Transmit { at, bytes } => {
                    assert!(at >= last_tx, "answers go out in time order");
                    last_tx = at;
                    assert!(
                        parse(rules(), &bytes).is_ok(),
                        "the drive sends only valid messages: {bytes:02X?}"
                    );
                }
                Output::DigitalOutputs { at, .. } => {
                    assert!(at >= last_io, "output changes come in time order");
                    last_io = at;
                }
            }
        }
    }
}
