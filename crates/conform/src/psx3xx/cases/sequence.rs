//! Cases from the spec's PSx3xx `sequence` vectors (`spec/psx3xx/vectors`): each vector's
//! start state and steps, read through the family [`VectorStep`] type, become the inputs of one
//! motion case; the device must show what the reference shows (manual 3.3, 4.4–4.6, 5.9–5.14).

use super::{address, env, pd_out, step, Gen, PsxCase, StepDef, SETTLE};
use crate::case::Role;
use crate::cyclic::Env;
use drivespec_positioner::script::kebab;
use drivespec_positioner::step::read_sequence;
use drivespec_psd4xx::model::LinkEvent;
use drivespec_psx3xx::isdu::Value;
use drivespec_psx3xx::step::{
    Event, IsduOp, IsduStep, Key, LoopSide, ProcessData, PsxSequence, Run, Step, VectorStep,
};
use drivespec_psx3xx::{Output, Stamp, TsCode};
use drivespec_spec::{Vector, VectorKind};

/// The rule that a target speed of 0 in the 8-byte format runs at ISDU 142 (3.3.1).
const SPEED_ZERO: &str = "PSX-VEL-006";

/// ms the model tests of the vectors let pass after every step.
const STEP_MS: u64 = 8;

/// Longest wait, ms, for the start or the standstill a vector step leads to: longer than the
/// start, stop or reversal of a run by a drive that reacts some cycles after the reference
/// (chapter 5 fixes no reaction time), short enough not to run a long positioning to its end.
const REACTION_MS: u64 = 1000;

impl Gen<'_, '_> {
    /// One case per `sequence` vector that applies to the model, needs no property the master
    /// cannot set (another model code or software version, the IO-Link connection as a row
    /// input) and does not switch the process-data format in its steps.
    pub(super) fn sequence_cases(&mut self) {
        let vectors: Vec<&Vector> = self
            .family
            .vectors
            .iter()
            .filter(|v| v.kind == VectorKind::Sequence)
            .collect();
        for v in vectors {
            if v.model
                .as_deref()
                .is_some_and(|m| self.family.model(m).map(|x| &x.id) != Some(&self.model.id))
            {
                continue;
            }
            let seq = match read_sequence::<PsxSequence>(v) {
                Ok(seq) => seq,
                Err(e) => {
                    self.errors.push(format!("{}: {e}", v.id));
                    continue;
                }
            };
            if let Some(steps) = self.sequence_steps(&seq) {
                let mut reqs = v.requirements.clone();
                // A run in the 8-byte format without a speed of its own runs at ISDU 142.
                let own_speed = seq
                    .input
                    .steps
                    .iter()
                    .filter_map(|s| s.pd.as_ref())
                    .all(|pd| pd.target_speed.unwrap_or(0) != 0);
                if self.format_of(&seq) == 2 && !own_speed {
                    reqs.push(SPEED_ZERO.to_owned());
                }
                let start = self.idle(self.rules.default_format());
                self.push(
                    format!("psx3xx/sequence/{}", v.id),
                    &reqs,
                    v.description.clone(),
                    PsxCase::motion(start, steps),
                );
            }
        }
    }

    /// The process-data format a vector runs in (its start state, else its `format`).
    fn format_of(&self, seq: &PsxSequence) -> u8 {
        let format_param = &self.rules.protocol().format_select.param;
        seq.input
            .state
            .get(format_param)
            .and_then(|v| v.int())
            .and_then(|f| u8::try_from(f).ok())
            .or(seq.input.format)
            .unwrap_or(self.rules.default_format())
    }

