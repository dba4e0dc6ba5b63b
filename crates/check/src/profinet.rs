//! PROFINET captures: generic checks any PROFINET user wants (IEC 61158-6-10: cycle counter
//! progression per stream against the send clock, DataStatus and TransferStatus, IOPS and
//! IOCS, frame lengths, gaps and jitter as statistics) and the PSD4xx checks
//! ([`crate::psd4xx`]) on every PSD4xx found ([`crate::locate`]).
//!
//! [`check`] is a pure function over `drivespec_capture::profinet::PnEvent`s (style rule
//! 12); [`PnChecker`] is the same as a push API. Memory is bounded whatever the capture size:
//! at most [`MAX_STREAMS`] streams, [`MAX_ARS`] application relations,
//! [`SEARCH_FRAMES`] buffered frames for the search, one C_SDU per stream to watch for
//! changes between search batches, [`MAX_STREAMS`] pairs of stations that ended an AR and
//! the bounded state of [`crate::pn_events`]; everything else is per stream or per drive. Nothing here
//! panics.
//!
//! Conditions are reported when they start (a transition), not on every frame: a provider
//! that goes to STOP for an hour is one finding, with the frame where it began. States the
//! standard allows (a provider in STOP from its first frame, bad IOPS while the provider is
//! in STOP) are listed as allowed states with their start and end.

use crate::error::SetupError;
use crate::locate::{self, Binding, Buffered, StreamKey};
use crate::pn_events::{mac, Frame, PnEvents};
use crate::pnio_names::PnioNames;
use crate::psd4xx::{PsdDrive, PsdOptions};
use crate::report::{
    Catalog, DriveInfo, Evidence, InputFault, Policy, Recorder, Report, Stats, StreamStats, Where,
};
use drivespec_capture::dcerpc::Uuid;
use drivespec_capture::link::LinkError;
use drivespec_capture::pcap::CaptureError;
use drivespec_capture::pnio::{
    Block, CmMessage, ControlKind, Direction, IocrBlockReq, Operation, PnioStatus,
};
use drivespec_capture::profinet::{Counts, MalformedError, Pdu, PduError, PnEvent, PnEventKind};
use drivespec_capture::rt::{ApduStatus, FrameClass, RtError, RtFrame};
use drivespec_psd4xx::model::{Drive, DriveConfig};
use drivespec_psd4xx::{Input, Output, Rules};
use drivespec_spec::{FamilyId, Spec};
use serde_json::json;
use std::collections::{BTreeMap, HashMap, VecDeque};
use std::sync::Arc;

/// Most cyclic streams tracked; frames of further streams are counted only.
pub const MAX_STREAMS: usize = 1024;
/// Most application relations (Connects) remembered.
pub const MAX_ARS: usize = 64;
/// Cyclic frames buffered for the PSD4xx search.
pub const SEARCH_FRAMES: usize = 4000;
/// Capture time (µs) after the first cyclic frame within which the search buffers frames.
pub const SEARCH_US: u64 = 10_000_000;

/// Why a provider in STOP from its first frame is no violation of PN-RT-DS-002.
const STARTUP_STOP: &str = "start-up: a provider reports STOP (DataStatus.ProviderState = 0) until its application runs; an IO controller sends STOP from its first cyclic frame until its program runs after ApplicationReady (IEC 61158-6-10 APDU_Status DataStatus bit 4)";

/// Why a provider that goes from RUN to STOP and stays there until its AR is released is no
/// violation of PN-RT-DS-002.
const SHUTDOWN_STOP: &str = "shut-down: an IO controller goes to STOP (DataStatus.ProviderState = 0) and then releases the AR; STOP is an operating state of the provider (IEC 61158-6-10 APDU_Status DataStatus bit 4) whose device behaviour bus description 3.9 gives (CPU in \"Stop\" state)";

/// Why a bad IOPS of a provider in STOP is no violation of PN-IO-IOPS-001.
const BAD_IN_STOP: &str = "a provider in STOP marks its data bad (IOPS = Bad: CPU in \"Stop\" state, bus description 3.9; IEC 61158-6-10 IOxS)";

/// Send intervals without a frame after which a stream with no Connect counts as stopped
/// (the least DataHoldFactor, IEC 61158-6-10 IOCRBlockReq).
const STOP_CYCLES: u64 = 3;

/// Capture time (µs) after a Connect request without which its missing answer is not
/// reported (the capture may end before the device could answer).
const CONNECT_ANSWER_US: u64 = 1_000_000;

/// µs per cycle counter unit (IEC 61158-6-10: 31.25 µs).
const COUNT_NS: u64 = 31_250;

/// The generic requirements checked on every capture.
const CHECKED: &[&str] = &[
    "PN-ALARM-002",
    "PN-AR-001",
    "PN-CM-003",
    "PN-DCP-001",
    "PN-DCP-002",
    "PN-DCP-003",
    "PN-RT-CC-001",
    "PN-RT-CC-002",
    "PN-RT-CC-003",
    "PN-RT-DS-001",
    "PN-RT-DS-002",
    "PN-RT-DS-003",
    "PN-RT-DS-004",
    "PN-RT-TS-001",
    "PN-FRAME-001",
    "PN-CM-001",
    "PN-CM-002",
];

/// Requirements checked when a Connect describes the streams.
const CHECKED_CONNECT: &[&str] = &[
    "PN-RT-LEN-001",
    "PN-RT-WD-001",
    "PN-IO-IOPS-001",
    "PN-IO-IOCS-001",
];

/// Where the PSD4xx process data are, given by options (`--frame-id`, `--offset`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Manual {
    /// FrameID of the frames with the output module.
    pub out_frame: u16,
    /// FrameID of the frames with the input module.
    pub in_frame: u16,
    /// Offset of the output module in its C_SDU.
    pub out_offset: usize,
    /// Offset of the input module in its C_SDU.
    pub in_offset: usize,
}

/// Options of the PROFINET checker.
#[derive(Debug, Clone)]
pub struct PnOptions {
    /// Most violations listed (all are counted).
    pub max_violations: Option<u64>,
    /// PSD4xx checks.
    pub psd: PsdOptions,
    /// PSD4xx process data at fixed places instead of the Connect or the search.
    pub manual: Option<Manual>,
    /// Module or submodule ident number of the PSD4xx (instead of the module lengths).
    pub module_ident: Option<u32>,
    /// Search the cyclic frames for PSD4xx process data when no Connect describes them.
    pub search: bool,
    /// The input can be read a second time: a drive the search finds late is checked from
    /// the capture's start in a second pass ([`PnChecker::replay_pdu`]) instead of from the
    /// frames buffered when it was found.
    pub rescan: bool,
}

impl Default for PnOptions {
    fn default() -> PnOptions {
        PnOptions {
            max_violations: None,
            psd: PsdOptions::default(),
            manual: None,
            module_ident: None,
            search: true,
            rescan: false,
        }
    }
}

/// What a Connect says about one IOCR.
#[derive(Debug, Clone)]
struct IocrInfo {
    frame_id: u16,
    src: Option<[u8; 6]>,
    data_length: usize,
    increment: u16,
    watchdog_us: Option<u64>,
    /// (label, offset) of IOPS and IOCS bytes.
    iops: Vec<(String, usize)>,
    iocs: Vec<(String, usize)>,
}

/// One cyclic stream.
#[derive(Debug, Clone)]
struct Stream {
    label: String,
    frames: u64,
    last: Option<(u16, u64, Where)>,
    increment: Option<u16>,
    learning: Vec<u16>,
    interval: Stats,
    jitter: Stats,
    missing: u64,
    gaps: u64,
    info: Option<IocrInfo>,
    valid_seen: bool,
    invalid: bool,
    stop: bool,
    /// The provider has been in RUN: a STOP after it is a finding, before it start-up.
    run_seen: bool,
    /// The listed start-up STOP, to be ended when the provider goes to RUN.
    stop_allowed: Option<usize>,
    /// A STOP after RUN not judged yet: a violation when the provider goes back to RUN or
    /// the capture ends, an allowed state when the AR is released first.
    stop_pending: Option<(Where, Evidence)>,
    /// IOxS offsets whose bad value is listed as allowed (provider in STOP), to be ended.
    iox_allowed: Vec<(usize, Option<usize>)>,
    /// Listed violations of the open conditions (DS-001, DS-003, DS-004, TS-001, LEN-001),
    /// to be ended.
    open: [Option<usize>; 5],
    problem: bool,
    reserved: bool,
    transfer: bool,
    short: bool,
    iox: HashMap<usize, bool>,
}

