//! Running a case of a cyclic family (PSD4xx, PSx3xx) over the cyclic-exchange protocol: the
//! device under test and a fresh reference drive get the same requests; every cycle's input
//! image is compared within the case's [`Tolerance`], every request between cycles by its
//! reply. A family supplies its images, its steps and its reply comparison through
//! [`CyclicFamily`].

use crate::case::{
    Answer, CaseInfo, CaseRun, Failure, Finding as CaseFinding, Outcome, Record, RequirementRef,
    Role,
};
use crate::cyclic::device::Device;
use crate::cyclic::{Env, LinkPeer, LocalPeer, Peer, PeerError, Reply, Request, Server, WireError};
use crate::dut::Dut;
use crate::link::{ExecLink, SerialLink, TcpLink};
use crate::suite::{Session, SetupError};
use drivespec_report::plot::{self, Sample};
use drivespec_spec::hex::to_hex_compact as hex;
use drivespec_spec::{Family, FamilyId, RuleAction};

/// Declared tolerances of a case (physics); everything else is exact.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Tolerance {
    /// A device sample may match a reference sample this many cycles earlier or later.
    pub cycles: u32,
    /// Actual position, in the family's position unit.
    pub position: i64,
    /// Speed, rpm.
    pub speed: i64,
    /// A motion case: judged by the properties of the run ([`CyclicSession::judge_motion`]),
    /// not cycle by cycle; `position` applies at standstill, `speed` to the speed limit.
    pub motion: bool,
}

/// How much later than the reference a device may make a change that a case ends before
/// (µs): above any start latency or braking tail a drive has (tens of ms), far below a run
/// that goes on where the reference stopped.
const REACTION_US: u64 = 100_000;

/// A live quantity an acyclic read reports, as the input image carries it too.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Live {
    /// Actual position.
    Position,
    /// Actual speed.
    Speed,
}

/// A live value read during a motion case, judged once the cycles after it are known.
struct LiveRead {
    /// Its evidence record.
    record: usize,
    /// Its step.
    step: usize,
    /// The number of cycles before the read.
    cycle: usize,
    /// What it reports.
    quantity: Live,
    /// The value read.
    value: i64,
    /// Whether it equals the reference's reply: the verdict when no device image follows the
    /// read (the case ends with it).
    as_reference: bool,
}

/// Whether both replies carry data of the same length: how a read of a device's own value
/// (spec `per_device`: serial number, version, a measurement) is judged.
pub(crate) fn same_length(expected: &Reply, got: &Reply) -> Option<String> {
    match (expected, got) {
        (Reply::Data(e), Reply::Data(g)) if e.len() == g.len() => {
            Some("the device's own value (the manual gives an example): type and length".to_owned())
        }
        _ => None,
    }
}

/// The evidence note of a live value read in a motion case.
const LIVE_NOTE: &str = "live value: within the device's own input images around the read";

/// How much faster than the reference's highest speed a device may move in a motion case, %:
/// the reference runs at the limit in force, a device's speed reading may round differently.
const SPEED_SLACK_PERCENT: i64 = 5;

/// Tolerance of the motion cases: judged by the properties of the run, positions within 20
/// units at standstill, speed within the reference's highest plus slack and 2 rpm.
pub const MOTION: Tolerance = Tolerance {
    cycles: 0,
    position: 20,
    speed: 2,
    motion: true,
};

/// A point of a motion case the manual leaves open (a silent point): the status bits and,
/// with `movement`, the direction of travel there are not judged; the case reports what the
/// device showed as a finding.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OpenPoint {
    /// The requirement the point belongs to.
    pub requirement: String,
    /// What the manual leaves open.
    pub text: String,
    /// The status bits not judged.
    pub bits: u16,
    /// Whether the direction of travel is not judged either.
    pub movement: bool,
}

impl OpenPoint {
    /// The point of a scenario's `open` setup: `bits` by number (0..15; others are ignored).
    pub(crate) fn of_scenario(
        requirement: &str,
        text: &str,
        bits: &[u16],
        movement: bool,
    ) -> OpenPoint {
        OpenPoint {
            requirement: requirement.to_owned(),
            text: text.to_owned(),
            bits: bits
                .iter()
                .filter_map(|b| 1u16.checked_shl(u32::from(*b)))
                .fold(0, |w, b| w | b),
            movement,
        }
    }
}

/// One cycle of a case run as a check of the device's own images sees it
/// ([`CyclicFamily::own_checks`]).
pub struct Seen<'c, I, O> {
    /// The step the cycle belongs to.
    pub step: usize,
    /// The output sent in the cycle.
    pub out: &'c O,
    /// The device's input image, when it answered.
    pub device: Option<&'c I>,
}

/// What a check judged from the device's own images found ([`CyclicFamily::own_checks`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OwnVerdict {
    /// The device broke `requirement` in cycle `cycle`: what was allowed there.
    Broken {
        /// The cycle (index into the run's cycles) that shows it.
        cycle: usize,
        /// The requirement broken.
        requirement: String,
        /// What the device showed, one line.
        what: String,
        /// What the requirement allowed there, one line.
        allowed: String,
    },
    /// The device took an outcome the manual allows where the check does not apply.
    Allowed(CaseFinding),
}

/// A step of a motion case through which the device must stand where it is, judged on its
/// own input images alone: every image of the step shows the running bit clear, speed 0 and
/// the position within the case's position tolerance of the step's first image.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Still {
    /// The step.
    pub step: usize,
    /// The requirement a movement in the step breaks.
    pub requirement: String,
    /// What standing still means there, in words (`no adjustment run`).
    pub what: String,
}

/// One step: who it is for, one line, what it does.
#[derive(Debug, Clone, PartialEq)]
pub struct StepDef<A> {
    /// Setup, check or cleanup.
    pub role: Role,
    /// One line.
    pub text: String,
    /// What to do.
    pub action: A,
}

/// What a step does, as the session runs it.
pub enum Op<O> {
    /// The output becomes this, then up to `max` cycles until the reference and the device
    /// have answered the step ([`CyclicFamily::answered`]).
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
    /// A step no device exchange plays (a direct write into the reference model, an
    /// environment text that is no injection): the case ends here with this reason.
    Refuse(String),
    /// A read repeated once a cycle (at that cycle's time) while the device's reply does not
    /// yet conform to the reference's, at most `max` cycles; judged by the last reply. A state
    /// the manual lets last a bounded time (PSx3xx 3.1: ISDU 193 reads ≠ 0 while a save runs,
    /// "saving can take up to 2000ms").
    Poll {
        /// The read.
        req: Request,
        /// Most cycles.
        max: u32,
    },
}

/// The `ENV` request at `t` for an environment change in its text form (`jam 1`).
pub(crate) fn env_request(t: u64, env: &str) -> Result<Request, WireError> {
    match Request::parse(&format!("ENV {t} {env}"))? {
        r @ Request::Env { .. } => Ok(r),
        _ => Err(WireError {
            line: env.to_owned(),
            what: String::from("not an environment change"),
        }),
    }
}

/// What an environment step in its text form does: its `ENV` request at `t`, or a refusal
/// naming the text.
pub(crate) fn env_op<O>(t: u64, env: &str) -> Op<O> {
    env_request(t, env).map_or_else(
        |e| Op::Refuse(format!("environment step {env:?}: {e}")),
        Op::Exchange,
    )
}

/// The requirements of status bit `bit`'s rules (spec bitfield `status`), each once: those
/// that make it `to` first (set rules for `Some(true)`, reset rules for `Some(false)`).
pub(crate) fn status_bit_rules(family: &Family, bit: u32, to: Option<bool>) -> Vec<String> {
    let Some(b) = family
        .bitfield("status")
        .and_then(|f| f.bits.iter().find(|x| x.bit == bit))
    else {
        return Vec::new();
    };
    let wanted = match to {
        Some(true) => Some(RuleAction::Set),
        Some(false) => Some(RuleAction::Reset),
        None => None,
    };
    let first = b
        .rules
        .iter()
        .filter(|r| Some(r.action) == wanted)
        .map(|r| r.requirement.clone())
        .collect();
    let rest: Vec<String> = b.rules.iter().map(|r| r.requirement.clone()).collect();
    merged(first, &rest)
}

