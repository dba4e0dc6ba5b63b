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

use drivespec_positioner::{CoreEvent, EnvChange};
use drivespec_psx3xx::isdu::{Response, Value};
use drivespec_psx3xx::model::{DriveConfig, Event, JogKeys, LinkEvent};
use drivespec_psx3xx::Output;
use drivespec_spec::{Vector, VectorKind, VectorResult};
use model_util::*;
use toml::Value as T;

fn int(v: Option<&T>) -> Option<i64> {
    v.and_then(T::as_integer)
}

fn list(v: Option<&T>) -> Vec<i64> {
    v.and_then(T::as_array)
        .map(|a| a.iter().filter_map(T::as_integer).collect())
        .unwrap_or_default()
}

/// Builds the drive of a vector: model, software version and model code from the state, the
/// process-data format saved and made active by a reset, the other state entries written.
fn setup(v: &Vector) -> Result<Sim, String> {
    let state = v
        .input("state")
        .and_then(T::as_table)
        .cloned()
        .unwrap_or_default();
    let mut config = DriveConfig::new(v.model.as_deref().unwrap_or("PSE312-8"));
    if let Some(sw) = int(state.get("80")) {
        config.software_version = Some(sw as u16);
    }
    if let Some(code) = int(state.get("79")) {
        config.model_code = Some(code as u16);
    }
    // ISDU 67 in a state is where the shaft stands (referencing value 0).
    if let Some(pos) = int(state.get("67")) {
        config.start_position = Some(pos);
    }
    let mut s = Sim::with(config);
    let format = int(state.get("116")).or(int(v.input("format")));
    if let Some(f) = format.filter(|f| *f != i64::from(s.drive.active_format())) {
        s.write_ok(116, f);
        s.write_ok(193, 1);
        s.write_ok(2, 128);
    }
    for (k, val) in &state {
        if ["67", "80", "79", "116"].contains(&k.as_str()) {
            continue;
        }
        let index: u16 = k.parse().map_err(|_| format!("state key {k}"))?;
        let r = s.write(index, val.as_integer().unwrap_or(0));
        if r != Response::Write {
            return Err(format!("state {k} = {val}: {r:?}"));
        }
    }
    while s.drive.poll_event().is_some() {}
    Ok(s)
}

