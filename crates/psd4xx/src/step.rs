//! The PSD4xx step language of the `sequence` vectors (`spec/psd4xx/vectors`): what the
//! environment does, what the master sends in the process data, what the step waits for and
//! what the drive must show then (manual 3.6, 3.7, chapter 4; `spec/SCHEMA.md` "Steps and
//! scenarios").
//!
//! Every record is `deny_unknown_fields`: a misspelt key is an error naming the key, and
//! [`check_steps`] reports it as a `spec check` problem.

use drivespec_positioner::step::{check_sequences, Sequence, State, Wait};
use drivespec_spec::{FamilyId, Problem, Spec};
use serde::{Deserialize, Serialize};

/// The `input` of a sequence vector.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Input {
    /// Parameter number to value, set before the first step (3: where the shaft stands,
    /// 1 and 2: a live status word and speed to reach, 13: the model string).
    #[serde(default)]
    pub state: State,
    /// The steps, in order.
    #[serde(default)]
    pub steps: Vec<Step>,
}

/// The `expect` of a sequence vector: what holds after the last step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Final {
    /// The actual position at the end, within the positioning window (par. 44).
    #[serde(default)]
    pub actual: Option<i64>,
}

/// A typed PSD4xx `sequence` vector.
#[derive(Debug, Clone, PartialEq)]
pub struct PsdSequence {
    /// Start state and steps.
    pub input: Input,
    /// What holds at the end.
    pub expect: Final,
}

impl Sequence for PsdSequence {
    type Input = Input;
    type Expect = Final;
    type Step = Step;
    fn new(input: Input, expect: Final) -> PsdSequence {
        PsdSequence { input, expect }
    }
}

/// One step: an event, then the process output (control word and target), then the wait,
/// then the expectations.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Step {
    /// Something the environment does first.
    #[serde(default)]
    pub event: Option<Event>,
    /// For `manual-rotation-at-standstill`: the direction of the turn.
    #[serde(default)]
    pub direction: Option<Direction>,
    /// For `manual-rotation-at-standstill`: how far, in increments.
    #[serde(default)]
    pub distance: Option<i64>,
    /// A new control word (3.7).
    #[serde(default)]
    pub control: Option<u16>,
    /// A new target.
    #[serde(default)]
    pub target: Option<i32>,
    /// A new target relative to the actual position at the start of the step.
    #[serde(default)]
    pub target_offset: Option<i64>,
    /// What the step waits for after the output went out.
    pub wait: Wait,
    /// Status bits set (3.6).
    #[serde(default)]
    pub status_set: Vec<u32>,
    /// Status bits clear (3.6).
    #[serde(default)]
    pub status_clear: Vec<u32>,
    /// The actual position, within the positioning window (par. 44).
    #[serde(default)]
    pub actual: Option<i64>,
    /// The lowest position passed during the step.
    #[serde(default)]
    pub min_position: Option<i64>,
    /// The lowest position passed, relative to the start of the step.
    #[serde(default)]
    pub min_position_offset: Option<i64>,
    /// `true`: the drive does not stand still between two runs.
    #[serde(default)]
    pub no_intermediate_standstill: Option<bool>,
}

/// Something the environment does during a step (3.6, 4.1, 4.5, 4.9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Event {
    /// Supply off and on again.
    PowerOn,
    /// The drive meets an obstruction.
    ObstructionDetected,
    /// The shaft is turned by hand at standstill.
    ManualRotationAtStandstill,
    /// The motor supply leaves its range.
    MotorVoltageOutOfRange,
    /// The motor supply returns into its range.
    MotorVoltageInRange,
    /// After a run the shaft is moved out of the positioning window.
    PositionOutsideWindowAfterRun,
    /// The PROFINET connection is interrupted.
    ConnectionInterrupted,
    /// The PROFINET connection is restored.
    ConnectionRestored,
    /// The controller's IOPS turns bad.
    IopsBad,
}

/// The direction of a turn by hand.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Direction {
    /// Towards higher positions.
    Increasing,
    /// Towards lower positions.
    Decreasing,
}

/// Every PSD4xx `sequence` vector that does not read as [`PsdSequence`], naming file, record
/// and key (`drivespec spec check`).
pub fn check_steps(spec: &Spec) -> Vec<Problem> {
    check_sequences::<PsdSequence>(spec.family(FamilyId::Psd4xx))
}
