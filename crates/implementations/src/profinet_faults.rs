//! PSD4xx PROFINET IO devices with a planted fault, to measure `drivespec fuzz --layer
//! profinet` from the failing side: each wraps the reference [`Device`] and deviates in one
//! named way. [`serve_profinet`] serves one on a network interface (`drivespec-impl
//! profinet-fault IFACE NAME`).

use drivespec_capture::link::{ethertype, parse_ethernet};
use drivespec_capture::rt::{FrameClass, RtFrame};
use drivespec_profinet::{Device, DeviceConfig, SansIo};
use drivespec_spec::Spec;
use drivespec_wire::{Filter, OpenOptions, RawSocket, WireError};
use std::time::{Duration, Instant};

/// How long the device is gone after the fault: a restart of a small device takes seconds.
pub const RESTART: Duration = Duration::from_secs(2);

/// A device that restarts after a DCP Identify request whose blocks do not parse (a block
/// length running past the PDU): for [`RESTART`] it neither receives nor sends, then it is
/// back as switched on (no AR). A correct device ignores such a request (IEC 61158-6-10 DCP:
/// a request that does not decode is discarded).
#[derive(Debug, Clone)]
pub struct RestartOnMalformedIdentify {
    fresh: Device,
    device: Device,
    gone_until: Option<Duration>,
}

impl RestartOnMalformedIdentify {
    /// The faulty device around the reference device `device`.
    pub fn new(device: Device) -> RestartOnMalformedIdentify {
        RestartOnMalformedIdentify {
            fresh: device.clone(),
            device,
            gone_until: None,
        }
    }

    /// Whether the device is restarting at `now` (a restart that has ended brings it back).
    fn gone(&mut self, now: Duration) -> bool {
        match self.gone_until {
            Some(t) if now < t => true,
            Some(_) => {
                self.gone_until = None;
                self.device = self.fresh.clone();
                false
            }
            None => false,
        }
    }
}

/// Whether `frame` is a DCP Identify request with a block that does not parse.
fn malformed_identify(frame: &[u8]) -> bool {
    let Ok(l) = parse_ethernet(frame) else {
        return false;
    };
    if l.ethertype != ethertype::PROFINET {
        return false;
    }
    let Ok(rt) = RtFrame::parse(l.payload) else {
        return false;
    };
    rt.class() == FrameClass::DcpIdentifyRequest
        && rt.dcp().is_ok_and(|h| h.iter_blocks().any(|b| b.is_err()))
}

impl SansIo for RestartOnMalformedIdentify {
    fn handle_frame(&mut self, now: Duration, frame: &[u8]) {
        if self.gone(now) {
            return;
        }
        if malformed_identify(frame) {
            self.gone_until = Some(now + RESTART);
            return;
        }
        self.device.handle_frame(now, frame);
    }

    fn handle_timeout(&mut self, now: Duration) {
        if !self.gone(now) {
            self.device.handle_timeout(now);
        }
    }

    fn poll_transmit(&mut self, now: Duration) -> Option<Vec<u8>> {
        if self.gone(now) {
            return None;
        }
        self.device.poll_transmit(now)
    }

    fn poll_timeout(&self) -> Option<Duration> {
        match self.gone_until {
            Some(t) => Some(t),
            None => self.device.poll_timeout(),
        }
    }
}

/// The faulty devices by name (`drivespec-impl profinet-fault NAME`).
pub const NAMES: [&str; 1] = ["restart-on-malformed-identify"];

/// The PSD4xx of `model` named `station` at `mac`/`ip` (the reference device's defaults).
pub fn reference(spec: &Spec, model: &str, mac: [u8; 6], ip: [u8; 4], station: &str) -> Device {
    let mut c = DeviceConfig::new(spec, model, mac, station).expect("the spec's PROFINET identity");
    c.ip = ip;
    c.netmask = [255, 255, 255, 0];
    Device::new(spec, c).expect("a model of the spec")
}

/// Longest sleep between two looks at the socket (as `drivespec sim --profinet`).
const STEP: Duration = Duration::from_micros(200);
/// Longest wait when the device has no timer due.
const IDLE: Duration = Duration::from_millis(50);

/// Serves the faulty device `name` (PSD426) as station `station` on interface `iface` for
/// `limit`; prints `profinet:IFACE/STATION` on stdout once it is on the wire.
pub fn serve_profinet(
    iface: &str,
    station: &str,
    name: &str,
    limit: Duration,
) -> Result<(), WireError> {
    let interface = drivespec_wire::Interface::by_name(iface)?;
    let mac = interface.mac.unwrap_or([0x02, 0, 0, 0, 0, 0x26]);
    let ip = interface.ipv4.first().map_or([0; 4], |a| a.octets());
    let mut device = match name {
        "restart-on-malformed-identify" => {
            RestartOnMalformedIdentify::new(reference(crate::spec(), "PSD426", mac, ip, station))
        }
        other => panic!("no PROFINET fault named {other:?}; known: {NAMES:?}"),
    };
    let options = OpenOptions {
        filter: Filter::ether_types(&drivespec_profinet::eth::STATION_ETHER_TYPES)
            .skipping_source(mac),
        promiscuous: false,
        poll: Duration::ZERO,
        ..OpenOptions::default()
    };
    let mut sock = RawSocket::open(iface, options)?;
    let _quiet = drivespec_wire::bind_udp(iface, drivespec_capture::dcerpc::PNIO_PORT).ok();
    println!("profinet:{iface}/{station}");
    let origin = Instant::now();
    while origin.elapsed() < limit {
        let now = origin.elapsed();
        device.handle_timeout(now);
        while let Some(frame) = device.poll_transmit(now) {
            sock.send(&frame)?;
        }
        let wait = device
            .poll_timeout()
            .map_or(IDLE, |t| t.saturating_sub(origin.elapsed()))
            .min(IDLE);
        sock.wait_frames(Instant::now() + wait, STEP, |r| {
            device.handle_frame(r.instant.saturating_duration_since(origin), &r.frame);
        })?;
    }
    Ok(())
}
