//! The family-neutral fuzzing loop: generate a sequence, run it on the device and the
//! reference, count what happened, and minimise every new finding (README "Verdicts, findings, minimisation").
//!
//! Determinism: the generator draws from one seeded [`Rng`] and never from the results, so
//! the same seed sends the same sequences whatever the device does; on `sim` every run is on
//! virtual time, so the findings and their replays are the same too. Wall-clock time only
//! decides when `--duration` stops the loop.

use crate::ddmin::ddmin;
use crate::replay::{Action, FamilyStep, FindingClass, Start, Step};
use crate::stats::Stats;
use drivespec_conform::case::{CaseRun, Failure, Outcome, RequirementRef};
use drivespec_conform::link::{Caps, LinkError};
use drivespec_hpd::step::Step as HpdStep;
use drivespec_sim::rng::Rng;
use drivespec_spec::{Family, FamilyId, Level};

/// What one run of a sequence found.
#[derive(Debug, Clone)]
pub(crate) struct Trial {
    /// The evidence, one record per step run (plus a liveness probe after a silence).
    pub(crate) run: CaseRun,
    /// The problem, when there is one.
    pub(crate) fault: Option<Fault>,
}

/// A problem at one step of a sequence.
#[derive(Debug, Clone)]
pub(crate) struct Fault {
    /// Mismatch, hang or crash.
    pub(crate) class: FindingClass,
    /// Index of the failing step in the sequence.
    pub(crate) step: usize,
    /// `class/message-kind/detail`.
    pub(crate) signature: String,
    /// The failure as the conformance runner words it.
    pub(crate) failure: Failure,
}

/// One family's fuzzing: sequences from the spec, and runs against the device and the
/// reference model (HPD in [`crate::hpd`], PSD4xx in [`crate::psd4xx`]).
pub(crate) trait Target {
    /// The family.
    fn family(&self) -> FamilyId;
    /// The device under test, one line.
    fn describe(&self) -> String;
    /// What the transport can do.
    fn caps(&self) -> Caps;
    /// The next sequence, drawn from `rng` only.
    fn generate(&mut self, rng: &mut Rng) -> Vec<Step>;
    /// Device and reference in their start state (reset, or a restarted process), when the
    /// transport can; `Start::AsIs` when it cannot.
    fn fresh(&mut self) -> Result<Start, LinkError>;
    /// Makes sure the device is talking (a just-started process), without judging.
    fn warm_up(&mut self);
    /// Runs `steps` from the current state, judged against the reference.
    fn run(&mut self, steps: &[Step]) -> Trial;
    /// A requirement with its text, for reports.
    fn requirement(&self, id: &str) -> Option<RequirementRef>;
    /// Every must/should requirement ID of the family, in spec order.
    fn requirement_ids(&self) -> Vec<(String, Level)>;
}

/// A finding: the minimised sequence and how it failed.
#[derive(Debug, Clone)]
pub(crate) struct Found {
    /// The minimised steps.
    pub(crate) steps: Vec<Step>,
    /// The run that confirmed it (or the original run when it did not reproduce).
    pub(crate) trial: Trial,
    /// The original failure.
    pub(crate) fault: Fault,
    /// Sequence number that found it.
    pub(crate) sequence: u64,
    /// Steps before minimisation.
    pub(crate) original_steps: usize,
    /// Runs spent minimising.
    pub(crate) runs: u64,
    /// Confirmed from the start state.
    pub(crate) reproduced: bool,
    /// How the device was at the start of the confirming run.
    pub(crate) start: Start,
    /// Times the signature was seen.
    pub(crate) occurrences: u64,
    /// The wall-clock budget ended the minimisation: the steps are as far as it got.
    pub(crate) cut_short: bool,
}

