//! Scenarios of the PSx3xx manual chapter 5 on the reference model: blocking (5.3),
//! readjustment (5.4), the master time-out (5.9), jog keys and bits (5.10), brakes (5.12,
//! 5.13), the drag error (5.8) and its correction, the initial reference loop (3.5 bit 7) and
//! the reference run to a block (5.14). Each test names the requirement IDs it covers.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

mod model_util;

use drivespec_positioner::{EnvChange, Flag};
use drivespec_psx3xx::model::{BrakeKind, DriveConfig, Event, JogKeys, LinkEvent, RunState};
use model_util::*;

fn brake_events(s: &mut Sim) -> Vec<(u64, bool)> {
    let mut out = Vec::new();
    while let Some((t, e)) = s.drive.poll_event() {
        if let Event::Brake { open } = e {
            out.push((t / MS, open));
        }
    }
    out
}

// ------------------------------------------------------------------ blocking (5.3)

#[test]
fn psx_obst_001_002_block_detected_after_isdu_159() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x14, 70000);
    s.run_ms(300);
    s.env(EnvChange::Jam { on: true });
    let t = s.until(2000, |d| d.status_word() >> 10 & 1 == 1);
    // PSX-OBST-001, PSX-STS-10-SET-1: speed below ISDU 146 % for longer than ISDU 159 ms.
    assert!(
        t as i64 >= s.read(159) && t as i64 <= s.read(159) + 5,
        "{t} ms"
    );
    assert_eq!(s.run(), "none");
    // PSX-OBST-002: the holding torque ISDU 155 applies.
    s.run_ms(1000);
    assert_eq!(s.drive.core().holding_torque(), Some(s.read(155)));
    // PSX-STS-1-SET-2: the drag error came first.
    assert!(s.bit(1));
}

#[test]
fn psx_obst_003_004_007_same_target_needs_release_toggle() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x14, 70000);
    s.run_ms(300);
    s.env(EnvChange::Jam { on: true });
    s.until(2000, |d| d.status_word() >> 10 & 1 == 1);
    s.env(EnvChange::Jam { on: false });
    s.f1(0x14, 70000);
    s.run_ms(50);
    assert_eq!(s.run(), "none");
    s.f1(0x04, 70000);
    s.f1(0x14, 70000);
    assert_eq!(s.run(), "positioning");
    // PSX-STS-10-RESET-1.
    assert!(!s.bit(10));
    s.settle(60_000);
    assert_eq!(s.actual(), 70000);
}

#[test]
fn psx_ref_004_block_inside_the_window_counts_as_reached() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x14, 51300);
    s.env(EnvChange::Block { at: 51299 });
    s.settle(10_000);
    assert!(s.bit(0) && !s.bit(10), "status {:#06x}", s.status());
}

// ------------------------------------------------------------------ readjustment (5.4)

#[test]
fn psx_adj_005_readjust_starts_when_the_window_is_left() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x0414, 60000);
    s.settle(60_000);
    assert!(s.bit(0));
    // Within the window (ISDU 131 = 2): nothing.
    s.env(EnvChange::Displace { by: -2 });
    assert_eq!(s.run(), "none");
    assert!(s.bit(0));
    // PSX-ADJ-005: one step beyond the window starts the readjustment.
    s.env(EnvChange::Displace { by: -1 });
    assert_eq!(s.run(), "positioning");
    // PSX-STS-11-SET-1.
    assert!(s.bit(11));
    s.settle(10_000);
    assert_eq!(s.actual(), 60000);
    // PSX-STS-0-SET-3.
    assert!(s.bit(0));
    // PSX-STS-11-RESET-1: a positioning order resets bit 11.
    s.f1(0x0414, 61000);
    assert!(!s.bit(11));
}

#[test]
fn psx_adj_008_009_no_readjust_without_bits_or_after_abort() {
    let mut s = Sim::new("PSE312-8");
    // PSX-ADJ-009: without bit 10.
    s.f1(0x14, 60000);
    s.settle(60_000);
    s.env(EnvChange::Displace { by: -10 });
    assert_eq!(s.run(), "none");
    assert!(s.bit(11) && !s.bit(0));
    // PSX-ADJ-008: a run stopped by withdrawing the release is not readjusted.
    s.f1(0x0414, 70000);
    s.run_ms(300);
    s.f1(0x0400, 70000);
    s.settle(10_000);
    s.f1(0x0410, 70000);
    s.env(EnvChange::Displace { by: -10 });
    assert_eq!(s.run(), "none");
}

