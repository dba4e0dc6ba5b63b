//! Running PSx3xx cases ([`crate::cyclic_session`]): every cycle's input image (status word
//! exact) and every ISDU and injection reply is compared with the reference's.

use super::cases::{range_requirement, PsxCase, StepDef};
use super::Psx3xxSuite;
use crate::case::CaseInfo;
use crate::cyclic::{Env, Reply, Request, Server};
use crate::cyclic_session::{
    env_op, merged, same_length, status_bit_rules, CyclicFamily, CyclicSession, Live, Op,
    OpenPoint, Still, Tolerance,
};
use drivespec_psd4xx::model::LinkEvent as BusEvent;
use drivespec_psx3xx::isdu::ErrorType;
use drivespec_psx3xx::model::LinkEvent;
use drivespec_psx3xx::step::Step;
use drivespec_psx3xx::{Input, Output, Stamp, TsCode};
use drivespec_spec::psx3xx::IsduErrorCase;
use drivespec_spec::{DataType, Family, FamilyId, Parameter};

/// A session on one device under test.
pub type Psx3xxSession<'a, 's> = CyclicSession<'a, Psx3xx<'a, 's>>;

/// The PSx3xx family as the cyclic session runs it: the suite's reference and cases, the
/// running bit and the ISDU indices of the live values.
#[derive(Clone)]
pub struct Psx3xx<'a, 's> {
    suite: &'a Psx3xxSuite<'s>,
    running_bit: u16,
    /// ISDU indices of the live speed and position (3.3.2 `rpm`, `actual`), judged in a
    /// motion case against the device's own process data.
    live: Vec<(u16, Live)>,
}

/// The requirement that multi-byte process values come most significant byte first (3.3.2).
const BYTE_ORDER: &str = "PSX-PD-008";

/// The requirement that format 2 runs at the speed in the process data (4.6.4).
const PD_SPEED: &str = "PSX-VEL-005";

/// The requirement that a format-2 speed of 0 runs at ISDU 142 or 145 (4.6.4).
const PD_SPEED_ZERO: &str = "PSX-VEL-006";

/// The prefix of the time-stamp requirements (3.3.1, 4.4): what a drive does in format 0
/// follows from them.
const TIME_STAMP: &str = "PSX-TS-";

/// The status bit the runner waits on (manual 3.4 bit 6).
const RUNNING: &str = "Drive is running";

impl<'a, 's> Psx3xx<'a, 's> {
    /// The family of `suite`.
    pub(crate) fn new(suite: &'a Psx3xxSuite<'s>) -> Psx3xx<'a, 's> {
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
        Psx3xx {
            suite,
            running_bit,
            live,
        }
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
            drivespec_spec::hex::parse_hex_digits(digits).map(ErrorType)
        })
    }

    /// The parameter an ISDU request addresses (3.1).
    fn parameter(&self, req: &Request) -> Option<&'s Parameter> {
        let (index, subindex) = match req {
            Request::IsduRead {
                index, subindex, ..
            }
            | Request::IsduWrite {
                index, subindex, ..
            } => (u32::from(*index), u32::from(*subindex)),
            _ => return None,
        };
        let params = &self.suite.family().parameters;
        params
            .iter()
            .find(|p| p.number == index && p.subindex == Some(subindex))
            .or_else(|| {
                params
                    .iter()
                    .find(|p| p.number == index && p.subindex.is_none())
            })
    }

    /// The requirements of the situation in which the reference refused with `code`
    /// (`protocol.isdu_errors.case`): among the situations with that code, the first that
    /// names the parameter or whose requirement does, else the first for any parameter;
    /// the parameter's range requirement first where the situation is a value outside it.
    fn refusal(&self, code: ErrorType, param: Option<&Parameter>, case: &[String]) -> Vec<String> {
        let Some(errors) = self.suite.family().psx3xx().map(|p| &p.isdu_errors) else {
            return Vec::new();
        };
        let family = self.suite.family();
        let names = |c: &&&IsduErrorCase| {
            param.is_some_and(|p| {
                c.params.contains(&p.id)
                    || c.requirement
                        .as_deref()
                        .and_then(|r| family.requirement(r))
                        .is_some_and(|r| r.params.contains(&p.id))
            })
        };
        let with_code: Vec<&IsduErrorCase> =
            errors.cases.iter().filter(|c| c.code == code.0).collect();
        let Some(situation) = with_code
            .iter()
            .find(names)
            .or_else(|| with_code.iter().find(|c| c.params.is_empty()))
        else {
            return Vec::new();
        };
        let mut ids = Vec::new();
        if let Some(p) = param.filter(|_| situation.range) {
            let own = range_requirement(&p.id);
            if case.contains(&own) {
                ids.push(own);
            }
        }
        ids.extend(situation.requirement.clone());
        ids
    }

    /// Whether the device's reply is the reference's exactly, or for an ISDU error the same
    /// ErrorType (named or hex) or one the spec's cases with that ErrorType accept
    /// (IEC 61131-9 C.2).
    fn error_type_match(&self, expected: &Reply, got: &Reply) -> (bool, Option<String>) {
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
}

