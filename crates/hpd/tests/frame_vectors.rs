//! The manual's serial examples (4.1, cases 1–8) from `spec/hpd/vectors`, byte-exact both ways.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_hpd::params::Target;
use drivespec_hpd::{parse, FrameRules, Message};
use drivespec_spec::hex::parse_hex;
use drivespec_spec::{FamilyId, Spec, VectorKind, VectorResult};

#[test]
fn manual_examples_decode_and_encode_byte_exact() {
    let spec = Spec::builtin().unwrap();
    let rules = FrameRules::from_spec(&spec).unwrap();
    let family = spec.family(FamilyId::Hpd);
    let vectors: Vec<_> = family
        .vectors
        .iter()
        .filter(|v| v.kind == VectorKind::HpdFrame)
        .collect();
    assert!(
        vectors.len() >= 8,
        "the eight examples of 4.1 are in the spec, found {}",
        vectors.len()
    );
    for v in vectors {
        let b = v.hpd_frame().unwrap();
        let request = parse_hex(&b.input.request).unwrap();
        if v.result == VectorResult::Invalid {
            assert!(
                parse(&rules, &request).is_err(),
                "{}: an invalid frame must not decode",
                v.id
            );
            assert!(
                b.expect.response.is_none(),
                "{}: nothing answers an invalid frame",
                v.id
            );
            continue;
        }
        let msg = parse(&rules, &request).unwrap_or_else(|e| panic!("{}: {e}", v.id));
        assert_eq!(
            msg.to_bytes(&rules).unwrap(),
            request,
            "{}: re-encoding",
            v.id
        );
        assert_eq!(Some(i64::from(msg.addr())), b.input.addr, "{}: addr", v.id);
        if let Some(cmd) = b.input.cmd {
            assert_eq!(i64::from(rules.code(msg.kind())), cmd, "{}: cmd", v.id);
        }
        let (lun, par) = match msg {
            Message::ReadPlc { lun, par, .. } | Message::ReadParam { lun, par, .. } => (lun, par),
            Message::WritePlc { par, data, .. }
            | Message::WriteParam { par, data, .. }
            | Message::Broadcast { par, data } => (data.len(), par),
            Message::BitChange { par, .. } => (rules.bit_change_lun, par),
            other => panic!("{}: a request, not {other:?}", v.id),
        };
        assert_eq!(Some(i64::from(lun)), b.input.lun, "{}: lun", v.id);
        assert_eq!(Some(i64::from(par)), b.input.par, "{}: par", v.id);
        match &b.expect.response {
            Some(hex) => {
                let response = parse_hex(hex).unwrap();
                let answer =
                    parse(&rules, &response).unwrap_or_else(|e| panic!("{}: response: {e}", v.id));
                assert!(!answer.is_request(), "{}", v.id);
                assert_eq!(
                    answer.addr(),
                    msg.addr(),
                    "{}: the addressed drive answers",
                    v.id
                );
                assert_eq!(
                    answer.to_bytes(&rules).unwrap(),
                    response,
                    "{}: response re-encoding",
                    v.id
                );
                if let (Some(want), Some(name), Message::Response { data, .. }) =
                    (b.expect.value, b.input.param.as_deref(), answer)
                {
                    let target = Target::parse(family, name).unwrap();
                    assert_eq!(target.value(&data), want, "{}: value of {name}", v.id);
                }
            }
            None => {
                let foreign = b
                    .input
                    .drive_addr
                    .is_some_and(|d| d != i64::from(msg.addr()));
                assert!(
                    foreign || msg.kind() == drivespec_hpd::MessageKind::Broadcast,
                    "{}: only broadcasts and other drives' messages go unanswered",
                    v.id
                );
            }
        }
    }
}
