//! Fuzz inputs and the replay file (`drivespec-fuzz-replay/1`, JSON; described in
//! `crates/conform/README.md`, "Fuzzing"): the steps of a sequence, what each exchange gave
//! when the file was written, and the finding it reproduces.
//!
//! Loading never panics: unknown keys, a wrong format name, bad hex or a step without the
//! fields its action needs are errors naming the step.

use crate::case::Record;
use crate::cyclic::{Env, Request};
use crate::link::Micros;
use drivespec_hpd::step::Step as HpdStep;
use drivespec_spec::hex::{parse_hex, to_hex};
use drivespec_spec::FamilyId;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Name and version of the replay format (README "Replay files").
pub const REPLAY_FORMAT: &str = "drivespec-fuzz-replay/1";

/// What one step does (README "Replay files", key `do`): a step of the file's family.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Action {
    /// An HPD step (exchange, send, listen, power-cycle, inputs, bit-rate).
    Hpd(HpdStep),
    /// A step of the cyclic-exchange protocol (PSD4xx, PSx3xx; README "Cyclic-exchange
    /// protocol").
    Cyclic(CyclicStep),
}

/// What one step of a cyclic-exchange sequence does; device and reference get the same
/// requests, every cycle's input image and every reply is judged (PSD4xx manual 3.5–3.9;
/// PSx3xx manual 3.1, 3.3).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CyclicStep {
    /// New control word and/or target (absent: unchanged), then one cycle (3.5.1).
    Process {
        /// Control word (par 32).
        control: Option<u16>,
        /// Target value (par 33).
        target: Option<i32>,
    },
    /// New control word (absent: unchanged) and a target this far from the reference's actual
    /// position, then one cycle.
    Offset {
        /// Control word (par 32).
        control: Option<u16>,
        /// Target minus actual position (increments).
        offset: i64,
    },
    /// A PKW block, any code (3.8), cycled until the reference answers it (at most 8 cycles).
    Pkw {
        /// Command code AK (0–15).
        ak: u8,
        /// SPM bit.
        spm: bool,
        /// Parameter number.
        pnu: u16,
        /// Subindex word IND.
        ind: u16,
        /// Parameter value PWE.
        pwe: u32,
    },
    /// Cycles with the outputs unchanged.
    Hold {
        /// How many.
        cycles: u32,
    },
    /// Cycles until the reference runs (`true`) or stands still, at most `max`.
    Until {
        /// Wait for "drive is running" set (true) or a standstill (false).
        running: bool,
        /// Most cycles.
        max: u32,
    },
    /// An acyclic record read (3.2.2).
    RecordRead {
        /// Record index (= parameter number).
        index: u16,
    },
    /// An acyclic record write, control byte first (3.2.2).
    RecordWrite {
        /// Record index (= parameter number).
        index: u16,
        /// The data.
        data: Vec<u8>,
    },
    /// An environment injection (`ENV`).
    Env(Env),
    /// Time passes without a bus cycle (`ADVANCE`).
    Advance {
        /// How long (µs).
        us: Micros,
    },
    /// A PSx3xx process output in `format`, then one cycle (PSx3xx manual 3.3.1): format 0
    /// sends `control` as the time-stamp code with `stamp`, format 1 the control word and
    /// `target`, format 2 also `speed`.
    ProcessData {
        /// Output format (0, 1, 2).
        format: u8,
        /// Control word (formats 1, 2) or time-stamp code (format 0).
        control: u16,
        /// Target position (formats 1, 2).
        target: i32,
        /// Target speed (format 2).
        speed: i16,
        /// Time stamp (format 0).
        stamp: u16,
    },
    /// A PSx3xx ISDU read between two cycles (PSx3xx manual 3.1).
    IsduRead {
        /// ISDU index.
        index: u16,
        /// Sub-index.
        subindex: u8,
    },
    /// A PSx3xx ISDU write between two cycles, most significant octet first (3.1).
    IsduWrite {
        /// ISDU index.
        index: u16,
        /// Sub-index.
        subindex: u8,
        /// The octets.
        data: Vec<u8>,
    },
}