/// Limits of a campaign.
#[derive(Debug, Clone)]
pub(crate) struct Limits {
    /// Sequences to run (None: until the deadline).
    pub(crate) iterations: Option<u64>,
    /// Wall-clock budget.
    pub(crate) duration: Option<std::time::Duration>,
    /// Distinct findings to minimise and keep; later ones are counted only.
    pub(crate) max_findings: usize,
    /// Runs per minimisation.
    pub(crate) minimize_runs: u64,
    /// Set by the caller to stop after the current sequence.
    pub(crate) stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
}

/// Steps kept since the last fresh start on transports that cannot reset (a restart, or the
/// latest half, beyond this).
const HISTORY_MAX: usize = 2_000;

/// Occurrences of one signature minimised at most this often: the shortest replay is kept.
const ATTEMPTS_PER_SIGNATURE: usize = 3;

/// Runs a campaign; `on_event` sees progress (sequence number) and each new finding.
pub(crate) fn campaign(
    target: &mut dyn Target,
    seed: u64,
    limits: Limits,
    stats: &mut Stats,
    on_event: &mut dyn FnMut(Event<'_>),
) -> Vec<Found> {
    let started = std::time::Instant::now();
    let deadline = limits.duration.map(|d| started + d);
    let caps = target.caps();
    let mut rng = Rng::new(seed);
    let mut found: Vec<Found> = Vec::new();
    let mut attempts: Vec<(String, usize)> = Vec::new();
    // Steps since the device was last in its start state (transports that cannot reset).
    let mut history: Vec<Step> = Vec::new();
    target.warm_up();
    let mut n: u64 = 0;
    loop {
        if limits.iterations.is_some_and(|max| n >= max) {
            stats.stopped_by = "iterations".to_owned();
            break;
        }
        if limits.duration.is_some_and(|d| started.elapsed() >= d) {
            stats.stopped_by = "duration".to_owned();
            break;
        }
        if limits.stop.load(std::sync::atomic::Ordering::Relaxed) {
            stats.stopped_by = "interrupted".to_owned();
            break;
        }
        let seq = target.generate(&mut rng);
        n += 1;
        if caps.reset {
            if let Err(e) = target.fresh() {
                stats.transport_error(&e);
            }
        }
        let trial = target.run(&seq);
        stats.record(&seq, &trial);
        on_event(Event::Sequence {
            n,
            findings: found.len(),
        });
        let Some(fault) = trial.fault.clone() else {
            if !caps.reset {
                history.extend(seq);
                if history.len() > HISTORY_MAX {
                    // Bounded memory: a fresh device where the transport allows, else only the
                    // latest steps are kept.
                    match target.fresh() {
                        Ok(Start::Fresh) => {
                            stats.restarts += 1;
                            history.clear();
                        }
                        Ok(Start::AsIs) => {
                            let extra = history.len().saturating_sub(HISTORY_MAX / 2);
                            history.drain(..extra);
                        }
                        Err(e) => stats.transport_error(&e),
                    }
                }
            }
            continue;
        };
        stats.failing_sequences += 1;
        if fault.class == FindingClass::Crash {
            stats.restarts += 1;
        }
        let known = found
            .iter()
            .position(|f| f.fault.signature == fault.signature);
        let tried = attempts
            .iter()
            .find(|(sig, _)| *sig == fault.signature)
            .map_or(0, |(_, k)| *k);
        // Minimise a new bug; minimise another occurrence only while the replay kept is
        // longer than one step or did not reproduce.
        let improvable = known
            .and_then(|i| found.get(i))
            .is_none_or(|g| g.steps.len() > 1 || !g.reproduced);
        let minimise_now = tried < ATTEMPTS_PER_SIGNATURE
            && improvable
            && (known.is_some() || found.len() < limits.max_findings);
        if let Some(g) = known.and_then(|i| found.get_mut(i)) {
            g.occurrences += 1;
        }
        if minimise_now {
            match attempts.iter_mut().find(|(sig, _)| *sig == fault.signature) {
                Some((_, k)) => *k += 1,
                None => attempts.push((fault.signature.clone(), 1)),
            }
            let cut: Vec<Step> = seq.iter().take(fault.step + 1).cloned().collect();
            let f = minimise(
                target,
                cut,
                &history,
                &fault,
                limits.minimize_runs,
                n,
                &trial,
                deadline,
            );
            stats.minimisation_runs += f.runs;
            match known {
                // Another occurrence of a known bug: keep the shorter replay.
                Some(i) => {
                    if let Some(g) = found.get_mut(i) {
                        let better =
                            f.reproduced && (!g.reproduced || weight(&f.steps) < weight(&g.steps));
                        if better {
                            let (occurrences, sequence) = (g.occurrences, g.sequence);
                            *g = f;
                            g.occurrences = occurrences;
                            g.sequence = sequence;
                            on_event(Event::Improved(i, g));
                        }
                    }
                }
                None => {
                    on_event(Event::Finding(&f));
                    found.push(f);
                }
            }
        } else if known.is_none() {
            stats.unminimised += 1;
        }
        // Back to a known state: a fresh device where the transport allows.
        match target.fresh() {
            Ok(Start::Fresh) => {
                if !caps.reset {
                    stats.restarts += 1;
                }
            }
            Ok(Start::AsIs) => {}
            Err(e) => stats.transport_error(&e),
        }
        history.clear();
    }
    stats.sequences = n;
    stats.wall_ms = started.elapsed().as_secs_f64() * 1000.0;
    found
}

/// What the campaign reports as it goes.
pub(crate) enum Event<'a> {
    /// Sequence `n` ran; `findings` so far.
    Sequence {
        /// Sequences run.
        n: u64,
        /// Findings so far.
        findings: usize,
    },
    /// A new finding, minimised.
    Finding(&'a Found),
    /// Finding `.0` got a shorter replay from another occurrence.
    Improved(usize, &'a Found),
}

/// Length of a replay for comparing minimisations: steps, then bytes.
fn weight(steps: &[Step]) -> (usize, usize) {
    let bytes = steps
        .iter()
        .map(|s| s.action.bytes().map_or(0, <[u8]>::len))
        .sum();
    (steps.len(), bytes)
}

/// Whether `trial` shows the fault with signature `sig`.
fn same_fault(trial: &Trial, sig: &str) -> bool {
    trial.fault.as_ref().is_some_and(|f| f.signature == sig)
}

/// Minimises `steps` (which failed with `fault` after `history`, the failing step last):
/// the failing step alone, else the sequence from the start state, else with the history;
/// then ddmin over the steps, over the bytes of each message, and over the steps again.
/// Every run starts from the start state where the transport allows; the last run that
/// showed the fault on the final sequence is its evidence (one more run confirms it if none
/// did). No run starts after `deadline`: the steps are then as far as minimisation got.
#[allow(clippy::too_many_arguments)]
pub(crate) fn minimise(
    target: &mut dyn Target,
    steps: Vec<Step>,
    history: &[Step],
    fault: &Fault,
    max_runs: u64,
    sequence: u64,
    original: &Trial,
    deadline: Option<std::time::Instant>,
) -> Found {
    let sig = fault.signature.clone();
    let original_steps = steps.len();
    let mut budget = max_runs;
    let mut start = Start::Fresh;
    let mut last: Option<(Vec<Step>, Trial)> = None;
    let cut_short = std::cell::Cell::new(false);
    let mut check = |target: &mut dyn Target, cand: &[Step]| -> Option<Trial> {
        if deadline.is_some_and(|d| std::time::Instant::now() >= d) {
            cut_short.set(true);
            return None;
        }
        match target.fresh() {
            Ok(s) => start = s,
            Err(_) => return None,
        }
        let t = target.run(cand);
        same_fault(&t, &sig).then_some(t)
    };
    let keep = |cand: &[Step], t: Option<Trial>, last: &mut Option<(Vec<Step>, Trial)>| {
        let ok = t.is_some();
        if let Some(t) = t {
            *last = Some((cand.to_vec(), t));
        }
        ok
    };
    let spend = |budget: &mut u64| {
        let ok = *budget > 0;
        *budget = budget.saturating_sub(1);
        ok
    };
    let mut base = steps;
    let mut reproduced = false;
    if let (true, Some(failing)) = (base.len() > 1, base.last().cloned()) {
        let one = std::slice::from_ref(&failing);
        if spend(&mut budget) && keep(one, check(target, one), &mut last) {
            base = vec![failing];
            reproduced = true;
        }
    }
    if !reproduced && spend(&mut budget) {
        reproduced = keep(&base, check(target, &base), &mut last);
    }
    if !reproduced && !history.is_empty() && spend(&mut budget) {
        let mut with: Vec<Step> = history.to_vec();
        with.extend(base.iter().cloned());
        if keep(&with, check(target, &with), &mut last) {
            base = with;
            reproduced = true;
        }
    }
    if reproduced {
        if base.len() > 1 {
            base = ddmin(base, &mut budget, &mut |cand: &[Step]| {
                keep(cand, check(target, cand), &mut last)
            });
        }
        let mut changed = false;
        for i in 0..base.len() {
            let Some(bytes) = base
                .get(i)
                .and_then(|s| s.action.bytes())
                .map(<[u8]>::to_vec)
            else {
                continue;
            };
            if bytes.len() < 2 || budget == 0 {
                continue;
            }
            let before = bytes.len();
            let shorter = ddmin(bytes, &mut budget, &mut |b: &[u8]| {
                let mut cand = base.clone();
                if let Some(s) = cand.get_mut(i) {
                    s.action = s.action.with_bytes(b.to_vec());
                }
                keep(&cand, check(target, &cand), &mut last)
            });
            if shorter.len() < before {
                changed = true;
                if let Some(s) = base.get_mut(i) {
                    s.action = s.action.with_bytes(shorter);
                    s.text = format!("{} (bytes minimised)", s.text);
                }
            }
        }
        if changed && base.len() > 1 {
            base = ddmin(base, &mut budget, &mut |cand: &[Step]| {
                keep(cand, check(target, cand), &mut last)
            });
        }
    }
    let mut runs = max_runs.saturating_sub(budget);
    let confirmed = match last.take() {
        Some((s, t)) if same_steps(&s, &base) => Some(t),
        _ if reproduced => {
            runs += 1;
            check(target, &base)
        }
        _ => None,
    };
    let (trial, reproduced) = match confirmed {
        Some(t) => (t, true),
        None => (original.clone(), false),
    };
    if !reproduced {
        start = Start::AsIs;
    }
    Found {
        fault: trial.fault.clone().unwrap_or_else(|| fault.clone()),
        steps: base,
        trial,
        sequence,
        original_steps,
        runs,
        reproduced,
        start,
        occurrences: 1,
        cut_short: cut_short.get(),
    }
}

/// Whether two step lists send the same (text aside).
fn same_steps(a: &[Step], b: &[Step]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.action == y.action)
}

/// Replays `steps` from the start state (where the transport allows) once.
pub(crate) fn replay_once(target: &mut dyn Target, steps: &[Step]) -> (Trial, Start) {
    let start = target.fresh().unwrap_or(Start::AsIs);
    (target.run(steps), start)
}

/// True with `percent` % probability.
pub(crate) fn chance(rng: &mut Rng, percent: i64) -> bool {
    rng.range(0, 99) < percent
}

/// A number in `0..n` (0 when `n` is 0).
pub(crate) fn below(rng: &mut Rng, n: usize) -> usize {
    let hi = i64::try_from(n).unwrap_or(i64::MAX).saturating_sub(1);
    usize::try_from(rng.range(0, hi.max(0))).unwrap_or(0)
}

/// Declares a generator's `Template` enum and its `TEMPLATES` table from one list of
/// `Name = weight` (the weight: how often the template is drawn, [`weighted`]).
macro_rules! templates {
    ($(#[$meta:meta])* $($name:ident = $weight:expr),+ $(,)?) => {
        $(#[$meta])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        enum Template {
            $($name),+
        }

        /// Every template with its weight.
        const TEMPLATES: &[(Template, u32)] = &[$((Template::$name, $weight)),+];
    };
}
pub(crate) use templates;

/// One of the items of `table` that `usable` accepts, drawn by weight with one draw of `rng`;
/// `fallback` when their weights add up to nothing.
pub(crate) fn weighted<T: Copy>(
    rng: &mut Rng,
    table: &[(T, u32)],
    usable: impl Fn(T) -> bool,
    fallback: T,
) -> T {
    let total: u32 = table
        .iter()
        .filter(|(t, _)| usable(*t))
        .map(|(_, w)| *w)
        .sum();
    let mut x = u32::try_from(rng.range(0, i64::from(total.max(1)) - 1)).unwrap_or(0);
    for (t, w) in table.iter().filter(|(t, _)| usable(*t)) {
        if x < *w {
            return *t;
        }
        x -= w;
    }
    fallback
}

/// One of `items`, None when there are none.
pub(crate) fn pick<'x, T>(rng: &mut Rng, items: &'x [T]) -> Option<&'x T> {
    if items.is_empty() {
        return None;
    }
    items.get(below(rng, items.len()))
}

