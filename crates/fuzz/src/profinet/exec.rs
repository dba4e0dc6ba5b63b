//! Running PROFINET-layer inputs on a device under test, and the liveness probe after them:
//! the device still answers DCP Identify by its name, still accepts a valid Connect (PrmEnd,
//! ApplicationReady) and still sends cyclic data (IEC 61158-6-10).
//!
//! Everything goes over a [`PnWire`]: the socket loop of the caller (a raw Ethernet socket on
//! an interface) or [`super::MemoryWire`] (a device in memory on a virtual clock). Every wait
//! has a deadline: the controllers' own (Identify, each RPC call and its repeat,
//! ApplicationReady, the input watchdog) and [`STAGE`] around each of them.

use super::step::PnStep;
use drivespec_capture::link::{ethertype, parse_ethernet};
use drivespec_capture::rt::{FrameClass, FrameId, RtFrame};
use drivespec_conform::case::{Answer, Record, Role};
use drivespec_profinet::controller::ControllerConfig;
use drivespec_profinet::dcp::{self, opt, service, service_type, DcpBlocks};
use drivespec_profinet::eth::{self, Mac, DCP_IDENTIFY_MAC};
use drivespec_profinet::identity::Identity;
use drivespec_profinet::udp::Ipv4;
use drivespec_profinet::{rt, Controller, ControllerError, ControllerEvent};
use drivespec_spec::hex::to_hex;
use std::time::Duration;

/// A wire to a PROFINET IO device under test (our doc: module `exec`).
pub trait PnWire {
    /// Own MAC and IPv4 address (the controller's).
    fn station(&self) -> (Mac, Ipv4);
    /// The NameOfStation of the device under test.
    fn target(&self) -> &str;
    /// The device under test, one line.
    fn describe(&self) -> String;
    /// Time on the wire's clock since its origin.
    fn now(&mut self) -> Duration;
    /// Sends one whole Ethernet frame.
    fn send(&mut self, frame: &[u8]) -> Result<(), PnWireError>;
    /// The frames received until `until` on the wire's clock, with their times; returns as
    /// soon as at least one came.
    fn recv(&mut self, until: Duration) -> Result<Vec<(Duration, Vec<u8>)>, PnWireError>;
    /// Whether [`PnWire::restart`] gives a device in its start state (a simulated device).
    fn can_restart(&self) -> bool;
    /// Puts the device in its start state and the clock at 0, where the wire can.
    fn restart(&mut self);
    /// Whether the clock is virtual (waiting costs nothing).
    fn virtual_time(&self) -> bool;
}

/// Why the wire failed (our doc: module `exec`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PnWireError {
    /// Sending or receiving failed.
    #[error("the wire failed: {0}")]
    Io(String),
}

/// Listening after a DCP request or a cyclic frame for what it brings back. A choice: a
/// device answers DCP within milliseconds (the requests ask for ResponseDelay 1); 20 ms
/// leaves room for a loaded machine.
const SETTLE: Duration = Duration::from_millis(20);
/// Time for one RPC call of the fuzzer's controllers before its one repeat. A choice: a
/// device answers PNIO-CM within milliseconds; the probe must notice a silent device well
/// within the seconds a restart takes.
const RPC_TIMEOUT: Duration = Duration::from_millis(300);
/// Time for the first Identify answer (one more try of [`RPC_TIMEOUT`] follows).
const IDENTIFY_TIMEOUT: Duration = Duration::from_millis(500);
/// Time for ApplicationReady after PrmEnd.
const APP_READY_TIMEOUT: Duration = Duration::from_secs(2);
/// Longest wait of one step or probe stage: above the controllers' own deadlines (Identify,
/// a call with its repeat, ApplicationReady), so their errors come first.
const STAGE: Duration = Duration::from_secs(5);
/// DataHoldFactor of the fuzzer's own ARs. A choice, as for `conform --dut profinet:`: 256
/// cycles (256 ms at 1 ms) keeps a process the machine leaves unscheduled for a while from
/// ending the AR, while a device that stops its frames is still noticed.
const DATA_HOLD: u16 = 256;
/// Input frames the probe waits for in data exchange.
const PROBE_FRAMES: u64 = 8;
/// Longest wait for a device to answer Identify again before a run (a device that
/// restarted); a choice: small devices restart within seconds.
const RECOVER: Duration = Duration::from_secs(15);
/// Longest wait for a device to answer Identify before the first probe of a run or replay
/// (a device still restarting from a finding a moment ago); a choice, short so that a name
/// nobody answers to is reported within seconds.
pub(crate) const SETUP_WAIT: Duration = Duration::from_secs(3);
/// Longest frame sent: 1,500 payload bytes and the Ethernet header (a controller asked for
/// longer module data than a frame holds sends nothing instead).
const MAX_FRAME: usize = 1514;
/// Received frames kept per step for its evidence.
const MAX_SEEN: usize = 4;

