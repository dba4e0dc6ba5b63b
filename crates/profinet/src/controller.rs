//! A PROFINET IO controller for one PSD4xx (IEC 61158-6-10; manual 3.2): DCP Identify by
//! NameOfStation (and DCP Set of the IP when the device has none), Connect with the PSD4xx
//! modules, parameter record writes, PrmEnd, waiting for ApplicationReady, cyclic exchange
//! at a configurable send clock, record read and write, Release.
//!
//! Sans-IO like [`crate::device::Device`]. Every wait has a deadline: an Identify without
//! answer ends in [`ControllerError::NoSuchStation`], an RPC call is repeated
//! [`ControllerConfig::rpc_retries`] times and then fails with [`ControllerError::Timeout`],
//! ApplicationReady is awaited for [`ControllerConfig::app_ready_timeout`], and in data
//! exchange the input watchdog (DataHoldFactor cycles) ends the AR with
//! [`ControllerError::Watchdog`]. Errors are reported once as [`ControllerEvent::Failed`];
//! the controller then sends nothing more. Memory is bounded: at most [`MAX_QUEUED`] frames,
//! events and calls wait.

use crate::cm::{self, Blocks};
use crate::dcp::{self, opt, service, service_type, DcpBlocks};
use crate::eth::{self, Mac, DCP_IDENTIFY_MAC};
use crate::identity::Identity;
use crate::rpc;
use crate::rt::{self, data_status, ioxs, MIN_C_SDU};
use crate::station::{self, classify, cycle, cycle_counter, Incoming};
use crate::status;
use crate::udp::{Endpoints, Ipv4};
use drivespec_capture::dcerpc::{Header, PacketType, Uuid, PNIO_PORT};
use drivespec_capture::link::ethertype;
use drivespec_capture::pnio::{
    alarm_cr_res, alarm_notification, block_type, control_command, module_diff, AlarmCrBlockReq,
    AlarmNote, ArBlockReq, Block, BlockHeader, CmMessage, ControlBlock, ControlKind, DiffModule,
    Direction, FrameOffset, IocrApi, IocrBlockReq, Operation, PnioStatus, RecordRequest,
};
use drivespec_capture::rt::{DataStatus, DcpHeader, FrameClass, FrameId};
use std::collections::VecDeque;
use std::time::Duration;

/// Most frames, events and calls waiting.
pub const MAX_QUEUED: usize = 256;

/// The UDP port the controller's calls go out from.
pub const CLIENT_PORT: u16 = 0xC001;

/// The controller's LocalAlarmReference (IEC 61158-6-10 AlarmCRBlockReq).
const ALARM_REF: u16 = 0x0003;

/// FrameID the controller gives the input CR (IEC 61158-6-10 RT class 1: 0xC000–0xF7FF).
pub const INPUT_FRAME_ID: FrameId = FrameId(0xC001);

/// How to run a controller (our doc: module `controller`).
#[derive(Debug, Clone)]
pub struct ControllerConfig {
    /// Own MAC address.
    pub mac: Mac,
    /// Own IP address.
    pub ip: Ipv4,
    /// Own station name (CMInitiatorStationName).
    pub station_name: String,
    /// NameOfStation of the device to connect to.
    pub target: String,
    /// IP to give the device by DCP Set when it has none.
    pub device_ip: Option<(Ipv4, Ipv4, Ipv4)>,
    /// The device (MAC) to give the NameOfStation `target` by DCP Set when no station
    /// answers the Identify for that name: a controller that knows its device by address.
    pub name_device: Option<Mac>,
    /// The device's modules.
    pub identity: Identity,
    /// SendClockFactor (units of 31.25 µs; 32 = 1 ms).
    pub send_clock_factor: u16,
    /// ReductionRatio.
    pub reduction_ratio: u16,
    /// DataHoldFactor (cycles without a valid frame before the AR ends).
    pub data_hold_factor: u16,
    /// C_SDU length asked for in both IOCRs (IEC 61158-6-10 "DataLength": 40 to 1440).
    pub data_length: u16,
    /// Time to wait for an answer to one RPC call or DCP request before repeating it.
    pub rpc_timeout: Duration,
    /// Repeats of an unanswered call before it fails.
    pub rpc_retries: u32,
    /// Time to wait for the Identify answer.
    pub identify_timeout: Duration,
    /// Time to wait for ApplicationReady after PrmEnd.
    pub app_ready_timeout: Duration,
    /// Records written between Connect and PrmEnd (index, data) on the output module.
    pub prm_records: Vec<(u16, Vec<u8>)>,
    /// The AR's UUID (its activity UUID is derived from it). [`ControllerConfig::new`] derives
    /// one from the MAC, the same on every run; a caller that runs several ARs in a row may
    /// set a fresh one for each.
    pub ar_uuid: Uuid,
    /// SessionKey.
    pub session_key: u16,
    /// CMInitiatorObjectUUID.
    pub object: Uuid,
}

impl ControllerConfig {
    /// A controller for the device named `target`, 1 ms cycle, DataHoldFactor 3, 1 s RPC
    /// timeout with 3 repeats, 3 s for Identify and ApplicationReady.
    pub fn new(identity: Identity, mac: Mac, ip: Ipv4, target: &str) -> ControllerConfig {
        let mut ar = [0u8; 16];
        for (a, m) in ar.iter_mut().zip(mac.iter().cycle()) {
            *a = *m;
        }
        // A version 4 (random) UUID layout: version nibble and variant bits.
        if let Some(b) = ar.get_mut(6) {
            *b = 0x40 | (*b & 0x0f);
        }
        if let Some(b) = ar.get_mut(8) {
            *b = 0x80 | (*b & 0x3f);
        }
        ControllerConfig {
            mac,
            ip,
            station_name: "drivespec-controller".to_owned(),
            target: target.to_owned(),
            device_ip: None,
            name_device: None,
            identity,
            send_clock_factor: 32,
            reduction_ratio: 1,
            data_hold_factor: 3,
            data_length: u16::try_from(MIN_C_SDU).unwrap_or(40),
            rpc_timeout: Duration::from_secs(1),
            rpc_retries: 3,
            identify_timeout: Duration::from_secs(3),
            app_ready_timeout: Duration::from_secs(3),
            prm_records: Vec::new(),
            ar_uuid: Uuid(ar),
            session_key: 1,
            object: Uuid([
                0xDE, 0xA0, 0x00, 0x00, 0x6C, 0x97, 0x11, 0xD1, 0x82, 0x71, 0x00, 0x01, 0x00, 0x0A,
                0x00, 0x2A,
            ]),
        }
    }
}

