//! Properties of the PSx3xx codecs over generated values and bytes (manual 3.1, 3.3; IEC
//! 61131-9 B.1, annex C): round trips, exact errors for every short length, no panics.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_psx3xx::{
    detect_order, explain_input, explain_output, ByteOrder, ErrorType, ImageError, Input, Output,
    Request, Rules, Stamp, Target, TsCode, Value, ValueError,
};
use drivespec_spec::{DataType, FamilyId, Spec};
use proptest::prelude::*;
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

fn rules() -> &'static Rules<'static> {
    static RULES: OnceLock<Rules<'static>> = OnceLock::new();
    RULES.get_or_init(|| Rules::from_spec(spec()).unwrap())
}

fn order() -> impl Strategy<Value = ByteOrder> {
    prop_oneof![Just(ByteOrder::BigEndian), Just(ByteOrder::LittleEndian)]
}

fn output() -> impl Strategy<Value = Output> {
    let max_stamp = (1u16 << rules().timestamp().bits) - 1;
    prop_oneof![
        (0u8..=3, 0..=max_stamp).prop_map(|(c, s)| Output::TimeStamp {
            control: TsCode(c),
            stamp: Stamp(s)
        }),
        (any::<u16>(), any::<i32>()).prop_map(|(control_word, target)| Output::ControlTarget {
            control_word,
            target
        }),
        (any::<i16>(), any::<u16>(), any::<i32>()).prop_map(
            |(target_speed, control_word, target)| Output::SpeedControlTarget {
                target_speed,
                control_word,
                target
            }
        ),
    ]
}

fn input() -> impl Strategy<Value = Input> {
    (any::<u16>(), any::<i16>(), any::<i32>()).prop_map(|(status, rpm, actual)| Input {
        status,
        rpm,
        actual,
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1000))]

    #[test]
    fn output_round_trip(out in output(), order in order()) {
        let r = rules();
        let bytes = out.to_bytes(r, order).unwrap();
        prop_assert_eq!(bytes.len(), out.buffer_len(r));
        let format = out.format(r).unwrap();
        prop_assert_eq!(Output::parse(r, format, order, &bytes), Ok(out));
        let named: Vec<(String, i64)> =
            out.values().into_iter().map(|(n, v)| (n.to_owned(), v)).collect();
        prop_assert_eq!(Output::from_fields(r, format, &named), Ok(out));
        // The other order reverses every word.
        let other = Output::parse(r, format, order.flipped(), &bytes).unwrap();
        prop_assert_eq!(other.to_bytes(r, order.flipped()).unwrap(), bytes);
    }

    #[test]
    fn input_round_trip(inp in input(), order in order()) {
        let r = rules();
        let bytes = inp.to_bytes(r, order).unwrap();
        prop_assert_eq!(Input::parse(r, order, &bytes), Ok(inp));
        let named: Vec<(String, i64)> =
            inp.values().into_iter().map(|(n, v)| (n.to_owned(), v)).collect();
        prop_assert_eq!(Input::from_fields(r, &named), Ok(inp));
    }

    #[test]
    fn any_image_bytes_parse_and_reencode(
        bytes in prop::collection::vec(any::<u8>(), 0..12),
        order in order(),
    ) {
        let r = rules();
        for o in r.outputs() {
            match Output::parse(r, o.format, order, &bytes) {
                Ok(out) => prop_assert_eq!(out.to_bytes(r, order).unwrap(), bytes.clone()),
                Err(e) => prop_assert_ne!(bytes.len(), o.layout.length(), "{}", e),
            }
            let _ = explain_output(r, o.format, order, None, &bytes);
        }
        match Input::parse(r, order, &bytes) {
            Ok(inp) => prop_assert_eq!(inp.to_bytes(r, order).unwrap(), bytes.clone()),
            Err(e) => prop_assert_ne!(bytes.len(), r.input().length(), "{}", e),
        }
        let _ = explain_input(r, order, None, &bytes);
        let _ = Output::parse(r, 3, order, &bytes);
        let _ = ErrorType::parse(&bytes);
    }

    #[test]
    fn no_panic_on_isdu_and_direct_bytes(
        index in any::<u16>(),
        subindex in any::<u8>(),
        data in prop::collection::vec(any::<u8>(), 0..24),
        first in any::<u8>(),
    ) {
        let r = rules();
        let read = Request::Read { index, subindex };
        let write = Request::Write { index, subindex, data: data.clone() };
        let _ = r.check_request(&read, None);
        if let Ok(a) = r.check_request(&write, None) {
            // An accepted write re-encodes to its data.
            let again = r.encode_value(&a.target, a.value.as_ref().unwrap()).unwrap();
            prop_assert_eq!(again, data.clone());
        }
        if let Ok(t) = r.isdu_target(index, subindex) {
            let _ = r.decode_value(&t, &data);
        }
        let _ = r.decode_direct(first, &data);
        let _ = detect_order(r, &[&data[..], &data[..]]);
    }

    #[test]
    fn error_type_round_trip(code in any::<u16>()) {
        let e = ErrorType(code);
        prop_assert_eq!(ErrorType::parse(&e.to_bytes()), Ok(e));
        prop_assert_eq!(u16::from(e.error_code()) << 8 | u16::from(e.additional_code()), code);
        // Unknown codes print as hex and stay open.
        let named = rules().error_types().named(e).to_string();
        prop_assert!(rules().error_types().contains(e) || named.starts_with("0x"));
    }

    #[test]
    fn isdu_values_round_trip(pick in any::<prop::sample::Index>(), raw in any::<i64>(), text in "[ -~]{0,20}") {
        let r = rules();
        let params = &spec().family(FamilyId::Psx3xx).parameters;
        let p = pick.get(params);
        let target = Target::Entry { param: p };
        let value = match p.data_type.bounds() {
            Some((lo, hi)) => Value::Int(lo + raw.rem_euclid(hi - lo + 1)),
            None => Value::Text(text),
        };
        match r.encode_value(&target, &value) {
            Ok(bytes) => prop_assert_eq!(r.decode_value(&target, &bytes), Ok(value)),
            Err(e) => {
                let too_long = matches!(e, ValueError::LengthOverrun { .. });
                prop_assert!(too_long && p.length.is_some(), "{}", e);
            }
        }
    }

    #[test]
    fn direct_page_round_trip(format in 0u8..3, pick in any::<prop::sample::Index>()) {
        let r = rules();
        let family = spec().family(FamilyId::Psx3xx);
        let models = &family.parameter("79").unwrap().values;
        let model = u32::try_from(pick.get(models).value).unwrap();
        let bytes = r.direct_page(format, model).unwrap();
        let page = r.decode_direct(0, &bytes).unwrap();
        prop_assert!(page.warnings.is_empty(), "{:?}", page.warnings);
        prop_assert_eq!(page.pd_out_format, Some(format));
        prop_assert_eq!(page.device_id_format, Some(format));
        prop_assert_eq!(page.model_code, Some(model));
        prop_assert_eq!(page.min_cycle_time_us, Some(r.protocol().constants.min_cycle_time_us));
    }

    #[test]
    fn stamp_from_delay(stamp in 0u32..=16368) {
        let ts = rules().timestamp();
        prop_assume!(stamp <= ts.max_valid);
        let s = Stamp::from_delay_us(ts, stamp * ts.unit_us).unwrap();
        prop_assert_eq!(u32::from(s.0), stamp);
        prop_assert_eq!(s.meaning(ts).delay_us(), Some(stamp * ts.unit_us));
    }
}

