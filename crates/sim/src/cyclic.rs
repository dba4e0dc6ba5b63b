//! `drivespec sim psd4xx|psx3xx`: a reference model served on the cyclic-exchange protocol
//! `drivespec-cyclic/1` (crates/cyclic/README.md).
//!
//! Any [`Server`] is served, so every family with a cyclic server joins by naming it in
//! [`with_cyclic_server`]. Each TCP connection, the pseudo-terminal and the stdio stream are one
//! [`Server::serve`] loop: one request line in, one reply line out. Times come from the
//! requests (virtual time), so serving needs no clock of its own except for the time limit.
//!
//! Faults act on the reply lines: `--drop-answers` leaves a reply out (the client times out),
//! `--corrupt-images` flips one bit of an input image (`IN` replies), `--delay-ms` holds every
//! reply back. Every read waits at most 20 ms, so a [`Stop`] or the time limit takes effect
//! within that. A request line longer than 64 KiB drops the client (memory stays bounded); a
//! reply line longer than that is cut. Nothing here panics.

use super::engine::{Options, Stats, Stop};
use super::faults::Dice;
use super::ServeError;
use crate::reference;
use drivespec_cyclic::{Reply, Server};
use drivespec_link::port::{Got, Port, StreamPort, TcpPort};
use drivespec_link::{Micros, WallClock};
use drivespec_spec::hex::to_hex_compact as hex;
use drivespec_spec::{FamilyId, Spec};
use std::cell::RefCell;
use std::io::{BufReader, ErrorKind, Read, Write};
use std::net::TcpListener;
use std::time::Duration;

/// Longest single wait for request bytes.
const MAX_WAIT: Duration = Duration::from_millis(20);

/// Longest request line taken (a client sending a longer one is dropped) and longest reply
/// line kept (a longer one is cut: the client sees a bad line).
const MAX_LINE: usize = 65_536;

/// How long the accept loop sleeps when no client is waiting.
const ACCEPT_POLL: Duration = Duration::from_millis(5);

