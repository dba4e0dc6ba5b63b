//! The family description the positioning core runs on (PSD4xx manual chapter 4; PSx3xx
//! chapters 4–5): the numbers of the position arithmetic, the status bit map and the readings
//! of the manuals' contradictions. A family crate builds it from the spec; nothing here names a
//! parameter number.

use crate::axis::AxisConfig;
use crate::status::BitMap;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// How a stop brakes (PSD4xx 4.3, erratum PSD-ERRATUM-058).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Ramp {
    /// With the deceleration parameter (PSD par. 59).
    Parameter,
    /// With the maximum possible deceleration (4.3).
    Maximum,
}

/// How far the drive backs off before a short final approach with lash present (PSD4xx 4.2.1
/// case 3; erratum PSD-ERRATUM-055).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Backoff {
    /// To target − loop length, so the final approach covers the loop length (4.2.1).
    LoopLength,
    /// A fixed fraction of a rotation back from the current position (4.2.1).
    FixedFromCurrent,
}

/// The reference loop rules (PSD4xx 4.1 notice, 4.2.1; PSx3xx 4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct LoopRules {
    /// The overshoot past a target behind the drive is |loop length| (true) or the fixed
    /// fraction of a rotation (false) (erratum PSD-ERRATUM-055).
    pub overshoot_is_loop_length: bool,
    /// A positive loop length approaches toward larger values (erratum PSD-ERRATUM-056).
    pub positive_approaches_up: bool,
    /// Back-off rule of case 3 (4.2.1).
    pub backoff: Backoff,
    /// The fixed fraction of a rotation, [numerator, denominator] (5/8) (4.2.1).
    pub fixed_rotations: [i64; 2],
    /// Positioning attempts in all: the run plus the automatic second positioning (2) (4.2.1).
    pub attempts: u32,
}

/// Motor supply limits in 0.1 V (PSD4xx 3.3 par. 90, 3.6 bits 4 and 13).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct VoltageRules {
    /// Fixed upper limit (300 = 30 V) (3.3 par. 90).
    pub upper: i64,
    /// Lowest voltage tolerated during a run (175 = 17.5 V); None: the UMot limit applies
    /// during runs too (erratum PSD-ERRATUM-020).
    pub run_minimum: Option<i64>,
}

/// Everything the core needs from a family (PSD4xx chapter 4).
#[derive(Debug, Clone, PartialEq)]
pub struct CoreConfig {
    /// Position arithmetic (4.7).
    pub axis: Arc<AxisConfig>,
    /// Flags to status bits, with priorities (3.6).
    pub bits: BitMap,
    /// A flag with priority suppresses the other (true) or both are shown (erratum
    /// PSD-ERRATUM-019).
    pub priority_exclusive: bool,
    /// Reference loop (4.2.1).
    pub loop_rules: LoopRules,
    /// Braking when the release is withdrawn (erratum PSD-ERRATUM-058).
    pub stop_ramp: Ramp,
    /// Braking on an invalid control combination, a lost motor voltage or a position fault
    /// (DECISION: the manual's "stop command" with the maximum ramp, 4.3).
    pub emergency_ramp: Ramp,
    /// The maximum possible deceleration in rpm/s (DECISION: the top of the deceleration
    /// parameter's range for the model) (4.3).
    pub max_deceleration: f64,
    /// Motor supply limits (chapter 4).
    pub voltage: VoltageRules,
    /// Over-temperature resets this many °C below the limit (5) (3.6 bit 7).
    pub temperature_hysteresis: i64,
    /// Withdrawing the release during a manual run sets the aborted flag too (erratum
    /// PSD-ERRATUM-018).
    pub aborted_on_manual_stop: bool,
    /// The manual-rotation flag is set also when a readjustment follows (erratum
    /// PSD-ERRATUM-022).
    pub manual_rotation_always: bool,
    /// Both manual-run bits together are an invalid combination (erratum PSD-ERRATUM-021).
    pub both_manual_invalid: bool,
    /// Readjustment works in both directions when the loop length is 0 (4.6).
    pub adjust_both_without_loop: bool,
    /// Virtual time step of the physics in µs (DECISION: 1 ms) (chapter 4).
    pub tick_us: u64,
    /// Blend distance of the harmonious end as a fraction of the braking distance from the
    /// maximum speed (DECISION: 0.5; 4.3 gives no number).
    pub blend: f64,
    /// Shaft position at the first power-up, base increments (PSD 0, PSx 51,200) (4.7).
    pub start_position: i64,
}
