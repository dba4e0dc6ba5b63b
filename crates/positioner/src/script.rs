//! The `sim-run` script: a small line format of timed commands, environment changes and
//! expectations that a family's reference model runs on virtual time.
//!
//! This module holds what every family shares: the line grammar, the times, the environment
//! changes of [`mod@crate::env`], the expectations and the resulting [`Trace`]. A family's own
//! commands (process data, parameter channel, link events) are a text form of the family's
//! step type (`Step` in the family crate's `step` module, `spec/SCHEMA.md` "Steps and
//! scenarios"), read through a [`Dialect`].
//!
//! ```text
//! # a comment; blank lines are skipped
//! 0 ms: control 0x14 target 12000     # family command (PSD4xx: control word and target)
//! 10 ms: pkw write:44=5               # family command (PSD4xx: PKW mini-syntax)
//! +490 ms: env motor-voltage 20.0     # "+": relative to the previous line's time
//! 1.5 s: env block 5000
//! 3 s: expect status bit 0 = 1
//! 3 s: expect position = 11990..12010
//! 4 s: end                            # stop here (default: run until the drive is idle)
//! ```
//!
//! Times are `<number> <unit>` with unit `us`, `ms` or `s` (decimals allowed, `1.5 s`), and
//! never go back. Environment changes (`env …`): `motor-voltage V`, `control-voltage V` (volts,
//! 0.1 V resolution; 0 switches the drive off), `temperature °C`, `load-torque cNm`,
//! `jam on|off`, `block POS`, `clear-blocks`, `displace INCR`, `back-drive RPM`,
//! `miss-steps INCR`, `position-fault`. Expectations (`expect …`): `position`, `speed`,
//! `status` or `status bit N`, then `=` and a value or an inclusive range `LOW..HIGH`.
//!
//! Parsing never panics; every error names its line. Memory grows with the script and the
//! trace only.

use crate::env::EnvChange;
use crate::machine::{CoreEvent, Micros};
use drivespec_spec::hex::IntError;
use serde::Serialize;
use std::fmt;

/// Why a script line cannot be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum LineError {
    /// The line has no `<time>:` prefix.
    #[error("expected `<time>: <command>`, e.g. `10 ms: env jam on`")]
    MissingTime,
    /// The time is not `<number> <unit>`.
    #[error("bad time {found:?}: expected a number and us, ms or s, e.g. `1.5 s`")]
    BadTime {
        /// The text found.
        found: String,
    },
    /// The time is before the previous line's.
    #[error("time {at} µs is before the previous line's {previous} µs")]
    TimeGoesBack {
        /// This line's time, µs.
        at: Micros,
        /// The previous line's time, µs.
        previous: Micros,
    },
    /// The time is past the longest script ([`MAX_SCRIPT_US`]).
    #[error("time {at} µs is past the longest script, {} s of simulated time", MAX_SCRIPT_US / 1_000_000)]
    TooLate {
        /// This line's time, µs.
        at: Micros,
    },
    /// Nothing after the colon.
    #[error("no command after the time")]
    Empty,
    /// An unknown word where a keyword belongs.
    #[error("unknown {what} {found:?}; expected one of: {expected}")]
    Unknown {
        /// What kind of word.
        what: &'static str,
        /// The word found.
        found: String,
        /// The words allowed there.
        expected: String,
    },
    /// An argument is missing.
    #[error("missing {what}")]
    Missing {
        /// What is missing.
        what: &'static str,
    },
    /// An argument is not a number in range.
    #[error("bad {what} {found:?}")]
    BadNumber {
        /// What the number is.
        what: &'static str,
        /// The text found.
        found: String,
    },
    /// More words than the command takes.
    #[error("unexpected {found:?} at the end of the command")]
    Trailing {
        /// The extra text.
        found: String,
    },
    /// A family command is malformed (the family's own error in words).
    #[error("{message}")]
    Family {
        /// What is wrong.
        message: String,
    },
}

/// A script error with the line it is on.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("line {line}: {error} (in {text:?})")]
pub struct ScriptError {
    /// Line number, 1-based.
    pub line: usize,
    /// The line as written, trimmed.
    pub text: String,
    /// What is wrong.
    pub error: LineError,
}

