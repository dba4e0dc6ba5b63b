//! The PSx3xx step language: [`Step`], one master action or environment change of a timed
//! sequence (suite cases, scenario files, fuzz replay files, and the `sim-run` script, whose
//! commands are a text form of it: [`crate::script`]), and the step language of the
//! `sequence` vectors (`spec/psx3xx/vectors`): what the
//! master sends (process data, ISDU), what the environment or the operator does (events, jog
//! keys, the IO-Link connection) and what the drive must show after each step (manual 3.3,
//! 4.4–4.6, 5.9–5.14; `spec/SCHEMA.md` "Steps and scenarios").
//!
//! Every record is `deny_unknown_fields`: a misspelt key is an error naming the key, and
//! [`check_steps`] reports it as a `spec check` problem.

use crate::model::LinkEvent;
use drivespec_positioner::step::{check_sequences, SequenceInput, SequenceVector, State};
use drivespec_spec::{Problem, Spec};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One master action or environment change on a PSx3xx drive, as the suites, scenario files,
/// sim-run scripts and fuzz replay files write it: `do` names the action, the other keys are
/// its own (manual 3.1, 3.3.1; a misspelt key is an error naming the key).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "do", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Step {
    /// A process output in `format`, then one cycle (3.3.1): format 0 sends `control` as the
    /// time-stamp code with `stamp`, format 1 the control word and `target`, format 2 also
    /// `speed`.
    PdOut {
        /// Output format (0, 1, 2).
        format: u8,
        /// Control word (formats 1, 2) or time-stamp code (format 0).
        control: u16,
        /// Target position (formats 1, 2).
        #[serde(default, skip_serializing_if = "is_zero_i32")]
        target: i32,
        /// Target speed, rpm (format 2).
        #[serde(default, skip_serializing_if = "is_zero_i16")]
        speed: i16,
        /// Time stamp (format 0).
        #[serde(default, skip_serializing_if = "is_zero_u16")]
        stamp: u16,
    },
    /// Cycles with the output unchanged.
    Hold {
        /// How many.
        cycles: u32,
    },
    /// Cycles until the drive reports a run (`running`) or stands still, at most `max`.
    Until {
        /// Wait for "drive is running" set (true) or a standstill (false).
        running: bool,
        /// Most cycles.
        max: u32,
    },
    /// The master stays silent: time passes without a bus cycle.
    Advance {
        /// How long, µs.
        us: u64,
    },
    /// An ISDU read between two cycles (3.1).
    IsduRead {
        /// ISDU index.
        index: u16,
        /// Sub-index.
        #[serde(default)]
        subindex: u8,
    },
    /// An ISDU read repeated once a cycle until it answers as a finished device does, at most
    /// `max` cycles (3.1 ISDU 193: "≠ 0 → Save is still running … (saving can take up to
    /// 2000ms)"; 5.5 comment 8: "As soon as the reading of ISDU 193 returns a 0, the save is
    /// finished").
    IsduPoll {
        /// ISDU index.
        index: u16,
        /// Sub-index.
        #[serde(default)]
        subindex: u8,
        /// Most cycles.
        max: u32,
    },
    /// An ISDU write between two cycles, most significant octet first (3.1).
    IsduWrite {
        /// ISDU index.
        index: u16,
        /// Sub-index.
        #[serde(default)]
        subindex: u8,
        /// The octets, written as hex text (`00 2A`).
        #[serde(rename = "hex", with = "drivespec_positioner::step::hex_text")]
        data: Vec<u8>,
    },
    /// An environment change in the cyclic-exchange protocol's text form (`jam 1`,
    /// `keys forward`, `link lost`; README "Cyclic-exchange protocol").
    Env {
        /// The change.
        env: String,
    },
    /// New values in the active format's process output (absent: unchanged), then one cycle
    /// (3.3.1): the control word (ISDU 110), the target (ISDU 112), the target speed in rpm
    /// (format 2).
    Process {
        /// Control word.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        control: Option<u16>,
        /// Target position.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        target: Option<i32>,
        /// Target speed, rpm (format 2).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        speed: Option<i16>,
    },
    /// The format-0 output from now on: control code and time stamp (3.3.1, 4.4).
    Stamp {
        /// Control code (bits 0–1).
        code: u8,
        /// Time stamp (bits 2–15).
        stamp: u16,
    },
    /// The jog key inputs (5.10).
    Keys {
        /// Forward key (pin 2) pressed.
        #[serde(default)]
        forward: bool,
        /// Reverse key (pin 3) pressed.
        #[serde(default)]
        reverse: bool,
    },
    /// A change of the IO-Link communication (5.9).
    Link {
        /// The change.
        event: LinkEvent,
    },
    /// Supply off and on again.
    PowerCycle,
    /// What the three LEDs show, read off the reference model (2.6, 3.3.1); a device under
    /// test shows them to the eye only.
    Leds,
}

