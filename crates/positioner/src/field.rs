//! One integer inside a process image: offset, length and byte order (PSD4xx manual 3.5,
//! PSx3xx manual 3.3), read and written over checked slices.
//!
//! A [`Field`] is built from a spec layout (offset and length of the bytes) and the byte
//! order setting. Reads and writes never panic: a buffer too short for the field gives
//! [`FieldError::Truncated`], a value too wide gives [`FieldError::Range`].

use crate::order::ByteOrder;
use serde::{Deserialize, Serialize};
use std::ops::Range;

/// Why a field cannot be built, read or written (PSD4xx 3.5, PSx3xx 3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FieldError {
    /// The buffer ends before the field does.
    #[error("truncated: field at offset {offset} needs {need} bytes, have {have}")]
    Truncated {
        /// Offset of the field's first byte.
        offset: usize,
        /// Buffer length the field needs (offset + length).
        need: usize,
        /// Buffer length present.
        have: usize,
    },
    /// A field length of 0 or more than [`Field::MAX_LEN`] bytes.
    #[error("field length {len} outside 1..={max}")]
    Length {
        /// Length asked for.
        len: usize,
        /// Largest length supported.
        max: usize,
    },
    /// offset + length overflows.
    #[error("field at offset {offset} with length {len} overflows")]
    Overflow {
        /// Offset asked for.
        offset: usize,
        /// Length asked for.
        len: usize,
    },
    /// The value does not fit the field.
    #[error("value {value} outside {min}..={max}")]
    Range {
        /// Value given.
        value: i128,
        /// Smallest value the field holds.
        min: i128,
        /// Largest value the field holds.
        max: i128,
    },
}

/// An integer of 1 to 8 bytes at a fixed offset, in a given byte order (PSD4xx 3.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Field {
    offset: usize,
    len: usize,
    order: ByteOrder,
}

impl Field {
    /// Longest field: 8 bytes (a `u64`) (PSD4xx 3.5).
    pub const MAX_LEN: usize = 8;

    /// A field of `len` bytes (1..=8) at `offset` (PSD4xx 3.5 byte tables).
    pub fn new(offset: usize, len: usize, order: ByteOrder) -> Result<Field, FieldError> {
        if len == 0 || len > Field::MAX_LEN {
            return Err(FieldError::Length {
                len,
                max: Field::MAX_LEN,
            });
        }
        if offset.checked_add(len).is_none() {
            return Err(FieldError::Overflow { offset, len });
        }
        Ok(Field { offset, len, order })
    }

    /// Offset of the first byte (PSD4xx 3.5).
    pub fn offset(&self) -> usize {
        self.offset
    }

    /// Length in bytes (PSD4xx 3.5).
    pub fn len(&self) -> usize {
        self.len
    }

    /// Always false: a field has at least one byte (PSD4xx 3.5).
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Offset just past the last byte (PSD4xx 3.5).
    pub fn end(&self) -> usize {
        self.offset.saturating_add(self.len)
    }

    /// The byte range in the buffer (PSD4xx 3.5).
    pub fn span(&self) -> Range<usize> {
        self.offset..self.end()
    }

    /// Byte order of the field (PSD4xx 3.5).
    pub fn order(&self) -> ByteOrder {
        self.order
    }

    /// The same bytes in another order (PSD4xx 3.5 notice "UseAsBits").
    pub fn with_order(self, order: ByteOrder) -> Field {
        Field { order, ..self }
    }

    /// Number of value bits (8 × length) (PSD4xx 3.5).
    pub fn bits(&self) -> u32 {
        u32::try_from(self.len * 8).unwrap_or(64)
    }

    /// Largest unsigned value the field holds (PSD4xx 3.5).
    pub fn max_unsigned(&self) -> u64 {
        u64::MAX >> (64 - self.bits().min(64))
    }

    /// Smallest and largest two's-complement value the field holds (PSD4xx 3.5).
    pub fn signed_range(&self) -> (i64, i64) {
        let max = (self.max_unsigned() >> 1) as i64;
        (-max - 1, max)
    }

