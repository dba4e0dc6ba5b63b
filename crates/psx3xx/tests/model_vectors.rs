//! The `sequence` vectors of `spec/psx3xx/vectors` (process.toml and isdu.toml) run against
//! the reference model, step by step: what the master sends or the environment does, and what
//! the drive must show. Every vector is run and reported; `valid` ones must pass, `acceptable`
//! ones may go either way (rustls bogo style: collect all, assert once).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

mod model_util;

use drivespec_positioner::step::{read_sequence, StateValue};
use drivespec_positioner::{CoreEvent, EnvChange};
use drivespec_psx3xx::isdu::{Response, Value};
use drivespec_psx3xx::model::{DriveConfig, Event, JogKeys, LinkEvent};
use drivespec_psx3xx::step::{
    Direction, Event as StepEvent, Expect, Input, IsduOp, Key, LoopSide, ProcessData, PsxSequence,
    Run, VectorStep,
};
use drivespec_psx3xx::Output;
use drivespec_spec::{Vector, VectorKind, VectorResult};
use model_util::*;

/// Builds the drive of a vector: model, software version and model code from the state, the
/// process-data format saved and made active by a reset, the other state entries written.
fn setup(v: &Vector, input: &Input) -> Result<Sim, String> {
    let state = &input.state;
    let int = |k: &str| state.get(k).and_then(StateValue::int);
    let mut config = DriveConfig::new(v.model.as_deref().unwrap_or("PSE312-8"));
    if let Some(sw) = int("80") {
        config.software_version = Some(sw as u16);
    }
    if let Some(code) = int("79") {
        config.model_code = Some(code as u16);
    }
    // ISDU 67 in a state is where the shaft stands (referencing value 0).
    if let Some(pos) = int("67") {
        config.start_position = Some(pos);
    }
    let mut s = Sim::with(config);
    let format = int("116").or(input.format.map(i64::from));
    if let Some(f) = format.filter(|f| *f != i64::from(s.drive.active_format())) {
        s.write_ok(116, f);
        s.write_ok(193, 1);
        s.write_ok(2, 128);
    }
    for (k, val) in state {
        if ["67", "80", "79", "116"].contains(&k.as_str()) {
            continue;
        }
        let index: u16 = k.parse().map_err(|_| format!("state key {k}"))?;
        let r = s.write(index, val.int().unwrap_or(0));
        if r != Response::Write {
            return Err(format!("state {k} = {val:?}: {r:?}"));
        }
    }
    while s.drive.poll_event().is_some() {}
    Ok(s)
}

fn pd(s: &mut Sim, t: &ProcessData) {
    let out = match s.drive.active_format() {
        0 => Output::TimeStamp {
            control: drivespec_psx3xx::TsCode(t.control.unwrap_or(0)),
            stamp: drivespec_psx3xx::Stamp(t.stamp.unwrap_or(0)),
        },
        1 => Output::ControlTarget {
            control_word: t.control_word.unwrap_or(0),
            target: t.target.unwrap_or(0),
        },
        _ => Output::SpeedControlTarget {
            target_speed: t.target_speed.unwrap_or(0),
            control_word: t.control_word.unwrap_or(0),
            target: t.target.unwrap_or(0),
        },
    };
    s.send(out);
}

/// Waypoints of the last run started, from the trace events.
fn last_waypoints(s: &mut Sim, store: &mut Option<Vec<i64>>) {
    while let Some((_, e)) = s.drive.poll_event() {
        if let Event::Core(CoreEvent::RunStarted { waypoints, .. }) = e {
            *store = Some(waypoints);
        }
    }
}