/// An application relation from a Connect request, completed by the response.
#[derive(Debug, Clone)]
struct Ar {
    activity: Uuid,
    ar_uuid: Uuid,
    initiator: [u8; 6],
    responder: Option<[u8; 6]>,
    request: CmMessage,
    response: Option<CmMessage>,
    /// A Connect response (accepting or refusing) was seen.
    answered: bool,
    applied: bool,
    at: Where,
}

/// A located drive and its bindings.
struct Located<'s> {
    drive: PsdDrive<'s>,
    out: Binding,
    inp: Binding,
    ar: Option<Uuid>,
    slot: Option<(u16, u16, u16)>,
    info: DriveInfo,
}

/// Where a frame came from: record number, time and MAC addresses.
#[derive(Debug, Clone, Copy)]
struct Origin {
    record: u64,
    time: Option<u64>,
    src: Option<[u8; 6]>,
    dst: Option<[u8; 6]>,
}

/// A pending record request.
#[derive(Debug, Clone, Copy)]
struct PendingRecord {
    drive: usize,
    write: bool,
    index: u16,
}

/// The PROFINET checker as a push API (see the module docs).
pub struct PnChecker<'s> {
    spec: &'s Spec,
    rules: Arc<Rules>,
    options: PnOptions,
    rec: Recorder,
    events: u64,
    streams: Vec<(StreamKey, Stream)>,
    stream_index: HashMap<StreamKey, usize, BuildFx>,
    ars: VecDeque<Ar>,
    iocrs: Vec<IocrInfo>,
    drives: Vec<Located<'s>>,
    search: Option<Vec<Buffered>>,
    search_start: Option<u64>,
    /// Batches searched without finding anything.
    batches: u64,
    /// Cyclic frames searched without finding anything.
    searched: u64,
    /// After a fruitless batch: the last C_SDU of each stream; the next batch starts when
    /// one changes (an idle drive starts to move or to talk).
    watch: HashMap<StreamKey, Vec<u8>, BuildFx>,
    /// Drives found in a later batch, to be checked from the capture's start in a second
    /// pass over the input.
    late: Vec<locate::Found>,
    /// Where the first of the late drives was found.
    late_at: Option<Where>,
    pending_records: HashMap<(Uuid, u16), PendingRecord>,
    cyclic_frames: u64,
    connects_without_psd: u64,
    first_without_psd: Option<Where>,
    /// Alarms, DCP conflicts and Sets.
    pn_events: PnEvents,
    /// The latest capture time seen.
    last_time: Option<u64>,
    /// When the stations of an AR (either order) last released or aborted it.
    ended: HashMap<([u8; 6], [u8; 6]), u64>,
}

/// A fast hasher for stream keys (FxHash's multiply-rotate; keys come from the capture, and
/// the map is bounded by [`MAX_STREAMS`], so a collision flood costs little).
#[derive(Debug, Clone, Copy, Default)]
struct Fx(u64);

impl std::hash::Hasher for Fx {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 =
                (self.0.rotate_left(5) ^ u64::from(*b)).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
        }
    }

    fn write_u16(&mut self, v: u16) {
        self.0 = (self.0.rotate_left(5) ^ u64::from(v)).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
}

/// Builds [`Fx`] hashers.
#[derive(Debug, Clone, Copy, Default)]
struct BuildFx;

impl std::hash::BuildHasher for BuildFx {
    type Hasher = Fx;

    fn build_hasher(&self) -> Fx {
        Fx::default()
    }
}

impl<'s> PnChecker<'s> {
    /// A checker with the spec's PSD4xx tables.
    pub fn new(spec: &'s Spec, options: PnOptions) -> Result<PnChecker<'s>, SetupError> {
        let catalog = Arc::new(Catalog::new(spec)?);
        PnChecker::with_catalog(spec, options, catalog)
    }

    /// Checks every item of `events` in order (see [`check`]) and gives the report.
    pub fn run<I>(mut self, events: I) -> Report
    where
        I: IntoIterator<Item = Result<PnEvent, CaptureError>>,
    {
        for item in events {
            match item {
                Ok(ev) => self.push(&ev),
                Err(e) => {
                    self.fail(&e);
                    break;
                }
            }
        }
        self.finish(None)
    }

    /// A checker sharing a catalogue.
    pub fn with_catalog(
        spec: &'s Spec,
        options: PnOptions,
        catalog: Arc<Catalog>,
    ) -> Result<PnChecker<'s>, SetupError> {
        let rules = Arc::new(Rules::from_spec(spec)?);
        if let Some(m) = &options.psd.model {
            if spec.family(FamilyId::Psd4xx).model(m).is_none() {
                let known: Vec<&str> = spec
                    .family(FamilyId::Psd4xx)
                    .models
                    .iter()
                    .map(|m| m.id.as_str())
                    .collect();
                return Err(SetupError::Option {
                    option: "--model",
                    reason: format!("unknown PSD4xx model {m:?}; known: {}", known.join(", ")),
                });
            }
        }
        let mut rec = Recorder::new(catalog, "psd4xx", options.max_violations);
        rec.checks(CHECKED);
        let mut c = PnChecker {
            spec,
            rules,
            rec,
            events: 0,
            streams: Vec::new(),
            stream_index: HashMap::with_hasher(BuildFx),
            ars: VecDeque::new(),
            iocrs: Vec::new(),
            drives: Vec::new(),
            search: (options.search && options.manual.is_none()).then(Vec::new),
            search_start: None,
            batches: 0,
            searched: 0,
            watch: HashMap::with_hasher(BuildFx),
            late: Vec::new(),
            late_at: None,
            pending_records: HashMap::new(),
            cyclic_frames: 0,
            connects_without_psd: 0,
            first_without_psd: None,
            pn_events: PnEvents::new(PnioNames::shared()?),
            last_time: None,
            ended: HashMap::new(),
            options,
        };
        if let Some(m) = c.options.manual {
            let out = Binding {
                frame_id: m.out_frame,
                src: None,
                offset: m.out_offset,
                iops: None,
            };
            let inp = Binding {
                frame_id: m.in_frame,
                src: None,
                offset: m.in_offset,
                iops: None,
            };
            let details = BTreeMap::from([
                (
                    "out_frame_id".to_owned(),
                    json!(format!("{:#06x}", m.out_frame)),
                ),
                ("out_offset".to_owned(), json!(m.out_offset)),
                (
                    "in_frame_id".to_owned(),
                    json!(format!("{:#06x}", m.in_frame)),
                ),
                ("in_offset".to_owned(), json!(m.in_offset)),
            ]);
            c.add_drive(out, inp, None, "options", 1.0, details);
        }
        Ok(c)
    }

    fn add_drive(
        &mut self,
        out: Binding,
        inp: Binding,
        ar: Option<(Uuid, (u16, u16, u16))>,
        found_by: &str,
        confidence: f64,
        details: BTreeMap<String, serde_json::Value>,
    ) {
        if self.drives.is_empty() {
            self.rec.checks(crate::psd4xx::CHECKED);
        }
        let n = self.drives.len() + 1;
        let slot = ar.map(|(_, s)| s);
        let ar = ar.map(|(a, _)| a);
        let label = match slot {
            Some((_, s, sub)) => format!("PSD4xx #{n} (slot {s}, subslot {sub})"),
            None => format!(
                "PSD4xx #{n} (frames {:#06x}@{} / {:#06x}@{})",
                out.frame_id, out.offset, inp.frame_id, inp.offset
            ),
        };
        let family = self.spec.family(FamilyId::Psd4xx);
        let model = self
            .options
            .psd
            .model
            .as_deref()
            .and_then(|m| family.model(m));
        let model_id = model.map_or_else(
            || {
                family
                    .models
                    .first()
                    .map_or(String::new(), |m| m.id.clone())
            },
            |m| m.id.clone(),
        );
        let oracle = Drive::new(self.spec, DriveConfig::new(&model_id)).ok();
        let drive = PsdDrive::new(
            &label,
            family,
            self.rules.clone(),
            model,
            oracle,
            self.options.psd.clone(),
        );
        self.drives.push(Located {
            drive,
            out,
            inp,
            ar,
            slot,
            info: DriveInfo {
                label,
                family: "psd4xx".into(),
                found_by: found_by.into(),
                confidence,
                details,
            },
        });
    }

