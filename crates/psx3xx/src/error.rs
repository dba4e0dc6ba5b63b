//! Errors of the PSx3xx codec (manual 3.1, 3.3; IEC 61131-9 B.1, annex C).

/// Why bytes are not a process image of the expected kind (manual 3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ImageError {
    /// The bytes end before the image does.
    #[error("truncated: the image needs {need} bytes, have {have}")]
    Truncated {
        /// Image length in bytes.
        need: usize,
        /// Bytes present.
        have: usize,
    },
    /// Bytes follow the image.
    #[error("{extra} byte(s) after the end of the {length}-byte image")]
    TrailingData {
        /// Image length in bytes.
        length: usize,
        /// Number of extra bytes.
        extra: usize,
    },
    /// No output image has this ISDU 116 format.
    #[error("no process output format {format} (ISDU 116)")]
    UnknownFormat {
        /// The format asked for.
        format: u8,
    },
}

/// Why a value cannot be written into a process image (manual 3.3).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum EmitError {
    /// The image has no field of this name.
    #[error("the image has no field {field:?}")]
    NoField {
        /// Field name given.
        field: String,
    },
    /// The value does not fit the field.
    #[error("{field} = {value} outside {min}..={max}")]
    Range {
        /// Spec name of the field.
        field: String,
        /// Value given.
        value: i64,
        /// Smallest value the field holds.
        min: i64,
        /// Largest value the field holds.
        max: i64,
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

/// Why named fields do not make a process image (manual 3.3).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum BuildError {
    /// No output image has this ISDU 116 format.
    #[error("no process output format {format} (ISDU 116)")]
    UnknownFormat {
        /// The format asked for.
        format: u8,
    },
    /// The image has no field of this name.
    #[error("the {image} image has no field {field:?}; fields: {known}")]
    UnknownField {
        /// Field name given.
        field: String,
        /// Spec name of the image.
        image: String,
        /// The image's field names, comma separated.
        known: String,
    },
    /// A field without a neutral value was not given.
    #[error("field {field:?} of the {image} image is required")]
    MissingField {
        /// Field name.
        field: String,
        /// Spec name of the image.
        image: String,
    },
    /// A field was given twice.
    #[error("field {field:?} given twice")]
    DuplicateField {
        /// Field name.
        field: String,
    },
    /// A field value is not a number or a name the spec knows for it.
    #[error("field {field:?}: cannot read {text:?} as a number or a known name")]
    BadValue {
        /// Field name.
        field: String,
        /// The text given.
        text: String,
    },
    /// The value does not fit its field.
    #[error(transparent)]
    Emit(#[from] EmitError),
}

/// Why ISDU data is not a value of an entry (manual 3.1; IEC 61131-9 C.2.12, C.2.13).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ValueError {
    /// More bytes than the entry's data type has.
    #[error("ISDU {id}: {found} data bytes, the entry has {expected}")]
    LengthOverrun {
        /// Parameter id.
        id: String,
        /// Bytes of the entry (largest string length for strings).
        expected: usize,
        /// Bytes present.
        found: usize,
    },
    /// Fewer bytes than the entry's data type has.
    #[error("ISDU {id}: {found} data bytes, the entry needs {expected}")]
    LengthUnderrun {
        /// Parameter id.
        id: String,
        /// Bytes of the entry.
        expected: usize,
        /// Bytes present.
        found: usize,
    },
    /// A string value that is not UTF-8.
    #[error("ISDU {id}: string data is not UTF-8 from offset {offset}")]
    NotText {
        /// Parameter id.
        id: String,
        /// Offset of the first byte that is not UTF-8.
        offset: usize,
    },
    /// A number where the entry holds text or the other way round.
    #[error("ISDU {id}: a {expected} value is needed")]
    Kind {
        /// Parameter id.
        id: String,
        /// `number`, `text` or `record`.
        expected: &'static str,
    },
    /// The number does not fit the entry's data type.
    #[error("ISDU {id}: {value} outside {min}..={max} of its data type")]
    Range {
        /// Parameter id.
        id: String,
        /// Value given.
        value: i64,
        /// Smallest value of the type.
        min: i64,
        /// Largest value of the type.
        max: i64,
    },
}

/// Why an ISDU error response is not two octets (IEC 61131-9 annex C).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ErrorTypeError {
    /// Fewer than two octets.
    #[error("truncated ErrorType: need {need} bytes, have {have}")]
    Truncated {
        /// Octets of an ErrorType.
        need: usize,
        /// Octets present.
        have: usize,
    },
    /// More than two octets.
    #[error("{extra} byte(s) after the ErrorType")]
    TrailingData {
        /// Number of extra bytes.
        extra: usize,
    },
}

/// Why Direct Parameter page 1 bytes cannot be decoded or built (manual 3.1 ISDU 0).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum DirectError {
    /// The bytes run past the last page address.
    #[error("{len} byte(s) from address {first:#04x} run past the page end {end:#04x}")]
    PastEnd {
        /// Address of the first byte.
        first: u8,
        /// Number of bytes.
        len: usize,
        /// First address after the page.
        end: usize,
    },
    /// No output format of this number (ISDU 116).
    #[error("no process data format {format} (ISDU 116)")]
    UnknownFormat {
        /// The format asked for.
        format: u8,
    },
    /// The device ID of this model code does not fit its octets.
    #[error("model code {model_code} gives no device ID of {octets} octets")]
    DeviceId {
        /// Model code (ISDU 79).
        model_code: u32,
        /// Octets of the device ID.
        octets: u32,
    },
}

/// The spec's PSx3xx tables lack something the codec needs (manual 3.1, 3.3).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum RulesError {
    /// The spec has no PSx3xx protocol table.
    #[error("the spec has no PSx3xx protocol table")]
    NoProtocol,
    /// A process image or field the codec needs is missing or malformed.
    #[error("process image {image}: {what}")]
    Image {
        /// Spec name of the image.
        image: String,
        /// What is wrong.
        what: String,
    },
    /// A table the codec needs is missing an entry or is inconsistent.
    #[error("{table}: {what}")]
    Table {
        /// Which table.
        table: &'static str,
        /// What is wrong.
        what: String,
    },
    /// A code table is unusable.
    #[error(transparent)]
    Codes(#[from] drivespec_positioner::CodeTableError),
}
