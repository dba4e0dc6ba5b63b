//! Errors of the PSD4xx codec (manual 3.2, 3.5, 3.8). Every variant carries the data needed
//! to act on it.

use crate::repr::Direction;
use drivespec_positioner::{CodeTableError, FieldError};

/// Why bytes are not a PSD4xx image, PKW block or record (manual 3.2.2, 3.5, 3.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum DecodeError {
    /// Fewer bytes than the image, block or record needs.
    #[error("truncated: need {need} bytes, have {have}")]
    Truncated {
        /// Length required.
        need: usize,
        /// Length given.
        have: usize,
    },
    /// More bytes than the image, block or record holds.
    #[error("trailing data: expected {expected} bytes, have {have}")]
    TrailingData {
        /// Length expected.
        expected: usize,
        /// Length given.
        have: usize,
    },
    /// A record index that names no parameter of the spec (3.2.2: index = parameter number).
    #[error("record index {index} names no parameter")]
    UnknownIndex {
        /// The index.
        index: u16,
    },
    /// A parameter whose type has no record length in the spec's record table (3.2.2).
    #[error("record index {index}: no record length for the parameter's type")]
    NoRecordLength {
        /// The index.
        index: u16,
    },
}

/// Why a representation cannot be written as bytes (manual 3.5, 3.8, 3.2.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum EmitError {
    /// The output buffer is too small.
    #[error("buffer of {have} bytes, need {need}")]
    Buffer {
        /// Bytes needed.
        need: usize,
        /// Bytes available.
        have: usize,
    },
    /// A value does not fit its bits (AK in 4 bits, PNU in 11 bits, 3.8 PKE format).
    #[error("{field} = {value} does not fit, largest is {max}")]
    FieldRange {
        /// Field name (`ak`, `pnu`, `spm`).
        field: &'static str,
        /// Value given.
        value: u64,
        /// Largest value.
        max: u64,
    },
    /// A parameter value outside what its width holds (3.2.2, 3.8).
    #[error("value {value} outside {min}..={max}")]
    Value {
        /// Value given.
        value: i64,
        /// Smallest value.
        min: i64,
        /// Largest value.
        max: i64,
    },
    /// A string longer than the parameter (3.3 par. 13).
    #[error("text of {len} bytes, the parameter holds {max}")]
    TextLength {
        /// Length given.
        len: usize,
        /// Largest length.
        max: usize,
    },
}

/// The spec's PSD4xx tables lack something the codec needs, or contradict themselves
/// (manual 3.2, 3.5, 3.8).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum RulesError {
    /// The spec has no PSD4xx protocol table.
    #[error("the spec has no PSD4xx protocol table")]
    NoProtocol,
    /// A field the codec needs is missing from a layout.
    #[error("{table} layout: no field {name:?}")]
    MissingField {
        /// `output`, `input` or `pkw`.
        table: &'static str,
        /// Field name.
        name: &'static str,
    },
    /// A field has another length than its value type.
    #[error("{table} layout: field {name:?} is {found} bytes, expected {expected}")]
    FieldWidth {
        /// `output`, `input` or `pkw`.
        table: &'static str,
        /// Field name.
        name: String,
        /// Length the value type needs.
        expected: usize,
        /// Length in the spec.
        found: usize,
    },
    /// A field reaches past the end of its module.
    #[error("{table} layout: field {name:?} ends at {end}, the module has {length} bytes")]
    FieldBounds {
        /// `output`, `input` or `pkw`.
        table: &'static str,
        /// Field name.
        name: String,
        /// End offset of the field.
        end: usize,
        /// Module length.
        length: usize,
    },
    /// Two fields share bytes.
    #[error("{table} layout: fields {a:?} and {b:?} overlap")]
    Overlap {
        /// `output`, `input` or `pkw`.
        table: &'static str,
        /// First field.
        a: String,
        /// Second field.
        b: String,
    },
    /// A field length the codec cannot handle.
    #[error("{table} layout: field {name:?}: {error}")]
    Field {
        /// `output`, `input` or `pkw`.
        table: &'static str,
        /// Field name.
        name: String,
        /// What is wrong.
        error: FieldError,
    },
    /// A PKE bit range is missing or unusable (3.8 PKE format).
    #[error("PKE bits: {what}")]
    PkeBits {
        /// What is wrong.
        what: &'static str,
    },
    /// A code table is unusable or lacks a code (3.8).
    #[error(transparent)]
    Codes(#[from] CodeTableError),
    /// A table entry contradicts the others (3.8, 3.2.2).
    #[error("{table}: {what}")]
    Table {
        /// Table name.
        table: &'static str,
        /// What is wrong.
        what: String,
    },
    /// A bitfield the explanation needs is missing (3.6, 3.7).
    #[error("no bitfield {id:?} in the spec")]
    MissingBitfield {
        /// Bitfield id.
        id: &'static str,
    },
}

