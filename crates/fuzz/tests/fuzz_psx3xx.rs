//! `drivespec fuzz psx3xx`: against every PSx3xx mutant (`drivespec_implementations::psx3xx_mutants`) the
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
use drivespec_fuzz::{self as fuzz, Action, Device, Options, Replay};
use drivespec_implementations::psx3xx_mutants::{mutants, Kind, Mutant};
use drivespec_implementations::spec;
use drivespec_psx3xx::step::Step as PsxStep;
use drivespec_spec::FamilyId;
use support::cyclic::{
    a_finding_replays, every_mutant_is_found, mutant_options, the_reference_gives_nothing,
};

/// Sequences each mutant gets.
const BOUND: u64 = 150;

fn options() -> Options {
    mutant_options(FamilyId::Psx3xx, BOUND, 2)
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
    let all: Vec<(&str, Kind)> = mutants()
        .into_iter()
        .filter(|m| !BEYOND_REACH.contains(&m.name))
        .map(|m| (m.name, m.kind))
        .collect();
    every_mutant_is_found(&options(), &all, 2, BOUND, limit, mutant);
}

#[test]
fn a_fixed_seed_run_against_the_reference_finds_nothing() {
    the_reference_gives_nothing(&options(), 400, 18, 50, 60);
}

#[test]
fn replay_files_replay_byte_for_byte() {
    let opts = Options {
        iterations: Some(60),
        ..options()
    };
    let kind = Kind::RangeIgnored;
    let (r, text, dir) =
        a_finding_replays(&opts, "psx", || mutant(kind, "range-ignored"), "isdu-write");
    // The file names ISDU steps.
    assert!(
        r.steps
            .iter()
            .any(|s| matches!(s.action, Action::Psx3xx(PsxStep::IsduWrite { .. }))),
        "{text}"
    );
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
