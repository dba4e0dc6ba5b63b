//! `drivespec fuzz psx3xx`: against every PSx3xx mutant (`support::psx3xx_mutants`) the
//! fuzzer finds the planted bug within a bounded number of sequences for a fixed seed, with a
//! short minimised replay; a fixed-seed run against the reference finds nothing; the same seed
//! gives byte-identical replay files, and they replay byte for byte; replay files of another
//! family are refused.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod support;

use drivespec_conform::cyclic::{LocalPeer, Server};
use drivespec_conform::suite::Settings;
use drivespec_conform::Progress;
use drivespec_fuzz::{self as fuzz, Action, Device, FindingClass, Options, Replay};
use drivespec_psx3xx::step::Step as PsxStep;
use drivespec_spec::FamilyId;
use std::time::Instant;
use support::mutants::spec;
use support::psx3xx_mutants::{mutants, Kind, Mutant};

/// Sequences each mutant gets.
const BOUND: u64 = 150;

fn options() -> Options {
    Options {
        family: FamilyId::Psx3xx,
        iterations: Some(BOUND),
        minimize_runs: 100,
        max_findings: 2,
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
    let server = Server::new(name, "psx3xx", Box::new(Mutant::new(kind)));
    Device::Peer(Box::new(LocalPeer::new(name, server)))
}

/// Most steps of the shortest replay: every planted bug shows within 5 steps, including the
/// ones that need a run under way (start, wait, the change that shows it), a format switch
/// (ISDU 116 write, then a cycle or read in the old format) or a save and a power cycle.
const LIMIT: usize = 5;

/// The single-message bugs (one ISDU request answered wrongly): their replay is that one
/// request.
const SINGLE: [Kind; 6] = [
    Kind::WrongErrorType,
    Kind::ReadOnlyWritable,
    Kind::RangeIgnored,
    Kind::LengthErrorsSwapped,
    Kind::CommandValueAccepted,
    Kind::TimeoutIgnored,
];

fn limit(kind: Kind) -> usize {
    if SINGLE.contains(&kind) {
        1
    } else {
        LIMIT
    }
}

/// Mutants whose deviation a random run of this bound cannot reach, each caught by the suite
/// instead: swapped range-limit bits show only when a run reaches an end of the range, which
/// `status/upper-limit` and `status/lower-limit` reach by moving the limits first.
const BEYOND_REACH: &[&str] = &["status bits 14 and 15 (range limits) swapped"];

#[test]
fn every_psx3xx_mutant_is_found_with_a_short_replay() {
    let opts = options();
    let all: Vec<_> = mutants()
        .into_iter()
        .filter(|m| !BEYOND_REACH.contains(&m.name))
        .collect();
    let results: Vec<(String, Kind, fuzz::Summary)> = std::thread::scope(|s| {
        let handles: Vec<_> = all
            .chunks(all.len().div_ceil(2))
            .map(|chunk| {
                let opts = &opts;
                s.spawn(move || {
                    chunk
                        .iter()
                        .map(|m| {
                            let summary = fuzz::run_on_device(
                                spec(),
                                opts,
                                mutant(m.kind, m.name),
                                &mut std::io::sink(),
                            )
                            .unwrap();
                            (m.name.to_owned(), m.kind, summary)
                        })
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap())
            .collect()
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
            "{name:<45} found after {:>3} sequence(s); shortest replay {} step(s); {} finding(s): {}",
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
            Some(n) if n > limit(*kind) => problems.push(format!(
                "{name}: shortest replay {n} steps > {}",
                limit(*kind)
            )),
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
fn a_fixed_seed_run_against_the_reference_finds_nothing() {
    let mut opts = Options {
        iterations: Some(400),
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
    assert_eq!(s.stats.sequences, 400);
    assert!(s.findings.is_empty(), "{:#?}", s.stats.findings);
    assert_eq!(s.exit_code(), 0);
    assert!(
        s.stats.inputs_by_class.len() >= 18,
        "{:?}",
        s.stats.inputs_by_class
    );
    assert!(s.stats.requirements_touched.len() >= 50);
    // The same seed sends the same sequences and gives the same statistics.
    let short = Options {
        iterations: Some(60),
        ..opts
    };
    let again = fuzz::run(spec(), &short, &mut std::io::sink()).unwrap();
    let twice = fuzz::run(spec(), &short, &mut std::io::sink()).unwrap();
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
    let dir = std::env::temp_dir().join(format!("drivespec-fuzz-psx-{}", std::process::id()));
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
    // The file round-trips exactly, and names ISDU steps.
    assert_eq!(r.to_json(), text);
    assert!(
        r.steps
            .iter()
            .any(|s| matches!(s.action, Action::Psx3xx(PsxStep::IsduWrite { .. }))),
        "{text}"
    );
    assert!(text.contains("\"do\": \"isdu-write\""), "{text}");
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
    // A replay of another family is refused, and so are PSD4xx or HPD steps in a PSx3xx file.
    let psd = Options {
        family: FamilyId::Psd4xx,
        ..opts.clone()
    };
    assert!(fuzz::replay(spec(), &psd, &r).is_err());
    let record = text.replacen("\"do\": \"isdu-write\"", "\"do\": \"record-write\"", 1);
    assert!(Replay::from_json(&record, "x").is_err());
    let hpd = text.replacen("\"do\": \"isdu-write\"", "\"do\": \"send\"", 1);
    assert!(Replay::from_json(&hpd, "x").is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}
