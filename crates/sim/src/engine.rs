//! The serving loop: the wall clock drives the model's clock, messages go out at their time,
//! faults are applied, and every wait is bounded.

use super::device::{Emitted, ServedDevice};
use super::faults::{Dice, Faults};
use super::ServeError;
use drivespec_link::port::{Got, Port};
use drivespec_link::{Micros, WallClock};
use drivespec_spec::hex::to_hex;
use std::collections::VecDeque;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Longest single wait, so a stop or the time limit takes effect within it.
const MAX_WAIT: Duration = Duration::from_millis(20);

/// How a model is served.
#[derive(Debug, Clone, PartialEq)]
pub struct Options {
    /// Faults applied to what the device sends.
    pub faults: Faults,
    /// Log every byte received and sent, with the time and the messages in words.
    pub log: bool,
    /// Stop after this long.
    pub time_limit: Option<Duration>,
    /// Stop after this many clients (TCP).
    pub max_clients: Option<u32>,
    /// Refuse bytes a pseudo-terminal client sends at another bit rate than the device's.
    pub check_bit_rate: bool,
}

impl Default for Options {
    /// No faults, no log, no limits, bit rates checked.
    fn default() -> Options {
        Options {
            faults: Faults::default(),
            log: false,
            time_limit: None,
            max_clients: None,
            check_bit_rate: true,
        }
    }
}

/// Stops a serving loop from another thread (within 20 ms).
#[derive(Debug, Clone, Default)]
pub struct Stop(Arc<AtomicBool>);

impl Stop {
    /// A handle that has not stopped anything yet.
    pub fn new() -> Stop {
        Stop::default()
    }

    /// Asks the loop to stop.
    pub fn stop(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether a stop was asked for.
    pub fn is_stopped(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// What happened while serving.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct Stats {
    /// Clients served (TCP; 0 elsewhere).
    pub clients: u32,
    /// Bytes received.
    pub received: u64,
    /// Bytes refused: sent at another bit rate than the device's (pseudo-terminal).
    pub refused: u64,
    /// Messages sent.
    pub sent: u64,
    /// Messages dropped (`--drop-answers`).
    pub dropped: u64,
    /// Messages sent with a wrong checksum (`--corrupt-checksums`).
    pub corrupted: u64,
    /// Messages not sent because the client went away first.
    pub lost: u64,
    /// Time served (µs).
    pub wall_us: u64,
}

/// Why a session ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum End {
    /// The client went away.
    Closed,
    /// Stop or time limit.
    Stopped,
}

/// A device being served, with its clock and the messages waiting for their time.
pub(crate) struct Engine<'l> {
    device: Box<dyn ServedDevice>,
    clock: WallClock,
    dice: Dice,
    /// Messages waiting for their send time, in time order.
    queue: VecDeque<(Micros, Vec<u8>)>,
    deadline: Option<Micros>,
    log_on: bool,
    log: &'l mut dyn Write,
    check_bit_rate: bool,
    /// The last bit-rate mismatch warned about: (client, device).
    warned: Option<(u32, u32)>,
    stats: Stats,
}

