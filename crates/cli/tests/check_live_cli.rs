//! `drivespec check --live IFACE`: the frames of a planted recording, replayed with
//! `drivespec-wire` in one network namespace at their recorded pace, are checked live in the
//! other; the live check finds the same `must` violations at the same frames as the check
//! of the file. Warnings may differ: they include the watchdog gaps of real receive times.
#![allow(
    clippy::expect_used,
    clippy::unwrap_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use drivespec_capture::input::Input;
use drivespec_capture::pcap::CaptureReader;
use drivespec_testkit::netns::{self, NetnsPair, NsChild};
use drivespec_testkit::run;
use drivespec_wire::{OpenOptions, RawSocket, MAX_FRAME};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

const TEST: &str = "live_check_finds_the_violations_of_the_recording";

const RECORDING: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../corpus/planted/psd426-planted-protocol.pcapng.gz"
);

/// Sends every frame of RECORDING on `iface`, each at its recorded offset from the first.
fn replay(iface: &str) {
    let file = std::fs::File::open(RECORDING).unwrap();
    let reader = CaptureReader::new(Input::open(file).unwrap()).unwrap();
    let mut sock = RawSocket::open(iface, OpenOptions::default()).unwrap();
    let (start, mut first, mut sent) = (Instant::now(), None, 0);
    for rec in reader {
        let rec = rec.unwrap();
        let t = rec.time.unwrap();
        let due = start + Duration::from_micros(t - *first.get_or_insert(t));
        if let Some(wait) = due.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
        assert!(rec.data.len() <= MAX_FRAME, "frame {}", rec.number);
        sock.send(&rec.data).unwrap();
        sent += 1;
    }
    println!("sent: {sent}");
}

/// The `must` violations of a JSON report: requirement, frame and message.
fn musts(json: &str) -> Vec<(String, u64, String)> {
    let doc: serde_json::Value = serde_json::from_str(json).unwrap();
    let report = &doc["reports"][0];
    report["violations"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|v| v["level"] == "must")
        .map(|v| {
            (
                v["requirement"].as_str().unwrap().to_owned(),
                v["where"]["frame"].as_u64().unwrap(),
                v["message"].as_str().unwrap().to_owned(),
            )
        })
        .collect()
}

#[test]
fn live_check_finds_the_violations_of_the_recording() {
    if netns::role().is_some() {
        replay(&std::env::var("DRIVESPEC_IFACE").unwrap());
        return;
    }
    let (code, file_json, err) = run(BIN, &["check", RECORDING, "--report", "json"]);
    assert_eq!(code, 1, "{err}");
    let want = musts(&file_json);
    assert!(!want.is_empty(), "{file_json}");
    let Some(pair) = NetnsPair::create() else {
        return;
    };
    let mut check = pair.b.command(BIN);
    check.args([
        "check",
        "--live",
        &pair.b.iface,
        "--duration",
        "12s",
        "--report",
        "json",
    ]);
    let mut checker = NsChild::spawn_piped(check);
    checker.wait_err_line("checking the frames on");
    let sender = pair
        .a
        .spawn_test(TEST, "replay", &[("DRIVESPEC_IFACE", &pair.a.iface)]);
    let (sent, _, _) = sender.finish();
    assert_eq!(sent, 0, "the replay failed");
    let (code, live_json, err) = checker.finish();
    assert_eq!(code, 1, "{err}{live_json}");
    let doc: serde_json::Value = serde_json::from_str(&live_json).unwrap();
    let events = &doc["reports"][0]["events"];
    println!("live: {events}");
    assert_eq!(musts(&live_json), want);
}

#[test]
fn live_check_names_missing_interfaces_and_permissions() {
    let (code, _, err) = run(BIN, &["check", "--live", "no-such-if0", "--duration", "1s"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("no network interface named `no-such-if0`"),
        "{err}"
    );
    let (code, _, err) = run(BIN, &["check", "--duration", "1s", "x.pcap"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--duration"), "{err}");
    // Without CAP_NET_RAW (setpriv drops it, where setpriv exists): one line saying what is
    // needed.
    let dropped = std::process::Command::new("setpriv")
        .args(["--inh-caps=-all", "--bounding-set=-net_raw,-net_admin", BIN])
        .args(["check", "--live", "lo", "--duration", "1s"])
        .output();
    match dropped {
        Ok(out) if out.status.code() != Some(127) => {
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{err}");
            assert!(err.contains("cap_net_raw,cap_net_admin+ep"), "{err}");
        }
        _ => println!("skipping the permission case: no setpriv"),
    }
}

/// SIGINT ends a live check without `--duration` cleanly: the report of what was received and
/// exit 130, as for an interrupted recording.
#[test]
fn sigint_ends_a_live_check_with_its_report() {
    use std::io::{BufRead, BufReader, Read};
    use std::process::{Command, Stdio};
    let mut child = Command::new(BIN)
        .args(["check", "--live", "lo"])
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let mut line = String::new();
    err.read_line(&mut line).unwrap();
    if line.contains("cap_net_raw") {
        println!("skipping: {line}");
        let _ = child.wait();
        return;
    }
    assert!(
        line.contains("checking the frames on lo until Ctrl-C"),
        "{line}"
    );
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args(["-INT", &pid])
        .status()
        .unwrap()
        .success());
    let mut out = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut out)
        .unwrap();
    let mut rest = String::new();
    err.read_to_string(&mut rest).unwrap();
    let code = child.wait().unwrap().code();
    assert_eq!(code, Some(130), "{out}{rest}");
    assert!(
        out.starts_with("lo [psd4xx]") && out.contains("interrupted"),
        "{out}"
    );
    assert!(rest.contains("interrupted by SIGINT"), "{rest}");
}
