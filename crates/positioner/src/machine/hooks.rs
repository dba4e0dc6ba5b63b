//! Hooks through which a family model adds the rules of its manual that the shared core does not
//! apply on its own (PSx3xx manual 3.4, 3.5, 5.3, 5.4, 5.10, 5.12): family status rules, the
//! family's own run-start edges, fixed-distance jog steps, the initial reference loop,
//! readjustment in both directions and braking-free waypoints.
//!
//! Nothing here runs unless a family calls it, so the PSD4xx behaviour of the core is
//! unchanged. Like the rest of the core, nothing here panics or reads a clock.

use super::{Command, CoreEvent, Micros, Motion, Plan, Positioner, Refusal, RunKind};
use crate::config::Ramp;
use crate::status::Flag;

impl Positioner {
    /// Sets or resets one status flag for a family rule the core does not apply itself, then
    /// applies the priorities (PSx3xx 3.4, e.g. PSX-STS-14-RESET-1, PSX-CTL-14-1).
    pub fn put_flag(&mut self, flag: Flag, on: bool) {
        self.flags.put(flag, on);
        self.normalize();
    }

    /// Takes `cmd` as the command in force without acting on it, so the edges of the next
    /// [`Positioner::command`] are measured against it (PSx3xx 5.3: the family decides which
    /// release edges start a run).
    pub fn assume_command(&mut self, cmd: Command) {
        self.prev = cmd;
    }

    /// Turns a manual run (or a jog step) into braking with the deceleration, without the
    /// manual-run lock, so a positioning command given next takes over from the shaft's speed
    /// (PSX-CMD-007: a target transferred during a manual run ends it and is approached at once).
    /// Returns whether a manual run was active.
    pub fn supersede_manual(&mut self, now: Micros) -> bool {
        self.advance(now);
        let running = match &self.motion {
            Motion::Manual { .. } => true,
            Motion::Positioning(p) => p.kind == RunKind::Manual,
            Motion::Stopping { after_manual, .. } => *after_manual,
            Motion::Idle => false,
        };
        if !running {
            return false;
        }
        if !matches!(self.motion, Motion::Stopping { .. }) {
            let actual = self.actual();
            self.emit(CoreEvent::RunEnded {
                kind: RunKind::Manual,
                outcome: super::Outcome::Superseded,
                actual,
            });
        }
        self.motion = Motion::Stopping {
            rate: self.ramp_rate(Ramp::Parameter),
            after_manual: false,
        };
        self.completed_ok = false;
        true
    }

    /// Starts a manual movement over `distance` increments in direction `dir` (+1 / −1),
    /// ending at the end limit in that direction at the latest (PSX-JOG-005 jog step,
    /// PSX-JOG-008). It runs like a positioning run at the positioning speed setting (the
    /// family sets it to the manual speed), obeys the manual-run status rules
    /// (PSX-STS-0-RESET-2, PSX-STS-8-SET-1) and reports its end as a manual run reaching its
    /// goal; the family then calls [`Positioner::settle_run`]. Returns whether it started.
    pub fn start_step(&mut self, now: Micros, dir: i8, distance: i64) -> bool {
        self.advance(now);
        if !self.powered || dir == 0 || distance <= 0 {
            return false;
        }
        // PSX-STS-9-BLOCK: no run orders while the error bit is set.
        if self.flags.get(Flag::Error) {
            self.refuse(Refusal::Error);
            return false;
        }
        if !self.start_voltage_ok() {
            self.refuse(Refusal::NoMotorVoltage);
            return false;
        }
        let x = self.actual();
        let (lo, hi) = self.limits();
        let wanted = x.saturating_add(i64::from(dir).saturating_mul(distance));
        let goal = if dir > 0 {
            wanted.min(hi.max(x))
        } else {
            wanted.max(lo.min(x))
        };
        if goal == x {
            return false;
        }
        self.flags.put(Flag::Reached, false);
        let loop_dir = self.loop_dir();
        if loop_dir != 0 && dir == -loop_dir {
            self.flags.put(Flag::AgainstLoop, true);
        }
        self.completed_ok = false;
        self.centre = None;
        self.hold_upper = false;
        self.hold_lower = false;
        if self.kin.vel == 0.0 {
            self.run_started = self.clock;
        }
        self.stall_us = 0;
        self.emit(CoreEvent::RunStarted {
            kind: RunKind::Manual,
            target: None,
            waypoints: vec![goal],
        });
        self.motion = Motion::Positioning(Plan {
            kind: RunKind::Manual,
            target: goal,
            waypoints: vec![goal],
            leg: 0,
            attempt: self.cfg.loop_rules.attempts.max(1),
            no_loop: true,
            approach: 0,
        });
        self.normalize();
        true
    }

