//! Decoding HPD messages from line bytes (manual 4.1): STX, stuffing, checksum.
//!
//! Decoding never panics and never allocates. It has three outcomes: a complete message with
//! the number of bytes it used, `Incomplete` (more bytes needed, not an error), or an error
//! with the number of bytes to skip.
//!
//! Resynchronisation: after an error the decoder skips to the next byte that can start a
//! message: an STX not followed by the stuffing byte (manual 4.1: a field equal to STX is
//! always followed by the stuffing byte, so `STX, stuff` never starts a message, and neither
//! does `STX, 0`, since CMD+ADDR is never zero). At least one byte is always skipped.

use crate::error::FrameError;
use crate::repr::{Data, Message};
use crate::rules::{FrameRules, MessageKind};

/// Outcome of decoding a possibly incomplete buffer.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status<T> {
    /// A whole message.
    Complete(T),
    /// The bytes so far are a valid beginning; at least `need` more are required.
    Incomplete {
        /// Fewest further bytes that could complete the message.
        need: usize,
    },
}

/// A message and the number of line bytes it occupied.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Decoded {
    /// The message.
    pub message: Message,
    /// Bytes used from the start of the buffer.
    pub len: usize,
}

/// A decoding error and how many bytes to drop before trying again.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("{error}")]
pub struct DecodeError {
    /// What is wrong.
    pub error: FrameError,
    /// Bytes to skip (at least 1): up to the next byte that can start a message.
    pub skip: usize,
}

/// When a short acknowledge `[STX][001+ADDR]` counts as complete.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AckEnd {
    /// Only when the next byte is known: STX (a new message) ends the acknowledge, any other
    /// byte is the LUN of a response with data.
    NextByte,
    /// At once: the caller knows the answer is an acknowledge (it sent a write), or the
    /// line went quiet.
    Immediate,
}

/// Decodes the message at the start of `bytes`.
pub fn decode(
    rules: &FrameRules,
    bytes: &[u8],
    ack: AckEnd,
) -> Result<Status<Decoded>, DecodeError> {
    if let Some(d) = decode_plain(rules, bytes) {
        return Ok(Status::Complete(d));
    }
    decode_general(rules, bytes, ack)
}

/// The common case in one pass: a complete, valid message with no stuffed byte inside.
/// Returns `None` for anything else, which the general decoder then handles (so both paths
/// always agree on valid input).
fn decode_plain(rules: &FrameRules, bytes: &[u8]) -> Option<Decoded> {
    let stx = rules.stx;
    let (&first, rest) = bytes.split_first()?;
    let (&cmd_addr, _) = rest.split_first()?;
    if first != stx || cmd_addr == stx || cmd_addr == 0 {
        return None;
    }
    let (cmd, addr) = rules.split(cmd_addr);
    let kind = rules.kind(cmd)?;
    let lun = *bytes.get(2)?;
    if kind == MessageKind::Response && lun == stx {
        return Some(Decoded {
            message: Message::Ack { addr },
            len: 2,
        });
    }
    if !(rules.lun_min..=rules.lun_max).contains(&lun)
        || (kind == MessageKind::Broadcast && addr != 0)
        || (kind == MessageKind::BitChange && lun != rules.bit_change_lun)
    {
        return None;
    }
    let data_len = match kind {
        MessageKind::ReadPlc | MessageKind::ReadParam => 0,
        _ => usize::from(lun),
    };
    let len = 5 + data_len;
    let frame = bytes.get(..len)?;
    let (&chk, fields) = frame.get(1..)?.split_last()?;
    let mut sum = 0u8;
    for &b in fields {
        if b == stx {
            return None;
        }
        sum = sum.wrapping_add(b);
    }
    if chk == stx || (sum != chk && !cfg!(fuzzing)) {
        return None;
    }
    let par = *frame.get(3)?;
    let data = frame.get(4..4 + data_len)?;
    let message = match kind {
        MessageKind::ReadPlc => Message::ReadPlc { addr, lun, par },
        MessageKind::ReadParam => Message::ReadParam { addr, lun, par },
        MessageKind::Response => Message::Response {
            addr,
            par,
            data: Data::new(data)?,
        },
        MessageKind::WritePlc => Message::WritePlc {
            addr,
            par,
            data: Data::new(data)?,
        },
        MessageKind::WriteParam => Message::WriteParam {
            addr,
            par,
            data: Data::new(data)?,
        },
        MessageKind::Broadcast => Message::Broadcast {
            par,
            data: Data::new(data)?,
        },
        MessageKind::BitChange => match data {
            [mask, value] => Message::BitChange {
                addr,
                par,
                mask: *mask,
                value: *value,
            },
            _ => return None,
        },
    };
    Some(Decoded { message, len })
}

