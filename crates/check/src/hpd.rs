//! HPD serial line checks (manual chapter 4, 4.1, 4.2, 3.8.1): framing, stuffing and
//! checksum; request/answer pairing; time-outs per the baud table when times are known;
//! answers consistent with the parameter memory the capture has shown; no answer to corrupt
//! messages or broadcasts; PLC uploads well formed.
//!
//! [`check`] is a pure function over [`SerialChunk`]s (style rule 12); [`HpdChecker`] is the
//! same as a push API. The line is decoded by `drivespec_hpd::LineDecoder` (bounded carry)
//! and paired by `drivespec_hpd::Pairer`; the checker keeps per drive address a shadow of
//! the parameter values written and acknowledged and the PLC bytes uploaded, so memory is
//! bounded by 32 addresses × (256 + 128) bytes plus one chunk. Nothing here panics.
//!
//! The parameter-memory check is conservative: a written value is expected back only for a
//! writable, non-`live` word parameter without write conditions or operating-mode ranges,
//! with the value inside its range, not written by the PLC program in force, while security
//! b99.7 is not known to be set; a write to Pb99 (commands) forgets every expectation.

use crate::error::SetupError;
use crate::report::{Catalog, Evidence, Policy, Recorder, Report, Stats, StreamStats, Where};
use drivespec_capture::serial::{Origin, SerialChunk, SerialError};
use drivespec_hpd::memory::ParamMap;
use drivespec_hpd::plc::{PlcCodec, PlcError, ProgramIssue};
use drivespec_hpd::{
    DiscardReason, Exchange, FrameError, FrameEvent, FrameRules, LineDecoder, LineEvent, Message,
    Mismatch, Pairer,
};
use drivespec_spec::hpd::Answer;
use drivespec_spec::{DataType, Family, FamilyId, Spec};
use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::sync::Arc;

/// Requirements the serial checker always checks (manual 4.1, 4.2, 3.2, 3.8.1).
const CHECKED: &[&str] = &[
    "HPD-FRAME-001",
    "HPD-FRAME-003",
    "HPD-FRAME-005",
    "HPD-FRAME-007",
    "HPD-FRAME-009",
    "HPD-FRAME-010",
    "HPD-FRAME-011",
    "HPD-FRAME-016",
    "HPD-FRAME-019",
    "HPD-FRAME-021",
    "HPD-FRAME-022",
    "HPD-SERIAL-001",
    "HPD-SERIAL-003",
    "HPD-SERIAL-012",
    "HPD-SERIAL-013",
    "HPD-SERIAL-017",
    "HPD-PAR-018",
    "HPD-PLC-003",
    "HPD-PLC-026",
    "HPD-PLC-030",
    "HPD-PLC-038",
    "HPD-PLC-039",
    "HPD-PLC-045",
];

/// Requirements checked when the message time-out is known (manual 4 table, 4.1).
const CHECKED_TIMEOUT: &[&str] = &["HPD-FRAME-020", "HPD-BAUD-002", "HPD-BAUD-003"];

/// Options of the serial checker.
#[derive(Debug, Clone, Default)]
pub struct HpdOptions {
    /// Line speed: a Pr26 code (0–10) or bits per second (manual 4 table); gives the
    /// message time-out, checked when the recording has times.
    pub baud: Option<u32>,
    /// Most violations listed (all are counted).
    pub max_violations: Option<u64>,
}

/// What a drive's shadow expects a parameter to read back.
#[derive(Debug, Clone)]
struct Expect {
    id: String,
    size: u8,
    raw: u32,
    at: Where,
}

/// What the checker knows of one drive address.
#[derive(Debug, Clone)]
struct DriveShadow {
    /// Expected values by serial address of the parameter.
    expect: BTreeMap<u8, Expect>,
    /// b99.7 (security) as last seen.
    secured: bool,
    /// b99.13 (PLC running) as last seen; None until seen.
    plc_running: Option<bool>,
    /// PLC area bytes uploaded or read.
    plc: Vec<Option<u8>>,
    /// An upload (PLC writes) is going on, started here.
    upload: Option<Where>,
    /// Address 0 was written in this upload.
    upload_from_zero: bool,
    /// Parameter numbers the PLC program in force writes.
    plc_writes: BTreeSet<u32>,
}

