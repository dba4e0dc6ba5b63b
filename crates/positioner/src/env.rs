//! The environment of a model drive as an explicit input (PSD4xx manual 3.3 par. 6–8, 3.6
//! bits 4, 7, 13, 4.5, 4.6, 4.10; PSx3xx 5.3, 5.4): supply voltages, device temperature,
//! obstructions and load torque, external rotation of the shaft, and faults.
//!
//! Tests and conformance cases change the environment at virtual times to inject what a real
//! drive meets on a machine. Voltages are raw 0.1 V, temperatures °C, torques cNm, positions
//! and distances user increments at the moment of the change.

use serde::{Deserialize, Serialize};

/// A change of the environment (PSD4xx 3.3, 3.6, 4.5, 4.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum EnvChange {
    /// Motor supply voltage in 0.1 V (par. 7; status bits 4 and 13).
    MotorVoltage {
        /// Raw 0.1 V.
        dv: u16,
    },
    /// Control supply voltage in 0.1 V (par. 6); 0 switches the device off, a later non-zero
    /// value switches it on again.
    ControlVoltage {
        /// Raw 0.1 V.
        dv: u16,
    },
    /// Device temperature in °C (par. 8; status bit 7).
    Temperature {
        /// °C.
        celsius: i16,
    },
    /// Extra load torque on the shaft in cNm: a run whose torque limit (par. 63/64) is lower
    /// stalls (4.4, 4.5).
    LoadTorque {
        /// cNm.
        cnm: u16,
    },
    /// The shaft is jammed (true) or free again (false): no rotation in either direction (4.5).
    Jam {
        /// Jammed.
        on: bool,
    },
    /// A hard block at a position; the drive cannot pass it from the side it is on now (4.10).
    Block {
        /// Position of the block, user increments.
        at: i64,
    },
    /// Removes every block (4.10 step 5).
    ClearBlocks,
    /// The shaft is turned externally by a distance at once (4.6 manual displacement).
    Displace {
        /// User increments, signed toward larger values.
        by: i64,
    },
    /// The shaft is turned externally at a constant speed while the motor is not driving it
    /// (4.6 "continually loses its position"; 4.11 back-driving); 0 stops it.
    BackDrive {
        /// rpm, signed toward larger values.
        rpm: i32,
    },
    /// The next arrival of a positioning run lands this many increments short of the target,
    /// as lost motor steps would (4.2.1 second positioning); each change arms one arrival.
    MissSteps {
        /// Increments short of the target, against the approach direction.
        by: i64,
    },
    /// An internal problem in the position calculation (3.6 bit 9).
    PositionFault,
}

/// A one-sided block (PSD4xx 4.10): the shaft cannot go above `at` (`upper`) or below it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Wall {
    /// Position of the block in rotations (4.10).
    pub at: f64,
    /// The block is above the shaft: it stops motion toward larger values (4.10).
    pub upper: bool,
}

/// The environment in force (PSD4xx 3.3 par. 6–8).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Environment {
    /// Motor supply voltage, 0.1 V.
    pub motor_dv: u16,
    /// Control supply voltage, 0.1 V.
    pub control_dv: u16,
    /// Device temperature, °C (3.3 par. 8).
    pub celsius: i16,
    /// Extra load torque, cNm (4.4).
    pub load_cnm: u16,
    /// The shaft is jammed (4.5).
    pub jammed: bool,
    /// Hard blocks (4.10).
    pub walls: Vec<Wall>,
    /// External rotation at standstill, rpm toward larger values (4.6).
    pub back_drive_rpm: i32,
    /// Armed step losses for the next arrivals, increments (4.2.1).
    pub missed: Vec<i64>,
}

impl Default for Environment {
    /// 24 V motor and control supply, 25 °C, no load, free shaft (DECISION: the manual gives
    /// no nominal values; 24 V lies inside the par. 90 window 18–24 V… 30 V).
    fn default() -> Environment {
        Environment {
            motor_dv: 240,
            control_dv: 240,
            celsius: 25,
            load_cnm: 0,
            jammed: false,
            walls: Vec::new(),
            back_drive_rpm: 0,
            missed: Vec::new(),
        }
    }
}

/// Most blocks and armed step losses kept at once, further ones dropped (4.10, 4.2.1).
pub const MAX_ENV_ENTRIES: usize = 16;
