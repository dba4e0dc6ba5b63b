//! Snapshot of the JSON report of a small PSD4xx run against `sim`: a PKW read, a record
//! write ignored for control byte 0, and a short positioning case with its plot data. Wall
//! times are normalised; the coverage matrix keeps the rows these cases touch.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

#[path = "support/report.rs"]
mod report;

use drivespec_conform::{run, Options, Progress};
use drivespec_spec::{FamilyId, Spec};

#[test]
fn psd4xx_json_report_of_a_small_run() {
    let spec = Spec::builtin().unwrap();
    let opts = Options {
        families: vec![FamilyId::Psd4xx],
        case: vec![
            "psd4xx/pkw/read/44".into(),
            "psd4xx/record/write/44/control-0".into(),
            "psd4xx/status/incorrect-target".into(),
        ],
        progress: Progress::Quiet,
        no_reports: true,
        ..Options::default()
    };
    let s = run(&spec, &opts, &mut std::io::sink()).unwrap();
    let v = report::normalised(&s.report.json());
    insta::assert_json_snapshot!(v);
}
