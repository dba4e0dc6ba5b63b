//! Protocol tables of `spec/psx3xx/protocol.toml` (PSE/PSS/PSW 3xx IO-Link manual).
//!
//! Everything a codec or a reference model of the PSx3xx needs beyond the parameter list:
//! the process images of the three output formats and the input image (3.3), the time-stamp
//! rules (3.3.1, 4.4), the target-speed rules of the 8-byte format (4.6.4), Direct Parameter
//! page 1 and the device ID (3.1), the ISDU error codes, the ISDU 2 / 193 command semantics,
//! the time-out behaviours (5.9), the jog-key table (5.10), brakes (5.12, 5.13), LEDs (2.6)
//! and the numeric constants of chapters 4 and 5. Parameters are referenced by their ids in
//! `parameters.toml` (`"110"`, `"0.3"` …).

use crate::{Access, DataType};
use serde::{Deserialize, Serialize};

/// The `[protocol]` table.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Protocol {
    /// Manual chapters the tables come from.
    pub source: String,
    /// Byte order of multi-byte process data and ISDU values (3.3.2 note; IEC 61131-9).
    pub byte_order: ByteOrderRule,
    /// Process-data format selection by ISDU 116 (3.1, 3.3.1).
    pub format_select: FormatSelect,
    /// The three process-output images, one per format 0, 1, 2 (3.3.1).
    #[serde(rename = "process_output")]
    pub process_outputs: Vec<ProcessImage>,
    /// The process-input image, the same for every format (3.3.2).
    pub process_input: ProcessImage,
    /// Time-stamp rules of format 0 (3.3.1, 4.4).
    pub timestamp: Timestamp,
    /// Target-speed rules of format 2 (4.6.4).
    pub target_speed: TargetSpeed,
    /// IO-Link Direct Parameter page 1 as read through ISDU 0 (3.1).
    pub direct_parameters: DirectParameterPage,
    /// How the device builds its IO-Link device ID (3.1 ISDU 116).
    pub device_id: DeviceId,
    /// IO-Link ISDU ErrorTypes and the situations in which the device answers with them.
    pub isdu_errors: IsduErrors,
    /// Command semantics of ISDU 2 and ISDU 193 (3.1).
    pub commands: Commands,
    /// Positioning, loop, speed, torque and blocking rules (2.7, 4.2, 4.3, 5.1–5.4, 5.8).
    pub motion: Motion,
    /// Position scaling and the upper mapping end (5.5–5.7).
    pub mapping: Mapping,
    /// Behaviour on loss of the master (5.9).
    pub timeout: Timeout,
    /// Jog keys and jog bits (5.10, 3.5).
    pub jog: Jog,
    /// Brake options (5.11–5.13, 3.5 bit 11).
    #[serde(rename = "brake")]
    pub brakes: Vec<Brake>,
    /// The LEDs (2.6, 3.3.1).
    #[serde(rename = "led")]
    pub leds: Vec<Led>,
    /// Reference run to a hard block (5.14, 2.7).
    pub reference_run: ReferenceRun,
    /// Numeric constants of chapters 2–6 a model needs.
    pub constants: Constants,
}

/// Byte order of multi-byte values (3.3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ByteOrder {
    /// Most significant byte first (IO-Link octet order).
    BigEndian,
    /// Least significant byte first (swapped by some masters).
    LittleEndian,
}

/// The byte order the device uses and the alternative some masters show (3.3.2).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ByteOrderRule {
    /// Order on the wire (IO-Link: octet 0 is the most significant).
    pub wire: ByteOrder,
    /// Order some masters present to the PLC (both directions swapped).
    pub swapped_by_some_masters: ByteOrder,
    /// How a user identifies the order (status bit 4 toggling with motor voltage).
    pub identify: String,
    /// Erratum that records the choice.
    pub erratum: String,
    /// Manual section, and the IO-Link clause where the manual is silent.
    pub source: String,
}

/// Selection of the output format by ISDU 116 (3.1, 3.3.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormatSelect {
    /// The parameter that selects the format (`"116"`).
    pub param: String,
    /// Delivery format (1 = 6 bytes).
    pub default: u8,
    /// A new format becomes active only after save and reset/restart.
    pub active_after: String,
    /// Manual section.
    pub source: String,
}

/// Direction of a process image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Master to device (process output data).
    Out,
    /// Device to master (process input data).
    In,
}

