//! The PSD4xx reference drive as a PROFINET IO device (IEC 61158-6-10 RT class 1; manual
//! 3.2–3.9): DCP, PNIO-CM Connect/Read/Write/Control/Release with refusals and their
//! PNIOStatus, cyclic input frames at the controller's send clock × reduction ratio, the
//! output watchdog (DataHoldFactor) ending the AR, the ERR-RTA alarm of an abort, and the
//! drive's output behaviour of 3.9 on a lost connection and on bad IOPS.
//!
//! Sans-IO: [`Device::handle_frame`], [`Device::handle_timeout`], [`Device::handle_link`]
//! in; [`Device::poll_transmit`], [`Device::poll_event`], [`Device::poll_timeout`] out.
//! Memory is bounded: at most [`MAX_QUEUED`] frames and events wait, at most
//! [`MAX_CACHED`] answers are kept for repeated calls. Nothing panics on any frame.
//!
//! Choices where the standard leaves room (documented, each a legal device behaviour):
//! - Identify responses go out at once (ResponseDelay spreads answers of many devices; one
//!   device may answer at any time within it).
//! - One AR at a time; a second Connect is refused with CMRPC "out of AR resources".
//! - A Connect whose expected modules differ in ident is accepted with a ModuleDiffBlock
//!   (IEC 61158-6-10 "ModuleDiffBlock": WrongModule / NoModule); the drive then ignores the
//!   outputs and its input submodule reports IOPS bad. A Connect whose lengths do not fit
//!   the modules of 3.2.1 is refused with the faulty field.
//! - DCP Set of NameOfStation or IP while an AR runs is refused (BlockError "SET not
//!   possible by local reasons").
//! - Calls to other RPC interfaces are rejected (nca_unk_if); a ping repeats a kept answer
//!   or gets nocall. ARP requests for the device's address are answered.

use crate::cm::{self, Blocks};
use crate::dcp::{self, block_error, opt, service, service_type, DcpBlocks};
use crate::eth::{self, Mac, DCP_HELLO_MAC, DCP_IDENTIFY_MAC};
use crate::identity::Identity;
use crate::rpc;
use crate::rt::{self, data_status, ioxs, MAX_C_SDU, MIN_C_SDU};
use crate::station::{self, classify, cycle, cycle_counter, micros, Incoming};
use crate::status::{self, code1, code2, rw};
use crate::udp::{Endpoints, Ipv4};
use drivespec_capture::dcerpc::{PacketType, Uuid, PNIO_PORT};
use drivespec_capture::link::ethertype;
use drivespec_capture::pnio::{
    alarm_cr_req, control_command, AlarmCrBlockRes, ArBlockReq, ArBlockRes, Block, CmMessage,
    ControlBlock, ControlKind, DiffModule, DiffSubmodule, Direction, ExpectedModule, IocrBlockReq,
    IocrBlockRes, ModuleDiff, Operation, PnioStatus, RecordRequest, RecordResponse,
};
use drivespec_capture::rt::{CyclicFrame, DcpHeader, FrameClass, FrameId};
use drivespec_psd4xx::model::{
    Drive, DriveConfig, Event, LinkEvent, ModelError, RecordAnswer, RecordFailure,
    RecordRequest as DriveRecord,
};
use drivespec_spec::Spec;
use std::collections::VecDeque;
use std::time::Duration;

/// Most frames and events waiting to be drained.
pub const MAX_QUEUED: usize = 256;
/// Most answers kept to repeat for a repeated call (same activity and sequence).
pub const MAX_CACHED: usize = 16;

/// The reject status of an unknown interface (C706 appendix E: nca_unk_if).
pub const NCA_UNK_IF: u32 = 0x1C01_0003;
/// The reject status of an operation number out of range (C706 appendix E: nca_op_rng_error).
pub const NCA_OP_RNG_ERROR: u32 = 0x1C01_0002;

/// Most option pairs of one DCP Get answered (the answer stays within one frame).
pub const MAX_GET: usize = 32;

/// Record index of I&M0 (IEC 61158-6-10 "Index": 0xAFF0).
pub const IM0_INDEX: u16 = 0xAFF0;

/// The UDP port the device's own RPC calls (ApplicationReady) go out from.
pub const CLIENT_PORT: u16 = 0xC000;

/// SendClockFactors accepted: 250 µs to 4 ms (IEC 61158-6-10 RT class 1 allows powers of
/// two from 1; the PSD4xx manual gives no cycle, 3.2: RT only).
pub const SEND_CLOCKS: [u16; 5] = [8, 16, 32, 64, 128];
/// Largest ReductionRatio accepted (IEC 61158-6-10 RT class 1: powers of two to 512).
pub const MAX_REDUCTION: u16 = 512;
/// DataHoldFactor range accepted (IEC 61158-6-10 "DataHoldFactor": 3 to 0x1E00).
pub const DATA_HOLD: std::ops::RangeInclusive<u16> = 3..=0x1E00;

/// Time between repeats of ApplicationReady while the controller does not answer.
pub const RPC_RESEND: Duration = Duration::from_millis(500);

/// Why a device cannot be built (our doc: module `device`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DeviceError {
    /// The drive model.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The identity.
    #[error(transparent)]
    Identity(#[from] crate::identity::IdentityError),
}

/// How to build a device (our doc: module `device`).
#[derive(Debug, Clone)]
pub struct DeviceConfig {
    /// Own MAC address.
    pub mac: Mac,
    /// IP address (0.0.0.0: none until a DCP Set).
    pub ip: Ipv4,
    /// Subnet mask.
    pub netmask: Ipv4,
    /// Gateway.
    pub gateway: Ipv4,
    /// NameOfStation (empty: none until a DCP Set).
    pub station_name: String,
    /// Vendor and device ID, slots and idents.
    pub identity: Identity,
    /// The drive model.
    pub drive: DriveConfig,
    /// Send a DCP Hello when the link comes up.
    pub hello: bool,
    /// Server boot time in the RPC headers.
    pub server_boot: u32,
}

impl DeviceConfig {
    /// A device of `model` at `mac` named `station_name`, with the spec's identity.
    pub fn new(
        spec: &Spec,
        model: &str,
        mac: Mac,
        station_name: &str,
    ) -> Result<DeviceConfig, DeviceError> {
        let mut drive = DriveConfig::new(model);
        drive.connected = false;
        drive.station_name = station_name.to_owned();
        Ok(DeviceConfig {
            mac,
            ip: [0; 4],
            netmask: [0; 4],
            gateway: [0; 4],
            station_name: station_name.to_owned(),
            identity: Identity::from_spec(spec)?,
            drive,
            hello: false,
            server_boot: 1,
        })
    }
}

/// Why an AR ended (our doc: module `device`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArEnd {
    /// The controller released it.
    Released,
    /// No valid output frame for DataHoldFactor cycles.
    Watchdog,
    /// The link went down.
    LinkDown,
    /// The controller did not answer ApplicationReady in its activity timeout.
    CmiTimeout,
    /// The controller aborted it (ERR-RTA).
    Aborted(PnioStatus),
}

