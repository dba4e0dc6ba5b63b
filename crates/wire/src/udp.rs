//! A UDP socket on an interface's IPv4 address, for PNIO-CM (DCE/RPC over UDP, IEC 61158-6-10;
//! the endpoint mapper port is 34964).

use crate::{Interface, WireError};
use std::net::{SocketAddrV4, UdpSocket};

/// Binds UDP `port` (0: any) on the first IPv4 address of interface `name`.
pub fn bind_udp(name: &str, port: u16) -> Result<UdpSocket, WireError> {
    let interface = Interface::by_name(name)?;
    let Some(addr) = interface.ipv4.first() else {
        return Err(WireError::NoIpv4 {
            name: name.to_owned(),
        });
    };
    UdpSocket::bind(SocketAddrV4::new(*addr, port)).map_err(|e| WireError::io(name, "bind", e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn loopback_binds_and_unknown_names_are_named() {
        let sock = bind_udp("lo", 0);
        assert!(sock.is_ok(), "{sock:?}");
        match bind_udp("no-such-if0", 0) {
            Err(WireError::NoSuchInterface { name, present }) => {
                assert_eq!(name, "no-such-if0");
                assert!(present.contains("lo"), "{present}");
            }
            other => panic!("{other:?}"),
        }
    }
}