    fn at(&self, ev: &Origin) -> Where {
        Where {
            event: self.events,
            frame: Some(ev.record),
            time: ev.time,
            ..Where::default()
        }
    }

    /// Takes the next event of the capture.
    pub fn push(&mut self, ev: &PnEvent) {
        let o = Origin {
            record: ev.record,
            time: ev.time,
            src: ev.src,
            dst: ev.dst,
        };
        self.saw_time(ev.time);
        match &ev.kind {
            PnEventKind::Cyclic {
                frame_id,
                data,
                apdu,
            } => self.push_cyclic(&o, frame_id.0, data, *apdu),
            PnEventKind::Acyclic { frame_id, body, .. } => self.push_acyclic(
                &o,
                &RtFrame {
                    frame_id: *frame_id,
                    body,
                },
            ),
            PnEventKind::Cm {
                message, header, ..
            } => self.push_cm(&o, header.activity, message),
            PnEventKind::RpcOther { .. } => self.push_other(&o, "rpc-other"),
            PnEventKind::Malformed { error } => self.push_malformed(&o, error),
            _ => self.push_other(&o, "other"),
        }
    }

    /// Takes one decoded frame without copying it (`Decoder::decode` of a capture record):
    /// the same as [`PnChecker::push`] of the event `drivespec_capture::profinet::Events`
    /// would make of it, for the hot path of large captures.
    pub fn push_pdu(&mut self, record: u64, time: Option<u64>, pdu: &Result<Pdu<'_>, PduError>) {
        let (src, dst) = match pdu {
            Ok(Pdu::Rt { link, .. } | Pdu::Rpc { link, .. } | Pdu::Other { link }) => {
                (link.src, link.dst)
            }
            Err(_) => (None, None),
        };
        let o = Origin {
            record,
            time,
            src,
            dst,
        };
        self.saw_time(time);
        match pdu {
            Ok(Pdu::Rt { frame, .. }) => match frame.cyclic() {
                Ok(c) => self.push_cyclic(&o, c.frame_id.0, c.data, c.apdu),
                Err(RtError::WrongClass { .. }) => self.push_acyclic(&o, frame),
                Err(e) => self.push_malformed(&o, &MalformedError::Frame(PduError::Rt(e))),
            },
            Ok(Pdu::Rpc {
                packet, message, ..
            }) => match message {
                Some(Ok(m)) => self.push_cm(&o, packet.header.activity, m),
                Some(Err(e)) => self.push_malformed(&o, &MalformedError::Cm(*e)),
                None if packet.header.is_fragment()
                    && !packet.header.is_last_fragment()
                    && packet.header.interface.is_pnio_interface() => {}
                None => self.push_other(&o, "rpc-other"),
            },
            Ok(Pdu::Other { .. }) | Err(PduError::Link(LinkError::Unsupported(_))) => {}
            Err(e) => self.push_malformed(&o, &MalformedError::Frame(*e)),
        }
    }

    fn push_cyclic(&mut self, o: &Origin, frame_id: u16, data: &[u8], apdu: ApduStatus) {
        self.cyclic_frames += 1;
        self.cyclic(o, frame_id, data, apdu);
        self.events += 1;
    }

    fn saw_time(&mut self, time: Option<u64>) {
        if let Some(t) = time {
            self.last_time = Some(self.last_time.map_or(t, |l| l.max(t)));
        }
    }

    fn push_acyclic(&mut self, o: &Origin, frame: &RtFrame<'_>) {
        let class = frame.class();
        if let (Some(src), Some(dst)) = (o.src, o.dst) {
            let f = Frame {
                at: self.at(o),
                src,
                dst,
            };
            if let Ok(h) = frame.alarm() {
                let (ar, since) = self.ar_between(src, dst).unzip();
                let closed = match (self.ended.get(&pair(src, dst)), since.flatten()) {
                    (Some(e), Some(c)) => *e >= c,
                    (Some(_), None) => true,
                    (None, _) => false,
                };
                if h.pdu_type & 0x0f == 4 {
                    if let Some(t) = o.time {
                        self.end_ar(src, dst, t);
                    }
                }
                self.pn_events.alarm(&mut self.rec, &f, &h, ar, closed);
            } else if let Ok(h) = frame.dcp() {
                let ar = self.running_ar_of(dst, o.time);
                self.pn_events.dcp(&mut self.rec, &f, &h, ar);
            }
        }
        let kind = if class.is_dcp() {
            "dcp"
        } else if class.is_ptcp() {
            "ptcp"
        } else {
            match class {
                FrameClass::AlarmHigh | FrameClass::AlarmLow => "alarm",
                _ => "rt-other",
            }
        };
        self.rec.report().count(kind);
        self.events += 1;
    }

    fn push_cm(&mut self, o: &Origin, activity: Uuid, m: &CmMessage) {
        self.rec.report().count("pnio-cm");
        self.cm(o, activity, m);
        self.events += 1;
    }

    fn push_other(&mut self, _o: &Origin, kind: &str) {
        self.rec.report().count(kind);
        self.events += 1;
    }

    fn push_malformed(&mut self, o: &Origin, error: &MalformedError) {
        self.rec.report().count("malformed");
        let at = self.at(o);
        let id = match error {
            MalformedError::Cm(_) => "PN-CM-001",
            MalformedError::Frame(PduError::Rpc(_)) => "PN-CM-001",
            _ => "PN-FRAME-001",
        };
        let subject = match (o.src, o.dst) {
            (Some(s), Some(d)) => format!("{} → {}", mac(&s), mac(&d)),
            _ => "capture".into(),
        };
        self.rec
            .violation(id, &subject, at, error.to_string(), Evidence::none());
        self.events += 1;
    }

    // ------------------------------------------------------------------ cyclic frames

    fn cyclic(&mut self, ev: &Origin, frame_id: u16, data: &[u8], apdu: ApduStatus) {
        let key: StreamKey = (frame_id, ev.src.unwrap_or([0; 6]), ev.dst.unwrap_or([0; 6]));
        let at = self.at(ev);
        let idx = match self.stream_index.get(&key) {
            Some(i) => *i,
            None => {
                if self.streams.len() >= MAX_STREAMS {
                    self.rec.report().count("untracked cyclic");
                    return;
                }
                let info = self.iocr_for(&key);
                let label = format!("{frame_id:#06x} {} → {}", mac(&key.1), mac(&key.2));
                self.streams.push((
                    key,
                    Stream {
                        label,
                        frames: 0,
                        last: None,
                        increment: info.as_ref().map(|i| i.increment),
                        learning: Vec::new(),
                        interval: Stats::default(),
                        jitter: Stats::default(),
                        missing: 0,
                        gaps: 0,
                        info,
                        valid_seen: false,
                        invalid: false,
                        stop: false,
                        run_seen: false,
                        stop_allowed: None,
                        stop_pending: None,
                        iox_allowed: Vec::new(),
                        open: [None; 5],
                        problem: false,
                        reserved: false,
                        transfer: false,
                        short: false,
                        iox: HashMap::new(),
                    },
                ));
                self.stream_index.insert(key, self.streams.len() - 1);
                self.streams.len() - 1
            }
        };
        let mut found = Vec::new();
        let mut label = String::new();
        if let Some((_, s)) = self.streams.get_mut(idx) {
            stream_frame(s, &at, data, apdu, &mut found, &mut self.rec);
            if !found.is_empty() {
                label = s.label.clone();
            }
        }
        for (id, msg, e) in found {
            self.rec.violation(id, &label, at, msg, e);
        }
        // PSD4xx images in this frame.
        let olen = Output::buffer_len(&self.rules);
        let ilen = Input::buffer_len(&self.rules);
        // Bus description 3.9: with IOPS bad (CPU in STOP) the drive keeps the last valid
        // outputs, so such an output image is not one the drive acts on.
        let valid = apdu.data_status.provider_run() && apdu.data_status.data_valid();
        for d in self.drives.iter_mut() {
            if d.out.matches(&key) && valid && output_good(&d.out, data) {
                if let Some(w) = data.get(d.out.offset..d.out.offset + olen) {
                    d.drive.output(&mut self.rec, at, w);
                }
            }
            if d.inp.matches(&key) {
                if let Some(w) = data.get(d.inp.offset..d.inp.offset + ilen) {
                    d.drive.input(&mut self.rec, at, w);
                }
            }
        }
        self.buffer_for_search(key, data, at, valid);
    }

