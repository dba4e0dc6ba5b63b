//! `drivespec fuzz psd4xx` as users run it: against the built-in model (nothing found, reports
//! written, progress on stderr) and against `drivespec sim psd4xx --listen` over TCP, against
//! the Python example adapter over `exec:` (findings with replay files), and `--replay` /
//! `--minimize` of such a file.
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

#[test]
fn against_the_reference_nothing_is_found() {
    fuzz_finds_nothing(
        BIN,
        "psd4xx",
        &["--model", "PSD426"],
        "PSD426",
        40,
        "pkw-handshake-violation",
    );
}

#[test]
fn findings_against_the_example_adapter_replay_and_minimise() {
    let adapter = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/psd4xx_adapter.py");
    let dut = format!("exec:python3 {}", adapter.display());
    let out = temp_dir("fuzz-psd-cli", "exec");
    let dir = out.display().to_string();
    let (code, stdout, stderr) = run(
        BIN,
        &[
            "fuzz",
            "psd4xx",
            "--dut",
            &dut,
            "--iterations",
            "4",
            "--max-findings",
            "2",
            "--minimize-runs",
            "20",
            "--out",
            &dir,
            "--quiet",
        ],
    );
    assert_eq!(code, 1, "{stdout}{stderr}");
    assert!(stdout.contains("psd4xx/fuzz/finding-1: "), "{stdout}");
    let file = out.join("finding-1.json");
    let f = file.display().to_string();
    let (code, stdout, stderr) = run(BIN, &["fuzz", "psd4xx", "--dut", &dut, "--replay", &f]);
    assert_eq!(code, 1, "{stdout}{stderr}");
    assert!(
        !stdout.contains("differs from the recorded one"),
        "{stdout}"
    );
    // Against the built-in reference the same file passes.
    let (code, stdout, _) = run(BIN, &["fuzz", "psd4xx", "--replay", &f]);
    assert_eq!(code, 0, "{stdout}");
    let (code, stdout, stderr) = run(
        BIN,
        &[
            "fuzz",
            "psd4xx",
            "--dut",
            &dut,
            "--minimize",
            &f,
            "--out",
            &dir,
        ],
    );
    assert_eq!(code, 1, "{stdout}{stderr}");
    assert!(out.join("finding-1.min.json").is_file(), "{stdout}");
    // An HPD replay is refused for psd4xx.
    let (code, _, stderr) = run(BIN, &["fuzz", "hpd", "--replay", &f]);
    assert_eq!(code, 2, "{stderr}");
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn over_tcp_against_drivespec_sim_nothing_is_found() {
    use std::io::BufRead;
    let mut sim = Command::new(BIN)
        .args([
            "sim",
            "psd4xx",
            "--listen",
            "tcp:127.0.0.1:0",
            "--time-limit",
            "60",
        ])
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let mut addr = String::new();
    std::io::BufReader::new(sim.stdout.take().unwrap())
        .read_line(&mut addr)
        .unwrap();
    let out = temp_dir("fuzz-psd-cli", "tcp");
    let dut = format!("tcp:{}", addr.trim());
    let (code, stdout, stderr) = run(
        BIN,
        &[
            "fuzz",
            "psd4xx",
            "--dut",
            &dut,
            "--iterations",
            "30",
            "--seed",
            "4",
            "--quiet",
            "--out",
            &out.display().to_string(),
        ],
    );
    let _ = sim.kill();
    let _ = sim.wait();
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(
        stdout.contains("30 sequence(s)") && stdout.contains("0 finding(s)"),
        "{stdout}"
    );
    std::fs::remove_dir_all(&out).unwrap();
}
