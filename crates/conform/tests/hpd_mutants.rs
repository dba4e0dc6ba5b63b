//! Mutation tests: the reference drive with one planted deviation (`support::mutants`) as the
//! device under test. Each mutant must fail at least the cases named for it, and every case it
//! fails must cite one of the requirements the deviation breaks (no collateral failures). The
//! score is printed. A mutant following another reading of an erratum is judged with the
//! adopted reading made strict (`--reading OPTION=ADOPTED`): by default that reading is legal.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod support;

use drivespec_conform::case::Outcome;
use drivespec_conform::hpd::HpdSuite;
use drivespec_conform::select::Pattern;
use drivespec_conform::suite::{Session, Settings, Suite};
use drivespec_sim::SimLink;
use support::mutants::{mutants, spec, strict_readings, Kind, Mutant};

#[test]
fn every_mutant_fails_exactly_cases_covering_its_broken_requirement() {
    let plain = HpdSuite::new(spec(), &Settings::default()).unwrap();
    let mut caught = 0;
    let mut report = Vec::new();
    let mut problems = Vec::new();
    let all = mutants();
    for m in &all {
        let strict_suite;
        let suite = match m.kind {
            Kind::Reading(..) => {
                let settings = Settings {
                    readings: strict_readings(m.kind),
                    ..Settings::default()
                };
                strict_suite = HpdSuite::new(spec(), &settings).unwrap();
                &strict_suite
            }
            _ => &plain,
        };
        let link = SimLink::new(format!("mutant: {}", m.name), Box::new(Mutant::new(m.kind)));
        let mut session = suite.session(Box::new(link));
        let mut failed = Vec::new();
        for (i, info) in suite.cases().iter().enumerate() {
            if let Outcome::Fail(f) = session.run(i).outcome {
                let cites: Vec<String> = f
                    .requirements
                    .iter()
                    .map(|r| r.id.clone())
                    .chain(info.requirements.iter().cloned())
                    .collect();
                if !m.breaks.iter().any(|b| cites.contains(b)) {
                    problems.push(format!(
                        "{}: collateral failure {} ({})",
                        m.name, info.id, f.message
                    ));
                }
                failed.push(info.id.clone());
            }
        }
        for want in m.must_fail {
            let p = Pattern::new(want).unwrap();
            if !failed.iter().any(|id| p.matches(id)) {
                problems.push(format!("{}: {want} did not fail", m.name));
            }
        }
        if !failed.is_empty() {
            caught += 1;
        }
        report.push(format!(
            "{:<34} breaks {:<40} fails {:>3} case(s)",
            m.name,
            m.breaks.join(", ").chars().take(40).collect::<String>(),
            failed.len()
        ));
    }
    println!("HPD mutants:\n{}", report.join("\n"));
    println!(
        "mutation score: {caught}/{} = {:.0} %",
        all.len(),
        100.0 * caught as f64 / all.len() as f64
    );
    assert!(all.len() >= 12);
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert_eq!(caught, all.len());
}

/// What a CI log shows first for a failure: the broken requirement, then what went wrong,
/// what the manual allows and what came.
#[test]
fn a_failure_names_the_broken_requirement_first() {
    let suite = HpdSuite::new(spec(), &Settings::default()).unwrap();
    let m = mutants()
        .into_iter()
        .find(|m| m.name == "checksum off by one")
        .unwrap();
    let link = SimLink::new(format!("mutant: {}", m.name), Box::new(Mutant::new(m.kind)));
    let mut session = suite.session(Box::new(link));
    let i = suite
        .cases()
        .iter()
        .position(|c| c.id == "hpd/frame/read-parameter")
        .unwrap();
    let Outcome::Fail(f) = session.run(i).outcome else {
        panic!("the mutant passes hpd/frame/read-parameter");
    };
    insta::assert_snapshot!(f.headline().join("\n"));
}