fn check(s: &mut Sim, expect: &Expect, started: &mut Option<Vec<i64>>) -> Result<(), String> {
    if let Some(run) = expect.run {
        if s.run() != run.as_str() {
            return Err(format!("run {} instead of {}", s.run(), run.as_str()));
        }
    }
    if let Some(t) = expect.target {
        let got = s.drive.core().run_target();
        if got != Some(t) {
            return Err(format!("run target {got:?} instead of {t}"));
        }
    }
    for &b in &expect.status_set {
        if !s.bit(b) {
            return Err(format!("status bit {b} not set ({:#06x})", s.status()));
        }
    }
    for &b in &expect.status_clear {
        if s.bit(b) {
            return Err(format!("status bit {b} not clear ({:#06x})", s.status()));
        }
    }
    if let Some(speed) = expect.speed_rpm {
        s.run_ms(1);
        let got = s.drive.set_speed_rpm();
        if got != speed {
            return Err(format!("speed {got} instead of {speed}"));
        }
    }
    if expect.reference_loop == Some(false) {
        last_waypoints(s, started);
        if started.as_ref().map(Vec::len) != Some(1) {
            return Err(format!("run with waypoints {started:?}, no loop expected"));
        }
    }
    if expect.stop == Some(false) {
        for _ in 0..50 {
            s.run_ms(1);
            if s.drive.core().speed_rpm() == 0 {
                return Err("the drive stopped".into());
            }
        }
    }
    if let Some(p) = &expect.torque_param {
        let want = s.read(p.parse().unwrap());
        s.run_ms(1000);
        if s.drive.core().holding_torque() != Some(want) {
            return Err(format!(
                "holding torque {:?} instead of ISDU {p} = {want}",
                s.drive.core().holding_torque()
            ));
        }
    }
    if let Some(active) = expect.keys_active {
        if s.run().starts_with("jog") != active {
            return Err(format!("keys active {active}, run {}", s.run()));
        }
    }
    if let Some(f) = expect.active_format {
        if s.drive.active_format() != f {
            return Err(format!("active format {}", s.drive.active_format()));
        }
    }
    Ok(())
}

/// Runs one step: the action, then its expectations.
fn step(s: &mut Sim, st: &VectorStep, started: &mut Option<Vec<i64>>) -> Result<(), String> {
    let expect = &st.expect;
    if st.bus.is_some() || st.key.is_some() {
        // Each row of the jog tables is its own situation: the previous jog ends first.
        s.settle(60_000);
    }
    if let Some(bus) = st.bus {
        if bus != s.drive.link_up() {
            s.link(if bus {
                LinkEvent::Connected
            } else {
                LinkEvent::Lost
            });
        }
        if let Some(cw) = st.control_word {
            if bus {
                s.f1(cw, s.actual() as i32);
            }
        }
    }
    let hold_ms = st.hold_ms;
    let mut before = s.actual();
    if let Some(key) = st.key {
        let k = match key {
            Key::Forward => JogKeys::FORWARD,
            Key::Reverse => JogKeys::REVERSE,
            Key::Both => JogKeys::BOTH,
            Key::None => JogKeys::NONE,
        };
        before = s.actual();
        s.keys(k);
    }
    if let Some(t) = &st.pd {
        pd(s, t);
    }
    if let Some(t) = &st.isdu {
        let (index, sub) = (t.index, t.subindex);
        if t.op == IsduOp::Read {
            let got = s.drive.read(index, sub).map_err(|e| e.to_string())?;
            if let Some(want) = expect.value {
                if got != Value::Int(want) {
                    return Err(format!("ISDU {index}.{sub} reads {got} instead of {want}"));
                }
            }
        } else {
            let value = t.value.unwrap_or(0);
            let r = s
                .drive
                .write(s.now, index, sub, &Value::Int(value))
                .unwrap();
            let answer = s.drive.poll_isdu();
            if let Some(e) = expect.error {
                let ok = (e == 0 && r == Response::Write)
                    || matches!(r, Response::Error { error } if i64::from(error.0) == e);
                if !ok {
                    return Err(format!("ISDU {index} = {value}: {r:?}"));
                }
            }
            if let Some(sup) = expect.suppressed {
                if answer.map(|a| a.suppressed) != Some(sup) {
                    return Err(format!("ISDU {index} suppressed != {sup}"));
                }
            }
        }
    }
    if let Some(ev) = st.event {
        let after = st.after_ms.unwrap_or(0);
        match ev {
            StepEvent::ObstructionDetected => {
                s.env(EnvChange::Jam { on: true });
                s.until(5_000, |d| d.status_word() >> 10 & 1 == 1);
                s.env(EnvChange::Jam { on: false });
            }
            StepEvent::TargetReached | StepEvent::TargetReachedInLoopDirection => {
                s.settle(120_000);
            }
            StepEvent::ManualRotationAtStandstill => {
                let n = st.steps.unwrap_or(1);
                let loop_dir = if s.read(134) == 0 { 1 } else { -1 };
                let against = st.direction == Some(LoopSide::AgainstLoop);
                let by = if against { -loop_dir * n } else { loop_dir * n };
                s.env(EnvChange::Displace { by });
            }
            StepEvent::MotorVoltageOutOfRange => {
                s.env(EnvChange::MotorVoltage { dv: 100 });
                s.run_ms(1000);
            }
            StepEvent::MotorVoltageInRange => {
                s.env(EnvChange::MotorVoltage { dv: 240 });
                s.run_ms(1000);
            }
            StepEvent::ConnectionLost => {
                s.link(LinkEvent::Lost);
                s.run_ms(after + 16);
            }
        }
    }
    if let Some(after_us) = expect.after_us {
        let after = after_us / MS;
        if after > 2 * CYCLE / MS && expect.run != Some(Run::None) {
            s.run_ms(after - 2 * CYCLE / MS);
            let want = expect.run.unwrap_or(Run::None).as_str();
            if s.run() == want {
                return Err(format!("{want} already {} ms early", 2 * CYCLE / MS));
            }
            s.run_ms(2 * CYCLE / MS + 1);
        } else {
            s.run_ms(after + 1);
        }
    }
    if let Some(after_ms) = expect.after_ms {
        if st.key.is_some() {
            s.run_ms(after_ms + 50);
        }
    }
    last_waypoints(s, started);
    let mut elapsed = expect.after_ms.map_or(0, |a| a + 50);
    if let (Some(hold), None, Some(Run::JogContinuous)) = (hold_ms, expect.after_ms, expect.run) {
        // Held for hold_ms: the continuous run is there by the end of the hold.
        s.run_ms(hold - 10);
        elapsed = hold - 10;
    }
    if check(s, expect, started).is_err() {
        // Status bits that follow the motion ("wait for bit 6", 5.14) get a moment.
        s.run_ms(50);
        elapsed += 50;
        check(s, expect, started)?;
    }
    if let Some(hold) = hold_ms {
        s.run_ms(hold.saturating_sub(elapsed));
        if let Some(n) = expect.steps {
            let moved = (s.actual() - before).abs();
            let step = s.read(135);
            if moved != n * step {
                return Err(format!("moved {moved} instead of {} steps", n * step));
            }
        }
        s.keys(JogKeys::NONE);
        s.settle(60_000);
        if let Some(at) = expect.stop_at {
            // A forward jog ends at the limit at the latest.
            if s.actual() > at {
                return Err(format!("jog ended at {} beyond {at}", s.actual()));
            }
        }
    }
    if let Some(d) = expect.direction {
        let moved = s.drive.core().run_target().unwrap_or(before) - before;
        if (d == Direction::Forward) != (moved > 0) {
            return Err(format!("jog moved {moved}"));
        }
    }
    Ok(())
}