/// One process image (3.3.1, 3.3.2).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessImage {
    /// `out` or `in`.
    pub direction: Direction,
    /// ISDU 116 value for output images; absent for the input image (valid in every format).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<u8>,
    /// Short kebab-case name (`time-stamp`, `six-byte`, `eight-byte`, `input`).
    pub name: String,
    /// Image length in bytes.
    pub length: u32,
    /// Lowest software version (ISDU 80) that offers the image.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_software: Option<u32>,
    /// Fields in byte order.
    #[serde(rename = "field")]
    pub fields: Vec<PdField>,
    /// Manual section.
    pub source: String,
}

/// One field of a process image (3.3).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PdField {
    /// Field name (`control`, `stamp`, `control_word`, `target`, `target_speed`, `status`, `rpm`, `actual`).
    pub name: String,
    /// Byte offset of the word that holds the field.
    pub offset: u32,
    /// Length in bytes of the word that holds the field.
    pub length: u32,
    /// Position of the field's least significant bit inside the word (0 = whole word).
    #[serde(default)]
    pub bit: u32,
    /// Width of the field in bits.
    pub bits: u32,
    /// Value type of the field.
    #[serde(rename = "type")]
    pub data_type: DataType,
    /// Byte order of the word.
    pub byte_order: ByteOrder,
    /// Corresponding ISDU parameters (the first one is the main one).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub params: Vec<String>,
    /// Bitfield id (in `bits.toml`) that describes the field's bits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bitfield: Option<String>,
    /// One line.
    pub description: String,
    /// Manual section.
    pub source: String,
}

/// What a time-stamp control code or a timeout does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RunAction {
    /// Stop any run (release withdrawn).
    Abort,
    /// Manual run to larger values.
    ManualForward,
    /// Manual run to smaller values.
    ManualReverse,
    /// Positioning run to the target in ISDU 112.
    Position,
    /// A started positioning ends as planned.
    FinishRun,
    /// Run to the safe position of ISDU 138.
    SafePosition,
    /// No action.
    None,
}

/// Time-stamp rules of format 0 (3.3.1, 4.4).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Timestamp {
    /// The output format that carries time stamps (0).
    pub format: u8,
    /// Time base of one stamp count in microseconds (4).
    pub unit_us: u32,
    /// Width of the stamp field in bits (14).
    pub bits: u32,
    /// Stamp value meaning "no new time stamp" (0x3FFF).
    pub inactive: u32,
    /// Largest valid stamp (16368).
    pub max_valid: u32,
    /// Largest delay in microseconds (max_valid × unit_us = 65472).
    pub max_delay_us: u32,
    /// Stamps below this value are executed at once (2000).
    pub immediate_below: u32,
    /// The delay that corresponds to `immediate_below` (8000 µs = IO-Link cycle time).
    pub immediate_below_us: u32,
    /// How the delay is computed and from when it counts.
    pub delay: String,
    /// Stamp values that are neither valid nor the inactive marker.
    pub reserved: Vec<[u32; 2]>,
    /// What the manual says (nothing) about reserved values, and the choice made.
    pub reserved_handling: String,
    /// When a pending stamp fires.
    pub trigger: String,
    /// Bits of the control word (ISDU 110) driven by the two control bits; the others come from ISDU 110.
    pub control_word_mask: u16,
    /// Parameter that holds the target of code 3 (`"112"`).
    pub target_param: String,
    /// Parameter that holds the rest of the control word (`"110"`).
    pub control_word_param: String,
    /// The four control codes.
    #[serde(rename = "command")]
    pub commands: Vec<TimestampCommand>,
    /// Erratum on the immediate execution of small stamps.
    pub erratum: String,
    /// Manual section.
    pub source: String,
}

/// One value of the two control bits of format 0 (3.3.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimestampCommand {
    /// Value of bits 0–1.
    pub code: u8,
    /// Short kebab-case name.
    pub name: String,
    /// What the drive does when the stamp fires.
    pub action: RunAction,
    /// Control-word bits (within `control_word_mask`) this code stands for.
    pub control_word: u16,
    /// One line.
    pub meaning: String,
    /// Manual section.
    pub source: String,
}

