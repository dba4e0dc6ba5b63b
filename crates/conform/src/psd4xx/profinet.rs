//! `--dut profinet:IFACE/NAME`: the `drivespec-cyclic/1` requests played against a PSD4xx on
//! the network through the PROFINET IO controller of `drivespec-profinet`, on real time.
//!
//! Opening identifies the station by NameOfStation (DCP), connects with the PSD4xx modules,
//! sends PrmEnd and waits for ApplicationReady; every wait has a deadline, and a failure is a
//! setup error naming the reason. Then:
//!
//! | request | over PROFINET |
//! | --- | --- |
//! | `RESET` | on a new AR, write par 96 = -6 (reset, as switching the control voltage off and on, 3.3); on the next, par 96 = -5 (delivery state saved, move to the middle of the range) and wait until the drive stands there; then par 96 = -6 again (the status word of power-on); the session clock restarts at 0 |
//! | `CYCLE T OUT` | wait until the session time `T`, send `OUT` as the output image (3.5.1), let one full RT cycle pass both ways and answer the latest input image (3.5.2): the input of a `CYCLE` reflects the output after the RT round trip |
//! | `ADVANCE T` | wait until `T` |
//! | `READ T INDEX`, `WRITE T INDEX HEX` | wait until `T`, then the acyclic record Read or Write of `INDEX` on the output module's subslot (3.2.2) |
//! | `ENV T power-cycle 0` | wait until `T`, write par 96 = -6 ("reset the drive, as switching the control voltage off and on", 3.3), connect again |
//! | other `ENV …` | `UNSUPPORTED`: a network cannot turn the shaft, cut the motor supply or drop the link |
//!
//! A refused record is answered by its PNIOStatus: ErrorCode1 `B1` (write length) is
//! `MALFORMED`, any other PNIORW refusal `REFUSED` with the PKW error number of ErrorCode2
//! (3.8), a state conflict (`B5`) `SILENT`. A write of control byte 0 that succeeds is
//! `IGNORED` (3.2.2: the drive ignores the write).

use crate::cyclic::{Env, Peer, PeerError, Reply, Request, VERSION};
use crate::link::LinkError;
use crate::suite::SetupError;
use drivespec_capture::link::{ethertype, parse_ethernet};
use drivespec_capture::pnio::PnioStatus;
use drivespec_capture::rt::{FrameClass, RtFrame};
use drivespec_profinet::identity::Identity;
use drivespec_profinet::status::{self, rw};
use drivespec_profinet::{
    Controller, ControllerConfig, ControllerError, ControllerEvent, RecordId,
};
use drivespec_spec::hex::to_hex_compact as hex;
use drivespec_wire::{Filter, OpenOptions, RawSocket};
use std::net::UdpSocket;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Longest sleep between two looks at the socket: a received frame waits at most this long
/// before the controller handles it. A choice: a fifth of the 1 ms send clock, against
/// 5,000 wake-ups a second.
const STEP: Duration = Duration::from_micros(200);

/// Longest wait for identify, connect, parameterisation and ApplicationReady together: the
/// controller's own deadlines (3 s Identify, 4 × 1 s per call, 3 s ApplicationReady) end
/// every step before it; this bounds the sum.
const START: Duration = Duration::from_secs(15);

/// Longest wait for a record answer or for the input frames of a cycle: above the
/// controller's RPC deadline with its repeats (4 × 1 s), so its own error comes first.
const ANSWER: Duration = Duration::from_secs(5);

/// DataHoldFactor of the AR: cycles without a valid frame before either side ends it. A
/// choice: the controller and the device here are ordinary processes, which a loaded machine
/// may leave unscheduled for tens of milliseconds; a PLC with a real-time kernel uses 3. 256
/// cycles (256 ms at the 1 ms send clock) keeps a starved process from ending the AR while a
/// device that stops its frames is still noticed within a case.
const DATA_HOLD_FACTOR: u16 = 256;

/// Longest wait for the drive to stand at the start position after par 96 = -5: saving
/// (up to 1 s, manual 4.7) and a run across the whole range of the largest model at a
/// tenth of its delivery speed.
const SETTLE: Duration = Duration::from_secs(30 * 60);

/// Longest the input image may stand still, away from the start position, after par 96 =
/// -5 before the drive counts as stopped elsewhere: above the save time (1 s, manual 4.7).
const STALL: Duration = Duration::from_secs(5);

