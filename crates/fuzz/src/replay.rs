//! Fuzz inputs and the replay file (`drivespec-fuzz-replay/1`, JSON; described in
//! `crates/fuzz/README.md`, "Replay files"): the steps of a sequence, what each exchange gave
//! when the file was written, and the finding it reproduces.
//!
//! A step is its family's step type (`drivespec_hpd::step::Step`,
//! `drivespec_psd4xx::step::Step`, `drivespec_psx3xx::step::Step`) with the keys `class`,
//! `text` and `requirements` beside it; the file's `family` says which.
//!
//! Loading never panics: unknown keys, a wrong format name, bad hex, an injection the
//! cyclic-exchange protocol does not know or a step without the fields its action needs are
//! errors naming the step.

use crate::profinet::PnStep;
use drivespec_conform::case::Record;
use drivespec_conform::cyclic::Request;
use drivespec_conform::link::Micros;
use drivespec_hpd::step::Step as HpdStep;
use drivespec_psd4xx::step::Step as PsdStep;
use drivespec_psx3xx::step::Step as PsxStep;
use drivespec_spec::FamilyId;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Largest replay file read (bytes): a minimised sequence is a few kilobytes.
const MAX_REPLAY_FILE: u64 = 16 << 20;

/// Name and version of the replay format (README "Replay files").
pub const REPLAY_FORMAT: &str = "drivespec-fuzz-replay/1";

/// What one step does (README "Replay files", key `do`): a step of the file's family.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Action {
    /// An HPD step (exchange, send, listen, power-cycle, inputs, bit-rate).
    Hpd(HpdStep),
    /// A PSD4xx step (process, offset, pkw, record-read, record-write, hold, until, env,
    /// advance; PSD4xx manual 3.5–3.9).
    Psd4xx(PsdStep),
    /// A PSx3xx step (pd-out, hold, until, advance, isdu-read, isdu-write, env; PSx3xx
    /// manual 3.1, 3.3).
    Psx3xx(PsxStep),
    /// A PSD4xx step at the PROFINET layer (dcp-identify, dcp-set, dcp-get, connect,
    /// record-read, record-write, rt; IEC 61158-6-10).
    Profinet(PnStep),
}

/// The layer a sequence's steps act at (README "Replay files", key `layer`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Layer {
    /// The family's own steps: serial frames, or the cyclic exchange of the drive's images
    /// and records.
    #[default]
    Application,
    /// PROFINET frames to a PSD4xx IO device: DCP, PNIO-CM, RT (`fuzz psd4xx --layer
    /// profinet`).
    Profinet,
}

impl Layer {
    /// The name on the command line and in files.
    pub fn as_str(self) -> &'static str {
        match self {
            Layer::Application => "application",
            Layer::Profinet => "profinet",
        }
    }

    /// Whether this is the default layer (not written to files).
    fn is_default(&self) -> bool {
        *self == Layer::Application
    }
}

impl std::fmt::Display for Layer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl Action {
    /// The family the step belongs to.
    pub fn family(&self) -> FamilyId {
        match self {
            Action::Hpd(_) => FamilyId::Hpd,
            Action::Psd4xx(_) => FamilyId::Psd4xx,
            Action::Psx3xx(_) => FamilyId::Psx3xx,
            Action::Profinet(_) => FamilyId::Psd4xx,
        }
    }

    /// The bytes the step puts on the line, if any (a record or ISDU write: its data).
    pub fn bytes(&self) -> Option<&[u8]> {
        match self {
            Action::Hpd(h) => h.bytes(),
            Action::Psd4xx(PsdStep::RecordWrite { hex, .. }) => Some(hex),
            Action::Psx3xx(PsxStep::IsduWrite { data, .. }) => Some(data),
            Action::Profinet(p) => p.bytes(),
            _ => None,
        }
    }

    /// The same action with other bytes (exchanges, sends, record and ISDU writes).
    pub fn with_bytes(&self, new: Vec<u8>) -> Action {
        match self {
            Action::Hpd(h) => Action::Hpd(h.with_bytes(new)),
            Action::Psd4xx(PsdStep::RecordWrite { index, .. }) => {
                Action::Psd4xx(PsdStep::RecordWrite {
                    index: *index,
                    hex: new,
                })
            }
            Action::Psx3xx(PsxStep::IsduWrite {
                index, subindex, ..
            }) => Action::Psx3xx(PsxStep::IsduWrite {
                index: *index,
                subindex: *subindex,
                data: new,
            }),
            Action::Profinet(p) => Action::Profinet(p.with_bytes(new)),
            other => other.clone(),
        }
    }

