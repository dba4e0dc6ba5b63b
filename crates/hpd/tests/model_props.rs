//! Properties of the drive model over generated requests, byte streams and time steps
//! (manual 4.1, 3.8.1): it answers a request iff the request is correct and addressed to it
//! (HPD-SERIAL-003, HPD-SERIAL-012, HPD-SERIAL-013), identical inputs give identical outputs,
//! and nothing panics.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_hpd::model::{Drive, DriveConfig, Output};
use drivespec_hpd::{Data, LineDecoder, LineEvent, Message, MessageKind, Micros};
use model_util::*;
use proptest::prelude::*;
use std::sync::OnceLock;

/// A commissioned drive at address 2, built once and cloned per case.
fn template() -> &'static Drive {
    static DRIVE: OnceLock<Drive> = OnceLock::new();
    DRIVE.get_or_init(|| drive(2))
}

fn data() -> impl Strategy<Value = Data> {
    prop::collection::vec(any::<u8>(), 1..=4).prop_map(|v| Data::new(&v).unwrap())
}

/// Requests, mostly to drives 0–3 so that the drive at 2 is often addressed.
fn request() -> impl Strategy<Value = Message> {
    let addr = prop_oneof![4 => 0u8..=3, 1 => 0u8..=31];
    prop_oneof![
        (addr.clone(), 1u8..=4, any::<u8>()).prop_map(|(addr, lun, par)| Message::ReadPlc {
            addr,
            lun,
            par
        }),
        (addr.clone(), any::<u8>(), data()).prop_map(|(addr, par, data)| Message::WritePlc {
            addr,
            par,
            data
        }),
        (addr.clone(), 1u8..=4, any::<u8>()).prop_map(|(addr, lun, par)| Message::ReadParam {
            addr,
            lun,
            par
        }),
        (addr.clone(), any::<u8>(), data()).prop_map(|(addr, par, data)| Message::WriteParam {
            addr,
            par,
            data
        }),
        (addr.clone(), any::<u8>(), any::<u8>(), any::<u8>()).prop_map(
            |(addr, par, mask, value)| Message::BitChange {
                addr,
                par,
                mask,
                value
            }
        ),
        (any::<u8>(), data()).prop_map(|(par, data)| Message::Broadcast { par, data }),
        addr.prop_map(|addr| Message::Ack { addr }),
    ]
}

/// How a request is damaged on the line.
#[derive(Debug, Clone)]
enum Damage {
    None,
    Flip(usize, u8),
    Cut(usize),
    Noise(Vec<u8>),
}

fn damage() -> impl Strategy<Value = Damage> {
    prop_oneof![
        3 => Just(Damage::None),
        2 => (any::<usize>(), 0u8..8).prop_map(|(i, b)| Damage::Flip(i, b)),
        1 => any::<usize>().prop_map(Damage::Cut),
        1 => prop::collection::vec(any::<u8>(), 1..6).prop_map(Damage::Noise),
    ]
}

fn damaged(msg: &Message, d: &Damage) -> Vec<u8> {
    let mut b = bytes(msg);
    match d {
        Damage::None => {}
        Damage::Flip(i, bit) => {
            let i = i % b.len();
            b[i] ^= 1 << bit;
        }
        Damage::Cut(i) => b.truncate(i % b.len()),
        Damage::Noise(n) => b.splice(0..0, n.iter().copied()).for_each(drop),
    }
    b
}

/// The requests a correct drive at `me` answers in `stream`, by the codec's own decoding.
fn expected_answers(stream: &[u8], me: u8) -> usize {
    let area = usize::from(protocol().plc.area_bytes);
    let mut dec = LineDecoder::new(rules());
    let mut n = 0;
    dec.feed(stream, Some(1_000), &mut |e| {
        let LineEvent::Frame(f) = e else { return };
        let m = f.message;
        let in_area = match m {
            Message::ReadPlc { lun, par, .. } => usize::from(par) + usize::from(lun) <= area,
            Message::WritePlc { par, data, .. } => {
                usize::from(par) + usize::from(data.len()) <= area
            }
            _ => true,
        };
        if m.is_request() && m.kind() != MessageKind::Broadcast && m.addr() == me && in_area {
            n += 1;
        }
    });
    n
}

/// Feeds `stream` in `chunks` at time 1000 and counts the transmissions.
fn answers(d: &mut Drive, stream: &[u8], chunks: &[usize]) -> usize {
    let mut rest = stream;
    for n in chunks.iter().cycle() {
        if rest.is_empty() {
            break;
        }
        let (head, tail) = rest.split_at((*n).clamp(1, rest.len()));
        d.handle_rx(1_000, head);
        rest = tail;
    }
    transmits(&drain(d)).len()
}

