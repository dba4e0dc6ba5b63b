//! Acyclic read and write records (manual 3.2.2): the record index is the parameter number; a
//! write carries a control byte (0 = ignore the write, anything else = execute it) and then the
//! value, 3 bytes for 16-bit and 5 bytes for 32-bit parameters; a read returns 2 or 4 bytes.
//! The lengths come from the spec's record table, the width from the parameter's type, the
//! byte order from the [`Options`] (not inverted for control and status,
//! erratum PSD-ERRATUM-061). String parameters (3.3 par. 13) are read whole.
//!
//! Parsing never panics; it allocates only for a string, at most the parameter's length.

use crate::error::{DecodeError, EmitError, RulesError};
use crate::rules::Options;
use crate::value::{Params, Width};
use drivespec_positioner::ByteOrder;
use drivespec_spec::psd4xx::Protocol;
use drivespec_spec::DataType;
use serde::{Deserialize, Serialize};

/// What a record of one index carries (manual 3.2.2, 3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum RecordShape {
    /// A 16- or 32-bit value.
    Number(Width),
    /// A whole string of at most `max` bytes (3.3 par. 13).
    Text {
        /// Longest string in bytes.
        max: usize,
    },
}

/// The record table of the spec and the byte order (manual 3.2.2).
#[derive(Debug, Clone)]
pub struct RecordRules {
    control_len: usize,
    ignore: u8,
    word: (usize, usize),
    dword: (usize, usize),
    order: ByteOrder,
    strings: Vec<(u32, usize)>,
    params: Params,
}

impl RecordRules {
    /// Reads the record table (manual 3.2.2) with the byte order of `options`.
    pub fn from_protocol(
        p: &Protocol,
        params: Params,
        options: &Options,
    ) -> Result<RecordRules, RulesError> {
        let r = &p.record;
        let err = |what: String| RulesError::Table {
            table: "record",
            what,
        };
        if r.control_byte_length != 1 {
            return Err(err(format!(
                "control byte length {} (the codec handles 1)",
                r.control_byte_length
            )));
        }
        if !r.index_is_parameter_number {
            return Err(err("record index is not the parameter number".into()));
        }
        let lengths = |bits: u32| -> Result<(usize, usize), RulesError> {
            let l = r
                .length_for(bits)
                .ok_or_else(|| err(format!("no length for {bits}-bit values")))?;
            if l.read * 8 != bits as usize || l.write != l.read + r.control_byte_length {
                return Err(err(format!(
                    "{bits}-bit lengths read {} / write {} do not agree",
                    l.read, l.write
                )));
            }
            Ok((l.read, l.write))
        };
        let strings = p
            .pkw
            .string_access
            .iter()
            .filter(|s| s.record_whole)
            .filter_map(|s| {
                let param = params.iter().find(|q| q.id == s.param)?;
                let max = param
                    .length
                    .map_or(s.segment_bytes * usize::from(s.segments), |l| {
                        usize::try_from(l).unwrap_or(0)
                    });
                Some((param.number, max))
            })
            .collect();
        Ok(RecordRules {
            control_len: r.control_byte_length,
            ignore: r.control_byte_ignore,
            word: lengths(16)?,
            dword: lengths(32)?,
            order: options.byte_order,
            strings,
            params,
        })
    }

    /// The control byte value that makes the drive ignore a write (0) (manual 3.2.2).
    pub fn control_ignore(&self) -> u8 {
        self.ignore
    }

    /// Byte order of record values (manual 3.2.2).
    pub fn byte_order(&self) -> ByteOrder {
        self.order
    }

    /// Bytes a read returns for a value of `width` (2 or 4) (manual 3.2.2).
    pub fn read_len(&self, width: Width) -> usize {
        match width {
            Width::Word => self.word.0,
            Width::Dword => self.dword.0,
        }
    }

    /// Bytes of a write request for a value of `width` (3 or 5) (manual 3.2.2).
    pub fn write_len(&self, width: Width) -> usize {
        match width {
            Width::Word => self.word.1,
            Width::Dword => self.dword.1,
        }
    }

