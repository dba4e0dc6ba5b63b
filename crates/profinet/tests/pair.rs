//! Controller and device in memory on a virtual clock: discovery, Connect, parameterisation,
//! cyclic exchange that decodes as the manual says, records, refusals, the watchdog, link
//! loss, Release; and the recorded exchange passes `drivespec check`.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_capture::dcerpc::PNIO_PORT;
use drivespec_capture::link::ethertype;
use drivespec_capture::pnio::PnioStatus;
use drivespec_capture::profinet::Events;
use drivespec_capture::rt::FrameId;
use drivespec_capture::write::PcapWriter;
use drivespec_capture::{CaptureReader, LinkType};
use drivespec_check::profinet::{check, PnOptions};
use drivespec_profinet::dcp::{self, opt, service, service_type, DcpBlocks};
use drivespec_profinet::device::ArEnd;
use drivespec_profinet::{
    eth, Controller, ControllerConfig, ControllerError, ControllerEvent, Device, DeviceConfig,
    DeviceEvent, Identity,
};
use drivespec_psd4xx::{Input, Output, RecordWrite, Reply, Request, Rules, Width};
use drivespec_spec::Spec;
use proptest::prelude::*;
use std::sync::OnceLock;
use std::time::Duration;

const DEV_MAC: [u8; 6] = [0x00, 0x30, 0xDE, 0x42, 0x60, 0x17];
const CTL_MAC: [u8; 6] = [0x00, 0x1B, 0x1B, 0x4A, 0x10, 0x01];
const DEV_IP: [u8; 4] = [192, 168, 10, 26];
const CTL_IP: [u8; 4] = [192, 168, 10, 1];
const NAME: &str = "psd426-axis-x";
/// 2026-01-01 in µs, the capture's time origin.
const T0_US: u64 = 1_767_225_600_000_000;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

fn rules() -> Rules {
    Rules::from_spec(spec()).unwrap()
}

fn device() -> Device {
    let mut c = DeviceConfig::new(spec(), "PSD426", DEV_MAC, NAME).unwrap();
    c.ip = DEV_IP;
    c.netmask = [255, 255, 255, 0];
    Device::new(spec(), c).unwrap()
}

fn controller_config() -> ControllerConfig {
    ControllerConfig::new(Identity::from_spec(spec()).unwrap(), CTL_MAC, CTL_IP, NAME)
}

/// The two stations joined by a lossless wire, every frame recorded.
struct Pair {
    dev: Device,
    ctl: Controller,
    now: Duration,
    frames: Vec<(Duration, Vec<u8>)>,
    ctl_events: Vec<ControllerEvent>,
    dev_events: Vec<DeviceEvent>,
    /// Device frames that are lost on the wire.
    lost: fn(&[u8]) -> bool,
    /// Device frames as the controller gets them.
    rewrite: fn(Vec<u8>) -> Vec<u8>,
}

impl Pair {
    fn new(config: ControllerConfig) -> Pair {
        let mut p = Pair {
            dev: device(),
            ctl: Controller::new(config),
            now: Duration::ZERO,
            frames: Vec::new(),
            ctl_events: Vec::new(),
            dev_events: Vec::new(),
            lost: |_| false,
            rewrite: |f| f,
        };
        p.ctl.start(p.now);
        p
    }

    fn deliver(&mut self) {
        loop {
            let mut moved = false;
            while let Some(f) = self.ctl.poll_transmit(self.now) {
                self.dev.handle_frame(self.now, &f);
                self.frames.push((self.now, f));
                moved = true;
            }
            while let Some(f) = self.dev.poll_transmit(self.now) {
                if (self.lost)(&f) {
                    continue;
                }
                let f = (self.rewrite)(f);
                self.ctl.handle_frame(self.now, &f);
                self.frames.push((self.now, f));
                moved = true;
            }
            if !moved {
                break;
            }
        }
        self.ctl_events
            .extend(std::iter::from_fn(|| self.ctl.poll_event()));
        self.dev_events
            .extend(std::iter::from_fn(|| self.dev.poll_event()));
    }

    /// One step: deliver what is due, then jump to the next wakeup.
    fn step(&mut self) {
        self.deliver();
        let next = [self.dev.poll_timeout(), self.ctl.poll_timeout()]
            .into_iter()
            .flatten()
            .min()
            .unwrap_or(self.now + Duration::from_millis(1));
        self.now = next.max(self.now + Duration::from_micros(1));
        self.dev.handle_timeout(self.now);
        self.ctl.handle_timeout(self.now);
        self.deliver();
    }

    /// Steps until `done` or the virtual time `limit` passed.
    fn run_until(&mut self, limit: Duration, done: impl Fn(&Pair) -> bool) -> bool {
        while self.now < limit {
            if done(self) {
                return true;
            }
            self.step();
        }
        done(self)
    }

    fn run_for(&mut self, d: Duration) {
        let end = self.now + d;
        self.run_until(end, |_| false);
    }

    fn running(config: ControllerConfig) -> Pair {
        let mut p = Pair::new(config);
        assert!(
            p.run_until(Duration::from_secs(5), |p| p.ctl.is_running()),
            "{:?}",
            p.ctl_events
        );
        p
    }

    fn input(&self) -> Input {
        Input::parse(&rules(), &self.ctl.input().unwrap().image).unwrap()
    }

    fn record(&mut self, id: drivespec_profinet::RecordId) -> Result<Vec<u8>, ControllerError> {
        let limit = self.now + Duration::from_secs(5);
        let found = |p: &Pair| {
            p.ctl_events.iter().find_map(|e| match e {
                ControllerEvent::Record { id: i, result } if *i == id => Some(result.clone()),
                _ => None,
            })
        };
        self.run_until(limit, |p| found(p).is_some());
        found(self).expect("record answered")
    }

    fn pcap(&self) -> Vec<u8> {
        let mut w = PcapWriter::new(Vec::new(), LinkType::ETHERNET, 65535).unwrap();
        for (t, f) in &self.frames {
            w.write_packet(T0_US + t.as_micros() as u64, f).unwrap();
        }
        w.into_inner().unwrap()
    }
}

fn output(pkw: Request, control: u16, target: i32) -> Vec<u8> {
    let r = rules();
    Output {
        pkw: r.pkw().encode_request(&pkw).unwrap(),
        control,
        target,
    }
    .to_bytes(&r)
    .unwrap()
}

