//! The line decoder (manual 4.1) over generated streams: split invariance, time-outs, pairing.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_hpd::{
    Data, DiscardReason, Exchange, FrameRules, LineDecoder, LineEvent, Message, Mismatch, Pairer,
};
use drivespec_spec::Spec;
use proptest::prelude::*;
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

fn rules() -> FrameRules {
    FrameRules::from_spec(spec()).unwrap()
}

/// Decodes `stream` fed in the given chunk sizes; returns all events.
fn run(stream: &[u8], chunks: &[usize]) -> Vec<LineEvent> {
    let mut dec = LineDecoder::new(rules());
    let mut events = Vec::new();
    let mut rest = stream;
    for n in chunks.iter().cycle() {
        if rest.is_empty() {
            break;
        }
        let (head, tail) = rest.split_at((*n).clamp(1, rest.len()));
        dec.feed(head, None, &mut |e| events.push(e));
        rest = tail;
    }
    dec.finish(&mut |e| events.push(e));
    events
}

fn frames(events: &[LineEvent]) -> Vec<(u64, Message)> {
    events
        .iter()
        .filter_map(|e| {
            if let LineEvent::Frame(f) = e {
                Some((f.offset, f.message))
            } else {
                None
            }
        })
        .collect()
}

fn discarded(events: &[LineEvent]) -> usize {
    events
        .iter()
        .map(|e| {
            if let LineEvent::Discarded(d) = e {
                d.len
            } else {
                0
            }
        })
        .sum()
}

/// A stream of valid requests and answers mixed with noise.
fn stream() -> impl Strategy<Value = Vec<u8>> {
    let piece = prop_oneof![
        3 => (0u8..=31, any::<u8>(), prop::collection::vec(any::<u8>(), 1..=4)).prop_map(|(addr, par, d)| {
            Message::WriteParam { addr, par, data: Data::new(&d).unwrap() }.to_bytes(&rules()).unwrap()
        }),
        3 => (0u8..=31, 1u8..=4, any::<u8>()).prop_map(|(addr, lun, par)| Message::ReadParam { addr, lun, par }.to_bytes(&rules()).unwrap()),
        2 => (0u8..=31, any::<u8>(), prop::collection::vec(any::<u8>(), 1..=4)).prop_map(|(addr, par, d)| {
            Message::Response { addr, par, data: Data::new(&d).unwrap() }.to_bytes(&rules()).unwrap()
        }),
        1 => (0u8..=31).prop_map(|addr| Message::Ack { addr }.to_bytes(&rules()).unwrap()),
        1 => prop::collection::vec(any::<u8>(), 1..6),
        1 => Just(vec![0x7E, 0x7E, 0x00]),
    ];
    prop::collection::vec(piece, 0..40).prop_map(|v| v.concat())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn same_frames_however_the_stream_is_split(s in stream(), chunks in prop::collection::vec(1usize..40, 1..8)) {
        let whole = run(&s, &[s.len().max(1)]);
        let split = run(&s, &chunks);
        prop_assert_eq!(frames(&whole), frames(&split));
        prop_assert_eq!(discarded(&whole), discarded(&split));
        let covered: usize = whole.iter().map(|e| match e { LineEvent::Frame(f) => f.len, LineEvent::Discarded(d) => d.len }).sum();
        prop_assert_eq!(covered, s.len(), "every byte is a frame or a discard");
    }

    #[test]
    fn arbitrary_bytes_never_panic_and_are_all_accounted_for(s in prop::collection::vec(any::<u8>(), 0..300), chunks in prop::collection::vec(1usize..20, 1..5)) {
        let events = run(&s, &chunks);
        let covered: usize = events.iter().map(|e| match e { LineEvent::Frame(f) => f.len, LineEvent::Discarded(d) => d.len }).sum();
        prop_assert_eq!(covered, s.len());
    }
}

