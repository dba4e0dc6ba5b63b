//! The drivespec conformance runner: cases generated from the spec, a differential oracle
//! (the family's reference model fed the same inputs as the device under test), transports to
//! the device, and reports (JUnit XML, JSON, self-contained HTML).
//!
//! - [`suite`]: the [`suite::Suite`]/[`suite::Session`] traits a family implements; HPD in
//!   [`hpd`], PSD4xx in [`psd4xx`], PSx3xx in [`psx3xx`] (the last two over the
//!   cyclic-exchange protocol of [`cyclic`], run by [`cyclic_session`]). `drivespec-fuzz` runs
//!   its sequences through these sessions.
//! - [`link`]: the transports (`serial`, `tcp`, `exec`) behind [`link::Link`] (the crate
//!   `drivespec-link`); `--dut sim` runs the reference models of `drivespec-sim`.
//! - [`runner`]: selection, expectations, progress, reports; [`runner::run`] is what the CLI
//!   calls.
//! - [`report`]: the report model and its renderings (schema in the crate
//!   README, "JSON report").
//!
//! Nothing here panics on any input or device behaviour; every wait is bounded by a deadline.
#![forbid(unsafe_code)]

pub mod bar;
pub mod case;
pub mod cyclic;
pub mod cyclic_session;
pub mod dut;
pub mod hpd;
pub mod psd4xx;
pub mod psx3xx;
pub mod report;
pub mod runner;
pub mod select;
pub mod suite;

pub use drivespec_link as link;
use drivespec_sim::rng;

pub use runner::{run, ConformError, Options, Progress, Summary};
