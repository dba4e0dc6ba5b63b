//! `drivespec fuzz psd4xx`: against every PSD4xx mutant (`drivespec_implementations::psd4xx_mutants`) the
//! fuzzer finds the planted bug within a bounded number of sequences for a fixed seed, with a
//! short minimised replay; a long fixed-seed run against the reference finds nothing; the same
//! seed gives byte-identical replay files, and they replay byte for byte; `exec:` works
//! against the Python example adapter, and an adapter that dies or hangs is a finding while
//! the run goes on.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod support;

use drivespec_conform::cyclic::{LocalPeer, Server};
use drivespec_conform::dut::Dut;
use drivespec_fuzz::{self as fuzz, Action, Device, FindingClass, Options, Replay};
use drivespec_implementations::psd4xx_mutants::{mutants, Kind, Mutant};
use drivespec_implementations::spec;
use drivespec_spec::FamilyId;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use support::cyclic::{
    a_finding_replays, every_mutant_is_found, mutant_options, the_reference_gives_nothing,
};

/// Sequences each mutant gets.
const BOUND: u64 = 120;

fn options() -> Options {
    mutant_options(FamilyId::Psd4xx, BOUND, 3)
}

fn mutant(kind: Kind, name: &str) -> Device {
    let server = Server::new(name, "psd4xx", Box::new(Mutant::new(kind)));
    Device::Peer(Box::new(LocalPeer::new(name, server)))
}

/// Most steps of the shortest replay: every planted bug shows within 5 steps, including the
/// ones that need a run under way (start, wait, the command that shows it) or a saved
/// parameter (write, save, par 96, read back).
const LIMIT: usize = 5;

/// Mutants whose deviation a random run of this bound cannot reach, each caught by the suite
/// instead: swapped limit bits and a missing lower-limit bit show only when the drive stands
/// beyond an end limit (805,200 increments at delivery), which the suite's limit cases reach by
/// moving par 42 or 43 first; the temperature and error bits need injections the generator
/// sends only with harmless values (25 °C) or not at all (a position fault), which
/// `psd4xx/status/temperature` and `psd4xx/status/position-fault` send; a par 44 lost at a
/// power cycle shows only when one sequence writes par 44, saves, power-cycles and reads it
/// back, which this bound does not reach and `psd4xx/pkw/backup/44` does; an adjustment after
/// an aborted run needs par 47 = 1, a run aborted by the release, the release set again
/// without motor voltage and the shaft turned, in that order, which
/// `psd4xx/position/readjust-after-abort` plays.
const BEYOND_REACH: &[&str] = &[
    "limit-bits-swapped",
    "lower-limit-bit-missing",
    "temperature-bit-without-hysteresis",
    "error-bit-reset-by-a-command",
    "window-not-backed-up",
    "readjustment-after-an-aborted-run",
];

#[test]
fn every_psd4xx_mutant_is_found_with_a_short_replay() {
    let all: Vec<(&str, Kind)> = mutants()
        .into_iter()
        .filter(|m| !BEYOND_REACH.contains(&m.name))
        .map(|m| (m.name, m.kind))
        .collect();
    let threads = all.len();
    every_mutant_is_found(&options(), &all, threads, BOUND, |_| LIMIT, mutant);
}

#[test]
fn a_long_run_against_the_reference_finds_nothing() {
    the_reference_gives_nothing(&options(), 1_500, 25, 60, 150);
}