#[test]
fn psx_adj_010_drives_with_brake_never_readjust() {
    let mut s = Sim::with(DriveConfig::new("PSE322-14").with_brake(BrakeKind::Snap));
    s.f1(0x0414, 60000);
    s.settle(60_000);
    assert!(s.bit(0));
    s.run_ms(2000);
    s.env(EnvChange::Displace { by: -10 });
    assert_eq!(s.run(), "none");
}

#[test]
fn psx_adj_004_bit_6_readjusts_in_loop_direction_too() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x0454, 60000);
    s.settle(60_000);
    s.env(EnvChange::Displace { by: 5 });
    assert_eq!(s.run(), "positioning");
    s.settle(10_000);
    assert_eq!(s.actual(), 60000);
    assert!(s.bit(0));
}

// ------------------------------------------------------------------ time-out (5.9)

#[test]
fn psx_timeout_002_006_no_timeout_with_isdu_118_zero() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x14, 90000);
    s.link(LinkEvent::Lost);
    // PSX-TIMEOUT-002: ISDU 118 = 0, the run ends as planned.
    s.settle(120_000);
    assert_eq!(s.actual(), 90000);
    assert!(s.bit(0));
}

#[test]
fn psx_timeout_003_004_abort_after_isdu_118() {
    let mut s = Sim::new("PSE312-8");
    s.write_ok(118, 300);
    s.write_ok(137, 1);
    s.f1(0x14, 90000);
    // The master keeps sending: no time-out.
    s.run_ms(1000);
    assert_eq!(s.run(), "positioning");
    let last = s.now;
    s.link(LinkEvent::Lost);
    s.until(1000, |d| {
        d.run_state() != RunState::Positioning { target: 90000 }
    });
    assert_eq!(s.now - last, 300 * MS);
    assert!(s.bit(5));
    s.settle(10_000);
    assert_ne!(s.actual(), 90000);
}

#[test]
fn psx_timeout_005_safe_position_from_standstill() {
    let mut s = Sim::new("PSE312-8");
    s.write_ok(118, 100);
    s.write_ok(137, 2);
    s.write_ok(138, 40000);
    s.link(LinkEvent::Lost);
    s.run_ms(101);
    assert_eq!(
        s.drive.run_state(),
        RunState::SafePosition { target: 40000 }
    );
    s.settle(60_000);
    assert_eq!(s.actual(), 40000);
    // The master comes back: normal operation.
    s.link(LinkEvent::Connected);
    s.f1(0x14, 45000);
    s.settle(60_000);
    assert_eq!(s.actual(), 45000);
}

// ------------------------------------------------------------------ jog (5.10)

#[test]
fn psx_jog_005_short_press_runs_one_step_of_isdu_135() {
    let mut s = Sim::new("PSE312-8");
    s.write_ok(135, 7);
    s.f1(0x20, 0);
    s.keys(JogKeys::FORWARD);
    // PSX-STS-3-SET-1.
    assert!(s.bit(3));
    // PSX-STS-0-RESET-2, PSX-STS-8-SET-1 do not apply to bit 3; the step runs.
    assert_eq!(s.run(), "jog-step");
    s.run_ms(8);
    // Released early: the step completes.
    s.keys(JogKeys::NONE);
    // PSX-STS-3-RESET-1.
    assert!(!s.bit(3));
    s.settle(5_000);
    assert_eq!(s.actual(), 51207);
    // A jog step never sets bit 0.
    assert!(!s.bit(0));
    // PSX-STS-2-SET-1, PSX-STS-8-SET-1: against the loop direction.
    s.keys(JogKeys::REVERSE);
    assert!(s.bit(2) && s.bit(8));
    s.settle(5_000);
    s.keys(JogKeys::NONE);
    // PSX-STS-2-RESET-1.
    assert!(!s.bit(2));
    assert_eq!(s.actual(), 51200);
    // PSX-JOG-003: with bits 4 and 5 both set the keys are inactive (bit 4 wins).
    s.f1(0x30, 0);
    s.keys(JogKeys::FORWARD);
    assert_eq!(s.run(), "none");
}

