//! The typed `input` and `expect` tables of each vector kind. Every key a kind knows is a
//! field; any other key is a schema problem of the vector.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A number written as an integer or a decimal.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Number {
    /// An integer.
    Int(i64),
    /// A decimal.
    Float(f64),
}

impl Number {
    /// The value as a float.
    pub fn as_f64(self) -> f64 {
        match self {
            Number::Int(i) => i as f64,
            Number::Float(f) => f,
        }
    }
}

/// One value or a list of them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum OneOrMany<T> {
    /// A single value.
    One(T),
    /// A list.
    Many(Vec<T>),
}

/// An integer or a name (a parameter value given as a number or as its enumerated text).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum IntOrText {
    /// A number.
    Int(i64),
    /// A name.
    Text(String),
}

/// Inputs of an HPD serial request (`kind = "hpd-frame"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HpdFrameInput {
    /// Address byte of the request.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub addr: Option<i64>,
    /// Bit number of a bit-change request.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bits: Option<i64>,
    /// Command code of the request.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cmd: Option<i64>,
    /// Data bytes of the request.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<Vec<i64>>,
    /// Address of the drive that receives the request, when not the addressed one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drive_addr: Option<i64>,
    /// PLC instructions as listed in the manual, one per line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub listing: Option<Vec<String>>,
    /// Length byte (LUN) of the request.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lun: Option<i64>,
    /// Bit mask of a bit-change request.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mask: Option<i64>,
    /// Parameter address byte of the request.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub par: Option<i64>,
    /// Parameter the request addresses (`Pr7`, `Pb99`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub param: Option<String>,
    /// The request frame in hex.
    pub request: String,
    /// Bit or parameter the request changes (`b99.13`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<String>,
    /// Value of the addressed parameter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<i64>,
}

/// Expected outputs of an HPD serial request (`kind = "hpd-frame"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HpdFrameExpect {
    /// PLC instructions as listed in the manual, one per line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub listing: Option<Vec<String>>,
    /// The drive's answer in hex; absent when it stays silent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub response: Option<String>,
    /// Value of the addressed parameter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<i64>,
}

/// Inputs of an HPD PLC program run (`kind = "hpd-plc"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HpdPlcInput {
    /// Bit values by bit name (`b90.1`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bits: Option<BTreeMap<String, i64>>,
    /// Parameter values by name (`Pr64`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub params: Option<BTreeMap<String, i64>>,
    /// PLC listing run on the drive, one instruction per line.
    pub program: Vec<String>,
    /// PLC scans to run (1 when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scans: Option<i64>,
}

/// Expected outputs of an HPD PLC program run (`kind = "hpd-plc"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HpdPlcExpect {
    /// Bit values by bit name (`b90.1`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bits: Option<BTreeMap<String, i64>>,
    /// Whether the PLC constants keep their values.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub constants_unchanged: Option<bool>,
    /// Expected 32-bit values by parameter pair (`Pr64:65`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dwords: Option<BTreeMap<String, i64>>,
    /// Time the scans take in ms.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub elapsed_ms: Option<f64>,
    /// Parameter values by name (`Pr64`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub params: Option<BTreeMap<String, i64>>,
}

/// Inputs of an HPD PLC listing (`kind = "hpd-plc-bytes"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HpdPlcBytesInput {
    /// PLC instructions as listed in the manual, one per line.
    pub listing: Vec<String>,
}

/// Expected outputs of an HPD PLC listing (`kind = "hpd-plc-bytes"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HpdPlcBytesExpect {
    /// The encoded program in hex.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bytes: Option<String>,
}

