//! How a PSx3xx model drive is built: the gearbox model, the erratum readings it follows, its
//! identity, its options (brake, jog keys) and where its shaft stands (manual 3.1, 3.2,
//! 5.10–5.13).

use drivespec_positioner::Environment;
use drivespec_spec::Readings;
use serde::Serialize;

/// The brake option of a drive (manual 5.12, 5.13; spec `[[protocol.brake]]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum BrakeKind {
    /// Snap brake of PSx30x-14, PSx31x-14, PSx32x, PSx33x (5.12).
    Snap,
    /// Holding brake of PSE34xx (5.13).
    Holding,
}

impl BrakeKind {
    /// Every brake option (5.11–5.13).
    pub const ALL: [BrakeKind; 2] = [BrakeKind::Snap, BrakeKind::Holding];

    /// The brake whose spec `kind` is `name` (case-insensitive), None for another name.
    pub fn from_spec_name(name: &str) -> Option<BrakeKind> {
        BrakeKind::ALL
            .into_iter()
            .find(|k| k.spec_name().eq_ignore_ascii_case(name.trim()))
    }

    /// The spec's `kind` of the brake (5.11–5.13).
    pub fn spec_name(self) -> &'static str {
        match self {
            BrakeKind::Snap => "snap",
            BrakeKind::Holding => "holding",
        }
    }
}

/// How to build a model drive (manual 3.2 model table; spec `[[erratum]]` options).
#[derive(Debug, Clone)]
pub struct DriveConfig {
    /// The gearbox model, matched forgivingly (`PSE312-8`, `pse 335-14`) (3.2).
    pub model: String,
    /// The erratum readings in force, adopted ones unless chosen (e.g. PSX-ERRATUM-004).
    pub readings: Readings,
    /// Shaft position at the first power-up in steps at the delivery scaling; None: the
    /// spec's delivery position (5.5: 51200).
    pub start_position: Option<i64>,
    /// The IO-Link master is in OPERATE from power-up on (4.1); false: the bus is not
    /// connected until [`LinkEvent::Connected`](super::LinkEvent::Connected) (5.10 table).
    pub connected: bool,
    /// The environment at power-up (supplies, temperature, load).
    pub environment: Environment,
    /// ISDU 80: software version; None: the first version with format 2 (1.6: 249).
    pub software_version: Option<u16>,
    /// ISDU 79 override; None: the model's code (3.1 ISDU 79).
    pub model_code: Option<u16>,
    /// ISDU 77: production date YYWW (3.1).
    pub production_date: u16,
    /// ISDU 78: serial number; ISDU 21 shows it with 5 digits (3.1).
    pub serial_number: u16,
    /// ISDU 22: hardware version string (3.1, e.g. "V1.0").
    pub hardware_version: String,
    /// ISDU 23: firmware version string (3.1, e.g. "V1.0").
    pub firmware_version: String,
    /// The brake option, None without brake (5.12, 5.13).
    pub brake: Option<BrakeKind>,
    /// The jog keys option is fitted (5.10); the jog bits 8/9 work without it.
    pub jog_keys: bool,
}

impl DriveConfig {
    /// A connected drive of `model` with the adopted readings, delivery values, no brake and
    /// the jog keys option (3.2).
    pub fn new(model: &str) -> DriveConfig {
        DriveConfig {
            model: model.to_owned(),
            readings: Readings::default(),
            start_position: None,
            connected: true,
            environment: Environment::default(),
            software_version: None,
            model_code: None,
            production_date: 0,
            serial_number: 0,
            hardware_version: "V1.0".to_owned(),
            firmware_version: "V1.0".to_owned(),
            brake: None,
            jog_keys: true,
        }
    }

    /// The same drive with other erratum readings (spec `[[erratum]]` options).
    pub fn with_readings(mut self, readings: Readings) -> DriveConfig {
        self.readings = readings;
        self
    }

    /// The same drive with its shaft at `position` steps at power-up (5.5).
    pub fn with_start_position(mut self, position: i64) -> DriveConfig {
        self.start_position = Some(position);
        self
    }

    /// The same drive with a brake option (5.12, 5.13).
    pub fn with_brake(mut self, brake: BrakeKind) -> DriveConfig {
        self.brake = Some(brake);
        self
    }

    /// The same drive with another software version (1.6, ISDU 80).
    pub fn with_software(mut self, version: u16) -> DriveConfig {
        self.software_version = Some(version);
        self
    }
}