impl CyclicStep {
    fn name(&self) -> &'static str {
        match self {
            CyclicStep::Process { .. } => "process",
            CyclicStep::Offset { .. } => "offset",
            CyclicStep::Pkw { .. } => "pkw",
            CyclicStep::Hold { .. } => "hold",
            CyclicStep::Until { .. } => "until",
            CyclicStep::RecordRead { .. } => "record-read",
            CyclicStep::RecordWrite { .. } => "record-write",
            CyclicStep::Env(_) => "env",
            CyclicStep::Advance { .. } => "advance",
            CyclicStep::ProcessData { .. } => "pd-out",
            CyclicStep::IsduRead { .. } => "isdu-read",
            CyclicStep::IsduWrite { .. } => "isdu-write",
        }
    }

    /// The family a step belongs to; None for steps every cyclic family has.
    pub fn family(&self) -> Option<FamilyId> {
        match self {
            CyclicStep::Process { .. }
            | CyclicStep::Offset { .. }
            | CyclicStep::Pkw { .. }
            | CyclicStep::RecordRead { .. }
            | CyclicStep::RecordWrite { .. } => Some(FamilyId::Psd4xx),
            CyclicStep::ProcessData { .. }
            | CyclicStep::IsduRead { .. }
            | CyclicStep::IsduWrite { .. } => Some(FamilyId::Psx3xx),
            CyclicStep::Hold { .. }
            | CyclicStep::Until { .. }
            | CyclicStep::Env(_)
            | CyclicStep::Advance { .. } => None,
        }
    }
}

/// The PKW block of a `pkw` step in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PkwFile {
    ak: u8,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    spm: bool,
    pnu: u16,
    #[serde(default)]
    ind: u16,
    #[serde(default)]
    pwe: u32,
}

impl Action {
    /// The bytes the step puts on the line, if any (a record write: its data).
    pub fn bytes(&self) -> Option<&[u8]> {
        match self {
            Action::Hpd(h) => h.bytes(),
            Action::Cyclic(
                CyclicStep::RecordWrite { data, .. } | CyclicStep::IsduWrite { data, .. },
            ) => Some(data),
            _ => None,
        }
    }

    /// The same action with other bytes (exchanges, sends, record and ISDU writes).
    pub fn with_bytes(&self, new: Vec<u8>) -> Action {
        match self {
            Action::Hpd(h) => Action::Hpd(h.with_bytes(new)),
            Action::Cyclic(CyclicStep::RecordWrite { index, .. }) => {
                Action::Cyclic(CyclicStep::RecordWrite {
                    index: *index,
                    data: new,
                })
            }
            Action::Cyclic(CyclicStep::IsduWrite {
                index, subindex, ..
            }) => Action::Cyclic(CyclicStep::IsduWrite {
                index: *index,
                subindex: *subindex,
                data: new,
            }),
            other => other.clone(),
        }
    }

    fn name(&self) -> &'static str {
        match self {
            Action::Hpd(h) => h.name(),
            Action::Cyclic(c) => c.name(),
        }
    }
}

/// One input of a fuzz sequence.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Step {
    /// What it does.
    pub action: Action,
    /// The generator class it came from (`out-of-range-write`, `bad-checksum`, …).
    pub class: String,
    /// One line.
    pub text: String,
    /// Requirement IDs the step exercises.
    pub requirements: Vec<String>,
}

/// What kind of problem a finding is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FindingClass {
    /// The device answered differently from the reference (other bytes, an answer where the
    /// reference is silent, silence where it answers while the device still answers others).
    Mismatch,
    /// The device stopped answering: silent where the reference answers, and silent to a
    /// liveness probe after it.
    Hang,
    /// The transport failed: the process exited, the connection closed, i/o failed.
    Crash,
}

impl FindingClass {
    /// The name used in reports and signatures.
    pub fn as_str(self) -> &'static str {
        match self {
            FindingClass::Mismatch => "mismatch",
            FindingClass::Hang => "hang",
            FindingClass::Crash => "crash",
        }
    }
}

/// How the device must be at the start of a replay.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Start {
    /// In its start state: reset (sim) or restarted (exec) before the first step.
    Fresh,
    /// As it is (tcp, serial: the device cannot be reset from here).
    AsIs,
}

