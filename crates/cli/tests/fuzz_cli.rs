//! `drivespec fuzz` as users run it: exit codes, reports, replay and minimise of a file.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use std::path::PathBuf;
use std::process::Command;

fn drivespec(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_drivespec"))
        .args(args)
        .env("CI", "true")
        .output()
        .expect("run drivespec");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("drivespec-fuzz-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn bad_usage_is_refused() {
    let (code, _, err) = drivespec(&["fuzz", "psx4xx"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("hpd, psd4xx or psx3xx"), "{err}");
    let (code, _, _) = drivespec(&["fuzz", "hpd", "--iterations", "3", "--duration", "1s"]);
    assert_eq!(code, 2);
    let (code, _, err) = drivespec(&["fuzz", "hpd", "--duration", "10 parsecs"]);
    assert_eq!(code, 2, "{err}");
}

#[test]
fn a_run_against_the_reference_passes_and_writes_reports() {
    let out = temp("run");
    let dir = out.display().to_string();
    let (code, stdout, stderr) = drivespec(&[
        "fuzz",
        "hpd",
        "--iterations",
        "30",
        "--seed",
        "5",
        "--out",
        &dir,
    ]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(
        stdout.contains("30 sequence(s)") && stdout.contains("0 finding(s)"),
        "{stdout}"
    );
    assert!(stderr.contains("fuzz hpd: 30/30 sequences"), "{stderr}");
    for f in ["fuzz.json", "fuzz.junit.xml", "fuzz.html"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let (code, stdout, _) = drivespec(&[
        "--format",
        "json",
        "fuzz",
        "hpd",
        "--iterations",
        "5",
        "--out",
        &dir,
        "--quiet",
    ]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["sequences"], 5);
    std::fs::remove_dir_all(&out).unwrap();
}

/// A replay whose recorded device answer (a wrong checksum) the reference does not give.
const REPLAY: &str = r#"{
  "format": "drivespec-fuzz-replay/1",
  "family": "hpd",
  "dut": "exec:./my-drive",
  "address": 0,
  "seed": 0,
  "start": "fresh",
  "steps": [
    { "do": "exchange", "hex": "7E 80 02 54 D6", "class": "valid-read", "text": "read Pr31" },
    { "do": "listen", "us": 6144, "class": "listen" },
    { "do": "exchange", "hex": "7E 80 02 C6 48", "class": "valid-read", "text": "read Pr33" }
  ],
  "exchanges": [
    { "step": 2, "at_us": 0, "sent": "7E 80 02 C6 48", "expected": "7E 20 02 C6 F4 01 DD", "got": "7E 20 02 C6 F4 01 DE", "ok": false }
  ]
}
"#;

#[test]
fn replay_and_minimize_a_file() {
    let out = temp("replay");
    std::fs::create_dir_all(&out).unwrap();
    let file = out.join("finding.json");
    std::fs::write(&file, REPLAY).unwrap();
    let f = file.display().to_string();
    let dir = out.display().to_string();
    // The reference answers correctly: the replay passes, and differs from the recording.
    let (code, stdout, stderr) = drivespec(&["fuzz", "hpd", "--replay", &f]);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(stdout.contains("passes"), "{stdout}");
    assert!(stdout.contains("differs from the recorded one"), "{stdout}");
    assert!(stdout.contains("7E 20 02 C6 F4 01 DD"), "{stdout}");
    let (code, stdout, _) = drivespec(&["fuzz", "hpd", "--minimize", &f, "--out", &dir]);
    assert_eq!(code, 0, "{stdout}");
    assert!(stdout.contains("nothing to minimise"), "{stdout}");
    // A broken file is unreadable input.
    std::fs::write(
        &file,
        REPLAY.replace("\"do\": \"listen\"", "\"do\": \"nap\""),
    )
    .unwrap();
    let (code, _, err) = drivespec(&["fuzz", "hpd", "--replay", &f]);
    assert_eq!(code, 2);
    assert!(err.contains("step 1") && err.contains("nap"), "{err}");
    std::fs::remove_dir_all(&out).unwrap();
}
