//! Running PSD4xx cases ([`crate::cyclic_session`]): every cycle's input image (PKW block and
//! status word exact) and every record and injection reply is compared with the reference's.

use super::cases::{control_bit, status_bit, OpenPoint, PsdCase, StepDef, PKW_MAX_CYCLES};
use super::{Psd4xxSuite, CYCLE_US};
use crate::case::{CaseInfo, Finding};
use crate::cyclic::{Env, Reply, Request, Server};
use crate::cyclic_session::{
    env_op, env_request, merged, same_length, CyclicFamily, CyclicSession, Op, OwnVerdict, Seen,
    Tolerance,
};
use drivespec_psd4xx::pkw::Reply as PkwReply;
use drivespec_psd4xx::step::Step;
use drivespec_psd4xx::{Input, Output, PkwRequest, PkwResponse};
use drivespec_spec::psd4xx::{PkwOp, PkwValue};
use drivespec_spec::{DataType, Family, FamilyId, Protocol};

/// The requirement that a run aborted by a stop command leaves the drive without adjustment
/// until a new run command has completed correctly (4.6 notice).
const ADJUST_AFTER_ABORT: &str = "PSD-ADJ-009";

/// The value of one process-data field of an input image.
type ImageValue = fn(&Input) -> i64;

/// A session on one device under test.
pub type Psd4xxSession<'a, 's> = CyclicSession<'a, Psd4xx<'a, 's>>;

/// The PSD4xx family as the cyclic session runs it: the suite's reference and cases.
#[derive(Clone, Copy)]
pub struct Psd4xx<'a, 's> {
    suite: &'a Psd4xxSuite<'s>,
}

impl<'a, 's> Psd4xx<'a, 's> {
    /// The family of `suite`.
    pub(crate) fn new(suite: &'a Psd4xxSuite<'s>) -> Psd4xx<'a, 's> {
        Psd4xx { suite }
    }

    /// Whether parameter `number` is the device's own value (spec `per_device`).
    fn per_device(&self, number: u16) -> bool {
        self.suite
            .family()
            .parameters
            .iter()
            .any(|p| p.per_device && p.number == u32::from(number))
    }

    /// What the input image shows of parameter `pnu` when the parameter is a live value with
    /// a process-data field (spec `live`, `process_data.input` `param`: status word, speed,
    /// actual position), and whether its values are bits (compared as a set) rather than a
    /// quantity (compared as a range).
    fn image_of(&self, pnu: u16) -> Option<(ImageValue, bool)> {
        let family = self.suite.family();
        let p = family
            .parameters
            .iter()
            .find(|p| p.live && p.number == u32::from(pnu))?;
        let Protocol::Psd4xx(proto) = &family.protocol else {
            return None;
        };
        let field = proto
            .process_data
            .input
            .fields
            .iter()
            .find(|f| f.param.as_deref() == Some(p.id.as_str()))?;
        let value: ImageValue = match field.name.as_str() {
            "status" => |i| i64::from(i.status),
            "speed" => |i| i64::from(i.speed),
            "actual" => |i| i64::from(i.actual),
            _ => return None,
        };
        let bits = matches!(
            p.data_type,
            DataType::Bits8 | DataType::Bits16 | DataType::Bits32
        );
        Some((value, bits))
    }

    /// Most cycles a PKW command is repeated: the longest save (4.7, spec
    /// `positioning.save.max_ms`) plus [`PKW_MAX_CYCLES`].
    fn pkw_cycles(&self) -> u32 {
        let save_ms = match &self.suite.family().protocol {
            Protocol::Psd4xx(p) => u64::from(p.positioning.save.max_ms),
            _ => 0,
        };
        let save = save_ms.saturating_mul(1000).div_ceil(CYCLE_US);
        PKW_MAX_CYCLES.saturating_add(u32::try_from(save).unwrap_or(u32::MAX))
    }

