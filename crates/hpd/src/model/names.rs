//! The names by which the model finds its rules in the spec: bit-rule triggers (bits.toml)
//! and the erratum options and readings it follows (errata-*.toml).

/// Bit-rule trigger of command bits the drive executes (bits.toml).
pub(super) const TRIGGER_COMMAND: &str = "command-executed";
/// Bit-rule trigger of bits cleared at power-up (bits.toml).
pub(super) const TRIGGER_POWER_ON: &str = "power-on";
/// Bit-rule trigger that clears the drive-healthy bit (bits.toml, b41.4).
pub(super) const TRIGGER_ALARM_RAISED: &str = "alarm-raised";

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
