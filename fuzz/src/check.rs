//! Fuzz harnesses of the trace checkers (drivespec-check): HPD serial recordings, PROFINET
//! captures, IO-Link logs, and PROFINET event streams with a PSD4xx at a fixed place. The
//! checkers must never panic, must end, and their reports must be consistent: every listed
//! violation counted and tallied under a requirement of the catalogue.

use drivespec_capture::iolink::IoLinkReader;
use drivespec_capture::pcap::Options;
use drivespec_capture::profinet::{Events, PnEvent, PnEventKind};
use drivespec_capture::rt::{ApduStatus, DataStatus, FrameId};
use drivespec_capture::serial::SerialReader;
use drivespec_capture::CaptureReader;
use drivespec_check::hpd::HpdChecker;
use drivespec_check::iolink::IoLinkChecker;
use drivespec_check::profinet::{Manual, PnChecker, PnOptions};
use drivespec_check::{Catalog, Report};
use drivespec_spec::Spec;
use std::sync::{Arc, OnceLock};

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().expect("the built-in spec loads"))
}

/// Built once: every checker of a run shares it, as `drivespec check` does over its files.
fn catalog() -> &'static Arc<Catalog> {
    static CATALOG: OnceLock<Arc<Catalog>> = OnceLock::new();
    CATALOG.get_or_init(|| Arc::new(Catalog::new(spec()).expect("the catalogue builds")))
}

/// The invariants of every report.
fn consistent(r: &Report) {
    assert!(r.violation_count >= r.violations.len() as u64);
    let tallied: u64 = r.requirements.values().map(|t| t.violations).sum();
    assert_eq!(tallied, r.violation_count);
    for v in &r.violations {
        assert!(
            catalog().has(&v.requirement),
            "{} not in the catalogue",
            v.requirement
        );
        assert!(r.requirements.contains_key(&v.requirement));
    }
    let _ = drivespec_check::render::text(std::slice::from_ref(r));
    let _ = drivespec_check::render::json(std::slice::from_ref(r));
}

/// HPD serial checker on any recording (raw, socat, text, serial pcap), with the time-out on.
pub fn hpd(data: &[u8]) {
    let Ok(reader) = SerialReader::open(data) else {
        return;
    };
    let options = drivespec_check::hpd::HpdOptions {
        baud: Some(8),
        max_violations: Some(16),
    };
    let r = HpdChecker::with_catalog(spec(), &options, catalog().clone())
        .expect("a checker builds from the built-in spec")
        .run(reader);
    consistent(&r);
}

/// PROFINET checker on any capture (Connect location and search on).
pub fn profinet(data: &[u8]) {
    let options = Options {
        max_block: 1 << 16,
        max_interfaces: 64,
    };
    let Ok(reader) = CaptureReader::with_options(data, options) else {
        return;
    };
    let pn = PnOptions {
        max_violations: Some(16),
        ..PnOptions::default()
    };
    let r = PnChecker::with_catalog(spec(), pn, catalog().clone())
        .expect("a checker builds from the built-in spec")
        .run(Events::new(reader));
    consistent(&r);
}

/// IO-Link checker on any log (JSON lines or CSV).
pub fn iolink(data: &[u8]) {
    let Ok(reader) = IoLinkReader::open(data) else {
        return;
    };
    let options = drivespec_check::iolink::PsxOptions {
        max_violations: Some(16),
        ..Default::default()
    };
    let r = IoLinkChecker::with_catalog(spec(), options, catalog().clone())
        .expect("a checker builds from the built-in spec")
        .run(reader);
    consistent(&r);
}

/// PSD4xx checks on a stream of cyclic frames built from the input: each 24-byte piece is
/// one frame (byte 0: direction, byte 1: time step, bytes 2–3: cycle counter step, byte 4:
/// DataStatus, then 16 data bytes); the drive sits at offset 0 of FrameIDs 0x8001 / 0x8000.
pub fn psd4xx(data: &[u8]) {
    let pn = PnOptions {
        max_violations: Some(16),
        manual: Some(Manual {
            out_frame: 0x8001,
            in_frame: 0x8000,
            out_offset: 0,
            in_offset: 0,
        }),
        ..PnOptions::default()
    };
    let mut time = 1_000_000u64;
    let mut counters = [0u16; 2];
    let events = data.chunks(24).enumerate().map(|(i, c)| {
        let b = |k: usize| c.get(k).copied().unwrap_or(0);
        let dir = usize::from(b(0) & 1);
        time += u64::from(b(1)) * 100;
        let step = u16::from_le_bytes([b(2), b(3)]);
        if let Some(x) = counters.get_mut(dir) {
            *x = x.wrapping_add(step);
        }
        let payload = c.get(5..).unwrap_or(&[]).to_vec();
        Ok(PnEvent {
            record: i as u64 + 1,
            time: Some(time),
            src: Some([dir as u8; 6]),
            dst: Some([1 - dir as u8; 6]),
            kind: PnEventKind::Cyclic {
                frame_id: FrameId(0x8000 + 1 - dir as u16),
                data: payload,
                apdu: ApduStatus {
                    cycle_counter: counters.get(dir).copied().unwrap_or(0),
                    data_status: DataStatus(b(4)),
                    transfer_status: 0,
                },
            },
        })
    });
    let r = PnChecker::with_catalog(spec(), pn, catalog().clone())
        .expect("a checker builds from the built-in spec")
        .run(events);
    consistent(&r);
}
