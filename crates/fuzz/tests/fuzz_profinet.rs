//! `fuzz psd4xx --layer profinet` in memory, on a virtual clock: the reference device passes
//! every liveness probe; a device with a planted fault (it restarts after a malformed DCP
//! Identify) is found, minimised to that Identify, and the replay reproduces it; the same
//! seed gives the same replay byte for byte.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_conform::dut::Dut;
use drivespec_conform::Progress;
use drivespec_fuzz::profinet::{MemoryWire, PnStep};
use drivespec_fuzz::{self as fuzz, Action, Device, Layer, Options, Replay};
use drivespec_implementations::profinet_faults::{reference, RestartOnMalformedIdentify};
use drivespec_implementations::spec;
use drivespec_spec::FamilyId;
use std::path::PathBuf;

const STATION: &str = "psd426-fuzzed";
const DEVICE: ([u8; 6], [u8; 4]) = ([0x02, 0, 0, 0, 0x26, 0x01], [192, 168, 26, 2]);
const FUZZER: ([u8; 6], [u8; 4]) = ([0x02, 0, 0, 0, 0x26, 0x02], [192, 168, 26, 1]);

fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("drivespec-pnfuzz-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn opts(out: PathBuf, iterations: u64) -> Options {
    Options {
        family: FamilyId::Psd4xx,
        layer: Layer::Profinet,
        dut: Dut::Sim { model: None },
        iterations: Some(iterations),
        out_dir: out,
        progress: Progress::Quiet,
        max_findings: 3,
        ..Options::default()
    }
}

fn faulty() -> Device {
    let device = reference(spec(), "PSD426", DEVICE.0, DEVICE.1, STATION);
    Device::Profinet(Box::new(MemoryWire::new(
        Box::new(move || RestartOnMalformedIdentify::new(device.clone())),
        FUZZER,
        STATION,
        "faulty PSD426 in memory",
    )))
}

fn correct() -> Device {
    let device = reference(spec(), "PSD426", DEVICE.0, DEVICE.1, STATION);
    Device::Profinet(Box::new(MemoryWire::new(
        Box::new(move || device.clone()),
        FUZZER,
        STATION,
        "PSD426 in memory",
    )))
}

#[test]
fn the_reference_device_passes_every_probe() {
    let out = dir("reference");
    let s = fuzz::run(spec(), &opts(out.clone(), 60), &mut std::io::sink()).unwrap();
    assert_eq!(s.exit_code(), 0, "{:#?}", s.stats.findings);
    assert_eq!(s.stats.sequences, 60);
    // Every kind of input was sent.
    for class in [
        "connect",
        "record-read",
        "record-write",
        "rt",
        "dcp-identify-malformed",
    ] {
        assert!(
            s.stats.inputs_by_class.contains_key(class),
            "{class}: {:?}",
            s.stats.inputs_by_class
        );
    }
    let _ = std::fs::remove_dir_all(out);
}

#[test]
fn a_planted_fault_is_found_minimised_and_replayed() {
    let (d1, d2) = (dir("fault-a"), dir("fault-b"));
    let a = fuzz::run_on_device(
        spec(),
        &opts(d1.clone(), 30),
        faulty(),
        &mut std::io::sink(),
    )
    .unwrap();
    assert_eq!(a.exit_code(), 1);
    let f = &a.findings[0];
    assert_eq!(
        f.replay.finding.as_ref().unwrap().signature,
        "hang/profinet-probe/dcp-identify"
    );
    println!(
        "seed 0: found in sequence {}",
        f.replay.finding.as_ref().unwrap().sequence
    );
    // Minimised to the one malformed Identify.
    assert_eq!(f.replay.steps.len(), 1, "{}", f.replay.to_json());
    let Action::Profinet(PnStep::DcpIdentify { blocks }) = &f.replay.steps[0].action else {
        panic!("{:?}", f.replay.steps[0]);
    };
    assert!(!blocks.is_empty());
    // The file reads back and replays: the fault again on the faulty device, nothing on a
    // correct one.
    let file = f.file.clone().unwrap();
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.contains("\"layer\": \"profinet\""), "{text}");
    let r = Replay::load(&file).unwrap();
    let o = opts(d1.clone(), 1);
    let again = fuzz::replay_on_device(spec(), &o, &r, faulty()).unwrap();
    assert_eq!(again.exit_code(), 1);
    assert!(again.same_finding);
    assert!(again.same_as_recorded);
    let fixed = fuzz::replay_on_device(spec(), &o, &r, correct()).unwrap();
    assert_eq!(fixed.exit_code(), 0);
    // The same seed writes the same replay.
    let b = fuzz::run_on_device(
        spec(),
        &opts(d2.clone(), 30),
        faulty(),
        &mut std::io::sink(),
    )
    .unwrap();
    assert_eq!(b.findings[0].replay.to_json(), f.replay.to_json());
    let _ = std::fs::remove_dir_all(d1);
    let _ = std::fs::remove_dir_all(d2);
}