/// What the device did, for logs and tests (our doc: module `device`).
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum DeviceEvent {
    /// A DCP Set changed the NameOfStation.
    NameSet(String),
    /// A DCP Set changed the IP suite.
    IpSet(Ipv4),
    /// DCP Signal: flash the LED (3.1).
    Signal,
    /// A Connect was accepted (with a ModuleDiffBlock when `diff`).
    Connected {
        /// The AR.
        ar_uuid: Uuid,
        /// Whether the expected modules differ from the real ones.
        diff: bool,
    },
    /// A call was refused with this PNIOStatus.
    Refused {
        /// The operation.
        operation: Operation,
        /// The status sent.
        status: PnioStatus,
    },
    /// PrmEnd received.
    PrmEnd,
    /// The controller confirmed ApplicationReady: data exchange.
    Data,
    /// The AR ended.
    ArEnded(ArEnd),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    WaitPrmEnd,
    AppReady { next: Duration, deadline: Duration },
    Data,
}

#[derive(Debug, Clone)]
struct InputCr {
    frame_id: FrameId,
    data_length: usize,
    period: Duration,
    next: Duration,
    /// (slot, subslot, offset) of each data object.
    objects: Vec<(u16, u16, usize)>,
    /// (slot, subslot, offset) of each IOCS.
    iocs: Vec<(u16, u16, usize)>,
}

#[derive(Debug, Clone)]
struct OutputCr {
    frame_id: FrameId,
    data_length: usize,
    /// Offset of the output module's data (its IOPS follows it).
    offset: usize,
    hold: Duration,
    deadline: Duration,
    /// A valid frame arrived (the DataHoldFactor watchdog runs).
    seen: bool,
}

#[derive(Debug, Clone)]
struct Ar {
    uuid: Uuid,
    session_key: u16,
    controller: Mac,
    controller_ip: Ipv4,
    controller_object: Uuid,
    activity_timeout: Duration,
    input: InputCr,
    output: OutputCr,
    alarm_remote: u16,
    phase: Phase,
    psd_ok: bool,
    iops_good: bool,
    client_seq: u32,
}

/// Local alarm reference of the device (IEC 61158-6-10 "LocalAlarmReference").
const ALARM_REF: u16 = 0x0001;
/// MaxAlarmDataLength answered (IEC 61158-6-10: 200 to 1432).
const MAX_ALARM_DATA: u16 = 200;
/// RT class 1 FrameIDs the device assigns to output CRs (IEC 61158-6-10: 0xC000–0xF7FF).
const OUTPUT_FRAME_ID: FrameId = FrameId(0xC100);

/// A PSD4xx reference drive behind a PROFINET IO device (our doc: module `device`).
#[derive(Debug, Clone)]
pub struct Device {
    config: DeviceConfig,
    drive: Drive,
    name: String,
    ip: Ipv4,
    netmask: Ipv4,
    gateway: Ipv4,
    link_up: bool,
    ar: Option<Ar>,
    tx: VecDeque<Vec<u8>>,
    events: VecDeque<DeviceEvent>,
    cache: VecDeque<((Uuid, u32), Vec<u8>)>,
    ip_id: u16,
    now: Duration,
}

fn push<T>(q: &mut VecDeque<T>, v: T) {
    if q.len() >= MAX_QUEUED {
        q.pop_front();
    }
    q.push_back(v);
}

impl crate::SansIo for Device {
    fn handle_frame(&mut self, now: Duration, frame: &[u8]) {
        Device::handle_frame(self, now, frame);
    }
    fn handle_timeout(&mut self, now: Duration) {
        Device::handle_timeout(self, now);
    }
    fn poll_transmit(&mut self, now: Duration) -> Option<Vec<u8>> {
        Device::poll_transmit(self, now)
    }
    fn poll_timeout(&self) -> Option<Duration> {
        Device::poll_timeout(self)
    }
}

impl Device {
    /// A device switched on at time 0 with the link up (manual 2.2).
    pub fn new(spec: &Spec, config: DeviceConfig) -> Result<Device, DeviceError> {
        let drive = Drive::new(spec, config.drive.clone())?;
        let mut d = Device {
            name: config.station_name.clone(),
            ip: config.ip,
            netmask: config.netmask,
            gateway: config.gateway,
            config,
            drive,
            link_up: true,
            ar: None,
            tx: VecDeque::new(),
            events: VecDeque::new(),
            cache: VecDeque::new(),
            ip_id: 0,
            now: Duration::ZERO,
        };
        if d.config.hello {
            d.hello();
        }
        Ok(d)
    }

    /// The drive model behind the device.
    pub fn drive(&self) -> &Drive {
        &self.drive
    }

    /// The NameOfStation in force.
    pub fn station_name(&self) -> &str {
        &self.name
    }

    /// The IP address in force.
    pub fn ip(&self) -> Ipv4 {
        self.ip
    }

    /// Whether an AR exists, and whether it exchanges data.
    pub fn ar_state(&self) -> Option<bool> {
        self.ar.as_ref().map(|a| a.phase == Phase::Data)
    }

    /// The next frame to send at `now`: answers first, then a cyclic frame when one is due.
    pub fn poll_transmit(&mut self, now: Duration) -> Option<Vec<u8>> {
        self.advance(now);
        if let Some(f) = self.tx.pop_front() {
            return Some(f);
        }
        if !self.link_up {
            return None;
        }
        let ar = self.ar.as_mut()?;
        if now < ar.input.next {
            return None;
        }
        let at = ar.input.next;
        ar.input.next = at + ar.input.period;
        if ar.input.next <= now {
            ar.input.next = now + ar.input.period;
        }
        let frame = self.input_frame(at);
        Some(frame)
    }

    /// The next event, oldest first.
    pub fn poll_event(&mut self) -> Option<DeviceEvent> {
        self.events.pop_front()
    }

