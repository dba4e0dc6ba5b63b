//! The steps of an HPD case: an HPD [`Action`] with its role, text and requirements.

use drivespec_hpd::memory::Slot;
pub use drivespec_hpd::step::{Compare, Step as Action};

/// One step of a case.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Step {
    /// Setup, check or cleanup.
    pub role: crate::case::Role,
    /// What to do.
    pub action: Action,
    /// The answer a golden vector gives to an exchange (None: not from a vector;
    /// Some(empty): silence).
    pub golden: Option<Vec<u8>>,
    /// One line.
    pub text: String,
    /// Requirements this step exercises.
    pub requirements: Vec<String>,
}

/// An HPD case: the generic description plus the steps.
#[derive(Debug, Clone)]
pub struct HpdCase {
    /// The steps, setup first, cleanup last.
    pub steps: Vec<Step>,
    /// Needs the transport to power-cycle the device.
    pub needs_power_cycle: bool,
    /// Parameter slots the case may change (resynchronised after a failure).
    pub touched: Vec<Slot>,
    /// The requirements the case itself checks, in the order declared: a value that differs
    /// breaks the first of them that is not a rule of the message form.
    pub checks: Vec<String>,
}
