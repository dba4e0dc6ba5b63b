//! Scenarios of manual chapter 4 and the status bits of 3.6 on the reference model, with
//! positions and status words checked step by step. Each test names the requirements it
//! covers. The drive is a PSD 401/411-5V (3.4: 200 rpm positioning, 70 rpm manual, 1000 rpm/s
//! acceleration, 2000 rpm/s deceleration, limits ±805,200) unless a test says otherwise.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_positioner::machine::{CoreEvent, Outcome, RunKind};
use drivespec_positioner::EnvChange;
use drivespec_psd4xx::model::{DriveConfig, Event, LinkEvent};
use model_util::*;

const MODEL: &str = "PSD401-5V";

fn drive() -> Sim {
    Sim::new(MODEL)
}

fn drive_with(choices: &[(&str, &str)]) -> Sim {
    Sim::with(DriveConfig::new(MODEL).with_readings(readings(choices)))
}

/// Positions to a target and waits until the run is over.
fn go(s: &mut Sim, target: i32) {
    s.send(0x14, target);
    s.wait_idle();
}

fn core_events(s: &mut Sim) -> Vec<CoreEvent> {
    s.events()
        .into_iter()
        .filter_map(|e| match e {
            Event::Core(c) => Some(c),
            _ => None,
        })
        .collect()
}

// ---------------------------------------------------------------- 4.1 positioning

/// 4.1 first order: 0x14 and the target start the run at once (PSD-POS-001, PSD-POS-020,
/// PSD-STS-6-SET-1, PSD-STS-6-RESET-1, PSD-STS-0-SET-1, PSD-STS-8-SET-1, PSD-STS-8-RESET-2).
#[test]
fn positioning_0x14_starts_at_once() {
    let mut s = drive();
    // Power-on: motor voltage present, lash not yet eliminated.
    assert_eq!(s.status(), 0x0110, "{}", s.describe());
    s.send(0x14, 4000);
    s.step(1);
    assert_eq!(s.status(), 0x0150, "running: {}", s.describe());
    s.wait_idle();
    assert_eq!(s.actual(), 4000);
    assert_eq!(
        s.status(),
        0x0011,
        "reached in loop direction: {}",
        s.describe()
    );
}

/// 4.1 second order: 0x04 transfers without running, 0x10 starts (PSD-POS-004, PSD-POS-005,
/// PSD-CTL-2-001, PSD-CTL-2-002, PSD-CTL-2-003).
#[test]
fn transfer_then_release() {
    let mut s = drive();
    s.send(0x04, 4000);
    s.step(300);
    assert_eq!(s.actual(), 0);
    assert_eq!(s.status(), 0x0110);
    assert_eq!(s.par(33), 4000, "the transferred target is the valid one");
    s.send(0x10, 4000);
    s.step(1);
    assert!(s.running());
    s.wait_idle();
    assert_eq!(s.actual(), 4000);
    assert_eq!(s.status(), 0x0011);
}

/// Without bit 2 the process-data target is ignored (PSD-POS-006).
#[test]
fn no_transfer_keeps_the_valid_target() {
    let mut s = drive();
    s.send(0x04, 4000);
    s.send(0x00, 8000);
    s.send(0x10, 8000);
    s.wait_idle();
    assert_eq!(s.actual(), 4000);
}

/// Repeating 0x14 and the target cyclically does not restart a finished run; the same word
/// after power-on without a valid target does nothing (PSD-PKW-002-like cyclic data, 3.7).
#[test]
fn cyclic_repetition_starts_nothing_new() {
    let mut s = drive();
    go(&mut s, 4000);
    s.events();
    s.step(500);
    assert!(!core_events(&mut s)
        .iter()
        .any(|e| matches!(e, CoreEvent::RunStarted { .. })));
    // Release alone after power-on: no target was ever transferred (DECISION).
    let mut t = drive();
    t.send(0x10, 0);
    t.step(100);
    assert!(!t.running());
}

/// A new target in the same direction is taken over without stopping (PSD-POS-002,
/// PSD-POS-003); one behind the drive reverses it.
#[test]
fn new_target_during_a_run() {
    let mut s = drive();
    s.send(0x14, 40_000);
    s.step(500);
    s.send(0x14, 80_000);
    let mut min_rpm = f64::MAX;
    assert!(s.until(60_000, |s| {
        if s.drive.core().run_kind().is_some() {
            min_rpm = min_rpm.min(s.rpm());
        }
        s.idle()
    }));
    assert!(min_rpm > 0.0, "never stopped on the way ({min_rpm})");
    assert_eq!(s.actual(), 80_000);
    s.send(0x14, 100_000);
    assert!(s.until(60_000, |s| s.actual() > 95_000));
    s.send(0x14, 90_000);
    let (lo, _) = s.span_until_idle();
    // Case 2 of 4.2.1 applies to the new target: overshoot below by the loop.
    assert_eq!(lo, 90_000 - 250);
    assert_eq!(s.actual(), 90_000);
}