/// The part of the liveness probe a device failed (our doc: module `exec`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Stage {
    /// No answer to DCP Identify by its NameOfStation.
    Identify,
    /// A valid Connect, PrmEnd or ApplicationReady failed.
    Connect,
    /// No cyclic input data in data exchange.
    Cyclic,
}

impl Stage {
    /// The name in signatures.
    pub(crate) fn as_str(self) -> &'static str {
        match self {
            Stage::Identify => "dcp-identify",
            Stage::Connect => "connect",
            Stage::Cyclic => "cyclic-data",
        }
    }
}

/// What one step or the probe gave.
pub(crate) struct Outcome {
    /// The frame sent (raw steps).
    pub(crate) sent: Option<Vec<u8>>,
    /// Frames received while listening (non-cyclic).
    pub(crate) seen: Vec<Vec<u8>>,
    /// What happened, one line.
    pub(crate) note: String,
}

/// Runs steps and probes on a wire (our doc: module `exec`).
pub(crate) struct Runner<'w> {
    pub(crate) wire: Box<dyn PnWire + 'w>,
    identity: Identity,
    ars: u16,
    xid: u32,
    device: Option<Mac>,
    session: Option<Controller>,
}

/// Whether `frame` is a cyclic RT frame.
fn is_cyclic(frame: &[u8]) -> bool {
    parse_ethernet(frame)
        .ok()
        .filter(|l| l.ethertype == ethertype::PROFINET)
        .and_then(|l| RtFrame::parse(l.payload).ok())
        .is_some_and(|r| matches!(r.frame_id.class(), FrameClass::Cyclic(_)))
}