#[test]
fn psx_jog_006_008_continuous_run_to_the_limit() {
    let mut s = Sim::new("PSE312-8");
    s.write_ok(129, 52000);
    s.link(LinkEvent::Lost);
    s.keys(JogKeys::FORWARD);
    // PSX-JOG-006: after ISDU 163 x 5 ms (PSX-ERRATUM-017).
    let wait = s.read(163) as u64 * 5;
    s.run_ms(wait - 20);
    assert_ne!(s.run(), "jog-continuous");
    s.run_ms(40);
    assert_eq!(s.run(), "jog-continuous");
    // PSX-JOG-008: up to the end limit; PSX-STS-14-SET-1.
    s.run_ms(30_000);
    assert_eq!(s.actual(), 52000);
    assert!(s.bit(14));
    s.keys(JogKeys::NONE);
    s.settle(5_000);
    assert!(!s.bit(5));
}

#[test]
fn psx_jog_004_release_cancels_a_jog() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x28, 0);
    s.keys(JogKeys::FORWARD);
    s.run_ms(2000);
    assert_eq!(s.run(), "jog-continuous");
    s.f1(0x10, 0);
    assert_eq!(s.run(), "none");
}

#[test]
fn psx_jog_009_both_keys_cancel() {
    let mut s = Sim::new("PSE312-8");
    s.link(LinkEvent::Lost);
    s.keys(JogKeys::FORWARD);
    s.run_ms(2000);
    s.keys(JogKeys::BOTH);
    assert_eq!(s.run(), "none");
    s.keys(JogKeys::REVERSE);
    s.run_ms(100);
    assert_eq!(s.run(), "none");
    s.keys(JogKeys::NONE);
    s.keys(JogKeys::REVERSE);
    assert_eq!(s.run(), "jog-step");
}

// ------------------------------------------------------------------ brakes (5.12, 5.13)

#[test]
fn psx_brake_003_005_snap_brake_wait_and_hold() {
    let mut s = Sim::with(DriveConfig::new("PSE322-14").with_brake(BrakeKind::Snap));
    brake_events(&mut s);
    let start = s.now;
    s.f1(0x14, 52000);
    // PSX-BRAKE-003: ISDU 164 without moving.
    assert_eq!(s.drive.run_state(), RunState::BrakeWait);
    s.until(1000, |d| d.run_state() != RunState::BrakeWait);
    assert_eq!(s.now - start, s.read(164) as u64 * MS);
    assert!(s.drive.brake_open());
    s.settle(60_000);
    let end = s.now;
    // PSX-BRAKE-005: open ISDU 165 after the end; a new run starts at once.
    s.f1(0x14, 53000);
    assert_eq!(s.run(), "positioning");
    s.settle(60_000);
    s.run_ms(s.read(165) as u64 + 100);
    assert!(!s.drive.brake_open());
    let ev = brake_events(&mut s);
    assert_eq!(ev.first(), Some(&(start / MS + s.read(164) as u64, true)));
    assert!(end > start);
}

#[test]
fn psx_ctl_11_1_braking_free_steps_with_bit_11() {
    let mut s = Sim::with(DriveConfig::new("PSE322-14").with_brake(BrakeKind::Snap));
    s.record = true;
    // PSX-CTL-11-2: bit 11 together with bit 4.
    s.f1(0x0814, 52000);
    s.settle(60_000);
    let n = s.read(136);
    let min = s.trace.iter().map(|x| x.actual).min().unwrap();
    // PSX-ERRATUM-023 "both-directions": against the run direction by ISDU 136, back, run.
    assert_eq!(min, 51200 - n);
    assert_eq!(s.actual(), 52000);
}

#[test]
fn psx_brake_007_holding_brake_closes_after_every_run() {
    let mut s = Sim::with(DriveConfig::new("PSE3410-14").with_brake(BrakeKind::Holding));
    s.f1(0x14, 52000);
    assert_eq!(s.drive.run_state(), RunState::BrakeWait);
    s.settle(60_000);
    assert!(!s.drive.brake_open());
    assert!(Drive_refuses_wrong_brake());
}

/// PSX-MODEL-NAMES: the brake option by model pattern (PSx30x-14 … PSE34xx).
#[allow(non_snake_case)]
fn Drive_refuses_wrong_brake() -> bool {
    drivespec_psx3xx::model::Drive::new(
        spec(),
        DriveConfig::new("PSE312-8").with_brake(BrakeKind::Snap),
    )
    .is_err()
}

// ------------------------------------------------------------------ drag error (5.8)

