//! `drivespec fuzz psd4xx`: against every PSD4xx mutant (`support::psd4xx_mutants`) the
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
use drivespec_conform::suite::Settings;
use drivespec_conform::Progress;
use drivespec_fuzz::{self as fuzz, Action, Device, FindingClass, Options, Replay};
use drivespec_spec::FamilyId;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use support::mutants::spec;
use support::psd4xx_mutants::{mutants, Kind, Mutant};

/// Sequences each mutant gets.
const BOUND: u64 = 120;

fn options() -> Options {
    Options {
        family: FamilyId::Psd4xx,
        iterations: Some(BOUND),
        minimize_runs: 100,
        max_findings: 3,
        no_reports: true,
        progress: Progress::Quiet,
        settings: Settings {
            seed: 1,
            ..Settings::default()
        },
        ..Options::default()
    }
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
/// back, which this bound does not reach and `psd4xx/pkw/backup/44` does.
const BEYOND_REACH: &[&str] = &[
    "limit-bits-swapped",
    "lower-limit-bit-missing",
    "temperature-bit-without-hysteresis",
    "error-bit-reset-by-a-command",
    "window-not-backed-up",
];

#[test]
fn every_psd4xx_mutant_is_found_with_a_short_replay() {
    let opts = options();
    let all: Vec<_> = mutants()
        .into_iter()
        .filter(|m| !BEYOND_REACH.contains(&m.name))
        .collect();
    let results: Vec<(String, Kind, fuzz::Summary)> = std::thread::scope(|s| {
        let handles: Vec<_> = all
            .iter()
            .map(|m| {
                let opts = &opts;
                s.spawn(move || {
                    let summary = fuzz::run_on_device(
                        spec(),
                        opts,
                        mutant(m.kind, m.name),
                        &mut std::io::sink(),
                    )
                    .unwrap();
                    (m.name.to_owned(), m.kind, summary)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let mut problems = Vec::new();
    for (name, kind, s) in &results {
        let first = s.stats.findings.iter().map(|f| f.first_sequence).min();
        let shortest = s
            .stats
            .findings
            .iter()
            .filter(|f| f.reproduced)
            .map(|f| f.steps)
            .min();
        println!(
            "{name:<40} found after {:>3} sequence(s); shortest replay {} step(s); {} finding(s): {}",
            first.map_or("-".to_owned(), |n| n.to_string()),
            shortest.map_or("-".to_owned(), |n| n.to_string()),
            s.findings.len(),
            s.stats
                .findings
                .iter()
                .map(|f| format!("{} ({})", f.signature, f.steps))
                .collect::<Vec<_>>()
                .join(", ")
        );
        match shortest {
            None => problems.push(format!("{name}: not found in {BOUND} sequences")),
            Some(n) if n > LIMIT => {
                problems.push(format!("{name}: shortest replay {n} steps > {LIMIT}"))
            }
            Some(_) => {}
        }
        if s.exit_code() != 1 {
            problems.push(format!("{name}: exit code {}", s.exit_code()));
        }
        for f in &s.findings {
            let info = f.replay.finding.as_ref().unwrap();
            assert_ne!(
                info.class,
                FindingClass::Crash,
                "{name}: nothing fails on sim"
            );
            assert!(!info.requirements.is_empty(), "{name}: {}", f.id);
            // Every finding replays: the same exchanges and the same verdict again.
            let again =
                fuzz::replay_on_device(spec(), &opts, &f.replay, mutant(*kind, name)).unwrap();
            if info.reproduced && !(again.same_as_recorded && again.same_finding) {
                problems.push(format!("{name}: {} does not replay exactly", f.id));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn a_long_run_against_the_reference_finds_nothing() {
    let mut opts = Options {
        iterations: Some(1_500),
        ..options()
    };
    opts.settings.seed = 7;
    let started = Instant::now();
    let s = fuzz::run(spec(), &opts, &mut std::io::sink()).unwrap();
    println!(
        "{} sequences, {} inputs in {:?}; {} requirement(s) touched, classes: {:?}",
        s.stats.sequences,
        s.stats.inputs,
        started.elapsed(),
        s.stats.requirements_touched.len(),
        s.stats.inputs_by_class.keys().collect::<Vec<_>>()
    );
    assert_eq!(s.stats.sequences, 1_500);
    assert!(s.findings.is_empty(), "{:#?}", s.stats.findings);
    assert_eq!(s.exit_code(), 0);
    assert!(
        s.stats.inputs_by_class.len() >= 25,
        "{:?}",
        s.stats.inputs_by_class
    );
    assert!(s.stats.requirements_touched.len() >= 60);
    // The same seed sends the same sequences and gives the same statistics.
    let again = fuzz::run(
        spec(),
        &Options {
            iterations: Some(150),
            ..opts.clone()
        },
        &mut std::io::sink(),
    )
    .unwrap();
    let twice = fuzz::run(
        spec(),
        &Options {
            iterations: Some(150),
            ..opts
        },
        &mut std::io::sink(),
    )
    .unwrap();
    assert_eq!(again.stats.inputs_by_class, twice.stats.inputs_by_class);
    assert_eq!(
        again.stats.answers_by_verdict,
        twice.stats.answers_by_verdict
    );
}

#[test]
fn replay_files_replay_byte_for_byte() {
    let opts = Options {
        iterations: Some(60),
        ..options()
    };
    let dir = std::env::temp_dir().join(format!("drivespec-fuzz-psd-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let kind = Kind::RangeIgnored;
    let s = fuzz::run_on_device(
        spec(),
        &Options {
            out_dir: dir.clone(),
            no_reports: false,
            ..opts.clone()
        },
        mutant(kind, "range-ignored"),
        &mut std::io::sink(),
    )
    .unwrap();
    // A finding reproduced from a fresh device replays on a fresh one.
    let f = s
        .findings
        .iter()
        .find(|f| f.replay.finding.as_ref().is_some_and(|i| i.reproduced))
        .expect("a reproduced finding");
    let file = f.file.clone().unwrap();
    let text = std::fs::read_to_string(&file).unwrap();
    // The same seed finds the same findings with byte-identical replay files.
    let again = fuzz::run_on_device(
        spec(),
        &opts,
        mutant(kind, "range-ignored"),
        &mut std::io::sink(),
    )
    .unwrap();
    assert_eq!(again.findings.len(), s.findings.len());
    for (a, b) in again.findings.iter().zip(&s.findings) {
        assert_eq!(a.replay.to_json(), b.replay.to_json());
    }
    let r = Replay::load(&file).unwrap();
    // The file round-trips exactly, and names cyclic steps.
    assert_eq!(r.to_json(), text);
    assert!(
        r.steps
            .iter()
            .all(|s| matches!(s.action, Action::Psd4xx(_))),
        "{text}"
    );
    assert!(text.contains("\"do\": \"pkw\""), "{text}");
    // Replayed twice: the same exchanges as recorded, byte for byte, both times.
    for _ in 0..2 {
        let again =
            fuzz::replay_on_device(spec(), &opts, &r, mutant(kind, "range-ignored")).unwrap();
        assert!(again.same_as_recorded, "{text}\n{:#?}", again.exchanges);
        assert!(again.same_finding);
        assert_eq!(again.exit_code(), 1);
        assert_eq!(again.exchanges, r.exchanges);
    }
    // Against the reference it passes.
    let fixed = fuzz::replay(spec(), &opts, &r).unwrap();
    assert_eq!(fixed.exit_code(), 0);
    assert!(!fixed.same_finding);
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