#[test]
fn every_shorter_or_longer_length_is_a_typed_error() {
    let r = rules();
    let mut lengths: Vec<(Option<u8>, usize)> = r
        .outputs()
        .iter()
        .map(|o| (Some(o.format), o.layout.length()))
        .collect();
    lengths.push((None, r.input().length()));
    for (format, length) in lengths {
        for order in ByteOrder::ALL {
            for n in 0..length + 3 {
                let bytes = vec![0xA5; n];
                let got = match format {
                    Some(f) => Output::parse(r, f, order, &bytes).map(|_| ()),
                    None => Input::parse(r, order, &bytes).map(|_| ()),
                };
                let want = match n.cmp(&length) {
                    std::cmp::Ordering::Less => Err(ImageError::Truncated {
                        need: length,
                        have: n,
                    }),
                    std::cmp::Ordering::Equal => Ok(()),
                    std::cmp::Ordering::Greater => Err(ImageError::TrailingData {
                        length,
                        extra: n - length,
                    }),
                };
                assert_eq!(got, want, "format {format:?}, {n} bytes");
            }
        }
    }
    assert_eq!(
        Output::parse(r, 9, ByteOrder::BigEndian, &[0; 6]),
        Err(ImageError::UnknownFormat { format: 9 })
    );
}