/// Release withdrawn during a run: the run stops with par. 59 and bit 5 is set; the next
/// run command resets it (PSD-RUN-001, PSD-CTL-4-003, PSD-STS-5-SET-1, PSD-STS-5-RESET-1,
/// PSD-VEL-006).
#[test]
fn release_withdrawn_aborts() {
    let mut s = drive();
    s.send(0x14, 400_000);
    s.step(1000);
    let v0 = s.rpm();
    assert!((v0 - 200.0).abs() < 1e-6, "cruising at par. 53: {v0}");
    s.control(0x00);
    let speeds = s.speeds(200);
    // Par. 59 = 2000 rpm/s: 2 rpm per ms, 100 ms to stop.
    assert!((v0 - speeds[0] - 2.0).abs() < 1e-6, "{}", speeds[0]);
    let stop = speeds.iter().position(|v| *v == 0.0).unwrap();
    assert!((99..=100).contains(&stop), "{stop}");
    assert!(s.bit(5) && !s.bit(6) && !s.bit(0), "{}", s.describe());
    s.send(0x14, 400_000);
    assert!(!s.bit(5));
    s.step(1);
    assert!(s.running());
}

/// With the other reading the stop uses the maximum deceleration (PSD-VEL-007,
/// erratum PSD-ERRATUM-058).
#[test]
fn stop_ramp_maximum_reading() {
    let mut s = drive_with(&[("psd-stop-ramp", "maximum")]);
    s.send(0x14, 400_000);
    s.step(1000);
    s.control(0x00);
    let speeds = s.speeds(100);
    // 5000 rpm/s, the top of par. 59: 40 ms from 200 rpm.
    let stop = speeds.iter().position(|v| *v == 0.0).unwrap();
    assert!((39..=40).contains(&stop), "{stop}");
}

/// A manual command during a positioning run takes over at the manual speed without bit 5
/// (PSD-RUN-002, PSD-RUN-003, PSD-VEL-009).
#[test]
fn manual_command_during_positioning() {
    let mut s = drive();
    s.send(0x14, 400_000);
    s.step(1000);
    s.control(0x11);
    let speeds = s.speeds(300);
    // Par. 58 = 1000 rpm/s for the reduction: 1 rpm per ms down to 70 rpm.
    assert!((speeds[0] - 199.0).abs() < 1e-6, "{}", speeds[0]);
    assert!((speeds[299] - 70.0).abs() < 1e-6, "{}", speeds[299]);
    assert!(!s.bit(5));
    assert_eq!(s.drive.core().run_kind(), Some(RunKind::Manual));
    s.control(0x10);
    s.wait_idle();
    assert!(!s.bit(5) && !s.bit(0));
}

// ---------------------------------------------------------------- 4.2 types of positioning

/// 4.2.1 case 1: a larger target is approached directly (PSD-POS-007, PSD-POS-010).
#[test]
fn loop_case_1_direct() {
    let mut s = drive();
    s.send(0x14, 4000);
    let (lo, hi) = s.span_until_idle();
    assert_eq!((lo, hi, s.actual()), (0, 4000, 4000));
}

/// 4.2.1 case 2: a smaller target is overrun by the loop (250 = 5/8 rotation) and approached
/// forward (PSD-POS-011, PSD-POS-008, PSD-STS-8-SET-3, PSD-STS-8-RESET-2).
#[test]
fn loop_case_2_overshoot() {
    let mut s = drive();
    go(&mut s, 8000);
    s.send(0x14, 4000);
    // PSD-STS-0-RESET-1: the new target lies outside the window.
    assert!(!s.bit(0));
    s.step(1);
    assert!(s.bit(8), "against the loop: {}", s.describe());
    let (lo, hi) = s.span_until_idle();
    assert_eq!((lo, hi), (3750, 8000));
    assert_eq!(s.actual(), 4000);
    assert_eq!(s.status(), 0x0011);
}

/// 4.2.1 case 3: lash present (after a manual run down), a target less than the loop ahead
/// is reached via target − loop; one further ahead directly (PSD-POS-012, PSD-STS-8-SET-4).
#[test]
fn loop_case_3_back_off() {
    let mut s = drive();
    s.control(0x12);
    s.step(500);
    s.control(0x10);
    s.wait_idle();
    assert!(s.bit(8));
    let x = s.actual();
    s.send(0x14, (x + 100) as i32);
    let (lo, _) = s.span_until_idle();
    assert_eq!(lo, x + 100 - 250);
    assert_eq!(s.actual(), x + 100);
    assert!(!s.bit(8));
    // Lash present again, target 1000 ahead: direct.
    s.control(0x12);
    s.step(300);
    s.control(0x10);
    s.wait_idle();
    let x = s.actual();
    s.send(0x14, (x + 1000) as i32);
    let (lo, _) = s.span_until_idle();
    assert_eq!(lo, x);
}

/// Case 3 with the fixed-5/8 reading backs off 5/8 rotation from the current position
/// (erratum PSD-ERRATUM-055).
#[test]
fn loop_case_3_fixed_reading() {
    let mut s = drive_with(&[("psd-loop-backoff", "fixed-five-eighths")]);
    s.control(0x12);
    s.step(500);
    s.control(0x10);
    s.wait_idle();
    let x = s.actual();
    s.send(0x14, (x + 100) as i32);
    let (lo, _) = s.span_until_idle();
    assert_eq!(lo, x - 250);
}

