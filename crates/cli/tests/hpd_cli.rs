//! `drivespec decode|encode|plc hpd` as users run them: output snapshots and exit codes.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::run;

/// The eight examples of manual 4.1, requests and answers, as one line.
const CASES: &str = "7E 80 01 54 D5 7E 20 01 54 09 7E 00 \
    7E 81 02 42 C5 7E 21 02 42 D0 07 3C \
    7E A3 01 54 01 F9 7E 23 \
    7E A3 02 C6 FD 00 68 7E 23 \
    7E C0 02 93 BF 40 54 7E 20 \
    7E C0 02 5D FD 00 1C 7E 20 \
    7E 60 02 00 40 5A FC 7E 20 \
    7E 40 04 00 44 7E 20 04 00 10 5A A7 5A 8F";

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

#[test]
fn decode_manual_form_of_case_2() {
    let (code, out, _) = run(
        BIN,
        &["decode", "hpd", "[$7E][$21][$02][$42][$D0][$07][$3C]"],
    );
    assert_eq!(code, 0);
    insta::assert_snapshot!(out);
}

#[test]
fn decode_the_eight_manual_examples_as_a_line() {
    let dir = std::env::temp_dir().join(format!("drivespec-hpd-line-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("line.hex");
    std::fs::write(&file, CASES).unwrap();
    let (code, text, _) = run(BIN, &["decode", "hpd", "--stream", file.to_str().unwrap()]);
    assert_eq!(code, 0, "{text}");
    insta::assert_snapshot!("line_text", text);
    let (code, json, _) = run(
        BIN,
        &[
            "decode",
            "hpd",
            "--stream",
            file.to_str().unwrap(),
            "--format",
            "json",
        ],
    );
    assert_eq!(code, 0);
    insta::assert_snapshot!("line_json", json);
    // The same bytes raw give the same result.
    let raw = drivespec_spec::hex::parse_hex(CASES).unwrap();
    let bin = dir.join("line.bin");
    std::fs::write(&bin, raw).unwrap();
    let (_, raw_json, _) = run(
        BIN,
        &[
            "decode",
            "hpd",
            "--stream",
            bin.to_str().unwrap(),
            "--format",
            "json",
        ],
    );
    assert_eq!(raw_json, json);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn decode_reports_a_bad_checksum_and_exits_1() {
    let (code, out, _) = run(BIN, &["decode", "hpd", "7E 80 01 54 D6"]);
    assert_eq!(code, 1);
    insta::assert_snapshot!(out);
}

#[test]
fn decode_flags_plc_bytes_outside_the_area_and_exits_1() {
    // A PLC write of `LD 90.4` at 0x80, one byte past the area (4.1: 0x00–0x7F).
    let (code, out, _) = run(BIN, &["decode", "hpd", "7E 60 02 80 40 5A 7C"]);
    assert_eq!(code, 1, "{out}");
    assert!(
        out.contains("breaks HPD-PLC-038: PLC bytes 0x80-0x81 lie outside the PLC area 0x00-0x7F"),
        "{out}"
    );
    // The same bytes at 0x7C are inside.
    let (code, out, _) = run(BIN, &["decode", "hpd", "7E 60 02 7C 40 5A 78"]);
    assert_eq!((code, out.contains("breaks")), (0, false), "{out}");
}

#[test]
fn decode_rejects_odd_hex_with_exit_2() {
    let (code, out, err) = run(BIN, &["decode", "hpd", "7E 8"]);
    assert_eq!((code, out.as_str()), (2, ""));
    assert_eq!(
        err,
        "drivespec: bad hex: odd number of hex digits in \"8\" at offset 3\n"
    );
}

#[test]
fn encode_rebuilds_the_manual_requests_from_names() {
    let cases: [(&[&str], &str); 7] = [
        (&["read", "--addr", "0", "Pr31"], "7E 80 01 54 D5"),
        (&["read", "--addr", "1", "Pr7"], "7E 81 02 42 C5"),
        (&["write", "--addr", "3", "Pr31=1"], "7E A3 01 54 01 F9"),
        (
            &["write", "--addr", "3", "Pr33=25.3"],
            "7E A3 02 C6 FD 00 68",
        ),
        (&["bit", "--addr", "0", "b99.14=1"], "7E C0 02 93 BF 40 54"),
        (&["bit", "--addr", "0", "b40.9=0"], "7E C0 02 5D FD 00 1C"),
        (
            &["plc-write", "--addr", "0", "--at", "0", "LD 90.4"],
            "7E 60 02 00 40 5A FC",
        ),
    ];
    for (args, want) in cases {
        let mut full = vec!["encode", "hpd"];
        full.extend_from_slice(args);
        let (code, out, err) = run(BIN, &full);
        assert_eq!((code, out.trim()), (0, want), "{args:?}: {err}");
    }
    let (code, out, _) = run(
        BIN,
        &[
            "encode", "hpd", "plc-read", "--addr", "0", "--at", "0", "--lun", "4",
        ],
    );
    assert_eq!((code, out.trim()), (0, "7E 40 04 00 44"));
}

#[test]
fn encode_errors_are_one_line_with_exit_2() {
    let cases: [(&[&str], &str); 6] = [
        (
            &["write", "Pr33=99.9"],
            "drivespec: Pr33 = 999 outside range 100..500\n",
        ),
        (&["write", "Pr7=1"], "drivespec: Pr7 is read-only\n"),
        (
            &["read", "Pr200"],
            "drivespec: unknown parameter \"Pr200\"\n",
        ),
        (
            &["bit", "b99.16=1"],
            "drivespec: bit 16 outside Pb99 (16 bits)\n",
        ),
        (
            &["plc-write", "--at", "200", "LD 90.4"],
            "drivespec: PLC bytes 0xC8-0xC9 lie outside the PLC area 0x00-0x7F (3.8.1)\n",
        ),
        (
            &["plc-read", "--at", "0x7E", "--lun", "4"],
            "drivespec: PLC bytes 0x7E-0x81 lie outside the PLC area 0x00-0x7F (3.8.1)\n",
        ),
    ];
    for (args, want) in cases {
        let mut full = vec!["encode", "hpd"];
        full.extend_from_slice(args);
        let (code, _, err) = run(BIN, &full);
        assert_eq!((code, err.as_str()), (2, want), "{args:?}");
    }
}

#[test]
fn disassemble_case_8_and_flag_a_program_without_end() {
    let (code, out, _) = run(BIN, &["plc", "hpd", "disasm", "10 5A A7 5A 0F 00"]);
    assert_eq!(code, 0);
    insta::assert_snapshot!(out);
    let (code, _, err) = run(BIN, &["plc", "hpd", "disasm", "10 5A A7 5A"]);
    assert_eq!(
        (code, err.as_str()),
        (2, "drivespec: program has no END within 4 bytes\n")
    );
}

#[test]
fn assemble_reports_fin_out_of_place_and_exits_1() {
    let dir = std::env::temp_dir().join(format!("drivespec-hpd-asm-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("prog.il");
    std::fs::write(
        &file,
        "; FIN after another instruction is a no-op\nLD 90.1\nFIN 3,1\nOUT 91.0\nEND\n",
    )
    .unwrap();
    let (code, out, _) = run(BIN, &["plc", "hpd", "asm", file.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 1);
    insta::assert_snapshot!(out);
}