#[test]
fn time_stamp_edges() {
    let r = rules();
    let ts = r.timestamp();
    let f0 = r
        .output_of(drivespec_psx3xx::OutputKind::TimeStamp)
        .unwrap()
        .format;
    let cases = [
        (0u16, Some(0), true, false, "executes immediately"),
        (1999, Some(7996), true, false, "executes immediately"),
        (2000, Some(8000), false, false, "executes in 8.000 ms"),
        (16368, Some(65472), false, false, "executes in 65.472 ms"),
        (16369, None, false, false, "reserved"),
        (16383, None, false, true, "inactive"),
    ];
    for (stamp, delay, immediate, inactive, text) in cases {
        let m = Stamp(stamp).meaning(ts);
        assert_eq!(m.delay_us(), delay, "{stamp}");
        assert_eq!(m.is_immediate(), immediate, "{stamp}");
        assert_eq!(m.is_inactive(), inactive, "{stamp}");
        assert!(m.to_string().starts_with(text), "{stamp}: {m}");
        let out = Output::TimeStamp {
            control: TsCode(3),
            stamp: Stamp(stamp),
        };
        let bytes = out.to_bytes(r, ByteOrder::BigEndian).unwrap();
        assert_eq!(
            u16::from_be_bytes([bytes[0], bytes[1]]),
            stamp << 2 | 3,
            "the stamp sits above the two control bits (PSX-ERRATUM-051)"
        );
        assert_eq!(Output::parse(r, f0, ByteOrder::BigEndian, &bytes), Ok(out));
    }
    assert_eq!(Stamp::inactive(ts), Stamp(0x3FFF));
    assert_eq!(Stamp::from_delay_us(ts, 65_476), None);
    assert_eq!(Stamp::from_delay_us(ts, 40_003), Some(Stamp(10_000)));
    // A stamp wider than 14 bits is refused by the builder.
    let err = Output::from_fields(r, f0, &[("control", 0), ("stamp", 0x4000)]).unwrap_err();
    assert!(
        err.to_string().contains("stamp = 16384 outside 0..=16383"),
        "{err}"
    );
}

#[test]
fn isdu_values_encode_per_entry() {
    let r = rules();
    let family = spec().family(FamilyId::Psx3xx);
    for p in &family.parameters {
        let Ok(target) = r.isdu_target(
            u16::try_from(p.number).unwrap(),
            u8::try_from(p.subindex.unwrap_or(0)).unwrap(),
        ) else {
            panic!("{} is not addressable", p.id)
        };
        assert_eq!(target, Target::Entry { param: p });
        match p.data_type.bounds() {
            Some((lo, hi)) => {
                let w = p.data_type.width().unwrap() as usize;
                for v in [lo, hi, (lo + hi) / 2] {
                    let bytes = r.encode_value(&target, &Value::Int(v)).unwrap();
                    assert_eq!(bytes.len(), w, "{}", p.id);
                    assert_eq!(
                        r.decode_value(&target, &bytes),
                        Ok(Value::Int(v)),
                        "{}",
                        p.id
                    );
                }
                assert!(r.encode_value(&target, &Value::Int(hi + 1)).is_err());
                assert!(matches!(
                    r.decode_value(&target, &vec![0; w + 1]),
                    Err(ValueError::LengthOverrun { .. })
                ));
                assert!(matches!(
                    r.decode_value(&target, &vec![0; w - 1]),
                    Err(ValueError::LengthUnderrun { .. })
                ));
            }
            None => assert_eq!(p.data_type, DataType::String),
        }
    }
    // ISDU 24: at most 16 characters; writes beyond are a length overrun (0x8033).
    let tag = r.isdu_target(24, 0).unwrap();
    let ok = "0123456789ABCDEF";
    assert_eq!(
        r.encode_value(&tag, &Value::Text(ok.into())).unwrap(),
        ok.as_bytes()
    );
    let too_long = Request::Write {
        index: 24,
        subindex: 0,
        data: b"0123456789ABCDEFG".to_vec(),
    };
    let rej = r.check_request(&too_long, None).unwrap_err();
    assert_eq!(rej.error, ErrorType(0x8033), "{rej}");
    let write = Request::Write {
        index: 24,
        subindex: 0,
        data: ok.as_bytes().to_vec(),
    };
    let a = r.check_request(&write, None).unwrap();
    assert_eq!(a.value, Some(Value::Text(ok.into())));
    // Not UTF-8: refused as out of range, the offset reported by the decoder.
    assert_eq!(
        r.decode_value(&tag, &[b'a', 0xFF]),
        Err(ValueError::NotText {
            id: "24".into(),
            offset: 1
        })
    );
    // Read-only strings of any length decode.
    let vendor = r.isdu_target(16, 0).unwrap();
    assert_eq!(
        r.decode_value(&vendor, b"halstrup-walcher GmbH"),
        Ok(Value::Text("halstrup-walcher GmbH".into()))
    );
    // Signed entries: the actual value -12600.
    let actual = r.isdu_target(67, 0).unwrap();
    assert_eq!(
        r.decode_value(&actual, &[0xFF, 0xFF, 0xCE, 0xC8]),
        Ok(Value::Int(-12600))
    );
    // Sub-index 0 of ISDU 0 reads the whole Direct Parameter page as a record.
    let page = r.isdu_target(0, 0).unwrap();
    let bytes = r.direct_page(1, 31208).unwrap();
    let Ok(Value::Record(items)) = r.decode_value(&page, &bytes) else {
        panic!("record")
    };
    assert_eq!(items.len(), 16);
    assert_eq!(items[2], Value::Int(0x44));
    assert_eq!(r.encode_value(&page, &Value::Record(items)).unwrap(), bytes);
    let rej = r
        .check_request(
            &Request::Write {
                index: 0,
                subindex: 0,
                data: bytes,
            },
            None,
        )
        .unwrap_err();
    assert_eq!(rej.error, ErrorType(0x8023), "{rej}");
}

