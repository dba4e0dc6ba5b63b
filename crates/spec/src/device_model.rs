//! `[[model]]` records: device models and their parameter ranges and defaults.

use crate::family::fold;
use crate::Ranges;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// A model's own range or default for one parameter.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelParam {
    /// Parameter id.
    pub id: String,
    /// Range replacing the parameter's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub range: Option<Ranges>,
    /// Default replacing the parameter's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub default: Option<i64>,
    /// Remark.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// One device model (PSD 3.4, PSx 3.2, HPD sizes).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceModel {
    /// Canonical short id.
    pub id: String,
    /// The manual's name.
    pub name: String,
    /// Other spellings.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub aliases: Vec<String>,
    /// Manual section.
    pub source: String,
    /// Numeric facts of the model.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub attributes: BTreeMap<String, f64>,
    /// Per-model parameter values.
    #[serde(default, rename = "param", skip_serializing_if = "Vec::is_empty")]
    pub params: Vec<ModelParam>,
    /// File the record was loaded from.
    #[serde(skip)]
    pub file: String,
}

impl DeviceModel {
    /// Id, name and aliases, folded for matching.
    pub(crate) fn folded_names(&self) -> impl Iterator<Item = String> + '_ {
        std::iter::once(&self.id)
            .chain(std::iter::once(&self.name))
            .chain(self.aliases.iter())
            .map(|s| fold(s))
    }

    /// A numeric attribute.
    pub fn attribute(&self, key: &str) -> Option<f64> {
        self.attributes.get(key).copied()
    }
}