    /// The case steps of a vector, None when it cannot be played through the bus.
    fn sequence_steps(&mut self, seq: &PsxSequence) -> Option<Vec<StepDef>> {
        let input = &seq.input;
        // Start-state entries a master cannot write (3.1: e.g. the model code and the software
        // version) are properties of the device; a vector that needs other values than the
        // model's is left to the model tests.
        let fixed = |k: &str| {
            self.family
                .parameter(k)
                .is_some_and(|p| !p.access.writable())
        };
        let fixed_differs = input
            .state
            .iter()
            .any(|(k, v)| fixed(k) && v.int() != Some(self.value(k)));
        let format_param = self.rules.protocol().format_select.param.clone();
        let format_index: Option<u16> = format_param.parse().ok();
        let switches = input.steps.iter().any(|s| {
            s.isdu
                .is_some_and(|i| i.op == IsduOp::Write && Some(i.index) == format_index)
        });
        if input.steps.is_empty()
            || fixed_differs
            || switches
            || input.steps.iter().any(|s| s.bus.is_some())
        {
            return None;
        }
        let format = self.format_of(seq);
        let mut steps = Vec::new();
        if format != self.rules.default_format() {
            steps.extend(self.switch_to(format, Role::Setup));
        }
        let loop_param = self.rules.protocol().motion.loop_direction_param.clone();
        let mut loop_direction = self.value(&loop_param);
        for (k, value) in &input.state {
            if *k == format_param || fixed(k) {
                continue;
            }
            let value = value.int()?;
            if *k == loop_param {
                loop_direction = value;
            }
            let write = IsduStep {
                op: IsduOp::Write,
                index: k.parse().ok()?,
                subindex: 0,
                value: Some(value),
            };
            steps.push(self.isdu_step(Role::Setup, "state", &write)?);
        }
        // Whether the vector expects a run in progress before the step.
        let mut moving = false;
        for (n, s) in input.steps.iter().enumerate() {
            let n = n.saturating_add(1);
            // A run is waited for where the next step's event is meant for the running drive.
            let event_next = input.steps.get(n).is_some_and(|next| next.event.is_some());
            self.sequence_step(
                &mut steps,
                n,
                s,
                format,
                loop_direction,
                !moving && event_next,
            )?;
            if let Some(run) = s.expect.run {
                moving = run != Run::None;
            }
        }
        // Each side ends the vector's last step at its own pace; a run that goes on is judged
        // up to the end of the wait.
        steps.push(step(
            Role::Check,
            format!("until standstill, at most {REACTION_MS} ms"),
            Step::Until {
                running: false,
                max: self.cycles_for(REACTION_MS),
            },
        ));
        steps.push(step(Role::Check, "settle", Step::Hold { cycles: SETTLE }));
        Some(steps)
    }

