//! What the fuzzer's tests of the two cyclic families check the same way: every mutant is
//! found with a short replay that replays exactly, a fixed-seed run against the reference finds
//! nothing and repeats, and a finding's replay file replays byte for byte.

use drivespec_conform::suite::Settings;
use drivespec_conform::Progress;
use drivespec_fuzz::{self as fuzz, Device, FindingClass, Options, Replay};
use drivespec_implementations::spec;
use drivespec_spec::FamilyId;
use std::path::PathBuf;
use std::time::Instant;

/// The options of the mutant runs of `family`: at most `bound` sequences and `max_findings`
/// findings, 100 minimising runs, seed 1, quiet, no reports.
pub fn mutant_options(family: FamilyId, bound: u64, max_findings: usize) -> Options {
    Options {
        family,
        iterations: Some(bound),
        minimize_runs: 100,
        max_findings,
        no_reports: true,
        progress: Progress::Quiet,
        settings: Settings {
            seed: 1,
            ..Settings::default()
        },
        ..Options::default()
    }
}

/// Runs the fuzzer (`opts`, at most `bound` sequences) against every mutant of `all` (name and
/// kind), on `threads` threads, and fails naming each mutant that is not found, whose shortest
/// replay is longer than `limit(kind)` steps, whose exit code is not 1 or whose findings do not
/// replay exactly.
pub fn every_mutant_is_found<K: Copy + Send + Sync>(
    opts: &Options,
    all: &[(&str, K)],
    threads: usize,
    bound: u64,
    limit: impl Fn(K) -> usize,
    mutant: fn(K, &str) -> Device,
) {
    let results: Vec<(String, K, fuzz::Summary)> = std::thread::scope(|s| {
        let handles: Vec<_> = all
            .chunks(all.len().div_ceil(threads.max(1)).max(1))
            .map(|chunk| {
                s.spawn(move || {
                    chunk
                        .iter()
                        .map(|&(name, kind)| {
                            let summary = fuzz::run_on_device(
                                spec(),
                                opts,
                                mutant(kind, name),
                                &mut std::io::sink(),
                            )
                            .unwrap();
                            (name.to_owned(), kind, summary)
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
            None => problems.push(format!("{name}: not found in {bound} sequences")),
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
                fuzz::replay_on_device(spec(), opts, &f.replay, mutant(*kind, name)).unwrap();
            if info.reproduced && !(again.same_as_recorded && again.same_finding) {
                problems.push(format!("{name}: {} does not replay exactly", f.id));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// A run of `iterations` sequences at seed 7 against the reference finds nothing and sends
/// inputs of at least `classes` classes touching at least `requirements` requirements; two
/// runs of `repeat` sequences give the same statistics.
pub fn the_reference_gives_nothing(
    opts: &Options,
    iterations: u64,
    classes: usize,
    requirements: usize,
    repeat: u64,
) {
    let mut opts = Options {
        iterations: Some(iterations),
        ..opts.clone()
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
    assert_eq!(s.stats.sequences, iterations);
    assert!(s.findings.is_empty(), "{:#?}", s.stats.findings);
    assert_eq!(s.exit_code(), 0);
    assert!(
        s.stats.inputs_by_class.len() >= classes,
        "{:?}",
        s.stats.inputs_by_class
    );
    assert!(s.stats.requirements_touched.len() >= requirements);
    // The same seed sends the same sequences and gives the same statistics.
    let short = Options {
        iterations: Some(repeat),
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

/// A finding against the device `mutant` makes, run with `opts` into a folder tagged `tag`:
/// the same seed gives byte-identical replay files; the file round-trips exactly, holds a
/// step `do = step` and replays twice with the recorded exchanges; against the reference it
/// passes. Returns the loaded replay, its text and the folder (removed by the caller).
pub fn a_finding_replays(
    opts: &Options,
    tag: &str,
    mutant: impl Fn() -> Device,
    step: &str,
) -> (Replay, String, PathBuf) {
    let dir = std::env::temp_dir().join(format!("drivespec-fuzz-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let s = fuzz::run_on_device(
        spec(),
        &Options {
            out_dir: dir.clone(),
            no_reports: false,
            ..opts.clone()
        },
        mutant(),
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
    let again = fuzz::run_on_device(spec(), opts, mutant(), &mut std::io::sink()).unwrap();
    assert_eq!(again.findings.len(), s.findings.len());
    for (a, b) in again.findings.iter().zip(&s.findings) {
        assert_eq!(a.replay.to_json(), b.replay.to_json());
    }
    let r = Replay::load(&file).unwrap();
    assert_eq!(r.to_json(), text);
    assert!(text.contains(&format!("\"do\": \"{step}\"")), "{text}");
    // Replayed twice: the same exchanges as recorded, byte for byte, both times.
    for _ in 0..2 {
        let again = fuzz::replay_on_device(spec(), opts, &r, mutant()).unwrap();
        assert!(again.same_as_recorded, "{text}\n{:#?}", again.exchanges);
        assert!(again.same_finding);
        assert_eq!(again.exit_code(), 1);
        assert_eq!(again.exchanges, r.exchanges);
    }
    // Against the reference it passes.
    let fixed = fuzz::replay(spec(), opts, &r).unwrap();
    assert_eq!(fixed.exit_code(), 0);
    assert!(!fixed.same_finding);
    (r, text, dir)
}
