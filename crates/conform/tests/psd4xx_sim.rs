//! The whole PSD4xx suite passes against the built-in reference model, over the cyclic
//! protocol in-process (`sim`), for every device model.
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

fn run_model(spec: &Spec, model: Option<&str>) -> (usize, Vec<String>) {
    let settings = Settings {
        model: model.map(str::to_owned),
        ..Settings::default()
    };
    let s = suite(spec, FamilyId::Psd4xx, &settings).unwrap();
    let mut session = s.open(&Dut::default()).unwrap();
    let mut failed = Vec::new();
    for (i, c) in s.cases().iter().enumerate() {
        match session.run(i).outcome {
            Outcome::Pass => {}
            Outcome::Skip { reason } => failed.push(format!("{}: skipped: {reason}", c.id)),
            Outcome::Fail(f) => failed.push(format!(
                "{}: {} expected {} got {}",
                c.id, f.message, f.expected, f.got
            )),
        }
    }
    (s.cases().len(), failed)
}

#[test]
fn every_psd4xx_case_passes_against_sim_for_every_model() {
    let spec = Spec::builtin().unwrap();
    let models: Vec<String> = spec
        .family(FamilyId::Psd4xx)
        .models
        .iter()
        .map(|m| m.id.clone())
        .collect();
    assert!(models.len() >= 11);
    let mut problems = Vec::new();
    for m in &models {
        let (n, failed) = run_model(&spec, Some(m));
        println!("{m}: {n} cases, {} failed", failed.len());
        problems.extend(failed.into_iter().map(|f| format!("{m}: {f}")));
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn psd4xx_case_counts_by_group() {
    let spec = Spec::builtin().unwrap();
    let s = suite(&spec, FamilyId::Psd4xx, &Settings::default()).unwrap();
    let mut m = std::collections::BTreeMap::new();
    for c in s.cases() {
        let g = c.id.split('/').nth(1).unwrap().to_owned();
        *m.entry(g).or_insert(0) += 1;
        assert!(!c.requirements.is_empty(), "{}", c.id);
    }
    println!("{m:?} total {}", s.cases().len());
    assert!(s.cases().len() > 200);
    let ids: std::collections::BTreeSet<&str> = s.cases().iter().map(|c| c.id.as_str()).collect();
    assert_eq!(ids.len(), s.cases().len(), "duplicate case IDs");
}
