//! What the fuzz targets over the cyclic-exchange protocol (PSD4xx, PSx3xx) share: their
//! capabilities, the bounds a replay file cannot exceed, the signature of a step and how a
//! failed case run becomes a finding (README "Cyclic-exchange protocol", "Fuzzing").

use super::engine::{Fault, Trial};
use super::replay::{Action, CyclicStep, FindingClass, Step};
use crate::case::{CaseRun, Outcome, RequirementRef};
use crate::cyclic::{Env, PeerError};
use crate::link::Caps;
use drivespec_spec::Family;

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

/// The kind of an injection: the first word of its `ENV` line (`jam`, `link`, …).
pub(crate) fn env_kind(env: &Env) -> String {
    env.to_string()
        .split(' ')
        .next()
        .unwrap_or_default()
        .to_owned()
}

/// What kind of step a fuzz step is, for signatures: `own` names the family's steps, the
/// steps every cyclic family has are named here.
pub(crate) fn kind(s: Option<&Step>, own: fn(&CyclicStep) -> Option<String>) -> String {
    let Some(action) = s.map(|s| &s.action) else {
        return "start".to_owned();
    };
    let Action::Cyclic(c) = action else {
        return "not-cyclic".to_owned();
    };
    if let Some(name) = own(c) {
        return name;
    }
    match c {
        CyclicStep::Env(env) => format!("env-{}", env_kind(env)),
        CyclicStep::Hold { .. } => "hold".to_owned(),
        CyclicStep::Until { .. } => "until".to_owned(),
        CyclicStep::Advance { .. } => "advance".to_owned(),
        _ => "cyclic".to_owned(),
    }
}

/// The trial of a case run: none when it passed; otherwise a crash when the transport failed,
/// a hang when the device did not reply in time, a mismatch otherwise (`differs` names the
/// fields of the failing step's answer that differ), with the failing step's requirements.
pub(crate) fn trial(
    mut run: CaseRun,
    peer_error: Option<PeerError>,
    steps: &[Step],
    family: &Family,
    own: fn(&CyclicStep) -> Option<String>,
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
    let signature = format!("{}/{}{detail}", class.as_str(), kind(steps.get(step), own));
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
