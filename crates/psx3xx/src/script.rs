//! `sim-run` for the PSx3xx: the script's text form of the family [`Step`] and the runner
//! that plays a script on the reference [`Drive`] on virtual time.
//!
//! The line grammar, environment changes and expectations are the shared ones of
//! [`drivespec_positioner::script`]; the PSx3xx commands and the steps they are:
//!
//! ```text
//! control WORD [target POS] [speed RPM]   process: formats 1 and 2: control word (ISDU 110),
//!                                         target (ISDU 112) and, in format 2, the target speed
//! target POS                              process: target only
//! stamp CODE STAMP                        stamp: format 0: control code and time stamp (4.4)
//! isdu read INDEX[.SUB]                   isdu-read: ISDU read (3.1)
//! isdu write INDEX[.SUB] = VALUE          isdu-write: an integer, encoded per the spec
//! keys forward|reverse|both|none          keys: jog key inputs (5.10)
//! link connected|lost                     link: IO-Link communication (5.9)
//! power-cycle                             power-cycle: supply off and on again
//! leds                                    leds: what the three LEDs show (2.6, 3.3.1)
//! ```
//!
//! The master sends the process output of the active format once per cycle; in format 0 it
//! sends nothing until a `stamp` line gives a control code. The runner plays every step but
//! those that count bus cycles or wait on the drive (`hold`, `until`, `isdu-poll`, `advance`),
//! a process output in a fixed format (`pd-out`) and the cyclic-exchange text form of an
//! environment change (`env` steps; a script writes `env …` lines): a script holding one is
//! refused with [`PlayError::Unplayable`]. Nothing here panics; the trace grows with the
//! simulated time divided by the sampling period, plus one entry per change.

use crate::isdu::{Request, Response, Value};
use crate::model::{Drive, DriveConfig, Event, JogKeys, LinkEvent, ModelError};
use crate::step::Step;
use crate::{Output, Rules, Stamp, TsCode};
use drivespec_positioner::script::{
    describe_core, kebab, no_more, parse_in, play, split_word, BitName, Dialect, LineError,
    Observation, Recorder, Script, ScriptError, Simulated, Trace,
};
pub use drivespec_positioner::script::{PlayError, RunOptions};
use drivespec_positioner::{decode_bits, EnvChange, Micros};
use drivespec_spec::hex::to_hex;
use drivespec_spec::{FamilyId, Spec};
use serde::Serialize;
use std::fmt;

/// The PSx3xx script commands, parsed into [`Step`]s against the codec tables.
#[derive(Debug, Clone, Copy)]
pub struct PsxDialect<'a, 's> {
    rules: &'a Rules<'s>,
}

impl<'a, 's> PsxDialect<'a, 's> {
    /// The dialect of a drive with these codec tables (3.1, 3.3).
    pub fn new(rules: &'a Rules<'s>) -> PsxDialect<'a, 's> {
        PsxDialect { rules }
    }

    fn address(text: &str) -> Result<(u16, u8), LineError> {
        match text.split_once('.') {
            Some((i, s)) => Ok((parse_in("ISDU index", i)?, parse_in("sub-index", s)?)),
            None => Ok((parse_in("ISDU index", text)?, 0)),
        }
    }

    fn isdu(&self, rest: &str) -> Result<Step, LineError> {
        let (op, tail) = split_word(rest);
        match op {
            "read" => {
                let (addr, tail) = split_word(tail);
                no_more(tail)?;
                let (index, subindex) = Self::address(addr)?;
                Ok(Step::IsduRead { index, subindex })
            }
            "write" => {
                let (lhs, rhs) = tail.split_once('=').ok_or(LineError::Missing {
                    what: "`INDEX[.SUB] = VALUE`",
                })?;
                let (index, subindex) = Self::address(lhs.trim())?;
                let value: i64 = parse_in("value", rhs)?;
                let family = |message: String| LineError::Family { message };
                let target = self
                    .rules
                    .isdu_target(index, subindex)
                    .map_err(|e| family(format!("ISDU {index}.{subindex}: {e}")))?;
                let data = self
                    .rules
                    .encode_value(&target, &Value::Int(value))
                    .map_err(|e| family(format!("ISDU {index}.{subindex} = {value}: {e}")))?;
                Ok(Step::IsduWrite {
                    index,
                    subindex,
                    data,
                })
            }
            other => Err(LineError::Unknown {
                what: "ISDU operation",
                found: other.to_owned(),
                expected: "read, write".to_owned(),
            }),
        }
    }
}

