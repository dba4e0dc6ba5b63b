//! Requirement coverage gate: every `must` requirement of a gated family is named by
//! an implementation or a test somewhere in the workspace's Rust sources, or has a written
//! reason in `tests/uncovered-<family>.toml` (rustls `bogo/config.json.in` style: no
//! exclusion without a reason).
//!
//! "Covered" means the exact ID appears in a `.rs` file under `crates/` or `fuzz/` (the spec
//! crate is left out: its loader tests quote IDs as data). The test prints the coverage of
//! every family, lists the uncovered IDs, and fails when a gated family has an uncovered
//! `must` requirement without a reason, or when an exclusion is stale (the ID is covered by
//! now, unknown, or not `must`) or has no reason.
//!
//! Both positioning families are gated: PSD4xx with `tests/uncovered-psd4xx.toml`, PSx3xx with
//! `tests/uncovered-psx3xx.toml` (its reference model is crates/psx3xx/src/model).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_spec::{FamilyId, Level, Spec};
use serde::Deserialize;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Families whose `must` requirements the gate enforces.
const GATED: &[FamilyId] = &[FamilyId::Psd4xx, FamilyId::Psx3xx];
/// Families reported only.
const REPORTED: &[FamilyId] = &[FamilyId::Psd4xx, FamilyId::Psx3xx];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Exclusions {
    #[serde(default)]
    uncovered: Vec<Exclusion>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Exclusion {
    id: String,
    reason: String,
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        let name = e.file_name();
        if p.is_dir() {
            if name != "target" && name != "snapshots" {
                rust_files(&p, out);
            }
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Every ID-shaped token (`PSD-STS-8-SET-1`) in the sources, with the files naming it.
fn mentioned() -> BTreeMap<String, BTreeSet<PathBuf>> {
    let root = root();
    let me = Path::new(file!()).file_name().unwrap().to_owned();
    let mut files = Vec::new();
    for top in ["crates", "fuzz"] {
        rust_files(&root.join(top), &mut files);
    }
    let spec_crate = root.join("crates/spec");
    let mut ids: BTreeMap<String, BTreeSet<PathBuf>> = BTreeMap::new();
    for f in files {
        if f.starts_with(&spec_crate) || f.file_name() == Some(me.as_os_str()) {
            continue;
        }
        let Ok(text) = std::fs::read_to_string(&f) else {
            continue;
        };
        let token = |c: char| c.is_ascii_alphanumeric() || c == '-';
        for word in text.split(|c: char| !token(c)) {
            let word = word.trim_matches('-');
            if word.starts_with("PS") && word.contains('-') {
                ids.entry(word.to_owned()).or_default().insert(f.clone());
            }
        }
    }
    ids
}

fn exclusions(family: FamilyId) -> Option<Vec<Exclusion>> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join(format!("uncovered-{family}.toml"));
    let text = std::fs::read_to_string(&path).ok()?;
    let parsed: Exclusions =
        toml::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    Some(parsed.uncovered)
}

#[test]
fn every_must_requirement_is_covered_or_has_a_reason() {
    let spec = Spec::builtin().unwrap();
    let ids = mentioned();
    let mut problems = Vec::new();
    println!("requirement coverage (IDs named in crates/ and fuzz/ sources and tests):");
    for &family in REPORTED {
        let reqs = &spec.family(family).requirements;
        let must: Vec<_> = reqs.iter().filter(|r| r.level == Level::Must).collect();
        let covered_all = reqs.iter().filter(|r| ids.contains_key(&r.id)).count();
        let uncovered: Vec<_> = must.iter().filter(|r| !ids.contains_key(&r.id)).collect();
        let excl = exclusions(family).unwrap_or_default();
        let reasons: BTreeMap<&str, &str> = excl
            .iter()
            .map(|e| (e.id.as_str(), e.reason.as_str()))
            .collect();
        let unexplained: Vec<_> = uncovered
            .iter()
            .filter(|r| !reasons.contains_key(r.id.as_str()))
            .collect();
        let n_must = must.len();
        let n_cov = n_must - uncovered.len();
        let pct = |a: usize, b: usize| {
            if b == 0 {
                100.0
            } else {
                100.0 * a as f64 / b as f64
            }
        };
        println!(
            "  {family}: must {n_cov}/{n_must} covered ({:.1}%), {} excluded with a reason, {} \
             unexplained; all levels {covered_all}/{} ({:.1}%){}",
            pct(n_cov, n_must),
            uncovered.len() - unexplained.len(),
            unexplained.len(),
            reqs.len(),
            pct(covered_all, reqs.len()),
            if GATED.contains(&family) {
                ""
            } else {
                "  [reported, not gated]"
            }
        );
        if !GATED.contains(&family) {
            continue;
        }
        for r in &unexplained {
            println!("    uncovered {}: {}", r.id, r.text);
            problems.push(format!(
                "{family}: {} is not covered and has no reason in uncovered-{family}.toml",
                r.id
            ));
        }
        let mut seen = BTreeSet::new();
        for e in &excl {
            if !seen.insert(e.id.as_str()) {
                problems.push(format!("{family}: exclusion {} listed twice", e.id));
            }
            if e.reason.trim().len() < 10 {
                problems.push(format!("{family}: exclusion {} has no real reason", e.id));
            }
            match reqs.iter().find(|r| r.id == e.id) {
                None => problems.push(format!("{family}: exclusion {} is not a requirement", e.id)),
                Some(r) if r.level != Level::Must => problems.push(format!(
                    "{family}: exclusion {} is not a must requirement",
                    e.id
                )),
                Some(r) if ids.contains_key(&r.id) => problems.push(format!(
                    "{family}: exclusion {} is stale: covered in {}",
                    e.id,
                    ids[&r.id]
                        .iter()
                        .map(|p| p.strip_prefix(root()).unwrap_or(p).display().to_string())
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
                Some(_) => {}
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
