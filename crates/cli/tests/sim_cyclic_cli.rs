//! `drivespec sim psd4xx` as users run it: `--listen` with `drivespec conform psd4xx --dut
//! tcp:`, `--stdio` answering a HELLO/RESET/CYCLE exchange and as an `exec:` device under
//! test, `--pty` with a line client, the fault flags, and the usage errors. Every server gets
//! `--time-limit` and is killed at the end of its test; every address is loopback.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run_with, temp_dir, Sim};
use std::io::{Read, Write};
use std::time::Duration;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

const CASES: &[&str] = &[
    "psd4xx/pkw/read/44",
    "psd4xx/pkw/write/44",
    "psd4xx/record/write/44",
    "psd4xx/position/loop/up",
    "psd4xx/status/toggle",
    "psd4xx/status/obstruction",
];

fn conform(dut: &str, name: &str) -> (i32, String) {
    let dir = temp_dir("simc", name);
    let mut args = vec![
        "conform".to_owned(),
        "psd4xx".to_owned(),
        "--dut".to_owned(),
        dut.to_owned(),
        "--quiet".to_owned(),
        "--report-dir".to_owned(),
        dir.display().to_string(),
    ];
    for c in CASES {
        args.push("--case".to_owned());
        args.push((*c).to_owned());
    }
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, out, err) = run_with(BIN, &argv, Some(""), &[]);
    let _ = std::fs::remove_dir_all(&dir);
    (code, format!("{out}{err}"))
}

#[test]
fn listen_serves_conform_over_tcp() {
    let mut sim = Sim::start(BIN, &["psd4xx", "--listen", "tcp:127.0.0.1:0"]);
    let addr = sim.first_line();
    assert!(addr.starts_with("127.0.0.1:"), "{addr}");
    let (code, out) = conform(&format!("tcp:{addr}"), "tcp");
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("0 failed"), "{out}");
    let err = sim.stop();
    assert!(err.contains("psd4xx reference PSD401-5V"), "{err}");
    assert!(err.contains("connected"), "{err}");
}

#[test]
fn stdio_answers_an_exchange_and_serves_exec() {
    let (code, out, err) = run_with(BIN, &["sim", "psd4xx", "--stdio", "--model", "PSD426"], Some("HELLO drivespec-cyclic 1 psd4xx PSD426\nRESET\nCYCLE 10000 0000000000000000000000000000\nCYCLE 20000 102c000000000000000000000000\nbogus\n"), &[]);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 5, "{out}");
    assert!(
        lines[0].starts_with("HELLO drivespec-cyclic 1 ") && lines[0].contains("PSD426"),
        "{out}"
    );
    assert_eq!(lines[1], "OK");
    assert!(
        lines[2].starts_with("IN ") && lines[2].len() == 3 + 32,
        "{out}"
    );
    // A PKW read of par 44 (AK 1, PNU 44) is answered in the same cycle.
    assert!(lines[3].to_uppercase().starts_with("IN 102C"), "{out}");
    assert!(lines[4].starts_with("ERR "), "{out}");
    let dut = format!("exec:{BIN} sim psd4xx --stdio --time-limit 60");
    let (code, out) = conform(&dut, "stdio");
    assert_eq!(code, 0, "{out}");
}

#[test]
fn faults_drop_and_corrupt_replies() {
    let input = "HELLO drivespec-cyclic 1 psd4xx PSD401-5V\nRESET\nCYCLE 10000 0000000000000000000000000000\n";
    let (code, out, err) = run_with(
        BIN,
        &["sim", "psd4xx", "--stdio", "--drop-answers", "1"],
        Some(input),
        &[],
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.is_empty(), "{out}");
    assert!(err.contains("3 dropped"), "{err}");
    let (code, clean, _) = run_with(BIN, &["sim", "psd4xx", "--stdio"], Some(input), &[]);
    assert_eq!(code, 0);
    let (code, bad, err) = run_with(
        BIN,
        &["sim", "psd4xx", "--stdio", "--corrupt-images", "1", "--log"],
        Some(input),
        &[],
    );
    assert_eq!(code, 0, "{err}");
    let (c, b): (Vec<&str>, Vec<&str>) = (clean.lines().collect(), bad.lines().collect());
    assert_eq!(c[..2], b[..2]);
    assert_ne!(c[2], b[2]);
    assert!(err.contains("image corrupted (fault)"), "{err}");
    // A conform run against corrupted images fails (exit 1), it does not hang or crash.
    let dut = format!("exec:{BIN} sim psd4xx --stdio --corrupt-images 1 --time-limit 60");
    let (code, out) = conform(&dut, "corrupt");
    assert_eq!(code, 1, "{out}");
}

