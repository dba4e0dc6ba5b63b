//! Why a PSx3xx model drive cannot be built (manual 3.1, 3.2).

use crate::RulesError;
use drivespec_positioner::status::BitMapError;

/// Why the PSx3xx drive model cannot be built (manual 3.1, 3.2, 3.4).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The spec's codec tables are unusable (3.1, 3.3).
    #[error(transparent)]
    Rules(#[from] RulesError),
    /// No model of table 3.2 matches the name.
    #[error("unknown PSx3xx model {model:?}; known: {known}")]
    UnknownModel {
        /// The name given.
        model: String,
        /// The model ids there are.
        known: String,
    },
    /// The model is not offered with the brake asked for (5.12, 5.13).
    #[error("model {model} is not offered with a {brake} brake")]
    NoSuchBrake {
        /// The model id.
        model: String,
        /// The brake kind asked for.
        brake: &'static str,
    },
    /// The status bits cannot be placed (3.4).
    #[error(transparent)]
    Bits(#[from] BitMapError),
    /// The spec lacks a parameter or table the model needs, or its tables disagree (3.1).
    #[error("spec: {what}")]
    Spec {
        /// What is missing or inconsistent.
        what: String,
    },
}
