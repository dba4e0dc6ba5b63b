//! Byte-stream transports with time-outs: all the operating-system I/O of drivespec.
//!
//! - [`Link`]: the runner's side of a device under test, one trait for a serial port
//!   ([`SerialLink`]), a TCP byte stream ([`TcpLink`]) and a subprocess on stdin/stdout
//!   ([`ExecLink`]); an in-process model implements it too (`drivespec-sim`).
//! - [`port`]: the served side, one client's byte stream ([`port::Port`]): a TCP client, a
//!   reader and writer pair, or the master of a pseudo-terminal ([`Pty`], Unix).
//!
//! Every call is bounded in time: `recv` returns at its deadline whatever came, writes time
//! out, and nothing waits on a peer without a limit. A peer that misbehaves (garbage, partial
//! frames, a closed connection, a process that hangs or dies) gives an error or unexpected
//! bytes, never a hang or a panic; `recover` reconnects or restarts it.
//!
//! Time: each link has a clock in µs from when it was opened. The links here use the
//! monotonic wall clock ([`WallClock`]); an in-process model's clock is virtual and only moves
//! when the runner waits.
//!
//! Nothing here panics. Memory is bounded whatever a peer sends: one `recv` returns at most
//! [`MAX_RECV`] bytes, a subprocess's output is read ahead in a bounded queue, and every buffer
//! a peer fills is read in bounded slices.
#![forbid(unsafe_code)]

mod exec;
pub mod port;
#[cfg(unix)]
mod pty;
mod quote;
mod serial;
mod tcp;

pub use exec::ExecLink;
pub use port::PortError;
#[cfg(unix)]
pub use pty::{Pty, PtyPort};
pub use quote::shell_quote;
pub use serial::SerialLink;
pub use tcp::TcpLink;

/// Time in µs on a link's clock.
pub type Micros = u64;

/// Most bytes one [`Link::recv`] returns: a device flooding the line is judged on what fits,
/// and memory stays bounded whatever it sends.
pub const MAX_RECV: usize = 64 * 1024;

/// Why a transport operation failed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum LinkError {
    /// The transport could not be opened.
    #[error("cannot open {what}: {reason}")]
    Open {
        /// The transport.
        what: String,
        /// Why.
        reason: String,
    },
    /// The peer closed the connection.
    #[error("the device under test closed the connection{detail}")]
    Closed {
        /// More about it (exit status, stderr tail), starting with a separator.
        detail: String,
    },
    /// Reading or writing failed.
    #[error("i/o error: {0}")]
    Io(String),
}

impl LinkError {
    pub(crate) fn io(e: &std::io::Error) -> LinkError {
        LinkError::Io(e.to_string())
    }
}

/// Bytes that arrived together, with the time the first of them came.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Chunk {
    /// Arrival time on the link's clock.
    pub at: Micros,
    /// The bytes.
    pub bytes: Vec<u8>,
}

/// What a link can do besides moving bytes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Caps {
    /// `reset` gives a device in its start state, cheaply (the simulator).
    pub reset: bool,
    /// `power_cycle` switches the device off and on (the simulator).
    pub power_cycle: bool,
    /// The clock is virtual: waiting costs nothing.
    pub virtual_time: bool,
    /// `set_inputs` drives the device's digital inputs (the simulator, manual 3.8.1 b90).
    pub inputs: bool,
}

/// What `recover` did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Recovered {
    /// A fresh device in its start state (a restarted process).
    Fresh,
    /// The same device, state unknown (a reconnected socket or reopened port).
    Same,
}

/// A byte stream to the device under test, with time-outs.
pub trait Link: Send {
    /// What the link is connected to, one line (for reports).
    fn describe(&self) -> String;

    /// What the link can do besides moving bytes.
    fn caps(&self) -> Caps;

    /// The link's clock (µs since it was opened).
    fn now(&mut self) -> Micros;

    /// Sends bytes; returns once they are handed to the transport (bounded).
    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError>;

    /// Receives until `deadline`, or until `enough` says the bytes so far suffice.
    fn recv(
        &mut self,
        deadline: Micros,
        enough: &mut dyn FnMut(&[u8]) -> bool,
    ) -> Result<Vec<Chunk>, LinkError>;

    /// Switches the line to `bps` bits per second (serial ports; a no-op elsewhere).
    fn set_bit_rate(&mut self, bps: u32) -> Result<(), LinkError> {
        let _ = bps;
        Ok(())
    }

    /// A device in its start state, when `caps().reset`; false when not supported.
    fn reset(&mut self) -> Result<bool, LinkError> {
        Ok(false)
    }

    /// Switches the device off and on, when `caps().power_cycle`; false when not supported.
    fn power_cycle(&mut self) -> Result<bool, LinkError> {
        Ok(false)
    }

    /// Sets the device's digital inputs (bit i = input i, manual 3.8.1 b90), when
    /// `caps().inputs`; false when not supported.
    fn set_inputs(&mut self, inputs: u16) -> Result<bool, LinkError> {
        let _ = inputs;
        Ok(false)
    }

    /// Reconnects or restarts after an error.
    fn recover(&mut self) -> Result<Recovered, LinkError>;
}

/// Collects chunks into one byte vector.
pub fn concat(chunks: &[Chunk]) -> Vec<u8> {
    chunks
        .iter()
        .flat_map(|c| c.bytes.iter().copied())
        .collect()
}

/// A monotonic clock in µs from its creation.
#[derive(Debug, Clone, Copy)]
pub struct WallClock(std::time::Instant);

impl WallClock {
    /// A clock at 0 now.
    pub fn start() -> WallClock {
        WallClock(std::time::Instant::now())
    }

    /// µs since [`WallClock::start`].
    pub fn now(&self) -> Micros {
        u64::try_from(self.0.elapsed().as_micros()).unwrap_or(u64::MAX)
    }

    /// Time left until `deadline`, None when it has passed.
    pub(crate) fn until(&self, deadline: Micros) -> Option<std::time::Duration> {
        let now = self.now();
        (deadline > now).then(|| std::time::Duration::from_micros(deadline - now))
    }
}
