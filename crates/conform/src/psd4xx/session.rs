//! Running PSD4xx cases: the device under test and a fresh reference drive get the same
//! requests; every cycle's input image and every record and injection reply is compared.

use super::cases::{status_bit, Action, PsdCase, Tolerance, PKW_MAX_CYCLES};
use super::{Psd4xxSuite, CYCLE_US};
use crate::case::{Answer, CaseInfo, CaseRun, Failure, Outcome, Record, RequirementRef, Role};
use crate::cyclic::device::Device;
use crate::cyclic::wire::hex;
use crate::cyclic::{Env, Peer, PeerError, Reply, Request, Server};
use crate::suite::Session;
use drivespec_psd4xx::model::RecordRequest;
use drivespec_psd4xx::{Input, Output, PkwRequest};
use drivespec_report::plot::{self, Sample};
use drivespec_spec::FamilyId;

/// A session on one device under test.
pub struct Psd4xxSession<'a, 's> {
    suite: &'a Psd4xxSuite<'s>,
    /// The device under test; its first transport failure of a case run is a crash or hang
    /// to the fuzzer.
    device: Device<'a>,
}

/// One cycle as both sides saw it.
struct Cycle {
    step: usize,
    t: u64,
    reference: Input,
    dut: Result<Input, String>,
}

/// What one case run collected.
struct Run<'r> {
    reference: Server<'static>,
    out: Output,
    t: u64,
    cycles: Vec<Cycle>,
    evidence: Vec<Record>,
    failure: Option<Failure>,
    reqs: &'r [String],
}

impl<'a, 's> Psd4xxSession<'a, 's> {
    pub(crate) fn new(suite: &'a Psd4xxSuite<'s>, peer: Box<dyn Peer>) -> Psd4xxSession<'a, 's> {
        Psd4xxSession {
            suite,
            device: Device::new(peer, FamilyId::Psd4xx, suite.model()),
        }
    }

    /// Exchanges `HELLO`; an error names what the device side said.
    pub fn hello(&mut self) -> Result<String, String> {
        self.device.hello()
    }

    /// The first transport failure of the case run last, if any (taken).
    pub(crate) fn take_peer_error(&mut self) -> Option<PeerError> {
        self.device.take_error()
    }

    /// Whether the device takes the injection `env` ([`Device::takes`]).
    pub(crate) fn takes(&mut self, env: Env) -> bool {
        self.device.takes(env)
    }

    fn refs(&self, ids: &[String]) -> Vec<RequirementRef> {
        let family = self.suite.family();
        ids.iter()
            .filter_map(|id| RequirementRef::of(family, id))
            .collect()
    }