    fn buffer_for_search(&mut self, key: StreamKey, data: &[u8], at: Where, valid: bool) {
        let Some(buf) = self.search.as_mut() else {
            return;
        };
        if buf.is_empty() && self.batches > 0 {
            // Between batches: wait until a stream's data change.
            let changed = match self.watch.get_mut(&key) {
                Some(last) if last.as_slice() == data => false,
                Some(last) => {
                    last.clear();
                    last.extend_from_slice(data);
                    true
                }
                None => {
                    if self.watch.len() < MAX_STREAMS {
                        self.watch.insert(key, data.to_vec());
                    }
                    false
                }
            };
            if !changed {
                return;
            }
            self.search_start = None;
        }
        if let Some(t) = at.time {
            self.search_start.get_or_insert(t);
        }
        let elapsed = match (self.search_start, at.time) {
            (Some(s), Some(t)) => t.saturating_sub(s),
            _ => 0,
        };
        buf.push(Buffered {
            key,
            data: data.to_vec(),
            at,
            valid,
        });
        if buf.len() >= SEARCH_FRAMES || elapsed >= SEARCH_US {
            self.run_search();
        }
    }

    /// Searches the buffered frames (a batch); the drives found are checked from the
    /// capture's start: by replaying the buffer when it is the capture's first batch,
    /// else in a second pass when the input allows it ([`PnOptions::rescan`]), else from
    /// the batch on.
    fn run_search(&mut self) {
        let Some(buf) = self.search.take() else {
            return;
        };
        if !self.drives.is_empty() {
            return;
        }
        let found = if buf.is_empty() {
            Vec::new()
        } else {
            locate::search(&self.rules, &buf)
        };
        if found.is_empty() {
            self.searched += buf.len() as u64;
            self.batches += 1;
            // Keep searching later batches, watching for changes from the last frames on.
            for b in buf.iter().rev() {
                if self.watch.len() >= MAX_STREAMS {
                    break;
                }
                self.watch.entry(b.key).or_insert_with(|| b.data.clone());
            }
            let mut buf = buf;
            buf.clear();
            self.search = Some(buf);
            return;
        }
        let first = self.batches == 0;
        let at = buf.first().map(|b| b.at);
        if !first && self.options.rescan {
            self.late = found;
            self.late_at = at;
            return;
        }
        if !first {
            if let Some(w) = at {
                self.rec.report().note(format!(
                    "PSD4xx found in the frames from {w} on; the input cannot be read twice, so the drive checks start there"
                ));
            }
        }
        self.add_found(&found);
        self.replay(&buf);
    }

    fn add_found(&mut self, found: &[locate::Found]) {
        for f in found {
            let details = BTreeMap::from([
                (
                    "out_frame_id".to_owned(),
                    json!(format!("{:#06x}", f.out.frame_id)),
                ),
                ("out_offset".to_owned(), json!(f.out.offset)),
                (
                    "in_frame_id".to_owned(),
                    json!(format!("{:#06x}", f.inp.frame_id)),
                ),
                ("in_offset".to_owned(), json!(f.inp.offset)),
                ("evidence".to_owned(), json!(f.evidence)),
            ]);
            self.add_drive(f.out, f.inp, None, "search", f.confidence, details);
        }
    }

    /// Feeds buffered frames to the drives.
    fn replay(&mut self, buf: &[Buffered]) {
        let olen = Output::buffer_len(&self.rules);
        let ilen = Input::buffer_len(&self.rules);
        for b in buf {
            let at = b.at;
            for d in self.drives.iter_mut() {
                if d.out.matches(&b.key) && b.valid && output_good(&d.out, &b.data) {
                    if let Some(w) = b.data.get(d.out.offset..d.out.offset + olen) {
                        d.drive.output(&mut self.rec, at, w);
                    }
                }
                if d.inp.matches(&b.key) {
                    if let Some(w) = b.data.get(d.inp.offset..d.inp.offset + ilen) {
                        d.drive.input(&mut self.rec, at, w);
                    }
                }
            }
        }
    }

    /// Whether drives were found late and wait for a second pass over the input
    /// ([`PnChecker::replay_pdu`] for every record from the start, then
    /// [`PnChecker::finish`]).
    pub fn wants_second_pass(&self) -> bool {
        !self.late.is_empty()
    }

    /// Starts the second pass: the drives found late are checked from here on.
    pub fn begin_second_pass(&mut self) {
        let late = std::mem::take(&mut self.late);
        if let Some(w) = self.late_at {
            self.rec.report().note(format!(
                "PSD4xx found in the frames from {w} on; its checks ran from the capture's start in a second pass"
            ));
        }
        self.add_found(&late);
    }

    /// One record of the second pass: only the drives' images and record reads and writes
    /// are checked (the generic checks ran in the first pass).
    pub fn replay_pdu(&mut self, record: u64, time: Option<u64>, pdu: &Result<Pdu<'_>, PduError>) {
        if let Ok(Pdu::Rpc {
            message: Some(Ok(m)),
            link,
            ..
        }) = pdu
        {
            if matches!(
                m.operation,
                Operation::Read | Operation::Write | Operation::ReadImplicit
            ) {
                let o = Origin {
                    record,
                    time,
                    src: link.src,
                    dst: link.dst,
                };
                self.record(&o, m);
            }
            return;
        }
        let Ok(Pdu::Rt { frame, link, .. }) = pdu else {
            return;
        };
        let Ok(c) = frame.cyclic() else {
            return;
        };
        let key: StreamKey = (
            c.frame_id.0,
            link.src.unwrap_or([0; 6]),
            link.dst.unwrap_or([0; 6]),
        );
        let at = Where {
            event: 0,
            frame: Some(record),
            time,
            ..Where::default()
        };
        let valid = c.apdu.data_status.provider_run() && c.apdu.data_status.data_valid();
        let olen = Output::buffer_len(&self.rules);
        let ilen = Input::buffer_len(&self.rules);
        for d in self.drives.iter_mut() {
            if d.out.matches(&key) && valid && output_good(&d.out, c.data) {
                if let Some(w) = c.data.get(d.out.offset..d.out.offset + olen) {
                    d.drive.output(&mut self.rec, at, w);
                }
            }
            if d.inp.matches(&key) {
                if let Some(w) = c.data.get(d.inp.offset..d.inp.offset + ilen) {
                    d.drive.input(&mut self.rec, at, w);
                }
            }
        }
    }

    /// Notes that the stations `a` and `b` released or aborted their AR at `t` (at most
    /// [`MAX_STREAMS`] pairs are remembered).
    fn end_ar(&mut self, a: [u8; 6], b: [u8; 6], t: u64) {
        let k = pair(a, b);
        if self.ended.len() < MAX_STREAMS || self.ended.contains_key(&k) {
            self.ended.insert(k, t);
        }
    }

    /// Lists the STOP of the streams between `a` and `b` that went from RUN to STOP and are
    /// still in STOP as allowed (a controller shutting down, PN-RT-DS-002), ended by the
    /// Release at `at`.
    fn released_in_stop(&mut self, a: [u8; 6], b: [u8; 6], at: Where) {
        for ((_, src, dst), s) in &mut self.streams {
            if pair(*src, *dst) != pair(a, b) {
                continue;
            }
            if let Some((start, _)) = s.stop_pending.take() {
                let i = self.rec.allowed(
                    "PN-RT-DS-002",
                    &s.label,
                    start,
                    "provider in STOP from RUN until the Release of its AR (shut-down)",
                    SHUTDOWN_STOP,
                );
                if let Some(i) = i {
                    self.rec.ended(i, at);
                }
            }
        }
    }