/// Target-speed rules of the 8-byte format (4.6.4, 4.6.1, 5.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TargetSpeed {
    /// The output format with a speed field (2).
    pub format: u8,
    /// Name of the speed field in that image.
    pub field: String,
    /// Speed parameter replaced (not overwritten) during positioning runs (`"142"`).
    pub positioning_param: String,
    /// Speed parameter replaced (not overwritten) during manual runs (`"145"`).
    pub manual_param: String,
    /// Field value that means "use the ISDU speed" (0).
    pub use_parameter_value: i64,
    /// How validity is judged: against the model range of the replaced parameter.
    pub valid_range: String,
    /// Status bit set by an invalid speed (12, "incorrect target value").
    pub invalid_status_bit: u32,
    /// An invalid speed starts no run.
    pub invalid_starts_no_run: bool,
    /// An invalid speed aborts an active run.
    pub invalid_aborts_run: bool,
    /// A new speed received during a positioning run is used at once.
    pub applied_during_run: bool,
    /// Cap for counter-clockwise rotation (`"143"`).
    pub ccw_limit_param: String,
    /// Cap for clockwise rotation (`"144"`).
    pub cw_limit_param: String,
    /// How the cap applies: the smaller of requested speed and cap.
    pub limit_rule: String,
    /// Erratum on the manual's PSE335 example.
    pub erratum: String,
    /// Manual section.
    pub source: String,
}

/// Direct Parameter page 1 as read through ISDU index 0 (3.1; IEC 61131-9 B.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectParameterPage {
    /// ISDU index of the page (0).
    pub isdu_index: u16,
    /// ISDU subindex = page address + this offset (1).
    pub subindex_offset: u8,
    /// The sixteen entries.
    #[serde(rename = "entry")]
    pub entries: Vec<DirectParameter>,
    /// MinCycleTime time bases (IEC 61131-9 B.1.3).
    #[serde(rename = "cycle_time_base")]
    pub cycle_time_bases: Vec<CycleTimeBase>,
    /// M-sequence codes the device announces (IEC 61131-9 A.2.6).
    #[serde(rename = "m_sequence")]
    pub m_sequences: Vec<MSequenceCode>,
    /// ProcessDataIn/Out bytes per output format.
    #[serde(rename = "pd_length")]
    pub pd_lengths: Vec<PdLengthCode>,
    /// Erratum on the manual's delivery column.
    pub erratum: String,
    /// Manual section.
    pub source: String,
}

/// One Direct Parameter page 1 entry (3.1 ISDU 0).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectParameter {
    /// Page address 0x00–0x0F.
    pub address: u8,
    /// Parameter id in `parameters.toml` (`"0.1"` … `"0.16"`).
    pub param: String,
    /// IO-Link name.
    pub name: String,
    /// Access through ISDU 0 as the manual lists it.
    pub access: Access,
    /// The manual's delivery byte, where it gives one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delivery: Option<u8>,
    /// The byte depends on the output format or the model (see `pd_length`, `device_id`).
    #[serde(default)]
    pub varies: bool,
    /// Decoded meaning of the delivery byte.
    pub meaning: String,
    /// Sub-fields of the byte.
    #[serde(default, rename = "field", skip_serializing_if = "Vec::is_empty")]
    pub fields: Vec<DpField>,
    /// Manual section, and the IO-Link clause for the encoding.
    pub source: String,
}

/// A bit field inside a Direct Parameter byte (IEC 61131-9 B.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DpField {
    /// Field name.
    pub name: String,
    /// Least significant bit.
    pub bit: u32,
    /// Width in bits.
    pub bits: u32,
    /// Value in the delivery byte.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<u32>,
    /// One line.
    pub meaning: String,
}

/// MinCycleTime time base: time = offset + multiplier × step (IEC 61131-9 B.1.3).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CycleTimeBase {
    /// Value of bits 6–7.
    pub code: u8,
    /// Time for multiplier 0, µs.
    pub offset_us: u32,
    /// Time per multiplier count, µs.
    pub step_us: u32,
    /// IO-Link clause.
    pub source: String,
}

/// An M-sequence code (IEC 61131-9 A.2.6).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MSequenceCode {
    /// `operate` or `preoperate`.
    pub mode: String,
    /// Code value.
    pub code: u8,
    /// M-sequence type.
    pub m_type: String,
    /// On-request data octets.
    pub od_octets: u32,
    /// IO-Link clause.
    pub source: String,
}

/// Direct Parameter ProcessDataIn/Out bytes for one output format (3.1, 3.3).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PdLengthCode {
    /// ISDU 116 value.
    pub format: u8,
    /// ProcessDataIn byte (address 0x05).
    pub pd_in: u8,
    /// ProcessDataOut byte (address 0x06).
    pub pd_out: u8,
    /// Manual section.
    pub source: String,
}