impl<'s> CyclicFamily<'s> for Psx3xx<'_, 's> {
    type Input = Input;
    type Output = Output;
    type Action = Step;
    type Case = PsxCase;
    const ID: FamilyId = FamilyId::Psx3xx;
    const EXACT: &'static str = "status";
    const CHANNEL: &'static str = "";
    type Channel = ();

    fn channel(_: &Input) {}

    fn spec(&self) -> &Family {
        self.suite.family()
    }

    fn model(&self) -> &str {
        self.suite.model()
    }

    fn server(&self) -> Server<'s> {
        self.suite.server()
    }

    fn case(&self, index: usize) -> Option<(&CaseInfo, &PsxCase)> {
        self.suite.case(index)
    }

    fn steps(case: &PsxCase) -> &[StepDef] {
        &case.steps
    }

    fn tolerance(case: &PsxCase) -> Tolerance {
        case.tol
    }

    fn plot(case: &PsxCase) -> bool {
        case.plot
    }

    fn start(&self, case: &PsxCase) -> Output {
        case.start
    }

    fn open(case: &PsxCase) -> Option<OpenPoint> {
        case.open.clone()
    }

    fn still(case: &PsxCase) -> Option<Still> {
        case.still.clone()
    }

    /// A case for the other brake option (5.4, `--brake`).
    fn not_applicable(case: &PsxCase) -> Option<String> {
        case.not_applicable.clone()
    }

    fn cycle_us(&self) -> u64 {
        self.suite.cycle_us()
    }

    fn image(&self, out: &Output) -> Result<Vec<u8>, String> {
        let d = self.suite.reference();
        out.to_bytes(d.rules(), d.byte_order())
            .map_err(|e| e.to_string())
    }

    fn parse(&self, bytes: &[u8]) -> Result<Input, String> {
        let d = self.suite.reference();
        Input::parse(d.rules(), d.byte_order(), bytes).map_err(|e| e.to_string())
    }

    fn input_bytes(&self, input: &Input) -> Result<Vec<u8>, String> {
        let d = self.suite.reference();
        input
            .to_bytes(d.rules(), d.byte_order())
            .map_err(|e| e.to_string())
    }

    fn describe(&self, i: &Input) -> String {
        format!(
            "status {:#06x} speed {} actual {}",
            i.status, i.rpm, i.actual
        )
    }

    /// The process output in words (manual 3.3.1).
    fn describe_output(&self, out: &Output) -> String {
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
            } => format!(
                "format 2: speed {target_speed} control {control_word:#06x} target {target}"
            ),
        }
    }

    fn motion(i: &Input) -> (i64, i64, u16) {
        (i64::from(i.actual), i64::from(i.rpm), i.status)
    }

    fn exact_equal(&self, d: &Input, r: &Input) -> bool {
        d.status == r.status
    }

    fn running_bit(&self) -> u16 {
        self.running_bit
    }

    /// What differs, then `case`: the byte order of the process data (PSX-PD-008) when the
    /// device's status word is the reference's with its two octets swapped; else while a
    /// time stamp is sent (format 0) the time-stamp requirements of `case` (3.3.1, 4.4) and
    /// the rules of every status bit that differs (3.4; those that give the reference's
    /// value first); where the speeds differ in format 2, the process-data speed (4.6.4).
    fn cited(
        &self,
        case: &[String],
        out: &Output,
        dut: Option<&Input>,
        reference: &Input,
    ) -> Vec<String> {
        let mut ids: Vec<String> = Vec::new();
        if let Some(d) = dut {
            if d.status != reference.status && d.status == reference.status.swap_bytes() {
                ids.push(BYTE_ORDER.to_owned());
            } else if d.status != reference.status {
                if matches!(out, Output::TimeStamp { .. }) {
                    ids.extend(case.iter().filter(|r| r.starts_with(TIME_STAMP)).cloned());
                }
                let differ = d.status ^ reference.status;
                for bit in (0..16u32).filter(|b| differ & (1 << b) != 0) {
                    ids.extend(status_bit_rules(
                        self.suite.family(),
                        bit,
                        Some(reference.status & (1 << bit) != 0),
                    ));
                }
            }
            ids.extend(speed_cited(out, d, reference));
        }
        merged(ids, case)
    }

    /// What the cycle shows, then `reqs` (a judgement's findings lead): the byte order of
    /// the process data (PSX-PD-008) when the status word comes swapped; else while a time
    /// stamp is sent (format 0: the run follows the stamp) the time-stamp requirements of
    /// `reqs` (3.3.1, 4.4); where the speeds differ in format 2, the process-data speed
    /// (4.6.4).
    fn judged_cited(
        &self,
        reqs: &[String],
        out: &Output,
        dut: Option<&Input>,
        reference: &Input,
    ) -> Vec<String> {
        let mut ids: Vec<String> = Vec::new();
        if let Some(d) = dut {
            if d.status != reference.status && d.status == reference.status.swap_bytes() {
                ids.push(BYTE_ORDER.to_owned());
            } else if matches!(out, Output::TimeStamp { .. }) {
                ids.extend(reqs.iter().filter(|r| r.starts_with(TIME_STAMP)).cloned());
            }
            ids.extend(speed_cited(out, d, reference));
        }
        merged(ids, reqs)
    }

    /// What the reply shows, then `case`: where the reference refused with an ErrorType the
    /// device did not give, the requirement of that refusal (`protocol.isdu_errors.case`;
    /// the parameter's range requirement first for a value outside it); then the case's
    /// requirements that concern the addressed parameter (a read whose value differs), in
    /// the case's order.
    fn reply_cited(
        &self,
        case: &[String],
        req: &Request,
        expected: &Reply,
        got: &Reply,
    ) -> Vec<String> {
        let param = self.parameter(req);
        let mut ids: Vec<String> = Vec::new();
        if let Some(code) = self.error_code(expected) {
            if self.error_code(got) != Some(code) {
                ids.extend(self.refusal(code, param, case));
            }
        }
        if let Some(p) = param {
            let family = self.suite.family();
            ids.extend(
                case.iter()
                    .filter(|r| {
                        family
                            .requirement(r)
                            .is_some_and(|x| x.params.contains(&p.id))
                    })
                    .cloned(),
            );
        }
        merged(ids, case)
    }

    /// The reference's reply exactly, or for an ISDU error the same ErrorType (named or hex)
    /// or one the spec's cases with that ErrorType accept (IEC 61131-9 C.2).
    fn same_reply(
        &self,
        req: &Request,
        expected: &Reply,
        got: &Reply,
        _tol: Tolerance,
    ) -> (bool, Option<String>) {
        if let Request::IsduRead { index, .. } = req {
            let own = self
                .suite
                .family()
                .parameters
                .iter()
                .find(|p| p.per_device && p.number == u32::from(*index));
            if let Some(p) = own {
                // A string of the device's own may be shorter than the reference's (3.1).
                let text = match (p.data_type, got) {
                    (DataType::String, Reply::Data(g)) => p
                        .length
                        .and_then(|n| usize::try_from(n).ok())
                        .is_none_or(|n| g.len() <= n),
                    _ => false,
                };
                if text && matches!(expected, Reply::Data(_)) {
                    return (
                        true,
                        Some(
                            "the device's own text (the manual gives an example): length"
                                .to_owned(),
                        ),
                    );
                }
                if let Some(note) = same_length(expected, got) {
                    return (true, Some(note));
                }
            }
        }
        self.error_type_match(expected, got)
    }

    /// A read of ISDU 65 or 67 (sub-index 0) answered with data: signed, most significant
    /// octet first (3.1).
    fn live(&self, req: &Request, got: &Reply) -> Option<(Live, i64)> {
        let Request::IsduRead {
            index, subindex: 0, ..
        } = req
        else {
            return None;
        };
        let (_, kind) = self.live.iter().find(|(i, _)| i == index)?;
        let Reply::Data(b) = got else {
            return None;
        };
        if b.is_empty() || b.len() > 8 {
            return None;
        }
        let first = i64::from(i8::from_ne_bytes([*b.first()?]));
        let value = b
            .iter()
            .skip(1)
            .fold(first, |a, x| (a << 8) | i64::from(*x));
        Some((*kind, value))
    }

    fn op(&self, action: &Step, out: &Output, _last: Option<&Input>, t: u64) -> Op<Output> {
        let env = |env| Op::Exchange(Request::Env { t, env });
        match action {
            Step::PdOut {
                format,
                control,
                target,
                speed,
                stamp,
            } => Op::Send {
                out: output(*format, *control, *target, *speed, *stamp),
                max: 1,
            },
            Step::Hold { cycles } => Op::Hold(*cycles),
            Step::Until { running, max } => Op::Until {
                running: *running,
                max: *max,
            },
            Step::Advance { us } => Op::Advance(*us),
            Step::IsduRead { index, subindex } => Op::Exchange(Request::IsduRead {
                t,
                index: *index,
                subindex: *subindex,
            }),
            Step::IsduPoll {
                index,
                subindex,
                max,
            } => Op::Poll {
                req: Request::IsduRead {
                    t,
                    index: *index,
                    subindex: *subindex,
                },
                max: *max,
            },
            Step::IsduWrite {
                index,
                subindex,
                data,
            } => Op::Exchange(Request::IsduWrite {
                t,
                index: *index,
                subindex: *subindex,
                data: data.clone(),
            }),
            Step::Env { env } => env_op(t, env),
            Step::Process {
                control,
                target,
                speed,
            } => Op::Send {
                out: changed(*out, *control, *target, *speed),
                max: 1,
            },
            Step::Stamp { code, stamp } => Op::Send {
                out: Output::TimeStamp {
                    control: TsCode(*code),
                    stamp: Stamp(*stamp),
                },
                max: 1,
            },
            Step::Keys { forward, reverse } => env(Env::Keys {
                forward: *forward,
                reverse: *reverse,
            }),
            Step::Link { event } => env(Env::Link(match event {
                LinkEvent::Connected => BusEvent::Connected,
                LinkEvent::Lost => BusEvent::Lost,
            })),
            Step::PowerCycle => env(Env::PowerCycle),
            Step::Leds => Op::Refuse(
                "an `leds` step reads the reference model's LEDs; a device shows them to the eye only"
                    .to_owned(),
            ),
        }
    }

    /// Every output step is one cycle.
    fn answered(&self, _action: &Step, _reference: &Input) -> bool {
        true
    }
}