    /// When [`Device::handle_timeout`] or [`Device::poll_transmit`] has work next.
    pub fn poll_timeout(&self) -> Option<Duration> {
        if !self.tx.is_empty() {
            return Some(self.now);
        }
        let drive = self.drive.poll_timeout().map(Duration::from_micros);
        let ar = self.ar.as_ref().filter(|_| self.link_up).map(|a| {
            let mut t = a.input.next.min(a.output.deadline);
            if let Phase::AppReady { next, deadline } = a.phase {
                t = t.min(next).min(deadline);
            }
            t
        });
        match (drive, ar) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// Runs timers up to `now`: the drive, the output watchdog, ApplicationReady repeats.
    pub fn handle_timeout(&mut self, now: Duration) {
        self.advance(now);
    }

    /// The link went down (`false`) or came up (`true`) at `now` (manual 3.9: a lost
    /// connection sets the outputs to 0).
    pub fn handle_link(&mut self, now: Duration, up: bool) {
        self.advance(now);
        if up == self.link_up {
            return;
        }
        self.link_up = up;
        if up {
            if self.config.hello {
                self.hello();
            }
        } else {
            self.tx.clear();
            self.end_ar(ArEnd::LinkDown, None);
        }
    }

    /// A frame received at `now`. Frames for other stations and anything malformed are
    /// ignored.
    pub fn handle_frame(&mut self, now: Duration, frame: &[u8]) {
        self.advance(now);
        if !self.link_up {
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
            } if eth::accepts(own, dst, &[DCP_IDENTIFY_MAC]) => self.dcp(src, class, &dcp),
            Incoming::Cyclic { src, dst, frame } if dst == own => self.cyclic(now, src, &frame),
            Incoming::Alarm { src, dst, alarm } if dst == own => {
                let from_controller = self.ar.as_ref().is_some_and(|a| a.controller == src);
                if from_controller && alarm.pdu_type & 0x0f == 4 {
                    let s = alarm.var_part;
                    let status = match s {
                        [a, b, c, d, ..] => status::status(*a, *b, *c, *d),
                        _ => PnioStatus::default(),
                    };
                    self.end_ar(ArEnd::Aborted(status), None);
                }
            }
            Incoming::Cm {
                src,
                dst,
                ep,
                header,
                message,
            } if dst == own && ep.dst == self.ip && station::has_ip(self.ip) => {
                self.cm(now, src, ep, &header, &message)
            }
            Incoming::Arp(payload) => {
                if let Some(f) = crate::arp::answer(payload, own, self.ip) {
                    push(&mut self.tx, f);
                }
            }
            Incoming::OtherRpc {
                src,
                dst,
                ep,
                header,
                ..
            } if dst == own && ep.dst == self.ip && station::has_ip(self.ip) => {
                self.other_rpc(src, ep, &header)
            }
            _ => {}
        }
    }

    // ------------------------------------------------------------------ time

    fn advance(&mut self, now: Duration) {
        self.now = self.now.max(now);
        let now = self.now;
        self.drive.advance(micros(now));
        self.drain_drive();
        let Some(ar) = self.ar.as_mut() else {
            return;
        };
        if !self.link_up {
            return;
        }
        if now >= ar.output.deadline {
            let (end, reason) = if ar.output.seen {
                (ArEnd::Watchdog, code2::DHT_EXPIRED)
            } else {
                (ArEnd::CmiTimeout, code2::CMI_TIMEOUT)
            };
            self.end_ar(end, Some(status::abort(reason)));
            return;
        }
        if let Phase::AppReady { next, deadline } = ar.phase {
            if now >= deadline {
                self.end_ar(ArEnd::CmiTimeout, Some(status::abort(code2::CMI_TIMEOUT)));
            } else if now >= next {
                ar.phase = Phase::AppReady {
                    next: now + RPC_RESEND,
                    deadline,
                };
                self.application_ready();
            }
        }
    }

    /// Drops the drive's input images (the cyclic frames read the current one) and follows
    /// its events: par. 96 = -3 deletes the station name (manual 3.3, 2.1).
    fn drain_drive(&mut self) {
        while self.drive.poll_input().is_some() {}
        while let Some((_, e)) = self.drive.poll_event() {
            if e == Event::StationNameCleared && !self.name.is_empty() {
                self.name.clear();
                push(&mut self.events, DeviceEvent::NameSet(String::new()));
            }
        }
    }

    fn end_ar(&mut self, why: ArEnd, alarm: Option<PnioStatus>) {
        let Some(ar) = self.ar.take() else {
            return;
        };
        // Answers kept for repeated calls belong to the AR: a controller that connects again
        // with the same activity gets its calls executed, not an old answer.
        self.cache.clear();
        if let Some(s) = alarm {
            let pdu = rt::abort(ar.alarm_remote, ALARM_REF, s);
            let f = eth::frame(
                ar.controller,
                self.config.mac,
                None,
                ethertype::PROFINET,
                &pdu,
            );
            push(&mut self.tx, f);
        }
        // Manual 3.9: a lost connection sets the outputs to 0 (and aborts a run, 4.9).
        self.drive.handle_link(micros(self.now), LinkEvent::Lost);
        push(&mut self.events, DeviceEvent::ArEnded(why));
    }

    // ------------------------------------------------------------------ DCP

    fn own_blocks(&self, b: &mut DcpBlocks, with_options: bool) {
        let ip_info = if station::has_ip(self.ip) {
            dcp::IP_SET
        } else {
            0
        };
        let id = &self.config.identity;
        b.with_info(opt::NAME_OF_STATION, 0, self.name.as_bytes())
            .with_info(
                opt::IP_PARAMETER,
                ip_info,
                &dcp::ip_parameter(self.ip, self.netmask, self.gateway),
            );
        let mut dev = id.vendor_id.to_be_bytes().to_vec();
        dev.extend_from_slice(&id.device_id.to_be_bytes());
        b.with_info(opt::DEVICE_ID, 0, &dev)
            .with_info(opt::DEVICE_VENDOR, 0, self.vendor_text().as_bytes())
            .with_info(opt::DEVICE_ROLE, 0, &[id.device_role, 0]);
        if with_options {
            let supported = [
                opt::IP_MAC,
                opt::IP_PARAMETER,
                opt::DEVICE_VENDOR,
                opt::NAME_OF_STATION,
                opt::DEVICE_ID,
                opt::DEVICE_ROLE,
                opt::DEVICE_OPTIONS,
                opt::CONTROL_START,
                opt::CONTROL_STOP,
                opt::CONTROL_SIGNAL,
                opt::CONTROL_RESPONSE,
                opt::CONTROL_FACTORY_RESET,
                opt::DEVICE_INITIATIVE,
            ];
            let list: Vec<u8> = supported.iter().flat_map(|(o, s)| [*o, *s]).collect();
            b.with_info(opt::DEVICE_OPTIONS, 0, &list);
        }
    }

    fn vendor_text(&self) -> String {
        self.config.drive.model.to_uppercase()
    }

    fn hello(&mut self) {
        let mut b = DcpBlocks::new();
        self.own_blocks(&mut b, false);
        b.with_info(opt::DEVICE_INITIATIVE, 0, &[0x00, 0x01]);
        let pdu = dcp::pdu(
            FrameId::DCP_HELLO,
            service::HELLO,
            service_type::REQUEST,
            0x0000_0001,
            0,
            &b.into_bytes(),
        );
        let f = eth::frame(
            DCP_HELLO_MAC,
            self.config.mac,
            None,
            ethertype::PROFINET,
            &pdu,
        );
        push(&mut self.tx, f);
    }

    fn dcp_reply(
        &mut self,
        to: Mac,
        frame_id: FrameId,
        sid: u8,
        stype: u8,
        xid: u32,
        blocks: &[u8],
    ) {
        let pdu = dcp::pdu(frame_id, sid, stype, xid, 0, blocks);
        let f = eth::frame(to, self.config.mac, None, ethertype::PROFINET, &pdu);
        push(&mut self.tx, f);
    }