/// Why the controller stopped or a request failed (our doc: module `controller`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ControllerError {
    /// No device answered the Identify for this name.
    #[error("no station named {0:?} answered DCP Identify")]
    NoSuchStation(String),
    /// The device has no IP address and none was given to set.
    #[error("station {0:?} has no IP address")]
    NoIp(String),
    /// The device refused a DCP Set.
    #[error("DCP Set refused with BlockError {0}")]
    DcpSet(u8),
    /// A call or wait ran past its deadline.
    #[error("no answer to {0} in time")]
    Timeout(&'static str),
    /// A call was refused.
    #[error("{operation} refused with PNIOStatus {status}")]
    Refused {
        /// The call.
        operation: &'static str,
        /// Its PNIOStatus.
        status: PnioStatus,
    },
    /// The device's modules differ from the expected PSD4xx modules.
    #[error("the device's modules differ from the PSD4xx's: {0:?}")]
    ModuleDiff(Vec<DiffModule>),
    /// An answer could not be read.
    #[error("malformed answer to {0}")]
    Malformed(&'static str),
    /// No valid input frame for DataHoldFactor cycles.
    #[error("input watchdog: no valid frame for {0:?}")]
    Watchdog(Duration),
    /// The device aborted the AR (ERR-RTA).
    #[error("the device aborted the AR with PNIOStatus {0}")]
    Aborted(PnioStatus),
    /// The request needs an AR in data exchange.
    #[error("no AR in data exchange")]
    NotRunning,
    /// The device rejected a call at the RPC level (C706 reject or fault status).
    #[error("RPC call rejected with status {0:#010x}")]
    Rejected(u32),
    /// Too many requests wait already.
    #[error("{MAX_QUEUED} requests wait already")]
    Busy,
}

/// Identifies a record request (our doc: module `controller`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct RecordId(pub u64);

/// What the controller reports (our doc: module `controller`).
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum ControllerEvent {
    /// The device answered Identify.
    Identified {
        /// Its MAC.
        mac: Mac,
        /// Its IP (after a DCP Set, the one set).
        ip: Ipv4,
        /// VendorID and DeviceID it reported.
        id: Option<(u16, u16)>,
    },
    /// The Connect was accepted.
    Connected,
    /// ApplicationReady arrived: data exchange.
    Running,
    /// A record request finished.
    Record {
        /// The request.
        id: RecordId,
        /// The data read (empty for a write), or why it failed.
        result: Result<Vec<u8>, ControllerError>,
    },
    /// The device sent an alarm notification; it was acknowledged.
    Alarm(AlarmNote),
    /// The AR was released.
    Released,
    /// The controller stopped.
    Failed(ControllerError),
}

/// Sequence numbers of the alarm channel (IEC 61158-6-10 APMS/APMR: start 0xFFFF, then
/// 0…0x7FFF cyclically).
#[derive(Debug, Clone, Copy)]
struct RtaSeq {
    /// SendSeqNum of the next DATA.
    send: u16,
    /// SendSeqNum of the last DATA the device acknowledged.
    sent: u16,
    /// SendSeqNum expected of the device's next DATA.
    expected: u16,
    /// SendSeqNum of the device's last DATA.
    received: u16,
}

impl Default for RtaSeq {
    fn default() -> RtaSeq {
        RtaSeq {
            send: 0xFFFF,
            sent: 0xFFFE,
            expected: 0xFFFF,
            received: 0xFFFE,
        }
    }
}

fn next_seq(s: u16) -> u16 {
    if s == 0xFFFF {
        0
    } else {
        s.wrapping_add(1) & 0x7FFF
    }
}

/// The FrameID of a received frame (after any VLAN tags).
fn frame_id_of(frame: &[u8]) -> FrameId {
    drivespec_capture::link::parse_ethernet(frame)
        .ok()
        .and_then(|l| drivespec_capture::rt::RtFrame::parse(l.payload).ok())
        .map_or(FrameId::ALARM_LOW, |r| r.frame_id)
}

/// The latest input frame's contents (our doc: module `controller`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputData {
    /// The input module's image (3.5.2).
    pub image: Vec<u8>,
    /// Its IOPS.
    pub iops: u8,
    /// The frame's DataStatus.
    pub data_status: DataStatus,
    /// The frame's CycleCounter.
    pub cycle_counter: u16,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum CallKind {
    SetIp,
    SetName,
    Connect,
    Prm,
    PrmEnd,
    Record(RecordId, bool),
    Release,
}

impl CallKind {
    /// Whether the call is a DCP Set (answered by DCP, not by RPC).
    fn is_dcp(self) -> bool {
        matches!(self, CallKind::SetIp | CallKind::SetName)
    }

    fn name(self) -> &'static str {
        match self {
            CallKind::SetIp | CallKind::SetName => "DCP Set",
            CallKind::Connect => "Connect",
            CallKind::Prm => "Write (parameterisation)",
            CallKind::PrmEnd => "Control PrmEnd",
            CallKind::Record(_, true) => "Write",
            CallKind::Record(_, false) => "Read",
            CallKind::Release => "Release",
        }
    }
}

#[derive(Debug, Clone)]
struct Call {
    kind: CallKind,
    opnum: u16,
    blocks: Vec<u8>,
    sequence: u32,
    deadline: Duration,
    tries: u32,
    frame: Vec<u8>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    Idle,
    Identify { deadline: Duration, tries: u32 },
    Connecting,
    WaitAppReady { deadline: Duration },
    Running,
    Closed,
}

