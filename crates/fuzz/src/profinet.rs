//! `fuzz psd4xx --layer profinet`: spec-aware mutation of what a PSD4xx PROFINET IO device
//! receives (IEC 61158-6-10: DCP, PNIO-CM Connect and records, RT class 1 cyclic frames),
//! each sequence followed by a liveness probe (crates/fuzz/README.md, "The PROFINET layer").
//!
//! - [`generate`]: the sequences, drawn from the spec and the standard's boundaries.
//! - [`exec`]: running them over a [`PnWire`] and probing the device after them: it must
//!   still answer DCP Identify by its name, accept a valid Connect up to ApplicationReady
//!   and send cyclic data. A device that fails the probe is a finding (class `hang`,
//!   signature `hang/profinet-probe/<stage>`), minimised by the campaign of `engine.rs`.
//! - [`MemoryWire`]: a device in memory on a virtual clock (`--dut sim`, tests).
//!
//! The socket loop of a real interface is the caller's (`drivespec fuzz` in the CLI).

mod exec;
mod generate;
mod memory;
mod step;

pub use exec::{PnWire, PnWireError};
pub use memory::MemoryWire;
pub use step::PnStep;

use crate::engine::{self, Fault, Target, Trial};
use crate::replay::{Action, FindingClass, Start, Step};
use drivespec_conform::case::{Answer, CaseRun, Failure, Outcome, Record, RequirementRef, Role};
use drivespec_conform::link::{Caps, LinkError};
use drivespec_profinet::identity::Identity;
use drivespec_sim::rng::Rng;
use drivespec_spec::{FamilyId, Level, Spec};
use exec::Runner;
use generate::Generator;

/// What the probe checks, for the evidence and the failure text.
const PROBE: &str = "liveness probe: DCP Identify by name, Connect, PrmEnd, ApplicationReady, \
                     cyclic data, Release";

/// The PROFINET layer of a PSD4xx as a fuzzing target (our doc: module `profinet`).
pub(crate) struct ProfinetTarget<'s> {
    spec: &'s Spec,
    runner: Runner<'s>,
    generator: Generator,
}

impl<'s> ProfinetTarget<'s> {
    /// The target on `wire`, with the PSD4xx identity of `spec`.
    pub(crate) fn new(
        spec: &'s Spec,
        wire: Box<dyn PnWire + 's>,
        identity: Identity,
    ) -> ProfinetTarget<'s> {
        let generator = Generator::of_spec(spec, &identity, wire.target());
        ProfinetTarget {
            spec,
            runner: Runner::new(wire, identity),
            generator,
        }
    }

    /// The probe alone, after the device restarted (a simulated one) or answered Identify
    /// again (a device that may be restarting): None when it passes, else why not (a setup
    /// error before fuzzing: no station).
    pub(crate) fn check_alive(&mut self) -> Option<String> {
        if let Err(e) = self.runner.fresh_within(exec::SETUP_WAIT) {
            return Some(e.to_string());
        }
        match self.runner.probe() {
            Ok(Ok(_)) => None,
            Ok(Err((stage, why))) => Some(format!("{}: {why}", stage.as_str())),
            Err(e) => Some(e.to_string()),
        }
    }
}

impl Target for ProfinetTarget<'_> {
    fn family(&self) -> FamilyId {
        FamilyId::Psd4xx
    }

    fn describe(&self) -> String {
        format!("{} (PROFINET layer)", self.runner.wire.describe())
    }

    fn caps(&self) -> Caps {
        Caps {
            reset: self.runner.wire.can_restart(),
            power_cycle: false,
            virtual_time: self.runner.wire.virtual_time(),
            inputs: false,
        }
    }

    fn generate(&mut self, rng: &mut Rng) -> Vec<Step> {
        self.generator.sequence(rng)
    }

    fn fresh(&mut self) -> Result<Start, LinkError> {
        match self.runner.fresh() {
            Ok(true) => Ok(Start::Fresh),
            Ok(false) => Ok(Start::AsIs),
            Err(e) => Err(LinkError::Io(e.to_string())),
        }
    }

    fn warm_up(&mut self) {}

    fn run(&mut self, steps: &[Step]) -> Trial {
        let start = self.runner.wire.now();
        let mut evidence: Vec<Record> = Vec::new();
        let last = steps.len().saturating_sub(1);
        let crash = |i: usize, e: PnWireError, evidence: Vec<Record>| {
            let failure = Failure {
                step: Some(i),
                message: e.to_string(),
                expected: "the wire carries the frames".to_owned(),
                got: e.to_string(),
                requirements: Vec::new(),
            };
            Trial {
                run: CaseRun {
                    outcome: Outcome::Fail(failure.clone()),
                    findings: Vec::new(),
                    checked: Vec::new(),
                    evidence,
                    elapsed_us: 0,
                },
                fault: Some(Fault {
                    class: FindingClass::Crash,
                    step: i,
                    signature: "crash/profinet/wire".to_owned(),
                    failure,
                }),
            }
        };
        for (i, s) in steps.iter().enumerate() {
            let Action::Profinet(p) = &s.action else {
                continue;
            };
            match self.runner.step(p) {
                Ok(o) => evidence.push(self.runner.record_of(i, &s.text, &o)),
                Err(e) => return crash(i, e, evidence),
            }
        }
        let probe = match self.runner.probe() {
            Ok(p) => p,
            Err(e) => return crash(last, e, evidence),
        };
        let at_us = u64::try_from(self.runner.wire.now().as_micros()).unwrap_or(u64::MAX);
        let elapsed_us = u64::try_from((self.runner.wire.now().saturating_sub(start)).as_micros())
            .unwrap_or(u64::MAX);
        let (ok, text) = match &probe {
            Ok(t) => (true, t.clone()),
            Err((stage, why)) => (false, format!("{}: {why}", stage.as_str())),
        };
        evidence.push(Record {
            step: steps.len(),
            role: Role::Check,
            action: PROBE.to_owned(),
            at_us,
            sent: None,
            sent_text: Some(PROBE.to_owned()),
            expected: None,
            got: Some(Answer {
                hex: String::new(),
                text: text.clone(),
                delay_us: None,
            }),
            ok: Some(ok),
            note: None,
        });
        let fault = probe.err().map(|(stage, why)| {
            let failure = Failure {
                step: Some(last),
                message: format!(
                    "after step {last} the device fails the liveness probe at {}: {why}",
                    stage.as_str()
                ),
                expected: "the device answers DCP Identify, accepts a valid Connect and sends \
                           cyclic data"
                    .to_owned(),
                got: text,
                requirements: Vec::new(),
            };
            Fault {
                class: FindingClass::Hang,
                step: last,
                signature: format!("hang/profinet-probe/{}", stage.as_str()),
                failure,
            }
        });
        Trial {
            run: CaseRun {
                outcome: match &fault {
                    Some(f) => Outcome::Fail(f.failure.clone()),
                    None => Outcome::Pass,
                },
                findings: Vec::new(),
                checked: Vec::new(),
                evidence,
                elapsed_us,
            },
            fault,
        }
    }

    fn requirement(&self, id: &str) -> Option<RequirementRef> {
        RequirementRef::of(self.spec.family(FamilyId::Psd4xx), id)
    }

    fn requirement_ids(&self) -> Vec<(String, Level)> {
        engine::requirement_ids(self.spec.family(FamilyId::Psd4xx))
    }
}
