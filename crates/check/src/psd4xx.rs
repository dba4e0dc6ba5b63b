//! PSD4xx checks on one drive's traffic (bus description 3.2.2, 3.5–3.8): the PKW
//! handshake and its answers, control/status relations, values inside the model's ranges,
//! and acyclic records. The PROFINET checker ([`crate::profinet`]) finds the drive's images
//! in the cyclic frames and feeds them here in capture order.
//!
//! Relations between the controller's output and the drive's input allow for the drive's
//! processing time: a relation must hold within [`PsdOptions::lag_cycles`] input images (the
//! toggle-bit echo, the aborted bit after a release withdrawal, the running bit vs the
//! speed), and a PKW command must be answered within [`PsdOptions::pkw_cycles`].
//!
//! The reference model (`drivespec_psd4xx::model::Drive`) is the oracle for parameter writes:
//! it is seeded with the values the capture shows (PKW and record reads), and every write the
//! drive accepted or refused is replayed on it to see whether the drive should have refused
//! it (unknown parameter, read-only, out of range). Values the capture established are
//! expected back on later reads, except for `live` parameters. Memory is bounded by the
//! parameter table. Nothing here panics.

use crate::report::{Evidence, Recorder, Where};
use crate::timeline::{Sample, Timeline};
use drivespec_psd4xx::model::Drive;
use drivespec_psd4xx::pkw::PkwRules;
use drivespec_psd4xx::{
    CommandCode, ErrorCode, Input, Output, PkwRequest, PkwResponse, RecordShape, Rules, Verdict,
    Width,
};
use drivespec_spec::hex::to_hex;
use drivespec_spec::psd4xx::{PkwOp, PkwValue};
use drivespec_spec::{DeviceModel, Family};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Requirements checked on every located PSD4xx (bus description 3.2.2, 3.5–3.8).
pub const CHECKED: &[&str] = &[
    "PSD-PKW-002",
    "PSD-PKW-003",
    "PSD-PKW-006",
    "PSD-PKW-010",
    "PSD-PKW-012",
    "PSD-PKW-013",
    "PSD-PKW-014",
    "PSD-PKW-015",
    "PSD-PKW-016",
    "PSD-PKW-017",
    "PSD-PKW-018",
    "PSD-PKW-019",
    "PSD-PKW-021",
    "PSD-PKW-022",
    "PSD-PKW-023",
    "PSD-PKW-024",
    "PSD-PKW-025",
    "PSD-PKW-026",
    "PSD-PKW-027",
    "PSD-PKW-028",
    "PSD-PKW-030",
    "PSD-PKW-034",
    "PSD-PKW-038",
    "PSD-CTL-13-001",
    "PSD-CTL-3-001",
    "PSD-CTL-5-001",
    "PSD-CTL-7-001",
    "PSD-CTL-14-001",
    "PSD-STS-0-PRIO",
    "PSD-STS-5-SET-1",
    "PSD-STS-6-SET-1",
    "PSD-STS-6-RESET-1",
    "PSD-STS-12-SET-1",
    "PSD-STS-14-RESET-1",
    "PSD-STS-15-RESET-1",
    "PSD-PAR-44-001",
    "PSD-PAR-RANGE-001",
    "PSD-REC-006",
    "PSD-REC-007",
    "PSD-REC-008",
    "PSD-REC-009",
    "PSD-VEL-001",
    "PSD-VEL-002",
];

/// Options of the PSD4xx checks.
#[derive(Debug, Clone)]
pub struct PsdOptions {
    /// Device model (`PSD426`, matched forgivingly): per-model ranges and the oracle.
    pub model: Option<String>,
    /// Input images within which a relation between output and input must hold.
    pub lag_cycles: u64,
    /// Input images within which a PKW command must be answered.
    pub pkw_cycles: u64,
    /// Percent by which a speed may exceed the fastest the model allows before it is a
    /// violation (PSD-VEL-001/002): a measured speed overshoots a little.
    pub speed_slack_percent: u64,
    /// Time (µs) added to the interval between two input images when the position change
    /// between them is judged: capture time stamps jitter, and frames bunch after a delay.
    pub jump_slack_us: u64,
}

impl Default for PsdOptions {
    fn default() -> PsdOptions {
        PsdOptions {
            model: None,
            lag_cycles: 20,
            pkw_cycles: 2000,
            speed_slack_percent: 10,
            jump_slack_us: 4000,
        }
    }
}

/// Status and control bits used by the relations (bus description 3.6, 3.7).
mod bit {
    pub const TARGET_REACHED: u16 = 1 << 0;
    pub const TOGGLE_ECHO: u16 = 1 << 2;
    pub const ABORTED: u16 = 1 << 5;
    pub const RUNNING: u16 = 1 << 6;
    pub const OVERLOAD: u16 = 1 << 10;
    pub const BAD_TARGET: u16 = 1 << 12;
    pub const UPPER_LIMIT: u16 = 1 << 14;
    pub const LOWER_LIMIT: u16 = 1 << 15;
    pub const MANUAL_UP: u16 = 1 << 0;
    pub const MANUAL_DOWN: u16 = 1 << 1;
    pub const TRANSFER: u16 = 1 << 2;
    pub const RELEASE: u16 = 1 << 4;
    pub const TOGGLE: u16 = 1 << 13;
}

/// Parameter numbers the relations use (bus description 3.3).
mod par {
    pub const ACTUAL: u16 = 3;
    pub const NUMERATOR: u16 = 38;
    pub const DENOMINATOR: u16 = 39;
    pub const UPPER_LIMIT: u16 = 42;
    pub const LOWER_LIMIT: u16 = 43;
    pub const WINDOW: u16 = 44;
    pub const POSITIONING_SPEED: u16 = 53;
    pub const MANUAL_SPEED: u16 = 56;
    pub const COMMAND: u16 = 96;

    /// Whether an accepted write of `pnu` may change the actual position at once (4.7:
    /// par 3 references it, par 37–41 recalculate it, par 96 restores or resets).
    pub fn moves_actual(pnu: u16) -> bool {
        matches!(pnu, ACTUAL | 37..=41 | COMMAND)
    }
}

/// A relation that has failed for some input images.
#[derive(Debug, Clone, Default)]
struct Streak {
    /// Input images seen, where and the image bytes when it started failing.
    since: Option<(u64, Where, Vec<u8>)>,
    reported: bool,
}

