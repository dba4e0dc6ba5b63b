//! `drivespec fuzz` as users run it: exit codes, reports, replay and minimise of a file.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run_with, temp_dir, CI};

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

#[test]
fn bad_usage_is_refused() {
    let (code, _, err) = run_with(BIN, &["fuzz", "psx4xx"], None, CI);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("hpd, psd4xx or psx3xx"), "{err}");
    let (code, _, _) = run_with(
        BIN,
        &["fuzz", "hpd", "--iterations", "3", "--duration", "1s"],
        None,
        CI,
    );
    assert_eq!(code, 2);
    let (code, _, err) = run_with(BIN, &["fuzz", "hpd", "--duration", "10 parsecs"], None, CI);
    assert_eq!(code, 2, "{err}");
}

#[test]
fn a_run_against_the_reference_passes_and_writes_reports() {
    let out = temp_dir("fuzz-cli", "run");
    let dir = out.display().to_string();
    let (code, stdout, stderr) = run_with(
        BIN,
        &[
            "fuzz",
            "hpd",
            "--iterations",
            "30",
            "--seed",
            "5",
            "--out",
            &dir,
        ],
        None,
        CI,
    );
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(
        stdout.contains("30 sequence(s)") && stdout.contains("0 finding(s)"),
        "{stdout}"
    );
    assert!(stderr.contains("fuzz hpd: 30/30 sequences"), "{stderr}");
    for f in ["fuzz.json", "fuzz.junit.xml", "fuzz.html"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let (code, stdout, _) = run_with(
        BIN,
        &[
            "--format",
            "json",
            "fuzz",
            "hpd",
            "--iterations",
            "5",
            "--out",
            &dir,
            "--quiet",
        ],
        None,
        CI,
    );
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
    let out = temp_dir("fuzz-cli", "replay");
    std::fs::create_dir_all(&out).unwrap();
    let file = out.join("finding.json");
    std::fs::write(&file, REPLAY).unwrap();
    let f = file.display().to_string();
    let dir = out.display().to_string();
    // The reference answers correctly: the replay passes, and differs from the recording.
    let (code, stdout, stderr) = run_with(BIN, &["fuzz", "hpd", "--replay", &f], None, CI);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(stdout.contains("passes"), "{stdout}");
    assert!(stdout.contains("differs from the recorded one"), "{stdout}");
    assert!(stdout.contains("7E 20 02 C6 F4 01 DD"), "{stdout}");
    let (code, stdout, _) = run_with(
        BIN,
        &["fuzz", "hpd", "--minimize", &f, "--out", &dir],
        None,
        CI,
    );
    assert_eq!(code, 0, "{stdout}");
    assert!(stdout.contains("nothing to minimise"), "{stdout}");
    // A broken file is unreadable input.
    std::fs::write(
        &file,
        REPLAY.replace("\"do\": \"listen\"", "\"do\": \"nap\""),
    )
    .unwrap();
    let (code, _, err) = run_with(BIN, &["fuzz", "hpd", "--replay", &f], None, CI);
    assert_eq!(code, 2);
    assert!(err.contains("step 1") && err.contains("nap"), "{err}");
    std::fs::remove_dir_all(&out).unwrap();
}