/// The process-data speed requirement (4.6.4; speed 0: ISDU 142/145) where the device's
/// speed differs from the reference's in format 2.
fn speed_cited(out: &Output, dut: &Input, reference: &Input) -> Option<String> {
    let Output::SpeedControlTarget { target_speed, .. } = out else {
        return None;
    };
    (dut.rpm != reference.rpm).then(|| {
        if *target_speed == 0 {
            PD_SPEED_ZERO
        } else {
            PD_SPEED
        }
        .to_owned()
    })
}

/// `out` with the control word, target and target speed a `process` step gives (absent:
/// unchanged); a format-0 output becomes format 1 with the control word, or stays as it is.
fn changed(out: Output, control: Option<u16>, target: Option<i32>, speed: Option<i16>) -> Output {
    match out {
        Output::TimeStamp { .. } => match control {
            Some(control_word) => Output::ControlTarget {
                control_word,
                target: target.unwrap_or(0),
            },
            None => out,
        },
        Output::ControlTarget {
            control_word,
            target: t,
        } => Output::ControlTarget {
            control_word: control.unwrap_or(control_word),
            target: target.unwrap_or(t),
        },
        Output::SpeedControlTarget {
            target_speed,
            control_word,
            target: t,
        } => Output::SpeedControlTarget {
            target_speed: speed.unwrap_or(target_speed),
            control_word: control.unwrap_or(control_word),
            target: target.unwrap_or(t),
        },
    }
}

/// The process output of a `pd-out` step (manual 3.3.1).
pub fn output(format: u8, control: u16, target: i32, speed: i16, stamp: u16) -> Output {
    match format {
        0 => Output::TimeStamp {
            control: TsCode(u8::try_from(control).unwrap_or(u8::MAX)),
            stamp: Stamp(stamp),
        },
        1 => Output::ControlTarget {
            control_word: control,
            target,
        },
        _ => Output::SpeedControlTarget {
            target_speed: speed,
            control_word: control,
            target,
        },
    }
}
