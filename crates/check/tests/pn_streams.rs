//! Generic PROFINET stream checks on hand-made cyclic streams: frames missing are counted by
//! the capture time as well as the cycle counter, so a counter glitch loses no frame.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_capture::profinet::Events;
use drivespec_capture::write::PcapWriter;
use drivespec_capture::{CaptureReader, LinkType};
use drivespec_check::profinet::{check, PnOptions};
use drivespec_check::synth::profinet::{ethernet, rt_cyclic, CONTROLLER_MAC, DEVICE_MAC};
use drivespec_spec::Spec;

/// A 1 ms stream (32 counts per frame) with the given counters, one frame per `times` µs.
fn stream(frames: &[(u16, u64)]) -> Vec<u8> {
    let mut w = PcapWriter::new(Vec::new(), LinkType::ETHERNET, 65535).unwrap();
    for (counter, t) in frames {
        let f = ethernet(
            DEVICE_MAC,
            CONTROLLER_MAC,
            0x8892,
            &rt_cyclic(0x8001, &[0x80; 4], 40, *counter, 0x35),
        );
        w.write_packet(1_700_000_000_000_000 + t, &f).unwrap();
    }
    w.into_inner().unwrap()
}

fn missing(frames: &[(u16, u64)]) -> (u64, u64) {
    let spec = Spec::builtin().unwrap();
    let bytes = stream(frames);
    let r = check(
        &spec,
        PnOptions::default(),
        Events::new(CaptureReader::new(&bytes[..]).unwrap()),
    )
    .unwrap();
    (r.streams[0].missing, r.streams[0].gaps)
}

#[test]
fn a_counter_glitch_loses_no_frame_and_a_real_gap_counts_its_frames() {
    let mut frames: Vec<(u16, u64)> = (0..20u16).map(|i| (i * 32, u64::from(i) * 1000)).collect();
    // Frame 21 one cycle later, its counter 4 cycles on; then the stream goes on.
    frames.push((20 * 32 + 3 * 32, 20_000));
    frames.extend((21..30u16).map(|i| (i * 32 + 3 * 32, u64::from(i) * 1000 + 3000)));
    assert_eq!(missing(&frames), (0, 0), "a glitch");
    // Three frames really missing: counter and time agree.
    let mut frames: Vec<(u16, u64)> = (0..20u16).map(|i| (i * 32, u64::from(i) * 1000)).collect();
    frames.extend((23..30u16).map(|i| (i * 32, u64::from(i) * 1000)));
    assert_eq!(missing(&frames), (3, 1), "a gap");
}
