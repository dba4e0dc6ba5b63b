//! The PSD4xx reference drive model (manual 3.2–3.9, chapter 4): the oracle that conformance
//! runs, trace checks and the fuzzer compare implementations against.
//!
//! Sans-IO with explicit virtual time, after quinn-proto: the caller feeds output images
//! ([`Drive::handle_image`]), acyclic records ([`Drive::handle_record`]), connection events
//! ([`Drive::handle_link`]), environment changes ([`Drive::handle_env`]) and the passing of
//! time ([`Drive::advance`]), each with a timestamp in µs, then drains [`Drive::poll_input`],
//! [`Drive::poll_record`] and [`Drive::poll_event`] and sleeps until [`Drive::poll_timeout`].
//! Nothing here reads a clock, spawns a thread or touches a socket; the same inputs always
//! give the same outputs, and a 30-second run simulates in milliseconds.
//!
//! The positioning behaviour lives in the shared core
//! ([`drivespec_positioner::Positioner`]); this module adds what is PSD4xx: the process-data
//! control word, the PKW server (one command at a time, held until the next one), records with
//! their control byte, parameters with per-model ranges and delivery values, the EEPROM image
//! apart from the working values, par. 96, and the output behaviour of 3.9 and 4.9. Every
//! number comes from the spec; decisions where the manual is silent are marked DECISION.
//!
//! Nothing here panics. Memory is bounded: queues keep at most [`MAX_QUEUED`] entries.

mod config;
mod drive;
mod error;
mod family;
mod io;

pub use config::DriveConfig;
pub use drive::{Drive, MAX_QUEUED};
pub use error::ModelError;
pub use io::{Event, LinkEvent, RecordAnswer, RecordFailure, RecordRequest, RecordResponse};