    fn dcp(&mut self, src: Mac, class: FrameClass, h: &DcpHeader<'_>) {
        if h.service_type != service_type::REQUEST {
            return;
        }
        match (class, h.service_id) {
            (FrameClass::DcpIdentifyRequest, service::IDENTIFY) if self.identify_matches(h) => {
                let mut b = DcpBlocks::new();
                self.own_blocks(&mut b, true);
                let blocks = b.into_bytes();
                self.dcp_reply(
                    src,
                    FrameId::DCP_IDENTIFY_RES,
                    service::IDENTIFY,
                    service_type::SUCCESS,
                    h.xid,
                    &blocks,
                );
            }
            (FrameClass::DcpGetSet, service::GET) => {
                let mut b = DcpBlocks::new();
                let mut full = DcpBlocks::new();
                self.own_blocks(&mut full, true);
                let full = full.into_bytes();
                for pair in h.blocks.chunks_exact(2).take(MAX_GET) {
                    let &[o, s] = pair else { continue };
                    let found = DcpHeader {
                        blocks: &full,
                        ..*h
                    }
                    .iter_blocks()
                    .filter_map(Result::ok)
                    .find(|x| (x.option, x.suboption) == (o, s));
                    match found {
                        Some(x) => {
                            b.plain((o, s), x.data);
                        }
                        None if (o, s) == opt::IP_MAC => {
                            b.with_info(opt::IP_MAC, 0, &self.config.mac);
                        }
                        None => {
                            b.plain(opt::CONTROL_RESPONSE, &[o, s, block_error::SUBOPTION]);
                        }
                    }
                }
                let blocks = b.into_bytes();
                self.dcp_reply(
                    src,
                    FrameId::DCP_GET_SET,
                    service::GET,
                    service_type::SUCCESS,
                    h.xid,
                    &blocks,
                );
            }
            (FrameClass::DcpGetSet, service::SET) => {
                let mut b = DcpBlocks::new();
                let blocks: Vec<_> = h.iter_blocks().filter_map(Result::ok).collect();
                for x in blocks {
                    let err = self.dcp_set((x.option, x.suboption), x.data.get(2..).unwrap_or(&[]));
                    b.plain(opt::CONTROL_RESPONSE, &[x.option, x.suboption, err]);
                }
                let blocks = b.into_bytes();
                self.dcp_reply(
                    src,
                    FrameId::DCP_GET_SET,
                    service::SET,
                    service_type::SUCCESS,
                    h.xid,
                    &blocks,
                );
            }
            _ => {}
        }
    }

    fn identify_matches(&self, h: &DcpHeader<'_>) -> bool {
        let id = &self.config.identity;
        let mut any = false;
        for b in h.iter_blocks() {
            let Ok(b) = b else { return false };
            any = true;
            let ok = match (b.option, b.suboption) {
                o if o == opt::ALL => true,
                o if o == opt::NAME_OF_STATION => {
                    !self.name.is_empty() && b.data == self.name.as_bytes()
                }
                o if o == opt::DEVICE_ID => {
                    let mut v = id.vendor_id.to_be_bytes().to_vec();
                    v.extend_from_slice(&id.device_id.to_be_bytes());
                    b.data == v.as_slice()
                }
                o if o == opt::DEVICE_VENDOR => b.data == self.vendor_text().as_bytes(),
                o if o == opt::DEVICE_ROLE => b.data.first() == Some(&id.device_role),
                o if o == opt::IP_PARAMETER => b.data.get(..4) == Some(&self.ip[..]),
                _ => false,
            };
            if !ok {
                return false;
            }
        }
        any
    }

    fn dcp_set(&mut self, which: (u8, u8), data: &[u8]) -> u8 {
        let busy = self.ar.is_some();
        match which {
            o if o == opt::NAME_OF_STATION => {
                if busy {
                    return block_error::LOCAL;
                }
                if !data.is_empty() && !dcp::valid_station_name(data) {
                    return block_error::LOCAL;
                }
                self.name = String::from_utf8_lossy(data).into_owned();
                push(&mut self.events, DeviceEvent::NameSet(self.name.clone()));
                block_error::OK
            }
            o if o == opt::IP_PARAMETER => {
                let (Some(ip), Some(mask), Some(gw)) =
                    (data.get(0..4), data.get(4..8), data.get(8..12))
                else {
                    return block_error::LOCAL;
                };
                if busy {
                    return block_error::LOCAL;
                }
                let arr = |s: &[u8]| <[u8; 4]>::try_from(s).unwrap_or([0; 4]);
                self.ip = arr(ip);
                self.netmask = arr(mask);
                self.gateway = arr(gw);
                push(&mut self.events, DeviceEvent::IpSet(self.ip));
                block_error::OK
            }
            o if o == opt::CONTROL_SIGNAL => {
                push(&mut self.events, DeviceEvent::Signal);
                block_error::OK
            }
            o if o == opt::CONTROL_START || o == opt::CONTROL_STOP => block_error::OK,
            o if o == opt::CONTROL_FACTORY_RESET => {
                if busy {
                    return block_error::LOCAL;
                }
                self.name.clear();
                self.ip = [0; 4];
                self.netmask = [0; 4];
                self.gateway = [0; 4];
                block_error::OK
            }
            (1, _) | (2, _) | (5, _) => block_error::SUBOPTION,
            _ => block_error::OPTION,
        }
    }

    // ------------------------------------------------------------------ cyclic

    fn input_frame(&mut self, at: Duration) -> Vec<u8> {
        let image = self.drive.input_image();
        let Some(ar) = self.ar.as_ref() else {
            return Vec::new();
        };
        let id = &self.config.identity;
        let running = ar.phase != Phase::WaitPrmEnd && ar.psd_ok;
        let mut c_sdu = vec![0u8; ar.input.data_length];
        for &(slot, subslot, off) in &ar.input.objects {
            let psd = (slot, subslot) == (id.input.slot, id.input.subslot);
            let (len, iops) = if psd {
                (image.len(), if running { ioxs::GOOD } else { ioxs::BAD })
            } else {
                (0, ioxs::GOOD)
            };
            if psd {
                if let Some(dst) = c_sdu.get_mut(off..off + len) {
                    dst.copy_from_slice(&image);
                }
            }
            if let Some(b) = c_sdu.get_mut(off + len) {
                *b = iops;
            }
        }
        for &(slot, subslot, off) in &ar.input.iocs {
            let psd = (slot, subslot) == (id.output.slot, id.output.subslot);
            if let Some(b) = c_sdu.get_mut(off) {
                *b = if psd && !ar.psd_ok {
                    ioxs::BAD
                } else {
                    ioxs::GOOD
                };
            }
        }
        let pdu = rt::cyclic(
            ar.input.frame_id,
            &c_sdu,
            cycle_counter(at),
            data_status::GOOD_RUN,
        );
        eth::frame(
            ar.controller,
            self.config.mac,
            None,
            ethertype::PROFINET,
            &pdu,
        )
    }