/// A family's commands in a script: parses the words after the time that are not `env`,
/// `expect` or `end` into the family's step.
pub trait Dialect {
    /// The family's step.
    type Step;
    /// Parses one family command: `verb` is the first word, `rest` the text after it.
    fn command(&self, verb: &str, rest: &str) -> Result<Self::Step, LineError>;
    /// The family's verbs, for error messages.
    fn verbs(&self) -> &'static str;
}

/// What an expectation looks at.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "what", rename_all = "kebab-case")]
pub enum Probe {
    /// Actual position, user increments.
    Position,
    /// Current speed, rpm.
    Speed,
    /// The whole status word.
    Status,
    /// One status bit, 0 or 1.
    StatusBit {
        /// Bit number.
        bit: u32,
    },
}

/// An expectation: a probe and the inclusive range its value must lie in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Expect {
    /// What is looked at.
    pub probe: Probe,
    /// Lowest value allowed.
    pub low: i64,
    /// Highest value allowed.
    pub high: i64,
}

/// What the drive shows at one moment, for expectations and samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Observation {
    /// Actual position, user increments.
    pub position: i64,
    /// Current speed, rpm.
    pub speed: i64,
    /// Status word.
    pub status: u64,
}

impl Expect {
    /// The value the probe reads in `o`.
    pub fn value(&self, o: &Observation) -> i64 {
        match self.probe {
            Probe::Position => o.position,
            Probe::Speed => o.speed,
            Probe::Status => i64::try_from(o.status).unwrap_or(i64::MAX),
            Probe::StatusBit { bit } => i64::from(bit < 64 && (o.status >> bit) & 1 == 1),
        }
    }

    /// Whether `o` meets the expectation.
    pub fn holds(&self, o: &Observation) -> bool {
        (self.low..=self.high).contains(&self.value(o))
    }
}

/// What one script line does.
#[derive(Debug, Clone, PartialEq)]
pub enum Action<C> {
    /// An environment change.
    Env(EnvChange),
    /// An expectation checked at the step's time.
    Expect(Expect),
    /// The run ends here.
    End,
    /// A family step.
    Step(C),
}

/// One script line.
#[derive(Debug, Clone, PartialEq)]
pub struct Line<C> {
    /// Line number, 1-based.
    pub line: usize,
    /// Virtual time, µs.
    pub at: Micros,
    /// The command as written, after the time.
    pub text: String,
    /// What to do.
    pub action: Action<C>,
}

/// A parsed script: lines in time order.
#[derive(Debug, Clone, PartialEq)]
pub struct Script<C> {
    /// The lines, in file order (times never decrease).
    pub lines: Vec<Line<C>>,
}

impl<C> Script<C> {
    /// Parses a script with a family's dialect.
    pub fn parse<D: Dialect<Step = C>>(text: &str, dialect: &D) -> Result<Script<C>, ScriptError> {
        let mut lines = Vec::new();
        let mut previous: Micros = 0;
        for (i, raw) in text.lines().enumerate() {
            let line = i.saturating_add(1);
            let body = raw.split_once('#').map_or(raw, |(b, _)| b).trim();
            if body.is_empty() {
                continue;
            }
            let fail = |error| ScriptError {
                line,
                text: body.to_owned(),
                error,
            };
            let (time, command) = body.split_once(':').ok_or(fail(LineError::MissingTime))?;
            let at = parse_time(time, previous).map_err(fail)?;
            if at < previous {
                return Err(fail(LineError::TimeGoesBack { at, previous }));
            }
            previous = at;
            let command = command.trim();
            let action = parse_action(command, dialect).map_err(fail)?;
            lines.push(Line {
                line,
                at,
                text: command.to_owned(),
                action,
            });
        }
        Ok(Script { lines })
    }

    /// The time of the `end` line, if there is one.
    pub fn end(&self) -> Option<Micros> {
        self.lines
            .iter()
            .find(|s| matches!(s.action, Action::End))
            .map(|s| s.at)
    }