/// Builds the cyclic server on the reference model of `family` (`model`: matched forgivingly;
/// `brake`: the PSx3xx brake option, PSx3xx manual 5.11–5.13) and hands it to `f` with one
/// line naming it (family, model and brake) for banners.
pub fn with_cyclic_server<R>(
    spec: &Spec,
    family: FamilyId,
    model: Option<&str>,
    brake: Option<reference::BrakeKind>,
    f: impl FnOnce(&mut Server<'_>, &str) -> R,
) -> Result<R, ServeError> {
    if let (Some(b), false) = (brake, family == FamilyId::Psx3xx) {
        return Err(ServeError::Usage(format!(
            "a {} brake is an option of the psx3xx drives, not of {family}",
            b.spec_name()
        )));
    }
    match family {
        FamilyId::Psd4xx => {
            let r = reference::psd4xx(spec, model)?;
            let name = format!("psd4xx reference {}", r.model.id);
            Ok(f(&mut r.server(family), &name))
        }
        FamilyId::Psx3xx => {
            let r = reference::psx3xx(spec, model, brake)?;
            let name = match brake {
                Some(b) => format!(
                    "psx3xx reference {} with a {} brake",
                    r.model.id,
                    b.spec_name()
                ),
                None => format!("psx3xx reference {}", r.model.id),
            };
            Ok(f(&mut r.server(family), &name))
        }
        other => Err(ServeError::NotAvailable { family: other }),
    }
}

/// What the serving loop shares between the request reader and the reply writer.
struct Line<'p, 'l> {
    port: &'p mut dyn Port,
    dice: Dice,
    clock: &'p WallClock,
    deadline: Option<Micros>,
    stop: &'p Stop,
    stopped: bool,
    log_on: bool,
    log: &'l mut dyn Write,
    stats: &'p mut Stats,
    /// Reply bytes written but not yet ended by `\n`.
    pending: Vec<u8>,
    /// Request bytes read since the last `\n`.
    partial: usize,
}

impl Line<'_, '_> {
    fn should_stop(&self) -> bool {
        self.stop.is_stopped() || self.deadline.is_some_and(|d| self.clock.now() >= d)
    }

    fn note(&mut self, text: &str) {
        let t = self.clock.now();
        let _ = writeln!(self.log, "{} {text}", stamp(t));
    }

    /// Reads request bytes, waiting in slices of 20 ms; 0 at the end (client gone, stop).
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        loop {
            if self.should_stop() {
                self.stopped = true;
                return Ok(0);
            }
            let mut wait = MAX_WAIT;
            if let Some(d) = self.deadline {
                wait = wait.min(Duration::from_micros(d.saturating_sub(self.clock.now())));
            }
            match self.port.read(buf, wait) {
                Ok(Got::Bytes(n)) => {
                    let got = buf.get(..n).unwrap_or(&[]);
                    self.partial = match got.iter().rposition(|b| *b == b'\n') {
                        Some(i) => n.saturating_sub(i).saturating_sub(1),
                        None => self.partial.saturating_add(n),
                    };
                    if self.partial > MAX_LINE {
                        // A client that never ends its line is dropped, not buffered.
                        return Err(std::io::Error::new(
                            ErrorKind::InvalidData,
                            format!("request line longer than {MAX_LINE} bytes"),
                        ));
                    }
                    self.stats.received = self.stats.received.saturating_add(n as u64);
                    if self.log_on {
                        let text = String::from_utf8_lossy(buf.get(..n).unwrap_or(&[]))
                            .trim_end()
                            .to_owned();
                        self.note(&format!("rx {text}"));
                    }
                    return Ok(n);
                }
                Ok(Got::Idle) => {}
                Ok(Got::Closed) => return Ok(0),
                Err(e) => return Err(std::io::Error::other(e.to_string())),
            }
        }
    }

    /// Takes reply bytes; each complete line goes out with the faults applied.
    fn write(&mut self, bytes: &[u8]) -> std::io::Result<()> {
        self.pending.extend_from_slice(bytes);
        while let Some(pos) = self.pending.iter().position(|b| *b == b'\n') {
            let rest = self.pending.split_off(pos.saturating_add(1));
            let line = std::mem::replace(&mut self.pending, rest);
            self.send(line)?;
        }
        if self.pending.len() > MAX_LINE {
            let mut line = std::mem::take(&mut self.pending);
            line.truncate(MAX_LINE);
            line.push(b'\n');
            self.send(line)?;
        }
        Ok(())
    }

    fn send(&mut self, line: Vec<u8>) -> std::io::Result<()> {
        let text = String::from_utf8_lossy(&line).trim_end().to_owned();
        if self.dice.drop() {
            self.stats.dropped = self.stats.dropped.saturating_add(1);
            if self.log_on {
                self.note(&format!("tx dropped (fault): {text}"));
            }
            return Ok(());
        }
        let mut out = line;
        if let Ok(Reply::In(mut image)) = Reply::parse(&text) {
            if !image.is_empty() && self.dice.corrupt_image() {
                let bit = self.dice.pick(image.len().saturating_mul(8));
                if let Some(b) = image.get_mut(bit / 8) {
                    *b ^= 1 << (bit % 8);
                }
                let bad = format!("IN {}", hex(&image));
                self.stats.corrupted = self.stats.corrupted.saturating_add(1);
                if self.log_on {
                    self.note(&format!(
                        "tx image corrupted (fault): {bad} instead of {text}"
                    ));
                }
                out = format!("{bad}\n").into_bytes();
            }
        }
        let delay = self.dice.delay();
        if delay > 0 {
            std::thread::sleep(Duration::from_micros(delay));
        }
        match self.port.write(&out) {
            Ok(true) => {
                self.stats.sent = self.stats.sent.saturating_add(1);
                if self.log_on {
                    let shown = String::from_utf8_lossy(&out).trim_end().to_owned();
                    self.note(&format!("tx {shown}"));
                }
                Ok(())
            }
            Ok(false) => {
                self.stats.lost = self.stats.lost.saturating_add(1);
                Err(std::io::Error::new(
                    ErrorKind::BrokenPipe,
                    "the client went away",
                ))
            }
            Err(e) => Err(std::io::Error::other(e.to_string())),
        }
    }
}