    fn cyclic(&mut self, now: Duration, src: Mac, f: &CyclicFrame<'_>) {
        let Some(ar) = self.ar.as_mut() else {
            return;
        };
        if src != ar.controller || f.frame_id != ar.output.frame_id {
            return;
        }
        let ds = f.apdu.data_status;
        if !ds.data_valid() || ds.ignore() {
            return;
        }
        let Ok(c_sdu) = f.c_sdu(ar.output.data_length) else {
            return;
        };
        ar.output.deadline = now + ar.output.hold;
        ar.output.seen = true;
        if ar.phase != Phase::Data || !ar.psd_ok {
            return;
        }
        let len = usize::from(self.config.identity.output.length);
        let off = ar.output.offset;
        let (Some(image), Some(&iops)) = (c_sdu.get(off..off + len), c_sdu.get(off + len)) else {
            return;
        };
        // Manual 3.9: with IOPS bad (controller CPU in STOP) the outputs keep their last
        // valid values; the drive model holds them while told IopsBad.
        let good = ds.provider_run() && iops & 0x80 != 0;
        if good != ar.iops_good {
            ar.iops_good = good;
            let ev = if good {
                LinkEvent::IopsGood
            } else {
                LinkEvent::IopsBad
            };
            self.drive.handle_link(micros(now), ev);
        }
        if good {
            let _ = self.drive.handle_image(micros(now), image);
            self.drain_drive();
        }
    }

    // ------------------------------------------------------------------ PNIO-CM

    fn cm(
        &mut self,
        now: Duration,
        src: Mac,
        ep: Endpoints,
        h: &drivespec_capture::dcerpc::Header,
        m: &CmMessage,
    ) {
        match (h.ptype, m.direction) {
            (PacketType::REQUEST, Direction::Request) if ep.dst_port == PNIO_PORT => {
                let key = (h.activity, h.sequence);
                if let Some((_, f)) = self.cache.iter().find(|(k, _)| *k == key) {
                    let f = f.clone();
                    push(&mut self.tx, f);
                    return;
                }
                let Some((status, blocks)) = self.call(now, src, ep, m) else {
                    // C706 12.5.3.9: an operation the interface does not have.
                    self.reject(src, ep, h, NCA_OP_RNG_ERROR);
                    return;
                };
                if !status.is_ok() {
                    push(
                        &mut self.events,
                        DeviceEvent::Refused {
                            operation: m.operation,
                            status,
                        },
                    );
                }
                let body = cm::response(status, &blocks, rpc::DREP.integer);
                let header = rpc::response_header(h, self.config.server_boot);
                self.ip_id = self.ip_id.wrapping_add(1);
                let f = station::rpc_frame(
                    self.config.mac,
                    src,
                    station::reply(ep),
                    self.ip_id,
                    &header,
                    &body,
                );
                if self.cache.len() >= MAX_CACHED {
                    self.cache.pop_front();
                }
                self.cache.push_back((key, f.clone()));
                // The Connect answer goes out before the first input frame, PrmEnd's answer
                // before ApplicationReady.
                self.tx.push_front(f);
                if let Some(ar) = self.ar.as_mut() {
                    if matches!(ar.phase, Phase::AppReady { .. })
                        && m.operation == Operation::Control
                    {
                        self.application_ready();
                    }
                }
            }
            (PacketType::RESPONSE, Direction::Response) if ep.dst_port == CLIENT_PORT => {
                let Some(ar) = self.ar.as_mut() else {
                    return;
                };
                if !matches!(ar.phase, Phase::AppReady { .. }) || h.activity != ar.uuid_activity() {
                    return;
                }
                let done = m.ndr.status.is_none_or(|s| s.is_ok())
                    && m.blocks.iter().any(|b| {
                        matches!(b, Block::Control(c) if c.response && c.command & control_command::DONE != 0)
                    });
                if done {
                    ar.phase = Phase::Data;
                    ar.iops_good = true;
                    self.drive.handle_link(micros(now), LinkEvent::Connected);
                    push(&mut self.events, DeviceEvent::Data);
                }
            }
            _ => {}
        }
    }

    /// PDUs that are no PNIO-CM call: a call to another interface is rejected with
    /// nca_unk_if (C706 12.5.3.9); a ping of a call answered is answered again, of any other
    /// call with nocall (C706 12.5.3.6, the device answers every call at once).
    fn other_rpc(&mut self, src: Mac, ep: Endpoints, header: &drivespec_capture::dcerpc::Header) {
        if !header.interface.is_pnio_interface() {
            if header.ptype == PacketType::REQUEST && ep.dst_port == PNIO_PORT {
                self.reject(src, ep, header, NCA_UNK_IF);
            }
            return;
        }
        if header.ptype == PacketType::PING {
            let key = (header.activity, header.sequence);
            if let Some((_, f)) = self.cache.iter().find(|(k, _)| *k == key) {
                let f = f.clone();
                push(&mut self.tx, f);
                return;
            }
            self.rpc_pdu(src, ep, header, PacketType::NOCALL, &[]);
        }
    }

    /// Rejects a call with `status` (C706 12.5.3.9: a reject PDU carries the status).
    fn reject(
        &mut self,
        src: Mac,
        ep: Endpoints,
        header: &drivespec_capture::dcerpc::Header,
        status: u32,
    ) {
        self.rpc_pdu(src, ep, header, PacketType::REJECT, &status.to_le_bytes());
    }

    /// Sends a PDU of `ptype` for the call `header`, from the endpoint it came to.
    fn rpc_pdu(
        &mut self,
        src: Mac,
        ep: Endpoints,
        header: &drivespec_capture::dcerpc::Header,
        ptype: PacketType,
        body: &[u8],
    ) {
        let mut h = rpc::response_header(header, self.config.server_boot);
        h.ptype = ptype;
        self.ip_id = self.ip_id.wrapping_add(1);
        let f = station::rpc_frame(
            self.config.mac,
            src,
            station::reply(ep),
            self.ip_id,
            &h,
            body,
        );
        push(&mut self.tx, f);
    }

    /// Answers one call: its PNIOStatus and response blocks; `None` for an unknown operation.
    fn call(
        &mut self,
        now: Duration,
        src: Mac,
        ep: Endpoints,
        m: &CmMessage,
    ) -> Option<(PnioStatus, Vec<u8>)> {
        Some(match m.operation {
            Operation::Connect => self.connect(now, src, ep, m),
            Operation::Read | Operation::ReadImplicit => self.read(m),
            Operation::Write => self.write(m),
            Operation::Control => self.control(m, false),
            Operation::Release => self.control(m, true),
            Operation::Other(_) => return None,
        })
    }

    fn connect(
        &mut self,
        now: Duration,
        src: Mac,
        ep: Endpoints,
        m: &CmMessage,
    ) -> (PnioStatus, Vec<u8>) {
        match self.check_connect(now, src, ep, m) {
            Ok((ar, res)) => {
                let uuid = ar.uuid;
                let diff = !ar.psd_ok;
                self.ar = Some(ar);
                push(
                    &mut self.events,
                    DeviceEvent::Connected {
                        ar_uuid: uuid,
                        diff,
                    },
                );
                (PnioStatus::default(), res)
            }
            Err(s) => (s, Vec::new()),
        }
    }

