//! Every JUnit file the binary writes validates against the Jenkins xUnit schema
//! (`../shared/schemas/junit-10.xsd` beside the repository) with `xmllint --schema`: `conform`
//! with failures, `fuzz` with and without findings, and `check` with violations and with a
//! recording cut short (an `<error>`). The test says why and passes when the schema or
//! `xmllint` (Debian's `libxml2-utils`) is missing.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run_with, temp_dir, CI};
use std::path::{Path, PathBuf};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

fn manifest(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// The schema, when it and xmllint are there.
fn schema() -> Option<PathBuf> {
    let xsd = manifest("../../../shared/schemas/junit-10.xsd");
    if !xsd.is_file() {
        println!("skipped: no schema at {}", xsd.display());
        return None;
    }
    if Command::new("xmllint").arg("--version").output().is_err() {
        println!("skipped: xmllint is not installed (Debian package libxml2-utils)");
        return None;
    }
    Some(xsd)
}

/// Validates `file` against `xsd`; returns the file's text.
fn valid(xsd: &Path, file: &Path) -> String {
    let out = Command::new("xmllint")
        .args(["--noout", "--schema"])
        .arg(xsd)
        .arg(file)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{} does not validate:\n{}",
        file.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(file).unwrap();
    assert!(
        text.contains(" timestamp=\"") && text.contains(" hostname=\""),
        "{text}"
    );
    text
}

#[test]
fn conform_junit_with_failures_validates_and_logs_the_exchange() {
    let Some(xsd) = schema() else { return };
    let dir = temp_dir("junit-schema", "conform");
    let adapter = manifest("../../tests/hpd_adapter.py");
    let dut = format!("exec:python3 {}", adapter.display());
    let (code, out, err) = run_with(
        BIN,
        &[
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
        ],
        None,
        CI,
    );
    assert_eq!(code, 1, "{out}{err}");
    let x = valid(&xsd, &dir.join("conform.junit.xml"));
    assert!(x.contains("<failure message=\"breaks HPD-"), "{x}");
    assert!(x.contains("<system-out>exchange:"), "{x}");
    assert!(!x.contains(" time=\"0.000\">\n  <testsuite"), "{x}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fuzz_junit_validates_and_carries_the_run_time() {
    let Some(xsd) = schema() else { return };
    let dir = temp_dir("junit-schema", "fuzz");
    let (code, out, err) = run_with(
        BIN,
        &[
            "fuzz",
            "hpd",
            "--iterations",
            "20",
            "--out",
            dir.to_str().unwrap(),
        ],
        None,
        CI,
    );
    assert_eq!(code, 0, "{out}{err}");
    let x = valid(&xsd, &dir.join("fuzz.junit.xml"));
    assert!(!x.contains("time=\"0.000\" timestamp"), "{x}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fuzz_junit_with_findings_validates() {
    let Some(xsd) = schema() else { return };
    let dir = temp_dir("junit-schema", "fuzz-findings");
    let relay = manifest("tests/dying_psx3xx_relay.py");
    let dut = format!("exec:python3 {} {BIN} sim psx3xx --stdio", relay.display());
    let (code, out, err) = run_with(
        BIN,
        &[
            "fuzz",
            "psx3xx",
            "--dut",
            &dut,
            "--iterations",
            "10",
            "--seed",
            "2",
            "--max-findings",
            "2",
            "--minimize-runs",
            "4",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ],
        None,
        CI,
    );
    assert_eq!(code, 1, "{out}{err}");
    let x = valid(&xsd, &dir.join("fuzz.junit.xml"));
    assert!(x.contains("<failure"), "{x}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn check_junit_validates_names_suites_by_file_and_makes_a_cut_an_error() {
    let Some(xsd) = schema() else { return };
    let dir = temp_dir("junit-schema", "check");
    let faults = manifest("../../corpus/captures/psx3xx-faults.jsonl");
    let truncated = manifest("../../corpus/captures/psd4xx-truncated.pcap.gz");
    let (code, out, err) = run_with(
        BIN,
        &[
            "check",
            "--report-dir",
            dir.to_str().unwrap(),
            faults.to_str().unwrap(),
            truncated.to_str().unwrap(),
        ],
        None,
        CI,
    );
    assert_eq!(code, 2, "{out}{err}");
    let x = valid(&xsd, &dir.join("check.xml"));
    assert!(x.contains("<testsuite name=\"psx3xx-faults.jsonl\""), "{x}");
    assert!(
        x.contains("<testsuite name=\"psd4xx-truncated.pcap.gz\""),
        "{x}"
    );
    assert!(x.contains("<failure message="), "{x}");
    assert!(x.contains("<error message="), "{x}");
    assert!(
        !x.contains(">\n</failure>") && !x.contains("\">\n\n"),
        "{x}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
