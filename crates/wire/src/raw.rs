//! A raw Ethernet socket (AF_PACKET, all protocols) on one interface: send whole frames,
//! receive whole frames with the time they were read.

use crate::{Filter, WireError};
use pnet_datalink::{Channel, Config, DataLinkReceiver, DataLinkSender, NetworkInterface};
use std::io;
use std::net::Ipv4Addr;
use std::os::fd::IntoRawFd;
use std::time::{Duration, Instant, SystemTime};

/// Least frame length sent: an Ethernet II header (IEEE 802.3 3.1.1, without FCS).
pub const MIN_FRAME: usize = 14;

/// Greatest frame length sent: 1,500 payload bytes, an Ethernet II header and one 802.1Q tag
/// (IEEE 802.1Q 9.6), without FCS.
pub const MAX_FRAME: usize = 1518;

/// Most frames [`RawSocket::wait_frames`] hands on in one call.
pub const MAX_BATCH: usize = 64;

/// How long one wait for a frame lasts before the deadline of [`RawSocket::recv`] is looked
/// at again. A choice: a frame is returned as soon as it arrives, so this bounds only how late
/// a receive with no frame returns (at most this past its timeout) against the wake-ups of an
/// idle socket (100 a second).
const DEFAULT_POLL: Duration = Duration::from_millis(10);

/// Receive buffer asked of the kernel (SO_RCVBUF; it grants at most `net.core.rmem_max`).
/// A choice: 4 MiB holds several seconds of a 1 ms PROFINET exchange, so a receiver that the
/// scheduler starves for a while loses no frame; the kernel's default (about 200 KiB) holds
/// about a quarter of a second of it.
const DEFAULT_RECV_BUFFER: usize = 4 << 20;

/// ETH_P_ALL (linux/if_ether.h): every protocol, in network byte order as `socket(2)` wants.
const ETH_P_ALL: u16 = 0x0003;

/// A network interface of the caller's network namespace.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Interface {
    /// Its name (`eth0`, `veth0`).
    pub name: String,
    /// Its kernel index.
    pub index: u32,
    /// Its MAC address, if it has one.
    pub mac: Option<[u8; 6]>,
    /// Its IPv4 addresses.
    pub ipv4: Vec<Ipv4Addr>,
}

impl Interface {
    /// The interface named `name`, or [`WireError::NoSuchInterface`] naming those present.
    pub fn by_name(name: &str) -> Result<Self, WireError> {
        Ok(Self::from_pnet(&find(name)?))
    }

    fn from_pnet(i: &NetworkInterface) -> Self {
        Self {
            name: i.name.clone(),
            index: i.index,
            mac: i.mac.map(|m| m.octets()),
            ipv4: i
                .ips
                .iter()
                .filter_map(|ip| match ip.ip() {
                    std::net::IpAddr::V4(v4) => Some(v4),
                    std::net::IpAddr::V6(_) => None,
                })
                .collect(),
        }
    }
}

fn find(name: &str) -> Result<NetworkInterface, WireError> {
    let all = pnet_datalink::interfaces();
    match all.iter().find(|i| i.name == name) {
        Some(i) => Ok(i.clone()),
        None => Err(WireError::NoSuchInterface {
            name: name.to_owned(),
            present: all
                .iter()
                .map(|i| i.name.as_str())
                .collect::<Vec<_>>()
                .join(", "),
        }),
    }
}

/// How a [`RawSocket`] is opened.
#[derive(Debug, Clone)]
pub struct OpenOptions {
    /// Which received frames are returned (default: all).
    pub filter: Filter,
    /// Whether the interface is put in promiscuous mode (default: yes, as a mirror port needs).
    pub promiscuous: bool,
    /// Longest single wait inside [`RawSocket::recv`] (default 10 ms).
    pub poll: Duration,
    /// Kernel receive buffer asked for, in bytes (default 4 MiB; capped by the kernel at
    /// `net.core.rmem_max`).
    pub recv_buffer: usize,
}

impl Default for OpenOptions {
    fn default() -> Self {
        Self {
            filter: Filter::all(),
            promiscuous: true,
            poll: DEFAULT_POLL,
            recv_buffer: DEFAULT_RECV_BUFFER,
        }
    }
}

/// A frame received, with the time it was read from the socket.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Received {
    /// The whole frame from the destination address on, without FCS.
    pub frame: Vec<u8>,
    /// Wall-clock time it was read (for recordings and for comparing with another process).
    pub at: SystemTime,
    /// Monotonic time it was read (for intervals within this process).
    pub instant: Instant,
}

