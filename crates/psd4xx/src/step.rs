//! The PSD4xx step language: [`Step`], one master action, environment event or wait of a
//! timed sequence (suite cases, scenario files, fuzz replay files, and the `sim-run` script,
//! whose commands are a text form of it: [`crate::script`]), and the
//! `sequence` vectors (`spec/psd4xx/vectors`) with their [`VectorStep`]: what the environment
//! does, what the master sends in the process data, what the step waits for and what the
//! drive must show then (manual 3.6, 3.7, 3.8, chapter 4; `spec/SCHEMA.md` "Steps and
//! scenarios").
//!
//! Every record is `deny_unknown_fields`: a misspelt key is an error naming the key, and
//! [`check_steps`] reports it as a `spec check` problem.

use crate::model::LinkEvent;
use crate::{CommandCode, PkwRequest};
use drivespec_positioner::step::{check_sequences, SequenceInput, SequenceVector, State, Wait};
use drivespec_spec::{FamilyId, Problem, Spec};
use serde::{Deserialize, Serialize};

/// One step of a PSD4xx sequence, keyed by `do` (`spec/SCHEMA.md` "Steps and scenarios").
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "do", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Step {
    /// New control word and/or target (absent: unchanged), then one cycle (3.5.1, 3.7).
    Process {
        /// Control word (par 32).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        control: Option<u16>,
        /// Target value (par 33).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        target: Option<i32>,
    },
    /// New control word (absent: unchanged) and a target this far from the actual position,
    /// then one cycle.
    Offset {
        /// Control word (par 32).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        control: Option<u16>,
        /// Target minus actual position (increments).
        offset: i64,
    },
    /// A PKW block, any code, cycled until the drive answers it (3.8).
    Pkw {
        /// The block.
        pkw: PkwBlock,
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
        /// The data, as hex (`01 00 07`).
        #[serde(with = "drivespec_positioner::step::hex_text")]
        hex: Vec<u8>,
    },
    /// Cycles with the outputs unchanged.
    Hold {
        /// How many.
        cycles: u32,
    },
    /// Cycles until the drive runs (`true`) or stands still, at most `max`.
    Until {
        /// Wait for "drive is running" set (true) or a standstill (false).
        running: bool,
        /// Most cycles.
        max: u32,
    },
    /// An environment injection in the text form of the cyclic-exchange protocol's `ENV`
    /// (`jam 1`, `power-cycle 0`).
    Env {
        /// The injection.
        env: String,
    },
    /// Time passes without a bus cycle (`ADVANCE`).
    Advance {
        /// How long (µs).
        us: u64,
    },
    /// A direct parameter write: the reference model's own access, no PKW or record traffic
    /// (3.3); a device under test has no such access.
    Par {
        /// Parameter number.
        pnu: u16,
        /// Value.
        value: i64,
    },
    /// A change of the connection to the IO controller (3.9, 4.9).
    Link {
        /// The change.
        event: LinkEvent,
    },
    /// Control voltage off and on again (2.2).
    PowerCycle,
}

impl Step {
    /// The step's `do` key.
    pub fn name(&self) -> &'static str {
        match self {
            Step::Process { .. } => "process",
            Step::Offset { .. } => "offset",
            Step::Pkw { .. } => "pkw",
            Step::RecordRead { .. } => "record-read",
            Step::RecordWrite { .. } => "record-write",
            Step::Hold { .. } => "hold",
            Step::Until { .. } => "until",
            Step::Env { .. } => "env",
            Step::Advance { .. } => "advance",
            Step::Par { .. } => "par",
            Step::Link { .. } => "link",
            Step::PowerCycle => "power-cycle",
        }
    }
}

/// A PKW block as a step writes it (3.8): codes and fields as numbers.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PkwBlock {
    /// Command code AK (0–15).
    pub ak: u8,
    /// SPM bit.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub spm: bool,
    /// Parameter number.
    pub pnu: u16,
    /// Subindex word IND.
    #[serde(default)]
    pub ind: u16,
    /// Parameter value PWE.
    #[serde(default)]
    pub pwe: u32,
}

impl From<PkwRequest> for PkwBlock {
    fn from(r: PkwRequest) -> PkwBlock {
        PkwBlock {
            ak: u8::from(r.ak),
            spm: r.spm,
            pnu: r.pnu,
            ind: r.ind,
            pwe: r.pwe,
        }
    }
}

impl From<PkwBlock> for PkwRequest {
    fn from(b: PkwBlock) -> PkwRequest {
        PkwRequest {
            ak: CommandCode::from(b.ak),
            spm: b.spm,
            pnu: b.pnu,
            ind: b.ind,
            pwe: b.pwe,
        }
    }
}

/// The `input` of a sequence vector.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Input {
    /// Parameter number to value, set before the first step (3: where the shaft stands,
    /// 1 and 2: a live status word and speed to reach, 13: the model string).
    pub state: State,
    /// The steps, in order.
    pub steps: Vec<VectorStep>,
}

/// The `expect` of a sequence vector: what holds after the last step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Final {
    /// The actual position at the end, within the positioning window (par. 44).
    pub actual: Option<i64>,
}

impl SequenceInput for Input {
    type Step = VectorStep;
}

/// A typed PSD4xx `sequence` vector.
pub type PsdSequence = SequenceVector<Input, Final>;

/// One step of a `sequence` vector: an event, then the process output (control word and
/// target), then the wait, then the expectations.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VectorStep {
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

#[cfg(test)]
mod tests {
    use super::{PkwBlock, Step};

    fn read(text: &str) -> Result<Step, toml::de::Error> {
        toml::from_str(text)
    }

    #[test]
    fn steps_read_with_the_replay_keys() {
        assert_eq!(
            read("do = \"process\"\ncontrol = 20\ntarget = 4000").ok(),
            Some(Step::Process {
                control: Some(20),
                target: Some(4000)
            })
        );
        assert_eq!(
            read("do = \"pkw\"\npkw = { ak = 1, pnu = 44 }").ok(),
            Some(Step::Pkw {
                pkw: PkwBlock {
                    ak: 1,
                    spm: false,
                    pnu: 44,
                    ind: 0,
                    pwe: 0
                }
            })
        );
        assert_eq!(
            read("do = \"record-write\"\nindex = 44\nhex = \"01 00 07\"").ok(),
            Some(Step::RecordWrite {
                index: 44,
                hex: vec![1, 0, 7]
            })
        );
        let s = Step::Until {
            running: false,
            max: 12_000,
        };
        let text = toml::to_string(&s).unwrap_or_default();
        assert_eq!(read(&text).ok(), Some(s));
    }

    #[test]
    fn a_misspelt_key_is_an_error_naming_it() {
        let e = read("do = \"hold\"\ncylces = 3")
            .err()
            .map(|e| e.to_string());
        assert!(e.is_some_and(|e| e.contains("cylces")));
        let e = read("do = \"pkw\"\npkw = { ak = 1, pnuu = 44 }")
            .err()
            .map(|e| e.to_string());
        assert!(e.is_some_and(|e| e.contains("pnuu")));
        assert!(read("do = \"isdu-read\"\nindex = 1").is_err());
    }
}
