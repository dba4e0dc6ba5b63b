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
//! The positioning core both families share (PSD4xx chapter 4, PSx3xx chapters 4–5), a
//! sans-IO state machine on virtual time configured by a family description:
//!
//! - [`axis`]: position arithmetic: scaling, referencing value, mapping end, limits and the
//!   recalculation cascades (PSD4xx 4.7, 4.8).
//! - [`profile`]: the trapezoidal motion profile with the harmonious end (PSD4xx 4.3).
//! - [`status`]: status flags and their bits in a family's status word (PSD4xx 3.6).
//! - [`mod@env`]: the environment as an explicit input (supplies, temperature, obstructions,
//!   external rotation, faults).
//! - [`config`]: the family description ([`CoreConfig`]).
//! - [`machine`]: the state machine ([`Positioner`]): runs, reference loop, faults, status.
//! - [`script`]: the `sim-run` script grammar, expectations and traces every family shares.
//! - [`step`]: the start state, waits and typed reading of the `sequence` vectors every
//!   cyclic family shares.
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

pub mod axis;
pub mod config;
pub mod env;
pub mod machine;
pub mod profile;
pub mod script;
pub mod status;
pub mod step;

pub use bits::{decode_bits, BitsDecoded, NamedWord, SetBit};
pub use code::{CodeEntry, CodeTable, CodeTableError, Named, WireCode};
pub use field::{Field, FieldError};
pub use order::{ByteOrder, ByteOrderParseError};

pub use axis::{Axis, AxisConfig, AxisError, AxisValues};
pub use config::CoreConfig;
pub use env::{EnvChange, Environment};
pub use machine::{Command, CoreEvent, Micros, Positioner, RunKind, Setting, Settings};
pub use status::{BitMap, Flag, Flags};

/// Re-exported for the [`open_enum!`] macro (serde impls of the generated newtypes).
#[doc(hidden)]
pub use serde as __serde;
