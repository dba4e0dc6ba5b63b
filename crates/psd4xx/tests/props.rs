//! Properties of the PSD4xx codec (manual 3.2.2, 3.5, 3.8) over generated values and bytes:
//! round trips for every representation, every option setting, no panic on any bytes, and a
//! typed `Truncated { need, have }` for every short length.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_positioner::ByteOrder;
use drivespec_psd4xx::{
    explain, explain_pkw, DecodeError, Direction, Input, Options, Output, Pkw, PkwRequest,
    PkwResponse, RecordRead, RecordValue, RecordWrite, Reply, Request, Rules, Width,
};
use drivespec_spec::psd4xx::{IndLayout, WordFill, WordPosition};
use drivespec_spec::{DataType, FamilyId, Spec};
use proptest::prelude::*;
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

/// The manual's rules and every combination of the settings.
fn all_rules() -> &'static [Rules] {
    static RULES: OnceLock<Vec<Rules>> = OnceLock::new();
    RULES.get_or_init(|| {
        let base = Options::manual(spec()).unwrap();
        let mut out = vec![Rules::from_spec(spec()).unwrap()];
        for byte_order in ByteOrder::ALL {
            for invert_bit_words in [true, false] {
                for word_position in [WordPosition::Low, WordPosition::High] {
                    for word_fill in [WordFill::Zero, WordFill::SignExtend] {
                        for ind_layout in [IndLayout::Word, IndLayout::HighByte, IndLayout::LowByte]
                        {
                            let o = Options {
                                byte_order,
                                invert_bit_words,
                                word_position,
                                word_fill,
                                ind_layout,
                            };
                            if o != base {
                                out.push(Rules::with_options(spec(), o).unwrap());
                            }
                        }
                    }
                }
            }
        }
        out
    })
}

fn manual() -> &'static Rules {
    &all_rules()[0]
}

fn any_rules() -> impl Strategy<Value = &'static Rules> {
    (0..all_rules().len()).prop_map(|i| &all_rules()[i])
}

/// Numeric parameters: (pnu, width, signed).
fn numeric_params() -> Vec<(u16, Width, bool)> {
    spec()
        .family(FamilyId::Psd4xx)
        .parameters
        .iter()
        .filter_map(|p| {
            let w = Width::of_type(p.data_type)?;
            Some((u16::try_from(p.number).ok()?, w, p.data_type.signed()))
        })
        .collect()
}

fn pkw_block<C: From<u8> + std::fmt::Debug>() -> impl Strategy<Value = Pkw<C>> {
    (
        0u8..=15,
        any::<bool>(),
        0u16..=2047,
        any::<u16>(),
        any::<u32>(),
    )
        .prop_map(|(ak, spm, pnu, ind, pwe)| Pkw {
            ak: C::from(ak),
            spm,
            pnu,
            ind,
            pwe,
        })
}

fn output() -> impl Strategy<Value = Output> {
    (pkw_block(), any::<u16>(), any::<i32>()).prop_map(|(pkw, control, target)| Output {
        pkw,
        control,
        target,
    })
}

fn input() -> impl Strategy<Value = Input> {
    (pkw_block(), any::<u16>(), any::<i16>(), any::<i32>()).prop_map(
        |(pkw, status, speed, actual)| Input {
            pkw,
            status,
            speed,
            actual,
        },
    )
}

/// A value of a parameter's width and signedness.
fn value_of(width: Width, signed: bool) -> impl Strategy<Value = i64> {
    let (min, max) = width.range(Some(signed));
    min..=max
}

fn index(rules: &Rules) -> impl Strategy<Value = u16> {
    0..=rules.pkw().index_max()
}

/// Typed requests for numeric parameters (scalar or as array elements), reads of any PNU.
fn request(rules: &'static Rules) -> impl Strategy<Value = Request> {
    let params = numeric_params();
    let write = (
        prop::sample::select(params),
        prop::option::of(index(rules)),
        any::<bool>(),
    )
        .prop_flat_map(|((pnu, width, signed), index, other_width)| {
            let width = match (other_width, width) {
                (false, w) => w,
                (true, Width::Word) => Width::Dword,
                (true, Width::Dword) => Width::Word,
            };
            // A value in range of both the command width and the parameter's signedness.
            value_of(width, signed).prop_map(move |value| Request::Write {
                pnu,
                index,
                width,
                value,
            })
        });
    prop_oneof![
        Just(Request::None),
        (0u16..=2047, prop::option::of(index(rules)))
            .prop_map(|(pnu, index)| Request::Read { pnu, index }),
        (0u16..=2047).prop_map(|pnu| Request::Count { pnu }),
        write,
    ]
}

