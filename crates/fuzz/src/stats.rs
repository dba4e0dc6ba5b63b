//! What a campaign counts (the `fuzz` section of the report, README "Fuzz reports"): inputs
//! by generator class, judged answers by verdict, requirement IDs touched, findings.

use crate::engine::Trial;
use crate::replay::{FindingClass, Step};
use drivespec_spec::FamilyId;
use serde::Serialize;
use std::collections::BTreeMap;

/// Name and version of the `fuzz` section (README "Fuzz reports").
pub const STATS_SCHEMA: &str = "drivespec-fuzz/1";

/// A finding in the statistics.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct FindingSummary {
    /// Case ID in the report (`hpd/fuzz/finding-1`).
    pub id: String,
    /// Mismatch, hang or crash.
    pub class: FindingClass,
    /// `class/message-kind/detail`.
    pub signature: String,
    /// The sequence that found it first.
    pub first_sequence: u64,
    /// Failing sequences that showed the same bug.
    pub occurrences: u64,
    /// Steps of the minimised replay.
    pub steps: usize,
    /// Steps that put bytes on the line.
    pub exchanges: usize,
    /// Steps before minimisation.
    pub original_steps: usize,
    /// Confirmed from the start state after minimisation.
    pub reproduced: bool,
    /// The replay file, when written.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// Requirements the failing step covers.
    pub requirements: Vec<String>,
}

/// Counts of a campaign.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stats {
    /// `drivespec-fuzz/1`.
    pub schema: &'static str,
    /// The family.
    pub family: FamilyId,
    /// Seed of the generator.
    pub seed: u64,
    /// Sequences run.
    pub sequences: u64,
    /// Inputs (steps) sent.
    pub inputs: u64,
    /// Inputs by generator class.
    pub inputs_by_class: BTreeMap<String, u64>,
    /// Judged steps by verdict: `answer` and `silence` (matched the reference),
    /// `mismatch`, `hang`, `crash`; `not-run` for steps after a failure.
    pub answers_by_verdict: BTreeMap<String, u64>,
    /// Requirement ID → inputs that exercised it.
    pub requirements_touched: BTreeMap<String, u64>,
    /// Must/should requirements no input exercised.
    pub requirements_not_touched: Vec<String>,
    /// Sequences that failed.
    pub failing_sequences: u64,
    /// Failing sequences not minimised (past `max_findings`, new signature).
    pub unminimised: u64,
    /// Device restarts and reconnections by the fuzzer.
    pub restarts: u64,
    /// Runs spent minimising.
    pub minimisation_runs: u64,
    /// Transport errors outside sequences (resets, restarts; the first 100).
    pub transport_errors: Vec<String>,
    /// `iterations` or `duration`.
    pub stopped_by: String,
    /// Wall-clock time of the campaign (ms).
    pub wall_ms: f64,
    /// The findings.
    pub findings: Vec<FindingSummary>,
}

impl Stats {
    /// Empty counts for a campaign of `family` with `seed`.
    pub fn new(family: FamilyId, seed: u64) -> Stats {
        Stats {
            schema: STATS_SCHEMA,
            family,
            seed,
            sequences: 0,
            inputs: 0,
            inputs_by_class: BTreeMap::new(),
            answers_by_verdict: BTreeMap::new(),
            requirements_touched: BTreeMap::new(),
            requirements_not_touched: Vec::new(),
            failing_sequences: 0,
            unminimised: 0,
            restarts: 0,
            minimisation_runs: 0,
            transport_errors: Vec::new(),
            stopped_by: String::new(),
            wall_ms: 0.0,
            findings: Vec::new(),
        }
    }

    /// Keeps a transport error outside sequences (the first 100).
    pub(crate) fn transport_error(&mut self, e: &drivespec_conform::link::LinkError) {
        if self.transport_errors.len() < 100 {
            self.transport_errors.push(e.to_string());
        }
    }

    /// Counts one run of `seq` (minimisation runs are not counted here).
    pub(crate) fn record(&mut self, seq: &[Step], trial: &Trial) {
        let bump = |m: &mut BTreeMap<String, u64>, k: &str| {
            *m.entry(k.to_owned()).or_insert(0) += 1;
        };
        for s in seq {
            self.inputs += 1;
            bump(&mut self.inputs_by_class, &s.class);
        }
        let mut ran = vec![false; seq.len()];
        for r in &trial.run.evidence {
            let Some(step) = seq.get(r.step) else {
                // The liveness probe after a silence.
                continue;
            };
            if let Some(x) = ran.get_mut(r.step) {
                *x = true;
            }
            for id in &step.requirements {
                bump(&mut self.requirements_touched, id);
            }
            let verdict = match r.ok {
                None => continue,
                Some(true) => {
                    // Cyclic records and injections are lines: `SILENT` is their silence.
                    let lines = r.sent.is_none() && r.sent_text.is_some();
                    let answered = r.got.as_ref().is_some_and(|a| {
                        if lines {
                            a.text != "SILENT"
                        } else {
                            !a.is_silence()
                        }
                    });
                    if answered {
                        "answer"
                    } else {
                        "silence"
                    }
                }
                Some(false) => match &trial.fault {
                    Some(f) if f.step == r.step => f.class.as_str(),
                    _ => "mismatch",
                },
            };
            bump(&mut self.answers_by_verdict, verdict);
        }
        for _ in ran.iter().filter(|x| !**x) {
            bump(&mut self.answers_by_verdict, "not-run");
        }
    }
}