    fn sequence_step(
        &mut self,
        steps: &mut Vec<StepDef>,
        n: usize,
        s: &VectorStep,
        format: u8,
        loop_direction: i64,
        await_run: bool,
    ) -> Option<()> {
        if let Some(key) = s.key {
            let (forward, reverse) = match key {
                Key::Forward => (true, false),
                Key::Reverse => (false, true),
                Key::Both => (true, true),
                Key::None => (false, false),
            };
            steps.push(step(
                Role::Check,
                format!("step {n}: keys {}", kebab(&key)),
                env(Env::Keys { forward, reverse }),
            ));
        }
        if let Some(pd) = &s.pd {
            steps.push(step(
                Role::Check,
                format!("step {n}: process data"),
                pd_out(output(format, pd)),
            ));
        }
        if let Some(isdu) = &s.isdu {
            steps.push(self.isdu_step(Role::Check, &format!("step {n}"), isdu)?);
        }
        if let Some(e) = s.event {
            let text = format!("step {n}: {}", kebab(&e));
            match e {
                Event::ObstructionDetected => {
                    steps.push(step(Role::Check, text, env(Env::Jam(true))));
                    steps.push(step(
                        Role::Check,
                        format!("step {n}: until standstill"),
                        Gen::until(false),
                    ));
                    steps.push(step(
                        Role::Check,
                        format!("step {n}: obstruction removed"),
                        env(Env::Jam(false)),
                    ));
                }
                Event::TargetReached | Event::TargetReachedInLoopDirection => {
                    steps.push(step(Role::Check, text, Gen::until(false)));
                }
                Event::ManualRotationAtStandstill => {
                    let by = s.steps.unwrap_or(1);
                    let with = if loop_direction == 0 { by } else { -by };
                    let by = match s.direction {
                        Some(LoopSide::AgainstLoop) => -with,
                        _ => with,
                    };
                    steps.push(step(Role::Check, text, env(Env::Displace(by))));
                }
                Event::MotorVoltageOutOfRange | Event::MotorVoltageInRange => {
                    let dv = if e == Event::MotorVoltageInRange {
                        240
                    } else {
                        100
                    };
                    steps.push(step(Role::Check, text, env(Env::MotorVoltage(dv))));
                    steps.push(step(
                        Role::Check,
                        format!("step {n}: 1 s"),
                        Step::Hold {
                            cycles: self.cycles_for(1000),
                        },
                    ));
                }
                Event::ConnectionLost => {
                    steps.push(step(Role::Check, text, env(Env::Link(LinkEvent::Lost))));
                    let ms = s.after_ms.unwrap_or(0).saturating_add(16);
                    steps.push(step(
                        Role::Check,
                        format!("step {n}: {ms} ms"),
                        Step::Hold {
                            cycles: self.cycles_for(ms),
                        },
                    ));
                }
            }
        }
        let e = &s.expect;
        // The standstill a step leads to, and a run it starts when the next step's event (an
        // obstruction, a lost connection) is meant for the running drive, are waited for on
        // each side: a drive may react later than the reference (chapter 5 fixes no reaction
        // time).
        // An event's own waits are above (an obstruction is removed once the drive stands).
        let master = s.pd.is_some() || s.isdu.is_some();
        let wait = |running: bool| Step::Until {
            running,
            max: self.cycles_for(REACTION_MS),
        };
        match e.run {
            Some(Run::None) if master => steps.push(step(
                Role::Check,
                format!("step {n}: until standstill, at most {REACTION_MS} ms"),
                wait(false),
            )),
            Some(r) if r != Run::None && (master || s.event.is_some()) && await_run => {
                steps.push(step(
                    Role::Check,
                    format!("step {n}: until running, at most {REACTION_MS} ms"),
                    wait(true),
                ))
            }
            _ => {}
        }
        let ms = e.after_us.map_or(0, |us| us / 1000 + 1)
            + s.hold_ms.or(e.after_ms).unwrap_or(0)
            + if e.stop == Some(false) { 50 } else { 0 }
            + if e.torque_param.is_some() { 1000 } else { 0 }
            + STEP_MS;
        steps.push(step(
            Role::Check,
            format!("step {n}: {ms} ms"),
            Step::Hold {
                cycles: self.cycles_for(ms),
            },
        ));
        if s.key.is_some_and(|k| k != Key::None) && s.hold_ms.is_some() {
            steps.push(step(
                Role::Check,
                format!("step {n}: keys released"),
                env(Env::Keys {
                    forward: false,
                    reverse: false,
                }),
            ));
            steps.push(step(
                Role::Check,
                format!("step {n}: until standstill"),
                Gen::until(false),
            ));
        }
        Some(())
    }

    /// An ISDU read, or a write of an integer encoded per the entry's data type (3.1).
    fn isdu_step(&self, role: Role, at: &str, isdu: &IsduStep) -> Option<StepDef> {
        let (index, subindex) = (isdu.index, isdu.subindex);
        let request = match isdu.op {
            IsduOp::Read => Step::IsduRead { index, subindex },
            IsduOp::Write => {
                let value = isdu.value.unwrap_or(0);
                let target = self.rules.isdu_target(index, subindex).ok()?;
                let data = self.rules.encode_value(&target, &Value::Int(value)).ok()?;
                Step::IsduWrite {
                    index,
                    subindex,
                    data,
                }
            }
        };
        let name = self
            .family
            .parameters
            .iter()
            .find(|p| address(p) == Some((index, subindex)))
            .map_or(String::new(), |p| format!(" ({})", p.name));
        let text = match (isdu.op, isdu.value) {
            (IsduOp::Write, Some(v)) => format!("{at}: ISDU write {index}.{subindex}{name} = {v}"),
            _ => format!("{at}: ISDU {} {index}.{subindex}{name}", kebab(&isdu.op)),
        };
        Some(step(role, text, request))
    }
}

/// A process output of `format` from a step's fields; absent fields are zero (3.3.1).
fn output(format: u8, pd: &ProcessData) -> Output {
    match format {
        0 => Output::TimeStamp {
            control: TsCode(pd.control.unwrap_or(0)),
            stamp: Stamp(pd.stamp.unwrap_or(0)),
        },
        1 => Output::ControlTarget {
            control_word: pd.control_word.unwrap_or(0),
            target: pd.target.unwrap_or(0),
        },
        _ => Output::SpeedControlTarget {
            target_speed: pd.target_speed.unwrap_or(0),
            control_word: pd.control_word.unwrap_or(0),
            target: pd.target.unwrap_or(0),
        },
    }
}
