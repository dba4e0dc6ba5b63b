//! Reading back what a case's set-up relies on, to name the requirement a failure broke: a
//! case that fails after bit changes (CMD 6, manual 4.1) or applied digital inputs (3.8.1:
//! b90.0..b90.7 read at the start of each PLC scan) runs again with each of them read back
//! from the device right after it. A read-back that shows the change or the inputs not taken
//! fails the case there, naming the rule of the bit change or of the inputs; when every
//! read-back holds, the first run's failure stands. Only a failing case runs again, so a
//! device that passes never pays for the read-backs.

use super::{HpdSession, ANSWER_TIME_REQUIREMENT, FORM, TIMEOUT_REQUIREMENT};
use crate::case::{CaseInfo, CaseRun, Failure, Outcome, Record, RequirementRef, Role};
use crate::hpd::attribute::{self, BYTE_RULE};
use crate::hpd::step::{Action, HpdCase, Step};
use crate::link::concat;
use drivespec_hpd::Message;
use drivespec_spec::hex::to_hex;

impl HpdSession<'_, '_> {
    /// The case's failing `run`, or the run again with its bit changes and inputs read back
    /// when one of those shows not taken (see the module doc).
    pub(super) fn verified(&mut self, info: &CaseInfo, case: &HpdCase, run: CaseRun) -> CaseRun {
        let Outcome::Fail(f) = &run.outcome else {
            return run;
        };
        let Some(at) = f.step.and_then(|e| run.evidence.get(e)).map(|r| r.step) else {
            return run;
        };
        let settled = f.requirements.first().is_none_or(|r| {
            let id = r.id.as_str();
            FORM.contains(&id)
                || [ANSWER_TIME_REQUIREMENT, TIMEOUT_REQUIREMENT, BYTE_RULE].contains(&id)
                || case.steps.iter().any(|s| input_rule(s) == Some(id))
        });
        let relied_on = case.steps.iter().take(at).any(|s| {
            s.role != Role::Cleanup && (self.bit_change(s).is_some() || input_rule(s).is_some())
        });
        if settled || self.link_broke || !relied_on {
            return run;
        }
        self.verify = true;
        self.read_back_failed = false;
        let mut again = self.attempt(info, case, true);
        self.verify = false;
        if !self.read_back_failed {
            return run;
        }
        if let Some(first) = again.evidence.first_mut() {
            let note = format!(
                "the case failed at step {at} ({}) and ran again with its bit changes and inputs read back",
                f.message
            );
            first.note = Some(match first.note.take() {
                Some(n) => format!("{note}; {n}"),
                None => note,
            });
        }
        again
    }

    /// The bit change (address, PAR, mask, value) step `s` sends, if it is one.
    fn bit_change(&self, s: &Step) -> Option<(u8, u8, u8, u8)> {
        let Action::Exchange { bytes, .. } = &s.action else {
            return None;
        };
        match drivespec_hpd::parse(&self.suite.rules, bytes) {
            Ok(Message::BitChange {
                addr,
                par,
                mask,
                value,
            }) => Some((addr, par, mask, value)),
            _ => None,
        }
    }

    /// In a run that reads back (see the module doc): reads back what step `i` changed, when
    /// its record (the last of `evidence`) shows it done, and the failure if it did not take.
    pub(super) fn read_back(
        &mut self,
        i: usize,
        step: &Step,
        evidence: &mut Vec<Record>,
    ) -> Option<Failure> {
        if !self.verify {
            return None;
        }
        let failure = if let Some((addr, par, mask, value)) = self.bit_change(step) {
            if evidence.last().and_then(|r| r.ok) != Some(true) {
                return None;
            }
            self.read_back_bits(i, step, (addr, par, mask, value), evidence)
        } else if let Action::Inputs { .. } = step.action {
            self.read_back_inputs(i, step, evidence)
        } else {
            None
        };
        self.read_back_failed |= failure.is_some();
        failure
    }

    /// Reads the parameter holding the byte a bit change wrote and judges whether it took
    /// ([`attribute::bit_change_broken`]).
    fn read_back_bits(
        &mut self,
        i: usize,
        step: &Step,
        (addr, par, mask, value): (u8, u8, u8, u8),
        evidence: &mut Vec<Record>,
    ) -> Option<Failure> {
        let p = self.suite.family().parameter_at_address(u32::from(par))?;
        let base = u8::try_from(p.address?).ok()?;
        let lun = u8::try_from(p.size?).ok()?;
        let offset = usize::from(par.checked_sub(base)?);
        let what = format!("{} after the bit change", p.id);
        let (exp, got, mut rec) = self.read_for(i, step, addr, base, lun, &what)?;
        let broken =
            attribute::bit_change_broken(&self.suite.rules, offset, mask, value, &exp, &got);
        let changed = !mask;
        let why = format!(
            "the bit change wrote bits {changed:#04x} of byte {par:#04x} as {:#04x}",
            value & changed
        );
        self.judge_read_back(i, step, broken, why, &mut rec, evidence)
    }