#[test]
fn a_controller_connects_exchanges_data_and_records_and_releases() {
    let mut p = Pair::running(controller_config());
    let id = Identity::from_spec(spec()).unwrap();
    assert!(matches!(
        p.ctl_events[0],
        ControllerEvent::Identified { mac: DEV_MAC, ip: DEV_IP, id: Some((v, d)) } if v == id.vendor_id && d == id.device_id
    ));
    assert!(p.ctl_events.contains(&ControllerEvent::Connected));
    assert!(p.dev_events.contains(&DeviceEvent::PrmEnd));
    assert!(p.dev_events.contains(&DeviceEvent::Data));

    // PKW read of par. 1 (3.8): answered with the status word.
    let r = rules();
    p.ctl.set_output(&output(
        Request::Read {
            pnu: 1,
            index: None,
        },
        0,
        0,
    ));
    p.run_for(Duration::from_millis(20));
    let reply = r.pkw().reply(&p.input().pkw).unwrap();
    assert!(matches!(reply, Reply::Value { pnu: 1, .. }), "{reply:?}");
    let before = p.ctl.input_frames();

    // A positioning run (4.1: control word 0x14 with the target; 3.7 bit 6 no loop).
    let target = 800;
    p.ctl.set_output(&output(Request::None, 0x54, target));
    p.run_until(p.now + Duration::from_secs(20), |p| {
        p.input().actual == target && p.input().status & 1 != 0
    });
    let input = p.input();
    assert_eq!(input.actual, target, "the run reaches its target");
    assert_eq!(
        input.status & 1,
        1,
        "status bit 0: target position achieved (3.6)"
    );
    assert!(
        p.ctl.input_frames() - before >= 1000,
        "at least 1,000 cycles exchanged"
    );
    assert_eq!(p.dev.drive().outputs_in_force().target, target);

    // Records (3.2.2): read par. 1, write par. 44, read it back; I&M0 on the DAP.
    let (slot, sub) = (id.output.slot, id.output.subslot);
    let rid = p.ctl.read_record(p.now, slot, sub, 1).unwrap();
    assert_eq!(
        p.record(rid).unwrap().len(),
        2,
        "16-bit values read as 2 bytes"
    );
    let data = RecordWrite {
        index: 44,
        control: 1,
        width: Width::Word,
        value: 7,
    }
    .to_bytes(r.record())
    .unwrap();
    let rid = p.ctl.write_record(p.now, slot, sub, 44, &data).unwrap();
    assert_eq!(p.record(rid), Ok(Vec::new()));
    assert_eq!(p.dev.drive().parameter(44), Ok(7));
    let rid = p.ctl.read_record(p.now, id.dap_slot, 1, 0xAFF0).unwrap();
    let im0 = p.record(rid).unwrap();
    assert_eq!(&im0[..2], &[0x00, 0x20]);
    assert_eq!(u16::from_be_bytes([im0[6], im0[7]]), id.vendor_id);

    // Release: the AR ends and the drive's outputs become 0 (3.9).
    p.ctl.release(p.now).unwrap();
    p.run_until(p.now + Duration::from_secs(2), |p| p.ctl.is_closed());
    assert!(p.ctl_events.contains(&ControllerEvent::Released));
    assert!(p
        .dev_events
        .contains(&DeviceEvent::ArEnded(ArEnd::Released)));
    assert_eq!(p.dev.drive().outputs_in_force().control, 0);
    assert_eq!(p.dev.ar_state(), None);
}

#[test]
fn the_recorded_exchange_passes_drivespec_check_and_finds_the_drive() {
    let mut p = Pair::running(controller_config());
    p.ctl.set_output(&output(
        Request::Read {
            pnu: 1,
            index: None,
        },
        0,
        0,
    ));
    p.run_for(Duration::from_millis(50));
    p.ctl.set_output(&output(Request::None, 0x54, 400));
    p.run_for(Duration::from_millis(400));
    let id = Identity::from_spec(spec()).unwrap();
    let rid = p
        .ctl
        .read_record(p.now, id.output.slot, id.output.subslot, 3)
        .unwrap();
    p.record(rid).unwrap();
    p.run_for(Duration::from_millis(50));
    p.ctl.release(p.now).unwrap();
    p.run_until(p.now + Duration::from_secs(2), |p| p.ctl.is_closed());
    let bytes = p.pcap();
    let report = check(
        spec(),
        PnOptions::default(),
        Events::new(CaptureReader::new(&bytes[..]).unwrap()),
    )
    .unwrap();
    assert_eq!(report.violation_count, 0, "{:#?}", report.violations);
    assert_eq!(report.drives.len(), 1, "{:#?}", report.notes);
}

#[test]
fn an_unknown_record_index_is_refused_with_invalid_index() {
    let mut p = Pair::running(controller_config());
    let id = Identity::from_spec(spec()).unwrap();
    let rid = p
        .ctl
        .read_record(p.now, id.output.slot, id.output.subslot, 0x7FFF)
        .unwrap();
    let want = PnioStatus {
        code: 0xDE,
        decode: 0x80,
        code1: 0xB0,
        code2: 0,
    };
    assert_eq!(
        p.record(rid),
        Err(ControllerError::Refused {
            operation: "Read",
            status: want
        })
    );
    // A wrong write length (3.2.2: 3 bytes for a 16-bit value) is a write length error.
    let rid = p
        .ctl
        .write_record(p.now, id.output.slot, id.output.subslot, 44, &[1, 0])
        .unwrap();
    let want = PnioStatus {
        code: 0xDF,
        decode: 0x80,
        code1: 0xB1,
        code2: 0,
    };
    assert_eq!(
        p.record(rid),
        Err(ControllerError::Refused {
            operation: "Write",
            status: want
        })
    );
    // The AR goes on.
    assert!(p.ctl.is_running());
}

#[test]
fn a_wrong_module_ident_gives_a_module_diff_and_the_controller_refuses_it() {
    let mut c = controller_config();
    c.identity.output.module_ident = 0x0999;
    let mut p = Pair::new(c);
    p.run_until(Duration::from_secs(5), |p| p.ctl.is_closed());
    let diff = p.ctl_events.iter().find_map(|e| match e {
        ControllerEvent::Failed(ControllerError::ModuleDiff(d)) => Some(d.clone()),
        _ => None,
    });
    let diff = diff.expect("a ModuleDiff failure");
    let id = Identity::from_spec(spec()).unwrap();
    assert_eq!(diff.len(), 1);
    assert_eq!(
        (diff[0].slot, diff[0].ident, diff[0].state),
        (id.output.slot, id.output.module_ident, 1)
    );
    assert!(matches!(
        p.dev_events[0],
        DeviceEvent::Connected { diff: true, .. }
    ));
    // The controller released the AR it did not want.
    p.run_for(Duration::from_millis(10));
    assert_eq!(p.dev.ar_state(), None);
}

#[test]
fn wrong_module_lengths_refuse_the_connect_with_the_faulty_field() {
    let mut c = controller_config();
    c.identity.output.length = 12;
    let mut p = Pair::new(c);
    p.run_until(Duration::from_secs(5), |p| p.ctl.is_closed());
    let want = PnioStatus {
        code: 0xDB,
        decode: 0x81,
        code1: 0x03,
        code2: 14,
    };
    assert!(
        p.ctl_events
            .contains(&ControllerEvent::Failed(ControllerError::Refused {
                operation: "Connect",
                status: want
            })),
        "{:?}",
        p.ctl_events
    );
    assert_eq!(p.dev.ar_state(), None);
}

