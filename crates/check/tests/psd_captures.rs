//! PSD4xx checks on PROFINET captures generated from the reference model: a clean run gives
//! no violation, each planted fault exactly its violations; the drive is found from the
//! Connect, from options and by the search.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_capture::profinet::Events;
use drivespec_capture::CaptureReader;
use drivespec_check::profinet::{check, Manual, PnOptions};
use drivespec_check::synth::profinet::{psd_capture, PsdFault, PsdScenario, IN_FRAME, OUT_FRAME};
use drivespec_check::Report;
use drivespec_spec::Spec;
use std::collections::BTreeMap;

fn run(spec: &Spec, bytes: &[u8], options: PnOptions) -> Report {
    let events = Events::new(CaptureReader::new(bytes).unwrap());
    check(spec, options, events).unwrap()
}

fn counts(r: &Report) -> BTreeMap<String, u64> {
    r.counts()
        .into_iter()
        .map(|(k, v)| (k.to_owned(), v))
        .collect()
}

#[test]
fn a_clean_capture_has_no_violation() {
    let spec = Spec::builtin().unwrap();
    let bytes = psd_capture(&spec, &PsdScenario::default()).unwrap();
    let r = run(&spec, &bytes, PnOptions::default());
    assert_eq!(r.drives.len(), 1, "{:?}", r.notes);
    assert_eq!(r.drives[0].found_by, "connect");
    assert!(r.clean(), "{:#?}", r.violations);
    assert!(r.requirements.contains_key("PSD-PKW-034"));
    assert!(r.frames["rt-cyclic"] > 1000, "{:?}", r.frames);
}

#[test]
fn each_planted_fault_gives_exactly_its_violations() {
    let spec = Spec::builtin().unwrap();
    let mut failures = Vec::new();
    for fault in PsdFault::ALL {
        let scenario = PsdScenario {
            faults: vec![fault],
            ..PsdScenario::default()
        };
        let bytes = psd_capture(&spec, &scenario).unwrap();
        let r = run(&spec, &bytes, PnOptions::default());
        let want: BTreeMap<String, u64> = fault
            .expected()
            .iter()
            .map(|(k, v)| ((*k).to_owned(), *v))
            .collect();
        if counts(&r) != want {
            failures.push(format!(
                "{fault:?}: got {:?}, want {want:?}\n{:#?}",
                counts(&r),
                r.violations
            ));
        }
        for v in &r.violations {
            assert!(v.at.frame.is_some() && v.at.time.is_some(), "{v:?}");
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_drive_is_found_by_options_and_by_search_without_a_connect() {
    let spec = Spec::builtin().unwrap();
    let scenario = PsdScenario {
        connect: false,
        faults: vec![PsdFault::ToggleNotEchoed],
        ..PsdScenario::default()
    };
    let bytes = psd_capture(&spec, &scenario).unwrap();
    let searched = run(&spec, &bytes, PnOptions::default());
    assert_eq!(searched.drives.len(), 1, "{:?}", searched.notes);
    let d = &searched.drives[0];
    assert_eq!(d.found_by, "search");
    assert!(d.confidence >= 0.75, "{d:?}");
    assert_eq!(d.details["out_offset"], 0);
    assert_eq!(d.details["in_offset"], 0);
    assert_eq!(counts(&searched).get("PSD-CTL-13-001"), Some(&1));
    let manual = PnOptions {
        manual: Some(Manual {
            out_frame: OUT_FRAME,
            in_frame: IN_FRAME,
            out_offset: 0,
            in_offset: 0,
        }),
        ..PnOptions::default()
    };
    let r = run(&spec, &bytes, manual);
    assert_eq!(r.drives[0].found_by, "options");
    assert_eq!(counts(&r).get("PSD-CTL-13-001"), Some(&1));
}

#[test]
fn without_psd4xx_data_nothing_is_found() {
    let spec = Spec::builtin().unwrap();
    let bytes = psd_capture(&spec, &PsdScenario::default()).unwrap();
    let options = PnOptions {
        module_ident: Some(0x1234),
        search: false,
        ..PnOptions::default()
    };
    let r = run(&spec, &bytes, options);
    assert!(r.drives.is_empty());
    assert!(r.clean(), "{:#?}", r.violations);
}