#[test]
fn replay_files_replay_byte_for_byte() {
    let opts = Options {
        iterations: Some(60),
        ..options()
    };
    let kind = Kind::RangeIgnored;
    let (r, text, dir) = a_finding_replays(&opts, "psd", || mutant(kind, "range-ignored"), "pkw");
    // The file names cyclic steps only.
    assert!(
        r.steps
            .iter()
            .all(|s| matches!(s.action, Action::Psd4xx(_))),
        "{text}"
    );
    // A replay of another family is refused, and so are HPD steps in a PSD4xx file.
    let hpd = Options {
        family: FamilyId::Hpd,
        ..opts.clone()
    };
    assert!(fuzz::replay(spec(), &hpd, &r).is_err());
    let bad = text.replace("\"do\": \"pkw\"", "\"do\": \"listen-timeout\"");
    assert!(Replay::from_json(&bad, "x").is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The Python interpreter itself (not a shim), or None.
fn python() -> Option<String> {
    let out = std::process::Command::new("python3")
        .args(["-c", "import sys; print(sys.executable)"])
        .output()
        .ok()?;
    let exe = String::from_utf8(out.stdout).ok()?.trim().to_owned();
    (out.status.success() && !exe.is_empty()).then_some(exe)
}

fn exec(py: &str, script: PathBuf) -> Dut {
    Dut::Exec {
        argv: vec![
            py.to_owned(),
            "-S".into(),
            "-I".into(),
            script.display().to_string(),
        ],
    }
}

#[test]
fn exec_against_the_python_adapter_and_a_dying_one() {
    let Some(py) = python() else {
        eprintln!("no python3: skipped");
        return;
    };
    let started = Instant::now();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    // The example adapter: the run works; what it leaves out are mismatches, nothing crashes.
    let opts = Options {
        dut: exec(&py, root.join("../../tests/psd4xx_adapter.py")),
        iterations: Some(20),
        minimize_runs: 20,
        max_findings: 5,
        ..options()
    };
    let s = fuzz::run(spec(), &opts, &mut std::io::sink()).unwrap();
    assert_eq!(s.stats.sequences, 20);
    assert!(s
        .stats
        .findings
        .iter()
        .all(|f| f.class == FindingClass::Mismatch));
    for f in s
        .findings
        .iter()
        .filter(|f| f.replay.finding.as_ref().unwrap().reproduced)
    {
        let again = fuzz::replay(spec(), &opts, &f.replay).unwrap();
        assert!(again.same_finding, "{}", f.replay.to_json());
        assert!(again.same_as_recorded, "{}", f.replay.to_json());
    }
    // The dying adapter: the crash and the hang are findings with one-step replays, and the
    // run goes on to the end after each restart.
    let opts = Options {
        dut: exec(&py, root.join("tests/support/dying_psd4xx_adapter.py")),
        iterations: Some(40),
        minimize_runs: 10,
        max_findings: 20,
        ..options()
    };
    let s = fuzz::run(spec(), &opts, &mut std::io::sink()).unwrap();
    for f in &s.stats.findings {
        println!(
            "{} {} in {} step(s), first in sequence {}, seen {}",
            f.id, f.signature, f.steps, f.first_sequence, f.occurrences
        );
    }
    assert_eq!(s.stats.sequences, 40, "the run went on to the end");
    assert!(s.stats.restarts >= 1, "{}", s.stats.restarts);
    let of = |class: FindingClass| {
        s.findings
            .iter()
            .find(|f| {
                f.replay
                    .finding
                    .as_ref()
                    .is_some_and(|i| i.class == class && i.reproduced)
            })
            .unwrap_or_else(|| panic!("no reproduced {class:?} finding: {:#?}", s.stats.findings))
    };
    let crash = of(FindingClass::Crash);
    assert_eq!(crash.replay.steps.len(), 1, "{}", crash.replay.to_json());
    assert!(
        crash.replay.to_json().contains("\"do\": \"record-write\""),
        "{}",
        crash.replay.to_json()
    );
    assert!(
        crash.failure.message.contains("boom") || crash.failure.got.contains("boom"),
        "{:?}",
        crash.failure
    );
    let hang = of(FindingClass::Hang);
    assert_eq!(hang.replay.steps.len(), 1, "{}", hang.replay.to_json());
    assert!(hang.replay.to_json().contains("\"do\": \"advance\""));
    for f in [crash, hang] {
        let again = fuzz::replay(spec(), &opts, &f.replay).unwrap();
        assert!(again.same_finding, "{}: {:?}", f.id, again.fault);
        assert_eq!(again.exit_code(), 1);
    }
    assert!(
        started.elapsed() < Duration::from_secs(120),
        "{:?}",
        started.elapsed()
    );
}
