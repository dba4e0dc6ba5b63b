//! What a CI log shows of a failing `drivespec conform` run (no terminal): each failure as it
//! happens with the broken requirement, allowed vs got and the replay line, then a recap of
//! the failures and the summary; passing cases only with `--verbose`; `--quiet` keeps the
//! failures. The device is the example adapter `tests/hpd_adapter.py`, which has no PLC area.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run_with, temp_dir, CI};
use std::path::Path;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// Runs the adapter on one failing and one passing case with `extra` options; exit code and
/// stderr + stdout with the machine's paths replaced by `$REPO` and `$DIR`.
fn log(name: &str, extra: &[&str]) -> (i32, String) {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .canonicalize()
        .unwrap();
    let dir = temp_dir("conform-log", name);
    let dut = format!("exec:python3 {}/tests/hpd_adapter.py", repo.display());
    let mut args = vec![
        "conform",
        "hpd",
        "--dut",
        &dut,
        "--case",
        "hpd/frame/read-plc",
        "--case",
        "hpd/frame/read-parameter",
        "--report-dir",
        dir.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (code, out, err) = run_with(BIN, &args, None, CI);
    let _ = std::fs::remove_dir_all(&dir);
    let text = format!("--- stderr\n{err}--- stdout\n{out}")
        .replace(&repo.display().to_string(), "$REPO")
        .replace(&dir.display().to_string(), "$DIR");
    (code, text)
}

#[test]
fn a_failing_run_tells_the_story_in_the_log() {
    let (code, text) = log("default", &[]);
    assert_eq!(code, 1, "{text}");
    insta::assert_snapshot!(text);
}

#[test]
fn verbose_lists_passing_cases_and_quiet_keeps_the_failures() {
    let (code, verbose) = log("verbose", &["--verbose"]);
    assert_eq!(code, 1, "{verbose}");
    assert!(
        verbose.contains("pass             hpd/frame/read-parameter (1/2)"),
        "{verbose}"
    );
    let (code, quiet) = log("quiet", &["--quiet"]);
    assert_eq!(code, 1, "{quiet}");
    assert!(!quiet.contains("hpd/frame/read-parameter"), "{quiet}");
    assert!(
        quiet.contains("FAIL hpd/frame/read-plc (2/2)\n  breaks HPD-"),
        "{quiet}"
    );
    assert!(quiet.contains("failures (1):"), "{quiet}");
    assert!(
        quiet.contains("1 passed (0 acceptable), 1 failed"),
        "{quiet}"
    );
}