#[test]
fn psx_sts_1_set_1_drag_error_when_load_slows_the_run() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x14, 90000);
    s.run_ms(1000);
    // A short jam, shorter than the block time.
    s.env(EnvChange::Jam { on: true });
    s.run_ms(60);
    s.env(EnvChange::Jam { on: false });
    assert!(s.bit(1));
    assert!(!s.bit(10));
    // PSX-STS-1-RESET-1: a new run command resets it.
    s.f1(0x14, 80000);
    assert!(!s.bit(1));
    // PSX-STS-1-RESET-2, PSX-CTL-14-1: bit 14 clears the error bits.
    s.env(EnvChange::Jam { on: true });
    s.run_ms(400);
    assert!(s.bit(1) && s.bit(10));
    s.env(EnvChange::Jam { on: false });
    s.f1(0x4014, 80000);
    assert!(!s.bit(1) && !s.bit(10));
}

#[test]
fn psx_ctl_12_1_drag_correction_catches_up() {
    let run = |word: u16| {
        let mut s = Sim::new("PSE312-8");
        s.write_ok(142, 100);
        s.f1(word, 95000);
        s.run_ms(1500);
        s.env(EnvChange::Jam { on: true });
        s.run_ms(100);
        s.env(EnvChange::Jam { on: false });
        s.run_ms(2000);
        (s.actual(), s.drive.core().speed_rpm())
    };
    let (plain, v_plain) = run(0x14);
    let (corrected, _) = run(0x1014);
    assert_eq!(v_plain, 100);
    // PSX-CTL-12-1: with bit 12 the drive ran faster and is further along.
    assert!(corrected > plain, "{corrected} vs {plain}");
    // PSX-CTL-12-2: not in manual runs, and the run still ends on its target.
    let mut s = Sim::new("PSE312-8");
    s.f1(0x1011, 0);
    s.run_ms(3000);
    assert_eq!(s.drive.core().speed_rpm(), s.read(145));
    s.f1(0x1014, 60000);
    s.settle(60_000);
    assert_eq!(s.actual(), 60000);
}

// ------------------------------------------------------------------ reference loop (3.5 bit 7)

#[test]
fn psx_ctl_7_1_initial_reference_loop_clears_error_bits() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x14, 60000);
    s.settle(60_000);
    s.env(EnvChange::Displace { by: -10 });
    assert!(s.bit(11) && !s.bit(0));
    // Back into the window by hand: bit 0 stays reset without readjustment (PSX-STS-0-SET-3
    // needs bits 4 and 10).
    s.env(EnvChange::Displace { by: 10 });
    assert!(!s.bit(0));
    s.env(EnvChange::PositionFault);
    // PSX-STS-9-SET-1.
    assert!(s.bit(9));
    // PSX-STS-9-BLOCK: no run but the reference loop.
    s.f1(0x14, 61000);
    assert_eq!(s.run(), "none");
    s.f1(0x94, 61000);
    assert_eq!(s.run(), "reference-loop");
    s.record = true;
    s.settle(30_000);
    let min = s.trace.iter().map(|x| x.actual).min().unwrap();
    assert_eq!(min, 60000 - 250);
    // PSX-STS-9-RESET-1, PSX-STS-8-RESET-2, PSX-STS-11-RESET-2, PSX-STS-10-RESET-2.
    assert!(!s.bit(9) && !s.bit(8) && !s.bit(11) && !s.bit(10));
    // PSX-VEL-001: at the manual speed.
    let vmax = s.trace.iter().map(|x| x.rpm.abs()).max().unwrap();
    assert_eq!(vmax, s.read(145));
    // PSX-STS-0-SET-2: the last transferred target (60000; 61000 was refused with bit 9) is
    // where the loop ends.
    assert_eq!(s.drive.core().axis().target(), Some(60000));
    assert!(s.bit(0));
}

/// PSX-STS-9-BLOCK: with the error bit set, a connection time-out's run to the safe position
/// (PSX-TIMEOUT-005) is refused and the reference loop in progress ends as the loop: bit 9
/// reset (PSX-STS-9-RESET-1), bit 0 set for the transferred target (PSX-STS-0-SET-2).
#[test]
fn psx_sts_9_block_a_time_out_during_the_reference_loop_leaves_the_loop_running() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x14, 60000);
    s.settle(60_000);
    s.write_ok(137, 2);
    s.write_ok(138, 30000);
    s.write_ok(118, 300);
    s.env(EnvChange::PositionFault);
    s.f1(0x94, 60000);
    assert_eq!(s.run(), "reference-loop");
    s.run_ms(100);
    s.link(LinkEvent::Lost);
    s.run_ms(400);
    assert_eq!(s.run(), "reference-loop");
    s.settle(30_000);
    assert_eq!(s.actual(), 60000);
    assert!(!s.bit(9) && s.bit(0));
    assert_eq!(s.drive.core().axis().target(), Some(60000));
}

