//! One manual's part of the spec: its parameters, models, bits, requirements and vectors.

use crate::{
    hpd, psd4xx, psx3xx, Bitfield, DeviceModel, Erratum, Parameter, Requirement, Resolved,
    Scenario, Vector,
};
use serde::{Deserialize, Serialize};
use std::fmt;

/// The three device families, one per manual.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FamilyId {
    /// Parker HPD servo drive, RS-422/485 serial (hpd-users-manual).
    Hpd,
    /// halstrup-walcher PSD4xx over PROFINET (psd4xx-profinet-bus-description).
    Psd4xx,
    /// halstrup-walcher PSE/PSS/PSW 3xx over IO-Link (psx3xx-iolink-instruction-manual).
    Psx3xx,
}

impl FamilyId {
    /// All families.
    pub const ALL: [FamilyId; 3] = [FamilyId::Hpd, FamilyId::Psd4xx, FamilyId::Psx3xx];

    /// The folder name and CLI name: `hpd`, `psd4xx`, `psx3xx`.
    pub fn as_str(self) -> &'static str {
        match self {
            FamilyId::Hpd => "hpd",
            FamilyId::Psd4xx => "psd4xx",
            FamilyId::Psx3xx => "psx3xx",
        }
    }

    /// The prefix of the family's requirement IDs.
    pub fn requirement_prefix(self) -> &'static str {
        match self {
            FamilyId::Hpd => "HPD",
            FamilyId::Psd4xx => "PSD",
            FamilyId::Psx3xx => "PSX",
        }
    }

    /// Parses a family name (case-insensitive).
    pub fn parse(s: &str) -> Option<FamilyId> {
        FamilyId::ALL
            .into_iter()
            .find(|f| f.as_str().eq_ignore_ascii_case(s.trim()))
    }
}

impl fmt::Display for FamilyId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// `family.toml`: names and the manual a family distils.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FamilyInfo {
    /// `hpd`, `psd4xx` or `psx3xx`.
    pub id: FamilyId,
    /// Product family name.
    pub name: String,
    /// The bus and protocol.
    pub bus: String,
    /// File name of the manual under `shared/manuals/`.
    pub manual: String,
    /// The manual's title.
    pub title: String,
}

/// The family-specific protocol tables of `protocol.toml`.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum Protocol {
    /// HPD serial protocol, PLC instruction set and alarms.
    Hpd(Box<hpd::Protocol>),
    /// PSD4xx process data, PKW and records.
    Psd4xx(Box<psd4xx::Protocol>),
    /// PSx3xx process data, ISDU, time stamps and Direct Parameter page 1.
    Psx3xx(Box<psx3xx::Protocol>),
}

/// One manual's part of the spec.
#[derive(Debug)]
pub struct Family {
    /// Names and manual.
    pub info: FamilyInfo,
    /// Parameters in file order.
    pub parameters: Vec<Parameter>,
    /// Device models.
    pub models: Vec<DeviceModel>,
    /// Bitfields with their rules.
    pub bitfields: Vec<Bitfield>,
    /// Normative statements: those the bit rules state first, in rule order, then the records.
    pub requirements: Vec<Requirement>,
    /// Contradictions in the manual and the readings adopted.
    pub errata: Vec<Erratum>,
    /// Golden vectors from the manual's worked examples.
    pub vectors: Vec<Vector>,
    /// Hand-written cases kept as data.
    pub scenarios: Vec<Scenario>,
    /// Protocol tables.
    pub protocol: Protocol,
}

/// Normalises a model or parameter name for forgiving matching.
pub(crate) fn fold(s: &str) -> String {
    s.chars()
        .filter(|c| c.is_ascii_alphanumeric())
        .map(|c| c.to_ascii_lowercase())
        .collect()
}

impl Family {
    /// The family id.
    pub fn id(&self) -> FamilyId {
        self.info.id
    }

    /// A parameter by id (`"63"`, `"0.1"`, `"Pr64"`, case-insensitive), or by exact name.
    pub fn parameter(&self, key: &str) -> Option<&Parameter> {
        let key = key.trim();
        let bare = key
            .strip_prefix("par")
            .or_else(|| key.strip_prefix("Par"))
            .unwrap_or(key);
        let bare = bare.trim_start_matches(['.', ' ']);
        self.parameters
            .iter()
            .find(|p| p.id.eq_ignore_ascii_case(key) || p.id.eq_ignore_ascii_case(bare))
            .or_else(|| self.hpd_alias(key))
            .or_else(|| self.parameters.iter().find(|p| fold(&p.name) == fold(key)))
    }