    /// The time of the last line, 0 for an empty script.
    pub fn last(&self) -> Micros {
        self.lines.last().map_or(0, |s| s.at)
    }
}

fn parse_time(text: &str, previous: Micros) -> Result<Micros, LineError> {
    let t = text.trim();
    let bad = || LineError::BadTime {
        found: t.to_owned(),
    };
    let (relative, t2) = match t.strip_prefix('+') {
        Some(rest) => (true, rest.trim()),
        None => (false, t),
    };
    let split = t2
        .find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '_'))
        .ok_or_else(bad)?;
    let (num, unit) = (
        t2.get(..split).ok_or_else(bad)?,
        t2.get(split..).ok_or_else(bad)?,
    );
    let scale = match unit.trim() {
        "us" | "µs" => 1.0,
        "ms" => 1e3,
        "s" => 1e6,
        _ => return Err(bad()),
    };
    let n: f64 = num.replace('_', "").parse().map_err(|_| bad())?;
    let us = (n * scale).round();
    if !us.is_finite() || !(0.0..=1e15).contains(&us) {
        return Err(bad());
    }
    let us = us as Micros;
    let at = if relative {
        previous.saturating_add(us)
    } else {
        us
    };
    if at > MAX_SCRIPT_US {
        return Err(LineError::TooLate { at });
    }
    Ok(at)
}

/// The latest time a script line may name: one hour of simulated time (3.6 million 1 ms bus
/// cycles), so a run and its trace stay bounded.
pub const MAX_SCRIPT_US: Micros = 3_600_000_000;

fn parse_action<D: Dialect>(command: &str, dialect: &D) -> Result<Action<D::Step>, LineError> {
    let (verb, rest) = split_word(command);
    match verb {
        "" => Err(LineError::Empty),
        "env" => parse_env(rest).map(Action::Env),
        "expect" => parse_expect(rest).map(Action::Expect),
        "end" => {
            no_more(rest)?;
            Ok(Action::End)
        }
        _ => dialect.command(verb, rest).map(Action::Step),
    }
}

/// The first word and the trimmed rest.
pub fn split_word(text: &str) -> (&str, &str) {
    let t = text.trim();
    match t.split_once(char::is_whitespace) {
        Some((w, rest)) => (w, rest.trim()),
        None => (t, ""),
    }
}

/// Fails when `rest` is not empty.
pub fn no_more(rest: &str) -> Result<(), LineError> {
    if rest.trim().is_empty() {
        Ok(())
    } else {
        Err(LineError::Trailing {
            found: rest.trim().to_owned(),
        })
    }
}

/// An integer: decimal with an optional sign, or `0x` hex, `_` allowed.
pub fn parse_int(what: &'static str, text: &str) -> Result<i64, LineError> {
    drivespec_spec::hex::parse_int(text).map_err(|e| match e {
        IntError::Empty => LineError::Missing { what },
        _ => LineError::BadNumber {
            what,
            found: text.to_owned(),
        },
    })
}

/// An integer that fits `T`.
pub fn parse_in<T: TryFrom<i64>>(what: &'static str, text: &str) -> Result<T, LineError> {
    let n = parse_int(what, text)?;
    T::try_from(n).map_err(|_| LineError::BadNumber {
        what,
        found: text.trim().to_owned(),
    })
}

fn parse_volts(what: &'static str, text: &str) -> Result<u16, LineError> {
    let bad = || LineError::BadNumber {
        what,
        found: text.trim().to_owned(),
    };
    let v: f64 = text.trim().parse().map_err(|_| bad())?;
    let dv = (v * 10.0).round();
    if !(0.0..=f64::from(u16::MAX)).contains(&dv) {
        return Err(bad());
    }
    Ok(dv as u16)
}

const ENV_KINDS: &str = "motor-voltage, control-voltage, temperature, load-torque, jam, block, \
                         clear-blocks, displace, back-drive, miss-steps, position-fault";

fn one_arg<'a>(what: &'static str, rest: &'a str) -> Result<&'a str, LineError> {
    let (arg, tail) = split_word(rest);
    if arg.is_empty() {
        return Err(LineError::Missing { what });
    }
    no_more(tail)?;
    Ok(arg)
}

