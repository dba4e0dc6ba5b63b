//! Cases from the spec's PSx3xx `[[scenario]]` records (`spec/psx3xx/scenarios`, typed by
//! [`drivespec_psx3xx::scenario`]): the suite resolves the control-word names, parameter
//! values and quantities the steps name from the spec and the reference drive (manual
//! 3.3–3.5, 4, 5).

use super::{step, Gen, OpenPoint, PsxCase, StepDef, RUN_MAX};
use crate::case::Role;
use drivespec_psx3xx::scenario::{Action, Control, Judge, Quantity, ScenarioStep, Setup, StepRole};
use drivespec_psx3xx::step::Step;

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
            let start = self.idle(self.rules.default_format());
            let judged = match typed.setup.judge {
                Judge::Exact => PsxCase::exact(start, steps),
                Judge::Motion => PsxCase::motion(start, steps),
            };
            let open = typed
                .setup
                .open
                .as_ref()
                .map(|o| OpenPoint::of_scenario(&o.requirement, &o.text, &o.bits, false));
            if let Some(o) = &open {
                if self.family.requirement(&o.requirement).is_none() {
                    self.errors.push(format!(
                        "{}: scenario {:?}: unknown requirement {} of the open point",
                        record.file, record.id, o.requirement
                    ));
                }
            }
            let case = PsxCase { open, ..judged };
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
