//! Raw Ethernet frames and PNIO-CM UDP sockets on a named network interface (Linux
//! AF_PACKET through `pnet_datalink`; IEC 61158-6-10 carries PROFINET RT, DCP and alarms in
//! Ethernet II frames of EtherType 0x8892, PNIO-CM in UDP).
//!
//! Opening a raw socket needs root or the capabilities `cap_net_raw,cap_net_admin+ep`; a
//! refusal is [`WireError::PermissionDenied`], whose message says so on one line. Receiving
//! never blocks longer than the timeout given plus the poll interval of [`OpenOptions`]. No
//! function panics; a received frame is copied into one buffer of at most the interface's
//! read buffer size (4,096 bytes).
#![forbid(unsafe_code)]

mod error;
mod filter;
mod raw;
mod udp;

pub use error::WireError;
pub use filter::Filter;
pub use raw::{Interface, OpenOptions, RawSocket, Received, MAX_BATCH, MAX_FRAME, MIN_FRAME};
pub use udp::bind_udp;
