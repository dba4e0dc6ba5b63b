//! The PSD4xx scenario files (`spec/psd4xx/scenarios/*.toml`): hand-written cases as data.
//! A step is the family's [`Step`] or a form naming spec values that the suite resolves:
//! control words by their names in bitfield `control`, parameters by spec id
//! (`spec/SCHEMA.md` "Steps and scenarios").

use crate::case::Role;
use drivespec_psd4xx::step::Step;
use serde::{Deserialize, Deserializer};

/// How a scenario is judged and shown (`setup` table).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Setup {
    /// `exact`: the exchange tolerance; `motion`: the motion tolerance.
    pub judge: Judge,
    /// Whether the report gets a position/speed/status plot.
    #[serde(default)]
    pub plot: bool,
    /// The point of a motion case the manual leaves open, if any.
    #[serde(default)]
    pub open: Option<Open>,
}

/// What a motion scenario does not judge because the manual leaves it open there; the case
/// reports what the device showed.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct Open {
    /// The requirement the point belongs to.
    pub requirement: String,
    /// What the manual leaves open, one line.
    pub text: String,
    /// The status bits not judged (0..15).
    pub bits: Vec<u16>,
    /// Whether the direction of travel is not judged either.
    #[serde(default)]
    pub movement: bool,
}

/// The tolerance a scenario is judged with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum Judge {
    /// PKW, status and replies exact; the answer may come one cycle late.
    Exact,
    /// Position and speed within the motion tolerance.
    Motion,
}

/// A step's role in the case (`role`, default `check`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum StepRole {
    /// Brings the drive into the state the case needs.
    Setup,
    /// The behaviour under test.
    #[default]
    Check,
}

impl From<StepRole> for Role {
    fn from(r: StepRole) -> Role {
        match r {
            StepRole::Setup => Role::Setup,
            StepRole::Check => Role::Check,
        }
    }
}

/// A step that names spec values (keyed by `do`).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(tag = "do", rename_all = "kebab-case", deny_unknown_fields)]
pub(crate) enum SpecStep {
    /// A control word (names in bitfield `control` or numbers, joined by `|`) and optionally
    /// a target, then one cycle.
    Control {
        /// `release-and-transfer`, `Toggle bit|release-and-transfer`, `0`.
        control: String,
        /// The target.
        #[serde(default)]
        target: Option<Target>,
    },
    /// A PKW read of a parameter (by spec id), element `index` of an array.
    PkwRead {
        /// Parameter spec id.
        par: String,
        /// Array element.
        #[serde(default)]
        index: Option<u16>,
    },
    /// The PKW block "no command".
    PkwNone {},
    /// A PKW write of a parameter's delivery value on the model.
    PkwWriteDefault {
        /// Parameter spec id.
        par: String,
    },
    /// An acyclic record write of `value` with the control byte that executes it (3.2.2).
    RecordSet {
        /// Parameter spec id.
        par: String,
        /// The value.
        value: i64,
    },
}

/// A target: a number or the largest value the target field holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(untagged)]
pub(crate) enum Target {
    /// This target.
    Value(i32),
    /// `type-max`: the largest target the field holds.
    Named(TargetName),
}

/// A named target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub(crate) enum TargetName {
    /// The largest target the field holds.
    TypeMax,
}

/// What a scenario step does.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Action {
    /// The family's step as written.
    Step(Step),
    /// A step the suite resolves from the spec.
    Spec(SpecStep),
}

/// One scenario step: role, text and action, all keys beside `do`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct ScenarioStep {
    /// Setup or check.
    pub role: StepRole,
    /// The report line; absent: derived from the action.
    pub text: Option<String>,
    /// What to do.
    pub action: Action,
}

/// The `do` values of [`SpecStep`].
const SPEC_KINDS: [&str; 5] = [
    "control",
    "pkw-read",
    "pkw-none",
    "pkw-write-default",
    "record-set",
];

impl<'de> Deserialize<'de> for ScenarioStep {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<ScenarioStep, D::Error> {
        use serde::de::Error;
        let mut t = toml::Table::deserialize(d)?;
        let role = match t.remove("role") {
            Some(v) => v.try_into().map_err(D::Error::custom)?,
            None => StepRole::default(),
        };
        let text = match t.remove("text") {
            Some(v) => Some(v.try_into().map_err(D::Error::custom)?),
            None => None,
        };
        let spec = t
            .get("do")
            .and_then(toml::Value::as_str)
            .is_some_and(|k| SPEC_KINDS.contains(&k));
        let v = toml::Value::Table(t);
        let action = if spec {
            Action::Spec(v.try_into().map_err(D::Error::custom)?)
        } else {
            Action::Step(v.try_into().map_err(D::Error::custom)?)
        };
        Ok(ScenarioStep { role, text, action })
    }
}

#[cfg(test)]
mod tests {
    use super::{Action, ScenarioStep, SpecStep, StepRole};

    #[test]
    fn steps_read_with_role_and_text_beside_do() {
        let s: Result<ScenarioStep, _> =
            toml::from_str("role = \"setup\"\ntext = \"no command\"\ndo = \"pkw-none\"");
        assert_eq!(
            s.ok(),
            Some(ScenarioStep {
                role: StepRole::Setup,
                text: Some("no command".to_owned()),
                action: Action::Spec(SpecStep::PkwNone {}),
            })
        );
    }

    #[test]
    fn a_misspelt_key_is_an_error_naming_it() {
        for text in [
            "do = \"hold\"\ncycle = 3",
            "do = \"control\"\ncontrol = \"stop\"\ntraget = 3",
        ] {
            let e = toml::from_str::<ScenarioStep>(text)
                .err()
                .map(|e| e.to_string());
            assert!(e.is_some_and(|e| e.contains("unknown field")), "{text}");
        }
    }
}
