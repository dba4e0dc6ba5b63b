//! HPD legal variants (`drivespec_implementations::hpd_variants`): drives that differ from the reference only
//! where the manual allows must pass every case (0 failures). The findings each variant
//! showed (which erratum reading it follows, points the manual leaves open) are printed.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod support;

use drivespec_conform::case::Outcome;
use drivespec_conform::hpd::HpdSuite;
use drivespec_conform::suite::{Session, Settings, Suite};
use drivespec_implementations::hpd_variants::{variants, Variant};
use drivespec_implementations::spec;
use drivespec_sim::SimLink;
use std::collections::BTreeSet;
use support::legal::describe;

#[test]
fn every_hpd_legal_variant_passes() {
    let suite = HpdSuite::new(spec(), &Settings::default()).unwrap();
    let mut problems = Vec::new();
    for (name, kind) in variants() {
        let link = SimLink::new(format!("variant: {name}"), Box::new(Variant::new(kind)));
        let mut session = suite.session(Box::new(link));
        let mut failed = Vec::new();
        let mut findings = BTreeSet::new();
        for (i, info) in suite.cases().iter().enumerate() {
            let run = session.run(i);
            for f in &run.findings {
                findings.insert(f.line());
            }
            if let Outcome::Fail(f) = run.outcome {
                failed.push((info.id.clone(), f));
            }
        }
        println!(
            "{name:<40} fails {:>3} case(s); findings: {findings:?}",
            failed.len()
        );
        problems.extend(describe(&name, &failed));
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