#[test]
fn a_send_clock_out_of_range_is_refused() {
    for (scf, rr, field) in [(9, 1, 10), (32, 3, 11), (65524, 1, 10)] {
        let mut c = controller_config();
        c.send_clock_factor = scf;
        c.reduction_ratio = rr;
        let mut p = Pair::new(c);
        p.run_until(Duration::from_secs(5), |p| p.ctl.is_closed());
        let want = PnioStatus {
            code: 0xDB,
            decode: 0x81,
            code1: 0x02,
            code2: field,
        };
        assert!(
            p.ctl_events
                .contains(&ControllerEvent::Failed(ControllerError::Refused {
                    operation: "Connect",
                    status: want
                })),
            "SCF {scf} RR {rr}: {:?}",
            p.ctl_events
        );
    }
}

#[test]
fn the_watchdog_ends_the_ar_when_the_controller_stops_sending() {
    let mut p = Pair::running(controller_config());
    p.ctl.set_output(&output(Request::None, 0x54, 4000));
    p.run_for(Duration::from_millis(50));
    assert!(p.dev.drive().outputs_in_force().control != 0);
    p.ctl.set_sending(false);
    p.run_until(p.now + Duration::from_secs(1), |p| p.ctl.is_closed());
    assert!(
        p.dev_events
            .contains(&DeviceEvent::ArEnded(ArEnd::Watchdog)),
        "{:?}",
        p.dev_events
    );
    let abort = PnioStatus {
        code: 0xCF,
        decode: 0x81,
        code1: 0xFD,
        code2: 0x05,
    };
    assert!(
        p.ctl_events
            .contains(&ControllerEvent::Failed(ControllerError::Aborted(abort))),
        "{:?}",
        p.ctl_events
    );
    // Manual 3.9: the connection is lost, the outputs become 0.
    assert_eq!(p.dev.drive().outputs_in_force().control, 0);
}

#[test]
fn link_loss_zeroes_the_outputs_and_the_controller_sees_its_watchdog() {
    let mut p = Pair::running(controller_config());
    p.ctl.set_output(&output(Request::None, 0x54, 4000));
    p.run_for(Duration::from_millis(50));
    p.dev.handle_link(p.now, false);
    assert_eq!(p.dev.drive().outputs_in_force().control, 0);
    p.run_until(p.now + Duration::from_secs(1), |p| p.ctl.is_closed());
    assert!(matches!(
        p.ctl_events.last(),
        Some(ControllerEvent::Failed(ControllerError::Watchdog(_)))
    ));
    assert!(p
        .dev_events
        .contains(&DeviceEvent::ArEnded(ArEnd::LinkDown)));
}

#[test]
fn bad_iops_keeps_the_last_outputs() {
    let mut p = Pair::running(controller_config());
    p.ctl.set_output(&output(Request::None, 0x54, 4000));
    p.run_for(Duration::from_millis(20));
    // A frame with the output module's IOPS bad (controller CPU in STOP, 3.9 item 1).
    let mut c = controller_config();
    c.identity = Identity::from_spec(spec()).unwrap();
    let in_force = *p.dev.drive().outputs_in_force();
    let stop_frame = {
        let (_, last) = p
            .frames
            .iter()
            .rev()
            .find(|(_, f)| {
                f.get(..6) == Some(&DEV_MAC[..])
                    && f.get(12..14) == Some(&[0x88, 0x92][..])
                    && f[14] == 0xC1
            })
            .unwrap()
            .clone();
        let mut f = last;
        let dap = c.identity.dap_submodules.len();
        let iops_at = 16 + dap + 1 + 14;
        f[iops_at] = 0x00;
        // Output image with control 0 in the same frame: it must not be applied.
        for b in &mut f[16 + dap + 1 + 8..16 + dap + 1 + 10] {
            *b = 0;
        }
        f
    };
    p.ctl.set_sending(false);
    p.dev.handle_frame(p.now, &stop_frame);
    assert_eq!(*p.dev.drive().outputs_in_force(), in_force);
}

#[test]
fn an_absent_station_ends_in_no_such_station() {
    let mut c = controller_config();
    c.target = "nobody-here".into();
    let mut p = Pair::new(c);
    p.run_until(Duration::from_secs(30), |p| p.ctl.is_closed());
    assert_eq!(
        p.ctl_events.last(),
        Some(&ControllerEvent::Failed(ControllerError::NoSuchStation(
            "nobody-here".into()
        )))
    );
}

#[test]
fn a_device_without_ip_gets_one_by_dcp_set() {
    let mut c = DeviceConfig::new(spec(), "PSD426", DEV_MAC, NAME).unwrap();
    c.ip = [0; 4];
    let mut cc = controller_config();
    cc.device_ip = Some((DEV_IP, [255, 255, 255, 0], [0; 4]));
    let mut p = Pair::new(cc);
    p.dev = Device::new(spec(), c).unwrap();
    assert!(
        p.run_until(Duration::from_secs(10), |p| p.ctl.is_running()),
        "{:?}",
        p.ctl_events
    );
    assert_eq!(p.dev.ip(), DEV_IP);
    assert!(p.dev_events.contains(&DeviceEvent::IpSet(DEV_IP)));
}

#[test]
fn dcp_set_name_and_identify_all() {
    let mut d = device();
    let mut b = DcpBlocks::new();
    b.with_info(opt::NAME_OF_STATION, dcp::PERMANENT, b"psd-07");
    let pdu = dcp::pdu(
        FrameId::DCP_GET_SET,
        service::SET,
        service_type::REQUEST,
        9,
        0,
        &b.into_bytes(),
    );
    d.handle_frame(
        Duration::ZERO,
        &eth::frame(DEV_MAC, CTL_MAC, None, ethertype::PROFINET, &pdu),
    );
    assert_eq!(d.station_name(), "psd-07");
    let res = d.poll_transmit(Duration::ZERO).unwrap();
    assert_eq!(&res[..6], &CTL_MAC);
    let mut b = DcpBlocks::new();
    b.plain(opt::ALL, &[]);
    let pdu = dcp::pdu(
        FrameId::DCP_IDENTIFY_REQ,
        service::IDENTIFY,
        service_type::REQUEST,
        10,
        1,
        &b.into_bytes(),
    );
    d.handle_frame(
        Duration::ZERO,
        &eth::frame(
            eth::DCP_IDENTIFY_MAC,
            CTL_MAC,
            None,
            ethertype::PROFINET,
            &pdu,
        ),
    );
    let res = d.poll_transmit(Duration::ZERO).unwrap();
    assert!(res.windows(6).any(|w| w == b"psd-07"));
    // Identify for another name: no answer.
    let mut b = DcpBlocks::new();
    b.plain(opt::NAME_OF_STATION, b"other");
    let pdu = dcp::pdu(
        FrameId::DCP_IDENTIFY_REQ,
        service::IDENTIFY,
        service_type::REQUEST,
        11,
        1,
        &b.into_bytes(),
    );
    d.handle_frame(
        Duration::ZERO,
        &eth::frame(
            eth::DCP_IDENTIFY_MAC,
            CTL_MAC,
            None,
            ethertype::PROFINET,
            &pdu,
        ),
    );
    assert_eq!(d.poll_transmit(Duration::ZERO), None);
}