/// Inputs of a formula (`kind = "formula"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormulaInput {
    /// Acc in rad/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub acc_rad_s2: Option<f64>,
    /// Pb40 bit 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b40_0: Option<i64>,
    /// Pb42 bit 5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b42_5: Option<i64>,
    /// Pb42 bit 6.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub b42_6: Option<i64>,
    /// Count.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub count: Option<i64>,
    /// Delay the stamp stands for, in µs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delay_us: Option<i64>,
    /// Delta in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delta_rpm: Option<i64>,
    /// Denominator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub denominator: Option<i64>,
    /// Drive current in A.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub drive_current_a: Option<f64>,
    /// Fin in Hz.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fin_hz: Option<i64>,
    /// Process-data format (ISDU 116).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<i64>,
    /// Name of the formula (`pr33-rated-current`).
    pub formula: String,
    /// Increments.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub increments: Option<OneOrMany<i64>>,
    /// Jtot in kg·m².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jtot_kgm2: Option<f64>,
    /// Limit in °C.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limit_c: Option<i64>,
    /// Margin revolutions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub margin_revolutions: Option<i64>,
    /// Max speed in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_speed_rpm: Option<i64>,
    /// Model code.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_code: Option<i64>,
    /// Motor current in A.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub motor_current_a: Option<f64>,
    /// Nm peak.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nm_peak: Option<f64>,
    /// Numerator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub numerator: Option<i64>,
    /// Omega in rad/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub omega_rad_s: Option<f64>,
    /// Pr0 in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr0_rpm: Option<i64>,
    /// Pr16.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr16: Option<i64>,
    /// Pr17.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr17: Option<i64>,
    /// Pr18.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr18: Option<i64>,
    /// Pr2 in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr2_rpm: Option<i64>,
    /// Pr32 in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr32_rpm: Option<i64>,
    /// Pr33 in %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr33_percent: Option<f64>,
    /// Pr34.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr34: Option<i64>,
    /// Pr38 in %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr38_percent: Option<f64>,
    /// Pr3 in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr3_rpm: Option<i64>,
    /// Pr4 in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr4_rpm: Option<i64>,
    /// Ramp raw.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ramp_raw: Option<i64>,
    /// Rated torque in cNm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rated_torque_cnm: Option<i64>,
    /// Revolutions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub revolutions: Option<f64>,
    /// Set speed in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub set_speed_rpm: Option<i64>,
    /// Speed limit in %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed_limit_percent: Option<i64>,
    /// Start torque max in cNm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_torque_max_cnm: Option<i64>,
    /// Steps per revolution.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps_per_revolution: Option<i64>,
    /// Target speed in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_speed_rpm: Option<i64>,
    /// Time in ms.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_ms: Option<i64>,
    /// Top position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top_position: Option<i64>,
    /// Turns denominator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turns_denominator: Option<i64>,
    /// Turns numerator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turns_numerator: Option<i64>,
    /// Umot limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub umot_limit: Option<i64>,
    /// Upper mapping end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_mapping_end: Option<i64>,
    /// Expected value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<i64>,
    /// Vin in V.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vin_v: Option<f64>,
    /// Vmain in V.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vmain_v: Option<f64>,
    /// Vmains in V.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vmains_v: Option<f64>,
    /// Vmax in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vmax_rpm: Option<f64>,
    /// Vmot in V.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vmot_v: Option<f64>,
}