    /// The step's `do` key.
    pub fn name(&self) -> &'static str {
        match self {
            Action::Hpd(h) => h.name(),
            Action::Psd4xx(p) => p.name(),
            Action::Psx3xx(p) => p.name(),
            Action::Profinet(p) => p.name(),
        }
    }

    /// The injection of an `env` step.
    fn env_mut(&mut self) -> Option<&mut String> {
        match self {
            Action::Psd4xx(PsdStep::Env { env }) | Action::Psx3xx(PsxStep::Env { env }) => {
                Some(env)
            }
            _ => None,
        }
    }
}

/// A family's step type, as one [`Action`] variant holds it.
pub trait FamilyStep {
    /// The family.
    const FAMILY: FamilyId;
    /// The step `a` holds, None when `a` is of another family.
    fn of(a: &Action) -> Option<&Self>;
}

impl FamilyStep for HpdStep {
    const FAMILY: FamilyId = FamilyId::Hpd;
    fn of(a: &Action) -> Option<&HpdStep> {
        match a {
            Action::Hpd(s) => Some(s),
            _ => None,
        }
    }
}

impl FamilyStep for PsdStep {
    const FAMILY: FamilyId = FamilyId::Psd4xx;
    fn of(a: &Action) -> Option<&PsdStep> {
        match a {
            Action::Psd4xx(s) => Some(s),
            _ => None,
        }
    }
}