/// Whether a step puts something on the line (for counting exchanges): every cyclic step
/// is at least one request and reply.
pub(crate) fn is_exchange(s: &Step) -> bool {
    matches!(
        s.action,
        Action::Hpd(HpdStep::Exchange { .. } | HpdStep::Send { .. })
            | Action::Psd4xx(_)
            | Action::Psx3xx(_)
    )
}

/// A step of another family in a sequence run on a target.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("step {index} ({text:?}) is a {step} step, not a {family} step")]
pub(crate) struct OtherFamilyStep {
    /// Index of the step in the sequence.
    pub index: usize,
    /// The step's text.
    pub text: String,
    /// The step's family.
    pub step: FamilyId,
    /// The target's family.
    pub family: FamilyId,
}

impl OtherFamilyStep {
    /// The run of a sequence that holds this step: failed before anything was sent.
    pub(crate) fn failed_run(&self) -> CaseRun {
        CaseRun {
            findings: Vec::new(),
            checked: Vec::new(),
            outcome: Outcome::Fail(Failure {
                step: Some(self.index),
                message: self.to_string(),
                expected: format!("a {} step", self.family),
                got: format!("a {} step", self.step),
                requirements: Vec::new(),
            }),
            evidence: Vec::new(),
            elapsed_us: 0,
        }
    }
}