/// Expected outputs of a formula (`kind = "formula"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FormulaExpect {
    /// Angle in degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angle_deg: Option<f64>,
    /// Counts.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub counts: Option<i64>,
    /// Cutoff in Hz.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutoff_hz: Option<f64>,
    /// Device id.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device_id: Option<i64>,
    /// High.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub high: Option<i64>,
    /// Increments per rotation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub increments_per_rotation: Option<Number>,
    /// K.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub k: Option<i64>,
    /// Loop steps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loop_steps: Option<i64>,
    /// Low signed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub low_signed: Option<i64>,
    /// Low unsigned.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub low_unsigned: Option<i64>,
    /// Lower limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower_limit: Option<i64>,
    /// Max duration in s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_duration_s: Option<Vec<f64>>,
    /// Max in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_rpm: Option<i64>,
    /// Max torque in cNm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_torque_cnm: Option<i64>,
    /// Pmax in W.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pmax_w: Option<f64>,
    /// Pr17.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr17: Option<f64>,
    /// Pr18.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr18: Option<f64>,
    /// Pr19 max in %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr19_max_percent: Option<f64>,
    /// Pr19 max raw.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr19_max_raw: Option<i64>,
    /// Pr2.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr2: Option<f64>,
    /// Pr22 in %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr22_percent: Option<f64>,
    /// Pr22 raw.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr22_raw: Option<i64>,
    /// Pr32 in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr32_rpm: Option<f64>,
    /// Pr33 in %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr33_percent: Option<f64>,
    /// Pr33 raw.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr33_raw: Option<i64>,
    /// Pr7 in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pr7_rpm: Option<f64>,
    /// Reset below in °C.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reset_below_c: Option<i64>,
    /// Rotations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rotations: Option<OneOrMany<f64>>,
    /// Run min.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub run_min: Option<i64>,
    /// Scale.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale: Option<f64>,
    /// Set above in °C.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub set_above_c: Option<i64>,
    /// Time stamp value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stamp: Option<i64>,
    /// Start max.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_max: Option<i64>,
    /// Start min.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start_min: Option<i64>,
    /// Steps.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps: Option<i64>,
    /// Steps per revolution.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps_per_revolution: Option<i64>,
    /// Tacho in V.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tacho_v: Option<f64>,
    /// Threshold in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold_rpm: Option<f64>,
    /// Time in ms.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_ms: Option<Number>,
    /// Time in s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time_s: Option<f64>,
    /// Tolerance.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<Number>,
    /// Upper limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_limit: Option<i64>,
    /// Upper mapping end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_mapping_end: Option<i64>,
    /// Vout in V.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vout_v: Option<f64>,
}

/// Inputs of a PKW command (`kind = "pkw"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PkwInput {
    /// PKW AK field.
    pub ak: i64,
    /// The PKW part in hex.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bytes: Option<String>,
    /// PKW IND field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ind: Option<i64>,
    /// PKW PNU field.
    pub pnu: i64,
    /// PKW PWE field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pwe: Option<i64>,
    /// Parameter values by parameter id before the exchange.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub state: Option<BTreeMap<String, IntOrText>>,
}

/// Expected outputs of a PKW command (`kind = "pkw"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PkwExpect {
    /// PKW AK field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ak: Option<i64>,
    /// The PKW part in hex.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bytes: Option<String>,
    /// PKW IND field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ind: Option<i64>,
    /// PKW PNU field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pnu: Option<i64>,
    /// PKW PWE field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pwe: Option<i64>,
    /// Parameter values by parameter id after the exchange.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub state: Option<BTreeMap<String, i64>>,
    /// Expected text value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub text: Option<String>,
    /// Expected value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<i64>,
}

/// Inputs of a process image (`kind = "process-image"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessImageInput {
    /// Actual position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub actual: Option<i64>,
    /// Byte order of the image (`big` or `little`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub byte_order: Option<String>,
    /// The image in hex.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bytes: Option<String>,
    /// Control word (PSD4xx process image).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control: Option<i64>,
    /// Control word (PSx3xx process image).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control_word: Option<i64>,
    /// `in` (device to master) or `out`.
    pub direction: String,
    /// Process-data format (ISDU 116).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub format: Option<i64>,
    /// PKE word of the PKW part.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pke: Option<i64>,
    /// PKW PWE field.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pwe: Option<i64>,
    /// Speed in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rpm: Option<i64>,
    /// Speed value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed: Option<i64>,
    /// Time stamp value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stamp: Option<i64>,
    /// Status word.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub status: Option<i64>,
    /// Target position in increments.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<i64>,
    /// Target speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_speed: Option<i64>,
}

