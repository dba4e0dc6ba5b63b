//! What people read: `explain` text and JSON for golden images (insta snapshots), the `--pkw`
//! mini-syntax and its typed errors, and the image builder (manual 3.5–3.8).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_positioner::ByteOrder;
use drivespec_psd4xx::{
    explain, explain_pkw, BuildError, Direction, ImageBuilder, Options, Output, Reply, Request,
    RequestError, Rules, Width,
};
use drivespec_spec::hex::parse_hex;
use drivespec_spec::Spec;
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

fn rules() -> &'static Rules {
    static RULES: OnceLock<Rules> = OnceLock::new();
    RULES.get_or_init(|| Rules::from_spec(spec()).unwrap())
}

/// Golden images: name, direction, hex.
const GOLDEN: &[(&str, Direction, &str)] = &[
    (
        "out_read_44_release_transfer",
        Direction::Out,
        "10 2C 00 00 00 00 00 00 14 00 00 00 03 E8",
    ),
    (
        "out_violations",
        Direction::Out,
        "38 2C 00 03 00 01 00 0A 08 08 FF F3 B6 B0",
    ),
    (
        "out_unknown_command",
        Direction::Out,
        "40 2C 00 00 00 00 00 00 00 00 00 00 00 00",
    ),
    (
        "in_error_2_obstruction",
        Direction::In,
        "70 2C 00 00 00 00 00 02 54 44 FF B5 00 0C 49 50",
    ),
    (
        "in_string_segment_13",
        Direction::In,
        "50 0D 00 01 32 32 2D 50 11 00 00 00 00 00 03 E8",
    ),
    (
        "in_negative_speed_word",
        Direction::In,
        "10 02 00 00 00 00 FF 88 50 01 00 C8 FF FF FC 18",
    ),
];

#[test]
fn golden_text() {
    for (name, d, hex) in GOLDEN {
        let e = explain(rules(), *d, &parse_hex(hex).unwrap()).unwrap();
        insta::assert_snapshot!(format!("text_{name}"), e.to_string());
    }
}

#[test]
fn golden_json() {
    for (name, d, hex) in GOLDEN.iter().filter(|(n, ..)| {
        matches!(
            *n,
            "out_read_44_release_transfer" | "out_violations" | "in_error_2_obstruction"
        )
    }) {
        let e = explain(rules(), *d, &parse_hex(hex).unwrap()).unwrap();
        insta::assert_json_snapshot!(format!("json_{name}"), e);
    }
}

#[test]
fn little_endian_setting_text() {
    let mut o = Options::manual(spec()).unwrap();
    o.byte_order = ByteOrder::LittleEndian;
    let le = Rules::with_options(spec(), o).unwrap();
    let mut b = ImageBuilder::new(&le, Direction::Out);
    b.set("control", 0x14).unwrap().set("target", 1000).unwrap();
    b.pkw("write:45=-250").unwrap();
    let e = explain(&le, Direction::Out, b.bytes()).unwrap();
    insta::assert_snapshot!("text_out_little_endian", e.to_string());
}

#[test]
fn pkw_summaries_in_words() {
    let p = rules().pkw();
    let say_req = |t: &str| p.describe_request(&p.request_from_text(t).unwrap());
    let say_resp = |t: &str| p.describe_response(&p.reply_from_text(t).unwrap());
    assert_eq!(say_req("read:44"), "read par 44 (Positioning window)");
    assert_eq!(
        say_req("write:44=5"),
        "write par 44 (Positioning window) = 5 increments (word)"
    );
    assert_eq!(
        say_req("read:13[2]"),
        "read par 13 (Device model (as string)) element 2"
    );
    assert_eq!(
        say_req("count:13"),
        "read the number of elements of par 13 (Device model (as string))"
    );
    assert_eq!(say_req("none"), "no command");
    assert_eq!(
        say_req("read:20"),
        "read par 20 (not in the parameter table)"
    );
    assert_eq!(
        say_resp("error:44=2"),
        "par 44 (Positioning window): error 2 (out-of-range): lower or upper limit value exceeded"
    );
    assert_eq!(
        say_resp("error:3=operating-state"),
        "par 3 (Actual value): error 17 (operating-state): order cannot be executed in the current operating state"
    );
    assert_eq!(
        say_resp("value:2=-120"),
        "par 2 (Actual speed) = -120 rpm (word)"
    );
    assert_eq!(
        say_resp("count:13=5"),
        "par 13 (Device model (as string)) has 5 elements"
    );
    assert_eq!(say_resp("none"), "no response");
    let e = explain_pkw(
        rules(),
        Direction::In,
        &parse_hex("70 2C 00 00 00 00 00 63").unwrap(),
    )
    .unwrap();
    assert_eq!(
        e.summary,
        "par 44 (Positioning window): error 99 (not in the error table)"
    );
    assert_eq!(
        e.notes,
        vec!["error 99 is not in the spec's error table (3.8)".to_owned()]
    );
}