    /// HPD: `Pr40` and `Pb40` name the same word; `P40`, `Pr.40` are accepted too.
    fn hpd_alias(&self, key: &str) -> Option<&Parameter> {
        if self.id() != FamilyId::Hpd {
            return None;
        }
        let digits = key.trim_start_matches(|c: char| !c.is_ascii_digit());
        let n: u32 = digits.parse().ok()?;
        self.parameters
            .iter()
            .find(|p| p.number == n && p.subindex.is_none())
    }

    /// HPD: the parameter whose serial bytes include `address`.
    pub fn parameter_at_address(&self, address: u32) -> Option<&Parameter> {
        self.parameters.iter().find(|p| match (p.address, p.size) {
            (Some(a), Some(s)) => (a..a.saturating_add(s)).contains(&address),
            _ => false,
        })
    }

    /// The ids of the family's models, comma-separated (an error naming the models there are).
    pub fn model_ids(&self) -> String {
        let ids: Vec<&str> = self.models.iter().map(|m| m.id.as_str()).collect();
        ids.join(", ")
    }

    /// The model matching `query` forgivingly (see `spec/SCHEMA.md`).
    pub fn model(&self, query: &str) -> Option<&DeviceModel> {
        let q = fold(query);
        if q.is_empty() {
            return None;
        }
        let exact = |q: &str| {
            self.models
                .iter()
                .find(|m| m.folded_names().any(|n| n == q))
        };
        if let Some(m) = exact(&q) {
            return Some(m);
        }
        // Drop a trailing suffix such as "-14", "-14H" or " 8H/14H" and try again.
        let mut raw = query.trim().to_owned();
        while let Some(cut) = raw.rfind(['-', ' ', '/']) {
            raw.truncate(cut);
            if let Some(m) = exact(&fold(&raw)) {
                return Some(m);
            }
        }
        // A unique model whose name starts with the query.
        let mut hits = self
            .models
            .iter()
            .filter(|m| m.folded_names().any(|n| n.starts_with(&q)));
        match (hits.next(), hits.next()) {
            (Some(m), None) => Some(m),
            _ => None,
        }
    }

    /// A requirement by id.
    pub fn requirement(&self, id: &str) -> Option<&Requirement> {
        self.requirements.iter().find(|r| r.id == id)
    }

    /// Range and default of a parameter, resolved for a model when one is given.
    pub fn resolve(&self, param: &Parameter, model: Option<&DeviceModel>) -> Resolved {
        let over = model.and_then(|m| m.params.iter().find(|mp| mp.id == param.id));
        let range = over
            .and_then(|o| o.range.clone())
            .or_else(|| param.range.clone())
            .or_else(|| {
                param
                    .data_type
                    .bounds()
                    .map(|(lo, hi)| crate::Ranges::new(lo, hi))
            });
        let default = over.and_then(|o| o.default).or(param.default);
        Resolved { range, default }
    }

    /// Bitfields stored in a parameter.
    pub fn bitfields_of<'a>(&'a self, param: &'a str) -> impl Iterator<Item = &'a Bitfield> + 'a {
        self.bitfields.iter().filter(move |b| b.param == param)
    }

    /// A bitfield by id.
    pub fn bitfield(&self, id: &str) -> Option<&Bitfield> {
        self.bitfields.iter().find(|b| b.id == id)
    }

    /// HPD protocol tables (None for the other families).
    pub fn hpd(&self) -> Option<&hpd::Protocol> {
        match &self.protocol {
            Protocol::Hpd(p) => Some(p),
            _ => None,
        }
    }

    /// PSD4xx protocol tables (None for the other families).
    pub fn psd4xx(&self) -> Option<&psd4xx::Protocol> {
        match &self.protocol {
            Protocol::Psd4xx(p) => Some(p),
            _ => None,
        }
    }

    /// PSx3xx protocol tables (None for the other families).
    pub fn psx3xx(&self) -> Option<&psx3xx::Protocol> {
        match &self.protocol {
            Protocol::Psx3xx(p) => Some(p),
            _ => None,
        }
    }
}