/// How the device ID is built (3.1 ISDU 116, ISDU 79).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceId {
    /// IO-Link vendor ID (Direct Parameter 0x07–0x08).
    pub vendor_id: u16,
    /// Parameter that holds the model code (`"79"`).
    pub model_param: String,
    /// device ID = model code × multiplier + suffix (decimal).
    pub multiplier: u32,
    /// Bytes of the device ID (Direct Parameter 0x09–0x0B, MSB first).
    pub octets: u32,
    /// Suffix per output format.
    #[serde(rename = "suffix")]
    pub suffixes: Vec<FormatSuffix>,
    /// When a new ID is reported.
    pub takes_effect: String,
    /// Manual section.
    pub source: String,
}

/// Device-ID suffix of one output format (3.1 ISDU 116).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormatSuffix {
    /// ISDU 116 value.
    pub format: u8,
    /// Last two decimal digits of the device ID.
    pub suffix: u32,
    /// The manual's example ID.
    pub example: u32,
}

/// ISDU ErrorTypes (IEC 61131-9 annex C) and where the device uses them.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsduErrors {
    /// The ErrorType codes.
    #[serde(rename = "code")]
    pub codes: Vec<IsduError>,
    /// Situations mapped to codes.
    #[serde(rename = "case")]
    pub cases: Vec<IsduErrorCase>,
    /// Where the codes come from.
    pub source: String,
}

/// One IO-Link ISDU ErrorType (IEC 61131-9 C.2).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsduError {
    /// ErrorCode × 256 + AdditionalCode (0x8011 …).
    pub code: u16,
    /// IO-Link name (`IDX_NOTAVAIL` …).
    pub name: String,
    /// One line.
    pub meaning: String,
}

/// A situation and the ErrorType the device answers with.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsduErrorCase {
    /// Kebab-case situation name.
    pub case: String,
    /// ErrorType adopted.
    pub code: u16,
    /// Other codes a conforming device may send instead.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub acceptable: Vec<u16>,
    /// Parameters concerned (empty = any).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub params: Vec<String>,
    /// The requirement a device breaks that does not refuse in this situation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub requirement: Option<String>,
    /// The refused value lies outside the parameter's own range: the parameter's range
    /// requirement is broken before `requirement`.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub range: bool,
    /// One line.
    pub text: String,
    /// Manual statement, or the IO-Link clause where the manual is silent.
    pub source: String,
}

/// Command semantics of ISDU 2 and ISDU 193 (3.1, 5.5 comment 8).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Commands {
    /// Every command value, with its effects as flags.
    #[serde(rename = "command")]
    pub commands: Vec<StateCommand>,
    /// Meanings of values read back from ISDU 193.
    #[serde(rename = "readback")]
    pub readbacks: Vec<Readback>,
    /// Longest time a save to EEPROM takes, ms.
    pub save_max_ms: u32,
    /// Manual section.
    pub source: String,
}

/// What a command does to the process-data format.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FormatEffect {
    /// ISDU 116 keeps its value.
    Keep,
    /// ISDU 116 is set to its delivery value 1.
    Default,
    /// Not stated.
    Unspecified,
}

/// One value of ISDU 2 or ISDU 193 and its effects (3.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StateCommand {
    /// Parameter written (`"2"` or `"193"`).
    pub param: String,
    /// Value written.
    pub value: i64,
    /// Short kebab-case name.
    pub name: String,
    /// Device restarts (new format becomes active).
    pub reset: bool,
    /// All parameters get their delivery values.
    pub defaults: bool,
    /// Effect on ISDU 116.
    pub format: FormatEffect,
    /// Parameters are saved to EEPROM.
    pub save: bool,
    /// An initial reference loop is run.
    pub reference_loop: bool,
    /// The drive then positions to mid-range.
    pub centre_run: bool,
    /// One line.
    pub meaning: String,
    /// Manual section.
    pub source: String,
}

/// A documented read-back value of ISDU 193 (3.1, 5.5 comment 8).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Readback {
    /// `after-boot` or `after-save`.
    pub when: String,
    /// `zero` or `nonzero`.
    pub value: String,
    /// One line.
    pub meaning: String,
    /// Manual section.
    pub source: String,
}

