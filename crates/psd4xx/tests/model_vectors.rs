//! The spec's vectors run against the reference model: every `sequence` vector of
//! `spec/psd4xx/vectors/process.toml` step by step, every `record` vector through the model's
//! record server and every `pkw` vector through its PKW server (manual 3.2.2, 3.6, 3.8, 3.9,
//! chapter 4).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_positioner::step::{read_sequence, Wait};
use drivespec_positioner::EnvChange;
use drivespec_psd4xx::model::{DriveConfig, LinkEvent, RecordAnswer, RecordRequest};
use drivespec_psd4xx::step::{Direction, Event, PsdSequence};
use drivespec_psd4xx::{Output, Pkw, PkwRequest, PkwResponse};
use drivespec_spec::hex::parse_hex;
use drivespec_spec::{IntOrText, Vector, VectorKind, VectorResult};
use model_util::*;
use std::collections::BTreeMap;

/// The model the vectors assume when they name none: limits ±805,200 at delivery (an
/// ungeared PSD4xx, 3.4).
const DEFAULT_MODEL: &str = "PSD401-5V";

fn vectors(kind: VectorKind) -> Vec<&'static Vector> {
    family().vectors.iter().filter(|v| v.kind == kind).collect()
}

/// A drive set up with a vector's `state`: "3" places the shaft, "13" names the model string,
/// everything else is written as a parameter.
fn setup(v: &Vector, state: Option<&BTreeMap<String, IntOrText>>) -> Sim {
    let model = v.model.as_deref().unwrap_or(DEFAULT_MODEL);
    let mut config = DriveConfig::new(model);
    if let Some(IntOrText::Int(p)) = state.and_then(|s| s.get("3")) {
        config = config.with_start_position(*p);
    }
    if let Some(IntOrText::Text(t)) = state.and_then(|s| s.get("13")) {
        config.model_string = Some(t.clone());
    }
    let mut s = Sim::with(config);
    if let Some(state) = state {
        // Mapping end before the limits, as 4.7 note 7 orders them.
        let mut keys: Vec<&String> = state.keys().collect();
        keys.sort_by_key(|k| (k.as_str() != "41", k.parse::<u32>().unwrap_or(0)));
        for k in keys
            .into_iter()
            .filter(|k| !matches!(k.as_str(), "3" | "13"))
        {
            let value = match &state[k] {
                IntOrText::Int(i) => *i,
                IntOrText::Text(t) => panic!("{}: par {k} = {t:?} is not a number", v.id),
            };
            match k.as_str() {
                "1" => reach_status(&mut s, value),
                "2" => reach_speed(&mut s, value),
                _ => s.write(k.parse().unwrap(), value),
            }
        }
    }
    s
}

/// Brings the drive into a documented status word (the vectors' live par. 1).
fn reach_status(s: &mut Sim, status: i64) {
    // A positioning run in loop direction clears bit 8 first.
    s.send(0x14, 4000);
    s.wait_idle();
    match status {
        // bits 0, 4: reached.
        0x11 => {}
        // bits 4, 6: running.
        0x50 => {
            s.send(0x14, 400_000);
            s.wait_running();
            s.step(500);
        }
        other => panic!("no recipe for status {other:#x}"),
    }
    assert_eq!(i64::from(s.status()), status, "{}", s.describe());
}

/// Brings the drive to a steady speed (the vectors' live par. 2) with a manual run.
fn reach_speed(s: &mut Sim, rpm: i64) {
    s.write(56, rpm.abs());
    s.control(if rpm < 0 { 0x12 } else { 0x11 });
    assert!(s.until(10_000, |s| s.drive.core().speed_rpm() == rpm));
}

fn run_sequence(v: &Vector) {
    let id = &v.id;
    let seq: PsdSequence = read_sequence(v).unwrap_or_else(|e| panic!("{id}: {e}"));
    let state: Option<BTreeMap<String, IntOrText>> = v
        .sequence()
        .and_then(|b| b.input.get("state"))
        .map(|t| t.clone().try_into().unwrap());
    let mut s = setup(v, state.as_ref());
    let window = s.par(44);
    for (n, step) in seq.input.steps.iter().enumerate() {
        let at = |s: &Sim, what: &str| format!("{id} step {n}: {what}; {}", s.describe());
        let start = s.actual();
        let mut jammed = false;
        match step.event {
            None => {}
            Some(Event::PowerOn) => s.drive.power_cycle(s.now),
            Some(Event::ObstructionDetected) => {
                s.env(EnvChange::Jam { on: true });
                jammed = true;
            }
            Some(Event::ManualRotationAtStandstill) => {
                let d = step.distance.unwrap();
                let by = match step.direction {
                    Some(Direction::Decreasing) => -d,
                    _ => d,
                };
                s.env(EnvChange::Displace { by });
            }
            Some(Event::MotorVoltageOutOfRange) => s.env(EnvChange::MotorVoltage { dv: 100 }),
            Some(Event::MotorVoltageInRange) => s.env(EnvChange::MotorVoltage { dv: 240 }),
            Some(Event::PositionOutsideWindowAfterRun) => {
                s.env(EnvChange::MissSteps { by: window + 1 })
            }
            Some(Event::ConnectionInterrupted) => s.link(LinkEvent::Lost),
            Some(Event::ConnectionRestored) => s.link(LinkEvent::Connected),
            Some(Event::IopsBad) => s.link(LinkEvent::IopsBad),
        }
        if let Some(c) = step.control {
            s.control = c;
        }
        if let Some(t) = step.target {
            s.target = t;
        }
        if let Some(o) = step.target_offset {
            s.target = (start + o) as i32;
        }
        s.cycle();
        let mut min = s.actual();
        let mut dropped = false;
        let mut track = |s: &Sim| {
            min = min.min(s.actual());
            if s.drive.core().run_kind().is_some() && !s.running() && s.actual() != start {
                dropped |= !s.idle();
            }
        };
        match step.wait {
            Wait::Running => {
                let ok = s.until(10_000, |s| {
                    track(s);
                    s.running()
                });
                assert!(ok, "{}", at(&s, "never running"));
            }
            Wait::Standstill => {
                let ok = s.until(600_000, |s| {
                    track(s);
                    s.idle()
                });
                assert!(ok, "{}", at(&s, "never at standstill"));
                s.step(1);
            }
            Wait::Settle => {
                for _ in 0..500 {
                    s.step(1);
                    track(&s);
                }
            }
        }
        if jammed {
            s.env(EnvChange::Jam { on: false });
        }
        for &b in &step.status_set {
            assert!(s.bit(b), "{}", at(&s, &format!("bit {b} should be set")));
        }
        for &b in &step.status_clear {
            assert!(!s.bit(b), "{}", at(&s, &format!("bit {b} should be clear")));
        }
        if let Some(want) = step.actual {
            assert!(
                s.actual().abs_diff(want) <= window as u64,
                "{}",
                at(&s, &format!("actual should be {want}"))
            );
        }
        if let Some(m) = step.min_position {
            assert_eq!(min, m, "{}", at(&s, "lowest position passed"));
        }
        if let Some(m) = step.min_position_offset {
            assert_eq!(min - start, m, "{}", at(&s, "lowest position passed"));
        }
        if step.no_intermediate_standstill == Some(true) {
            assert!(!dropped, "{}", at(&s, "the drive stopped in between"));
        }
    }
    if let Some(a) = seq.expect.actual {
        assert!(
            s.actual().abs_diff(a) <= window as u64,
            "{id}: final actual"
        );
    }
}

