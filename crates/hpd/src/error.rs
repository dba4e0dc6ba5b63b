//! Errors of the HPD frame codec (manual 4.1).

/// Why bytes are not a valid HPD message (manual 4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FrameError {
    /// The first byte is not STX.
    #[error("expected STX {stx:#04x} at offset 0, found {found:#04x}")]
    NoStx {
        /// The STX value.
        stx: u8,
        /// The byte found.
        found: u8,
    },
    /// A field equal to STX is not followed by the stuffing byte.
    #[error("STX value at offset {offset} not followed by the stuffing byte {stuff:#04x} (found {found:#04x})")]
    Stuffing {
        /// Offset of the unstuffed STX value in the raw bytes.
        offset: usize,
        /// The stuffing byte expected.
        stuff: u8,
        /// The byte found.
        found: u8,
    },
    /// CMD+ADDR is zero.
    #[error("CMD+ADDR is zero")]
    ZeroCmdAddr,
    /// The CMD bits name no message type.
    #[error("unknown message type CMD {cmd}")]
    UnknownCmd {
        /// The 3-bit command.
        cmd: u8,
    },
    /// LUN outside its range.
    #[error("LUN {lun} outside {min}..={max}")]
    Lun {
        /// LUN found.
        lun: u8,
        /// Smallest allowed.
        min: u8,
        /// Largest allowed.
        max: u8,
    },
    /// LUN differs from what the message type requires.
    #[error("LUN {found} where the message type requires {expected}")]
    LengthMismatch {
        /// LUN required.
        expected: u8,
        /// LUN found.
        found: u8,
    },
    /// A broadcast names a drive address.
    #[error("broadcast with ADDR {addr}, expected 0")]
    BroadcastAddr {
        /// The address found.
        addr: u8,
    },
    /// The checksum does not match the fields.
    #[error("checksum {found:#04x}, expected {expected:#04x}")]
    Checksum {
        /// Sum of the fields mod 256.
        expected: u8,
        /// Checksum byte received.
        found: u8,
    },
    /// The bytes end before the message does.
    #[error("truncated: need {need} more byte(s), have {have}")]
    Truncated {
        /// Bytes still needed at least.
        need: usize,
        /// Bytes present.
        have: usize,
    },
    /// Bytes follow a complete message.
    #[error("{extra} byte(s) after the end of the message")]
    TrailingData {
        /// Number of extra bytes.
        extra: usize,
    },
}

/// Why a message cannot be encoded (manual 4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum EmitError {
    /// Drive address outside 0..=max.
    #[error("drive address {addr} outside 0..={max}")]
    Addr {
        /// The address given.
        addr: u8,
        /// Largest address.
        max: u8,
    },
    /// LUN outside its range.
    #[error("LUN {lun} outside {min}..={max}")]
    Lun {
        /// LUN given.
        lun: u8,
        /// Smallest allowed.
        min: u8,
        /// Largest allowed.
        max: u8,
    },
    /// The output buffer is too small.
    #[error("buffer of {have} bytes, need {need}")]
    Buffer {
        /// Bytes needed.
        need: usize,
        /// Bytes available.
        have: usize,
    },
}
