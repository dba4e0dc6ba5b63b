//! Readable traces of the PSx3xx reference model (time, position, speed, status word, run),
//! kept as insta snapshots: a time-stamp positioning with the loop of 4.2 case 2 (4.4.1), a
//! block with the same-target restart of 5.3 in the 6-byte format, and a snap-brake drive
//! (5.12) that loses its master and runs to the safe position (5.9 case 3).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

mod model_util;

use drivespec_positioner::EnvChange;
use drivespec_psx3xx::model::{BrakeKind, DriveConfig, LinkEvent};
use model_util::*;

#[test]
fn trace_timestamp_positioning_with_loop() {
    let mut s = Sim::new("PSE312-8");
    s.write_ok(116, 0);
    s.write_ok(193, 1);
    s.write_ok(2, 128);
    s.record = true;
    s.f0(0, 0x3FFF);
    s.write_ok(112, 50_000);
    s.f0(3, 10_000);
    s.run_ms(16);
    s.f0(3, 0x3FFF);
    s.run_ms(50);
    s.settle(30_000);
    assert_eq!(s.actual(), 50_000);
    insta::assert_snapshot!(s.trace_text(250));
}

#[test]
fn trace_block_and_same_target_restart() {
    let mut s = Sim::new("PSE312-8");
    s.record = true;
    s.f1(0x14, 52_000);
    s.run_ms(300);
    s.env(EnvChange::Jam { on: true });
    s.until(2_000, |d| d.status_word() >> 10 & 1 == 1);
    s.env(EnvChange::Jam { on: false });
    s.run_ms(100);
    s.f1(0x00, 52_000);
    s.run_ms(16);
    s.f1(0x14, 52_000);
    s.settle(30_000);
    assert_eq!(s.actual(), 52_000);
    insta::assert_snapshot!(s.trace_text(250));
}

#[test]
fn trace_snap_brake_and_master_timeout_to_the_safe_position() {
    let mut s = Sim::with(DriveConfig::new("PSE322-14").with_brake(BrakeKind::Snap));
    s.write_ok(118, 200);
    s.write_ok(137, 2);
    s.write_ok(138, 50_000);
    s.record = true;
    // ISDU 164 wait, the run, ISDU 165 with the brake open.
    s.f1(0x14, 53_000);
    s.settle(30_000);
    s.run_ms(1_000);
    // The master goes silent: after ISDU 118 the drive waits for the brake again and runs to
    // ISDU 138 without loop (DECISION of the model, PSX-TIMEOUT-005).
    s.link(LinkEvent::Lost);
    s.run_ms(250);
    s.settle(60_000);
    assert_eq!(s.actual(), 50_000);
    insta::assert_snapshot!(s.trace_text(250));
}