#[test]
fn an_acknowledge_followed_by_silence_is_complete_at_the_end() {
    let events = run(&[0x7E, 0x23], &[2]);
    assert_eq!(frames(&events), vec![(0, Message::Ack { addr: 3 })]);
}

#[test]
fn a_message_split_across_the_time_out_is_dropped() {
    // Pr26 time-outs come from the spec; any positive time-out shows the rule.
    let mut dec = LineDecoder::new(rules()).with_timeout(10_000);
    let mut events = Vec::new();
    let read = Message::ReadParam {
        addr: 1,
        lun: 2,
        par: 0x42,
    }
    .to_bytes(&rules())
    .unwrap();
    dec.feed(&read[..3], Some(0), &mut |e| events.push(e));
    dec.feed(&read[3..], Some(10_001), &mut |e| events.push(e));
    dec.finish(&mut |e| events.push(e));
    assert!(
        matches!(events[0], LineEvent::Discarded(d) if d.offset == 0 && d.len == 3 && d.reason == DiscardReason::Timeout { timeout: 10_000, elapsed: 10_001 }),
        "{events:?}"
    );
    assert!(frames(&events).is_empty(), "{events:?}");
    // Within the time-out the same bytes make a message.
    let mut dec = LineDecoder::new(rules()).with_timeout(10_000);
    let mut events = Vec::new();
    dec.feed(&read[..3], Some(0), &mut |e| events.push(e));
    dec.feed(&read[3..], Some(10_000), &mut |e| events.push(e));
    assert_eq!(
        frames(&events),
        vec![(
            0,
            Message::ReadParam {
                addr: 1,
                lun: 2,
                par: 0x42
            }
        )]
    );
}

#[test]
fn pairing_follows_the_message_table() {
    let r = rules();
    let msgs = [
        Message::ReadParam {
            addr: 1,
            lun: 2,
            par: 0x42,
        },
        Message::Response {
            addr: 1,
            par: 0x42,
            data: Data::new(&[0xD0, 0x07]).unwrap(),
        },
        Message::WriteParam {
            addr: 3,
            par: 0x54,
            data: Data::new(&[1]).unwrap(),
        },
        Message::Ack { addr: 3 },
        Message::Broadcast {
            par: 0x54,
            data: Data::new(&[1]).unwrap(),
        },
        Message::WriteParam {
            addr: 2,
            par: 0x54,
            data: Data::new(&[1]).unwrap(),
        },
        Message::Ack { addr: 4 },
        Message::ReadParam {
            addr: 5,
            lun: 1,
            par: 0x54,
        },
        Message::ReadParam {
            addr: 5,
            lun: 1,
            par: 0x54,
        },
        Message::Ack { addr: 5 },
    ];
    let bytes: Vec<u8> = msgs.iter().flat_map(|m| m.to_bytes(&r).unwrap()).collect();
    let mut pairer = Pairer::from_spec(spec()).unwrap();
    let mut out = Vec::new();
    for e in run(&bytes, &[7]) {
        if let LineEvent::Frame(f) = e {
            pairer.push(f, &mut |x| out.push(x));
        }
    }
    pairer.flush(&mut |x| out.push(x));
    let kinds: Vec<String> = out
        .iter()
        .map(|x| match x {
            Exchange::Answered { request, .. } => format!("answered {}", request.message.addr()),
            Exchange::Unanswered { request } => format!("unanswered {}", request.message.addr()),
            Exchange::Broadcast { .. } => "broadcast".into(),
            Exchange::Unexpected {
                reason: Mismatch::WrongDrive { expected, found },
                ..
            } => format!("wrong drive {expected}/{found}"),
            Exchange::Unexpected { reason, .. } => format!("unexpected {reason:?}"),
        })
        .collect();
    assert_eq!(
        kinds,
        [
            "answered 1",
            "answered 3",
            "broadcast",
            "wrong drive 2/4",
            "unanswered 5",
            "unexpected WrongKind { expected: Data, found: Ack }"
        ]
    );
}
