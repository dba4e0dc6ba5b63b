//! The positioning core on its own, configured with PSD4xx numbers (manual 4.1, 4.2.1, 4.2.3,
//! 4.5, 3.6): commands, environment and time in, status and position out; identical inputs
//! give identical outputs.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod common;

use common::*;
use drivespec_positioner::machine::{Command, CoreEvent, Outcome, RunKind, Setting};
use drivespec_positioner::{EnvChange, Environment, Flag, Positioner};

fn core() -> Positioner {
    Positioner::new(psd_core(), psd_settings(), Environment::default())
}

fn cmd(word: u16, target: i64) -> Command {
    Command {
        manual_up: word & 0x01 != 0,
        manual_down: word & 0x02 != 0,
        transfer: word & 0x04 != 0,
        release: word & 0x10 != 0,
        no_loop: word & 0x40 != 0,
        toggle: word & 0x2000 != 0,
        reserved: word & !0x2057 != 0,
        target,
    }
}

/// Runs until no run is in progress; returns the lowest position passed.
fn settle(p: &mut Positioner) -> i64 {
    let mut lo = p.actual();
    for _ in 0..1_000_000 {
        let t = p.now() + 1000;
        p.advance(t);
        lo = lo.min(p.actual());
        if p.run_kind().is_none() && p.speed_rpm() == 0 {
            return lo;
        }
    }
    panic!("never settled");
}

/// 4.2.1 cases 1 and 2 through typed commands (PSD-POS-010, PSD-POS-011, PSD-STS-0-SET-1,
/// PSD-STS-8-RESET-2).
#[test]
fn loop_cases_on_the_core() {
    let mut p = core();
    assert!(p.flags().get(Flag::AgainstLoop));
    p.command(0, cmd(0x14, 8000));
    settle(&mut p);
    assert_eq!(p.actual(), 8000);
    assert!(p.flags().get(Flag::Reached) && !p.flags().get(Flag::AgainstLoop));
    let now = p.now();
    p.command(now, cmd(0x14, 4000));
    assert_eq!(settle(&mut p), 3750);
    assert_eq!(p.actual(), 4000);
    assert_eq!(p.status_word(), 0x0011);
}

/// A manual run up to the limit, and the events it leaves (PSD-RUN-004, PSD-STS-14-SET-1).
#[test]
fn manual_run_events() {
    let mut p = core();
    p.set(0, Setting::UpperLimit, 1000).unwrap();
    p.command(0, cmd(0x11, 0));
    settle_manual(&mut p);
    assert_eq!(p.actual(), 1000);
    assert!(p.flags().get(Flag::UpperLimit));
    let events: Vec<CoreEvent> = std::iter::from_fn(|| p.poll_event())
        .map(|(_, e)| e)
        .collect();
    assert!(events.contains(&CoreEvent::RunEnded {
        kind: RunKind::Manual,
        outcome: Outcome::LimitReached,
        actual: 1000
    }));
}

fn settle_manual(p: &mut Positioner) {
    for _ in 0..100_000 {
        let t = p.now() + 1000;
        p.advance(t);
        if p.is_standstill() && p.speed_rpm() == 0 {
            return;
        }
    }
    panic!("never settled");
}

/// Time is a grid: how the caller slices it does not change the result; the same inputs give
/// the same outputs (style rule 11).
#[test]
fn slicing_time_changes_nothing() {
    let run = |step: u64| {
        let mut p = core();
        p.command(0, cmd(0x14, 30_000));
        let mut t = 0;
        let mut samples = Vec::new();
        while t < 6_000_000 {
            let next = (t + step).min(6_000_000);
            if t < 1_500_000 && next >= 1_500_000 {
                p.advance(1_500_000);
                p.env(1_500_000, EnvChange::Displace { by: 7 });
            }
            t = next;
            p.advance(t);
            if t % 500_000 == 0 {
                samples.push((t, p.actual(), p.speed_rpm(), p.status_word()));
            }
        }
        samples
    };
    let a = run(1000);
    assert_eq!(a, run(1000));
    assert_eq!(a, run(250));
    assert_eq!(a, run(100_000));
    assert_eq!(a.len(), 12);
}

/// With the control voltage gone the core does nothing; it powers on again with lash assumed
/// (PSD-STS-8-SET-1).
#[test]
fn power_off_and_on() {
    let mut p = core();
    p.command(0, cmd(0x14, 8000));
    settle(&mut p);
    let now = p.now();
    p.env(now, EnvChange::ControlVoltage { dv: 0 });
    assert!(!p.powered());
    p.command(now, cmd(0x14, 0));
    p.advance(now + 100_000);
    assert_eq!(p.actual(), 8000);
    p.env(now + 100_000, EnvChange::ControlVoltage { dv: 240 });
    assert!(p.powered() && p.flags().get(Flag::AgainstLoop));
    assert_eq!(p.axis().target(), None);
}