/// Positioning, loop, speed, torque, blocking and drag rules (2.7, 4.2, 4.3, 5.1–5.4, 5.8).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Motion {
    /// Loop length in steps, 0 = no loop (`"132"`).
    pub loop_length_param: String,
    /// Loop direction, 0 forwards, 1 backwards (`"134"`).
    pub loop_direction_param: String,
    /// Control bit "run without loop" (6).
    pub no_loop_bit: u32,
    /// Control bit "initial reference loop" (7).
    pub reference_loop_bit: u32,
    /// Control bit "release" (4).
    pub release_bit: u32,
    /// Control bit "transfer target values" (2).
    pub transfer_bit: u32,
    /// Control bit "readjustment" (10).
    pub readjust_bit: u32,
    /// Control bit "drag error correction" (12).
    pub drag_correction_bit: u32,
    /// Initial reference loop: turns against then with the loop direction, as [numerator, denominator] (5/8).
    pub reference_loop_turns: [u32; 2],
    /// Loop planning rules, in the order they are checked.
    #[serde(rename = "loop_case")]
    pub loop_cases: Vec<LoopCase>,
    /// Speed used by positioning runs (`"142"`).
    pub positioning_speed_param: String,
    /// Speed used by manual runs and the initial reference loop (`"145"`).
    pub manual_speed_param: String,
    /// Speed cap for counter-clockwise rotation (`"143"`).
    pub ccw_speed_param: String,
    /// Speed cap for clockwise rotation (`"144"`).
    pub cw_speed_param: String,
    /// Acceleration for all runs (`"147"`).
    pub acceleration_param: String,
    /// Deceleration for all runs (`"148"`).
    pub deceleration_param: String,
    /// Direction of rotation: 0 = position rises clockwise (`"123"`).
    pub direction_param: String,
    /// Start torque (`"152"`), valid for `start_time_param` after each start.
    pub start_torque_param: String,
    /// Duration of the start phase, ms (`"160"`).
    pub start_time_param: String,
    /// Running torque after the start phase (`"153"`).
    pub torque_param: String,
    /// Holding torque at standstill (`"155"`).
    pub holding_torque_param: String,
    /// Holding torque during the end-of-run phase (`"154"`).
    pub end_holding_torque_param: String,
    /// Duration of the end-of-run holding phase, ms (`"161"`).
    pub end_holding_time_param: String,
    /// Idle time before a reversal of direction, ms (`"162"`).
    pub reversal_wait_param: String,
    /// Torque formula of 5.2: the largest running torque at a reduced speed.
    pub torque_formula: String,
    /// Block detection: speed threshold in % of the target speed (`"146"`).
    pub block_speed_param: String,
    /// Block detection: time below the threshold, ms (`"159"`).
    pub block_time_param: String,
    /// Status bit set by a block (10).
    pub block_status_bit: u32,
    /// Positioning window in steps (`"131"`).
    pub window_param: String,
    /// Drag error limit in steps (`"133"`).
    pub drag_error_param: String,
    /// What is compared with the drag error limit.
    pub drag_rule: String,
    /// Manual section.
    pub source: String,
}

/// One case of loop planning (2.7, 4.2); positions in loop-direction terms.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoopCase {
    /// Case number of the manual (1, 2, 3) or 0 for the no-loop rule.
    pub case: u32,
    /// Kebab-case name.
    pub name: String,
    /// Condition, with d = target − actual measured in loop direction and L = loop length.
    pub condition: String,
    /// The movement made.
    pub motion: String,
    /// Manual section.
    pub source: String,
}

/// Position scaling and mapping (5.5–5.7, 3.1 ISDU 124–132).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mapping {
    /// Steps per output revolution when numerator = denominator (400).
    pub scaling_base: u32,
    /// Numerator parameter (`"124"`).
    pub numerator_param: String,
    /// Denominator parameter (`"125"`).
    pub denominator_param: String,
    /// Referencing value parameter (`"127"`).
    pub reference_param: String,
    /// Upper mapping end parameter (`"128"`).
    pub upper_mapping_end_param: String,
    /// Upper limit parameter (`"129"`).
    pub upper_limit_param: String,
    /// Lower limit parameter (`"130"`).
    pub lower_limit_param: String,
    /// Actual value parameter, writing it sets the referencing value (`"67"`).
    pub actual_param: String,
    /// Steps per revolution formula.
    pub steps_per_revolution: String,
    /// Sign convention of the referencing value.
    pub reference_rule: String,
    /// Erratum that records the sign convention.
    pub reference_erratum: String,
    /// Distance of the upper limit below the mapping end, in base steps (1200 = 3 rev).
    pub upper_margin_steps: u32,
    /// Distance of the lowest position below the mapping end, in base steps (101200 = 253 rev).
    pub lower_offset_steps: u32,
    /// Fixed bounds of the mapping end: 1 + ref ≤ end ≤ span × den/num − 1 + ref, span in base steps (204800 = 512 rev).
    pub mapping_end_span_steps: u32,
    /// Rule for the mapping-end range that depends on the actual position.
    pub mapping_end_rule: String,
    /// Tolerance of the actual-position check after setting the mapping end, steps (1).
    pub mapping_tolerance_steps: u32,
    /// Rounding of scaled bounds when numerator ≠ denominator.
    pub rounding: String,
    /// How the encoder position is mapped into user positions.
    pub mapping_rule: String,
    /// Automatic resets and recalculations when a parameter changes.
    #[serde(rename = "recalculation")]
    pub recalculations: Vec<Recalculation>,
    /// Recommended order for writing the position parameters (5.5 comment 7, 5.6.5).
    #[serde(rename = "order")]
    pub order: Vec<OrderStep>,
    /// Manual section.
    pub source: String,
}