/// After the run the position is compared with the encoder: one miss starts a second
/// positioning, two set bit 10 (PSD-POS-013, PSD-POS-014, PSD-STS-10-SET-2).
#[test]
fn second_positioning_and_positioning_error() {
    let mut s = drive();
    s.env(EnvChange::MissSteps { by: 5 });
    go(&mut s, 4000);
    assert_eq!(s.actual(), 4000);
    assert!(s.bit(0) && !s.bit(10));
    assert!(core_events(&mut s)
        .iter()
        .any(|e| matches!(e, CoreEvent::SecondAttempt { actual: 3995 })));
    s.env(EnvChange::MissSteps { by: 5 });
    s.env(EnvChange::MissSteps { by: 5 });
    go(&mut s, 8000);
    assert_eq!(s.actual(), 7995);
    assert!(s.bit(10) && !s.bit(0), "{}", s.describe());
}

/// With loop > 0 a target whose loop would cross the lower limit is refused with bit 12; the
/// upper limit is reachable. With loop < 0 it is the other way round (PSD-PAR-45-002, PSD-POS-016,
/// PSD-STS-12-SET-1, PSD-STS-12-SET-2, PSD-STS-0-RESET-3, PSD-STS-12-RESET-1).
#[test]
fn limits_and_the_loop() {
    let mut s = drive();
    s.send(0x14, -805_200);
    assert!(s.bit(12) && !s.bit(0));
    s.step(100);
    assert_eq!(s.actual(), 0);
    s.send(0x14, 900_000);
    assert!(s.bit(12));
    let mut s = Sim::with(DriveConfig::new(MODEL).with_start_position(804_000));
    go(&mut s, 805_200);
    assert!(!s.bit(12));
    assert_eq!(s.actual(), 805_200);
    let mut s = Sim::with(DriveConfig::new(MODEL).with_start_position(-804_000));
    s.write(45, -250);
    s.send(0x14, 805_200);
    assert!(s.bit(12));
    go(&mut s, -805_200);
    assert_eq!(s.actual(), -805_200);
    assert!(!s.bit(12) && s.bit(0));
}

/// Bit 6 of the control word approaches directly, also against the loop (PSD-POS-017,
/// PSD-POS-018, PSD-STS-8-SET-3).
#[test]
fn run_without_loop() {
    let mut s = drive();
    go(&mut s, 8000);
    s.send(0x54, 6000);
    let (lo, _) = s.span_until_idle();
    assert_eq!((lo, s.actual()), (6000, 6000));
    assert!(s.bit(0) && s.bit(8), "lash left: {}", s.describe());
    // The lower limit is reachable without loop.
    go(&mut s, 0);
    s.send(0x54, -805_200);
    s.step(1);
    assert!(!s.bit(12));
}

/// Loop length 0: no loop, bit 8 reset by every run (PSD-PAR-45-001, PSD-STS-8-RESET-1).
#[test]
fn loop_length_zero() {
    let mut s = drive();
    s.write(45, 0);
    go(&mut s, 8000);
    s.send(0x14, 4000);
    assert!(!s.bit(8));
    let (lo, _) = s.span_until_idle();
    assert_eq!(lo, 4000);
    s.control(0x12);
    s.step(10);
    assert!(!s.bit(8));
}

/// 4.2.3 manual runs: 0x11 up and 0x12 down at par. 56, 0x10 and 0x00 stop; bit 5 stays 0
/// (PSD-RUN-004, PSD-RUN-005, PSD-RUN-006, PSD-RUN-007, PSD-VEL-001, PSD-STS-0-RESET-2,
/// erratum PSD-ERRATUM-018).
#[test]
fn manual_runs() {
    let mut s = drive();
    go(&mut s, 4000);
    s.control(0x11);
    assert!(!s.bit(0));
    s.step(1000);
    assert!((s.rpm() - 70.0).abs() < 1e-6);
    assert!(s.actual() > 4000);
    s.control(0x10);
    s.wait_idle();
    assert!(!s.bit(5));
    s.control(0x12);
    s.step(1000);
    assert!((s.rpm() + 70.0).abs() < 1e-6);
    assert!(s.bit(8));
    s.control(0x00);
    s.wait_idle();
    assert!(!s.bit(5), "{}", s.describe());
    // The other reading of PSD-ERRATUM-018.
    let mut s = drive_with(&[("psd-bit5-manual-run", "any-run")]);
    s.control(0x11);
    s.step(100);
    s.control(0x00);
    assert!(s.bit(5));
}

/// Positioning during a manual run needs a standstill first (PSD-RUN-008, PSD-RUN-009).
#[test]
fn positioning_needs_standstill_after_manual_run() {
    let mut s = drive();
    s.control(0x11);
    s.step(500);
    s.send(0x14, -4000);
    s.wait_idle();
    assert!(s.actual() > 0, "no positioning while the manual run stops");
    s.control(0x00);
    go(&mut s, -4000);
    assert_eq!(s.actual(), -4000);
}