/// One input to the drive.
#[derive(Debug, Clone)]
enum Op {
    Rx(Micros, Vec<u8>),
    Inputs(Micros, u16),
    Advance(Micros),
    PowerCycle(Micros),
}

fn ops() -> impl Strategy<Value = Vec<Op>> {
    let bytes = prop_oneof![
        (request(), damage()).prop_map(|(m, d)| damaged(&m, &d)),
        prop::collection::vec(any::<u8>(), 0..24),
    ];
    let op = prop_oneof![
        6 => (0u64..20_000, bytes).prop_map(|(t, b)| Op::Rx(t, b)),
        2 => (0u64..20_000, any::<u16>()).prop_map(|(t, v)| Op::Inputs(t, v)),
        2 => (0u64..40_000).prop_map(Op::Advance),
        1 => (0u64..20_000).prop_map(Op::PowerCycle),
    ];
    prop::collection::vec(op, 1..40)
}

/// Runs `ops` (times relative to the previous op, some going backwards) on `d`.
fn run(d: &mut Drive, ops: &[Op]) -> Vec<Output> {
    let mut t: Micros = 0;
    let mut back = false;
    let mut latest: Micros = d.now();
    let mut out = Vec::new();
    for op in ops {
        // Every other step is given a time in the past, which must change nothing.
        let step = |dt: Micros, t: &mut Micros, back: &mut bool| {
            *back = !*back;
            if *back {
                t.saturating_sub(dt)
            } else {
                *t += dt;
                *t
            }
        };
        let now = match op {
            Op::Rx(dt, _) | Op::Inputs(dt, _) | Op::Advance(dt) | Op::PowerCycle(dt) => {
                step(*dt, &mut t, &mut back)
            }
        };
        match op {
            Op::Rx(_, b) => d.handle_rx(now, b),
            Op::Inputs(_, v) => d.set_inputs(now, *v),
            Op::Advance(_) => d.advance(now),
            Op::PowerCycle(_) => d.power_cycle(now),
        }
        // Time never goes backwards: an earlier time is taken as the current one.
        latest = latest.max(now);
        assert_eq!(d.now(), latest);
        if let Some(next) = d.poll_timeout() {
            assert!(next > d.now(), "the next wake-up lies in the future");
        }
        out.extend(drain(d));
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn answers_a_request_iff_it_is_correct_and_addressed_to_it(
        msg in request(),
        dmg in damage(),
        chunks in prop::collection::vec(1usize..8, 1..4),
    ) {
        let stream = damaged(&msg, &dmg);
        let mut d = template().clone();
        let me = d.line().unwrap().address;
        prop_assert_eq!(answers(&mut d, &stream, &chunks), expected_answers(&stream, me));
    }

    #[test]
    fn identical_inputs_give_identical_outputs(ops in ops()) {
        let mut a = Drive::new(spec(), DriveConfig::commissioned(2)).unwrap();
        let mut b = Drive::new(spec(), DriveConfig::commissioned(2)).unwrap();
        let (out_a, out_b) = (run(&mut a, &ops), run(&mut b, &ops));
        prop_assert_eq!(out_a, out_b);
        prop_assert_eq!(a.memory(), b.memory());
        prop_assert_eq!(a.saved_memory(), b.saved_memory());
        prop_assert_eq!(a.plc_area(), b.plc_area());
        prop_assert_eq!(a.now(), b.now());
    }

    #[test]
    fn arbitrary_bytes_and_time_steps_never_panic(
        ops in ops(),
        noise in prop::collection::vec(any::<u8>(), 0..300),
        factory in any::<bool>(),
    ) {
        let config = if factory { DriveConfig::factory() } else { DriveConfig::commissioned(2) };
        let mut d = Drive::new(spec(), config).unwrap();
        run(&mut d, &ops);
        d.handle_rx(d.now(), &noise);
        d.advance(d.now() + 100_000);
        let _ = drain(&mut d);
    }
}

#[test]
fn outputs_come_in_time_order() {
    let mut d = drive(0);
    let mut out = Vec::new();
    for i in 0..200u64 {
        d.handle_rx(i * 997, &bytes(&read(0, "Pb99")));
        d.set_inputs(i * 997 + 3, if i % 3 == 0 { 0xFF } else { 0 });
        out.extend(drain(&mut d));
    }
    let times: Vec<Micros> = out
        .iter()
        .map(|o| match o {
            Output::Transmit { at, .. } | Output::DigitalOutputs { at, .. } => *at,
        })
        .collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]));
}
