//! The Parker HPD serial protocol (manual chapter 4) and pico-PLC (3.8, appendix G).
//!
//! Sans-IO: nothing here touches a port, a socket or the clock. Decoders never panic on any
//! input and use bounded memory.
#![forbid(unsafe_code)]

mod error;
mod exchange;
pub mod explain;
mod line;
pub mod memory;
pub mod model;
pub mod params;
pub mod plc;
mod repr;
mod rules;
pub mod step;
mod wire;

pub use error::{EmitError, FrameError};
pub use exchange::{Exchange, Mismatch, Pairer};
pub use line::{Discard, DiscardReason, FrameEvent, LineDecoder, LineEvent, Micros};
pub use repr::{Data, Message, MAX_FRAME};
pub use rules::{FrameRules, MessageKind, RulesError};
pub use wire::{decode, next_start, parse, AckEnd, DecodeError, Decoded, Status};
