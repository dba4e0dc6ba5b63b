//! The PSx3xx fuzz target: sequences from [`sequences`], run as a case through the
//! conformance session ([`Psx3xxSession`]) over the cyclic-exchange protocol, so every cycle's
//! input image and every ISDU and injection reply is judged exactly as `drivespec conform`
//! judges it: the reference drive fed the same requests, ISDU replies and the status word
//! exact (ErrorTypes the spec accepts as variants included), position and speed within the
//! motion cases' tolerance when the sequence may move the drive (manual 3.1–3.4, 4, 5).
//!
//! Environment injections are optional in the protocol: before the first sequence each kind
//! the generator uses is tried once (then `RESET`), and only the kinds the device takes
//! (`OK`) are sent.
//!
//! A failing step is a crash when the transport failed (the process exited, the connection
//! closed), a hang when the device sent no reply within the protocol's time-out (2 s), and a
//! mismatch otherwise; the signature names the step kind and what differs.

mod sequences;

use crate::cyclic_target::{self, image_differences, Bound, CyclicFuzz, CyclicTarget};
use crate::replay::Step;
use drivespec_conform::case::{CaseInfo, CaseRun, Role};
use drivespec_conform::cyclic::Peer;
use drivespec_conform::psx3xx::cases::{PsxCase, StepDef, EXACT, MOTION};
use drivespec_conform::psx3xx::output;
use drivespec_conform::psx3xx::{Psx3xx, Psx3xxSuite};
use drivespec_conform::suite::SetupError;
use drivespec_psx3xx::step::Step as PsxStep;
use drivespec_psx3xx::{Input, Output, Stamp};
use drivespec_sim::rng::Rng;
use drivespec_spec::hex::parse_hex;
use drivespec_spec::{Family, FamilyId, Level};
use sequences::{PsxGen, ENV_KINDS};

/// The PSx3xx target on one device under test.
pub(crate) type Psx3xxTarget<'a, 's> = CyclicTarget<'a, Psx3xx<'a, 's>, PsxFuzz<'a, 's>>;

/// A target on `peer`, with the reference from `suite`.
pub(crate) fn target<'a, 's>(
    suite: &'a Psx3xxSuite<'s>,
    peer: Box<dyn Peer + 'a>,
) -> Result<Psx3xxTarget<'a, 's>, SetupError> {
    CyclicTarget::new(suite.cyclic_session(peer), &ENV_KINDS, |envs| {
        let gen = PsxGen::new(suite, envs).map_err(SetupError::Spec)?;
        let ts = suite.reference().rules().timestamp();
        let family = suite.family();
        let moving = ["2", "193", &ts.control_word_param, &ts.target_param]
            .iter()
            .filter_map(|id| family.parameters.iter().find(|p| p.id == *id))
            .filter_map(|p| u16::try_from(p.number).ok())
            .collect();
        Ok(PsxFuzz { suite, gen, moving })
    })
}

/// The PSx3xx sequences and their cases.
pub(crate) struct PsxFuzz<'a, 's> {
    suite: &'a Psx3xxSuite<'s>,
    gen: PsxGen<'s>,
    /// ISDU indices whose writes may move the drive: the commands (ISDU 2, 193) and the
    /// control word and target of the time-stamp format (ISDU 110, 112).
    moving: Vec<u16>,
}

impl<'a, 's> CyclicFuzz<'s> for PsxFuzz<'a, 's> {
    type Family = Psx3xx<'a, 's>;
    type Step = PsxStep;

    fn generate(&mut self, rng: &mut Rng) -> Vec<Step> {
        self.gen.sequence(rng)
    }

    fn kind(s: &PsxStep) -> String {
        kind(s)
    }

    fn bound(s: &mut PsxStep) -> Option<Bound<'_>> {
        match s {
            PsxStep::Hold { cycles: c }
            | PsxStep::Until { max: c, .. }
            | PsxStep::IsduPoll { max: c, .. } => Some(Bound::Cycles(c)),
            PsxStep::Advance { us } => Some(Bound::Micros(us)),
            _ => None,
        }
    }

    fn spec(&self) -> &Family {
        self.suite.family()
    }

    fn case(&self, steps: &[Step], own: &[&PsxStep]) -> (CaseInfo, PsxCase) {
        let mut requirements: Vec<String> = steps
            .iter()
            .flat_map(|s| s.requirements.iter().cloned())
            .collect();
        requirements.sort();
        requirements.dedup();
        let info = CaseInfo {
            id: "psx3xx/fuzz/sequence".to_owned(),
            family: FamilyId::Psx3xx,
            requirements,
            level: Level::Must,
            description: "a fuzz sequence".to_owned(),
            steps: steps.iter().map(|s| s.text.clone()).collect(),
        };
        // The motion cases' tolerance as soon as anything may move the drive; the ISDU
        // cases' (exact) otherwise.
        let moves = own.iter().any(|a| match a {
            PsxStep::IsduRead { .. }
            | PsxStep::IsduPoll { .. }
            | PsxStep::Hold { .. }
            | PsxStep::Advance { .. } => false,
            PsxStep::IsduWrite { index, .. } => self.moving.contains(index),
            _ => true,
        });
        let d = self.suite.reference().rules().default_format();
        let case = PsxCase {
            start: idle(self.suite, d),
            steps: own
                .iter()
                .zip(steps)
                .map(|(a, s)| StepDef {
                    role: Role::Check,
                    text: s.text.clone(),
                    action: Self::bounded(a),
                })
                .collect(),
            tol: if moves { MOTION } else { EXACT },
            plot: false,
            open: None,
            still: None,
            not_applicable: None,
        };
        (info, case)
    }

    /// Which parts of the failing step's answer differ: `reply` for ISDU replies and
    /// injections, the input-image fields otherwise (`status-b<bits>`, `speed`, `position`).
    fn differs(&self, run: &CaseRun, step: usize) -> String {
        let Some(r) = run
            .evidence
            .iter()
            .find(|r| r.step == step && r.ok == Some(false))
        else {
            return "input-image".to_owned();
        };
        if r.sent.is_none() {
            return "reply".to_owned();
        }
        let d = self.suite.reference();
        let image = |a: Option<&drivespec_conform::case::Answer>| {
            a.and_then(|a| parse_hex(&a.hex).ok())
                .and_then(|b| Input::parse(d.rules(), d.byte_order(), &b).ok())
        };
        let (Some(e), Some(g)) = (image(r.expected.as_ref()), image(r.got.as_ref())) else {
            return "no-image".to_owned();
        };
        image_differences(
            Vec::new(),
            e.status ^ g.status,
            e.rpm != g.rpm,
            e.actual != g.actual,
        )
    }
}

/// The all-zero output of a format (format 0: the stamp inactive).
fn idle(suite: &Psx3xxSuite<'_>, format: u8) -> Output {
    let inactive = Stamp::inactive(suite.reference().rules().timestamp());
    output(format, 0, 0, 0, inactive.0)
}

/// The signature name of a PSx3xx step: `pd-format-<format>`, `isdu-read-<index>`,
/// `isdu-write-<index>`, `env-<kind>` or the step's name.
fn kind(s: &PsxStep) -> String {
    match s {
        PsxStep::PdOut { format, .. } => format!("pd-format-{format}"),
        PsxStep::IsduRead { index, .. } | PsxStep::IsduPoll { index, .. } => {
            format!("isdu-read-{index}")
        }
        PsxStep::IsduWrite { index, .. } => format!("isdu-write-{index}"),
        PsxStep::Env { env } => cyclic_target::env_signature(env),
        other => other.name().to_owned(),
    }
}
