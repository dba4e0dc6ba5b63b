//! `sim-run` for the PSD4xx: the family's script commands and the runner that plays a
//! script on the reference [`Drive`] on virtual time.
//!
//! The line grammar, environment changes and expectations are the shared ones of
//! [`drivespec_positioner::script`]; the PSD4xx commands are:
//!
//! ```text
//! control WORD [target POS]      control word (3.7) and optionally the target (par. 33)
//! target POS                     target only
//! pkw REQUEST                    PKW block in the mini-syntax (`read:44`, `write:44=5`, `none`)
//! record read INDEX              acyclic read record (3.2.2)
//! record write INDEX BYTE…       acyclic write record, hex bytes, control byte first
//! par PNU = VALUE                direct parameter write (the oracle's access, no PKW traffic)
//! link connected|lost|iops-bad|iops-good     connection events (3.9, 4.9)
//! power-cycle                    control voltage off and on again
//! ```
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
use crate::{Output, PkwRequest, PkwResponse, Rules};
pub use drivespec_positioner::script::RunOptions;
use drivespec_positioner::script::{
    describe_core, kebab, no_more, parse_in, play, split_word, BitName, Dialect, LineError,
    Observation, Recorder, Script, ScriptError, Simulated, Trace,
};
use drivespec_positioner::{decode_bits, EnvChange, Micros};
use drivespec_spec::hex::{parse_hex_digits, to_hex};
use drivespec_spec::{FamilyId, Spec};
use serde::Serialize;
use std::fmt;

/// One PSD4xx script command (manual 3.2.2, 3.5.1, 3.7, 3.8, 3.9).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum PsdCommand {
    /// Control word and optionally the target (3.7, par. 33).
    Control {
        /// Control word.
        word: u16,
        /// New target, or the one sent before.
        target: Option<i32>,
    },
    /// The target only (par. 33).
    Target(i32),
    /// The PKW block sent from now on (3.8).
    Pkw(PkwRequest),
    /// An acyclic record request (3.2.2).
    Record(RecordRequest),
    /// A direct parameter write (3.3).
    Par {
        /// Parameter number.
        pnu: u16,
        /// Value.
        value: i64,
    },
    /// A connection event (3.9, 4.9).
    Link(LinkEvent),
    /// Control voltage off and on again (2.2).
    PowerCycle,
}

/// The PSD4xx script commands, parsed against the codec tables.
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
    type Command = PsdCommand;

    fn command(&self, verb: &str, rest: &str) -> Result<PsdCommand, LineError> {
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
                Ok(PsdCommand::Control { word, target })
            }
            "target" => {
                let (pos, tail) = split_word(rest);
                no_more(tail)?;
                Ok(PsdCommand::Target(parse_in("target", pos)?))
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
                    .map(PsdCommand::Pkw)
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
                        Ok(PsdCommand::Record(RecordRequest::Read {
                            index: parse_in("record index", index)?,
                        }))
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
                        Ok(PsdCommand::Record(RecordRequest::Write { index, data }))
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
                Ok(PsdCommand::Par {
                    pnu: parse_in("parameter number", lhs)?,
                    value: parse_in("value", rhs)?,
                })
            }
            "link" => {
                let (ev, tail) = split_word(rest);
                no_more(tail)?;
                let ev = match ev {
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
                Ok(PsdCommand::Link(ev))
            }
            "power-cycle" => {
                no_more(rest)?;
                Ok(PsdCommand::PowerCycle)
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
    type Command = PsdCommand;
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

    fn command(&mut self, now: Micros, c: &PsdCommand, rec: &mut Recorder<TraceEvent>) {
        match c {
            PsdCommand::Control { word, target } => {
                self.out.control = *word;
                if let Some(t) = target {
                    self.out.target = *t;
                }
                self.send(now);
            }
            PsdCommand::Target(t) => {
                self.out.target = *t;
                self.send(now);
            }
            PsdCommand::Pkw(p) => {
                self.out.pkw = *p;
                self.send(now);
            }
            PsdCommand::Record(r) => self.record(now, r.clone(), rec),
            PsdCommand::Par { pnu, value } => self.par(now, *pnu, *value, rec),
            PsdCommand::Link(ev) => self.drive.handle_link(now, *ev),
            PsdCommand::PowerCycle => self.drive.power_cycle(now),
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
    script: &Script<PsdCommand>,
    opts: &RunOptions,
) -> Result<Trace<TraceEvent>, RunError> {
    let family = spec.family(FamilyId::Psd4xx);
    let model = family
        .model(&config.model)
        .map_or_else(|| config.model.clone(), |m| m.id.clone());
    let mut sim = PsdSim::new(Drive::new(spec, config)?);
    let played = play(&mut sim, script, opts);
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
pub fn parse(rules: &Rules, text: &str) -> Result<Script<PsdCommand>, ScriptError> {
    Script::parse(text, &PsdDialect::new(rules))
}