/// What happens to other parameters when one changes (5.5 comments 3–6).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Recalculation {
    /// Parameters whose change triggers the rule.
    pub trigger: Vec<String>,
    /// `reset-to-delivery`, `relative-to-mapping-end` or `recalculate`.
    pub effect: String,
    /// Values affected (parameter ids; `target` and `actual` for the live positions).
    pub affects: Vec<String>,
    /// One line.
    pub text: String,
    /// Erratum that records a reading, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub erratum: Option<String>,
    /// Manual section.
    pub source: String,
}

/// One step of the recommended parameter order (5.5 comment 7).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OrderStep {
    /// Step number (1 = first).
    pub step: u32,
    /// Parameters written in this step.
    pub params: Vec<String>,
    /// Manual section.
    pub source: String,
}

/// Behaviour on loss of the master (5.9, 3.1 ISDU 118/137/138).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Timeout {
    /// Communication time-out in ms, 0 = off (`"118"`).
    pub timeout_param: String,
    /// Reaction selector (`"137"`).
    pub config_param: String,
    /// Safe position (`"138"`).
    pub safe_position_param: String,
    /// Largest time-out, ms (10000).
    pub max_ms: u32,
    /// The behaviours.
    #[serde(rename = "behaviour")]
    pub behaviours: Vec<TimeoutBehaviour>,
    /// Manual section.
    pub source: String,
}

/// One time-out behaviour (5.9).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimeoutBehaviour {
    /// Kebab-case name.
    pub name: String,
    /// Whether ISDU 118 is > 0 for this behaviour.
    pub timeout_enabled: bool,
    /// ISDU 137 value, absent when it does not matter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub config: Option<u16>,
    /// What happens to a run in progress.
    pub running: RunAction,
    /// What happens at standstill.
    pub standstill: RunAction,
    /// New positioning runs are refused while the connection is lost.
    pub blocks_new_runs: bool,
    /// One line.
    pub text: String,
    /// Manual section.
    pub source: String,
}

/// Jog keys and jog bits (5.10, 3.5 bits 3, 5, 8, 9, 2.5.3).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Jog {
    /// Steps of one short jog (`"135"`).
    pub step_param: String,
    /// Hold time before continuous jog, in 5 ms units (`"163"`).
    pub wait_param: String,
    /// Control bit "release" (4).
    pub release_bit: u32,
    /// Control bit "release jog with keys" (5).
    pub key_release_bit: u32,
    /// Control bit "release continuous manual run in jog mode" (3).
    pub continuous_bit: u32,
    /// Control bit "jog to larger values" (8).
    pub forward_bit: u32,
    /// Control bit "jog to smaller values" (9).
    pub reverse_bit: u32,
    /// Status bit "forward jog key active" (3).
    pub forward_key_status_bit: u32,
    /// Status bit "reverse jog key active" (2).
    pub reverse_key_status_bit: u32,
    /// Continuous jog runs up to these limits (`"129"`, `"130"`).
    pub limit_params: Vec<String>,
    /// Both keys pressed cancel the run; a new jog needs both released.
    pub both_keys_cancel: bool,
    /// A started single step completes even if the key is released.
    pub step_completes: bool,
    /// Connector pins: [+24 V out, forward, reverse, ground] of the M8 jog connector.
    pub pins: [u32; 4],
    /// When the keys are active.
    #[serde(rename = "row")]
    pub rows: Vec<JogRow>,
    /// Manual section.
    pub source: String,
}

