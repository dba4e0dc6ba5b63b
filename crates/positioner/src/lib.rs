//! What the halstrup-walcher positioning drives (PSD4xx over PROFINET, PSx3xx over IO-Link)
//! share at the codec level.
//!
//! - [`order`]: the byte order of multi-byte values as a setting (PSD4xx manual 3.5 notice
//!   "UseAsBits", PSx3xx manual 3.3.2), since engineering tools and masters differ.
//! - [`field`]: a checked view of one integer inside a process image (offset, length, order).
//! - [`code`]: open enums over wire codes, rustls style: a newtype over the raw code, names
//!   looked up in the spec's tables; unknown codes decode and re-encode unchanged.
//! - [`bits`]: a status or control word decoded against a spec [`Bitfield`]
//!   (PSD4xx manual 3.6/3.7, PSx3xx manual 3.5): the named bits set and the
//!   must-be-zero violations.
//!
//! Guarantees: nothing here panics on any input, and nothing touches a port, a socket or the
//! clock. Allocation is bounded by the spec tables (names) and by the width of a word
//! (at most 64 bits listed).
//!
//! [`Bitfield`]: drivespec_spec::Bitfield
#![forbid(unsafe_code)]

pub mod bits;
pub mod code;
pub mod field;
pub mod order;

pub use bits::{decode_bits, BitsDecoded, NamedWord, SetBit};
pub use code::{CodeEntry, CodeTable, CodeTableError, Named, WireCode};
pub use field::{Field, FieldError};
pub use order::{ByteOrder, ByteOrderParseError};

/// Re-exported for the [`open_enum!`] macro (serde impls of the generated newtypes).
#[doc(hidden)]
pub use serde as __serde;