/// Expected outputs of a process image (`kind = "process-image"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessImageExpect {
    /// Actual position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub actual: Option<i64>,
    /// The image in hex.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bytes: Option<String>,
    /// Control word (PSD4xx process image).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control: Option<i64>,
    /// Control word (PSx3xx process image).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub control_word: Option<i64>,
    /// Speed in rpm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rpm: Option<i64>,
    /// Speed value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed: Option<i64>,
    /// Time stamp value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stamp: Option<i64>,
    /// Status word.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub status: Option<i64>,
    /// Target position in increments.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<i64>,
    /// Target speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target_speed: Option<i64>,
}

/// Inputs of an acyclic record access (`kind = "record"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordInput {
    /// Record data in hex.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<String>,
    /// Record or ISDU index.
    pub index: i64,
    /// `read` or `write`.
    pub op: String,
    /// Parameter values by parameter id before the exchange.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub state: Option<BTreeMap<String, IntOrText>>,
}

/// Expected outputs of an acyclic record access (`kind = "record"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordExpect {
    /// Record data in hex.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<String>,
    /// Parameter values by parameter id after the exchange.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub state: Option<BTreeMap<String, i64>>,
    /// Expected text value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub text: Option<String>,
}

/// Inputs of an ISDU request (`kind = "isdu"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsduInput {
    /// Data bytes in hex.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<String>,
    /// Record or ISDU index.
    pub index: i64,
    /// `read` or `write`.
    pub op: String,
    /// Parameter values by parameter id before the exchange.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub state: Option<BTreeMap<String, i64>>,
    /// ISDU subindex (0 when absent).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub subindex: Option<i64>,
}

/// Expected outputs of an ISDU request (`kind = "isdu"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsduExpect {
    /// Active format before reset.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub active_format_before_reset: Option<i64>,
    /// Command.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub command: Option<String>,
    /// Data bytes in hex.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub data: Option<String>,
    /// Error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<i64>,
    /// Error alternatives.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error_alternatives: Option<Vec<i64>>,
    /// Final actual.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub final_actual: Option<i64>,
    /// Moves.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moves: Option<bool>,
    /// Readback.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub readback: Option<i64>,
    /// Readback within in ms.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub readback_within_ms: Option<i64>,
    /// Saved.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub saved: Option<BTreeMap<String, i64>>,
    /// Parameter values by parameter id after the exchange.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub state: Option<BTreeMap<String, i64>>,
    /// Expected value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<i64>,
}

/// Inputs of a time stamp (`kind = "timestamp"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimestampInput {
    /// Time stamp value.
    pub stamp: i64,
}

/// Expected outputs of a time stamp (`kind = "timestamp"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TimestampExpect {
    /// Delay the stamp stands for, in µs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delay_us: Option<i64>,
    /// Whether the stamp means "at once".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub immediate: Option<bool>,
    /// Whether the stamp means "no time stamp".
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inactive: Option<bool>,
    /// Whether the stamp is valid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub valid: Option<bool>,
}

/// Inputs of position arithmetic (`kind = "position"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositionInput {
    /// Actual position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub actual: Option<i64>,
    /// Denominator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub denominator: Option<i64>,
    /// Denominator before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub denominator_before: Option<i64>,
    /// Direction of travel (`up`/`down` or a code).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction: Option<IntOrText>,
    /// Direction before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub direction_before: Option<i64>,
    /// Down revolutions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub down_revolutions: Option<i64>,
    /// Last move.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub last_move: Option<String>,
    /// Loop direction.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loop_direction: Option<i64>,
    /// Loop length.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loop_length: Option<i64>,
    /// Lower limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower_limit: Option<i64>,
    /// Mapping end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mapping_end: Option<i64>,
    /// No loop.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub no_loop: Option<bool>,
    /// Numerator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub numerator: Option<i64>,
    /// Pitch in µm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch_um: Option<i64>,
    /// Position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<i64>,
    /// Range.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<String>,
    /// Reference.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<i64>,
    /// Reference before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference_before: Option<i64>,
    /// Resolution in µm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resolution_um: Option<i64>,
    /// Target position in increments.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<i64>,
    /// Up revolutions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up_revolutions: Option<i64>,
    /// Upper limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_limit: Option<i64>,
    /// Upper mapping end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_mapping_end: Option<i64>,
    /// Upper mapping end before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_mapping_end_before: Option<i64>,
    /// Window.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window: Option<i64>,
    /// Write actual.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub write_actual: Option<i64>,
}