/// A manual run stops at the limit with bit 14; bit 0 only when the limit is the target;
/// the bit stays at the limit until the next run command (PSD-STS-14-SET-1,
/// PSD-STS-14-RESET-1, PSD-STS-0-SET-2, PSD-STS-14-NOPOS, PSD-VEL-008, PSD-STS-14-MAP).
#[test]
fn manual_run_to_the_limits() {
    let mut s = drive();
    s.write(42, 2000);
    s.write(43, -2000);
    s.control(0x11);
    s.wait_idle();
    assert_eq!(s.actual(), 2000);
    assert!(s.bit(14) && !s.bit(0), "{}", s.describe());
    s.control(0x10);
    s.step(100);
    assert!(s.bit(14), "kept at the limit until a run command");
    s.control(0x00);
    go(&mut s, 2000);
    assert!(
        s.bit(0) && !s.bit(14),
        "positioning to the limit: {}",
        s.describe()
    );
    s.control(0x00);
    s.send(0x12, 2000);
    s.wait_idle();
    assert_eq!(s.actual(), -2000);
    assert!(s.bit(15) && !s.bit(14) && !s.bit(0));
    // The target equal to the limit reached by a manual run sets bit 0.
    s.control(0x00);
    s.send(0x54, -1990);
    s.wait_idle();
    s.control(0x00);
    // Transfer without release and without loop (a loop would leave the limits).
    s.send(0x44, -2000);
    s.control(0x12);
    s.wait_idle();
    assert_eq!(s.actual(), -2000);
    assert!(s.bit(0) && s.bit(15), "{}", s.describe());
}

/// Bits 14/15 for limits moved past the position and external force at standstill
/// (PSD-STS-14-SET-2, PSD-STS-15-SET-2, PSD-STS-14-SET-3, PSD-STS-15-SET-3,
/// PSD-STS-15-RESET-1, PSD-STS-15-NOPOS).
#[test]
fn limit_bits_at_standstill() {
    let mut s = drive();
    go(&mut s, 4000);
    s.write(42, 3000);
    assert!(s.bit(14));
    s.write(42, 805_200);
    assert!(!s.bit(14));
    s.write(43, 5000);
    assert!(s.bit(15));
    s.write(43, -805_200);
    assert!(!s.bit(15));
    s.write(43, 3990);
    s.env(EnvChange::Displace { by: -20 });
    assert!(s.bit(15));
    s.env(EnvChange::Displace { by: 20 });
    assert!(!s.bit(15));
    // A positioning run to the lower limit does not set bit 15.
    s.write(45, -250);
    go(&mut s, 3990);
    assert!(!s.bit(15) && s.bit(0));
}

// ---------------------------------------------------------------- 4.3 velocity

/// Speeds never exceed par. 53/56, speed changes never exceed par. 58/59, and the
/// deceleration falls as the target nears (PSD-VEL-002, PSD-VEL-003, PSD-VEL-004,
/// PSD-VEL-005).
#[test]
fn velocity_profile() {
    let mut s = drive();
    s.write(53, 300);
    s.write(58, 500);
    s.write(59, 1500);
    s.send(0x14, 100_000);
    let mut v = vec![0.0];
    assert!(s.until(600_000, |s| {
        v.push(s.rpm());
        s.idle()
    }));
    let dv: Vec<f64> = v.windows(2).map(|w| w[1] - w[0]).collect();
    let max = v.iter().cloned().fold(0.0, f64::max);
    assert!((max - 300.0).abs() < 1e-9, "cruise at par. 53: {max}");
    assert!(
        dv.iter().all(|d| *d <= 0.5 + 1e-9),
        "acceleration ≤ 500 rpm/s"
    );
    assert!(
        dv.iter().all(|d| *d >= -1.5 - 1e-9),
        "deceleration ≤ 1500 rpm/s"
    );
    // The harmonious end: the last braking steps are gentler than the full deceleration.
    let braking: Vec<f64> = dv.iter().copied().filter(|d| *d < 0.0).collect();
    let tail = &braking[braking.len() - 20..braking.len() - 1];
    assert!(tail.iter().all(|d| *d > -1.0), "{tail:?}");
    assert_eq!(s.actual(), 100_000);
}

// ---------------------------------------------------------------- 4.4 torque, 4.5 obstruction

/// A load above the operating torque but below the start-up torque moves the drive during
/// par. 71 and stalls it after; above the start-up torque it never moves (PSD-TRQ-001,
/// PSD-TRQ-002, PSD-PAR-64-001, PSD-PAR-71-001, PSD-OBST-001, PSD-OBST-007).
#[test]
fn torque_limits_and_stall() {
    let mut s = drive();
    // Delivery: par. 63 = 50 cNm for 200 ms, then par. 64 = 40 cNm.
    s.env(EnvChange::LoadTorque { cnm: 45 });
    s.send(0x14, 400_000);
    s.step(150);
    assert!(s.running() && s.actual() > 0);
    s.step(100);
    assert!(
        !s.running(),
        "stalled after the start-up phase: {}",
        s.describe()
    );
    assert!(!s.bit(10));
    s.wait_idle();
    assert!(s.bit(10) && !s.bit(6), "{}", s.describe());
    let mut s = drive();
    s.env(EnvChange::LoadTorque { cnm: 60 });
    s.send(0x14, 400_000);
    s.step(150);
    assert_eq!(s.actual(), 0);
}

