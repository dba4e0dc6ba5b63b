//! The drive model's mode-8 test profile (manual 3.6.3): b70.0 with b40.2 = 1 runs strokes of
//! Pr52 revolutions at Pr51 rpm, the first by the starting point Pr53, with a pause of Pr54
//! tenths of a second at 0 rpm between them. One scenario per rule, named by its requirement
//! ID; the shaft is followed through Pr28 and Pr0 as a master sees it.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_hpd::model::{Drive, DriveConfig, MotionStyle};
use drivespec_hpd::Micros;
use model_util::*;

const STEPS_PER_REV: i64 = 4096;
/// How often the shaft is looked at (µs).
const EVERY_US: Micros = 5_000;
const RPM: i64 = 60;
const REVS: i64 = 2;
const PAUSE_TENTHS: i64 = 5;

/// One look at the shaft: time, travel from the start (steps, unwrapped), Pr0.
#[derive(Debug, Clone, Copy)]
struct Look {
    t: Micros,
    travel: i64,
    speed: i64,
}

/// A drive in mode 8 with the PLC stopped, the test profile's parameters and the ramps set,
/// b40.2 = 1 and Pr53 = `start`; b70.0 not set yet. Returns the time reached.
fn mode_8(d: &mut Drive, start: i64) -> Micros {
    let mut t = 10;
    for msg in [
        bit(0, "b99.13", false),
        write(0, "Pr31", 8),
        write(0, "Pr51", RPM),
        write(0, "Pr52", REVS),
        write(0, "Pr53", start),
        write(0, "Pr54", PAUSE_TENTHS),
        write(0, "Pr8", 1000),
        write(0, "Pr9", 500),
        write(0, "Pr10", 800),
        write(0, "Pr11", 500),
        bit(0, "b40.2", true),
    ] {
        assert_eq!(exchange(d, t, &msg), [ack(0)], "{msg:?}");
        t += 1_000;
    }
    t
}

/// Follows the shaft from `from` for `us` µs.
fn follow(d: &mut Drive, from: Micros, us: Micros) -> Vec<Look> {
    let mut looks = Vec::new();
    let mut travel = 0;
    let mut last = value(d, "Pr28");
    let mut t = from;
    while t <= from + us {
        d.advance(t);
        let p = value(d, "Pr28");
        let step = (p - last).rem_euclid(STEPS_PER_REV);
        travel += if step >= STEPS_PER_REV / 2 {
            step - STEPS_PER_REV
        } else {
            step
        };
        last = p;
        looks.push(Look {
            t,
            travel,
            speed: value(d, "Pr0"),
        });
        t += EVERY_US;
    }
    looks
}

/// The first stroke: (travel where it stopped, when it stopped, when the next one started,
/// the next one's first speed).
fn first_stroke(looks: &[Look]) -> (i64, Micros, Micros, i64) {
    let from = looks.iter().position(|l| l.speed != 0).unwrap();
    let stop = from + looks[from..].iter().position(|l| l.speed == 0).unwrap();
    let next = stop + looks[stop..].iter().position(|l| l.speed != 0).unwrap();
    (
        looks[stop].travel,
        looks[stop].t,
        looks[next].t,
        looks[next].speed,
    )
}

/// Runs the profile with starting point `start` for `us` µs from b70.0 = 1.
fn run(config: DriveConfig, start: i64, us: Micros) -> Vec<Look> {
    let mut d = Drive::new(spec(), config).unwrap();
    let t = mode_8(&mut d, start);
    assert_eq!(exchange(&mut d, t, &bit(0, "b70.0", true)), [ack(0)]);
    follow(&mut d, t, us)
}

#[test]
fn hpd_mode_8_006_the_starting_point_sets_the_first_stroke() {
    for (start, travel) in [
        (1, REVS * STEPS_PER_REV),
        (2, REVS * STEPS_PER_REV / 2),
        (3, -REVS * STEPS_PER_REV),
    ] {
        let looks = run(DriveConfig::commissioned(0), start, 4_000_000);
        let (end, _, _, next) = first_stroke(&looks);
        assert!((end - travel).abs() <= 1, "Pr53 = {start}: {end} steps");
        assert_eq!(next.signum(), -travel.signum(), "Pr53 = {start}");
    }
}

