//! IO-Link master logs of PSx3xx drives (instruction manual chapter 3, 4.4–4.6; log format
//! in `crates/capture/IOLINK-LOG.md`): process-data format consistency, time-stamp rules,
//! control/status relations as for the PSD4xx, ISDU answers against the object directory
//! and the per-model ranges, guard entries and standard commands.
//!
//! [`check`] is a pure function over `IoLinkEvent`s (style rule 12); [`IoLinkChecker`] is the
//! same as a push API. State is kept per master port (at most 255) and bounded per port.
//! Nothing here panics.
//!
//! ISDU answers are judged by the codec (`drivespec_psx3xx::Rules::check_request`), which
//! says for every request whether a conforming device refuses it and with which ErrorTypes:
//! a refused request answered with success, or answered with an ErrorType the case does not
//! allow, is a violation; read values must lie in the entry's range for the model.

use crate::error::SetupError;
use crate::report::{
    Catalog, DriveInfo, Evidence, InputFault, Policy, Recorder, Report, Stats, StreamStats, Where,
};
use crate::timeline::{Sample, Timeline};
use drivespec_capture::iolink::{Access, IoLinkError, IoLinkEvent, IoLinkKind, IsduResult};
use drivespec_psx3xx::isdu::{ErrorCase, ErrorType, Request, Value};
use drivespec_psx3xx::{ByteOrder, Guards, Input, Output, Rules, StampMeaning, WriteFate};
use drivespec_spec::hex::to_hex;
use drivespec_spec::psx3xx::RunAction;
use drivespec_spec::{DeviceModel, FamilyId, Readings, Spec};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Requirements always checked (manual 3.1, 3.3, 3.4, 3.5).
const CHECKED: &[&str] = &[
    "PSX-PD-001",
    "PSX-PD-006",
    "PSX-PD-010",
    "PSX-TS-001",
    "PSX-TS-003",
    "PSX-TS-005",
    "PSX-CTL-13-1",
    "PSX-CTL-15-1",
    "PSX-STS-5-SET-1",
    "PSX-STS-6-SET-1",
    "PSX-STS-6-RESET-1",
    "PSX-ISDU-131-WINDOW",
    "PSX-DP-ERR-001",
    "PSX-DP-ERR-002",
    "PSX-DP-ERR-003",
    "PSX-DP-ERR-004",
    "PSX-DP-ERR-005",
    "PSX-DP-ERR-006",
    "PSX-DP-ERR-007",
    "PSX-CMD-011",
    "PSX-GUARD-ONESHOT",
];

/// Options of the IO-Link checker.
#[derive(Debug, Clone)]
pub struct PsxOptions {
    /// Most violations listed (all are counted).
    pub max_violations: Option<u64>,
    /// Device model (`PSE335-14`, matched forgivingly): per-model ranges of 3.2.
    pub model: Option<String>,
    /// Byte order of the process data; None: the spec's (IO-Link, big-endian).
    pub order: Option<ByteOrder>,
    /// Input samples within which a relation between output and input must hold.
    pub lag_cycles: u64,
}

impl Default for PsxOptions {
    fn default() -> PsxOptions {
        PsxOptions {
            max_violations: None,
            model: None,
            order: None,
            lag_cycles: 20,
        }
    }
}

/// Bits of the status and control words (manual 3.4, 3.5).
mod bit {
    pub const TARGET_REACHED: u16 = 1 << 0;
    pub const ABORTED: u16 = 1 << 5;
    pub const RUNNING: u16 = 1 << 6;
    pub const MANUAL: u16 = 0b11;
    pub const TRANSFER: u16 = 1 << 2;
    pub const RELEASE: u16 = 1 << 4;
}

/// ISDU indices the relations use (manual 3.1).
mod isdu {
    pub const COMMAND: u16 = 2;
    pub const FORMAT: u16 = 116;
    pub const WINDOW: u16 = 131;
    pub const DELIVERY: u16 = 193;
}

