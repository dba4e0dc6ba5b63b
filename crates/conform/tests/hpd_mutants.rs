//! Mutation tests: the reference drive with one planted deviation (`drivespec_implementations::hpd_mutants`) as the
//! device under test. Each mutant must fail at least the cases named for it, and every case it
//! fails must cite one of the requirements the deviation breaks first (no collateral failures,
//! no failure led by another requirement). The score is printed. A mutant following another reading of an erratum is judged with the
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
use drivespec_implementations::hpd_mutants::{mutants, strict_readings, Kind, Mutant};
use drivespec_implementations::spec;
use drivespec_sim::SimLink;

#[test]
fn every_mutant_fails_exactly_cases_covering_its_broken_requirement() {
    let plain = HpdSuite::new(spec(), &Settings::default()).unwrap();
    let mut caught = 0;
    let mut report = Vec::new();
    let mut problems = Vec::new();
    let mut led_by_effect: Vec<&str> = Vec::new();
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
                } else if !f
                    .requirements
                    .first()
                    .is_some_and(|r| m.breaks.contains(&r.id))
                {
                    let led = format!(
                        "{}: {} fails citing {:?} first, not one of {:?} ({})",
                        m.name,
                        info.id,
                        f.requirements.first().map(|r| r.id.as_str()),
                        m.breaks,
                        f.message
                    );
                    if LED_BY_ITS_EFFECT.iter().any(|(name, _)| *name == m.name) {
                        led_by_effect.push(m.name);
                    } else {
                        problems.push(led);
                    }
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

/// Mutants whose deviation leaves no trace on any byte the suite can read: the case that
/// fails cites the behaviour its check evaluates first, and the broken requirement further
/// down. Each must still show such a case; one whose failures all lead with a requirement it
/// breaks is taken off.
const LED_BY_ITS_EFFECT: [(&str, &str); 1] = [(
    "wrong bit-change byte",
    "a bit change of the self-clearing command bit b99.11 lands on b99.3, a bit the drive computes itself: \
     read back, Pb99 is the reference's, and only the missing effect of the command shows",
)];

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

/// Runs the case `id` of the HPD suite against `kind`.
fn run_one(
    kind: drivespec_implementations::hpd_mutants::Kind,
    id: &str,
) -> drivespec_conform::case::CaseRun {
    let suite = HpdSuite::new(spec(), &Settings::default()).unwrap();
    let link = SimLink::new("mutant", Box::new(Mutant::new(kind)));
    let mut session = suite.session(Box::new(link));
    let i = suite.cases().iter().position(|c| c.id == id).unwrap();
    session.run(i)
}

/// A set-up write the drive takes without answering fails at that step, naming the
/// acknowledge rule (manual 4.1 CMD 1) first.
#[test]
fn a_missing_answer_to_a_set_up_write_fails_naming_the_acknowledge_rule() {
    let run = run_one(
        drivespec_implementations::hpd_mutants::Kind::SilentSetupWrite,
        "hpd/param/Pr33/min",
    );
    let Outcome::Fail(f) = run.outcome else {
        panic!("a silent set-up write passes");
    };
    let step = &run.evidence[f.step.unwrap()];
    assert_eq!(step.role, drivespec_conform::case::Role::Setup, "{f:?}");
    assert_eq!(f.requirements[0].id, "HPD-FRAME-011", "{f:?}");
}

/// Clean-up writes back the value the device had, not the reference's: a drive delivered
/// with Pr15 = 20 (as 3.3 prints it, HPD-ERRATUM-005) gets 20 back after a Pr15 case.
#[test]
fn clean_up_writes_back_the_devices_own_value() {
    let family = spec().family(drivespec_spec::FamilyId::Hpd);
    let pr15 = drivespec_hpd::params::Target::parse(family, "Pr15").unwrap();
    let mut drive = drivespec_hpd::model::Drive::new(
        spec(),
        drivespec_hpd::model::DriveConfig::commissioned(0),
    )
    .unwrap();
    drive.set_value(0, &pr15, 20).unwrap();
    let suite = HpdSuite::new(spec(), &Settings::default()).unwrap();
    let link = SimLink::new("Pr15 = 20", Box::new(drive));
    let mut session = suite.session(Box::new(link));
    let i = suite
        .cases()
        .iter()
        .position(|c| c.id == "hpd/param/Pr15/min")
        .unwrap();
    let run = session.run(i);
    assert!(matches!(run.outcome, Outcome::Pass), "{:?}", run.outcome);
    let back: Vec<&str> = run
        .evidence
        .iter()
        .filter(|r| r.action.starts_with("write back the Pr15"))
        .filter_map(|r| r.sent.as_deref())
        .collect();
    // CMD 5 to drive 0 (0xA0), LUN 2, PAR 0x46, data 20 = 14 00.
    assert_eq!(back, ["7E A0 02 46 14 00 FC"]);
}

/// Every motion mutant (`support::hpd_motion_mutants`) fails the cases named for it, each
/// citing the requirement the deviation breaks first, and fails no case that cites none of
/// the requirements it breaks.
#[test]
fn every_motion_mutant_fails_citing_its_requirement_first() {
    use drivespec_implementations::hpd_motion_mutants::{motion_mutants, MotionMutant};
    let suite = HpdSuite::new(spec(), &Settings::default()).unwrap();
    let mut problems = Vec::new();
    let mut report = Vec::new();
    let all = motion_mutants();
    for m in &all {
        let link = SimLink::new(
            format!("mutant: {}", m.name),
            Box::new(MotionMutant::new(m.kind)),
        );
        let mut session = suite.session(Box::new(link));
        let mut failed = Vec::new();
        for (i, info) in suite.cases().iter().enumerate() {
            if let Outcome::Fail(f) = session.run(i).outcome {
                let cites: Vec<&str> = f
                    .requirements
                    .iter()
                    .map(|r| r.id.as_str())
                    .chain(info.requirements.iter().map(String::as_str))
                    .collect();
                if !m.breaks.iter().any(|b| cites.contains(b)) {
                    problems.push(format!(
                        "{}: collateral failure {} ({})",
                        m.name, info.id, f.message
                    ));
                } else if !f
                    .requirements
                    .first()
                    .is_some_and(|r| m.breaks.contains(&r.id.as_str()))
                {
                    problems.push(format!(
                        "{}: {} fails citing {:?} first, not one of {:?} ({})",
                        m.name,
                        info.id,
                        f.requirements.first().map(|r| r.id.as_str()),
                        m.breaks,
                        f.message
                    ));
                }
                failed.push((
                    info.id.clone(),
                    f.requirements.first().map(|r| r.id.clone()),
                ));
            }
        }
        for want in m.must_fail {
            match failed.iter().find(|(id, _)| id == want) {
                None => problems.push(format!("{}: {want} did not fail", m.name)),
                Some((_, first)) if first.as_deref() != Some(m.first) => problems.push(format!(
                    "{}: {want} cites {first:?} first, not {}",
                    m.name, m.first
                )),
                Some(_) => {}
            }
        }
        report.push(format!(
            "{:<58} first {:<26} fails {:>3} case(s)",
            m.name,
            m.first,
            failed.len()
        ));
    }
    println!("HPD motion mutants:\n{}", report.join("\n"));
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// A case that fails after a set-up it relies on runs again with its bit changes and inputs
/// read back: a bit change that landed in the other byte fails at its read-back naming the
/// PAR rule of CMD 6 (4.1), inputs never read name the input rule (3.8.1); a passing device
/// sees no read-back.
#[test]
fn a_set_up_that_did_not_take_fails_at_its_read_back() {
    use drivespec_implementations::hpd_mutants::Kind;
    for (kind, id, rule) in [
        (
            Kind::WrongBitChangeByte,
            "hpd/plc/vector/plc-add-71-72-64",
            "HPD-FRAME-018",
        ),
        (
            Kind::DeafInputs,
            "hpd/plc/vector/plc-ld-out",
            "HPD-BIT-90-INPUTS",
        ),
    ] {
        let run = run_one(kind, id);
        let Outcome::Fail(f) = run.outcome else {
            panic!("{kind:?} passes {id}");
        };
        assert_eq!(f.requirements[0].id, rule, "{id}: {f:?}");
        let step = &run.evidence[f.step.unwrap()];
        assert!(step.action.starts_with("read back"), "{id}: {step:?}");
    }
    let suite = HpdSuite::new(spec(), &Settings::default()).unwrap();
    let drive = drivespec_hpd::model::Drive::new(
        spec(),
        drivespec_hpd::model::DriveConfig::commissioned(0),
    )
    .unwrap();
    let mut session = suite.session(Box::new(SimLink::new("reference", Box::new(drive))));
    let i = suite
        .cases()
        .iter()
        .position(|c| c.id == "hpd/plc/vector/plc-ld-out")
        .unwrap();
    let run = session.run(i);
    assert!(matches!(run.outcome, Outcome::Pass), "{:?}", run.outcome);
    assert!(run
        .evidence
        .iter()
        .all(|r| !r.action.starts_with("read back")));
}