fn is_zero_i32(v: &i32) -> bool {
    *v == 0
}

fn is_zero_i16(v: &i16) -> bool {
    *v == 0
}

fn is_zero_u16(v: &u16) -> bool {
    *v == 0
}

impl Step {
    /// The `do` name of the step.
    pub fn name(&self) -> &'static str {
        match self {
            Step::PdOut { .. } => "pd-out",
            Step::Hold { .. } => "hold",
            Step::Until { .. } => "until",
            Step::Advance { .. } => "advance",
            Step::IsduRead { .. } => "isdu-read",
            Step::IsduPoll { .. } => "isdu-poll",
            Step::IsduWrite { .. } => "isdu-write",
            Step::Env { .. } => "env",
            Step::Process { .. } => "process",
            Step::Stamp { .. } => "stamp",
            Step::Keys { .. } => "keys",
            Step::Link { .. } => "link",
            Step::PowerCycle => "power-cycle",
            Step::Leds => "leds",
        }
    }
}

/// The `input` of a sequence vector.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Input {
    /// Process-data format made active before the first step (ISDU 116, 3.3.1).
    pub format: Option<u8>,
    /// ISDU index to value, written before the first step (67: where the shaft stands).
    pub state: State,
    /// The steps, in order.
    pub steps: Vec<VectorStep>,
}

/// The `expect` of a sequence vector: what holds after the last step.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Final {
    /// The run in progress at the end.
    pub final_run: Option<Run>,
    /// ISDU index to the value it reads at the end.
    pub final_state: BTreeMap<String, i64>,
    /// The device ID at the end (ISDU 0, Direct Parameter page 1).
    pub device_id: Option<u32>,
    /// Rows of the manual's table the vector stands for (a table kept in the spec, 5.10).
    pub rows: Option<u32>,
}

impl SequenceInput for Input {
    type Step = VectorStep;
}

/// A typed PSx3xx `sequence` vector.
pub type PsxSequence = SequenceVector<Input, Final>;

/// One step of a `sequence` vector: at most one of each action, in the order process data,
/// ISDU, event; then the expectations.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct VectorStep {
    /// A new process output in the active format.
    pub pd: Option<ProcessData>,
    /// An ISDU request (3.1).
    pub isdu: Option<IsduStep>,
    /// Something the environment does.
    pub event: Option<Event>,
    /// For `manual-rotation-at-standstill`: the turn relative to the loop direction.
    pub direction: Option<LoopSide>,
    /// For `manual-rotation-at-standstill`: how far, in steps.
    pub steps: Option<i64>,
    /// The IO-Link connection is up (jog-key table, 5.10).
    pub bus: Option<bool>,
    /// The control word sent while the connection is up (jog-key table, 5.10).
    pub control_word: Option<u16>,
    /// The jog keys pressed (5.10).
    pub key: Option<Key>,
    /// How long the keys are held, ms.
    pub hold_ms: Option<u64>,
    /// For `connection-lost`: how long after it the expectations are checked, ms.
    pub after_ms: Option<u64>,
    /// What the drive shows after the step.
    pub expect: Expect,
}

/// A process output; the fields of the active format are used, the others are zero (3.3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ProcessData {
    /// Format 0: control code.
    pub control: Option<u8>,
    /// Format 0: time stamp.
    pub stamp: Option<u16>,
    /// Formats 1 and 2: control word.
    pub control_word: Option<u16>,
    /// Formats 1 and 2: target.
    pub target: Option<i32>,
    /// Format 2: target speed, rpm.
    pub target_speed: Option<i16>,
}

/// An ISDU read or write of an integer (3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsduStep {
    /// Read or write.
    pub op: IsduOp,
    /// ISDU index.
    pub index: u16,
    /// Sub-index (0 when absent).
    #[serde(default)]
    pub subindex: u8,
    /// The value written.
    #[serde(default)]
    pub value: Option<i64>,
}

/// An ISDU operation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IsduOp {
    /// Read.
    Read,
    /// Write.
    Write,
}

/// Something the environment does during a step (5.9, 5.11–5.14).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Event {
    /// The drive meets an obstruction and detects it (status bit 10).
    ObstructionDetected,
    /// The run ends at its target.
    TargetReached,
    /// The run ends at its target, approached in loop direction.
    TargetReachedInLoopDirection,
    /// The shaft is turned by hand at standstill.
    ManualRotationAtStandstill,
    /// The motor supply leaves its range.
    MotorVoltageOutOfRange,
    /// The motor supply returns into its range.
    MotorVoltageInRange,
    /// The IO-Link connection is lost (5.9).
    ConnectionLost,
}

/// A turn relative to the loop direction (ISDU 134).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LoopSide {
    /// In loop direction.
    WithLoop,
    /// Against loop direction.
    AgainstLoop,
}

