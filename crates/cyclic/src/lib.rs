//! The cyclic-exchange protocol `drivespec-cyclic/1` between the runner and a PSD4xx or PSx3xx
//! simulator or hardware-in-the-loop adapter (README "Protocol").
//!
//! One request line in, one reply line out, ASCII, `\n`-terminated, over any
//! [`drivespec_link::Link`] (tcp, exec, serial). The crate does no I/O of its own: lines are
//! parsed and printed, a [`Server`] answers lines read from any [`std::io::BufRead`], and a
//! [`LinkPeer`] moves them over a link it is given. Every request that acts on the device carries the
//! virtual time in µs since the last `RESET`, so a run is deterministic on any transport.
//!
//! - [`wire`]: the request and reply lines, parsed and printed.
//! - [`server`]: the device side for the built-in reference models (and test wrappers).
//! - [`peer`]: the runner side: in-process (`sim`) or over a link.
//!
//! Nothing here panics on any line; every wait on a remote peer is bounded, a reply line is
//! taken up to 4 KiB, and one request moves the model's clock by at most
//! [`server::MAX_STEP_US`].
#![forbid(unsafe_code)]

pub mod peer;
pub mod server;
pub mod wire;

pub use peer::{LinkPeer, LocalPeer, Peer, PeerError};
pub use server::{CyclicDevice, Server};
pub use wire::{Env, Reply, Request, WireError, VERSION};
