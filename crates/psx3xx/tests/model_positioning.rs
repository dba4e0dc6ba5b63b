//! Positioning scenarios of the PSx3xx manual chapter 4 on the reference model: the loop
//! cases of 4.2, time-stamp sequences of 4.4, the 6- and 8-byte formats of 4.5/4.6 and the
//! speed rules of 4.6.4 and 5.1. Each test names the requirement IDs it covers.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

mod model_util;

use drivespec_positioner::CoreEvent;
use drivespec_psx3xx::model::{DriveConfig, Event, RunState};
use model_util::*;

fn waypoints(s: &mut Sim) -> Vec<Vec<i64>> {
    let mut out = Vec::new();
    while let Some((_, e)) = s.drive.poll_event() {
        if let Event::Core(CoreEvent::RunStarted { waypoints, .. }) = e {
            out.push(waypoints);
        }
    }
    out
}

fn format(model: &str, f: i64) -> Sim {
    let mut s = Sim::with(DriveConfig::new(model));
    s.write_ok(116, f);
    s.write_ok(193, 1);
    s.write_ok(2, 128);
    assert_eq!(i64::from(s.drive.active_format()), f);
    s
}

#[test]
fn psx_cmd_001_format_1_positioning_reaches_target() {
    let mut s = Sim::new("PSE312-8");
    assert_eq!(s.drive.active_format(), 1);
    // PSX-START-001, PSX-POS-002: delivery position 51200, a run can start at once.
    assert_eq!(s.actual(), 51200);
    s.f1(0x14, 60000);
    assert_eq!(s.run(), "positioning");
    s.settle(20_000);
    assert_eq!(s.actual(), 60000);
    // PSX-STS-0-SET-1, PSX-STS-6-RESET-1.
    assert!(s.bit(0) && !s.bit(6), "status {:#06x}", s.status());
}

#[test]
fn psx_run_002_003_loop_cases_forward_and_backward() {
    let mut s = Sim::new("PSE312-8");
    while s.drive.poll_event().is_some() {}
    // PSX-RUN-001: with the delivery loop both targets are approached forwards (ISDU 134 = 0).
    // Case 2 (PSX-RUN-003, PSX-STS-8-SET-2): below, overrun by 250 and approach forward.
    s.f1(0x14, 50000);
    assert_eq!(waypoints(&mut s), vec![vec![49750, 50000]]);
    assert!(s.bit(8));
    s.settle(30_000);
    // PSX-STS-8-RESET-1: reached in loop direction.
    assert!(s.bit(0) && !s.bit(8));
    // Case 1 (PSX-RUN-002): above, directly.
    s.f1(0x14, 50100);
    assert_eq!(waypoints(&mut s), vec![vec![50100]]);
    s.settle(30_000);
    assert_eq!(s.actual(), 50100);
}

#[test]
fn psx_run_004_005_short_target_after_run_without_loop() {
    let mut s = Sim::new("PSE312-8");
    // A run without loop against the loop direction leaves the lash (bit 8).
    s.f1(0x54, 50000);
    s.settle(30_000);
    assert!(s.bit(8));
    while s.drive.poll_event().is_some() {}
    // PSX-RUN-004: 100 steps ahead: back to target - 250 first.
    s.f1(0x14, 50100);
    assert_eq!(waypoints(&mut s), vec![vec![49850, 50100]]);
    s.settle(30_000);
    assert_eq!(s.actual(), 50100);
    assert!(!s.bit(8));
}

#[test]
fn psx_ctl_2_1_ctl_4_1_runs_need_bits_2_and_4() {
    let mut s = Sim::new("PSE312-8");
    // PSX-CTL-2-1: a target without bit 2 starts nothing.
    s.f1(0x10, 60000);
    assert_eq!(s.run(), "none");
    // PSX-CTL-4-1: without bit 4 nothing runs either; the target is transferred.
    s.f1(0x04, 60000);
    assert_eq!(s.run(), "none");
    s.f1(0x10, 60000);
    assert_eq!(s.run(), "positioning");
}

#[test]
fn psx_isdu_134_meaning_backward_loop() {
    let mut s = Sim::new("PSE312-8");
    // PSX-ISDU-134-MEANING: 1 approaches with the loop backwards.
    s.write_ok(134, 1);
    while s.drive.poll_event().is_some() {}
    s.f1(0x14, 52000);
    assert_eq!(waypoints(&mut s), vec![vec![52250, 52000]]);
    s.settle(30_000);
    assert!(s.bit(0) && !s.bit(8));
}

#[test]
fn psx_run_007_cmd_008_no_loop_bit_approaches_directly() {
    let mut s = Sim::new("PSE312-8");
    while s.drive.poll_event().is_some() {}
    s.f1(0x54, 50000);
    assert_eq!(waypoints(&mut s), vec![vec![50000]]);
}