    /// What a record of `index` carries (manual 3.2.2: index = parameter number).
    pub fn shape(&self, index: u16) -> Result<RecordShape, DecodeError> {
        let p = self
            .params
            .get(u32::from(index))
            .ok_or(DecodeError::UnknownIndex { index })?;
        if p.data_type == DataType::String {
            return self
                .strings
                .iter()
                .find(|(n, _)| *n == p.number)
                .map(|(_, max)| RecordShape::Text { max: *max })
                .ok_or(DecodeError::NoRecordLength { index });
        }
        Width::of_type(p.data_type)
            .map(RecordShape::Number)
            .ok_or(DecodeError::NoRecordLength { index })
    }

    fn signed(&self, index: u16) -> Option<bool> {
        self.params.signed(u32::from(index))
    }

    fn read_value(&self, width: Width, bytes: &[u8]) -> u32 {
        self.order.decode(bytes).unwrap_or(0) as u32 & ((1u64 << width.bits()) - 1) as u32
    }
}

fn exact(data: &[u8], need: usize) -> Result<(), DecodeError> {
    match data.len() {
        n if n < need => Err(DecodeError::Truncated { need, have: n }),
        n if n > need => Err(DecodeError::TrailingData {
            expected: need,
            have: n,
        }),
        _ => Ok(()),
    }
}

fn out_buffer(out: &mut [u8], need: usize) -> Result<&mut [u8], EmitError> {
    let have = out.len();
    out.get_mut(..need).ok_or(EmitError::Buffer { need, have })
}

fn raw_for(rules: &RecordRules, index: u16, width: Width, value: i64) -> Result<u32, EmitError> {
    width
        .to_raw(value, rules.signed(index))
        .map_err(|(min, max)| EmitError::Value { value, min, max })
}

/// A write request: control byte and value (manual 3.2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct RecordWrite {
    /// Record index = parameter number.
    pub index: u16,
    /// Control byte: the control-ignore value (0) makes the drive ignore the write.
    pub control: u8,
    /// 16 or 32 bits, by the parameter's type.
    pub width: Width,
    /// The value (two's complement for signed parameters).
    pub value: i64,
}

impl RecordWrite {
    /// Parses the data of a write to `index`; the width comes from the parameter (3.2.2).
    pub fn parse(rules: &RecordRules, index: u16, data: &[u8]) -> Result<RecordWrite, DecodeError> {
        match rules.shape(index)? {
            RecordShape::Number(width) => RecordWrite::parse_as(rules, index, width, data),
            RecordShape::Text { .. } => Err(DecodeError::NoRecordLength { index }),
        }
    }

    /// Parses the data of a write with a given width (for indices the spec does not list) (manual 3.2.2).
    pub fn parse_as(
        rules: &RecordRules,
        index: u16,
        width: Width,
        data: &[u8],
    ) -> Result<RecordWrite, DecodeError> {
        exact(data, rules.write_len(width))?;
        let control = data.first().copied().unwrap_or(0);
        let raw = rules.read_value(width, data.get(rules.control_len..).unwrap_or(&[]));
        let signed = rules.signed(index).unwrap_or(false);
        Ok(RecordWrite {
            index,
            control,
            width,
            value: width.to_value(raw, signed),
        })
    }

    /// Whether the drive executes the write: control byte not the ignore value (3.2.2).
    pub fn executes(&self, rules: &RecordRules) -> bool {
        self.control != rules.control_ignore()
    }

    /// Number of bytes `emit` writes (3 or 5) (manual 3.2.2).
    pub fn buffer_len(&self, rules: &RecordRules) -> usize {
        rules.write_len(self.width)
    }

    /// Writes control byte and value; returns the bytes written (3.2.2).
    pub fn emit(&self, rules: &RecordRules, out: &mut [u8]) -> Result<usize, EmitError> {
        let raw = raw_for(rules, self.index, self.width, self.value)?;
        let need = self.buffer_len(rules);
        let out = out_buffer(out, need)?;
        let (head, value) = out.split_at_mut(rules.control_len.min(need));
        if let Some(c) = head.first_mut() {
            *c = self.control;
        }
        rules.order.encode(u64::from(raw), value);
        Ok(need)
    }