fn prefixed() -> impl Strategy<Value = Vec<u8>> {
    let pn = {
        let mut h = DEV_MAC.to_vec();
        h.extend_from_slice(&CTL_MAC);
        h.extend_from_slice(&[0x88, 0x92]);
        h
    };
    let udp = {
        let mut h = DEV_MAC.to_vec();
        h.extend_from_slice(&CTL_MAC);
        h.extend_from_slice(&[0x08, 0x00, 0x45, 0, 0, 0xFF, 0, 0, 0, 0, 64, 17, 0, 0]);
        h.extend_from_slice(&CTL_IP);
        h.extend_from_slice(&DEV_IP);
        h.extend_from_slice(&[0xC0, 0x01]);
        h.extend_from_slice(&PNIO_PORT.to_be_bytes());
        h.extend_from_slice(&[0, 0xEB, 0, 0, 4, 0]);
        h
    };
    (0usize..3, proptest::collection::vec(any::<u8>(), 0..300)).prop_map(move |(k, tail)| {
        let mut f = match k {
            0 => pn.clone(),
            1 => udp.clone(),
            _ => Vec::new(),
        };
        f.extend_from_slice(&tail);
        f
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]
    #[test]
    fn arbitrary_frames_never_panic_a_device_or_a_controller(frames in proptest::collection::vec(prefixed(), 1..8)) {
        let mut d = device();
        let mut c = Controller::new(controller_config());
        c.start(Duration::ZERO);
        for (i, f) in frames.iter().enumerate() {
            let t = Duration::from_millis(i as u64);
            d.handle_frame(t, f);
            c.handle_frame(t, f);
            while d.poll_transmit(t).is_some() {}
            while c.poll_transmit(t).is_some() {}
        }
    }
}

#[test]
fn a_connect_without_answer_times_out_after_its_repeats() {
    let mut p = Pair::new(controller_config());
    p.lost = |f| f.get(12..14) == Some(&[0x08, 0x00][..]);
    p.run_until(Duration::from_secs(10), |p| p.ctl.is_closed());
    let connects = p
        .frames
        .iter()
        .filter(|(_, f)| {
            f.get(..6) == Some(&DEV_MAC[..]) && f.get(12..14) == Some(&[0x08, 0x00][..])
        })
        .count();
    assert_eq!(connects, 4, "the Connect and its 3 repeats");
    assert_eq!(
        p.ctl_events.last(),
        Some(&ControllerEvent::Failed(ControllerError::Timeout(
            "Connect"
        )))
    );
}

/// The frames of a whole session, and a device in data exchange.
fn session() -> &'static (Vec<Vec<u8>>, Device) {
    static S: OnceLock<(Vec<Vec<u8>>, Device)> = OnceLock::new();
    S.get_or_init(|| {
        let mut p = Pair::running(controller_config());
        let id = Identity::from_spec(spec()).unwrap();
        let rid = p
            .ctl
            .read_record(p.now, id.output.slot, id.output.subslot, 1)
            .unwrap();
        p.record(rid).unwrap();
        p.run_for(Duration::from_millis(5));
        let dev = p.dev.clone();
        p.ctl.release(p.now).unwrap();
        p.run_until(p.now + Duration::from_secs(2), |p| p.ctl.is_closed());
        (p.frames.into_iter().map(|(_, f)| f).collect(), dev)
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]
    #[test]
    fn mutated_session_frames_never_panic_a_running_device(
        pick in any::<prop::sample::Index>(),
        flips in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6),
        cut in any::<prop::sample::Index>(),
    ) {
        let (frames, dev) = session();
        let mut f = pick.get(frames).clone();
        for (at, v) in &flips {
            let i = at.index(f.len());
            f[i] ^= v | 1;
        }
        f.truncate(cut.index(f.len() + 1).max(1));
        let mut d = dev.clone();
        let t = Duration::from_secs(1);
        d.handle_frame(t, &f);
        while d.poll_transmit(t).is_some() {}
        d.handle_timeout(t + Duration::from_millis(100));
        while d.poll_transmit(t + Duration::from_millis(100)).is_some() {}
    }
}

#[test]
fn the_controller_watchdog_aborts_the_ar_at_the_device() {
    let mut p = Pair::running(controller_config());
    p.run_for(Duration::from_millis(10));
    // The device's frames stop reaching the controller.
    p.lost = |_| true;
    p.run_until(p.now + Duration::from_secs(1), |p| p.ctl.is_closed());
    assert!(matches!(
        p.ctl_events.last(),
        Some(ControllerEvent::Failed(ControllerError::Watchdog(d))) if *d == Duration::from_millis(3)
    ));
    p.run_for(Duration::from_millis(5));
    let abort = PnioStatus {
        code: 0xCF,
        decode: 0x81,
        code1: 0xFD,
        code2: 0x05,
    };
    assert!(
        p.dev_events
            .contains(&DeviceEvent::ArEnded(ArEnd::Aborted(abort))),
        "{:?}",
        p.dev_events
    );
}

#[test]
fn hello_and_get_answer_with_the_identity() {
    let mut c = DeviceConfig::new(spec(), "PSD426", DEV_MAC, NAME).unwrap();
    c.hello = true;
    c.ip = DEV_IP;
    let mut d = Device::new(spec(), c).unwrap();
    let hello = d.poll_transmit(Duration::ZERO).unwrap();
    assert_eq!(&hello[..6], &eth::DCP_HELLO_MAC);
    assert_eq!(&hello[14..16], &[0xFE, 0xFC]);
    assert!(hello.windows(NAME.len()).any(|w| w == NAME.as_bytes()));
    // Get of DeviceID and an unsupported suboption.
    let pdu = dcp::pdu(
        FrameId::DCP_GET_SET,
        service::GET,
        service_type::REQUEST,
        3,
        0,
        &[2, 3, 2, 9],
    );
    d.handle_frame(
        Duration::ZERO,
        &eth::frame(DEV_MAC, CTL_MAC, None, ethertype::PROFINET, &pdu),
    );
    let res = d.poll_transmit(Duration::ZERO).unwrap();
    let id = Identity::from_spec(spec()).unwrap();
    let l = drivespec_capture::link::parse_ethernet(&res).unwrap();
    let h = drivespec_capture::rt::RtFrame::parse(l.payload)
        .unwrap()
        .dcp()
        .unwrap();
    let blocks: Vec<_> = h.iter_blocks().map(Result::unwrap).collect();
    assert_eq!((blocks[0].option, blocks[0].suboption), opt::DEVICE_ID);
    assert_eq!(&blocks[0].data[2..4], &id.vendor_id.to_be_bytes());
    assert_eq!(&blocks[0].data[4..6], &id.device_id.to_be_bytes());
    assert_eq!(
        (blocks[1].option, blocks[1].suboption),
        opt::CONTROL_RESPONSE
    );
    assert_eq!(blocks[1].data, &[2, 9, dcp::block_error::SUBOPTION][..]);
}

