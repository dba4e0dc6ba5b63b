//! `drivespec sim-run` as users run it: the two example scripts under `tests/` as readable
//! trace snapshots, the JSON form, a failing expectation (exit 1) and script errors that name
//! their line (exit 2).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::run_with;
use std::path::PathBuf;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

fn example(name: &str) -> String {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests")
        .join(name);
    p.to_string_lossy().into_owned()
}

#[test]
fn positioning_example_trace() {
    let script = example("psd4xx_positioning.sim");
    let (code, out, err) = run_with(
        BIN,
        &[
            "sim-run", "psd4xx", "--model", "PSD426", "--script", &script, "--every", "1000",
        ],
        None,
        &[],
    );
    assert_eq!(code, 0, "{err}\n{out}");
    insta::assert_snapshot!("psd4xx_positioning", out);
}

#[test]
fn faults_example_trace() {
    let script = example("psd4xx_faults.sim");
    let (code, out, err) = run_with(
        BIN,
        &[
            "sim-run",
            "psd4xx",
            "--model",
            "psd 426/436-14h",
            "--script",
            &script,
            "--every",
            "1000",
        ],
        None,
        &[],
    );
    assert_eq!(code, 0, "{err}\n{out}");
    insta::assert_snapshot!("psd4xx_faults", out);
}

/// The PSx3xx example runs with its expectations met; the trace is asserted loosely while
/// the PSx3xx model is still being completed.
#[test]
fn psx3xx_example_runs() {
    let script = example("psx3xx_positioning.sim");
    let (code, out, err) = run_with(
        BIN,
        &[
            "sim-run",
            "psx3xx",
            "--model",
            "PSE335-14",
            "--script",
            &script,
            "--every",
            "0",
        ],
        None,
        &[],
    );
    assert_eq!(code, 0, "{err}\n{out}");
    assert!(out.starts_with("psx3xx PSE335-14\n"), "{out}");
    assert!(out.contains("< isdu 116.0 data"), "{out}");
    assert!(out.contains("expectations: 3 passed, 0 failed"), "{out}");
}

#[test]
fn json_trace_and_failed_expectation_exit_1() {
    let script = "0 ms: control 0x14 target 400\n100 ms: expect position = 400\n";
    let (code, out, _) = run_with(
        BIN,
        &[
            "sim-run", "psd4xx", "--model", "PSD426", "--script", "-", "--every", "0", "--format",
            "json",
        ],
        Some(script),
        &[],
    );
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["family"], "psd4xx");
    assert_eq!(v["failed"], 1);
    assert_eq!(v["passed"], 0);
    let entries = v["entries"].as_array().unwrap();
    let check = entries.iter().find(|e| e["kind"] == "check").unwrap();
    assert_eq!(check["line"], 2);
    assert_eq!(check["passed"], false);
    assert!(entries
        .iter()
        .any(|e| e["kind"] == "event" && e["event"]["core"] == "run-ended"));
}

#[test]
fn script_errors_name_the_line_and_exit_2() {
    let cases = [
        ("0 ms: control 0x14\nsoon: end\n", "line 2"),
        ("# c\n0 ms: pkw write:44\n", "line 2"),
        ("1 s: env jam on\n0 s: env jam off\n", "line 2"),
        ("0 ms: warp 9\n", "unknown command \"warp\""),
        ("0 ms: record write 44 zz\n", "hex byte"),
    ];
    for (script, needle) in cases {
        let (code, out, err) = run_with(
            BIN,
            &["sim-run", "psd4xx", "--model", "PSD426", "--script", "-"],
            Some(script),
            &[],
        );
        assert_eq!(code, 2, "{script}: {out}");
        assert!(err.starts_with("drivespec: "), "{err}");
        assert!(err.contains(needle), "{script}: {err}");
        assert_eq!(err.lines().count(), 1, "{err}");
    }
    let (code, _, err) = run_with(
        BIN,
        &["sim-run", "psd4xx", "--model", "PSD999", "--script", "-"],
        Some("0 ms: end\n"),
        &[],
    );
    assert_eq!(code, 2);
    assert!(err.contains("PSD426"), "{err}");
}
