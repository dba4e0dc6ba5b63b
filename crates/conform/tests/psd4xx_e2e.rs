//! PSD4xx end to end over the cyclic-exchange protocol: a real TCP socket on 127.0.0.1
//! serving the reference drive (the same `Server` as `sim`), `exec:` with the Python example
//! adapter `tests/psd4xx_adapter.py` and its expectations file, and the HTML report's plot.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_conform::dut::Dut;
use drivespec_conform::report::Status;
use drivespec_conform::{run, Options, Progress};
use drivespec_spec::{FamilyId, Spec};
use std::io::BufReader;
use std::net::TcpListener;
use std::path::PathBuf;

fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn options(dut: Dut, cases: &[&str]) -> Options {
    Options {
        families: vec![FamilyId::Psd4xx],
        dut,
        case: cases.iter().map(|s| (*s).to_owned()).collect(),
        progress: Progress::Quiet,
        no_reports: true,
        ..Options::default()
    }
}

const CASES: &[&str] = &[
    "psd4xx/pkw/read/1",
    "psd4xx/pkw/read/44",
    "psd4xx/pkw/read/45",
    "psd4xx/pkw/write/1",
    "psd4xx/pkw/write/44",
    "psd4xx/pkw/write/45",
    "psd4xx/pkw/unknown",
    "psd4xx/pkw/no-command",
    "psd4xx/record/read/44",
    "psd4xx/record/read/45",
    "psd4xx/record/write/44",
    "psd4xx/record/write/45",
    "psd4xx/position/loop/up",
    "psd4xx/status/toggle",
];

#[test]
fn tcp_against_the_reference_server_passes() {
    let spec = Spec::builtin().unwrap();
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let server_spec = Spec::builtin().unwrap();
    let t = std::thread::spawn(move || {
        let reference = drivespec_sim::reference::psd4xx(&server_spec, None).unwrap();
        let mut server = reference.server(FamilyId::Psd4xx);
        let (stream, _) = listener.accept().unwrap();
        stream.set_nodelay(true).unwrap();
        let reader = BufReader::new(stream.try_clone().unwrap());
        let _ = server.serve(reader, stream);
    });
    let opts = options(
        Dut::Tcp {
            addr: addr.to_string(),
        },
        &[
            "psd4xx/pkw/write/44",
            "psd4xx/pkw/held-while-running",
            "psd4xx/record/write/45",
            "psd4xx/sequence/seq-obstruction-same-target",
            "psd4xx/par96/minus-1",
            "psd4xx/position/new-target",
        ],
    );
    let summary = run(&spec, &opts, &mut std::io::sink()).unwrap();
    let r = &summary.report;
    let bad: Vec<String> = r
        .cases
        .iter()
        .filter(|c| !matches!(c.status, Status::Pass | Status::Acceptable))
        .map(|c| format!("{} {:?}", c.id, c.failure.as_ref().map(|f| &f.message)))
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
    assert!(r.summary.passed >= 10, "{:?}", r.summary);
    assert_eq!(summary.exit_code(), 0);
    drop(summary);
    t.join().unwrap();
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
    let spec = Spec::builtin().unwrap();
    let dir = std::env::temp_dir().join(format!("drivespec-psd4xx-e2e-{}", std::process::id()));
    let mut opts = options(
        Dut::Exec {
            argv: vec![
                py,
                root.join("tests/psd4xx_adapter.py").display().to_string(),
            ],
        },
        CASES,
    );
    opts.expect = Some(root.join("tests/psd4xx_adapter_expect.toml"));
    opts.no_reports = false;
    opts.report_dir = dir.clone();
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
                c.failure
                    .as_ref()
                    .map(|f| (&f.message, &f.expected, &f.got))
            )
        })
        .collect();
    assert!(bad.is_empty(), "{bad:#?}");
    assert_eq!(r.summary.expected_failures, 2, "{:?}", r.summary);
    assert!(r.summary.passed >= 20, "{:?}", r.summary);
    assert!(r.stale_expectations.is_empty());
    assert_eq!(summary.exit_code(), 0);
    // The positioning case gets its plot in the HTML report.
    let html = std::fs::read_to_string(dir.join("conform.html")).unwrap();
    assert!(
        html.matches("<svg").count() >= 2,
        "no plots in the HTML report"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_wrong_protocol_peer_is_a_setup_error() {
    let spec = Spec::builtin().unwrap();
    let opts = options(
        Dut::Exec {
            argv: vec![
                "sh".into(),
                "-c".into(),
                "read x; echo 'HELLO nonsense'".into(),
            ],
        },
        &["psd4xx/pkw/no-command"],
    );
    assert!(run(&spec, &opts, &mut std::io::sink()).is_err());
}

#[test]
fn a_dying_adapter_fails_cases_with_evidence_and_the_run_goes_on() {
    let spec = Spec::builtin().unwrap();
    let opts = options(
        Dut::Exec {
            argv: vec![
                "sh".into(),
                "-c".into(),
                "read l; echo 'HELLO drivespec-cyclic 1 dying'; read l; echo OK; read l; exit 3"
                    .into(),
            ],
        },
        &[
            "psd4xx/pkw/read/44",
            "psd4xx/pkw/read/45",
            "psd4xx/pkw/no-command",
        ],
    );
    let summary = run(&spec, &opts, &mut std::io::sink()).unwrap();
    let r = &summary.report;
    assert_eq!(r.summary.failed, 3, "{:?}", r.summary);
    for c in &r.cases {
        let f = c.failure.as_ref().unwrap();
        assert!(
            !f.message.is_empty() && !f.got.is_empty(),
            "{}: {f:?}",
            c.id
        );
    }
    assert_eq!(summary.exit_code(), 1);
}