    /// The field's bytes in `buf` (PSD4xx 3.5).
    pub fn bytes<'a>(&self, buf: &'a [u8]) -> Result<&'a [u8], FieldError> {
        buf.get(self.span()).ok_or(FieldError::Truncated {
            offset: self.offset,
            need: self.end(),
            have: buf.len(),
        })
    }

    fn bytes_mut<'a>(&self, buf: &'a mut [u8]) -> Result<&'a mut [u8], FieldError> {
        let have = buf.len();
        buf.get_mut(self.span()).ok_or(FieldError::Truncated {
            offset: self.offset,
            need: self.end(),
            have,
        })
    }

    /// The unsigned value of the field in `buf` (PSD4xx 3.5).
    pub fn read_unsigned(&self, buf: &[u8]) -> Result<u64, FieldError> {
        let bytes = self.bytes(buf)?;
        Ok(self.order.decode(bytes).unwrap_or(0))
    }

    /// The two's-complement value of the field in `buf` (PSD4xx 3.5).
    pub fn read_signed(&self, buf: &[u8]) -> Result<i64, FieldError> {
        let raw = self.read_unsigned(buf)?;
        let shift = 64 - self.bits().min(64);
        Ok(((raw << shift) as i64) >> shift)
    }

    /// Writes an unsigned value (PSD4xx 3.5); `Range` when it needs more bits.
    pub fn write_unsigned(&self, buf: &mut [u8], value: u64) -> Result<(), FieldError> {
        if value > self.max_unsigned() {
            return Err(FieldError::Range {
                value: i128::from(value),
                min: 0,
                max: i128::from(self.max_unsigned()),
            });
        }
        let order = self.order;
        order.encode(value, self.bytes_mut(buf)?);
        Ok(())
    }

    /// Writes a two's-complement value (PSD4xx 3.5); `Range` when it needs more bits.
    pub fn write_signed(&self, buf: &mut [u8], value: i64) -> Result<(), FieldError> {
        let (min, max) = self.signed_range();
        if !(min..=max).contains(&value) {
            return Err(FieldError::Range {
                value: i128::from(value),
                min: i128::from(min),
                max: i128::from(max),
            });
        }
        let order = self.order;
        order.encode(value as u64 & self.max_unsigned(), self.bytes_mut(buf)?);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_and_writes() -> Result<(), FieldError> {
        let be = Field::new(2, 2, ByteOrder::BigEndian)?;
        let le = be.with_order(ByteOrder::LittleEndian);
        let mut buf = [0u8; 4];
        be.write_signed(&mut buf, -75)?;
        assert_eq!(buf, [0, 0, 0xFF, 0xB5]);
        assert_eq!(be.read_signed(&buf)?, -75);
        assert_eq!(be.read_unsigned(&buf)?, 0xFFB5);
        assert_eq!(le.read_unsigned(&buf)?, 0xB5FF);
        le.write_unsigned(&mut buf, 0x0014)?;
        assert_eq!(buf, [0, 0, 0x14, 0x00]);
        assert_eq!(be.signed_range(), (-32768, 32767));
        assert_eq!(be.max_unsigned(), 0xFFFF);
        Ok(())
    }

    #[test]
    fn errors_carry_data() -> Result<(), FieldError> {
        let f = Field::new(12, 4, ByteOrder::BigEndian)?;
        assert_eq!(
            f.read_unsigned(&[0; 14]),
            Err(FieldError::Truncated {
                offset: 12,
                need: 16,
                have: 14
            })
        );
        assert_eq!(
            Field::new(0, 2, ByteOrder::BigEndian)?.write_unsigned(&mut [0; 2], 0x1_0000),
            Err(FieldError::Range {
                value: 0x1_0000,
                min: 0,
                max: 0xFFFF
            })
        );
        assert_eq!(
            Field::new(0, 1, ByteOrder::BigEndian)?.write_signed(&mut [0; 1], -129),
            Err(FieldError::Range {
                value: -129,
                min: -128,
                max: 127
            })
        );
        assert_eq!(
            Field::new(0, 9, ByteOrder::BigEndian),
            Err(FieldError::Length { len: 9, max: 8 })
        );
        assert_eq!(
            Field::new(usize::MAX, 1, ByteOrder::BigEndian),
            Err(FieldError::Overflow {
                offset: usize::MAX,
                len: 1
            })
        );
        let full = Field::new(0, 8, ByteOrder::LittleEndian)?;
        let mut b = [0u8; 8];
        full.write_signed(&mut b, i64::MIN)?;
        assert_eq!(full.read_signed(&b)?, i64::MIN);
        full.write_unsigned(&mut b, u64::MAX)?;
        assert_eq!(full.read_unsigned(&b)?, u64::MAX);
        Ok(())
    }
}