/// A time stamp whose command starts a run, not yet executed (manual 3.3.1, 4.4).
#[derive(Debug, Clone, Copy)]
struct Armed {
    /// Control code sent with the stamp.
    code: u8,
    /// The stamp value.
    stamp: u16,
    /// Delay the stamp encodes, µs.
    delay_us: u32,
    /// Log time of the last output carrying it.
    received: u64,
    /// Log time the stamp field turned inactive.
    inactive: Option<u64>,
}

/// Which reading of the time-stamp errata the checker applies.
#[derive(Debug, Clone, Copy)]
struct StampReadings {
    /// PSX-ERRATUM-064 reading "last-stamp": the delay counts from the stamp's reception.
    from_last: bool,
    /// Reading "on-reception" of `psx-ts-immediate`: stamps below the threshold run at once.
    immediate: bool,
}

#[derive(Debug, Clone, Copy, Default)]
struct Streak {
    since: Option<(u64, Where)>,
    reported: bool,
}

impl Streak {
    fn update(&mut self, failing: bool, n: u64, at: Where, bound: u64) -> Option<Where> {
        if !failing {
            *self = Streak::default();
            return None;
        }
        let (start, w) = *self.since.get_or_insert((n, at));
        if !self.reported && n.saturating_sub(start) >= bound {
            self.reported = true;
            return Some(w);
        }
        None
    }
}

/// One master port.
struct Port {
    label: String,
    format: Option<u8>,
    /// A format written to ISDU 116: (format, saved since).
    pending_format: Option<(u8, bool)>,
    out_len: Option<usize>,
    last_time: Option<u64>,
    interval: Stats,
    samples: u64,
    control: Option<u16>,
    target: Option<(i32, u64)>,
    stamp_bad: bool,
    /// A pending run command by time stamp; cleared by an ISDU write (the control word
    /// may then change by other means).
    armed: Option<Armed>,
    reserved: u16,
    inp: Option<Input>,
    toggle_window: bool,
    speed_without_run: Streak,
    run_without_speed: Streak,
    abort_pending: Option<(u64, Where)>,
    request: Option<(Request, Where)>,
    window: Option<i64>,
    guards: Option<Guards>,
    values: BTreeMap<u16, (i64, Where)>,
    timeline: Timeline,
}

impl Port {
    /// A port without guards or bit names (`add_port` adds them).
    fn empty(n: u8) -> Port {
        let label = format!("port {n}");
        Port {
            timeline: Timeline::new(&label, Vec::new()),
            label,
            format: None,
            pending_format: None,
            out_len: None,
            last_time: None,
            interval: Stats::default(),
            samples: 0,
            control: None,
            target: None,
            stamp_bad: false,
            armed: None,
            reserved: 0,
            inp: None,
            toggle_window: false,
            speed_without_run: Streak::default(),
            run_without_speed: Streak::default(),
            abort_pending: None,
            request: None,
            window: None,
            guards: None,
            values: BTreeMap::new(),
        }
    }
}

/// The IO-Link checker as a push API (see the module docs).
pub struct IoLinkChecker<'s> {
    rules: Rules<'s>,
    model: Option<&'s DeviceModel>,
    options: PsxOptions,
    order: ByteOrder,
    rec: Recorder,
    ports: BTreeMap<u8, Port>,
    events: u64,
    readings: Readings,
    stamps: StampReadings,
}

fn case_requirement(case: ErrorCase, index: u16, catalog: &Catalog) -> String {
    let range = format!("PSX-ISDU-{index}-RANGE");
    match case {
        ErrorCase::IndexNotAvailable => "PSX-DP-ERR-001".into(),
        ErrorCase::SubindexNotAvailable => "PSX-DP-ERR-002".into(),
        ErrorCase::WriteReadOnly => "PSX-DP-ERR-003".into(),
        ErrorCase::ReadWriteOnly => "PSX-DP-ERR-007".into(),
        ErrorCase::CommandNotAvailable if index == isdu::COMMAND => "PSX-CMD-011".into(),
        ErrorCase::CommandNotAvailable => "PSX-DP-ERR-005".into(),
        ErrorCase::LengthOverrun | ErrorCase::LengthUnderrun => "PSX-DP-ERR-006".into(),
        ErrorCase::WriteLocked => "PSX-DP-ERR-008".into(),
        _ if catalog.has(&range) => range,
        _ => "PSX-DP-ERR-004".into(),
    }
}

