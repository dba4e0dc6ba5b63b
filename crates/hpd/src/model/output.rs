//! What a model drive gives back: line bytes, digital outputs, and read-only views of its state
//! (manual 4.1, 3.3, 3.8.1).

use crate::line::Micros;

/// Something the drive does towards the outside world (manual 4.1, 3.8.1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Output {
    /// Bytes the drive sends on the line (an answer or an IDC broadcast, manual 4.1, 3.8.2).
    Transmit {
        /// When the first byte goes out (virtual µs).
        at: Micros,
        /// The message as sent, stuffing included.
        bytes: Vec<u8>,
    },
    /// The digital outputs changed at the end of a PLC scan (manual 3.8.1, b91.0–b91.6).
    DigitalOutputs {
        /// Time of the scan (virtual µs).
        at: Micros,
        /// Bit j = digital output j.
        value: u16,
    },
}

/// The alarm parameters (manual 3.3 Pr23, Pr24).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Alarms {
    /// Pr23: active alarm code, 0 for none.
    pub active: u8,
    /// Pr24: last alarm, kept until the alarm reset b99.10.
    pub last: u8,
}

/// The serial line as last initialised by power-up or b42.3 (manual 4, 4.1, 3.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LineSettings {
    /// Whether the drive communicates now: enabled at initialisation and b40.14 still 1.
    pub active: bool,
    /// b40.14 at the last initialisation.
    pub enabled: bool,
    /// Pr26 code in force.
    pub baud_code: u8,
    /// Bits per second of that code.
    pub bps: u32,
    /// Message time-out from STX (µs).
    pub timeout_us: Micros,
    /// Delay before each answer (µs; 25 ms for Pr26 = 4).
    pub answer_delay_us: Micros,
    /// Pr27 address in force.
    pub address: u8,
    /// Inter-drive communication mode (Pr26 = 10).
    pub idc: bool,
}