fn run_vector(v: &Vector) -> Result<(), String> {
    let seq: PsxSequence = read_sequence(v).map_err(|e| e.to_string())?;
    let mut s = setup(v, &seq.input)?;
    if seq.input.steps.is_empty() {
        return Err("no steps".into());
    }
    let mut started = None;
    for (i, st) in seq.input.steps.iter().enumerate() {
        step(&mut s, st, &mut started).map_err(|e| format!("step {}: {e}", i + 1))?;
        s.run_ms(8);
    }
    if let Some(run) = seq.expect.final_run {
        if s.run() != run.as_str() {
            return Err(format!("final run {} instead of {}", s.run(), run.as_str()));
        }
    }
    if let Some(id) = seq.expect.device_id {
        if s.drive.device_id() != Some(id) {
            return Err(format!("device ID {:?}", s.drive.device_id()));
        }
    }
    for (k, val) in &seq.expect.final_state {
        let got = s.read(k.parse().unwrap());
        if got != *val {
            return Err(format!("final ISDU {k} = {got} instead of {val}"));
        }
    }
    Ok(())
}

#[test]
fn sequence_vectors_run_against_the_model() {
    let mut failures = Vec::new();
    let mut report = String::new();
    let vectors: Vec<&Vector> = family()
        .vectors
        .iter()
        .filter(|v| v.kind == VectorKind::Sequence)
        .collect();
    assert!(
        vectors.len() >= 40,
        "only {} sequence vectors",
        vectors.len()
    );
    for v in vectors {
        let result =
            std::panic::catch_unwind(|| run_vector(v)).unwrap_or_else(|_| Err("panicked".into()));
        let verdict = match (&result, v.result) {
            (Ok(()), _) => "pass",
            (Err(_), VectorResult::Acceptable) => "acceptable-fail",
            (Err(_), _) => "FAIL",
        };
        report.push_str(&format!("{verdict:<16} {}", v.id));
        if let Err(e) = &result {
            report.push_str(&format!("  -- {e}"));
            if verdict == "FAIL" {
                failures.push(v.id.clone());
            }
        }
        report.push('\n');
    }
    println!("{report}");
    assert!(
        failures.is_empty(),
        "failing vectors: {failures:?}\n{report}"
    );
}