#[test]
fn psx_run_008_map_001_targets_the_loop_cannot_reach_are_refused() {
    let mut s = Sim::new("PSE312-8");
    // PSX-STS-12-SET-2: the lower limit cannot be approached with a forward loop.
    s.f1(0x14, 1200);
    assert_eq!(s.run(), "none");
    assert!(s.bit(12));
    // PSX-STS-12-RESET-1: a valid setpoint clears it.
    s.f1(0x14, 2000);
    assert!(!s.bit(12));
    // PSX-STS-12-SET-1, PSX-MAP-001: outside the limits (in the 3-revolution margin).
    s.f1(0x14, 101201);
    assert!(s.bit(12));
    assert_eq!(s.run(), "positioning");
}

#[test]
fn psx_cmd_003_new_target_same_direction_without_stop() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x14, 70000);
    s.run_ms(500);
    let v = s.drive.core().speed_rpm();
    assert!(v > 0);
    s.f1(0x14, 90000);
    for _ in 0..200 {
        s.run_ms(1);
        assert!(s.drive.core().speed_rpm() > 0);
    }
    s.settle(60_000);
    assert_eq!(s.actual(), 90000);
}

#[test]
fn psx_cmd_004_manual_command_interrupts_positioning() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x14, 90000);
    s.run_ms(1000);
    // PSX-CTL-0-1: bit 0 with bit 4.
    s.f1(0x11, 90000);
    assert_eq!(s.drive.run_state(), RunState::Manual { dir: 1 });
    // PSX-VEL-001: the manual run goes on at ISDU 145.
    s.run_ms(2000);
    assert_eq!(s.drive.core().speed_rpm(), s.read(145));
    // PSX-CMD-006: 0x10 stops the manual run.
    s.f1(0x10, 90000);
    s.settle(10_000);
    // PSX-STS-0-RESET-2: a manual run resets bit 0; no bit 5 for 0x10.
    assert!(!s.bit(0) && !s.bit(5));
}

#[test]
fn psx_cmd_002_sts_5_set_1_release_withdrawn_cancels() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x14, 90000);
    s.run_ms(500);
    s.f1(0x00, 90000);
    // PSX-CMD-002: control word 0x00 cancels the run; PSX-STS-5-SET-1, PSX-CTL-4-3.
    assert!(s.bit(5));
    s.settle(10_000);
    assert!(s.actual() < 90000);
    // PSX-STS-5-RESET-1: a new run command resets it.
    s.f1(0x14, 90000);
    assert!(!s.bit(5));
}

#[test]
fn psx_cmd_007_target_during_manual_run_is_approached_at_once() {
    let mut s = format("PSE312-8", 0);
    s.f0(0, 0x3FFF);
    // PSX-CTL-1-1: bit 1 with bit 4.
    s.write_ok(110, 0x12);
    s.run_ms(500);
    assert_eq!(s.run(), "manual-reverse");
    s.write_ok(112, 60000);
    assert_eq!(s.drive.run_state(), RunState::Positioning { target: 60000 });
    s.settle(60_000);
    assert_eq!(s.actual(), 60000);
    assert!(s.bit(0));
}

// ------------------------------------------------------------------ time stamps (4.4)

#[test]
fn psx_ts_001_003_004_005_delayed_stamp_fires_after_inactive() {
    let mut s = format("PSE312-8", 0);
    s.f0(0, 0x3FFF);
    s.write_ok(112, 60000);
    // PSX-TS-004: a valid stamp sent cyclically does nothing.
    s.f0(3, 10000);
    s.run_ms(200);
    assert_eq!(s.run(), "none");
    let sent = s.now;
    s.f0(3, 10000);
    // PSX-TS-005, PSX-TS-008, PSX-PD-011: the inactive marker fires the code sent with the
    // last valid stamp, 10000 x 4 us after it
    // (PSX-ERRATUM-064 "last-stamp").
    s.f0(3, 0x3FFF);
    let t = s.until(100, |d| d.run_state() != RunState::Idle);
    assert_eq!(s.now - sent, 40 * MS, "fired {t} ms after the marker");
    assert_eq!(s.run(), "positioning");
}

#[test]
fn psx_ts_006_007_small_stamps_execute_on_reception() {
    let mut s = format("PSE312-8", 0);
    s.f0(0, 0x3FFF);
    s.write_ok(112, 60000);
    s.f0(3, 1999);
    assert_eq!(s.run(), "positioning");
    s.run_ms(300);
    s.f0(0, 0);
    assert_eq!(s.run(), "none");
    assert!(s.bit(5));
}

#[test]
fn psx_ts_006_erratum_052_after_inactive_reading() {
    let cfg = DriveConfig::new("PSE312-8")
        .with_readings(readings(&[("psx-ts-immediate", "after-inactive")]));
    let mut s = Sim::with(cfg);
    s.write_ok(116, 0);
    s.write_ok(193, 1);
    s.write_ok(2, 128);
    s.f0(0, 0x3FFF);
    s.write_ok(112, 60000);
    s.f0(3, 1999);
    assert_eq!(s.run(), "none");
    s.f0(3, 0x3FFF);
    s.run_ms(9);
    assert_eq!(s.run(), "positioning");
}