impl<'w> Runner<'w> {
    /// A runner on `wire` for a device with `identity`.
    pub(crate) fn new(wire: Box<dyn PnWire + 'w>, identity: Identity) -> Runner<'w> {
        Runner {
            wire,
            identity,
            ars: 0,
            xid: 0x4655_0000,
            device: None,
            session: None,
        }
    }

    /// Back to the start: the device restarted where the wire can (true), else waited for
    /// until it answers Identify again (at most [`RECOVER`]).
    pub(crate) fn fresh(&mut self) -> Result<bool, PnWireError> {
        self.fresh_within(RECOVER)
    }

    /// [`Runner::fresh`], waiting at most `wait` for a device that cannot be restarted.
    pub(crate) fn fresh_within(&mut self, wait: Duration) -> Result<bool, PnWireError> {
        self.session = None;
        if self.wire.can_restart() {
            self.wire.restart();
            self.ars = 0;
            self.xid = 0x4655_0000;
            self.device = None;
            return Ok(true);
        }
        let until = self.wire.now() + wait;
        while self.wire.now() < until {
            if self.locate()?.is_some() {
                break;
            }
        }
        Ok(false)
    }

    /// A controller configuration of the fuzzer's with a fresh AR UUID and SessionKey.
    fn config(&mut self) -> ControllerConfig {
        let (mac, ip) = self.wire.station();
        let mut c = ControllerConfig::new(self.identity.clone(), mac, ip, self.wire.target());
        self.ars = self.ars.wrapping_add(1);
        if let Some(b) = c.ar_uuid.0.get_mut(0..2) {
            b.copy_from_slice(&self.ars.to_be_bytes());
        }
        c.session_key = self.ars;
        c.rpc_timeout = RPC_TIMEOUT;
        c.rpc_retries = 1;
        c.identify_timeout = IDENTIFY_TIMEOUT;
        c.app_ready_timeout = APP_READY_TIMEOUT;
        c.data_hold_factor = DATA_HOLD;
        c
    }

    fn send(&mut self, frame: &[u8]) -> Result<(), PnWireError> {
        if frame.len() > MAX_FRAME {
            return Ok(());
        }
        self.wire.send(frame)
    }

    /// One round for `ctl`: its timers and frames, then the frames received until its next
    /// timer or `until`. Returns its events.
    fn pump(
        &mut self,
        ctl: &mut Controller,
        until: Duration,
        seen: &mut Vec<Vec<u8>>,
    ) -> Result<Vec<ControllerEvent>, PnWireError> {
        let now = self.wire.now();
        ctl.handle_timeout(now);
        while let Some(f) = ctl.poll_transmit(now) {
            self.send(&f)?;
        }
        let mut events = Vec::new();
        while let Some(e) = ctl.poll_event() {
            events.push(e);
        }
        if !events.is_empty() || now >= until {
            return Ok(events);
        }
        let wake = ctl
            .poll_timeout()
            .map_or(until, |t| t.min(until))
            .max(now + Duration::from_micros(1));
        for (t, f) in self.wire.recv(wake)? {
            ctl.handle_frame(t, &f);
            if seen.len() < MAX_SEEN && !is_cyclic(&f) {
                seen.push(f);
            }
        }
        Ok(events)
    }

    /// Listens until `until`, keeping the fuzzer's AR (if any) running.
    fn listen(&mut self, until: Duration) -> Result<Vec<Vec<u8>>, PnWireError> {
        let mut seen = Vec::new();
        while self.wire.now() < until {
            if let Some(mut ctl) = self.session.take() {
                self.pump(&mut ctl, until, &mut seen)?;
                if !ctl.is_closed() {
                    self.session = Some(ctl);
                }
            } else {
                for (_, f) in self.wire.recv(until)? {
                    if seen.len() < MAX_SEEN && !is_cyclic(&f) {
                        seen.push(f);
                    }
                }
            }
        }
        Ok(seen)
    }

    /// Sends a DCP Identify by the station's name and waits [`IDENTIFY_TIMEOUT`] for the
    /// answer: the device's MAC, if it answered.
    fn locate(&mut self) -> Result<Option<Mac>, PnWireError> {
        let mut b = DcpBlocks::new();
        b.plain(opt::NAME_OF_STATION, self.wire.target().as_bytes());
        let xid = self.next_xid();
        let frame = self.dcp_frame(
            FrameId::DCP_IDENTIFY_REQ,
            service::IDENTIFY,
            xid,
            DCP_IDENTIFY_MAC,
            &b.into_bytes(),
        );
        self.send(&frame)?;
        let until = self.wire.now() + IDENTIFY_TIMEOUT;
        while self.wire.now() < until {
            for (_, f) in self.wire.recv(until)? {
                let Ok(l) = parse_ethernet(&f) else { continue };
                let answered = RtFrame::parse(l.payload)
                    .ok()
                    .filter(|r| r.class() == FrameClass::DcpIdentifyResponse)
                    .and_then(|r| r.dcp().ok())
                    .is_some_and(|h| h.xid == xid);
                if let (true, Some(src)) = (l.ethertype == ethertype::PROFINET && answered, l.src) {
                    self.device = Some(src);
                    return Ok(Some(src));
                }
            }
        }
        Ok(None)
    }

    fn next_xid(&mut self) -> u32 {
        self.xid = self.xid.wrapping_add(1);
        self.xid
    }

    fn dcp_frame(&self, id: FrameId, sid: u8, xid: u32, dst: Mac, blocks: &[u8]) -> Vec<u8> {
        let pdu = dcp::pdu(id, sid, service_type::REQUEST, xid, 1, blocks);
        eth::frame(dst, self.wire.station().0, None, ethertype::PROFINET, &pdu)
    }

    /// Runs one step.
    pub(crate) fn step(&mut self, step: &PnStep) -> Result<Outcome, PnWireError> {
        match step {
            PnStep::DcpIdentify { blocks } => {
                let xid = self.next_xid();
                let f = self.dcp_frame(
                    FrameId::DCP_IDENTIFY_REQ,
                    service::IDENTIFY,
                    xid,
                    DCP_IDENTIFY_MAC,
                    blocks,
                );
                self.raw(f)
            }
            PnStep::DcpSet { blocks } | PnStep::DcpGet { blocks } => {
                let dst = match self.device {
                    Some(d) => Some(d),
                    None => self.locate()?,
                };
                let Some(dst) = dst else {
                    return Ok(note("not sent: the station did not answer Identify"));
                };
                let sid = if matches!(step, PnStep::DcpSet { .. }) {
                    service::SET
                } else {
                    service::GET
                };
                let xid = self.next_xid();
                let f = self.dcp_frame(FrameId::DCP_GET_SET, sid, xid, dst, blocks);
                self.raw(f)
            }
            PnStep::Connect {
                send_clock_factor,
                reduction_ratio,
                data_hold_factor,
                data_length,
                input_length,
                output_length,
                module_ident,
                submodule_ident,
            } => {
                self.close_session()?;
                let mut c = self.config();
                c.send_clock_factor = *send_clock_factor;
                c.reduction_ratio = *reduction_ratio;
                c.data_hold_factor = *data_hold_factor;
                c.data_length = *data_length;
                c.identity.input.length = *input_length;
                c.identity.output.length = *output_length;
                c.identity.output.module_ident = *module_ident;
                c.identity.output.submodule_ident = *submodule_ident;
                self.connect_once(c)
            }
            PnStep::RecordRead {
                slot,
                subslot,
                index,
            } => self.record(*slot, *subslot, *index, None),
            PnStep::RecordWrite {
                slot,
                subslot,
                index,
                data,
            } => self.record(*slot, *subslot, *index, Some(data)),
            PnStep::Rt {
                cycle_counter,
                data_status,
                transfer_status,
                ioxs,
                length,
            } => {
                let Some(ctl) = self.open_session()? else {
                    return Ok(note("not sent: no AR"));
                };
                let (Some((dev, _)), id) = (ctl.device(), ctl.output_frame_id()) else {
                    return Ok(note("not sent: no AR"));
                };
                let c_sdu = vec![*ioxs; usize::from(*length)];
                let mut pdu = rt::cyclic(id, &c_sdu, *cycle_counter, *data_status);
                if let Some(t) = pdu.last_mut() {
                    *t = *transfer_status;
                }
                let f = eth::frame(dev, self.wire.station().0, None, ethertype::PROFINET, &pdu);
                self.raw(f)
            }
        }
    }

    /// Sends `frame` and listens for [`SETTLE`].
    fn raw(&mut self, frame: Vec<u8>) -> Result<Outcome, PnWireError> {
        self.send(&frame)?;
        let until = self.wire.now() + SETTLE;
        let seen = self.listen(until)?;
        let note = format!("{} frame(s) back", seen.len());
        Ok(Outcome {
            sent: Some(frame),
            seen,
            note,
        })
    }

    /// A Connect with `c`; an accepted AR is released at once.
    fn connect_once(&mut self, c: ControllerConfig) -> Result<Outcome, PnWireError> {
        let mut ctl = Controller::new(c);
        let start = self.wire.now();
        ctl.start(start);
        let until = start + STAGE;
        let mut seen = Vec::new();
        let mut what = "no answer".to_owned();
        while !ctl.is_closed() && self.wire.now() < until {
            for e in self.pump(&mut ctl, until, &mut seen)? {
                match e {
                    ControllerEvent::Connected => {
                        what = "accepted".to_owned();
                        let now = self.wire.now();
                        // Released at once; a release that cannot be asked any more
                        // (the controller failed) is what its abort already did.
                        let _ = ctl.release(now);
                    }
                    ControllerEvent::Released => what = format!("{what}, released"),
                    ControllerEvent::Failed(e) => what = format!("{what}; {e}"),
                    _ => {}
                }
            }
        }
        // Frames the controller still holds (an abort) go out.
        let now = self.wire.now();
        while let Some(f) = ctl.poll_transmit(now) {
            self.send(&f)?;
        }
        Ok(Outcome {
            sent: None,
            seen,
            note: what,
        })
    }

    /// The fuzzer's AR in data exchange: the running one, or a new one.
    fn open_session(&mut self) -> Result<Option<&mut Controller>, PnWireError> {
        if self.session.as_ref().is_some_and(Controller::is_running) {
            return Ok(self.session.as_mut());
        }
        self.session = None;
        let c = self.config();
        let mut ctl = Controller::new(c);
        let start = self.wire.now();
        ctl.start(start);
        let until = start + STAGE;
        let mut seen = Vec::new();
        while !ctl.is_closed() && !ctl.is_running() && self.wire.now() < until {
            self.pump(&mut ctl, until, &mut seen)?;
        }
        if ctl.is_running() {
            self.device = ctl.device().map(|(m, _)| m);
            self.session = Some(ctl);
        }
        Ok(self.session.as_mut())
    }

    /// Releases the fuzzer's AR, if any.
    fn close_session(&mut self) -> Result<(), PnWireError> {
        let Some(mut ctl) = self.session.take() else {
            return Ok(());
        };
        let now = self.wire.now();
        if ctl.release(now).is_err() {
            return Ok(());
        }
        let until = now + STAGE;
        let mut seen = Vec::new();
        while !ctl.is_closed() && self.wire.now() < until {
            self.pump(&mut ctl, until, &mut seen)?;
        }
        Ok(())
    }

    fn record(
        &mut self,
        slot: u16,
        subslot: u16,
        index: u16,
        data: Option<&[u8]>,
    ) -> Result<Outcome, PnWireError> {
        let now = self.wire.now();
        let Some(ctl) = self.open_session()? else {
            return Ok(note("not sent: no AR"));
        };
        let asked = match data {
            Some(d) => ctl.write_record(now, slot, subslot, index, d),
            None => ctl.read_record(now, slot, subslot, index),
        };
        let Ok(id) = asked else {
            return Ok(note("not sent: no AR"));
        };
        let Some(mut ctl) = self.session.take() else {
            return Ok(note("not sent: no AR"));
        };
        let until = self.wire.now() + STAGE;
        let mut seen = Vec::new();
        let mut what = "no answer".to_owned();
        'wait: while !ctl.is_closed() && self.wire.now() < until {
            for e in self.pump(&mut ctl, until, &mut seen)? {
                match e {
                    ControllerEvent::Record { id: got, result } if got == id => {
                        what = match result {
                            Ok(d) => format!("answered, {} byte(s)", d.len()),
                            Err(e) => e.to_string(),
                        };
                        break 'wait;
                    }
                    ControllerEvent::Failed(e) => what = format!("the AR failed: {e}"),
                    _ => {}
                }
            }
        }
        if !ctl.is_closed() {
            self.session = Some(ctl);
        }
        Ok(Outcome {
            sent: None,
            seen,
            note: what,
        })
    }

