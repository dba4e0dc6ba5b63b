//! How a PSD4xx model drive is built: the device model, the erratum readings it follows, its
//! identity and where its shaft stands (manual 3.3, 3.4, 2.1).

use drivespec_positioner::Environment;
use drivespec_spec::Readings;

/// How to build a model drive (manual 3.4 model table; spec `[[erratum]]` options).
#[derive(Debug, Clone)]
pub struct DriveConfig {
    /// The device model, matched forgivingly (`PSD426`, `psd 426/436-14h`) (3.4).
    pub model: String,
    /// The erratum readings in force, adopted ones unless chosen (e.g. PSD-ERRATUM-018).
    pub readings: Readings,
    /// Shaft position at the first power-up, increments at the delivery scaling; None: the
    /// spec's delivery position (4.7: position 0).
    pub start_position: Option<i64>,
    /// The controller is connected from power-up on (3.9); false: outputs are 0 until
    /// [`LinkEvent::Connected`](super::LinkEvent::Connected).
    pub connected: bool,
    /// Time without an output image after which the connection counts as lost (4.9); None:
    /// only an explicit [`LinkEvent::Lost`](super::LinkEvent::Lost) (the manual gives no value).
    pub watchdog_us: Option<u64>,
    /// The environment at power-up (3.4).
    pub environment: Environment,
    /// Par. 9: setting of the address switches (2.1).
    pub address_switch: u16,
    /// Par. 10: production date YYWW (3.3).
    pub production_date: u16,
    /// Par. 11: serial number (3.3).
    pub serial_number: u16,
    /// Par. 12: device model as a number (3.3; its encoding is not given, PSD-ERRATUM-004).
    pub model_number: u16,
    /// Par. 13: device model string; None: the model's id with "-PN-x", after the manual's
    /// example "PSD422-PN-x" (3.3).
    pub model_string: Option<String>,
    /// Par. 14: software version (3.3).
    pub version: u32,
    /// PROFINET station name (2.1; par. 96 = -3 deletes it).
    pub station_name: String,
}

impl DriveConfig {
    /// A connected drive of `model` with the adopted readings and delivery values (3.4).
    pub fn new(model: &str) -> DriveConfig {
        DriveConfig {
            model: model.to_owned(),
            readings: Readings::default(),
            start_position: None,
            connected: true,
            watchdog_us: None,
            environment: Environment::default(),
            address_switch: 0,
            production_date: 0,
            serial_number: 0,
            model_number: 0,
            model_string: None,
            version: 0,
            station_name: String::new(),
        }
    }

    /// The same drive with other erratum readings (spec `[[erratum]]` options) (3.4).
    pub fn with_readings(mut self, readings: Readings) -> DriveConfig {
        self.readings = readings;
        self
    }

    /// The same drive with its shaft at `position` increments at power-up (4.7).
    pub fn with_start_position(mut self, position: i64) -> DriveConfig {
        self.start_position = Some(position);
        self
    }
}