#[cfg(unix)]
#[test]
fn pty_speaks_the_line_protocol() {
    let mut sim = Sim::start(BIN, &["psd4xx", "--pty"]);
    let path = sim.first_line();
    assert!(path.starts_with("/dev/"), "{path}");
    let mut f = std::fs::OpenOptions::new()
        .read(true)
        .write(true)
        .open(&path)
        .unwrap();
    f.write_all(b"HELLO drivespec-cyclic 1 psd4xx PSD401-5V\nRESET\n")
        .unwrap();
    let mut got = Vec::new();
    let mut buf = [0u8; 256];
    let until = std::time::Instant::now() + Duration::from_secs(10);
    while got.iter().filter(|b| **b == b'\n').count() < 2 && std::time::Instant::now() < until {
        let n = f.read(&mut buf).unwrap();
        got.extend_from_slice(&buf[..n]);
    }
    let text = String::from_utf8_lossy(&got);
    assert!(text.starts_with("HELLO drivespec-cyclic 1 "), "{text}");
    assert!(text.contains("\nOK\n"), "{text}");
    drop(f);
    sim.stop();
}

#[test]
fn bad_usage_exits_2() {
    for args in [
        &["sim", "psd4xx", "--stdio", "--corrupt-checksums", "0.5"][..],
        &["sim", "psd4xx", "--stdio", "--corrupt-images", "2"],
        &["sim", "psd4xx", "--stdio", "--model", "PSD999"],
        &["sim", "psd4xx", "--stdio", "--baud-code", "3"],
        &["sim", "hpd", "--stdio", "--corrupt-images", "0.5"],
        &["sim", "psd4xx", "--listen", "udp:127.0.0.1:0"],
        &["sim", "psx3xx", "--stdio", "--brake", "snap"],
        &[
            "sim",
            "psx3xx",
            "--stdio",
            "--model",
            "PSE312-14",
            "--brake",
            "disc",
        ],
        &["sim", "psd4xx", "--stdio", "--brake", "snap"],
    ] {
        let (code, _, err) = run_with(BIN, args, Some(""), &[]);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.starts_with("drivespec: "), "{err}");
    }
}

#[test]
fn psx3xx_is_served_on_stdio() {
    let (code, out, err) = run_with(
        BIN,
        &["sim", "psx3xx", "--stdio"],
        Some("HELLO drivespec-cyclic 1 psx3xx x\nRESET\nHELLO drivespec-cyclic 1 psd4xx x\n"),
        &[],
    );
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 3, "{out}");
    assert!(lines[0].starts_with("HELLO drivespec-cyclic 1 "), "{out}");
    assert_eq!(lines[1], "OK");
    assert!(lines[2].starts_with("ERR "), "{out}");
    assert!(err.contains("psx3xx reference "), "{err}");
}

#[test]
fn psx3xx_with_a_snap_brake_is_served_on_stdio() {
    let (code, out, err) = run_with(
        BIN,
        &[
            "sim",
            "psx3xx",
            "--stdio",
            "--model",
            "PSE312-14",
            "--brake",
            "snap",
        ],
        Some("HELLO drivespec-cyclic 1 psx3xx x\nRESET\n"),
        &[],
    );
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().nth(1), Some("OK"), "{out}");
    assert!(
        err.contains("psx3xx reference PSE312-14 with a snap brake"),
        "{err}"
    );
}
