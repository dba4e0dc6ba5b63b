//! The halstrup-walcher PSD4xx over PROFINET IO (manual "PSD4xx PROFINET bus description",
//! chapter 3): cyclic process data with the PKW parameter channel, and acyclic records.
//!
//! - [`wire`]: checked views of the 14-byte output and 16-byte input modules and the 8-byte
//!   PKW block, with field positions from the spec (3.5, 3.8).
//! - [`Output`], [`Input`]: the typed modules (3.5.1, 3.5.2); [`ImageBuilder`] builds images
//!   from named fields.
//! - [`pkw`]: the PKW block, its open-enum codes from the spec's tables, typed requests and
//!   replies, the `--pkw` mini-syntax (3.8).
//! - [`PkwClient`]: the controller's side of the PKW handshake, sans-IO, one bus cycle at a time.
//! - [`record`]: acyclic read and write records (3.2.2).
//! - [`mod@explain`]: every field of an image by name, in words and as stable JSON.
//! - [`model`]: the reference drive on virtual time (3.2–3.9, chapter 4).
//! - [`script`]: `sim-run`: the family's script commands and the runner over [`model`].
//!
//! Everything numeric (offsets, lengths, codes, bit positions, record lengths) is read from the
//! spec through [`Rules`]; the byte order and the PKW word and index layouts are [`Options`]
//! defaulting to the spec's adopted readings.
//!
//! Guarantees: sans-IO (no sockets, no clock); no `unsafe`; no decoder panics on any input;
//! decoding allocates nothing except a record string (bounded by the parameter's length) and
//! [`explain()`] output (bounded by the spec's tables).
#![forbid(unsafe_code)]

mod client;
mod error;
pub mod explain;
pub mod model;
pub mod pkw;
pub mod record;
mod repr;
mod rules;
pub mod script;
pub mod step;
mod value;
pub mod wire;

pub use client::{ClientConfig, Completion, Outcome, Phase, PkwClient, RequestId};
pub use error::{BuildError, ClientError, DecodeError, EmitError, RequestError, RulesError};
pub use explain::{explain, explain_pkw, Explanation};
pub use pkw::{
    parse_number, CommandCode, ErrorCode, Pkw, PkwRequest, PkwResponse, PkwRules, Reply, Request,
    ResponseCode, Verdict,
};
pub use record::{RecordRead, RecordRules, RecordShape, RecordValue, RecordWrite};
pub use repr::{Direction, ImageBuilder, Input, Output};
pub use rules::{Options, Rules};
pub use value::{Params, Width};