#[test]
fn a_call_to_another_interface_is_rejected() {
    use drivespec_capture::dcerpc::{self, PacketType, Uuid};
    use drivespec_profinet::{rpc, udp};
    let mut d = device();
    // The endpoint mapper (C706 appendix L: E1AF8308-5D1F-11C9-91A4-08002B14A0FA).
    let epm = Uuid([
        0xE1, 0xAF, 0x83, 0x08, 0x5D, 0x1F, 0x11, 0xC9, 0x91, 0xA4, 0x08, 0x00, 0x2B, 0x14, 0xA0,
        0xFA,
    ]);
    let h = rpc::request_header(Uuid::default(), epm, Uuid([7; 16]), 0, 2);
    let ep = udp::Endpoints {
        src: CTL_IP,
        src_port: 0xC001,
        dst: DEV_IP,
        dst_port: PNIO_PORT,
    };
    let ip = udp::ipv4_udp(ep, 1, &rpc::encode(&h, &[0; 16]));
    d.handle_frame(
        Duration::ZERO,
        &eth::frame(DEV_MAC, CTL_MAC, None, ethertype::IPV4, &ip),
    );
    let res = d.poll_transmit(Duration::ZERO).unwrap();
    let l = drivespec_capture::link::parse_ethernet(&res).unwrap();
    let u = drivespec_capture::ip::parse_ipv4_udp(l.payload).unwrap();
    assert_eq!((u.dst, u.dst_port), (CTL_IP, 0xC001));
    let p = dcerpc::parse(u.payload).unwrap();
    assert_eq!(p.header.ptype, PacketType::REJECT);
    assert_eq!(p.header.activity, Uuid([7; 16]));
    assert_eq!(p.body, &0x1C01_0003u32.to_le_bytes()[..]);
}

#[test]
fn records_need_the_ar_and_an_existing_subslot() {
    let mut p = Pair::running(controller_config());
    let rid = p.ctl.read_record(p.now, 9, 1, 1).unwrap();
    let want = PnioStatus {
        code: 0xDE,
        decode: 0x80,
        code1: 0xB2,
        code2: 0,
    };
    assert_eq!(
        p.record(rid),
        Err(ControllerError::Refused {
            operation: "Read",
            status: want
        })
    );
    // I&M0 cannot be written.
    let rid = p.ctl.write_record(p.now, 0, 1, 0xAFF0, &[0; 4]).unwrap();
    let want = PnioStatus {
        code: 0xDF,
        decode: 0x80,
        code1: 0xB6,
        code2: 0,
    };
    assert_eq!(
        p.record(rid),
        Err(ControllerError::Refused {
            operation: "Write",
            status: want
        })
    );
}

#[test]
fn a_device_without_name_gets_it_by_dcp_set_from_a_controller_that_knows_its_mac() {
    let mut c = DeviceConfig::new(spec(), "PSD426", DEV_MAC, "").unwrap();
    c.ip = DEV_IP;
    let mut unknown = Pair::new(controller_config());
    unknown.dev = Device::new(spec(), c.clone()).unwrap();
    unknown.run_until(Duration::from_secs(30), |p| p.ctl.is_closed());
    assert_eq!(
        unknown.ctl_events.last(),
        Some(&ControllerEvent::Failed(ControllerError::NoSuchStation(
            NAME.into()
        )))
    );
    let mut cc = controller_config();
    cc.name_device = Some(DEV_MAC);
    let mut p = Pair::new(cc);
    p.dev = Device::new(spec(), c).unwrap();
    assert!(
        p.run_until(Duration::from_secs(30), |p| p.ctl.is_running()),
        "{:?}",
        p.ctl_events
    );
    assert_eq!(p.dev.station_name(), NAME);
    assert!(p.dev_events.contains(&DeviceEvent::NameSet(NAME.into())));
}

#[test]
fn par_96_minus_3_deletes_the_station_name() {
    let mut p = Pair::running(controller_config());
    let id = Identity::from_spec(spec()).unwrap();
    let data = RecordWrite {
        index: 96,
        control: 1,
        width: Width::Word,
        value: -3,
    }
    .to_bytes(rules().record())
    .unwrap();
    let rid = p
        .ctl
        .write_record(p.now, id.output.slot, id.output.subslot, 96, &data)
        .unwrap();
    assert_eq!(p.record(rid), Ok(Vec::new()));
    assert_eq!(p.dev.station_name(), "");
    assert!(p.dev_events.contains(&DeviceEvent::NameSet(String::new())));
}

#[test]
fn parameter_records_are_written_before_prm_end() {
    let mut c = controller_config();
    let data = RecordWrite {
        index: 44,
        control: 1,
        width: Width::Word,
        value: 9,
    }
    .to_bytes(rules().record())
    .unwrap();
    // Control byte 0: the drive ignores the write (3.2.2).
    let ignored = RecordWrite {
        index: 45,
        control: 0,
        width: Width::Dword,
        value: 123,
    }
    .to_bytes(rules().record())
    .unwrap();
    c.prm_records = vec![(44, data), (45, ignored)];
    let before = device().drive().parameter(45);
    let p = Pair::running(c);
    assert_eq!(p.dev.drive().parameter(44), Ok(9));
    assert_eq!(p.dev.drive().parameter(45), before);
    let prm_end = p
        .dev_events
        .iter()
        .position(|e| *e == DeviceEvent::PrmEnd)
        .unwrap();
    assert!(prm_end > 0);
}

#[test]
fn a_refused_parameter_record_stops_the_start_up() {
    let mut c = controller_config();
    c.prm_records = vec![(0x7FFF, vec![1, 0, 0])];
    let mut p = Pair::new(c);
    p.run_until(Duration::from_secs(5), |p| p.ctl.is_closed());
    let want = PnioStatus {
        code: 0xDF,
        decode: 0x80,
        code1: 0xB0,
        code2: 0,
    };
    assert!(
        p.ctl_events.iter().any(|e| matches!(
            e,
            ControllerEvent::Failed(ControllerError::Refused { status, .. }) if *status == want
        )),
        "{:?}",
        p.ctl_events
    );
    assert!(!p.dev_events.contains(&DeviceEvent::PrmEnd));
}

#[test]
fn both_stations_answer_arp_for_their_address() {
    use drivespec_capture::arp::{parse_arp, Arp, REPLY, REQUEST};
    let asker = [0x02, 0, 0, 0, 0, 9];
    let ask = |ip| {
        drivespec_profinet::arp::frame(
            eth::BROADCAST,
            &Arp {
                operation: REQUEST,
                sender_mac: asker,
                sender_ip: [192, 168, 10, 9],
                target_mac: [0; 6],
                target_ip: ip,
            },
        )
    };
    let mut d = device();
    d.handle_frame(Duration::ZERO, &ask(DEV_IP));
    let res = d.poll_transmit(Duration::ZERO).unwrap();
    assert_eq!(&res[..6], &asker);
    let a = parse_arp(&res[14..]).unwrap();
    assert_eq!(
        (a.operation, a.sender_mac, a.sender_ip),
        (REPLY, DEV_MAC, DEV_IP)
    );
    d.handle_frame(Duration::ZERO, &ask([192, 168, 10, 77]));
    assert_eq!(d.poll_transmit(Duration::ZERO), None, "not its address");
    let mut c = Controller::new(controller_config());
    c.handle_frame(Duration::ZERO, &ask(CTL_IP));
    let res = c.poll_transmit(Duration::ZERO).unwrap();
    assert_eq!(parse_arp(&res[14..]).unwrap().sender_mac, CTL_MAC);
}