/// Offsets of the controller's CR layout: DAP IOxS first, then the modules.
#[derive(Debug, Clone, Copy)]
struct Layout {
    /// Output CR: where the output module's data start (IOCS before, IOPS after).
    out_data: usize,
    /// Input CR: where the input module's data start (DAP IOPS before, its IOPS and the
    /// output module's IOCS after).
    in_data: usize,
}

/// A PROFINET IO controller for one PSD4xx (our doc: module `controller`).
#[derive(Debug, Clone)]
pub struct Controller {
    config: ControllerConfig,
    state: State,
    device: Option<(Mac, Ipv4)>,
    xid: u32,
    tx: VecDeque<Vec<u8>>,
    events: VecDeque<ControllerEvent>,
    calls: VecDeque<Call>,
    sequence: u32,
    /// The name was given by DCP Set once ([`ControllerConfig::name_device`]).
    named: bool,
    next_record: u64,
    record_seq: u16,
    alarm_remote: Option<u16>,
    rta: RtaSeq,
    ip_id: u16,
    cyclic: bool,
    sending: bool,
    next_send: Duration,
    output: Vec<u8>,
    input: Option<InputData>,
    in_frames: u64,
    input_deadline: Duration,
    output_frame: FrameId,
    input_frame: FrameId,
    layout: Layout,
    now: Duration,
}

fn push<T>(q: &mut VecDeque<T>, v: T) {
    if q.len() >= MAX_QUEUED {
        q.pop_front();
    }
    q.push_back(v);
}

impl Controller {
    /// A controller that has not started.
    pub fn new(config: ControllerConfig) -> Controller {
        let dap = config.identity.dap_submodules.len();
        let out_len = usize::from(config.identity.output.length);
        Controller {
            output: vec![0; out_len],
            layout: Layout {
                out_data: dap + 1,
                in_data: dap,
            },
            config,
            state: State::Idle,
            device: None,
            xid: 0x0000_1000,
            tx: VecDeque::new(),
            events: VecDeque::new(),
            calls: VecDeque::new(),
            sequence: 0,
            named: false,
            next_record: 0,
            record_seq: 0,
            alarm_remote: None,
            rta: RtaSeq::default(),
            ip_id: 0,
            cyclic: false,
            sending: true,
            next_send: Duration::ZERO,
            input: None,
            in_frames: 0,
            input_deadline: Duration::MAX,
            output_frame: FrameId(0xFFFF),
            input_frame: INPUT_FRAME_ID,
            now: Duration::ZERO,
        }
    }

    /// Starts the session at `now`: Identify, then Connect and the rest.
    pub fn start(&mut self, now: Duration) {
        self.now = now;
        if self.state == State::Idle {
            self.identify(now, 0);
        }
    }

    /// Whether the AR exchanges data.
    pub fn is_running(&self) -> bool {
        self.state == State::Running
    }

    /// Whether the controller has stopped (released or failed).
    pub fn is_closed(&self) -> bool {
        self.state == State::Closed
    }

    /// The device found by Identify: MAC and IP.
    pub fn device(&self) -> Option<(Mac, Ipv4)> {
        self.device
    }

    /// The latest input data.
    pub fn input(&self) -> Option<&InputData> {
        self.input.as_ref()
    }

    /// The FrameID the device gave the output CR (0xFFFF before its Connect answer).
    pub fn output_frame_id(&self) -> FrameId {
        self.output_frame
    }

    /// Input frames received.
    pub fn input_frames(&self) -> u64 {
        self.in_frames
    }

    /// Sets the output image sent from the next cycle on (3.5.1; longer images are cut,
    /// shorter ones padded with zeros).
    pub fn set_output(&mut self, image: &[u8]) {
        let n = self.output.len();
        self.output = image
            .iter()
            .copied()
            .chain(std::iter::repeat(0))
            .take(n)
            .collect();
    }

    /// Stops (`false`) or resumes the cyclic output frames, e.g. to let the device's
    /// watchdog end the AR.
    pub fn set_sending(&mut self, on: bool) {
        self.sending = on;
    }

    /// Reads record `index` of (`slot`, `subslot`) (IEC 61158-6-10 Read; manual 3.2.2).
    pub fn read_record(
        &mut self,
        now: Duration,
        slot: u16,
        subslot: u16,
        index: u16,
    ) -> Result<RecordId, ControllerError> {
        self.record(now, slot, subslot, index, None)
    }

    /// Writes record `index` of (`slot`, `subslot`) (IEC 61158-6-10 Write; manual 3.2.2).
    pub fn write_record(
        &mut self,
        now: Duration,
        slot: u16,
        subslot: u16,
        index: u16,
        data: &[u8],
    ) -> Result<RecordId, ControllerError> {
        self.record(now, slot, subslot, index, Some(data))
    }

    /// Releases the AR (IEC 61158-6-10 IODReleaseReq).
    pub fn release(&mut self, now: Duration) -> Result<(), ControllerError> {
        self.advance(now);
        if !matches!(
            self.state,
            State::Running | State::WaitAppReady { .. } | State::Connecting
        ) {
            return Err(ControllerError::NotRunning);
        }
        let blocks = self.control_block(ControlKind::Release, control_command::RELEASE);
        self.queue_call(CallKind::Release, 1, blocks);
        Ok(())
    }

    /// The next event, oldest first.
    pub fn poll_event(&mut self) -> Option<ControllerEvent> {
        self.events.pop_front()
    }

    /// The next frame to send at `now`: calls and answers first, then a due output frame.
    pub fn poll_transmit(&mut self, now: Duration) -> Option<Vec<u8>> {
        self.advance(now);
        if let Some(f) = self.tx.pop_front() {
            return Some(f);
        }
        if !self.cyclic || !self.sending || now < self.next_send {
            return None;
        }
        let at = self.next_send;
        let period = self.period();
        self.next_send = at + period;
        if self.next_send <= now {
            self.next_send = now + period;
        }
        Some(self.output_frame(at))
    }

