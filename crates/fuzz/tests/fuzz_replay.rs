//! Replay files: the same seed writes the same files byte for byte, a replay gives the same
//! exchange byte for byte every time, `minimize` shortens a padded replay, and the reports
//! come in the conform formats with the fuzz statistics.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod support;

use drivespec_conform::dut::Dut;
use drivespec_conform::Progress;
use drivespec_fuzz::{self as fuzz, Action, Options, Replay, Step};
use drivespec_hpd::step::{Compare, Step as HpdStep};
use drivespec_implementations::hpd_mutants::{Kind, Mutant};
use drivespec_implementations::spec;
use drivespec_sim::SimLink;
use std::path::PathBuf;

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("drivespec-fuzz-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn mutant() -> Box<SimLink> {
    Box::new(SimLink::new(
        "mutant: answers not stuffed",
        Box::new(Mutant::new(Kind::NoStuffing)),
    ))
}

fn opts(out: PathBuf) -> Options {
    Options {
        iterations: Some(40),
        out_dir: out,
        progress: Progress::Quiet,
        ..Options::default()
    }
}

#[test]
fn replays_are_deterministic_and_minimise() {
    let (d1, d2) = (dir("a"), dir("b"));
    let a = fuzz::run_on(spec(), &opts(d1.clone()), mutant(), &mut std::io::sink()).unwrap();
    let b = fuzz::run_on(spec(), &opts(d2.clone()), mutant(), &mut std::io::sink()).unwrap();
    assert_eq!(a.exit_code(), 1);
    assert!(!a.findings.is_empty());
    // The same seed: the same replay files, byte for byte.
    for f in &a.findings {
        let p1 = f.file.as_ref().unwrap();
        let p2 = d2.join(p1.file_name().unwrap());
        assert_eq!(
            std::fs::read(p1).unwrap(),
            std::fs::read(&p2).unwrap(),
            "{}",
            p1.display()
        );
    }
    assert_eq!(a.stats.findings.len(), b.stats.findings.len());

    // A replay gives the recorded exchange byte for byte, every time.
    let file = a.findings[0].file.clone().unwrap();
    let r = Replay::load(&file).unwrap();
    let info = r.finding.clone().unwrap();
    assert!(info.reproduced);
    assert!(r.steps.len() <= 2, "{}", r.to_json());
    let o = opts(dir("c"));
    let x = fuzz::replay_on(spec(), &o, &r, mutant()).unwrap();
    let y = fuzz::replay_on(spec(), &o, &r, mutant()).unwrap();
    assert!(x.same_as_recorded && x.same_finding, "{:#?}", x.exchanges);
    assert_eq!(x.exchanges, y.exchanges);
    assert_eq!(x.exit_code(), 1);
    assert_eq!(x.fault.as_ref().unwrap().1, info.signature);
    // Against the reference (--dut sim) it passes.
    let on_sim = fuzz::replay(
        spec(),
        &Options {
            dut: Dut::default(),
            ..o.clone()
        },
        &r,
    )
    .unwrap();
    assert_eq!(on_sim.exit_code(), 0);
    assert!(!on_sim.same_finding);

    // Padding in front and behind is minimised away again.
    let read = |par: u8| Step {
        action: Action::Hpd(HpdStep::Exchange {
            bytes: drivespec_hpd::Message::ReadParam {
                addr: 0,
                lun: 2,
                par,
            }
            .to_bytes(&drivespec_hpd::FrameRules::from_spec(spec()).unwrap())
            .unwrap(),
            compare: Compare::Exact,
            silence_ok: false,
        }),
        class: "valid-read".into(),
        text: "padding".into(),
        requirements: vec![],
    };
    let mut padded = r.clone();
    padded.steps = [read(0xC6), read(0x54)]
        .into_iter()
        .chain(r.steps.iter().cloned())
        .chain([read(0xC6)])
        .collect();
    padded.finding = None;
    padded.exchanges.clear();
    let m = fuzz::minimize_on(spec(), &o, &padded, mutant())
        .unwrap()
        .unwrap();
    assert!(m.steps.len() <= r.steps.len(), "{}", m.to_json());
    assert!(m
        .steps
        .iter()
        .all(|s| s.text != "padding" || r.steps.len() > 2));
    // A replay that passes has nothing to minimise.
    assert!(fuzz::minimize(spec(), &o, &r).unwrap().is_none());

    // The reports: the conform formats plus the fuzz statistics.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d1.join("fuzz.json")).unwrap()).unwrap();
    assert_eq!(json["schema"], "drivespec-conform/1");
    assert_eq!(json["fuzz"]["schema"], "drivespec-fuzz/1");
    assert_eq!(
        json["summary"]["failed"].as_u64().unwrap() as usize,
        a.findings.len()
    );
    assert!(json["cases"][0]["replay"]
        .as_str()
        .unwrap()
        .contains("--replay"));
    assert!(json["fuzz"]["inputs_by_class"].as_object().unwrap().len() > 10);
    let junit = std::fs::read_to_string(d1.join("fuzz.junit.xml")).unwrap();
    assert!(junit.contains("<testsuites name=\"drivespec fuzz\"") && junit.contains("<failure"));
    assert!(junit.contains("fuzz.sequences"));
    let html = std::fs::read_to_string(d1.join("fuzz.html")).unwrap();
    assert!(html.contains("<h2>Fuzzing</h2>") && html.contains("drivespec fuzz hpd"));
    for d in [d1, d2] {
        std::fs::remove_dir_all(d).unwrap();
    }
}