/// Expected outputs of position arithmetic (`kind = "position"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PositionExpect {
    /// Accepted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub accepted: Option<bool>,
    /// Actual position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub actual: Option<i64>,
    /// Delivery mapping end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delivery_mapping_end: Option<i64>,
    /// Denominator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub denominator: Option<i64>,
    /// Increments per rotation.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub increments_per_rotation: Option<i64>,
    /// Legs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub legs: Option<Vec<i64>>,
    /// Loop length.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loop_length: Option<i64>,
    /// Lower limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower_limit: Option<i64>,
    /// Lower offset.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower_offset: Option<i64>,
    /// Lower position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower_position: Option<i64>,
    /// Mapping end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mapping_end: Option<i64>,
    /// Mapping end max.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mapping_end_max: Option<i64>,
    /// Mapping end min.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mapping_end_min: Option<i64>,
    /// Mapping end rotations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mapping_end_rotations: Option<i64>,
    /// Mapping end rotations above actual.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mapping_end_rotations_above_actual: Option<i64>,
    /// Numerator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub numerator: Option<i64>,
    /// Range rotations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range_rotations: Option<i64>,
    /// Reference.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reference: Option<i64>,
    /// Status set.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub status_set: Option<Vec<i64>>,
    /// Steps per revolution.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steps_per_revolution: Option<i64>,
    /// Target position in increments.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub target: Option<i64>,
    /// Travel down.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub travel_down: Option<i64>,
    /// Travel down rotations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub travel_down_rotations: Option<i64>,
    /// Travel up.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub travel_up: Option<i64>,
    /// Travel up rotations.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub travel_up_rotations: Option<i64>,
    /// Ume max.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ume_max: Option<i64>,
    /// Ume min.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ume_min: Option<i64>,
    /// Upper limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_limit: Option<i64>,
    /// Upper mapping end.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_mapping_end: Option<i64>,
    /// Upper margin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_margin: Option<i64>,
    /// Upper position.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper_position: Option<i64>,
    /// Valid target.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub valid_target: Option<bool>,
    /// Window.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub window: Option<i64>,
}

/// Inputs of a Direct Parameter page (`kind = "direct-parameter"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectParameterInput {
    /// Direct Parameter page 1 in hex.
    pub bytes: String,
    /// Direct Parameter address of the first byte.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub first_address: Option<i64>,
}

/// Expected outputs of a Direct Parameter page (`kind = "direct-parameter"`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DirectParameterExpect {
    /// Device id.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub device_id: Option<i64>,
    /// Isdu.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub isdu: Option<bool>,
    /// Min cycle time in µs.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min_cycle_time_us: Option<i64>,
    /// Model code.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_code: Option<i64>,
    /// Operate code.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub operate_code: Option<i64>,
    /// Operate od octets.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub operate_od_octets: Option<i64>,
    /// Operate type.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub operate_type: Option<String>,
    /// Pd in octets.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pd_in_octets: Option<i64>,
    /// Pd out bits.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pd_out_bits: Option<i64>,
    /// Pd out format.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pd_out_format: Option<i64>,
    /// Pd out octets.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pd_out_octets: Option<i64>,
    /// Preoperate code.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preoperate_code: Option<i64>,
    /// Preoperate od octets.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preoperate_od_octets: Option<i64>,
    /// Preoperate type.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub preoperate_type: Option<String>,
    /// Revision major.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub revision_major: Option<i64>,
    /// Revision minor.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub revision_minor: Option<i64>,
    /// Vendor id.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vendor_id: Option<i64>,
}
