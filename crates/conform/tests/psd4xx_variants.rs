//! PSD4xx legal variants (`support::psd4xx_variants`): drives that differ from the reference
//! only where the manual allows must pass every case; a later start must pass every motion
//! case (a PKW read of the position during a run still compares the value of the moment with
//! the reference's). The cases each variant fails are printed.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod support;

use drivespec_conform::case::Outcome;
use drivespec_conform::cyclic::{LocalPeer, Server};
use drivespec_conform::psd4xx::Psd4xxSuite;
use drivespec_conform::suite::{Session, Settings, Suite};
use support::mutants::spec;
use support::psd4xx_variants::{variants, Kind, Variant};

#[test]
fn every_psd4xx_legal_variant_passes() {
    let suite = Psd4xxSuite::new(spec(), &Settings::default()).unwrap();
    let mut problems = Vec::new();
    for (name, kind) in variants() {
        let server = Server::new(name, "psd4xx", Box::new(Variant::new(kind)));
        let mut session = suite.session(Box::new(LocalPeer::new(name, server)));
        let mut failed = Vec::new();
        for (i, info) in suite.cases().iter().enumerate() {
            let run = session.run(i);
            let motion = run
                .evidence
                .iter()
                .any(|r| r.note.as_deref().is_some_and(|n| n.starts_with("motion:")));
            if let Outcome::Fail(f) = run.outcome {
                failed.push(info.id.clone());
                if motion || !matches!(kind, Kind::StartLatency(_)) {
                    problems.push(format!(
                        "{name}: {} failed: {}\n  expected {}\n  got      {}",
                        info.id, f.message, f.expected, f.got
                    ));
                }
            }
        }
        println!("{name:<30} fails {:>3} case(s): {:?}", failed.len(), failed);
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