/// A raw Ethernet socket bound to one interface.
pub struct RawSocket {
    interface: Interface,
    tx: Box<dyn DataLinkSender>,
    rx: Box<dyn DataLinkReceiver>,
    filter: Filter,
}

impl std::fmt::Debug for RawSocket {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RawSocket")
            .field("interface", &self.interface)
            .field("filter", &self.filter)
            .finish_non_exhaustive()
    }
}

impl RawSocket {
    /// Opens interface `name` with `options`.
    pub fn open(name: &str, options: OpenOptions) -> Result<Self, WireError> {
        let pnet = find(name)?;
        let socket = socket2::Socket::new(
            socket2::Domain::PACKET,
            socket2::Type::RAW,
            Some(socket2::Protocol::from(i32::from(ETH_P_ALL.to_be()))),
        )
        .map_err(|e| WireError::io(name, "open", e))?;
        socket
            .set_recv_buffer_size(options.recv_buffer)
            .map_err(|e| WireError::io(name, "open", e))?;
        // pnet binds the socket to the interface and owns (closes) it from here on.
        let config = Config {
            read_timeout: Some(options.poll),
            promiscuous: options.promiscuous,
            socket_fd: Some(socket.into_raw_fd()),
            ..Config::default()
        };
        match pnet_datalink::channel(&pnet, config) {
            Ok(Channel::Ethernet(tx, rx)) => Ok(Self {
                interface: Interface::from_pnet(&pnet),
                tx,
                rx,
                filter: options.filter,
            }),
            Ok(_) => Err(WireError::NotEthernet {
                name: name.to_owned(),
            }),
            Err(e) => Err(WireError::io(name, "open", e)),
        }
    }

    /// The interface this socket is bound to.
    pub fn interface(&self) -> &Interface {
        &self.interface
    }

    /// Sends one whole Ethernet frame (destination address first, no FCS; the kernel does
    /// not pad it).
    pub fn send(&mut self, frame: &[u8]) -> Result<(), WireError> {
        if !(MIN_FRAME..=MAX_FRAME).contains(&frame.len()) {
            return Err(WireError::FrameLength {
                len: frame.len(),
                min: MIN_FRAME,
                max: MAX_FRAME,
            });
        }
        match self.tx.send_to(frame, None) {
            Some(Ok(())) => Ok(()),
            Some(Err(e)) => Err(WireError::io(&self.interface.name, "send", e)),
            None => Err(WireError::io(
                &self.interface.name,
                "send",
                io::Error::other("no send buffer"),
            )),
        }
    }

    /// Hands every frame that passes the filter to `on_frame` as it arrives, until at least
    /// one came or `until` passes; between two looks at the socket it sleeps at most `step`.
    /// Returns the number of frames handed on, at most [`MAX_BATCH`] (a flood of frames
    /// cannot keep the caller from its timers). For pacing finer than a millisecond (a cyclic
    /// exchange), open the socket with a zero [`OpenOptions::poll`]: a look then never blocks,
    /// and a frame waits at most `step` (plus the timer slack of the system) to be handed on.
    pub fn wait_frames(
        &mut self,
        until: Instant,
        step: Duration,
        mut on_frame: impl FnMut(Received),
    ) -> Result<usize, WireError> {
        let mut n = 0usize;
        loop {
            while n < MAX_BATCH {
                let Some(r) = self.recv(Duration::ZERO)? else {
                    break;
                };
                on_frame(r);
                n = n.saturating_add(1);
            }
            let now = Instant::now();
            if n > 0 || now >= until {
                return Ok(n);
            }
            std::thread::sleep(step.min(until.saturating_duration_since(now)));
        }
    }

    /// The next frame that passes the filter, or `None` when `timeout` passes first.
    pub fn recv(&mut self, timeout: Duration) -> Result<Option<Received>, WireError> {
        let deadline = Instant::now().checked_add(timeout);
        loop {
            match self.rx.next() {
                Ok(frame) => {
                    let (at, instant) = (SystemTime::now(), Instant::now());
                    if self.filter.passes(frame) {
                        return Ok(Some(Received {
                            frame: frame.to_vec(),
                            at,
                            instant,
                        }));
                    }
                }
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::TimedOut
                            | io::ErrorKind::WouldBlock
                            | io::ErrorKind::Interrupted
                    ) => {}
                Err(e) => return Err(WireError::io(&self.interface.name, "receive", e)),
            }
            if deadline.is_some_and(|d| Instant::now() >= d) {
                return Ok(None);
            }
        }
    }
}