impl<'l> Engine<'l> {
    pub(crate) fn new(
        device: Box<dyn ServedDevice>,
        opts: &Options,
        log: &'l mut dyn Write,
    ) -> Engine<'l> {
        Engine {
            device,
            clock: WallClock::start(),
            dice: Dice::new(opts.faults),
            queue: VecDeque::new(),
            deadline: opts
                .time_limit
                .map(|d| u64::try_from(d.as_micros()).unwrap_or(u64::MAX)),
            log_on: opts.log,
            log,
            check_bit_rate: opts.check_bit_rate,
            warned: None,
            stats: Stats::default(),
        }
    }

    pub(crate) fn clients(&self) -> u32 {
        self.stats.clients
    }

    /// Counts a client that connected.
    pub(crate) fn client(&mut self) {
        self.stats.clients = self.stats.clients.saturating_add(1);
    }

    /// Stop asked for, or the time limit reached.
    pub(crate) fn should_stop(&self, stop: &Stop) -> bool {
        stop.is_stopped() || self.deadline.is_some_and(|d| self.clock.now() >= d)
    }

    /// A line for the log (always written: connections, warnings).
    pub(crate) fn note(&mut self, text: &str) {
        let t = self.clock.now();
        let _ = writeln!(self.log, "{} {text}", stamp(t));
    }

    pub(crate) fn finish(mut self) -> Stats {
        self.stats.wall_us = self.clock.now();
        let _ = self.log.flush();
        self.stats
    }

    /// Serves one client on `port` until it goes away, `stop` or the time limit.
    pub(crate) fn session(&mut self, port: &mut dyn Port, stop: &Stop) -> Result<End, ServeError> {
        let mut buf = [0u8; 1024];
        let end = loop {
            if self.should_stop(stop) {
                break End::Stopped;
            }
            let now = self.clock.now();
            self.pump(now);
            if !self.send_due(now, port)? {
                break End::Closed;
            }
            let now = self.clock.now();
            let mut wait = match self.next_wake() {
                Some(t) => Duration::from_micros(t.saturating_sub(now)),
                None => MAX_WAIT,
            }
            .min(MAX_WAIT);
            if let Some(d) = self.deadline {
                wait = wait.min(Duration::from_micros(d.saturating_sub(now)));
            }
            match port.read(&mut buf, wait)? {
                Got::Bytes(n) => {
                    let t = self.clock.now();
                    let bps = if self.check_bit_rate {
                        port.bit_rate()
                    } else {
                        None
                    };
                    self.rx(t, buf.get(..n).unwrap_or(&[]), bps);
                }
                Got::Idle => {}
                Got::Closed => break End::Closed,
            }
        };
        // Messages for a client that went away are not kept for the next one.
        self.stats.lost = self.stats.lost.saturating_add(self.queue.len() as u64);
        self.queue.clear();
        Ok(end)
    }

    /// When something is next due: a queued message or the device's own timer.
    fn next_wake(&self) -> Option<Micros> {
        let queued = self.queue.front().map(|(t, _)| *t);
        match (queued, self.device.poll_timeout()) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// Advances the device to `now` and queues what it sends, faults applied.
    fn pump(&mut self, now: Micros) {
        self.device.advance(now);
        while let Some(e) = self.device.poll_output() {
            match e {
                Emitted::Line { at, bytes } => self.schedule(at, bytes),
                Emitted::Note { at, text } => {
                    if self.log_on {
                        let _ = writeln!(self.log, "{} -- {text}", stamp(at));
                    }
                }
            }
        }
    }

    fn schedule(&mut self, at: Micros, mut bytes: Vec<u8>) {
        if self.dice.drop() {
            self.stats.dropped = self.stats.dropped.saturating_add(1);
            if self.log_on {
                let _ = writeln!(
                    self.log,
                    "{} tx dropped (fault): {}",
                    stamp(at),
                    to_hex(&bytes)
                );
            }
            return;
        }
        if self.dice.corrupting() {
            if let Some(bad) = self.device.corrupt(&bytes) {
                if self.dice.corrupt() {
                    self.stats.corrupted = self.stats.corrupted.saturating_add(1);
                    if self.log_on {
                        let _ = writeln!(
                            self.log,
                            "{} tx checksum corrupted (fault): {} instead of {}",
                            stamp(at),
                            to_hex(&bad),
                            to_hex(&bytes)
                        );
                    }
                    bytes = bad;
                }
            }
        }
        let due = at.saturating_add(self.dice.delay());
        let pos = self.queue.partition_point(|(t, _)| *t <= due);
        self.queue.insert(pos, (due, bytes));
    }

    /// Writes the messages due by `now`; false when the client went away.
    fn send_due(&mut self, now: Micros, port: &mut dyn Port) -> Result<bool, ServeError> {
        while self.queue.front().is_some_and(|(t, _)| *t <= now) {
            let Some((_, bytes)) = self.queue.pop_front() else {
                break;
            };
            if !port.write(&bytes)? {
                self.stats.lost = self.stats.lost.saturating_add(1);
                return Ok(false);
            }
            self.stats.sent = self.stats.sent.saturating_add(1);
            if self.log_on {
                let t = self.clock.now();
                let words = self.device.explain(t, &bytes, true);
                let _ = writeln!(self.log, "{} tx {}  {words}", stamp(t), to_hex(&bytes));
            }
        }
        Ok(true)
    }

    /// Bytes received at `now`; `client_bps` is the bit rate the client set, when known.
    fn rx(&mut self, now: Micros, bytes: &[u8], client_bps: Option<u32>) {
        let n = bytes.len() as u64;
        self.stats.received = self.stats.received.saturating_add(n);
        if let (Some(client), Some(device)) = (client_bps, self.device.bit_rate()) {
            if client != device {
                self.stats.refused = self.stats.refused.saturating_add(n);
                if self.warned != Some((client, device)) || self.log_on {
                    self.warned = Some((client, device));
                    self.note(&format!(
                        "rx {} refused: the client sends at {client} b/s, the drive listens at {device} b/s",
                        to_hex(bytes)
                    ));
                }
                return;
            }
        }
        self.warned = None;
        if self.log_on {
            let words = self.device.explain(now, bytes, false);
            let _ = writeln!(self.log, "{} rx {}  {words}", stamp(now), to_hex(bytes));
        }
        self.device.handle_rx(now, bytes);
    }
}

/// A time on the serving clock for the log: seconds with µs.
fn stamp(t: Micros) -> String {
    format!("{:>4}.{:06}", t / 1_000_000, t % 1_000_000)
}