const VERBS: &str = "control, target, stamp, isdu, keys, link, power-cycle, leds, env, expect, end";

fn word_in<'t>(what: &'static str, text: &'t str, allowed: &str) -> Result<&'t str, LineError> {
    let (w, tail) = split_word(text);
    no_more(tail)?;
    if allowed.split(", ").any(|a| a == w) {
        Ok(w)
    } else if w.is_empty() {
        Err(LineError::Missing { what })
    } else {
        Err(LineError::Unknown {
            what,
            found: w.to_owned(),
            expected: allowed.to_owned(),
        })
    }
}

impl Dialect for PsxDialect<'_, '_> {
    type Step = Step;

    fn command(&self, verb: &str, rest: &str) -> Result<Step, LineError> {
        match verb {
            "control" => {
                let (word, mut tail) = split_word(rest);
                let word = parse_in("control word", word)?;
                let (mut target, mut speed) = (None, None);
                while !tail.is_empty() {
                    let (key, t) = split_word(tail);
                    let (value, t) = split_word(t);
                    match key {
                        "target" => target = Some(parse_in("target", value)?),
                        "speed" => speed = Some(parse_in("speed in rpm", value)?),
                        other => {
                            return Err(LineError::Trailing {
                                found: other.to_owned(),
                            })
                        }
                    }
                    tail = t;
                }
                Ok(Step::Process {
                    control: Some(word),
                    target,
                    speed,
                })
            }
            "target" => {
                let (pos, tail) = split_word(rest);
                no_more(tail)?;
                Ok(Step::Process {
                    control: None,
                    target: Some(parse_in("target", pos)?),
                    speed: None,
                })
            }
            "stamp" => {
                let (code, tail) = split_word(rest);
                let (stamp, tail) = split_word(tail);
                no_more(tail)?;
                Ok(Step::Stamp {
                    code: parse_in("control code", code)?,
                    stamp: parse_in("time stamp", stamp)?,
                })
            }
            "isdu" => self.isdu(rest),
            "keys" => {
                let keys = match word_in("jog keys", rest, "forward, reverse, both, none")? {
                    "forward" => JogKeys::FORWARD,
                    "reverse" => JogKeys::REVERSE,
                    "both" => JogKeys::BOTH,
                    _ => JogKeys::NONE,
                };
                Ok(Step::Keys {
                    forward: keys.forward,
                    reverse: keys.reverse,
                })
            }
            "link" => Ok(Step::Link {
                event: match word_in("link event", rest, "connected, lost")? {
                    "connected" => LinkEvent::Connected,
                    _ => LinkEvent::Lost,
                },
            }),
            "power-cycle" => {
                no_more(rest)?;
                Ok(Step::PowerCycle)
            }
            "leds" => {
                no_more(rest)?;
                Ok(Step::Leds)
            }
            other => Err(LineError::Unknown {
                what: "command",
                found: other.to_owned(),
                expected: VERBS.to_owned(),
            }),
        }
    }

    fn verbs(&self) -> &'static str {
        VERBS
    }
}

/// A model event in a trace: its JSON is the event's, its text a short sentence (3.1, 4, 5).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(transparent)]
pub struct TraceEvent(pub Event);