/// Jog keys pressed (5.10).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Key {
    /// Forward only.
    Forward,
    /// Reverse only.
    Reverse,
    /// Both.
    Both,
    /// None.
    None,
}

/// A jog direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Direction {
    /// Increasing positions.
    Forward,
    /// Decreasing positions.
    Reverse,
}

/// The run a drive is in (4.4–4.6, 5.10, 5.13).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Run {
    /// No run.
    None,
    /// A positioning run.
    Positioning,
    /// A manual run forward.
    ManualForward,
    /// A manual run in reverse.
    ManualReverse,
    /// A jog step.
    JogStep,
    /// A continuous jog run.
    JogContinuous,
    /// The run to the safe position after a connection loss (5.9).
    SafePosition,
}

impl Run {
    /// The name used in the spec files.
    pub fn as_str(self) -> &'static str {
        match self {
            Run::None => "none",
            Run::Positioning => "positioning",
            Run::ManualForward => "manual-forward",
            Run::ManualReverse => "manual-reverse",
            Run::JogStep => "jog-step",
            Run::JogContinuous => "jog-continuous",
            Run::SafePosition => "safe-position",
        }
    }
}

/// What the drive shows after a step; absent keys are not checked.
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Expect {
    /// The run in progress.
    pub run: Option<Run>,
    /// The run's target.
    pub target: Option<i64>,
    /// The run starts this many µs after the step, not earlier (time stamps, 4.4).
    pub after_us: Option<u64>,
    /// Status bits set (3.5).
    pub status_set: Vec<u32>,
    /// Status bits clear (3.5).
    pub status_clear: Vec<u32>,
    /// `false`: the drive does not stop on the way (a new target in the same direction).
    pub stop: Option<bool>,
    /// `false`: the run has no loop (one waypoint).
    #[serde(rename = "loop")]
    pub reference_loop: Option<bool>,
    /// The set speed, rpm.
    pub speed_rpm: Option<i64>,
    /// The ISDU whose value the holding torque takes at standstill.
    pub torque_param: Option<String>,
    /// Whether the jog keys act (5.10).
    pub keys_active: Option<bool>,
    /// A jog moves this many jog increments (ISDU 135).
    pub steps: Option<i64>,
    /// The jog state is checked this many ms after the keys are pressed.
    pub after_ms: Option<u64>,
    /// A forward jog ends here at the latest (the upper limit).
    pub stop_at: Option<i64>,
    /// The direction a jog moves.
    pub direction: Option<Direction>,
    /// The active process-data format.
    pub active_format: Option<u8>,
    /// The value an ISDU read returns.
    pub value: Option<i64>,
    /// The ISDU ErrorType of a write (0: accepted).
    pub error: Option<i64>,
    /// Whether a guard entry suppressed the write (3.1 ISDU 66, 109, 111, 126).
    pub suppressed: Option<bool>,
}

/// Every PSx3xx `sequence` vector that does not read as [`PsxSequence`], naming file, record
/// and key (`drivespec spec check`).
pub fn check_steps(spec: &Spec) -> Vec<Problem> {
    check_sequences::<PsxSequence>(spec.family(drivespec_spec::FamilyId::Psx3xx))
}

#[cfg(test)]
mod tests {
    use super::Step;

    fn read(text: &str) -> Result<Step, toml::de::Error> {
        toml::from_str(text)
    }

    #[test]
    fn a_step_reads_its_keys() {
        assert_eq!(
            read("do = \"isdu-write\"\nindex = 135\nhex = \"00 2A\"").ok(),
            Some(Step::IsduWrite {
                index: 135,
                subindex: 0,
                data: vec![0, 0x2A],
            })
        );
        assert_eq!(
            read("do = \"pd-out\"\nformat = 1\ncontrol = 3\ntarget = -5").ok(),
            Some(Step::PdOut {
                format: 1,
                control: 3,
                target: -5,
                speed: 0,
                stamp: 0,
            })
        );
    }

    #[test]
    fn a_misspelt_key_is_an_error_naming_it() {
        let e = read("do = \"hold\"\ncycels = 3")
            .err()
            .map(|e| e.to_string());
        assert!(e.as_deref().is_some_and(|e| e.contains("cycels")), "{e:?}");
        let e = read("do = \"isdu-read\"\nindex = 1\nsubindx = 2")
            .err()
            .map(|e| e.to_string());
        assert!(e.as_deref().is_some_and(|e| e.contains("subindx")), "{e:?}");
    }

    #[test]
    fn a_step_writes_what_it_reads() {
        let s = Step::IsduWrite {
            index: 193,
            subindex: 1,
            data: vec![1, 2],
        };
        let text = toml::to_string(&s).unwrap_or_default();
        assert_eq!(read(&text).ok(), Some(s));
    }
}