/// One row of the jog-key table (5.10); `None` = don't care.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JogRow {
    /// IO-Link connection established.
    pub bus: bool,
    /// Control bit 4 (release).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bit4: Option<bool>,
    /// Control bit 5 (release jog with keys).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bit5: Option<bool>,
    /// Keys work.
    pub keys_active: bool,
    /// Holding a key gives a continuous run (otherwise only single steps).
    pub continuous: String,
}

/// A brake option (5.11–5.13).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Brake {
    /// `snap` or `holding`.
    pub kind: String,
    /// Model patterns the option exists for.
    pub models: Vec<String>,
    /// Wait before the start of a run for the brake to open (`"164"`), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_wait_param: Option<String>,
    /// Breaking-free steps (`"136"`), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_steps_param: Option<String>,
    /// Time the brake stays open after the end of a run (`"165"`), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end_wait_param: Option<String>,
    /// Control bit that orders the breaking-free run (11), if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub free_run_bit: Option<u32>,
    /// Drives with this brake readjust after manual displacement.
    pub readjustment: bool,
    /// The brake can be opened over the bus without a run.
    pub release_without_run: bool,
    /// Manual turning without opening the brake destroys it.
    pub forced_turning_destroys: bool,
    /// One line on the run sequence.
    pub sequence: String,
    /// Erratum that records a reading, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub erratum: Option<String>,
    /// Manual section.
    pub source: String,
}

/// An LED (2.6).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Led {
    /// `green`, `orange` or `yellow`.
    pub colour: String,
    /// What it shows.
    pub name: String,
    /// Its states.
    #[serde(rename = "state")]
    pub states: Vec<LedState>,
    /// Manual section.
    pub source: String,
}

/// One LED state (2.6).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LedState {
    /// Kebab-case pattern (`off`, `on`, `on-90-percent`, `dark-250ms`).
    pub pattern: String,
    /// One line.
    pub meaning: String,
}

/// Reference run to a hard block (5.14).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceRun {
    /// Largest start and running torque, % of rated torque (10).
    pub max_torque_percent: u32,
    /// Settings to apply before the run.
    #[serde(rename = "setting")]
    pub settings: Vec<Setting>,
    /// Steps of the procedure, one line each.
    pub steps: Vec<String>,
    /// Manual section.
    pub source: String,
}

/// A parameter value for a procedure (5.14).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Setting {
    /// Parameter id.
    pub param: String,
    /// Raw value, when a fixed one is prescribed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<i64>,
    /// The rule, when the value depends on the model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rule: Option<String>,
}

/// Numeric constants of chapters 2–6 (raw integers; units in the field names).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Constants {
    /// Measuring range of the absolute encoder, output revolutions (256; 5.6.4, 6.3).
    pub encoder_revolutions: u32,
    /// Usable positioning range, revolutions (250; 5.5, 6.3).
    pub usable_revolutions: u32,
    /// Safety margin at each end of the range, revolutions (3; 5.5, 5.6.1).
    pub margin_revolutions: u32,
    /// Steps per revolution at numerator = denominator (400; 5.7).
    pub steps_per_revolution: u32,
    /// Angle of one step at default scaling, millidegrees (900 = 0.9°; 5.6.2, 6.2).
    pub step_angle_mdeg: u32,
    /// Delivery actual position, steps (51200; 5.5).
    pub delivery_position: i64,
    /// Delivery upper mapping end, steps (102400; 5.5, 5.6.1).
    pub delivery_upper_mapping_end: i64,
    /// Delivery upper limit, steps (101200; 5.5).
    pub delivery_upper_limit: i64,
    /// Delivery lower limit, steps (1200; 5.5).
    pub delivery_lower_limit: i64,
    /// Travel each way from the delivery position, revolutions (125; 5.5).
    pub delivery_travel_revolutions: u32,
    /// Delivery loop length, steps (250 = 5/8 rev; 4.2, 3.1).
    pub delivery_loop_steps: u32,
    /// Spindle pitch at which default scaling gives 0.01 mm, µm (4000; 5.7).
    pub default_spindle_pitch_um: u32,
    /// Numerator and denominator range, [min, max] (1 … 10000; 5.7).
    pub scaling_factor_range: [u32; 2],
    /// Upper bound of the motor-voltage window for status bits 4 and 13, 0.1 V (300; 3.4).
    pub motor_voltage_max_dv: u32,
    /// Hysteresis of the temperature bit, °C (5; 3.4 bit 7).
    pub temperature_hysteresis_c: u32,
    /// Clamp of the internal protection diode during regeneration, V (31; 5.15).
    pub regen_clamp_v: u32,
    /// Regeneration without a consumer destroys the diode after this, ms (1000 … 2000; 5.15).
    pub regen_max_ms: [u32; 2],
    /// IO-Link minimum cycle time, µs (8000; 3.3.1, Direct Parameter 0x02).
    pub min_cycle_time_us: u32,
    /// Default block detection threshold, % of target speed (30; 5.3).
    pub block_speed_percent_default: u32,
    /// Default block detection time, ms (200; 5.3).
    pub block_time_ms_default: u32,
    /// Software version (ISDU 80) from which format 2 and control bit 14 exist (249; 1.6).
    pub format2_min_software: u32,
    /// IO-Link specification version used (3 intro, 6.2).
    pub iolink_version: String,
    /// Manual sections.
    pub source: String,
}

