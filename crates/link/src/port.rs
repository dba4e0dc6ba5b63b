//! The byte streams a served device talks on: every read waits at most the time given, every
//! write is bounded.

use std::io::{ErrorKind, Read, Write};
use std::net::TcpStream;
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::time::Duration;

/// Why a port cannot be opened or used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PortError {
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
        /// What was being read or written.
        what: &'static str,
        /// The error.
        reason: String,
    },
}

/// How long a write to a client may take before the client counts as gone.
const WRITE_LIMIT: Duration = Duration::from_secs(2);

/// What a read gave.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Got {
    /// This many bytes, at the start of the buffer.
    Bytes(usize),
    /// Nothing within the wait.
    Idle,
    /// The client went away.
    Closed,
}

/// A byte stream to one client.
pub trait Port {
    /// Waits up to `wait` (may be zero) for bytes.
    fn read(&mut self, buf: &mut [u8], wait: Duration) -> Result<Got, PortError>;
    /// Writes `bytes`; `Ok(false)` when the client went away.
    fn write(&mut self, bytes: &[u8]) -> Result<bool, PortError>;
    /// The bit rate the client set on the line, where the transport has one.
    fn bit_rate(&self) -> Option<u32> {
        None
    }
}

/// Waits up to `wait` for `fd` to have bytes (or an end) to read; false when it has none.
#[cfg(unix)]
pub fn readable(
    fd: impl rustix::fd::AsFd,
    wait: Duration,
    what: &'static str,
) -> Result<bool, PortError> {
    use rustix::event::{poll, PollFd, PollFlags, Timespec};
    let timeout = Timespec {
        tv_sec: i64::try_from(wait.as_secs()).unwrap_or(i64::MAX),
        tv_nsec: i64::from(wait.subsec_nanos()),
    };
    let mut fds = [PollFd::new(&fd, PollFlags::IN)];
    match poll(&mut fds, Some(&timeout)) {
        Ok(n) => Ok(n > 0),
        Err(rustix::io::Errno::INTR) => Ok(false),
        Err(e) => Err(PortError::Io {
            what,
            reason: e.to_string(),
        }),
    }
}

/// A TCP client.
pub struct TcpPort(TcpStream);

impl TcpPort {
    /// A port on an accepted client's stream (blocking, no small-packet delay, writes bounded).
    pub fn new(s: TcpStream) -> std::io::Result<TcpPort> {
        s.set_nonblocking(false)?;
        s.set_nodelay(true)?;
        s.set_write_timeout(Some(WRITE_LIMIT))?;
        // Reads wait in `poll` (µs precision); this only bounds a read after a spurious wake.
        s.set_read_timeout(Some(Duration::from_millis(20)))?;
        Ok(TcpPort(s))
    }
}

impl Port for TcpPort {
    fn read(&mut self, buf: &mut [u8], wait: Duration) -> Result<Got, PortError> {
        #[cfg(unix)]
        if !readable(&self.0, wait, "client socket")? {
            return Ok(Got::Idle);
        }
        #[cfg(not(unix))]
        {
            // A zero read time-out means "block forever" to the OS: never ask for it.
            let wait = wait.max(Duration::from_micros(1));
            if let Err(e) = self.0.set_read_timeout(Some(wait)) {
                return Err(PortError::Io {
                    what: "client socket",
                    reason: e.to_string(),
                });
            }
        }
        match self.0.read(buf) {
            Ok(0) => Ok(Got::Closed),
            Ok(n) => Ok(Got::Bytes(n)),
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
                ) =>
            {
                Ok(Got::Idle)
            }
            // Reset, aborted: the client is gone, the next one may come.
            Err(_) => Ok(Got::Closed),
        }
    }

    fn write(&mut self, bytes: &[u8]) -> Result<bool, PortError> {
        Ok(self
            .0
            .write_all(bytes)
            .and_then(|()| self.0.flush())
            .is_ok())
    }
}

/// A reader (on its own thread, so reads can time out) and a writer.
pub struct StreamPort<'w> {
    from: Receiver<Vec<u8>>,
    /// Bytes received but not yet handed out.
    held: Vec<u8>,
    to: &'w mut dyn Write,
}

impl<'w> StreamPort<'w> {
    /// A port reading `input` on a thread of its own and writing to `to`.
    pub fn new<R: Read + Send + 'static>(input: R, to: &'w mut dyn Write) -> StreamPort<'w> {
        let (tx, from) = mpsc::channel();
        std::thread::spawn(move || {
            let mut input = input;
            let mut buf = [0u8; 512];
            loop {
                match input.read(&mut buf) {
                    Ok(0) => break,
                    Ok(n) => {
                        if tx.send(buf.get(..n).unwrap_or(&[]).to_vec()).is_err() {
                            break;
                        }
                    }
                    Err(e) if e.kind() == ErrorKind::Interrupted => {}
                    Err(_) => break,
                }
            }
        });
        StreamPort {
            from,
            held: Vec::new(),
            to,
        }
    }
}

impl Port for StreamPort<'_> {
    fn read(&mut self, buf: &mut [u8], wait: Duration) -> Result<Got, PortError> {
        if self.held.is_empty() {
            match self.from.recv_timeout(wait) {
                Ok(bytes) => self.held = bytes,
                Err(RecvTimeoutError::Timeout) => return Ok(Got::Idle),
                Err(RecvTimeoutError::Disconnected) => return Ok(Got::Closed),
            }
        }
        let n = self.held.len().min(buf.len());
        for (dst, src) in buf.iter_mut().zip(self.held.drain(..n)) {
            *dst = src;
        }
        Ok(Got::Bytes(n))
    }

    fn write(&mut self, bytes: &[u8]) -> Result<bool, PortError> {
        Ok(self
            .to
            .write_all(bytes)
            .and_then(|()| self.to.flush())
            .is_ok())
    }
}