fn parse_env(rest: &str) -> Result<EnvChange, LineError> {
    let (kind, args) = split_word(rest);
    Ok(match kind {
        "motor-voltage" => EnvChange::MotorVoltage {
            dv: parse_volts("voltage in V", one_arg("voltage in V", args)?)?,
        },
        "control-voltage" => EnvChange::ControlVoltage {
            dv: parse_volts("voltage in V", one_arg("voltage in V", args)?)?,
        },
        "temperature" => EnvChange::Temperature {
            celsius: parse_in("temperature in °C", one_arg("temperature in °C", args)?)?,
        },
        "load-torque" => EnvChange::LoadTorque {
            cnm: parse_in("torque in cNm", one_arg("torque in cNm", args)?)?,
        },
        "jam" => EnvChange::Jam {
            on: match one_arg("on or off", args)? {
                "on" => true,
                "off" => false,
                other => {
                    return Err(LineError::Unknown {
                        what: "jam state",
                        found: other.to_owned(),
                        expected: "on, off".to_owned(),
                    })
                }
            },
        },
        "block" => {
            let args = args.strip_prefix("at ").unwrap_or(args);
            EnvChange::Block {
                at: parse_int("position", one_arg("position", args)?)?,
            }
        }
        "clear-blocks" => {
            no_more(args)?;
            EnvChange::ClearBlocks
        }
        "displace" => EnvChange::Displace {
            by: parse_int("distance", one_arg("distance", args)?)?,
        },
        "back-drive" => EnvChange::BackDrive {
            rpm: parse_in("speed in rpm", one_arg("speed in rpm", args)?)?,
        },
        "miss-steps" => EnvChange::MissSteps {
            by: parse_int("distance", one_arg("distance", args)?)?,
        },
        "position-fault" => {
            no_more(args)?;
            EnvChange::PositionFault
        }
        "" => {
            return Err(LineError::Missing {
                what: "environment change",
            })
        }
        other => {
            return Err(LineError::Unknown {
                what: "environment change",
                found: other.to_owned(),
                expected: ENV_KINDS.to_owned(),
            })
        }
    })
}

fn parse_expect(rest: &str) -> Result<Expect, LineError> {
    let (lhs, rhs) = rest.split_once('=').ok_or(LineError::Missing {
        what: "`=` and the expected value",
    })?;
    let words: Vec<&str> = lhs.split_whitespace().collect();
    let probe = match words.as_slice() {
        ["position"] => Probe::Position,
        ["speed"] => Probe::Speed,
        ["status"] => Probe::Status,
        ["status", "bit", n] => Probe::StatusBit {
            bit: parse_in("bit number", n)?,
        },
        _ => {
            return Err(LineError::Unknown {
                what: "expectation",
                found: lhs.trim().to_owned(),
                expected: "position, speed, status, status bit N".to_owned(),
            })
        }
    };
    let rhs = rhs.trim();
    let (low, high) = match rhs.split_once("..") {
        Some((a, b)) => (parse_int("low end", a)?, parse_int("high end", b)?),
        None => {
            let v = parse_int("expected value", rhs)?;
            (v, v)
        }
    };
    Ok(Expect { probe, low, high })
}

impl fmt::Display for Expect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.probe {
            Probe::Position => f.write_str("position")?,
            Probe::Speed => f.write_str("speed")?,
            Probe::Status => f.write_str("status")?,
            Probe::StatusBit { bit } => write!(f, "status bit {bit}")?,
        }
        if self.low == self.high {
            write!(f, " = {}", self.low)
        } else {
            write!(f, " = {}..{}", self.low, self.high)
        }
    }
}

// ---------------------------------------------------------------------- traces

/// A status bit's number and spec name, for the trace legend.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct BitName {
    /// Bit number.
    pub bit: u32,
    /// The spec's name.
    pub name: String,
}

