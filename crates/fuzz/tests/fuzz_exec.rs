//! The fuzzer against an `exec:` device that dies or hangs on particular inputs
//! (`support/faulty_relay.py`: the reference drive relayed from a TCP port, exiting on a
//! broadcast and going silent for good on a PLC read). The crash and the hang are findings
//! with short replays that reproduce, and the run goes on after each restart.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod support;

use drivespec_conform::dut::Dut;
use drivespec_conform::Progress;
use drivespec_fuzz::{self as fuzz, FindingClass, Options};
use drivespec_implementations::spec;
use std::path::PathBuf;
use std::time::Duration;

/// The Python interpreter itself (not a shim), or None.
fn python() -> Option<String> {
    let out = std::process::Command::new("python3")
        .args(["-c", "import sys; print(sys.executable)"])
        .output()
        .ok()?;
    let exe = String::from_utf8(out.stdout).ok()?.trim().to_owned();
    (out.status.success() && !exe.is_empty()).then_some(exe)
}

#[test]
fn a_dying_and_a_hanging_device_are_findings_and_the_run_goes_on() {
    let Some(py) = python() else {
        eprintln!("no python3: skipped");
        return;
    };
    let port = support::reference_server::start(Duration::from_secs(600));
    let relay = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/support/faulty_relay.py");
    let out = std::env::temp_dir().join(format!("drivespec-fuzz-exec-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let mut opts = Options {
        dut: Dut::Exec {
            argv: vec![
                py,
                "-S".into(),
                "-I".into(),
                relay.display().to_string(),
                port.to_string(),
            ],
        },
        iterations: Some(10),
        out_dir: out.clone(),
        progress: Progress::Quiet,
        max_findings: 4,
        minimize_runs: 20,
        ..Options::default()
    };
    // Generous: a loaded machine must not turn a slow answer into a finding.
    opts.settings.slack_us = Some(100_000);
    let s = fuzz::run(spec(), &opts, &mut std::io::sink()).unwrap();
    let st = &s.stats;
    for f in &st.findings {
        println!(
            "{} {} in {} step(s) (from {}), first in sequence {}, seen {}",
            f.id, f.signature, f.steps, f.original_steps, f.first_sequence, f.occurrences
        );
    }
    assert_eq!(st.sequences, 10, "the run went on to the end");
    assert!(st.restarts >= 2, "{}", st.restarts);
    assert_eq!(s.exit_code(), 1);
    let of = |class: FindingClass| {
        s.findings
            .iter()
            .find(|f| {
                f.replay
                    .finding
                    .as_ref()
                    .is_some_and(|i| i.class == class && i.reproduced)
            })
            .unwrap_or_else(|| panic!("no reproduced {class:?} finding: {:#?}", st.findings))
    };
    // The crash: one message with CMD 7 in it, the exit status and stderr as evidence.
    let crash = of(FindingClass::Crash);
    assert_eq!(crash.replay.steps.len(), 1, "{}", crash.replay.to_json());
    let bytes = crash.replay.steps[0].action.bytes().unwrap();
    assert!(
        bytes.windows(2).any(|w| w[0] == 0x7E && w[1] >> 5 == 7),
        "{bytes:02X?}"
    );
    assert!(
        crash.failure.message.contains("boom") || crash.failure.got.contains("boom"),
        "{:?}",
        crash.failure
    );
    // The hang: a message with CMD 2 in it, and silence to the liveness probe as well.
    let hang = of(FindingClass::Hang);
    assert!(hang.replay.steps.len() <= 2, "{}", hang.replay.to_json());
    let trigger = hang
        .replay
        .steps
        .iter()
        .filter_map(|s| s.action.bytes())
        .any(|b| b.windows(2).any(|w| w[0] == 0x7E && w[1] >> 5 == 2));
    assert!(trigger, "{}", hang.replay.to_json());
    assert!(hang.run.evidence.iter().any(|e| e
        .note
        .as_deref()
        .is_some_and(|n| n.contains("liveness probe"))));
    // Each replays to the same finding after a restart.
    for f in [crash, hang] {
        let again = fuzz::replay(spec(), &opts, &f.replay).unwrap();
        assert!(again.same_finding, "{}: {:?}", f.id, again.fault);
        assert_eq!(again.exit_code(), 1);
    }
    assert!(out.join("fuzz.json").is_file());
    std::fs::remove_dir_all(&out).unwrap();
}
