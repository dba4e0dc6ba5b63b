//! Running PSx3xx cases: the device under test and a fresh reference drive get the same
//! requests; every cycle's input image and every ISDU and injection reply is compared.

use super::cases::{Action, PsxCase, Tolerance};
use super::Psx3xxSuite;
use crate::case::{Answer, CaseInfo, CaseRun, Failure, Outcome, Record, RequirementRef, Role};
use crate::cyclic::device::Device;
use crate::cyclic::wire::hex;
use crate::cyclic::{Env, Peer, PeerError, Reply, Request, Server};
use crate::suite::Session;
use drivespec_psx3xx::isdu::{ErrorType, Request as IsduRequest};
use drivespec_psx3xx::{Input, Output};
use drivespec_report::plot::{self, Sample};
use drivespec_spec::FamilyId;

/// A session on one device under test.
pub struct Psx3xxSession<'a, 's> {
    suite: &'a Psx3xxSuite<'s>,
    /// The device under test.
    device: Device<'a>,
    running_bit: u16,
    /// ISDU indices of the live speed and position (3.3.2 `rpm`, `actual`), judged within
    /// the case's speed and position tolerance.
    live: Vec<(u16, Live)>,
}

/// Which tolerance a live ISDU value gets.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Live {
    /// Actual speed (ISDU 65).
    Speed,
    /// Actual position (ISDU 67).
    Position,
}

/// One cycle as both sides saw it.
struct Cycle {
    step: usize,
    t: u64,
    reference: Input,
    dut: Result<Input, String>,
}

/// What one case run collected.
struct Run<'r, 's> {
    reference: Server<'s>,
    tol: Tolerance,
    out: Output,
    t: u64,
    cycles: Vec<Cycle>,
    /// The step being run.
    step: usize,
    evidence: Vec<Record>,
    failure: Option<Failure>,
    reqs: &'r [String],
}

/// The status bit the runner waits on (manual 3.4 bit 6).
const RUNNING: &str = "Drive is running";

