//! The fuzzer against the correct reference model on `sim`: a long fixed-seed run finds
//! nothing and covers the generator's classes; the same seed gives the same run.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod support;

use drivespec_conform::Progress;
use drivespec_fuzz::{self as fuzz, Options};
use drivespec_implementations::spec;

fn opts(seed: u64, iterations: u64) -> Options {
    let mut o = Options {
        iterations: Some(iterations),
        no_reports: true,
        progress: Progress::Quiet,
        ..Options::default()
    };
    o.settings.seed = seed;
    o
}

#[test]
fn a_long_run_against_the_reference_finds_nothing() {
    let s = fuzz::run(spec(), &opts(42, 1000), &mut std::io::sink()).unwrap();
    let st = &s.stats;
    assert!(s.findings.is_empty(), "{:#?}", st.findings);
    assert_eq!(s.exit_code(), 0);
    assert_eq!(st.sequences, 1000);
    assert!(st.inputs > 8_000, "{}", st.inputs);
    assert_eq!(st.stopped_by, "iterations");
    for class in [
        "valid-read",
        "valid-write",
        "boundary-write",
        "out-of-range-write",
        "read-only-write",
        "bit-change",
        "read-only-bit",
        "command",
        "broadcast",
        "foreign-address",
        "bad-checksum",
        "bad-stuffing",
        "truncated",
        "over-long",
        "wrong-lun",
        "split-timeout",
        "split-within",
        "noise",
        "plc-upload",
        "plc-bad-program",
        "plc-run-stop",
        "plc-vector",
        "suite-case",
        "inputs",
        "power-cycle",
        "mutated-bytes",
    ] {
        assert!(
            st.inputs_by_class.get(class).copied().unwrap_or(0) > 0,
            "no {class} input: {:?}",
            st.inputs_by_class
        );
    }
    for verdict in ["answer", "silence"] {
        assert!(st.answers_by_verdict.get(verdict).copied().unwrap_or(0) > 100);
    }
    assert!(!st.answers_by_verdict.contains_key("mismatch"));
    assert!(
        st.requirements_touched.len() > 150,
        "{}",
        st.requirements_touched.len()
    );
    // The report: one passing case and the coverage of the requirements touched.
    assert_eq!(s.report.summary.failed, 0);
    assert_eq!(s.report.cases.len(), 1);
    assert!(s
        .report
        .coverage
        .iter()
        .any(|c| c.requirement == "HPD-FRAME-009"));
}

#[test]
fn the_same_seed_gives_the_same_run() {
    let a = fuzz::run(spec(), &opts(7, 60), &mut std::io::sink()).unwrap();
    let b = fuzz::run(spec(), &opts(7, 60), &mut std::io::sink()).unwrap();
    let c = fuzz::run(spec(), &opts(8, 60), &mut std::io::sink()).unwrap();
    assert_eq!(a.stats.inputs_by_class, b.stats.inputs_by_class);
    assert_eq!(a.stats.answers_by_verdict, b.stats.answers_by_verdict);
    assert_eq!(a.stats.requirements_touched, b.stats.requirements_touched);
    assert_ne!(a.stats.inputs_by_class, c.stats.inputs_by_class);
}
