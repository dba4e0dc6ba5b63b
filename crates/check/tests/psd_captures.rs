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
use drivespec_check::run::{check_path, RunOptions};
use drivespec_check::synth::profinet::{psd_capture, PsdFault, PsdScenario, IN_FRAME, OUT_FRAME};
use drivespec_check::{Policy, Report, Verdict};
use drivespec_spec::Spec;
use std::collections::BTreeMap;

fn run(spec: &Spec, bytes: &[u8], options: PnOptions) -> Report {
    let events = Events::new(CaptureReader::new(bytes).unwrap());
    check(spec, options, events).unwrap()
}

/// A classic pcap file without its last `n` records.
fn without_last(pcap: &[u8], n: usize) -> Vec<u8> {
    let mut starts = Vec::new();
    let mut at = 24;
    while at + 16 <= pcap.len() {
        starts.push(at);
        let len = u32::from_le_bytes(pcap[at + 8..at + 12].try_into().unwrap()) as usize;
        at += 16 + len;
    }
    pcap[..starts[starts.len() - n]].to_vec()
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

/// A capture of a drive left idle for 3 s (1 ms cycle) before the controller talks to it,
/// without a Connect: the search finds the drive when its PKW traffic starts, and the checks
/// run from the capture's start — in a second pass for a file, from the stretch where it
/// was found for an input read once.
#[test]
fn a_drive_idle_for_3_s_is_found_and_checked() {
    let spec = Spec::builtin().unwrap();
    let scenario = PsdScenario {
        connect: false,
        idle_start: 3000,
        faults: vec![PsdFault::ToggleNotEchoed],
        ..PsdScenario::default()
    };
    let bytes = psd_capture(&spec, &scenario).unwrap();
    let once = run(&spec, &bytes, PnOptions::default());
    assert_eq!(once.drives.len(), 1, "{:?}", once.notes);
    assert_eq!(once.drives[0].found_by, "search");
    assert_eq!(counts(&once).get("PSD-CTL-13-001"), Some(&1));
    assert!(
        once.notes
            .iter()
            .any(|n| n.contains("cannot be read twice")),
        "{:?}",
        once.notes
    );
    let path = std::env::temp_dir().join(format!("drivespec-idle-{}.pcap", std::process::id()));
    std::fs::write(&path, &bytes).unwrap();
    let file = check_path(&spec, &path, &RunOptions::default(), &mut |_| {});
    let _ = std::fs::remove_file(&path);
    let file = file.unwrap();
    assert_eq!(file.drives.len(), 1, "{:?}", file.notes);
    let want: BTreeMap<String, u64> = [("PSD-CTL-13-001".to_owned(), 1)].into();
    assert_eq!(counts(&file), want, "{:#?}", file.violations);
    assert_eq!(counts(&once), want, "{:#?}", once.violations);
    assert!(
        file.notes.iter().any(|n| n.contains("second pass")),
        "{:?}",
        file.notes
    );
    assert!(file.scopes.iter().all(|s| s.ran), "{:?}", file.scopes);
    assert_eq!(file.verdict, Verdict::Fail);
}

/// Without a drive, the PSD4xx checks did not run: the result says so, and a required
/// family makes the verdict fail.
#[test]
fn a_missing_required_drive_fails() {
    let spec = Spec::builtin().unwrap();
    let bytes = psd_capture(&spec, &PsdScenario::default()).unwrap();
    let options = PnOptions {
        module_ident: Some(0x1234),
        search: false,
        ..PnOptions::default()
    };
    let mut r = run(&spec, &bytes, options);
    assert_eq!(r.verdict, Verdict::Pass);
    assert_eq!(r.scope_line(), "PROFINET: pass; PSD4xx: no drive found");
    r.judge(Policy {
        strict: false,
        require: vec!["psd4xx".into()],
    });
    assert_eq!(r.verdict, Verdict::Fail);
}

/// A controller that goes to STOP and then releases the AR (shutting down) violates nothing:
/// the STOP from RUN to the Release is listed as an allowed state with its end at the
/// Release; the same STOP without the Release stays a `should` finding.
#[test]
fn a_controller_in_stop_until_its_release_is_no_violation() {
    let spec = Spec::builtin().unwrap();
    let scenario = PsdScenario {
        stop_before_release: true,
        ..PsdScenario::default()
    };
    let bytes = psd_capture(&spec, &scenario).unwrap();
    let r = run(&spec, &bytes, PnOptions::default());
    assert_eq!(r.drives.len(), 1, "{:?}", r.notes);
    assert_eq!(counts(&r), BTreeMap::new(), "{:#?}", r.violations);
    assert_eq!(r.verdict, Verdict::Pass);
    let shutdown = r
        .allowed
        .iter()
        .find(|a| a.requirement == "PN-RT-DS-002")
        .unwrap();
    assert!(shutdown.message.contains("Release"), "{shutdown:?}");
    assert!(shutdown.end.unwrap().frame > shutdown.start.frame);
    // Without the Release (its request and answer: the last two records) the STOP is still
    // a finding.
    let r = run(&spec, &without_last(&bytes, 2), PnOptions::default());
    let want: BTreeMap<String, u64> = [("PN-RT-DS-002".to_owned(), 1)].into();
    assert_eq!(counts(&r), want, "{:#?}", r.violations);
}

/// A controller in STOP from its first frame (start-up) and one that goes to STOP during a
/// run with bad IOPS and zeroed outputs: the drive keeps the last valid outputs (3.9), so
/// its toggle echo keeps the old value. Neither is a `must` violation; the start-up STOP
/// and the bad IOPS in STOP are listed as allowed states with start, end and duration,
/// the STOP after RUN is a `should` finding (a warning).
#[test]
fn a_controller_in_stop_is_no_violation() {
    let spec = Spec::builtin().unwrap();
    let scenario = PsdScenario {
        startup_stop: 30,
        stop_during_run: true,
        ..PsdScenario::default()
    };
    let bytes = psd_capture(&spec, &scenario).unwrap();
    let r = run(&spec, &bytes, PnOptions::default());
    assert_eq!(r.drives.len(), 1, "{:?}", r.notes);
    let want: BTreeMap<String, u64> = [("PN-RT-DS-002".to_owned(), 1)].into();
    assert_eq!(counts(&r), want, "{:#?}", r.violations);
    assert_eq!(r.must_count(), 0);
    assert_eq!(r.verdict, Verdict::Warn);
    // The STOP after RUN is a condition with an end and a duration (50 cycles).
    let stop = &r.violations[0];
    assert!(stop.end.is_some(), "{stop:?}");
    assert_eq!(stop.duration_us, Some(50_000), "{stop:?}");
    let startup = r
        .allowed
        .iter()
        .find(|a| a.requirement == "PN-RT-DS-002")
        .unwrap();
    assert!(startup.message.contains("start-up"), "{startup:?}");
    let end = startup.end.unwrap();
    assert!(startup.duration_us.unwrap() >= 29_000, "{startup:?}");
    assert!(end.frame > startup.start.frame);
    let iops: Vec<_> = r
        .allowed
        .iter()
        .filter(|a| a.requirement == "PN-IO-IOPS-001")
        .collect();
    assert_eq!(iops.len(), 1, "{:#?}", r.allowed);
    assert!(iops[0].duration_us.is_some_and(|d| d >= 49_000), "{iops:?}");
    let mut strict = r.clone();
    strict.judge(Policy {
        strict: true,
        require: Vec::new(),
    });
    assert_eq!(strict.verdict, Verdict::Fail);
}
