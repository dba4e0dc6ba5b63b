//! IO-Link checks on logs built with the PSx3xx codec after the manual's sequences, in both
//! log forms: a clean log gives no violation, each planted fault exactly its violations.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_capture::iolink::IoLinkReader;
use drivespec_check::iolink::{check, PsxOptions};
use drivespec_check::synth::iolink::{psx_log, to_csv, to_jsonl, PsxFault};
use drivespec_check::Report;
use drivespec_spec::Spec;
use std::collections::BTreeMap;

fn run(spec: &Spec, text: &str) -> Report {
    let reader = IoLinkReader::open(text.as_bytes()).unwrap();
    check(spec, PsxOptions::default(), reader).unwrap()
}

fn counts(r: &Report) -> BTreeMap<String, u64> {
    r.counts()
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v))
        .collect()
}

#[test]
fn a_clean_log_has_no_violation_in_either_form() {
    let spec = Spec::builtin().unwrap();
    let events = psx_log(&spec, &[]).unwrap();
    for (name, text) in [("jsonl", to_jsonl(&events)), ("csv", to_csv(&events))] {
        let r = run(&spec, &text);
        assert!(r.clean(), "{name}: {:#?}\n{:?}", r.violations, r.notes);
        assert_eq!(r.drives.len(), 2, "{name}");
        assert!(r.frames["pd"] > 100, "{name}: {:?}", r.frames);
        assert_eq!(
            r.frames.get("unreadable line"),
            None,
            "{name}: {:?}",
            r.notes
        );
    }
}

#[test]
fn each_planted_fault_gives_exactly_its_violations() {
    let spec = Spec::builtin().unwrap();
    let mut failures = Vec::new();
    for fault in PsxFault::ALL {
        let events = psx_log(&spec, &[fault]).unwrap();
        for (name, text) in [("jsonl", to_jsonl(&events)), ("csv", to_csv(&events))] {
            let r = run(&spec, &text);
            let want: BTreeMap<String, u64> = fault
                .expected()
                .iter()
                .map(|(k, v)| ((*k).to_owned(), *v))
                .collect();
            if counts(&r) != want {
                failures.push(format!(
                    "{fault:?} in {name}: got {:?}, want {want:?}\n{:#?}",
                    counts(&r),
                    r.violations
                ));
            }
            for v in &r.violations {
                assert!(v.at.line.is_some() && v.at.time.is_some(), "{v:?}");
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