    /// The case's requirements plus those of what differs in a cycle: the PKW handshake
    /// rules (3.6: response held, value of the moment, command 0 answered with 0, one command
    /// at a time) when the PKW block differs, the speed (par. 2) and position (par. 3) rules
    /// when those differ, and the set/reset rules of every status bit that differs (spec
    /// bitfield `status`).
    fn cited(&self, case: &[String], dut: Option<&Input>, reference: &Input) -> Vec<String> {
        let mut ids = case.to_vec();
        let mut add = |id: &str| {
            if !ids.iter().any(|x| x == id) {
                ids.push(id.to_owned());
            }
        };
        let Some(d) = dut else {
            return ids;
        };
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

    fn parse_input(&self, reply: &Reply) -> Result<Input, String> {
        match reply {
            Reply::In(b) => Input::parse(self.suite.reference().rules(), b)
                .map_err(|e| format!("bad input image {}: {e}", hex(b))),
            other => Err(format!("{other}")),
        }
    }

    /// One cycle with the current outputs on both sides.
    fn cycle(&mut self, run: &mut Run<'_>, step: usize) -> Result<(), String> {
        let rules = self.suite.reference().rules();
        run.t = run.t.saturating_add(CYCLE_US);
        let image = run.out.to_bytes(rules).map_err(|e| e.to_string())?;
        let req = Request::Cycle { t: run.t, image };
        let reference = self.parse_input(&run.reference.handle(req.clone()))?;
        let dut = match self.device.call(&req) {
            Ok(r) => self.parse_input(&r),
            Err(e) => {
                self.device.failed(&e);
                run.cycles.push(Cycle {
                    step,
                    t: run.t,
                    reference,
                    dut: Err(e.to_string()),
                });
                return Err(e.to_string());
            }
        };
        run.cycles.push(Cycle {
            step,
            t: run.t,
            reference,
            dut,
        });
        Ok(())
    }

    fn last_ref(run: &Run<'_>) -> Option<Input> {
        run.cycles.last().map(|c| c.reference)
    }

    /// An exact exchange (record, injection).
    fn exact(
        &mut self,
        run: &mut Run<'_>,
        step: usize,
        role: Role,
        text: &str,
        req: Request,
    ) -> bool {
        let expected = run.reference.handle(req.clone());
        let got = match self.device.call(&req) {
            Ok(r) => r.to_string(),
            Err(e) => {
                self.device.failed(&e);
                format!("error: {e}")
            }
        };
        let ok = expected.to_string() == got;
        run.evidence.push(Record {
            step,
            role,
            action: text.to_owned(),
            at_us: run.t,
            sent: None,
            sent_text: Some(req.to_string()),
            expected: Some(Answer {
                hex: String::new(),
                text: expected.to_string(),
                delay_us: None,
            }),
            got: Some(Answer {
                hex: String::new(),
                text: got.clone(),
                delay_us: None,
            }),
            ok: Some(ok),
            note: Some("exact".to_owned()),
        });
        if !ok && run.failure.is_none() {
            run.failure = Some(Failure {
                step: Some(step),
                message: format!("step {step} ({text}): the reply differs from the reference"),
                expected: expected.to_string(),
                got,
                requirements: self.refs(run.reqs),
            });
        }
        ok
    }

    fn run_steps(&mut self, case: &PsdCase, run: &mut Run<'_>) -> Result<(), String> {
        let pkw = self.suite.reference().rules().pkw();
        let running_bit = status_bit(self.suite.family(), "Drive is running")?;
        let no_response = pkw.response_codes().no_response;
        for (n, s) in case.steps.iter().enumerate() {
            let first = run.cycles.len();
            match &s.action {
                Action::Process { control, target } => {
                    if let Some(c) = control {
                        run.out.control = *c;
                    }
                    if let Some(t) = target {
                        run.out.target = *t;
                    }
                    self.cycle(run, n)?;
                }
                Action::Offset { control, offset } => {
                    if let Some(c) = control {
                        run.out.control = *c;
                    }
                    let actual = Self::last_ref(run).map_or(0, |i| i64::from(i.actual));
                    let t = actual.saturating_add(*offset);
                    run.out.target =
                        i32::try_from(t).unwrap_or(if t < 0 { i32::MIN } else { i32::MAX });
                    self.cycle(run, n)?;
                }
                Action::Pkw(req) => {
                    run.out.pkw = *req;
                    for _ in 0..PKW_MAX_CYCLES {
                        self.cycle(run, n)?;
                        let answered = Self::last_ref(run).is_some_and(|i| {
                            if req == &PkwRequest::default()
                                || pkw
                                    .command_info(req.ak)
                                    .is_some_and(|c| c.op == drivespec_spec::psd4xx::PkwOp::None)
                            {
                                i.pkw.ak == no_response
                            } else {
                                pkw.answers(req, &i.pkw)
                            }
                        });
                        if answered {
                            break;
                        }
                    }
                }
                Action::Hold(k) => {
                    for _ in 0..*k {
                        self.cycle(run, n)?;
                    }
                }
                Action::Until { running, max } => {
                    for i in 0..*max {
                        self.cycle(run, n)?;
                        let done = Self::last_ref(run).is_some_and(|r| {
                            let on = r.status & running_bit != 0;
                            if *running {
                                on
                            } else {
                                i >= 2 && !on && r.speed == 0
                            }
                        });
                        if done {
                            break;
                        }
                    }
                }
                Action::Record(r) => {
                    let req = match r {
                        RecordRequest::Read { index } => Request::Read {
                            t: run.t,
                            index: *index,
                        },
                        RecordRequest::Write { index, data } => Request::Write {
                            t: run.t,
                            index: *index,
                            data: data.clone(),
                        },
                    };
                    if !self.exact(run, n, s.role, &s.text, req) {
                        return Ok(());
                    }
                    continue;
                }
                Action::Env(env) => {
                    let req = Request::Env {
                        t: run.t,
                        env: *env,
                    };
                    if !self.exact(run, n, s.role, &s.text, req) {
                        return Ok(());
                    }
                    continue;
                }
                Action::Advance(us) => {
                    run.t = run.t.saturating_add(*us);
                    let req = Request::Advance { t: run.t };
                    if !self.exact(run, n, s.role, &s.text, req) {
                        return Ok(());
                    }
                    continue;
                }
            }
            // One record per cycle step: the last cycle of the step.
            let image = run
                .out
                .to_bytes(self.suite.reference().rules())
                .unwrap_or_default();
            let sent_text = format!(
                "control {:#06x} target {} | {} ({} cycle(s))",
                run.out.control,
                run.out.target,
                pkw.describe_request(&run.out.pkw),
                run.cycles.len().saturating_sub(first)
            );
            if let Some(c) = run.cycles.last() {
                let rules = self.suite.reference().rules();
                let expected = Answer {
                    hex: c
                        .reference
                        .to_bytes(rules)
                        .map(|b| hex(&b))
                        .unwrap_or_default(),
                    text: self.describe(&c.reference),
                    delay_us: None,
                };
                let got = match &c.dut {
                    Ok(i) => Answer {
                        hex: i.to_bytes(rules).map(|b| hex(&b)).unwrap_or_default(),
                        text: self.describe(i),
                        delay_us: None,
                    },
                    Err(e) => Answer {
                        hex: String::new(),
                        text: e.clone(),
                        delay_us: None,
                    },
                };
                run.evidence.push(Record {
                    step: n,
                    role: s.role,
                    action: s.text.clone(),
                    at_us: c.t,
                    sent: Some(hex(&image)),
                    sent_text: Some(sent_text),
                    expected: Some(expected),
                    got: Some(got),
                    ok: None,
                    note: None,
                });
            }
        }
        Ok(())
    }

    /// Judges the cycles under `tol`; marks the records and sets the first failure.
    fn judge(&self, run: &mut Run<'_>, tol: Tolerance) {
        let k = usize::try_from(tol.cycles).unwrap_or(0);
        let fits = |d: &Input, r: &Input| {
            d.pkw == r.pkw
                && d.status == r.status
                && (i64::from(d.actual) - i64::from(r.actual)).abs() <= tol.position
                && (i64::from(d.speed) - i64::from(r.speed)).abs() <= tol.speed
        };
        let n = run.cycles.len();
        let mut bad_steps = Vec::new();
        for (i, c) in run.cycles.iter().enumerate() {
            let ok = match &c.dut {
                Ok(d) => run
                    .cycles
                    .get(i.saturating_sub(k)..=(i + k).min(n.saturating_sub(1)))
                    .unwrap_or(&[])
                    .iter()
                    .any(|r| fits(d, &r.reference)),
                Err(_) => false,
            };
            if ok {
                continue;
            }
            if !bad_steps.contains(&c.step) {
                bad_steps.push(c.step);
            }
            if run.failure.is_none() {
                let got = match &c.dut {
                    Ok(d) => self.describe(d),
                    Err(e) => e.clone(),
                };
                run.failure = Some(Failure {
                    step: Some(c.step),
                    message: format!(
                        "cycle {} at {} ms (step {}): the input image differs from the reference (tolerance ±{} cycle(s), position ±{}, speed ±{})",
                        i + 1,
                        c.t / 1000,
                        c.step,
                        tol.cycles,
                        tol.position,
                        tol.speed
                    ),
                    expected: self.describe(&c.reference),
                    got,
                    requirements: self.refs(&self.cited(run.reqs, c.dut.as_ref().ok(), &c.reference)),
                });
            }
        }
        for r in &mut run.evidence {
            if r.ok.is_none() && r.role != Role::Cleanup {
                r.ok = Some(!bad_steps.contains(&r.step));
                r.note = Some(format!(
                    "every cycle: PKW and status exact; position ±{}, speed ±{}, time ±{} cycle(s)",
                    tol.position, tol.speed, tol.cycles
                ));
            }
        }
    }

    /// Runs one case (a generated one, or a fuzz sequence) against the device and a fresh
    /// reference.
    pub(crate) fn run_case(&mut self, info: &CaseInfo, case: &PsdCase) -> CaseRun {
        self.device.clear_error();
        let rules = self.suite.reference().rules();
        let mut run = Run {
            reference: self.suite.server(),
            out: Output::idle(rules),
            t: 0,
            cycles: Vec::new(),
            evidence: Vec::new(),
            failure: None,
            reqs: &info.requirements,
        };
        let reset_ok = match self.device.call(&Request::Reset) {
            Ok(Reply::Ok) => Ok(()),
            Ok(other) => Err(format!("RESET answered with {other}")),
            Err(e) => {
                self.device.failed(&e);
                Err(e.to_string())
            }
        };
        if let Err(e) = reset_ok {
            return CaseRun {
                outcome: Outcome::Fail(Failure {
                    step: None,
                    message: format!("the device could not be reset: {e}"),
                    expected: "OK".to_owned(),
                    got: e,
                    requirements: self.refs(&info.requirements),
                }),
                evidence: Vec::new(),
                elapsed_us: 0,
            };
        }
        let _ = run.reference.handle(Request::Reset);
        if let Err(e) = self.run_steps(case, &mut run) {
            if run.failure.is_none() {
                run.failure = Some(Failure {
                    step: run.cycles.last().map(|c| c.step),
                    message: format!("the exchange failed: {e}"),
                    expected: "a reply".to_owned(),
                    got: e,
                    requirements: self.refs(&info.requirements),
                });
            }
        }
        self.judge(&mut run, case.tol);
        if case.plot {
            let samples: Vec<Sample> = run
                .cycles
                .iter()
                .map(|c| Sample {
                    t_ms: c.t / 1000,
                    reference: (
                        i64::from(c.reference.actual),
                        i64::from(c.reference.speed),
                        c.reference.status,
                    ),
                    dut: c
                        .dut
                        .as_ref()
                        .ok()
                        .map(|d| (i64::from(d.actual), i64::from(d.speed), d.status)),
                })
                .collect();
            run.evidence.push(Record {
                step: case.steps.len(),
                role: Role::Cleanup,
                action: plot::ACTION.to_owned(),
                at_us: run.t,
                sent: None,
                sent_text: None,
                expected: None,
                got: None,
                ok: None,
                note: Some(plot::encode(&samples)),
            });
        }
        CaseRun {
            outcome: match run.failure {
                Some(f) => Outcome::Fail(f),
                None => Outcome::Pass,
            },
            evidence: run.evidence,
            elapsed_us: run.t,
        }
    }
}

impl Session for Psd4xxSession<'_, '_> {
    fn describe(&self) -> String {
        self.device.describe()
    }

    fn run(&mut self, index: usize) -> CaseRun {
        let Some((info, case)) = self.suite.case(index) else {
            return CaseRun {
                outcome: Outcome::Skip {
                    reason: format!("no case {index}"),
                },
                evidence: Vec::new(),
                elapsed_us: 0,
            };
        };
        self.run_case(info, case)
    }
}