/// `first`, then `rest`, each requirement once, in that order.
pub(crate) fn merged(first: Vec<String>, rest: &[String]) -> Vec<String> {
    let mut ids: Vec<String> = Vec::new();
    for id in first.into_iter().chain(rest.iter().cloned()) {
        if !ids.contains(&id) {
            ids.push(id);
        }
    }
    ids
}

/// `req` with its time set to `t` (requests without a time unchanged).
fn at_time(req: &Request, t: u64) -> Request {
    let mut req = req.clone();
    match &mut req {
        Request::Hello { .. } | Request::Reset => {}
        Request::Cycle { t: x, .. }
        | Request::Advance { t: x }
        | Request::Read { t: x, .. }
        | Request::Write { t: x, .. }
        | Request::IsduRead { t: x, .. }
        | Request::IsduWrite { t: x, .. }
        | Request::Env { t: x, .. } => *x = t,
    }
    req
}

/// What a cyclic family's session needs from the family: its reference, images, steps and
/// reply comparison.
/// `'s` is the lifetime of the reference server.
pub trait CyclicFamily<'s> {
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
    /// The part of the input image besides status, position and speed that is compared
    /// exactly, as the evidence names it (empty: none).
    const CHANNEL: &'static str;
    /// That part of an input image.
    type Channel: PartialEq + Clone;
    /// The channel of an input image.
    fn channel(input: &Self::Input) -> Self::Channel;
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
    /// Whether the parts compared exactly are equal (a device's own values, spec
    /// `per_device`, by type and length only).
    fn exact_equal(&self, device: &Self::Input, reference: &Self::Input) -> bool;
    /// The "Drive is running" status bit.
    fn running_bit(&self) -> u16;
    /// The requirements a differing cycle cites, the one the device broke first: those of
    /// what differs, as far as the images show it, and the case's (`case`, declared order).
    /// `out` is the output image both sides were sent.
    fn cited(
        &self,
        case: &[String],
        out: &Self::Output,
        dut: Option<&Self::Input>,
        reference: &Self::Input,
    ) -> Vec<String>;
    /// The requirements a failure of a motion case's judgement cites (`reqs`: what the
    /// judgement found, then the case's), the one the device broke first, where the device's
    /// image of the failing cycle differs from the reference's: by default [`Self::cited`].
    fn judged_cited(
        &self,
        reqs: &[String],
        out: &Self::Output,
        dut: Option<&Self::Input>,
        reference: &Self::Input,
    ) -> Vec<String> {
        self.cited(reqs, out, dut, reference)
    }
    /// The requirements a differing reply to `req` cites, the one the device broke first
    /// (what the reply shows), then the case's (`case`, declared order).
    fn reply_cited(
        &self,
        case: &[String],
        _req: &Request,
        _expected: &Reply,
        _got: &Reply,
    ) -> Vec<String> {
        case.to_vec()
    }
    /// Whether the device's reply to `req` conforms to the reference's, with a remark for the
    /// evidence when it conforms other than by equality.
    fn same_reply(
        &self,
        req: &Request,
        expected: &Reply,
        got: &Reply,
        tol: Tolerance,
    ) -> (bool, Option<String>);
    /// For a read of a live value in a motion case (actual position, speed): which quantity
    /// of [`CyclicFamily::motion`] the reply carries and its value. Such a read is judged
    /// against the device's own input images around it, not against the reference's run.
    fn live(&self, _req: &Request, _got: &Reply) -> Option<(Live, i64)> {
        None
    }
    /// What `action` does, given the current output, the reference's last input and the time.
    fn op(
        &self,
        action: &Self::Action,
        out: &Self::Output,
        last: Option<&Self::Input>,
        t: u64,
    ) -> Op<Self::Output>;
    /// Whether an input image answers `action` (ends an [`Op::Send`] once both sides have).
    fn answered(&self, action: &Self::Action, reference: &Self::Input) -> bool;
    /// The device's input of cycle `at` as it is judged against the reference's (`device` and
    /// `reference` hold every cycle's input, None where none came): a family may put the
    /// reference's value in place of a value the device read itself at the moment of a
    /// request where the manual bounds that value by the device's own data. By default the
    /// input as it came.
    fn judged(
        &self,
        device: &[Option<Self::Input>],
        _reference: &[Self::Input],
        at: usize,
    ) -> Option<Self::Input> {
        device.get(at).copied().flatten()
    }
    /// The other readings of the errata that bear on a case (`spec errata`), each with a
    /// reference server that follows it: a case the device fails against the adopted reading
    /// passes when it passes against one of them, reporting which. By default none.
    fn readings(&self, _info: &CaseInfo) -> Vec<(CaseFinding, Server<'s>)> {
        Vec::new()
    }
    /// The point of a motion case the manual leaves open, if any. By default none.
    fn open(_case: &Self::Case) -> Option<OpenPoint> {
        None
    }
    /// Checks of a motion case judged from the device's own images alone, not against the
    /// reference's: `reqs` are the case's requirements, `cycles` the run. By default none.
    fn own_checks(
        &self,
        _case: &Self::Case,
        _reqs: &[String],
        _cycles: &[Seen<'_, Self::Input, Self::Output>],
    ) -> Vec<OwnVerdict> {
        Vec::new()
    }
    /// The step of a motion case through which the device must stand still, if any. By
    /// default none.
    fn still(_case: &Self::Case) -> Option<Still> {
        None
    }
    /// Why a case does not apply to the device under test (an option it has or lacks), if
    /// it does not: the case is skipped with that reason. By default every case applies.
    fn not_applicable(_case: &Self::Case) -> Option<String> {
        None
    }
    /// The requirements bounding a run's speed change (acceleration, deceleration), which a
    /// motion case checks against the reference's steepest change per cycle
    /// ([`RAMP_SLACK_PERCENT`]). By default none: the ramps are not judged.
    fn ramp_requirements(&self) -> Option<[&'static str; 2]> {
        None
    }
    /// The requirement stating the sign of the speed in the input image, which a device
    /// breaks when its speed's sign differs from the reference's while its position moves
    /// the same way. By default none.
    fn speed_sign_requirement(&self) -> Option<&'static str> {
        None
    }
}

/// How much steeper than the reference's steepest speed change per cycle a device's may be,
/// %: the reference ramps at the acceleration and deceleration in force; a device's speed
/// samples round to whole rpm, and on real time two cycles may fall closer together or
/// further apart than the nominal cycle. The check catches a ramp that ignores the limit,
/// not one that differs from the reference's shape.
const RAMP_SLACK_PERCENT: i64 = 50;

/// The highest speed (rpm) an image taken `late_us` after its request may show: `limit`,
/// plus the speed-up of `ramp_per_cycle` rpm a cycle (and [`RAMP_SLACK_PERCENT`]) for every
/// cycle of `cycle_us` begun in the delay.
fn speed_allowed(limit: i64, ramp_per_cycle: i64, late_us: u64, cycle_us: u64) -> i64 {
    let cycles = late_us.div_ceil(cycle_us.max(1));
    let ramp = ramp_per_cycle
        .saturating_mul(100 + RAMP_SLACK_PERCENT)
        .saturating_div(100);
    limit.saturating_add(ramp.saturating_mul(i64::try_from(cycles).unwrap_or(i64::MAX)))
}