/// Where a condition started that held too long: the violation is reported there.
#[derive(Debug, Clone)]
struct Started {
    at: Where,
    bytes: Vec<u8>,
}

/// Evidence of a condition that started at `start` and still held at `at`.
fn held(start: &Started, at: Where) -> Evidence {
    Evidence::bytes(&start.bytes).with("still_at", at.to_string())
}

impl Streak {
    /// Updates the streak with the image `bytes` at `at`; gives where the streak started
    /// when it just exceeded `bound` images.
    fn update(
        &mut self,
        failing: bool,
        n: u64,
        at: Where,
        bytes: &[u8],
        bound: u64,
    ) -> Option<Started> {
        if !failing {
            *self = Streak::default();
            return None;
        }
        let (start, w, b) = self.since.get_or_insert_with(|| (n, at, bytes.to_vec()));
        if !self.reported && n.saturating_sub(*start) >= bound {
            self.reported = true;
            return Some(Started {
                at: *w,
                bytes: b.clone(),
            });
        }
        None
    }
}

/// The PKW command in force and what became of it.
#[derive(Debug, Clone, Copy)]
struct Command {
    req: PkwRequest,
    at: Where,
    /// Input images seen when it was first sent.
    since: u64,
    answer: Option<PkwResponse>,
    reported: bool,
}

/// A value the capture established for a parameter.
#[derive(Debug, Clone, Copy)]
struct Known {
    value: i64,
    at: Where,
}

/// One PSD4xx in a capture (see the module docs).
pub struct PsdDrive<'s> {
    label: String,
    family: &'s Family,
    rules: Arc<Rules>,
    model: Option<&'s DeviceModel>,
    oracle: Option<Drive>,
    options: PsdOptions,
    out: Option<Output>,
    inp: Option<Input>,
    inputs: u64,
    command: Option<Command>,
    last_pkw_out: Option<PkwRequest>,
    known: BTreeMap<u16, Known>,
    target: Option<(i32, u64)>,
    toggle: Streak,
    run_without_speed: Streak,
    speed_without_run: Streak,
    upper: Streak,
    lower: Streak,
    window_state: bool,
    /// A transferred target beyond the limits, waiting for status bit 12: (image count then,
    /// where, target, the limit it exceeds).
    bad_target: Option<(u64, Started, i32, i64)>,
    /// Checks already reported as undecidable on this drive (each once).
    undecided: Vec<&'static str>,
    prio_state: bool,
    /// The release withdrawn during a positioning run: (input images then, where).
    abort_pending: Option<(u64, Started)>,
    spm_state: bool,
    records: BTreeMap<u16, Vec<u8>>,
    /// The fastest any run of this drive may be (rpm): the largest par 53 or 56 of its
    /// model, of every model when the model is unknown (3.4).
    max_rpm: Option<i64>,
    /// The previous input image's actual position and capture time.
    last_actual: Option<(i32, u64)>,
    /// A speed above the limit is shown (reported once per stretch).
    too_fast: bool,
    /// Input images up to which a change of the actual position is excused: a write that
    /// moves it (par 3, 37–41, 96) was just accepted.
    excused_until: u64,
    timeline: Timeline,
    /// The oracle's clock: (capture time of the latest event, oracle time then).
    clock: Option<(u64, u64)>,
}

/// The longest pause between two events the oracle lives through (µs): a longer one (a
/// capture paused, or a crafted time stamp) counts as this long. The oracle judges parameter
/// writes, which do not depend on how long the drive stood, and it simulates every
/// millisecond it is moved on, so the work per event stays bounded.
const MAX_GAP_US: u64 = 1_000_000;

fn command_requirement(rules: &PkwRules, ak: CommandCode) -> &'static str {
    let Some(info) = rules.command_info(ak) else {
        return "PSD-PKW-019";
    };
    match (info.op, info.array, info.value) {
        (PkwOp::None, _, _) => "PSD-PKW-006",
        (PkwOp::Read, false, _) => "PSD-PKW-012",
        (PkwOp::Read, true, _) => "PSD-PKW-015",
        (PkwOp::Write, false, Some(PkwValue::Dword)) => "PSD-PKW-014",
        (PkwOp::Write, false, _) => "PSD-PKW-013",
        (PkwOp::Write, true, Some(PkwValue::ArrayDword | PkwValue::Dword)) => "PSD-PKW-017",
        (PkwOp::Write, true, _) => "PSD-PKW-016",
        (PkwOp::Count, _, _) => "PSD-PKW-018",
    }
}