impl<'a, 's> Psx3xxSession<'a, 's> {
    pub(crate) fn new(
        suite: &'a Psx3xxSuite<'s>,
        peer: Box<dyn Peer + 'a>,
    ) -> Psx3xxSession<'a, 's> {
        let running_bit = suite
            .reference()
            .rules()
            .status_bits()
            .and_then(|b| b.bits.iter().find(|x| x.name == RUNNING))
            .and_then(|x| 1u16.checked_shl(x.bit))
            .unwrap_or(0);
        let family = suite.family();
        let live = suite
            .reference()
            .rules()
            .protocol()
            .process_input
            .fields
            .iter()
            .filter_map(|f| {
                let kind = match f.name.as_str() {
                    "rpm" => Live::Speed,
                    "actual" => Live::Position,
                    _ => return None,
                };
                let param = f.params.first()?;
                let p = family.parameters.iter().find(|p| &p.id == param)?;
                Some((u16::try_from(p.number).ok()?, kind))
            })
            .collect();
        Psx3xxSession {
            suite,
            device: Device::new(peer, FamilyId::Psx3xx, suite.model()),
            running_bit,
            live,
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

    fn describe(i: &Input) -> String {
        format!(
            "status {:#06x} speed {} actual {}",
            i.status, i.rpm, i.actual
        )
    }

    fn parse_input(&self, reply: &Reply) -> Result<Input, String> {
        let d = self.suite.reference();
        match reply {
            Reply::In(b) => Input::parse(d.rules(), d.byte_order(), b)
                .map_err(|e| format!("bad input image {}: {e}", hex(b))),
            other => Err(format!("{other}")),
        }
    }

    fn image(&self, out: &Output) -> Result<Vec<u8>, String> {
        let d = self.suite.reference();
        out.to_bytes(d.rules(), d.byte_order())
            .map_err(|e| e.to_string())
    }

    /// One cycle with the current output on both sides.
    fn cycle(&mut self, run: &mut Run<'_, 's>, step: usize) -> Result<(), String> {
        run.t = run.t.saturating_add(self.suite.cycle_us());
        let image = self.image(&run.out)?;
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

    /// The ErrorType a reply names (spec name or hex), None for other replies.
    fn error_code(&self, reply: &Reply) -> Option<ErrorType> {
        let Reply::IsduError(name) = reply else {
            return None;
        };
        let table = self.suite.reference().rules().error_types();
        table.code(name).or_else(|| {
            let digits = name
                .strip_prefix("0x")
                .or_else(|| name.strip_prefix("0X"))?;
            u16::from_str_radix(digits, 16).ok().map(ErrorType)
        })
    }

    /// Whether the device's reply conforms: the reference's exactly, or for an ISDU error
    /// the same ErrorType (named or hex) or one the spec's cases with that ErrorType accept
    /// (IEC 61131-9 C.2).
    fn same_reply(&self, expected: &Reply, got: &Reply) -> (bool, Option<String>) {
        if expected == got {
            return (true, None);
        }
        let (Some(e), Some(g)) = (self.error_code(expected), self.error_code(got)) else {
            return (false, None);
        };
        if e == g {
            return (true, None);
        }
        let accepted = self
            .suite
            .reference()
            .rules()
            .case_rules()
            .iter()
            .any(|r| r.code == e && r.acceptable.contains(&g));
        (
            accepted,
            accepted.then(|| format!("ErrorType {g} accepted for {e}")),
        )
    }

    /// A live value read by ISDU (speed, position) within the case's tolerance: both replies
    /// `DATA` of the same width, signed, most significant octet first.
    fn live_within(
        &self,
        req: &Request,
        expected: &Reply,
        got: &Reply,
        tol: Tolerance,
    ) -> Option<String> {
        let Request::IsduRead {
            index, subindex: 0, ..
        } = req
        else {
            return None;
        };
        let (_, kind) = self.live.iter().find(|(i, _)| i == index)?;
        let (Reply::Data(e), Reply::Data(g)) = (expected, got) else {
            return None;
        };
        let signed = |b: &[u8]| -> Option<i64> {
            if b.is_empty() || b.len() > 8 {
                return None;
            }
            let first = i64::from(i8::from_ne_bytes([*b.first()?]));
            Some(
                b.iter()
                    .skip(1)
                    .fold(first, |a, x| (a << 8) | i64::from(*x)),
            )
        };
        let (ev, gv) = (signed(e)?, signed(g)?);
        let limit = match kind {
            Live::Speed => tol.speed,
            Live::Position => tol.position,
        };
        (e.len() == g.len() && (ev - gv).abs() <= limit && limit > 0)
            .then(|| format!("live value within ±{limit}"))
    }

    /// An exchange judged exactly (ISDU, injection); live values within the tolerance.
    fn exact(
        &mut self,
        run: &mut Run<'_, 's>,
        step: usize,
        role: Role,
        text: &str,
        req: Request,
    ) -> bool {
        let expected = run.reference.handle(req.clone());
        let (got, got_text) = match self.device.call(&req) {
            Ok(r) => {
                let t = r.to_string();
                (Some(r), t)
            }
            Err(e) => {
                self.device.failed(&e);
                (None, format!("error: {e}"))
            }
        };
        let (ok, remark) = match &got {
            Some(g) => match self.same_reply(&expected, g) {
                (false, _) => match self.live_within(&req, &expected, g, run.tol) {
                    Some(note) => (true, Some(note)),
                    None => (false, None),
                },
                same => same,
            },
            None => (false, None),
        };
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
                text: got_text.clone(),
                delay_us: None,
            }),
            ok: Some(ok),
            note: Some(remark.unwrap_or_else(|| "exact".to_owned())),
        });
        if !ok && run.failure.is_none() {
            run.failure = Some(Failure {
                step: Some(step),
                message: format!("step {step} ({text}): the reply differs from the reference"),
                expected: expected.to_string(),
                got: got_text,
                requirements: self.refs(run.reqs),
            });
        }
        ok
    }

    fn run_steps(&mut self, case: &PsxCase, run: &mut Run<'_, 's>) -> Result<(), String> {
        for (n, s) in case.steps.iter().enumerate() {
            run.step = n;
            let first = run.cycles.len();
            match &s.action {
                Action::Out(out) => {
                    run.out = *out;
                    self.cycle(run, n)?;
                }
                Action::Hold(k) => {
                    for _ in 0..*k {
                        self.cycle(run, n)?;
                    }
                }
                Action::Until { running, max } => {
                    for i in 0..*max {
                        self.cycle(run, n)?;
                        let done = run.cycles.last().is_some_and(|c| {
                            let on = c.reference.status & self.running_bit != 0;
                            if *running {
                                on
                            } else {
                                i >= 2 && !on && c.reference.rpm == 0
                            }
                        });
                        if done {
                            break;
                        }
                    }
                }
                Action::Silence(us) => {
                    run.t = run.t.saturating_add(*us);
                    let req = Request::Advance { t: run.t };
                    if !self.exact(run, n, s.role, &s.text, req) {
                        return Ok(());
                    }
                    continue;
                }
                Action::Isdu(r) => {
                    let req = match r.clone() {
                        IsduRequest::Read { index, subindex } => Request::IsduRead {
                            t: run.t,
                            index,
                            subindex,
                        },
                        IsduRequest::Write {
                            index,
                            subindex,
                            data,
                        } => Request::IsduWrite {
                            t: run.t,
                            index,
                            subindex,
                            data,
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
            }
            // One record per cycle step: the last cycle of the step.
            let image = self.image(&run.out).unwrap_or_default();
            let sent_text = format!(
                "{} ({} cycle(s))",
                out_text(&run.out),
                run.cycles.len().saturating_sub(first)
            );
            if let Some(c) = run.cycles.last() {
                let d = self.suite.reference();
                let to_hex = |i: &Input| {
                    i.to_bytes(d.rules(), d.byte_order())
                        .map(|b| hex(&b))
                        .unwrap_or_default()
                };
                let expected = Answer {
                    hex: to_hex(&c.reference),
                    text: Self::describe(&c.reference),
                    delay_us: None,
                };
                let got = match &c.dut {
                    Ok(i) => Answer {
                        hex: to_hex(i),
                        text: Self::describe(i),
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
    fn judge(&self, run: &mut Run<'_, 's>, tol: Tolerance) {
        let k = usize::try_from(tol.cycles).unwrap_or(0);
        let fits = |d: &Input, r: &Input| {
            d.status == r.status
                && (i64::from(d.actual) - i64::from(r.actual)).abs() <= tol.position
                && (i64::from(d.rpm) - i64::from(r.rpm)).abs() <= tol.speed
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
                    Ok(d) => Self::describe(d),
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
                    expected: Self::describe(&c.reference),
                    got,
                    requirements: self.refs(run.reqs),
                });
            }
        }
        for r in &mut run.evidence {
            if r.ok.is_none() && r.role != Role::Cleanup {
                r.ok = Some(!bad_steps.contains(&r.step));
                r.note = Some(format!(
                    "every cycle: status exact; position ±{}, speed ±{}, time ±{} cycle(s)",
                    tol.position, tol.speed, tol.cycles
                ));
            }
        }
    }

    pub(crate) fn run_case(&mut self, info: &CaseInfo, case: &PsxCase) -> CaseRun {
        self.device.clear_error();
        let mut run = Run {
            reference: self.suite.server(),
            tol: case.tol,
            out: case.start,
            t: 0,
            cycles: Vec::new(),
            step: 0,
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
                    step: Some(run.step),
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
                        i64::from(c.reference.rpm),
                        c.reference.status,
                    ),
                    dut: c
                        .dut
                        .as_ref()
                        .ok()
                        .map(|d| (i64::from(d.actual), i64::from(d.rpm), d.status)),
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

/// The process output in words (manual 3.3.1).
fn out_text(out: &Output) -> String {
    match out {
        Output::TimeStamp { control, stamp } => {
            format!("format 0: code {} stamp {}", control.0, stamp.0)
        }
        Output::ControlTarget {
            control_word,
            target,
        } => format!("format 1: control {control_word:#06x} target {target}"),
        Output::SpeedControlTarget {
            target_speed,
            control_word,
            target,
        } => format!("format 2: speed {target_speed} control {control_word:#06x} target {target}"),
    }
}

impl Session for Psx3xxSession<'_, '_> {
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