#[test]
fn mini_syntax() {
    let p = rules().pkw();
    assert_eq!(
        p.parse_request(" read:44 ").unwrap(),
        Request::Read {
            pnu: 44,
            index: None
        }
    );
    assert_eq!(
        p.parse_request("READ:13[2]").unwrap(),
        Request::Read {
            pnu: 13,
            index: Some(2)
        }
    );
    assert_eq!(
        p.parse_request("write:44=5").unwrap(),
        Request::Write {
            pnu: 44,
            index: None,
            width: Width::Word,
            value: 5
        }
    );
    assert_eq!(
        p.parse_request("write:3=-0x10").unwrap(),
        Request::Write {
            pnu: 3,
            index: None,
            width: Width::Dword,
            value: -16
        }
    );
    assert_eq!(
        p.parse_request("write-dword:44=10").unwrap(),
        Request::Write {
            pnu: 44,
            index: None,
            width: Width::Dword,
            value: 10
        }
    );
    assert_eq!(
        p.request_from_text("write:44=5")
            .unwrap()
            .to_bytes(p)
            .unwrap(),
        parse_hex("20 2C 00 00 00 00 00 05").unwrap()
    );
    assert_eq!(
        p.request_from_text("read-array:13[1]")
            .unwrap()
            .to_bytes(p)
            .unwrap(),
        parse_hex("60 0D 00 01 00 00 00 00").unwrap()
    );
    assert_eq!(
        p.parse_reply("error:44=out-of-range").unwrap(),
        Reply::Error {
            pnu: 44,
            index: 0,
            error: p.error_codes().out_of_range
        }
    );
    assert_eq!(
        p.reply_from_text("value:42=805200")
            .unwrap()
            .to_bytes(p)
            .unwrap(),
        parse_hex("20 2A 00 00 00 0C 49 50").unwrap()
    );
}

#[test]
fn mini_syntax_errors_are_typed() {
    let p = rules().pkw();
    let err = |t: &str| p.parse_request(t).unwrap_err();
    assert_eq!(err(""), RequestError::Empty);
    assert!(matches!(err("fetch:44"), RequestError::UnknownVerb { verb, .. } if verb == "fetch"));
    assert_eq!(
        err("read:2048"),
        RequestError::PnuRange {
            pnu: 2048,
            max: 2047
        }
    );
    assert_eq!(
        err("read:4x"),
        RequestError::Number {
            what: "PNU",
            found: "4x".into()
        }
    );
    assert_eq!(
        err("write:44"),
        RequestError::MissingValue {
            verb: "write".into()
        }
    );
    assert_eq!(
        err("read:44=3"),
        RequestError::UnexpectedValue {
            verb: "read".into()
        }
    );
    assert_eq!(
        err("count:13[1]"),
        RequestError::UnexpectedIndex {
            verb: "count".into()
        }
    );
    assert_eq!(
        err("read-array:13"),
        RequestError::MissingIndex {
            verb: "read-array".into()
        }
    );
    assert_eq!(err("write:20=1"), RequestError::UnknownWidth { pnu: 20 });
    assert_eq!(
        err("write:44=70000"),
        RequestError::ValueRange {
            value: 70000,
            min: 0,
            max: 65535
        }
    );
    assert_eq!(
        err("write:2=40000"),
        RequestError::ValueRange {
            value: 40000,
            min: -32768,
            max: 32767
        }
    );
    assert!(matches!(
        err("read:13[2"),
        RequestError::Syntax { expected, .. } if expected.contains(']')
    ));
    assert!(matches!(err("none:44"), RequestError::Syntax { .. }));
    assert!(matches!(err("read"), RequestError::Syntax { .. }));
    assert_eq!(
        p.parse_reply("error:44=tired").unwrap_err(),
        RequestError::UnknownError {
            name: "tired".into()
        }
    );
    assert_eq!(
        err("read:2048").to_string(),
        "PNU 2048 does not fit, largest is 2047"
    );
}

#[test]
fn builder_from_named_fields() {
    let r = rules();
    let mut b = ImageBuilder::new(r, Direction::Out);
    b.set("control", 0x14)
        .unwrap()
        .set("target", 12000)
        .unwrap()
        .pkw("read:44")
        .unwrap();
    assert_eq!(
        b.bytes(),
        parse_hex("10 2C 00 00 00 00 00 00 14 00 00 00 2E E0").unwrap()
    );
    let out = Output::parse(r, b.bytes()).unwrap();
    assert_eq!((out.control, out.target), (0x14, 12000));
    assert!(matches!(
        b.set("status", 1),
        Err(BuildError::UnknownField { direction: Direction::Out, ref name, .. }) if name == "status"
    ));
    assert!(matches!(
        b.set("control", 0x1_0000),
        Err(BuildError::Field { ref name, .. }) if name == "control"
    ));
    assert!(matches!(
        b.set("target", i64::from(i32::MAX) + 1),
        Err(BuildError::Field { .. })
    ));
    let mut i = ImageBuilder::new(r, Direction::In);
    i.set("status", 0x11)
        .unwrap()
        .set("actual", 1000)
        .unwrap()
        .pkw("value:44=2")
        .unwrap();
    assert_eq!(
        i.into_bytes(),
        parse_hex("10 2C 00 00 00 00 00 02 11 00 00 00 00 00 03 E8").unwrap()
    );
}

#[test]
fn array_access_notes() {
    let r = rules();
    let notes = |t: &str| {
        let b = r
            .pkw()
            .request_from_text(t)
            .unwrap()
            .to_bytes(r.pkw())
            .unwrap();
        explain_pkw(r, Direction::Out, &b).unwrap().notes
    };
    assert_eq!(r.pkw().elements(13), Some(5));
    assert!(notes("read:13[4]").is_empty());
    assert_eq!(
        notes("read:13[5]"),
        vec!["index 5 is beyond the 5 elements of par 13 (3.8 error 3 \"error in the subindex\")"]
    );
    assert_eq!(
        notes("read:44[0]"),
        vec!["par 44 is not an array (3.8 error 4 \"no array\")"]
    );
    assert_eq!(
        notes("count:44"),
        vec!["par 44 is not an array (3.8 error 4 \"no array\")"]
    );
    assert!(notes("count:13").is_empty());
    assert_eq!(drivespec_psd4xx::parse_number("0x14"), Ok(20));
    assert_eq!(drivespec_psd4xx::parse_number("-12_000"), Ok(-12000));
    assert!(drivespec_psd4xx::parse_number("12k").is_err());
}