    /// When [`Controller::handle_timeout`] or [`Controller::poll_transmit`] has work next.
    pub fn poll_timeout(&self) -> Option<Duration> {
        if !self.tx.is_empty() {
            return Some(self.now);
        }
        let mut t: Option<Duration> = None;
        let mut at = |d: Duration| t = Some(t.map_or(d, |x| x.min(d)));
        match self.state {
            State::Identify { deadline, .. } | State::WaitAppReady { deadline } => at(deadline),
            State::Running => at(self.input_deadline),
            _ => {}
        }
        if let Some(c) = self.calls.front() {
            at(c.deadline);
        }
        if self.cyclic && self.sending {
            at(self.next_send);
        }
        t
    }

    /// Runs the deadlines up to `now`.
    pub fn handle_timeout(&mut self, now: Duration) {
        self.advance(now);
    }

    /// A frame received at `now`; frames for other stations and anything malformed are
    /// ignored.
    pub fn handle_frame(&mut self, now: Duration, frame: &[u8]) {
        self.advance(now);
        if self.state == State::Closed {
            return;
        }
        let Some(incoming) = classify(frame) else {
            return;
        };
        let own = self.config.mac;
        match incoming {
            Incoming::Dcp {
                src,
                dst,
                class,
                dcp,
            } if dst == own => self.dcp(src, class, &dcp),
            Incoming::Cyclic { src, dst, frame } if dst == own => {
                let Some((dev, _)) = self.device else { return };
                if src != dev || frame.frame_id != self.input_frame {
                    return;
                }
                let ds = frame.apdu.data_status;
                if !ds.data_valid() || ds.ignore() {
                    return;
                }
                let len = usize::from(self.config.identity.input.length);
                let off = self.layout.in_data;
                let (Some(image), Some(&iops)) =
                    (frame.data.get(off..off + len), frame.data.get(off + len))
                else {
                    return;
                };
                self.in_frames += 1;
                self.input = Some(InputData {
                    image: image.to_vec(),
                    iops,
                    data_status: ds,
                    cycle_counter: frame.apdu.cycle_counter,
                });
                self.input_deadline = now + self.period() * u32::from(self.config.data_hold_factor);
            }
            Incoming::Arp(payload) => {
                if let Some(f) = crate::arp::answer(payload, own, self.config.ip) {
                    push(&mut self.tx, f);
                }
            }
            Incoming::Alarm { src, dst, alarm }
                if dst == own && self.device.is_some_and(|(m, _)| m == src) =>
            {
                self.alarm(frame_id_of(frame), &alarm)
            }
            Incoming::OtherRpc {
                src,
                dst,
                ep,
                header,
                body,
            } if dst == own
                && ep.dst == self.config.ip
                && matches!(header.ptype, PacketType::REJECT | PacketType::FAULT) =>
            {
                let mine = self.device.is_some_and(|(d, _)| d == src)
                    && header.activity == self.activity()
                    && self
                        .calls
                        .front()
                        .is_some_and(|c| c.sequence == header.sequence && !c.kind.is_dcp());
                if mine {
                    let order = header.drep.integer;
                    let st = match body {
                        [a, b, c, d, ..] => match order {
                            drivespec_capture::Endian::Big => u32::from_be_bytes([*a, *b, *c, *d]),
                            drivespec_capture::Endian::Little => {
                                u32::from_le_bytes([*a, *b, *c, *d])
                            }
                        },
                        _ => 0,
                    };
                    if let Some(call) = self.calls.pop_front() {
                        self.call_failed(call.kind, ControllerError::Rejected(st));
                    }
                }
            }
            Incoming::Cm {
                src,
                dst,
                ep,
                header,
                message,
            } if dst == own && ep.dst == self.config.ip => self.cm(src, ep, &header, &message),
            _ => {}
        }
    }

    // ------------------------------------------------------------------ internals

    fn period(&self) -> Duration {
        cycle(self.config.send_clock_factor, self.config.reduction_ratio)
    }

    fn fail(&mut self, e: ControllerError) {
        if self.state == State::Closed {
            return;
        }
        self.state = State::Closed;
        // An AR the device still holds is aborted with an ERR-RTA (IEC 61158-6-10): for a
        // watchdog with its reason, for any other failure as an abort request.
        let reason = match e {
            ControllerError::Watchdog(_) => Some(status::code2::DHT_EXPIRED),
            ControllerError::Aborted(_) | ControllerError::ModuleDiff(_) => None,
            _ => Some(status::code2::ABORT_REQ),
        };
        if let (true, Some(reason), Some((dev, _)), Some(remote)) =
            (self.cyclic, reason, self.device, self.alarm_remote)
        {
            let pdu = rt::abort(remote, ALARM_REF, status::abort(reason));
            push(
                &mut self.tx,
                eth::frame(dev, self.config.mac, None, ethertype::PROFINET, &pdu),
            );
        }
        self.cyclic = false;
        for c in std::mem::take(&mut self.calls) {
            if let CallKind::Record(id, _) = c.kind {
                push(
                    &mut self.events,
                    ControllerEvent::Record {
                        id,
                        result: Err(e.clone()),
                    },
                );
            }
        }
        push(&mut self.events, ControllerEvent::Failed(e));
    }

    fn advance(&mut self, now: Duration) {
        self.now = self.now.max(now);
        let now = self.now;
        match self.state {
            State::Identify { deadline, tries } if now >= deadline => {
                if tries >= self.config.rpc_retries {
                    match self.config.name_device.filter(|_| !self.named) {
                        Some(mac) => {
                            self.named = true;
                            self.set_name(mac);
                        }
                        None => {
                            let name = self.config.target.clone();
                            self.fail(ControllerError::NoSuchStation(name));
                        }
                    }
                } else {
                    self.identify(now, tries + 1);
                }
            }
            State::WaitAppReady { deadline } if now >= deadline => {
                self.fail(ControllerError::Timeout("ApplicationReady"));
            }
            State::Running if now >= self.input_deadline => {
                let hold = self.period() * u32::from(self.config.data_hold_factor);
                self.fail(ControllerError::Watchdog(hold));
            }
            _ => {}
        }
        let retries = self.config.rpc_retries;
        let timeout = self.config.rpc_timeout;
        let mut failed = None;
        if let Some(c) = self.calls.front_mut() {
            if now >= c.deadline {
                if c.tries >= retries {
                    failed = Some(c.kind);
                } else {
                    c.tries += 1;
                    c.deadline = now + timeout;
                    let f = c.frame.clone();
                    push(&mut self.tx, f);
                }
            }
        }
        if let Some(kind) = failed {
            self.calls.pop_front();
            self.call_failed(kind, ControllerError::Timeout(kind.name()));
        }
    }

