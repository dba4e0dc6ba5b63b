//! The PSx3xx reference drive model (manual chapters 3–5): the oracle that conformance runs,
//! trace checks and the fuzzer compare implementations against.
//!
//! Sans-IO with explicit virtual time, after quinn-proto: the caller feeds process output
//! images in the active format ([`Drive::handle_image`], [`Drive::handle_output`]), ISDU
//! requests ([`Drive::handle_isdu`]), IO-Link communication events ([`Drive::handle_link`]),
//! jog keys ([`Drive::handle_keys`]), environment changes ([`Drive::handle_env`]) and the
//! passing of time ([`Drive::advance`]), each with a timestamp in µs, then drains
//! [`Drive::poll_input`], [`Drive::poll_isdu`] and [`Drive::poll_event`] and sleeps until
//! [`Drive::poll_timeout`]. Nothing here reads a clock, spawns a thread or touches a port; the
//! same inputs always give the same outputs.
//!
//! The positioning behaviour lives in the shared core ([`drivespec_positioner::Positioner`]),
//! configured by the PSx3xx family description built from the spec (256-revolution encoder
//! with 250 usable, ISDU numbers, per-model ranges and defaults). This module adds what is
//! PSx3xx: the three process-data formats and the format switch after a restart, time-stamp
//! execution, the run-start rules of 5.3, the 8-byte format's speed rules and the CW/CCW speed
//! caps, jog keys and jog bits, brakes, the drag error and its correction, the initial
//! reference loop, the ISDU server with guard entries, ISDU 2 / 193 with the EEPROM image kept
//! apart from the working values, the three master time-out behaviours of 5.9, the idle
//! period before a reversal (ISDU 162) and the three LEDs of 2.6 ([`Drive::leds`]). Every
//! number comes from the spec; erratum readings come from [`drivespec_spec::Readings`];
//! decisions where the manual is silent are marked DECISION.
//!
//! Nothing here panics. Memory is bounded: queues keep at most [`MAX_QUEUED`] entries.

mod config;
mod control;
mod drive;
mod error;
mod family;
mod io;
mod server;

pub use config::{BrakeKind, DriveConfig};
pub use drive::{Drive, MAX_QUEUED};
pub use error::ModelError;
pub use io::{Event, IsduAnswer, JogKeys, LedLight, Leds, LinkEvent, RunState};
