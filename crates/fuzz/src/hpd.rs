//! The HPD fuzz target: sequences from [`sequences`], run through the conformance
//! session ([`HpdSession`]) so every answer is judged exactly as `drivespec conform` judges it
//! (the reference drive fed the same bytes at the same times, manual chapter 4).
//!
//! A failing step is a crash when the transport failed (the process exited, the connection
//! closed), a hang when the device was silent where the reference answers and stays silent
//! to a liveness probe (a read of Pr33), and a mismatch otherwise.

mod sequences;

use crate::engine::{self, Fault, OtherFamilyStep, Target, Trial};
use crate::replay::{Action, FindingClass, Start, Step};
use drivespec_conform::case::{CaseInfo, CaseRun, Outcome, RequirementRef, Role};
use drivespec_conform::hpd::step::{Action as HAction, HpdCase, Step as HStep};
use drivespec_conform::hpd::{GenError, HpdSession, HpdSuite};
use drivespec_conform::link::{Caps, Link, LinkError, Recovered};
use drivespec_conform::suite::SetupError;
use drivespec_hpd::memory::Slot;
use drivespec_hpd::{FrameRules, Message};
use drivespec_sim::rng::Rng;
use drivespec_spec::{Family, FamilyId, Level};
use sequences::HpdGen;

/// The HPD target on one device under test.
pub(crate) struct HpdTarget<'a, 's> {
    family: &'s Family,
    rules: FrameRules,
    session: HpdSession<'a, 's>,
    gen: HpdGen<'a, 's>,
    caps: Caps,
    probe: Vec<Step>,
    /// Whether `recover` restarts the device (exec) rather than reconnecting (tcp, serial);
    /// None until tried.
    restarts: Option<bool>,
    /// The session restarted the device after a transport error in the last run: it is in
    /// its start state already.
    clean: bool,
}

impl<'a, 's> HpdTarget<'a, 's> {
    /// A target on `link`, with cases and the reference from `suite`.
    pub(crate) fn new(
        suite: &'a HpdSuite<'s>,
        link: Box<dyn Link>,
    ) -> Result<HpdTarget<'a, 's>, SetupError> {
        let caps = link.caps();
        let rules = FrameRules::from_spec(suite.spec()).map_err(GenError::from)?;
        let mut gen = HpdGen::new(suite, caps)?;
        let probe = gen.probe();
        Ok(HpdTarget {
            family: suite.family(),
            rules,
            session: suite.session(link),
            gen,
            caps,
            probe,
            restarts: None,
            clean: false,
        })
    }

    fn case(&self, steps: &[Step]) -> Result<(CaseInfo, HpdCase), OtherFamilyStep> {
        let hsteps: Vec<HStep> = engine::own_steps::<HAction>(steps)?
            .into_iter()
            .zip(steps)
            .map(|(action, s)| to_hpd(action, s))
            .collect();
        let info = CaseInfo {
            id: "hpd/fuzz/sequence".to_owned(),
            family: FamilyId::Hpd,
            requirements: Vec::new(),
            level: Level::Must,
            description: "a fuzz sequence".to_owned(),
            steps: steps.iter().map(|s| s.text.clone()).collect(),
        };
        let case = HpdCase {
            needs_power_cycle: steps
                .iter()
                .any(|s| s.action == Action::Hpd(HAction::PowerCycle {})),
            touched: self.touched(steps),
            steps: hsteps,
            checks: Vec::new(),
        };
        Ok((info, case))
    }

    /// Parameter slots the steps may change (read back after a failure on transports that
    /// cannot reset, as the conformance runner does).
    fn touched(&self, steps: &[Step]) -> Vec<Slot> {
        let mut out: Vec<Slot> = Vec::new();
        for s in steps {
            let Some(bytes) = s.action.bytes() else {
                continue;
            };
            let (par, len) = match drivespec_hpd::parse(&self.rules, bytes) {
                Ok(Message::WriteParam { par, data, .. } | Message::Broadcast { par, data }) => {
                    (par, data.len())
                }
                Ok(Message::BitChange { par, .. }) => (par, 1),
                _ => continue,
            };
            for i in 0..len {
                let Some(a) = par.checked_add(i) else { break };
                let Some(p) = self.family.parameter_at_address(u32::from(a)) else {
                    continue;
                };
                let (Some(addr), Some(size)) = (p.address, p.size) else {
                    continue;
                };
                let (Ok(addr), Ok(size)) = (u8::try_from(addr), u8::try_from(size)) else {
                    continue;
                };
                let slot = Slot { addr, size };
                if !out.contains(&slot) {
                    out.push(slot);
                }
            }
        }
        out
    }

    /// Runs the steps as one case; a step of another family fails the run with
    /// [`OtherFamilyStep`] before anything is sent.
    fn run_raw(&mut self, steps: &[Step]) -> CaseRun {
        match self.case(steps) {
            Ok((info, case)) => self.session.run_case(&info, &case, false),
            Err(e) => e.failed_run(),
        }
    }

    /// What kind of message a step sends, for signatures.
    fn kind(&self, s: Option<&Step>) -> String {
        match s.map(|s| &s.action) {
            Some(Action::Hpd(HAction::Exchange { bytes, .. })) => {
                match drivespec_hpd::parse(&self.rules, bytes) {
                    Ok(m) => m.kind().spec_name().to_owned(),
                    Err(_) => "malformed".to_owned(),
                }
            }
            Some(Action::Hpd(
                HAction::Listen { .. } | HAction::ListenTimeout {} | HAction::ListenHalfTimeout {},
            )) => "listen".to_owned(),
            Some(Action::Hpd(h)) => h.name().to_owned(),
            Some(Action::Psd4xx(_) | Action::Psx3xx(_)) => "cyclic".to_owned(),
            Some(Action::Profinet(_)) => "profinet".to_owned(),
            None => "start".to_owned(),
        }
    }
}

