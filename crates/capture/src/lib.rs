//! Reading recorded traffic of the drivespec devices into event streams.
//!
//! - [`pcap`]: pcap and pcapng (plain or gzip-compressed) through one pull API on top of
//!   `pcap-parser`'s streaming readers; [`write`](mod@write) writes them, for tests.
//! - [`link`], [`ip`], [`arp`]: Ethernet (802.1Q, QinQ), Linux cooked captures, IPv4/UDP, ARP.
//! - [`rt`]: PROFINET RT frames (FrameID classes, APDU status); [`dcerpc`] and [`pnio`]:
//!   PNIO-CM calls over DCE/RPC; [`profinet`] ties them into [`profinet::Events`].
//! - [`serial`]: HPD serial recordings (raw, socat dumps, our text format, serial pcaps) as
//!   chunks for `drivespec_hpd::LineDecoder::feed`.
//! - [`iolink`]: IO-Link master logs for the PSx3xx (JSON lines, CSV; see `IOLINK-LOG.md`).
//! - [`detect`](mod@detect): which of these a file is, and why.
//!
//! Capture reading is kept apart from checking (style rule 12): this crate yields events;
//! checkers consume them. Parsers are sans-IO where they can be (they take byte slices), the
//! readers stream with bounded memory whatever the input size, nothing panics on any input,
//! and errors are typed, name the byte offset (and record, frame or line) and leave everything
//! read before them usable.
#![forbid(unsafe_code)]

pub mod arp;
mod bytes;
pub mod dcerpc;
pub mod detect;
pub mod input;
pub mod iolink;
pub mod ip;
pub mod link;
pub mod pcap;
pub mod pnio;
pub mod profinet;
pub mod rt;
pub mod serial;
pub mod time;
pub mod write;

pub use bytes::{Endian, Truncated};
pub use detect::{detect, Detection, Format};
pub use input::{GzipTail, Input};
pub use link::LinkType;
pub use pcap::{CaptureError, CaptureReader, Record, RecordRef};