/// The finding a replay reproduces.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FindingInfo {
    /// Mismatch, hang or crash.
    pub class: FindingClass,
    /// `class/message-kind/detail`: findings with the same signature are one bug.
    pub signature: String,
    /// One line: what went wrong at the failing step.
    pub message: String,
    /// Index of the failing step in `steps`.
    pub step: usize,
    /// Requirements the failing step and the reference's answer cover.
    pub requirements: Vec<String>,
    /// Sequence number in the run that found it.
    pub sequence: u64,
    /// Steps before minimisation.
    pub original_steps: usize,
    /// Runs the minimisation took.
    pub minimisation_runs: u64,
    /// Whether the minimised sequence was confirmed from the start state.
    pub reproduced: bool,
}

/// What one step gave when the file was written (hex; empty: silence; the request and reply
/// lines for cyclic records and injections).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Observed {
    /// Step index.
    pub step: usize,
    /// Time of the step from the start of the replay (µs on the transport's clock).
    pub at_us: Micros,
    /// Bytes sent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sent: Option<String>,
    /// The reference's answer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub expected: Option<String>,
    /// The device's answer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub got: Option<String>,
    /// Whether the step matched (absent: not judged).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ok: Option<bool>,
    /// Remarks (transport errors, the liveness probe).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl Observed {
    /// The observation of an evidence record, with times from `t0`.
    pub fn of(r: &Record, t0: Micros) -> Observed {
        // Cyclic records and injections travel as lines, not bytes: their lines are kept.
        let lines = r.sent.is_none() && r.sent_text.is_some();
        let shown = |a: &crate::case::Answer| {
            if lines {
                a.text.clone()
            } else {
                a.hex.clone()
            }
        };
        Observed {
            step: r.step,
            at_us: r.at_us.saturating_sub(t0),
            sent: if lines {
                r.sent_text.clone()
            } else {
                r.sent.clone()
            },
            expected: r.expected.as_ref().map(shown),
            got: r.got.as_ref().map(shown),
            ok: r.ok,
            note: r.note.clone(),
        }
    }

    /// Whether two observations show the same bytes and verdict (times and notes aside).
    pub fn same_exchange(&self, other: &Observed) -> bool {
        self.step == other.step
            && self.sent == other.sent
            && self.expected == other.expected
            && self.got == other.got
            && self.ok == other.ok
    }
}

/// A replay file: the sequence, where it was found, and what it gave.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Replay {
    /// The family.
    pub family: FamilyId,
    /// The device under test it was found on (informative).
    pub dut: String,
    /// Device address (HPD Pr27).
    pub address: u8,
    /// Device model.
    pub model: Option<String>,
    /// Bit rate (serial).
    pub bit_rate: Option<u32>,
    /// Seed of the run that found it.
    pub seed: u64,
    /// Start state.
    pub start: Start,
    /// The finding (absent: a plain sequence).
    pub finding: Option<FindingInfo>,
    /// The inputs, in order.
    pub steps: Vec<Step>,
    /// What each step gave when the file was written.
    pub exchanges: Vec<Observed>,
}

/// Why a replay file cannot be used.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReplayError {
    /// The file cannot be read or written.
    #[error("{file}: {why}")]
    Io {
        /// The file.
        file: String,
        /// Why.
        why: String,
    },
    /// The text is not a replay file.
    #[error("{file}: {why}")]
    Format {
        /// The file.
        file: String,
        /// What is wrong (with the step index where it applies).
        why: String,
    },
    /// A step of another family than the file's.
    #[error("{file}: step {step}: `{action}` is not a {family} step")]
    OtherFamily {
        /// The file.
        file: String,
        /// Index of the step.
        step: usize,
        /// The step's name (key `do`).
        action: String,
        /// The file's family.
        family: FamilyId,
    },
}

/// The file form of [`Replay`]; `S` is the form its steps are read or written in.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ReplayFile<S> {
    format: String,
    family: FamilyId,
    dut: String,
    address: u8,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    model: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    bit_rate: Option<u32>,
    seed: u64,
    start: Start,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    finding: Option<FindingInfo>,
    steps: Vec<S>,
    #[serde(default)]
    exchanges: Vec<Observed>,
}

