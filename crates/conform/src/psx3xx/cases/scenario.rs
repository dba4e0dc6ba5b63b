//! Cases from the spec's PSx3xx `[[scenario]]` records (`spec/psx3xx/scenarios`): each
//! scenario's steps name control words, parameters and quantities by their spec names, and
//! the suite resolves them from the spec and the reference drive (manual 3.3–3.5, 4, 5).

use super::{step, Gen, PsxCase, StepDef, EXACT, MOTION, RUN_MAX};
use crate::case::Role;
use drivespec_psx3xx::step::Step;
use serde::Deserialize;

/// How a scenario is judged (`setup` of a PSx3xx scenario).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Setup {
    /// The tolerance and plot of the case.
    pub judge: Judge,
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

impl Gen<'_, '_> {
    fn quantity(&mut self, q: &Quantity) -> Option<i64> {
        match q {
            Quantity::Number(n) => Some(*n),
            Quantity::Of(of) => {
                self.param(&of.param)?;
                Some(
                    self.value(&of.param)
                        .saturating_mul(of.times)
                        .saturating_add(of.plus),
                )
            }
        }
    }

    fn control_word(&mut self, c: &Control) -> u16 {
        let names = match c {
            Control::Word(w) => return *w,
            Control::Name(n) => std::slice::from_ref(n),
            Control::Names(n) => n.as_slice(),
        };
        names.iter().fold(0, |w, name| w | self.control_named(name))
    }

    /// Every case of the family's scenarios, in file order.
    pub(super) fn scenario_cases(&mut self) {
        let family = self.family;
        for record in &family.scenarios {
            let typed = match record.typed::<Setup, ScenarioStep>() {
                Ok(t) => t,
                Err(e) => {
                    self.errors
                        .push(format!("{}: scenario {:?}: {e}", record.file, record.id));
                    continue;
                }
            };
            let mut steps = Vec::new();
            for s in &typed.steps {
                if let Some(def) = self.scenario_step(s) {
                    steps.push(def);
                } else {
                    self.errors.push(format!(
                        "{}: scenario {:?}: step {:?} does not resolve",
                        record.file, record.id, s.text
                    ));
                }
            }
            let (tol, plot) = match typed.setup.judge {
                Judge::Exact => (EXACT, false),
                Judge::Motion => (MOTION, true),
            };
            let case = PsxCase {
                start: self.idle(self.rules.default_format()),
                steps,
                tol,
                plot,
            };
            self.push(
                format!("psx3xx/{}", record.id),
                &record.requirements,
                record.description.clone(),
                case,
            );
        }
    }

    fn scenario_step(&mut self, s: &ScenarioStep) -> Option<StepDef> {
        let role = match s.role {
            StepRole::Setup => Role::Setup,
            StepRole::Check => Role::Check,
        };
        let mut value = None;
        let mut control = None;
        let action = match &s.action {
            Action::IsduRead { param } => {
                let mut d = self.read(param)?;
                d.role = role;
                return Some(d);
            }
            Action::IsduWrite { param, value } => {
                let v = self.quantity(value)?;
                return self.write(role, param, v);
            }
            Action::PdOut {
                format,
                control: c,
                target,
                speed,
                stamp,
            } => {
                let word = self.control_word(c);
                control = Some(word);
                let target = match target {
                    Some(q) => i32::try_from(self.quantity(q)?).ok()?,
                    None => 0,
                };
                Step::PdOut {
                    format: *format,
                    control: word,
                    target,
                    speed: *speed,
                    stamp: *stamp,
                }
            }
            Action::Hold { cycles, ms } => match (cycles, ms) {
                (Some(c), None) => Step::Hold { cycles: *c },
                (None, Some(ms)) => {
                    let ms = self.quantity(ms)?;
                    value = Some(ms);
                    Step::Hold {
                        cycles: self.cycles_for(u64::try_from(ms).ok()?),
                    }
                }
                _ => return None,
            },
            Action::Until { running } => Step::Until {
                running: *running,
                max: RUN_MAX,
            },
            Action::Advance { us, ms } => match (us, ms) {
                (Some(us), None) => Step::Advance { us: *us },
                (None, Some(ms)) => {
                    let ms = self.quantity(ms)?;
                    value = Some(ms);
                    let cycles = self.cycles_for(u64::try_from(ms).ok()?);
                    Step::Advance {
                        us: u64::from(cycles).saturating_mul(self.cycle_us),
                    }
                }
                _ => return None,
            },
            Action::Env { env, value: q } => match q {
                None => Step::Env { env: env.clone() },
                Some(q) => {
                    let v = self.quantity(q)?;
                    value = Some(v);
                    Step::Env {
                        env: format!("{env} {v}"),
                    }
                }
            },
        };
        let mut text = s.text.clone()?;
        if let Some(v) = value {
            text = text.replace("{value}", &v.to_string());
        }
        if let Some(c) = control {
            text = text.replace("{control}", &format!("{c:#06x}"));
        }
        Some(step(role, text, action))
    }
}