    fn call_failed(&mut self, kind: CallKind, e: ControllerError) {
        match kind {
            CallKind::Record(id, _) => {
                push(
                    &mut self.events,
                    ControllerEvent::Record { id, result: Err(e) },
                );
                self.send_next_call();
            }
            _ => self.fail(e),
        }
    }

    fn identify(&mut self, now: Duration, tries: u32) {
        self.xid = self.xid.wrapping_add(1);
        let mut b = DcpBlocks::new();
        b.plain(opt::NAME_OF_STATION, self.config.target.as_bytes());
        let pdu = dcp::pdu(
            FrameId::DCP_IDENTIFY_REQ,
            service::IDENTIFY,
            service_type::REQUEST,
            self.xid,
            1,
            &b.into_bytes(),
        );
        push(
            &mut self.tx,
            eth::frame(
                DCP_IDENTIFY_MAC,
                self.config.mac,
                None,
                ethertype::PROFINET,
                &pdu,
            ),
        );
        let wait = if tries == 0 {
            self.config.identify_timeout
        } else {
            self.config.rpc_timeout
        };
        self.state = State::Identify {
            deadline: now + wait,
            tries,
        };
    }

    fn dcp(&mut self, src: Mac, class: FrameClass, h: &DcpHeader<'_>) {
        if h.xid != self.xid {
            return;
        }
        match (self.state, class, h.service_id) {
            (State::Identify { .. }, FrameClass::DcpIdentifyResponse, service::IDENTIFY)
                if h.service_type == service_type::SUCCESS =>
            {
                let mut name = None;
                let mut ip = None;
                let mut id = None;
                for b in h.iter_blocks().filter_map(Result::ok) {
                    let data = b.data.get(2..).unwrap_or(&[]);
                    match (b.option, b.suboption) {
                        o if o == opt::NAME_OF_STATION => name = Some(data.to_vec()),
                        o if o == opt::IP_PARAMETER => {
                            ip = data.get(..4).and_then(|s| <[u8; 4]>::try_from(s).ok())
                        }
                        o if o == opt::DEVICE_ID => {
                            if let [a, b, c, d, ..] = data {
                                id = Some((
                                    u16::from_be_bytes([*a, *b]),
                                    u16::from_be_bytes([*c, *d]),
                                ));
                            }
                        }
                        _ => {}
                    }
                }
                if name.as_deref() != Some(self.config.target.as_bytes()) {
                    return;
                }
                let ip = ip.filter(|i| station::has_ip(*i));
                match (ip, self.config.device_ip) {
                    (Some(ip), _) => {
                        self.device = Some((src, ip));
                        push(
                            &mut self.events,
                            ControllerEvent::Identified { mac: src, ip, id },
                        );
                        self.connect();
                    }
                    (None, Some((ip, mask, gw))) => {
                        self.device = Some((src, ip));
                        push(
                            &mut self.events,
                            ControllerEvent::Identified { mac: src, ip, id },
                        );
                        self.set_ip(src, ip, mask, gw);
                    }
                    (None, None) => {
                        let name = self.config.target.clone();
                        self.fail(ControllerError::NoIp(name));
                    }
                }
            }
            (State::Connecting, FrameClass::DcpGetSet, service::SET) => {
                let Some(c) = self.calls.front() else { return };
                let kind = c.kind;
                if !kind.is_dcp() {
                    return;
                }
                self.calls.pop_front();
                let err = h
                    .iter_blocks()
                    .filter_map(Result::ok)
                    .find(|b| (b.option, b.suboption) == opt::CONTROL_RESPONSE)
                    .and_then(|b| b.data.get(2).copied())
                    .unwrap_or(0xFF);
                if err != dcp::block_error::OK {
                    self.fail(ControllerError::DcpSet(err));
                } else if kind == CallKind::SetName {
                    self.identify(self.now, 0);
                } else {
                    self.connect();
                }
            }
            _ => {}
        }
    }

    fn set_ip(&mut self, dev: Mac, ip: Ipv4, mask: Ipv4, gw: Ipv4) {
        let mut b = DcpBlocks::new();
        b.with_info(
            opt::IP_PARAMETER,
            dcp::PERMANENT,
            &dcp::ip_parameter(ip, mask, gw),
        );
        self.dcp_set(dev, b, CallKind::SetIp);
    }

    /// Gives the device `dev` the NameOfStation `target` (IEC 61158-6-10 DCP Set).
    fn set_name(&mut self, dev: Mac) {
        let mut b = DcpBlocks::new();
        let name = self.config.target.clone();
        b.with_info(opt::NAME_OF_STATION, dcp::PERMANENT, name.as_bytes());
        self.dcp_set(dev, b, CallKind::SetName);
    }

    fn dcp_set(&mut self, dev: Mac, b: DcpBlocks, kind: CallKind) {
        self.xid = self.xid.wrapping_add(1);
        let pdu = dcp::pdu(
            FrameId::DCP_GET_SET,
            service::SET,
            service_type::REQUEST,
            self.xid,
            0,
            &b.into_bytes(),
        );
        let frame = eth::frame(dev, self.config.mac, None, ethertype::PROFINET, &pdu);
        self.state = State::Connecting;
        push(&mut self.tx, frame.clone());
        push(
            &mut self.calls,
            Call {
                kind,
                opnum: 0,
                blocks: Vec::new(),
                sequence: 0,
                deadline: self.now + self.config.rpc_timeout,
                tries: 0,
                frame,
            },
        );
    }

