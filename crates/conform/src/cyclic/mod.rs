//! The cyclic-exchange protocol `drivespec-cyclic/1` between the runner and a PSD4xx or PSx3xx
//! simulator or hardware-in-the-loop adapter (README "Cyclic-exchange protocol").
//!
//! One request line in, one reply line out, ASCII, `\n`-terminated, over any
//! [`crate::link::Link`] (tcp, exec, serial). Every request that acts on the device carries the
//! virtual time in µs since the last `RESET`, so a run is deterministic on any transport.
//!
//! - [`wire`]: the request and reply lines, parsed and printed.
//! - [`server`]: the device side for the built-in reference models (and test wrappers).
//! - [`peer`]: the runner side: in-process (`sim`) or over a link.
//! - `device`: a peer as a conformance session holds it (greeting, restarts, failures).
//!
//! Nothing here panics on any line; every wait on a remote peer is bounded.

pub(crate) mod device;
pub mod peer;
pub mod server;
pub mod wire;

pub use peer::{LinkPeer, LocalPeer, Peer, PeerError};
pub use server::{CyclicDevice, Server};
pub use wire::{Env, Reply, Request, WireError, VERSION};
