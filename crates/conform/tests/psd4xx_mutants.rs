//! PSD4xx mutation tests: the reference drive with one planted deviation
//! (`drivespec_implementations::psd4xx_mutants`, served over the cyclic protocol in-process) as the device under
//! test. Each mutant must fail the cases named for it, and every case it fails must cite a
//! requirement the deviation breaks first; the mutation score is printed.
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
use drivespec_conform::select::Pattern;
use drivespec_conform::suite::{Session, Settings, Suite};
use drivespec_implementations::psd4xx_mutants::{mutants, Mutant};
use drivespec_implementations::spec;

#[test]
fn every_psd4xx_mutant_fails_the_cases_covering_its_deviation() {
    let suite = Psd4xxSuite::new(spec(), &Settings::default()).unwrap();
    let all = mutants();
    let mut caught = 0;
    let mut problems = Vec::new();
    let mut report = Vec::new();
    let mut led_by_effect: Vec<(&str, &str)> = Vec::new();
    for m in &all {
        let server = Server::new(m.name, "psd4xx", Box::new(Mutant::new(m.kind)));
        let mut session = suite.session(Box::new(LocalPeer::new(m.name, server)));
        let breaks: Vec<Pattern> = m.breaks.iter().map(|b| Pattern::new(b).unwrap()).collect();
        let mut failed = Vec::new();
        for (i, info) in suite.cases().iter().enumerate() {
            if let Outcome::Fail(f) = session.run(i).outcome {
                let first = f
                    .requirements
                    .first()
                    .is_some_and(|r| breaks.iter().any(|b| b.matches(&r.id)));
                let excused = LED_BY_ITS_EFFECT
                    .iter()
                    .any(|(name, case, _)| *name == m.name && *case == info.id);
                if excused {
                    led_by_effect.push((m.name, info.id.as_str()));
                } else if !first {
                    let ids: Vec<&str> = f.requirements.iter().map(|r| r.id.as_str()).collect();
                    problems.push(format!(
                        "{}: {} failed citing {ids:?}, not one of {:?} first: {}",
                        m.name, info.id, m.breaks, f.message
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
            "{:<40} fails {:>3} case(s), e.g. {}",
            m.name,
            failed.len(),
            failed.first().map_or("-", String::as_str)
        ));
    }
    println!("PSD4xx mutants:\n{}", report.join("\n"));
    println!(
        "PSD4xx mutation score: {caught}/{} = {:.0} %",
        all.len(),
        100.0 * caught as f64 / all.len() as f64
    );
    for (name, case, why) in LED_BY_ITS_EFFECT {
        if !led_by_effect.iter().any(|(n, c)| *n == name && *c == case) {
            problems.push(format!(
                "{name}: {case} no longer fails led by another requirement ({why}); take it off LED_BY_ITS_EFFECT"
            ));
        }
    }
    assert!(all.len() >= 12);
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert_eq!(caught, all.len());
}

/// Cases a mutant fails where the images cannot show the requirement it breaks, so the
/// failure leads with the case's requirement: (mutant, case, why). Each must still fail so;
/// one whose failure leads with a requirement the mutant breaks is taken off.
const LED_BY_ITS_EFFECT: [(&str, &str, &str); 4] = [
    (
        "speed-sign-inverted",
        "psd4xx/status/obstruction",
        "the shaft is blocked: with no travel the images cannot tell a wrong speed sign from a run the wrong way",
    ),
    (
        "loop-on-the-wrong-side",
        "psd4xx/image/layout",
        "a PKW read answered from a drive standing elsewhere after its loop; the case's requirements are the image layout's",
    ),
    (
        "loop-on-the-wrong-side",
        "psd4xx/status/toggle",
        "the case checks the toggle bit alone; the run its set-up starts ends elsewhere, which shows first in the running bit, judged with the case's requirement",
    ),
    (
        "pkw-answers-before-no-command",
        "psd4xx/par96/minus-4/run-command-held",
        "the early answer shows as a later change of the PKW response in a par 96 sequence, whose requirements lead",
    ),
];
