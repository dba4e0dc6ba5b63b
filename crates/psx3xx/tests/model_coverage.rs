//! Every requirement ID the PSx3xx reference model cites exists in the spec and is named by a
//! model test: in a test's name (`psx_cmd_001_…`), in a test comment, or in the requirement
//! list of a vector the model tests run (`sequence`, `position`, `formula`).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

mod model_util;

use drivespec_spec::VectorKind;
use model_util::family;
use std::collections::BTreeSet;

const SOURCES: &[&str] = &[
    include_str!("../src/model/mod.rs"),
    include_str!("../src/model/config.rs"),
    include_str!("../src/model/control.rs"),
    include_str!("../src/model/drive.rs"),
    include_str!("../src/model/error.rs"),
    include_str!("../src/model/family.rs"),
    include_str!("../src/model/io.rs"),
    include_str!("../src/model/server.rs"),
];

const TESTS: &[&str] = &[
    include_str!("model_errata.rs"),
    include_str!("model_features.rs"),
    include_str!("model_parameters.rs"),
    include_str!("model_position.rs"),
    include_str!("model_positioning.rs"),
    include_str!("model_props.rs"),
    include_str!("model_requirements.rs"),
    include_str!("model_traces.rs"),
    include_str!("model_vectors.rs"),
];

/// Requirement IDs in a text: `PSX-` followed by dash-separated upper-case words.
fn ids(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let bytes = text.as_bytes();
    let mut i = 0;
    while let Some(at) = text[i..].find("PSX-") {
        let start = i + at;
        let mut end = start + 4;
        while end < bytes.len()
            && (bytes[end].is_ascii_uppercase()
                || bytes[end].is_ascii_digit()
                || (bytes[end] == b'-'
                    && end + 1 < bytes.len()
                    && (bytes[end + 1].is_ascii_uppercase() || bytes[end + 1].is_ascii_digit())))
        {
            end += 1;
        }
        out.insert(text[start..end].to_owned());
        i = end;
    }
    out
}

/// Test function names as requirement prefixes: `fn psx_cmd_001_004_x` names PSX-CMD-001 and
/// PSX-CMD-004 (a run of numbers after the group).
fn named_by_tests() -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for t in TESTS {
        out.extend(ids(t));
        for line in t.lines() {
            let Some(name) = line.trim().strip_prefix("fn psx_") else {
                continue;
            };
            let name: String = name.chars().take_while(|c| *c != '(').collect();
            let parts: Vec<&str> = name.split('_').collect();
            // psx_<group>[_<sub>]_<n>[_<n>…]_<words>
            for split in 1..parts.len() {
                let head = parts[..split].join("-").to_uppercase();
                for n in parts[split..].iter().take_while(|p| {
                    p.chars()
                        .all(|c| c.is_ascii_digit() || c.is_ascii_uppercase())
                }) {
                    out.insert(format!("PSX-{head}-{}", n.to_uppercase()));
                }
            }
        }
    }
    for v in &family().vectors {
        if matches!(
            v.kind,
            VectorKind::Sequence | VectorKind::Position | VectorKind::Formula
        ) {
            out.extend(v.requirements.iter().cloned());
        }
    }
    out
}

#[test]
fn every_cited_requirement_exists_and_is_tested() {
    let fam = family();
    let cited: BTreeSet<String> = SOURCES.iter().flat_map(|s| ids(s)).collect();
    assert!(cited.len() >= 100, "only {} IDs cited", cited.len());
    let unknown: Vec<&String> = cited
        .iter()
        .filter(|id| fam.requirement(id).is_none() && fam.errata.iter().all(|e| &e.id != *id))
        .collect();
    assert!(unknown.is_empty(), "IDs not in the spec: {unknown:?}");
    let tested = named_by_tests();
    let untested: Vec<&String> = cited
        .iter()
        .filter(|id| !id.contains("ERRATUM") && !tested.contains(*id))
        .collect();
    assert!(
        untested.is_empty(),
        "cited but named by no test: {untested:?}"
    );
}