/// The HPD serial checker as a push API (see the module docs).
pub struct HpdChecker<'s> {
    family: &'s Family,
    rules: FrameRules,
    pairer: Pairer,
    decoder: LineDecoder,
    codec: Option<PlcCodec>,
    map: ParamMap,
    rec: Recorder,
    timeout: Option<u64>,
    answer_delay: Option<u64>,
    /// Line events so far.
    events: u64,
    /// The bytes of the current chunk and up to 64 before it, and the stream offset of the
    /// first.
    window: Vec<u8>,
    window_base: u64,
    /// Stream offsets where recent chunks began, with their origin.
    origins: VecDeque<(u64, Origin)>,
    /// The last line event was a discard (a corrupt or timed-out message).
    after_discard: Option<(bool, Where)>,
    /// The last request was a broadcast and nothing answered it yet.
    after_broadcast: bool,
    frames_seen: u64,
    times_known: bool,
    drives: BTreeMap<u8, DriveShadow>,
    default_plc_writes: BTreeSet<u32>,
    latency: Stats,
    unanswered: BTreeMap<u8, u64>,
    pr26_hint: Option<(u32, Where)>,
}

/// Serial address of parameter `n` and bit `y` (manual 4.2).
fn bit_addr(map: &ParamMap, n: u8, y: u8) -> Option<(u8, u8)> {
    map.bit(n, y).map(|b| (b.byte, b.mask))
}

/// Parameter number of a PLC effect (`b40.0`, `Pr5`).
fn effect_param(e: &str) -> Option<u32> {
    let digits: String = e
        .trim_start_matches(|c: char| c.is_ascii_alphabetic())
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    digits.parse().ok()
}