/// The file form of an HPD [`Step`]: the step's keys, then class, text and requirements.
#[derive(Debug, Serialize, Deserialize)]
struct HpdStepFile {
    #[serde(flatten)]
    step: HpdStep,
    #[serde(default)]
    class: String,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    text: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    requirements: Vec<String>,
}

impl HpdStepFile {
    fn into_step(self) -> Step {
        Step {
            action: Action::Hpd(self.step),
            class: self.class,
            text: self.text,
            requirements: self.requirements,
        }
    }
}

/// A step as written: in the form of its family.
#[derive(Debug, Serialize)]
#[serde(untagged)]
enum StepOut {
    Hpd(HpdStepFile),
    Cyclic(StepFile),
}

impl StepOut {
    fn of(s: &Step) -> StepOut {
        match &s.action {
            Action::Hpd(h) => StepOut::Hpd(HpdStepFile {
                step: h.clone(),
                class: s.class.clone(),
                text: s.text.clone(),
                requirements: s.requirements.clone(),
            }),
            Action::Cyclic(_) => StepOut::Cyclic(StepFile::of(s)),
        }
    }
}

/// Step `index` of a `family` file; a step that reads as one of another family is
/// [`ReplayError::OtherFamily`].
fn read_step(
    family: FamilyId,
    index: usize,
    v: &serde_json::Value,
    file: &str,
) -> Result<Step, ReplayError> {
    let hpd = HpdStepFile::deserialize(v)
        .map(HpdStepFile::into_step)
        .map_err(|e| format!("step {index}: {e}"));
    let cyclic = StepFile::deserialize(v)
        .map_err(|e| format!("step {index}: {e}"))
        .and_then(|f| f.step(index));
    let (own, other) = if family == FamilyId::Hpd {
        (hpd, cyclic.ok())
    } else {
        (cyclic, hpd.ok())
    };
    own.map_err(|why| match other {
        Some(s) => ReplayError::OtherFamily {
            file: file.to_owned(),
            step: index,
            action: s.action.name().to_owned(),
            family,
        },
        None => ReplayError::Format {
            file: file.to_owned(),
            why,
        },
    })
}

/// The file form of a cyclic [`Step`]: `do` names the action; the other keys are the action's.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct StepFile {
    #[serde(rename = "do")]
    action: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hex: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    us: Option<Micros>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    control: Option<u16>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    target: Option<i32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    offset: Option<i64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pkw: Option<PkwFile>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    cycles: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    running: Option<bool>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    max: Option<u32>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    index: Option<u16>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    subindex: Option<u8>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    format: Option<u8>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    speed: Option<i16>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    stamp: Option<u16>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    env: Option<String>,
    #[serde(default)]
    class: String,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    text: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    requirements: Vec<String>,
}

/// `v`, or an error naming the step, its action and the missing key.
fn need<T>(v: Option<T>, index: usize, action: &str, key: &str) -> Result<T, String> {
    v.ok_or_else(|| format!("step {index}: `{action}` needs `{key}`"))
}