/// The family steps of a sequence, or the first step of another family.
pub(crate) fn own_steps<S: FamilyStep>(steps: &[Step]) -> Result<Vec<&S>, OtherFamilyStep> {
    steps
        .iter()
        .enumerate()
        .map(|(index, s)| {
            S::of(&s.action).ok_or_else(|| OtherFamilyStep {
                index,
                text: s.text.clone(),
                step: s.action.family(),
                family: S::FAMILY,
            })
        })
        .collect()
}

/// Fails with the IDs a generator's templates name that `family` lacks.
pub(crate) fn requirements_known<'i>(
    family: &Family,
    ids: impl Iterator<Item = &'i &'static str>,
) -> Result<(), String> {
    let mut missing: Vec<&str> = ids
        .copied()
        .filter(|id| family.requirement(id).is_none())
        .collect();
    missing.dedup();
    if missing.is_empty() {
        Ok(())
    } else {
        Err(format!(
            "fuzz templates name requirements the spec lacks: {}",
            missing.join(", ")
        ))
    }
}

/// Every must/should requirement ID of `family`, in spec order ([`Target::requirement_ids`]).
pub(crate) fn requirement_ids(family: &Family) -> Vec<(String, Level)> {
    family
        .requirements
        .iter()
        .filter(|r| r.level != Level::Informative)
        .map(|r| (r.id.clone(), r.level))
        .collect()
}
