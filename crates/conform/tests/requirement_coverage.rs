//! Requirement coverage gate, counted from checks that evaluated: `drivespec conform all` runs
//! on the built-in models and each case reports the requirements its judged steps checked
//! (`CaseRun::checked`). The PSx3xx coverage is the union of that run and one run of the
//! psx3xx suite with a snap brake (`--brake snap`) on the first model of the spec that may
//! have one (manual 5.12): the brake is an ordering option no ISDU entry reports, and what a
//! drive with a brake must do (PSX-ADJ-010) shows only on one. Every `must` requirement of
//! every family is checked, or marked
//! `observable = false` in the spec with the reason no check can see it over the interface, or
//! listed in `tests/unchecked-<family>.toml` with a reason (rustls `bogo/config.json.in` style:
//! no exclusion without a reason).
//!
//! The lists only shrink: an entry whose requirement is checked by now, is unknown or is not
//! `must` fails the gate as stale, and a checked requirement that stops being checked fails it
//! as unlisted. `DRIVESPEC_BLESS=1` rewrites the lists from the run, keeping the reasons
//! written for entries that stay and giving new entries the reason "no check evaluates it".
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_conform::report::Coverage;
use drivespec_conform::suite::Settings;
use drivespec_conform::{Options, Progress};
use drivespec_sim::reference::BrakeKind;
use drivespec_spec::{FamilyId, Level, Spec};
use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;

/// The reason a blessed new entry gets until someone writes a better one.
const NO_CHECK: &str = "no check evaluates it";

#[derive(Deserialize, Serialize, Default)]
#[serde(deny_unknown_fields)]
struct Unchecked {
    #[serde(default)]
    unchecked: Vec<Entry>,
}

#[derive(Deserialize, Serialize, Clone)]
#[serde(deny_unknown_fields)]
struct Entry {
    id: String,
    reason: String,
}

fn list_path(family: FamilyId) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join(format!("unchecked-{family}.toml"))
}

fn load(family: FamilyId) -> Vec<Entry> {
    let path = list_path(family);
    let Ok(text) = std::fs::read_to_string(&path) else {
        return Vec::new();
    };
    let parsed: Unchecked =
        toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    parsed.unchecked
}

fn bless(family: FamilyId, entries: &[Entry]) {
    let mut text = format!(
        "# {family} `must` requirements that no check of `drivespec conform all` evaluates on the\n\
         # built-in model, each with the reason. Read by tests/requirement_coverage.rs; the list\n\
         # only shrinks (DRIVESPEC_BLESS=1 rewrites it from a run).\n"
    );
    for e in entries {
        text.push_str(&format!(
            "\n[[unchecked]]\nid = {}\nreason = {}\n",
            toml::Value::String(e.id.clone()),
            toml::Value::String(e.reason.clone())
        ));
    }
    std::fs::write(list_path(family), text).unwrap();
}

/// The options of a run of the psx3xx suite with a snap brake on the first model of the spec
/// that may have one (manual 5.12, spec `[[protocol.brake]] models`).
fn snap_brake(spec: &Spec) -> Options {
    let snap = Some(BrakeKind::Snap);
    let model = spec
        .family(FamilyId::Psx3xx)
        .models
        .iter()
        .find(|m| drivespec_sim::reference::psx3xx(spec, Some(&m.id), snap).is_ok())
        .expect("a PSx3xx model that may have a snap brake");
    Options {
        families: vec![FamilyId::Psx3xx],
        settings: Settings {
            model: Some(model.id.clone()),
            brake: snap,
            ..Settings::default()
        },
        no_reports: true,
        progress: Progress::Quiet,
        ..Options::default()
    }
}

#[test]
fn every_must_requirement_is_checked_or_listed_with_a_reason() {
    let spec = Spec::builtin().unwrap();
    let opts = Options {
        families: Vec::new(),
        no_reports: true,
        progress: Progress::Quiet,
        ..Options::default()
    };
    let summary = drivespec_conform::run(&spec, &opts, &mut std::io::sink()).unwrap();
    let braked = drivespec_conform::run(&spec, &snap_brake(&spec), &mut std::io::sink()).unwrap();
    let checked: BTreeSet<&str> = [&summary.report, &braked.report]
        .into_iter()
        .flat_map(|r| &r.coverage)
        .filter(|r| matches!(r.verdict, Coverage::Pass | Coverage::Fail))
        .map(|r| r.requirement.as_str())
        .collect();
    let blessing = std::env::var("DRIVESPEC_BLESS").is_ok_and(|v| v == "1");
    let mut problems = Vec::new();
    println!(
        "requirement coverage (checks that evaluated in `conform all` on the built-in models, \
         and for psx3xx also `conform psx3xx --brake snap` on {}):",
        braked.report.run.model.as_deref().unwrap_or("-")
    );
    for family in FamilyId::ALL {
        let must: Vec<_> = spec
            .family(family)
            .requirements
            .iter()
            .filter(|r| r.level == Level::Must)
            .collect();
        let listed = load(family);
        let reasons: BTreeMap<&str, &str> = listed
            .iter()
            .map(|e| (e.id.as_str(), e.reason.as_str()))
            .collect();
        let unobservable = must.iter().filter(|r| !r.observable).count();
        let unchecked: Vec<_> = must
            .iter()
            .filter(|r| r.observable && !checked.contains(r.id.as_str()))
            .collect();
        let n = must.len();
        let k = n - unchecked.len() - unobservable;
        let observable = n - unobservable;
        println!(
            "  {family}: {k}/{n} must requirements checked ({:.1}% of the {observable} observable), \
             {unobservable} not observable, {} listed as unchecked",
            if observable == 0 {
                100.0
            } else {
                100.0 * k as f64 / observable as f64
            },
            unchecked.len()
        );
        if blessing {
            let entries: Vec<Entry> = unchecked
                .iter()
                .map(|r| Entry {
                    id: r.id.clone(),
                    reason: reasons.get(r.id.as_str()).unwrap_or(&NO_CHECK).to_string(),
                })
                .collect();
            bless(family, &entries);
            continue;
        }
        for r in &unchecked {
            if !reasons.contains_key(r.id.as_str()) {
                problems.push(format!(
                    "{family}: {} is not checked and not in unchecked-{family}.toml: {}",
                    r.id, r.text
                ));
            }
        }
        let mut seen = BTreeSet::new();
        for e in &listed {
            if !seen.insert(e.id.as_str()) {
                problems.push(format!("{family}: {} listed twice", e.id));
            }
            if e.reason.trim().len() < 10 {
                problems.push(format!("{family}: {} has no real reason", e.id));
            }
            match must.iter().find(|r| r.id == e.id) {
                None => problems.push(format!(
                    "{family}: {} is listed but is not a must requirement",
                    e.id
                )),
                Some(r) if !r.observable => problems.push(format!(
                    "{family}: {} is listed but the spec marks it not observable: remove the entry",
                    e.id
                )),
                Some(r) if checked.contains(r.id.as_str()) => problems.push(format!(
                    "{family}: {} is listed but checked by now: remove the entry",
                    e.id
                )),
                Some(_) => {}
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