/// Why a `--pkw` text or a typed request/reply cannot be turned into a PKW block (manual 3.8).
///
/// Syntax (requests): `none`, `read:44`, `read:13[2]`, `write:44=5`, `write:13[1]=0x50`,
/// `count:13`, or a command's spec name as the verb (`write-dword:44=10`). Replies: `none`,
/// `value:44=2`, `value:13[0]=0x50534434`, `count:13=5`, `error:44=2` or
/// `error:44=out-of-range`, or a response's spec name as the verb.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum RequestError {
    /// Nothing given.
    #[error("empty PKW text")]
    Empty,
    /// A verb that is neither a generic one nor a spec name.
    #[error("unknown PKW verb {verb:?} (expected {expected})")]
    UnknownVerb {
        /// The verb.
        verb: String,
        /// The verbs allowed.
        expected: String,
    },
    /// The text does not follow the syntax.
    #[error("PKW text {text:?}: expected {expected} at offset {offset}")]
    Syntax {
        /// The whole text.
        text: String,
        /// Byte offset of the problem.
        offset: usize,
        /// What was expected.
        expected: &'static str,
    },
    /// A number that does not parse.
    #[error("{what} {found:?} is not a number")]
    Number {
        /// What the number is (`PNU`, `index`, `value`).
        what: &'static str,
        /// The text.
        found: String,
    },
    /// A parameter number beyond the PNU bits (3.8: 11 bits).
    #[error("PNU {pnu} does not fit, largest is {max}")]
    PnuRange {
        /// Number given.
        pnu: i64,
        /// Largest PNU.
        max: u64,
    },
    /// A subindex beyond the IND layout.
    #[error("index {index} does not fit, largest is {max}")]
    IndexRange {
        /// Index given.
        index: i64,
        /// Largest index.
        max: u64,
    },
    /// The verb needs `=value`.
    #[error("{verb} needs a value (`=…`)")]
    MissingValue {
        /// The verb.
        verb: String,
    },
    /// The verb takes no `=value`.
    #[error("{verb} takes no value")]
    UnexpectedValue {
        /// The verb.
        verb: String,
    },
    /// The command addresses an array element and needs `[index]`.
    #[error("{verb} needs an array index (`[…]`)")]
    MissingIndex {
        /// The verb.
        verb: String,
    },
    /// The command takes no array index.
    #[error("{verb} takes no array index")]
    UnexpectedIndex {
        /// The verb.
        verb: String,
    },
    /// Word or double word cannot be told: the parameter is unknown or not numeric.
    #[error("par {pnu}: width unknown; name the command (write-word, write-dword …)")]
    UnknownWidth {
        /// The parameter number.
        pnu: u16,
    },
    /// The value does not fit the parameter's type.
    #[error("value {value} outside {min}..={max}")]
    ValueRange {
        /// Value given.
        value: i64,
        /// Smallest value.
        min: i64,
        /// Largest value.
        max: i64,
    },
    /// An error name the spec's error table does not list.
    #[error("unknown PKW error {name:?}")]
    UnknownError {
        /// The name.
        name: String,
    },
    /// The spec's tables have no code for this kind of request or reply.
    #[error("the spec lists no PKW code for {what}")]
    NoCode {
        /// The kind of request or reply.
        what: String,
    },
}

/// Why a request cannot be queued in the PKW client (manual 3.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ClientError {
    /// Queued requests and uncollected results fill the capacity.
    #[error("PKW client full: {capacity} requests pending or uncollected")]
    Full {
        /// The capacity.
        capacity: usize,
    },
    /// "No command" is sent between requests by the client itself (3.8).
    #[error("\"no command\" is not a request")]
    NotACommand,
}

/// Why an image cannot be built from named fields (manual 3.5).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum BuildError {
    /// No field of that name in the module.
    #[error("the {direction} image has no field {name:?} (fields: {known})")]
    UnknownField {
        /// Image direction.
        direction: Direction,
        /// The name given.
        name: String,
        /// The field names of the module.
        known: String,
    },
    /// The value does not fit the field.
    #[error("field {name:?}: {error}")]
    Field {
        /// Field name.
        name: String,
        /// What is wrong.
        error: FieldError,
    },
    /// The PKW text is wrong.
    #[error(transparent)]
    Pkw(#[from] RequestError),
    /// The PKW block cannot be written.
    #[error(transparent)]
    Emit(#[from] EmitError),
}
