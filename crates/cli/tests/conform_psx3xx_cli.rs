//! `drivespec conform psx3xx` as users run it: against the built-in model with `--dut
//! sim:MODEL`, and through `exec:` with `drivespec sim psx3xx --stdio` as the device, both
//! writing the JSON report; `all` includes PSx3xx.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::temp_dir;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// Runs `drivespec conform` with `args`; exit code, output and the JSON report.
fn conform(name: &str, args: &[&str]) -> (i32, String, serde_json::Value) {
    let dir = temp_dir("conform-psx3xx", name);
    let out = Command::new(BIN)
        .arg("conform")
        .args(args)
        .args(["--quiet", "--report-dir"])
        .arg(&dir)
        .output()
        .unwrap();
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let json = std::fs::read_to_string(dir.join("conform.json")).unwrap_or_default();
    let _ = std::fs::remove_dir_all(&dir);
    (
        out.status.code().unwrap_or(-1),
        text,
        serde_json::from_str(&json).unwrap_or(serde_json::Value::Null),
    )
}

#[test]
fn sim_with_a_model_suffix_passes() {
    let (code, out, json) = conform(
        "sim",
        &[
            "psx3xx",
            "--dut",
            "sim:PSS325-14",
            "--case",
            "psx3xx/format/*",
            "--case",
            "psx3xx/guard/109/*",
        ],
    );
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("against sim:PSS325-14"), "{out}");
    assert_eq!(json["run"]["families"][0], "psx3xx");
    assert!(json["summary"]["passed"].as_u64().unwrap() >= 15, "{json}");
}

#[test]
fn exec_against_the_served_model_passes() {
    let dut = format!("exec:{} sim psx3xx --stdio", BIN);
    let (code, out, json) = conform(
        "exec",
        &[
            "psx3xx",
            "--dut",
            &dut,
            "--case",
            "psx3xx/isdu/unknown-*",
            "--case",
            "psx3xx/timestamp/position",
            "--case",
            "psx3xx/status/jog-keys",
        ],
    );
    assert_eq!(code, 0, "{out}");
    assert_eq!(json["summary"]["failed"], 0, "{json}");
    assert!(json["summary"]["passed"].as_u64().unwrap() >= 5, "{json}");
}

#[test]
fn all_lists_psx3xx_cases() {
    let out = Command::new(BIN)
        .args(["conform", "all", "--list", "--case", "psx3xx/guard/*"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("psx3xx/guard/66/suppress"), "{text}");
}

#[test]
fn a_declared_snap_brake_runs_the_brake_cases_against_a_served_drive_with_one() {
    let dut = format!(
        "exec:{} sim psx3xx --stdio --model PSE312-14 --brake snap",
        BIN
    );
    let (code, out, json) = conform(
        "brake",
        &[
            "psx3xx",
            "--dut",
            &dut,
            "--model",
            "PSE312-14",
            "--brake",
            "snap",
            "--case",
            "psx3xx/brake",
            "--case",
            "psx3xx/position/readjust-disabled",
        ],
    );
    assert_eq!(code, 0, "{out}");
    assert_eq!(json["run"]["brake"], "snap", "{json}");
    assert_eq!(json["summary"]["passed"], 2, "{json}");
    assert_eq!(json["summary"]["skipped"], 1, "{json}");
    let skipped = json["cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["status"] == "skipped")
        .unwrap();
    let reason = skipped["skip_reason"].as_str().unwrap();
    assert!(
        reason.starts_with("not applicable: the drive has a snap brake"),
        "{reason}"
    );
}

#[test]
fn a_brake_the_model_cannot_have_is_a_usage_error() {
    for (args, says) in [
        (
            &["psx3xx", "--brake", "snap"][..],
            "PSE312-8 cannot have a snap brake; the snap brake is for PSx30x-14",
        ),
        (
            &["psx3xx", "--model", "PSE312-14", "--brake", "holding"][..],
            "PSE312-14 cannot have a holding brake; the holding brake is for PSE34xx",
        ),
        (
            &["psx3xx", "--model", "PSE312-14", "--brake", "disc"][..],
            "no such brake option; the PSx3xx brakes are snap, holding",
        ),
        (
            &["psd4xx", "--brake", "snap"][..],
            "the brake is an option of the psx3xx drives",
        ),
    ] {
        let (code, out, _) = conform("brake-usage", args);
        assert_eq!(code, 2, "{args:?}: {out}");
        assert!(out.contains(says), "{args:?}: {out}");
        assert_eq!(out.trim().lines().count(), 1, "{args:?}: {out}");
    }
}
