//! Guard entries (manual 3.1 ISDU 66, 109, 111, 126): writing the suppress value to a guard
//! makes the device drop a following write of the entry it guards, under the reading of
//! PSX-ERRATUM-004 in force (adopted: only the directly following write command).
//!
//! Which entries are guards comes from the spec: a parameter with the enumerated values
//! `suppress-next` and `allow`; the entry it guards is the second parameter of its
//! `-SUPPRESS` requirement (PSX-ERRATUM-003 for ISDU 111). The tracker is sans-IO state: feed
//! it every write command the device executes, in order.

use crate::error::RulesError;
use crate::rules::Rules;
use drivespec_spec::Readings;
use serde::Serialize;
use std::fmt;

/// The erratum option that selects the guard reading (PSX-ERRATUM-004).
pub const OPTION: &str = "psx-guard-semantics";

/// Spec name of a guard's suppressing value.
const SUPPRESS: &str = "suppress-next";
/// Spec name of a guard's allowing value.
const ALLOW: &str = "allow";

/// How a guard's 0 acts (PSX-ERRATUM-004 readings).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum GuardReading {
    /// Only the directly following write command is suppressed, if it targets the entry.
    OneShot,
    /// The next write of the entry is suppressed, even with other writes between.
    NextTargetWrite,
    /// Every write of the entry is suppressed while the guard holds the suppress value.
    Persistent,
}

impl GuardReading {
    /// All readings (manual 3.1; PSX-ERRATUM-004).
    pub const ALL: [GuardReading; 3] = [
        GuardReading::OneShot,
        GuardReading::NextTargetWrite,
        GuardReading::Persistent,
    ];

    /// The reading id in the erratum (manual 3.1; PSX-ERRATUM-004).
    pub fn spec_name(self) -> &'static str {
        match self {
            GuardReading::OneShot => "one-shot",
            GuardReading::NextTargetWrite => "next-target-write",
            GuardReading::Persistent => "persistent",
        }
    }

    /// The reading with an erratum reading id (manual 3.1; PSX-ERRATUM-004).
    pub fn from_spec_name(name: &str) -> Option<GuardReading> {
        GuardReading::ALL
            .into_iter()
            .find(|r| r.spec_name() == name)
    }
}

/// One guard entry and the entry it guards (manual 3.1).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Guard {
    /// The guard's parameter id (`66`).
    pub guard: String,
    /// The guarded parameter id (`67`).
    pub guarded: String,
    /// The value that suppresses (0).
    pub suppress: i64,
    /// The value that allows (1).
    pub allow: Option<i64>,
    /// The guard's delivery value.
    pub delivery: Option<i64>,
    /// The requirement naming the pair.
    pub requirement: String,
}

/// What becomes of a write command (manual 3.1 guard entries).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
#[serde(tag = "fate", rename_all = "kebab-case")]
pub enum WriteFate {
    /// The write is executed.
    Execute,
    /// The write is acknowledged but dropped.
    Suppressed {
        /// The guard's parameter id.
        guard: String,
    },
}

impl fmt::Display for WriteFate {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            WriteFate::Execute => f.write_str("executed"),
            WriteFate::Suppressed { guard } => write!(f, "suppressed by ISDU {guard}"),
        }
    }
}

/// The guards of the spec and their state (manual 3.1; PSX-ERRATUM-004).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Guards {
    guards: Vec<Guard>,
    reading: GuardReading,
    armed: Vec<bool>,
}

impl Guards {
    /// The spec's guards under the reading chosen in `readings`, by default the adopted one
    /// (manual 3.1; PSX-ERRATUM-004).
    pub fn from_rules(rules: &Rules<'_>, readings: &Readings) -> Result<Guards, RulesError> {
        let family = rules.family();
        let name = readings
            .reading(family, OPTION)
            .ok_or_else(|| RulesError::Table {
                table: "erratum",
                what: format!("no erratum with option {OPTION}"),
            })?;
        let reading = GuardReading::from_spec_name(name).ok_or_else(|| RulesError::Table {
            table: "erratum",
            what: format!("unknown guard reading {name:?}"),
        })?;
        Guards::with_reading(rules, reading)
    }