#[test]
fn a_replay_of_another_layer_is_refused() {
    let out = dir("layer");
    let s = fuzz::run_on_device(
        spec(),
        &opts(out.clone(), 30),
        faulty(),
        &mut std::io::sink(),
    )
    .unwrap();
    let r = s.findings[0].replay.clone();
    let mut o = opts(out.clone(), 1);
    o.layer = Layer::Application;
    let e = fuzz::replay_on_device(spec(), &o, &r, faulty()).unwrap_err();
    assert!(e.to_string().contains("--layer profinet"), "{e}");
    let text = r.to_json().replace("\"psd4xx\"", "\"hpd\"");
    assert!(Replay::from_json(&text, "x").is_err());
    let _ = std::fs::remove_dir_all(out);
}

/// The reference device with the frames it sends that `drop` picks lost on the wire.
struct Lossy {
    device: drivespec_profinet::Device,
    drop: fn(&[u8]) -> bool,
}

impl drivespec_profinet::SansIo for Lossy {
    fn handle_frame(&mut self, now: std::time::Duration, frame: &[u8]) {
        self.device.handle_frame(now, frame);
    }
    fn handle_timeout(&mut self, now: std::time::Duration) {
        self.device.handle_timeout(now);
    }
    fn poll_transmit(&mut self, now: std::time::Duration) -> Option<Vec<u8>> {
        loop {
            let f = self.device.poll_transmit(now)?;
            if !(self.drop)(&f) {
                return Some(f);
            }
        }
    }
    fn poll_timeout(&self) -> Option<std::time::Duration> {
        self.device.poll_timeout()
    }
}

fn lossy(drop: fn(&[u8]) -> bool) -> Device {
    let device = reference(spec(), "PSD426", DEVICE.0, DEVICE.1, STATION);
    Device::Profinet(Box::new(MemoryWire::new(
        Box::new(move || Lossy {
            device: device.clone(),
            drop,
        }),
        FUZZER,
        STATION,
        "lossy PSD426 in memory",
    )))
}

#[test]
fn the_probe_names_the_stage_a_device_fails() {
    let out = dir("stages");
    let run = |d: Device| match fuzz::run_on_device(
        spec(),
        &opts(out.clone(), 1),
        d,
        &mut std::io::sink(),
    ) {
        Ok(_) => panic!("a device that fails the probe is a setup error"),
        Err(e) => e.to_string(),
    };
    // No cyclic frame (RT class 1 FrameIDs 0xC000–0xF7FF) reaches the fuzzer.
    let e = run(lossy(|f| {
        f.get(12..14) == Some(&[0x88, 0x92])
            && f.get(14..16)
                .is_some_and(|id| (0xC000..0xF800).contains(&u16::from_be_bytes([id[0], id[1]])))
    }));
    assert!(e.contains("cyclic-data"), "{e}");
    // No IPv4 frame (the PNIO-CM answers) reaches the fuzzer.
    let e = run(lossy(|f| f.get(12..14) == Some(&[0x08, 0x00])));
    assert!(e.contains("connect"), "{e}");
    // Nothing at all.
    let e = run(lossy(|_| true));
    assert!(e.contains("dcp-identify") && e.contains(STATION), "{e}");
    let _ = std::fs::remove_dir_all(out);
}