/// Field-by-field decoding with stuffing, partial input and every error.
fn decode_general(
    rules: &FrameRules,
    bytes: &[u8],
    ack: AckEnd,
) -> Result<Status<Decoded>, DecodeError> {
    let mut cur = Cursor {
        rules,
        bytes,
        pos: 1,
    };
    let fail = |error| DecodeError {
        error,
        skip: next_start(rules, bytes, 1),
    };
    let Some(&first) = bytes.first() else {
        return Ok(Status::Incomplete { need: 2 });
    };
    if first != rules.stx {
        return Err(fail(FrameError::NoStx {
            stx: rules.stx,
            found: first,
        }));
    }
    let mut fields = Fields::default();
    macro_rules! field {
        ($remaining:expr) => {
            match cur.field()? {
                Some(b) => {
                    fields.push(b);
                    b
                }
                None => return Ok(Status::Incomplete { need: $remaining }),
            }
        };
    }
    let cmd_addr = field!(1);
    if cmd_addr == 0 {
        return Err(fail(FrameError::ZeroCmdAddr));
    }
    let (cmd, addr) = rules.split(cmd_addr);
    let kind = rules
        .kind(cmd)
        .ok_or_else(|| fail(FrameError::UnknownCmd { cmd }))?;
    if kind == MessageKind::Broadcast && addr != 0 {
        return Err(fail(FrameError::BroadcastAddr { addr }));
    }
    if kind == MessageKind::Response {
        let short = Decoded {
            message: Message::Ack { addr },
            len: cur.pos,
        };
        match (bytes.get(cur.pos), ack) {
            (_, AckEnd::Immediate) => return Ok(Status::Complete(short)),
            (None, AckEnd::NextByte) => return Ok(Status::Incomplete { need: 1 }),
            (Some(b), AckEnd::NextByte) if *b == rules.stx => return Ok(Status::Complete(short)),
            _ => {}
        }
    }
    let lun = field!(3);
    if !(rules.lun_min..=rules.lun_max).contains(&lun) {
        return Err(fail(FrameError::Lun {
            lun,
            min: rules.lun_min,
            max: rules.lun_max,
        }));
    }
    if kind == MessageKind::BitChange && lun != rules.bit_change_lun {
        return Err(fail(FrameError::LengthMismatch {
            expected: rules.bit_change_lun,
            found: lun,
        }));
    }
    let data_len = match kind {
        MessageKind::ReadPlc | MessageKind::ReadParam => 0,
        _ => usize::from(lun),
    };
    let par = field!(2 + data_len);
    let mut data = [0u8; 4];
    for i in 0..data_len {
        let b = field!(1 + data_len - i);
        if let Some(slot) = data.get_mut(i) {
            *slot = b;
        }
    }
    let expected = fields.sum();
    let found = field!(1);
    if found != expected && !cfg!(fuzzing) {
        return Err(fail(FrameError::Checksum { expected, found }));
    }
    let data = Data::new(data.get(..data_len).unwrap_or(&[]));
    let message = match (kind, data) {
        (MessageKind::ReadPlc, _) => Message::ReadPlc { addr, lun, par },
        (MessageKind::ReadParam, _) => Message::ReadParam { addr, lun, par },
        (MessageKind::Response, Some(data)) => Message::Response { addr, par, data },
        (MessageKind::WritePlc, Some(data)) => Message::WritePlc { addr, par, data },
        (MessageKind::WriteParam, Some(data)) => Message::WriteParam { addr, par, data },
        (MessageKind::Broadcast, Some(data)) => Message::Broadcast { par, data },
        (MessageKind::BitChange, Some(d)) => {
            let [mask, value, ..] = d.unsigned().to_le_bytes();
            Message::BitChange {
                addr,
                par,
                mask,
                value,
            }
        }
        // A LUN in range always gives 1..=4 data bytes.
        (_, None) => {
            return Err(fail(FrameError::Lun {
                lun,
                min: rules.lun_min,
                max: rules.lun_max,
            }))
        }
    };
    Ok(Status::Complete(Decoded {
        message,
        len: cur.pos,
    }))
}

/// Parses exactly one message: no bytes missing, none left over.
pub fn parse(rules: &FrameRules, bytes: &[u8]) -> Result<Message, FrameError> {
    let ack = if bytes.len() == 2 {
        AckEnd::Immediate
    } else {
        AckEnd::NextByte
    };
    match decode(rules, bytes, ack).map_err(|e| e.error)? {
        Status::Complete(d) if d.len == bytes.len() => Ok(d.message),
        Status::Complete(d) => Err(FrameError::TrailingData {
            extra: bytes.len() - d.len,
        }),
        Status::Incomplete { need } => Err(FrameError::Truncated {
            need,
            have: bytes.len(),
        }),
    }
}

/// Index of the first byte at or after `from` (at least 1) that can start a message, or
/// `bytes.len()` when none can.
pub fn next_start(rules: &FrameRules, bytes: &[u8], from: usize) -> usize {
    let can_start = |i: usize| {
        bytes.get(i) == Some(&rules.stx)
            && !matches!(bytes.get(i + 1), Some(n) if *n == rules.stuff || *n == 0)
    };
    (from.max(1)..bytes.len())
        .find(|i| can_start(*i))
        .unwrap_or(bytes.len())
}

/// Reads unstuffed fields after STX.
struct Cursor<'a> {
    rules: &'a FrameRules,
    bytes: &'a [u8],
    pos: usize,
}

impl Cursor<'_> {
    /// The next field, `None` when the bytes end first.
    fn field(&mut self) -> Result<Option<u8>, DecodeError> {
        let Some(&b) = self.bytes.get(self.pos) else {
            return Ok(None);
        };
        if b == self.rules.stx {
            match self.bytes.get(self.pos + 1) {
                None => return Ok(None),
                Some(&s) if s == self.rules.stuff => {
                    self.pos += 2;
                    return Ok(Some(b));
                }
                Some(&found) => {
                    let error = FrameError::Stuffing {
                        offset: self.pos,
                        stuff: self.rules.stuff,
                        found,
                    };
                    return Err(DecodeError {
                        error,
                        skip: self.pos,
                    });
                }
            }
        }
        self.pos += 1;
        Ok(Some(b))
    }
}

/// The fields read so far, for the checksum.
#[derive(Default)]
struct Fields {
    sum: u8,
}

impl Fields {
    fn push(&mut self, b: u8) {
        self.sum = self.sum.wrapping_add(b);
    }

    /// Sum mod 256 of the fields pushed so far.
    fn sum(&self) -> u8 {
        self.sum
    }
}
