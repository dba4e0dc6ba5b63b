//! `drivespec sim psd4xx --profinet IFACE`: the PSD4xx reference drive as a PROFINET IO
//! device (`drivespec_profinet::Device`) on a network interface, paced by the monotonic clock.

use crate::interrupt::Interrupt;
use crate::Outcome;
use anyhow::{anyhow, Context as _, Result};
use drivespec_profinet::{Device, DeviceConfig, DeviceEvent};
use drivespec_spec::{FamilyId, Spec};
use drivespec_wire::{Filter, OpenOptions, RawSocket};
use std::io::Write;
use std::time::{Duration, Instant};

/// Longest sleep between two looks at the socket: a received frame waits at most this long
/// (plus the timer slack of the system) before the device handles it. A choice: a fraction of
/// the shortest cycle the device serves (SendClockFactor 8: 250 µs), against 5,000 wake-ups a
/// second.
pub const STEP: Duration = Duration::from_micros(200);

/// Longest wait when the device has no timer due: how late a signal is noticed.
const IDLE: Duration = Duration::from_millis(50);

/// How `sim psd4xx --profinet` runs.
pub struct ProfinetSim<'a> {
    /// The network interface.
    pub iface: &'a str,
    /// The NameOfStation the device starts with.
    pub name: &'a str,
    /// The device model (forgiving match; default: the family's default).
    pub model: Option<&'a str>,
    /// Log every AR and DCP event on stderr.
    pub log: bool,
    /// Stop after this long.
    pub time_limit: Option<Duration>,
}

/// Serves the device on the interface until SIGINT, SIGTERM or the time limit.
pub fn run(spec: &Spec, sim: &ProfinetSim<'_>) -> Result<Outcome> {
    let family = spec.family(FamilyId::Psd4xx);
    let query = sim
        .model
        .unwrap_or(drivespec_sim::reference::PSD4XX_DEFAULT_MODEL);
    let model = family.model(query).ok_or_else(|| {
        let known: Vec<&str> = family.models.iter().map(|m| m.id.as_str()).collect();
        anyhow!(
            "unknown PSD4xx model {query:?}; known: {}",
            known.join(", ")
        )
    })?;
    let interface = drivespec_wire::Interface::by_name(sim.iface)?;
    let mac = interface
        .mac
        .ok_or_else(|| anyhow!("network interface `{}` has no MAC address", sim.iface))?;
    let mut config = DeviceConfig::new(spec, &model.id, mac, sim.name)
        .with_context(|| format!("building the PSD4xx {}", model.id))?;
    // The interface's own address, if it has one; else the device waits for a DCP Set.
    if let Some(ip) = interface.ipv4.first() {
        config.ip = ip.octets();
        config.netmask = [255, 255, 255, 0];
    }
    config.hello = true;
    let options = OpenOptions {
        filter: Filter::ether_types(&drivespec_profinet::eth::STATION_ETHER_TYPES)
            .skipping_source(mac),
        promiscuous: false,
        poll: Duration::ZERO,
        ..OpenOptions::default()
    };
    let mut sock = RawSocket::open(sim.iface, options)?;
    // Bound PNIO-CM ports keep the kernel from answering with ICMP "port unreachable" the
    // calls the device serves on the interface's own address and the answers to the calls it
    // makes itself (ApplicationReady); nothing reads them.
    let _quiet = drivespec_wire::bind_udp(sim.iface, drivespec_capture::dcerpc::PNIO_PORT).ok();
    let _quiet_client =
        drivespec_wire::bind_udp(sim.iface, drivespec_profinet::device::CLIENT_PORT).ok();
    let interrupt = Interrupt::install(sim.time_limit)?;
    let mut device = Device::new(spec, config)?;
    let stderr = std::io::stderr();
    let mut log = stderr.lock();
    let _ = writeln!(
        log,
        "drivespec sim: {} as PROFINET IO device {:?} on {} ({}){}",
        model.id,
        sim.name,
        sim.iface,
        mac_text(mac),
        interface
            .ipv4
            .first()
            .map(|ip| format!(", IP {ip}"))
            .unwrap_or_default()
    );
    let _ = writeln!(
        log,
        "drivespec sim: test it with: drivespec conform psd4xx --dut profinet:IFACE/{}",
        sim.name
    );
    // The one line on stdout: the device is on the wire.
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "profinet:{}/{}", sim.iface, sim.name);
    let _ = out.flush();
    drop(out);
    let origin = Instant::now();
    let (mut sent, mut received) = (0u64, 0u64);
    while !interrupt.stopped() {
        let now = origin.elapsed();
        device.handle_timeout(now);
        while let Some(frame) = device.poll_transmit(now) {
            sock.send(&frame)?;
            sent = sent.saturating_add(1);
        }
        while let Some(e) = device.poll_event() {
            if sim.log || !matches!(e, DeviceEvent::Refused { .. }) {
                let _ = writeln!(log, "drivespec sim: {:.3} s: {e:?}", now.as_secs_f64());
            }
        }
        let wait = device
            .poll_timeout()
            .map_or(IDLE, |t| t.saturating_sub(origin.elapsed()))
            .min(IDLE);
        received = received.saturating_add(sock.wait_frames(Instant::now() + wait, STEP, |r| {
            let at = r.instant.saturating_duration_since(origin);
            device.handle_frame(at, &r.frame);
        })? as u64);
    }
    let _ = writeln!(
        log,
        "drivespec sim: served {:.1} s on {}: {received} frame(s) received, {sent} sent; stopped by {}",
        origin.elapsed().as_secs_f64(),
        sim.iface,
        match interrupt.exit_code() {
            Some(124) => "--time-limit",
            _ => interrupt.cause().unwrap_or("a signal"),
        }
    );
    Ok(Outcome::Pass)
}

/// `02:00:00:00:00:01`.
fn mac_text(mac: [u8; 6]) -> String {
    mac.iter()
        .map(|b| format!("{b:02x}"))
        .collect::<Vec<_>>()
        .join(":")
}