    /// The requirement the device's PKW answer `got` to `command` breaks where it differs
    /// from the reference's `want`, as the codes show (3.8, spec `pkw`): the answer to "no
    /// command" (where the reference shows "no response"); the error the situation gives when the reference refuses; the answer code of
    /// the command; the echo of a write. None when only the value differs (the parameter's
    /// own requirement, the case's, applies).
    fn pkw_broken(
        &self,
        command: &PkwRequest,
        got: &PkwResponse,
        want: &PkwResponse,
    ) -> Option<&'s str> {
        let Protocol::Psd4xx(p) = &self.suite.family().protocol else {
            return None;
        };
        let pkw = &p.pkw;
        let code = u8::from(command.ak);
        let info = pkw.commands.iter().find(|c| c.code == code)?;
        let (got_ak, want_ak) = (u8::from(got.ak), u8::from(want.ak));
        let answer = |ak: u8, value: PkwValue| {
            pkw.responses
                .iter()
                .any(|r| r.code == ak && r.value == value)
        };
        // "No command" is answered with "no response": where the reference shows it, the
        // device shows something else.
        if info.op == PkwOp::None || answer(want_ak, PkwValue::None) {
            return pkw
                .commands
                .iter()
                .find(|c| c.op == PkwOp::None)
                .map(|c| c.requirement.as_str());
        }
        let refused = |ak: u8| answer(ak, PkwValue::Error);
        if refused(want_ak) {
            return pkw
                .errors
                .iter()
                .find(|e| u32::from(e.code) == want.pwe)
                .map(|e| e.requirement.as_str());
        }
        if got_ak != want_ak {
            return Some(&info.requirement);
        }
        let echoed = (got.pnu, got.ind, got.pwe) == (command.pnu, command.ind, command.pwe);
        (pkw.echo.commands.contains(&code) && !echoed).then_some(pkw.echo.requirement.as_str())
    }
}