/// An obstruction aborts the run after par. 70 below par. 57 % (200 ms at delivery); the
/// drive then holds with par. 66 (PSD-OBST-001, PSD-OBST-003, PSD-OBST-007, PSD-OBST-008,
/// PSD-STS-10-SET-1, PSD-PAR-70-001, PSD-PAR-57-001, PSD-PAR-66-001).
#[test]
fn obstruction_detection_time() {
    let mut s = drive();
    s.send(0x14, 40_000);
    s.step(500);
    s.env(EnvChange::Jam { on: true });
    s.step(200);
    assert!(!s.bit(10), "not before 200 ms: {}", s.describe());
    assert!(!s.running());
    s.step(2);
    assert!(s.bit(10), "{}", s.describe());
    assert!(s.idle());
    assert_eq!(s.drive.core().holding_torque(), Some(s.par(66)));
    assert!(core_events(&mut s).iter().any(|e| matches!(
        e,
        CoreEvent::RunEnded {
            outcome: Outcome::Obstructed,
            ..
        }
    )));
}

/// After an obstruction a changed target starts a new run at once; the same target only
/// after the release was withdrawn and set again with bit 2 (PSD-OBST-004, PSD-OBST-005,
/// PSD-STS-10-RESET-1).
#[test]
fn obstruction_same_target_exception() {
    let mut s = drive();
    s.send(0x14, 40_000);
    s.step(300);
    s.env(EnvChange::Jam { on: true });
    s.wait_idle();
    s.env(EnvChange::Jam { on: false });
    let stuck = s.actual();
    s.send(0x14, 40_000);
    s.step(300);
    assert_eq!(s.actual(), stuck);
    assert!(s.bit(10));
    s.send(0x10, 40_000);
    s.step(100);
    assert_eq!(
        s.actual(),
        stuck,
        "release alone keeps it (0x10 is no release edge)"
    );
    s.send(0x04, 40_000);
    s.send(0x14, 40_000);
    assert!(!s.bit(10));
    s.wait_idle();
    assert_eq!(s.actual(), 40_000);
    // A changed target after an obstruction runs at once.
    s.send(0x14, 60_000);
    s.step(300);
    s.env(EnvChange::Jam { on: true });
    s.wait_idle();
    s.env(EnvChange::Jam { on: false });
    go(&mut s, 20_000);
    assert_eq!(s.actual(), 20_000);
}

/// An obstruction inside the positioning window is not recognised: bit 0 wins over bit 10
/// (PSD-OBST-009, PSD-STS-0-PRIO, erratum PSD-ERRATUM-019).
#[test]
fn obstruction_inside_the_window_counts_as_reached() {
    for (reading, both) in [("exclusive", false), ("both", true)] {
        let mut s = drive_with(&[("psd-bit0-priority", reading)]);
        s.env(EnvChange::Block { at: 3999 });
        go(&mut s, 4000);
        assert_eq!(s.actual(), 3999);
        assert!(s.bit(0), "{reading}: {}", s.describe());
        assert_eq!(s.bit(10), both, "{reading}: {}", s.describe());
    }
}

/// 4.10 reference run to a block with the recommended settings: a manual run at reduced
/// torque runs into the block, stops with bit 10 after 100 ms below 60 %, and frees itself
/// with a short manual run the other way (PSD-REF-001..PSD-REF-012, PSD-OBST-006).
#[test]
fn reference_run_to_a_block() {
    let mut s = drive();
    let run = &family().psd4xx().unwrap().positioning.reference_run;
    for setting in &run.settings {
        for p in &setting.params {
            let pnu: u16 = p.parse().unwrap();
            let value = match (setting.value, setting.percent_of_max) {
                (Some(v), _) => Some(v),
                (None, Some(pc)) => {
                    let param = family().parameter(p).unwrap();
                    let model = family().model(MODEL).unwrap();
                    let r = family().resolve(param, Some(model)).range.unwrap();
                    Some((r.max().unwrap() * pc / 100).max(r.min().unwrap()))
                }
                (None, None) => None,
            };
            if let Some(v) = value {
                s.write(pnu, v);
            }
        }
    }
    assert_eq!(
        (s.par(57), s.par(70), s.par(65), s.par(66)),
        (60, 100, 0, 0)
    );
    // 1e: the block lies well inside the limits.
    s.env(EnvChange::Block { at: -20_000 });
    assert!(run.manual_run);
    s.control(0x12);
    s.wait_running();
    let (lo, _) = s.span_until_idle();
    assert_eq!(lo, -20_000);
    assert!(!s.bit(6) && s.bit(10), "{}", s.describe());
    s.control(0x00);
    s.control(0x11);
    s.step(300);
    s.control(0x10);
    s.wait_idle();
    assert!(s.actual() > -20_000 && !s.bit(10));
}

