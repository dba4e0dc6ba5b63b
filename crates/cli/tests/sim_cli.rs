//! `drivespec sim` as users run it: `--stdio` as an `exec:` device under test, `--pty` with
//! `drivespec conform --dut serial:`, `--listen` with a raw client and the log, fault flags,
//! and the usage errors. Every server gets `--time-limit` and is killed at the end of its
//! test; every address is loopback.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run, temp_dir, Sim};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// `drivespec conform hpd` on `dut` with `cases`; a failing run is repeated once (cases that
/// read real time closely can miss under heavy load). Returns the last exit code and stdout.
fn conform(dut: &str, cases: &[&str], name: &str) -> (i32, String) {
    let dir = temp_dir("sim", name);
    let mut args = vec![
        "conform".to_owned(),
        "hpd".to_owned(),
        "--dut".to_owned(),
        dut.to_owned(),
        "--quiet".to_owned(),
        "--report-dir".to_owned(),
        dir.display().to_string(),
    ];
    for c in cases {
        args.push("--case".to_owned());
        args.push((*c).to_owned());
    }
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let (mut code, mut out, _) = run(BIN, &argv);
    if code == 1 {
        eprintln!("run again after a failure (timing under load?):\n{out}");
        (code, out, _) = run(BIN, &argv);
    }
    let _ = std::fs::remove_dir_all(&dir);
    (code, out)
}

#[test]
fn stdio_serves_an_exec_device_under_test() {
    let dut = format!("exec:{BIN} sim hpd --stdio --time-limit 60");
    let (code, out) = conform(
        &dut,
        &["hpd/frame", "hpd/param/Pr33", "hpd/vector"],
        "stdio",
    );
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("0 failed"), "{out}");
}

#[test]
fn stdio_with_corrupt_checksums_fails_the_read() {
    let dir = temp_dir("sim", "corrupt");
    let dut = format!("exec:{BIN} sim hpd --stdio --corrupt-checksums 1.0 --time-limit 60");
    let (code, out, _) = run(
        BIN,
        &[
            "conform",
            "hpd",
            "--dut",
            &dut,
            "--case",
            "hpd/frame/read-parameter",
            "--case",
            "hpd/frame/foreign-address/7",
            "--quiet",
            "--report-dir",
            &dir.display().to_string(),
        ],
    );
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 1, "{out}");
    // The read's answer fails; silence to a foreign address is still right.
    assert!(out.contains("1 passed (0 acceptable), 1 failed"), "{out}");
}

#[cfg(unix)]
#[test]
fn pty_path_works_as_a_serial_device_under_test() {
    let mut sim = Sim::start(BIN, &["hpd", "--pty"]);
    let path = sim.first_line();
    assert!(path.starts_with("/dev/"), "{path}");
    let (code, out) = conform(
        &format!("serial:{path}"),
        &[
            "hpd/frame/read-parameter",
            "hpd/frame/timeout-split",
            "hpd/baud/code-5",
            "hpd/baud/code-4",
        ],
        "pty",
    );
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("4 passed"), "{out}");
    let err = sim.stop();
    assert!(err.contains("57600 b/s"), "{err}");
    assert!(err.contains(&format!("--dut serial:{path}")), "{err}");
}

#[test]
fn listen_prints_the_address_and_logs_the_traffic_in_words() {
    let mut sim = Sim::start(
        BIN,
        &["hpd", "--listen", "tcp:127.0.0.1:0", "--log", "--addr", "1"],
    );
    let addr = sim.first_line();
    let mut s = TcpStream::connect(&addr).unwrap();
    s.set_read_timeout(Some(Duration::from_millis(200)))
        .unwrap();
    // Manual 4.1 case 2: read Pr7 from drive 1.
    s.write_all(&[0x7E, 0x81, 0x02, 0x42, 0xC5]).unwrap();
    let mut got = Vec::new();
    let mut buf = [0u8; 16];
    let until = Instant::now() + Duration::from_secs(2);
    while got.len() < 7 && Instant::now() < until {
        if let Ok(n) = s.read(&mut buf) {
            got.extend_from_slice(&buf[..n]);
        }
    }
    assert_eq!(got[..3], [0x7E, 0x21, 0x02]);
    drop(s);
    std::thread::sleep(Duration::from_millis(50));
    let err = sim.stop();
    assert!(err.contains("rx 7E 81 02 42 C5"), "{err}");
    assert!(err.contains("read Pr7"), "{err}");
    assert!(err.contains("tx 7E 21 02 42"), "{err}");
    assert!(err.contains("disconnected"), "{err}");
}

#[test]
fn bad_usage_exits_2() {
    for args in [
        &["sim", "hpd"][..],
        &["sim", "hpd", "--pty", "--stdio"],
        &["sim", "hpd", "--listen", "udp:127.0.0.1:0"],
        &["sim", "hpd", "--stdio", "--drop-answers", "1.5"],
        &["sim", "hpd", "--stdio", "--time-limit", "1e30"],
        &["sim", "hpd", "--stdio", "--delay-ms", "-1"],
        &["sim", "hpd", "--stdio", "--baud-code", "11"],
        &["sim", "hpd", "--stdio", "--addr", "40"],
        &["sim", "nope", "--stdio"],
    ] {
        let (code, _, err) = run(BIN, args);
        assert_eq!(code, 2, "{args:?}: {err}");
    }
}
