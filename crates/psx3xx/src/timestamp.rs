//! Time stamps of process output format 0 (manual 3.3.1, 4.4): what a stamp value means.
//!
//! All numbers come from `protocol.timestamp` of the spec: the 4 µs unit, the inactive marker
//! 0x3FFF, the largest valid stamp 16368 and the threshold 2000 below which a stamp executes
//! on reception (PSX-ERRATUM-052). Values between the largest valid stamp and the inactive
//! marker are reported as reserved (PSX-ERRATUM-061).

use drivespec_spec::psx3xx::Timestamp;
use serde::{Deserialize, Serialize};
use std::fmt;

/// A time-stamp value: delay in units of `protocol.timestamp.unit_us` (manual 3.3.1).
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize,
)]
#[serde(transparent)]
pub struct Stamp(pub u16);

impl Stamp {
    /// The inactive marker of the spec, "no new time stamp" (manual 3.3.1).
    pub fn inactive(ts: &Timestamp) -> Stamp {
        Stamp(u16::try_from(ts.inactive).unwrap_or(u16::MAX))
    }

    /// The stamp for a delay, rounded down to the time base; None beyond the largest valid
    /// stamp (manual 3.3.1: stamp = delay / 4 µs, at most 16368).
    pub fn from_delay_us(ts: &Timestamp, delay_us: u32) -> Option<Stamp> {
        let stamp = delay_us.checked_div(ts.unit_us)?;
        if stamp > ts.max_valid {
            return None;
        }
        u16::try_from(stamp).ok().map(Stamp)
    }

    /// What the value means under the spec's rules (manual 3.3.1).
    pub fn meaning(self, ts: &Timestamp) -> StampMeaning {
        StampMeaning::of(ts, u32::from(self.0))
    }
}

impl fmt::Display for Stamp {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// The meaning of a stamp value (manual 3.3.1, 4.4; PSX-ERRATUM-052, PSX-ERRATUM-061).
///
/// JSON: `{"kind": "inactive" | "immediate" | "delayed" | "reserved", "delay_us"?: n}`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum StampMeaning {
    /// The inactive marker: no new stamp; a pending stamp fires (manual 3.3.1).
    Inactive,
    /// A valid stamp below the immediate threshold: executes on reception (manual 3.3.1).
    Immediate {
        /// Delay the value encodes, µs.
        delay_us: u32,
    },
    /// A valid stamp: executes this long after its reception (manual 3.3.1, PSX-ERRATUM-064).
    Delayed {
        /// Delay, µs.
        delay_us: u32,
    },
    /// Neither a valid stamp nor the inactive marker; adopted: ignored (PSX-ERRATUM-061).
    Reserved,
}

impl StampMeaning {
    /// The meaning of `stamp` under the spec's time-stamp rules (manual 3.3.1).
    pub fn of(ts: &Timestamp, stamp: u32) -> StampMeaning {
        if stamp == ts.inactive {
            return StampMeaning::Inactive;
        }
        match ts.delay_us(stamp) {
            Some(delay_us) if ts.immediate(stamp) => StampMeaning::Immediate { delay_us },
            Some(delay_us) => StampMeaning::Delayed { delay_us },
            None => StampMeaning::Reserved,
        }
    }

    /// The delay of a valid stamp, µs (manual 3.3.1).
    pub fn delay_us(self) -> Option<u32> {
        match self {
            StampMeaning::Immediate { delay_us } | StampMeaning::Delayed { delay_us } => {
                Some(delay_us)
            }
            StampMeaning::Inactive | StampMeaning::Reserved => None,
        }
    }

    /// Whether the value is a valid stamp (manual 3.3.1: 0..=16368).
    pub fn is_valid(self) -> bool {
        self.delay_us().is_some()
    }

    /// Whether the value is the inactive marker (manual 3.3.1).
    pub fn is_inactive(self) -> bool {
        self == StampMeaning::Inactive
    }

    /// Whether the stamp executes on reception (manual 3.3.1).
    pub fn is_immediate(self) -> bool {
        matches!(self, StampMeaning::Immediate { .. })
    }
}

/// Microseconds as milliseconds with three decimals: `40000` → `40.000 ms`.
pub fn ms(us: u32) -> String {
    format!("{}.{:03} ms", us / 1000, us % 1000)
}

impl fmt::Display for StampMeaning {
    /// `executes in 40.000 ms`, `executes immediately (7.996 ms)`, `inactive`, `reserved`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            StampMeaning::Inactive => f.write_str("inactive (no new time stamp)"),
            StampMeaning::Immediate { delay_us } => {
                write!(
                    f,
                    "executes immediately ({} is below one cycle)",
                    ms(delay_us)
                )
            }
            StampMeaning::Delayed { delay_us } => write!(f, "executes in {}", ms(delay_us)),
            StampMeaning::Reserved => f.write_str("reserved value, not a time stamp (ignored)"),
        }
    }
}