impl StepFile {
    fn of(s: &Step) -> StepFile {
        let mut f = StepFile {
            action: s.action.name().to_owned(),
            hex: s.action.bytes().map(to_hex),
            us: None,
            control: None,
            target: None,
            offset: None,
            pkw: None,
            cycles: None,
            running: None,
            max: None,
            index: None,
            subindex: None,
            format: None,
            speed: None,
            stamp: None,
            env: None,
            class: s.class.clone(),
            text: s.text.clone(),
            requirements: s.requirements.clone(),
        };
        match &s.action {
            Action::Cyclic(c) => match c {
                CyclicStep::Process { control, target } => {
                    f.control = *control;
                    f.target = *target;
                }
                CyclicStep::Offset { control, offset } => {
                    f.control = *control;
                    f.offset = Some(*offset);
                }
                CyclicStep::Pkw {
                    ak,
                    spm,
                    pnu,
                    ind,
                    pwe,
                } => {
                    f.pkw = Some(PkwFile {
                        ak: *ak,
                        spm: *spm,
                        pnu: *pnu,
                        ind: *ind,
                        pwe: *pwe,
                    })
                }
                CyclicStep::Hold { cycles } => f.cycles = Some(*cycles),
                CyclicStep::Until { running, max } => {
                    f.running = Some(*running);
                    f.max = Some(*max);
                }
                CyclicStep::RecordRead { index } | CyclicStep::RecordWrite { index, .. } => {
                    f.index = Some(*index)
                }
                CyclicStep::Env(env) => f.env = Some(env.to_string()),
                CyclicStep::Advance { us } => f.us = Some(*us),
                CyclicStep::ProcessData {
                    format,
                    control,
                    target,
                    speed,
                    stamp,
                } => {
                    f.format = Some(*format);
                    f.control = Some(*control);
                    match format {
                        0 => f.stamp = Some(*stamp),
                        1 => f.target = Some(*target),
                        _ => {
                            f.target = Some(*target);
                            f.speed = Some(*speed);
                        }
                    }
                }
                CyclicStep::IsduRead { index, subindex }
                | CyclicStep::IsduWrite {
                    index, subindex, ..
                } => {
                    f.index = Some(*index);
                    f.subindex = Some(*subindex);
                }
            },
            // HPD steps are written as [`HpdStepFile`].
            Action::Hpd(_) => {}
        }
        f
    }

    fn step(self, index: usize) -> Result<Step, String> {
        let action_name = self.action.clone();
        let bytes = || -> Result<Vec<u8>, String> {
            let hex = self
                .hex
                .as_deref()
                .ok_or_else(|| format!("step {index}: `{}` needs `hex`", self.action))?;
            parse_hex(hex).map_err(|e| format!("step {index}: hex: {e}"))
        };
        let action = match self.action.as_str() {
            "process" => Action::Cyclic(CyclicStep::Process {
                control: self.control,
                target: self.target,
            }),
            "offset" => Action::Cyclic(CyclicStep::Offset {
                control: self.control,
                offset: need(self.offset, index, &action_name, "offset")?,
            }),
            "pkw" => {
                let p = need(self.pkw, index, &action_name, "pkw")?;
                Action::Cyclic(CyclicStep::Pkw {
                    ak: p.ak,
                    spm: p.spm,
                    pnu: p.pnu,
                    ind: p.ind,
                    pwe: p.pwe,
                })
            }
            "hold" => Action::Cyclic(CyclicStep::Hold {
                cycles: need(self.cycles, index, &action_name, "cycles")?,
            }),
            "until" => Action::Cyclic(CyclicStep::Until {
                running: need(self.running, index, &action_name, "running")?,
                max: need(self.max, index, &action_name, "max")?,
            }),
            "record-read" => Action::Cyclic(CyclicStep::RecordRead {
                index: need(self.index, index, &action_name, "index")?,
            }),
            "record-write" => Action::Cyclic(CyclicStep::RecordWrite {
                index: need(self.index, index, &action_name, "index")?,
                data: bytes()?,
            }),
            "env" => {
                let text = need(self.env.clone(), index, &action_name, "env")?;
                match Request::parse(&format!("ENV 0 {text}")) {
                    Ok(Request::Env { env, .. }) => Action::Cyclic(CyclicStep::Env(env)),
                    _ => return Err(format!("step {index}: env {text:?}: not an injection (e.g. \"jam 1\")")),
                }
            }
            "advance" => Action::Cyclic(CyclicStep::Advance {
                us: need(self.us, index, &action_name, "us")?,
            }),
            "pd-out" => Action::Cyclic(CyclicStep::ProcessData {
                format: need(self.format, index, &action_name, "format")?,
                control: need(self.control, index, &action_name, "control")?,
                target: self.target.unwrap_or(0),
                speed: self.speed.unwrap_or(0),
                stamp: self.stamp.unwrap_or(0),
            }),
            "isdu-read" => Action::Cyclic(CyclicStep::IsduRead {
                index: need(self.index, index, &action_name, "index")?,
                subindex: self.subindex.unwrap_or(0),
            }),
            "isdu-write" => Action::Cyclic(CyclicStep::IsduWrite {
                index: need(self.index, index, &action_name, "index")?,
                subindex: self.subindex.unwrap_or(0),
                data: bytes()?,
            }),
            other => {
                return Err(format!(
                    "step {index}: unknown action {other:?} (hpd: exchange, send, listen, listen-timeout, listen-half-timeout, power-cycle, inputs, bit-rate; cyclic: hold, until, env, advance; psd4xx: process, offset, pkw, record-read, record-write; psx3xx: pd-out, isdu-read, isdu-write)"
                ))
            }
        };
        Ok(Step {
            action,
            class: self.class,
            text: self.text,
            requirements: self.requirements,
        })
    }
}

