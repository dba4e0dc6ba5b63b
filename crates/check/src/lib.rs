//! Trace checkers: spec violations in recorded traffic of the three drive families,
//! each with the requirement ID and text, where it happened (frame number or byte offset,
//! time) and the evidence.
//!
//! - [`hpd`]: HPD serial lines (manual chapter 4): framing, pairing, time-outs, parameter
//!   memory, PLC uploads.
//!
//! Checkers are pure functions over event streams (style rule 12, after stateright):
//! `check(&Spec, options, events) -> Result<Report, SetupError>`, where a read error inside
//! the stream ends it and is kept in [`Report::error`], everything before it checked. They
//! stream with memory bounded whatever the input size, never read a clock, and never panic.
#![forbid(unsafe_code)]

pub mod error;
pub mod hpd;
pub mod iolink;
pub mod locate;
pub mod ndjson;
pub mod pn_events;
pub mod pnio_names;
pub mod profinet;
pub mod psd4xx;
pub mod render;
pub mod report;
pub mod run;
pub mod synth;
pub mod timeline;

pub use error::SetupError;
pub use report::{
    Catalog, Evidence, Observation, Policy, Report, Scope, Verdict, Violation, Where,
    DEFAULT_MAX_VIOLATIONS, MAX_LISTED_PER_REQUIREMENT,
};