    /// Waits one PLC scan and more (the drive reads its inputs at the start of each) and
    /// reads the parameter holding the inputs: the device's input bits must be the
    /// reference's.
    fn read_back_inputs(
        &mut self,
        i: usize,
        step: &Step,
        evidence: &mut Vec<Record>,
    ) -> Option<Failure> {
        let io = &self.suite.protocol().io;
        let family = self.suite.family();
        let p = family.parameter(&io.input_param)?;
        let base = u8::try_from(p.address?).ok()?;
        let lun = u8::try_from(p.size?).ok()?;
        let bits = io
            .inputs
            .iter()
            .filter_map(|point| point.bit.rsplit('.').next()?.parse::<u32>().ok())
            .fold(0u32, |m, b| m | 1u32.checked_shl(b).unwrap_or(0));
        let wait = self.oracle.scan_period() + self.slack.max(1_000);
        if self.listen(wait).is_err() {
            return None;
        }
        let what = format!("{} one PLC scan after the inputs", p.id);
        let (exp, got, mut rec) =
            self.read_for(i, step, self.suite.settings.address, base, lun, &what)?;
        let rules = &self.suite.rules;
        let value = |bytes: &[u8]| match drivespec_hpd::parse(rules, bytes) {
            Ok(Message::Response { data, .. }) => Some(data.unsigned()),
            _ => None,
        };
        let broken = match (value(&exp), value(&got)) {
            (Some(e), Some(g)) if (e ^ g) & bits != 0 => input_rule(step),
            _ => None,
        };
        let why = format!("input bits {bits:#06x} as the inputs were applied");
        self.judge_read_back(i, step, broken, why, &mut rec, evidence)
    }

    /// Sends a read of `lun` bytes at `par` to `addr` for step `i`: the reference's and the
    /// device's answers, and the record of the read.
    fn read_for(
        &mut self,
        i: usize,
        step: &Step,
        addr: u8,
        par: u8,
        lun: u8,
        what: &str,
    ) -> Option<(Vec<u8>, Vec<u8>, Record)> {
        let msg = Message::ReadParam { addr, lun, par };
        let bytes = msg.to_bytes(&self.suite.rules).ok()?;
        let at_us = self.link.now();
        let obs = self.exchange(&bytes).ok()?;
        let rec = Record {
            step: i,
            role: step.role,
            action: format!("read back {what}"),
            at_us,
            sent: Some(to_hex(&bytes)),
            sent_text: Some(self.words(&bytes, None)),
            expected: Some(self.answer(&obs.expected, obs.t0, Some(&msg))),
            got: Some(self.answer(&obs.got, obs.t0, Some(&msg))),
            ok: None,
            note: Some("read back to name the requirement a failure of the case broke".to_owned()),
        };
        Some((concat(&obs.expected), concat(&obs.got), rec))
    }

    /// Records a read-back with its verdict: the failure naming `broken` first, then the
    /// step's requirements, when there is one.
    fn judge_read_back(
        &mut self,
        i: usize,
        step: &Step,
        broken: Option<&str>,
        why: String,
        rec: &mut Record,
        evidence: &mut Vec<Record>,
    ) -> Option<Failure> {
        rec.ok = Some(broken.is_none());
        let show = |a: Option<&crate::case::Answer>| a.map(super::show).unwrap_or_default();
        let failure = broken.map(|id| {
            let family = self.suite.family();
            let mut ids = vec![id.to_owned()];
            for r in &step.requirements {
                if !ids.contains(r) {
                    ids.push(r.clone());
                }
            }
            Failure {
                step: Some(evidence.len()),
                message: format!(
                    "step {i} ({}) did not take: {why}; {}: expected {}, got {}",
                    step.text,
                    rec.action,
                    show(rec.expected.as_ref()),
                    show(rec.got.as_ref())
                ),
                expected: show(rec.expected.as_ref()),
                got: show(rec.got.as_ref()),
                requirements: ids
                    .iter()
                    .filter_map(|id| RequirementRef::of(family, id))
                    .collect(),
            }
        });
        self.note_order(rec);
        evidence.push(rec.clone());
        failure
    }
}

/// The rule an inputs step relies on (its first requirement: the drive reads its inputs into
/// b90.0..b90.7), if `s` applies inputs.
fn input_rule(s: &Step) -> Option<&str> {
    match s.action {
        Action::Inputs { .. } => s.requirements.first().map(String::as_str),
        _ => None,
    }
}
