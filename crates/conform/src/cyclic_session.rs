//! Running a case of a cyclic family (PSD4xx, PSx3xx) over the cyclic-exchange protocol: the
//! device under test and a fresh reference drive get the same requests; every cycle's input
//! image is compared within the case's [`Tolerance`], every request between cycles by its
//! reply. A family supplies its images, its steps and its reply comparison through
//! [`CyclicFamily`].

use crate::case::{Answer, CaseInfo, CaseRun, Failure, Outcome, Record, RequirementRef, Role};
use crate::cyclic::device::Device;
use crate::cyclic::{Env, LinkPeer, LocalPeer, Peer, PeerError, Reply, Request, Server};
use crate::dut::Dut;
use crate::link::{ExecLink, SerialLink, TcpLink};
use crate::suite::{Session, SetupError};
use drivespec_report::plot::{self, Sample};
use drivespec_spec::hex::to_hex_compact as hex;
use drivespec_spec::{Family, FamilyId};

/// Declared tolerances of a case (physics); everything else is exact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct Tolerance {
    /// A device sample may match a reference sample this many cycles earlier or later.
    pub cycles: u32,
    /// Actual position, in the family's position unit.
    pub position: i64,
    /// Speed, rpm.
    pub speed: i64,
}

/// Tolerance of the motion cases: ±3 cycles, ±20 position units, ±2 rpm.
pub(crate) const MOTION: Tolerance = Tolerance {
    cycles: 3,
    position: 20,
    speed: 2,
};

/// One step: who it is for, one line, what it does.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct StepDef<A> {
    /// Setup, check or cleanup.
    pub role: Role,
    /// One line.
    pub text: String,
    /// What to do.
    pub action: A,
}

/// What a step does, as the session runs it.
pub(crate) enum Op<O> {
    /// The output becomes this, then up to `max` cycles until the reference answers the step
    /// ([`CyclicFamily::answered`]).
    Send {
        /// The new output.
        out: O,
        /// Most cycles.
        max: u32,
    },
    /// Cycles with the output unchanged.
    Hold(u32),
    /// Cycles until the reference's "Drive is running" status bit is set (`true`) or the
    /// reference stands still (`false`), at most `max`.
    Until {
        /// Wait for running (true) or standstill (false).
        running: bool,
        /// Most cycles.
        max: u32,
    },
    /// Time passes by this many µs without a bus cycle (`ADVANCE`), judged by its reply.
    Advance(u64),
    /// A request between two cycles, judged by its reply.
    Exchange(Request),
}

/// What a cyclic family's session needs from the family: its reference, images, steps and
/// reply comparison.
/// `'s` is the lifetime of the reference server.
pub(crate) trait CyclicFamily<'s> {
    /// The input image.
    type Input: Copy;
    /// The output image.
    type Output: Clone;
    /// A step's action.
    type Action;
    /// A case.
    type Case: Clone;
    /// The family.
    const ID: FamilyId;
    /// What every cycle compares exactly, as the evidence says (`status`).
    const EXACT: &'static str;
    /// The family's spec.
    fn spec(&self) -> &Family;
    /// The device model.
    fn model(&self) -> &str;
    /// A fresh reference server.
    fn server(&self) -> Server<'s>;
    /// Case `index`.
    fn case(&self, index: usize) -> Option<(&CaseInfo, &Self::Case)>;
    /// A case's steps.
    fn steps(case: &Self::Case) -> &[StepDef<Self::Action>];
    /// A case's tolerances.
    fn tolerance(case: &Self::Case) -> Tolerance;
    /// Whether a case's report gets a position/speed/status plot.
    fn plot(case: &Self::Case) -> bool;
    /// The output the master sends before a case's first step that sets one.
    fn start(&self, case: &Self::Case) -> Self::Output;
    /// The bus cycle (µs).
    fn cycle_us(&self) -> u64;
    /// The bytes of an output image.
    fn image(&self, out: &Self::Output) -> Result<Vec<u8>, String>;
    /// An input image from its bytes.
    fn parse(&self, bytes: &[u8]) -> Result<Self::Input, String>;
    /// The bytes of an input image.
    fn input_bytes(&self, input: &Self::Input) -> Result<Vec<u8>, String>;
    /// An input image in words.
    fn describe(&self, input: &Self::Input) -> String;
    /// An output image in words.
    fn describe_output(&self, out: &Self::Output) -> String;
    /// Actual position, speed and status word of an input image.
    fn motion(input: &Self::Input) -> (i64, i64, u16);
    /// Whether the parts compared exactly are equal.
    fn exact_equal(device: &Self::Input, reference: &Self::Input) -> bool;
    /// The "Drive is running" status bit.
    fn running_bit(&self) -> u16;
    /// The requirements a differing cycle cites: the case's plus those of what differs.
    fn cited(
        &self,
        case: &[String],
        dut: Option<&Self::Input>,
        reference: &Self::Input,
    ) -> Vec<String>;
    /// Whether the device's reply to `req` conforms to the reference's, with a remark for the
    /// evidence when it conforms other than by equality.
    fn same_reply(
        &self,
        req: &Request,
        expected: &Reply,
        got: &Reply,
        tol: Tolerance,
    ) -> (bool, Option<String>);
    /// What `action` does, given the current output, the reference's last input and the time.
    fn op(
        &self,
        action: &Self::Action,
        out: &Self::Output,
        last: Option<&Self::Input>,
        t: u64,
    ) -> Op<Self::Output>;
    /// Whether the reference's input answers `action` (ends an [`Op::Send`] early).
    fn answered(&self, action: &Self::Action, reference: &Self::Input) -> bool;
}