    fn iocr(&self, input: bool) -> IocrBlockReq {
        let id = &self.config.identity;
        let dap: Vec<(u16, u16)> = id
            .dap_submodules
            .iter()
            .map(|(s, _)| (id.dap_slot, *s))
            .collect();
        let fo = |(slot, subslot): (u16, u16), off: usize| FrameOffset {
            slot,
            subslot,
            frame_offset: u16::try_from(off).unwrap_or(u16::MAX),
        };
        let (data_objects, iocs) = if input {
            let mut objects: Vec<FrameOffset> =
                dap.iter().enumerate().map(|(i, s)| fo(*s, i)).collect();
            objects.push(fo((id.input.slot, id.input.subslot), self.layout.in_data));
            let after = self.layout.in_data + usize::from(id.input.length) + 1;
            (
                objects,
                vec![fo((id.output.slot, id.output.subslot), after)],
            )
        } else {
            let mut iocs: Vec<FrameOffset> =
                dap.iter().enumerate().map(|(i, s)| fo(*s, i)).collect();
            iocs.push(fo((id.input.slot, id.input.subslot), dap.len()));
            (
                vec![fo(
                    (id.output.slot, id.output.subslot),
                    self.layout.out_data,
                )],
                iocs,
            )
        };
        IocrBlockReq {
            header: header(block_type::IOCR_REQ),
            iocr_type: if input { 1 } else { 2 },
            reference: if input { 1 } else { 2 },
            lt: ethertype::PROFINET,
            properties: 1,
            data_length: self.config.data_length,
            frame_id: if input {
                INPUT_FRAME_ID
            } else {
                FrameId(0xFFFF)
            },
            send_clock_factor: self.config.send_clock_factor,
            reduction_ratio: self.config.reduction_ratio,
            phase: 1,
            sequence: 0,
            frame_send_offset: 0xFFFF_FFFF,
            watchdog_factor: self.config.data_hold_factor,
            data_hold_factor: self.config.data_hold_factor,
            tag_header: 0xC000,
            multicast_mac: [0; 6],
            apis: vec![IocrApi {
                api: 0,
                data_objects,
                iocs,
            }],
        }
    }

    fn connect(&mut self) {
        self.state = State::Connecting;
        let c = &self.config;
        let mut b = Blocks::new();
        b.ar_req(&ArBlockReq {
            header: header(block_type::AR_REQ),
            ar_type: 1,
            ar_uuid: c.ar_uuid,
            session_key: c.session_key,
            initiator_mac: c.mac,
            initiator_object: c.object,
            properties: 0x0000_0011,
            activity_timeout_factor: 100,
            udp_rt_port: ethertype::PROFINET,
            station_name: c.station_name.clone(),
        });
        b.iocr_req(&self.iocr(true)).iocr_req(&self.iocr(false));
        b.alarm_cr_req(&AlarmCrBlockReq {
            alarm_cr_type: 1,
            lt: ethertype::PROFINET,
            properties: 0,
            rta_timeout_factor: 1,
            rta_retries: 3,
            local_alarm_reference: ALARM_REF,
            max_alarm_data_length: 200,
            tag_header_high: 0xC000,
            tag_header_low: 0xA000,
        });
        b.expected(&self.config.identity.expected_submodules());
        self.queue_call(CallKind::Connect, 0, b.into_bytes());
    }

    fn control_block(&self, kind: ControlKind, command: u16) -> Vec<u8> {
        let mut b = Blocks::new();
        b.control(&ControlBlock {
            header: header(cm::control_block_type(kind)),
            kind,
            response: false,
            ar_uuid: self.config.ar_uuid,
            session_key: self.config.session_key,
            command,
            properties: 0,
        });
        b.into_bytes()
    }

    fn record_blocks(
        &mut self,
        slot: u16,
        subslot: u16,
        index: u16,
        data: Option<&[u8]>,
    ) -> Vec<u8> {
        let seq = self.record_seq;
        self.record_seq = self.record_seq.wrapping_add(1);
        let req = RecordRequest {
            header: header(if data.is_some() {
                block_type::WRITE_REQ
            } else {
                block_type::READ_REQ
            }),
            sequence: seq,
            ar_uuid: self.config.ar_uuid,
            api: 0,
            slot,
            subslot,
            index,
            record_data_length: 4096,
            target_ar_uuid: Some(Uuid::default()),
            data: data.map(<[u8]>::to_vec).unwrap_or_default(),
        };
        let mut b = Blocks::new();
        match data {
            Some(_) => b.write_req(&req),
            None => b.read_req(&req),
        };
        b.into_bytes()
    }

    fn record(
        &mut self,
        now: Duration,
        slot: u16,
        subslot: u16,
        index: u16,
        data: Option<&[u8]>,
    ) -> Result<RecordId, ControllerError> {
        self.advance(now);
        if self.state != State::Running {
            return Err(ControllerError::NotRunning);
        }
        if self.calls.len() >= MAX_QUEUED {
            return Err(ControllerError::Busy);
        }
        let id = RecordId(self.next_record);
        self.next_record += 1;
        let blocks = self.record_blocks(slot, subslot, index, data);
        let opnum = if data.is_some() { 3 } else { 2 };
        self.queue_call(CallKind::Record(id, data.is_some()), opnum, blocks);
        Ok(id)
    }

    fn activity(&self) -> Uuid {
        let mut u = self.config.ar_uuid;
        if let Some(b) = u.0.get_mut(15) {
            *b = b.wrapping_add(1);
        }
        u
    }

    /// Adds a call; it goes out when the calls before it are answered.
    fn queue_call(&mut self, kind: CallKind, opnum: u16, blocks: Vec<u8>) {
        let idle = self.calls.is_empty();
        push(
            &mut self.calls,
            Call {
                kind,
                opnum,
                blocks,
                sequence: 0,
                deadline: Duration::MAX,
                tries: 0,
                frame: Vec::new(),
            },
        );
        if idle {
            self.send_next_call();
        }
    }