#[test]
fn every_sequence_vector_runs_on_the_model() {
    let list = vectors(VectorKind::Sequence);
    assert!(list.len() >= 25, "{} sequence vectors", list.len());
    for v in list {
        assert_eq!(v.result, VectorResult::Valid, "{}", v.id);
        run_sequence(v);
    }
}

fn state_matches(s: &Sim, id: &str, expect: &Option<BTreeMap<String, i64>>) {
    for (k, v) in expect.iter().flatten() {
        let pnu: u16 = k.parse().unwrap();
        assert_eq!(s.par(pnu), *v, "{id}: par {k} after");
    }
}

/// Each vector lists its requirements (PSD-REC-001..PSD-REC-010 among them).
#[test]
fn every_record_vector_runs_on_the_model() {
    let list = vectors(VectorKind::Record);
    assert!(!list.is_empty());
    for v in list {
        let id = &v.id;
        let b = v.record().unwrap();
        let mut s = setup(v, b.input.state.as_ref());
        let index = u16::try_from(b.input.index).unwrap();
        let req = match b.input.op.as_str() {
            "read" => RecordRequest::Read { index },
            "write" => RecordRequest::Write {
                index,
                data: parse_hex(b.input.data.as_deref().unwrap()).unwrap(),
            },
            other => panic!("{id}: op {other:?}"),
        };
        let answer = s
            .record(req)
            .result
            .unwrap_or_else(|e| panic!("{id}: {e:?}"));
        match (&answer, b.expect.data.as_deref()) {
            (RecordAnswer::Data { bytes }, Some(hex)) => {
                assert_eq!(bytes, &parse_hex(hex).unwrap(), "{id}: data")
            }
            (RecordAnswer::Written | RecordAnswer::Ignored, Some("")) => {}
            (RecordAnswer::Data { bytes }, None) => {
                let text = b.expect.text.as_deref().unwrap();
                let until_nul: Vec<u8> = bytes.iter().copied().take_while(|b| *b != 0).collect();
                assert_eq!(until_nul, text.as_bytes(), "{id}: text");
            }
            other => panic!("{id}: {other:?}"),
        }
        state_matches(&s, id, &b.expect.state);
    }
}

/// Each vector lists its requirements; among them the block layout and codes (PSD-PKW-008,
/// PSD-PKW-009, PSD-PKW-011, PSD-PKW-020, PSD-PKW-021) and the model string segments
/// (PSD-PKW-015, PSD-PKW-018, PSD-PKW-035, PSD-PKW-036, PSD-PKW-037).
#[test]
fn every_pkw_vector_runs_on_the_model() {
    let list = vectors(VectorKind::Pkw);
    assert!(list.len() >= 25);
    for v in list {
        let id = &v.id;
        let b = v.pkw().unwrap();
        let mut s = setup(v, b.input.state.as_ref());
        let rules = s.rules().clone();
        let req_bytes = parse_hex(b.input.bytes.as_deref().unwrap()).unwrap();
        let req: PkwRequest = Pkw::parse(rules.pkw(), &req_bytes).unwrap();
        // A fresh command: the controller sends "no command" first (PSD-PKW-005).
        let out = Output {
            control: s.control,
            target: s.target,
            ..Output::idle(&rules)
        };
        s.drive.handle_output(s.now, &out);
        s.drive.handle_output(s.now, &Output { pkw: req, ..out });
        let (_, input) = std::iter::from_fn(|| s.drive.poll_input()).last().unwrap();
        let want = parse_hex(b.expect.bytes.as_deref().unwrap()).unwrap();
        let got: PkwResponse = input.pkw;
        assert_eq!(got.to_bytes(rules.pkw()).unwrap(), want, "{id}: response");
        state_matches(&s, id, &b.expect.state);
    }
}