/// The peer of the device under test `dut`; `sim` is the reference server of `model`, built
/// by `server` only then.
pub(crate) fn peer<'p>(
    dut: &Dut,
    model: &str,
    server: impl FnOnce() -> Server<'p>,
) -> Result<Box<dyn Peer + 'p>, SetupError> {
    // Real peers get 2 s per reply (a process may take a while to start).
    const TIMEOUT_US: u64 = 2_000_000;
    Ok(match dut {
        Dut::Sim { .. } => Box::new(LocalPeer::new(&format!("sim:{model}"), server())),
        Dut::Serial { path, baud } => {
            // The cyclic protocol is plain text: 8N1.
            let character = drivespec_spec::hpd::CharacterFormat {
                source: "drivespec-cyclic/1".to_owned(),
                start_bits: 1,
                data_bits: 8,
                parity: drivespec_spec::hpd::Parity::None,
                stop_bits: 1,
                bits_per_char: 10,
            };
            Box::new(LinkPeer::new(
                Box::new(SerialLink::open(path, baud.unwrap_or(115_200), &character)?),
                TIMEOUT_US,
            ))
        }
        Dut::Tcp { addr } => Box::new(LinkPeer::new(Box::new(TcpLink::connect(addr)?), TIMEOUT_US)),
        Dut::Exec { argv } => Box::new(LinkPeer::new(Box::new(ExecLink::spawn(argv)?), TIMEOUT_US)),
    })
}

/// A session of family `F` on one device under test.
pub(crate) struct CyclicSession<'a, F> {
    family: F,
    /// The device under test; its first transport failure of a case run is a crash or hang
    /// to the fuzzer.
    device: Device<'a>,
}

/// One cycle as both sides saw it.
struct Cycle<I> {
    step: usize,
    t: u64,
    reference: I,
    dut: Result<I, String>,
}

/// What one case run collected.
struct Run<'r, 's, I, O> {
    reference: Server<'s>,
    tol: Tolerance,
    out: O,
    t: u64,
    /// The step being run.
    step: usize,
    cycles: Vec<Cycle<I>>,
    evidence: Vec<Record>,
    failure: Option<Failure>,
    reqs: &'r [String],
}

