//! Why an interface cannot be opened, written or read.

use std::io;

/// An error of the raw Ethernet or UDP I/O (our doc: crate `drivespec-wire`).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WireError {
    /// No interface has this name (in the caller's network namespace).
    #[error("no network interface named `{name}` (present: {present})")]
    NoSuchInterface {
        /// The name asked for.
        name: String,
        /// The names present, comma-separated.
        present: String,
    },
    /// The kernel refused the raw socket: the process lacks CAP_NET_RAW / CAP_NET_ADMIN.
    #[error(
        "raw Ethernet on `{name}` needs root or the capabilities cap_net_raw,cap_net_admin+ep \
         (sudo setcap cap_net_raw,cap_net_admin+ep on the drivespec binary)"
    )]
    PermissionDenied {
        /// The interface.
        name: String,
    },
    /// The interface has no IPv4 address to bind a UDP socket to.
    #[error("network interface `{name}` has no IPv4 address")]
    NoIpv4 {
        /// The interface.
        name: String,
    },
    /// A frame to send is shorter than an Ethernet II header or longer than [`crate::MAX_FRAME`].
    #[error("a frame of {len} bytes cannot be sent (Ethernet II: {min} to {max} bytes)")]
    FrameLength {
        /// Its length.
        len: usize,
        /// The least length sent.
        min: usize,
        /// The greatest length sent.
        max: usize,
    },
    /// The kernel gave a channel that is not Ethernet.
    #[error("network interface `{name}` gives no Ethernet channel")]
    NotEthernet {
        /// The interface.
        name: String,
    },
    /// Any other failure of the operating system.
    #[error("network interface `{name}`: {op}: {source}")]
    Io {
        /// The interface.
        name: String,
        /// What was done: "open", "send", "receive", "bind".
        op: &'static str,
        /// The operating system's error.
        source: io::Error,
    },
}

impl WireError {
    /// The error of `op` on interface `name`, permission refusals told apart.
    pub(crate) fn io(name: &str, op: &'static str, source: io::Error) -> Self {
        if source.kind() == io::ErrorKind::PermissionDenied {
            WireError::PermissionDenied {
                name: name.to_owned(),
            }
        } else {
            WireError::Io {
                name: name.to_owned(),
                op,
                source,
            }
        }
    }
}