impl fmt::Display for TraceEvent {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.0 {
            Event::Core(e) => f.write_str(&describe_core(e)),
            Event::Written {
                index,
                subindex,
                value,
            } => write!(f, "ISDU {index}.{subindex} = {value} written"),
            Event::Saved => f.write_str("parameters saved to EEPROM"),
            Event::Restored { delivery: true } => {
                f.write_str("parameters loaded from the delivery table")
            }
            Event::Restored { delivery: false } => {
                f.write_str("parameters loaded from the EEPROM image")
            }
            Event::Restarted { format } => write!(f, "restarted in process-data format {format}"),
            Event::Link(ev) => write!(f, "link {}", kebab(ev)),
            Event::Keys(k) => {
                let keys = match (k.forward, k.reverse) {
                    (true, true) => "both",
                    (true, false) => "forward",
                    (false, true) => "reverse",
                    (false, false) => "none",
                };
                write!(f, "jog keys: {keys}")
            }
            other => write!(f, "{other:?}"),
        }
    }
}

/// Why a script cannot be run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RunError {
    /// The drive cannot be built.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The script has an error.
    #[error(transparent)]
    Script(#[from] ScriptError),
    /// The script holds a step the runner cannot play.
    #[error(transparent)]
    Play(#[from] PlayError),
}

/// The reference drive with the master's process output, as the script runner drives it.
#[derive(Debug, Clone)]
pub struct PsxSim<'s> {
    drive: Drive<'s>,
    control: u16,
    target: i32,
    speed: i16,
    stamp: Option<(u8, u16)>,
}

impl<'s> PsxSim<'s> {
    /// A master with zero outputs in front of `drive` (3.3.1).
    pub fn new(drive: Drive<'s>) -> PsxSim<'s> {
        PsxSim {
            drive,
            control: 0,
            target: 0,
            speed: 0,
            stamp: None,
        }
    }

    /// The drive (chapters 3–5).
    pub fn drive(&self) -> &Drive<'s> {
        &self.drive
    }

    /// The process output of the active format; None in format 0 before a `stamp` line.
    fn output(&self) -> Option<Output> {
        match self.drive.active_format() {
            0 => self.stamp.map(|(code, stamp)| Output::TimeStamp {
                control: TsCode(code),
                stamp: Stamp(stamp),
            }),
            1 => Some(Output::ControlTarget {
                control_word: self.control,
                target: self.target,
            }),
            _ => Some(Output::SpeedControlTarget {
                target_speed: self.speed,
                control_word: self.control,
                target: self.target,
            }),
        }
    }

    fn send(&mut self, now: Micros, rec: Option<&mut Recorder<TraceEvent>>) {
        if let Some(out) = self.output() {
            if let (Err(e), Some(rec)) = (self.drive.handle_output(now, &out), rec) {
                rec.answer(now, "pd".to_owned(), "refused".to_owned(), e.to_string());
            }
        }
        while self.drive.poll_input().is_some() {}
    }

    fn answers(&mut self, rec: &mut Recorder<TraceEvent>) {
        while let Some(a) = self.drive.poll_isdu() {
            let (answer, meaning) = match &a.response {
                Response::Read { data } => {
                    let meaning = self
                        .drive
                        .rules()
                        .isdu_target(a.index, a.subindex)
                        .ok()
                        .and_then(|t| self.drive.rules().decode_value(&t, data).ok())
                        .map_or_else(String::new, |v| format!("= {v}"));
                    (format!("data {}", to_hex(data)), meaning)
                }
                Response::Write if a.suppressed => (
                    "written".to_owned(),
                    "acknowledged, dropped by a guard entry".to_owned(),
                ),
                Response::Write => ("written".to_owned(), String::new()),
                Response::Error { error } => {
                    let named = self.drive.rules().error_types().named(*error);
                    (format!("error {error}"), named.to_string())
                }
            };
            rec.answer(
                a.at,
                format!("isdu {}.{}", a.index, a.subindex),
                answer,
                meaning,
            );
        }
    }
}

impl<'s> Simulated for PsxSim<'s> {
    type Step = Step;
    type Event = TraceEvent;

    fn advance(&mut self, now: Micros) {
        self.drive.advance(now);
    }

    fn cycle(&mut self, now: Micros) {
        self.send(now, None);
    }

    fn env(&mut self, now: Micros, change: EnvChange) {
        self.drive.handle_env(now, change);
    }