#[test]
fn a_ping_gets_the_answer_again_or_nocall() {
    use drivespec_capture::dcerpc::{self, PacketType, Uuid};
    use drivespec_profinet::{rpc, udp};
    let mut p = Pair::running(controller_config());
    // The Connect call: its activity and sequence from the recording.
    let (_, connect) = p
        .frames
        .iter()
        .find(|(_, f)| f.get(..6) == Some(&DEV_MAC[..]) && f.get(12..14) == Some(&[0x08, 0x00][..]))
        .unwrap()
        .clone();
    let l = drivespec_capture::link::parse_ethernet(&connect).unwrap();
    let u = drivespec_capture::ip::parse_ipv4_udp(l.payload).unwrap();
    let call = dcerpc::parse(u.payload).unwrap().header;
    let ping = |seq: u32| {
        let mut h = rpc::request_header(call.object, Uuid::PNIO_DEVICE, call.activity, seq, 0);
        h.ptype = PacketType::PING;
        let ep = udp::Endpoints {
            src: CTL_IP,
            src_port: 0xC001,
            dst: DEV_IP,
            dst_port: PNIO_PORT,
        };
        eth::frame(
            DEV_MAC,
            CTL_MAC,
            None,
            ethertype::IPV4,
            &udp::ipv4_udp(ep, 1, &rpc::encode(&h, &[])),
        )
    };
    let answer = |d: &mut Device, f: &[u8]| {
        d.handle_frame(p.now, f);
        let res = d.poll_transmit(p.now).unwrap();
        let l = drivespec_capture::link::parse_ethernet(&res).unwrap();
        let u = drivespec_capture::ip::parse_ipv4_udp(l.payload).unwrap();
        dcerpc::parse(u.payload).unwrap().header
    };
    let mut d = p.dev.clone();
    let again = answer(&mut d, &ping(call.sequence));
    assert_eq!(
        (again.ptype, again.sequence, again.opnum),
        (PacketType::RESPONSE, call.sequence, 0)
    );
    let unknown = answer(&mut d, &ping(call.sequence + 1000));
    assert_eq!(unknown.ptype, PacketType::NOCALL);
    p.run_for(Duration::from_millis(1));
}

#[test]
fn an_unknown_operation_is_rejected() {
    use drivespec_capture::dcerpc::{self, PacketType, Uuid};
    use drivespec_profinet::{cm, rpc, udp};
    let mut d = device();
    let h = rpc::request_header(Uuid::default(), Uuid::PNIO_DEVICE, Uuid([7; 16]), 0, 9);
    let body = cm::request(4096, &[], drivespec_capture::Endian::Little);
    let ep = udp::Endpoints {
        src: CTL_IP,
        src_port: 0xC001,
        dst: DEV_IP,
        dst_port: PNIO_PORT,
    };
    let ip = udp::ipv4_udp(ep, 1, &rpc::encode(&h, &body));
    d.handle_frame(
        Duration::ZERO,
        &eth::frame(DEV_MAC, CTL_MAC, None, ethertype::IPV4, &ip),
    );
    let res = d.poll_transmit(Duration::ZERO).unwrap();
    let l = drivespec_capture::link::parse_ethernet(&res).unwrap();
    let u = drivespec_capture::ip::parse_ipv4_udp(l.payload).unwrap();
    let p = dcerpc::parse(u.payload).unwrap();
    assert_eq!(p.header.ptype, PacketType::REJECT);
    assert_eq!(p.body, &0x1C01_0002u32.to_le_bytes()[..]);
}

/// The device's Connect response with a ModuleDiffBlock appended that lists `diff`.
fn with_diff(frame: Vec<u8>, diff: drivespec_capture::pnio::ModuleDiff) -> Vec<u8> {
    use drivespec_capture::dcerpc::{self, PacketType};
    use drivespec_capture::pnio::{self, Operation};
    use drivespec_profinet::{cm, rpc, udp};
    let Ok(l) = drivespec_capture::link::parse_ethernet(&frame) else {
        return frame;
    };
    let Ok(u) = drivespec_capture::ip::parse_ipv4_udp(l.payload) else {
        return frame;
    };
    let Ok(p) = dcerpc::parse(u.payload) else {
        return frame;
    };
    let h = p.header;
    let Ok(m) = pnio::decode_body(h.ptype, h.opnum, h.drep.integer, p.body) else {
        return frame;
    };
    if h.ptype != PacketType::RESPONSE || m.operation != Operation::Connect {
        return frame;
    }
    let mut blocks = p.body[20..].to_vec();
    let mut extra = cm::Blocks::new();
    extra.module_diff(&diff);
    blocks.extend_from_slice(&extra.into_bytes());
    let body = cm::response(PnioStatus::default(), &blocks, h.drep.integer);
    let ep = udp::Endpoints {
        src: u.src,
        src_port: u.src_port,
        dst: u.dst,
        dst_port: u.dst_port,
    };
    eth::frame(
        l.dst.unwrap(),
        l.src.unwrap(),
        None,
        ethertype::IPV4,
        &udp::ipv4_udp(ep, 1, &rpc::encode(&h, &body)),
    )
}

#[test]
fn a_module_diff_that_only_reports_state_is_accepted() {
    use drivespec_capture::pnio::{DiffModule, DiffSubmodule, ModuleDiff};
    let mut p = Pair::new(controller_config());
    // Proper module, submodule with ARInfo ApplicationReadyPending (format 1, bits 7-10 = 1).
    p.rewrite = |f| {
        with_diff(
            f,
            ModuleDiff {
                modules: vec![DiffModule {
                    api: 0,
                    slot: 1,
                    ident: 0x101,
                    state: 2,
                    submodules: vec![DiffSubmodule {
                        subslot: 1,
                        ident: 1,
                        state: 0x8000 | (1 << 7),
                    }],
                }],
            },
        )
    };
    assert!(
        p.run_until(Duration::from_secs(5), |p| p.ctl.is_running()),
        "{:?}",
        p.ctl_events
    );
    // A wrong submodule (IdentInfo Wrong) is not.
    let mut p = Pair::new(controller_config());
    p.rewrite = |f| {
        with_diff(
            f,
            ModuleDiff {
                modules: vec![DiffModule {
                    api: 0,
                    slot: 2,
                    ident: 0x102,
                    state: 2,
                    submodules: vec![DiffSubmodule {
                        subslot: 1,
                        ident: 5,
                        state: 0x8000 | (2 << 11),
                    }],
                }],
            },
        )
    };
    p.run_until(Duration::from_secs(5), |p| p.ctl.is_closed());
    assert!(
        matches!(
            p.ctl_events.last(),
            Some(ControllerEvent::Failed(ControllerError::ModuleDiff(_)))
        ),
        "{:?}",
        p.ctl_events
    );
}

