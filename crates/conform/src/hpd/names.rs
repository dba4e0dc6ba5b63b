//! Names of the bits and parameters the HPD cases act on that the spec's protocol tables do
//! not name (the same few the reference model names in `drivespec_hpd::model`). Addresses,
//! masks, ranges and defaults still come from the spec's parameter table.

/// Operating mode (manual 3.3 Pr31, 3.6).
pub const OPERATING_MODE: &str = "Pr31";
/// Extended menu, needed by b42.3 and b94.1 (manual 3.3 b99.6, 3.4).
pub const EXTENDED_MENU: &str = "b99.6";
/// Security (manual 3.3 b99.7).
pub const SECURITY: &str = "b99.7";
/// Reserved reference select, must be 0 for b99.11 (manual 3.3 b40.2, 3.4).
pub const RESERVED_REFERENCE: &str = "b40.2";
/// Alarm reset command (manual 3.4 b99.10).
pub const ALARM_RESET: &str = "b99.10";
/// Operating-mode defaults command (manual 3.4 b99.11).
pub const MODE_DEFAULTS: &str = "b99.11";
/// Active and last alarm (manual 3.3 Pr23, Pr24).
pub const ALARMS: [&str; 2] = ["Pr23", "Pr24"];
/// A saved word free for the user (manual 3.8.1 Pr80), the usual scratch parameter.
pub const SCRATCH: &str = "Pr80";
/// Its neighbour, the high word of the `SCRATCH` double word (manual 3.8.1 Pr81).
pub const SCRATCH_HIGH: &str = "Pr81";
/// A word parameter with a narrow range (manual 3.3 Pr33, raw 100..500).
pub const RANGED: &str = "Pr33";
/// A read-only, not live parameter (manual 3.3 Pr25, software version).
pub const READ_ONLY: &str = "Pr25";
/// A saved parameter with a delivery value (manual 3.3 Pr2).
pub const WITH_DEFAULT: &str = "Pr2";
/// The torque monitor, in % of the drive's peak (manual 3.3 Pr35).
pub const TORQUE_MONITOR: &str = "Pr35";
/// The current limit, in % of the drive's peak (manual 3.3 Pr19).
pub const PEAK_CURRENT: &str = "Pr19";
/// The hardware enable status bit (manual 3.3 b41.5).
pub const HARDWARE_ENABLE: &str = "b41.5";
/// The drive enabled bit (manual 3.3 b41.12).
pub const DRIVE_ENABLED: &str = "b41.12";
/// A user flag bit (manual 3.8.1 b90.8).
pub const USER_FLAG: &str = "b90.8";
/// Another saved user flag, kept by the parameter save (manual 3.8.1 b90.8..b90.15).
pub const SAVED_FLAG: &str = "b90.9";
/// Volatile user flags, 0 at power-up (manual 3.8.1 b91.8..b91.15).
pub const VOLATILE_FLAGS: [&str; 2] = ["b91.9", "b91.12"];
/// The double-word flag and two FIN disables, 0 at power-up (manual 3.8.1 b94.0, b94.5..b94.7).
pub const POWER_UP_CLEARED: [&str; 3] = ["b94.0", "b94.5", "b94.7"];

/// Bit-rule trigger of command bits (bits.toml).
pub const TRIGGER_COMMAND: &str = "command-executed";
/// Bit-rule trigger of the end of the wiring test (bits.toml b70.3): manual 3.6.3 gives the
/// test no duration, so a read right after the start may show b70.3 either way.
pub const TRIGGER_TEST_FINISHED: &str = "wiring-test-finished";
/// A delivery value the manual prints two ways (3.3 Pr15 default 20, 3.2 "±20 rpm",
/// HPD-ERRATUM-005): a read at the start shows one of them.
pub const TWO_WAY_DEFAULT: &str = "Pr15";
/// Stop function (manual 3.3 b40.6).
pub const STOP: &str = "b40.6";
/// Absolute speed window (manual 3.3 b40.7).
pub const ABSOLUTE_WINDOW: &str = "b40.7";
/// Software enable (manual 3.3 b40.9).
pub const SOFTWARE_ENABLE: &str = "b40.9";
/// Digital reference, Pr7 = Pr5 with b40.13 = 0 (manual 3.3 b40.12).
pub const DIGITAL_REFERENCE: &str = "b40.12";
/// The appendix F task that updates the speed windows (`protocol.task_slots`).
pub const TASK_SPEED_WINDOWS: &str = "speed windows manager";
/// The appendix F task the operating modes run in (`protocol.task_slots`).
pub const TASK_SLOW_MODE: &str = "slow operating mode";
/// Pr53 in mode 8, the test profile's starting points (manual 3.6.3): Pr52 revolutions at
/// positive speed, Pr52 / 2 at positive speed, Pr52 at negative speed.
pub const TEST_STARTS: [i64; 3] = [1, 2, 3];