    /// The spec's guards under a given reading (manual 3.1; PSX-ERRATUM-004).
    pub fn with_reading(rules: &Rules<'_>, reading: GuardReading) -> Result<Guards, RulesError> {
        let family = rules.family();
        let mut guards = Vec::new();
        for p in &family.parameters {
            let Some(suppress) = p.values.iter().find(|v| v.name == SUPPRESS) else {
                continue;
            };
            let req = family
                .requirements
                .iter()
                .find(|r| {
                    r.id.ends_with("-SUPPRESS")
                        && r.params.len() == 2
                        && r.params.first() == Some(&p.id)
                })
                .ok_or_else(|| RulesError::Table {
                    table: "requirement",
                    what: format!(
                        "guard {} has no -SUPPRESS requirement naming its entry",
                        p.id
                    ),
                })?;
            let guarded = req.params.get(1).cloned().unwrap_or_default();
            if family.parameter(&guarded).is_none() {
                return Err(RulesError::Table {
                    table: "requirement",
                    what: format!("{} names an unknown entry {guarded}", req.id),
                });
            }
            guards.push(Guard {
                guard: p.id.clone(),
                guarded,
                suppress: suppress.value,
                allow: p.values.iter().find(|v| v.name == ALLOW).map(|v| v.value),
                delivery: p.default,
                requirement: req.id.clone(),
            });
        }
        let mut g = Guards {
            armed: vec![false; guards.len()],
            guards,
            reading,
        };
        g.reset();
        Ok(g)
    }

    /// The guards (manual 3.1; PSX-ERRATUM-004).
    pub fn guards(&self) -> &[Guard] {
        &self.guards
    }

    /// The reading in force (manual 3.1; PSX-ERRATUM-004).
    pub fn reading(&self) -> GuardReading {
        self.reading
    }

    /// The guard of an entry (manual 3.1; PSX-ERRATUM-004).
    pub fn guard_of(&self, guarded: &str) -> Option<&Guard> {
        self.guards.iter().find(|g| g.guarded == guarded)
    }

    /// Back to power-on: every guard holds its delivery value (manual 3.1, not saved).
    pub fn reset(&mut self) {
        for (g, armed) in self.guards.iter().zip(self.armed.iter_mut()) {
            *armed = self.reading == GuardReading::Persistent && g.delivery == Some(g.suppress);
        }
    }

    /// Whether the guard of `guarded` would suppress a write of it now (manual 3.1).
    pub fn is_armed(&self, guarded: &str) -> bool {
        self.guards
            .iter()
            .zip(&self.armed)
            .any(|(g, a)| *a && g.guarded == guarded)
    }

    /// Records a write command the device accepted and says whether it is executed
    /// (manual 3.1 ISDU 66, 109, 111, 126; PSX-ERRATUM-004). `value` is the value written,
    /// when numeric.
    pub fn on_write(&mut self, param: &str, value: Option<i64>) -> WriteFate {
        let hit = self
            .guards
            .iter()
            .zip(&self.armed)
            .find(|(g, a)| **a && g.guarded == param)
            .map(|(g, _)| g.guard.clone());
        match self.reading {
            GuardReading::OneShot => self.armed.iter_mut().for_each(|a| *a = false),
            GuardReading::NextTargetWrite => {
                for (g, a) in self.guards.iter().zip(self.armed.iter_mut()) {
                    if g.guarded == param {
                        *a = false;
                    }
                }
            }
            GuardReading::Persistent => {}
        }
        for (g, a) in self.guards.iter().zip(self.armed.iter_mut()) {
            if g.guard == param {
                if value == Some(g.suppress) {
                    *a = true;
                } else if self.reading != GuardReading::OneShot {
                    *a = false;
                }
            }
        }
        match hit {
            Some(guard) => WriteFate::Suppressed { guard },
            None => WriteFate::Execute,
        }
    }
}
