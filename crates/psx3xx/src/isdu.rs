//! ISDU access to the object directory (manual 3.1; IEC 61131-9 annex C): which entry an
//! index and sub-index name, how its value is encoded, which requests the codec can already
//! tell are refused and with which ErrorType, and what ISDU 2 / ISDU 193 commands do.
//!
//! Values travel in the wire byte order of the spec (IO-Link: most significant octet first),
//! one entry's data type wide: 8, 16 or 32 bits, signed or not, or a string of at most the
//! entry's `length` octets (ISDU 24: 16). An ErrorType is two octets, ErrorCode then
//! AdditionalCode; [`ErrorType`] is an open enum, so codes the spec does not list decode and
//! re-encode unchanged.
//!
//! The checks here need no device state: index and sub-index, access, data length, the data
//! type, the range of 3.1 (and of 3.2 when a model is given), must-be-zero bits and command
//! values. Refusals that depend on other parameters (write lock ISDU 12, software version,
//! mapping windows of 5.6) belong to the reference model.
//!
//! Nothing here panics; allocation is bounded by the request's data and the spec tables.

use crate::error::{ErrorTypeError, ValueError};
use crate::rules::Rules;
use drivespec_spec::psx3xx::{Readback, StateCommand};
use drivespec_spec::{DataType, DeviceModel, Parameter};
use serde::Serialize;
use std::fmt;

drivespec_positioner::open_enum! {
    /// An IO-Link ISDU ErrorType, ErrorCode × 256 + AdditionalCode (IEC 61131-9 annex C);
    /// names from `protocol.isdu_errors.code`.
    pub struct ErrorType(u16);
    /// The ErrorTypes the adopted cases use, looked up by IO-Link name (manual 3.1).
    pub struct ErrorTypes {
        /// Device application error.
        app_dev = "APP_DEV",
        /// Index not available.
        idx_notavail = "IDX_NOTAVAIL",
        /// Sub-index not available.
        subidx_notavail = "SUBIDX_NOTAVAIL",
        /// Access denied.
        idx_not_writeable = "IDX_NOT_WRITEABLE",
        /// Parameter value out of range.
        par_valoutofrng = "PAR_VALOUTOFRNG",
        /// Parameter length overrun.
        val_lenovrrun = "VAL_LENOVRRUN",
        /// Parameter length underrun.
        val_lenundrun = "VAL_LENUNDRUN",
        /// Function not available.
        func_notavail = "FUNC_NOTAVAIL",
    }
}

impl ErrorType {
    /// Octets of an ErrorType on the wire, ErrorCode and AdditionalCode (IEC 61131-9 C.1).
    pub const LEN: usize = 2;

    /// The ErrorCode octet (IEC 61131-9 C.1).
    pub fn error_code(self) -> u8 {
        let [code, _] = self.0.to_be_bytes();
        code
    }

    /// The AdditionalCode octet (IEC 61131-9 C.1).
    pub fn additional_code(self) -> u8 {
        let [_, additional] = self.0.to_be_bytes();
        additional
    }

    /// The two octets of an ISDU error response (IEC 61131-9 C.1).
    pub fn to_bytes(self) -> [u8; 2] {
        self.0.to_be_bytes()
    }

    /// Reads exactly two octets of an ISDU error response (IEC 61131-9 C.1).
    pub fn parse(bytes: &[u8]) -> Result<ErrorType, ErrorTypeError> {
        match bytes {
            [code, additional] => Ok(ErrorType(u16::from_be_bytes([*code, *additional]))),
            b if b.len() < ErrorType::LEN => Err(ErrorTypeError::Truncated {
                need: ErrorType::LEN,
                have: b.len(),
            }),
            b => Err(ErrorTypeError::TrailingData {
                extra: b.len() - ErrorType::LEN,
            }),
        }
    }
}

/// A situation in which the device refuses an ISDU request; names and codes from
/// `protocol.isdu_errors.case` (manual 3.1; IEC 61131-9 C.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum ErrorCase {
    /// The index is not in the object directory of 3.1.
    IndexNotAvailable,
    /// The sub-index does not exist for the index.
    SubindexNotAvailable,
    /// Write to a read-only entry.
    WriteReadOnly,
    /// Read of a write-only entry.
    ReadWriteOnly,
    /// Value outside the range of 3.1 / 3.2.
    ValueOutOfRange,
    /// Value inconsistent with other parameters (model check).
    ValueInconsistent,
    /// ISDU 193 value outside the commands.
    DeliveryStateInvalid,
    /// ISDU 116 format not offered.
    FormatNotSupported,
    /// A must-be-zero bit is set.
    ReservedBitsSet,
    /// More data octets than the entry has.
    LengthOverrun,
    /// Fewer data octets than the entry has.
    LengthUnderrun,
    /// Standard command value not offered.
    CommandNotAvailable,
    /// Parameter write while ISDU 12 locks writes (model check).
    WriteLocked,
}

