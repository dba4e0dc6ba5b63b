//! `[[model]]` records: device models and their parameter ranges and defaults, and the
//! `[[param_set]]` records models share.

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
    /// Lower end of the range whose upper end is the model attribute the parameter's
    /// `model_max` names; the loader turns it into `range`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub min: Option<i64>,
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
    /// The `[[param_set]]` whose values the model takes before its own `param` entries.
    #[serde(default, skip_serializing)]
    pub param_set: Option<String>,
    /// Per-model parameter values (after loading: the set's, then the model's own, with the
    /// values that follow from the attributes filled in).
    #[serde(default, rename = "param", skip_serializing_if = "Vec::is_empty")]
    pub params: Vec<ModelParam>,
    /// File the record was loaded from.
    #[serde(skip)]
    pub file: String,
}

/// Parameter values shared by the models of one table column (PSx 3.2 gearbox columns).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamSet {
    /// Name the models' `param_set` refers to.
    pub id: String,
    /// Manual section.
    pub source: String,
    /// The values.
    pub param: Vec<ModelParam>,
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