impl<'s> PsdDrive<'s> {
    /// A drive labelled `label` (the subject of its violations).
    pub fn new(
        label: &str,
        family: &'s Family,
        rules: Arc<Rules>,
        model: Option<&'s DeviceModel>,
        oracle: Option<Drive>,
        options: PsdOptions,
    ) -> PsdDrive<'s> {
        let names = (0..16u32)
            .map(|b| {
                rules
                    .status_bits()
                    .bit(b)
                    .map_or_else(|| format!("bit {b}"), |x| x.name.clone())
            })
            .collect();
        let models: Vec<&DeviceModel> = match model {
            Some(m) => vec![m],
            None => family.models.iter().collect(),
        };
        let max_rpm = [par::POSITIONING_SPEED, par::MANUAL_SPEED]
            .iter()
            .filter_map(|n| rules.parameter(u32::from(*n)))
            .flat_map(|p| {
                models
                    .iter()
                    .filter_map(|m| family.resolve(p, Some(m)).range.and_then(|r| r.max()))
            })
            .max();
        PsdDrive {
            label: label.to_owned(),
            family,
            rules,
            model,
            oracle,
            options,
            out: None,
            inp: None,
            inputs: 0,
            command: None,
            last_pkw_out: None,
            known: BTreeMap::new(),
            target: None,
            toggle: Streak::default(),
            run_without_speed: Streak::default(),
            speed_without_run: Streak::default(),
            upper: Streak::default(),
            lower: Streak::default(),
            window_state: false,
            bad_target: None,
            undecided: Vec::new(),
            prio_state: false,
            abort_pending: None,
            spm_state: false,
            records: BTreeMap::new(),
            max_rpm,
            last_actual: None,
            too_fast: false,
            excused_until: 0,
            timeline: Timeline::new(label, names),
            clock: None,
        }
    }

    /// The drive's label.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// The drive's timeline (for the HTML report).
    pub fn into_timeline(self) -> Timeline {
        self.timeline
    }

    /// Records a violation of `id`; the message and evidence are made only when the recorder
    /// lists it (a broken stream violates on every image).
    fn violation(
        &mut self,
        rec: &mut Recorder,
        id: &str,
        at: Where,
        detail: impl FnOnce() -> (String, Evidence),
    ) {
        if let Some(t) = at.time {
            self.timeline.mark(t, id);
        }
        rec.violation_with(id, &self.label, at, detail);
    }

    /// The oracle's time for a capture time: µs since the drive's first event (the model
    /// simulates every tick it is advanced, so it must not start at 1970), with pauses longer
    /// than [`MAX_GAP_US`] shortened to it.
    fn model_time(&mut self, at: Where) -> Option<u64> {
        let t = at.time?;
        let (last, now) = self.clock.unwrap_or((t, 0));
        let now = now.saturating_add(t.saturating_sub(last).min(MAX_GAP_US));
        self.clock = Some((t.max(last), now));
        Some(now)
    }

    fn pkw(&self) -> &PkwRules {
        self.rules.pkw()
    }

    // ------------------------------------------------------------------ output images

    /// An output image (14 bytes, bus description 3.5.1) sent by the controller.
    pub fn output(&mut self, rec: &mut Recorder, at: Where, bytes: &[u8]) {
        self.model_time(at);
        let Ok(out) = Output::parse(&self.rules, bytes) else {
            return;
        };
        let prev = self.out;
        let prev_control = prev.map(|o| o.control);
        if prev_control != Some(out.control) {
            self.control_changed(rec, at, bytes, prev_control, out.control);
        }
        let transfer = out.control & bit::TRANSFER != 0;
        let was = prev.filter(|p| p.control & bit::TRANSFER != 0);
        if transfer && was.is_none_or(|p| p.target != out.target) {
            self.target = Some((out.target, self.inputs));
            self.transferred(rec, at, bytes, out.target);
        }
        if self.last_pkw_out != Some(out.pkw) {
            self.pkw_command(rec, at, bytes, out.pkw);
            self.last_pkw_out = Some(out.pkw);
        }
        self.out = Some(out);
    }

    fn control_changed(
        &mut self,
        rec: &mut Recorder,
        at: Where,
        bytes: &[u8],
        prev: Option<u16>,
        control: u16,
    ) {
        let mbz = self.rules.control_bits().must_be_zero_mask() as u16;
        let bad = control & mbz & !prev.unwrap_or(0);
        for b in 0..16u16 {
            if bad & (1 << b) == 0 {
                continue;
            }
            let id = match b {
                3 => "PSD-CTL-3-001",
                5 => "PSD-CTL-5-001",
                7..=12 => "PSD-CTL-7-001",
                14 | 15 => "PSD-CTL-14-001",
                _ => "PSD-CTL-ZERO-001",
            };
            rec.checks(&[id]);
            self.violation(rec, id, at, || {
                (
                    format!("control word {control:#06x} sets reserved bit {b}"),
                    Evidence::bytes(bytes).with("control", format!("{control:#06x}")),
                )
            });
        }
        // Release withdrawn during a positioning run (not a manual run): bit 5 must follow.
        let p = prev.unwrap_or(0);
        let running = self.inp.is_some_and(|i| i.status & bit::RUNNING != 0);
        let manual = p & (bit::MANUAL_UP | bit::MANUAL_DOWN) != 0;
        if p & bit::RELEASE != 0 && control & bit::RELEASE == 0 && running && !manual {
            self.abort_pending = Some((
                self.inputs,
                Started {
                    at,
                    bytes: bytes.to_vec(),
                },
            ));
        }
        if control & bit::RELEASE != 0 {
            self.abort_pending = None;
        }
    }

    fn pkw_command(&mut self, rec: &mut Recorder, at: Where, bytes: &[u8], req: PkwRequest) {
        if let Some(c) = self.command {
            let no_command = self.pkw().command_codes().no_command;
            if c.req.ak != no_command && c.answer.is_none() && self.inputs > c.since {
                let ev = Evidence::bytes(bytes)
                    .with("command", self.pkw().describe_request(&c.req))
                    .with("new_command", self.pkw().describe_request(&req));
                let detail: (String, Evidence) = (
                    format!(
                        "the controller replaced `{}` (sent at {}) before the drive answered it",
                        self.pkw().describe_request(&c.req),
                        c.at
                    ),
                    ev,
                );
                self.violation(rec, "PSD-PKW-002", at, || detail);
            }
        }
        self.command = Some(Command {
            req,
            at,
            since: self.inputs,
            answer: None,
            reported: false,
        });
    }

    // ------------------------------------------------------------------ input images

    /// An input image (16 bytes, bus description 3.5.2) sent by the drive.
    pub fn input(&mut self, rec: &mut Recorder, at: Where, bytes: &[u8]) {
        self.model_time(at);
        let Ok(inp) = Input::parse(&self.rules, bytes) else {
            return;
        };
        self.inputs += 1;
        let n = self.inputs;
        let lag = self.options.lag_cycles;
        let ev = || {
            Evidence::bytes(bytes)
                .with("status", format!("{:#06x}", inp.status))
                .with("speed", inp.speed)
                .with("actual", inp.actual)
        };
        if let Some(t) = at.time {
            self.timeline.push(Sample {
                time: t,
                actual: i64::from(inp.actual),
                speed: i64::from(inp.speed),
                target: self.target.map(|(t, _)| i64::from(t)),
                status: inp.status,
                control: self.out.map_or(0, |o| o.control),
            });
        }
        // PSD-STS-0-PRIO: bit 0 wins over bit 10, never both.
        let both = inp.status & bit::TARGET_REACHED != 0 && inp.status & bit::OVERLOAD != 0;
        if both && !self.prio_state {
            self.violation(rec, "PSD-STS-0-PRIO", at, || {
                (
                    "status bits 0 (target reached) and 10 (overload) are set together".into(),
                    ev(),
                )
            });
        }
        self.prio_state = both;
        // PSD-CTL-13-001: control bit 13 comes back in status bit 2.
        if let Some(out) = self.out {
            let want = out.control & bit::TOGGLE != 0;
            let have = inp.status & bit::TOGGLE_ECHO != 0;
            if let Some(w) = self.toggle.update(want != have, n, at, bytes, lag) {
                self.violation(rec, "PSD-CTL-13-001", w.at, || (format!(
                        "status bit 2 = {} does not echo control bit 13 = {} from here to {at} ({lag} input images)",
                        u8::from(have),
                        u8::from(want)
                    ), held(&w, at).with("control", format!("{:#06x}", out.control))));
            }
        }
        // PSD-STS-6-SET-1 / PSD-STS-6-RESET-1: the running bit follows the speed.
        let running = inp.status & bit::RUNNING != 0;
        if let Some(w) =
            self.speed_without_run
                .update(!running && inp.speed != 0, n, at, bytes, lag)
        {
            self.violation(rec, "PSD-STS-6-SET-1", w.at, || (format!(
                    "speed {} rpm with status bit 6 (running) clear from here to {at} ({lag} input images)",
                    inp.speed
                ), held(&w, at).with("speed", inp.speed)));
        }
        if let Some(w) = self.run_without_speed.update(
            running && inp.speed == 0,
            n,
            at,
            bytes,
            lag.saturating_mul(5),
        ) {
            self.violation(rec, "PSD-STS-6-RESET-1", w.at, || {
                (
                    format!(
                        "status bit 6 (running) set at speed 0 from here to {at} ({} input images)",
                        lag.saturating_mul(5)
                    ),
                    held(&w, at),
                )
            });
        }
        // PSD-STS-5-SET-1: a positioning run aborted by withdrawing the release sets bit 5.
        if let Some((since, w)) = self.abort_pending.take() {
            // Bit 5 (or the target reached after all) ends the wait.
            let shown = inp.status & (bit::ABORTED | bit::TARGET_REACHED) != 0;
            let stopped = n.saturating_sub(since) >= lag && !running;
            if !shown && stopped {
                self.violation(rec, "PSD-STS-5-SET-1", w.at, || (format!("the release is withdrawn here during a run; the drive stopped at {at} without status bit 5"), held(&w, at).with("status", format!("{:#06x}", inp.status))));
            } else if !shown {
                self.abort_pending = Some((since, w));
            }
        }
        self.window_check(rec, at, &inp, bytes);
        self.bad_target_check(rec, at, &inp);
        self.limit_check(rec, at, &inp, bytes);
        self.speed_check(rec, at, &inp, bytes);
        self.pkw_answer(rec, at, bytes, inp.pkw);
        self.inp = Some(inp);
    }

    /// Reports once per drive that check `id` cannot decide, and why.
    fn undecided(&mut self, rec: &mut Recorder, id: &'static str, at: Where, why: &str) {
        if self.undecided.contains(&id) {
            return;
        }
        self.undecided.push(id);
        rec.inconclusive(id, &self.label, at, "not checked on this drive", why);
    }

    /// The positioning window in force: par 44 as the capture shows it, else the largest the
    /// manual allows (3.3 par 44: 1 to 100 at delivery scaling, scaled with the resolution,
    /// PSD-PAR-44-003), with how it was decided.
    fn window(&self) -> Option<(i64, &'static str)> {
        if let Some(k) = self.known.get(&par::WINDOW) {
            return Some((k.value, "par 44"));
        }
        let p = self.rules.parameter(u32::from(par::WINDOW))?;
        let max = self.family.resolve(p, self.model).range?.max()?;
        let scale = match (
            self.known.get(&par::NUMERATOR).map(|k| k.value),
            self.known.get(&par::DENOMINATOR).map(|k| k.value),
        ) {
            (Some(n), Some(d)) if n > 0 && d > 0 => (n.max(d) + n.min(d) - 1) / n.min(d),
            (None, None) => 1,
            _ => return None,
        };
        Some((
            max.saturating_mul(scale),
            "par 44 not seen: the largest window (3.3 par 44)",
        ))
    }

    /// The values par 44 surely accepts at the scaling the capture shows: 1 up to the
    /// delivery-scaling maximum (100, 3.3) times the resolution factor par 39 / par 38
    /// (rounded down: "the maximum setting value changes according to the same factor as
    /// the resolution"); none while the scaling was not seen.
    fn window_range(&self, p: &drivespec_spec::Parameter) -> Option<(i64, i64)> {
        let range = self.family.resolve(p, self.model).range?;
        let n = self.known.get(&par::NUMERATOR)?.value;
        let d = self.known.get(&par::DENOMINATOR)?.value;
        let hi = range.max()?.checked_mul(d)?.checked_div(n)?;
        Some((range.min()?, hi))
    }

    /// PSD-PAR-44-001: bit 0 only inside the positioning window around the target in force,
    /// at standstill and during a run.
    fn window_check(&mut self, rec: &mut Recorder, at: Where, inp: &Input, bytes: &[u8]) {
        let reached = inp.status & bit::TARGET_REACHED != 0;
        let Some((target, since)) = self.target else {
            if reached {
                self.undecided(
                    rec,
                    "PSD-PAR-44-001",
                    at,
                    "status bit 0 is set but no target was transferred in the capture so far",
                );
            }
            return;
        };
        let Some((window, basis)) = self.window() else {
            if reached {
                self.undecided(
                    rec,
                    "PSD-PAR-44-001",
                    at,
                    "par 44 not seen and only one of the scaling parameters (par 38, 39) known",
                );
            }
            return;
        };
        let settled = self.inputs.saturating_sub(since) >= self.options.lag_cycles;
        let off = (i64::from(inp.actual) - i64::from(target)).abs();
        let bad = settled && reached && off > window;
        if bad && !self.window_state {
            let running = if inp.status & bit::RUNNING != 0 {
                " during a run"
            } else {
                ""
            };
            self.violation(rec, "PSD-PAR-44-001", at, || (format!(
                    "target reached (status bit 0){running} at {} while the target is {target}: {off} apart, window {window} ({basis})",
                    inp.actual
                ), Evidence::bytes(bytes)
                    .with("actual", inp.actual)
                    .with("target", target)
                    .with("window", window)));
        }
        self.window_state = bad;
    }

    /// A target transferred: beyond the limits in force (par 42/43), status bit 12 is due
    /// (3.6 bit 12, PSD-STS-12-SET-1).
    fn transferred(&mut self, rec: &mut Recorder, at: Where, bytes: &[u8], target: i32) {
        self.bad_target = None;
        let (Some(upper), Some(lower)) = (
            self.known.get(&par::UPPER_LIMIT).map(|k| k.value),
            self.known.get(&par::LOWER_LIMIT).map(|k| k.value),
        ) else {
            self.undecided(
                rec,
                "PSD-STS-12-SET-1",
                at,
                "the limits (par 42, 43) were not seen before the first target transfer",
            );
            return;
        };
        let t = i64::from(target);
        let limit = if t > upper {
            upper
        } else if t < lower {
            lower
        } else {
            return;
        };
        let start = Started {
            at,
            bytes: bytes.to_vec(),
        };
        self.bad_target = Some((self.inputs, start, target, limit));
    }

    /// PSD-STS-12-SET-1: after a target beyond the limits, bit 12 within the lag.
    fn bad_target_check(&mut self, rec: &mut Recorder, at: Where, inp: &Input) {
        let Some((since, w, target, limit)) = self.bad_target.take() else {
            return;
        };
        if inp.status & bit::BAD_TARGET != 0 {
            return;
        }
        if self.inputs.saturating_sub(since) < self.options.lag_cycles {
            self.bad_target = Some((since, w, target, limit));
        } else {
            let running = if inp.status & bit::RUNNING != 0 {
                ", and the drive is running"
            } else {
                ""
            };
            self.violation(rec, "PSD-STS-12-SET-1", w.at, || (format!(
                    "target {target} transferred here lies beyond the limit {limit}; status bit 12 (incorrect target value) is not set at {at}{running}"
                ), held(&w, at)
                    .with("target", target)
                    .with("limit", limit)
                    .with("status", format!("{:#06x}", inp.status))));
        }
    }

    /// PSD-STS-14-RESET-1 and PSD-STS-15-RESET-1: a limit bit only while the position is at or
    /// beyond the limit.
    fn limit_check(&mut self, rec: &mut Recorder, at: Where, inp: &Input, bytes: &[u8]) {
        let window = self.known.get(&par::WINDOW).map_or(0, |k| k.value);
        let lag = self.options.lag_cycles;
        let n = self.inputs;
        let actual = i64::from(inp.actual);
        let standstill = inp.status & bit::RUNNING == 0;
        if let Some(upper) = self.known.get(&par::UPPER_LIMIT).map(|k| k.value) {
            let bad = standstill && inp.status & bit::UPPER_LIMIT != 0 && actual < upper - window;
            if let Some(w) = self.upper.update(bad, n, at, bytes, lag) {
                self.violation(rec, "PSD-STS-14-RESET-1", w.at, || (format!("status bit 14 (upper limit) set at {actual}, inside the limit {upper}, from here to {at}"), held(&w, at).with("actual", actual).with("upper_limit", upper)));
            }
        }
        if let Some(lower) = self.known.get(&par::LOWER_LIMIT).map(|k| k.value) {
            let bad = standstill && inp.status & bit::LOWER_LIMIT != 0 && actual > lower + window;
            if let Some(w) = self.lower.update(bad, n, at, bytes, lag) {
                self.violation(rec, "PSD-STS-15-RESET-1", w.at, || (format!("status bit 15 (lower limit) set at {actual}, inside the limit {lower}, from here to {at}"), held(&w, at).with("actual", actual).with("lower_limit", lower)));
            }
        }
    }

    /// Increments per rotation at the scaling the capture shows (4.8: 400 × par 39 / par
    /// 38), when both factors were seen.
    fn increments_per_rotation(&self) -> Option<f64> {
        let scaling = &self.family.psd4xx()?.positioning.scaling;
        let n = self.known.get(&par::NUMERATOR)?.value;
        let d = self.known.get(&par::DENOMINATOR)?.value;
        scaling
            .increments_per_rotation(n, d)
            .filter(|i| i.is_finite() && *i > 0.0)
    }

    /// Whether a write that moves the actual position is in force or just accepted (PKW
    /// command standing, record write unanswered, or answered within the lag).
    fn actual_may_move(&self) -> bool {
        let pkw_write = self.command.is_some_and(|c| {
            par::moves_actual(c.req.pnu)
                && self
                    .pkw()
                    .command_info(c.req.ak)
                    .is_some_and(|i| i.op == PkwOp::Write)
        });
        pkw_write
            || self.records.keys().any(|k| par::moves_actual(*k))
            || self.inputs <= self.excused_until
    }

    /// PSD-VEL-001 / PSD-VEL-002 (4.3 with 3.4 par 53, 56): no run is faster than the
    /// fastest speed the model can be set to, with [`PsdOptions::speed_slack_percent`] —
    /// neither the current speed the drive reports nor the speed its actual position
    /// implies between two input images (over their capture interval plus
    /// [`PsdOptions::jump_slack_us`], at the scaling the capture shows; the shortest way
    /// round a wrap of the 32-bit value; excused while a write that moves the actual
    /// position is in force). Reported once per stretch, as a manual run (PSD-VEL-001) when
    /// the control word in force starts one, else as a positioning run (PSD-VEL-002).
    fn speed_check(&mut self, rec: &mut Recorder, at: Where, inp: &Input, bytes: &[u8]) {
        let prev = self.last_actual.take();
        self.last_actual = at.time.map(|t| (inp.actual, t));
        let Some(max) = self.max_rpm else {
            return;
        };
        let slack = self.options.speed_slack_percent;
        let limit = max.saturating_mul(i64::try_from(slack).unwrap_or(0).saturating_add(100)) / 100;
        let who = self.model.map_or_else(
            || "the fastest PSD4xx model (model unknown)".to_owned(),
            |m| m.name.clone(),
        );
        let speed = i64::from(inp.speed);
        let mut finding = None;
        if speed.abs() > limit {
            finding = Some((
                format!(
                    "current speed {speed} rpm is above {limit} rpm: {who} runs at most {max} rpm (3.4 par 53, 56), {slack} % allowed"
                ),
                Evidence::bytes(bytes)
                    .with("speed", speed)
                    .with("limit_rpm", limit),
            ));
        } else if let (Some((p, t0)), Some(t1)) = (prev, at.time) {
            let moved = (i64::from(inp.actual) - i64::from(p)).abs();
            let moved = moved.min((1i64 << 32) - moved);
            let dt = t1.saturating_sub(t0);
            match self.increments_per_rotation() {
                _ if moved == 0 || self.actual_may_move() => {}
                Some(ipr) => {
                    let window = dt.saturating_add(self.options.jump_slack_us) as f64;
                    let allowed = (limit as f64 * ipr * window / 60e6).ceil() + 2.0;
                    if moved as f64 > allowed {
                        let rpm = moved as f64 * 60e6 / (ipr * dt.max(1) as f64);
                        finding = Some((
                            format!(
                                "actual position moved {moved} increments ({p} to {}) in {dt} µs: about {rpm:.0} rpm at {ipr:.0} increments per rotation, above {limit} rpm ({who}: at most {max} rpm, 3.4 par 53, 56, {slack} % allowed)",
                                inp.actual
                            ),
                            Evidence::bytes(bytes)
                                .with("previous_actual", p)
                                .with("actual", inp.actual)
                                .with("interval_us", dt)
                                .with("allowed_increments", allowed),
                        ));
                    }
                }
                None => self.undecided(
                    rec,
                    "PSD-VEL-002",
                    at,
                    "the actual position changes, but the scaling (par 38, 39) was not seen: increments per rotation unknown",
                ),
            }
        }
        let manual = self.out.is_some_and(|o| {
            o.control & bit::RELEASE != 0 && o.control & (bit::MANUAL_UP | bit::MANUAL_DOWN) != 0
        });
        let id = if manual { "PSD-VEL-001" } else { "PSD-VEL-002" };
        let bad = finding.is_some();
        if let (Some((message, ev)), false) = (finding, self.too_fast) {
            self.violation(rec, id, at, || (message, ev));
        }
        self.too_fast = bad;
    }

    // ------------------------------------------------------------------ PKW

    fn pkw_answer(&mut self, rec: &mut Recorder, at: Where, bytes: &[u8], resp: PkwResponse) {
        if resp.spm != self.spm_state && resp.spm {
            self.violation(rec, "PSD-PKW-010", at, || {
                (
                    "the drive sets SPM (spontaneous messages are not implemented)".into(),
                    Evidence::bytes(bytes.get(..8).unwrap_or(bytes)),
                )
            });
        }
        self.spm_state = resp.spm;
        let Some(mut c) = self.command else {
            return;
        };
        let codes = *self.pkw().command_codes();
        let no_response = self.pkw().response_codes().no_response;
        let pkw_ev = || Evidence::bytes(bytes.get(..8).unwrap_or(bytes));
        if c.req.ak == codes.no_command {
            // PSD-PKW-006: command 0 is answered with response 0.
            let late = self.inputs.saturating_sub(c.since) > self.options.lag_cycles;
            if resp.ak != no_response && late && !c.reported {
                c.reported = true;
                let detail: (String, Evidence) = (
                    format!(
                        "response `{}` to command 0 (no command, sent at {})",
                        self.pkw().describe_response(&resp),
                        c.at
                    ),
                    pkw_ev(),
                );
                self.violation(rec, "PSD-PKW-006", at, || detail);
            }
            self.command = Some(c);
            return;
        }
        match c.answer {
            Some(answer) => {
                // PSD-PKW-003: the response is held until the controller sends a new command.
                if resp != answer && !c.reported {
                    c.reported = true;
                    let detail: (String, Evidence) = (
                        format!(
                            "the response changed from `{}` to `{}` while the command `{}` stayed",
                            self.pkw().describe_response(&answer),
                            self.pkw().describe_response(&resp),
                            self.pkw().describe_request(&c.req)
                        ),
                        pkw_ev(),
                    );
                    self.violation(rec, "PSD-PKW-003", at, || detail);
                }
            }
            None if self.pkw().answers(&c.req, &resp) => {
                c.answer = Some(resp);
                self.command = Some(c);
                self.evaluate(rec, at, bytes, c.req, resp);
                return;
            }
            None => {
                if self.inputs.saturating_sub(c.since) > self.options.pkw_cycles && !c.reported {
                    c.reported = true;
                    let detail: (String, Evidence) = (
                        format!(
                            "no response to `{}`, sent here, within {} input images (until {at})",
                            self.pkw().describe_request(&c.req),
                            self.options.pkw_cycles
                        ),
                        pkw_ev()
                            .with("command", self.pkw().describe_request(&c.req))
                            .with("still_at", at.to_string()),
                    );
                    self.violation(rec, "PSD-PKW-002", c.at, || detail);
                }
            }
        }
        self.command = Some(c);
    }

    /// Checks the answer `resp` to `req` (bus description 3.8).
    fn evaluate(
        &mut self,
        rec: &mut Recorder,
        at: Where,
        bytes: &[u8],
        req: PkwRequest,
        resp: PkwResponse,
    ) {
        let rules = self.rules.clone();
        let pkw = rules.pkw();
        let ev = Evidence::bytes(bytes.get(..8).unwrap_or(bytes))
            .with("command", pkw.describe_request(&req))
            .with("response", pkw.describe_response(&resp));
        let cannot = pkw.response_codes().cannot_execute;
        let verdict = pkw.verdict(req.ak, resp.ak);
        let id = command_requirement(pkw, req.ak);
        match verdict {
            Verdict::UnknownCommand => {
                if resp.ak != cannot {
                    self.violation(rec, "PSD-PKW-019", at, || {
                        (
                            format!(
                                "unknown command {} answered with response {}",
                                u8::from(req.ak),
                                u8::from(resp.ak)
                            ),
                            ev,
                        )
                    });
                }
                return;
            }
            Verdict::NotAllowed => {
                self.violation(rec, id, at, || {
                    (
                        format!(
                            "response {} is not an answer the command allows",
                            u8::from(resp.ak)
                        ),
                        ev,
                    )
                });
                return;
            }
            Verdict::Negative => {
                self.refusal(rec, at, ev, req, resp);
                return;
            }
            Verdict::Positive => {}
        }
        let Some(info) = pkw.command_info(req.ak).cloned() else {
            return;
        };
        let param = rules.parameter(u32::from(req.pnu));
        // A positive answer for a parameter the drive does not have (error 0 is due).
        if param.is_none() {
            self.violation(rec, "PSD-PKW-023", at, || {
                (
                    format!(
                        "positive answer for parameter {}, which the drive does not have",
                        req.pnu
                    ),
                    ev,
                )
            });
            return;
        }
        if let Some(code) = pkw.expected_response(&req) {
            if code != resp.ak {
                self.violation(rec, id, at, || {
                    (
                        format!(
                            "response {} where the parameter's width calls for {}",
                            u8::from(resp.ak),
                            u8::from(code)
                        ),
                        ev,
                    )
                });
                return;
            }
        }
        if let Some(false) = pkw.echo_holds(&req, &resp) {
            self.violation(rec, "PSD-PKW-034", at, || {
                (
                    "the answer to the write does not repeat PNU, IND and PWE of the command"
                        .into(),
                    ev.clone(),
                )
            });
        }
        let string = pkw.string_access(req.pnu).is_some();
        let width = if info.array {
            pkw.element_width(req.pnu)
        } else {
            pkw.width(req.pnu)
        };
        if let (Some(Width::Word), false) = (width, string) {
            if pkw.raw_of(resp.pwe, Width::Dword) >> 16 != 0
                && pkw.pwe_of(pkw.raw_of(resp.pwe, Width::Word), Width::Word, false) != resp.pwe
                && pkw.pwe_of(pkw.raw_of(resp.pwe, Width::Word), Width::Word, true) != resp.pwe
            {
                self.violation(rec, "PSD-PKW-038", at, || {
                    (
                        format!(
                            "16-bit value with PWE {:#010x}: the unused word is not 0",
                            resp.pwe
                        ),
                        ev.clone(),
                    )
                });
            }
        }
        if string || info.array || info.op == PkwOp::Count {
            return;
        }
        let Some(width) = width else {
            return;
        };
        let value = pkw.value_of(req.pnu, resp.pwe, width);
        match info.op {
            PkwOp::Read => self.read_value(rec, at, req.pnu, value, ev),
            PkwOp::Write => {
                let written = pkw.value_of(req.pnu, req.pwe, width);
                self.accepted_write(rec, at, req.pnu, written, ev);
            }
            _ => {}
        }
    }

    /// A value the drive reports for `pnu` (PKW or record read).
    fn read_value(&mut self, rec: &mut Recorder, at: Where, pnu: u16, value: i64, ev: Evidence) {
        let rules = self.rules.clone();
        let Some(p) = rules.parameter(u32::from(pnu)) else {
            return;
        };
        if p.range_note.is_none() && (!p.range_model || self.model.is_some()) {
            if let Some(r) = self.family.resolve(p, self.model).range {
                if !r.contains(value) {
                    self.violation(rec, "PSD-PAR-RANGE-001", at, || {
                        (
                            format!(
                                "par {pnu} ({}) reads {value}, outside its range {r}",
                                p.name
                            ),
                            ev.clone().with("value", value),
                        )
                    });
                }
            }
        }
        if !p.live {
            if let Some(k) = self.known.get(&pnu).copied() {
                if k.value != value {
                    self.violation(rec, "PSD-PKW-021", at, || {
                        (
                            format!(
                            "par {pnu} ({}) reads {value}, but the capture established {} at {}",
                            p.name, k.value, k.at
                        ),
                            ev.with("value", value).with("expected", k.value),
                        )
                    });
                }
            }
            let seedable = p.access.writable() && pnu != par::COMMAND && p.conditions.is_empty();
            if seedable {
                let t = self.model_time(at);
                if let (Some(o), Some(t)) = (self.oracle.as_mut(), t) {
                    let _ = o.write_parameter(t, pnu, value);
                }
            }
            self.known.insert(pnu, Known { value, at });
        }
    }

    /// A write of `value` to `pnu` the drive accepted (PKW or record).
    fn accepted_write(
        &mut self,
        rec: &mut Recorder,
        at: Where,
        pnu: u16,
        value: i64,
        ev: Evidence,
    ) {
        if par::moves_actual(pnu) {
            self.excused_until = self.inputs.saturating_add(self.options.lag_cycles);
        }
        if pnu == par::COMMAND {
            // Par. 96 restores, resets or saves: every value may change.
            self.known.clear();
            return;
        }
        let codes = *self.pkw().error_codes();
        let t = self.model_time(at);
        let predicted = match (self.oracle.as_mut(), t) {
            (Some(o), Some(t)) => Some(o.write_parameter(t, pnu, value)),
            _ => None,
        };
        if let Some(Err(e)) = predicted {
            let id = if e == codes.unknown_parameter {
                Some("PSD-PKW-023")
            } else if e == codes.read_only {
                Some("PSD-PKW-024")
            } else if e == codes.out_of_range && !self.another_model_allows(pnu, value) {
                Some("PSD-PKW-025")
            } else {
                None
            };
            if let Some(id) = id {
                let name = self.pkw().errors().name(e).unwrap_or("?").to_owned();
                self.violation(rec, id, at, || (format!(
                        "the drive accepted par {pnu} = {value}; the reference model refuses it with error {} ({name})",
                        u32::from(e)
                    ), ev.with("value", value)));
                return;
            }
        }
        self.rereferenced(pnu, value);
        let live = self.rules.parameter(u32::from(pnu)).is_none_or(|p| p.live);
        if !live {
            self.known.insert(pnu, Known { value, at });
        }
    }

    /// With the model unknown, whether some model of the family accepts `value` for a
    /// parameter whose range depends on the model (3.4): the oracle stands for one model
    /// only, so its refusal proves nothing then.
    fn another_model_allows(&self, pnu: u16, value: i64) -> bool {
        let Some(p) = self.rules.parameter(u32::from(pnu)) else {
            return false;
        };
        self.model.is_none()
            && p.range_model
            && self.family.models.iter().any(|m| {
                self.family
                    .resolve(p, Some(m))
                    .range
                    .is_some_and(|r| r.contains(value))
            })
    }

    /// Values the drive recalculates after an accepted write of `pnu` (4.7 notes 3–6 and
    /// "Reference value"): writing the actual value (par 3) shifts the referencing value
    /// (par 40), and with it the target, the actual value and the limits, by the difference
    /// to the current position; the direction (37), scaling (38, 39), referencing value
    /// (40) and mapping end (41) change them by amounts the capture does not show, so the
    /// target and limits are forgotten until transferred or read again.
    fn rereferenced(&mut self, pnu: u16, value: i64) {
        match pnu {
            par::ACTUAL => {
                let Some(actual) = self.inp.map(|i| i64::from(i.actual)) else {
                    self.target = None;
                    return;
                };
                let delta = value.saturating_sub(actual);
                self.target = self.target.map(|(t, since)| {
                    let shifted = i64::from(t).saturating_add(delta);
                    (i32::try_from(shifted).unwrap_or(t), since)
                });
                for p in [par::UPPER_LIMIT, par::LOWER_LIMIT] {
                    if let Some(k) = self.known.get_mut(&p) {
                        k.value = k.value.saturating_add(delta);
                    }
                }
                self.known.remove(&40);
            }
            37..=41 => {
                self.target = None;
                self.bad_target = None;
                for p in [par::UPPER_LIMIT, par::LOWER_LIMIT, par::WINDOW, 40] {
                    self.known.remove(&p);
                }
            }
            _ => {}
        }
    }

    /// Response 7: is the error code plausible for the command, parameter and model?
    fn refusal(
        &mut self,
        rec: &mut Recorder,
        at: Where,
        ev: Evidence,
        req: PkwRequest,
        resp: PkwResponse,
    ) {
        let rules = self.rules.clone();
        let pkw = rules.pkw();
        let codes = *pkw.error_codes();
        let e = ErrorCode::from(resp.pwe);
        let Some(info) = pkw.command_info(req.ak).cloned() else {
            return;
        };
        if !pkw.errors().contains(e) {
            self.violation(rec, "PSD-PKW-022", at, || {
                (
                    format!("error code {} is not in the error table", resp.pwe),
                    ev,
                )
            });
            return;
        }
        let p = rules.parameter(u32::from(req.pnu));
        let write = info.op == PkwOp::Write;
        let width = pkw.width(req.pnu);
        let value = width.map(|w| pkw.value_of(req.pnu, req.pwe, w));
        let (plausible, id) = if e == codes.unknown_parameter {
            (p.is_none(), "PSD-PKW-023")
        } else if e == codes.read_only {
            (
                write && p.is_none_or(|p| !p.access.writable()),
                "PSD-PKW-024",
            )
        } else if e == codes.out_of_range {
            let outside = match (p, value) {
                (Some(p), Some(v)) if write && p.number == u32::from(par::WINDOW) => {
                    self.window_range(p).is_none_or(|(lo, hi)| v < lo || v > hi)
                }
                (Some(p), Some(v)) if write => {
                    p.range_note.is_some()
                        || (p.range_model && self.model.is_none())
                        || self
                            .family
                            .resolve(p, self.model)
                            .range
                            .is_none_or(|r| !r.contains(v))
                }
                _ => false,
            };
            (outside, "PSD-PKW-025")
        } else if e == codes.bad_subindex {
            (info.array, "PSD-PKW-026")
        } else if e == codes.no_array {
            (info.array && pkw.elements(req.pnu).is_none(), "PSD-PKW-027")
        } else if e == codes.wrong_type {
            let declared = match info.value {
                Some(PkwValue::Word | PkwValue::ArrayWord) => Some(Width::Word),
                Some(PkwValue::Dword | PkwValue::ArrayDword) => Some(Width::Dword),
                _ => None,
            };
            let string = pkw.string_access(req.pnu).is_some();
            (
                string || (declared.is_some() && declared != width) || p.is_none(),
                "PSD-PKW-028",
            )
        } else if e == codes.operating_state {
            (
                write && p.is_none_or(|p| !p.conditions.is_empty() || p.number == 96),
                "PSD-PKW-030",
            )
        } else {
            (true, "")
        };
        if !plausible {
            let name = pkw.errors().name(e).unwrap_or("?").to_owned();
            self.violation(rec, id, at, || {
                (
                    format!(
                        "error {} ({name}) is not plausible for `{}`",
                        resp.pwe,
                        pkw.describe_request(&req)
                    ),
                    ev,
                )
            });
        }
    }

    // ------------------------------------------------------------------ records

    /// A record write request (bus description 3.2.2): index = parameter, control byte, value.
    pub fn record_write(&mut self, rec: &mut Recorder, at: Where, index: u16, data: &[u8]) {
        let rr = self.rules.record();
        let Ok(shape) = rr.shape(index) else {
            return;
        };
        if let RecordShape::Number(w) = shape {
            let need = rr.write_len(w);
            if data.len() != need {
                let id = if w == Width::Word {
                    "PSD-REC-006"
                } else {
                    "PSD-REC-007"
                };
                self.violation(rec, id, at, || (format!(
                        "record write of par {index} ({w}) is {} byte(s) long; control byte and value make {need}",
                        data.len()
                    ), Evidence::bytes(data).with("index", index)));
                return;
            }
        }
        self.records.insert(index, data.to_vec());
        if self.records.len() > 64 {
            if let Some(k) = self.records.keys().next().copied() {
                self.records.remove(&k);
            }
        }
    }

    /// The answer to a record write: `ok` when PNIOStatus is OK.
    pub fn record_written(&mut self, rec: &mut Recorder, at: Where, index: u16, ok: bool) {
        let Some(data) = self.records.remove(&index) else {
            return;
        };
        if !ok {
            return;
        }
        let rr = self.rules.record().clone();
        let Ok(w) = drivespec_psd4xx::RecordWrite::parse(&rr, index, &data) else {
            return;
        };
        if !w.executes(&rr) {
            return;
        }
        let value = w.value;
        let ev = Evidence::bytes(&data).with("index", index);
        self.accepted_write(rec, at, index, value, ev);
    }

    /// The answer to a record read (bus description 3.2.2): 2 or 4 bytes, or the string.
    pub fn record_read(&mut self, rec: &mut Recorder, at: Where, index: u16, data: &[u8]) {
        let rr = self.rules.record().clone();
        let Ok(shape) = rr.shape(index) else {
            return;
        };
        let RecordShape::Number(w) = shape else {
            return;
        };
        let need = rr.read_len(w);
        if data.len() != need {
            let id = if w == Width::Word {
                "PSD-REC-008"
            } else {
                "PSD-REC-009"
            };
            self.violation(rec, id, at, || {
                (
                    format!(
                        "record read of par {index} ({w}) answered with {} byte(s), not {need}",
                        data.len()
                    ),
                    Evidence::bytes(data)
                        .with("index", index)
                        .with("data", to_hex(data)),
                )
            });
            return;
        }
        if let Ok(r) = drivespec_psd4xx::RecordRead::parse(&rr, index, data) {
            if let drivespec_psd4xx::RecordValue::Number { value: v, .. } = r.value {
                self.read_value(
                    rec,
                    at,
                    index,
                    v,
                    Evidence::bytes(data).with("index", index),
                );
            }
        }
    }
}