/// The steepest speed-up and slow-down per cycle (rpm) of a run's speeds (each with the
/// time of its request and the time it was taken), a sign change counted as slowing to 0
/// and speeding up from it.
fn steepest(
    speeds: impl Iterator<Item = Option<(i64, u64, u64)>>,
) -> (i64, i64, Option<usize>, Option<usize>) {
    let (mut up, mut down, mut up_at, mut down_at) = (0i64, 0i64, None, None);
    let mut last: Option<(i64, u64, u64)> = None;
    for (i, v) in speeds.enumerate() {
        if let (Some((a, t0, taken0)), Some((b, t1, taken1))) = (last, v) {
            let (slow, fast) = if a.signum() * b.signum() < 0 {
                (a.abs(), b.abs())
            } else {
                (
                    a.abs().saturating_sub(b.abs()).max(0),
                    b.abs().saturating_sub(a.abs()).max(0),
                )
            };
            // Images taken further apart than their requests (a transport on real time)
            // count per the requests' interval.
            let (nominal, real) = (t1.saturating_sub(t0), taken1.saturating_sub(taken0));
            let per = |x: i64| {
                if real > nominal && nominal > 0 {
                    let scaled = i128::from(x) * i128::from(nominal) / i128::from(real);
                    i64::try_from(scaled).unwrap_or(x)
                } else {
                    x
                }
            };
            let (slow, fast) = (per(slow), per(fast));
            if fast > up {
                (up, up_at) = (fast, Some(i));
            }
            if slow > down {
                (down, down_at) = (slow, Some(i));
            }
        }
        last = v;
    }
    (up, down, up_at, down_at)
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
        Dut::Profinet { .. } => return Err(profinet_is_psd4xx()),
    })
}

/// The setup error of `--dut profinet:` for a family without PROFINET.
pub(crate) fn profinet_is_psd4xx() -> SetupError {
    SetupError::Usage("--dut profinet:IFACE/NAME is for psd4xx (a PROFINET IO device)".to_owned())
}

/// A session of family `F` on one device under test.
pub struct CyclicSession<'a, F> {
    family: F,
    /// The device under test; its first transport failure of a case run is a crash or hang
    /// to the fuzzer.
    device: Device<'a>,
    /// Whether a run still going at a case's end is judged only up to where the device got
    /// (suite cases); a fuzz sequence cut at its failing step is judged whole.
    late_end: bool,
}

/// Whether one side has arrived where an [`Op::Until`] waits: it has shown "Drive is running"
/// since the step began and moved since, or shown it for [`Arrival::MIN_CYCLES`] cycles (a
/// run that first waits, PSx3xx 5.12: for its brake to open); or it has stood still (running
/// bit clear, speed 0) with an unchanged status word for [`Arrival::SETTLE_US`] and at least
/// [`Arrival::MIN_CYCLES`] cycles. Each side is waited for on its own, so a device that starts
/// later, brakes longer or confirms the position later than the reference is judged at its
/// own arrival, its first movement on the same side of the wait's end as the reference's.
struct Arrival {
    running: bool,
    seen: bool,
    /// Cycles since the running bit was first seen, and whether the side has moved since.
    under_way: (u32, bool),
    /// The status word the side stands still with, and for how many cycles.
    still: Option<(u16, u32)>,
    cycle_us: u64,
}

impl Arrival {
    /// How long a standstill lasts before a wait ends, µs: longer than a stop at the
    /// reversal of a reference loop and than a drive's check of its position before it
    /// reports the target reached.
    const SETTLE_US: u64 = 50_000;
    /// Fewest cycles of standstill that end a wait.
    const MIN_CYCLES: u32 = 3;

    fn new(running: bool, cycle_us: u64) -> Arrival {
        Arrival {
            running,
            seen: false,
            under_way: (0, false),
            still: None,
            cycle_us,
        }
    }

    fn see(&mut self, (_, speed, status): (i64, i64, u16), running_bit: u16) {
        let on = status & running_bit != 0;
        self.seen |= on;
        if self.seen {
            let (n, moved) = self.under_way;
            self.under_way = (n.saturating_add(1), moved || speed != 0);
        }
        self.still = match self.still {
            _ if on || speed != 0 => None,
            Some((word, n)) if word == status => Some((word, n.saturating_add(1))),
            _ => Some((status, 1)),
        };
    }

    fn done(&self) -> bool {
        if self.running {
            let (n, moved) = self.under_way;
            return self.seen && (moved || n >= Arrival::MIN_CYCLES);
        }
        self.still.is_some_and(|(_, n)| {
            n >= Arrival::MIN_CYCLES
                && u64::from(n).saturating_mul(self.cycle_us) >= Arrival::SETTLE_US
        })
    }
}

/// The status bit that says a run ended at its target (PSD4xx 3.6, PSx3xx 3.4 bit 0).
const REACHED: &str = "Target position reached";

/// Cycles at the reference's highest speed that make it the speed in force, which the device
/// must reach too.
const CRUISE_CYCLES: usize = 10;

/// A violation found by [`CyclicSession::judge_motion`].
struct Finding {
    /// The device's cycle.
    cycle: usize,
    /// Its step.
    step: usize,
    /// The reference's cycle to show beside it.
    reference: Option<usize>,
    /// What differs.
    what: String,
    /// The requirements the violation breaks, most specific first (cited before the case's).
    breaks: Vec<String>,
    /// Whether `breaks` leads even in a case that checks one requirement: the check found a
    /// change the other side does not make at all, or a ramp or sign the images show alone.
    own: bool,
    /// What was allowed, where a check of the device's own images says it (shown instead
    /// of the reference's image).
    allowed: Option<String>,
}

impl Finding {
    fn at(cycle: usize, step: usize, reference: Option<usize>, what: String) -> Finding {
        Finding {
            cycle,
            step,
            reference,
            what,
            breaks: Vec::new(),
            own: false,
            allowed: None,
        }
    }

    fn breaking(mut self, breaks: Vec<String>) -> Finding {
        self.breaks = breaks;
        self
    }

    fn leading(mut self, own: bool) -> Finding {
        self.own = own;
        self
    }
}

/// Cycles after a change of the speed's sign within which the position shows the way the
/// shaft turns: the first cycle of a run may not move it by a whole increment yet.
const TRAVEL_CYCLES: usize = 20;

/// Cycles whose sample a comparison of changes passes over, per side (by cycle index).
#[derive(Clone, Copy)]
struct Held<'h> {
    device: &'h dyn Fn(usize) -> bool,
    reference: &'h dyn Fn(usize) -> bool,
}

impl Held<'static> {
    const NONE: Held<'static> = Held {
        device: &|_| false,
        reference: &|_| false,
    };
}

/// Samples of a stop where a run reverses (the reference loop, 4.2.1): a drive may stand
/// for a moment there and show it in the running bit. The cycles that show `running` clear
/// with at most [`REVERSAL_SAMPLES`] samples to the nearest moving samples before and after,
/// which move in opposite directions; `motion` gives (speed, status) of a cycle's sample.
fn reversal_stops(
    len: usize,
    running: u16,
    motion: impl Fn(usize) -> Option<(i64, u16)>,
) -> Vec<bool> {
    let moving = |i: usize| {
        motion(i)
            .filter(|(v, st)| st & running != 0 && *v != 0)
            .map(|(v, _)| v.signum())
    };
    (0..len)
        .map(|j| {
            if motion(j).is_none_or(|(_, st)| st & running != 0) {
                return false;
            }
            let before = (1..=REVERSAL_SAMPLES).find_map(|k| j.checked_sub(k).and_then(moving));
            let after = (1..=REVERSAL_SAMPLES).find_map(|k| moving(j + k));
            matches!((before, after), (Some(a), Some(b)) if a == -b)
        })
        .collect()
}

/// Longest stop, in samples, at a reversal that [`reversal_stops`] passes over. A choice:
/// at the 10 ms cycle of the suites, two samples are a stop of up to 30 ms.
const REVERSAL_SAMPLES: usize = 2;

/// Where the changes of one observed quantity differ between the device and the reference.
struct Divergence<T> {
    /// The cycle where it shows.
    at: usize,
    /// The reference's cycle of the same change.
    theirs: Option<usize>,
    /// Which change (1-based).
    change: usize,
    /// The device's value after the change (None: no further change).
    device: Option<T>,
    /// The reference's value after the change.
    reference: Option<T>,
}

