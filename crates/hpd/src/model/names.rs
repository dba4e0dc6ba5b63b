//! The names by which the model finds its rules in the spec: bit-rule triggers (bits.toml)
//! and the erratum options and readings it follows (errata-*.toml).

/// Bit-rule trigger of command bits the drive executes (bits.toml).
pub(super) const TRIGGER_COMMAND: &str = "command-executed";
/// Bit-rule trigger of bits cleared at power-up (bits.toml).
pub(super) const TRIGGER_POWER_ON: &str = "power-on";
/// Bit-rule trigger that clears the drive-healthy bit (bits.toml, b41.4).
pub(super) const TRIGGER_ALARM_RAISED: &str = "alarm-raised";
/// Bit-rule trigger that sets the hardware enable status bit (bits.toml, b41.5).
pub(super) const TRIGGER_HARDWARE_ENABLE: &str = "hardware-enable-on";
/// Bit-rule trigger that sets the drive enabled bit (bits.toml, b41.12).
pub(super) const TRIGGER_DRIVE_ENABLED: &str = "drive-enabled";

/// Erratum option: do command bits clear themselves (HPD-ERRATUM-012).
pub(super) const OPTION_SELF_CLEAR: &str = "command-self-clear";
/// Reading of `OPTION_SELF_CLEAR` where command bits stay 1.
pub(super) const READING_LATCHED: &str = "latched";
/// Erratum option: is b99.14 refused on checksum alarms (HPD-ERRATUM-013).
pub(super) const OPTION_PLC_SAVE: &str = "b99-14-checksum";
/// Reading of `OPTION_PLC_SAVE` where b99.14 is refused like b99.15.
pub(super) const READING_BOTH: &str = "both";
/// Erratum option: does security b99.7 cover serial writes (HPD-ERRATUM-011).
pub(super) const OPTION_SECURITY: &str = "b99-7-scope";
/// Reading of `OPTION_SECURITY` where only the keypad is locked.
pub(super) const READING_KEYPAD_ONLY: &str = "keypad-only";
/// Erratum option: the range of Pr31 (HPD-ERRATUM-014).
pub(super) const OPTION_MODE_RANGE: &str = "pr31-range";
/// Reading of `OPTION_MODE_RANGE` where any byte is accepted.
pub(super) const READING_ANY_BYTE: &str = "byte";
/// Erratum option: is a refused write acknowledged (HPD-ERRATUM-069).
pub(super) const OPTION_REFUSED_WRITE: &str = "refused-write";
/// Reading of `OPTION_REFUSED_WRITE` where a refused write is not answered.
pub(super) const READING_SILENT: &str = "silent";

/// The appendix F task the motor and the operating modes run in (`protocol.task_slots`).
pub(super) const TASK_SLOW_MODE: &str = "slow operating mode";
/// Operating mode 8, maintenance and commissioning (manual 3.6.3).
pub(super) const MODE_MAINTENANCE: u32 = 8;
/// Operating mode 9, positioner (manual 3.6.4).
pub(super) const MODE_POSITIONER: u32 = 9;
/// Operating mode 10, digital locking (manual 3.6.5).
pub(super) const MODE_LOCKING: u32 = 10;
/// Operating mode 12, spindle orientation (manual 3.6.7).
pub(super) const MODE_ORIENTATION: u32 = 12;
/// The modes with a position loop, Pr60:61 and Pr62:63 (manual 3.6.4–3.6.6).
pub(super) const POSITION_MODES: [u32; 3] = [9, 10, 11];
/// b40.2: the operating mode's reference Pr6 drives the speed loop (manual 3.3).
pub(super) const B40_RESERVED: u8 = 2;
/// b40.3: reference freeze (manual 3.3).
pub(super) const B40_FREEZE: u8 = 3;
/// b40.4: left-hand stroke end (manual 3.3).
pub(super) const B40_LEFT_END: u8 = 4;
/// b40.5: right-hand stroke end (manual 3.3).
pub(super) const B40_RIGHT_END: u8 = 5;
/// b40.6: stop function (manual 3.3).
pub(super) const B40_STOP: u8 = 6;
/// b40.7: absolute speed window (manual 3.3).
pub(super) const B40_ABSOLUTE_WINDOW: u8 = 7;
/// b40.12: digital reference (manual 3.3).
pub(super) const B40_DIGITAL: u8 = 12;
/// b40.13: frequency input instead of Pr5 (manual 3.3).
pub(super) const B40_FREQUENCY: u8 = 13;
/// b70.0 in mode 8: start the test profile (manual 3.6.3).
pub(super) const B70_TEST_PROFILE: u8 = 0;
/// b70.1 in mode 8: jog forward (manual 3.6.3).
pub(super) const B70_JOG_FORWARD: u8 = 1;
/// b70.2 in mode 8: jog in reverse (manual 3.6.3).
pub(super) const B70_JOG_REVERSE: u8 = 2;
/// b70.3 in mode 8: wiring test (manual 3.6.3).
pub(super) const B70_WIRING_TEST: u8 = 3;
/// b70.4 in mode 9: direction of the next profile (manual 3.6.4).
pub(super) const B70_DIRECTION: u8 = 4;
/// b70.5 in modes 9–12: servo error (manual 3.6.4–3.6.7).
pub(super) const B70_SERVO_ERROR: u8 = 5;
/// b70.7 in mode 9: profile in execution (manual 3.6.4).
pub(super) const B70_BUSY: u8 = 7;
/// b70.8 in mode 9: start profile; in modes 10 and 11: axis lock (manual 3.6.4–3.6.6).
pub(super) const B70_START: u8 = 8;
/// Pr53 in mode 8: the test profile starts with Pr52 / 2 revolutions at positive speed
/// (manual 3.6.3).
pub(super) const START_HALF_FORWARD: i64 = 2;
/// Pr53 in mode 8: the test profile starts with Pr52 revolutions at negative speed (manual
/// 3.6.3).
pub(super) const START_REVERSE: i64 = 3;
/// Wiring test code 1: b40.9 = 1 or the drive disabled through the hardware (manual 3.6.3).
pub(super) const WIRING_DISABLED: i64 = 1;
/// Mode-9 position commands by bit of Pb70 (manual 3.6.4 b70.2, b70.10–b70.12).
pub(super) const POSITION_COMMAND_BITS: [u8; 4] = [2, 10, 11, 12];