    /// The latest AR between two stations (either initiator), in words, and the time of
    /// its Connect.
    fn ar_between(&self, a: [u8; 6], b: [u8; 6]) -> Option<(String, Option<u64>)> {
        self.ars
            .iter()
            .rev()
            .find(|x| {
                x.responder
                    .is_some_and(|r| pair(x.initiator, r) == pair(a, b))
            })
            .map(|x| (format!("AR {}, Connect at {}", x.ar_uuid, x.at), x.at.time))
    }

    /// The AR whose IO device is `device`, established and neither released nor aborted
    /// by `now`, in words.
    fn running_ar_of(&self, device: [u8; 6], now: Option<u64>) -> Option<String> {
        self.ars
            .iter()
            .rev()
            .find(|x| {
                x.applied
                    && x.responder == Some(device)
                    && match (self.ended.get(&pair(x.initiator, device)), x.at.time, now) {
                        (Some(e), Some(start), Some(n)) => *e < start || *e > n,
                        (Some(_), _, _) => false,
                        (None, _, _) => true,
                    }
            })
            .map(|x| format!("AR {}, Connect at {}", x.ar_uuid, x.at))
    }

    /// The Connect's IOCR for a stream, if one describes it.
    fn iocr_for(&self, key: &StreamKey) -> Option<IocrInfo> {
        self.iocrs
            .iter()
            .rev()
            .find(|i| i.frame_id == key.0 && i.src.is_none_or(|s| s == key.1))
            .cloned()
    }

    // ------------------------------------------------------------------ PNIO-CM

    fn cm(&mut self, ev: &Origin, activity: Uuid, m: &CmMessage) {
        let at = self.at(ev);
        match (m.operation, m.direction) {
            (Operation::Connect, Direction::Request) => {
                let ar_uuid = m.blocks.iter().find_map(|b| match b {
                    Block::ArReq(a) => Some((a.ar_uuid, a.initiator_mac)),
                    _ => None,
                });
                let Some((ar_uuid, initiator)) = ar_uuid else {
                    return;
                };
                self.ars.retain(|a| a.ar_uuid != ar_uuid);
                self.ars.push_back(Ar {
                    activity,
                    ar_uuid,
                    initiator,
                    responder: None,
                    request: m.clone(),
                    response: None,
                    answered: false,
                    applied: false,
                    at,
                });
                while self.ars.len() > MAX_ARS {
                    self.ars.pop_front();
                }
            }
            (Operation::Connect, Direction::Response) => {
                if let Some(a) = self.ars.iter_mut().find(|a| a.activity == activity) {
                    a.answered = true;
                }
                if let Some(s) = m.ndr.status.filter(|s| !s.is_ok()) {
                    self.cm_failed(ev, "Connect", s);
                    return;
                }
                let Some(i) = self.ars.iter().position(|a| a.activity == activity) else {
                    self.rec.report().note(format!(
                        "Connect response at {at} without its request; its streams are checked without Connect data"
                    ));
                    return;
                };
                if let Some(a) = self.ars.get_mut(i) {
                    a.responder = m.blocks.iter().find_map(|b| match b {
                        Block::ArRes(r) => Some(r.responder_mac),
                        _ => None,
                    });
                    a.response = Some(m.clone());
                }
                self.apply_ar(i);
            }
            (Operation::Control, Direction::Response) => {
                if let Some(s) = m.ndr.status.filter(|s| !s.is_ok()) {
                    self.cm_failed(ev, "Control", s);
                }
            }
            (Operation::Release, _) | (Operation::Control, Direction::Request) => {
                for b in &m.blocks {
                    if let Block::Control(c) = b {
                        if c.kind == ControlKind::Release && !c.response {
                            self.rec
                                .report()
                                .note(format!("AR {} released at {at}", c.ar_uuid));
                            if let (Some(a), Some(b)) = (ev.src, ev.dst) {
                                self.released_in_stop(a, b, at);
                                if let Some(t) = ev.time {
                                    self.end_ar(a, b, t);
                                }
                            }
                        }
                    }
                }
            }
            (Operation::Read | Operation::Write | Operation::ReadImplicit, d) => {
                if d == Direction::Response {
                    let bad = m.ndr.status.filter(|s| !s.is_ok()).or_else(|| {
                        m.blocks.iter().find_map(|b| match b {
                            Block::ReadRes(r) | Block::WriteRes(r) => {
                                r.status.filter(|s| !s.is_ok())
                            }
                            _ => None,
                        })
                    });
                    if let Some(s) = bad {
                        let what = if m.operation == Operation::Write {
                            "Write"
                        } else {
                            "Read"
                        };
                        self.cm_failed(ev, what, s);
                    }
                }
                self.record(ev, m);
            }
            _ => {}
        }
    }

    fn cm_failed(&mut self, ev: &Origin, what: &str, s: PnioStatus) {
        let at = self.at(ev);
        let subject = match (ev.src, ev.dst) {
            (Some(a), Some(b)) => format!("{} → {}", mac(&a), mac(&b)),
            _ => "PNIO-CM".into(),
        };
        let words = self.pn_events.status(s);
        self.rec.violation(
            "PN-CM-002",
            &subject,
            at,
            format!("{what} answered with PNIOStatus {s}: {words}"),
            Evidence::none().with("pnio_status", s.to_string()),
        );
    }

    /// Registers the IOCRs of a Connect and locates the PSD4xx modules in it.
    fn apply_ar(&mut self, i: usize) {
        let Some(ar) = self.ars.get_mut(i) else {
            return;
        };
        if ar.applied {
            return;
        }
        ar.applied = true;
        let ar = ar.clone();
        self.rec.checks(CHECKED_CONNECT);
        let res_frame = |iocr: &IocrBlockReq| -> u16 {
            ar.response
                .as_ref()
                .and_then(|r| {
                    r.blocks.iter().find_map(|b| match b {
                        Block::IocrRes(x)
                            if x.reference == iocr.reference && x.iocr_type == iocr.iocr_type =>
                        {
                            Some(x.frame_id.0)
                        }
                        _ => None,
                    })
                })
                .unwrap_or(iocr.frame_id.0)
        };
        let expected: Vec<_> = ar
            .request
            .blocks
            .iter()
            .filter_map(|b| match b {
                Block::ExpectedSubmodules(e) => Some(e.modules.clone()),
                _ => None,
            })
            .flatten()
            .collect();
        let sub_len = |slot: u16, subslot: u16, input: bool| -> usize {
            expected
                .iter()
                .filter(|m| m.slot == slot)
                .flat_map(|m| m.submodules.iter())
                .find(|s| s.subslot == subslot)
                .and_then(|s| if input { s.input } else { s.output })
                .map_or(0, |d| usize::from(d.data_length))
        };
        let mut bindings: Vec<(u16, u16, u16, bool, u16, usize, usize)> = Vec::new();
        for b in &ar.request.blocks {
            let Block::IocrReq(iocr) = b else {
                continue;
            };
            let frame_id = res_frame(iocr);
            let input_cr = iocr.iocr_type == 1 || iocr.iocr_type == 3;
            let src = if input_cr {
                ar.responder
            } else {
                Some(ar.initiator)
            };
            let mut iops = Vec::new();
            let mut iocs = Vec::new();
            for api in &iocr.apis {
                for d in &api.data_objects {
                    let len = sub_len(d.slot, d.subslot, input_cr);
                    let off = usize::from(d.frame_offset);
                    iops.push((format!("IOPS {}/{}", d.slot, d.subslot), off + len));
                    bindings.push((
                        api.api as u16,
                        d.slot,
                        d.subslot,
                        input_cr,
                        frame_id,
                        off,
                        len,
                    ));
                }
                for d in &api.iocs {
                    iocs.push((
                        format!("IOCS {}/{}", d.slot, d.subslot),
                        usize::from(d.frame_offset),
                    ));
                }
            }
            let increment = iocr
                .send_clock_factor
                .saturating_mul(iocr.reduction_ratio.max(1));
            let info = IocrInfo {
                frame_id,
                src,
                data_length: usize::from(iocr.data_length),
                increment: increment.max(1),
                watchdog_us: (iocr.watchdog_factor > 0)
                    .then(|| u64::from(iocr.watchdog_factor) * iocr.cycle_micros()),
                iops,
                iocs,
            };
            // Streams seen before the Connect take its data from now on.
            for (k, s) in self.streams.iter_mut() {
                if k.0 == frame_id && src.is_none_or(|m| m == k.1) {
                    s.increment = Some(info.increment);
                    s.info = Some(info.clone());
                    s.learning.clear();
                }
            }
            self.iocrs.push(info);
            if self.iocrs.len() > MAX_ARS * 8 {
                self.iocrs.remove(0);
            }
        }
        self.locate_in(&ar, &expected, &bindings);
    }

