//! PSx3xx end to end over the cyclic-exchange protocol: a real TCP socket on 127.0.0.1
//! serving the reference drive (`drivespec_sim::reference`, the same `Server` as `sim`) with the
//! ISDU requests and environment injections on the wire, and the HTML report's plots.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_conform::dut::Dut;
use drivespec_conform::report::Status;
use drivespec_conform::suite::Settings;
use drivespec_conform::{run, Options, Progress};
use drivespec_spec::{FamilyId, Spec};
use std::io::BufReader;
use std::net::TcpListener;

/// Serves the reference drive of `model` on a fresh port; returns `tcp:` address.
fn serve(model: &'static str) -> String {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    std::thread::spawn(move || {
        let spec = Spec::builtin().unwrap();
        let reference = drivespec_sim::reference::psx3xx(&spec, Some(model), None).unwrap();
        let mut server = reference.server(FamilyId::Psx3xx);
        let (stream, _) = listener.accept().unwrap();
        stream.set_nodelay(true).unwrap();
        let reader = BufReader::new(stream.try_clone().unwrap());
        let _ = server.serve(reader, stream);
    });
    addr.to_string()
}

#[test]
fn tcp_against_the_reference_server_passes_and_plots() {
    let spec = Spec::builtin().unwrap();
    let addr = serve("PSE312-8");
    let dir = std::env::temp_dir().join(format!("drivespec-psx3xx-e2e-{}", std::process::id()));
    let opts = Options {
        families: vec![FamilyId::Psx3xx],
        dut: Dut::Tcp { addr },
        case: [
            "psx3xx/isdu/read/0.*",
            "psx3xx/isdu/unknown-*",
            "psx3xx/isdu/write/135/*",
            "psx3xx/guard/111/*",
            "psx3xx/command/193/save",
            "psx3xx/format/*",
            "psx3xx/timestamp/not-while-active",
            "psx3xx/status/jog-keys",
            "psx3xx/timeout/*",
            "psx3xx/position/loop-down",
        ]
        .map(str::to_owned)
        .to_vec(),
        progress: Progress::Quiet,
        report_dir: dir.clone(),
        ..Options::default()
    };
    let summary = run(&spec, &opts, &mut std::io::sink()).unwrap();
    let bad: Vec<String> = summary
        .report
        .cases
        .iter()
        .filter(|c| !matches!(c.status, Status::Pass | Status::Acceptable))
        .map(|c| format!("{}: {:?} {:?}", c.id, c.status, c.failure))
        .collect();
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let n = summary.report.cases.len();
    assert!(n > 40, "only {n} cases ran");
    assert!(
        summary.report.run.transport.starts_with("tcp"),
        "{}",
        summary.report.run.transport
    );
    let html = std::fs::read_to_string(dir.join("conform.html")).unwrap();
    assert!(
        html.matches("<svg").count() >= 5,
        "positioning cases carry plots"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_model_without_a_documented_code_runs_over_tcp() {
    // PSX-ERRATUM-016: PSE3210-14 has no documented ISDU 79 code; both ends use the same one.
    let spec = Spec::builtin().unwrap();
    let addr = serve("PSE3210-14");
    let opts = Options {
        families: vec![FamilyId::Psx3xx],
        dut: Dut::Tcp { addr },
        settings: Settings {
            model: Some("PSE3210-14".to_owned()),
            ..Settings::default()
        },
        case: vec![
            "psx3xx/format/2/*".to_owned(),
            "psx3xx/isdu/read/79".to_owned(),
        ],
        progress: Progress::Quiet,
        no_reports: true,
        ..Options::default()
    };
    let summary = run(&spec, &opts, &mut std::io::sink()).unwrap();
    assert!(summary.report.cases.len() >= 5);
    for c in &summary.report.cases {
        assert!(
            matches!(c.status, Status::Pass | Status::Acceptable),
            "{}: {:?}",
            c.id,
            c.failure
        );
    }
}

#[test]
fn a_device_that_answers_garbage_fails_its_cases_and_the_run_goes_on() {
    // Greets and resets correctly, then answers every other request with a line that is no
    // reply: each case fails with the evidence, none hangs.
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    std::thread::spawn(move || {
        use std::io::{BufRead, Write};
        // The runner reconnects after a bad reply: every connection gets the same treatment.
        for stream in listener.incoming() {
            let Ok(stream) = stream else { break };
            let mut out = stream.try_clone().unwrap();
            for line in BufReader::new(stream).lines() {
                let Ok(line) = line else { break };
                let reply = if line.starts_with("HELLO") {
                    "HELLO drivespec-cyclic 1 broken".to_owned()
                } else if line == "RESET" {
                    "OK".to_owned()
                } else {
                    "WHAT 42".to_owned()
                };
                if writeln!(out, "{reply}").is_err() {
                    break;
                }
            }
        }
    });
    let spec = Spec::builtin().unwrap();
    let opts = Options {
        families: vec![FamilyId::Psx3xx],
        dut: Dut::Tcp {
            addr: addr.to_string(),
        },
        case: vec![
            "psx3xx/isdu/read/116".to_owned(),
            "psx3xx/position/loop-up".to_owned(),
        ],
        progress: Progress::Quiet,
        no_reports: true,
        ..Options::default()
    };
    let summary = run(&spec, &opts, &mut std::io::sink()).unwrap();
    assert_eq!(summary.report.cases.len(), 2);
    for c in &summary.report.cases {
        assert_eq!(c.status, Status::Fail, "{}", c.id);
        let f = c.failure.as_ref().unwrap();
        assert!(f.got.contains("WHAT"), "{}: {f:?}", c.id);
        assert!(!f.requirements.is_empty());
    }
    assert_eq!(summary.report.summary.exit_code, 1);
}