// ---------------------------------------------------------------- 4.6 readjustment

fn readjusting() -> Sim {
    let mut s = drive();
    s.write(47, 1);
    go(&mut s, 4000);
    s
}

/// Turned against the loop at standstill the drive returns to the target; bit 11 is set
/// (erratum PSD-ERRATUM-022) and bit 0 again after the adjustment (PSD-ADJ-001, PSD-ADJ-005,
/// PSD-STS-11-SET-1, PSD-STS-0-RESET-4, PSD-STS-0-SET-4, PSD-PAR-47-001).
#[test]
fn readjust_against_the_loop() {
    let mut s = readjusting();
    s.env(EnvChange::Displace { by: -100 });
    assert!(s.bit(11) && !s.bit(0));
    s.step(1);
    assert!(s.running());
    s.wait_idle();
    assert_eq!(s.actual(), 4000);
    assert!(s.bit(0) && s.bit(11), "{}", s.describe());
    // Within the window nothing happens.
    s.env(EnvChange::Displace { by: -2 });
    assert!(s.bit(0));
    s.step(10);
    assert!(!s.running());
}

/// Turned in the loop direction: bit 11, bit 0 reset, no adjustment; back into the window
/// sets bit 0 again; loop 0 adjusts both ways (PSD-ADJ-003, PSD-ADJ-004, PSD-STS-0-SET-3).
#[test]
fn readjust_directions() {
    let mut s = readjusting();
    s.env(EnvChange::Displace { by: 100 });
    s.step(300);
    assert_eq!(s.actual(), 4100);
    assert!(s.bit(11) && !s.bit(0));
    s.env(EnvChange::Displace { by: -99 });
    assert!(s.bit(0), "back in the window: {}", s.describe());
    // PSD-STS-11-RESET-1: the next run command resets bit 11.
    s.control(0x04);
    s.send(0x14, 5000);
    assert!(!s.bit(11));
    let mut s = drive();
    s.write(47, 1);
    s.write(45, 0);
    go(&mut s, 4000);
    s.env(EnvChange::Displace { by: 100 });
    s.wait_idle();
    assert_eq!(s.actual(), 4000);
}

/// Without motor voltage no adjustment starts; bits 10 and 13 are set and the returning
/// voltage starts nothing (PSD-ADJ-006, PSD-ADJ-008, PSD-STS-10-SET-3, PSD-STS-13-SET-3).
#[test]
fn readjust_without_motor_voltage() {
    let mut s = readjusting();
    s.env(EnvChange::MotorVoltage { dv: 100 });
    s.step(200);
    assert!(!s.bit(4));
    s.env(EnvChange::Displace { by: -100 });
    assert!(s.bit(10) && s.bit(13) && !s.bit(0), "{}", s.describe());
    s.env(EnvChange::MotorVoltage { dv: 240 });
    s.step(500);
    assert!(s.bit(4) && !s.running());
    assert_eq!(s.actual(), 3900);
}

/// Release or par. 47 off prevent the adjustment; after an aborted run it adjusts only once a
/// new run has completed (PSD-ADJ-009, PSD-ADJ-010).
#[test]
fn readjust_prevented() {
    let mut s = readjusting();
    s.control(0x00);
    s.env(EnvChange::Displace { by: -100 });
    s.step(300);
    assert_eq!(s.actual(), 3900);
    let mut s = readjusting();
    s.write(47, 0);
    s.env(EnvChange::Displace { by: -100 });
    s.step(300);
    assert_eq!(s.actual(), 3900);
    // Aborted by a stop command; the release is set again but the new run command cannot
    // run (no motor voltage), so no run has completed since.
    let mut s = readjusting();
    s.send(0x14, 400_000);
    s.step(300);
    s.control(0x00);
    s.wait_idle();
    s.env(EnvChange::MotorVoltage { dv: 100 });
    s.step(200);
    s.control(0x10);
    assert!(s.bit(13));
    s.env(EnvChange::MotorVoltage { dv: 240 });
    s.step(200);
    let x = s.actual();
    s.env(EnvChange::Displace { by: -100 });
    s.step(300);
    assert_eq!(s.actual(), x - 100);
    assert!(!s.running() && s.drive.core().run_kind().is_none());
}

/// A drive that keeps losing its position adjusts whenever it just leaves the window (4.6
/// notice; PSD-ADJ-005), with the bit-11 reading "no-readjust-only" leaving bit 11 clear
/// (erratum PSD-ERRATUM-022).
#[test]
fn readjust_while_drifting() {
    let mut s = Sim::with(
        DriveConfig::new(MODEL)
            .with_readings(readings(&[("psd-bit11-readjust", "no-readjust-only")])),
    );
    s.write(47, 1);
    go(&mut s, 4000);
    s.env(EnvChange::BackDrive { rpm: -1 });
    s.events();
    s.step(2000);
    let adjustments = core_events(&mut s)
        .iter()
        .filter(|e| {
            matches!(
                e,
                CoreEvent::RunStarted {
                    kind: RunKind::Readjust,
                    ..
                }
            )
        })
        .count();
    assert!(adjustments >= 2, "{adjustments}");
    assert!(s.actual().abs_diff(4000) <= 3);
    assert!(!s.bit(11));
}