    fn locate_in(
        &mut self,
        ar: &Ar,
        expected: &[drivespec_capture::pnio::ExpectedModule],
        bindings: &[(u16, u16, u16, bool, u16, usize, usize)],
    ) {
        let olen = Output::buffer_len(&self.rules);
        let ilen = Input::buffer_len(&self.rules);
        let ident = self.options.module_ident;
        // Submodules with PSD4xx output or input data.
        let mut outs = Vec::new();
        let mut ins = Vec::new();
        for m in expected {
            for s in &m.submodules {
                let by_ident = ident.is_some_and(|x| x == m.ident || x == s.ident);
                let out_ok = s.output.is_some_and(|d| usize::from(d.data_length) == olen);
                let in_ok = s.input.is_some_and(|d| usize::from(d.data_length) == ilen);
                if (ident.is_none() || by_ident) && out_ok {
                    outs.push((m.slot, s.subslot, m.ident));
                }
                if (ident.is_none() || by_ident) && in_ok {
                    ins.push((m.slot, s.subslot, m.ident));
                }
            }
        }
        let mut used_in = vec![false; ins.len()];
        let mut units = Vec::new();
        for o in &outs {
            let pick = ins
                .iter()
                .enumerate()
                .filter(|(k, _)| !used_in.get(*k).copied().unwrap_or(true))
                .min_by_key(|(_, i)| (i.0 != o.0, i.1 != o.1, i.0.abs_diff(o.0)))
                .map(|(k, i)| (k, *i));
            if let Some((k, i)) = pick {
                if let Some(u) = used_in.get_mut(k) {
                    *u = true;
                }
                units.push((*o, i));
            }
        }
        if units.is_empty() {
            if !expected.is_empty() {
                self.connects_without_psd += 1;
                self.first_without_psd.get_or_insert(ar.at);
            }
            return;
        }
        // A Connect describes the drives: the search is not needed.
        self.search = None;
        for (o, i) in units {
            let find = |slot: u16, subslot: u16, input: bool| {
                bindings
                    .iter()
                    .find(|b| b.1 == slot && b.2 == subslot && b.3 == input)
                    .copied()
            };
            let (Some(ob), Some(ib)) = (find(o.0, o.1, false), find(i.0, i.1, true)) else {
                self.rec.report().note(format!(
                    "Connect at {}: PSD4xx submodule in slot {} has no data object in the IOCRs",
                    ar.at, o.0
                ));
                continue;
            };
            let out = Binding {
                frame_id: ob.4,
                src: Some(ar.initiator),
                offset: ob.5,
                iops: Some(ob.5 + ob.6),
            };
            let inp = Binding {
                frame_id: ib.4,
                src: ar.responder,
                offset: ib.5,
                iops: Some(ib.5 + ib.6),
            };
            let details = BTreeMap::from([
                ("ar_uuid".to_owned(), json!(ar.ar_uuid.to_string())),
                ("slot".to_owned(), json!(o.0)),
                ("output_subslot".to_owned(), json!(o.1)),
                ("input_subslot".to_owned(), json!(i.1)),
                ("module_ident".to_owned(), json!(format!("{:#x}", o.2))),
                (
                    "out_frame_id".to_owned(),
                    json!(format!("{:#06x}", out.frame_id)),
                ),
                ("out_offset".to_owned(), json!(out.offset)),
                (
                    "in_frame_id".to_owned(),
                    json!(format!("{:#06x}", inp.frame_id)),
                ),
                ("in_offset".to_owned(), json!(inp.offset)),
            ]);
            self.add_drive(
                out,
                inp,
                Some((ar.ar_uuid, (i.1, o.0, o.1))),
                "connect",
                1.0,
                details,
            );
        }
    }

    /// Record reads and writes of the located drives (bus description 3.2.2).
    fn record(&mut self, ev: &Origin, m: &CmMessage) {
        let at = self.at(ev);
        for b in &m.blocks {
            match b {
                Block::ReadReq(r) | Block::WriteReq(r) => {
                    let write = matches!(b, Block::WriteReq(_));
                    if r.index >= 0x8000 {
                        continue;
                    }
                    let Some(d) = self.drive_for(r.ar_uuid, r.slot, r.subslot) else {
                        continue;
                    };
                    if write {
                        if let Some(x) = self.drives.get_mut(d) {
                            x.drive.record_write(&mut self.rec, at, r.index, &r.data);
                        }
                    }
                    self.pending_records.insert(
                        (r.ar_uuid, r.sequence),
                        PendingRecord {
                            drive: d,
                            write,
                            index: r.index,
                        },
                    );
                    if self.pending_records.len() > 256 {
                        self.pending_records.clear();
                    }
                }
                Block::ReadRes(r) | Block::WriteRes(r) => {
                    let Some(p) = self.pending_records.remove(&(r.ar_uuid, r.sequence)) else {
                        continue;
                    };
                    let ok = m.ndr.status.is_none_or(|s| s.is_ok())
                        && r.status.is_none_or(|s| s.is_ok());
                    let Some(x) = self.drives.get_mut(p.drive) else {
                        continue;
                    };
                    if p.write {
                        x.drive.record_written(&mut self.rec, at, p.index, ok);
                    } else if ok {
                        x.drive.record_read(&mut self.rec, at, p.index, &r.data);
                    }
                }
                _ => {}
            }
        }
    }

    /// The drive a record addresses: by AR and slot, or the only drive found without Connect.
    fn drive_for(&self, ar: Uuid, slot: u16, subslot: u16) -> Option<usize> {
        let by_ar = self.drives.iter().position(|d| {
            d.ar == Some(ar)
                && d.slot
                    .is_some_and(|(si, s, so)| s == slot && (subslot == si || subslot == so))
        });
        by_ar.or_else(|| {
            let free: Vec<usize> = (0..self.drives.len())
                .filter(|i| self.drives.get(*i).is_some_and(|d| d.ar.is_none()))
                .collect();
            (free.len() == 1 && self.drives.len() == 1)
                .then(|| free.first().copied())
                .flatten()
        })
    }

    /// Streams whose last frame is followed by more than their watchdog time of capture
    /// (from the Connect, else [`STOP_CYCLES`] send intervals) with no Release or abort
    /// of their stations: a connection abort (PN-AR-001).
    fn stopped_streams(&mut self, end: Option<u64>) {
        let Some(end) = end else {
            return;
        };
        for (key, s) in &self.streams {
            let Some((_, last, w)) = s.last else {
                continue;
            };
            if w.time.is_none() {
                continue;
            }
            let (bound, why) = match s.info.as_ref().and_then(|i| i.watchdog_us) {
                Some(b) => (b, "watchdog time from the Connect"),
                None => match s.increment {
                    Some(i) => (
                        u64::from(i) * COUNT_NS / 1000 * STOP_CYCLES,
                        "no Connect seen: 3 send intervals, the least DataHoldFactor",
                    ),
                    None => continue,
                },
            };
            let gap = end.saturating_sub(last);
            if gap <= bound {
                continue;
            }
            let released = self
                .ended
                .get(&pair(key.1, key.2))
                .is_some_and(|t| *t <= last.saturating_add(bound));
            if released {
                continue;
            }
            self.rec.violation(
                "PN-AR-001",
                &s.label,
                w,
                format!(
                    "cyclic stream stops: no frame for {} ms after this one while the capture goes on (bound {} ms, {why}); no Release or abort of these stations was seen",
                    gap / 1000,
                    bound.div_ceil(1000)
                ),
                Evidence::none().with("gap_us", gap).with("bound_us", bound),
            );
        }
    }

