//! Typed HPD messages (manual 4.1, message types 1–7).

use crate::error::EmitError;
use crate::rules::{FrameRules, MessageKind};

/// The data bytes of a message: 1 to 4 bytes (LUN), least significant first.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Data {
    len: u8,
    bytes: [u8; 4],
}

impl Data {
    /// Up to four bytes; None when `bytes` is empty or longer than four.
    pub fn new(bytes: &[u8]) -> Option<Data> {
        if bytes.is_empty() || bytes.len() > 4 {
            return None;
        }
        let mut b = [0; 4];
        for (slot, v) in b.iter_mut().zip(bytes) {
            *slot = *v;
        }
        Some(Data {
            len: bytes.len() as u8,
            bytes: b,
        })
    }

    /// A value of `len` bytes, little-endian as in manual 4.1 case 2 (2000 → D0 07).
    pub fn from_value(value: i64, len: u8) -> Option<Data> {
        let bytes = value.to_le_bytes();
        Data::new(bytes.get(..usize::from(len))?)
    }

    /// The bytes.
    pub fn as_slice(&self) -> &[u8] {
        self.bytes.get(..usize::from(self.len)).unwrap_or(&[])
    }

    /// Number of bytes (the LUN).
    pub fn len(&self) -> u8 {
        self.len
    }

    /// Always false: data has at least one byte.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The bytes as an unsigned little-endian value.
    pub fn unsigned(&self) -> u32 {
        u32::from_le_bytes(self.bytes)
    }

    /// The bytes as a two's-complement little-endian value of `len` bytes.
    pub fn signed(&self) -> i32 {
        let shift = 32 - 8 * u32::from(self.len);
        ((self.unsigned() << shift) as i32) >> shift
    }
}

impl std::fmt::Debug for Data {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Data({})", drivespec_spec::hex::to_hex(self.as_slice()))
    }
}

/// One HPD message (manual 4.1, "Message types").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Message {
    /// CMD 1: the drive answers a read with data.
    Response {
        /// Answering drive.
        addr: u8,
        /// Address read.
        par: u8,
        /// Value read.
        data: Data,
    },
    /// CMD 1 short form `[STX][001+ADDR]`: the drive confirms a write.
    Ack {
        /// Answering drive.
        addr: u8,
    },
    /// CMD 2: read `lun` bytes of the PLC area.
    ReadPlc {
        /// Drive addressed.
        addr: u8,
        /// Bytes to read.
        lun: u8,
        /// PLC area address.
        par: u8,
    },
    /// CMD 3: write PLC area bytes.
    WritePlc {
        /// Drive addressed.
        addr: u8,
        /// PLC area address.
        par: u8,
        /// Instruction bytes.
        data: Data,
    },
    /// CMD 4: read `lun` bytes of parameter memory.
    ReadParam {
        /// Drive addressed.
        addr: u8,
        /// Bytes to read.
        lun: u8,
        /// Serial address.
        par: u8,
    },
    /// CMD 5: write parameter memory.
    WriteParam {
        /// Drive addressed.
        addr: u8,
        /// Serial address.
        par: u8,
        /// Value.
        data: Data,
    },
    /// CMD 6: change bits of one byte; mask has 0 at the bits to change.
    BitChange {
        /// Drive addressed.
        addr: u8,
        /// Serial address of the byte (word address + 1 for bits 8–15).
        par: u8,
        /// 0 at the bits to change, 1 elsewhere.
        mask: u8,
        /// New values of the bits to change.
        value: u8,
    },
    /// CMD 7: write a parameter on every drive; nobody answers.
    Broadcast {
        /// Serial address.
        par: u8,
        /// Value.
        data: Data,
    },
}

/// Longest logical message: CMD+ADDR, LUN, PAR, 4 data bytes, CHK after STX.
pub(crate) const MAX_FIELDS: usize = 8;
/// Longest message on the line: STX plus every field stuffed.
pub const MAX_FRAME: usize = 1 + 2 * MAX_FIELDS;

impl Message {
    /// The message type.
    pub fn kind(&self) -> MessageKind {
        match self {
            Message::Response { .. } | Message::Ack { .. } => MessageKind::Response,
            Message::ReadPlc { .. } => MessageKind::ReadPlc,
            Message::WritePlc { .. } => MessageKind::WritePlc,
            Message::ReadParam { .. } => MessageKind::ReadParam,
            Message::WriteParam { .. } => MessageKind::WriteParam,
            Message::BitChange { .. } => MessageKind::BitChange,
            Message::Broadcast { .. } => MessageKind::Broadcast,
        }
    }