impl Replay {
    /// The file text (pretty JSON, one key per line).
    pub fn to_json(&self) -> String {
        let file = ReplayFile {
            format: REPLAY_FORMAT.to_owned(),
            family: self.family,
            dut: self.dut.clone(),
            address: self.address,
            model: self.model.clone(),
            bit_rate: self.bit_rate,
            seed: self.seed,
            start: self.start,
            finding: self.finding.clone(),
            steps: self.steps.iter().map(StepOut::of).collect(),
            exchanges: self.exchanges.clone(),
        };
        serde_json::to_string_pretty(&file)
            .map(|mut s| {
                s.push('\n');
                s
            })
            .unwrap_or_else(|e| format!("{{\"error\": {:?}}}\n", e.to_string()))
    }

    /// Parses the file text; `file` names it in errors.
    pub fn from_json(text: &str, file: &str) -> Result<Replay, ReplayError> {
        let bad = |why: String| ReplayError::Format {
            file: file.to_owned(),
            why,
        };
        let f: ReplayFile<serde_json::Value> =
            serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
        if f.format != REPLAY_FORMAT {
            return Err(bad(format!(
                "format {:?}, expected {REPLAY_FORMAT:?}",
                f.format
            )));
        }
        let steps = f
            .steps
            .iter()
            .enumerate()
            .map(|(i, v)| read_step(f.family, i, v, file))
            .collect::<Result<Vec<Step>, ReplayError>>()?;
        // Cyclic steps of another family (PSD4xx records in a PSx3xx file) are refused too.
        let foreign = |a: &Action| match a {
            Action::Cyclic(c) => c.family().is_some_and(|x| x != f.family),
            Action::Hpd(_) => false,
        };
        if let Some((i, s)) = steps.iter().enumerate().find(|(_, s)| foreign(&s.action)) {
            return Err(ReplayError::OtherFamily {
                file: file.to_owned(),
                step: i,
                action: s.action.name().to_owned(),
                family: f.family,
            });
        }
        if let Some(fi) = &f.finding {
            if fi.step >= steps.len() {
                return Err(bad(format!(
                    "finding.step {} but only {} step(s)",
                    fi.step,
                    steps.len()
                )));
            }
        }
        Ok(Replay {
            family: f.family,
            dut: f.dut,
            address: f.address,
            model: f.model,
            bit_rate: f.bit_rate,
            seed: f.seed,
            start: f.start,
            finding: f.finding,
            steps,
            exchanges: f.exchanges,
        })
    }