    fn unplayable(step: &Step) -> Option<&'static str> {
        match step {
            Step::PdOut { .. }
            | Step::Hold { .. }
            | Step::Until { .. }
            | Step::Advance { .. }
            | Step::IsduPoll { .. }
            | Step::Env { .. } => Some(step.name()),
            _ => None,
        }
    }

    fn step(&mut self, now: Micros, step: &Step, rec: &mut Recorder<TraceEvent>) {
        match step {
            Step::Process {
                control,
                target,
                speed,
            } => {
                if let Some(c) = control {
                    self.control = *c;
                }
                if let Some(t) = target {
                    self.target = *t;
                }
                if let Some(s) = speed {
                    self.speed = *s;
                }
                self.send(now, Some(rec));
            }
            Step::Stamp { code, stamp } => {
                self.stamp = Some((*code, *stamp));
                self.send(now, Some(rec));
            }
            Step::IsduRead { index, subindex } => {
                let req = Request::Read {
                    index: *index,
                    subindex: *subindex,
                };
                self.drive.handle_isdu(now, req);
                self.answers(rec);
            }
            Step::IsduWrite {
                index,
                subindex,
                data,
            } => {
                let req = Request::Write {
                    index: *index,
                    subindex: *subindex,
                    data: data.clone(),
                };
                self.drive.handle_isdu(now, req);
                self.answers(rec);
            }
            Step::Keys { forward, reverse } => {
                let keys = JogKeys {
                    forward: *forward,
                    reverse: *reverse,
                };
                self.drive.handle_keys(now, keys);
            }
            Step::Link { event } => self.drive.handle_link(now, *event),
            Step::PowerCycle => self.drive.power_cycle(now),
            // Refused by `unplayable` before the script plays.
            Step::PdOut { .. }
            | Step::Hold { .. }
            | Step::Until { .. }
            | Step::Advance { .. }
            | Step::IsduPoll { .. }
            | Step::Env { .. } => {}
            Step::Leds => {
                self.drive.advance(now);
                let l = self.drive.leds();
                let shown = format!(
                    "green {}, orange {}, yellow {}",
                    l.green.pattern(),
                    l.orange.pattern(),
                    l.yellow.pattern()
                );
                rec.answer(now, "leds".to_owned(), shown, String::new());
            }
        }
    }

    fn drain(&mut self, _now: Micros, rec: &mut Recorder<TraceEvent>) {
        while let Some((at, e)) = self.drive.poll_event() {
            rec.event(at, TraceEvent(e));
        }
        self.answers(rec);
    }

    fn observe(&self) -> Observation {
        let i = self.drive.input();
        Observation {
            position: i64::from(i.actual),
            speed: i64::from(i.rpm),
            status: u64::from(i.status),
        }
    }

    fn poll_timeout(&self) -> Option<Micros> {
        self.drive.poll_timeout()
    }

    fn status_width(&self) -> u32 {
        16
    }
}

/// Parses a script with the PSx3xx commands of `rules`.
pub fn parse(rules: &Rules<'_>, text: &str) -> Result<Script<Step>, ScriptError> {
    Script::parse(text, &PsxDialect::new(rules))
}

/// Parses `text` and plays it on a drive built from `config`.
pub fn run_text(
    spec: &Spec,
    config: DriveConfig,
    text: &str,
    opts: &RunOptions,
) -> Result<Trace<TraceEvent>, RunError> {
    let drive = Drive::new(spec, config)?;
    let script = parse(drive.rules(), text)?;
    let model = drive.model_id().to_owned();
    let mut sim = PsxSim::new(drive);
    let played = play(&mut sim, &script, opts)?;
    let bits = sim
        .drive
        .rules()
        .status_bits()
        .map(|b| {
            decode_bits(b, played.seen_status)
                .set
                .into_iter()
                .map(|s| BitName {
                    bit: s.bit,
                    name: s.name,
                })
                .collect()
        })
        .unwrap_or_default();
    Ok(Trace {
        family: FamilyId::Psx3xx.to_string(),
        model,
        every_ms: opts.every_ms,
        bits,
        entries: played.entries,
        passed: played.passed,
        failed: played.failed,
    })
}