    /// The liveness probe: Identify by name, a valid Connect up to data exchange,
    /// [`PROBE_FRAMES`] input frames, Release.
    pub(crate) fn probe(&mut self) -> Result<Result<String, (Stage, String)>, PnWireError> {
        self.close_session()?;
        let c = self.config();
        let mut ctl = Controller::new(c);
        let start = self.wire.now();
        ctl.start(start);
        let until = start + STAGE + STAGE;
        let mut seen = Vec::new();
        let (mut identified, mut running) = (false, false);
        let stage = |identified: bool, running: bool| match (identified, running) {
            (false, _) => Stage::Identify,
            (true, false) => Stage::Connect,
            (true, true) => Stage::Cyclic,
        };
        loop {
            if running && ctl.input_frames() >= PROBE_FRAMES {
                break;
            }
            if self.wire.now() >= until {
                let s = stage(identified, running);
                return Ok(Err((s, format!("no progress within {:?}", STAGE + STAGE))));
            }
            for e in self.pump(&mut ctl, until, &mut seen)? {
                match e {
                    ControllerEvent::Identified { mac, .. } => {
                        identified = true;
                        self.device = Some(mac);
                    }
                    ControllerEvent::Running => running = true,
                    ControllerEvent::Failed(e) => {
                        let s = match e {
                            ControllerError::NoSuchStation(_) | ControllerError::NoIp(_) => {
                                Stage::Identify
                            }
                            _ => stage(identified, running),
                        };
                        return Ok(Err((s, e.to_string())));
                    }
                    _ => {}
                }
            }
        }
        let frames = ctl.input_frames();
        let now = self.wire.now();
        if ctl.release(now).is_ok() {
            let until = now + STAGE;
            while !ctl.is_closed() && self.wire.now() < until {
                self.pump(&mut ctl, until, &mut seen)?;
            }
        }
        Ok(Ok(format!(
            "identified, connected, {frames} input frame(s), released"
        )))
    }

    /// The evidence record of step `step`.
    pub(crate) fn record_of(&mut self, step: usize, text: &str, o: &Outcome) -> Record {
        let at_us = u64::try_from(self.wire.now().as_micros()).unwrap_or(u64::MAX);
        let got = match o.seen.first() {
            Some(f) => Answer {
                hex: to_hex(f),
                text: format!("{} frame(s)", o.seen.len()),
                delay_us: None,
            },
            None => Answer::silence(),
        };
        Record {
            step,
            role: Role::Check,
            action: text.to_owned(),
            at_us,
            sent: o.sent.as_deref().map(to_hex),
            sent_text: Some(text.to_owned()),
            expected: None,
            got: Some(got),
            ok: None,
            note: Some(o.note.clone()),
        }
    }
}

/// An outcome with nothing sent.
fn note(text: &str) -> Outcome {
    Outcome {
        sent: None,
        seen: Vec::new(),
        note: text.to_owned(),
    }
}
