//! The PSx3xx `[[scenario]]` records (`spec/psx3xx/scenarios`): hand-written conformance
//! cases as data. A step is a role, a text and the keys of the family [`Step`](crate::step::Step)
//! beside `do`, with control words named by the spec's `control` bitfield and values named by
//! parameter (`{ param = "67", plus = 2000 }`); a misspelt key is an error naming scenario,
//! step and key (`spec/SCHEMA.md` "Steps and scenarios").

use drivespec_spec::{FamilyId, Problem, Spec};
use serde::Deserialize;

/// How a scenario is judged (`setup` of a PSx3xx scenario).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Setup {
    /// The tolerance and plot of the case.
    pub judge: Judge,
    /// Status bits the manual leaves open in the case, not judged (a motion case).
    #[serde(default)]
    pub open: Option<Open>,
}

/// Status bits a scenario does not judge because the manual leaves them open there; the case
/// reports what the device showed.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Open {
    /// The requirement the point belongs to.
    pub requirement: String,
    /// What the manual leaves open, one line.
    pub text: String,
    /// The status bits not judged (0..15).
    pub bits: Vec<u16>,
}

/// The tolerance a scenario is judged with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Judge {
    /// Every cycle and every live value exact; no plot.
    Exact,
    /// The motion tolerance; a position/speed/status plot in the report.
    Motion,
}

/// One scenario step: `role` (default `check`), `text` (absent for ISDU steps, which name
/// their entry) and the action's keys beside `do`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(try_from = "toml::Table")]
pub struct ScenarioStep {
    /// Setup or check.
    pub role: StepRole,
    /// What the report shows; `{value}` stands for the step's quantity, `{control}` for its
    /// control word (`0x0011`).
    pub text: Option<String>,
    /// What the step does.
    pub action: Action,
}

/// The role of a scenario step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StepRole {
    /// Brings the drive into the state the case needs.
    Setup,
    /// The behaviour under test.
    #[default]
    Check,
}

impl TryFrom<toml::Table> for ScenarioStep {
    type Error = toml::de::Error;
    fn try_from(mut t: toml::Table) -> Result<ScenarioStep, toml::de::Error> {
        let role = t.remove("role").map(|v| v.try_into()).transpose()?;
        let text = t.remove("text").map(|v| v.try_into()).transpose()?;
        Ok(ScenarioStep {
            role: role.unwrap_or_default(),
            text,
            action: toml::Value::Table(t).try_into()?,
        })
    }
}

/// What a scenario step does: the family [`Step`] with values named by the spec.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "do", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Action {
    /// A process output, then one cycle (3.3.1).
    PdOut {
        /// Output format (0, 1, 2).
        format: u8,
        /// Control word or time-stamp code.
        control: Control,
        /// Target position.
        #[serde(default)]
        target: Option<Quantity>,
        /// Target speed (format 2).
        #[serde(default)]
        speed: i16,
        /// Time stamp (format 0).
        #[serde(default)]
        stamp: u16,
    },
    /// Cycles with the output unchanged: `cycles`, or the whole cycles covering `ms`.
    Hold {
        /// How many cycles.
        #[serde(default)]
        cycles: Option<u32>,
        /// Bus time, ms.
        #[serde(default)]
        ms: Option<Quantity>,
    },
    /// Cycles until the drive runs (`running`) or stands still, at most the suite's limit.
    Until {
        /// Wait for a run (true) or a standstill (false).
        running: bool,
    },
    /// The master is silent for `us`, or for the whole cycles covering `ms`.
    Advance {
        /// How long, µs.
        #[serde(default)]
        us: Option<u64>,
        /// How long, ms, rounded up to whole bus cycles.
        #[serde(default)]
        ms: Option<Quantity>,
    },
    /// An environment change (`jam 1`); with `value` the text is the change's name and the
    /// value follows it (`motor-voltage` 230).
    Env {
        /// The change in its text form, or its name when `value` is given.
        env: String,
        /// The change's value.
        #[serde(default)]
        value: Option<Quantity>,
    },
    /// An ISDU read of a parameter (3.1).
    IsduRead {
        /// Parameter id.
        param: String,
    },
    /// An ISDU write of a parameter (3.1).
    IsduWrite {
        /// Parameter id.
        param: String,
        /// The value.
        value: Quantity,
    },
}

/// A number, or a parameter's value at power-on scaled and shifted:
/// `{ param = "67", plus = 2000 }`.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(untagged)]
pub enum Quantity {
    /// A number.
    Number(i64),
    /// `param` × `times` + `plus`.
    Of(Of),
}

/// A parameter's value scaled and shifted.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Of {
    /// Parameter id.
    pub param: String,
    /// Factor (default 1).
    #[serde(default = "one")]
    pub times: i64,
    /// Offset (default 0).
    #[serde(default)]
    pub plus: i64,
}

fn one() -> i64 {
    1
}

/// A control word: a number, or names of `control` bitfield values and bits, or-ed.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(untagged)]
pub enum Control {
    /// A number.
    Word(u16),
    /// One name.
    Name(String),
    /// Names, or-ed.
    Names(Vec<String>),
}

/// Every PSx3xx scenario whose setup or steps do not read as [`Setup`] and [`ScenarioStep`],
/// naming file, scenario, step and key (`drivespec spec check`).
pub fn check_scenarios(spec: &Spec) -> Vec<Problem> {
    drivespec_spec::check_scenarios::<Setup, ScenarioStep>(spec.family(FamilyId::Psx3xx))
}

#[cfg(test)]
mod tests {
    use super::ScenarioStep;

    fn read(text: &str) -> Result<ScenarioStep, toml::de::Error> {
        toml::from_str(text)
    }

    #[test]
    fn a_misspelt_step_key_is_an_error_naming_it() {
        assert!(read("text = \"cycles\"\ndo = \"hold\"\ncycles = 3").is_ok());
        let e = read("text = \"cycles\"\ndo = \"hold\"\ncycels = 3")
            .err()
            .map(|e| e.to_string());
        assert!(e.as_deref().is_some_and(|e| e.contains("cycels")), "{e:?}");
        let e = read("rol = \"setup\"\ndo = \"isdu-read\"\nparam = \"67\"")
            .err()
            .map(|e| e.to_string());
        assert!(e.as_deref().is_some_and(|e| e.contains("rol")), "{e:?}");
    }
}
