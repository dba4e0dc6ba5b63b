//! The runner side of `drivespec-cyclic/1`: a [`Peer`] sends one request and waits for one
//! reply, in-process ([`LocalPeer`], `--dut sim`) or over a [`Link`] ([`LinkPeer`]: tcp, exec,
//! serial). Both go through the same request and reply lines.

use super::server::Server;
use super::wire::{Reply, Request};
use drivespec_link::{Link, LinkError, Micros};

/// Why a request got no usable reply (a closed set: the fuzzer classifies every kind).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PeerError {
    /// The transport failed.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// No complete line came before the deadline.
    #[error("no reply within {ms} ms to {request:?} (got {partial:?})")]
    Timeout {
        /// The request.
        request: String,
        /// The wait (ms).
        ms: u64,
        /// What came, if anything.
        partial: String,
    },
    /// A line came that is no reply.
    #[error("bad reply to {request:?}: {why}")]
    Garbage {
        /// The request.
        request: String,
        /// What is wrong.
        why: String,
    },
}

/// One end of the cyclic exchange.
pub trait Peer: Send {
    /// What the peer is, one line.
    fn describe(&self) -> String;
    /// Sends one request and returns the reply (bounded in time).
    fn call(&mut self, req: &Request) -> Result<Reply, PeerError>;
    /// Reconnects or restarts after an error.
    fn recover(&mut self) -> Result<(), PeerError>;
    /// When the input image of the last `CYCLE` was taken, µs on the request's clock, where
    /// that is not the request's own time (a device on real time); `None` where it is.
    fn taken_at(&self) -> Option<u64> {
        None
    }
}

/// The device side in the same process: lines go straight to a [`Server`].
pub struct LocalPeer<'s> {
    name: String,
    server: Server<'s>,
}

impl<'s> LocalPeer<'s> {
    /// A peer on `server`, described as `name`.
    pub fn new(name: &str, server: Server<'s>) -> LocalPeer<'s> {
        LocalPeer {
            name: name.to_owned(),
            server,
        }
    }
}

impl Peer for LocalPeer<'_> {
    fn describe(&self) -> String {
        self.name.clone()
    }

    fn call(&mut self, req: &Request) -> Result<Reply, PeerError> {
        let line = self.server.handle_line(&req.to_string());
        Reply::parse(&line).map_err(|e| PeerError::Garbage {
            request: req.to_string(),
            why: e.to_string(),
        })
    }

    fn recover(&mut self) -> Result<(), PeerError> {
        Ok(())
    }
}

/// The device side at the other end of a [`Link`].
pub struct LinkPeer {
    link: Box<dyn Link>,
    buf: Vec<u8>,
    timeout_us: Micros,
}

/// Longest reply line accepted.
const MAX_LINE: usize = 4096;

/// Longest wait for the answer to `HELLO`, µs: a device process may take this long to start
/// on a loaded machine.
const START_US: Micros = 15_000_000;

impl LinkPeer {
    /// A peer over `link`; each reply is awaited at most `timeout_us`.
    pub fn new(link: Box<dyn Link>, timeout_us: Micros) -> LinkPeer {
        LinkPeer {
            link,
            buf: Vec::new(),
            timeout_us,
        }
    }

    fn take_line(&mut self) -> Option<String> {
        let pos = self.buf.iter().position(|b| *b == b'\n')?;
        let rest = self.buf.split_off(pos.saturating_add(1));
        let line = std::mem::replace(&mut self.buf, rest);
        Some(
            String::from_utf8_lossy(&line)
                .trim_end_matches(['\n', '\r'])
                .to_owned(),
        )
    }
}

impl Peer for LinkPeer {
    fn describe(&self) -> String {
        self.link.describe()
    }

    fn call(&mut self, req: &Request) -> Result<Reply, PeerError> {
        let text = req.to_string();
        // Anything left from an earlier, timed-out request is stale.
        self.buf.clear();
        let mut line = text.clone().into_bytes();
        line.push(b'\n');
        self.link.send(&line)?;
        let timeout_us = match req {
            Request::Hello { .. } => self.timeout_us.max(START_US),
            _ => self.timeout_us,
        };
        let deadline = self.link.now().saturating_add(timeout_us);
        loop {
            if let Some(l) = self.take_line() {
                return Reply::parse(&l).map_err(|e| PeerError::Garbage {
                    request: text,
                    why: e.to_string(),
                });
            }
            if self.buf.len() > MAX_LINE {
                return Err(PeerError::Garbage {
                    request: text,
                    why: format!("no line end within {MAX_LINE} bytes"),
                });
            }
            if self.link.now() >= deadline {
                return Err(PeerError::Timeout {
                    request: text,
                    ms: timeout_us / 1000,
                    partial: String::from_utf8_lossy(&self.buf).into_owned(),
                });
            }
            // The line limit holds while reading: a reply without end stops the wait.
            let have = self.buf.len();
            let chunks = self.link.recv(deadline, &mut |b: &[u8]| {
                b.contains(&b'\n') || have.saturating_add(b.len()) > MAX_LINE
            })?;
            for c in chunks {
                self.buf.extend_from_slice(&c.bytes);
            }
        }
    }

    fn recover(&mut self) -> Result<(), PeerError> {
        self.buf.clear();
        self.link.recover()?;
        Ok(())
    }
}