// ---------------------------------------------------------------- 3.6 supply, temperature, error

/// Bit 4 follows the averaged motor voltage (par. 76), bit 13 is set by a run command without
/// it and reset by one with it (PSD-STS-4-SET-1, PSD-STS-4-RESET-1, PSD-STS-13-SET-1,
/// PSD-STS-13-RESET-1, PSD-PAR-90-001, PSD-PAR-90-002, PSD-PAR-76-001, PSD-RUN-012).
#[test]
fn motor_voltage_window() {
    let mut s = drive();
    // A 10 ms dip to 0 V is averaged away.
    s.env(EnvChange::MotorVoltage { dv: 0 });
    s.step(10);
    s.env(EnvChange::MotorVoltage { dv: 240 });
    s.step(200);
    assert!(s.bit(4));
    // formula-motor-voltage-window: 18.5 V is not above the limit, 18.6 V is; 30 V is not
    // below 30 V.
    for (dv, ok) in [
        (185, false),
        (186, true),
        (299, true),
        (300, false),
        (310, false),
    ] {
        let mut s = drive();
        s.env(EnvChange::MotorVoltage { dv });
        s.step(200);
        s.send(0x14, 4000);
        s.step(1);
        assert_eq!(s.running(), ok, "{dv}: {}", s.describe());
        assert_eq!(s.bit(13), !ok, "{dv}");
        // At exactly 18.5 V or 30 V bit 4 keeps its state (neither "above" nor "below").
        if dv != 185 && dv != 300 {
            assert_eq!(s.bit(4), ok, "{dv}");
        }
    }
    let mut s = drive();
    s.env(EnvChange::MotorVoltage { dv: 100 });
    s.step(200);
    s.control(0x11);
    assert!(s.bit(13));
    s.control(0x00);
    s.env(EnvChange::MotorVoltage { dv: 240 });
    s.step(200);
    s.control(0x11);
    assert!(!s.bit(13));
}

/// During a run the voltage may fall to 17.5 V; below it the run ends with bit 13
/// (PSD-PAR-90-003, PSD-STS-13-SET-2, erratum PSD-ERRATUM-020).
#[test]
fn motor_voltage_during_a_run() {
    let mut s = drive();
    s.send(0x14, 400_000);
    s.step(300);
    s.env(EnvChange::MotorVoltage { dv: 180 });
    s.step(300);
    assert!(s.running() && !s.bit(4) && !s.bit(13), "{}", s.describe());
    s.env(EnvChange::MotorVoltage { dv: 170 });
    s.step(300);
    assert!(s.bit(13) && !s.running(), "{}", s.describe());
    let mut s = drive_with(&[("psd-run-voltage", "umot-limit")]);
    s.send(0x14, 400_000);
    s.step(300);
    s.env(EnvChange::MotorVoltage { dv: 180 });
    s.step(300);
    assert!(s.bit(13) && !s.running());
}

/// Bit 7 above par. 91, reset 5 °C below it (PSD-STS-7-SET-1, PSD-STS-7-RESET-1,
/// PSD-PAR-91-001; vector formula-temperature-hysteresis).
#[test]
fn temperature_hysteresis() {
    let mut s = drive();
    for (c, bit) in [(80, false), (81, true), (76, true), (75, true), (74, false)] {
        s.env(EnvChange::Temperature { celsius: c });
        assert_eq!(s.bit(7), bit, "{c} °C");
    }
    s.write(91, 50);
    s.env(EnvChange::Temperature { celsius: 51 });
    assert!(s.bit(7));
    assert_eq!(s.par(8), 51);
}

/// An internal position error sets bit 9 and stops the run; no run starts until a reset
/// (PSD-STS-9-SET-1, PSD-STS-9-NORUN, PSD-STS-9-RESET-1, PSD-PAR-96-001, PSD-STS-8-SET-2).
#[test]
fn error_bit() {
    let mut s = drive();
    s.send(0x14, 400_000);
    s.step(300);
    s.env(EnvChange::PositionFault);
    assert!(s.bit(9));
    s.wait_idle();
    s.send(0x14, 0);
    s.step(100);
    assert!(!s.running() && s.bit(9));
    go(&mut s, 4000);
    s.write(96, -6);
    assert!(!s.bit(9) && s.bit(8), "{}", s.describe());
    // Turning the shaft out of the encoder's range is a position error too.
    let mut s = drive();
    s.env(EnvChange::Displace { by: 806_000 });
    assert!(s.bit(9) && s.bit(14));
}

/// The toggle bit is echoed at once, whatever else happens (PSD-STS-2-SET-1,
/// PSD-STS-2-RESET-1, PSD-CTL-13-001).
#[test]
fn toggle_echo() {
    let mut s = drive();
    s.send(0x2014, 4000);
    assert!(s.bit(2));
    s.step(50);
    s.control(0x0014);
    assert!(!s.bit(2));
    assert!(s.running(), "the toggle alone is no command");
    s.control(0x2014);
    assert!(s.bit(2));
}