    fn send_next_call(&mut self) {
        let Some((dev, dev_ip)) = self.device else {
            return;
        };
        let seq = self.sequence;
        let object = self.config.identity.object_uuid();
        let activity = self.activity();
        let ep = Endpoints {
            src: self.config.ip,
            src_port: CLIENT_PORT,
            dst: dev_ip,
            dst_port: PNIO_PORT,
        };
        let (mac, deadline) = (self.config.mac, self.now + self.config.rpc_timeout);
        self.ip_id = self.ip_id.wrapping_add(1);
        let ip_id = self.ip_id;
        let Some(c) = self.calls.front_mut() else {
            return;
        };
        if c.kind.is_dcp() {
            return;
        }
        let body = cm::request(4096, &c.blocks, rpc::DREP.integer);
        let header = rpc::request_header(object, Uuid::PNIO_DEVICE, activity, seq, c.opnum);
        c.sequence = seq;
        c.deadline = deadline;
        c.frame = station::rpc_frame(mac, dev, ep, ip_id, &header, &body);
        let f = c.frame.clone();
        self.sequence = self.sequence.wrapping_add(1);
        push(&mut self.tx, f);
    }

    fn cm(&mut self, src: Mac, ep: Endpoints, h: &Header, m: &CmMessage) {
        if self.device.is_none_or(|(d, _)| d != src) {
            return;
        }
        match (h.ptype, m.direction) {
            (PacketType::RESPONSE, Direction::Response) if ep.dst_port == CLIENT_PORT => {
                let matches = self.calls.front().is_some_and(|c| {
                    c.sequence == h.sequence && h.activity == self.activity() && !c.kind.is_dcp()
                });
                if !matches {
                    return;
                }
                let Some(call) = self.calls.pop_front() else {
                    return;
                };
                self.answer(call.kind, m);
                if self.state != State::Closed {
                    self.send_next_call();
                }
            }
            (PacketType::REQUEST, Direction::Request)
                if ep.dst_port == PNIO_PORT && m.operation == Operation::Control =>
            {
                self.application_ready(src, ep, h, m);
            }
            _ => {}
        }
    }

    fn answer(&mut self, kind: CallKind, m: &CmMessage) {
        let st = m.ndr.status.unwrap_or_default();
        let refused = |s| ControllerError::Refused {
            operation: kind.name(),
            status: s,
        };
        match kind {
            CallKind::SetIp | CallKind::SetName => {}
            CallKind::Connect => {
                if !st.is_ok() {
                    return self.fail(refused(st));
                }
                let out_frame = m.blocks.iter().find_map(|b| match b {
                    Block::IocrRes(r) if r.iocr_type == 2 => Some(r.frame_id),
                    _ => None,
                });
                let Some(out_frame) = out_frame else {
                    return self.fail(ControllerError::Malformed("Connect"));
                };
                let diff: Vec<DiffModule> = m
                    .blocks
                    .iter()
                    .filter_map(|b| match b {
                        Block::Unknown(u) => module_diff(u),
                        _ => None,
                    })
                    .filter_map(Result::ok)
                    .flat_map(|d| d.modules)
                    .filter(wrong)
                    .collect();
                self.output_frame = out_frame;
                self.input_frame = m
                    .blocks
                    .iter()
                    .find_map(|b| match b {
                        Block::IocrRes(r) if r.iocr_type == 1 => Some(r.frame_id),
                        _ => None,
                    })
                    .unwrap_or(INPUT_FRAME_ID);
                self.alarm_remote = m
                    .blocks
                    .iter()
                    .filter_map(|b| match b {
                        Block::Unknown(u) => alarm_cr_res(u),
                        _ => None,
                    })
                    .filter_map(Result::ok)
                    .map(|a| a.local_alarm_reference)
                    .next();
                self.cyclic = true;
                self.next_send = self.now;
                self.input_deadline = Duration::MAX;
                if !diff.is_empty() {
                    // Release the AR the device holds, then report.
                    let blocks = self.control_block(ControlKind::Release, control_command::RELEASE);
                    self.calls.clear();
                    self.queue_call(CallKind::Release, 1, blocks);
                    self.calls.clear();
                    return self.fail(ControllerError::ModuleDiff(diff));
                }
                push(&mut self.events, ControllerEvent::Connected);
                let id = &self.config.identity;
                let (slot, subslot) = (id.output.slot, id.output.subslot);
                for (index, data) in self.config.prm_records.clone() {
                    let blocks = self.record_blocks(slot, subslot, index, Some(&data));
                    self.calls.push_back(Call {
                        kind: CallKind::Prm,
                        opnum: 3,
                        blocks,
                        sequence: 0,
                        deadline: Duration::MAX,
                        tries: 0,
                        frame: Vec::new(),
                    });
                }
                let blocks = self.control_block(ControlKind::PrmEnd, control_command::PRM_END);
                self.calls.push_back(Call {
                    kind: CallKind::PrmEnd,
                    opnum: 4,
                    blocks,
                    sequence: 0,
                    deadline: Duration::MAX,
                    tries: 0,
                    frame: Vec::new(),
                });
            }
            CallKind::Prm => {
                let block_status = record_status(m);
                if !st.is_ok() || !block_status.is_ok() {
                    let s = if st.is_ok() { block_status } else { st };
                    self.fail(refused(s));
                }
            }
            CallKind::PrmEnd => {
                if !st.is_ok() {
                    return self.fail(refused(st));
                }
                self.state = State::WaitAppReady {
                    deadline: self.now + self.config.app_ready_timeout,
                };
            }
            CallKind::Record(id, write) => {
                let block_status = record_status(m);
                let result = if !st.is_ok() {
                    Err(refused(st))
                } else if !block_status.is_ok() {
                    Err(refused(block_status))
                } else if write {
                    Ok(Vec::new())
                } else {
                    m.blocks
                        .iter()
                        .find_map(|b| match b {
                            Block::ReadRes(r) => Some(r.data.clone()),
                            _ => None,
                        })
                        .ok_or(ControllerError::Malformed("Read"))
                };
                push(&mut self.events, ControllerEvent::Record { id, result });
            }
            CallKind::Release => {
                self.cyclic = false;
                self.state = State::Closed;
                if st.is_ok() {
                    push(&mut self.events, ControllerEvent::Released);
                } else {
                    push(&mut self.events, ControllerEvent::Failed(refused(st)));
                }
            }
        }
    }