    /// The write data as bytes (3.2.2).
    pub fn to_bytes(&self, rules: &RecordRules) -> Result<Vec<u8>, EmitError> {
        let mut out = vec![0; self.buffer_len(rules)];
        self.emit(rules, &mut out)?;
        Ok(out)
    }
}

/// The value of a read record (manual 3.2.2, 3.3 par. 13).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RecordValue {
    /// A 16- or 32-bit value (two's complement for signed parameters).
    Number {
        /// 16 or 32 bits.
        width: Width,
        /// The value.
        value: i64,
    },
    /// A string, without the terminating 0 and what follows it.
    Text(Vec<u8>),
}

/// The answer to a read request (manual 3.2.2).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct RecordRead {
    /// Record index = parameter number.
    pub index: u16,
    /// The value read.
    pub value: RecordValue,
}

impl RecordRead {
    /// Parses the data a read of `index` returns (3.2.2).
    pub fn parse(rules: &RecordRules, index: u16, data: &[u8]) -> Result<RecordRead, DecodeError> {
        match rules.shape(index)? {
            RecordShape::Number(width) => RecordRead::parse_as(rules, index, width, data),
            RecordShape::Text { max } => {
                if data.len() > max {
                    return Err(DecodeError::TrailingData {
                        expected: max,
                        have: data.len(),
                    });
                }
                let text = data.iter().take_while(|b| **b != 0).copied().collect();
                Ok(RecordRead {
                    index,
                    value: RecordValue::Text(text),
                })
            }
        }
    }

    /// Parses read data with a given width (for indices the spec does not list) (manual 3.2.2).
    pub fn parse_as(
        rules: &RecordRules,
        index: u16,
        width: Width,
        data: &[u8],
    ) -> Result<RecordRead, DecodeError> {
        exact(data, rules.read_len(width))?;
        let raw = rules.read_value(width, data);
        let signed = rules.signed(index).unwrap_or(false);
        Ok(RecordRead {
            index,
            value: RecordValue::Number {
                width,
                value: width.to_value(raw, signed),
            },
        })
    }

    /// Number of bytes `emit` writes: 2 or 4, or the text and its 0 terminator when it fits (manual 3.2.2).
    pub fn buffer_len(&self, rules: &RecordRules) -> usize {
        match &self.value {
            RecordValue::Number { width, .. } => rules.read_len(*width),
            RecordValue::Text(t) => {
                let max = match rules.shape(self.index) {
                    Ok(RecordShape::Text { max }) => max,
                    _ => usize::MAX,
                };
                (t.len() + 1).min(max.max(t.len()))
            }
        }
    }

    /// Writes the read data; returns the bytes written (3.2.2).
    pub fn emit(&self, rules: &RecordRules, out: &mut [u8]) -> Result<usize, EmitError> {
        match &self.value {
            RecordValue::Number { width, value } => {
                let raw = raw_for(rules, self.index, *width, *value)?;
                let need = rules.read_len(*width);
                rules.order.encode(u64::from(raw), out_buffer(out, need)?);
                Ok(need)
            }
            RecordValue::Text(t) => {
                if let Ok(RecordShape::Text { max }) = rules.shape(self.index) {
                    if t.len() > max {
                        return Err(EmitError::TextLength { len: t.len(), max });
                    }
                }
                let need = self.buffer_len(rules);
                let out = out_buffer(out, need)?;
                for (i, slot) in out.iter_mut().enumerate() {
                    *slot = t.get(i).copied().unwrap_or(0);
                }
                Ok(need)
            }
        }
    }

    /// The read data as bytes (3.2.2).
    pub fn to_bytes(&self, rules: &RecordRules) -> Result<Vec<u8>, EmitError> {
        let mut out = vec![0; self.buffer_len(rules)];
        let n = self.emit(rules, &mut out)?;
        out.truncate(n);
        Ok(out)
    }
}