/// What one trace entry records.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum What<E> {
    /// A script step was applied.
    Step {
        /// Script line.
        line: usize,
        /// The command as written.
        text: String,
    },
    /// What the drive shows: on every change of the status word or of standstill, and every
    /// `every_ms`.
    Sample {
        /// Actual position, user increments.
        position: i64,
        /// Speed, rpm.
        speed: i64,
        /// Status word.
        status: u64,
        /// Status bits set.
        bits: Vec<u32>,
    },
    /// An answer on a parameter channel (PKW, record, ISDU, direct write).
    Answer {
        /// The channel.
        channel: String,
        /// The answer in the channel's mini-syntax.
        answer: String,
        /// The answer in words.
        meaning: String,
    },
    /// Something the model did.
    Event {
        /// The event.
        event: E,
    },
    /// An expectation was checked.
    Check {
        /// Script line.
        line: usize,
        /// The expectation.
        expect: Expect,
        /// The value found.
        found: i64,
        /// Whether it held.
        passed: bool,
    },
    /// The run stopped after the tail limit while the drive still moved.
    TailLimit,
}

/// One trace entry.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Entry<E> {
    /// Virtual time, µs.
    pub t_us: Micros,
    /// What happened.
    #[serde(flatten)]
    pub what: What<E>,
}

/// The result of a script run.
///
/// JSON: `{"family", "model", "every_ms", "bits": [{"bit", "name"}], "entries": [{"t_us",
/// "kind": "step"|"sample"|"answer"|"event"|"check"|"tail-limit", …}], "passed", "failed"}`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Trace<E> {
    /// Family id.
    pub family: String,
    /// Device model id.
    pub model: String,
    /// Sampling period, ms (0: changes only).
    pub every_ms: u64,
    /// Names of the status bits that were set at some point.
    pub bits: Vec<BitName>,
    /// Everything that happened, in time order.
    pub entries: Vec<Entry<E>>,
    /// Expectations that held.
    pub passed: usize,
    /// Expectations that failed.
    pub failed: usize,
}

impl<E: fmt::Display> Trace<E> {
    /// The trace as text for people: one line per entry, then the bit legend and the verdict.
    pub fn to_text(&self) -> String {
        use fmt::Write as _;
        let mut out = format!("{} {}\n\n", self.family, self.model);
        out.push_str("    t/ms     actual    rpm  status  bits\n");
        for e in &self.entries {
            let t = format_ms(e.t_us);
            let _ = match &e.what {
                What::Sample {
                    position,
                    speed,
                    status,
                    bits,
                } => {
                    let b: Vec<String> = bits.iter().map(u32::to_string).collect();
                    writeln!(
                        out,
                        "{t:>8} {position:>10} {speed:>6}  {status:#06x}  {}",
                        b.join(",")
                    )
                }
                What::Step { line, text } => writeln!(out, "{t:>8}  > line {line}: {text}"),
                What::Answer {
                    channel,
                    answer,
                    meaning,
                } if meaning.is_empty() => writeln!(out, "{t:>8}  < {channel} {answer}"),
                What::Answer {
                    channel,
                    answer,
                    meaning,
                } => writeln!(out, "{t:>8}  < {channel} {answer}  ({meaning})"),
                What::Event { event } => writeln!(out, "{t:>8}  * {event}"),
                What::Check {
                    line,
                    expect,
                    found,
                    passed,
                } => writeln!(
                    out,
                    "{t:>8}  {} line {line}: expect {expect} (found {found})",
                    if *passed { "ok  " } else { "FAIL" }
                ),
                What::TailLimit => {
                    writeln!(out, "{t:>8}  ! still moving: stopped at the tail limit")
                }
            };
        }
        if !self.bits.is_empty() {
            out.push_str("\nstatus bits:\n");
            for b in &self.bits {
                let _ = writeln!(out, "  {:>2} {}", b.bit, b.name);
            }
        }
        let _ = writeln!(
            out,
            "\nexpectations: {} passed, {} failed",
            self.passed, self.failed
        );
        out
    }
}

// ---------------------------------------------------------------------- runner