    /// Reads a replay file.
    pub fn load(path: &Path) -> Result<Replay, ReplayError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| ReplayError::Io {
            file: file.clone(),
            why: e.to_string(),
        })?;
        Replay::from_json(&text, &file)
    }

    /// Writes the file atomically.
    pub fn save(&self, path: &Path) -> Result<(), ReplayError> {
        drivespec_report::write_atomic(path, &self.to_json()).map_err(|e| ReplayError::Io {
            file: path.display().to_string(),
            why: e.to_string(),
        })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use drivespec_hpd::step::Compare;

    fn sample() -> Replay {
        Replay {
            family: FamilyId::Hpd,
            dut: "sim".into(),
            address: 0,
            model: None,
            bit_rate: None,
            seed: 7,
            start: Start::Fresh,
            finding: None,
            steps: vec![
                Step {
                    action: Action::Hpd(HpdStep::Send {
                        bytes: vec![0x7E, 0x80],
                    }),
                    class: "split-timeout".into(),
                    text: "first part".into(),
                    requirements: vec![],
                },
                Step {
                    action: Action::Hpd(HpdStep::ListenTimeout {}),
                    class: "split-timeout".into(),
                    text: String::new(),
                    requirements: vec![],
                },
                Step {
                    action: Action::Hpd(HpdStep::Exchange {
                        bytes: vec![0x02, 0xC6, 0x48],
                        compare: Compare::Mask(0xFF00),
                        silence_ok: false,
                    }),
                    class: "split-timeout".into(),
                    text: "rest".into(),
                    requirements: vec!["HPD-FRAME-020".into()],
                },
                Step {
                    action: Action::Hpd(HpdStep::Inputs { value: 5 }),
                    class: "inputs".into(),
                    text: String::new(),
                    requirements: vec![],
                },
                Step {
                    action: Action::Hpd(HpdStep::Listen { us: 6144 }),
                    class: "listen".into(),
                    text: String::new(),
                    requirements: vec![],
                },
            ],
            exchanges: vec![],
        }
    }

    #[test]
    fn the_readme_example_loads() {
        let readme = include_str!("../../README.md");
        let from = readme.find("### Replay files").unwrap();
        let block = readme[from..].split("```json").nth(1).unwrap();
        let json = block.split("```").next().unwrap();
        let r = Replay::from_json(json, "README.md").unwrap();
        assert_eq!(r.steps.len(), 3);
        assert_eq!(r.steps[1].action, Action::Hpd(HpdStep::ListenTimeout {}));
        assert_eq!(r.start, Start::Fresh);
    }

    #[test]
    fn cyclic_steps_round_trip_and_stay_in_their_family() {
        let step = |c: CyclicStep| Step {
            action: Action::Cyclic(c),
            class: "x".into(),
            text: String::new(),
            requirements: vec![],
        };
        let r = Replay {
            family: FamilyId::Psd4xx,
            steps: vec![
                step(CyclicStep::Process {
                    control: Some(0x14),
                    target: Some(-4000),
                }),
                step(CyclicStep::Process {
                    control: None,
                    target: None,
                }),
                step(CyclicStep::Offset {
                    control: Some(0x54),
                    offset: 12,
                }),
                step(CyclicStep::Pkw {
                    ak: 15,
                    spm: true,
                    pnu: 2047,
                    ind: 3,
                    pwe: u32::MAX,
                }),
                step(CyclicStep::Hold { cycles: 3 }),
                step(CyclicStep::Until {
                    running: false,
                    max: 100,
                }),
                step(CyclicStep::RecordRead { index: 44 }),
                step(CyclicStep::RecordWrite {
                    index: 44,
                    data: vec![1, 0, 5],
                }),
                step(CyclicStep::Env(Env::Jam(true))),
                step(CyclicStep::Env(Env::Link(
                    drivespec_psd4xx::model::LinkEvent::IopsBad,
                ))),
                step(CyclicStep::Advance { us: 2_500_000 }),
            ],
            ..sample()
        };
        let text = r.to_json();
        assert_eq!(Replay::from_json(&text, "x").unwrap(), r);
        assert!(text.contains("\"env\": \"link iops-bad\""), "{text}");
        // Cyclic steps in an HPD file, a bad injection or a missing key are refused.
        let hpd = text.replace("\"psd4xx\"", "\"hpd\"");
        assert!(Replay::from_json(&hpd, "x").is_err());
        let bad = text.replace("jam 1", "warp 9");
        assert!(Replay::from_json(&bad, "x").is_err());
        let bad = text.replace("\"cycles\": 3", "\"cylces\": 3");
        assert!(Replay::from_json(&bad, "x").is_err());
        let mut hpd_with_cyclic = sample();
        hpd_with_cyclic
            .steps
            .push(step(CyclicStep::Hold { cycles: 1 }));
        assert!(Replay::from_json(&hpd_with_cyclic.to_json(), "x").is_err());
    }

    #[test]
    fn psx3xx_steps_round_trip_and_stay_in_their_family() {
        let step = |c: CyclicStep| Step {
            action: Action::Cyclic(c),
            class: "x".into(),
            text: String::new(),
            requirements: vec![],
        };
        let r = Replay {
            family: FamilyId::Psx3xx,
            steps: vec![
                step(CyclicStep::ProcessData {
                    format: 0,
                    control: 3,
                    target: 0,
                    speed: 0,
                    stamp: 16_383,
                }),
                step(CyclicStep::ProcessData {
                    format: 1,
                    control: 0x14,
                    target: -4000,
                    speed: 0,
                    stamp: 0,
                }),
                step(CyclicStep::ProcessData {
                    format: 2,
                    control: 0x11,
                    target: 12,
                    speed: -1,
                    stamp: 0,
                }),
                step(CyclicStep::IsduRead {
                    index: 0,
                    subindex: 16,
                }),
                step(CyclicStep::IsduWrite {
                    index: 116,
                    subindex: 0,
                    data: vec![2],
                }),
                step(CyclicStep::Env(Env::Keys {
                    forward: true,
                    reverse: false,
                })),
                step(CyclicStep::Hold { cycles: 2 }),
            ],
            ..sample()
        };
        let text = r.to_json();
        assert_eq!(Replay::from_json(&text, "x").unwrap(), r);
        assert!(text.contains("\"do\": \"isdu-write\""), "{text}");
        // The bytes of an ISDU write are what minimisation shortens.
        assert_eq!(r.steps[4].action.bytes(), Some(&[2u8][..]));
        // PSx3xx steps in a PSD4xx or HPD file, and PSD4xx steps in a PSx3xx file, are refused.
        let psd = text.replace("\"psx3xx\"", "\"psd4xx\"");
        assert!(Replay::from_json(&psd, "x").is_err());
        let hpd = text.replace("\"psx3xx\"", "\"hpd\"");
        assert!(Replay::from_json(&hpd, "x").is_err());
        let mut with_record = r.clone();
        with_record
            .steps
            .push(step(CyclicStep::RecordRead { index: 44 }));
        assert!(Replay::from_json(&with_record.to_json(), "x").is_err());
        let bad = text.replace("\"format\": 2,", "");
        assert!(Replay::from_json(&bad, "x").is_err());
    }

    #[test]
    fn round_trips_and_rejects_bad_files() {
        let r = sample();
        let text = r.to_json();
        assert_eq!(Replay::from_json(&text, "x").unwrap(), r);
        assert!(text.contains("\"do\": \"listen-timeout\""));
        let bad = text.replace("listen-timeout", "nap");
        assert!(Replay::from_json(&bad, "x").is_err());
        let bad = text.replace("\"seed\"", "\"sead\"");
        assert!(Replay::from_json(&bad, "x").is_err());
        let bad = text.replace(REPLAY_FORMAT, "drivespec-fuzz-replay/0");
        assert!(Replay::from_json(&bad, "x").is_err());
        assert!(Replay::from_json("{", "x").is_err());
        // A misspelt key of an HPD step, and a key a step does not take, are refused.
        let bad = text.replace("\"us\"", "\"uss\"");
        let e = Replay::from_json(&bad, "x").unwrap_err().to_string();
        assert!(e.contains("step 4") && e.contains("uss"), "{e}");
        let bad = text.replace(
            "\"do\": \"listen-timeout\"",
            "\"do\": \"listen-timeout\", \"us\": 5",
        );
        assert!(Replay::from_json(&bad, "x").is_err());
    }

    #[test]
    fn a_step_of_another_family_is_refused_by_name() {
        let text = sample().to_json().replace(
            "\"do\": \"listen-timeout\"",
            "\"do\": \"pkw\", \"pkw\": { \"ak\": 1, \"pnu\": 3 }",
        );
        let e = Replay::from_json(&text, "x.json").unwrap_err();
        assert!(
            matches!(&e, ReplayError::OtherFamily { step: 1, action, family: FamilyId::Hpd, .. } if action == "pkw"),
            "{e:?}"
        );
        assert_eq!(e.to_string(), "x.json: step 1: `pkw` is not a hpd step");
        // And an HPD step in a cyclic file.
        let text = sample().to_json().replace("\"hpd\"", "\"psd4xx\"");
        let e = Replay::from_json(&text, "x.json").unwrap_err();
        assert_eq!(e.to_string(), "x.json: step 0: `send` is not a psd4xx step");
    }
}
