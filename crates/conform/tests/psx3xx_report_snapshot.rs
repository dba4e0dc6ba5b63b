//! Snapshots of the JSON and JUnit reports of a small PSx3xx run against `sim` (`--case`
//! globs): the guard entry of ISDU 111, an unknown index, and a time-stamp positioning with its
//! plot data. Wall times are normalised; the coverage matrix keeps the rows these cases touch.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

#[path = "support/report.rs"]
mod report;

use drivespec_conform::report::junit;
use drivespec_conform::{run, Options, Progress, Summary};
use drivespec_spec::{FamilyId, Spec};

fn small_run() -> Summary {
    let spec = Spec::builtin().unwrap();
    let opts = Options {
        families: vec![FamilyId::Psx3xx],
        case: vec![
            "psx3xx/guard/111/s*".into(),
            "psx3xx/isdu/unknown-index/65535".into(),
            "psx3xx/timestamp/edge/first-*".into(),
        ],
        progress: Progress::Quiet,
        no_reports: true,
        ..Options::default()
    };
    let s = run(&spec, &opts, &mut std::io::sink()).unwrap();
    assert_eq!(s.report.cases.len(), 3);
    s
}

#[test]
fn psx3xx_json_report_of_a_small_run() {
    let s = small_run();
    let v = report::normalised(&s.report.json());
    insta::assert_json_snapshot!(v);
}

#[test]
fn psx3xx_junit_report_of_a_small_run() {
    let mut report = small_run().report;
    // The start time and host are the machine's.
    report.timing = None;
    let x = junit(&report);
    let mut out = String::new();
    for line in x.lines() {
        // time="…" is wall-clock time.
        let mut l = line.to_owned();
        while let Some(i) = l.find("time=\"") {
            let rest = &l[i + 6..];
            let end = rest.find('"').unwrap();
            l = format!("{}TIME={}", &l[..i], &rest[end + 1..]);
        }
        out.push_str(&l);
        out.push('\n');
    }
    insta::assert_snapshot!(out);
}