/// Runs `tshark` on `pcap` with a display filter; `None` when tshark is not installed.
fn tshark_lines(pcap: &[u8], filter: &str) -> Option<Vec<String>> {
    use std::process::Command;
    if Command::new("tshark").arg("--version").output().is_err() {
        return None;
    }
    let path = std::env::temp_dir().join(format!(
        "drivespec-profinet-{}-{filter:.8}.pcap",
        std::process::id()
    ));
    std::fs::write(&path, pcap).unwrap();
    let out = Command::new("tshark")
        .arg("-n")
        .arg("-r")
        .arg(&path)
        .arg("-Y")
        .arg(filter)
        .output()
        .unwrap();
    std::fs::remove_file(&path).unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(
        String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(str::to_owned)
            .collect(),
    )
}

/// Wireshark, an independent decoder, reads every frame both stations send (start-up,
/// cyclic data, records, refusals, ModuleDiff, DCP, ARP, aborts) without a malformed frame
/// or an expert note, warning or error. Runs where `tshark` is installed, says "skipped" otherwise.
#[test]
fn tshark_decodes_every_frame_without_malformed_or_expert_info() {
    let id = Identity::from_spec(spec()).unwrap();
    let mut frames = Vec::new();
    // A whole session with records, a refusal and a watchdog abort.
    let mut p = Pair::running(controller_config());
    p.ctl.set_output(&output(
        Request::Read {
            pnu: 13,
            index: None,
        },
        0x54,
        400,
    ));
    p.run_for(Duration::from_millis(30));
    for index in [1, 13, 0x7FFF] {
        let rid = p
            .ctl
            .read_record(p.now, id.output.slot, id.output.subslot, index)
            .unwrap();
        let _ = p.record(rid);
    }
    let rid = p.ctl.read_record(p.now, id.dap_slot, 1, 0xAFF0).unwrap();
    p.record(rid).unwrap();
    let data = RecordWrite {
        index: 44,
        control: 1,
        width: Width::Word,
        value: 7,
    }
    .to_bytes(rules().record())
    .unwrap();
    let rid = p
        .ctl
        .write_record(p.now, id.output.slot, id.output.subslot, 44, &data)
        .unwrap();
    p.record(rid).unwrap();
    p.ctl.set_sending(false);
    p.run_until(p.now + Duration::from_secs(1), |p| p.ctl.is_closed());
    frames.extend(p.frames);
    // A ModuleDiff and its Release; a refused Connect.
    let mut c = controller_config();
    c.identity.output.module_ident = 0x999;
    let mut p = Pair::new(c);
    p.run_until(Duration::from_secs(5), |p| p.ctl.is_closed());
    p.run_for(Duration::from_millis(5));
    frames.extend(p.frames);
    let mut c = controller_config();
    c.send_clock_factor = 9;
    let mut p = Pair::new(c);
    p.run_until(Duration::from_secs(5), |p| p.ctl.is_closed());
    frames.extend(p.frames);
    // DCP Hello, Set, Get and an ARP answer.
    let mut dc = DeviceConfig::new(spec(), "PSD426", DEV_MAC, NAME).unwrap();
    dc.hello = true;
    dc.ip = DEV_IP;
    let mut d = Device::new(spec(), dc).unwrap();
    let mut set = DcpBlocks::new();
    set.with_info(opt::NAME_OF_STATION, dcp::PERMANENT, b"psd-07");
    let requests = [
        eth::frame(
            DEV_MAC,
            CTL_MAC,
            None,
            ethertype::PROFINET,
            &dcp::pdu(
                FrameId::DCP_GET_SET,
                service::SET,
                service_type::REQUEST,
                9,
                0,
                &set.into_bytes(),
            ),
        ),
        eth::frame(
            DEV_MAC,
            CTL_MAC,
            None,
            ethertype::PROFINET,
            &dcp::pdu(
                FrameId::DCP_GET_SET,
                service::GET,
                service_type::REQUEST,
                10,
                0,
                &[2, 2, 2, 3, 1, 2, 2, 9],
            ),
        ),
        drivespec_profinet::arp::frame(
            eth::BROADCAST,
            &drivespec_capture::arp::Arp {
                operation: drivespec_capture::arp::REQUEST,
                sender_mac: CTL_MAC,
                sender_ip: CTL_IP,
                target_mac: [0; 6],
                target_ip: DEV_IP,
            },
        ),
    ];
    while let Some(f) = d.poll_transmit(Duration::ZERO) {
        frames.push((Duration::ZERO, f));
    }
    for r in requests {
        d.handle_frame(Duration::ZERO, &r);
        frames.push((Duration::ZERO, r));
        while let Some(f) = d.poll_transmit(Duration::ZERO) {
            frames.push((Duration::ZERO, f));
        }
    }
    let mut w = PcapWriter::new(Vec::new(), LinkType::ETHERNET, 65535).unwrap();
    for (i, (_, f)) in frames.iter().enumerate() {
        w.write_packet(T0_US + i as u64, f).unwrap();
    }
    let pcap = w.into_inner().unwrap();
    // Expert notes of severity "chat" (e.g. the BlockError of a refused DCP Get) describe
    // the exchange; notes, warnings and errors would mean a frame Wireshark finds wrong.
    let Some(bad) = tshark_lines(&pcap, "_ws.malformed || _ws.expert.severity >= 0x00400000")
    else {
        eprintln!("skipped: tshark is not installed");
        return;
    };
    assert!(bad.is_empty(), "{bad:#?}");
    let all = tshark_lines(&pcap, "frame").unwrap();
    assert_eq!(all.len(), frames.len());
    let known = tshark_lines(&pcap, "pn_dcp || pn_rt || dcerpc || arp").unwrap();
    assert_eq!(
        known.len(),
        frames.len(),
        "every frame is PROFINET, DCE/RPC or ARP to Wireshark"
    );
    let cm = tshark_lines(&pcap, "pn_io").unwrap();
    assert!(cm.len() >= 20, "{cm:#?}");
}