impl ErrorCase {
    /// All cases (manual 3.1; IEC 61131-9 annex C).
    pub const ALL: [ErrorCase; 13] = [
        ErrorCase::IndexNotAvailable,
        ErrorCase::SubindexNotAvailable,
        ErrorCase::WriteReadOnly,
        ErrorCase::ReadWriteOnly,
        ErrorCase::ValueOutOfRange,
        ErrorCase::ValueInconsistent,
        ErrorCase::DeliveryStateInvalid,
        ErrorCase::FormatNotSupported,
        ErrorCase::ReservedBitsSet,
        ErrorCase::LengthOverrun,
        ErrorCase::LengthUnderrun,
        ErrorCase::CommandNotAvailable,
        ErrorCase::WriteLocked,
    ];

    /// The case name in `protocol.isdu_errors.case` (manual 3.1; IEC 61131-9 annex C).
    pub fn spec_name(self) -> &'static str {
        match self {
            ErrorCase::IndexNotAvailable => "index-not-available",
            ErrorCase::SubindexNotAvailable => "subindex-not-available",
            ErrorCase::WriteReadOnly => "write-read-only",
            ErrorCase::ReadWriteOnly => "read-write-only",
            ErrorCase::ValueOutOfRange => "value-out-of-range",
            ErrorCase::ValueInconsistent => "value-inconsistent",
            ErrorCase::DeliveryStateInvalid => "delivery-state-invalid",
            ErrorCase::FormatNotSupported => "format-not-supported",
            ErrorCase::ReservedBitsSet => "reserved-bits-set",
            ErrorCase::LengthOverrun => "length-overrun",
            ErrorCase::LengthUnderrun => "length-underrun",
            ErrorCase::CommandNotAvailable => "command-not-available",
            ErrorCase::WriteLocked => "write-locked",
        }
    }
}

impl fmt::Display for ErrorCase {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.spec_name())
    }
}

/// A case with the ErrorType adopted and the ones also accepted (IEC 61131-9 C.2).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct CaseRule {
    /// The situation.
    pub case: ErrorCase,
    /// The ErrorType adopted.
    pub code: ErrorType,
    /// ErrorTypes a conforming device may send instead.
    pub acceptable: Vec<ErrorType>,
    /// Parameters the case concerns (empty = any).
    pub params: Vec<String>,
    /// One line.
    pub text: String,
    /// Manual section or IO-Link clause.
    pub source: String,
}

/// What an index and sub-index name (manual 3.1); equal when they name the same entries.
#[derive(Debug, Clone, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Target<'s> {
    /// One entry (a single-value index, or one sub-index of a record).
    Entry {
        /// The entry.
        #[serde(serialize_with = "ser_param")]
        param: &'s Parameter,
    },
    /// Sub-index 0 of a record index: all its sub-indices in order (ISDU 0).
    Record {
        /// The ISDU index.
        index: u16,
        /// The entries by sub-index.
        #[serde(serialize_with = "ser_params")]
        entries: Vec<&'s Parameter>,
    },
}

impl PartialEq for Target<'_> {
    fn eq(&self, other: &Self) -> bool {
        let ids = |t: &Self| -> Vec<String> { t.entries().iter().map(|p| p.id.clone()).collect() };
        ids(self) == ids(other)
    }
}

fn ser_param<S: serde::Serializer>(p: &&Parameter, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(&p.id)
}

fn ser_params<S: serde::Serializer>(p: &[&Parameter], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(p.iter().map(|p| p.id.as_str()))
}

impl<'s> Target<'s> {
    /// The entries addressed, one for a single entry (manual 3.1; IEC 61131-9 annex C).
    pub fn entries(&self) -> Vec<&'s Parameter> {
        match self {
            Target::Entry { param } => vec![*param],
            Target::Record { entries, .. } => entries.clone(),
        }
    }

    /// The single entry, None for a record (manual 3.1; IEC 61131-9 annex C).
    pub fn param(&self) -> Option<&'s Parameter> {
        match self {
            Target::Entry { param } => Some(param),
            Target::Record { .. } => None,
        }
    }
}

