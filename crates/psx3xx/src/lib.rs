//! The halstrup-walcher PSE/PSS/PSW 3xx over IO-Link (manual chapter 3, 4.4–4.6): process
//! images of the three output formats and the input, time stamps, byte-order detection, ISDU
//! access to the object directory with IO-Link ErrorTypes, guard entries, ISDU 2 / 193
//! commands, and Direct Parameter page 1.
//!
//! Everything numeric comes from the spec (`spec/psx3xx`) through [`Rules`]: image layouts,
//! field types, the time-stamp unit and limits, command and error codes, the Direct Parameter
//! encodings. Names are the contract with the spec (field `control_word`, error case
//! `value-out-of-range`, entry `MinCycleTime`).
//!
//! Layers, smoltcp style: [`wire`] holds checked views over image bytes, [`repr`] the typed
//! [`Output`] / [`Input`] with `parse` / `emit`; [`explain`] describes an image for people
//! (text) and programs (JSON, shape documented there).
//!
//! Guarantees: sans-IO (nothing touches a port, a socket or the clock); no decoder panics on
//! any input; allocation is bounded by the input and the spec tables. Process images have a
//! fixed length per format, so decoding is `Ok` or a typed error (`Truncated { need, have }`,
//! `TrailingData`), never "incomplete".
//!
//! ```
//! use drivespec_psx3xx::{explain_output, ByteOrder, Output, Rules};
//!
//! let spec = drivespec_spec::Spec::builtin()?;
//! let rules = Rules::from_spec(&spec)?;
//! // Format 1: control word 0x14 (release and transfer), target 51200 (manual 4.5.1).
//! let out = Output::from_fields(&rules, 1, &[("control_word", 0x14), ("target", 51200)])?;
//! assert_eq!(out.to_bytes(&rules, ByteOrder::BigEndian)?, [0x00, 0x14, 0x00, 0x00, 0xC8, 0x00]);
//! // Format 0: code 3 with stamp 10000 executes the positioning 40 ms later (manual 4.4.1).
//! let e = explain_output(&rules, 0, rules.wire_order(), None, &[0x9C, 0x43])?;
//! assert_eq!(e.fields[1].text, "10000: executes in 40.000 ms");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]

pub mod detect;
pub mod direct;
mod error;
pub mod explain;
pub mod guard;
pub mod isdu;
pub mod model;
pub mod repr;
pub mod rules;
pub mod scenario;
pub mod script;
pub mod step;
pub mod timestamp;
pub mod wire;

pub use detect::{detect_order, Detection, Evidence, EvidenceKind};
pub use direct::{DirectPage, DpEntry, DpFieldValue};
pub use drivespec_positioner::ByteOrder;
pub use error::{
    BuildError, DirectError, EmitError, ErrorTypeError, ImageError, RulesError, ValueError,
};
pub use explain::{explain_input, explain_output, explain_value, Explained, FieldExplained};
pub use guard::{Guard, GuardReading, Guards, WriteFate};
pub use isdu::{
    Accepted, CaseRule, ErrorCase, ErrorType, ErrorTypes, Rejection, Request, Response, Target,
    Value,
};
pub use repr::{parse_assignments, parse_field_value, Input, Output, OutputKind, TsCode, TsCodes};
pub use rules::{OutputLayout, Rules};
pub use timestamp::{Stamp, StampMeaning};