/// The changes of `value` over `segment` (cycles numbered from `from`, `before` the cycle
/// ahead of it) on the device and on the reference, values for which `skip` holds left out: the first change that differs in
/// value, or that the device makes in a step before the stimulus of the reference's (a
/// reaction may come later than the reference's, never before its stimulus).
fn first_difference<I, O, T: PartialEq + Clone>(
    before: Option<&Cycle<I, O>>,
    segment: &[Cycle<I, O>],
    from: usize,
    value: impl Fn(&I) -> T,
    skip: impl Fn(&T) -> bool,
    lead: Option<T>,
    held: Held<'_>,
) -> Option<Divergence<T>> {
    let changes = |start: Option<T>,
                   side: &mut dyn Iterator<Item = (usize, usize, &I)>,
                   held: &dyn Fn(usize) -> bool| {
        let mut out: Vec<(usize, usize, T)> = Vec::new();
        if let Some(v) = start.filter(|v| !skip(v)) {
            out.push((from, 0, v));
        }
        for (i, step, x) in side {
            if held(from + i) {
                continue;
            }
            let v = value(x);
            if !skip(&v) && out.last().is_none_or(|(_, _, last)| *last != v) {
                out.push((from + i, step, v));
            }
        }
        out
    };
    // Both sides start from what they showed before the segment; the first segment starts
    // from what the device showed first (the state both had before the first stimulus),
    // unless that is the `lead` value (a run) the reference only reaches later: then the
    // device had already reacted to the first stimulus when it answered (its image taken
    // after the output reached it), and both start from the reference's first.
    let first = segment
        .first()
        .and_then(|c| c.dut.as_ref().ok())
        .map(&value);
    let reference_first = segment.first().map(|c| value(&c.reference));
    let reacted = lead.is_some()
        && first == lead
        && first != reference_first
        && segment
            .iter()
            .any(|c| first.as_ref() == Some(&value(&c.reference)));
    let (d_start, r_start) = match before {
        Some(c) => (c.dut.as_ref().ok().map(&value), Some(value(&c.reference))),
        None if reacted => (reference_first.clone(), reference_first),
        None => (first.clone(), first),
    };
    let d = changes(
        d_start,
        &mut segment
            .iter()
            .enumerate()
            .filter_map(|(i, c)| c.dut.as_ref().ok().map(|d| (i, c.step, d))),
        held.device,
    );
    let r = changes(
        r_start,
        &mut segment
            .iter()
            .enumerate()
            .map(|(i, c)| (i, c.step, &c.reference)),
        held.reference,
    );
    // The step of the stimulus of a reference's change: that of the cycle before it at the
    // latest (the reference shows a reaction in the cycle after the output that caused it).
    let stimulus = |y: &(usize, usize, T)| {
        y.0.checked_sub(1)
            .and_then(|i| i.checked_sub(from))
            .and_then(|i| segment.get(i))
            .or(before)
            .map_or(y.1, |c| c.step)
            .min(y.1)
    };
    let k = (0..d.len().max(r.len())).find(|&k| match (d.get(k), r.get(k)) {
        (Some(x), Some(y)) => x.2 != y.2 || (lead.as_ref() == Some(&x.2) && x.1 < stimulus(y)),
        (None, None) => false,
        _ => true,
    })?;
    // Where the divergence shows: the later of the two changes (a missing change shows at
    // the other side's), or the device's change made too early.
    let at = match (d.get(k), r.get(k)) {
        (Some(x), Some(y)) if x.2 == y.2 => x.0,
        (Some(x), Some(y)) => x.0.max(y.0),
        (Some(x), None) => x.0,
        (None, Some(y)) => y.0,
        (None, None) => from,
    };
    Some(Divergence {
        at,
        theirs: r.get(k).map(|x| x.0),
        change: k + 1,
        device: d.get(k).map(|x| x.2.clone()),
        reference: r.get(k).map(|x| x.2.clone()),
    })
}

