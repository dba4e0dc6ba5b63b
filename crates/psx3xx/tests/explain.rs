//! Snapshots of what people read: image descriptions in text and JSON (manual 3.3, 3.4,
//! 3.5), Direct Parameter page 1 and byte-order detection.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_psx3xx::{
    detect_order, explain_input, explain_output, explain_value, ByteOrder, Input, Output, Rules,
};
use drivespec_spec::hex::parse_hex;
use drivespec_spec::{FamilyId, Spec};
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

fn rules() -> &'static Rules<'static> {
    static RULES: OnceLock<Rules<'static>> = OnceLock::new();
    RULES.get_or_init(|| Rules::from_spec(spec()).unwrap())
}

/// Golden images: (snapshot name, output format or None for input, order, hex).
const GOLDEN: &[(&str, Option<u8>, ByteOrder, &str)] = &[
    (
        "out_f0_position_40ms",
        Some(0),
        ByteOrder::BigEndian,
        "9C 43",
    ),
    ("out_f0_abort_now", Some(0), ByteOrder::BigEndian, "00 00"),
    ("out_f0_inactive", Some(0), ByteOrder::BigEndian, "FF FF"),
    ("out_f0_reserved", Some(0), ByteOrder::BigEndian, "FF C7"),
    (
        "out_f1_release_transfer",
        Some(1),
        ByteOrder::BigEndian,
        "00 14 00 00 C8 00",
    ),
    (
        "out_f1_reserved_bit",
        Some(1),
        ByteOrder::BigEndian,
        "20 54 FF FF 41 60",
    ),
    (
        "out_f2_speed",
        Some(2),
        ByteOrder::BigEndian,
        "00 55 00 14 00 00 C8 00",
    ),
    (
        "out_f2_invalid_speed",
        Some(2),
        ByteOrder::BigEndian,
        "FF FF 00 14 00 00 C8 00",
    ),
    (
        "in_standstill",
        None,
        ByteOrder::BigEndian,
        "00 11 00 00 00 00 C8 00",
    ),
    (
        "in_running_negative",
        None,
        ByteOrder::BigEndian,
        "01 50 FF D8 FF FF CE C8",
    ),
    (
        "in_swapped_master",
        None,
        ByteOrder::LittleEndian,
        "11 00 00 00 00 C8 00 00",
    ),
];

#[test]
fn golden_images_text_and_json() {
    let r = rules();
    for (name, format, order, hex) in GOLDEN {
        let bytes = parse_hex(hex).unwrap();
        let e = match format {
            Some(f) => explain_output(r, *f, *order, None, &bytes).unwrap(),
            None => explain_input(r, *order, None, &bytes).unwrap(),
        };
        insta::assert_snapshot!(format!("{name}_text"), e.to_string());
        insta::assert_json_snapshot!(format!("{name}_json"), e);
    }
}

#[test]
fn model_ranges_judge_the_target_speed() {
    let r = rules();
    let pse = spec().family(FamilyId::Psx3xx).model("PSE335-14").unwrap();
    let out = Output::SpeedControlTarget {
        target_speed: 5,
        control_word: 0x14,
        target: 60000,
    };
    let e = explain_value(r, &out, ByteOrder::BigEndian, Some(pse)).unwrap();
    insta::assert_snapshot!("out_f2_pse335_speed_5", e.to_string());
    let e = explain_value(r, &out, ByteOrder::BigEndian, None).unwrap();
    assert!(e.warnings.is_empty(), "{e}");
}

#[test]
fn direct_page_text() {
    let r = rules();
    let page = r
        .decode_direct(
            0,
            &parse_hex("00 00 44 2B 11 87 85 02 D8 2F 9E A2 00 00 00 00").unwrap(),
        )
        .unwrap();
    insta::assert_snapshot!("direct_page_pse312_8_format1", page.to_string());
    let odd = r
        .decode_direct(2, &parse_hex("48 2B 12 87 87 02 D9 2F 9E A2").unwrap())
        .unwrap();
    insta::assert_snapshot!("direct_page_disagreements", odd.to_string());
}

#[test]
fn detection_text() {
    let r = rules();
    let seq: Vec<Vec<u8>> = [
        (0x0011, 0, 51200),
        (0x0001, 0, 51200),
        (0x0011, 0, 51200),
        (0x0051, 85, 51210),
        (0x0050, 85, 51290),
    ]
    .iter()
    .map(|(status, rpm, actual)| {
        Input {
            status: *status,
            rpm: *rpm,
            actual: *actual,
        }
        .to_bytes(r, ByteOrder::LittleEndian)
        .unwrap()
    })
    .collect();
    let d = detect_order(r, &seq);
    insta::assert_snapshot!("detect_swapped_master", d.to_string());
    insta::assert_json_snapshot!("detect_swapped_master_json", d);
}
