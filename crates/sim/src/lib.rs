//! `drivespec sim`: a family's reference model served in real time on a byte stream, so
//! masters and PLC drivers can be developed and tested against it; and the same models
//! in-process on virtual time, as the `sim` device under test of a conformance run.
//!
//! - [`mod@device`]: the served model behind [`ServedDevice`] (HPD's reference [`Drive`]).
//! - PSD4xx and PSx3xx speak the cyclic-exchange protocol instead: [`with_cyclic_server`] and
//!   [`serve_cyclic_tcp`], [`serve_cyclic_stream`], `serve_cyclic_pty` (module `cyclic`), on
//!   the server [`reference`] builds from the spec and the family's model crate.
//! - Transports (from `drivespec-link`): [`serve_tcp`] (one client at a time), [`serve_pty`]
//!   on a [`Pty`] (Unix: a pseudo-terminal whose path any serial library opens) and
//!   [`serve_stream`]/[`serve_stdio`].
//! - [`Faults`]: seeded fault injection for a client's error handling: answers dropped,
//!   checksums corrupted, answers delayed (decisions drawn from [`rng::Rng`]).
//! - [`SimLink`]: a model on virtual time behind [`drivespec_link::Link`], the runner's
//!   `--dut sim` for HPD.
//!
//! Time: the wall clock drives the model's virtual clock at the edge. A byte read at wall
//! time `t` (µs since serving started) is handed to the model at `t`; the model is advanced to
//! the wall clock whenever it asks ([`ServedDevice::poll_timeout`]) and each answer is written
//! when the wall clock reaches its time (the Pr26 = 4 answer delay, plus `--delay-ms`). A wait
//! never exceeds 20 ms, so a [`Stop`] or the time limit takes effect within that.
//!
//! On a pseudo-terminal the bit rate the client set is checked against the drive's (Pr26 in
//! force): bytes sent at another rate are refused, as a real line would garble them.
//!
//! Nothing here panics; memory is bounded by the model, the answers waiting for their time
//! and one request line (64 KiB) per client.
//!
//! [`Drive`]: drivespec_hpd::model::Drive
#![forbid(unsafe_code)]

mod cyclic;
pub mod device;
mod engine;
mod faults;
mod link;
pub mod reference;
pub mod rng;

#[cfg(unix)]
pub use cyclic::serve_cyclic_pty;
pub use cyclic::{serve_cyclic_stdio, serve_cyclic_stream, serve_cyclic_tcp, with_cyclic_server};
pub use device::{device, DeviceOptions, Emitted, HpdDevice, ServedDevice};
pub use engine::{Options, Stats, Stop};
pub use faults::Faults;
pub use link::{SimDevice, SimLink};

#[cfg(unix)]
pub use drivespec_link::Pty;
use drivespec_link::{port::StreamPort, port::TcpPort, PortError};
use drivespec_spec::FamilyId;
use engine::{End, Engine};
use std::io::{Read, Write};
use std::net::TcpListener;
use std::time::Duration;

/// Why a model cannot be served.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ServeError {
    /// The family has no model to serve yet.
    #[error("serving {family} is not available yet: its reference model has no server")]
    NotAvailable {
        /// The family asked for.
        family: FamilyId,
    },
    /// The options do not fit the device (unknown model, address, baud-rate code, fault rate).
    #[error("{0}")]
    Usage(String),
    /// The model cannot be built from the spec.
    #[error("the reference model cannot be built: {0}")]
    Model(String),
    /// The transport cannot be set up.
    #[error("cannot open {what}: {reason}")]
    Open {
        /// The transport.
        what: String,
        /// Why.
        reason: String,
    },
    /// Reading or writing failed for good.
    #[error("{what}: {reason}")]
    Io {
        /// What was being done.
        what: &'static str,
        /// The error.
        reason: String,
    },
}

impl From<reference::ReferenceError> for ServeError {
    fn from(e: reference::ReferenceError) -> ServeError {
        match e {
            reference::ReferenceError::UnknownModel { .. }
            | reference::ReferenceError::NoSuchBrake { .. } => ServeError::Usage(e.to_string()),
            other => ServeError::Model(other.to_string()),
        }
    }
}

impl From<PortError> for ServeError {
    fn from(e: PortError) -> ServeError {
        match e {
            PortError::Open { what, reason } => ServeError::Open { what, reason },
            PortError::Io { what, reason } => ServeError::Io { what, reason },
            // A kind of failure added later: its text, as an i/o failure of the port.
            other => ServeError::Io {
                what: "port",
                reason: other.to_string(),
            },
        }
    }
}

/// How long the accept loop sleeps when no client is waiting.
const ACCEPT_POLL: Duration = Duration::from_millis(5);

/// Serves `device` to the clients of `listener`, one at a time, keeping its state, until stopped.
pub fn serve_tcp(
    listener: TcpListener,
    device: Box<dyn ServedDevice>,
    opts: &Options,
    stop: &Stop,
    log: &mut dyn Write,
) -> Result<Stats, ServeError> {
    opts.faults.check()?;
    listener.set_nonblocking(true).map_err(|e| ServeError::Io {
        what: "listening socket",
        reason: e.to_string(),
    })?;
    let mut engine = Engine::new(device, opts, log);
    loop {
        if engine.should_stop(stop) || opts.max_clients.is_some_and(|m| engine.clients() >= m) {
            return Ok(engine.finish());
        }
        match listener.accept() {
            Ok((stream, peer)) => {
                engine.client();
                engine.note(&format!("client {peer} connected"));
                let mut port = match TcpPort::new(stream) {
                    Ok(p) => p,
                    Err(e) => {
                        engine.note(&format!("client {peer} dropped: {e}"));
                        continue;
                    }
                };
                let end = engine.session(&mut port, stop)?;
                engine.note(&match end {
                    End::Closed => format!("client {peer} disconnected"),
                    End::Stopped => format!("stopped while client {peer} was connected"),
                });
            }
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                std::thread::sleep(ACCEPT_POLL);
            }
            // A connection that failed before it was accepted: wait for the next one.
            Err(e) => {
                engine.note(&format!("accept: {e}"));
                std::thread::sleep(ACCEPT_POLL);
            }
        }
    }
}

/// Serves `device` on the pseudo-terminal `pty` (clients may come and go) until stopped.
#[cfg(unix)]
pub fn serve_pty(
    pty: &Pty,
    device: Box<dyn ServedDevice>,
    opts: &Options,
    stop: &Stop,
    log: &mut dyn Write,
) -> Result<Stats, ServeError> {
    opts.faults.check()?;
    let mut engine = Engine::new(device, opts, log);
    let mut port = pty.port()?;
    engine.session(&mut port, stop)?;
    Ok(engine.finish())
}

/// Serves `device` with requests from `input` (read on a thread) and answers to `output`.
pub fn serve_stream<R: Read + Send + 'static>(
    input: R,
    output: &mut dyn Write,
    device: Box<dyn ServedDevice>,
    opts: &Options,
    stop: &Stop,
    log: &mut dyn Write,
) -> Result<Stats, ServeError> {
    opts.faults.check()?;
    let mut engine = Engine::new(device, opts, log);
    let mut port = StreamPort::new(input, output);
    engine.session(&mut port, stop)?;
    Ok(engine.finish())
}

/// Serves `device` on stdin and stdout until stdin ends: an `exec:` device under test.
pub fn serve_stdio(
    device: Box<dyn ServedDevice>,
    opts: &Options,
    stop: &Stop,
    log: &mut dyn Write,
) -> Result<Stats, ServeError> {
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    serve_stream(std::io::stdin(), &mut out, device, opts, stop, log)
}