impl CyclicFamily<'static> for Psd4xx<'_, '_> {
    type Input = Input;
    type Output = Output;
    type Action = Step;
    type Case = PsdCase;
    const ID: FamilyId = FamilyId::Psd4xx;
    const EXACT: &'static str = "PKW and status";
    const CHANNEL: &'static str = "PKW response";
    type Channel = drivespec_psd4xx::PkwResponse;

    fn channel(i: &Input) -> drivespec_psd4xx::PkwResponse {
        i.pkw
    }

    fn spec(&self) -> &Family {
        self.suite.family()
    }

    fn model(&self) -> &str {
        self.suite.model()
    }

    fn server(&self) -> Server<'static> {
        self.suite.server()
    }

    fn case(&self, index: usize) -> Option<(&CaseInfo, &PsdCase)> {
        self.suite.case(index)
    }

    fn steps(case: &PsdCase) -> &[StepDef] {
        &case.steps
    }

    fn tolerance(case: &PsdCase) -> Tolerance {
        case.tol
    }

    fn plot(case: &PsdCase) -> bool {
        case.plot
    }

    fn open(case: &PsdCase) -> Option<OpenPoint> {
        case.open.clone()
    }

    /// A case citing PSD-ADJ-009 is judged by [`Psd4xx::adjust_after_abort`].
    fn own_checks(
        &self,
        case: &PsdCase,
        reqs: &[String],
        cycles: &[Seen<'_, Input, Output>],
    ) -> Vec<OwnVerdict> {
        if !reqs.iter().any(|r| r == ADJUST_AFTER_ABORT) {
            return Vec::new();
        }
        self.adjust_after_abort(case, cycles).into_iter().collect()
    }

    /// Idle: no PKW command, control word and target 0.
    fn start(&self, _case: &PsdCase) -> Output {
        Output::idle(self.suite.reference().rules())
    }

    fn cycle_us(&self) -> u64 {
        CYCLE_US
    }

    fn image(&self, out: &Output) -> Result<Vec<u8>, String> {
        out.to_bytes(self.suite.reference().rules())
            .map_err(|e| e.to_string())
    }

    fn parse(&self, bytes: &[u8]) -> Result<Input, String> {
        Input::parse(self.suite.reference().rules(), bytes).map_err(|e| e.to_string())
    }

    fn input_bytes(&self, input: &Input) -> Result<Vec<u8>, String> {
        input
            .to_bytes(self.suite.reference().rules())
            .map_err(|e| e.to_string())
    }

    fn describe(&self, i: &Input) -> String {
        let pkw = self
            .suite
            .reference()
            .rules()
            .pkw()
            .describe_response(&i.pkw);
        format!(
            "status {:#06x} speed {} actual {} | {pkw}",
            i.status, i.speed, i.actual
        )
    }

    fn describe_output(&self, out: &Output) -> String {
        format!(
            "control {:#06x} target {} | {}",
            out.control,
            out.target,
            self.suite
                .reference()
                .rules()
                .pkw()
                .describe_request(&out.pkw),
        )
    }

    fn motion(i: &Input) -> (i64, i64, u16) {
        (i64::from(i.actual), i64::from(i.speed), i.status)
    }

    /// A read of a device's own value (spec `per_device`) is equal when code, parameter and
    /// index are: the response code fixes type and length.
    fn exact_equal(&self, d: &Input, r: &Input) -> bool {
        let own = || {
            d.pkw.ak == r.pkw.ak
                && d.pkw.pnu == r.pkw.pnu
                && d.pkw.ind == r.pkw.ind
                && self.per_device(d.pkw.pnu)
                && self
                    .suite
                    .reference()
                    .rules()
                    .pkw()
                    .response_codes()
                    .cannot_execute
                    != d.pkw.ak
        };
        d.status == r.status && (d.pkw == r.pkw || own())
    }

    fn running_bit(&self) -> u16 {
        status_bit(self.suite.family(), "Drive is running").unwrap_or(0)
    }

    /// 4.3: all runs accelerate with at most par 58 and decelerate with at most par 59.
    fn ramp_requirements(&self) -> Option<[&'static str; 2]> {
        Some(["PSD-VEL-003", "PSD-VEL-004"])
    }

    /// Par. 2, the actual speed, signed (3.3).
    fn speed_sign_requirement(&self) -> Option<&'static str> {
        Some("PSD-PAR-2-001")
    }

    /// The requirements of what differs in a cycle: first the one the PKW answer breaks as
    /// its codes show ([`Psd4xx::pkw_broken`]), then the case's, then the PKW handshake rules
    /// (3.8: response held, value of the moment, command 0 answered with 0, one command at a
    /// time) when the PKW block differs, the speed (par. 2) and position (par. 3) rules when
    /// those differ, and the set/reset rules of every status bit that differs (spec bitfield
    /// `status`).
    fn cited(
        &self,
        case: &[String],
        out: &Output,
        dut: Option<&Input>,
        reference: &Input,
    ) -> Vec<String> {
        let Some(d) = dut else {
            return case.to_vec();
        };
        let mut ids: Vec<String> = Vec::new();
        let mut add = |id: &str| {
            if !ids.iter().any(|x| x == id) {
                ids.push(id.to_owned());
            }
        };
        if d.pkw != reference.pkw {
            match self.pkw_broken(&out.pkw, &d.pkw, &reference.pkw) {
                Some(id) => add(id),
                // Only the value differs: the requirement of the parameter answered.
                None => {
                    let pnu = reference.pkw.pnu.to_string();
                    let family = self.suite.family();
                    if let Some(id) = case.iter().find(|id| {
                        family
                            .requirement(id)
                            .is_some_and(|r| r.params.contains(&pnu))
                    }) {
                        add(id);
                    }
                }
            }
        }
        for id in case {
            add(id);
        }
        if d.pkw != reference.pkw {
            for id in ["PSD-PKW-003", "PSD-PKW-004", "PSD-PKW-006", "PSD-PKW-007"] {
                add(id);
            }
        }
        if d.speed != reference.speed {
            add("PSD-PAR-2-001");
        }
        if d.actual != reference.actual {
            add("PSD-PAR-3-001");
        }
        let differs = d.status ^ reference.status;
        if let Some(field) = self.suite.family().bitfield("status") {
            for b in field
                .bits
                .iter()
                .filter(|b| b.bit < 16 && differs & (1 << b.bit) != 0)
            {
                for rule in &b.rules {
                    add(&rule.requirement);
                }
            }
        }
        ids
    }

    /// A record read answered with another number of bytes than the reference's breaks the
    /// read length of the reference's width (3.2.2, spec `record.length`) first.
    fn reply_cited(
        &self,
        case: &[String],
        req: &Request,
        expected: &Reply,
        got: &Reply,
    ) -> Vec<String> {
        let length = match (req, expected, got) {
            (Request::Read { .. }, Reply::Data(e), Reply::Data(g)) if e.len() != g.len() => {
                match &self.suite.family().protocol {
                    Protocol::Psd4xx(p) => p
                        .record
                        .lengths
                        .iter()
                        .find(|l| l.read == e.len())
                        .map(|l| l.read_requirement.clone()),
                    _ => None,
                }
            }
            _ => None,
        };
        merged(length.into_iter().collect(), case)
    }

    /// Records and injections are exact.
    fn same_reply(
        &self,
        req: &Request,
        expected: &Reply,
        got: &Reply,
        _tol: Tolerance,
    ) -> (bool, Option<String>) {
        if let Request::Read { index, .. } = req {
            if self.per_device(*index) {
                if let Some(note) = same_length(expected, got) {
                    return (true, Some(note));
                }
            }
        }
        (expected.to_string() == got.to_string(), None)
    }

    fn op(&self, action: &Step, out: &Output, last: Option<&Input>, t: u64) -> Op<Output> {
        let mut next = *out;
        match action {
            Step::Process { control, target } => {
                if let Some(c) = control {
                    next.control = *c;
                }
                if let Some(t) = target {
                    next.target = *t;
                }
                Op::Send { out: next, max: 1 }
            }
            Step::Offset { control, offset } => {
                if let Some(c) = control {
                    next.control = *c;
                }
                let actual = last.map_or(0, |i| i64::from(i.actual));
                let t = actual.saturating_add(*offset);
                next.target = i32::try_from(t).unwrap_or(if t < 0 { i32::MIN } else { i32::MAX });
                Op::Send { out: next, max: 1 }
            }
            Step::Pkw { pkw } => {
                next.pkw = PkwRequest::from(*pkw);
                Op::Send {
                    out: next,
                    max: self.pkw_cycles(),
                }
            }
            Step::Hold { cycles } => Op::Hold(*cycles),
            Step::Until { running, max } => Op::Until {
                running: *running,
                max: *max,
            },
            Step::RecordRead { index } => Op::Exchange(Request::Read { t, index: *index }),
            Step::RecordWrite { index, hex } => Op::Exchange(Request::Write {
                t,
                index: *index,
                data: hex.clone(),
            }),
            Step::Env { env } => env_op(t, env),
            Step::Advance { us } => Op::Advance(*us),
            Step::Link { event } => Op::Exchange(Request::Env {
                t,
                env: Env::Link(*event),
            }),
            Step::PowerCycle => Op::Exchange(Request::Env {
                t,
                env: Env::PowerCycle,
            }),
            Step::Par { .. } => Op::Refuse(
                "a `par` step writes into the reference model directly; a device has no such access"
                    .to_owned(),
            ),
        }
    }

    /// Every other reading of each selectable erratum (spec `option`) whose requirements the
    /// case covers.
    fn readings(&self, info: &CaseInfo) -> Vec<(Finding, Server<'static>)> {
        let mut out = Vec::new();
        for e in &self.suite.family().errata {
            let Some(option) = &e.option else { continue };
            if !e.requirements.iter().any(|r| info.requirements.contains(r)) {
                continue;
            }
            for r in e.readings.iter().filter(|r| r.id != e.adopted) {
                if let Some(server) = self.suite.reading_server(option, &r.id) {
                    let finding = Finding::Reading {
                        erratum: e.id.clone(),
                        reading: r.id.clone(),
                        text: r.text.clone(),
                    };
                    out.push((finding, server));
                }
            }
        }
        out
    }

    /// A read of a live value is judged by the device's own process data around it
    /// ([`Psd4xx::moment`]); everything else as it came.
    fn judged(&self, device: &[Option<Input>], reference: &[Input], at: usize) -> Option<Input> {
        self.moment(device, reference, at)
            .or_else(|| device.get(at).copied().flatten())
    }

    /// A PKW block is answered when the reference's response answers it ("no command" and
    /// commands without an operation: when it says "no response").
    fn answered(&self, action: &Step, i: &Input) -> bool {
        let Step::Pkw { pkw: req } = action else {
            return true;
        };
        let req = &PkwRequest::from(*req);
        let pkw = self.suite.reference().rules().pkw();
        if req == &PkwRequest::default()
            || pkw
                .command_info(req.ak)
                .is_some_and(|c| c.op == drivespec_spec::psd4xx::PkwOp::None)
        {
            i.pkw.ak == pkw.response_codes().no_response
        } else {
            pkw.answers(req, &i.pkw)
        }
    }
}