    /// The drive address (0 for broadcasts).
    pub fn addr(&self) -> u8 {
        match *self {
            Message::Response { addr, .. }
            | Message::Ack { addr }
            | Message::ReadPlc { addr, .. }
            | Message::WritePlc { addr, .. }
            | Message::ReadParam { addr, .. }
            | Message::WriteParam { addr, .. }
            | Message::BitChange { addr, .. } => addr,
            Message::Broadcast { .. } => 0,
        }
    }

    /// Whether the message goes from master to drive.
    pub fn is_request(&self) -> bool {
        self.kind() != MessageKind::Response
    }

    /// The logical fields after STX, checksum included, unstuffed.
    pub(crate) fn fields(
        &self,
        rules: &FrameRules,
    ) -> Result<([u8; MAX_FIELDS], usize), EmitError> {
        let addr = self.addr();
        if addr > rules.addr_max {
            return Err(EmitError::Addr {
                addr,
                max: rules.addr_max,
            });
        }
        let lun_ok = |lun: u8| {
            if (rules.lun_min..=rules.lun_max).contains(&lun) {
                Ok(lun)
            } else {
                Err(EmitError::Lun {
                    lun,
                    min: rules.lun_min,
                    max: rules.lun_max,
                })
            }
        };
        let mut f = FieldBuf::default();
        f.push(rules.join(rules.code(self.kind()), addr));
        match self {
            Message::Ack { .. } => return Ok((f.fields, f.len)),
            Message::ReadPlc { lun, par, .. } | Message::ReadParam { lun, par, .. } => {
                f.push(lun_ok(*lun)?);
                f.push(*par);
            }
            Message::Response { par, data, .. }
            | Message::WritePlc { par, data, .. }
            | Message::WriteParam { par, data, .. }
            | Message::Broadcast { par, data } => {
                f.push(lun_ok(data.len())?);
                f.push(*par);
                data.as_slice().iter().for_each(|b| f.push(*b));
            }
            Message::BitChange {
                par, mask, value, ..
            } => {
                f.push(rules.bit_change_lun);
                f.push(*par);
                f.push(*mask);
                f.push(*value);
            }
        }
        f.push(f.sum);
        Ok((f.fields, f.len))
    }

    /// Number of bytes `emit` writes, stuffing included.
    pub fn buffer_len(&self, rules: &FrameRules) -> Result<usize, EmitError> {
        let (f, n) = self.fields(rules)?;
        Ok(1 + f
            .iter()
            .take(n)
            .map(|b| if *b == rules.stx { 2 } else { 1 })
            .sum::<usize>())
    }

    /// Writes the message with STX, checksum and stuffing; returns the bytes written.
    pub fn emit(&self, rules: &FrameRules, out: &mut [u8]) -> Result<usize, EmitError> {
        let need = self.buffer_len(rules)?;
        let have = out.len();
        let out = out
            .get_mut(..need)
            .ok_or(EmitError::Buffer { need, have })?;
        let (f, n) = self.fields(rules)?;
        let mut i = 0;
        let mut push = |b: u8| {
            if let Some(slot) = out.get_mut(i) {
                *slot = b;
            }
            i += 1;
        };
        push(rules.stx);
        for b in f.iter().take(n) {
            push(*b);
            if *b == rules.stx {
                push(rules.stuff);
            }
        }
        Ok(i)
    }

    /// The message as bytes on the line.
    pub fn to_bytes(&self, rules: &FrameRules) -> Result<Vec<u8>, EmitError> {
        let mut buf = [0u8; MAX_FRAME];
        let n = self.emit(rules, &mut buf)?;
        Ok(buf.get(..n).unwrap_or(&[]).to_vec())
    }
}

/// Fields being assembled, with their running checksum.
#[derive(Default)]
struct FieldBuf {
    fields: [u8; MAX_FIELDS],
    len: usize,
    sum: u8,
}

impl FieldBuf {
    fn push(&mut self, b: u8) {
        if let Some(slot) = self.fields.get_mut(self.len) {
            *slot = b;
            self.len += 1;
        }
        self.sum = self.sum.wrapping_add(b);
    }
}