    fn check_connect(
        &self,
        now: Duration,
        src: Mac,
        ep: Endpoints,
        m: &CmMessage,
    ) -> Result<(Ar, Vec<u8>), PnioStatus> {
        use status::connect_field as field;
        let rpc_err = |c2| status::status(status::CONNECT, status::PNIO, code1::CMRPC, c2);
        let ars: Vec<&ArBlockReq> = m
            .blocks
            .iter()
            .filter_map(|b| match b {
                Block::ArReq(a) => Some(a),
                _ => None,
            })
            .collect();
        let iocrs: Vec<&IocrBlockReq> = m
            .blocks
            .iter()
            .filter_map(|b| match b {
                Block::IocrReq(c) => Some(c),
                _ => None,
            })
            .collect();
        let alarms: Vec<_> = m
            .blocks
            .iter()
            .filter_map(|b| match b {
                Block::Unknown(u) => alarm_cr_req(u),
                _ => None,
            })
            .collect();
        let expected: Vec<&ExpectedModule> = m
            .blocks
            .iter()
            .filter_map(|b| match b {
                Block::ExpectedSubmodules(e) => Some(&e.modules),
                _ => None,
            })
            .flatten()
            .collect();
        let [ar] = ars.as_slice() else {
            return Err(rpc_err(code2::WRONG_BLOCK_COUNT));
        };
        if self.ar.is_some() {
            return Err(rpc_err(code2::NO_AR_RESOURCES));
        }
        if ar.ar_type != 1 {
            return Err(field(code1::AR_BLOCK, 4));
        }
        let [Ok(alarm)] = alarms.as_slice() else {
            return Err(rpc_err(code2::WRONG_BLOCK_COUNT));
        };
        if alarm.alarm_cr_type != 1 {
            return Err(field(code1::ALARM_CR_BLOCK, 4));
        }
        let id = &self.config.identity;
        let input = iocrs.iter().find(|c| c.iocr_type == 1);
        let output = iocrs.iter().find(|c| c.iocr_type == 2);
        let (Some(input), Some(output)) = (input, output) else {
            return Err(rpc_err(code2::IOCR_MISSING));
        };
        if iocrs.len() != 2 {
            return Err(rpc_err(code2::WRONG_BLOCK_COUNT));
        }
        for c in [input, output] {
            let f = |n| Err(field(code1::IOCR_BLOCK, n));
            if c.lt != ethertype::PROFINET {
                return f(6);
            }
            if !matches!(c.rt_class(), 1 | 2) {
                return f(7);
            }
            let len = usize::from(c.data_length);
            if !(MIN_C_SDU..=MAX_C_SDU).contains(&len) {
                return f(8);
            }
            if !SEND_CLOCKS.contains(&c.send_clock_factor) {
                return f(10);
            }
            let rr = c.reduction_ratio;
            if rr == 0 || rr > MAX_REDUCTION || !rr.is_power_of_two() {
                return f(11);
            }
            if c.phase == 0 || c.phase > rr {
                return f(12);
            }
            if !DATA_HOLD.contains(&c.data_hold_factor) {
                return f(16);
            }
            if c.apis.iter().any(|a| a.api != 0) {
                return f(20);
            }
        }
        if !matches!(input.frame_id.class(), FrameClass::Cyclic(_)) {
            return Err(field(code1::IOCR_BLOCK, 9));
        }
        // The expected submodules: lengths must fit the modules of 3.2.1; idents that differ
        // go into the ModuleDiffBlock.
        let mut diff = Vec::new();
        let mut psd_ok = true;
        for em in &expected {
            if em.api != 0 {
                return Err(field(code1::EXPECTED_BLOCK, 5));
            }
            let real = if em.slot == id.dap_slot {
                Some(id.dap_module_ident)
            } else if em.slot == id.output.slot {
                Some(id.output.module_ident)
            } else if em.slot == id.input.slot {
                Some(id.input.module_ident)
            } else {
                None
            };
            let Some(real) = real else {
                diff.push(DiffModule {
                    api: 0,
                    slot: em.slot,
                    ident: 0,
                    state: 0,
                    submodules: Vec::new(),
                });
                continue;
            };
            let mut subs = Vec::new();
            for s in &em.submodules {
                let (real_ident, want_in, want_out) = if em.slot == id.dap_slot {
                    match id.dap_submodules.iter().find(|(ss, _)| *ss == s.subslot) {
                        Some((_, ident)) => (Some(*ident), 0, 0),
                        None => (None, 0, 0),
                    }
                } else if em.slot == id.output.slot && s.subslot == id.output.subslot {
                    (Some(id.output.submodule_ident), 0, id.output.length)
                } else if em.slot == id.input.slot && s.subslot == id.input.subslot {
                    (Some(id.input.submodule_ident), id.input.length, 0)
                } else {
                    (None, 0, 0)
                };
                let Some(real_ident) = real_ident else {
                    // IdentInfo NoSubmodule (3), format 1.
                    subs.push(DiffSubmodule {
                        subslot: s.subslot,
                        ident: 0,
                        state: 0x8000 | (3 << 11),
                    });
                    continue;
                };
                let in_len = s.input.map_or(0, |d| d.data_length);
                let out_len = s.output.map_or(0, |d| d.data_length);
                if in_len != want_in || out_len != want_out {
                    return Err(field(code1::EXPECTED_BLOCK, 14));
                }
                if s.ident != real_ident {
                    // IdentInfo Wrong (2), format 1.
                    subs.push(DiffSubmodule {
                        subslot: s.subslot,
                        ident: real_ident,
                        state: 0x8000 | (2 << 11),
                    });
                }
            }
            let wrong_module = em.ident != real;
            if wrong_module || !subs.is_empty() {
                if em.slot != id.dap_slot {
                    psd_ok = false;
                }
                diff.push(DiffModule {
                    api: 0,
                    slot: em.slot,
                    ident: real,
                    state: if wrong_module { 1 } else { 2 },
                    submodules: subs,
                });
            }
        }
        let has = |slot, subslot| {
            expected
                .iter()
                .any(|m| m.slot == slot && m.submodules.iter().any(|s| s.subslot == subslot))
        };
        if !has(id.output.slot, id.output.subslot) || !has(id.input.slot, id.input.subslot) {
            psd_ok = false;
        }
        // Where the modules' data sit in the two CRs.
        let objects = |c: &IocrBlockReq| -> Vec<(u16, u16, usize)> {
            c.apis
                .iter()
                .flat_map(|a| a.data_objects.iter())
                .map(|o| (o.slot, o.subslot, usize::from(o.frame_offset)))
                .collect()
        };
        let iocs = |c: &IocrBlockReq| -> Vec<(u16, u16, usize)> {
            c.apis
                .iter()
                .flat_map(|a| a.iocs.iter())
                .map(|o| (o.slot, o.subslot, usize::from(o.frame_offset)))
                .collect()
        };
        let in_objects = objects(input);
        let out_objects = objects(output);
        let fits = |list: &[(u16, u16, usize)], c: &IocrBlockReq, slot, subslot, len: usize| {
            list.iter()
                .find(|o| o.0 == slot && o.1 == subslot)
                .map(|o| o.2 + len < usize::from(c.data_length))
        };
        if fits(
            &in_objects,
            input,
            id.input.slot,
            id.input.subslot,
            usize::from(id.input.length),
        ) == Some(false)
            || in_objects
                .iter()
                .chain(iocs(input).iter())
                .any(|o| o.2 >= usize::from(input.data_length))
        {
            return Err(field(code1::IOCR_BLOCK, 24));
        }
        let out_offset = out_objects
            .iter()
            .find(|o| o.0 == id.output.slot && o.1 == id.output.subslot)
            .map(|o| o.2);
        if fits(
            &out_objects,
            output,
            id.output.slot,
            id.output.subslot,
            usize::from(id.output.length),
        ) == Some(false)
            || out_objects
                .iter()
                .chain(iocs(output).iter())
                .any(|o| o.2 >= usize::from(output.data_length))
        {
            return Err(field(code1::IOCR_BLOCK, 24));
        }
        let Some(out_offset) = out_offset else {
            return Err(field(code1::IOCR_BLOCK, 21));
        };
        let in_period = cycle(input.send_clock_factor, input.reduction_ratio);
        let out_period = cycle(output.send_clock_factor, output.reduction_ratio);
        let hold = out_period * u32::from(output.data_hold_factor);
        let activity_timeout =
            Duration::from_millis(100 * u64::from(ar.activity_timeout_factor.max(1)));
        let ar_block = Ar {
            uuid: ar.ar_uuid,
            session_key: ar.session_key,
            controller: src,
            controller_ip: ep.src,
            controller_object: ar.initiator_object,
            activity_timeout,
            input: InputCr {
                frame_id: input.frame_id,
                data_length: usize::from(input.data_length),
                period: in_period,
                next: now,
                objects: in_objects,
                iocs: iocs(input),
            },
            output: OutputCr {
                frame_id: OUTPUT_FRAME_ID,
                data_length: usize::from(output.data_length),
                offset: out_offset,
                hold,
                // Until the first frame arrives the AR waits for the controller's activity
                // timeout; from then on DataHoldFactor cycles (IEC 61158-6-10 DHT).
                deadline: now + activity_timeout,
                seen: false,
            },
            alarm_remote: alarm.local_alarm_reference,
            phase: Phase::WaitPrmEnd,
            psd_ok,
            iops_good: true,
            client_seq: 0,
        };
        let mut res = Blocks::new();
        res.ar_res(&ArBlockRes {
            header: ar.header,
            ar_type: ar.ar_type,
            ar_uuid: ar.ar_uuid,
            session_key: ar.session_key,
            responder_mac: self.config.mac,
            udp_rt_port: ethertype::PROFINET,
        });
        for (c, frame_id) in [(input, input.frame_id), (output, OUTPUT_FRAME_ID)] {
            res.iocr_res(&IocrBlockRes {
                header: c.header,
                iocr_type: c.iocr_type,
                reference: c.reference,
                frame_id,
            });
        }
        res.alarm_cr_res(&AlarmCrBlockRes {
            alarm_cr_type: 1,
            local_alarm_reference: ALARM_REF,
            max_alarm_data_length: MAX_ALARM_DATA
                .min(alarm.max_alarm_data_length.max(MAX_ALARM_DATA)),
        });
        if !diff.is_empty() {
            res.module_diff(&ModuleDiff { modules: diff });
        }
        Ok((ar_block, res.into_bytes()))
    }

