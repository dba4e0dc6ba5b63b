//! Fuzz harness of the PROFINET IO device (`drivespec_profinet::Device`, the PSD426 behind
//! DCP, PNIO-CM and RT class 1, IEC 61158-6-10) on any sequence of received frames.

use drivespec_profinet::{dcp, eth, Device, DeviceConfig};
use drivespec_spec::Spec;
use std::sync::OnceLock;
use std::time::Duration;

/// The device's MAC address in the seeds.
pub const DEVICE_MAC: [u8; 6] = [0x02, 0x00, 0x00, 0x00, 0x26, 0x01];
/// The device's IPv4 address in the seeds.
pub const DEVICE_IP: [u8; 4] = [192, 168, 26, 2];
/// The device's NameOfStation in the seeds.
pub const STATION: &str = "psd426-fuzz";
/// The MAC the closing Identify comes from.
const ASKER: [u8; 6] = [0x02, 0x00, 0x00, 0x00, 0x26, 0x02];
/// Longest frame a device may send: 1,500 payload bytes, the Ethernet header, one 802.1Q tag.
const MAX_FRAME: usize = 1518;
/// Shortest frame a device may send: an Ethernet header.
const MIN_FRAME: usize = 14;
/// Time between two input frames.
const STEP: Duration = Duration::from_millis(1);

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().expect("the built-in spec loads"))
}

/// The device as switched on, built once and cloned per input.
fn template() -> &'static Device {
    static DEVICE: OnceLock<Device> = OnceLock::new();
    DEVICE.get_or_init(|| {
        let mut c = DeviceConfig::new(spec(), "PSD426", DEVICE_MAC, STATION)
            .expect("the PSD426 device config builds");
        c.ip = DEVICE_IP;
        c.netmask = [255, 255, 255, 0];
        Device::new(spec(), c).expect("the PSD426 device builds")
    })
}

/// Drains what the device sends at `now`: every frame a whole Ethernet frame of at most
/// [`MAX_FRAME`] bytes, the queue bounded. Returns the frames.
fn drain(d: &mut Device, now: Duration) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    while let Some(f) = d.poll_transmit(now) {
        assert!(
            (MIN_FRAME..=MAX_FRAME).contains(&f.len()),
            "a frame of {} bytes",
            f.len()
        );
        out.push(f);
        assert!(
            out.len() <= drivespec_profinet::device::MAX_QUEUED + 1,
            "the device sends without end"
        );
    }
    out
}

/// `data` is a sequence of frames, each a big-endian u16 length and that many bytes (the last
/// cut where the input ends), received [`STEP`] apart. Whatever came, the device sends only
/// whole frames, keeps its queue bounded, and still answers a DCP Identify of all stations.
pub fn device(data: &[u8]) {
    let mut d = template().clone();
    let mut now = Duration::ZERO;
    let mut rest = data;
    while let [hi, lo, tail @ ..] = rest {
        let len = usize::from(u16::from_be_bytes([*hi, *lo])).min(tail.len());
        let (frame, next) = tail.split_at(len);
        d.handle_frame(now, frame);
        drain(&mut d, now);
        now += STEP;
        d.handle_timeout(now);
        drain(&mut d, now);
        rest = next;
    }
    let mut b = dcp::DcpBlocks::new();
    b.plain(dcp::opt::ALL, &[]);
    let pdu = dcp::pdu(
        drivespec_capture::rt::FrameId::DCP_IDENTIFY_REQ,
        dcp::service::IDENTIFY,
        dcp::service_type::REQUEST,
        0x0BAD_CAFE,
        1,
        &b.into_bytes(),
    );
    let ask = eth::frame(
        eth::DCP_IDENTIFY_MAC,
        ASKER,
        None,
        drivespec_capture::link::ethertype::PROFINET,
        &pdu,
    );
    d.handle_frame(now, &ask);
    let answered = drain(&mut d, now).iter().any(|f| {
        f.get(..6) == Some(&ASKER[..])
            && f.get(14..16)
                == Some(
                    &drivespec_capture::rt::FrameId::DCP_IDENTIFY_RES
                        .0
                        .to_be_bytes()[..],
                )
    });
    assert!(answered, "the device no longer answers Identify all");
}
