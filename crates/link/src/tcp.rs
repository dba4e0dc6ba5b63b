//! `tcp:HOST:PORT`: a raw byte stream (ser2net, a simulator, a gateway).

#[cfg(unix)]
use super::serial::TIMER_SLACK;
use super::{Caps, Chunk, Link, LinkError, Micros, Recovered, WallClock};
use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::time::Duration;

/// How long connecting and writing may take.
const IO_LIMIT: Duration = Duration::from_secs(2);

/// A TCP connection to the device under test.
pub struct TcpLink {
    addr: String,
    stream: Option<TcpStream>,
    clock: WallClock,
}

impl TcpLink {
    /// Connects to `addr` (`HOST:PORT`) within two seconds.
    pub fn connect(addr: &str) -> Result<TcpLink, LinkError> {
        let stream = connect(addr)?;
        Ok(TcpLink {
            addr: addr.to_owned(),
            stream: Some(stream),
            clock: WallClock::start(),
        })
    }

    fn stream(&mut self) -> Result<&mut TcpStream, LinkError> {
        self.stream.as_mut().ok_or(LinkError::Closed {
            detail: String::new(),
        })
    }
}

fn connect(addr: &str) -> Result<TcpStream, LinkError> {
    let open = |reason: String| LinkError::Open {
        what: format!("tcp:{addr}"),
        reason,
    };
    let addrs: Vec<SocketAddr> = addr
        .to_socket_addrs()
        .map_err(|e| open(e.to_string()))?
        .collect();
    let mut last = "no address".to_owned();
    for a in addrs {
        match TcpStream::connect_timeout(&a, IO_LIMIT) {
            Ok(s) => {
                s.set_nodelay(true).map_err(|e| open(e.to_string()))?;
                s.set_write_timeout(Some(IO_LIMIT))
                    .map_err(|e| open(e.to_string()))?;
                return Ok(s);
            }
            Err(e) => last = e.to_string(),
        }
    }
    Err(open(last))
}

impl Link for TcpLink {
    fn describe(&self) -> String {
        format!("tcp:{}", self.addr)
    }

    fn caps(&self) -> Caps {
        Caps::default()
    }

    fn now(&mut self) -> Micros {
        self.clock.now()
    }

    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        let s = self.stream()?;
        let r = s.write_all(bytes).and_then(|()| s.flush());
        if let Err(e) = r {
            self.stream = None;
            return Err(LinkError::io(&e));
        }
        Ok(())
    }

    fn recv(
        &mut self,
        deadline: Micros,
        enough: &mut dyn FnMut(&[u8]) -> bool,
    ) -> Result<Vec<Chunk>, LinkError> {
        let clock = self.clock;
        let mut chunks = Vec::new();
        let mut all = Vec::new();
        let mut buf = [0u8; 512];
        while let Some(left) = clock.until(deadline) {
            let s = self.stream()?;
            // SO_RCVTIMEO counts in scheduler ticks (up to 4 ms): on Unix wait in poll, to the
            // µs, and only poll below the timer slack (a check for late bytes).
            #[cfg(unix)]
            {
                let wait = if left < TIMER_SLACK {
                    Duration::ZERO
                } else {
                    left
                };
                let ready = crate::port::readable(&*s, wait, "tcp")
                    .map_err(|e| LinkError::Io(e.to_string()))?;
                if !ready {
                    continue;
                }
            }
            s.set_read_timeout(Some(left.max(Duration::from_micros(50))))
                .map_err(|e| LinkError::io(&e))?;
            match s.read(&mut buf) {
                Ok(0) => {
                    self.stream = None;
                    return Err(LinkError::Closed {
                        detail: format!(" after {} byte(s)", all.len()),
                    });
                }
                Ok(n) => {
                    let bytes = buf.get(..n).unwrap_or(&[]).to_vec();
                    all.extend_from_slice(&bytes);
                    chunks.push(Chunk {
                        at: clock.now(),
                        bytes,
                    });
                    if all.len() >= crate::MAX_RECV || enough(&all) {
                        break;
                    }
                }
                Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => {
                    self.stream = None;
                    return Err(LinkError::io(&e));
                }
            }
        }
        Ok(chunks)
    }

    fn recover(&mut self) -> Result<Recovered, LinkError> {
        self.stream = None;
        self.stream = Some(connect(&self.addr)?);
        Ok(Recovered::Same)
    }
}
