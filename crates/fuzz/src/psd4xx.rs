//! The PSD4xx fuzz target: sequences from [`sequences`], run as a case through the
//! conformance session ([`Psd4xxSession`]) over the cyclic-exchange protocol, so every cycle's
//! input image and every record and injection reply is judged exactly as `drivespec conform`
//! judges it: the reference drive fed the same requests, PKW and status exact, position and
//! speed within the motion cases' tolerance when the sequence moves the drive (manual 3.5–3.9,
//! chapter 4).
//!
//! Environment injections are optional in the protocol: before the first sequence each kind
//! the generator uses is tried once (then `RESET`), and only the kinds the device takes
//! (`OK`) are sent.
//!
//! A failing step is a crash when the transport failed (the process exited, the connection
//! closed), a hang when the device sent no reply within the protocol's time-out (2 s), and a
//! mismatch otherwise; the signature names the step kind and the fields that differ.

mod sequences;

use crate::cyclic_target::{self, image_differences, Bound, CyclicFuzz, CyclicTarget};
use crate::replay::Step;
use drivespec_conform::case::{CaseInfo, CaseRun, Role};
use drivespec_conform::cyclic::Peer;
use drivespec_conform::psd4xx::cases::{PsdCase, StepDef, EXCHANGE, MOTION};
use drivespec_conform::psd4xx::{Psd4xx, Psd4xxSuite};
use drivespec_conform::suite::SetupError;
use drivespec_psd4xx::step::Step as PsdStep;
use drivespec_psd4xx::Input;
use drivespec_sim::rng::Rng;
use drivespec_spec::hex::parse_hex;
use drivespec_spec::{Family, FamilyId, Level};
use sequences::{PsdGen, ENV_KINDS};

/// The PSD4xx target on one device under test.
pub(crate) type Psd4xxTarget<'a, 's> = CyclicTarget<'a, Psd4xx<'a, 's>, PsdFuzz<'a, 's>>;

/// A target on `peer`, with the reference from `suite`.
pub(crate) fn target<'a, 's>(
    suite: &'a Psd4xxSuite<'s>,
    peer: Box<dyn Peer + 'a>,
) -> Result<Psd4xxTarget<'a, 's>, SetupError> {
    CyclicTarget::new(suite.cyclic_session(peer), &ENV_KINDS, |envs| {
        Ok(PsdFuzz {
            suite,
            gen: PsdGen::new(suite, envs).map_err(SetupError::Spec)?,
        })
    })
}

/// The PSD4xx sequences and their cases.
pub(crate) struct PsdFuzz<'a, 's> {
    suite: &'a Psd4xxSuite<'s>,
    gen: PsdGen,
}

impl<'a, 's> CyclicFuzz<'static> for PsdFuzz<'a, 's> {
    type Family = Psd4xx<'a, 's>;
    type Step = PsdStep;

    fn generate(&mut self, rng: &mut Rng) -> Vec<Step> {
        self.gen.sequence(rng)
    }

    fn kind(s: &PsdStep) -> String {
        kind(s)
    }

    fn bound(s: &mut PsdStep) -> Option<Bound<'_>> {
        match s {
            PsdStep::Hold { cycles: c } | PsdStep::Until { max: c, .. } => Some(Bound::Cycles(c)),
            PsdStep::Advance { us } => Some(Bound::Micros(us)),
            _ => None,
        }
    }

    fn spec(&self) -> &Family {
        self.suite.family()
    }

    fn case(&self, steps: &[Step], own: &[&PsdStep]) -> (CaseInfo, PsdCase) {
        let mut requirements: Vec<String> = steps
            .iter()
            .flat_map(|s| s.requirements.iter().cloned())
            .collect();
        requirements.sort();
        requirements.dedup();
        let info = CaseInfo {
            id: "psd4xx/fuzz/sequence".to_owned(),
            family: FamilyId::Psd4xx,
            requirements,
            level: Level::Must,
            description: "a fuzz sequence".to_owned(),
            steps: steps.iter().map(|s| s.text.clone()).collect(),
        };
        // The motion cases' tolerance as soon as anything may move the drive; the exchange
        // cases' otherwise.
        let moves = own.iter().any(|a| {
            !matches!(
                a,
                PsdStep::Pkw { .. }
                    | PsdStep::Hold { .. }
                    | PsdStep::RecordRead { .. }
                    | PsdStep::RecordWrite { .. }
                    | PsdStep::Advance { .. }
            )
        });
        let case = PsdCase {
            steps: own
                .iter()
                .zip(steps)
                .map(|(a, s)| StepDef {
                    role: Role::Check,
                    text: s.text.clone(),
                    action: Self::bounded(a),
                })
                .collect(),
            tol: if moves { MOTION } else { EXCHANGE },
            plot: false,
            open: None,
        };
        (info, case)
    }

    /// Which parts of the failing step's answer differ: `reply` for records and injections,
    /// the input-image fields otherwise (`status-b<bits>`, `pkw-code`, `pkw-value`, `speed`,
    /// `position`).
    fn differs(&self, run: &CaseRun, step: usize) -> String {
        let Some(r) = run
            .evidence
            .iter()
            .find(|r| r.step == step && r.ok == Some(false))
        else {
            return "input-image".to_owned();
        };
        if r.note.as_deref() == Some("exact") {
            return "reply".to_owned();
        }
        let rules = self.suite.reference().rules();
        let image = |a: Option<&drivespec_conform::case::Answer>| {
            a.and_then(|a| parse_hex(&a.hex).ok())
                .and_then(|b| Input::parse(rules, &b).ok())
        };
        let (Some(e), Some(g)) = (image(r.expected.as_ref()), image(r.got.as_ref())) else {
            return "no-image".to_owned();
        };
        let mut parts: Vec<String> = Vec::new();
        if e.pkw.ak != g.pkw.ak {
            parts.push("pkw-code".to_owned());
        } else if e.pkw != g.pkw {
            parts.push("pkw-value".to_owned());
        }
        image_differences(
            parts,
            e.status ^ g.status,
            e.speed != g.speed,
            e.actual != g.actual,
        )
    }
}

/// The signature name of a PSD4xx step: `pkw-ak<code>`, `env-<kind>` or the step's name.
fn kind(s: &PsdStep) -> String {
    match s {
        PsdStep::Pkw { pkw } => format!("pkw-ak{}", pkw.ak),
        PsdStep::Env { env } => cyclic_target::env_signature(env),
        other => other.name().to_owned(),
    }
}