/// A parameter value (manual 3.1 value column).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
#[serde(untagged)]
pub enum Value {
    /// An integer or bit field, raw.
    Int(i64),
    /// A string.
    Text(String),
    /// The values of a record, by sub-index.
    Record(Vec<Value>),
}

impl fmt::Display for Value {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Value::Int(v) => write!(f, "{v}"),
            Value::Text(t) => write!(f, "{t:?}"),
            Value::Record(items) => {
                f.write_str("[")?;
                for (i, v) in items.iter().enumerate() {
                    if i > 0 {
                        f.write_str(", ")?;
                    }
                    write!(f, "{v}")?;
                }
                f.write_str("]")
            }
        }
    }
}

/// An ISDU request (IEC 61131-9 A.5; manual 3.1).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
#[serde(tag = "op", rename_all = "lowercase")]
pub enum Request {
    /// Read an entry.
    Read {
        /// ISDU index.
        index: u16,
        /// Sub-index (0 = the whole index).
        subindex: u8,
    },
    /// Write an entry.
    Write {
        /// ISDU index.
        index: u16,
        /// Sub-index (0 = the whole index).
        subindex: u8,
        /// Value octets.
        data: Vec<u8>,
    },
}

impl Request {
    /// The index and sub-index addressed (manual 3.1; IEC 61131-9 annex C).
    pub fn address(&self) -> (u16, u8) {
        match self {
            Request::Read { index, subindex }
            | Request::Write {
                index, subindex, ..
            } => (*index, *subindex),
        }
    }
}

/// An ISDU response (IEC 61131-9 A.5, annex C).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Response {
    /// Read response (+) with the value octets.
    Read {
        /// Value octets.
        data: Vec<u8>,
    },
    /// Write response (+).
    Write,
    /// Read or write response (−) with an ErrorType.
    Error {
        /// The ErrorType.
        error: ErrorType,
    },
}

/// A request the codec finds no fault with (manual 3.1).
#[derive(Debug, Clone, Serialize)]
pub struct Accepted<'s> {
    /// What is addressed.
    pub target: Target<'s>,
    /// The value written (writes only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<Value>,
    /// The ISDU 2 / 193 command a write triggers.
    #[serde(
        skip_serializing_if = "Option::is_none",
        serialize_with = "ser_command"
    )]
    pub command: Option<&'s StateCommand>,
}

impl PartialEq for Accepted<'_> {
    fn eq(&self, other: &Self) -> bool {
        self.target == other.target
            && self.value == other.value
            && self.command.map(|c| (&c.param, c.value))
                == other.command.map(|c| (&c.param, c.value))
    }
}

fn ser_command<S: serde::Serializer>(c: &Option<&StateCommand>, s: S) -> Result<S::Ok, S::Error> {
    match c {
        Some(c) => s.serialize_str(&c.name),
        None => s.serialize_none(),
    }
}

/// A request the device refuses, with the ErrorType to answer (IEC 61131-9 C.2).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, thiserror::Error)]
#[error("{case}: {detail} (ErrorType {error})")]
pub struct Rejection {
    /// The situation.
    pub case: ErrorCase,
    /// The ErrorType adopted for it.
    pub error: ErrorType,
    /// ErrorTypes a conforming device may send instead.
    pub acceptable: Vec<ErrorType>,
    /// What is wrong, one line.
    pub detail: String,
}

impl Rejection {
    /// Whether a device answering `code` conforms: the adopted or an acceptable ErrorType
    /// (IEC 61131-9 C.2).
    pub fn accepts(&self, code: ErrorType) -> bool {
        self.error == code || self.acceptable.contains(&code)
    }

    /// The error response (IEC 61131-9 C.1).
    pub fn response(&self) -> Response {
        Response::Error { error: self.error }
    }
}

/// The numeric width of a data type, in octets.
fn width(t: DataType) -> Option<usize> {
    t.width().and_then(|w| usize::try_from(w).ok())
}

impl<'s> Rules<'s> {
    /// The case rule of a situation (manual 3.1; IEC 61131-9 C.2).
    pub fn case_rule(&self, case: ErrorCase) -> Option<&CaseRule> {
        self.cases.iter().find(|c| c.case == case)
    }

    /// All case rules in spec order (manual 3.1; IEC 61131-9 annex C).
    pub fn case_rules(&self) -> &[CaseRule] {
        &self.cases
    }