/// Pause before a failed start-up is tried again.
const RETRY: Duration = Duration::from_millis(50);

/// Longest wait for the answer to a Release.
const RELEASE: Duration = Duration::from_secs(2);

/// Longest sleep of the exchange thread when the controller has no timer due.
const IDLE: Duration = Duration::from_millis(10);

/// Input frames to wait for after the first output frame carrying a new image: the first may
/// have crossed it on the wire, the second left the device after it took the image.
const ROUND_TRIP_FRAMES: u64 = 2;

/// Whether an input image shows the drive settled at the start position.
pub(crate) type Settled = Box<dyn Fn(&[u8]) -> bool + Send>;

/// What `RESET` writes and waits for (module doc).
pub(crate) struct StartRecords {
    /// The write (index, data) that restarts the drive.
    pub restart: (u16, Vec<u8>),
    /// The write that restores and saves the delivery state and moves to the start position.
    pub centre: (u16, Vec<u8>),
    /// Whether an input image shows the drive settled at the start position.
    pub settled: Settled,
}

/// What the exchange thread and the requests share.
struct Shared {
    ctl: Controller,
    /// Output frames sent since the controller was made.
    cyclic_sent: u64,
    /// The failure the controller reported, if any.
    failed: Option<ControllerError>,
    /// The answer to the record request waited for.
    record: Option<(RecordId, Result<Vec<u8>, ControllerError>)>,
    /// A send or receive that failed; the thread has ended.
    wire: Option<String>,
    /// The peer is dropped: the thread ends.
    stop: bool,
}

/// The peer of a PSD4xx reached by PROFINET IO (our doc: module `profinet`). A thread runs
/// the controller on the wire all the time (the cyclic frames go on between requests); the
/// requests act on it and wait for what they need.
pub struct ProfinetPeer {
    what: String,
    target: String,
    identity: Identity,
    mac: [u8; 6],
    ip: [u8; 4],
    /// The clock every `now` of the controller counts from.
    origin: Instant,
    /// Session time 0 (the last `RESET`).
    base: Instant,
    /// When the input image of the last `CYCLE` was taken (session µs).
    taken: Option<u64>,
    /// ARs made so far (each gets its own AR UUID and SessionKey).
    ars: u16,
    /// The device's MAC once found: a case that deletes the name (par 96 = -3) leaves a
    /// device the next start-up names again by DCP Set.
    device: Option<[u8; 6]>,
    start: StartRecords,
    shared: Arc<Mutex<Shared>>,
    thread: Option<JoinHandle<()>>,
    /// Keeps the kernel from answering the device's RPC answers with ICMP.
    _quiet: Option<UdpSocket>,
}

impl std::fmt::Debug for ProfinetPeer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ProfinetPeer")
            .field("what", &self.what)
            .finish_non_exhaustive()
    }
}

/// Whether `frame` is a cyclic RT frame.
fn is_cyclic(frame: &[u8]) -> bool {
    parse_ethernet(frame)
        .ok()
        .filter(|l| l.ethertype == ethertype::PROFINET)
        .and_then(|l| RtFrame::parse(l.payload).ok())
        .is_some_and(|r| matches!(r.frame_id.class(), FrameClass::Cyclic(_)))
}

