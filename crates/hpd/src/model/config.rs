//! How a model drive starts: factory state or commissioned for the serial line (manual 4.1,
//! "serial line initialisation"), and the erratum readings it follows.

use super::motor::MotionStyle;
use drivespec_spec::Readings;

/// The state a model drive is in when it is first powered (manual 4.1, 3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Start {
    /// As delivered (manual 4.1): factory defaults, serial line disabled (b40.14 = 0).
    Factory,
    /// Commissioned as manual 4.1 describes (Pr26, Pr27, b40.14 = 1, b42.3, b99.15) and powered
    /// up again: the line answers at `address` with baud-rate code `baud_code`.
    Commissioned {
        /// Pr26 code; `None` keeps the spec's default (3.3 Pr26).
        baud_code: Option<u8>,
        /// Pr27 serial address (manual 4).
        address: u8,
    },
}

impl Default for Start {
    /// Commissioned at address 0 with the default Pr26 code (manual 4.1).
    fn default() -> Start {
        Start::Commissioned {
            baud_code: None,
            address: 0,
        }
    }
}

/// How to build a model drive (manual 4.1 set-up; erratum readings of the spec).
#[derive(Debug, Clone, Default)]
pub struct DriveConfig {
    /// Factory or commissioned state (manual 4.1).
    pub start: Start,
    /// The erratum readings in force, adopted ones unless chosen (e.g. HPD-ERRATUM-012, 3.4).
    pub readings: Readings,
    /// How the motor uses the freedom the manual leaves (3.3 ramps, 3.6.4 start).
    pub motion: MotionStyle,
}

impl DriveConfig {
    /// Factory state as delivered, serial line disabled (manual 4.1, b40.14 = 0).
    pub fn factory() -> DriveConfig {
        DriveConfig {
            start: Start::Factory,
            readings: Readings::default(),
            motion: MotionStyle::default(),
        }
    }

    /// Commissioned at `address` with the default baud-rate code (manual 4.1).
    pub fn commissioned(address: u8) -> DriveConfig {
        DriveConfig {
            start: Start::Commissioned {
                baud_code: None,
                address,
            },
            readings: Readings::default(),
            motion: MotionStyle::default(),
        }
    }

    /// Commissioned at `address` with Pr26 = `baud_code` (manual 4 table).
    pub fn commissioned_at(baud_code: u8, address: u8) -> DriveConfig {
        DriveConfig {
            start: Start::Commissioned {
                baud_code: Some(baud_code),
                address,
            },
            readings: Readings::default(),
            motion: MotionStyle::default(),
        }
    }

    /// The same start with another motion style (manual 3.3, 3.6.4).
    pub fn with_motion(mut self, motion: MotionStyle) -> DriveConfig {
        self.motion = motion;
        self
    }

    /// The same start with other erratum readings (spec `[[erratum]]` options).
    pub fn with_readings(mut self, readings: Readings) -> DriveConfig {
        self.readings = readings;
        self
    }
}
