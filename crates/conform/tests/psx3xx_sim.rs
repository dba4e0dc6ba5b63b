//! The PSx3xx suite passes against the built-in reference model, over the cyclic protocol
//! in-process (`sim`).
//!
//! The whole suite runs on the default model and on the first and the last model of the
//! spec's table; every other of the 59 models runs the `isdu`, `guard`, `command`, `format`
//! and `status` groups plus the first case of every other group. The whole suite on all 59
//! models takes several minutes in a debug build on the shared machine; the release benchmark
//! (`examples/bench_conform.rs`) runs it on every model and reports the failures. A case for the
//! other brake option (manual 5.4) is skipped as not applicable; the whole suite also runs
//! with a snap brake on a model that may have one.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_conform::case::Outcome;
use drivespec_conform::dut::Dut;
use drivespec_conform::suite::{suite, Settings};
use drivespec_sim::reference::BrakeKind;
use drivespec_spec::{FamilyId, Spec};
use std::collections::BTreeMap;

/// How the reason of a case for the other brake option begins.
const NOT_APPLICABLE: &str = "not applicable: ";

/// Runs the cases `pick` selects on `model`; the number run and the failures.
fn run_model(
    spec: &Spec,
    model: Option<&str>,
    pick: &dyn Fn(&str, usize) -> bool,
) -> (usize, Vec<String>) {
    let settings = Settings {
        model: model.map(str::to_owned),
        ..Settings::default()
    };
    run_settings(spec, &settings, pick, &mut |_, _| {})
}

/// Runs the cases `pick` selects with `settings`, showing each case's ID and outcome to
/// `seen`; the number run and the failures (a case skipped as not applicable is none).
fn run_settings(
    spec: &Spec,
    settings: &Settings,
    pick: &dyn Fn(&str, usize) -> bool,
    seen: &mut dyn FnMut(&str, &Outcome),
) -> (usize, Vec<String>) {
    let s = suite(spec, FamilyId::Psx3xx, settings).unwrap();
    let mut session = s.open(&Dut::default()).unwrap();
    let mut failed = Vec::new();
    let mut run = 0;
    let mut per_group: BTreeMap<String, usize> = BTreeMap::new();
    for (i, c) in s.cases().iter().enumerate() {
        let group = c.id.split('/').nth(1).unwrap().to_owned();
        let n = per_group.entry(group).or_insert(0);
        *n += 1;
        if !pick(&c.id, *n) {
            continue;
        }
        run += 1;
        let outcome = session.run(i).outcome;
        seen(&c.id, &outcome);
        match outcome {
            Outcome::Pass => {}
            Outcome::Skip { reason } if reason.starts_with(NOT_APPLICABLE) => {}
            Outcome::Skip { reason } => failed.push(format!("{}: skipped: {reason}", c.id)),
            Outcome::Fail(f) => failed.push(format!(
                "{}: {} expected {} got {}",
                c.id, f.message, f.expected, f.got
            )),
        }
    }
    (run, failed)
}

#[test]
fn every_psx3xx_case_passes_against_sim_on_the_default_model() {
    let spec = Spec::builtin().unwrap();
    let (n, failed) = run_model(&spec, None, &|_, _| true);
    println!("default model: {n} cases, {} failed", failed.len());
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}

#[test]
fn psx3xx_suite_passes_on_every_model() {
    let spec = Spec::builtin().unwrap();
    let family = spec.family(FamilyId::Psx3xx);
    let models: Vec<String> = family.models.iter().map(|m| m.id.clone()).collect();
    assert_eq!(models.len(), 59);
    let full = [
        models.first().unwrap().clone(),
        models.last().unwrap().clone(),
    ];
    let subset = |id: &str, n: usize| {
        let group = id.split('/').nth(1).unwrap_or("");
        matches!(group, "isdu" | "guard" | "command" | "format" | "status") || n <= 1
    };
    let mut problems = Vec::new();
    for m in &models {
        let all = full.contains(m);
        let (n, failed) = if all {
            run_model(&spec, Some(m), &|_, _| true)
        } else {
            run_model(&spec, Some(m), &subset)
        };
        println!("{m}: {n} cases, {} failed", failed.len());
        problems.extend(failed.into_iter().map(|f| format!("{m}: {f}")));
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn psx3xx_case_counts_by_group() {
    let spec = Spec::builtin().unwrap();
    let s = suite(&spec, FamilyId::Psx3xx, &Settings::default()).unwrap();
    let mut m = BTreeMap::new();
    for c in s.cases() {
        assert!(c.id.starts_with("psx3xx/"), "{}", c.id);
        let g = c.id.split('/').nth(1).unwrap().to_owned();
        *m.entry(g).or_insert(0) += 1;
        assert!(!c.requirements.is_empty(), "{}", c.id);
        assert!(!c.steps.is_empty(), "{}", c.id);
    }
    println!("{m:?} total {}", s.cases().len());
    for g in [
        "isdu",
        "guard",
        "command",
        "format",
        "timestamp",
        "status",
        "timeout",
        "position",
    ] {
        assert!(m.get(g).copied().unwrap_or(0) > 0, "no {g} cases");
    }
    let ids: std::collections::BTreeSet<&str> = s.cases().iter().map(|c| c.id.as_str()).collect();
    assert_eq!(ids.len(), s.cases().len(), "duplicate case IDs");
}

#[test]
fn with_a_snap_brake_every_case_passes_or_is_not_applicable_and_the_brake_cases_run() {
    let spec = Spec::builtin().unwrap();
    let family = spec.family(FamilyId::Psx3xx);
    let model = family
        .models
        .iter()
        .find(|m| {
            drivespec_sim::reference::psx3xx(&spec, Some(&m.id), Some(BrakeKind::Snap)).is_ok()
        })
        .unwrap();
    let settings = Settings {
        model: Some(model.id.clone()),
        brake: Some(BrakeKind::Snap),
        ..Settings::default()
    };
    let (mut skipped, mut braked) = (Vec::new(), Vec::new());
    let (n, failed) = run_settings(&spec, &settings, &|_, _| true, &mut |id, o| {
        if let Outcome::Skip { reason } = o {
            skipped.push((id.to_owned(), reason.clone()));
        }
        if id.starts_with("psx3xx/brake/") {
            braked.push((id.to_owned(), o.clone()));
        }
    });
    println!(
        "{} with a snap brake: {n} cases, {} failed, {} not applicable",
        model.id,
        failed.len(),
        skipped.len()
    );
    assert!(failed.is_empty(), "{}", failed.join("\n"));
    assert!(braked.len() >= 2, "{braked:?}");
    assert!(
        braked.iter().all(|(_, o)| *o == Outcome::Pass),
        "{braked:?}"
    );
    for id in [
        "readjust-against-loop",
        "readjust-no-loop-both",
        "readjust-with-loop",
    ] {
        let (_, reason) = skipped
            .iter()
            .find(|(c, _)| c.ends_with(id))
            .unwrap_or_else(|| panic!("{id} ran with a snap brake"));
        assert!(reason.contains("no adjustment function"), "{reason}");
    }
    // Without a brake the brake cases are the ones not applicable.
    let (_, failed) = run_settings(
        &spec,
        &Settings {
            model: Some(model.id.clone()),
            ..Settings::default()
        },
        &|id, _| id.starts_with("psx3xx/brake/"),
        &mut |id, o| {
            assert!(
                matches!(o, Outcome::Skip { reason } if reason.starts_with(NOT_APPLICABLE)),
                "{id}: {o:?}"
            );
        },
    );
    assert!(failed.is_empty(), "{}", failed.join("\n"));
}