fn pd(s: &mut Sim, t: &toml::Table) {
    let g = |k: &str| int(t.get(k)).unwrap_or(0);
    let out = match s.drive.active_format() {
        0 => Output::TimeStamp {
            control: drivespec_psx3xx::TsCode(g("control") as u8),
            stamp: drivespec_psx3xx::Stamp(g("stamp") as u16),
        },
        1 => Output::ControlTarget {
            control_word: g("control_word") as u16,
            target: g("target") as i32,
        },
        _ => Output::SpeedControlTarget {
            target_speed: g("target_speed") as i16,
            control_word: g("control_word") as u16,
            target: g("target") as i32,
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

fn check(s: &mut Sim, expect: &toml::Table, started: &mut Option<Vec<i64>>) -> Result<(), String> {
    if let Some(run) = expect.get("run").and_then(T::as_str) {
        if s.run() != run {
            return Err(format!("run {} instead of {run}", s.run()));
        }
    }
    if let Some(t) = int(expect.get("target")) {
        let got = s.drive.core().run_target();
        if got != Some(t) {
            return Err(format!("run target {got:?} instead of {t}"));
        }
    }
    for b in list(expect.get("status_set")) {
        if !s.bit(b as u32) {
            return Err(format!("status bit {b} not set ({:#06x})", s.status()));
        }
    }
    for b in list(expect.get("status_clear")) {
        if s.bit(b as u32) {
            return Err(format!("status bit {b} not reset ({:#06x})", s.status()));
        }
    }
    if let Some(speed) = int(expect.get("speed_rpm")) {
        s.run_ms(1);
        let got = s.drive.set_speed_rpm();
        if got != speed {
            return Err(format!("speed {got} instead of {speed}"));
        }
    }
    if expect.get("loop").and_then(T::as_bool) == Some(false) {
        last_waypoints(s, started);
        if started.as_ref().map(Vec::len) != Some(1) {
            return Err(format!("run with waypoints {started:?}, no loop expected"));
        }
    }
    if expect.get("stop").and_then(T::as_bool) == Some(false) {
        for _ in 0..50 {
            s.run_ms(1);
            if s.drive.core().speed_rpm() == 0 {
                return Err("the drive stopped".into());
            }
        }
    }
    if let Some(p) = expect.get("torque_param").and_then(T::as_str) {
        let want = s.read(p.parse().unwrap());
        s.run_ms(1000);
        if s.drive.core().holding_torque() != Some(want) {
            return Err(format!(
                "holding torque {:?} instead of ISDU {p} = {want}",
                s.drive.core().holding_torque()
            ));
        }
    }
    if let Some(f) = int(expect.get("active_format")) {
        if i64::from(s.drive.active_format()) != f {
            return Err(format!("active format {}", s.drive.active_format()));
        }
    }
    Ok(())
}

/// Runs one step: the action, then its expectations.
fn step(s: &mut Sim, st: &toml::Table, started: &mut Option<Vec<i64>>) -> Result<(), String> {
    let empty = toml::Table::new();
    let expect = st.get("expect").and_then(T::as_table).unwrap_or(&empty);
    if st.get("bus").is_some() || st.get("key").is_some() {
        // Each row of the jog tables is its own situation: the previous jog ends first.
        s.settle(60_000);
    }
    if let Some(bus) = st.get("bus").and_then(T::as_bool) {
        if bus != s.drive.link_up() {
            s.link(if bus {
                LinkEvent::Connected
            } else {
                LinkEvent::Lost
            });
        }
        if let Some(cw) = int(st.get("control_word")) {
            if bus {
                s.f1(cw as u16, s.actual() as i32);
            }
        }
    }
    let hold_ms = int(st.get("hold_ms"));
    let mut before = s.actual();
    if let Some(key) = st.get("key").and_then(T::as_str) {
        let k = match key {
            "forward" => JogKeys::FORWARD,
            "reverse" => JogKeys::REVERSE,
            "both" => JogKeys::BOTH,
            _ => JogKeys::NONE,
        };
        before = s.actual();
        s.keys(k);
    }
    if let Some(t) = st.get("pd").and_then(T::as_table) {
        pd(s, t);
    }
    if let Some(t) = st.get("isdu").and_then(T::as_table) {
        let index = int(t.get("index")).unwrap_or(0) as u16;
        let sub = int(t.get("subindex")).unwrap_or(0) as u8;
        if t.get("op").and_then(T::as_str) == Some("read") {
            let got = s.drive.read(index, sub).map_err(|e| e.to_string())?;
            if let Some(want) = int(expect.get("value")) {
                if got != Value::Int(want) {
                    return Err(format!("ISDU {index}.{sub} reads {got} instead of {want}"));
                }
            }
        } else {
            let value = int(t.get("value")).unwrap_or(0);
            let r = s
                .drive
                .write(s.now, index, sub, &Value::Int(value))
                .unwrap();
            let answer = s.drive.poll_isdu();
            if let Some(e) = int(expect.get("error")) {
                let ok = (e == 0 && r == Response::Write)
                    || matches!(r, Response::Error { error } if i64::from(error.0) == e);
                if !ok {
                    return Err(format!("ISDU {index} = {value}: {r:?}"));
                }
            }
            if let Some(sup) = expect.get("suppressed").and_then(T::as_bool) {
                if answer.map(|a| a.suppressed) != Some(sup) {
                    return Err(format!("ISDU {index} suppressed != {sup}"));
                }
            }
        }
    }
    if let Some(ev) = st.get("event").and_then(T::as_str) {
        let after = int(st.get("after_ms")).unwrap_or(0) as u64;
        match ev {
            "obstruction-detected" => {
                s.env(EnvChange::Jam { on: true });
                s.until(5_000, |d| d.status_word() >> 10 & 1 == 1);
                s.env(EnvChange::Jam { on: false });
            }
            "target-reached" | "target-reached-in-loop-direction" => {
                s.settle(120_000);
            }
            "manual-rotation-at-standstill" => {
                let n = int(st.get("steps")).unwrap_or(1);
                let loop_dir = if s.read(134) == 0 { 1 } else { -1 };
                let against = st.get("direction").and_then(T::as_str) == Some("against-loop");
                let by = if against { -loop_dir * n } else { loop_dir * n };
                s.env(EnvChange::Displace { by });
            }
            "motor-voltage-out-of-range" => {
                s.env(EnvChange::MotorVoltage { dv: 100 });
                s.run_ms(1000);
            }
            "motor-voltage-in-range" => {
                s.env(EnvChange::MotorVoltage { dv: 240 });
                s.run_ms(1000);
            }
            "connection-lost" => {
                s.link(LinkEvent::Lost);
                s.run_ms(after + 16);
            }
            other => return Err(format!("unknown event {other}")),
        }
    }
    if let Some(after_us) = int(expect.get("after_us")) {
        let after = after_us as u64 / MS;
        if after > 2 * CYCLE / MS && expect.get("run").and_then(T::as_str) != Some("none") {
            s.run_ms(after - 2 * CYCLE / MS);
            let want = expect.get("run").and_then(T::as_str).unwrap_or("none");
            if s.run() == want {
                return Err(format!("{want} already {} ms early", 2 * CYCLE / MS));
            }
            s.run_ms(2 * CYCLE / MS + 1);
        } else {
            s.run_ms(after + 1);
        }
    }
    if let Some(after_ms) = int(expect.get("after_ms")) {
        if st.get("key").is_some() {
            s.run_ms(after_ms as u64 + 50);
        }
    }
    last_waypoints(s, started);
    let mut elapsed = int(expect.get("after_ms")).map_or(0, |a| a as u64 + 50);
    if let (Some(hold), None, Some("jog-continuous")) = (
        hold_ms,
        expect.get("after_ms"),
        expect.get("run").and_then(T::as_str),
    ) {
        // Held for hold_ms: the continuous run is there by the end of the hold.
        s.run_ms(hold as u64 - 10);
        elapsed = hold as u64 - 10;
    }
    if check(s, expect, started).is_err() {
        // Status bits that follow the motion ("wait for bit 6", 5.14) get a moment.
        s.run_ms(50);
        elapsed += 50;
        check(s, expect, started)?;
    }
    if let Some(hold) = hold_ms {
        s.run_ms((hold as u64).saturating_sub(elapsed));
        if let Some(n) = int(expect.get("steps")) {
            let moved = (s.actual() - before).abs();
            let step = s.read(135);
            if moved != n * step {
                return Err(format!("moved {moved} instead of {} steps", n * step));
            }
        }
        s.keys(JogKeys::NONE);
        s.settle(60_000);
    }
    if let Some(d) = expect.get("direction").and_then(T::as_str) {
        let moved = s.drive.core().run_target().unwrap_or(before) - before;
        if (d == "forward") != (moved > 0) {
            return Err(format!("jog moved {moved}"));
        }
    }
    Ok(())
}

fn run_vector(v: &Vector) -> Result<(), String> {
    let mut s = setup(v)?;
    let steps = v
        .input("steps")
        .and_then(T::as_array)
        .ok_or("no steps")?
        .clone();
    let mut started = None;
    for (i, st) in steps.iter().enumerate() {
        let st = st.as_table().ok_or("a step is not a table")?;
        step(&mut s, st, &mut started).map_err(|e| format!("step {}: {e}", i + 1))?;
        s.run_ms(8);
    }
    if let Some(run) = v.expected("final_run").and_then(T::as_str) {
        if s.run() != run {
            return Err(format!("final run {} instead of {run}", s.run()));
        }
    }
    if let Some(id) = int(v.expected("device_id")) {
        if s.drive.device_id().map(i64::from) != Some(id) {
            return Err(format!("device ID {:?}", s.drive.device_id()));
        }
    }
    if let Some(state) = v.expected("final_state").and_then(T::as_table) {
        for (k, val) in state {
            let got = s.read(k.parse().unwrap());
            if Some(got) != val.as_integer() {
                return Err(format!("final ISDU {k} = {got} instead of {val}"));
            }
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