    /// Connect requests with no answer and at least [`CONNECT_ANSWER_US`] of capture after
    /// them (PN-CM-003).
    fn unanswered_connects(&mut self, end: Option<u64>) {
        let Some(end) = end else {
            return;
        };
        let open: Vec<(Uuid, [u8; 6], Where)> = self
            .ars
            .iter()
            .filter(|a| {
                !a.answered
                    && a.at
                        .time
                        .is_some_and(|t| end.saturating_sub(t) >= CONNECT_ANSWER_US)
            })
            .map(|a| (a.ar_uuid, a.initiator, a.at))
            .collect();
        for (uuid, initiator, at) in open {
            self.rec.violation(
                "PN-CM-003",
                &mac(&initiator),
                at,
                format!(
                    "Connect for AR {uuid} not answered in the {} s of capture after it",
                    CONNECT_ANSWER_US / 1_000_000
                ),
                Evidence::none(),
            );
        }
    }

    /// Records that reading stopped with `error`; what was read is still checked.
    pub fn fail(&mut self, error: &CaptureError) {
        let offset = match error {
            CaptureError::Truncated { offset, .. }
            | CaptureError::BadBlockLength { offset, .. }
            | CaptureError::TooLarge { offset, .. }
            | CaptureError::BadCapturedLength { offset, .. }
            | CaptureError::UnknownInterface { offset, .. }
            | CaptureError::Corrupt { offset, .. } => Some(*offset),
            CaptureError::Read(r) => Some(r.offset),
            _ => None,
        };
        self.rec.report().error = Some(InputFault {
            message: error.to_string(),
            offset,
        });
    }

    /// Ends the first pass over the input: searches the frames still buffered. Then
    /// [`PnChecker::wants_second_pass`] tells whether a second pass is due.
    pub fn end_of_input(&mut self) {
        self.run_search();
    }

    /// Ends the capture; `counts` are the reader's frame counts, when known.
    pub fn finish(mut self, counts: Option<Counts>) -> Report {
        self.run_search();
        if !self.late.is_empty() {
            let late = std::mem::take(&mut self.late);
            self.add_found(&late);
            if let Some(w) = self.late_at {
                self.rec.report().note(format!(
                    "PSD4xx found in the frames from {w} on, but the input was not read a second time: its checks did not run"
                ));
            }
        } else if self.drives.is_empty() && self.options.search && self.options.manual.is_none() {
            let searched = self.searched;
            let note = if searched == 0 {
                "no PSD4xx found: no Connect with PSD4xx modules and no cyclic frames".to_owned()
            } else {
                format!(
                    "no PSD4xx found: no Connect with PSD4xx modules, and the search over {searched} cyclic frames (the capture's first frames and every later stretch in which the data changed) found no window that behaves like PSD4xx process data (give --frame-id and --offset to check anyway)"
                )
            };
            if self.connects_without_psd == 0 || searched > 0 {
                self.rec.report().note(note);
            }
        }
        let end = self.last_time;
        self.pn_events.finish(&mut self.rec, end);
        self.stopped_streams(end);
        for (_, s) in &mut self.streams {
            if let Some((start, evidence)) = s.stop_pending.take() {
                stop_after_run(&mut self.rec, &s.label, start, evidence, None);
            }
        }
        self.unanswered_connects(end);
        let mut streams: Vec<(StreamKey, Stream)> = std::mem::take(&mut self.streams);
        streams.sort_by_key(|(k, _)| *k);
        let drives = std::mem::take(&mut self.drives);
        let events = self.events;
        let cyclic = self.cyclic_frames;
        if let Some(w) = self.first_without_psd {
            let olen = Output::buffer_len(&self.rules);
            let ilen = Input::buffer_len(&self.rules);
            let ident = self
                .options
                .module_ident
                .map_or(String::new(), |x| format!(" with module ident {x:#x}"));
            let n = self.connects_without_psd;
            self.rec.report().note(format!(
                "{n} Connect(s) (the first at {w}) expect no submodule{ident} with a {olen}-byte output and a {ilen}-byte input (PSD4xx modules)"
            ));
        }
        let r = self.rec.report();
        r.events = events;
        if cyclic > 0 {
            r.frames.insert("rt-cyclic".into(), cyclic);
        }
        if let Some(c) = counts {
            r.frames.insert("records".into(), c.records);
            r.frames.insert("not-profinet".into(), c.other);
        }
        for (_, s) in streams {
            let nominal = s.increment.map(|i| f64::from(i) * COUNT_NS as f64 / 1000.0);
            r.streams.push(StreamStats {
                stream: s.label,
                frames: s.frames,
                nominal_us: nominal,
                interval_us: s.interval.done(),
                jitter_us: nominal.map(|_| s.jitter.done()),
                missing: s.missing,
                gaps: s.gaps,
            });
        }
        for d in drives {
            r.drives.push(d.info);
            r.timelines.push(d.drive.into_timeline());
        }
        if r.drives.is_empty() && !r.notes.iter().any(|n| n.starts_with("no PSD4xx")) {
            r.note("no PSD4xx found in this capture; only the generic PROFINET checks ran");
        }
        r.scope("PROFINET", None, None);
        let why_not = r.drives.is_empty().then(|| "no drive found".to_owned());
        r.scope("PSD4xx", Some("psd4xx"), why_not);
        r.judge(Policy::default());
        self.rec.finish()
    }
}

/// Records the STOP after RUN of stream `label` from `start` (PN-RT-DS-002), ended at `end`
/// when the provider went back to RUN.
fn stop_after_run(
    rec: &mut Recorder,
    label: &str,
    start: Where,
    evidence: Evidence,
    end: Option<Where>,
) {
    let i = rec.violation(
        "PN-RT-DS-002",
        label,
        start,
        "provider went from RUN to STOP",
        evidence,
    );
    if let (Some(i), Some(end)) = (i, end) {
        rec.violation_ended(i, end);
    }
}

/// A pair of stations in a fixed order.
fn pair(a: [u8; 6], b: [u8; 6]) -> ([u8; 6], [u8; 6]) {
    if a <= b {
        (a, b)
    } else {
        (b, a)
    }
}

