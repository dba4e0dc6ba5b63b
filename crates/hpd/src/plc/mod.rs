//! The pico-PLC (manual 3.8.1, 4.1 "PLC instructions", appendix G): instruction codec,
//! listing text, program checks and the interpreter.

mod codec;
mod interp;
mod listing;
mod program;

pub use codec::{Instr, Operands, OutsideArea, PlcCodec, PlcError};
pub use interp::{PlcRuntime, PlcState, ZeroFlag};
pub use listing::ListingError;
pub use program::{Effects, Program, ProgramIssue};