/// A fuzz step as a conformance step (judged).
fn to_hpd(action: &HAction, s: &Step) -> HStep {
    HStep {
        role: Role::Check,
        action: action.clone(),
        golden: None,
        text: s.text.clone(),
        requirements: s.requirements.clone(),
    }
}

impl Target for HpdTarget<'_, '_> {
    fn family(&self) -> FamilyId {
        FamilyId::Hpd
    }

    fn describe(&self) -> String {
        drivespec_conform::suite::Session::describe(&self.session)
    }

    fn caps(&self) -> Caps {
        self.caps
    }

    fn generate(&mut self, rng: &mut Rng) -> Vec<Step> {
        self.gen.sequence(rng)
    }

    fn fresh(&mut self) -> Result<Start, LinkError> {
        if self.caps.reset {
            return Ok(if self.session.reset()? {
                Start::Fresh
            } else {
                Start::AsIs
            });
        }
        if self.restarts == Some(false) {
            return Ok(Start::AsIs);
        }
        if std::mem::take(&mut self.clean) {
            self.warm_up();
            self.session.restart_reference();
            return Ok(Start::Fresh);
        }
        let r = self.session.recover()?;
        self.restarts = Some(r == Recovered::Fresh);
        self.warm_up();
        if r == Recovered::Fresh {
            self.session.restart_reference();
        }
        Ok(match r {
            Recovered::Fresh => Start::Fresh,
            Recovered::Same => Start::AsIs,
        })
    }

    fn warm_up(&mut self) {
        if self.caps.virtual_time {
            return;
        }
        let probe: Vec<u8> = self
            .probe
            .iter()
            .find_map(|s| s.action.bytes())
            .map(<[u8]>::to_vec)
            .unwrap_or_default();
        if !probe.is_empty() {
            // Bytes of the answer that come after are dropped before the next request.
            let _ = self.session.wake(&probe);
        }
    }

    fn run(&mut self, steps: &[Step]) -> Trial {
        self.clean = false;
        let (info, case) = match self.case(steps) {
            Ok(c) => c,
            // Not a finding of the device: the sequence itself is of another family.
            Err(e) => {
                return Trial {
                    run: e.failed_run(),
                    fault: None,
                }
            }
        };
        let mut run = self.session.run_case(&info, &case, false);
        let Outcome::Fail(failure) = run.outcome.clone() else {
            return Trial { run, fault: None };
        };
        let rec = failure.step.and_then(|i| run.evidence.get(i)).cloned();
        let step = rec.as_ref().map_or(0, |r| r.step);
        let kind = self.kind(steps.get(step));
        let transport = rec
            .as_ref()
            .and_then(|r| r.note.as_deref())
            .is_some_and(|n| n.starts_with("transport:"))
            || rec.is_none();
        let exp_silent = rec
            .as_ref()
            .and_then(|r| r.expected.as_ref())
            .is_none_or(|a| a.is_silence());
        let got_silent = rec
            .as_ref()
            .and_then(|r| r.got.as_ref())
            .is_none_or(|a| a.is_silence());
        let (class, detail) = if transport {
            // The session restarted a process that died (a reconnected socket is not new).
            self.clean = self.restarts == Some(true);
            (FindingClass::Crash, String::new())
        } else if !exp_silent && got_silent {
            // Still talking? A read the reference answers.
            let probe = self.probe.clone();
            let p = self.run_raw(&probe);
            let base = steps.len();
            let hung = p.outcome.failed();
            for mut r in p.evidence {
                r.step += base;
                r.note = Some(match r.note {
                    Some(n) => format!("liveness probe; {n}"),
                    None => "liveness probe".to_owned(),
                });
                run.evidence.push(r);
            }
            if hung {
                (FindingClass::Hang, String::new())
            } else {
                (FindingClass::Mismatch, "/silence-where-answer".to_owned())
            }
        } else if exp_silent && !got_silent {
            (FindingClass::Mismatch, "/answer-where-silent".to_owned())
        } else {
            (FindingClass::Mismatch, "/different-answer".to_owned())
        };
        let signature = format!("{}/{kind}{detail}", class.as_str());
        Trial {
            run,
            fault: Some(Fault {
                class,
                step,
                signature,
                failure,
            }),
        }
    }

    fn requirement(&self, id: &str) -> Option<RequirementRef> {
        RequirementRef::of(self.family, id)
    }

    fn requirement_ids(&self) -> Vec<(String, Level)> {
        engine::requirement_ids(self.family)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use drivespec_psd4xx::step::Step as PsdStep;

    fn step(action: Action) -> Step {
        Step {
            action,
            class: "test".to_owned(),
            text: "a step".to_owned(),
            requirements: Vec::new(),
        }
    }

    #[test]
    fn a_cyclic_step_is_not_an_hpd_step() {
        let listen = step(Action::Hpd(HAction::Listen { us: 5 }));
        let cyclic = step(Action::Psd4xx(PsdStep::Hold { cycles: 1 }));
        assert!(engine::own_steps::<HAction>(std::slice::from_ref(&listen)).is_ok());
        let steps = [listen.clone(), listen.clone(), listen, cyclic];
        let e = engine::own_steps::<HAction>(&steps).unwrap_err();
        assert_eq!(
            e.to_string(),
            "step 3 (\"a step\") is a psd4xx step, not a hpd step"
        );
        let run = e.failed_run();
        assert!(
            matches!(&run.outcome, Outcome::Fail(f) if f.step == Some(3) && f.message == e.to_string())
        );
    }
}
