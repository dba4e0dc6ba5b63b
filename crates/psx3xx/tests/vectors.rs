//! The manual's worked examples from `spec/psx3xx/vectors` (process images, time stamps, ISDU
//! exchanges, Direct Parameter page 1), decoded and encoded as each vector says. `sequence`
//! and `position` vectors belong to the reference model and are skipped; `acceptable`
//! vectors are run but may go either way.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_psx3xx::{
    ByteOrder, ErrorType, Input, Output, Request, Rules, Stamp, StampMeaning, Target, Value,
};
use drivespec_spec::hex::parse_hex;
use drivespec_spec::{FamilyId, Spec, Vector, VectorKind, VectorResult};
use std::collections::BTreeMap;
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

fn rules() -> Rules<'static> {
    Rules::from_spec(spec()).unwrap()
}

fn vectors(kind: VectorKind) -> Vec<&'static Vector> {
    spec()
        .family(FamilyId::Psx3xx)
        .vectors
        .iter()
        .filter(|v| v.kind == kind)
        .collect()
}

fn hex(v: &Option<String>) -> Option<Vec<u8>> {
    v.as_deref().map(|s| parse_hex(s).unwrap())
}

#[test]
fn process_image_vectors_decode_and_encode() {
    let rules = rules();
    let list = vectors(VectorKind::ProcessImage);
    assert!(list.len() >= 15, "process-image vectors: {}", list.len());
    for v in list {
        let body = v.process_image().unwrap();
        let (input, expect) = v.body.tables();
        let out = body.input.direction == "out";
        let format = body.input.format.map(|f| u8::try_from(f).unwrap());
        let order = body
            .input
            .byte_order
            .as_deref()
            .map_or(rules.wire_order(), |s| s.parse::<ByteOrder>().unwrap());
        let strict = v.result == VectorResult::Valid;
        let check = |ok: bool, what: &str| {
            if strict {
                assert!(ok, "{}: {what}", v.id);
            }
        };
        if let Some(bytes) = hex(&body.input.bytes) {
            let (values, again) = if out {
                let o = Output::parse(&rules, format.unwrap(), order, &bytes)
                    .unwrap_or_else(|e| panic!("{}: {e}", v.id));
                (o.values(), o.to_bytes(&rules, order).unwrap())
            } else {
                let i =
                    Input::parse(&rules, order, &bytes).unwrap_or_else(|e| panic!("{}: {e}", v.id));
                (i.values(), i.to_bytes(&rules, order).unwrap())
            };
            check(again == bytes, "re-encoding");
            for (k, want) in &expect {
                let got = values.iter().find(|(n, _)| n == k).map(|(_, x)| *x);
                check(got == want.as_integer(), &format!("field {k}: {got:?}"));
            }
        } else {
            let fields: Vec<(String, i64)> = input
                .iter()
                .filter(|(k, _)| !["direction", "format", "byte_order"].contains(&k.as_str()))
                .map(|(k, x)| (k.clone(), x.as_integer().unwrap()))
                .collect();
            let bytes = if out {
                Output::from_fields(&rules, format.unwrap(), &fields)
                    .unwrap_or_else(|e| panic!("{}: {e}", v.id))
                    .to_bytes(&rules, order)
                    .unwrap()
            } else {
                Input::from_fields(&rules, &fields)
                    .unwrap_or_else(|e| panic!("{}: {e}", v.id))
                    .to_bytes(&rules, order)
                    .unwrap()
            };
            check(Some(&bytes) == hex(&body.expect.bytes).as_ref(), "bytes");
        }
    }
}

#[test]
fn timestamp_vectors_have_their_meaning() {
    let rules = rules();
    let ts = rules.timestamp();
    let list = vectors(VectorKind::Timestamp);
    assert!(list.len() >= 8, "timestamp vectors: {}", list.len());
    for v in list {
        let b = v.timestamp().unwrap();
        let stamp = u16::try_from(b.input.stamp).unwrap();
        let m = Stamp(stamp).meaning(ts);
        if v.result == VectorResult::Valid {
            let e = &b.expect;
            if let Some(want) = e.delay_us {
                assert_eq!(
                    m.delay_us().map(i64::from),
                    Some(want),
                    "{}: delay_us",
                    v.id
                );
            }
            let flags = [
                ("immediate", e.immediate, m.is_immediate()),
                ("inactive", e.inactive, m.is_inactive()),
                ("valid", e.valid, m.is_valid()),
            ];
            for (key, want, got) in flags {
                if let Some(want) = want {
                    assert_eq!(got, want, "{}: {key}", v.id);
                }
            }
        }
        if v.result == VectorResult::Acceptable {
            assert_eq!(m, StampMeaning::Reserved, "{}: adopted reading", v.id);
        }
    }
}

/// What a device in delivery state (or in the vector's state) reads back for a target.
fn delivery_read(
    rules: &Rules<'_>,
    target: &Target<'_>,
    state: &BTreeMap<String, i64>,
) -> Option<Value> {
    let p = target.param()?;
    let dp = &rules.protocol().direct_parameters;
    if p.number == u32::from(dp.isdu_index) {
        let format = state
            .get("116")
            .map_or(rules.default_format(), |f| u8::try_from(*f).unwrap());
        let model = state.get("79").map_or(0, |m| u32::try_from(*m).unwrap());
        let page = rules.direct_page(format, model).ok()?;
        let sub = u8::try_from(p.subindex?).unwrap();
        let at = usize::from(sub.checked_sub(dp.subindex_offset)?);
        return page.get(at).map(|b| Value::Int(i64::from(*b)));
    }
    state.get(&p.id).copied().or(p.default).map(Value::Int)
}