impl<'a, 's, F: CyclicFamily<'s>> CyclicSession<'a, F> {
    /// A session of `family` on `peer`.
    pub(crate) fn new(family: F, peer: Box<dyn Peer + 'a>) -> CyclicSession<'a, F> {
        let device = Device::new(peer, F::ID, family.model());
        CyclicSession { family, device }
    }

    /// Exchanges `HELLO`; an error names what the device side said.
    pub(crate) fn hello(&mut self) -> Result<String, String> {
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
        let family = self.family.spec();
        ids.iter()
            .filter_map(|id| RequirementRef::of(family, id))
            .collect()
    }

    fn parse_input(&self, reply: &Reply) -> Result<F::Input, String> {
        match reply {
            Reply::In(b) => self
                .family
                .parse(b)
                .map_err(|e| format!("bad input image {}: {e}", hex(b))),
            other => Err(format!("{other}")),
        }
    }

    /// One cycle with the current output on both sides.
    fn cycle(
        &mut self,
        run: &mut Run<'_, 's, F::Input, F::Output>,
        step: usize,
    ) -> Result<(), String> {
        run.t = run.t.saturating_add(self.family.cycle_us());
        let image = self.family.image(&run.out)?;
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

    /// An exchange judged by its reply (the family's [`CyclicFamily::same_reply`]).
    fn exact(
        &mut self,
        run: &mut Run<'_, 's, F::Input, F::Output>,
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
            Some(g) => self.family.same_reply(&req, &expected, g, run.tol),
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

    fn run_steps(
        &mut self,
        steps: &[StepDef<F::Action>],
        run: &mut Run<'_, 's, F::Input, F::Output>,
    ) -> Result<(), String> {
        for (n, s) in steps.iter().enumerate() {
            run.step = n;
            let first = run.cycles.len();
            let last = run.cycles.last().map(|c| c.reference);
            match self.family.op(&s.action, &run.out, last.as_ref(), run.t) {
                Op::Send { out, max } => {
                    run.out = out;
                    for _ in 0..max {
                        self.cycle(run, n)?;
                        if run
                            .cycles
                            .last()
                            .is_some_and(|c| self.family.answered(&s.action, &c.reference))
                        {
                            break;
                        }
                    }
                }
                Op::Hold(k) => {
                    for _ in 0..k {
                        self.cycle(run, n)?;
                    }
                }
                Op::Until { running, max } => {
                    let running_bit = self.family.running_bit();
                    for i in 0..max {
                        self.cycle(run, n)?;
                        let done = run.cycles.last().is_some_and(|c| {
                            let (_, speed, status) = F::motion(&c.reference);
                            let on = status & running_bit != 0;
                            if running {
                                on
                            } else {
                                i >= 2 && !on && speed == 0
                            }
                        });
                        if done {
                            break;
                        }
                    }
                }
                Op::Advance(us) => {
                    run.t = run.t.saturating_add(us);
                    let req = Request::Advance { t: run.t };
                    if !self.exact(run, n, s.role, &s.text, req) {
                        return Ok(());
                    }
                    continue;
                }
                Op::Exchange(req) => {
                    if !self.exact(run, n, s.role, &s.text, req) {
                        return Ok(());
                    }
                    continue;
                }
            }
            // One record per cycle step: the last cycle of the step.
            let image = self.family.image(&run.out).unwrap_or_default();
            let sent_text = format!(
                "{} ({} cycle(s))",
                self.family.describe_output(&run.out),
                run.cycles.len().saturating_sub(first)
            );
            if let Some(c) = run.cycles.last() {
                let to_hex = |i: &F::Input| {
                    self.family
                        .input_bytes(i)
                        .map(|b| hex(&b))
                        .unwrap_or_default()
                };
                let expected = Answer {
                    hex: to_hex(&c.reference),
                    text: self.family.describe(&c.reference),
                    delay_us: None,
                };
                let got = match &c.dut {
                    Ok(i) => Answer {
                        hex: to_hex(i),
                        text: self.family.describe(i),
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
    fn judge(&self, run: &mut Run<'_, 's, F::Input, F::Output>, tol: Tolerance) {
        let k = usize::try_from(tol.cycles).unwrap_or(0);
        let fits = |d: &F::Input, r: &F::Input| {
            let ((da, ds, _), (ra, rs, _)) = (F::motion(d), F::motion(r));
            F::exact_equal(d, r) && (da - ra).abs() <= tol.position && (ds - rs).abs() <= tol.speed
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
                    Ok(d) => self.family.describe(d),
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
                    expected: self.family.describe(&c.reference),
                    got,
                    requirements: self.refs(&self.family.cited(run.reqs, c.dut.as_ref().ok(), &c.reference)),
                });
            }
        }
        for r in &mut run.evidence {
            if r.ok.is_none() && r.role != Role::Cleanup {
                r.ok = Some(!bad_steps.contains(&r.step));
                r.note = Some(format!(
                    "every cycle: {} exact; position ±{}, speed ±{}, time ±{} cycle(s)",
                    F::EXACT,
                    tol.position,
                    tol.speed,
                    tol.cycles
                ));
            }
        }
    }

    /// Runs one case (a generated one, or a fuzz sequence) against the device and a fresh
    /// reference.
    pub(crate) fn run_case(&mut self, info: &CaseInfo, case: &F::Case) -> CaseRun {
        let (steps, tol) = (F::steps(case), F::tolerance(case));
        self.device.clear_error();
        let mut run = Run {
            reference: self.family.server(),
            tol,
            out: self.family.start(case),
            t: 0,
            step: 0,
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
        if let Err(e) = self.run_steps(steps, &mut run) {
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
        self.judge(&mut run, tol);
        if F::plot(case) {
            let samples: Vec<Sample> = run
                .cycles
                .iter()
                .map(|c| Sample {
                    t_ms: c.t / 1000,
                    reference: F::motion(&c.reference),
                    dut: c.dut.as_ref().ok().map(F::motion),
                })
                .collect();
            run.evidence.push(Record {
                step: steps.len(),
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

impl<'s, F: CyclicFamily<'s>> Session for CyclicSession<'_, F> {
    fn describe(&self) -> String {
        self.device.describe()
    }

    fn run(&mut self, index: usize) -> CaseRun {
        let Some((info, case)) = self.family.case(index) else {
            return CaseRun {
                outcome: Outcome::Skip {
                    reason: format!("no case {index}"),
                },
                evidence: Vec::new(),
                elapsed_us: 0,
            };
        };
        // The case borrows the family; run a copy of it.
        let (info, case) = (info.clone(), case.clone());
        self.run_case(&info, &case)
    }
}
