//! The HPD reference drive model (manual chapter 4, 3.3–3.4, 3.6, 3.8, appendix G): the oracle
//! for conformance runs and trace checks.
//!
//! Sans-IO with explicit virtual time, after quinn-proto: the caller feeds line bytes
//! ([`Drive::handle_rx`]), digital inputs ([`Drive::set_inputs`]) and the passing of time
//! ([`Drive::advance`]), then drains [`Drive::poll_output`] and sleeps until
//! [`Drive::poll_timeout`]. Nothing here reads a clock, spawns a thread or touches a port; the
//! same inputs always give the same outputs.
//!
//! Every number (serial addresses, lengths, defaults, ranges, baud codes, time-outs, alarm
//! codes, PLC timing, the appendix G program) comes from the spec; `names.rs` holds the few
//! bit and parameter names the spec's protocol tables do not name.
//!
//! Nothing here panics. Memory is bounded by the parameter and PLC areas plus the queued
//! outputs the caller has not drained. [`Drive::advance`] costs one PLC scan per 6.144 ms of
//! virtual time (and one FIN copy per 512 µs while a FIN instruction runs), so its cost grows
//! with the time skipped.

mod access;
mod commands;
mod config;
mod drive;
mod error;
mod layout;
mod motor;
mod names;
mod output;
mod scan;
mod serial;

pub use config::{DriveConfig, Start};
pub use drive::Drive;
pub use error::ModelError;
pub use motor::MotionStyle;
pub use output::{Alarms, LineSettings, Output};
