//! End to end through real transports: a TCP socket on 127.0.0.1 serving the reference drive,
//! misbehaving peers (a closing socket, a dying and a hanging subprocess), and `exec:` with
//! the Python example adapter `tests/hpd_adapter.py` and its expectations file.
//! Every loop is bounded and every network address is loopback.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_conform::dut::Dut;
use drivespec_conform::report::Status;
use drivespec_conform::{run, Options, Progress};
use drivespec_hpd::model::{Drive, DriveConfig, Output};
use drivespec_spec::Spec;
use std::io::{Read, Write};
use std::net::TcpListener;
use std::path::PathBuf;
use std::time::{Duration, Instant};

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn options(dut: Dut, cases: &[&str]) -> Options {
    Options {
        dut,
        case: cases.iter().map(|s| (*s).to_owned()).collect(),
        progress: Progress::Quiet,
        no_reports: true,
        ..Options::default()
    }
}

/// Serves `drive` on `listener` in wall-clock time, for `limit` at most. The drive is built
/// before the thread starts: a server still loading the spec would leave the first requests
/// unanswered (the kernel accepts the connection meanwhile).
fn serve_reference(listener: TcpListener, mut drive: Drive, limit: Duration) {
    let start = Instant::now();
    listener.set_nonblocking(true).unwrap();
    let mut conn = None;
    while start.elapsed() < limit {
        if conn.is_none() {
            match listener.accept() {
                Ok((s, _)) => {
                    s.set_nonblocking(false).unwrap();
                    s.set_read_timeout(Some(Duration::from_micros(500)))
                        .unwrap();
                    conn = Some(s);
                }
                Err(_) => std::thread::sleep(Duration::from_millis(1)),
            }
            continue;
        }
        let Some(s) = conn.as_mut() else { continue };
        let now = start.elapsed().as_micros() as u64;
        let mut buf = [0u8; 256];
        let mut closed = false;
        match s.read(&mut buf) {
            Ok(0) => closed = true,
            Ok(n) => drive.handle_rx(now, &buf[..n]),
            Err(_) => {}
        }
        drive.advance(start.elapsed().as_micros() as u64);
        while let Some(o) = drive.poll_output() {
            if let Output::Transmit { bytes, .. } = o {
                if s.write_all(&bytes).is_err() {
                    closed = true;
                }
            }
        }
        if closed {
            conn = None;
        }
    }
}

const TCP_CASES: &[&str] = &[
    "hpd/frame/read-parameter",
    "hpd/frame/write-parameter",
    "hpd/frame/bit-change",
    "hpd/frame/read-plc",
    "hpd/frame/checksum-bad/read-parameter",
    "hpd/frame/foreign-address/7",
    "hpd/frame/timeout-split",
    "hpd/frame/split-within-timeout",
    "hpd/param/Pr33/*",
    "hpd/vector/serial-case-1",
];

#[test]
fn tcp_against_the_reference_drive_passes() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let spec = Spec::builtin().unwrap();
    let drive = Drive::new(&spec, DriveConfig::commissioned(0)).unwrap();
    let server =
        std::thread::spawn(move || serve_reference(listener, drive, Duration::from_secs(60)));
    let opts = options(
        Dut::Tcp {
            addr: addr.to_string(),
        },
        TCP_CASES,
    );
    let summary = run(&spec, &opts, &mut std::io::sink()).unwrap();
    let r = &summary.report;
    let failed: Vec<String> = r
        .cases
        .iter()
        .filter(|c| !matches!(c.status, Status::Pass | Status::Acceptable))
        .map(|c| format!("{}: {:?}", c.id, c.failure.as_ref().map(|f| &f.message)))
        .collect();
    assert!(failed.is_empty(), "{failed:#?}");
    assert!(r.summary.passed >= 12, "{:?}", r.summary);
    assert_eq!(summary.exit_code(), 0);
    drop(server);
}

#[test]
fn a_peer_that_closes_fails_cases_with_evidence_and_the_run_goes_on() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    // Accepts up to 10 connections; answers each request with garbage and hangs up.
    let server = std::thread::spawn(move || {
        listener.set_nonblocking(true).unwrap();
        let start = Instant::now();
        let mut served = 0;
        while served < 10 && start.elapsed() < Duration::from_secs(20) {
            match listener.accept() {
                Ok((mut s, _)) => {
                    served += 1;
                    s.set_nonblocking(false).unwrap();
                    s.set_read_timeout(Some(Duration::from_secs(2))).unwrap();
                    let mut buf = [0u8; 64];
                    let _ = s.read(&mut buf);
                    let _ = s.write_all(&[0x7E, 0x20, 0x02]);
                }
                Err(_) => std::thread::sleep(Duration::from_millis(2)),
            }
        }
    });
    let spec = Spec::builtin().unwrap();
    let opts = options(
        Dut::Tcp {
            addr: addr.to_string(),
        },
        &[
            "hpd/frame/read-parameter",
            "hpd/frame/read-lun-1",
            "hpd/frame/read-lun-2",
        ],
    );
    let summary = run(&spec, &opts, &mut std::io::sink()).unwrap();
    let r = &summary.report;
    assert_eq!(r.summary.total, 3);
    assert_eq!(r.summary.failed, 3, "{:#?}", r.summary);
    for c in &r.cases {
        let f = c.failure.as_ref().unwrap();
        assert!(!c.evidence.is_empty());
        assert!(c.replay.as_ref().unwrap().contains(&c.id));
        assert!(
            f.message.contains("7E 20 02")
                || f.message.contains("closed")
                || f.message.contains("transport"),
            "{}",
            f.message
        );
    }
    assert_eq!(summary.exit_code(), 1);
    server.join().unwrap();
}

