//! Why a model drive cannot be built or cannot do what a test asked (manual 4, 3.3).

use crate::params::ParamError;
use crate::rules::RulesError;

/// Why the drive model cannot be built or cannot do what was asked (manual 4.1, 4.2, 3.3).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The spec's frame or PLC tables are unusable (manual 4.1, 3.8.1).
    #[error(transparent)]
    Rules(#[from] RulesError),
    /// The spec lacks a parameter, bit or table the model needs (manual 4.2, 3.4).
    #[error("spec: {what}")]
    Spec {
        /// What is missing or malformed.
        what: String,
    },
    /// A baud-rate code the Pr26 table does not list (manual 4 table).
    #[error("Pr26 code {code} is not in the baud-rate table")]
    BaudCode {
        /// The code given.
        code: u8,
    },
    /// A serial address outside the frame's address range (manual 4.1, Pr27).
    #[error("serial address {addr} outside 0..={max}")]
    Address {
        /// The address given.
        addr: u8,
        /// Largest address.
        max: u8,
    },
    /// An alarm code the alarm table does not list (manual 3.3).
    #[error("alarm code {code} is not in the alarm table")]
    Alarm {
        /// The code given.
        code: u8,
    },
    /// The appendix G program of the spec does not assemble (manual appendix G, 4.1).
    #[error("appendix G program, line {line}: {what}")]
    DefaultProgram {
        /// 1-based line of `protocol.default_program`.
        line: usize,
        /// What is wrong.
        what: String,
    },
    /// A parameter reference the model cannot use (manual 4.2).
    #[error(transparent)]
    Param(#[from] ParamError),
}
