//! `drivespec sim-run --reading OPTION=READING`: a script played under another reading of a
//! selectable erratum (PSX-ERRATUM-056: the referencing value's sign), and a reading the
//! spec does not have (exit 2, naming the readings there are).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::run_with;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// Sets the actual value 0 at the delivery position 51200 and reads ISDU 127 back.
const SCRIPT: &str = "0 ms: isdu write 67 = 0\n10 ms: isdu read 127\n20 ms: end\n";

fn sim_run(extra: &[&str]) -> (i32, String, String) {
    let mut args = vec![
        "sim-run", "psx3xx", "--model", "PSE312-8", "--script", "-", "--every", "0",
    ];
    args.extend_from_slice(extra);
    run_with(BIN, &args, Some(SCRIPT), &[])
}

fn isdu_127(out: &str) -> &str {
    out.lines()
        .find(|l| l.contains("< isdu 127.0 data"))
        .unwrap_or_else(|| panic!("no ISDU 127 answer in\n{out}"))
}

#[test]
fn reading_changes_what_the_drive_answers() {
    let (code, out, err) = sim_run(&[]);
    assert_eq!(code, 0, "{err}");
    assert!(isdu_127(&out).ends_with("(= -51200)"), "{out}");
    let (code, out, err) = sim_run(&["--reading", "psx-ref-sign=physical-minus-written"]);
    assert_eq!(code, 0, "{err}");
    assert!(isdu_127(&out).ends_with("(= 51200)"), "{out}");
}

#[test]
fn unknown_readings_are_usage_errors() {
    let (code, _, err) = sim_run(&["--reading", "psx-ref-sign=nonsense"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("written-minus-physical, physical-minus-written"),
        "{err}"
    );
    let (code, _, err) = sim_run(&["--reading", "psx-ref-sign"]);
    assert_eq!(code, 2);
    assert!(err.contains("OPTION=READING"), "{err}");
    let (code, _, err) = sim_run(&["--reading", "no-such-option=x"]);
    assert_eq!(code, 2);
    assert!(err.contains("psx-ref-sign"), "{err}");
}