impl FamilyStep for PsxStep {
    const FAMILY: FamilyId = FamilyId::Psx3xx;
    fn of(a: &Action) -> Option<&PsxStep> {
        match a {
            Action::Psx3xx(s) => Some(s),
            _ => None,
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
        let shown = |a: &drivespec_conform::case::Answer| {
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
    /// The layer the steps act at.
    pub layer: Layer,
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
    #[serde(default, skip_serializing_if = "Layer::is_default")]
    layer: Layer,
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

/// The file form of a [`Step`]: the family step's keys, then class, text and requirements.
#[derive(Debug, Serialize, Deserialize)]
struct StepFile<S> {
    #[serde(flatten)]
    step: S,
    #[serde(default)]
    class: String,
    #[serde(default, skip_serializing_if = "String::is_empty")]
    text: String,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    requirements: Vec<String>,
}

impl<S> StepFile<S> {
    fn of(s: &Step, step: S) -> StepFile<S> {
        StepFile {
            step,
            class: s.class.clone(),
            text: s.text.clone(),
            requirements: s.requirements.clone(),
        }
    }
}

/// A step as written: in the form of its family.
#[derive(Debug, Serialize)]
#[serde(untagged)]
enum StepOut<'a> {
    Hpd(StepFile<&'a HpdStep>),
    Psd4xx(StepFile<&'a PsdStep>),
    Psx3xx(StepFile<&'a PsxStep>),
    Profinet(StepFile<&'a PnStep>),
}

impl StepOut<'_> {
    fn of(s: &Step) -> StepOut<'_> {
        match &s.action {
            Action::Hpd(h) => StepOut::Hpd(StepFile::of(s, h)),
            Action::Psd4xx(p) => StepOut::Psd4xx(StepFile::of(s, p)),
            Action::Psx3xx(p) => StepOut::Psx3xx(StepFile::of(s, p)),
            Action::Profinet(p) => StepOut::Profinet(StepFile::of(s, p)),
        }
    }
}

/// `v` read as a step of type `S`, wrapped by `action`.
fn read_as<S: DeserializeOwned>(
    v: &serde_json::Value,
    action: fn(S) -> Action,
) -> Result<Step, serde_json::Error> {
    StepFile::<S>::deserialize(v).map(|f| Step {
        action: action(f.step),
        class: f.class,
        text: f.text,
        requirements: f.requirements,
    })
}

/// `v` read as a step of `family` at `layer`.
fn read_in(
    family: FamilyId,
    layer: Layer,
    v: &serde_json::Value,
) -> Result<Step, serde_json::Error> {
    match (family, layer) {
        (FamilyId::Psd4xx, Layer::Profinet) => read_as(v, Action::Profinet),
        (FamilyId::Hpd, _) => read_as(v, Action::Hpd),
        (FamilyId::Psd4xx, _) => read_as(v, Action::Psd4xx),
        (FamilyId::Psx3xx, _) => read_as(v, Action::Psx3xx),
    }
}

/// Step `index` of a `family` file, its injection (if any) in the protocol's own spelling; a
/// step that reads as one of another family is [`ReplayError::OtherFamily`].
fn read_step(
    family: FamilyId,
    layer: Layer,
    index: usize,
    v: &serde_json::Value,
    file: &str,
) -> Result<Step, ReplayError> {
    let bad = |why: String| ReplayError::Format {
        file: file.to_owned(),
        why,
    };
    let mut step = read_in(family, layer, v).map_err(|e| {
        let other = FamilyId::ALL
            .into_iter()
            .filter(|f| *f != family)
            .find_map(|f| read_in(f, Layer::Application, v).ok());
        match other {
            Some(s) => ReplayError::OtherFamily {
                file: file.to_owned(),
                step: index,
                action: s.action.name().to_owned(),
                family,
            },
            None => bad(format!("step {index}: {e}")),
        }
    })?;
    if let Some(text) = step.action.env_mut() {
        match Request::parse(&format!("ENV 0 {text}")) {
            Ok(Request::Env { env, .. }) => *text = env.to_string(),
            _ => {
                return Err(bad(format!(
                    "step {index}: env {text:?}: not an injection (e.g. \"jam 1\")"
                )))
            }
        }
    }
    Ok(step)
}

impl Replay {
    /// The file text (pretty JSON, one key per line).
    pub fn to_json(&self) -> String {
        let file = ReplayFile {
            format: REPLAY_FORMAT.to_owned(),
            family: self.family,
            layer: self.layer,
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
        if f.layer == Layer::Profinet && f.family != FamilyId::Psd4xx {
            return Err(bad(format!(
                "layer profinet is a psd4xx layer, not {}",
                f.family
            )));
        }
        let steps = f
            .steps
            .iter()
            .enumerate()
            .map(|(i, v)| read_step(f.family, f.layer, i, v, file))
            .collect::<Result<Vec<Step>, ReplayError>>()?;
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
            layer: f.layer,
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
        let text =
            drivespec_spec::bounded::read_text_bounded(path, MAX_REPLAY_FILE).map_err(|e| {
                ReplayError::Io {
                    file: file.clone(),
                    why: e.to_string(),
                }
            })?;
        Replay::from_json(&text, &file)
    }

    /// Writes the file atomically.
    pub fn save(&self, path: &Path) -> Result<(), ReplayError> {
        drivespec_report::write_atomic(path, &self.to_json()).map_err(|e| ReplayError::Io {
            file: path.display().to_string(),
            why: e.why.to_string(),
        })
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use drivespec_hpd::step::Compare;
    use drivespec_psd4xx::step::PkwBlock;

    fn sample() -> Replay {
        Replay {
            family: FamilyId::Hpd,
            layer: Layer::Application,
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
        let readme = include_str!("../README.md");
        let from = readme.find("## Replay files").unwrap();
        let block = readme[from..].split("```json").nth(1).unwrap();
        let json = block.split("```").next().unwrap();
        let r = Replay::from_json(json, "README.md").unwrap();
        assert_eq!(r.steps.len(), 3);
        assert_eq!(r.steps[1].action, Action::Hpd(HpdStep::ListenTimeout {}));
        assert_eq!(r.start, Start::Fresh);
    }

    fn psd(p: PsdStep) -> Step {
        Step {
            action: Action::Psd4xx(p),
            class: "x".into(),
            text: String::new(),
            requirements: vec![],
        }
    }

    fn psx(p: PsxStep) -> Step {
        Step {
            action: Action::Psx3xx(p),
            class: "x".into(),
            text: String::new(),
            requirements: vec![],
        }
    }

    #[test]
    fn psd4xx_steps_round_trip_and_stay_in_their_family() {
        let r = Replay {
            family: FamilyId::Psd4xx,
            steps: vec![
                psd(PsdStep::Process {
                    control: Some(0x14),
                    target: Some(-4000),
                }),
                psd(PsdStep::Process {
                    control: None,
                    target: None,
                }),
                psd(PsdStep::Offset {
                    control: Some(0x54),
                    offset: 12,
                }),
                psd(PsdStep::Pkw {
                    pkw: PkwBlock {
                        ak: 15,
                        spm: true,
                        pnu: 2047,
                        ind: 3,
                        pwe: u32::MAX,
                    },
                }),
                psd(PsdStep::Hold { cycles: 3 }),
                psd(PsdStep::Until {
                    running: false,
                    max: 100,
                }),
                psd(PsdStep::RecordRead { index: 44 }),
                psd(PsdStep::RecordWrite {
                    index: 44,
                    hex: vec![1, 0, 5],
                }),
                psd(PsdStep::Env {
                    env: "jam 1".into(),
                }),
                psd(PsdStep::Env {
                    env: "link iops-bad".into(),
                }),
                psd(PsdStep::Advance { us: 2_500_000 }),
            ],
            ..sample()
        };
        let text = r.to_json();
        assert_eq!(Replay::from_json(&text, "x").unwrap(), r);
        assert!(text.contains("\"env\": \"link iops-bad\""), "{text}");
        // The bytes of a record write are what minimisation shortens.
        assert_eq!(r.steps[7].action.bytes(), Some(&[1u8, 0, 5][..]));
        // Cyclic steps in an HPD file, a bad injection or a missing key are refused.
        let hpd = text.replace("\"psd4xx\"", "\"hpd\"");
        assert!(Replay::from_json(&hpd, "x").is_err());
        let bad = text.replace("jam 1", "warp 9");
        let e = Replay::from_json(&bad, "x").unwrap_err().to_string();
        assert!(e.contains("step 8") && e.contains("warp 9"), "{e}");
        let bad = text.replace("\"cycles\": 3", "\"cylces\": 3");
        assert!(Replay::from_json(&bad, "x").is_err());
        let mut hpd_with_cyclic = sample();
        hpd_with_cyclic.steps.push(psd(PsdStep::Hold { cycles: 1 }));
        assert!(Replay::from_json(&hpd_with_cyclic.to_json(), "x").is_err());
    }

    #[test]
    fn psx3xx_steps_round_trip_and_stay_in_their_family() {
        let r = Replay {
            family: FamilyId::Psx3xx,
            steps: vec![
                psx(PsxStep::PdOut {
                    format: 0,
                    control: 3,
                    target: 0,
                    speed: 0,
                    stamp: 16_383,
                }),
                psx(PsxStep::PdOut {
                    format: 1,
                    control: 0x14,
                    target: -4000,
                    speed: 0,
                    stamp: 0,
                }),
                psx(PsxStep::PdOut {
                    format: 2,
                    control: 0x11,
                    target: 12,
                    speed: -1,
                    stamp: 0,
                }),
                psx(PsxStep::IsduRead {
                    index: 0,
                    subindex: 16,
                }),
                psx(PsxStep::IsduWrite {
                    index: 116,
                    subindex: 0,
                    data: vec![2],
                }),
                psx(PsxStep::Env {
                    env: "keys forward".into(),
                }),
                psx(PsxStep::Hold { cycles: 2 }),
            ],
            ..sample()
        };
        let text = r.to_json();
        assert_eq!(Replay::from_json(&text, "x").unwrap(), r);
        assert!(text.contains("\"do\": \"isdu-write\""), "{text}");
        // The bytes of an ISDU write are what minimisation shortens.
        assert_eq!(r.steps[4].action.bytes(), Some(&[2u8][..]));
        // PSx3xx steps in a PSD4xx or HPD file, and PSD4xx steps in a PSx3xx file, are refused.
        let psd_file = text.replace("\"psx3xx\"", "\"psd4xx\"");
        assert!(Replay::from_json(&psd_file, "x").is_err());
        let hpd = text.replace("\"psx3xx\"", "\"hpd\"");
        assert!(Replay::from_json(&hpd, "x").is_err());
        let mut with_record = r.clone();
        with_record
            .steps
            .push(psd(PsdStep::RecordRead { index: 44 }));
        assert!(Replay::from_json(&with_record.to_json(), "x").is_err());
        let bad = text.replace("\"format\": 2,", "");
        assert!(Replay::from_json(&bad, "x").is_err());
    }

    #[test]
    fn a_pd_out_step_in_a_psd4xx_file_is_refused_by_name() {
        let mut r = Replay {
            family: FamilyId::Psd4xx,
            steps: vec![psd(PsdStep::Hold { cycles: 1 })],
            ..sample()
        };
        r.steps.push(psx(PsxStep::PdOut {
            format: 1,
            control: 0x14,
            target: 100,
            speed: 0,
            stamp: 0,
        }));
        let e = Replay::from_json(&r.to_json(), "x.json").unwrap_err();
        assert!(
            matches!(&e, ReplayError::OtherFamily { step: 1, action, family: FamilyId::Psd4xx, .. } if action == "pd-out"),
            "{e:?}"
        );
        assert_eq!(
            e.to_string(),
            "x.json: step 1: `pd-out` is not a psd4xx step"
        );
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