#[test]
fn isdu_vectors_are_answered_as_the_vector_says() {
    let rules = rules();
    let family = spec().family(FamilyId::Psx3xx);
    let list = vectors(VectorKind::Isdu);
    assert!(list.len() >= 40, "isdu vectors: {}", list.len());
    let mut stateful = 0;
    for v in list {
        let b = v.isdu().unwrap();
        let index = u16::try_from(b.input.index).unwrap();
        let subindex = b.input.subindex.map_or(0, |s| u8::try_from(s).unwrap());
        let data = hex(&b.input.data);
        let state = b.input.state.clone().unwrap_or_default();
        let model = v.model.as_deref().and_then(|m| family.model(m));
        let request = match b.input.op.as_str() {
            "read" => Request::Read { index, subindex },
            "write" => Request::Write {
                index,
                subindex,
                data: data.clone().unwrap(),
            },
            other => panic!("{}: op {other:?}", v.id),
        };
        let strict = v.result == VectorResult::Valid;
        let checked = rules.check_request(&request, model);
        if let Some(code) = b.expect.error {
            let code = ErrorType(u16::try_from(code).unwrap());
            assert!(
                rules.error_types().contains(code),
                "{}: {code} in the spec",
                v.id
            );
            assert_eq!(ErrorType::parse(&code.to_bytes()), Ok(code), "{}", v.id);
            let alternatives: Vec<ErrorType> = b
                .expect
                .error_alternatives
                .iter()
                .flatten()
                .map(|x| ErrorType(u16::try_from(*x).unwrap()))
                .collect();
            match checked {
                Err(rejection) if strict => {
                    assert_eq!(rejection.error, code, "{}: {rejection}", v.id);
                    for alt in alternatives {
                        assert!(rejection.accepts(alt), "{}: {alt} also accepted", v.id);
                    }
                }
                Err(_) => {}
                // Refusals that depend on other parameters are the reference model's.
                Ok(_) if !state.is_empty() => stateful += 1,
                Ok(a) => assert!(!strict, "{}: accepted {a:?}", v.id),
            }
            continue;
        }
        let accepted = match checked {
            Ok(a) => a,
            Err(e) if !strict => {
                let _ = e;
                continue;
            }
            Err(e) => panic!("{}: refused: {e}", v.id),
        };
        match &request {
            Request::Read { .. } => {
                let Some(data) = hex(&b.expect.data) else {
                    continue;
                };
                let value = rules
                    .decode_value(&accepted.target, &data)
                    .unwrap_or_else(|e| panic!("{}: {e}", v.id));
                if let Some(want) = b.expect.value {
                    assert_eq!(value, Value::Int(want), "{}: value", v.id);
                }
                assert_eq!(
                    rules.encode_value(&accepted.target, &value).unwrap(),
                    data,
                    "{}: re-encoding",
                    v.id
                );
                if let Some(delivered) = delivery_read(&rules, &accepted.target, &state) {
                    assert_eq!(
                        rules.encode_value(&accepted.target, &delivered).unwrap(),
                        data,
                        "{}: the spec's value reads as the vector's data",
                        v.id
                    );
                }
                if let (Some(p), Value::Int(x)) = (accepted.target.param(), &value) {
                    if !rules.command_rows(p).is_empty() {
                        assert!(!rules.readbacks(p, *x).is_empty(), "{}: readback", v.id);
                    }
                }
            }
            Request::Write { data, .. } => {
                assert_eq!(
                    rules
                        .encode_value(&accepted.target, accepted.value.as_ref().unwrap())
                        .unwrap(),
                    *data,
                    "{}: re-encoding",
                    v.id
                );
                if let Some(name) = b.expect.command.as_deref() {
                    assert_eq!(
                        accepted.command.map(|c| c.name.as_str()),
                        Some(name),
                        "{}: command",
                        v.id
                    );
                }
            }
        }
    }
    assert!(
        stateful <= 6,
        "stateful refusals left to the model: {stateful}"
    );
}

#[test]
fn direct_parameter_vectors_decode() {
    let rules = rules();
    let list = vectors(VectorKind::DirectParameter);
    assert!(list.len() >= 4, "direct-parameter vectors: {}", list.len());
    for v in list {
        let b = v.direct_parameter().unwrap();
        let first = u8::try_from(b.input.first_address.unwrap()).unwrap();
        let bytes = parse_hex(&b.input.bytes).unwrap();
        let page = rules
            .decode_direct(first, &bytes)
            .unwrap_or_else(|e| panic!("{}: {e}", v.id));
        assert!(page.warnings.is_empty(), "{}: {:?}", v.id, page.warnings);
        let json = serde_json::to_value(&page).unwrap();
        let (_, expect) = v.body.tables();
        for (k, want) in &expect {
            let want = serde_json::to_value(want).unwrap();
            assert_eq!(json.get(k), Some(&want), "{}: {k}", v.id);
        }
        let format = page.pd_out_format.unwrap();
        let built = rules
            .direct_page(format, page.model_code.unwrap_or(0))
            .unwrap();
        let region = &built[usize::from(first)..usize::from(first) + bytes.len()];
        if page.device_id.is_some() {
            assert_eq!(region, &bytes[..], "{}: built page", v.id);
        } else {
            assert_eq!(region[..7], bytes[..7], "{}: built page", v.id);
        }
    }
}
