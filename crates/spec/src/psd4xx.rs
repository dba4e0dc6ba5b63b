//! Protocol tables of `spec/psd4xx/protocol.toml`.

use serde::{Deserialize, Serialize};

/// The `[protocol]` table.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Protocol {
    /// Manual chapter the tables come from.
    pub source: String,
}