/// How a script is played.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RunOptions {
    /// A sample every this many ms besides the changes; 0: changes only.
    pub every_ms: u64,
    /// Bus cycle: the master's cyclic output goes out every this many µs (DECISION: 1 ms, a
    /// common PROFINET send clock and IO-Link cycle order of magnitude).
    pub cycle_us: Micros,
    /// Without an `end` line the run continues after the last line until the drive is idle,
    /// but at most this long (µs).
    pub tail_limit_us: Micros,
}

impl Default for RunOptions {
    /// Samples every 100 ms, 1 ms bus cycle, at most 120 s after the last line.
    fn default() -> RunOptions {
        RunOptions {
            every_ms: 100,
            cycle_us: 1000,
            tail_limit_us: 120_000_000,
        }
    }
}

/// Collects trace entries while a script plays.
#[derive(Debug, Clone, PartialEq)]
pub struct Recorder<E> {
    entries: Vec<Entry<E>>,
}

impl<E> Recorder<E> {
    /// Records `what` at `t_us`.
    pub fn push(&mut self, t_us: Micros, what: What<E>) {
        self.entries.push(Entry { t_us, what });
    }

    /// Records a model event.
    pub fn event(&mut self, t_us: Micros, event: E) {
        self.push(t_us, What::Event { event });
    }

    /// Records an answer on a parameter channel.
    pub fn answer(&mut self, t_us: Micros, channel: String, answer: String, meaning: String) {
        self.push(
            t_us,
            What::Answer {
                channel,
                answer,
                meaning,
            },
        );
    }
}

/// A family's reference model as a script runner sees it: the master's
/// cyclic output, the family's steps, the environment and what the drive shows.
pub trait Simulated {
    /// The family's step.
    type Step;
    /// The model's trace events.
    type Event;
    /// Runs the model up to `now`.
    fn advance(&mut self, now: Micros);
    /// One bus cycle at `now`: the master's current output goes out.
    fn cycle(&mut self, now: Micros);
    /// An environment change at `now`.
    fn env(&mut self, now: Micros, change: EnvChange);
    /// Whether the runner can play `step` at one moment; the `do` name of the step when it
    /// cannot (a step that waits on the drive or counts bus cycles).
    fn unplayable(step: &Self::Step) -> Option<&'static str>;
    /// A family step at `now`, one [`Self::unplayable`] accepts; answers go to `rec`.
    fn step(&mut self, now: Micros, step: &Self::Step, rec: &mut Recorder<Self::Event>);
    /// Moves the model's pending events and asynchronous answers (e.g. a new PKW response in
    /// the input image) into `rec`, stamped `now` when they carry no time.
    fn drain(&mut self, now: Micros, rec: &mut Recorder<Self::Event>);
    /// What the drive shows now.
    fn observe(&self) -> Observation;
    /// When the model next changes by itself; None when it is idle.
    fn poll_timeout(&self) -> Option<Micros>;
    /// Width of the status word in bits.
    fn status_width(&self) -> u32;
}

/// What playing a script produced; the family adds its name and model to make a [`Trace`].
#[derive(Debug, Clone, PartialEq)]
pub struct Played<E> {
    /// Everything that happened, in time order.
    pub entries: Vec<Entry<E>>,
    /// The OR of every status word sampled (for the bit legend).
    pub seen_status: u64,
    /// Expectations that held.
    pub passed: usize,
    /// Expectations that failed.
    pub failed: usize,
}

struct Sampler {
    last: Option<(u64, bool)>,
    last_at: Option<Micros>,
    every_us: Micros,
    seen: u64,
}

impl Sampler {
    fn sample<S: Simulated>(
        &mut self,
        sim: &mut S,
        now: Micros,
        force: bool,
        rec: &mut Recorder<S::Event>,
    ) {
        sim.drain(now, rec);
        let o = sim.observe();
        let key = (o.status, o.speed != 0);
        let periodic = self.every_us > 0 && now % self.every_us == 0;
        let fresh = self.last_at != Some(now);
        if self.last != Some(key) || (fresh && (force || periodic)) {
            self.last = Some(key);
            self.last_at = Some(now);
            self.seen |= o.status;
            let bits = (0..sim.status_width().min(64))
                .filter(|b| (o.status >> b) & 1 == 1)
                .collect();
            rec.push(
                now,
                What::Sample {
                    position: o.position,
                    speed: o.speed,
                    status: o.status,
                    bits,
                },
            );
        }
    }
}