impl<'s> IoLinkChecker<'s> {
    /// A checker with the spec's PSx3xx tables.
    pub fn new(spec: &'s Spec, options: PsxOptions) -> Result<IoLinkChecker<'s>, SetupError> {
        let catalog = Arc::new(Catalog::new(spec)?);
        IoLinkChecker::with_catalog(spec, options, catalog)
    }

    /// Checks every item of `events` in order (see [`check`]) and gives the report.
    pub fn run<I>(mut self, events: I) -> Report
    where
        I: IntoIterator<Item = Result<IoLinkEvent, IoLinkError>>,
    {
        for item in events {
            match item {
                Ok(ev) => self.push(&ev),
                Err(e) if continues(&e) => self.skipped(&e),
                Err(e) => {
                    self.fail(&e);
                    break;
                }
            }
        }
        self.finish()
    }

    /// A checker sharing a catalogue.
    pub fn with_catalog(
        spec: &'s Spec,
        options: PsxOptions,
        catalog: Arc<Catalog>,
    ) -> Result<IoLinkChecker<'s>, SetupError> {
        let rules = Rules::from_spec(spec).map_err(|e| SetupError::Psx3xx(e.to_string()))?;
        let family = spec.family(FamilyId::Psx3xx);
        let model = match &options.model {
            Some(m) => Some(family.model(m).ok_or_else(|| SetupError::Option {
                option: "--model",
                reason: format!(
                    "unknown PSx3xx model {m:?}; known: {}",
                    family
                        .models
                        .iter()
                        .map(|m| m.id.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            })?),
            None => None,
        };
        let order = options.order.unwrap_or_else(|| rules.wire_order());
        let readings = Readings::default();
        let stamps = StampReadings {
            from_last: readings.reading(family, "psx-ts-reference") == Some("last-stamp"),
            immediate: readings.reading(family, "psx-ts-immediate") == Some("on-reception"),
        };
        let mut rec = Recorder::new(catalog, "psx3xx", options.max_violations);
        rec.checks(CHECKED);
        Ok(IoLinkChecker {
            rules,
            model,
            options,
            order,
            rec,
            ports: BTreeMap::new(),
            events: 0,
            readings,
            stamps,
        })
    }

    fn port(&mut self, n: u8) -> &mut Port {
        if !self.ports.contains_key(&n) {
            self.add_port(n);
        }
        self.ports.entry(n).or_insert_with(|| Port::empty(n))
    }

    fn add_port(&mut self, n: u8) {
        let guards = Guards::from_rules(&self.rules, &self.readings).ok();
        let names: Vec<String> = (0..16u32)
            .map(|b| {
                self.rules
                    .status_bits()
                    .and_then(|s| s.bit(b))
                    .map_or_else(|| format!("bit {b}"), |x| x.name.clone())
            })
            .collect();
        let mut p = Port::empty(n);
        p.guards = guards;
        p.timeline = Timeline::new(&p.label, names);
        self.ports.insert(n, p);
    }

    fn violation(&mut self, port: u8, id: &str, at: Where, msg: impl Into<String>, ev: Evidence) {
        let label = self
            .ports
            .get(&port)
            .map_or_else(|| format!("port {port}"), |p| p.label.clone());
        if let (Some(t), Some(p)) = (at.time, self.ports.get_mut(&port)) {
            p.timeline.mark(t, id);
        }
        self.rec.violation(id, &label, at, msg, ev);
    }

    /// Takes the next log event.
    pub fn push(&mut self, ev: &IoLinkEvent) {
        let at = Where {
            event: self.events,
            line: Some(ev.line),
            time: ev.time,
            ..Where::default()
        };
        let port = ev.port.unwrap_or(1);
        match &ev.kind {
            IoLinkKind::ProcessData { out, input } => {
                self.rec.report().count("pd");
                self.pd(port, at, out.as_deref(), input.as_deref());
            }
            IoLinkKind::IsduRequest {
                access,
                index,
                subindex,
                data,
            } => {
                self.rec.report().count("isdu-request");
                let req = match access {
                    Access::Read => Request::Read {
                        index: *index,
                        subindex: *subindex,
                    },
                    Access::Write => Request::Write {
                        index: *index,
                        subindex: *subindex,
                        data: data.clone(),
                    },
                };
                let p = self.port(port);
                if matches!(access, Access::Write) {
                    p.armed = None;
                }
                if let Some((old, w)) = p.request.take() {
                    let (i, _) = old.address();
                    self.rec.report().note(format!(
                        "port {port}: ISDU request for index {i} at {w} has no response before the next request"
                    ));
                }
                self.port(port).request = Some((req, at));
            }
            IoLinkKind::IsduResponse {
                index,
                subindex,
                result,
            } => {
                self.rec.report().count("isdu-response");
                self.isdu_response(port, at, *index, *subindex, result);
            }
            IoLinkKind::PortEvent { .. } => self.rec.report().count("event"),
            _ => self.rec.report().count("other"),
        }
        self.events += 1;
    }

    // ------------------------------------------------------------------ process data

    fn format_of_len(&self, len: usize) -> Option<u8> {
        self.rules
            .outputs()
            .iter()
            .find(|o| o.layout.length() == len)
            .map(|o| o.format)
    }

    fn pd(&mut self, port: u8, at: Where, out: Option<&[u8]>, input: Option<&[u8]>) {
        let lag = self.options.lag_cycles;
        let p = self.port(port);
        p.samples += 1;
        let n = p.samples;
        if let Some(t) = at.time {
            if let Some(l) = p.last_time {
                if t > l {
                    p.interval.add((t - l) as f64);
                }
            }
            p.last_time = Some(t);
        }
        if let Some(bytes) = out {
            self.pd_out(port, at, bytes);
        }
        let Some(bytes) = input else {
            return;
        };
        let len = Input::buffer_len(&self.rules);
        let Ok(inp) = Input::parse(&self.rules, self.order, bytes) else {
            let msg = format!("process input of {} byte(s), not {len}", bytes.len());
            self.violation(port, "PSX-PD-006", at, msg, Evidence::bytes(bytes));
            return;
        };
        let ev = || {
            Evidence::bytes(bytes)
                .with("status", format!("{:#06x}", inp.status))
                .with("rpm", inp.rpm)
                .with("actual", inp.actual)
        };
        let mut found: Vec<(&'static str, String, Evidence)> = Vec::new();
        let stamps = self.stamps;
        let p = self.port(port);
        if let Some(t) = at.time {
            p.timeline.push(Sample {
                time: t,
                actual: i64::from(inp.actual),
                speed: i64::from(inp.rpm),
                target: p.target.map(|(t, _)| i64::from(t)),
                status: inp.status,
                control: p.control.unwrap_or(0),
            });
        }
        let running = inp.status & bit::RUNNING != 0;
        let started = running && p.inp.is_some_and(|i| i.status & bit::RUNNING == 0);
        let cycle_us = p.interval.mean;
        let armed = if started { p.armed.take() } else { None };
        if let (Some(t), Some(armed)) = (at.time, armed) {
            if let Some((id, msg)) = early_start(&armed, t, cycle_us, stamps) {
                let e = ev().with("stamp", armed.stamp).with("code", armed.code);
                found.push((id, msg, e));
            }
        }
        if let Some(w) = p
            .speed_without_run
            .update(!running && inp.rpm != 0, n, at, lag)
        {
            found.push((
                "PSX-STS-6-SET-1",
                format!(
                    "speed {} rpm with status bit 6 (running) clear since {w}",
                    inp.rpm
                ),
                ev(),
            ));
        }
        if let Some(w) =
            p.run_without_speed
                .update(running && inp.rpm == 0, n, at, lag.saturating_mul(5))
        {
            found.push((
                "PSX-STS-6-RESET-1",
                format!("status bit 6 (running) set at speed 0 since {w}"),
                ev(),
            ));
        }
        if let Some((since, w)) = p.abort_pending {
            if inp.status & (bit::ABORTED | bit::TARGET_REACHED) != 0 {
                p.abort_pending = None;
            } else if n.saturating_sub(since) >= lag && !running {
                p.abort_pending = None;
                found.push((
                    "PSX-STS-5-SET-1",
                    format!("the release was withdrawn during a run at {w}; the drive stopped without status bit 5"),
                    ev(),
                ));
            }
        }
        if let (Some((target, since)), Some(window)) = (p.target, p.window) {
            let settled = n.saturating_sub(since) >= lag;
            let reached = inp.status & bit::TARGET_REACHED != 0 && !running;
            let off = (i64::from(inp.actual) - i64::from(target)).abs();
            let bad = settled && reached && off > window;
            if bad && !p.toggle_window {
                found.push((
                    "PSX-ISDU-131-WINDOW",
                    format!("target reached (status bit 0) at {} with target {target}: {off} apart, window (ISDU 131) {window}", inp.actual),
                    ev().with("target", target).with("window", window),
                ));
            }
            p.toggle_window = bad;
        }
        p.inp = Some(inp);
        for (id, msg, e) in found {
            self.violation(port, id, at, msg, e);
        }
    }

    /// Tracks a time stamp of a format 0 output (manual 3.3.1, 4.4): a valid stamp with a
    /// run command arms it (a new valid stamp replaces the pending one, PSX-TS-004); the
    /// inactive marker releases it (PSX-TS-005).
    fn arm(&mut self, port: u8, at: Where, code: u8, stamp: u16, meaning: StampMeaning) {
        let Some(t) = at.time else {
            return;
        };
        let starts_run = self.rules.timestamp().command(code).is_some_and(|c| {
            matches!(
                c.action,
                RunAction::ManualForward
                    | RunAction::ManualReverse
                    | RunAction::Position
                    | RunAction::SafePosition
            )
        });
        let immediate = self.stamps.immediate;
        let p = self.port(port);
        match meaning {
            StampMeaning::Inactive => {
                if let Some(a) = p.armed.as_mut() {
                    a.inactive.get_or_insert(t);
                }
            }
            StampMeaning::Immediate { .. } if immediate => p.armed = None,
            StampMeaning::Immediate { delay_us } | StampMeaning::Delayed { delay_us } => {
                p.armed = starts_run.then_some(Armed {
                    code,
                    stamp,
                    delay_us,
                    received: t,
                    inactive: None,
                });
            }
            StampMeaning::Reserved => {}
        }
    }

    fn pd_out(&mut self, port: u8, at: Where, bytes: &[u8]) {
        let len = bytes.len();
        let by_len = self.format_of_len(len);
        let Some(f) = by_len else {
            let lens: Vec<String> = self
                .rules
                .outputs()
                .iter()
                .map(|o| format!("{} (format {})", o.layout.length(), o.format))
                .collect();
            let msg = format!(
                "process output of {len} byte(s) fits no format: {}",
                lens.join(", ")
            );
            self.violation(port, "PSX-PD-001", at, msg, Evidence::bytes(bytes));
            return;
        };
        let p = self.port(port);
        let previous = p.format;
        if previous.is_some_and(|old| old != f) {
            // PSX-PD-010: a new format only after ISDU 116, a save and a reset or restart.
            let allowed = p.pending_format.is_some_and(|(pf, _)| pf == f);
            if !allowed {
                let msg = format!(
                    "process output changes from format {} to format {f} without ISDU 116 = {f}, save and reset",
                    previous.unwrap_or(0)
                );
                self.violation(port, "PSX-PD-010", at, msg, Evidence::bytes(bytes));
            }
            self.port(port).pending_format = None;
        }
        let p = self.port(port);
        p.format = Some(f);
        p.out_len = Some(len);
        let samples = p.samples;
        let running = p.inp.is_some_and(|i| i.status & bit::RUNNING != 0);
        let Ok(out) = Output::parse(&self.rules, f, self.order, bytes) else {
            return;
        };
        let mut found: Vec<(&'static str, String)> = Vec::new();
        match out {
            Output::TimeStamp { control, stamp } => {
                let ts = self.rules.timestamp();
                let valid = stamp.meaning(ts).is_valid() || stamp.meaning(ts).is_inactive();
                let p = self.port(port);
                if !valid && !p.stamp_bad {
                    found.push((
                        "PSX-TS-003",
                        format!(
                            "time stamp {} is neither valid (0..16368) nor inactive (16383)",
                            stamp.0
                        ),
                    ));
                }
                self.port(port).stamp_bad = !valid;
                self.arm(port, at, control.0, stamp.0, stamp.meaning(ts));
            }
            _ => {
                let control = out.control_word().unwrap_or(0);
                let target = out.target().unwrap_or(0);
                let p = self.port(port);
                let prev = p.control;
                let reserved = control & (1 << 13 | 1 << 15);
                for (b, id) in [(13u16, "PSX-CTL-13-1"), (15, "PSX-CTL-15-1")] {
                    if reserved & (1 << b) != 0 && p.reserved & (1 << b) == 0 {
                        found.push((
                            id,
                            format!("control word {control:#06x} sets reserved bit {b}"),
                        ));
                    }
                }
                p.reserved = reserved;
                let pc = prev.unwrap_or(0);
                if pc & bit::RELEASE != 0
                    && control & bit::RELEASE == 0
                    && pc & bit::MANUAL == 0
                    && running
                {
                    p.abort_pending = Some((samples, at));
                }
                if control & bit::RELEASE != 0 {
                    p.abort_pending = None;
                }
                if control & bit::TRANSFER != 0 && p.target.is_none_or(|(t, _)| t != target) {
                    p.target = Some((target, samples));
                }
                p.control = Some(control);
            }
        }
        for (id, msg) in found {
            self.violation(port, id, at, msg, Evidence::bytes(bytes));
        }
    }

    // ------------------------------------------------------------------ ISDU

    fn isdu_response(
        &mut self,
        port: u8,
        at: Where,
        index: Option<u16>,
        subindex: Option<u8>,
        result: &IsduResult,
    ) {
        let Some((req, req_at)) = self.port(port).request.take() else {
            self.rec.report().note(format!(
                "port {port}: ISDU response at {at} without a request in the log"
            ));
            return;
        };
        let (ri, rs) = req.address();
        if index.is_some_and(|i| i != ri) || subindex.is_some_and(|s| s != rs) {
            self.rec.report().note(format!(
                "port {port}: ISDU response at {at} names index {}/{}, the request at {req_at} {ri}/{rs}",
                index.map_or_else(|| "?".to_owned(), |i| i.to_string()),
                subindex.map_or_else(|| "?".to_owned(), |i| i.to_string())
            ));
            return;
        }
        let ev = Evidence::none()
            .with("request", request_words(&req))
            .with("request_at", req_at.to_string())
            .with(
                "response",
                match result {
                    IsduResult::Data(d) => format!("data {}", to_hex(d)),
                    IsduResult::Error(e) => format!("error {e:#06x}"),
                },
            );
        let verdict = self.rules.check_request(&req, self.model);
        let catalog = self.rec.catalog().clone();
        match (&verdict, result) {
            (Err(rej), IsduResult::Data(_)) => {
                let id = case_requirement(rej.case, ri, &catalog);
                let msg = format!(
                    "ISDU {ri}/{rs} accepted, but a conforming device refuses it: {}",
                    rej.detail
                );
                self.violation(port, &id, at, msg, ev);
                return;
            }
            (Err(rej), IsduResult::Error(code)) => {
                if !rej.accepts(ErrorType(*code)) {
                    let id = case_requirement(rej.case, ri, &catalog);
                    let msg = format!(
                        "ISDU {ri}/{rs} refused with ErrorType {code:#06x}; the case ({}) calls for {}",
                        rej.case.spec_name(),
                        rej.error
                    );
                    self.violation(port, &id, at, msg, ev);
                }
                return;
            }
            (Ok(_), IsduResult::Error(code)) => {
                if *code == 0x8011 || *code == 0x8012 {
                    let id = if *code == 0x8011 {
                        "PSX-DP-ERR-001"
                    } else {
                        "PSX-DP-ERR-002"
                    };
                    let msg = format!("ISDU {ri}/{rs} exists, but the device answers {code:#06x}");
                    self.violation(port, id, at, msg, ev);
                }
                return;
            }
            (Ok(_), IsduResult::Data(_)) => {}
        }
        let Ok(accepted) = verdict else {
            return;
        };
        match (&req, result) {
            (Request::Write { data, .. }, _) => {
                self.written(port, at, ri, data, accepted.value.as_ref(), &ev);
            }
            (Request::Read { .. }, IsduResult::Data(data)) => {
                self.read(port, at, ri, &accepted.target, data, ev);
            }
            _ => {}
        }
    }

    fn written(
        &mut self,
        port: u8,
        at: Where,
        index: u16,
        _data: &[u8],
        value: Option<&Value>,
        ev: &Evidence,
    ) {
        let v = match value {
            Some(Value::Int(v)) => Some(*v),
            _ => None,
        };
        let id = index.to_string();
        let fate = self
            .port(port)
            .guards
            .as_mut()
            .map_or(WriteFate::Execute, |g| g.on_write(&id, v));
        let p = self.port(port);
        match fate {
            WriteFate::Suppressed { .. } => {
                // The suppressed value must not show on a later read: what was known stays.
            }
            WriteFate::Execute => {
                if let Some(v) = v {
                    p.values.insert(index, (v, at));
                    match index {
                        isdu::FORMAT => {
                            if let Ok(f) = u8::try_from(v) {
                                p.pending_format = Some((f, false));
                            }
                        }
                        isdu::WINDOW => p.window = Some(v),
                        isdu::DELIVERY if v == 1 => {
                            if let Some((f, _)) = p.pending_format {
                                p.pending_format = Some((f, true));
                            }
                        }
                        isdu::COMMAND if v == 161 => {
                            if let Some((f, _)) = p.pending_format {
                                p.pending_format = Some((f, true));
                            }
                        }
                        _ => {}
                    }
                }
            }
        }
        let _ = ev;
    }

    fn read(
        &mut self,
        port: u8,
        at: Where,
        index: u16,
        target: &drivespec_psx3xx::Target<'_>,
        data: &[u8],
        ev: Evidence,
    ) {
        let Ok(Value::Int(v)) = self.rules.decode_value(target, data) else {
            return;
        };
        let Some(p) = target.param() else {
            return;
        };
        let family = self.rules.family();
        let mut found = Vec::new();
        if !p.range_model || self.model.is_some() {
            if let Some(r) = family.resolve(p, self.model).range {
                if !r.contains(v) && p.range_note.is_none() {
                    let range = format!("PSX-ISDU-{index}-RANGE");
                    let id = if self.rec.catalog().has(&range) {
                        range
                    } else {
                        "PSX-DP-ERR-004".into()
                    };
                    found.push((
                        id,
                        format!("ISDU {index} ({}) reads {v}, outside {r}", p.name),
                    ));
                }
            }
        }
        let guarded = self.port(port).guards.as_ref().and_then(|g| {
            g.guard_of(&index.to_string())
                .map(|x| x.requirement.clone())
        });
        let live = p.live;
        let port_state = self.port(port);
        if let (Some(req), false) = (guarded, live) {
            if let Some((w, wat)) = port_state.values.get(&index).copied() {
                if w != v {
                    found.push((
                        req,
                        format!("ISDU {index} reads {v}, but {w} was written at {wat} and not suppressed"),
                    ));
                }
            }
        }
        match index {
            isdu::WINDOW => port_state.window = Some(v),
            isdu::FORMAT => {
                if let Ok(f) = u8::try_from(v) {
                    if port_state.format.is_none() {
                        port_state.format = Some(f);
                    }
                }
            }
            _ => {}
        }
        if !live {
            port_state.values.insert(index, (v, at));
        }
        for (id, msg) in found {
            self.violation(port, &id, at, msg, ev.clone().with("value", v));
        }
    }

    /// Records that reading stopped with `error`; what was read is still checked.
    pub fn fail(&mut self, error: &IoLinkError) {
        let offset = match error {
            IoLinkError::Read(r) => Some(r.offset),
            _ => None,
        };
        self.rec.report().error = Some(InputFault {
            message: error.to_string(),
            offset,
        });
    }

    /// Records a line the reader skipped (reading went on).
    pub fn skipped(&mut self, error: &IoLinkError) {
        self.rec.report().count("unreadable line");
        self.rec.report().note(format!("skipped: {error}"));
    }

    /// Ends the log and returns the report.
    pub fn finish(mut self) -> Report {
        let events = self.events;
        self.rec.report().unreadable_lines(events);
        let ports = std::mem::take(&mut self.ports);
        let r = self.rec.report();
        r.events = events;
        for (n, p) in ports {
            r.streams.push(StreamStats {
                stream: p.label.clone(),
                frames: p.samples,
                nominal_us: None,
                interval_us: p.interval.done(),
                jitter_us: None,
                missing: 0,
                gaps: 0,
            });
            r.drives.push(DriveInfo {
                label: p.label.clone(),
                family: "psx3xx".into(),
                found_by: "port".into(),
                confidence: 1.0,
                details: BTreeMap::from([
                    ("port".to_owned(), serde_json::json!(n)),
                    ("format".to_owned(), serde_json::json!(p.format)),
                ]),
            });
            if p.window.is_none() {
                r.note(format!(
                    "{}: ISDU 131 (positioning window) not in the log; the target-window check did not run",
                    p.label
                ));
            }
            r.timelines.push(p.timeline);
        }
        let r = self.rec.report();
        r.scope("PSx3xx", Some("psx3xx"), None);
        r.judge(Policy::default());
        self.rec.finish()
    }
}

/// Whether the IO-Link reader goes on after this error (IOLINK-LOG.md: a bad line is skipped).
pub fn continues(e: &IoLinkError) -> bool {
    !matches!(e, IoLinkError::Read(_) | IoLinkError::NotIoLink(_))
}

/// Checks an IO-Link log (style rule 12): every event in order; a read error ends the
/// stream (recorded in [`Report::error`]), a bad line is counted and skipped.
pub fn check<I>(spec: &Spec, options: PsxOptions, events: I) -> Result<Report, SetupError>
where
    I: IntoIterator<Item = Result<IoLinkEvent, IoLinkError>>,
{
    Ok(IoLinkChecker::new(spec, options)?.run(events))
}

/// Whether a run seen starting at log time `t` came before its time stamp allowed
/// (manual 3.3.1, 4.4): while the stamp was still being sent (PSX-TS-005), or before its delay
/// ran out (PSX-TS-001), by more than one mean process-data cycle (the log's time resolution).
fn early_start(
    armed: &Armed,
    t: u64,
    cycle_us: f64,
    readings: StampReadings,
) -> Option<(&'static str, String)> {
    let Some(inactive) = armed.inactive else {
        return Some((
            "PSX-TS-005",
            format!(
                "the drive started while time stamp {} (control code {}) was still being sent; it may start only after the stamp field turns inactive (0x3FFF)",
                armed.stamp, armed.code
            ),
        ));
    };
    let from = if readings.from_last {
        armed.received
    } else {
        inactive
    };
    let due = from.saturating_add(u64::from(armed.delay_us));
    let slack = cycle_us.max(0.0) as u64;
    (t.saturating_add(slack) < due).then(|| {
        (
            "PSX-TS-001",
            format!(
                "the drive started {} µs after time stamp {} (control code {}), before its delay of {} µs (stamp × 4 µs) ran out",
                t.saturating_sub(from),
                armed.stamp,
                armed.code,
                armed.delay_us
            ),
        )
    })
}

/// An ISDU request in words: `write index 2/0: 63`, `read index 24/0`.
fn request_words(req: &Request) -> String {
    match req {
        Request::Read { index, subindex } => format!("read index {index}/{subindex}"),
        Request::Write {
            index,
            subindex,
            data,
        } => format!("write index {index}/{subindex}: {}", to_hex(data)),
    }
}