/// A condition `k` of a stream (DataStatus, TransferStatus, length): a violation when it
/// starts (`now` and not `was`), ended with its duration when it stops.
#[allow(clippy::too_many_arguments)]
fn condition(
    rec: &mut Recorder,
    label: &str,
    open: &mut [Option<usize>; 5],
    k: usize,
    now: bool,
    was: bool,
    at: &Where,
    what: &dyn Fn() -> (&'static str, String),
    ev: &dyn Fn() -> Evidence,
) {
    let Some(slot) = open.get_mut(k) else {
        return;
    };
    if now && !was {
        let (id, message) = what();
        *slot = rec.violation(id, label, *at, message, ev());
    } else if !now && was {
        if let Some(i) = slot.take() {
            rec.violation_ended(i, *at);
        }
    }
}

/// Whether the provider status (IOPS) of the output module `b` in `data` is good, or unknown.
fn output_good(b: &Binding, data: &[u8]) -> bool {
    b.iops
        .and_then(|o| data.get(o))
        .is_none_or(|iops| iops & 0x80 != 0)
}

/// Adds a violation of `id` to `found`, with its message and evidence made only when the
/// recorder will list it (a fuzzed or broken stream violates on every frame).
fn found_push(
    found: &mut Vec<(&'static str, String, Evidence)>,
    rec: &Recorder,
    id: &'static str,
    detail: impl FnOnce() -> (String, Evidence),
) {
    let (message, evidence) = if rec.lists(id) {
        detail()
    } else {
        (String::new(), Evidence::none())
    };
    found.push((id, message, evidence));
}

/// The generic checks of one cyclic frame of stream `s`.
fn stream_frame(
    s: &mut Stream,
    at: &Where,
    data: &[u8],
    apdu: ApduStatus,
    found: &mut Vec<(&'static str, String, Evidence)>,
    rec: &mut Recorder,
) {
    s.frames += 1;
    let counter = apdu.cycle_counter;
    let time = at.time;
    let ds = apdu.data_status;
    let ev = || {
        Evidence::none()
            .with("cycle_counter", counter)
            .with("data_status", ds.to_string())
            .with("transfer_status", apdu.transfer_status)
    };
    if let Some((last, last_t, last_at)) = s.last {
        let dt = time.map(|t| t.saturating_sub(last_t));
        let delta = counter.wrapping_sub(last);
        // A pause longer than the counter's wrap (2.048 s) makes the counter ambiguous.
        let restart = dt.is_some_and(|d| d >= 2_000_000);
        if let Some(d) = dt {
            if !restart {
                s.interval.add(d as f64);
            }
        }
        if !restart {
            if delta == 0 || delta > 0x8000 {
                found_push(found, rec, "PN-RT-CC-002", || {
                    (
                        format!(
                            "cycle counter {counter} after {last} ({})",
                            if delta == 0 { "repeated" } else { "backwards" }
                        ),
                        ev().with("previous", last)
                            .with("previous_frame", last_at.frame),
                    )
                });
            } else if let Some(inc) = s.increment {
                if delta % inc != 0 {
                    found_push(found, rec, "PN-RT-CC-001", || {
                        (
                            format!(
                            "cycle counter advanced by {delta}, not a multiple of the send interval {inc}"
                        ),
                            ev().with("previous", last).with("increment", inc),
                        )
                    });
                } else {
                    let steps = u64::from(delta / inc);
                    // Frames missing: the cycles the counter skipped, unless the capture
                    // time shows fewer passed (a counter glitch loses no frame).
                    let nominal = u64::from(inc) * COUNT_NS / 1000;
                    let by_time = dt.map(|d| (d + nominal / 2) / nominal.max(1));
                    let cycles = by_time.map_or(steps, |t| steps.min(t.max(1)));
                    if cycles > 1 {
                        s.gaps += 1;
                        s.missing += cycles - 1;
                    }
                    if let Some(d) = dt {
                        s.jitter.add((d as f64 - (steps * nominal) as f64).abs());
                        let expected = u64::from(delta) * COUNT_NS / 1000;
                        if d > expected * 2 + 4000 || d + 4000 < expected / 2 {
                            found_push(found, rec, "PN-RT-CC-003", || {
                                (
                                    format!(
                                    "{d} µs between frames whose cycle counters are {expected} µs apart"
                                ),
                                    ev().with("interval_us", d).with("counter_us", expected),
                                )
                            });
                        }
                        if let Some(w) = s.info.as_ref().and_then(|i| i.watchdog_us) {
                            if d > w {
                                found_push(found, rec, "PN-RT-WD-001", || {
                                    (
                                        format!("{d} µs without a frame, more than the watchdog time {w} µs"),
                                        ev().with("gap_us", d),
                                    )
                                });
                            }
                        }
                    }
                }
            } else {
                s.learning.push(delta);
                if s.learning.len() >= 16 {
                    let mut counts: BTreeMap<u16, u32> = BTreeMap::new();
                    for d in &s.learning {
                        *counts.entry(*d).or_default() += 1;
                    }
                    s.increment = counts
                        .iter()
                        .max_by_key(|(d, n)| (**n, std::cmp::Reverse(**d)))
                        .map(|(d, _)| *d);
                }
            }
        }
    }
    s.last = time.map(|t| (counter, t, *at)).or(Some((counter, 0, *at)));
    // DataStatus and TransferStatus: report when a condition starts, end it when it stops.
    let valid = ds.data_valid();
    if valid {
        s.valid_seen = true;
    }
    let invalid = s.valid_seen && !valid;
    let label = s.label.clone();
    let mut cond = |k: usize, now: bool, was: bool, what: &dyn Fn() -> (&'static str, String)| {
        condition(rec, &label, &mut s.open, k, now, was, at, what, &ev);
    };
    cond(0, invalid, s.invalid, &|| {
        ("PN-RT-DS-001", "DataValid cleared after valid data".into())
    });
    let stop = !ds.provider_run();
    let problem = !ds.station_ok();
    cond(1, problem, s.problem, &|| {
        (
            "PN-RT-DS-003",
            "StationProblemIndicator signals a problem".into(),
        )
    });
    let reserved = ds.reserved() != 0;
    cond(2, reserved, s.reserved, &|| {
        (
            "PN-RT-DS-004",
            format!("reserved DataStatus bits {:#04x} set", ds.reserved()),
        )
    });
    let transfer = apdu.transfer_status != 0;
    cond(3, transfer, s.transfer, &|| {
        (
            "PN-RT-TS-001",
            format!("TransferStatus {:#04x}", apdu.transfer_status),
        )
    });
    let short = s
        .info
        .as_ref()
        .is_some_and(|info| data.len() < info.data_length);
    let announced = s.info.as_ref().map_or(0, |i| i.data_length);
    cond(4, short, s.short, &|| {
        (
            "PN-RT-LEN-001",
            format!(
                "{} byte(s) of data where the Connect announced a C_SDU of {announced}",
                data.len()
            ),
        )
    });
    if stop && !s.stop && s.run_seen {
        s.stop_pending = Some((*at, ev()));
    }
    if !stop {
        if let Some((start, evidence)) = s.stop_pending.take() {
            stop_after_run(rec, &s.label, start, evidence, Some(*at));
        }
    }
    if stop && !s.stop && !s.run_seen {
        s.stop_allowed = rec.allowed(
            "PN-RT-DS-002",
            &s.label,
            *at,
            "provider in STOP from its first frame (start-up)",
            STARTUP_STOP,
        );
    }
    if !stop {
        if let Some(i) = s.stop_allowed.take() {
            rec.ended(i, *at);
        }
        s.run_seen = true;
    }
    s.invalid = invalid;
    s.stop = stop;
    s.problem = problem;
    s.reserved = reserved;
    s.transfer = transfer;
    s.short = short;
    let Some(info) = s.info.as_ref() else {
        return;
    };
    // IOxS: bit 7 DataState good (0x80).
    let positions: Vec<(String, usize, &'static str)> = info
        .iops
        .iter()
        .map(|(l, o)| (l.clone(), *o, "PN-IO-IOPS-001"))
        .chain(
            info.iocs
                .iter()
                .map(|(l, o)| (l.clone(), *o, "PN-IO-IOCS-001")),
        )
        .collect();
    for (label, offset, id) in positions {
        let Some(b) = data.get(offset).copied() else {
            continue;
        };
        let good = b & 0x80 != 0;
        let was = s.iox.insert(offset, good);
        if !good && was.is_some_and(|g| g) && s.valid_seen {
            if stop {
                let listed = rec.allowed(
                    id,
                    &s.label,
                    *at,
                    format!("{label} = {b:#04x} (bad) while the provider is in STOP"),
                    BAD_IN_STOP,
                );
                s.iox_allowed.push((offset, listed));
            } else {
                found_push(found, rec, id, || {
                    (
                        format!("{label} = {b:#04x} (bad)"),
                        ev().with("offset", offset).with("iox", format!("{b:#04x}")),
                    )
                });
            }
        }
        if good && was.is_some_and(|g| !g) {
            if let Some(k) = s.iox_allowed.iter().position(|(o, _)| *o == offset) {
                if let (_, Some(i)) = s.iox_allowed.swap_remove(k) {
                    rec.ended(i, *at);
                }
            }
        }
    }
}

/// Checks a PROFINET capture (style rule 12): every event in order; a capture error ends
/// the stream (recorded in [`Report::error`]).
pub fn check<I>(spec: &Spec, options: PnOptions, events: I) -> Result<Report, SetupError>
where
    I: IntoIterator<Item = Result<PnEvent, CaptureError>>,
{
    Ok(PnChecker::new(spec, options)?.run(events))
}