/// Why a script cannot be played.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PlayError {
    /// A line holds a family step that acts over bus cycles or waits on the drive, which a
    /// timed script cannot play.
    #[error("line {line}: a `{step}` step cannot be played at one moment of a script")]
    Unplayable {
        /// Line number, 1-based.
        line: usize,
        /// The step's `do` name.
        step: &'static str,
    },
}

/// Plays `script` on `sim`.
///
/// The master's output goes out once per bus cycle from time 0; each line acts at its time,
/// in file order, before the cycle of that time. Without an `end` line the run goes on after
/// the last line until the model is idle, at most [`RunOptions::tail_limit_us`]. A zero
/// `cycle_us` counts as 1 µs. A script with a step [`Simulated::unplayable`] names is refused
/// before anything plays.
pub fn play<S: Simulated>(
    sim: &mut S,
    script: &Script<S::Step>,
    opts: &RunOptions,
) -> Result<Played<S::Event>, PlayError> {
    for l in &script.lines {
        if let Action::Step(step) = &l.action {
            if let Some(name) = S::unplayable(step) {
                return Err(PlayError::Unplayable {
                    line: l.line,
                    step: name,
                });
            }
        }
    }
    let mut rec = Recorder {
        entries: Vec::new(),
    };
    let mut smp = Sampler {
        last: None,
        last_at: None,
        every_us: opts.every_ms.saturating_mul(1000),
        seen: 0,
    };
    let (mut passed, mut failed) = (0, 0);
    let cycle = opts.cycle_us.max(1);
    let end = script.end();
    let last = script.last();
    let mut steps = script.lines.iter().peekable();
    let mut next_cycle: Micros = 0;
    let mut now: Micros = 0;
    loop {
        if let Some(step) = steps.next_if(|s| s.at <= next_cycle) {
            now = step.at;
            sim.advance(now);
            sim.drain(now, &mut rec);
            rec.push(
                now,
                What::Step {
                    line: step.line,
                    text: step.text.clone(),
                },
            );
            match &step.action {
                Action::Env(c) => sim.env(now, *c),
                Action::Step(c) => sim.step(now, c, &mut rec),
                Action::Expect(e) => {
                    let o = sim.observe();
                    let ok = e.holds(&o);
                    if ok {
                        passed += 1;
                    } else {
                        failed += 1;
                    }
                    rec.push(
                        now,
                        What::Check {
                            line: step.line,
                            expect: *e,
                            found: e.value(&o),
                            passed: ok,
                        },
                    );
                }
                Action::End => {
                    smp.sample(sim, now, true, &mut rec);
                    break;
                }
            }
            smp.sample(sim, now, false, &mut rec);
            continue;
        }
        if steps.peek().is_none() && end.is_none() && next_cycle > last {
            if sim.poll_timeout().is_none() {
                smp.sample(sim, now, true, &mut rec);
                break;
            }
            if next_cycle > last.saturating_add(opts.tail_limit_us) {
                smp.sample(sim, now, true, &mut rec);
                rec.push(now, What::TailLimit);
                break;
            }
        }
        now = next_cycle;
        sim.cycle(now);
        smp.sample(sim, now, false, &mut rec);
        next_cycle = next_cycle.saturating_add(cycle);
    }
    Ok(Played {
        entries: rec.entries,
        seen_status: smp.seen,
        passed,
        failed,
    })
}

/// A unit variant's name in kebab case, from its `Debug` form: `LimitReached` →
/// `limit-reached`.
pub fn kebab<T: fmt::Debug>(v: &T) -> String {
    let mut out = String::new();
    for (i, c) in format!("{v:?}").chars().enumerate() {
        if c.is_ascii_uppercase() {
            if i > 0 {
                out.push('-');
            }
            out.push(c.to_ascii_lowercase());
        } else {
            out.push(c);
        }
    }
    out
}