#[test]
fn alarm_notifications_are_acknowledged() {
    use drivespec_capture::rt::RtFrame;
    use drivespec_profinet::rt;
    let mut p = Pair::running(controller_config());
    let note = |seq: u16| {
        // AlarmNotification low: diagnosis (1), API 0, slot 1/1, idents, specifier 0x0801.
        let mut body = vec![0x00, 0x01, 0, 0, 0, 0, 0, 1, 0, 1];
        body.extend_from_slice(&0x101u32.to_be_bytes());
        body.extend_from_slice(&1u32.to_be_bytes());
        body.extend_from_slice(&[0x08, 0x01, 0xAA]);
        let mut b = drivespec_profinet::cm::Blocks::new();
        b.other(0x0001, &body);
        let pdu = rt::alarm(
            FrameId::ALARM_LOW,
            3,
            1,
            rt::pdu_type::DATA,
            seq,
            0xFFFE,
            &b.into_bytes(),
        );
        eth::frame(CTL_MAC, DEV_MAC, None, ethertype::PROFINET, &pdu)
    };
    let alarms = |p: &mut Pair| -> Vec<(u8, u16, u16, Vec<u8>)> {
        std::iter::from_fn(|| p.ctl.poll_transmit(p.now))
            .filter_map(|f| {
                let l = drivespec_capture::link::parse_ethernet(&f).ok()?;
                let a = RtFrame::parse(l.payload).ok()?.alarm().ok()?;
                Some((a.pdu_type, a.send_seq, a.ack_seq, a.var_part.to_vec()))
            })
            .collect()
    };
    p.ctl.handle_frame(p.now, &note(0xFFFF));
    let sent = alarms(&mut p);
    assert_eq!(sent.len(), 2, "{sent:?}");
    assert_eq!(
        (sent[0].0, sent[0].1, sent[0].2),
        (rt::pdu_type::ACK, 0xFFFE, 0xFFFF)
    );
    let (t, s, a, ack) = &sent[1];
    assert_eq!((*t, *s, *a), (rt::pdu_type::DATA, 0xFFFF, 0xFFFF));
    // AlarmAck low (0x8001): AlarmType, API, slot, subslot, specifier, PNIOStatus OK.
    assert_eq!(&ack[..2], &[0x80, 0x01]);
    assert_eq!(
        &ack[6..],
        &[0, 1, 0, 0, 0, 0, 0, 1, 0, 1, 0x08, 0x01, 0, 0, 0, 0]
    );
    let n = p
        .ctl_events
        .iter()
        .chain(
            std::iter::from_fn(|| p.ctl.poll_event())
                .collect::<Vec<_>>()
                .iter(),
        )
        .find_map(|e| match e {
            ControllerEvent::Alarm(n) => Some(n.clone()),
            _ => None,
        });
    let n = n.expect("an alarm event");
    assert_eq!(
        (
            n.alarm_type,
            n.slot,
            n.subslot,
            n.specifier,
            n.items.as_slice()
        ),
        (1, 1, 1, 0x0801, &[0xAA][..])
    );
    // The same notification again: only the ACK is repeated.
    p.ctl.handle_frame(p.now, &note(0xFFFF));
    let again = alarms(&mut p);
    assert_eq!(again.len(), 1);
    assert_eq!(again[0].0, rt::pdu_type::ACK);
    // The device acknowledges the AlarmAck; the next notification (SendSeqNum 0) is new.
    let ack = rt::alarm(
        FrameId::ALARM_LOW,
        3,
        1,
        rt::pdu_type::ACK,
        0xFFFE,
        0xFFFF,
        &[],
    );
    p.ctl.handle_frame(
        p.now,
        &eth::frame(CTL_MAC, DEV_MAC, None, ethertype::PROFINET, &ack),
    );
    p.ctl.handle_frame(p.now, &note(0));
    let next = alarms(&mut p);
    assert_eq!(next.len(), 2);
    assert_eq!(
        (next[0].0, next[0].1, next[0].2),
        (rt::pdu_type::ACK, 0xFFFF, 0)
    );
    assert_eq!(
        (next[1].0, next[1].1, next[1].2),
        (rt::pdu_type::DATA, 0, 0)
    );
    assert!(p.ctl.is_running());
}

#[test]
fn cyclic_frames_follow_send_clock_times_reduction_ratio() {
    use drivespec_capture::rt::RtFrame;
    for (scf, rr) in [(8u16, 1u16), (16, 4), (32, 2), (128, 1)] {
        let mut c = controller_config();
        c.send_clock_factor = scf;
        c.reduction_ratio = rr;
        let mut p = Pair::running(c);
        let start = p.frames.len();
        p.run_for(Duration::from_millis(100));
        let period = u64::from(scf) * u64::from(rr) * 31_250;
        for from_device in [true, false] {
            let src = if from_device { DEV_MAC } else { CTL_MAC };
            let frames: Vec<(u64, u16)> = p.frames[start..]
                .iter()
                .filter(|(_, f)| f.get(6..12) == Some(&src[..]))
                .filter_map(|(t, f)| {
                    let l = drivespec_capture::link::parse_ethernet(f).ok()?;
                    let c = RtFrame::parse(l.payload).ok()?.cyclic().ok()?;
                    Some((t.as_nanos() as u64, c.apdu.cycle_counter))
                })
                .collect();
            assert!(
                frames.len() as u64 >= 100_000_000 / period - 1,
                "SCF {scf} RR {rr}: {} frames",
                frames.len()
            );
            for w in frames.windows(2) {
                assert_eq!(w[1].0 - w[0].0, period, "SCF {scf} RR {rr}: interval");
                assert_eq!(
                    w[1].1.wrapping_sub(w[0].1),
                    scf * rr,
                    "SCF {scf} RR {rr}: cycle counter"
                );
            }
        }
    }
}

#[test]
fn a_device_accepts_a_new_connect_after_release_and_after_an_abort() {
    let mut p = Pair::running(controller_config());
    p.ctl.release(p.now).unwrap();
    p.run_until(p.now + Duration::from_secs(2), |p| p.ctl.is_closed());
    let mut second = controller_config();
    second.ar_uuid.0[0] ^= 0xFF;
    p.ctl = Controller::new(second.clone());
    p.ctl.start(p.now);
    let limit = p.now + Duration::from_secs(5);
    assert!(
        p.run_until(limit, |p| p.ctl.is_running()),
        "after Release: {:?}",
        p.ctl_events
    );
    // The controller falls silent: the device's watchdog ends the AR.
    p.ctl.set_sending(false);
    p.run_until(p.now + Duration::from_secs(1), |p| p.ctl.is_closed());
    assert_eq!(p.dev.ar_state(), None);
    second.ar_uuid.0[1] ^= 0xFF;
    p.ctl = Controller::new(second);
    p.ctl.start(p.now);
    let limit = p.now + Duration::from_secs(5);
    assert!(
        p.run_until(limit, |p| p.ctl.is_running()),
        "after the watchdog: {:?}",
        p.ctl_events
    );
}

#[test]
fn the_same_controller_can_connect_again_after_release() {
    let mut p = Pair::running(controller_config());
    p.ctl.release(p.now).unwrap();
    p.run_until(p.now + Duration::from_secs(2), |p| p.ctl.is_closed());
    p.ctl = Controller::new(controller_config());
    p.ctl.start(p.now);
    let limit = p.now + Duration::from_secs(5);
    assert!(
        p.run_until(limit, |p| p.ctl.is_running()),
        "{:?}",
        p.ctl_events
    );
    assert_eq!(p.dev.ar_state(), Some(true));
}
