//! The PSx3xx step language of the `sequence` vectors (`spec/psx3xx/vectors`): what the
//! master sends (process data, ISDU), what the environment or the operator does (events, jog
//! keys, the IO-Link connection) and what the drive must show after each step (manual 3.3,
//! 4.4–4.6, 5.9–5.14; `spec/SCHEMA.md` "Steps and scenarios").
//!
//! Every record is `deny_unknown_fields`: a misspelt key is an error naming the key, and
//! [`check_steps`] reports it as a `spec check` problem.

use drivespec_positioner::step::{check_sequences, Sequence, State};
use drivespec_spec::{Problem, Spec};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The `input` of a sequence vector.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Input {
    /// Process-data format made active before the first step (ISDU 116, 3.3.1).
    #[serde(default)]
    pub format: Option<u8>,
    /// ISDU index to value, written before the first step (67: where the shaft stands).
    #[serde(default)]
    pub state: State,
    /// The steps, in order.
    #[serde(default)]
    pub steps: Vec<Step>,
}

/// The `expect` of a sequence vector: what holds after the last step.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Final {
    /// The run in progress at the end.
    #[serde(default)]
    pub final_run: Option<Run>,
    /// ISDU index to the value it reads at the end.
    #[serde(default)]
    pub final_state: BTreeMap<String, i64>,
    /// The device ID at the end (ISDU 0, Direct Parameter page 1).
    #[serde(default)]
    pub device_id: Option<u32>,
    /// Rows of the manual's table the vector stands for (a table kept in the spec, 5.10).
    #[serde(default)]
    pub rows: Option<u32>,
}

/// A typed PSx3xx `sequence` vector.
#[derive(Debug, Clone, PartialEq)]
pub struct PsxSequence {
    /// Start state and steps.
    pub input: Input,
    /// What holds at the end.
    pub expect: Final,
}

impl Sequence for PsxSequence {
    type Input = Input;
    type Expect = Final;
    type Step = Step;
    fn new(input: Input, expect: Final) -> PsxSequence {
        PsxSequence { input, expect }
    }
}

/// One step: at most one of each action, in the order process data, ISDU, event; then the
/// expectations.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    /// A new process output in the active format.
    #[serde(default)]
    pub pd: Option<ProcessData>,
    /// An ISDU request (3.1).
    #[serde(default)]
    pub isdu: Option<IsduStep>,
    /// Something the environment does.
    #[serde(default)]
    pub event: Option<Event>,
    /// For `manual-rotation-at-standstill`: the turn relative to the loop direction.
    #[serde(default)]
    pub direction: Option<LoopSide>,
    /// For `manual-rotation-at-standstill`: how far, in steps.
    #[serde(default)]
    pub steps: Option<i64>,
    /// The IO-Link connection is up (jog-key table, 5.10).
    #[serde(default)]
    pub bus: Option<bool>,
    /// The control word sent while the connection is up (jog-key table, 5.10).
    #[serde(default)]
    pub control_word: Option<u16>,
    /// The jog keys pressed (5.10).
    #[serde(default)]
    pub key: Option<Key>,
    /// How long the keys are held, ms.
    #[serde(default)]
    pub hold_ms: Option<u64>,
    /// For `connection-lost`: how long after it the expectations are checked, ms.
    #[serde(default)]
    pub after_ms: Option<u64>,
    /// What the drive shows after the step.
    #[serde(default)]
    pub expect: Expect,
}

/// A process output; the fields of the active format are used, the others are zero (3.3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessData {
    /// Format 0: control code.
    #[serde(default)]
    pub control: Option<u8>,
    /// Format 0: time stamp.
    #[serde(default)]
    pub stamp: Option<u16>,
    /// Formats 1 and 2: control word.
    #[serde(default)]
    pub control_word: Option<u16>,
    /// Formats 1 and 2: target.
    #[serde(default)]
    pub target: Option<i32>,
    /// Format 2: target speed, rpm.
    #[serde(default)]
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
#[serde(deny_unknown_fields)]
pub struct Expect {
    /// The run in progress.
    #[serde(default)]
    pub run: Option<Run>,
    /// The run's target.
    #[serde(default)]
    pub target: Option<i64>,
    /// The run starts this many µs after the step, not earlier (time stamps, 4.4).
    #[serde(default)]
    pub after_us: Option<u64>,
    /// Status bits set (3.5).
    #[serde(default)]
    pub status_set: Vec<u32>,
    /// Status bits clear (3.5).
    #[serde(default)]
    pub status_clear: Vec<u32>,
    /// `false`: the drive does not stop on the way (a new target in the same direction).
    #[serde(default)]
    pub stop: Option<bool>,
    /// `false`: the run has no loop (one waypoint).
    #[serde(rename = "loop", default)]
    pub reference_loop: Option<bool>,
    /// The set speed, rpm.
    #[serde(default)]
    pub speed_rpm: Option<i64>,
    /// The ISDU whose value the holding torque takes at standstill.
    #[serde(default)]
    pub torque_param: Option<String>,
    /// Whether the jog keys act (5.10).
    #[serde(default)]
    pub keys_active: Option<bool>,
    /// A jog moves this many jog increments (ISDU 135).
    #[serde(default)]
    pub steps: Option<i64>,
    /// The jog state is checked this many ms after the keys are pressed.
    #[serde(default)]
    pub after_ms: Option<u64>,
    /// A forward jog ends here at the latest (the upper limit).
    #[serde(default)]
    pub stop_at: Option<i64>,
    /// The direction a jog moves.
    #[serde(default)]
    pub direction: Option<Direction>,
    /// The active process-data format.
    #[serde(default)]
    pub active_format: Option<u8>,
    /// The value an ISDU read returns.
    #[serde(default)]
    pub value: Option<i64>,
    /// The ISDU ErrorType of a write (0: accepted).
    #[serde(default)]
    pub error: Option<i64>,
    /// Whether a guard entry suppressed the write (3.1 ISDU 66, 109, 111, 126).
    #[serde(default)]
    pub suppressed: Option<bool>,
}

/// Every PSx3xx `sequence` vector that does not read as [`PsxSequence`], naming file, record
/// and key (`drivespec spec check`).
pub fn check_steps(spec: &Spec) -> Vec<Problem> {
    check_sequences::<PsxSequence>(spec.family(drivespec_spec::FamilyId::Psx3xx))
}