#[test]
fn isdu_refusals_and_commands() {
    let r = rules();
    let family = spec().family(FamilyId::Psx3xx);
    let write = |index: u16, data: &[u8]| Request::Write {
        index,
        subindex: 0,
        data: data.to_vec(),
    };
    let code = |req: &Request| {
        r.check_request(req, None)
            .map(|_| ())
            .map_err(|e| e.error.0)
    };
    assert_eq!(
        code(&Request::Read {
            index: 1,
            subindex: 0
        }),
        Err(0x8011)
    );
    assert_eq!(
        code(&Request::Read {
            index: 131,
            subindex: 1
        }),
        Err(0x8012)
    );
    assert_eq!(
        code(&Request::Read {
            index: 0,
            subindex: 17
        }),
        Err(0x8012)
    );
    assert_eq!(
        code(&Request::Read {
            index: 0,
            subindex: 1
        }),
        Err(0x8023)
    );
    assert_eq!(code(&write(64, &[0, 0])), Err(0x8023));
    assert_eq!(
        code(&write(119, &[0x02])),
        Err(0x8030),
        "ISDU 119 bit 1 must be 0"
    );
    assert_eq!(
        code(&write(110, &[0x80, 0x00])),
        Err(0x8030),
        "bit 15 must be 0"
    );
    assert_eq!(
        code(&write(110, &[0x40, 0x14])),
        Ok(()),
        "bit 14 clears errors"
    );
    assert_eq!(
        code(&write(116, &[2])),
        Ok(()),
        "software version is the model's"
    );
    // The Direct Parameter SystemCommand takes the commands of ISDU 2.
    assert_eq!(
        code(&Request::Write {
            index: 0,
            subindex: 16,
            data: vec![0x81]
        }),
        Err(0x8035)
    );
    let ok = r
        .check_request(
            &Request::Write {
                index: 0,
                subindex: 16,
                data: vec![0xA1],
            },
            None,
        )
        .unwrap();
    assert_eq!(ok.command.map(|c| c.name.as_str()), Some("save"));
    // Per-model ranges (3.2) apply when a model is given.
    let pse = family.model("PSE335-14").unwrap();
    let speed_range = family
        .resolve(family.parameter("142").unwrap(), Some(pse))
        .range
        .unwrap();
    let too_fast = speed_range.max().unwrap() + 1;
    let req = write(142, &u16::try_from(too_fast).unwrap().to_be_bytes());
    assert_eq!(r.check_request(&req, None).map(|_| ()), Ok(()));
    assert_eq!(
        r.check_request(&req, Some(pse))
            .map_err(|e| e.error.0)
            .map(|_| ()),
        Err(0x8030)
    );
    // ISDU 193: every write value names its command; reads have their readback meanings.
    let p193 = family.parameter("193").unwrap();
    for v in -2..=3 {
        let c = r.command(p193, v).unwrap();
        assert_eq!(c.value, v);
        let req = write(193, &i16::try_from(v).unwrap().to_be_bytes());
        assert_eq!(
            r.check_request(&req, None).unwrap().command.unwrap().name,
            c.name
        );
    }
    let zero: Vec<&str> = r
        .readbacks(p193, 0)
        .iter()
        .map(|b| b.when.as_str())
        .collect();
    assert_eq!(zero, ["after-boot", "after-save"]);
    assert!(r.readbacks(p193, 1).iter().all(|b| b.value == "nonzero"));
    assert!(r.readbacks(family.parameter("131").unwrap(), 0).is_empty());
    assert_eq!(r.error_known().idx_notavail, ErrorType(0x8011));
    // Rejections print their case and ErrorType name.
    let rej = r.check_request(&write(131, &[0, 101]), None).unwrap_err();
    assert_eq!(rej.case.spec_name(), "value-out-of-range");
    assert_eq!(
        r.error_types().named(rej.error).to_string(),
        "PAR_VALOUTOFRNG"
    );
    assert!(rej.accepts(ErrorType(0x8031)));
}