impl Psd4xx<'_, '_> {
    /// PSD-ADJ-009 (4.6 notice) judged from the device's own images: after a run aborted by
    /// a stop command (the output clears the release while the device reports "Drive is
    /// running") and the shaft turned at standstill (the case's last `displace` after it),
    /// the actual position stays within par 44 (its delivery value) of where the turn left
    /// it. A device that reported "Target position reached" at a standstill since the abort
    /// has completed a run, so the rule no longer holds it back: not applicable, a finding.
    /// None where the case never reaches that state.
    fn adjust_after_abort(
        &self,
        case: &PsdCase,
        cycles: &[Seen<'_, Input, Output>],
    ) -> Option<OwnVerdict> {
        let family = self.suite.family();
        let release = control_bit(family, "Release").ok()?;
        let running = status_bit(family, "Drive is running").ok()?;
        let reached = status_bit(family, "Target position reached").ok()?;
        let window = family
            .parameter("44")
            .and_then(|p| family.resolve(p, family.model(self.suite.model())).default)?;
        let abort = cycles
            .windows(2)
            .position(|w| match w {
                [a, b] => {
                    a.out.control & release != 0
                        && b.out.control & release == 0
                        && a.device.is_some_and(|d| d.status & running != 0)
                }
                _ => false,
            })?
            .saturating_add(1);
        let abort_step = cycles.get(abort)?.step;
        let (turn_step, by) =
            case.steps
                .iter()
                .enumerate()
                .rev()
                .find_map(|(n, s)| match &s.action {
                    Step::Env { env } if n > abort_step => match env_request(0, env) {
                        Ok(Request::Env {
                            env: Env::Displace(by),
                            ..
                        }) => Some((n, by)),
                        _ => None,
                    },
                    _ => None,
                })?;
        let after = cycles.iter().position(|c| c.step > turn_step)?;
        let before = cycles.get(..after)?.iter().rev().find_map(|c| c.device)?;
        let left = i64::from(before.actual).saturating_add(by);
        let (lo, hi) = (left.saturating_sub(window), left.saturating_add(window));
        let moved = cycles.iter().enumerate().skip(after).find_map(|(i, c)| {
            c.device
                .filter(|d| !(lo..=hi).contains(&i64::from(d.actual)))
                .map(|d| (i, d))
        });
        let completed = cycles
            .get(abort..moved.map_or(cycles.len(), |(i, _)| i))?
            .iter()
            .position(|c| {
                c.device
                    .is_some_and(|d| d.status & reached != 0 && d.status & running == 0)
            })
            .map(|k| abort.saturating_add(k));
        let cycle_no = |i: usize| i.saturating_add(1);
        match (completed, moved) {
            (Some(k), moved) => Some(OwnVerdict::Allowed(Finding::Open {
                requirement: ADJUST_AFTER_ABORT.to_owned(),
                text: format!(
                    "not applicable: the device reported a completed run (\"Target position reached\") in cycle {} (step {}) after the run aborted by the stop command in cycle {}; after the turn it {}",
                    cycle_no(k),
                    cycles.get(k).map_or(0, |c| c.step),
                    cycle_no(abort),
                    if moved.is_some() { "adjusted" } else { "did not adjust" }
                ),
            })),
            (None, Some((i, d))) => Some(OwnVerdict::Broken {
                cycle: i,
                requirement: ADJUST_AFTER_ABORT.to_owned(),
                what: format!(
                    "actual position {}: the drive adjusts after the turn, with no run completed since the run aborted by the stop command in cycle {}",
                    d.actual,
                    cycle_no(abort)
                ),
                allowed: format!(
                    "actual position {lo}…{hi} (where the turn by {by} left it, {left}, ± par 44 = {window}): no adjustment until a new run command has completed"
                ),
            }),
            (None, None) => None,
        }
    }

    /// A read of a live value with a process-data field answered at cycle `at` (3.6: the
    /// value of the moment; PSD-PKW-004: held while the command is repeated), judged by the
    /// device's own process data: the request begins where the reference's answer does (it
    /// answers such a read in the cycle the request comes); the device's first answer to it
    /// must be unchanged up to `at`, and its value must be one the device's own image showed
    /// between the cycle before the request and the cycle after that answer (a quantity: within
    /// their range; bits: one of them). Then the reference's answer stands in for it.
    fn moment(&self, device: &[Option<Input>], reference: &[Input], at: usize) -> Option<Input> {
        let mut d = device.get(at).copied().flatten()?;
        let pkw = self.suite.reference().rules().pkw();
        let Some(PkwReply::Value {
            pnu,
            index: None,
            value,
            ..
        }) = pkw.reply(&d.pkw)
        else {
            return None;
        };
        let (image, bits) = self.image_of(pnu)?;
        let same = |r: &PkwResponse| r.ak == d.pkw.ak && r.pnu == d.pkw.pnu && r.ind == d.pkw.ind;
        let pkw_at = |k: usize| device.get(k).copied().flatten().map(|i| i.pkw);
        // The device's answer: the cycles up to `at` with the same block.
        let mut first = at;
        while first > 0 && pkw_at(first - 1) == Some(d.pkw) {
            first -= 1;
        }
        // The request: where the reference's answer to it begins.
        let start = (0..=first).rev().find(|&k| {
            reference.get(k).is_some_and(|r| same(&r.pkw))
                && (k == 0 || reference.get(k - 1).is_none_or(|r| !same(&r.pkw)))
        })?;
        // No other answer to the same command between the request and this one.
        if (start..first).any(|k| pkw_at(k).is_some_and(|p| same(&p))) {
            return None;
        }
        let seen: Vec<i64> = device
            .get(
                start.saturating_sub(1)
                    ..=first.saturating_add(1).min(device.len().saturating_sub(1)),
            )
            .unwrap_or(&[])
            .iter()
            .flatten()
            .map(image)
            .collect();
        let within = if bits {
            seen.contains(&value)
        } else {
            let lo = seen.iter().copied().min()?;
            let hi = seen.iter().copied().max()?;
            (lo..=hi).contains(&value)
        };
        if !within {
            return None;
        }
        d.pkw = reference.get(start)?.pkw;
        Some(d)
    }
}
