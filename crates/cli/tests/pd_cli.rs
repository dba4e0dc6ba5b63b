//! `drivespec decode|encode psd4xx|psx3xx` as users run them: output snapshots and exit codes.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::run;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

#[test]
fn psd4xx_output_from_named_fields_and_back() {
    let (code, hex, _) = run(
        BIN,
        &[
            "encode",
            "psd4xx",
            "--out",
            "--control",
            "0x14",
            "--target",
            "12000",
            "--pkw",
            "read:44",
        ],
    );
    assert_eq!(
        (code, hex.trim()),
        (0, "10 2C 00 00 00 00 00 00 14 00 00 00 2E E0")
    );
    let (code, text, _) = run(BIN, &["decode", "psd4xx", "--out", hex.trim()]);
    assert_eq!(code, 0);
    insta::assert_snapshot!(text);
}

#[test]
fn psd4xx_input_with_a_pkw_error_and_obstruction() {
    let (code, text, _) = run(
        BIN,
        &[
            "decode",
            "psd4xx",
            "--in",
            "70 2C 00 00 00 00 00 02 54 44 FF B5 00 0C 49 50",
        ],
    );
    assert_eq!(code, 0);
    insta::assert_snapshot!("psd4xx_in_text", text);
    let (_, json, _) = run(
        BIN,
        &[
            "decode",
            "psd4xx",
            "--in",
            "--format",
            "json",
            "70 2C 00 00 00 00 00 02 54 44 FF B5 00 0C 49 50",
        ],
    );
    insta::assert_snapshot!("psd4xx_in_json", json);
}

#[test]
fn psd4xx_reserved_control_bits_are_violations() {
    let (code, text, _) = run(
        BIN,
        &[
            "decode",
            "psd4xx",
            "--out",
            "00 00 00 00 00 00 00 00 1C 00 00 00 00 00",
        ],
    );
    assert_eq!(code, 1, "{text}");
}

#[test]
fn psd4xx_wrong_length_is_a_one_line_error() {
    let (code, out, err) = run(BIN, &["decode", "psd4xx", "--in", "00 11"]);
    assert_eq!((code, out.as_str()), (2, ""));
    assert!(
        err.starts_with("drivespec: ") && err.lines().count() == 1,
        "{err}"
    );
}

#[test]
fn psx3xx_images_in_all_formats() {
    let (code, hex, _) = run(
        BIN,
        &[
            "encode",
            "psx3xx",
            "--out",
            "--pd-format",
            "1",
            "control_word=0x14",
            "target=12000",
        ],
    );
    assert_eq!((code, hex.trim()), (0, "00 14 00 00 2E E0"));
    let mut all = String::new();
    for (format, bytes) in [
        ("0", "00 64"),
        ("1", "00 14 00 00 2E E0"),
        ("2", "00 C8 00 14 00 00 2E E0"),
    ] {
        let (code, text, err) = run(
            BIN,
            &["decode", "psx3xx", "--out", "--pd-format", format, bytes],
        );
        assert_eq!(code, 0, "{err}{text}");
        all.push_str(&text);
    }
    let (code, text, _) = run(
        BIN,
        &["decode", "psx3xx", "--in", "00 11 00 00 00 00 03 E8"],
    );
    assert_eq!(code, 0);
    all.push_str(&text);
    insta::assert_snapshot!(all);
}

#[test]
fn psx3xx_unknown_model_lists_the_known_ones() {
    let (code, _, err) = run(
        BIN,
        &[
            "decode",
            "psx3xx",
            "--in",
            "--model",
            "PSE999",
            "00 11 00 00 00 00 03 E8",
        ],
    );
    assert_eq!(code, 2);
    assert!(
        err.starts_with("drivespec: unknown psx3xx model \"PSE999\"; known models: PSE"),
        "{err}"
    );
}
