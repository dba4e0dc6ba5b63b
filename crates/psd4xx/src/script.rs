//! `sim-run` for the PSD4xx: the script's text form of the family [`Step`] and the runner
//! that plays a script on the reference [`Drive`] on virtual time.
//!
//! The line grammar, environment changes and expectations are the shared ones of
//! [`drivespec_positioner::script`]; the PSD4xx commands and the steps they are:
//!
//! ```text
//! control WORD [target POS]      process: control word (3.7), optionally the target (par. 33)
//! target POS                     process: the target only
//! pkw REQUEST                    pkw: PKW block in the mini-syntax (`read:44`, `write:44=5`, `none`)
//! record read INDEX              record-read: acyclic read record (3.2.2)
//! record write INDEX BYTE…       record-write: hex bytes, control byte first
//! par PNU = VALUE                par: direct parameter write (the oracle's access, no PKW traffic)
//! link connected|lost|iops-bad|iops-good     link: connection events (3.9, 4.9)
//! power-cycle                    power-cycle: control voltage off and on again
//! ```
//!
//! The runner plays every step but those that count bus cycles or wait on the drive (`hold`,
//! `until`, `advance`) and the cyclic-exchange text form of an environment change (`env` steps;
//! a script writes `env …` lines): a script holding one is refused with
//! [`PlayError::Unplayable`].
//!
//! The controller sends the output image (PKW block, control word, target) once per bus
//! cycle, and at once when a command changes it. The PKW block stays until a later `pkw` line
//! replaces it, as a controller holds it until the answer comes (3.8).
//!
//! Nothing here panics; the trace grows with the simulated time divided by the sampling
//! period, plus one entry per change.

use crate::model::{
    Drive, DriveConfig, Event, LinkEvent, ModelError, RecordAnswer, RecordFailure, RecordRequest,
};
use crate::step::{PkwBlock, Step};
use crate::{Output, PkwRequest, PkwResponse, Rules};
use drivespec_positioner::script::{
    describe_core, kebab, no_more, parse_in, play, split_word, BitName, Dialect, LineError,
    Observation, Recorder, Script, ScriptError, Simulated, Trace,
};
pub use drivespec_positioner::script::{PlayError, RunOptions};
use drivespec_positioner::{decode_bits, EnvChange, Micros};
use drivespec_spec::hex::{parse_hex_digits, to_hex};
use drivespec_spec::{FamilyId, Spec};
use serde::Serialize;
use std::fmt;

/// The PSD4xx script commands, parsed into [`Step`]s against the codec tables.
#[derive(Debug, Clone, Copy)]
pub struct PsdDialect<'r> {
    rules: &'r Rules,
}

impl<'r> PsdDialect<'r> {
    /// The dialect of a drive with these codec tables (3.5, 3.8).
    pub fn new(rules: &'r Rules) -> PsdDialect<'r> {
        PsdDialect { rules }
    }
}

const VERBS: &str = "control, target, pkw, record, par, link, power-cycle, env, expect, end";

impl Dialect for PsdDialect<'_> {
    type Step = Step;