impl<'s> HpdChecker<'s> {
    /// A checker with the spec's HPD tables (manual 4.1, 4.2).
    pub fn new(spec: &'s Spec, options: &HpdOptions) -> Result<HpdChecker<'s>, SetupError> {
        let catalog = Arc::new(Catalog::new(spec)?);
        HpdChecker::with_catalog(spec, options, catalog)
    }

    /// Checks every item of `chunks` in order (see [`check`]) and gives the report.
    pub fn run<I>(mut self, chunks: I) -> Report
    where
        I: IntoIterator<Item = Result<SerialChunk, SerialError>>,
    {
        for item in chunks {
            match item {
                Ok(chunk) => self.push(&chunk),
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
        options: &HpdOptions,
        catalog: Arc<Catalog>,
    ) -> Result<HpdChecker<'s>, SetupError> {
        let family = spec.family(FamilyId::Hpd);
        let protocol = family.hpd().ok_or(drivespec_hpd::RulesError::NoProtocol)?;
        let rules = FrameRules::from_spec(spec)?;
        let pairer = Pairer::from_spec(spec)?;
        let mut decoder = LineDecoder::new(rules.clone());
        let mut rec = Recorder::new(catalog, "hpd", options.max_violations);
        rec.checks(CHECKED);
        let mut timeout = None;
        let mut answer_delay = None;
        if let Some(b) = options.baud {
            let rate = if b <= 10 {
                u8::try_from(b).ok().and_then(|c| protocol.baud_rate(c))
            } else {
                protocol.baud_rates.iter().find(|r| r.bps == b)
            };
            let Some(rate) = rate else {
                let known: Vec<String> = protocol
                    .baud_rates
                    .iter()
                    .map(|r| format!("{}={}", r.code, r.bps))
                    .collect();
                return Err(SetupError::Option {
                    option: "--baud",
                    reason: format!(
                        "{b} is neither a Pr26 code nor a bit rate of the baud table (manual 4): {}",
                        known.join(", ")
                    ),
                });
            };
            let t = u64::from(rate.timeout_ms) * 1000;
            decoder = decoder.with_timeout(t);
            timeout = Some(t);
            answer_delay = rate.answer_delay_ms.map(|d| u64::from(d) * 1000);
            rec.checks(CHECKED_TIMEOUT);
            if answer_delay.is_some() {
                rec.checks(&["HPD-BAUD-004"]);
            }
            rec.report().detection.push(format!(
                "line: Pr26 code {} = {} b/s, message time-out {} ms (manual 4 table)",
                rate.code, rate.bps, rate.timeout_ms
            ));
        }
        let codec = PlcCodec::from_spec(spec);
        let mut default_plc_writes = BTreeSet::new();
        if let Some(c) = &codec {
            let listing: Vec<&str> = protocol
                .default_program
                .iter()
                .map(|l| l.listing.as_str())
                .collect();
            if let Ok(p) = c.parse_listing(&listing.join("\n")) {
                default_plc_writes = c
                    .effects(&p)
                    .writes
                    .iter()
                    .filter_map(|e| effect_param(e))
                    .collect();
            }
        }
        Ok(HpdChecker {
            family,
            rules,
            pairer,
            decoder,
            codec,
            map: ParamMap::from_family(family),
            rec,
            timeout,
            answer_delay,
            events: 0,
            window: Vec::new(),
            window_base: 0,
            origins: VecDeque::new(),
            after_discard: None,
            after_broadcast: false,
            frames_seen: 0,
            times_known: false,
            drives: BTreeMap::new(),
            default_plc_writes,
            latency: Stats::default(),
            unanswered: BTreeMap::new(),
            pr26_hint: None,
        })
    }

    /// Feeds one chunk of the recording.
    pub fn push(&mut self, chunk: &SerialChunk) {
        let start = self.decoder.position();
        self.origins.push_back((start, chunk.origin));
        while self.origins.len() > 64 {
            self.origins.pop_front();
        }
        if chunk.time.is_some() {
            self.times_known = true;
        }
        // Keep 64 bytes of the previous chunks so that evidence of carried messages is there.
        let keep = self.window.len().saturating_sub(64);
        self.window.drain(..keep);
        self.window_base = start.saturating_sub(self.window.len() as u64);
        self.window.extend_from_slice(&chunk.bytes);
        let mut events = Vec::new();
        self.decoder
            .feed(&chunk.bytes, chunk.time, &mut |e| events.push(e));
        for e in events {
            self.line_event(e);
        }
    }

    /// Records that reading stopped with `error`; what was read is still checked.
    pub fn fail(&mut self, error: &SerialError) {
        let offset = match error {
            SerialError::Read(r) => Some(r.offset),
            _ => None,
        };
        self.rec.report().error = Some(crate::report::InputFault {
            message: error.to_string(),
            offset,
        });
    }

    /// Records a line the reader skipped (a malformed text line; reading went on).
    pub fn skipped(&mut self, error: &SerialError) {
        self.rec.report().count("unreadable line");
        self.rec.report().note(format!("skipped: {error}"));
    }

    /// The recording reads Pr26 = `code` at `at`: without `--baud`, the message time-outs
    /// of that line speed (manual 4 table) are checked from there on.
    fn line_speed_read(&mut self, code: u8, at: Where) {
        if self.timeout.is_some() || !self.times_known {
            return;
        }
        let Some(rate) = self.family.hpd().and_then(|p| p.baud_rate(code)) else {
            return;
        };
        let t = u64::from(rate.timeout_ms) * 1000;
        let decoder = std::mem::replace(&mut self.decoder, LineDecoder::new(self.rules.clone()));
        self.decoder = decoder.with_timeout(t);
        self.timeout = Some(t);
        self.answer_delay = rate.answer_delay_ms.map(|d| u64::from(d) * 1000);
        self.rec.checks(CHECKED_TIMEOUT);
        if self.answer_delay.is_some() {
            self.rec.checks(&["HPD-BAUD-004"]);
        }
        let line = format!(
            "line: Pr26 code {} = {} b/s, message time-out {} ms (manual 4 table), read from the recording at {at}: time-outs checked from there on",
            rate.code, rate.bps, rate.timeout_ms
        );
        self.rec.report().detection.push(line);
    }

    /// Ends the line and returns the report.
    pub fn finish(mut self) -> Report {
        let mut events = Vec::new();
        self.decoder.finish(&mut |e| events.push(e));
        for e in events {
            self.line_event(e);
        }
        let mut ex = Vec::new();
        self.pairer.flush(&mut |e| ex.push(e));
        for e in ex {
            self.exchange(e);
        }
        let addrs: Vec<u8> = self.drives.keys().copied().collect();
        for a in addrs {
            self.end_upload(a);
        }
        if self.timeout.is_none() {
            let hint = match self.pr26_hint {
                Some((code, at)) => {
                    format!(" (the capture reads Pr26 = {code} at {at}; pass --baud {code})")
                }
                None => String::new(),
            };
            self.rec.report().note(format!(
                "message time-outs not checked: line speed unknown, give --baud{hint}"
            ));
        } else if !self.times_known {
            self.rec
                .report()
                .note("message time-outs not checked: the recording has no times");
        }
        let unanswered: Vec<(u8, u64)> = self.unanswered.iter().map(|(a, n)| (*a, *n)).collect();
        for (a, n) in unanswered {
            self.rec.report().note(format!(
                "drive {a}: {n} request(s) without answer (lost, or no drive at that address)"
            ));
        }
        let events = self.events;
        self.rec.report().unreadable_lines(events);
        let latency = self.latency;
        let r = self.rec.report();
        r.events = events;
        if latency.count > 0 {
            r.streams.push(StreamStats {
                stream: "request → answer".into(),
                frames: latency.count,
                nominal_us: None,
                interval_us: latency.done(),
                jitter_us: None,
                missing: 0,
                gaps: 0,
            });
        }
        for (addr, _) in self.drives.iter() {
            r.drives.push(crate::report::DriveInfo {
                label: format!("drive {addr}"),
                family: "hpd".into(),
                found_by: "address".into(),
                confidence: 1.0,
                details: BTreeMap::from([("address".to_owned(), serde_json::Value::from(*addr))]),
            });
        }
        let r = self.rec.report();
        r.scope("HPD", Some("hpd"), None);
        r.judge(Policy::default());
        self.rec.finish()
    }

    /// Where the line event at stream `offset` and `time` happened.
    fn at(&self, offset: u64, time: Option<u64>) -> Where {
        let origin = self
            .origins
            .iter()
            .rev()
            .find(|(start, _)| *start <= offset)
            .map(|(_, o)| *o);
        let mut w = Where {
            event: self.events,
            offset: Some(offset),
            time,
            ..Where::default()
        };
        match origin {
            Some(Origin::Record(n)) => w.frame = Some(n),
            Some(Origin::Line(n)) => w.line = Some(n),
            _ => {}
        }
        w
    }

    /// The bytes at stream `offset`, at most `len` (and 32), when still in the window.
    fn bytes_at(&self, offset: u64, len: usize) -> &[u8] {
        let Some(start) = offset.checked_sub(self.window_base) else {
            return &[];
        };
        let start = usize::try_from(start).unwrap_or(usize::MAX);
        let end = start.saturating_add(len.min(32)).min(self.window.len());
        self.window.get(start..end).unwrap_or(&[])
    }

    fn frame_evidence(&self, f: &FrameEvent, request: Option<&Message>) -> Evidence {
        let e = drivespec_hpd::explain::explain(
            self.family,
            &self.rules,
            self.codec.as_ref(),
            &f.message,
            request,
        );
        Evidence::bytes(self.bytes_at(f.offset, f.len)).with("message", e.summary)
    }

    fn line_event(&mut self, e: LineEvent) {
        match e {
            LineEvent::Frame(f) => {
                self.rec.report().count(match f.message {
                    Message::Ack { .. } => "acknowledge",
                    m => m.kind().spec_name(),
                });
                self.request_checks(&f);
                let mut ex = Vec::new();
                self.pairer.push(f, &mut |x| ex.push(x));
                for x in ex {
                    self.exchange(x);
                }
                self.frames_seen += 1;
                self.after_discard = None;
                self.after_broadcast = matches!(f.message, Message::Broadcast { .. });
            }
            LineEvent::Discarded(d) => {
                self.rec.report().count("discarded");
                let at = self.at(d.offset, d.time);
                let ev = Evidence::bytes(self.bytes_at(d.offset, d.len)).with("length", d.len);
                let (id, timeout) = match d.reason {
                    DiscardReason::Invalid(e) => (frame_error_requirement(&e), false),
                    DiscardReason::Timeout { .. } => ("HPD-FRAME-020", true),
                    DiscardReason::Truncated => {
                        self.rec.report().note(format!(
                            "the recording ends inside a message ({} byte(s) at {at})",
                            d.len
                        ));
                        ("", false)
                    }
                };
                if !id.is_empty() {
                    self.rec.violation(
                        id,
                        "line",
                        at,
                        format!("{} byte(s) dropped: {}", d.len, d.reason),
                        ev,
                    );
                }
                // A new (corrupt) message began: a request still waiting gets no answer now.
                let mut ex = Vec::new();
                self.pairer.flush(&mut |x| ex.push(x));
                for x in ex {
                    self.exchange(x);
                }
                self.after_discard = Some((timeout, at));
            }
        }
        self.events += 1;
    }

    fn drive(&mut self, addr: u8) -> &mut DriveShadow {
        let area = self
            .codec
            .as_ref()
            .map_or(128, |c| usize::from(c.plc().area_bytes));
        let writes = self.default_plc_writes.clone();
        self.drives.entry(addr).or_insert_with(|| DriveShadow {
            expect: BTreeMap::new(),
            secured: false,
            plc_running: None,
            plc: vec![None; area],
            upload: None,
            upload_from_zero: false,
            plc_writes: writes,
        })
    }

    /// Checks a request when it is seen: PLC writes, and the end of an upload.
    fn request_checks(&mut self, f: &FrameEvent) {
        if !f.message.is_request() {
            return;
        }
        let addr = f.message.addr();
        if let Message::WritePlc { par, data, .. } = f.message {
            let at = self.at(f.offset, f.time);
            let area_first = self.codec.as_ref().map_or(0, |c| c.plc().first_address);
            let area = self.drive(addr).plc.len();
            let start = usize::from(par.saturating_sub(area_first));
            let len = usize::from(data.len());
            if par < area_first || start + len > area {
                let ev = self.frame_evidence(f, None);
                self.rec.violation(
                    "HPD-PLC-038",
                    &format!("drive {addr}"),
                    at,
                    format!("PLC write of {len} byte(s) at {par:#04x} reaches outside the area 0x00–0x7F"),
                    ev,
                );
                return;
            }
            if !(len == 2 || len == 4) || start % 2 != 0 {
                let ev = self.frame_evidence(f, None);
                self.rec.violation(
                    "HPD-FRAME-022",
                    &format!("drive {addr}"),
                    at,
                    format!("PLC write of {len} byte(s) at {par:#04x}: not whole 2- or 4-byte instructions"),
                    ev,
                );
            }
            let running = self.drive(addr).plc_running == Some(true);
            if running {
                self.rec.checks(&["HPD-BIT-99-13"]);
                let ev = self.frame_evidence(f, None);
                self.rec.violation(
                    "HPD-BIT-99-13",
                    &format!("drive {addr}"),
                    at,
                    "PLC instructions written while the PLC runs (b99.13 = 1): the drive ignores them",
                    ev,
                );
            }
            let d = self.drive(addr);
            if d.upload.is_none() {
                d.upload = Some(at);
                d.upload_from_zero = false;
            }
            if start == 0 {
                d.upload_from_zero = true;
            }
            for (i, b) in data.as_slice().iter().enumerate() {
                if let Some(slot) = d.plc.get_mut(start + i) {
                    *slot = Some(*b);
                }
            }
            return;
        }
        match f.message {
            Message::Broadcast { .. } => {
                let addrs: Vec<u8> = self.drives.keys().copied().collect();
                for a in addrs {
                    self.end_upload(a);
                }
            }
            _ => self.end_upload(addr),
        }
    }

    /// Checks the program of a finished upload (manual 3.8.1, 4.1).
    fn end_upload(&mut self, addr: u8) {
        let Some(d) = self.drives.get_mut(&addr) else {
            return;
        };
        let Some(at) = d.upload.take() else {
            return;
        };
        let from_zero = d.upload_from_zero;
        let bytes: Vec<u8> = d.plc.iter().map_while(|b| *b).collect();
        let Some(codec) = self.codec.clone() else {
            return;
        };
        let subject = format!("drive {addr}");
        if !from_zero {
            self.rec.report().note(format!(
                "{subject}: PLC upload at {at} does not start at address 0; the program was not checked"
            ));
            return;
        }
        let ev = Evidence::bytes(bytes.get(..bytes.len().min(32)).unwrap_or(&[]))
            .with("program_bytes", bytes.len());
        match codec.decode_program(&bytes) {
            Err(e) => {
                let id = match e {
                    PlcError::UnknownCode { .. } | PlcError::Operand { .. } => "HPD-PLC-039",
                    _ => "HPD-PLC-045",
                };
                self.rec
                    .violation(id, &subject, at, format!("uploaded PLC program: {e}"), ev);
            }
            Ok(program) => {
                for issue in codec.check(&program) {
                    let id = match issue {
                        ProgramIssue::FinIgnored { .. } => "HPD-PLC-030",
                        ProgramIssue::ByteOperand { .. } => "HPD-PLC-026",
                        ProgramIssue::NoEnd => "HPD-PLC-045",
                        ProgramIssue::TooManyInstructions { .. } => "HPD-PLC-003",
                    };
                    self.rec.violation(
                        id,
                        &subject,
                        at,
                        format!("uploaded PLC program: {issue}"),
                        ev.clone().with("listing", codec.format_program(&program)),
                    );
                }
                let writes: BTreeSet<u32> = codec
                    .effects(&program)
                    .writes
                    .iter()
                    .filter_map(|e| effect_param(e))
                    .collect();
                if let Some(d) = self.drives.get_mut(&addr) {
                    d.plc_writes = writes;
                }
            }
        }
    }

    fn exchange(&mut self, x: Exchange) {
        match x {
            Exchange::Answered { request, answer } => self.answered(&request, &answer),
            Exchange::Unanswered { request } => {
                self.rec.report().count("unanswered request");
                *self.unanswered.entry(request.message.addr()).or_insert(0) += 1;
            }
            Exchange::Broadcast { request } => {
                if let Message::Broadcast { par, data } = request.message {
                    let at = self.at(request.offset, request.time);
                    let addrs: Vec<u8> = self.drives.keys().copied().collect();
                    for a in addrs {
                        self.written(a, par, data.as_slice(), at);
                    }
                }
            }
            Exchange::Unexpected {
                answer,
                request,
                reason,
            } => self.unexpected(&answer, request.as_ref(), reason),
        }
    }

    fn unexpected(&mut self, answer: &FrameEvent, request: Option<&FrameEvent>, reason: Mismatch) {
        let at = self.at(answer.offset, answer.time);
        let addr = answer.message.addr();
        let subject = format!("drive {addr}");
        let ev = self.frame_evidence(answer, request.map(|r| &r.message));
        let (id, msg) = match reason {
            Mismatch::NoRequest if self.after_broadcast && self.after_discard.is_none() => {
                ("HPD-SERIAL-013", "answer to a broadcast".to_owned())
            }
            Mismatch::NoRequest => match self.after_discard {
                Some((true, d)) => (
                    "HPD-BAUD-003",
                    format!("answer to a message that was not complete within the time-out ({d})"),
                ),
                Some((false, d)) => (
                    "HPD-SERIAL-012",
                    format!("answer to a corrupt message ({d})"),
                ),
                None if self.frames_seen == 0 => {
                    self.rec.report().note(format!(
                        "the recording starts with an answer ({at}); not checked"
                    ));
                    return;
                }
                None => (
                    "HPD-SERIAL-001",
                    "the drive transmits without being interrogated (no request waiting)"
                        .to_owned(),
                ),
            },
            Mismatch::ToBroadcast => ("HPD-SERIAL-013", "answer to a broadcast".to_owned()),
            Mismatch::WrongDrive { expected, found } => (
                "HPD-SERIAL-003",
                format!("drive {found} answers a request addressed to drive {expected}"),
            ),
            Mismatch::WrongKind { expected, found } => (
                if expected == Answer::Ack {
                    "HPD-FRAME-011"
                } else {
                    "HPD-FRAME-010"
                },
                format!(
                    "{} where {} is due",
                    answer_words(found),
                    answer_words(expected)
                ),
            ),
        };
        self.rec.violation(id, &subject, at, msg, ev);
    }

    fn answered(&mut self, request: &FrameEvent, answer: &FrameEvent) {
        let at = self.at(answer.offset, answer.time);
        let addr = request.message.addr();
        let subject = format!("drive {addr}");
        if let (Some(t0), Some(t1)) = (request.time, answer.time) {
            let dt = t1.saturating_sub(t0);
            self.latency.add(dt as f64);
            if let Some(delay) = self.answer_delay {
                if dt < delay {
                    let ev = self.frame_evidence(answer, Some(&request.message));
                    self.rec.violation(
                        "HPD-BAUD-004",
                        &subject,
                        at,
                        format!(
                            "answer {dt} µs after the request; Pr26 = 4 delays answers by {} ms",
                            delay / 1000
                        ),
                        ev.with("delay_us", dt),
                    );
                }
            }
        }
        match (request.message, answer.message) {
            (Message::ReadParam { lun, par, .. }, Message::Response { par: p2, data, .. })
            | (Message::ReadPlc { lun, par, .. }, Message::Response { par: p2, data, .. }) => {
                if p2 != par || data.len() != lun {
                    let ev = self.frame_evidence(answer, Some(&request.message));
                    self.rec.violation(
                        "HPD-SERIAL-017",
                        &subject,
                        at,
                        format!(
                            "read of {lun} byte(s) at {par:#04x} answered with {} byte(s) at {p2:#04x}",
                            data.len()
                        ),
                        ev,
                    );
                    return;
                }
                if matches!(request.message, Message::ReadParam { .. }) {
                    self.read_back(addr, par, data.as_slice(), at, answer, &request.message);
                } else {
                    let first = self.codec.as_ref().map_or(0, |c| c.plc().first_address);
                    let d = self.drive(addr);
                    let start = usize::from(par.saturating_sub(first));
                    for (i, b) in data.as_slice().iter().enumerate() {
                        if let Some(slot) = d.plc.get_mut(start + i) {
                            *slot = Some(*b);
                        }
                    }
                }
            }
            (Message::WriteParam { par, data, .. }, _) => {
                let w = self.at(request.offset, request.time);
                self.written(addr, par, data.as_slice(), w);
            }
            (
                Message::BitChange {
                    par, mask, value, ..
                },
                _,
            ) => self.bit_changed(addr, par, mask, value),
            _ => {}
        }
    }

    /// The parameters of table 4.2 whose bytes `[par, par + len)` cover exactly.
    fn covered(&self, par: u8, len: usize) -> Vec<(&'s drivespec_spec::Parameter, u8, u8)> {
        let mut out = Vec::new();
        let mut at = usize::from(par);
        let end = at + len;
        while at < end {
            let Some(p) = u32::try_from(at)
                .ok()
                .and_then(|a| self.family.parameter_at_address(a))
            else {
                break;
            };
            let (Some(a), Some(s)) = (p.address, p.size) else {
                break;
            };
            let (Ok(a), Ok(s)) = (u8::try_from(a), u8::try_from(s)) else {
                break;
            };
            if usize::from(a) != at || at + usize::from(s) > end {
                break;
            }
            out.push((p, a, s));
            at += usize::from(s);
        }
        out
    }

    /// A write (or broadcast) the drive took: what it should read back.
    fn written(&mut self, addr: u8, par: u8, bytes: &[u8], at: Where) {
        let commands = self.map.slot(99).map(|s| s.addr);
        let params = self.covered(par, bytes.len());
        let security = bit_addr(&self.map, 99, 7);
        let plc_run = bit_addr(&self.map, 99, 13);
        let d = self.drive(addr);
        if params.is_empty() {
            // Bytes that are not whole parameters: forget what they overlap.
            let lo = u16::from(par);
            let hi = lo + u16::try_from(bytes.len()).unwrap_or(u16::MAX).min(256);
            d.expect
                .retain(|a, e| u16::from(*a) + u16::from(e.size) <= lo || u16::from(*a) >= hi);
            return;
        }
        let mut offset = 0usize;
        let mut expectations = Vec::new();
        for (p, a, s) in params {
            let raw = bytes
                .get(offset..offset + usize::from(s))
                .unwrap_or(&[])
                .iter()
                .rev()
                .fold(0u32, |v, b| v << 8 | u32::from(*b));
            offset += usize::from(s);
            if Some(a) == commands {
                // Commands (b99.x) may restore or load every parameter.
                d.expect.clear();
                if let Some((byte, mask)) = security {
                    if byte == a {
                        d.secured = raw as u8 & mask != 0;
                    }
                }
                if let Some((byte, mask)) = plc_run {
                    if byte == a.wrapping_add(1) {
                        d.plc_running = Some((raw >> 8) as u8 & mask != 0);
                    }
                }
                continue;
            }
            d.expect.remove(&a);
            expectations.push((p, a, s, raw));
        }
        for (p, a, s, raw) in expectations {
            let d = self.drive(addr);
            if d.secured || d.plc_writes.contains(&p.number) {
                continue;
            }
            let bits = matches!(
                p.data_type,
                DataType::Bits8 | DataType::Bits16 | DataType::Bits32
            );
            if !p.access.writable()
                || p.live
                || bits
                || !p.modes.is_empty()
                || !p.conditions.is_empty()
                || p.range_model
            {
                continue;
            }
            let value = signed(p.data_type, raw);
            let in_range = self
                .family
                .resolve(p, None)
                .range
                .is_none_or(|r| r.contains(value));
            if !in_range {
                continue;
            }
            self.drive(addr).expect.insert(
                a,
                Expect {
                    id: p.id.clone(),
                    size: s,
                    raw,
                    at,
                },
            );
        }
    }

    /// A bit change the drive took.
    fn bit_changed(&mut self, addr: u8, par: u8, mask: u8, value: u8) {
        let security = bit_addr(&self.map, 99, 7);
        let plc_run = bit_addr(&self.map, 99, 13);
        let commands = self.map.slot(99);
        let d = self.drive(addr);
        if let Some((byte, m)) = security {
            if byte == par && mask & m == 0 {
                d.secured = value & m != 0;
            }
        }
        if let Some((byte, m)) = plc_run {
            if byte == par && mask & m == 0 {
                d.plc_running = Some(value & m != 0);
            }
        }
        if let Some(s) = commands {
            if (s.addr..s.addr.saturating_add(s.size)).contains(&par) {
                d.expect.clear();
                return;
            }
        }
        d.expect
            .retain(|a, e| !(*a..a.saturating_add(e.size)).contains(&par));
    }

    /// A read answer: compare with what was written, learn b99.7, b99.13 and Pr26.
    fn read_back(
        &mut self,
        addr: u8,
        par: u8,
        bytes: &[u8],
        at: Where,
        answer: &FrameEvent,
        request: &Message,
    ) {
        let security = bit_addr(&self.map, 99, 7);
        let plc_run = bit_addr(&self.map, 99, 13);
        let pr26 = self.map.slot(26);
        let byte_at = |a: u8| -> Option<u8> {
            a.checked_sub(par)
                .and_then(|i| bytes.get(usize::from(i)))
                .copied()
        };
        if let Some(s) = pr26 {
            if let Some(b) = byte_at(s.addr) {
                if self.pr26_hint.is_none() {
                    self.pr26_hint = Some((u32::from(b), at));
                    self.line_speed_read(b, at);
                }
            }
        }
        let mut mismatches = Vec::new();
        {
            let d = self.drive(addr);
            if let Some((byte, m)) = security {
                if let Some(b) = byte_at(byte) {
                    d.secured = b & m != 0;
                }
            }
            if let Some((byte, m)) = plc_run {
                if let Some(b) = byte_at(byte) {
                    d.plc_running = Some(b & m != 0);
                }
            }
            let end = usize::from(par) + bytes.len();
            for (a, e) in d.expect.iter() {
                if usize::from(*a) < usize::from(par) || usize::from(*a) + usize::from(e.size) > end
                {
                    continue;
                }
                let i = usize::from(*a - par);
                let raw = bytes
                    .get(i..i + usize::from(e.size))
                    .unwrap_or(&[])
                    .iter()
                    .rev()
                    .fold(0u32, |v, b| v << 8 | u32::from(*b));
                if raw != e.raw {
                    mismatches.push((*a, e.clone(), raw));
                }
            }
            for (a, _, _) in &mismatches {
                d.expect.remove(a);
            }
        }
        for (_, e, raw) in mismatches {
            let ev = self
                .frame_evidence(answer, Some(request))
                .with("parameter", e.id.clone())
                .with("written", e.raw)
                .with("read", raw);
            self.rec.violation(
                "HPD-PAR-018",
                &format!("drive {addr}"),
                at,
                format!(
                    "{} reads {raw}, but {} was written and acknowledged at {}",
                    e.id, e.raw, e.at
                ),
                ev,
            );
        }
    }
}

/// A raw value as the parameter's signed type.
fn signed(t: DataType, raw: u32) -> i64 {
    match t {
        DataType::I8 => i64::from(raw as u8 as i8),
        DataType::I16 => i64::from(raw as u16 as i16),
        DataType::I32 => i64::from(raw as i32),
        _ => i64::from(raw),
    }
}

/// The requirement a framing error breaks (manual 4.1).
fn frame_error_requirement(e: &FrameError) -> &'static str {
    match e {
        FrameError::Stuffing { .. } => "HPD-FRAME-003",
        FrameError::ZeroCmdAddr => "HPD-FRAME-005",
        FrameError::UnknownCmd { .. } => "HPD-FRAME-021",
        FrameError::Lun { .. } => "HPD-FRAME-007",
        FrameError::LengthMismatch { .. } => "HPD-FRAME-016",
        FrameError::BroadcastAddr { .. } => "HPD-FRAME-019",
        FrameError::Checksum { .. } => "HPD-FRAME-009",
        _ => "HPD-FRAME-001",
    }
}

/// Checks a serial recording (style rule 12): every chunk in order; a reader error ends the
/// stream (recorded in [`Report::error`]) unless the reader goes on after it (a bad text line).
pub fn check<I>(spec: &Spec, options: &HpdOptions, chunks: I) -> Result<Report, SetupError>
where
    I: IntoIterator<Item = Result<SerialChunk, SerialError>>,
{
    Ok(HpdChecker::new(spec, options)?.run(chunks))
}

/// Whether the serial reader goes on after this error (module doc of `capture::serial`).
pub fn continues(e: &SerialError) -> bool {
    matches!(
        e,
        SerialError::Line(_)
            | SerialError::Socat { .. }
            | SerialError::Text { .. }
            | SerialError::LinkType { .. }
            | SerialError::RtacHeader { .. }
    )
}

/// An answer kind in words (manual 4.1 table).
fn answer_words(a: Answer) -> &'static str {
    match a {
        Answer::None => "no answer",
        Answer::Data => "a data answer",
        Answer::Ack => "a short acknowledge",
    }
}
