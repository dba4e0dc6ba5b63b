//! The PSx3xx suite passes against the built-in reference model, over the cyclic protocol
//! in-process (`sim`).
//!
//! The whole suite runs on the default model and on the first and the last model of the
//! spec's table; every other of the 59 models runs the `isdu`, `guard`, `command`, `format`
//! and `status` groups plus the first case of every other group. The whole suite on all 59
//! models takes several minutes in a debug build on the shared machine; the release benchmark
//! (`examples/bench_conform.rs`) runs it on every model and reports the failures.
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
use std::collections::BTreeMap;

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
    let s = suite(spec, FamilyId::Psx3xx, &settings).unwrap();
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
        match session.run(i).outcome {
            Outcome::Pass => {}
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
