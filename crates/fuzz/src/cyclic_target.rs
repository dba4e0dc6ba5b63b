//! What the fuzz targets over the cyclic-exchange protocol (PSD4xx, PSx3xx) share: their
//! capabilities, the bounds a replay file cannot exceed, the signature of a step and how a
//! failed case run becomes a finding (`crates/cyclic/README.md`; README "Verdicts, findings, minimisation").

use crate::engine::{self, Fault, Target, Trial};
use crate::replay::{FamilyStep, FindingClass, Start, Step};
use drivespec_conform::case::{CaseInfo, CaseRun, Outcome, RequirementRef};
use drivespec_conform::cyclic::{Env, PeerError};
use drivespec_conform::cyclic_session::{CyclicFamily, CyclicSession};
use drivespec_conform::link::{Caps, LinkError};
use drivespec_conform::suite::{Session, SetupError};
use drivespec_sim::rng::Rng;
use drivespec_spec::{Family, FamilyId, Level};

/// Every run starts with `RESET` on the device and a fresh reference, on any transport; times
/// are virtual (carried in the requests).
pub(crate) const CAPS: Caps = Caps {
    reset: true,
    power_cycle: true,
    virtual_time: true,
    inputs: false,
};

/// Most cycles one `hold` or `until` step runs (10 min of bus time at 10 ms): a replay file
/// cannot make a run endless.
pub(crate) const MAX_STEP_CYCLES: u32 = 60_000;

/// Longest `advance` step (10 min).
pub(crate) const MAX_ADVANCE_US: u64 = 600_000_000;

/// The part of a step a replay file bounds.
pub(crate) enum Bound<'x> {
    /// Most cycles of a wait (`hold`, `until`, a poll): at most [`MAX_STEP_CYCLES`].
    Cycles(&'x mut u32),
    /// The time of an `advance`: at most [`MAX_ADVANCE_US`].
    Micros(&'x mut u64),
}

/// The kind of an injection: the first word of its `ENV` text (`jam`, `link`, …).
pub(crate) fn env_kind(env: &str) -> String {
    env.split(' ').next().unwrap_or_default().to_owned()
}

/// The signature name of an `env` step: `env-` and the injection's kind.
pub(crate) fn env_signature(env: &str) -> String {
    format!("env-{}", env_kind(env))
}

/// The trial of a case run: none when it passed; otherwise a crash when the transport failed,
/// a hang when the device did not reply in time, a mismatch otherwise (`differs` names the
/// fields of the failing step's answer that differ), with the failing step's requirements.
pub(crate) fn trial(
    mut run: CaseRun,
    peer_error: Option<PeerError>,
    steps: &[Step],
    family: &Family,
    kind: impl FnOnce(usize) -> String,
    differs: impl FnOnce(&CaseRun, usize) -> String,
) -> Trial {
    let Outcome::Fail(mut failure) = run.outcome.clone() else {
        return Trial { run, fault: None };
    };
    let step = failure.step.unwrap_or(0);
    let (class, detail) = match &peer_error {
        Some(PeerError::Timeout { .. }) => (FindingClass::Hang, String::new()),
        Some(PeerError::Link(_)) => (FindingClass::Crash, String::new()),
        Some(PeerError::Garbage { .. }) => (FindingClass::Mismatch, "/garbage".to_owned()),
        None if failure.message.starts_with("the exchange failed") => {
            (FindingClass::Mismatch, "/exchange".to_owned())
        }
        None => (FindingClass::Mismatch, format!("/{}", differs(&run, step))),
    };
    // The failing step's requirements, not the whole sequence's.
    if let Some(s) = steps.get(step) {
        failure.requirements = s
            .requirements
            .iter()
            .filter_map(|id| RequirementRef::of(family, id))
            .collect();
    }
    if let Some(e) = &peer_error {
        failure.message = format!("{} ({e})", failure.message);
    }
    run.outcome = Outcome::Fail(failure.clone());
    let signature = format!("{}/{}{detail}", class.as_str(), kind(step));
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

/// What a cyclic family's fuzz target adds to its conformance session: the sequences, the
/// case a sequence runs as, and the names of its steps and of what differs.
pub(crate) trait CyclicFuzz<'s> {
    /// The family the session runs.
    type Family: CyclicFamily<'s>;
    /// The family's step type.
    type Step: FamilyStep + Clone;
    /// A new sequence.
    fn generate(&mut self, rng: &mut Rng) -> Vec<Step>;
    /// The case a sequence runs as; `own` holds the family step of each of `steps`.
    fn case(
        &self,
        steps: &[Step],
        own: &[&Self::Step],
    ) -> (CaseInfo, <Self::Family as CyclicFamily<'s>>::Case);
    /// Which parts of the failing step's answer differ.
    fn differs(&self, run: &CaseRun, step: usize) -> String;
    /// The signature name of a step.
    fn kind(s: &Self::Step) -> String;
    /// The part of a step a replay file bounds, if it has one.
    fn bound(s: &mut Self::Step) -> Option<Bound<'_>>;
    /// A step within the bounds a replay file cannot exceed.
    fn bounded(s: &Self::Step) -> Self::Step {
        let mut s = s.clone();
        match Self::bound(&mut s) {
            Some(Bound::Cycles(c)) => *c = (*c).min(MAX_STEP_CYCLES),
            Some(Bound::Micros(us)) => *us = (*us).min(MAX_ADVANCE_US),
            None => {}
        }
        s
    }
    /// The family's spec.
    fn spec(&self) -> &Family;
}

/// A cyclic family's fuzz target on one device under test: its session and its fuzz part.
pub(crate) struct CyclicTarget<'a, F, P> {
    session: CyclicSession<'a, F>,
    part: P,
}

impl<'a, 's, F: CyclicFamily<'s>, P: CyclicFuzz<'s, Family = F>> CyclicTarget<'a, F, P> {
    /// A target on `session`, greeted with `HELLO`; `part` gets the kinds of the injections in
    /// `envs` the device takes (they are optional, only those are sent).
    pub(crate) fn new(
        session: CyclicSession<'a, F>,
        envs: &[Env],
        part: impl FnOnce(Vec<String>) -> Result<P, SetupError>,
    ) -> Result<CyclicTarget<'a, F, P>, SetupError> {
        let mut session = session.judging_whole_runs();
        session.hello().map_err(SetupError::Usage)?;
        let taken: Vec<String> = envs
            .iter()
            .filter(|e| session.takes(**e))
            .map(|e| env_kind(&e.to_string()))
            .collect();
        Ok(CyclicTarget {
            session,
            part: part(taken)?,
        })
    }
}