#[test]
fn psx_ts_009_reserved_stamps_are_ignored() {
    let mut s = format("PSE312-8", 0);
    s.f0(0, 0x3FFF);
    s.write_ok(112, 60000);
    s.f0(3, 10000);
    // PSX-ERRATUM-061 "ignored": neither replaces nor fires the pending stamp.
    s.f0(3, 16370);
    s.run_ms(100);
    assert_eq!(s.run(), "none");
    s.f0(3, 0x3FFF);
    s.run_ms(1);
    assert_eq!(s.run(), "positioning");
}

#[test]
fn psx_ts_012_pd_012_run_without_loop_through_isdu_110() {
    let mut s = format("PSE312-8", 0);
    s.f0(0, 0x3FFF);
    // PSX-TS-012: bit 6 set beforehand through ISDU 110.
    s.write_ok(110, 0x40);
    s.write_ok(112, 50000);
    while s.drive.poll_event().is_some() {}
    s.f0(3, 0);
    assert_eq!(waypoints(&mut s), vec![vec![50000]]);
    // The code drives bits 0, 1, 2, 4; bit 6 stays as ISDU 110 set it.
    assert_eq!(s.read(110), 0x54);
}

#[test]
fn psx_ts_011_manual_run_by_stamp() {
    let mut s = format("PSE312-8", 0);
    s.f0(0, 0x3FFF);
    // PSX-TS-011: stamp inactive, code 1, stamp, stamp inactive; the run starts after the
    // delay. PSX-ERRATUM-053 "after-disable": the code alone does not start.
    s.f0(1, 0x3FFF);
    assert_eq!(s.run(), "none");
    s.f0(1, 5000);
    s.f0(1, 0x3FFF);
    s.run_ms(21);
    assert_eq!(s.run(), "manual-forward");
    s.f0(0, 0);
    assert_eq!(s.run(), "none");
}

// ------------------------------------------------------------------ 8-byte format (4.6)

#[test]
fn psx_vel_005_006_008_process_data_speed() {
    let mut s = format("PSE312-8", 2);
    let isdu_142 = s.read(142);
    s.f2(50, 0x14, 90000);
    s.run_ms(2000);
    assert_eq!(s.drive.core().speed_rpm(), 50);
    // PSX-VEL-005: the ISDU value is not changed.
    assert_eq!(s.read(142), isdu_142);
    // PSX-VEL-008: a new speed during the run is used at once.
    s.f2(100, 0x14, 90000);
    s.run_ms(2000);
    assert_eq!(s.drive.core().speed_rpm(), 100);
    // PSX-VEL-006: speed 0 falls back to ISDU 142.
    s.f2(0, 0x14, 90000);
    s.run_ms(2000);
    assert_eq!(
        s.drive.core().speed_rpm(),
        isdu_142.min(s.read(143)).min(s.read(144))
    );
}

#[test]
fn psx_vel_007_invalid_speed_aborts_and_sets_bit_12() {
    let mut s = format("PSE335-14", 2);
    s.f2(-1, 0x14, 60000);
    assert_eq!(s.run(), "none");
    assert!(s.bit(12));
    s.f2(50, 0x14, 60000);
    assert_eq!(s.run(), "positioning");
    s.run_ms(500);
    s.f2(5, 0x14, 60000);
    assert!(s.bit(12));
    s.settle(10_000);
    assert_ne!(s.actual(), 60000);
}

#[test]
fn psx_vel_002_ccw_cap_for_runs_to_smaller_values() {
    let mut s = format("PSE335-14", 2);
    s.write_ok(143, 40);
    s.write_ok(144, 100);
    // ISDU 123 = 0: smaller values turn counter-clockwise (PSX-ISDU-123-MEANING).
    s.f2(85, 0x54, 20000);
    s.run_ms(3000);
    assert_eq!(s.drive.core().speed_rpm(), -40);
    // With ISDU 123 = 1 the caps swap.
    s.f2(85, 0x00, 20000);
    s.settle(10_000);
    s.write_ok(123, 1);
    let down = (s.actual() - 10000) as i32;
    s.f2(85, 0x54, down);
    s.run_ms(3000);
    assert_eq!(s.drive.core().speed_rpm(), -85);
}

#[test]
fn psx_vel_003_acceleration_and_deceleration_limits() {
    let mut s = Sim::new("PSE312-8");
    s.record = true;
    s.f1(0x14, 70000);
    s.settle(60_000);
    let accel = s.read(147) as f64;
    let decel = s.read(148) as f64;
    for w in s.trace.windows(2) {
        let dt = (w[1].t - w[0].t) as f64 / 1e6;
        if dt <= 0.0 {
            continue;
        }
        let a = (w[1].rpm - w[0].rpm) as f64 / dt;
        assert!(
            a.abs() <= accel.max(decel) + 1.0 / dt,
            "{a} rpm/s at {}",
            w[1].t
        );
    }
}
