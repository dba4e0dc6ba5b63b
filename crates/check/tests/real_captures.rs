//! The real PROFINET captures in `shared/captures/` (when that folder exists) are checked
//! without error; the generic checks' findings per file are the expectations in
//! `real_captures.toml` (none of these captures holds a PSD4xx).
//!
//! The text report of each is an insta snapshot (`snapshots/`), with the file named by its
//! base name.
//!
//! Set `DRIVESPEC_CAPTURES` to read another folder; `DRIVESPEC_PRINT_FINDINGS=1` prints the
//! findings as TOML (to update the expectations after reviewing them).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_check::run::{check_path, RunOptions};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Expectations {
    #[allow(dead_code)]
    note: String,
    #[serde(default)]
    file: Vec<Expected>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Expected {
    name: String,
    events: u64,
    rt_cyclic: u64,
    drives: usize,
    violations: BTreeMap<String, u64>,
    verdict: String,
    #[allow(dead_code)]
    note: Option<String>,
}

fn captures_dir() -> PathBuf {
    match std::env::var_os("DRIVESPEC_CAPTURES") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/captures"),
    }
}

#[test]
fn real_captures_check_without_error_and_give_the_recorded_findings() {
    let dir = captures_dir();
    if !dir.is_dir() {
        println!("skipped: no capture folder at {}", dir.display());
        return;
    }
    let spec = drivespec_spec::Spec::builtin().unwrap();
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/real_captures.toml"),
    )
    .unwrap();
    let expected: Expectations = toml::from_str(&text).unwrap();
    let print = std::env::var_os("DRIVESPEC_PRINT_FINDINGS").is_some();
    let mut names: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy().to_string();
            n.ends_with(".pcap") || n.ends_with(".pcapng") || n.ends_with(".gz")
        })
        .collect();
    names.sort();
    let mut mismatches = Vec::new();
    for path in &names {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let r = check_path(&spec, path, &RunOptions::default(), &mut |_| {})
            .unwrap_or_else(|e| panic!("{e}"));
        assert!(r.error.is_none(), "{name}: {:?}", r.error);
        let found: BTreeMap<String, u64> = r
            .counts()
            .into_iter()
            .map(|(k, v)| (k.to_owned(), v))
            .collect();
        let rt = r.frames.get("rt-cyclic").copied().unwrap_or(0);
        let verdict = serde_json::to_value(r.verdict).unwrap();
        let verdict = verdict.as_str().unwrap_or("");
        if print {
            println!("[[file]]\nname = {name:?}\nevents = {}\nrt_cyclic = {rt}\ndrives = {}\nviolations = {{ {} }}\n",
                r.events, r.drives.len(),
                found.iter().map(|(k, v)| format!("\"{k}\" = {v}")).collect::<Vec<_>>().join(", "));
        }
        match expected.file.iter().find(|e| e.name == name) {
            Some(e) => {
                if e.events != r.events
                    || e.rt_cyclic != rt
                    || e.drives != r.drives.len()
                    || e.violations != found
                    || e.verdict != verdict
                {
                    mismatches.push(format!(
                        "{name}: events {} rt_cyclic {rt} drives {} violations {found:?} verdict {verdict}",
                        r.events,
                        r.drives.len()
                    ));
                }
            }
            None => mismatches.push(format!("{name}: not in real_captures.toml")),
        }
    }
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
}

#[test]
fn real_captures_give_the_recorded_text_reports() {
    if std::env::var_os("DRIVESPEC_CAPTURES").is_some() {
        println!("skipped: the snapshots are of shared/captures, not DRIVESPEC_CAPTURES");
        return;
    }
    let dir = captures_dir();
    if !dir.is_dir() {
        println!("skipped: no capture folder at {}", dir.display());
        return;
    }
    let spec = drivespec_spec::Spec::builtin().unwrap();
    let mut names: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy().to_string();
            n.ends_with(".pcap") || n.ends_with(".pcapng")
        })
        .collect();
    names.sort();
    for path in &names {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let mut r = check_path(&spec, path, &RunOptions::default(), &mut |_| {}).unwrap();
        r.file = Some(name.clone());
        insta::assert_snapshot!(name, drivespec_check::render::text(&[r]));
    }
}
