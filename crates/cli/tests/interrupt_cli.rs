//! SIGINT, SIGTERM and `--timeout` on the real binary: `conform` against a drive that answers
//! in real time (`exec:` running `drivespec sim hpd --stdio`), `fuzz` with a long `--duration` and
//! `check` reading from a pipe that is fed without end stop after the current case, sequence or
//! record, write every report of what ran (the rest `not-run`, the run marked interrupted),
//! leave no temporary files and exit 130, 143 or 124.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::temp_dir;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// Starts `drivespec ARGS` with stderr piped and waits for its first line on stderr (the run
/// has started and its handlers are installed); the rest of stderr is drained in the back.
fn start(args: &[&str], stdin: Stdio) -> Child {
    let mut child = Command::new(BIN)
        .args(args)
        .env("CI", "true")
        .stdin(stdin)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut first = String::new();
        let _ = err.read_line(&mut first);
        let _ = tx.send(first);
        std::io::copy(&mut err, &mut std::io::sink())
    });
    let first = rx.recv_timeout(Duration::from_secs(30));
    if !first.as_ref().is_ok_and(|l| !l.is_empty()) {
        let _ = child.kill();
        panic!("no progress line within 30 s: {first:?}");
    }
    child
}

/// Sends `signal` (`INT`, `TERM`) to the child.
fn kill(child: &Child, signal: &str) {
    let status = Command::new("kill")
        .args(["-s", signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
}

/// Waits for the child (at most 20 s); its exit code and stdout.
fn finish(mut child: Child) -> (i32, String) {
    for _ in 0..200 {
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let _ = child.kill();
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
    )
}

/// The files in `dir` (names), sorted.
fn files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn conform_interrupted(signal: &str, code: i32) {
    let dir = temp_dir("interrupt", signal);
    let dut = format!("exec:{BIN} sim hpd --stdio --time-limit 60");
    let child = start(
        &[
            "conform",
            "hpd",
            "--dut",
            &dut,
            "--verbose",
            "--report-dir",
            dir.to_str().unwrap(),
        ],
        Stdio::null(),
    );
    kill(&child, signal);
    let (got, out) = finish(child);
    assert_eq!(got, code, "{out}");
    assert_eq!(
        files(&dir),
        ["conform.html", "conform.json", "conform.junit.xml"]
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("conform.json")).unwrap()).unwrap();
    let s = &json["summary"];
    assert_eq!(s["interrupted"], true, "{s}");
    let not_run = s["not_run"].as_u64().unwrap();
    let total = s["total"].as_u64().unwrap();
    assert!(not_run > 0 && not_run < total, "{s}");
    let cases = json["cases"].as_array().unwrap();
    assert_eq!(cases.len() as u64, total);
    assert!(cases.iter().any(|c| c["status"] != "not-run"));
    assert_eq!(cases.last().unwrap()["status"], "not-run");
    let junit = std::fs::read_to_string(dir.join("conform.junit.xml")).unwrap();
    assert!(junit.ends_with("</testsuites>\n"), "{junit}");
    assert!(
        junit.contains("<property name=\"interrupted\" value=\"true\"/>"),
        "{junit}"
    );
    assert!(
        junit.contains("not run: the run was interrupted"),
        "{junit}"
    );
    assert!(
        out.contains(&format!("interrupted by SIG{signal}")),
        "{out}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn conform_stopped_by_sigint_writes_every_report_and_exits_130() {
    conform_interrupted("INT", 130);
}

#[test]
fn conform_stopped_by_sigterm_writes_every_report_and_exits_143() {
    conform_interrupted("TERM", 143);
}

#[test]
fn conform_past_its_timeout_writes_every_report_and_exits_124() {
    let dir = temp_dir("interrupt", "timeout");
    let dut = format!("exec:{BIN} sim hpd --stdio --time-limit 60");
    let out = Command::new(BIN)
        .args([
            "conform",
            "hpd",
            "--dut",
            &dut,
            "--quiet",
            "--timeout",
            "1s",
        ])
        .arg("--report-dir")
        .arg(&dir)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(124), "{stdout}");
    assert!(
        stdout.contains("interrupted by the --timeout limit"),
        "{stdout}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("conform.json")).unwrap()).unwrap();
    assert_eq!(json["summary"]["interrupted"], true);
    assert!(json["summary"]["not_run"].as_u64().unwrap() > 0);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn fuzz_stopped_by_sigint_keeps_its_statistics_and_exits_130() {
    let dir = temp_dir("interrupt", "fuzz");
    let child = start(
        &[
            "fuzz",
            "hpd",
            "--duration",
            "60",
            "--format",
            "json",
            "--out",
            dir.to_str().unwrap(),
        ],
        Stdio::null(),
    );
    kill(&child, "INT");
    let (code, out) = finish(child);
    assert_eq!(code, 130, "{out}");
    assert_eq!(files(&dir), ["fuzz.html", "fuzz.json", "fuzz.junit.xml"]);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("fuzz.json")).unwrap()).unwrap();
    assert_eq!(json["summary"]["interrupted"], true, "{json}");
    assert_eq!(
        json["fuzz"]["stopped_by"], "interrupted",
        "{}",
        json["fuzz"]
    );
    assert!(json["fuzz"]["sequences"].as_u64().unwrap() > 0);
    let stdout: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert!(stdout["sequences"].as_u64().unwrap() > 0, "{out}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn check_stopped_by_sigterm_reports_what_was_read_and_exits_143() {
    let dir = temp_dir("interrupt", "check");
    let mut child = Command::new(BIN)
        .args(["check", "-", "--device", "hpd", "--input-format", "text"])
        .arg("--report-dir")
        .arg(&dir)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut input = child.stdin.take().unwrap();
    // An endless recording of polls and answers; the writer stops when the pipe closes.
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut t: u64 = 1_704_189_600_020_000;
        let mut sent = 0usize;
        loop {
            let pair = format!(
                "{t} > 7E 81 02 42 C5\n{} < 7E 21 02 42 00 00 65\n",
                t + 1000
            );
            if input.write_all(pair.as_bytes()).is_err() {
                return;
            }
            t += 20_000;
            sent += pair.len();
            if sent > 1 << 20 {
                let _ = tx.send(());
                sent = 0;
            }
        }
    });
    // A megabyte is through the pipe: the check is reading, its handlers are installed.
    rx.recv_timeout(Duration::from_secs(20)).unwrap();
    kill(&child, "TERM");
    let (code, out) = finish(child);
    assert_eq!(code, 143, "{out}");
    assert!(
        out.contains("interrupted: reading stopped before the end"),
        "{out}"
    );
    assert_eq!(
        files(&dir),
        ["check.html", "check.json", "check.txt", "check.xml"]
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("check.json")).unwrap()).unwrap();
    assert_eq!(json["reports"][0]["interrupted"], true);
    assert!(json["reports"][0]["events"].as_u64().unwrap() > 0);
    let _ = std::fs::remove_dir_all(&dir);
}
