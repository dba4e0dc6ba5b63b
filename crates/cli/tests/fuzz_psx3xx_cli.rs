//! `drivespec fuzz psx3xx` as users run it: against the built-in model (nothing found, reports
//! written, progress on stderr), against `drivespec sim psx3xx --stdio` over `exec:` (nothing
//! found), and `--replay` of a replay file on both, which gives the same exchanges; a PSx3xx
//! replay is refused for another family; a device that dies or hangs
//! (`dying_psx3xx_relay.py` in front of the simulator) gives one-step crash and hang findings
//! while the run goes on.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{fuzz_finds_nothing, run, temp_dir};
use std::path::PathBuf;
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// `exec:` running this binary's simulator on stdin/stdout.
fn exec_sim() -> String {
    format!("exec:{BIN} sim psx3xx --stdio")
}

#[test]
fn against_the_reference_nothing_is_found() {
    fuzz_finds_nothing(BIN, "psx3xx", &[], "PSE312-8", 30, "isdu-write");
}

#[test]
fn over_exec_against_drivespec_sim_nothing_is_found() {
    let out = temp_dir("fuzz-psx-cli", "exec");
    let dut = exec_sim();
    let (code, stdout, stderr) = run(
        BIN,
        &[
            "fuzz",
            "psx3xx",
            "--dut",
            &dut,
            "--iterations",
            "15",
            "--seed",
            "4",
            "--quiet",
            "--out",
            &out.display().to_string(),
        ],
    );
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(
        stdout.contains("15 sequence(s)") && stdout.contains("0 finding(s)"),
        "{stdout}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}

/// A hand-written replay: an out-of-range write, its read-back, a format switch to format 2
/// and a run with speed 0 (ISDU 142).
const REPLAY: &str = r#"{
  "format": "drivespec-fuzz-replay/1",
  "family": "psx3xx",
  "dut": "sim",
  "address": 0,
  "seed": 0,
  "start": "fresh",
  "steps": [
    {"do": "isdu-write", "index": 135, "subindex": 0, "hex": "00 65", "class": "isdu-write-out-of-range"},
    {"do": "isdu-read", "index": 135, "subindex": 0, "class": "isdu-write-out-of-range"},
    {"do": "isdu-write", "index": 116, "subindex": 0, "hex": "02", "class": "format-switch"},
    {"do": "isdu-write", "index": 193, "subindex": 0, "hex": "00 01", "class": "format-switch"},
    {"do": "hold", "cycles": 250, "class": "format-switch"},
    {"do": "isdu-write", "index": 2, "subindex": 0, "hex": "80", "class": "format-switch"},
    {"do": "pd-out", "format": 2, "control": 20, "target": 4000, "speed": 0, "class": "format-2-speed"},
    {"do": "until", "running": true, "max": 1500, "class": "format-2-speed"},
    {"do": "until", "running": false, "max": 1500, "class": "format-2-speed"}
  ]
}
"#;

#[test]
fn a_replay_gives_the_same_exchanges_on_sim_and_over_exec() {
    let out = temp_dir("fuzz-psx-cli", "replay");
    std::fs::create_dir_all(&out).unwrap();
    let file = out.join("sequence.json");
    std::fs::write(&file, REPLAY).unwrap();
    let f = file.display().to_string();
    let (code, on_sim, stderr) = run(BIN, &["fuzz", "psx3xx", "--replay", &f]);
    assert_eq!(code, 0, "{on_sim}{stderr}");
    assert!(on_sim.contains(": passes"), "{on_sim}");
    assert!(on_sim.contains("ISDU-WRITE"), "{on_sim}");
    let dut = exec_sim();
    let (code, on_exec, stderr) = run(BIN, &["fuzz", "psx3xx", "--dut", &dut, "--replay", &f]);
    assert_eq!(code, 0, "{on_exec}{stderr}");
    // Byte for byte the same exchanges on both transports (virtual time).
    assert_eq!(on_sim, on_exec);
    // A PSx3xx replay is refused for psd4xx (exit 2).
    let (code, _, stderr) = run(BIN, &["fuzz", "psd4xx", "--replay", &f]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("psx3xx"), "{stderr}");
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn a_device_that_dies_or_hangs_is_a_finding_and_the_run_goes_on() {
    let ok = Command::new("python3")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !ok {
        eprintln!("no python3: skipped");
        return;
    }
    let relay = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/dying_psx3xx_relay.py");
    let dut = format!("exec:python3 {} {BIN} sim psx3xx --stdio", relay.display());
    let out = temp_dir("fuzz-psx-cli", "dying");
    let dir = out.display().to_string();
    let (code, stdout, stderr) = run(
        BIN,
        &[
            "--format",
            "json",
            "fuzz",
            "psx3xx",
            "--dut",
            &dut,
            "--iterations",
            "25",
            "--seed",
            "2",
            "--max-findings",
            "10",
            "--minimize-runs",
            "8",
            "--quiet",
            "--out",
            &dir,
        ],
    );
    assert_eq!(code, 1, "{stdout}{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["sequences"], 25, "the run went on to the end: {stdout}");
    let findings = v["findings"].as_array().unwrap();
    let of = |class: &str| {
        findings
            .iter()
            .find(|f| f["class"] == class && f["reproduced"] == true)
            .unwrap_or_else(|| panic!("no reproduced {class}: {stdout}"))
    };
    let crash = of("crash");
    assert_eq!(crash["steps"], 1, "{crash}");
    assert!(
        crash["signature"]
            .as_str()
            .unwrap()
            .starts_with("crash/isdu-write-2"),
        "{crash}"
    );
    let hang = of("hang");
    assert_eq!(hang["steps"], 1, "{hang}");
    assert_eq!(hang["signature"], "hang/advance", "{hang}");
    // The crash replays: it still fails, against the reference it passes.
    let file = crash["file"].as_str().unwrap();
    let (code, stdout, stderr) = run(BIN, &["fuzz", "psx3xx", "--dut", &dut, "--replay", file]);
    assert_eq!(code, 1, "{stdout}{stderr}");
    let (code, stdout, _) = run(BIN, &["fuzz", "psx3xx", "--replay", file]);
    assert_eq!(code, 0, "{stdout}");
    std::fs::remove_dir_all(&out).unwrap();
}