fn lock(shared: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    shared.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The exchange thread: timers, frames to send and frames received, until stopped.
fn exchange(mut sock: RawSocket, origin: Instant, shared: &Mutex<Shared>) {
    loop {
        let wait = {
            let mut s = lock(shared);
            if s.stop {
                return;
            }
            let now = origin.elapsed();
            s.ctl.handle_timeout(now);
            while let Some(frame) = s.ctl.poll_transmit(now) {
                if is_cyclic(&frame) {
                    s.cyclic_sent = s.cyclic_sent.saturating_add(1);
                }
                if let Err(e) = sock.send(&frame) {
                    s.wire = Some(e.to_string());
                    return;
                }
            }
            while let Some(e) = s.ctl.poll_event() {
                match e {
                    ControllerEvent::Failed(e) => s.failed = Some(e),
                    ControllerEvent::Record { id, result } => s.record = Some((id, result)),
                    _ => {}
                }
            }
            s.ctl
                .poll_timeout()
                .map_or(IDLE, |t| t.saturating_sub(now))
                .min(IDLE)
        };
        let mut frames = Vec::new();
        let got = sock.wait_frames(Instant::now() + wait, STEP, |r| frames.push(r));
        let mut s = lock(shared);
        if let Err(e) = got {
            s.wire = Some(e.to_string());
            return;
        }
        for r in frames {
            let at = r.instant.saturating_duration_since(origin);
            s.ctl.handle_frame(at, &r.frame);
        }
    }
}

impl ProfinetPeer {
    /// Opens interface `iface` and brings up an AR with the station named `target`; any
    /// failure is a setup error with its reason.
    pub(crate) fn open(
        iface: &str,
        target: &str,
        identity: Identity,
        start: StartRecords,
    ) -> Result<ProfinetPeer, SetupError> {
        let what = format!("profinet:{iface}/{target}");
        let setup = |reason: String| {
            SetupError::Link(LinkError::Open {
                what: what.clone(),
                reason,
            })
        };
        let interface =
            drivespec_wire::Interface::by_name(iface).map_err(|e| setup(e.to_string()))?;
        let mac = interface
            .mac
            .ok_or_else(|| setup(format!("network interface `{iface}` has no MAC address")))?;
        let ip = interface
            .ipv4
            .first()
            .ok_or_else(|| setup(format!("network interface `{iface}` has no IPv4 address")))?
            .octets();
        let options = OpenOptions {
            filter: Filter::ether_types(&drivespec_profinet::eth::STATION_ETHER_TYPES)
                .skipping_source(mac),
            promiscuous: false,
            poll: Duration::ZERO,
            ..OpenOptions::default()
        };
        let sock = RawSocket::open(iface, options).map_err(|e| setup(e.to_string()))?;
        let quiet =
            drivespec_wire::bind_udp(iface, drivespec_profinet::controller::CLIENT_PORT).ok();
        let origin = Instant::now();
        let shared = Arc::new(Mutex::new(Shared {
            ctl: Controller::new(ControllerConfig::new(identity.clone(), mac, ip, "")),
            cyclic_sent: 0,
            failed: None,
            record: None,
            wire: None,
            stop: false,
        }));
        let thread = {
            let shared = Arc::clone(&shared);
            std::thread::Builder::new()
                .name("profinet-controller".to_owned())
                .spawn(move || exchange(sock, origin, &shared))
                .map_err(|e| setup(format!("cannot start the exchange thread: {e}")))?
        };
        let mut peer = ProfinetPeer {
            what: what.clone(),
            target: target.to_owned(),
            identity,
            mac,
            ip,
            origin,
            base: origin,
            taken: None,
            ars: 0,
            device: None,
            start,
            shared,
            thread: Some(thread),
            _quiet: quiet,
        };
        peer.connect().map_err(|e| setup(e.to_string()))?;
        peer.base = Instant::now();
        Ok(peer)
    }

    /// A fresh controller: identify, connect, PrmEnd, ApplicationReady. A refused or failed
    /// start-up is tried again until [`START`] has passed: an AR this side could not release
    /// (its controller failed) holds the device until the device's watchdog ends it.
    fn connect(&mut self) -> Result<(), PeerError> {
        let deadline = Instant::now() + START;
        while let Err(e) = self.start_up(deadline) {
            // No station of that name, and none to give it to: trying again cannot help.
            let gone = matches!(
                lock(&self.shared).failed,
                Some(ControllerError::NoSuchStation(_))
            );
            if gone || Instant::now() + RETRY >= deadline {
                return Err(e);
            }
            std::thread::sleep(RETRY);
        }
        Ok(())
    }

    fn start_up(&mut self, deadline: Instant) -> Result<(), PeerError> {
        self.ars = self.ars.wrapping_add(1);
        let mut config =
            ControllerConfig::new(self.identity.clone(), self.mac, self.ip, &self.target);
        for (u, n) in config
            .ar_uuid
            .0
            .iter_mut()
            .skip(14)
            .zip(self.ars.to_be_bytes())
        {
            *u ^= n;
        }
        config.session_key = self.ars;
        config.data_hold_factor = DATA_HOLD_FACTOR;
        config.name_device = self.device;
        {
            let mut s = lock(&self.shared);
            s.ctl = Controller::new(config);
            s.failed = None;
            s.record = None;
            s.ctl.start(self.origin.elapsed());
        }
        self.wait(
            deadline,
            "the start-up (Identify, Connect, PrmEnd, ApplicationReady)",
            |s| s.ctl.is_running(),
        )?;
        self.device = lock(&self.shared).ctl.device().map(|(mac, _)| mac);
        Ok(())
    }

    /// Waits until `done` holds of the shared state; an error of the controller or the wire,
    /// or `deadline`, ends the wait.
    fn wait(
        &self,
        deadline: Instant,
        what: &str,
        mut done: impl FnMut(&mut Shared) -> bool,
    ) -> Result<(), PeerError> {
        let started = Instant::now();
        loop {
            {
                let mut s = lock(&self.shared);
                if let Some(e) = &s.wire {
                    return Err(PeerError::Link(LinkError::Io(e.clone())));
                }
                if let Some(e) = &s.failed {
                    return Err(PeerError::Link(LinkError::Io(format!(
                        "{}: {e}",
                        self.what
                    ))));
                }
                if done(&mut s) {
                    return Ok(());
                }
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(PeerError::Timeout {
                    request: what.to_owned(),
                    ms: u64::try_from(now.duration_since(started).as_millis()).unwrap_or(u64::MAX),
                    partial: String::new(),
                });
            }
            std::thread::sleep(STEP.min(deadline - now));
        }
    }

    /// Lets the exchange run until session time `t` (µs).
    fn until(&self, t: u64) -> Result<(), PeerError> {
        let at = self.base + Duration::from_micros(t);
        self.wait(at, "", |_| false).or_else(|e| match e {
            PeerError::Timeout { .. } => Ok(()),
            other => Err(other),
        })
    }

    /// Restarts the drive (par 96 = reset) and makes a new AR: a real drive ends the AR
    /// doing so.
    fn restart(&mut self) -> Result<(), PeerError> {
        self.reconnect()?;
        let (index, data) = self.start.restart.clone();
        // The drive restarts after its answer; one that restarts before gives none.
        if let Ok(got) = self.record(0, index, Some(&data)) {
            expect_written("par 96 = reset", got)?;
        }
        self.reconnect()
    }

    /// Releases the AR (if one is up) and makes a new one.
    fn reconnect(&mut self) -> Result<(), PeerError> {
        let released = lock(&self.shared)
            .ctl
            .release(self.origin.elapsed())
            .is_ok();
        if released {
            // A release that fails still ends the AR on this side; connect anew.
            let _ = self.wait(Instant::now() + RELEASE, "Release", |s| s.ctl.is_closed());
        }
        self.connect()
    }

    fn cycle(&mut self, t: u64, image: &[u8]) -> Result<Reply, PeerError> {
        let out = usize::from(self.identity.output.length);
        if image.len() != out {
            return Ok(Reply::Err(format!(
                "output image of {} bytes (the output module has {out})",
                image.len()
            )));
        }
        self.until(t)?;
        let sent = {
            let mut s = lock(&self.shared);
            s.ctl.set_output(image);
            s.cyclic_sent
        };
        let mut first: Option<u64> = None;
        self.wait(Instant::now() + ANSWER, "CYCLE", |s| {
            if first.is_none() && s.cyclic_sent > sent {
                first = Some(s.ctl.input_frames());
            }
            first.is_some_and(|n| s.ctl.input_frames() >= n.saturating_add(ROUND_TRIP_FRAMES))
        })?;
        self.taken = u64::try_from(self.base.elapsed().as_micros()).ok();
        let s = lock(&self.shared);
        Ok(s.ctl
            .input()
            .map_or(Reply::Silent, |i| Reply::In(i.image.clone())))
    }

    fn record(&self, t: u64, index: u16, data: Option<&[u8]>) -> Result<Reply, PeerError> {
        self.until(t)?;
        let (slot, subslot) = (self.identity.output.slot, self.identity.output.subslot);
        let name = if data.is_some() { "WRITE" } else { "READ" };
        let id = {
            let mut s = lock(&self.shared);
            s.record = None;
            let now = self.origin.elapsed();
            match data {
                Some(d) => s.ctl.write_record(now, slot, subslot, index, d),
                None => s.ctl.read_record(now, slot, subslot, index),
            }
            .map_err(|e| PeerError::Link(LinkError::Io(format!("{}: {e}", self.what))))?
        };
        let mut result = None;
        self.wait(Instant::now() + ANSWER, name, |s| {
            if s.record.as_ref().is_some_and(|(r, _)| *r == id) {
                result = s.record.take().map(|(_, r)| r);
            }
            result.is_some()
        })?;
        let Some(result) = result else {
            return Ok(Reply::Silent);
        };
        Ok(match (result, data) {
            (Ok(_), Some(d)) if d.first() == Some(&0) => Reply::Ignored,
            (Ok(_), Some(_)) => Reply::Written,
            (Ok(bytes), None) => Reply::Data(bytes),
            (Err(ControllerError::Refused { status: s, .. }), _) => refused(s),
            (Err(e), _) => {
                return Err(PeerError::Garbage {
                    request: format!("{name} {t} {index}"),
                    why: e.to_string(),
                })
            }
        })
    }
}

impl Drop for ProfinetPeer {
    fn drop(&mut self) {
        {
            let mut s = lock(&self.shared);
            let _ = s.ctl.release(self.origin.elapsed());
        }
        // The Release goes out with the next turn of the thread; its answer is not awaited.
        let _ = self.wait(Instant::now() + RELEASE, "Release", |s| s.ctl.is_closed());
        lock(&self.shared).stop = true;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// `Ok` for a write the drive took; what `RESET` got otherwise.
fn expect_written(what: &str, got: Reply) -> Result<(), PeerError> {
    match got {
        Reply::Written => Ok(()),
        other => Err(PeerError::Garbage {
            request: "RESET".to_owned(),
            why: format!("{what} answered {other}"),
        }),
    }
}

/// The reply a refused record stands for (module doc).
fn refused(s: PnioStatus) -> Reply {
    if s.decode != status::PNIORW {
        return Reply::Err(format!("record refused with PNIOStatus {s}"));
    }
    match s.code1 {
        rw::WRITE_LENGTH => Reply::Malformed,
        rw::STATE_CONFLICT => Reply::Silent,
        _ => Reply::Refused(u32::from(s.code2)),
    }
}

impl Peer for ProfinetPeer {
    fn describe(&self) -> String {
        self.what.clone()
    }

    fn call(&mut self, req: &Request) -> Result<Reply, PeerError> {
        match req {
            Request::Hello { family, .. } if family == "psd4xx" => Ok(Reply::Hello {
                version: VERSION,
                name: format!("PROFINET IO device {} (drivespec controller)", self.target),
            }),
            Request::Hello { family, .. } => Ok(Reply::Err(format!(
                "{family}: a PROFINET IO device is a psd4xx"
            ))),
            Request::Reset => {
                self.restart()?;
                let (index, data) = self.start.centre.clone();
                let got = self.record(0, index, Some(&data))?;
                expect_written("par 96 = delivery state and centre", got)?;
                // Waits as long as the drive moves: a run across the whole range at the
                // delivery speed takes minutes; a drive whose image stands still for
                // [`STALL`] without being there has stopped elsewhere.
                let settled = &self.start.settled;
                let mut last = Vec::new();
                let mut changed = Instant::now();
                let moved = self.wait(Instant::now() + SETTLE, "", |s| {
                    let image = s.ctl.input().map(|i| i.image.clone()).unwrap_or_default();
                    if image != last {
                        (last, changed) = (image, Instant::now());
                    }
                    settled(&last) || changed.elapsed() > STALL
                });
                if moved.is_ok() && !settled(&last)
                    || matches!(moved, Err(PeerError::Timeout { .. }))
                {
                    return Err(PeerError::Garbage {
                        request: "RESET".to_owned(),
                        why: format!(
                            "the drive did not come to stand at the start position after par 96 = delivery state and centre; its last input image: {}",
                            hex(&last)
                        ),
                    });
                }
                moved?;
                self.restart()?;
                self.base = Instant::now();
                Ok(Reply::Ok)
            }
            Request::Cycle { t, image } => self.cycle(*t, image),
            Request::Advance { t } => {
                self.until(*t)?;
                Ok(Reply::Ok)
            }
            Request::Read { t, index } => self.record(*t, *index, None),
            Request::Write { t, index, data } => self.record(*t, *index, Some(data)),
            Request::IsduRead { .. } | Request::IsduWrite { .. } => Ok(Reply::Err(
                "ISDU requests are for psx3xx (IO-Link)".to_owned(),
            )),
            Request::Env {
                t,
                env: Env::PowerCycle,
            } => {
                self.until(*t)?;
                self.restart()?;
                Ok(Reply::Ok)
            }
            Request::Env { .. } => Ok(Reply::Unsupported),
        }
    }

    fn recover(&mut self) -> Result<(), PeerError> {
        self.connect()
    }

    fn taken_at(&self) -> Option<u64> {
        self.taken
    }
}
