//! The steps of an HPD case: what goes on the line and how the device's answer is compared
//! with the reference model's.

use crate::link::Micros;
use drivespec_hpd::memory::Slot;

/// How an answer of the device is compared with the reference model's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Compare {
    /// Byte for byte, silence included.
    Exact,
    /// The same frames; data bits outside `mask` (little-endian over the data bytes) are
    /// not compared (values the drive changes by itself, manual 3.3 "live").
    Mask(u32),
    /// The same frame header; the data as a value within ± `tolerance` (timers counting).
    Near {
        /// Largest allowed difference of the raw values.
        tolerance: i64,
    },
}

/// What a step does.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Action {
    /// Sends `bytes` and compares what the device and the reference send back within the
    /// answer window (the Pr26 time-out in force, any answer delay, and slack).
    Exchange {
        bytes: Vec<u8>,
        compare: Compare,
        /// Silence is also accepted (a vector whose result is `acceptable`).
        silence_ok: bool,
        /// The answer a golden vector gives (None: not from a vector; Some(empty): silence).
        golden: Option<Vec<u8>>,
    },
    /// Sends bytes without waiting (the first part of a split frame).
    Send { bytes: Vec<u8> },
    /// Listens for `us` and compares what comes (normally: nothing).
    Listen { us: Micros },
    /// Listens past the message time-out in force plus slack.
    ListenTimeout,
    /// Listens half the message time-out in force.
    ListenHalfTimeout,
    /// Switches the device and the reference off and on.
    PowerCycle,
    /// Sets the transport's bit rate to the one the reference now uses (after b42.3).
    BitRate,
    /// Sets the digital inputs of the device and the reference (bit i = input i, manual
    /// 3.8.1 b90); only on transports that can (`Caps::inputs`).
    Inputs { value: u16 },
}

/// One step of a case.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Step {
    /// Setup, check or cleanup.
    pub(crate) role: crate::case::Role,
    /// What to do.
    pub(crate) action: Action,
    /// One line.
    pub(crate) text: String,
    /// Requirements this step exercises.
    pub(crate) requirements: Vec<String>,
}

/// An HPD case: the generic description plus the steps.
#[derive(Debug, Clone)]
pub(crate) struct HpdCase {
    /// The steps, setup first, cleanup last.
    pub(crate) steps: Vec<Step>,
    /// Needs the transport to power-cycle the device.
    pub(crate) needs_power_cycle: bool,
    /// Parameter slots the case may change (resynchronised after a failure).
    pub(crate) touched: Vec<Slot>,
}