#[test]
fn hpd_mode_8_005_strokes_at_pr51_pause_pr54_and_alternate() {
    let looks = run(DriveConfig::commissioned(0), 1, 8_000_000);
    assert!(looks.iter().all(|l| l.speed.abs() <= RPM), "above Pr51");
    assert!(looks.iter().any(|l| l.speed == RPM), "Pr51 never reached");
    let (end, stopped, resumed, next) = first_stroke(&looks);
    assert_eq!(end, REVS * STEPS_PER_REV);
    let pause = resumed - stopped;
    let tenths = u64::try_from(PAUSE_TENTHS).unwrap() * 100_000;
    assert!(
        (tenths..=tenths + 2 * EVERY_US).contains(&pause),
        "{pause} µs"
    );
    assert!(next < 0);
    // The second stroke goes back by Pr52 revolutions, then the profile turns forward again.
    let back = looks.iter().map(|l| l.travel).min().unwrap();
    assert!(back.abs() <= 1, "{back}");
    let later: Vec<&Look> = looks.iter().filter(|l| l.t > resumed + 3_000_000).collect();
    assert!(later.iter().any(|l| l.speed > 0), "no third stroke");
}

#[test]
fn hpd_mode_8_005_the_pause_is_at_zero_rpm_with_the_shaft_still() {
    let looks = run(DriveConfig::commissioned(0), 2, 3_000_000);
    let (end, stopped, resumed, _) = first_stroke(&looks);
    let still: Vec<&Look> = looks
        .iter()
        .filter(|l| (stopped..resumed).contains(&l.t))
        .collect();
    assert!(!still.is_empty());
    assert!(still.iter().all(|l| l.speed == 0 && l.travel == end));
}

#[test]
fn hpd_mode_8_005_clearing_b70_0_or_b40_2_stops_the_profile() {
    for clear in ["b70.0", "b40.2"] {
        let mut d = drive(0);
        let t = mode_8(&mut d, 1);
        assert_eq!(exchange(&mut d, t, &bit(0, "b70.0", true)), [ack(0)]);
        let t = t + 500_000;
        d.advance(t);
        assert_eq!(value(&d, "Pr0"), RPM, "{clear}");
        assert_eq!(exchange(&mut d, t, &bit(0, clear, false)), [ack(0)]);
        let looks = follow(&mut d, t, 3_000_000);
        let rest = looks.iter().position(|l| l.speed == 0).unwrap();
        assert!(looks[rest..].iter().all(|l| l.speed == 0), "{clear}");
        let travel = looks.last().unwrap().travel;
        assert!(travel.abs() < STEPS_PER_REV / 8, "{clear}: {travel} steps");
    }
}

#[test]
fn hpd_mode_8_005_gentler_ramps_and_a_late_start_keep_the_strokes() {
    let config = DriveConfig::commissioned(0).with_motion(MotionStyle {
        start_latency_us: 30_000,
        ramp_percent: 20,
    });
    let looks = run(config, 3, 4_000_000);
    let (end, stopped, resumed, next) = first_stroke(&looks);
    assert_eq!(end, -REVS * STEPS_PER_REV);
    assert!(resumed - stopped >= 500_000);
    assert!(next > 0);
    let first = looks.iter().find(|l| l.speed != 0).unwrap();
    assert!(first.t >= looks[0].t + 30_000);
}

#[test]
fn hpd_mode_8_001_jog_bits_do_nothing_while_the_profile_runs() {
    let mut d = drive(0);
    let t = mode_8(&mut d, 1);
    assert_eq!(exchange(&mut d, t, &bit(0, "b70.2", true)), [ack(0)]);
    assert_eq!(
        exchange(&mut d, t + 1_000, &bit(0, "b70.0", true)),
        [ack(0)]
    );
    let looks = follow(&mut d, t + 1_000, 1_000_000);
    assert!(looks.iter().all(|l| l.speed >= 0));
    assert!(looks.iter().any(|l| l.speed == RPM));
}
