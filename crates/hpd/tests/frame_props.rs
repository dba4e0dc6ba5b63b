//! Properties of the HPD frame codec (manual 4.1) over generated messages and bytes.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_hpd::{decode, parse, AckEnd, Data, FrameRules, Message, Status};
use drivespec_spec::Spec;
use proptest::prelude::*;
use std::sync::OnceLock;

fn rules() -> &'static FrameRules {
    static RULES: OnceLock<FrameRules> = OnceLock::new();
    RULES.get_or_init(|| FrameRules::from_spec(&Spec::builtin().unwrap()).unwrap())
}

fn data() -> impl Strategy<Value = Data> {
    prop::collection::vec(any::<u8>(), 1..=4).prop_map(|v| Data::new(&v).unwrap())
}

fn message() -> impl Strategy<Value = Message> {
    let addr = 0u8..=31;
    prop_oneof![
        (addr.clone(), any::<u8>(), data()).prop_map(|(addr, par, data)| Message::Response {
            addr,
            par,
            data
        }),
        addr.clone().prop_map(|addr| Message::Ack { addr }),
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
        (addr, any::<u8>(), any::<u8>(), any::<u8>()).prop_map(|(addr, par, mask, value)| {
            Message::BitChange {
                addr,
                par,
                mask,
                value,
            }
        }),
        (any::<u8>(), data()).prop_map(|(par, data)| Message::Broadcast { par, data }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    #[test]
    fn encode_then_decode_is_identity(msg in message()) {
        let bytes = msg.to_bytes(rules()).unwrap();
        prop_assert_eq!(bytes.len(), msg.buffer_len(rules()).unwrap());
        prop_assert_eq!(parse(rules(), &bytes), Ok(msg));
        // Followed by the next message's STX, the stream decoder finds the same message.
        let mut stream = bytes.clone();
        stream.push(rules().stx);
        stream.push(0x80);
        let got = decode(rules(), &stream, AckEnd::NextByte).unwrap();
        prop_assert_eq!(got, Status::Complete(drivespec_hpd::Decoded { message: msg, len: bytes.len() }));
    }

    #[test]
    fn every_proper_prefix_is_incomplete(msg in message()) {
        let bytes = msg.to_bytes(rules()).unwrap();
        for n in 0..bytes.len() {
            let got = decode(rules(), &bytes[..n], AckEnd::NextByte);
            prop_assert!(matches!(got, Ok(Status::Incomplete { need }) if need >= 1), "prefix {n}: {got:?}");
        }
    }

    #[test]
    fn no_panic_and_progress_on_arbitrary_bytes(bytes in prop::collection::vec(any::<u8>(), 0..64), immediate in any::<bool>()) {
        let ack = if immediate { AckEnd::Immediate } else { AckEnd::NextByte };
        match decode(rules(), &bytes, ack) {
            Ok(Status::Complete(d)) => prop_assert!(d.len >= 2 && d.len <= bytes.len()),
            Ok(Status::Incomplete { need }) => prop_assert!(need >= 1),
            Err(e) => prop_assert!(e.skip >= 1 && e.skip <= bytes.len(), "{e:?}"),
        }
        let _ = parse(rules(), &bytes);
    }

    #[test]
    fn a_flipped_bit_never_yields_the_original_message(msg in message(), bit in 0usize..136) {
        let mut bytes = msg.to_bytes(rules()).unwrap();
        let bit = bit % (bytes.len() * 8);
        bytes[bit / 8] ^= 1 << (bit % 8);
        prop_assert_ne!(parse(rules(), &bytes), Ok(msg));
    }
}

#[test]
fn resync_skips_to_the_next_possible_stx() {
    let r = rules();
    // Garbage, a stuffed 7E 00 that must not be taken for STX, then a real request.
    let bytes = [0x11, 0x7E, 0x00, 0x22, 0x7E, 0x80, 0x01, 0x54, 0xD5];
    let err = decode(r, &bytes, AckEnd::NextByte).unwrap_err();
    assert_eq!(err.skip, 4);
    let got = decode(r, &bytes[err.skip..], AckEnd::NextByte).unwrap();
    assert_eq!(
        got,
        Status::Complete(drivespec_hpd::Decoded {
            message: Message::ReadParam {
                addr: 0,
                lun: 1,
                par: 0x54
            },
            len: 5
        })
    );
}

#[test]
fn errors_carry_their_data() {
    use drivespec_hpd::FrameError::*;
    let r = rules();
    assert_eq!(
        parse(r, &[0x7E, 0x80, 0x01, 0x54, 0xD6]),
        Err(Checksum {
            expected: 0xD5,
            found: 0xD6
        })
    );
    assert_eq!(
        parse(r, &[0x7E, 0x80, 0x05, 0x54, 0xD9]),
        Err(Lun {
            lun: 5,
            min: 1,
            max: 4
        })
    );
    assert_eq!(
        parse(r, &[0x7E, 0xE1, 0x01, 0x54, 0x01, 0x37]),
        Err(BroadcastAddr { addr: 1 })
    );
    assert_eq!(
        parse(r, &[0x7E, 0xC0, 0x01, 0x93, 0xBF, 0x13]),
        Err(LengthMismatch {
            expected: 2,
            found: 1
        })
    );
    assert_eq!(parse(r, &[0x7E, 0x00]), Err(ZeroCmdAddr));
    assert_eq!(
        parse(r, &[0x7E, 0x20, 0x01, 0x54, 0x09, 0x7E, 0x01]),
        Err(Stuffing {
            offset: 5,
            stuff: 0,
            found: 1
        })
    );
    assert_eq!(
        parse(r, &[0x7E, 0x80, 0x01]),
        Err(Truncated { need: 2, have: 3 })
    );
    assert_eq!(
        parse(r, &[0x7E, 0x80, 0x01, 0x54, 0xD5, 0x00]),
        Err(TrailingData { extra: 1 })
    );
    assert_eq!(
        parse(r, &[0x55]),
        Err(NoStx {
            stx: 0x7E,
            found: 0x55
        })
    );
    assert_eq!(parse(r, &[0x7E, 0x1F]), Err(UnknownCmd { cmd: 0 }));
}