    /// The refusal of a case, with its ErrorTypes (IEC 61131-9 C.2).
    pub fn reject(&self, case: ErrorCase, detail: impl Into<String>) -> Rejection {
        let rule = self.case_rule(case);
        Rejection {
            case,
            error: rule.map_or(ErrorType(0), |r| r.code),
            acceptable: rule.map(|r| r.acceptable.clone()).unwrap_or_default(),
            detail: detail.into(),
        }
    }

    /// The refusal of a value case that refines `value-out-of-range` (a command, delivery
    /// state, format or must-be-zero bit): the refined case's ErrorType is adopted, those of
    /// `value-out-of-range` conform too (IEC 61131-9 C.2.9–C.2.11).
    fn reject_value(&self, case: ErrorCase, detail: String) -> Rejection {
        let mut r = self.reject(case, detail);
        if let Some(general) = self.case_rule(ErrorCase::ValueOutOfRange) {
            for code in std::iter::once(general.code).chain(general.acceptable.iter().copied()) {
                if code != r.error && !r.acceptable.contains(&code) {
                    r.acceptable.push(code);
                }
            }
        }
        r
    }

    /// The entry or record an index and sub-index name (manual 3.1).
    pub fn isdu_target(&self, index: u16, subindex: u8) -> Result<Target<'s>, Rejection> {
        let mut entries: Vec<&'s Parameter> = self
            .family
            .parameters
            .iter()
            .filter(|p| p.number == u32::from(index))
            .collect();
        if entries.is_empty() {
            return Err(self.reject(
                ErrorCase::IndexNotAvailable,
                format!("index {index} is not in the object directory"),
            ));
        }
        let record = entries.iter().any(|p| p.subindex.is_some());
        if !record {
            return match (subindex, entries.first()) {
                (0, Some(param)) => Ok(Target::Entry { param }),
                _ => Err(self.reject(
                    ErrorCase::SubindexNotAvailable,
                    format!("index {index} is a single value; sub-index {subindex} does not exist"),
                )),
            };
        }
        if subindex == 0 {
            entries.retain(|p| p.subindex.is_some());
            entries.sort_by_key(|p| p.subindex);
            return Ok(Target::Record { index, entries });
        }
        entries
            .into_iter()
            .find(|p| p.subindex == Some(u32::from(subindex)))
            .map(|param| Target::Entry { param })
            .ok_or_else(|| {
                self.reject(
                    ErrorCase::SubindexNotAvailable,
                    format!("index {index} has no sub-index {subindex}"),
                )
            })
    }

    /// Decodes value octets of a target (manual 3.1; IEC 61131-9 wire order).
    pub fn decode_value(&self, target: &Target<'_>, data: &[u8]) -> Result<Value, ValueError> {
        match target {
            Target::Entry { param } => self.decode_entry(param, data),
            Target::Record { entries, .. } => {
                let mut rest = data;
                let mut items = Vec::with_capacity(entries.len());
                let total: usize = entries
                    .iter()
                    .map(|p| width(p.data_type).unwrap_or(0))
                    .sum();
                let id = || {
                    entries
                        .first()
                        .map_or(String::new(), |p| p.number.to_string())
                };
                for p in entries {
                    let w = width(p.data_type).ok_or_else(|| ValueError::Kind {
                        id: p.id.clone(),
                        expected: "number",
                    })?;
                    let Some((head, tail)) = rest.split_at_checked(w) else {
                        return Err(ValueError::LengthUnderrun {
                            id: id(),
                            expected: total,
                            found: data.len(),
                        });
                    };
                    items.push(self.decode_entry(p, head)?);
                    rest = tail;
                }
                if !rest.is_empty() {
                    return Err(ValueError::LengthOverrun {
                        id: id(),
                        expected: total,
                        found: data.len(),
                    });
                }
                Ok(Value::Record(items))
            }
        }
    }

    fn decode_entry(&self, p: &Parameter, data: &[u8]) -> Result<Value, ValueError> {
        let Some(w) = width(p.data_type) else {
            let max = p.length.and_then(|l| usize::try_from(l).ok());
            if let Some(max) = max.filter(|m| data.len() > *m) {
                return Err(ValueError::LengthOverrun {
                    id: p.id.clone(),
                    expected: max,
                    found: data.len(),
                });
            }
            return match std::str::from_utf8(data) {
                Ok(t) => Ok(Value::Text(t.to_owned())),
                Err(e) => Err(ValueError::NotText {
                    id: p.id.clone(),
                    offset: e.valid_up_to(),
                }),
            };
        };
        if data.len() != w {
            let (expected, found) = (w, data.len());
            return Err(if found > w {
                ValueError::LengthOverrun {
                    id: p.id.clone(),
                    expected,
                    found,
                }
            } else {
                ValueError::LengthUnderrun {
                    id: p.id.clone(),
                    expected,
                    found,
                }
            });
        }
        let raw = self.wire.decode(data).unwrap_or(0);
        let bits = 8 * u32::try_from(w).unwrap_or(8);
        Ok(Value::Int(if p.data_type.signed() {
            let shift = 64 - bits.clamp(1, 64);
            ((raw << shift) as i64) >> shift
        } else {
            i64::try_from(raw).unwrap_or(i64::MAX)
        }))
    }

    /// Encodes a value of a target as ISDU octets (manual 3.1; IEC 61131-9 wire order).
    pub fn encode_value(&self, target: &Target<'_>, value: &Value) -> Result<Vec<u8>, ValueError> {
        match (target, value) {
            (Target::Entry { param }, v) => self.encode_entry(param, v),
            (Target::Record { entries, .. }, Value::Record(items))
                if items.len() == entries.len() =>
            {
                let mut out = Vec::new();
                for (p, v) in entries.iter().zip(items) {
                    out.extend(self.encode_entry(p, v)?);
                }
                Ok(out)
            }
            (Target::Record { index, .. }, _) => Err(ValueError::Kind {
                id: index.to_string(),
                expected: "record",
            }),
        }
    }

    fn encode_entry(&self, p: &Parameter, value: &Value) -> Result<Vec<u8>, ValueError> {
        match (width(p.data_type), value) {
            (Some(w), Value::Int(v)) => {
                let (min, max) = p.data_type.bounds().unwrap_or((0, 0));
                if !(min..=max).contains(v) {
                    return Err(ValueError::Range {
                        id: p.id.clone(),
                        value: *v,
                        min,
                        max,
                    });
                }
                let mut out = vec![0u8; w];
                self.wire.encode(*v as u64, &mut out);
                Ok(out)
            }
            (None, Value::Text(t)) => {
                let max = p.length.and_then(|l| usize::try_from(l).ok());
                match max.filter(|m| t.len() > *m) {
                    Some(expected) => Err(ValueError::LengthOverrun {
                        id: p.id.clone(),
                        expected,
                        found: t.len(),
                    }),
                    None => Ok(t.as_bytes().to_vec()),
                }
            }
            (Some(_), _) => Err(ValueError::Kind {
                id: p.id.clone(),
                expected: "number",
            }),
            (None, _) => Err(ValueError::Kind {
                id: p.id.clone(),
                expected: "text",
            }),
        }
    }

    /// Checks a request as far as no device state is needed (manual 3.1; IEC 61131-9 C.2);
    /// `model` enables the per-model ranges of 3.2.
    pub fn check_request(
        &self,
        request: &Request,
        model: Option<&DeviceModel>,
    ) -> Result<Accepted<'s>, Rejection> {
        match request {
            Request::Read { index, subindex } => self.check_read(*index, *subindex),
            Request::Write {
                index,
                subindex,
                data,
            } => self.check_write(*index, *subindex, data, model),
        }
    }

    /// Checks a read (manual 3.1 R/W column).
    pub fn check_read(&self, index: u16, subindex: u8) -> Result<Accepted<'s>, Rejection> {
        let target = self.isdu_target(index, subindex)?;
        if let Target::Entry { param } = target {
            if !param.access.readable() {
                return Err(self.reject(
                    ErrorCase::ReadWriteOnly,
                    format!("ISDU {} ({}) is write-only", param.id, param.name),
                ));
            }
        }
        Ok(Accepted {
            target,
            value: None,
            command: None,
        })
    }

    /// Checks a write: access, length, type, range, must-be-zero bits, command values
    /// (manual 3.1, 3.2, 3.5).
    pub fn check_write(
        &self,
        index: u16,
        subindex: u8,
        data: &[u8],
        model: Option<&DeviceModel>,
    ) -> Result<Accepted<'s>, Rejection> {
        let target = self.isdu_target(index, subindex)?;
        if let Some(p) = target.entries().into_iter().find(|p| !p.access.writable()) {
            return Err(self.reject(
                ErrorCase::WriteReadOnly,
                format!("ISDU {} ({}) is read-only", p.id, p.name),
            ));
        }
        let value = self.decode_value(&target, data).map_err(|e| {
            let case = match e {
                ValueError::LengthOverrun { .. } => ErrorCase::LengthOverrun,
                ValueError::LengthUnderrun { .. } => ErrorCase::LengthUnderrun,
                _ => ErrorCase::ValueOutOfRange,
            };
            self.reject(case, e.to_string())
        })?;
        let mut command = None;
        let checks: Vec<(&'s Parameter, &Value)> = match (&target, &value) {
            (Target::Entry { param }, v) => vec![(*param, v)],
            (Target::Record { entries, .. }, Value::Record(items)) => {
                entries.iter().copied().zip(items).collect()
            }
            _ => Vec::new(),
        };
        for (p, v) in checks {
            if let Value::Int(v) = v {
                self.check_int(p, *v, model)?;
                if command.is_none() {
                    command = self.command(p, *v);
                }
            }
        }
        Ok(Accepted {
            target,
            value: Some(value),
            command,
        })
    }

    /// Must-be-zero bits, command values and ranges of one numeric entry.
    fn check_int(
        &self,
        p: &Parameter,
        v: i64,
        model: Option<&DeviceModel>,
    ) -> Result<(), Rejection> {
        let mbz = self
            .family
            .bitfields_of(&p.id)
            .fold(0u64, |m, b| m | b.must_be_zero_mask());
        if mbz != 0 && (v as u64) & mbz != 0 {
            return Err(self.reject_value(
                ErrorCase::ReservedBitsSet,
                format!(
                    "ISDU {} = 0x{v:04X} sets must-be-zero bits 0x{:04X}",
                    p.id,
                    (v as u64) & mbz
                ),
            ));
        }
        let commands = self.command_rows(p);
        if self.is_command_param(p) && !commands.iter().any(|c| c.value == v) {
            let offered: Vec<String> = commands.iter().map(|c| c.value.to_string()).collect();
            return Err(self.reject_value(
                ErrorCase::CommandNotAvailable,
                format!(
                    "ISDU {} command {v} is not offered ({})",
                    p.id,
                    offered.join(", ")
                ),
            ));
        }
        if p.range_model && model.is_none() {
            return Ok(());
        }
        let resolved = self.family.resolve(p, model);
        if let Some(range) = resolved.range.filter(|r| !r.contains(v)) {
            let case = [
                ErrorCase::DeliveryStateInvalid,
                ErrorCase::FormatNotSupported,
            ]
            .into_iter()
            .find(|c| self.case_rule(*c).is_some_and(|r| r.params.contains(&p.id)))
            .unwrap_or(ErrorCase::ValueOutOfRange);
            return Err(self.reject_value(case, format!("ISDU {} = {v} outside {range}", p.id)));
        }
        Ok(())
    }

    /// Whether the entry takes command values (`command-not-available` lists it).
    fn is_command_param(&self, p: &Parameter) -> bool {
        self.case_rule(ErrorCase::CommandNotAvailable)
            .is_some_and(|r| r.params.contains(&p.id))
    }

    /// The command rows of an entry: its own, or for another entry of the
    /// `command-not-available` case (Direct Parameter SystemCommand) those of the case
    /// (manual 3.1 ISDU 0 sub 16, ISDU 2, ISDU 193).
    pub fn command_rows(&self, p: &Parameter) -> Vec<&'s StateCommand> {
        let rows = &self.protocol.commands.commands;
        let own: Vec<&'s StateCommand> = rows.iter().filter(|c| c.param == p.id).collect();
        if !own.is_empty() || !self.is_command_param(p) {
            return own;
        }
        let group = self
            .case_rule(ErrorCase::CommandNotAvailable)
            .map(|r| r.params.clone())
            .unwrap_or_default();
        rows.iter().filter(|c| group.contains(&c.param)).collect()
    }

    /// The command a write of `value` to `p` triggers (manual 3.1 ISDU 2, ISDU 193).
    pub fn command(&self, p: &Parameter, value: i64) -> Option<&'s StateCommand> {
        self.command_rows(p).into_iter().find(|c| c.value == value)
    }

    /// What a value read back from a readable command entry means (ISDU 193: after boot and
    /// after a save; manual 3.1, PSX-ERRATUM-005).
    pub fn readbacks(&self, p: &Parameter, value: i64) -> Vec<&'s Readback> {
        if !p.access.readable() || self.command_rows(p).is_empty() {
            return Vec::new();
        }
        let which = if value == 0 { "zero" } else { "nonzero" };
        self.protocol
            .commands
            .readbacks
            .iter()
            .filter(|r| r.value == which)
            .collect()
    }
}