fn reply(rules: &'static Rules) -> impl Strategy<Value = Reply> {
    let params = numeric_params();
    let value = (prop::sample::select(params), prop::option::of(index(rules))).prop_flat_map(
        |((pnu, width, signed), index)| {
            value_of(width, signed).prop_map(move |value| Reply::Value {
                pnu,
                index,
                width,
                value,
            })
        },
    );
    prop_oneof![
        Just(Reply::None),
        (0u16..=2047, any::<u32>()).prop_map(|(pnu, count)| Reply::Count { pnu, count }),
        (0u16..=2047, index(rules), any::<u32>()).prop_map(|(pnu, index, e)| Reply::Error {
            pnu,
            index,
            error: drivespec_psd4xx::ErrorCode(e),
        }),
        value,
    ]
}

fn record_write() -> impl Strategy<Value = RecordWrite> {
    (prop::sample::select(numeric_params()), any::<u8>()).prop_flat_map(
        |((index, width, signed), control)| {
            value_of(width, signed).prop_map(move |value| RecordWrite {
                index,
                control,
                width,
                value,
            })
        },
    )
}

fn record_read() -> impl Strategy<Value = RecordRead> {
    let text = prop::collection::vec(1u8..=255, 0..=20).prop_map(|t| RecordRead {
        index: 13,
        value: RecordValue::Text(t),
    });
    let number = prop::sample::select(numeric_params()).prop_flat_map(|(index, width, signed)| {
        value_of(width, signed).prop_map(move |value| RecordRead {
            index,
            value: RecordValue::Number { width, value },
        })
    });
    prop_oneof![text, number]
}