    /// Starts the initial reference loop: `distance` increments against direction `dir`, then
    /// back in direction `dir` to the start (PSX-CTL-7-1). It runs also while the error bit is
    /// set (PSX-STS-9-BLOCK) and checks the motor voltage (PSX-STS-13-SET-1,
    /// PSX-STS-13-RESET-1). The family calls [`Positioner::settle_run`] when it ends.
    pub fn start_reference_loop(&mut self, now: Micros, dir: i8, distance: i64) -> bool {
        self.advance(now);
        if !self.powered || dir == 0 || distance <= 0 {
            return false;
        }
        if !self.start_voltage_ok() {
            self.flags.put(Flag::VoltageMissing, true);
            self.refuse(Refusal::NoMotorVoltage);
            self.normalize();
            return false;
        }
        self.flags.put(Flag::VoltageMissing, false);
        let x = self.actual();
        let back = x.saturating_sub(i64::from(dir).saturating_mul(distance));
        self.flags.put(Flag::Reached, false);
        self.completed_ok = false;
        self.centre = None;
        self.hold_upper = false;
        self.hold_lower = false;
        if self.kin.vel == 0.0 {
            self.run_started = self.clock;
        }
        self.stall_us = 0;
        self.emit(CoreEvent::RunStarted {
            kind: RunKind::Positioning,
            target: Some(x),
            waypoints: vec![back, x],
        });
        self.motion = Motion::Positioning(Plan {
            kind: RunKind::Positioning,
            target: x,
            waypoints: vec![back, x],
            leg: 0,
            attempt: self.cfg.loop_rules.attempts.max(1),
            no_loop: true,
            approach: dir,
        });
        self.normalize();
        true
    }

    /// Settles the end of a run the family started through a hook: target reached only when
    /// `reached_in_window` and the valid target lies within the positioning window
    /// (PSX-STS-0-SET-2 after the reference loop; a jog step never sets it, PSX-JOG-005).
    pub fn settle_run(&mut self, reached_in_window: bool) {
        let actual = self.actual();
        let window = self.axis.values().window.unsigned_abs();
        let inside = self
            .axis
            .target()
            .is_some_and(|t| actual.abs_diff(t) <= window);
        let reached = reached_in_window && inside;
        self.flags.put(Flag::Reached, reached);
        self.completed_ok = reached;
        self.was_inside = inside;
        self.normalize();
    }

    /// Readjusts to the valid target at standstill (PSX-ADJ-004: with control bit 6 in both
    /// directions); with the motor voltage out of range no readjustment starts and the
    /// obstruction and voltage flags are set (PSX-ADJ-006). Returns whether a run started.
    pub fn readjust(&mut self, now: Micros, no_loop: bool) -> bool {
        self.advance(now);
        if !self.powered || self.motion != Motion::Idle {
            return false;
        }
        let Some(target) = self.axis.target() else {
            return false;
        };
        if self.flags.get(Flag::MotorOk) && self.start_voltage_ok() {
            self.start_positioning(target, no_loop, RunKind::Readjust)
        } else {
            self.flags.put(Flag::Obstruction, true);
            self.flags.put(Flag::VoltageMissing, true);
            self.normalize();
            false
        }
    }

    /// Inserts positions to pass before the rest of the positioning run in progress
    /// (PSX-CTL-11-1: breaking-free steps); false when no positioning run is in progress.
    pub fn insert_waypoints(&mut self, points: &[i64]) -> bool {
        let Motion::Positioning(plan) = &mut self.motion else {
            return false;
        };
        for (i, w) in points.iter().enumerate() {
            let at = plan.leg.saturating_add(i).min(plan.waypoints.len());
            plan.waypoints.insert(at, *w);
        }
        true
    }
}