    fn record_subslot_ok(&self, slot: u16, subslot: u16, api: u32) -> bool {
        api == 0 && self.config.identity.subslots().contains(&(slot, subslot))
    }

    fn psd_slot(&self, slot: u16, subslot: u16) -> bool {
        let id = &self.config.identity;
        (slot, subslot) == (id.output.slot, id.output.subslot)
            || (slot, subslot) == (id.input.slot, id.input.subslot)
    }

    /// The PNIOStatus of a refused record: ErrorDecode PNIORW, ErrorCode1 the class the
    /// refusal falls in, ErrorCode2 (user specific, IEC 61158-6-10) the PKW error number of
    /// manual 3.2.2 (0 for a wrong length), so a controller can tell every refusal apart.
    fn refusal(&self, code: u8, failure: RecordFailure) -> PnioStatus {
        let codes = self.drive.rules().pkw().error_codes();
        let code2 = match failure {
            RecordFailure::Refused { error } => u8::try_from(error.0).unwrap_or(u8::MAX),
            RecordFailure::Malformed { .. } => 0,
        };
        let c1 = match failure {
            RecordFailure::Malformed { .. } => rw::WRITE_LENGTH,
            RecordFailure::Refused { error } if error == codes.unknown_parameter => {
                rw::INVALID_INDEX
            }
            RecordFailure::Refused { error } if error == codes.read_only => rw::ACCESS_DENIED,
            RecordFailure::Refused { error } if error == codes.out_of_range => rw::INVALID_RANGE,
            RecordFailure::Refused { .. } => rw::INVALID_PARAMETER,
        };
        status::status(code, status::PNIORW, c1, code2)
    }

    fn drive_record(&mut self, req: DriveRecord) -> Option<Result<RecordAnswer, RecordFailure>> {
        self.drive.handle_record(micros(self.now), req);
        let mut last = None;
        while let Some(r) = self.drive.poll_record() {
            last = Some(r.result);
        }
        self.drain_drive();
        last
    }

    fn ar_known(&self, uuid: Uuid) -> bool {
        self.ar.as_ref().is_some_and(|a| a.uuid == uuid)
    }

    fn read(&mut self, m: &CmMessage) -> (PnioStatus, Vec<u8>) {
        let Some(r) = m.blocks.iter().find_map(|b| match b {
            Block::ReadReq(r) => Some(r),
            _ => None,
        }) else {
            return (
                status::status(
                    status::READ,
                    status::PNIO,
                    code1::CMRPC,
                    code2::UNKNOWN_BLOCKS,
                ),
                Vec::new(),
            );
        };
        let implicit = m.operation == Operation::ReadImplicit;
        let result: Result<Vec<u8>, PnioStatus> = if !implicit && !self.ar_known(r.ar_uuid) {
            Err(status::status(
                status::READ,
                status::PNIO,
                code1::CMRPC,
                code2::AR_UUID_UNKNOWN,
            ))
        } else if !self.record_subslot_ok(r.slot, r.subslot, r.api) {
            Err(status::status(
                status::READ,
                status::PNIORW,
                rw::INVALID_SLOT,
                0,
            ))
        } else if r.index == IM0_INDEX {
            let d = &self.config.drive;
            Ok(self
                .config
                .identity
                .im0_record(&self.vendor_text(), &d.serial_number.to_string()))
        } else if r.index < 0x8000 && self.psd_slot(r.slot, r.subslot) {
            match self.drive_record(DriveRecord::Read { index: r.index }) {
                Some(Ok(RecordAnswer::Data { bytes })) => Ok(bytes),
                Some(Ok(_)) => Ok(Vec::new()),
                Some(Err(f)) => Err(self.refusal(status::READ, f)),
                None => Err(status::status(
                    status::READ,
                    status::PNIORW,
                    rw::STATE_CONFLICT,
                    0,
                )),
            }
        } else {
            Err(status::status(
                status::READ,
                status::PNIORW,
                rw::INVALID_INDEX,
                0,
            ))
        };
        let (st, data) = match result {
            Ok(d) if d.len() > usize::try_from(r.record_data_length).unwrap_or(usize::MAX) => (
                status::status(status::READ, status::PNIORW, rw::INVALID_RANGE, 0),
                Vec::new(),
            ),
            Ok(d) => (PnioStatus::default(), d),
            Err(s) => (s, Vec::new()),
        };
        let mut b = Blocks::new();
        b.read_res(&record_response(r, st, data));
        (st, b.into_bytes())
    }