fn python() -> Option<String> {
    ["python3", "python"]
        .into_iter()
        .map(str::to_owned)
        .find(|p| {
            std::process::Command::new(p)
                .arg("--version")
                .output()
                .is_ok_and(|o| o.status.success())
        })
}

#[test]
fn exec_python_adapter_passes_with_its_expectations() {
    let Some(py) = python() else {
        eprintln!("no python3: skipped");
        return;
    };
    let root = workspace();
    let adapter = root.join("tests/hpd_adapter.py");
    let spec = Spec::builtin().unwrap();
    let mut opts = options(
        Dut::Exec {
            argv: vec![py, adapter.display().to_string()],
        },
        &[
            "hpd/frame",
            "hpd/param/Pr33/*",
            "hpd/param/Pr80/*",
            "hpd/param/Pr31/*",
        ],
    );
    opts.expect = Some(root.join("tests/hpd_adapter_expect.toml"));
    let summary = run(&spec, &opts, &mut std::io::sink()).unwrap();
    let r = &summary.report;
    let bad: Vec<String> = r
        .cases
        .iter()
        .filter(|c| matches!(c.status, Status::Fail | Status::Fixed))
        .map(|c| {
            format!(
                "{} {}: {:?}",
                c.status.as_str(),
                c.id,
                c.failure.as_ref().map(|f| &f.message)
            )
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
    assert_eq!(r.summary.expected_failures, 3, "{:?}", r.summary);
    assert!(r.summary.passed > 60, "{:?}", r.summary);
    assert!(r.stale_expectations.is_empty());
    assert_eq!(summary.exit_code(), 0);
}

#[test]
fn a_dying_subprocess_is_restarted_and_each_case_fails_with_evidence() {
    let Some(py) = python() else { return };
    let spec = Spec::builtin().unwrap();
    let argv = vec![
        py,
        "-c".to_owned(),
        "import sys; sys.stdin.buffer.read(2); sys.stderr.write('boom'); sys.exit(3)".to_owned(),
    ];
    let opts = options(
        Dut::Exec { argv },
        &["hpd/frame/read-parameter", "hpd/frame/read-lun-1"],
    );
    let summary = run(&spec, &opts, &mut std::io::sink()).unwrap();
    let r = &summary.report;
    assert_eq!(r.summary.failed, 2, "{:?}", r.summary);
    let text = serde_json::to_string(&r.cases).unwrap();
    assert!(text.contains("exit") && text.contains("boom"), "{text}");
}

#[test]
fn a_hanging_subprocess_times_out_without_hanging_the_run() {
    let Some(py) = python() else { return };
    let spec = Spec::builtin().unwrap();
    let argv = vec![
        py,
        "-c".to_owned(),
        "import time; time.sleep(3600)".to_owned(),
    ];
    let opts = options(
        Dut::Exec { argv },
        &["hpd/frame/read-parameter", "hpd/frame/read-lun-1"],
    );
    let started = Instant::now();
    let summary = run(&spec, &opts, &mut std::io::sink()).unwrap();
    // The run ended long before the process would have answered.
    assert!(
        started.elapsed() < Duration::from_secs(600),
        "{:?}",
        started.elapsed()
    );
    assert_eq!(summary.report.summary.failed, 2);
    let f = summary.report.cases[0].failure.as_ref().unwrap();
    assert!(f.got.contains("silence"), "{}", f.got);
}

#[test]
fn an_unreachable_dut_is_a_setup_error() {
    let spec = Spec::builtin().unwrap();
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    drop(listener);
    let opts = options(
        Dut::Tcp {
            addr: addr.to_string(),
        },
        &["hpd/frame/read-parameter"],
    );
    assert!(run(&spec, &opts, &mut std::io::sink()).is_err());
    let opts = options(
        Dut::Exec {
            argv: vec!["/nonexistent/adapter".into()],
        },
        &["hpd/frame"],
    );
    assert!(run(&spec, &opts, &mut std::io::sink()).is_err());
}