/// A core event as a short sentence for text traces.
pub fn describe_core(e: &CoreEvent) -> String {
    match e {
        CoreEvent::RunStarted {
            kind,
            target,
            waypoints,
        } => {
            let mut s = format!("{} run started", kebab(kind));
            if let Some(t) = target {
                s.push_str(&format!(" to {t}"));
            }
            let via: Vec<String> = waypoints
                .iter()
                .take(waypoints.len().saturating_sub(1))
                .map(i64::to_string)
                .collect();
            if !via.is_empty() {
                s.push_str(&format!(" via {}", via.join(", ")));
            }
            s
        }
        CoreEvent::Refused { reason } => format!("run refused: {}", kebab(reason)),
        CoreEvent::SecondAttempt { actual } => format!("second positioning attempt from {actual}"),
        CoreEvent::RunEnded {
            kind,
            outcome,
            actual,
        } => format!("{} run ended: {} at {actual}", kebab(kind), kebab(outcome)),
        CoreEvent::PowerOn => "power on".to_owned(),
        CoreEvent::PowerOff => "power off".to_owned(),
    }
}

/// µs as milliseconds, with three decimals only when not whole.
fn format_ms(us: Micros) -> String {
    if us % 1000 == 0 {
        (us / 1000).to_string()
    } else {
        format!("{}.{:03}", us / 1000, us % 1000)
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;

    struct NoFamily;
    impl Dialect for NoFamily {
        type Step = String;
        fn command(&self, verb: &str, rest: &str) -> Result<String, LineError> {
            match verb {
                "say" => Ok(rest.to_owned()),
                _ => Err(LineError::Unknown {
                    what: "command",
                    found: verb.to_owned(),
                    expected: self.verbs().to_owned(),
                }),
            }
        }
        fn verbs(&self) -> &'static str {
            "say"
        }
    }

    #[test]
    fn parses_times_env_expect_and_family_commands() {
        let s = Script::parse(
            "# title\n\n0 ms: say hi\n+1.5 s: env motor-voltage 17.4 # low\n2 s: expect status bit 4 = 0\n2s: expect position = -5..0x10\n3 s: end\n",
            &NoFamily,
        )
        .unwrap();
        assert_eq!(s.lines.len(), 5);
        assert_eq!(s.lines[0].action, Action::Step("hi".to_owned()));
        assert_eq!(s.lines[1].at, 1_500_000);
        assert_eq!(
            s.lines[1].action,
            Action::Env(EnvChange::MotorVoltage { dv: 174 })
        );
        assert_eq!(
            s.lines[3].action,
            Action::Expect(Expect {
                probe: Probe::Position,
                low: -5,
                high: 16
            })
        );
        assert_eq!(s.end(), Some(3_000_000));
    }

    #[test]
    fn errors_name_the_line() {
        let e = Script::parse("1 s: env jam on\n0 s: env jam off", &NoFamily).unwrap_err();
        assert_eq!(e.line, 2);
        assert!(matches!(e.error, LineError::TimeGoesBack { .. }));
        let e = Script::parse("\n5 parsecs: end", &NoFamily).unwrap_err();
        assert_eq!(e.line, 2);
        assert!(matches!(e.error, LineError::BadTime { .. }));
        let e = Script::parse("1 s: env quake 5", &NoFamily).unwrap_err();
        assert!(matches!(e.error, LineError::Unknown { .. }));
        let e = Script::parse("1 s: dance", &NoFamily).unwrap_err();
        assert_eq!(
            e.to_string(),
            "line 1: unknown command \"dance\"; expected one of: say (in \"1 s: dance\")"
        );
        let e = Script::parse("no colon", &NoFamily).unwrap_err();
        assert_eq!(e.error, LineError::MissingTime);
    }

    #[test]
    fn expectations_read_the_observation() {
        let o = Observation {
            position: 100,
            speed: 0,
            status: 0x11,
        };
        let bit = |bit, v| Expect {
            probe: Probe::StatusBit { bit },
            low: v,
            high: v,
        };
        assert!(bit(0, 1).holds(&o));
        assert!(bit(1, 0).holds(&o));
        assert!(!bit(4, 0).holds(&o));
        assert!(bit(99, 0).holds(&o));
    }
}
