//! The delivery state of the reference drive (manual 2.1 notice, 3.3 par. 9, 92, 96).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_psd4xx::model::{Drive, DriveConfig};
use drivespec_spec::Spec;

/// PSD-START-010: delivered with the address switches at 0, EEPROM address (par. 92) 0 and
/// an empty device name; par. 96 = -3 brings the drive back to exactly that.
#[test]
fn delivery_state_has_address_0_and_no_name() {
    let spec = Spec::builtin().unwrap();
    let d = Drive::new(&spec, DriveConfig::new("PSD426")).unwrap();
    assert_eq!(d.parameter(9), Ok(0));
    assert_eq!(d.parameter(92), Ok(0));
    assert_eq!(d.saved_value(92), Some(0));
    assert_eq!(d.station_name(), "");

    let mut named = DriveConfig::new("PSD426");
    named.station_name = "psd-00007".to_owned();
    let mut d2 = Drive::new(&spec, named).unwrap();
    d2.write_parameter(0, 92, 7).unwrap();
    d2.write_parameter(0, 96, 1).unwrap();
    assert_eq!(d2.saved_value(92), Some(7));
    d2.write_parameter(1000, 96, -3).unwrap();
    assert_eq!(d2.parameter(92), Ok(0));
    assert_eq!(d2.saved_value(92), Some(0));
    assert_eq!(d2.station_name(), "");
}