impl<'s, F: CyclicFamily<'s>, P: CyclicFuzz<'s, Family = F>> Target for CyclicTarget<'_, F, P> {
    fn family(&self) -> FamilyId {
        F::ID
    }

    fn describe(&self) -> String {
        Session::describe(&self.session)
    }

    fn caps(&self) -> Caps {
        CAPS
    }

    fn generate(&mut self, rng: &mut Rng) -> Vec<Step> {
        self.part.generate(rng)
    }

    fn fresh(&mut self) -> Result<Start, LinkError> {
        // The case run resets both sides itself (and restarts a device that died).
        Ok(Start::Fresh)
    }

    fn warm_up(&mut self) {}

    fn run(&mut self, steps: &[Step]) -> Trial {
        let own = match engine::own_steps::<P::Step>(steps) {
            Ok(own) => own,
            // Not a finding of the device: the sequence itself is of another family.
            Err(e) => {
                return Trial {
                    run: e.failed_run(),
                    fault: None,
                }
            }
        };
        let (info, case) = self.part.case(steps, &own);
        let run = self.session.run_case(&info, &case);
        let peer_error = self.session.take_peer_error();
        trial(
            run,
            peer_error,
            steps,
            self.part.spec(),
            |step| {
                own.get(step)
                    .map_or_else(|| "start".to_owned(), |s| P::kind(s))
            },
            |run, step| self.part.differs(run, step),
        )
    }

    fn requirement(&self, id: &str) -> Option<RequirementRef> {
        RequirementRef::of(self.part.spec(), id)
    }

    fn requirement_ids(&self) -> Vec<(String, Level)> {
        engine::requirement_ids(self.part.spec())
    }
}

/// The detail of a mismatched input image in a signature: `parts` already found, then the
/// status bits that differ (`status-b0+6`), `speed`, `position`; `input-image` when the last
/// cycle of the step agrees and an earlier one did not.
pub(crate) fn image_differences(
    mut parts: Vec<String>,
    status_bits: u16,
    speed: bool,
    position: bool,
) -> String {
    if status_bits != 0 {
        let list: Vec<String> = (0..16u16)
            .filter(|b| status_bits & (1 << b) != 0)
            .map(|b| b.to_string())
            .collect();
        parts.push(format!("status-b{}", list.join("+")));
    }
    if speed {
        parts.push("speed".to_owned());
    }
    if position {
        parts.push("position".to_owned());
    }
    if parts.is_empty() {
        "input-image".to_owned()
    } else {
        parts.join(",")
    }
}