/// Reserved bits or both manual bits abort a positioning run with bit 5 (PSD-STS-5-SET-2,
/// PSD-CTL-3-001, PSD-CTL-5-001, PSD-CTL-7-001, PSD-CTL-14-001, PSD-CTL-ZERO-001,
/// PSD-RUN-011, erratum PSD-ERRATUM-021).
#[test]
fn invalid_control_combinations() {
    for bad in [0x001C_u16, 0x0034, 0x0094, 0x1014, 0x4014, 0x8014, 0x0013] {
        let mut s = drive();
        s.send(0x14, 400_000);
        s.step(300);
        s.control(bad);
        assert!(s.bit(5), "{bad:#06x}: {}", s.describe());
        s.wait_idle();
        assert!(s.actual() < 400_000);
    }
    // At standstill an invalid word starts nothing.
    let mut s = drive();
    s.send(0x1C, 4000);
    s.step(100);
    assert!(!s.running() && !s.bit(5));
    // With the reading "both" 0x13 is no invalid combination and starts no run either.
    let mut s = drive_with(&[("psd-ctl-0x13", "both")]);
    s.control(0x13);
    s.step(100);
    assert!(!s.running() && !s.bit(5));
}

// ---------------------------------------------------------------- 3.9 and 4.9

/// Connection lost: outputs 0, the run aborts with bit 5; restored with valid data the run
/// starts again at once (PSD-OUT-002, PSD-ABORT-001, PSD-ABORT-002, PSD-ABORT-003,
/// PSD-ABORT-004, erratum PSD-ERRATUM-063).
#[test]
fn connection_loss() {
    let mut s = drive();
    s.send(0x14, 400_000);
    s.step(300);
    s.link(LinkEvent::Lost);
    assert_eq!(s.drive.outputs_in_force().control, 0);
    assert!(s.bit(5));
    s.step(300);
    assert!(
        !s.running(),
        "the controller cannot stop it anyway: it is stopped"
    );
    s.link(LinkEvent::Connected);
    s.send(0x14, 400_000);
    s.step(1);
    assert!(s.running() && !s.bit(5));
    // The other reading: the abort leaves bit 5.
    let mut s = drive_with(&[("psd-master-failure", "internal-resume")]);
    s.send(0x14, 400_000);
    s.step(300);
    s.link(LinkEvent::Lost);
    s.wait_idle();
    assert!(!s.bit(5));
}

/// A watchdog time-out is a lost connection (4.9; DriveConfig::watchdog_us).
#[test]
fn watchdog_timeout() {
    let mut config = DriveConfig::new(MODEL);
    config.watchdog_us = Some(50 * MS);
    let mut s = Sim::with(config);
    s.send(0x14, 400_000);
    s.step(300);
    s.drive.advance(s.now + 100 * MS);
    assert!(!s.drive.connected());
    assert!(s.bit(5));
}

/// IOPS bad: the outputs keep their last value and the run completes; new images are
/// ignored until IOPS is good again (PSD-OUT-001).
#[test]
fn iops_bad_keeps_outputs() {
    let mut s = drive();
    s.send(0x14, 40_000);
    s.step(100);
    s.link(LinkEvent::IopsBad);
    s.send(0x00, 0);
    s.wait_idle();
    assert_eq!(s.actual(), 40_000);
    assert!(s.bit(0) && !s.bit(5));
    s.link(LinkEvent::IopsGood);
    s.send(0x14, 0);
    s.wait_idle();
    assert_eq!(s.actual(), 0);
}

/// Power-on without controller: the outputs are 0 and images are ignored until the
/// controller connects; runs may begin at once after (PSD-OUT-003, PSD-START-016,
/// PSD-PD-010, PSD-REF-001).
#[test]
fn power_on_without_controller() {
    let mut config = DriveConfig::new(MODEL);
    config.connected = false;
    let mut s = Sim::with(config);
    assert_eq!(s.drive.outputs_in_force().control, 0);
    s.send(0x14, 4000);
    s.step(100);
    assert!(!s.running());
    s.link(LinkEvent::Connected);
    s.send(0x14, 4000);
    s.step(1);
    assert!(s.running());
}

/// A geared model uses its own ranges, speeds and encoder span (PSD-MAP-029,
/// PSD-PAR-MODEL-001, PSD-MODEL-P53, PSD-MODEL-P41).
#[test]
fn geared_model() {
    let mut s = Sim::new("PSD426");
    assert_eq!(
        (s.par(41), s.par(42), s.par(43), s.par(53)),
        (256_000, 254_800, -254_800, 63)
    );
    assert_eq!(s.try_write(53, 1318), Err(2));
    s.send(0x14, 254_800);
    s.step(2000);
    assert_eq!(s.drive.core().speed_rpm(), 63);
    s.send(0x14, 260_000);
    assert!(s.bit(12));
}
