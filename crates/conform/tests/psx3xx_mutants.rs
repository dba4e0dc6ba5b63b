//! PSx3xx mutation tests: the reference drive with one planted deviation
//! (`drivespec_implementations::psx3xx_mutants`), served over the cyclic protocol in-process, as the device under
//! test. Each mutant must fail the cases named for it, and every case it fails must cite a
//! requirement the deviation breaks; the mutation score is printed. A mutant built on a model
//! with a brake option (`Kind::brake`) is run by a suite that declares them (`--model`,
//! `--brake`).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod support;

use drivespec_conform::case::Outcome;
use drivespec_conform::cyclic::{LocalPeer, Server};
use drivespec_conform::psx3xx::Psx3xxSuite;
use drivespec_conform::select::Pattern;
use drivespec_conform::suite::{Session, Settings, Suite};
use drivespec_implementations::psx3xx_mutants::{mutants, suite_mutants, Kind, Mutant};
use drivespec_implementations::spec;

/// The suite settings that declare the model and brake option of a mutant of `kind`.
fn settings(kind: Kind) -> Settings {
    let (model, brake) = kind.brake().unzip();
    Settings {
        model: model.map(str::to_owned),
        brake,
        ..Settings::default()
    }
}

#[test]
fn every_psx3xx_mutant_fails_the_cases_covering_its_deviation() {
    let plain = Psx3xxSuite::new(spec(), &Settings::default()).unwrap();
    let braked: Vec<(Kind, Psx3xxSuite<'_>)> = mutants()
        .into_iter()
        .chain(suite_mutants())
        .filter(|m| m.kind.brake().is_some())
        .map(|m| (m.kind, Psx3xxSuite::new(spec(), &settings(m.kind)).unwrap()))
        .collect();
    let all: Vec<_> = mutants().into_iter().chain(suite_mutants()).collect();
    let mut caught = 0;
    let mut problems = Vec::new();
    let mut report = Vec::new();
    let mut led_by_effect = Vec::new();
    for m in &all {
        let suite = braked
            .iter()
            .find(|(k, _)| *k == m.kind)
            .map_or(&plain, |(_, s)| s);
        let server = Server::new(m.name, "psx3xx", Box::new(Mutant::new(m.kind)));
        let mut session = suite.session(Box::new(LocalPeer::new(m.name, server)));
        let breaks: Vec<Pattern> = m.breaks.iter().map(|b| Pattern::new(b).unwrap()).collect();
        let mut failed = Vec::new();
        for (i, info) in suite.cases().iter().enumerate() {
            if let Outcome::Fail(f) = session.run(i).outcome {
                failed.push(info.id.clone());
                let first = f
                    .requirements
                    .first()
                    .is_some_and(|r| breaks.iter().any(|b| b.matches(&r.id)));
                if !first {
                    let ids: Vec<&str> = f.requirements.iter().map(|r| r.id.as_str()).collect();
                    let led = format!(
                        "{}: {} failed citing {ids:?}, not one of {:?} first: {}",
                        m.name, info.id, m.breaks, f.message
                    );
                    if LED_BY_ITS_EFFECT.iter().any(|(name, _)| *name == m.name) {
                        led_by_effect.push(m.name);
                    } else {
                        problems.push(led);
                    }
                }
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
            "{:<45} fails {:>3} case(s), e.g. {}",
            m.name,
            failed.len(),
            failed.first().map_or("-", String::as_str)
        ));
    }
    println!("PSx3xx mutants:\n{}", report.join("\n"));
    println!(
        "PSx3xx mutation score: {caught}/{} = {:.0} %",
        all.len(),
        100.0 * caught as f64 / all.len() as f64
    );
    for (name, why) in LED_BY_ITS_EFFECT {
        let n = led_by_effect.iter().filter(|m| **m == name).count();
        println!("{name}: {n} case(s) led by the requirement of the effect ({why})");
        if n == 0 {
            problems.push(format!(
                "{name}: every failure now leads with a requirement it breaks; take it off LED_BY_ITS_EFFECT"
            ));
        }
    }
    assert!(all.len() >= 12);
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert_eq!(caught, all.len());
}

/// Mutants some of whose failing cases show the deviation first by an effect that another
/// requirement governs: that requirement leads, the broken one follows. Each must still show
/// such a case; one whose failures all lead with a requirement it breaks is taken off.
const LED_BY_ITS_EFFECT: [(&str, &str); 6] = [
    (
        "format switch immediate",
        "the save and device reset it runs unasked show first: the reset's status word (status bit rules), \
         the unsaved ISDU 135 kept over a reset (PSX-PAR-SAVED), the new format's DeviceID (PSX-DP-007)",
    ),
    (
        "saved value lost on power cycle",
        "ISDU 116 read after the power cycle: the case's first requirement naming ISDU 116 is the DeviceID rule \
         (PSX-DP-007), PSX-PAR-SAVED follows",
    ),
    (
        "control bit 6 (no loop) ignored",
        "the extra loop shows as a status bit 6 event of a case with several requirements: the bit's rules lead, \
         the case's PSX-CMD-008 / PSX-ADJ-004 follow",
    ),
    (
        "ISDU 118 time-out ignored",
        "the missing time-out abort shows as a status bit 5 event: the bit's rules lead, PSX-TIMEOUT-003 follows",
    ),
    (
        "jog keys ignored",
        "a case with one requirement (PSX-JOG-003, PSX-JOG-004) names it first; the unseen keys show as the \
         status bit 3 set rule that follows",
    ),
    (
        "control bit 14 (clear error bits) ignored",
        "the status bit 5 event cites the bit's reset rules in declared order (PSX-STS-5-RESET-1 before \
         PSX-STS-5-RESET-2); which reset rule the output triggered is not told by the spec's rules",
    ),
];

#[test]
fn an_acceptable_error_type_given_as_hex_passes() {
    let suite = Psx3xxSuite::new(spec(), &Settings::default()).unwrap();
    let server = Server::new(
        "acceptable variant",
        "psx3xx",
        Box::new(Mutant::new(Kind::AcceptableVariant)),
    );
    let mut session = suite.session(Box::new(LocalPeer::new("variant", server)));
    let (mut run, mut accepted) = (0, 0);
    for (i, info) in suite.cases().iter().enumerate() {
        if !info.id.starts_with("psx3xx/isdu/write/") {
            continue;
        }
        run += 1;
        let r = session.run(i);
        assert_eq!(r.outcome, Outcome::Pass, "{}", info.id);
        let first = &r.evidence[0];
        if first.expected.as_ref().unwrap().text == "ISDU-ERROR PAR_VALOUTOFRNG" {
            accepted += 1;
            assert!(first
                .got
                .as_ref()
                .unwrap()
                .text
                .starts_with("ISDU-ERROR 0x"));
            let note = first.note.clone().unwrap();
            assert!(note.contains("accepted"), "{}: {note}", info.id);
        }
    }
    assert!(run > 50);
    assert!(
        accepted > 20,
        "{accepted} refusals answered with the variant"
    );
}

#[test]
fn live_positions_read_by_isdu_are_judged_by_the_devices_own_process_data() {
    let suite = Psx3xxSuite::new(spec(), &Settings::default()).unwrap();
    let server = Server::new(
        "live offset",
        "psx3xx",
        Box::new(Mutant::new(Kind::LivePositionOffset)),
    );
    let mut session = suite.session(Box::new(LocalPeer::new("offset", server)));
    let index = |id: &str| suite.cases().iter().position(|c| c.id == id).unwrap();
    let motion = session.run(index("psx3xx/timeout/safe-position"));
    assert_eq!(motion.outcome, Outcome::Pass);
    assert!(motion.evidence.iter().any(|e| e
        .note
        .as_deref()
        .is_some_and(|n| n.starts_with("live value: within"))));
    let exact = session.run(index("psx3xx/isdu/read/67"));
    assert!(exact.outcome.failed());
}

/// A refusal situation's requirement is what a failure cites first when a device answers
/// otherwise: each names a requirement of the spec (a missing one would be dropped).
#[test]
fn every_refusal_situation_names_a_requirement_of_the_spec() {
    let family = spec().family(drivespec_spec::FamilyId::Psx3xx);
    let errors = &family.psx3xx().unwrap().isdu_errors;
    for c in &errors.cases {
        let id = c.requirement.as_deref().unwrap();
        assert!(family.requirement(id).is_some(), "{}: {id}", c.case);
    }
}
