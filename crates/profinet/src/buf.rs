//! A growable byte writer for the encoders: big-endian fields, fields in a DCE/RPC data
//! representation, and length fields patched after their body is written. Never panics.

use drivespec_capture::Endian;

/// Bytes being encoded.
#[derive(Debug, Default, Clone)]
pub(crate) struct Buf(pub(crate) Vec<u8>);

impl Buf {
    pub(crate) fn u8(&mut self, v: u8) -> &mut Buf {
        self.0.push(v);
        self
    }

    pub(crate) fn be16(&mut self, v: u16) -> &mut Buf {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }

    pub(crate) fn be32(&mut self, v: u32) -> &mut Buf {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }

    pub(crate) fn u16(&mut self, v: u16, order: Endian) -> &mut Buf {
        match order {
            Endian::Big => self.0.extend_from_slice(&v.to_be_bytes()),
            Endian::Little => self.0.extend_from_slice(&v.to_le_bytes()),
        }
        self
    }

    pub(crate) fn u32(&mut self, v: u32, order: Endian) -> &mut Buf {
        match order {
            Endian::Big => self.0.extend_from_slice(&v.to_be_bytes()),
            Endian::Little => self.0.extend_from_slice(&v.to_le_bytes()),
        }
        self
    }

    pub(crate) fn bytes(&mut self, b: &[u8]) -> &mut Buf {
        self.0.extend_from_slice(b);
        self
    }

    pub(crate) fn len(&self) -> usize {
        self.0.len()
    }

    /// Writes `v` big-endian at `at` (a length field reserved earlier).
    pub(crate) fn patch16(&mut self, at: usize, v: u16) {
        if let Some(f) = self.0.get_mut(at..at.saturating_add(2)) {
            f.copy_from_slice(&v.to_be_bytes());
        }
    }
}

/// A length that fits a 16-bit field, saturated (the encoders' callers keep bodies far below).
pub(crate) fn len16(n: usize) -> u16 {
    u16::try_from(n).unwrap_or(u16::MAX)
}
