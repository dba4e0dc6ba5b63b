//! The whole HPD suite passes against the built-in reference model.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_conform::case::Outcome;
use drivespec_conform::dut::Dut;
use drivespec_conform::suite::{suite, Settings};
use drivespec_spec::{FamilyId, Spec};

#[test]
fn every_hpd_case_passes_against_sim() {
    let spec = Spec::builtin().unwrap();
    let s = suite(&spec, FamilyId::Hpd, &Settings::default()).unwrap();
    let mut session = s.open(&Dut::default()).unwrap();
    let mut failed = Vec::new();
    for (i, c) in s.cases().iter().enumerate() {
        let run = session.run(i);
        match run.outcome {
            Outcome::Pass => {}
            Outcome::Skip { reason } => panic!("{}: skipped: {reason}", c.id),
            Outcome::Fail(f) => failed.push(format!("{}: {}", c.id, f.message)),
        }
    }
    assert!(
        failed.is_empty(),
        "{} of {} failed:\n{}",
        failed.len(),
        s.cases().len(),
        failed.join("\n")
    );
}

#[test]
fn case_counts_by_group() {
    let spec = Spec::builtin().unwrap();
    let s = suite(&spec, FamilyId::Hpd, &Settings::default()).unwrap();
    let mut m = std::collections::BTreeMap::new();
    for c in s.cases() {
        let g = c.id.split('/').nth(1).unwrap().to_owned();
        *m.entry(g).or_insert(0) += 1;
    }
    println!("{m:?} total {}", s.cases().len());
    assert!(s.cases().len() > 500);
}