    fn application_ready(&mut self, src: Mac, ep: Endpoints, h: &Header, m: &CmMessage) {
        let Some(c) = m.blocks.iter().find_map(|b| match b {
            Block::Control(c) if !c.response && c.kind == ControlKind::ApplicationReady => Some(c),
            _ => None,
        }) else {
            return;
        };
        let ok = c.ar_uuid == self.config.ar_uuid && c.session_key == self.config.session_key;
        let (st, blocks) = if ok {
            let mut b = Blocks::new();
            b.control(&ControlBlock {
                header: c.header,
                kind: c.kind,
                response: true,
                ar_uuid: c.ar_uuid,
                session_key: c.session_key,
                command: control_command::DONE,
                properties: 0,
            });
            (PnioStatus::default(), b.into_bytes())
        } else {
            (
                status::status(
                    status::CONTROL,
                    status::PNIO,
                    status::code1::CONTROL_BLOCK,
                    5,
                ),
                Vec::new(),
            )
        };
        let body = cm::response(st, &blocks, rpc::DREP.integer);
        let header = rpc::response_header(h, 1);
        self.ip_id = self.ip_id.wrapping_add(1);
        let f = station::rpc_frame(
            self.config.mac,
            src,
            station::reply(ep),
            self.ip_id,
            &header,
            &body,
        );
        push(&mut self.tx, f);
        if ok && matches!(self.state, State::WaitAppReady { .. }) {
            self.state = State::Running;
            self.input_deadline =
                self.now + self.period() * u32::from(self.config.data_hold_factor);
            push(&mut self.events, ControllerEvent::Running);
        }
    }

    /// An RTA-PDU from the device (IEC 61158-6-10 APMR/ALPMR): ERR ends the AR; DATA (an
    /// alarm notification) is acknowledged at once by an ACK-RTA-PDU and answered with an
    /// AlarmAck in a DATA-RTA-PDU; a repeated DATA gets the ACK again. The AlarmAck is sent
    /// once (a lost one is not repeated; the device repeats its notification).
    fn alarm(&mut self, frame_id: FrameId, a: &drivespec_capture::rt::AlarmHeader<'_>) {
        let Some((dev, _)) = self.device else { return };
        match a.pdu_type & 0x0f {
            4 => {
                let s = match a.var_part {
                    [a, b, c, d, ..] => status::status(*a, *b, *c, *d),
                    _ => PnioStatus::default(),
                };
                self.fail(ControllerError::Aborted(s));
            }
            1 => {
                let Some(remote) = self.alarm_remote.filter(|_| self.cyclic) else {
                    return;
                };
                let fresh = a.send_seq == self.rta.expected;
                if !fresh && a.send_seq != self.rta.received {
                    return;
                }
                if fresh {
                    self.rta.received = a.send_seq;
                    self.rta.expected = next_seq(a.send_seq);
                }
                let ack = rt::alarm(
                    frame_id,
                    remote,
                    ALARM_REF,
                    rt::pdu_type::ACK,
                    self.rta.sent,
                    self.rta.received,
                    &[],
                );
                let mac = self.config.mac;
                push(
                    &mut self.tx,
                    eth::frame(dev, mac, None, ethertype::PROFINET, &ack),
                );
                if !fresh {
                    return;
                }
                let Some(n) = alarm_notification(a.var_part) else {
                    return;
                };
                let mut body = Vec::with_capacity(16);
                body.extend_from_slice(&n.alarm_type.to_be_bytes());
                body.extend_from_slice(&n.api.to_be_bytes());
                body.extend_from_slice(&n.slot.to_be_bytes());
                body.extend_from_slice(&n.subslot.to_be_bytes());
                body.extend_from_slice(&n.specifier.to_be_bytes());
                body.extend_from_slice(&cm::status_u32(PnioStatus::default()).to_be_bytes());
                let mut b = Blocks::new();
                b.other(n.block_type | 0x8000, &body);
                let data = rt::alarm(
                    frame_id,
                    remote,
                    ALARM_REF,
                    rt::pdu_type::DATA,
                    self.rta.send,
                    self.rta.received,
                    &b.into_bytes(),
                );
                push(
                    &mut self.tx,
                    eth::frame(dev, mac, None, ethertype::PROFINET, &data),
                );
                push(&mut self.events, ControllerEvent::Alarm(n));
            }
            3 if a.ack_seq == self.rta.send => {
                self.rta.sent = self.rta.send;
                self.rta.send = next_seq(self.rta.send);
            }
            _ => {}
        }
    }

    fn output_frame(&self, at: Duration) -> Vec<u8> {
        let Some((dev, _)) = self.device else {
            return Vec::new();
        };
        let mut c_sdu = vec![ioxs::GOOD; self.layout.out_data];
        c_sdu.extend_from_slice(&self.output);
        c_sdu.push(ioxs::GOOD);
        c_sdu.resize(MIN_C_SDU.max(c_sdu.len()), 0);
        let pdu = rt::cyclic(
            self.output_frame,
            &c_sdu,
            cycle_counter(at),
            data_status::GOOD_RUN,
        );
        eth::frame(dev, self.config.mac, None, ethertype::PROFINET, &pdu)
    }
}

/// Whether a ModuleDiffBlock entry means the device is not the expected PSD4xx: no module or
/// a wrong module (ModuleState 0, 1), or a submodule whose IdentInfo (SubmoduleState format
/// 1, bits 11–14) is Wrong (2) or NoSubmodule (3). Substitutes and entries that only report
/// ARInfo or diagnosis (e.g. ApplicationReadyPending) are accepted (IEC 61158-6-10
/// "ModuleDiffBlock").
fn wrong(m: &DiffModule) -> bool {
    let bad_sub = |s: &drivespec_capture::pnio::DiffSubmodule| {
        s.state & 0x8000 != 0 && matches!((s.state >> 11) & 0x0F, 2 | 3)
    };
    matches!(m.state, 0 | 1) || m.submodules.iter().any(bad_sub)
}

fn header(block_type: u16) -> BlockHeader {
    BlockHeader {
        block_type,
        length: 0,
        version_high: 1,
        version_low: 0,
        offset: 0,
    }
}

fn record_status(m: &CmMessage) -> PnioStatus {
    m.blocks
        .iter()
        .find_map(|b| match b {
            Block::WriteRes(r) => r.status,
            _ => None,
        })
        .unwrap_or_default()
}