fn expect_len_error(r: Result<impl std::fmt::Debug, DecodeError>, need: usize, have: usize) {
    match have.cmp(&need) {
        std::cmp::Ordering::Less => {
            assert_eq!(r.unwrap_err(), DecodeError::Truncated { need, have })
        }
        std::cmp::Ordering::Greater => assert_eq!(
            r.unwrap_err(),
            DecodeError::TrailingData {
                expected: need,
                have
            }
        ),
        std::cmp::Ordering::Equal => assert!(r.is_ok()),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn output_round_trips(rules in any_rules(), out in output()) {
        let bytes = out.to_bytes(rules).unwrap();
        prop_assert_eq!(bytes.len(), 14);
        prop_assert_eq!(Output::parse(rules, &bytes).unwrap(), out);
    }

    #[test]
    fn input_round_trips(rules in any_rules(), inp in input()) {
        let bytes = inp.to_bytes(rules).unwrap();
        prop_assert_eq!(bytes.len(), 16);
        prop_assert_eq!(Input::parse(rules, &bytes).unwrap(), inp);
    }

    #[test]
    fn every_image_re_encodes(rules in any_rules(), out in prop::collection::vec(any::<u8>(), 14), inp in prop::collection::vec(any::<u8>(), 16)) {
        prop_assert_eq!(Output::parse(rules, &out).unwrap().to_bytes(rules).unwrap(), out);
        prop_assert_eq!(Input::parse(rules, &inp).unwrap().to_bytes(rules).unwrap(), inp);
    }

    #[test]
    fn pkw_blocks_round_trip(rules in any_rules(), req in pkw_block::<drivespec_psd4xx::CommandCode>(), b in prop::collection::vec(any::<u8>(), 8)) {
        let bytes = req.to_bytes(rules.pkw()).unwrap();
        prop_assert_eq!(PkwRequest::parse(rules.pkw(), &bytes).unwrap(), req);
        prop_assert_eq!(PkwResponse::parse(rules.pkw(), &b).unwrap().to_bytes(rules.pkw()).unwrap(), b);
    }

    #[test]
    fn any_bytes_any_length(rules in any_rules(), bytes in prop::collection::vec(any::<u8>(), 0..40)) {
        let n = bytes.len();
        expect_len_error(Output::parse(rules, &bytes), 14, n);
        expect_len_error(Input::parse(rules, &bytes), 16, n);
        expect_len_error(PkwRequest::parse(rules.pkw(), &bytes), 8, n);
        expect_len_error(PkwResponse::parse(rules.pkw(), &bytes), 8, n);
        for d in [Direction::Out, Direction::In] {
            let need = if d == Direction::Out { 14 } else { 16 };
            match explain(rules, d, &bytes) {
                Ok(e) => {
                    prop_assert_eq!(n, need);
                    let _ = e.to_string();
                    let _ = serde_json::to_string(&e).unwrap();
                }
                Err(e) => prop_assert_eq!(e, if n < need {
                    DecodeError::Truncated { need, have: n }
                } else {
                    DecodeError::TrailingData { expected: need, have: n }
                }),
            }
            if let Ok(p) = explain_pkw(rules, d, &bytes) {
                let _ = p.to_string();
            }
        }
    }

    #[test]
    fn every_prefix_of_an_image_is_truncated(rules in any_rules(), out in output(), inp in input()) {
        let o = out.to_bytes(rules).unwrap();
        let i = inp.to_bytes(rules).unwrap();
        for k in 0..o.len() {
            prop_assert_eq!(Output::parse(rules, &o[..k]), Err(DecodeError::Truncated { need: 14, have: k }));
        }
        for k in 0..i.len() {
            prop_assert_eq!(Input::parse(rules, &i[..k]), Err(DecodeError::Truncated { need: 16, have: k }));
        }
    }

    #[test]
    fn byte_order_setting_mirrors_each_field(out in output()) {
        let spec = spec();
        let mut o = Options::manual(spec).unwrap();
        let be = Rules::with_options(spec, o).unwrap();
        o.byte_order = o.byte_order.flipped();
        let le = Rules::with_options(spec, o).unwrap();
        let a = out.to_bytes(&be).unwrap();
        let b = out.to_bytes(&le).unwrap();
        for f in &be.layout().output.module.fields {
            let mut x = a[f.field.span()].to_vec();
            x.reverse();
            prop_assert_eq!(x.as_slice(), &b[f.field.span()], "field {}", f.name);
        }
    }

    #[test]
    fn requests_round_trip(r in request(manual())) {
        let rules = manual();
        let block = rules.pkw().encode_request(&r).unwrap();
        prop_assert_eq!(rules.pkw().request(&block), Some(r));
        let text = rules.pkw().format_request(&r);
        prop_assert_eq!(rules.pkw().parse_request(&text).unwrap(), r, "{}", text);
        let bytes = block.to_bytes(rules.pkw()).unwrap();
        prop_assert!(explain_pkw(rules, Direction::Out, &bytes).is_ok());
    }

    #[test]
    fn requests_round_trip_in_every_setting(rules in any_rules(), seed in any::<u64>()) {
        // The same typed request survives every setting.
        let r = Request::Write { pnu: 3, index: None, width: Width::Dword, value: (seed as i32).into() };
        let block = rules.pkw().encode_request(&r).unwrap();
        prop_assert_eq!(rules.pkw().request(&block), Some(r));
        let w = Request::Write { pnu: 2, index: None, width: Width::Word, value: (seed as i16).into() };
        let block = rules.pkw().encode_request(&w).unwrap();
        prop_assert_eq!(rules.pkw().request(&block), Some(w));
        let i = (seed as u16) & rules.pkw().index_max();
        let a = Request::Read { pnu: 13, index: Some(i) };
        let block = rules.pkw().encode_request(&a).unwrap();
        prop_assert_eq!(rules.pkw().request(&block), Some(a));
    }

    #[test]
    fn replies_round_trip(r in reply(manual())) {
        let rules = manual();
        let block = rules.pkw().encode_reply(&r).unwrap();
        prop_assert_eq!(rules.pkw().reply(&block), Some(r));
        let text = rules.pkw().format_reply(&r);
        prop_assert_eq!(rules.pkw().parse_reply(&text).unwrap(), r, "{}", text);
    }

    #[test]
    fn any_text_parses_or_errs(text in "\\PC{0,24}", t2 in "(read|write|count|none|value|error|read-array|write-dword)(:[0-9x-]{0,6}(\\[[0-9]{0,6}\\]?)?(=[-0-9a-z]{0,12})?)?") {
        let pkw = manual().pkw();
        for t in [&text, &t2] {
            if let Ok(r) = pkw.parse_request(t) {
                prop_assert!(pkw.encode_request(&r).is_ok(), "{}", t);
            }
            if let Ok(r) = pkw.parse_reply(t) {
                prop_assert!(pkw.encode_reply(&r).is_ok(), "{}", t);
            }
        }
    }

    #[test]
    fn record_writes_round_trip(rules in any_rules(), w in record_write()) {
        let rec = rules.record();
        let data = w.to_bytes(rec).unwrap();
        prop_assert_eq!(data.len(), rec.write_len(w.width));
        prop_assert_eq!(RecordWrite::parse(rec, w.index, &data).unwrap(), w);
        prop_assert_eq!(w.executes(rec), w.control != rec.control_ignore());
        for k in 0..data.len() {
            prop_assert_eq!(RecordWrite::parse(rec, w.index, &data[..k]), Err(DecodeError::Truncated { need: data.len(), have: k }));
        }
    }

    #[test]
    fn record_reads_round_trip(rules in any_rules(), r in record_read()) {
        let rec = rules.record();
        let data = r.to_bytes(rec).unwrap();
        prop_assert_eq!(RecordRead::parse(rec, r.index, &data).unwrap(), r.clone());
        if let RecordValue::Number { width, .. } = r.value {
            for k in 0..data.len() {
                prop_assert_eq!(RecordRead::parse(rec, r.index, &data[..k]), Err(DecodeError::Truncated { need: rec.read_len(width), have: k }));
            }
        }
    }

    #[test]
    fn records_any_index_any_bytes(index in any::<u16>(), data in prop::collection::vec(any::<u8>(), 0..32)) {
        let rec = manual().record();
        if let Ok(w) = RecordWrite::parse(rec, index, &data) {
            prop_assert_eq!(w.to_bytes(rec).unwrap(), data.clone());
        }
        if let Ok(r) = RecordRead::parse(rec, index, &data) {
            let again = RecordRead::parse(rec, index, &r.to_bytes(rec).unwrap()).unwrap();
            prop_assert_eq!(again, r);
        }
        for width in [Width::Word, Width::Dword] {
            let _ = RecordWrite::parse_as(rec, index, width, &data);
            let _ = RecordRead::parse_as(rec, index, width, &data);
        }
    }
}

#[test]
fn record_errors_name_the_index() {
    let rec = manual().record();
    assert_eq!(
        RecordWrite::parse(rec, 20, &[1, 0, 0]),
        Err(DecodeError::UnknownIndex { index: 20 })
    );
    assert_eq!(
        RecordWrite::parse(rec, 13, &[1, 0, 0]),
        Err(DecodeError::NoRecordLength { index: 13 })
    );
    assert_eq!(
        RecordRead::parse(rec, 13, &[b'x'; 21]),
        Err(DecodeError::TrailingData {
            expected: 20,
            have: 21
        })
    );
    let w = RecordWrite {
        index: 44,
        control: 1,
        width: Width::Word,
        value: -1,
    };
    assert_eq!(
        w.to_bytes(rec),
        Err(drivespec_psd4xx::EmitError::Value {
            value: -1,
            min: 0,
            max: 65535
        })
    );
    assert_eq!(
        RecordWrite::parse_as(rec, 20, Width::Dword, &[0, 0, 0, 1, 2]).map(|w| w.value),
        Ok(258)
    );
}

#[test]
fn emit_errors_carry_data() {
    let rules = manual();
    let out = Output {
        pkw: Pkw {
            ak: drivespec_psd4xx::CommandCode(16),
            ..Pkw::default()
        },
        ..Output::default()
    };
    assert_eq!(
        out.to_bytes(rules),
        Err(drivespec_psd4xx::EmitError::FieldRange {
            field: "ak",
            value: 16,
            max: 15
        })
    );
    let big = PkwRequest {
        pnu: 2048,
        ..Pkw::default()
    };
    assert_eq!(
        big.to_bytes(rules.pkw()),
        Err(drivespec_psd4xx::EmitError::FieldRange {
            field: "pnu",
            value: 2048,
            max: 2047
        })
    );
    assert_eq!(
        Output::default().emit(rules, &mut [0; 13]),
        Err(drivespec_psd4xx::EmitError::Buffer { need: 14, have: 13 })
    );
    // The default image is all zero, which is the manual's "no command".
    assert_eq!(Output::idle(rules), Output::default());
    assert!(matches!(
        spec()
            .family(FamilyId::Psd4xx)
            .parameter("44")
            .map(|p| p.data_type),
        Some(DataType::U16)
    ));
}