    fn write(&mut self, m: &CmMessage) -> (PnioStatus, Vec<u8>) {
        let Some(r) = m.blocks.iter().find_map(|b| match b {
            Block::WriteReq(r) => Some(r),
            _ => None,
        }) else {
            return (
                status::status(
                    status::WRITE,
                    status::PNIO,
                    code1::CMRPC,
                    code2::UNKNOWN_BLOCKS,
                ),
                Vec::new(),
            );
        };
        let st = if !self.ar_known(r.ar_uuid) {
            status::status(
                status::WRITE,
                status::PNIO,
                code1::CMRPC,
                code2::AR_UUID_UNKNOWN,
            )
        } else if !self.record_subslot_ok(r.slot, r.subslot, r.api) {
            status::status(status::WRITE, status::PNIORW, rw::INVALID_SLOT, 0)
        } else if r.index == IM0_INDEX {
            status::status(status::WRITE, status::PNIORW, rw::ACCESS_DENIED, 0)
        } else if r.index < 0x8000 && self.psd_slot(r.slot, r.subslot) {
            match self.drive_record(DriveRecord::Write {
                index: r.index,
                data: r.data.clone(),
            }) {
                Some(Ok(_)) => PnioStatus::default(),
                Some(Err(f)) => self.refusal(status::WRITE, f),
                None => status::status(status::WRITE, status::PNIORW, rw::STATE_CONFLICT, 0),
            }
        } else {
            status::status(status::WRITE, status::PNIORW, rw::INVALID_INDEX, 0)
        };
        let mut res = record_response(r, st, Vec::new());
        res.record_data_length = u32::try_from(r.data.len()).unwrap_or(u32::MAX);
        res.status = Some(st);
        let mut b = Blocks::new();
        b.write_res(&res);
        (st, b.into_bytes())
    }

    fn control(&mut self, m: &CmMessage, release: bool) -> (PnioStatus, Vec<u8>) {
        let (code, block) = if release {
            (status::RELEASE, code1::RELEASE_BLOCK)
        } else {
            (status::CONTROL, code1::CONTROL_BLOCK)
        };
        let Some(c) = m.blocks.iter().find_map(|b| match b {
            Block::Control(c) if !c.response => Some(c),
            _ => None,
        }) else {
            return (
                status::status(code, status::PNIO, code1::CMRPC, code2::UNKNOWN_BLOCKS),
                Vec::new(),
            );
        };
        let Some(ar) = self.ar.as_mut() else {
            return (status::status(code, status::PNIO, block, 5), Vec::new());
        };
        let st = if c.ar_uuid != ar.uuid {
            status::status(code, status::PNIO, block, 5)
        } else if c.session_key != ar.session_key {
            status::status(code, status::PNIO, block, 6)
        } else if release {
            if c.kind != ControlKind::Release {
                status::status(code, status::PNIO, block, 0)
            } else {
                PnioStatus::default()
            }
        } else if c.kind != ControlKind::PrmEnd || c.command & control_command::PRM_END == 0 {
            status::status(code, status::PNIO, block, 8)
        } else if ar.phase != Phase::WaitPrmEnd {
            status::status(code, status::PNIO, code1::CMDEV, code2::STATE_CONFLICT)
        } else {
            PnioStatus::default()
        };
        if !st.is_ok() {
            return (st, Vec::new());
        }
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
        if release {
            self.end_ar(ArEnd::Released, None);
        } else {
            let now = self.now;
            ar.phase = Phase::AppReady {
                next: now + RPC_RESEND,
                deadline: now + ar.activity_timeout,
            };
            push(&mut self.events, DeviceEvent::PrmEnd);
        }
        (st, b.into_bytes())
    }

    /// Sends (or repeats) ApplicationReady to the controller (IEC 61158-6-10 IOXControlReq).
    fn application_ready(&mut self) {
        let Some(ar) = self.ar.as_ref() else {
            return;
        };
        let mut b = Blocks::new();
        b.control(&ControlBlock {
            header: drivespec_capture::pnio::BlockHeader {
                block_type: 0x0112,
                length: 0,
                version_high: 1,
                version_low: 0,
                offset: 0,
            },
            kind: ControlKind::ApplicationReady,
            response: false,
            ar_uuid: ar.uuid,
            session_key: ar.session_key,
            command: control_command::APPLICATION_READY,
            properties: 0,
        });
        let body = cm::request(MAX_ARGS, &b.into_bytes(), rpc::DREP.integer);
        let mut header = rpc::request_header(
            ar.controller_object,
            Uuid::PNIO_CONTROLLER,
            ar.uuid_activity(),
            ar.client_seq,
            4,
        );
        header.server_boot = self.config.server_boot;
        let ep = Endpoints {
            src: self.ip,
            src_port: CLIENT_PORT,
            dst: ar.controller_ip,
            dst_port: PNIO_PORT,
        };
        self.ip_id = self.ip_id.wrapping_add(1);
        let f = station::rpc_frame(
            self.config.mac,
            ar.controller,
            ep,
            self.ip_id,
            &header,
            &body,
        );
        push(&mut self.tx, f);
    }
}

/// ArgsMaximum of the device's own calls.
const MAX_ARGS: u32 = 4096;

impl Ar {
    /// The activity of the device's calls in this AR: the AR UUID with its last byte inverted.
    fn uuid_activity(&self) -> Uuid {
        let mut u = self.uuid;
        if let Some(b) = u.0.last_mut() {
            *b ^= 0xFF;
        }
        u
    }
}

fn record_response(r: &RecordRequest, status: PnioStatus, data: Vec<u8>) -> RecordResponse {
    RecordResponse {
        header: r.header,
        sequence: r.sequence,
        ar_uuid: r.ar_uuid,
        api: r.api,
        slot: r.slot,
        subslot: r.subslot,
        index: r.index,
        record_data_length: u32::try_from(data.len()).unwrap_or(u32::MAX),
        additional_value1: 0,
        additional_value2: 0,
        status: Some(status),
        data,
    }
}