/// The first image of the device in the step of `still` that shows a run (the `running`
/// bit, a speed) or a position more than `slack` from the step's first image; `motion` gives
/// an image's position, speed and status word.
fn still_violation<I, O>(
    cycles: &[Seen<'_, I, O>],
    still: &Still,
    slack: i64,
    running: u16,
    motion: impl Fn(&I) -> (i64, i64, u16),
) -> Option<OwnVerdict> {
    let mut images = cycles
        .iter()
        .enumerate()
        .filter(|(_, c)| c.step == still.step)
        .filter_map(|(i, c)| c.device.map(|d| (i, motion(d))));
    let (_, (start, _, _)) = images.clone().next()?;
    let (i, (position, speed, status)) = images.find(|(_, (p, v, st))| {
        st & running != 0 || *v != 0 || p.saturating_sub(start).abs() > slack
    })?;
    Some(OwnVerdict::Broken {
        cycle: i,
        requirement: still.requirement.clone(),
        what: format!(
            "{}: in step {} the device shows position {position}, speed {speed}, the running bit {}",
            still.what,
            still.step,
            if status & running != 0 { "set" } else { "clear" }
        ),
        allowed: format!(
            "no run, speed 0 and the position within {} ± {slack} (where the step began)",
            start
        ),
    })
}

/// " in step N" for a cycle, empty for none.
fn step_of<I, O>(cycles: &[Cycle<I, O>], at: Option<usize>) -> String {
    at.and_then(|i| cycles.get(i))
        .map(|c| format!(" in step {}", c.step))
        .unwrap_or_default()
}

/// One cycle as both sides saw it.
struct Cycle<I, O> {
    step: usize,
    /// The output image both sides were sent.
    out: O,
    t: u64,
    /// When the device's image was taken (µs; `t` on virtual time).
    taken: u64,
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
    cycles: Vec<Cycle<I, O>>,
    evidence: Vec<Record>,
    failure: Option<Failure>,
    /// The cycle that shows the failure, when one does (marked on the plot).
    failed_cycle: Option<usize>,
    reqs: &'r [String],
    /// The cycle counts at which [`Op::Until`] waits ended: both sides had arrived.
    arrivals: Vec<usize>,
    /// The point the manual leaves open ([`CyclicFamily::open`]).
    open: Option<OpenPoint>,
    /// Live values read in a motion case.
    live: Vec<LiveRead>,
    /// What the family's checks of the device's own images found ([`CyclicFamily::own_checks`]).
    own: Vec<OwnVerdict>,
    /// The step the device must stand still through ([`CyclicFamily::still`]).
    still: Option<Still>,
    /// Why the case cannot be run on this device: an injection the reference takes and the
    /// device answers `UNSUPPORTED` (optional, crates/cyclic/README.md); the case is skipped.
    unsupported: Option<String>,
}

impl<'a, 's, F: CyclicFamily<'s>> CyclicSession<'a, F> {
    /// A session of `family` on `peer`.
    pub(crate) fn new(family: F, peer: Box<dyn Peer + 'a>) -> CyclicSession<'a, F> {
        let device = Device::new(peer, F::ID, family.model());
        CyclicSession {
            family,
            device,
            late_end: true,
        }
    }

    /// The session judging every run whole, also one that goes on at a case's end.
    pub fn judging_whole_runs(mut self) -> Self {
        self.late_end = false;
        self
    }

    /// Exchanges `HELLO`; an error names what the device side said.
    pub fn hello(&mut self) -> Result<String, String> {
        self.device.hello()
    }

    /// The first transport failure of the case run last, if any (taken).
    pub fn take_peer_error(&mut self) -> Option<PeerError> {
        self.device.take_error()
    }

    /// Whether the device takes the injection `env` ([`Device::takes`]).
    pub fn takes(&mut self, env: Env) -> bool {
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
                    out: run.out.clone(),
                    t: run.t,
                    taken: run.t,
                    reference,
                    dut: Err(e.to_string()),
                });
                return Err(e.to_string());
            }
        };
        run.cycles.push(Cycle {
            step,
            out: run.out.clone(),
            t: run.t,
            taken: self.device.taken_at().unwrap_or(run.t),
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
        let live = got
            .as_ref()
            .filter(|g| run.tol.motion && same_length(&expected, g).is_some())
            .and_then(|g| self.family.live(&req, g));
        if let (Request::Env { env, .. }, Some(Reply::Unsupported)) = (&req, &got) {
            if expected != Reply::Unsupported {
                run.unsupported = Some(format!(
                    "step {step} ({text}): the device under test cannot take the injection `{env}` (ENV answered UNSUPPORTED)"
                ));
                return false;
            }
        }
        let (ok, remark) = match (&got, live) {
            (Some(g), Some((quantity, value))) => {
                let as_reference = self.family.same_reply(&req, &expected, g, run.tol).0;
                run.live.push(LiveRead {
                    record: run.evidence.len(),
                    step,
                    cycle: run.cycles.len(),
                    quantity,
                    value,
                    as_reference,
                });
                (true, Some(LIVE_NOTE.to_owned()))
            }
            (Some(g), None) => self.family.same_reply(&req, &expected, g, run.tol),
            (None, _) => (false, None),
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
                requirements: self.refs(&match &got {
                    Some(g) => self.family.reply_cited(run.reqs, &req, &expected, g),
                    None => run.reqs.to_vec(),
                }),
            });
        }
        ok
    }

    /// Whether the device's reply to the read `req` conforms to the reference's now (a probe of
    /// [`Op::Poll`], not recorded; a transport failure ends the polling).
    fn conforms(&mut self, run: &mut Run<'_, 's, F::Input, F::Output>, req: &Request) -> bool {
        let expected = run.reference.handle(req.clone());
        match self.device.call(req) {
            Ok(got) => self.family.same_reply(req, &expected, &got, run.tol).0,
            Err(_) => true,
        }
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
                    // The master repeats the output until both sides have answered it (PSD4xx
                    // 3.8: "repeats this command cyclically until the drive has processed the
                    // command and sent a response").
                    run.out = out;
                    let (mut reference, mut device) = (false, false);
                    for _ in 0..max {
                        self.cycle(run, n)?;
                        if let Some(c) = run.cycles.last() {
                            reference |= self.family.answered(&s.action, &c.reference);
                            device |= c
                                .dut
                                .as_ref()
                                .is_ok_and(|d| self.family.answered(&s.action, d));
                        }
                        if reference && device {
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
                    let bit = self.family.running_bit();
                    let cycle_us = self.family.cycle_us();
                    let mut reference = Arrival::new(running, cycle_us);
                    let mut device = Arrival::new(running, cycle_us);
                    for _ in 0..max {
                        self.cycle(run, n)?;
                        if let Some(c) = run.cycles.last() {
                            reference.see(F::motion(&c.reference), bit);
                            if let Ok(d) = &c.dut {
                                device.see(F::motion(d), bit);
                            }
                        }
                        if reference.done() && device.done() {
                            run.arrivals.push(run.cycles.len());
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
                Op::Refuse(reason) => return Err(reason),
                Op::Poll { req, max } => {
                    for _ in 0..max {
                        if self.conforms(run, &at_time(&req, run.t)) {
                            break;
                        }
                        self.cycle(run, n)?;
                    }
                    if !self.exact(run, n, s.role, &s.text, at_time(&req, run.t)) {
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

    /// Every live value read in a motion case lies between the device's own input images of
    /// the cycles before and after the read, widened by the case's tolerance; a record that
    /// does not is marked and is the failure unless one came first.
    fn judge_live(&self, run: &mut Run<'_, 's, F::Input, F::Output>, tol: Tolerance) {
        for l in std::mem::take(&mut run.live) {
            let after = run.cycles.get(l.cycle).is_some_and(|c| c.dut.is_ok());
            if !after && l.as_reference {
                continue;
            }
            let around: Vec<i64> = [l.cycle.checked_sub(1), Some(l.cycle)]
                .into_iter()
                .flatten()
                .filter_map(|i| run.cycles.get(i))
                .filter_map(|c| c.dut.as_ref().ok())
                .map(|d| {
                    let (position, speed, _) = F::motion(d);
                    match l.quantity {
                        Live::Position => position,
                        Live::Speed => speed,
                    }
                })
                .collect();
            let slack = match l.quantity {
                Live::Position => tol.position,
                Live::Speed => tol.speed,
            };
            let (Some(lo), Some(hi)) = (around.iter().min(), around.iter().max()) else {
                continue;
            };
            let (lo, hi) = (lo.saturating_sub(slack), hi.saturating_add(slack));
            if (lo..=hi).contains(&l.value) {
                continue;
            }
            let allowed = format!("{lo}…{hi} (the device's own input images around the read)");
            if let Some(r) = run.evidence.get_mut(l.record) {
                r.ok = Some(false);
                r.note = Some(format!("{LIVE_NOTE}: {allowed}"));
            }
            if run.failure.is_none() {
                run.failed_cycle = Some(l.cycle);
                run.failure = Some(Failure {
                    step: Some(l.step),
                    message: format!(
                        "step {}: the live value read differs from the device's own process data",
                        l.step
                    ),
                    expected: allowed,
                    got: l.value.to_string(),
                    requirements: self.refs(run.reqs),
                });
            }
        }
    }

    /// Judges the cycles under `tol`; marks the records and sets the first failure.
    fn judge(&self, run: &mut Run<'_, 's, F::Input, F::Output>, tol: Tolerance) {
        let device: Vec<Option<F::Input>> = run
            .cycles
            .iter()
            .map(|c| c.dut.as_ref().ok().copied())
            .collect();
        let reference: Vec<F::Input> = run.cycles.iter().map(|c| c.reference).collect();
        for (i, c) in run.cycles.iter_mut().enumerate() {
            if let (Ok(d), Some(j)) = (&mut c.dut, self.family.judged(&device, &reference, i)) {
                *d = j;
            }
        }
        self.judge_live(run, tol);
        let bad_steps = if tol.motion {
            self.judge_motion(run, tol)
        } else {
            self.judge_cycles(run, tol)
        };
        let note = if !tol.motion {
            format!(
                "every cycle: {} exact; position ±{}, speed ±{}, time ±{} cycle(s)",
                F::EXACT,
                tol.position,
                tol.speed,
                tol.cycles
            )
        } else {
            format!(
                "motion: between waits, each status bit{}and the direction change as the reference's, a run never starts in an earlier step; speed within ±{} % of the reference's highest; where both have settled, status exact and position ±{}",
                if F::CHANNEL.is_empty() {
                    " ".to_owned()
                } else {
                    format!(", the {} ", F::CHANNEL)
                },
                SPEED_SLACK_PERCENT,
                tol.position
            )
        };
        let still = run.still.as_ref().filter(|_| tol.motion).map(|s| {
            (
                s.step,
                format!(
                    "{note}; {}: on the device's own images, no run, speed 0 and the position within ±{} of the step's first",
                    s.requirement, tol.position
                ),
            )
        });
        for r in &mut run.evidence {
            if r.ok.is_none() && r.role != Role::Cleanup {
                r.ok = Some(!bad_steps.contains(&r.step));
                r.note = Some(match &still {
                    Some((step, text)) if *step == r.step => text.clone(),
                    _ => note.clone(),
                });
            }
        }
    }

    /// Every cycle of the device matches a reference cycle at most `tol.cycles` earlier or
    /// later (exact parts equal, position and speed within the tolerance); the steps with a
    /// cycle that does not.
    fn judge_cycles(
        &self,
        run: &mut Run<'_, 's, F::Input, F::Output>,
        tol: Tolerance,
    ) -> Vec<usize> {
        let k = usize::try_from(tol.cycles).unwrap_or(0);
        let fits = |d: &F::Input, r: &F::Input| {
            let ((da, ds, _), (ra, rs, _)) = (F::motion(d), F::motion(r));
            self.family.exact_equal(d, r)
                && (da - ra).abs() <= tol.position
                && (ds - rs).abs() <= tol.speed
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
                let what = format!(
                    "the input image differs from the reference (tolerance ±{} cycle(s), position ±{}, speed ±{})",
                    tol.cycles, tol.position, tol.speed
                );
                run.failed_cycle = Some(i);
                let reqs = self
                    .family
                    .cited(run.reqs, &c.out, c.dut.as_ref().ok(), &c.reference);
                run.failure = Some(self.cycle_failure(&reqs, i, c, &c.reference, what));
            }
        }
        bad_steps
    }

    /// A motion case is judged by what the manuals fix about a run, not by its timing.
    /// Between two arrivals of [`Op::Until`] (where both sides are waited for), every status
    /// bit goes through the same changes as the reference's (the order of status events) and
    /// the direction of travel changes as the reference's (approach and reference loop); the
    /// speed stays within the reference's highest (the limits in force) and reaches it where
    /// the reference cruises at it, and where the family names ramp requirements no speed
    /// change per cycle is steeper than the reference's steepest plus [`RAMP_SLACK_PERCENT`];
    /// wherever both have settled, the exact parts agree and the positions are within
    /// `tol.position`. The steps with a violation.
    fn judge_motion(
        &self,
        run: &mut Run<'_, 's, F::Input, F::Output>,
        tol: Tolerance,
    ) -> Vec<usize> {
        let mut bad: Vec<Finding> = Vec::new();
        if let Some((i, c)) = run.cycles.iter().enumerate().find(|(_, c)| c.dut.is_err()) {
            bad.push(Finding::at(i, c.step, None, "no input image".to_owned()));
        }
        // The checks of the device's own images lead where they find something: they judge
        // the requirement itself, not a difference from the reference.
        for v in &run.own {
            if let OwnVerdict::Broken {
                cycle,
                requirement,
                what,
                allowed,
            } = v
            {
                let mut f = Finding::at(
                    *cycle,
                    run.cycles.get(*cycle).map_or(0, |c| c.step),
                    None,
                    what.clone(),
                )
                .breaking(vec![requirement.clone()])
                .leading(true);
                f.allowed = Some(allowed.clone());
                bad.push(f);
            }
        }
        let running = self.family.running_bit();
        let mut bounds = vec![0];
        bounds.extend(run.arrivals.iter().copied());
        bounds.push(run.cycles.len());
        // A case that ends while the device still moves, or while the reference does (a run
        // it began shortly before the end, which the device may begin later), is judged up to
        // where the device has got: in its last segment the device's changes must begin the
        // reference's, the rest may come after the end (a drive may react later than the
        // reference).
        let moves = |i: &F::Input| {
            let (_, speed, status) = F::motion(i);
            speed != 0 || status & running != 0
        };
        let moving_at_end = run
            .cycles
            .last()
            .is_some_and(|c| moves(&c.reference) || c.dut.as_ref().is_ok_and(&moves));
        let end = run.cycles.len();
        let motion = |c: &Cycle<F::Input, F::Output>, dut: bool| {
            let i = if dut {
                c.dut.as_ref().ok()?
            } else {
                &c.reference
            };
            let (_, speed, status) = F::motion(i);
            Some((speed, status))
        };
        let stops = [true, false].map(|dut| {
            reversal_stops(end, running, |i| {
                run.cycles.get(i).and_then(|c| motion(c, dut))
            })
        });
        let [device_stop, reference_stop] = [0, 1].map(|k| {
            let v = stops.get(k);
            move |i: usize| v.and_then(|v| v.get(i)).copied().unwrap_or(false)
        });
        let none = |_: usize| false;
        for w in bounds.windows(2) {
            let (from, to) = match w {
                [a, b] if a < b => (*a, *b),
                _ => continue,
            };
            let open = self.late_end && moving_at_end && to == end;
            // A change the device has not made yet is excused only when the reference made
            // it shortly before the end: a later reaction, not a change never made.
            let end_t = run.cycles.last().map_or(0, |c| c.t);
            let late = |unmade: bool, theirs: Option<usize>| {
                open && unmade
                    && theirs
                        .and_then(|t| run.cycles.get(t))
                        .is_some_and(|c| end_t.saturating_sub(c.t) <= REACTION_US)
            };
            let segment = run.cycles.get(from..to).unwrap_or(&[]);
            let before = from.checked_sub(1).and_then(|i| run.cycles.get(i));
            let open_bits = run.open.as_ref().map_or(0, |o| o.bits);
            // Whether the speed's sign is the same on both sides over the cycles up to `at`.
            let moves_alike = |at: usize| {
                run.cycles
                    .get(at.saturating_sub(TRAVEL_CYCLES)..=at)
                    .is_some_and(|cs| {
                        cs.iter().all(|c| {
                            c.dut.as_ref().is_ok_and(|d| {
                                F::motion(d).1.signum() == F::motion(&c.reference).1.signum()
                            })
                        })
                    })
            };
            for bit in (0..16u16).filter(|b| open_bits & (1 << b) == 0) {
                let mask = 1u16 << bit;
                let what = |v: Option<bool>| match v {
                    Some(true) => "set",
                    Some(false) => "clear",
                    None => "no further change",
                };
                if let Some(x) = first_difference(
                    before,
                    segment,
                    from,
                    |i| F::motion(i).2 & mask != 0,
                    |_| false,
                    (mask == running).then_some(true),
                    if mask == running {
                        Held {
                            device: &device_stop,
                            reference: &reference_stop,
                        }
                    } else {
                        Held {
                            device: &none,
                            reference: &none,
                        }
                    },
                )
                .filter(|x| !late(x.device.is_none(), x.theirs))
                {
                    bad.push(Finding::at(
                        x.at,
                        run.cycles.get(x.at).map_or(0, |c| c.step),
                        x.theirs,
                        format!(
                            "status bit {bit}, change {}: {} on the device{}, {} on the reference{}",
                            x.change,
                            what(x.device),
                            step_of(&run.cycles, Some(x.at)),
                            what(x.reference),
                            step_of(&run.cycles, x.theirs)
                        ),
                    )
                    .breaking(status_bit_rules(self.family.spec(), u32::from(bit), x.reference.or(x.device)))
                    // One side makes a change the other does not make at all while both
                    // move alike: the bit's own rule. Where the motion differs too, the bit
                    // follows it and the case's requirements lead.
                    .leading(
                        mask != running
                            && x.device.is_none() != x.reference.is_none()
                            && moves_alike(x.at),
                    ));
                }
            }
            let word = |v: Option<i64>| match v {
                Some(1) => "increasing",
                Some(_) => "decreasing",
                None => "no further movement",
            };
            let movement_open = run.open.as_ref().is_some_and(|o| o.movement);
            if let Some(x) = first_difference(
                before,
                segment,
                from,
                |i| F::motion(i).1.signum(),
                |v| *v == 0,
                None,
                Held::NONE,
            )
            .filter(|x| !(movement_open || late(x.device.is_none(), x.theirs)))
            {
                // The position moving the reference's way while the speed says otherwise:
                // the speed's sign is wrong, not the run.
                let travel = |dut: bool| {
                    let at = |i: usize| {
                        run.cycles.get(i).and_then(|c| {
                            if dut {
                                c.dut.as_ref().ok().map(|d| F::motion(d).0)
                            } else {
                                Some(F::motion(&c.reference).0)
                            }
                        })
                    };
                    let from = if dut { x.at } else { x.theirs.unwrap_or(x.at) };
                    let start = from.checked_sub(1).and_then(at);
                    (from..from.saturating_add(TRAVEL_CYCLES))
                        .find_map(|i| {
                            let d = at(i)?.saturating_sub(start?).signum();
                            (d != 0).then_some(d)
                        })
                        .unwrap_or(0)
                };
                let sign_only = x.device.is_some()
                    && x.reference.is_some()
                    && travel(true) != 0
                    && travel(true) == travel(false);
                let sign = self
                    .family
                    .speed_sign_requirement()
                    .filter(|_| sign_only)
                    .map(|r| vec![r.to_owned()])
                    .unwrap_or_default();
                bad.push(
                    Finding::at(
                        x.at,
                        run.cycles.get(x.at).map_or(0, |c| c.step),
                        x.theirs,
                        format!(
                            "movement {}: {} on the device{}, {} on the reference{}",
                            x.change,
                            word(x.device),
                            step_of(&run.cycles, Some(x.at)),
                            word(x.reference),
                            step_of(&run.cycles, x.theirs)
                        ),
                    )
                    .leading(!sign.is_empty())
                    .breaking(sign),
                );
            }
            if let Some(x) = first_difference(
                before,
                segment,
                from,
                F::channel,
                |_| false,
                None,
                Held::NONE,
            ) {
                bad.push(Finding::at(
                    x.at,
                    run.cycles.get(x.at).map_or(0, |c| c.step),
                    x.theirs,
                    format!(
                        "{}: change {} differs from the reference's{}",
                        F::CHANNEL,
                        x.change,
                        step_of(&run.cycles, Some(x.at))
                    ),
                ));
            }
        }
        // The ramps: no speed change per cycle steeper than the reference's plus slack (ahead
        // of the speed bound: a steep ramp explains a speed too high in the same cycle).
        if let Some([accel, decel]) = self.family.ramp_requirements() {
            let (up, down, _, _) = steepest(
                run.cycles
                    .iter()
                    .map(|c| Some((F::motion(&c.reference).1, c.t, c.t))),
            );
            let (dev_up, dev_down, up_at, down_at) = steepest(
                run.cycles
                    .iter()
                    .map(|c| c.dut.as_ref().ok().map(|d| (F::motion(d).1, c.t, c.taken))),
            );
            let bound = |r: i64| {
                r.saturating_mul(100 + RAMP_SLACK_PERCENT)
                    .saturating_div(100)
                    .saturating_add(2 * tol.speed)
            };
            for (what, req, theirs, mine, at) in [
                ("speeds up", accel, up, dev_up, up_at),
                ("slows down", decel, down, dev_down, down_at),
            ] {
                if let Some(i) = at.filter(|_| theirs > 0 && mine > bound(theirs)) {
                    bad.push(
                        Finding::at(
                            i,
                            run.cycles.get(i).map_or(0, |c| c.step),
                            None,
                            format!(
                                "the speed {what} by {mine} rpm in one cycle; at most {} rpm (the steepest in force, {theirs} rpm, plus {RAMP_SLACK_PERCENT} % and {} rpm)",
                                bound(theirs),
                                2 * tol.speed
                            ),
                        )
                        .breaking(vec![req.to_owned()])
                        .leading(true),
                    );
                }
            }
        }
        // The speed: never above the reference's highest, and as high where it cruises.
        let speeds: Vec<i64> = run
            .cycles
            .iter()
            .map(|c| F::motion(&c.reference).1.abs())
            .collect();
        let top = speeds.iter().copied().max().unwrap_or(0);
        let limit = top
            .saturating_mul(100 + SPEED_SLACK_PERCENT)
            .saturating_div(100)
            .saturating_add(tol.speed);
        let cruise = speeds.iter().filter(|v| **v == top).count();
        // Where the reference never cruised, the case ended before the speed in force was
        // reached: an image taken later than its request may show the speed further up the
        // ramp, by the steepest speed-up in force over the delay.
        let ramp_per_cycle = if cruise >= CRUISE_CYCLES {
            0
        } else {
            steepest(
                run.cycles
                    .iter()
                    .map(|c| Some((F::motion(&c.reference).1, c.t, c.t))),
            )
            .0
        };
        let cycle_us = self.family.cycle_us();
        let device_top = run
            .cycles
            .iter()
            .enumerate()
            .filter_map(|(i, c)| c.dut.as_ref().ok().map(|d| (i, F::motion(d).1.abs())))
            .max_by_key(|(_, v)| *v);
        let too_fast = run.cycles.iter().enumerate().find_map(|(i, c)| {
            let v = F::motion(c.dut.as_ref().ok()?).1.abs();
            let allowed =
                speed_allowed(limit, ramp_per_cycle, c.taken.saturating_sub(c.t), cycle_us);
            (v > allowed).then_some((i, v, allowed))
        });
        if let Some((i, v, allowed)) = too_fast {
            bad.push(Finding::at(
                i,
                run.cycles.get(i).map_or(0, |c| c.step),
                None,
                format!("speed {v} rpm is above the highest allowed, {allowed} rpm"),
            ));
        }
        let floor = top
            .saturating_mul(100 - SPEED_SLACK_PERCENT)
            .saturating_div(100)
            .saturating_sub(tol.speed);
        if top > 0 && cruise >= CRUISE_CYCLES && device_top.is_none_or(|(_, v)| v < floor) {
            let (i, v) = device_top.unwrap_or((0, 0));
            bad.push(Finding::at(
                i,
                run.cycles.get(i).map_or(0, |c| c.step),
                None,
                format!("the highest speed is {v} rpm; the speed in force is {top} rpm (at least {floor} rpm)"),
            ));
        }
        // Settled on both sides: exact parts equal, positions within the tolerance.
        let cycle_us = self.family.cycle_us();
        let bit = self.family.running_bit();
        let reached = self
            .family
            .spec()
            .bitfield("status")
            .and_then(|b| b.bits.iter().find(|x| x.name == REACHED))
            .and_then(|x| 1u16.checked_shl(x.bit))
            .unwrap_or(0);
        let (mut dev, mut refr) = (Arrival::new(false, cycle_us), Arrival::new(false, cycle_us));
        for (i, c) in run.cycles.iter().enumerate() {
            refr.see(F::motion(&c.reference), bit);
            let Ok(d) = &c.dut else {
                dev = Arrival::new(false, cycle_us);
                continue;
            };
            dev.see(F::motion(d), bit);
            if !(dev.done() && refr.done()) {
                continue;
            }
            // Positions agree where the reference has reached its target; where a run ended
            // otherwise (an obstruction, a lost connection), where it stops depends on timing.
            let (dp, rp) = (F::motion(d).0, F::motion(&c.reference).0);
            let at_target = F::motion(&c.reference).2 & reached != 0;
            let open_bits = run.open.as_ref().map_or(0, |o| o.bits);
            let same_status = F::motion(d).2 & !open_bits == F::motion(&c.reference).2 & !open_bits;
            if !same_status || (at_target && (dp - rp).abs() > tol.position) {
                bad.push(Finding::at(
                    i,
                    c.step,
                    Some(i),
                    format!(
                        "both settled: the status word differs, or the positions at the target are more than {} apart",
                        tol.position
                    ),
                ));
                break;
            }
        }
        bad.sort_by_key(|b| b.cycle);
        let mut bad_steps: Vec<usize> = bad.iter().map(|b| b.step).collect();
        bad_steps.sort_unstable();
        bad_steps.dedup();
        if run.failure.is_none() {
            if let Some(f) = bad.first() {
                if let Some(c) = run.cycles.get(f.cycle) {
                    let reference = f
                        .reference
                        .and_then(|t| run.cycles.get(t))
                        .map_or(&c.reference, |r| &r.reference);
                    // A case that checks one requirement names it first (what it finds
                    // breaks that requirement; the status bit's own rules follow), unless
                    // the finding is the check's own (`Finding::own`).
                    let mut reqs: Vec<String> = match run.reqs {
                        [only] if !f.own => vec![only.clone()],
                        _ => Vec::new(),
                    };
                    for r in f.breaks.iter().chain(run.reqs) {
                        if !reqs.contains(r) {
                            reqs.push(r.clone());
                        }
                    }
                    run.failed_cycle = Some(f.cycle);
                    let reqs =
                        self.family
                            .judged_cited(&reqs, &c.out, c.dut.as_ref().ok(), reference);
                    let mut failure =
                        self.cycle_failure(&reqs, f.cycle, c, reference, f.what.clone());
                    if let Some(allowed) = &f.allowed {
                        failure.expected.clone_from(allowed);
                    }
                    run.failure = Some(failure);
                }
            }
        }
        bad_steps
    }

    /// The requirements a judged run checked: the case's, and in a motion case the ramp
    /// requirements where the reference moved and the rules of every status bit whose changes
    /// were compared (it changed on the reference).
    fn checked(&self, run: &Run<'_, 's, F::Input, F::Output>) -> Vec<String> {
        if !run.evidence.iter().any(|r| r.ok.is_some()) {
            return Vec::new();
        }
        let mut ids = run.reqs.to_vec();
        let moved = run.cycles.iter().any(|c| F::motion(&c.reference).1 != 0);
        if let Some(ramps) = self
            .family
            .ramp_requirements()
            .filter(|_| run.tol.motion && moved)
        {
            for id in ramps {
                if !ids.iter().any(|x| x == id) {
                    ids.push(id.to_owned());
                }
            }
        }
        if run.tol.motion {
            let words: Vec<u16> = run
                .cycles
                .iter()
                .map(|c| F::motion(&c.reference).2)
                .collect();
            let changed = words.windows(2).fold(0u16, |acc, w| match w {
                [a, b] => acc | (a ^ b),
                _ => acc,
            });
            for bit in (0..16u16).filter(|b| changed & (1 << b) != 0) {
                for id in status_bit_rules(self.family.spec(), u32::from(bit), None) {
                    if !ids.contains(&id) {
                        ids.push(id);
                    }
                }
            }
        }
        ids
    }

    /// The failure of cycle `i` against `reference`, saying `what`, citing `reqs`.
    fn cycle_failure(
        &self,
        reqs: &[String],
        i: usize,
        c: &Cycle<F::Input, F::Output>,
        reference: &F::Input,
        what: String,
    ) -> Failure {
        let got = match &c.dut {
            Ok(d) => self.family.describe(d),
            Err(e) => e.clone(),
        };
        Failure {
            step: Some(c.step),
            message: format!(
                "cycle {} at {} ms (step {}): {what}",
                i + 1,
                c.t / 1000,
                c.step
            ),
            expected: self.family.describe(reference),
            got,
            requirements: self.refs(reqs),
        }
    }

    /// Runs one case (a generated one, or a fuzz sequence) against the device and a fresh
    /// reference.
    pub fn run_case(&mut self, info: &CaseInfo, case: &F::Case) -> CaseRun {
        self.run_against(info, case, self.family.server())
    }

    /// Runs a suite case as [`CyclicSession::run_case`]; a failed case again against each
    /// other reading of the errata that bear on it ([`CyclicFamily::readings`]): it passes
    /// with the reading it follows as a finding.
    fn run_suite_case(&mut self, info: &CaseInfo, case: &F::Case) -> CaseRun {
        let first = self.run_case(info, case);
        if !first.outcome.failed() {
            return first;
        }
        for (finding, server) in self.family.readings(info) {
            let mut again = self.run_against(info, case, server);
            if !again.outcome.failed() {
                again.findings.push(finding);
                return again;
            }
        }
        first
    }

    /// Runs one case against the device and the reference `server`.
    fn run_against(&mut self, info: &CaseInfo, case: &F::Case, server: Server<'s>) -> CaseRun {
        let (steps, tol) = (F::steps(case), F::tolerance(case));
        self.device.clear_error();
        let mut run = Run {
            reference: server,
            tol,
            out: self.family.start(case),
            t: 0,
            step: 0,
            cycles: Vec::new(),
            evidence: Vec::new(),
            failure: None,
            failed_cycle: None,
            reqs: &info.requirements,
            arrivals: Vec::new(),
            open: F::open(case),
            live: Vec::new(),
            own: Vec::new(),
            still: F::still(case),
            unsupported: None,
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
                findings: Vec::new(),
                checked: Vec::new(),
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
        if tol.motion {
            let seen: Vec<Seen<'_, F::Input, F::Output>> = run
                .cycles
                .iter()
                .map(|c| Seen {
                    step: c.step,
                    out: &c.out,
                    device: c.dut.as_ref().ok(),
                })
                .collect();
            run.own = self.family.own_checks(case, &info.requirements, &seen);
            if let Some(still) = &run.still {
                run.own.extend(still_violation(
                    &seen,
                    still,
                    tol.position,
                    self.family.running_bit(),
                    F::motion,
                ));
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
                note: Some(plot::encode(&samples, run.failed_cycle)),
            });
        }
        // An open point is reported with the status bits the device ended with.
        // So is an outcome the manual allows that a check of the device's own images found.
        let allowed: Vec<CaseFinding> = run
            .own
            .iter()
            .filter_map(|v| match v {
                OwnVerdict::Allowed(f) if run.failure.is_none() => Some(f.clone()),
                _ => None,
            })
            .collect();
        let mut findings = match (&run.open, &run.failure) {
            (Some(o), None) => {
                let last = run.cycles.iter().rev().find_map(|c| c.dut.as_ref().ok());
                let bits = last.map_or(0, |d| F::motion(d).2 & o.bits);
                vec![CaseFinding::Open {
                    requirement: o.requirement.clone(),
                    text: format!(
                        "{}; the device ended with the open status bits at {bits:#06x}",
                        o.text
                    ),
                }]
            }
            _ => Vec::new(),
        };
        findings.extend(allowed);
        CaseRun {
            findings,
            checked: self.checked(&run),
            outcome: match (run.failure, run.unsupported) {
                (Some(f), _) => Outcome::Fail(f),
                (None, Some(reason)) => Outcome::Skip { reason },
                (None, None) => Outcome::Pass,
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
                findings: Vec::new(),
                checked: Vec::new(),
                outcome: Outcome::Skip {
                    reason: format!("no case {index}"),
                },
                evidence: Vec::new(),
                elapsed_us: 0,
            };
        };
        if let Some(reason) = F::not_applicable(case) {
            return CaseRun {
                findings: Vec::new(),
                checked: Vec::new(),
                outcome: Outcome::Skip { reason },
                evidence: Vec::new(),
                elapsed_us: 0,
            };
        }
        // The case borrows the family; run a copy of it.
        let (info, case) = (info.clone(), case.clone());
        self.run_suite_case(&info, &case)
    }
}

#[cfg(test)]
mod tests {
    use super::{reversal_stops, speed_allowed, steepest};

    #[test]
    fn an_image_taken_late_may_show_the_speed_further_up_the_ramp() {
        // On time: the limit itself.
        assert_eq!(speed_allowed(54, 4, 0, 10_000), 54);
        // 1 µs to a whole cycle late: one cycle's speed-up with its slack.
        assert_eq!(speed_allowed(54, 4, 1, 10_000), 60);
        assert_eq!(speed_allowed(54, 4, 10_000, 10_000), 60);
        // Two cycles begun in the delay.
        assert_eq!(speed_allowed(54, 4, 10_001, 10_000), 66);
        // A cruising reference (no ramp in force) allows nothing more, however late.
        assert_eq!(speed_allowed(54, 0, 1_000_000, 10_000), 54);
    }

    #[test]
    fn steepest_counts_a_change_per_the_requests_interval_when_the_images_lie_further_apart() {
        // 10 ms requests; the second image was taken 20 ms after the first.
        let late = [Some((0, 0, 0)), Some((20, 10_000, 20_000))];
        assert_eq!(steepest(late.into_iter()).0, 10);
        // Taken on time (virtual time): the change counts whole.
        let on_time = [Some((0, 0, 0)), Some((20, 10_000, 10_000))];
        assert_eq!(steepest(on_time.into_iter()).0, 20);
        // Taken closer together than requested: never counted steeper.
        let early = [Some((0, 0, 0)), Some((20, 10_000, 5_000))];
        assert_eq!(steepest(early.into_iter()).0, 20);
    }

    #[test]
    fn a_stop_near_moving_samples_of_opposite_directions_is_a_reversal_and_nothing_else_is() {
        const RUNNING: u16 = 0x0040;
        let samples = |s: &[(i64, u16)]| {
            let s = s.to_vec();
            reversal_stops(s.len(), RUNNING, move |i| s.get(i).copied())
        };
        // Down, a one-sample stop, up: the stop is a reversal.
        assert_eq!(
            samples(&[(-10, RUNNING), (0, 0), (10, RUNNING)]),
            [false, true, false]
        );
        // Down, a stop, down again: a stop in the run, not a reversal.
        assert_eq!(
            samples(&[(-10, RUNNING), (0, 0), (-10, RUNNING)]),
            [false, false, false]
        );
        // A stop too far from moving samples on both sides.
        assert_eq!(
            samples(&[
                (-10, RUNNING),
                (0, 0),
                (0, 0),
                (0, 0),
                (0, 0),
                (0, 0),
                (10, RUNNING)
            ]),
            [false; 7]
        );
    }
}
