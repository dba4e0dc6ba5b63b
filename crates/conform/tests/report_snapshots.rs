//! Snapshots of the JSON and JUnit reports of a small run against `sim`: a passing case, a
//! corrupt-frame case, a case the expectations file lists although it passes (`fixed`), and a
//! stale expectations entry. Wall-clock times and the temporary path are normalised.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

#[path = "support/report.rs"]
mod report;

use drivespec_conform::report::junit;
use drivespec_conform::{run, Options, Progress};
use drivespec_spec::Spec;

fn small_run(tag: &str) -> drivespec_conform::Summary {
    let dir = std::env::temp_dir().join(format!("conform-snap-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let expect = dir.join("expect.toml");
    std::fs::write(
        &expect,
        "[[failure]]\ncase = \"hpd/frame/read-lun-1\"\nreason = \"thought to answer 2 bytes\"\n\n\
         [[failure]]\ncase = \"hpd/param/Pr999/*\"\nreason = \"no such parameter\"\n",
    )
    .unwrap();
    let spec = Spec::builtin().unwrap();
    let opts = Options {
        case: vec![
            "hpd/frame/read-parameter".into(),
            "hpd/frame/checksum-bad/read-parameter".into(),
            "hpd/frame/read-lun-1".into(),
        ],
        expect: Some(expect),
        progress: Progress::Quiet,
        no_reports: true,
        ..Options::default()
    };
    let s = run(&spec, &opts, &mut std::io::sink()).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    s
}

#[test]
fn json_report_of_a_small_run() {
    let s = small_run("json");
    let mut v = report::normalised(&s.report.json());
    v["run"]["expectations"] = "EXPECT.toml".into();
    insta::assert_json_snapshot!(v);
    assert_eq!(s.exit_code(), 0);
}

#[test]
fn junit_report_of_a_small_run() {
    let mut report = small_run("junit").report;
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