/// PSX-STS-9-BLOCK: a jog key held during the reference loop with the link down (5.10) asks
/// for a continuous run that the error bit refuses; the loop ends as the loop, and no jog
/// follows while the key stays held.
#[test]
fn psx_sts_9_block_a_jog_key_during_the_reference_loop_leaves_the_loop_running() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x14, 60000);
    s.settle(60_000);
    s.env(EnvChange::PositionFault);
    s.f1(0x94, 60000);
    s.link(LinkEvent::Lost);
    s.keys(JogKeys::FORWARD);
    s.run_ms(2000);
    assert_eq!(s.run(), "reference-loop");
    s.settle(30_000);
    assert_eq!(s.actual(), 60000);
    assert!(!s.bit(9) && s.bit(0));
}

// ------------------------------------------------------------------ reference run (5.14)

#[test]
fn psx_ref_002_003_005_reference_run_to_a_block() {
    let mut s = Sim::new("PSE312-8");
    s.env(EnvChange::Block { at: 40000 });
    // PSX-REF-002, PSX-REF-003: reduced settings.
    let rated = s.read(153);
    s.write_ok(153, rated / 10);
    s.write_ok(152, rated / 10);
    s.write_ok(155, 0);
    s.write_ok(154, 0);
    s.write_ok(146, 60);
    s.write_ok(159, 100);
    // PSX-REF-005: manual run toward the block, bit 6, then bit 6 reset and bit 10.
    s.f1(0x12, 0);
    s.run_ms(50);
    assert!(s.bit(6));
    s.until(120_000, |d| d.status_word() >> 10 & 1 == 1);
    assert!(!s.bit(6));
    assert_eq!(s.actual(), 40000);
    // Away from the block with the same settings.
    s.f1(0x10, 0);
    s.f1(0x11, 0);
    s.run_ms(500);
    assert!(s.actual() > 40000);
    assert!(s.drive.flag(Flag::Obstruction));
}

// ------------------------------------------------------------------ encoder (5.5, 6.3)

#[test]
fn psx_pos_001_encoder_covers_256_revolutions() {
    let mut s = Sim::new("PSE312-8");
    s.f1(0x54, 1300);
    s.settle(600_000);
    // Pushed into the 3-revolution margin below the usable range: still measured.
    s.env(EnvChange::Displace { by: -1000 });
    assert_eq!(s.actual(), 300);
    assert!(s.bit(15) && !s.bit(9), "status {:#06x}", s.status());
    // Below the encoder's 256 revolutions (mapping end 102400 - 102400 = 0): error bit.
    s.env(EnvChange::Displace { by: -400 });
    assert!(s.bit(9));
    // PSX-STS-9-BLOCK.
    s.f1(0x14, 50_000);
    assert_eq!(s.run(), "none");
}

#[test]
fn psx_timeout_005_safe_run_of_a_brake_drive_waits_for_the_brake() {
    let mut s = Sim::with(DriveConfig::new("PSE322-14").with_brake(BrakeKind::Snap));
    s.write_ok(118, 100);
    s.write_ok(137, 2);
    s.write_ok(138, 50_000);
    s.link(LinkEvent::Lost);
    s.run_ms(101);
    // PSX-TIMEOUT-005, PSX-BRAKE-003: ISDU 164 first, then the run to ISDU 138.
    assert_eq!(s.drive.run_state(), RunState::BrakeWait);
    s.until(1_000, |d| d.run_state() != RunState::BrakeWait);
    assert_eq!(
        s.drive.run_state(),
        RunState::SafePosition { target: 50_000 }
    );
    s.settle(60_000);
    assert_eq!(s.actual(), 50_000);
    // The master returns and withdraws the release while the brake is still closed: the
    // next run is an ordinary positioning.
    let mut s = Sim::with(DriveConfig::new("PSE322-14").with_brake(BrakeKind::Snap));
    s.write_ok(118, 100);
    s.write_ok(137, 2);
    s.write_ok(138, 50_000);
    s.link(LinkEvent::Lost);
    s.run_ms(101);
    assert_eq!(s.drive.run_state(), RunState::BrakeWait);
    s.link(LinkEvent::Connected);
    s.f1(0x00, 0);
    s.run_ms(500);
    assert_eq!(s.run(), "none");
    s.f1(0x14, 52_000);
    s.until(1_000, |d| d.run_state() != RunState::BrakeWait);
    assert_eq!(
        s.drive.run_state(),
        RunState::Positioning { target: 52_000 }
    );
}