impl Protocol {
    /// The process-output image of an ISDU 116 format.
    pub fn output_format(&self, format: u8) -> Option<&ProcessImage> {
        self.process_outputs
            .iter()
            .find(|p| p.format == Some(format))
    }

    /// The Direct Parameter entry at a page address.
    pub fn direct_parameter(&self, address: u8) -> Option<&DirectParameter> {
        self.direct_parameters
            .entries
            .iter()
            .find(|e| e.address == address)
    }

    /// The device ID reported for a model code (ISDU 79) in an output format.
    pub fn device_id_for(&self, model_code: u32, format: u8) -> Option<u32> {
        let d = &self.device_id;
        let suffix = d.suffixes.iter().find(|s| s.format == format)?.suffix;
        model_code.checked_mul(d.multiplier)?.checked_add(suffix)
    }
}

impl ProcessImage {
    /// A field by name.
    pub fn field(&self, name: &str) -> Option<&PdField> {
        self.fields.iter().find(|f| f.name == name)
    }
}

impl Timestamp {
    /// Delay in µs for a valid stamp; `None` for the inactive marker or a reserved value.
    pub fn delay_us(&self, stamp: u32) -> Option<u32> {
        if stamp > self.max_valid {
            return None;
        }
        stamp.checked_mul(self.unit_us)
    }

    /// Whether a valid stamp is executed at once.
    pub fn immediate(&self, stamp: u32) -> bool {
        stamp < self.immediate_below
    }

    /// The command for a control code.
    pub fn command(&self, code: u8) -> Option<&TimestampCommand> {
        self.commands.iter().find(|c| c.code == code)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Parses the `[protocol]` table of the embedded psx3xx spec.
    fn protocol() -> Option<Protocol> {
        let text = include_str!("../../../spec/psx3xx/protocol.toml");
        let mut table: toml::Table = text.parse().ok()?;
        table.remove("protocol")?.try_into().ok()
    }

    #[test]
    fn tables_decode_the_manual_examples() {
        let Some(p) = protocol() else {
            panic!("spec/psx3xx/protocol.toml does not parse");
        };
        assert_eq!(p.device_id_for(31208, 0), Some(3_120_801));
        assert_eq!(p.device_id_for(31208, 1), Some(3_120_802));
        assert_eq!(p.device_id_for(31208, 2), Some(3_120_804));
        assert_eq!(p.timestamp.delay_us(10_000), Some(40_000));
        assert_eq!(
            p.timestamp.delay_us(p.timestamp.max_valid),
            Some(p.timestamp.max_delay_us)
        );
        assert_eq!(p.timestamp.delay_us(p.timestamp.inactive), None);
        assert!(p.timestamp.immediate(1999));
        assert!(!p.timestamp.immediate(2000));
        let lengths: Vec<u32> = [0, 1, 2]
            .iter()
            .filter_map(|f| p.output_format(*f).map(|i| i.length))
            .collect();
        assert_eq!(lengths, vec![2, 6, 8]);
        for image in p
            .process_outputs
            .iter()
            .chain(std::iter::once(&p.process_input))
        {
            for f in &image.fields {
                assert!(
                    f.offset + f.length <= image.length,
                    "{} {}",
                    image.name,
                    f.name
                );
                assert!(f.bit + f.bits <= f.length * 8, "{} {}", image.name, f.name);
            }
        }
        let min_cycle = p.direct_parameter(2).and_then(|e| e.delivery);
        assert_eq!(min_cycle, Some(0x44));
        let base = p
            .direct_parameters
            .cycle_time_bases
            .iter()
            .find(|b| b.code == 1);
        assert_eq!(
            base.map(|b| b.offset_us + 4 * b.step_us),
            Some(p.constants.min_cycle_time_us)
        );
    }
}
