//! Why a check cannot start: the spec lacks a table a checker needs, or an option is unusable.
//! (Problems of the checked traffic are violations, and read errors end up in
//! [`crate::Report::error`]; neither is an error here.)

use crate::pnio_names::NamesError;
use crate::report::CatalogError;

/// A checker cannot be set up (style rule 8: errors carry data).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SetupError {
    /// The requirement catalogue (generic PROFINET rules) is broken.
    #[error(transparent)]
    Catalog(#[from] CatalogError),
    /// The PNIOStatus and AlarmType names are unusable.
    #[error(transparent)]
    Names(#[from] NamesError),
    /// The HPD tables of the spec are unusable (manual 4.1).
    #[error("HPD rules: {0}")]
    Hpd(#[from] drivespec_hpd::RulesError),
    /// The PSD4xx tables of the spec are unusable (bus description 3.5, 3.8).
    #[error("PSD4xx rules: {0}")]
    Psd4xx(#[from] drivespec_psd4xx::RulesError),
    /// The PSx3xx tables of the spec are unusable (manual chapter 3).
    #[error("PSx3xx rules: {0}")]
    Psx3xx(String),
    /// An option names something the spec does not know.
    #[error("{option}: {reason}")]
    Option {
        /// The option (`--baud`, `--model`, …).
        option: &'static str,
        /// What is wrong.
        reason: String,
    },
}
