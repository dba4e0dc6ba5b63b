//! `fuzz psd4xx --layer profinet --dut profinet:IFACE/NAME`: the raw Ethernet socket loop
//! under the PROFINET-layer fuzzer of `drivespec_fuzz::profinet`, on the monotonic clock.

use anyhow::{anyhow, Result};
use drivespec_fuzz::profinet::{PnWire, PnWireError};
use drivespec_profinet::eth::Mac;
use drivespec_profinet::udp::Ipv4;
use drivespec_wire::{Filter, OpenOptions, RawSocket};
use std::net::UdpSocket;
use std::time::{Duration, Instant};

/// Longest sleep between two looks at the socket (as the controller of `conform --dut
/// profinet:`): a fifth of the 1 ms send clock of the fuzzer's ARs.
const STEP: Duration = Duration::from_micros(200);

/// A raw socket on an interface, towards the station named `target` (our doc: module
/// `fuzz_profinet`).
pub struct RawWire {
    sock: RawSocket,
    origin: Instant,
    station: (Mac, Ipv4),
    target: String,
    what: String,
    /// Keeps the kernel from answering the device's RPC answers with ICMP.
    _quiet: Option<UdpSocket>,
}

impl RawWire {
    /// Opens interface `iface` (it needs a MAC and an IPv4 address) towards `target`.
    pub fn open(iface: &str, target: &str) -> Result<RawWire> {
        let interface = drivespec_wire::Interface::by_name(iface)?;
        let mac = interface
            .mac
            .ok_or_else(|| anyhow!("network interface `{iface}` has no MAC address"))?;
        let ip = interface
            .ipv4
            .first()
            .ok_or_else(|| anyhow!("network interface `{iface}` has no IPv4 address"))?
            .octets();
        let options = OpenOptions {
            filter: Filter::ether_types(&drivespec_profinet::eth::STATION_ETHER_TYPES)
                .skipping_source(mac),
            promiscuous: false,
            poll: Duration::ZERO,
            ..OpenOptions::default()
        };
        let sock = RawSocket::open(iface, options)?;
        let quiet =
            drivespec_wire::bind_udp(iface, drivespec_profinet::controller::CLIENT_PORT).ok();
        Ok(RawWire {
            sock,
            origin: Instant::now(),
            station: (mac, ip),
            target: target.to_owned(),
            what: format!("profinet:{iface}/{target}"),
            _quiet: quiet,
        })
    }
}

impl PnWire for RawWire {
    fn station(&self) -> (Mac, Ipv4) {
        self.station
    }

    fn target(&self) -> &str {
        &self.target
    }

    fn describe(&self) -> String {
        self.what.clone()
    }

    fn now(&mut self) -> Duration {
        self.origin.elapsed()
    }

    fn send(&mut self, frame: &[u8]) -> Result<(), PnWireError> {
        self.sock
            .send(frame)
            .map_err(|e| PnWireError::Io(e.to_string()))
    }

    fn recv(&mut self, until: Duration) -> Result<Vec<(Duration, Vec<u8>)>, PnWireError> {
        let origin = self.origin;
        let mut out = Vec::new();
        self.sock
            .wait_frames(origin + until, STEP, |r| {
                out.push((r.instant.saturating_duration_since(origin), r.frame))
            })
            .map_err(|e| PnWireError::Io(e.to_string()))?;
        Ok(out)
    }

    fn can_restart(&self) -> bool {
        false
    }

    fn restart(&mut self) {}

    fn virtual_time(&self) -> bool {
        false
    }
}