    fn command(&self, verb: &str, rest: &str) -> Result<Step, LineError> {
        match verb {
            "control" => {
                let (word, tail) = split_word(rest);
                let word = parse_in("control word", word)?;
                let target = match split_word(tail) {
                    ("", _) => None,
                    ("target", t) => {
                        let (pos, tail) = split_word(t);
                        no_more(tail)?;
                        Some(parse_in("target", pos)?)
                    }
                    (other, _) => {
                        return Err(LineError::Trailing {
                            found: other.to_owned(),
                        })
                    }
                };
                Ok(Step::Process {
                    control: Some(word),
                    target,
                })
            }
            "target" => {
                let (pos, tail) = split_word(rest);
                no_more(tail)?;
                Ok(Step::Process {
                    control: None,
                    target: Some(parse_in("target", pos)?),
                })
            }
            "pkw" => {
                if rest.is_empty() {
                    return Err(LineError::Missing {
                        what: "PKW request, e.g. read:44 or write:44=5",
                    });
                }
                self.rules
                    .pkw()
                    .request_from_text(rest)
                    .map(|p| Step::Pkw {
                        pkw: PkwBlock::from(p),
                    })
                    .map_err(|e| LineError::Family {
                        message: format!("PKW request {rest:?}: {e}"),
                    })
            }
            "record" => {
                let (op, tail) = split_word(rest);
                let (index, tail) = split_word(tail);
                match op {
                    "read" => {
                        no_more(tail)?;
                        Ok(Step::RecordRead {
                            index: parse_in("record index", index)?,
                        })
                    }
                    "write" => {
                        let index = parse_in("record index", index)?;
                        let data = tail
                            .split_whitespace()
                            .map(|b| {
                                parse_hex_digits(b).ok_or_else(|| LineError::BadNumber {
                                    what: "hex byte",
                                    found: b.to_owned(),
                                })
                            })
                            .collect::<Result<Vec<u8>, LineError>>()?;
                        if data.is_empty() {
                            return Err(LineError::Missing {
                                what: "record bytes (hex, control byte first)",
                            });
                        }
                        Ok(Step::RecordWrite { index, hex: data })
                    }
                    other => Err(LineError::Unknown {
                        what: "record operation",
                        found: other.to_owned(),
                        expected: "read, write".to_owned(),
                    }),
                }
            }
            "par" => {
                let (lhs, rhs) = rest.split_once('=').ok_or(LineError::Missing {
                    what: "`PNU = VALUE`",
                })?;
                Ok(Step::Par {
                    pnu: parse_in("parameter number", lhs)?,
                    value: parse_in("value", rhs)?,
                })
            }
            "link" => {
                let (ev, tail) = split_word(rest);
                no_more(tail)?;
                let event = match ev {
                    "connected" => LinkEvent::Connected,
                    "lost" => LinkEvent::Lost,
                    "iops-bad" => LinkEvent::IopsBad,
                    "iops-good" => LinkEvent::IopsGood,
                    other => {
                        return Err(LineError::Unknown {
                            what: "link event",
                            found: other.to_owned(),
                            expected: "connected, lost, iops-bad, iops-good".to_owned(),
                        })
                    }
                };
                Ok(Step::Link { event })
            }
            "power-cycle" => {
                no_more(rest)?;
                Ok(Step::PowerCycle)
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

/// A model event in a trace: its JSON is the event's, its text a short sentence (3.2–3.9).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(transparent)]
pub struct TraceEvent(pub Event);

impl fmt::Display for TraceEvent {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.0 {
            Event::Core(e) => f.write_str(&describe_core(e)),
            Event::ParameterWritten { pnu, value } => write!(f, "par {pnu} = {value} written"),
            Event::Saved => f.write_str("parameters saved to EEPROM"),
            Event::Restored { delivery: true } => {
                f.write_str("parameters loaded from the delivery table")
            }
            Event::Restored { delivery: false } => {
                f.write_str("parameters loaded from the EEPROM image")
            }
            Event::StationNameCleared => f.write_str("station name deleted"),
            Event::Link(ev) => write!(f, "link {}", kebab(ev)),
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

/// The reference drive with the controller's output image, as the script runner drives it.
#[derive(Debug, Clone)]
pub struct PsdSim {
    drive: Drive,
    out: Output,
    last_pkw: PkwResponse,
}

impl PsdSim {
    /// A controller sending idle images to `drive` (3.8 "no command", 3.9).
    pub fn new(drive: Drive) -> PsdSim {
        let out = Output::idle(drive.rules());
        let last_pkw = drive.input().pkw;
        PsdSim {
            drive,
            out,
            last_pkw,
        }
    }

    /// The drive (3.2–3.9).
    pub fn drive(&self) -> &Drive {
        &self.drive
    }

    fn send(&mut self, now: Micros) {
        let out = self.out;
        self.drive.handle_output(now, &out);
        while self.drive.poll_input().is_some() {}
    }

    fn record(&mut self, now: Micros, req: RecordRequest, rec: &mut Recorder<TraceEvent>) {
        self.drive.handle_record(now, req);
        self.drain(now, rec);
        while let Some(r) = self.drive.poll_record() {
            let (answer, meaning) = match &r.result {
                Ok(RecordAnswer::Data { bytes }) => {
                    let meaning = match self.drive.parameter(r.index) {
                        Ok(v) => format!("par {} = {v}", r.index),
                        Err(_) => format!("par {}", r.index),
                    };
                    (format!("data {}", to_hex(bytes)), meaning)
                }
                Ok(RecordAnswer::Written) => {
                    ("written".to_owned(), format!("par {} written", r.index))
                }
                Ok(RecordAnswer::Ignored) => (
                    "ignored".to_owned(),
                    "control byte 0: the write is not executed".to_owned(),
                ),
                Err(RecordFailure::Malformed { error }) => {
                    ("malformed".to_owned(), error.to_string())
                }
                Err(RecordFailure::Refused { error }) => {
                    let named = self.drive.rules().pkw().errors().named(*error);
                    (
                        format!("error {}", error.0),
                        format!("par {}: {named}", r.index),
                    )
                }
            };
            rec.answer(r.at, format!("record {}", r.index), answer, meaning);
        }
    }

    fn par(&mut self, now: Micros, pnu: u16, value: i64, rec: &mut Recorder<TraceEvent>) {
        let (answer, meaning) = match self.drive.write_parameter(now, pnu, value) {
            Ok(()) => (format!("{pnu}={value}"), "written".to_owned()),
            Err(e) => {
                let named = self.drive.rules().pkw().errors().named(e);
                (format!("error:{pnu}={}", e.0), named.to_string())
            }
        };
        self.drain(now, rec);
        rec.answer(now, "par".to_owned(), answer, meaning);
    }
}

impl Simulated for PsdSim {
    type Step = Step;
    type Event = TraceEvent;

    fn advance(&mut self, now: Micros) {
        self.drive.advance(now);
    }

    fn cycle(&mut self, now: Micros) {
        self.send(now);
    }

    fn env(&mut self, now: Micros, change: EnvChange) {
        self.drive.handle_env(now, change);
    }

    fn unplayable(step: &Step) -> Option<&'static str> {
        match step {
            Step::Hold { .. } | Step::Until { .. } | Step::Advance { .. } | Step::Env { .. } => {
                Some(step.name())
            }
            _ => None,
        }
    }

    fn step(&mut self, now: Micros, step: &Step, rec: &mut Recorder<TraceEvent>) {
        match step {
            Step::Process { control, target } => {
                if let Some(c) = control {
                    self.out.control = *c;
                }
                if let Some(t) = target {
                    self.out.target = *t;
                }
                self.send(now);
            }
            Step::Offset { control, offset } => {
                if let Some(c) = control {
                    self.out.control = *c;
                }
                let t = i64::from(self.drive.input().actual).saturating_add(*offset);
                self.out.target =
                    i32::try_from(t).unwrap_or(if t < 0 { i32::MIN } else { i32::MAX });
                self.send(now);
            }
            Step::Pkw { pkw } => {
                self.out.pkw = PkwRequest::from(*pkw);
                self.send(now);
            }
            Step::RecordRead { index } => {
                self.record(now, RecordRequest::Read { index: *index }, rec);
            }
            Step::RecordWrite { index, hex } => {
                let req = RecordRequest::Write {
                    index: *index,
                    data: hex.clone(),
                };
                self.record(now, req, rec);
            }
            Step::Par { pnu, value } => self.par(now, *pnu, *value, rec),
            Step::Link { event } => self.drive.handle_link(now, *event),
            Step::PowerCycle => self.drive.power_cycle(now),
            // Refused by `unplayable` before the script plays.
            Step::Hold { .. } | Step::Until { .. } | Step::Advance { .. } | Step::Env { .. } => {}
        }
    }

    fn drain(&mut self, now: Micros, rec: &mut Recorder<TraceEvent>) {
        while let Some((at, e)) = self.drive.poll_event() {
            rec.event(at, TraceEvent(e));
        }
        let pkw = self.drive.input().pkw;
        if pkw != self.last_pkw {
            self.last_pkw = pkw;
            let pr = self.drive.rules().pkw();
            let answer = pr
                .reply(&pkw)
                .map(|r| pr.format_reply(&r))
                .unwrap_or_else(|| format!("ak {}", pkw.ak));
            rec.answer(now, "pkw".to_owned(), answer, pr.describe_response(&pkw));
        }
    }

    fn observe(&self) -> Observation {
        let i = self.drive.input();
        Observation {
            position: i64::from(i.actual),
            speed: i64::from(i.speed),
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

/// Parses `text` and plays it on a drive built from `config`.
pub fn run_text(
    spec: &Spec,
    config: DriveConfig,
    text: &str,
    opts: &RunOptions,
) -> Result<Trace<TraceEvent>, RunError> {
    let drive = Drive::new(spec, config.clone())?;
    let script = parse(drive.rules(), text)?;
    run(spec, config, &script, opts)
}

/// Plays `script` on a drive built from `config` and returns the trace.
///
/// The controller sends one output image per bus cycle from time 0; each line acts at its
/// time, in file order. Without an `end` line the run goes on after the last line until the
/// drive is idle, at most [`RunOptions::tail_limit_us`].
pub fn run(
    spec: &Spec,
    config: DriveConfig,
    script: &Script<Step>,
    opts: &RunOptions,
) -> Result<Trace<TraceEvent>, RunError> {
    let family = spec.family(FamilyId::Psd4xx);
    let model = family
        .model(&config.model)
        .map_or_else(|| config.model.clone(), |m| m.id.clone());
    let mut sim = PsdSim::new(Drive::new(spec, config)?);
    let played = play(&mut sim, script, opts)?;
    let bits = decode_bits(sim.drive.rules().status_bits(), played.seen_status)
        .set
        .into_iter()
        .map(|b| BitName {
            bit: b.bit,
            name: b.name,
        })
        .collect();
    Ok(Trace {
        family: FamilyId::Psd4xx.to_string(),
        model,
        every_ms: opts.every_ms,
        bits,
        entries: played.entries,
        passed: played.passed,
        failed: played.failed,
    })
}

/// Parses a script with the PSD4xx commands of `rules`.
pub fn parse(rules: &Rules, text: &str) -> Result<Script<Step>, ScriptError> {
    Script::parse(text, &PsdDialect::new(rules))
}
