//! Why a model drive cannot be built (manual 3.3, 3.4).

use crate::RulesError;
use drivespec_positioner::status::BitMapError;

/// Why the PSD4xx drive model cannot be built (manual 3.3, 3.4, 3.6).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModelError {
    /// The spec's codec tables are unusable (3.5, 3.8).
    #[error(transparent)]
    Rules(#[from] RulesError),
    /// No model of table 3.4 matches the name.
    #[error("unknown PSD4xx model {model:?}; known: {known}")]
    UnknownModel {
        /// The name given.
        model: String,
        /// The model ids there are.
        known: String,
    },
    /// The status bits cannot be placed (3.6).
    #[error(transparent)]
    Bits(#[from] BitMapError),
    /// The spec lacks a parameter or table the model needs, or its tables disagree (3.3).
    #[error("spec: {what}")]
    Spec {
        /// What is missing or inconsistent.
        what: String,
    },
}