/// The request side of a [`Line`].
struct Requests<'c, 'p, 'l>(&'c RefCell<Line<'p, 'l>>);

impl Read for Requests<'_, '_, '_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        self.0
            .try_borrow_mut()
            .map_err(|e| std::io::Error::other(e.to_string()))?
            .read(buf)
    }
}

/// The reply side of a [`Line`].
struct Replies<'c, 'p, 'l>(&'c RefCell<Line<'p, 'l>>);

impl Write for Replies<'_, '_, '_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.0
            .try_borrow_mut()
            .map_err(|e| std::io::Error::other(e.to_string()))?
            .write(buf)?;
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Serving state across clients: the clock, the fault dice, the statistics.
struct Serving<'l> {
    clock: WallClock,
    dice: Dice,
    deadline: Option<Micros>,
    log_on: bool,
    log: &'l mut dyn Write,
    stats: Stats,
}

impl<'l> Serving<'l> {
    fn new(opts: &Options, log: &'l mut dyn Write) -> Result<Serving<'l>, ServeError> {
        opts.faults.check()?;
        Ok(Serving {
            clock: WallClock::start(),
            dice: Dice::new(opts.faults),
            deadline: opts
                .time_limit
                .map(|d| u64::try_from(d.as_micros()).unwrap_or(u64::MAX)),
            log_on: opts.log,
            log,
            stats: Stats::default(),
        })
    }

    fn should_stop(&self, stop: &Stop) -> bool {
        stop.is_stopped() || self.deadline.is_some_and(|d| self.clock.now() >= d)
    }

    fn note(&mut self, text: &str) {
        let t = self.clock.now();
        let _ = writeln!(self.log, "{} {text}", stamp(t));
    }

    /// Serves one client on `port` until it goes away, `stop` or the time limit; true when
    /// stopped.
    fn session(&mut self, server: &mut Server<'_>, port: &mut dyn Port, stop: &Stop) -> bool {
        let cell = RefCell::new(Line {
            port,
            dice: self.dice.clone(),
            clock: &self.clock,
            deadline: self.deadline,
            stop,
            stopped: false,
            log_on: self.log_on,
            log: &mut *self.log,
            stats: &mut self.stats,
            pending: Vec::new(),
            partial: 0,
        });
        let result = server.serve(BufReader::new(Requests(&cell)), Replies(&cell));
        let line = cell.into_inner();
        let stopped = line.stopped;
        // The fault decisions go on where this client left them.
        self.dice = line.dice;
        if let Err(e) = result {
            if e.kind() != ErrorKind::BrokenPipe {
                self.note(&format!("client dropped: {e}"));
            }
        }
        stopped
    }

    fn finish(mut self) -> Stats {
        self.stats.wall_us = self.clock.now();
        let _ = self.log.flush();
        self.stats
    }
}

/// Serves `server` to the clients of `listener`, one at a time, keeping the device's state
/// across them (a client starts with `HELLO` and `RESET`), until stopped.
pub fn serve_cyclic_tcp(
    listener: TcpListener,
    server: &mut Server<'_>,
    opts: &Options,
    stop: &Stop,
    log: &mut dyn Write,
) -> Result<Stats, ServeError> {
    let mut serving = Serving::new(opts, log)?;
    listener.set_nonblocking(true).map_err(|e| ServeError::Io {
        what: "listening socket",
        reason: e.to_string(),
    })?;
    loop {
        if serving.should_stop(stop) || opts.max_clients.is_some_and(|m| serving.stats.clients >= m)
        {
            return Ok(serving.finish());
        }
        match listener.accept() {
            Ok((stream, peer)) => {
                serving.stats.clients = serving.stats.clients.saturating_add(1);
                serving.note(&format!("client {peer} connected"));
                let mut port = match TcpPort::new(stream) {
                    Ok(p) => p,
                    Err(e) => {
                        serving.note(&format!("client {peer} dropped: {e}"));
                        continue;
                    }
                };
                let stopped = serving.session(server, &mut port, stop);
                serving.note(&if stopped {
                    format!("stopped while client {peer} was connected")
                } else {
                    format!("client {peer} disconnected")
                });
            }
            Err(e) if e.kind() == ErrorKind::WouldBlock => std::thread::sleep(ACCEPT_POLL),
            Err(e) => {
                serving.note(&format!("accept: {e}"));
                std::thread::sleep(ACCEPT_POLL);
            }
        }
    }
}

/// Serves `server` on the pseudo-terminal `pty` (line protocol on the terminal) until stopped.
#[cfg(unix)]
pub fn serve_cyclic_pty(
    pty: &drivespec_link::Pty,
    server: &mut Server<'_>,
    opts: &Options,
    stop: &Stop,
    log: &mut dyn Write,
) -> Result<Stats, ServeError> {
    let mut serving = Serving::new(opts, log)?;
    let mut port = pty.port()?;
    // The pseudo-terminal never closes (the slave is held open): serve until stopped.
    while !serving.session(server, &mut port, stop) && !serving.should_stop(stop) {}
    Ok(serving.finish())
}

/// Serves `server` with requests from `input` (read on a thread) and replies to `output`,
/// until `input` ends or stopped.
pub fn serve_cyclic_stream<R: Read + Send + 'static>(
    input: R,
    output: &mut dyn Write,
    server: &mut Server<'_>,
    opts: &Options,
    stop: &Stop,
    log: &mut dyn Write,
) -> Result<Stats, ServeError> {
    let mut serving = Serving::new(opts, log)?;
    let mut port = StreamPort::new(input, output);
    serving.session(server, &mut port, stop);
    Ok(serving.finish())
}

