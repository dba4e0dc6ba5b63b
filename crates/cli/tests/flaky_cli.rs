//! `--retries`: a case that fails once on a noisy line (`flaky_hpd_relay.py` loses the first
//! answer) and passes when run again is reported as flaky — in the log, the JSON summary and
//! JUnit (`rerunFailure`, valid against the shared schema) — never silently as passed; without retries it fails the run.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run, temp_dir};
use std::path::Path;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// `drivespec conform hpd` over the lossy relay with `extra` arguments: exit code, stdout, the
/// JSON report and the JUnit report.
fn conform(name: &str, extra: &[&str]) -> (i32, String, serde_json::Value, String) {
    let dir = temp_dir("flaky", name);
    let relay = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/flaky_hpd_relay.py");
    let dut = format!("exec:python3 {relay} {BIN} sim hpd --stdio --time-limit 60");
    let report_dir = dir.display().to_string();
    let mut args = vec![
        "conform",
        "hpd",
        "--dut",
        dut.as_str(),
        "--case",
        "hpd/frame/read-parameter",
        "--report-dir",
        report_dir.as_str(),
    ];
    args.extend_from_slice(extra);
    let (code, out, err) = run(BIN, &args);
    let json =
        std::fs::read_to_string(dir.join("conform.json")).unwrap_or_else(|e| panic!("{e}: {err}"));
    let junit_path = dir.join("conform.junit.xml");
    let junit = std::fs::read_to_string(&junit_path).unwrap();
    let xsd = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/schemas/junit-10.xsd");
    match Command::new("xmllint")
        .args(["--noout", "--schema"])
        .arg(&xsd)
        .arg(&junit_path)
        .output()
    {
        Ok(v) if xsd.is_file() => {
            assert!(v.status.success(), "{}", String::from_utf8_lossy(&v.stderr))
        }
        _ => println!(
            "JUnit not validated: no xmllint or no schema at {}",
            xsd.display()
        ),
    }
    let _ = std::fs::remove_dir_all(&dir);
    (code, out, serde_json::from_str(&json).unwrap(), junit)
}

#[test]
fn a_case_that_passes_only_when_run_again_is_flaky_not_passed() {
    let (code, out, json, _) = conform("no-retries", &[]);
    assert_eq!(code, 1, "{out}");
    assert_eq!(json["summary"]["failed"], 1, "{out}");

    let (code, out, json, junit) = conform("retries", &["--retries", "2"]);
    assert_eq!(code, 0, "{out}");
    let summary = &json["summary"];
    assert_eq!(summary["flaky"], 1, "{summary}");
    assert_eq!(summary["failed"], 0, "{summary}");
    let case = &json["cases"][0];
    assert_eq!(case["status"], "flaky");
    assert!(case["failure"]["message"].is_string(), "{case}");
    assert!(
        out.contains("flaky: hpd/frame/read-parameter failed, then passed when run again"),
        "{out}"
    );
    assert!(out.contains("1 flaky case(s)"), "{out}");
    assert!(
        junit.contains("<rerunFailure message=\"failed, then passed when run again"),
        "{junit}"
    );
    assert!(!junit.contains("<failure"), "{junit}");
}