/// Serves `server` on stdin and stdout until stdin ends: an `exec:` device under test.
pub fn serve_cyclic_stdio(
    server: &mut Server<'_>,
    opts: &Options,
    stop: &Stop,
    log: &mut dyn Write,
) -> Result<Stats, ServeError> {
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    serve_cyclic_stream(std::io::stdin(), &mut out, server, opts, stop, log)
}

/// A time on the serving clock for the log: seconds with µs.
fn stamp(t: Micros) -> String {
    format!("{:>4}.{:06}", t / 1_000_000, t % 1_000_000)
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]
    use super::*;
    use crate::Faults;

    fn run(input: &str, faults: Faults) -> (Vec<String>, Stats) {
        let spec = Spec::builtin().unwrap();
        let opts = Options {
            faults,
            ..Options::default()
        };
        let mut out: Vec<u8> = Vec::new();
        let stats = with_cyclic_server(&spec, FamilyId::Psd4xx, None, None, |server, _| {
            serve_cyclic_stream(
                std::io::Cursor::new(input.as_bytes().to_vec()),
                &mut out,
                server,
                &opts,
                &Stop::new(),
                &mut std::io::sink(),
            )
        })
        .unwrap()
        .unwrap();
        let text = String::from_utf8(out).unwrap();
        (text.lines().map(str::to_owned).collect(), stats)
    }

    const EXCHANGE: &str = "HELLO drivespec-cyclic 1 psd4xx PSD401-5V\nRESET\nCYCLE 10000 0000000000000000000000000000\nCYCLE 20000 0000000000000000000000000000\n";

    #[test]
    fn answers_hello_reset_and_cycles() {
        let (lines, stats) = run(EXCHANGE, Faults::default());
        assert_eq!(lines.len(), 4, "{lines:?}");
        assert!(
            lines[0].starts_with("HELLO drivespec-cyclic 1 "),
            "{lines:?}"
        );
        assert_eq!(lines[1], "OK");
        assert!(lines[2].starts_with("IN "), "{lines:?}");
        assert_eq!(stats.sent, 4);
        assert_eq!(stats.received, EXCHANGE.len() as u64);
    }

    #[test]
    fn an_endless_request_line_ends_the_session() {
        let mut input = "RESET\n".to_owned();
        input.push_str(&"0".repeat(3 * MAX_LINE));
        input.push_str("\nRESET\n");
        let (lines, _) = run(&input, Faults::default());
        assert_eq!(lines, ["OK"]);
    }

    #[test]
    fn faults_drop_and_corrupt_replies() {
        let (clean, _) = run(EXCHANGE, Faults::default());
        let (dropped, stats) = run(
            EXCHANGE,
            Faults {
                drop_answers: 1.0,
                ..Faults::default()
            },
        );
        assert!(dropped.is_empty());
        assert_eq!(stats.dropped, 4);
        let (bad, stats) = run(
            EXCHANGE,
            Faults {
                corrupt_images: 1.0,
                ..Faults::default()
            },
        );
        assert_eq!(stats.corrupted, 2);
        assert_eq!(bad[..2], clean[..2]);
        for (b, c) in bad[2..].iter().zip(&clean[2..]) {
            assert_ne!(b, c);
            assert_eq!(b.len(), c.len());
            let (Ok(Reply::In(x)), Ok(Reply::In(y))) = (Reply::parse(b), Reply::parse(c)) else {
                panic!("{b} {c}");
            };
            let flipped: u32 = x.iter().zip(&y).map(|(p, q)| (p ^ q).count_ones()).sum();
            assert_eq!(flipped, 1);
        }
    }

    #[test]
    fn psx3xx_is_served_and_others_and_unknown_models_are_refused() {
        let spec = Spec::builtin().unwrap();
        let hello = with_cyclic_server(&spec, FamilyId::Psx3xx, None, None, |server, name| {
            (
                server.handle_line("HELLO drivespec-cyclic 1 psx3xx x"),
                name.to_owned(),
            )
        })
        .unwrap();
        assert!(
            hello.0.starts_with("HELLO drivespec-cyclic 1 "),
            "{hello:?}"
        );
        assert!(hello.1.starts_with("psx3xx reference "), "{hello:?}");
        assert!(matches!(
            with_cyclic_server(&spec, FamilyId::Hpd, None, None, |_, _| ()),
            Err(ServeError::NotAvailable { .. })
        ));
        assert!(matches!(
            with_cyclic_server(
                &spec,
                FamilyId::Psd4xx,
                Some("no such model"),
                None,
                |_, _| ()
            ),
            Err(ServeError::Usage(_))
        ));
    }

    #[test]
    fn a_psx3xx_brake_is_served_on_the_models_that_may_have_it_and_refused_elsewhere() {
        use crate::reference::BrakeKind;
        let spec = Spec::builtin().unwrap();
        let snap = Some(BrakeKind::Snap);
        let name = with_cyclic_server(&spec, FamilyId::Psx3xx, Some("PSE312-14"), snap, |_, n| {
            n.to_owned()
        })
        .unwrap();
        assert_eq!(name, "psx3xx reference PSE312-14 with a snap brake");
        let refused =
            with_cyclic_server(&spec, FamilyId::Psx3xx, Some("PSE312-8"), snap, |_, _| ());
        match refused {
            Err(ServeError::Usage(text)) => {
                assert!(text.contains("PSE312-8 cannot have a snap brake"), "{text}");
                assert!(text.contains("PSx31x-14"), "{text}");
            }
            other => panic!("{other:?}"),
        }
        assert!(matches!(
            with_cyclic_server(&spec, FamilyId::Psd4xx, None, snap, |_, _| ()),
            Err(ServeError::Usage(_))
        ));
    }
}
