//! Control of the PSx3xx drive model (manual 3.3.1, 3.5, chapters 4–5): from the control word
//! in force to the core's commands with the PSx3xx run-start rules, time stamps, jog keys and
//! bits, the brake, the master time-out, the drag error and the speed limits in force.

use super::drive::{Deferred, Drive, FamilyRun, Hot, Ideal, JogMode, PendingStamp};
use super::family::{ReservedStamp, Role};
use super::io::Event;
use crate::{Output, Stamp, StampMeaning};
use drivespec_positioner::machine::{Command, Outcome, Setting};
use drivespec_positioner::profile::{self, Ramps};
use drivespec_positioner::{CoreEvent, Flag, Micros, RunKind};
use drivespec_spec::psx3xx::RunAction;

/// Status flags a manual run leaves as they were: 3.4 resets bits 10 and 11 only by a
/// positioning order, bit 12 by a valid setpoint and bit 13 by a positioning or reference
/// loop order (PSX-STS-10-RESET-1, PSX-STS-11-RESET-1, PSX-STS-12-RESET-1, PSX-STS-13-RESET-1).
const KEPT_BY_MANUAL_RUN: [Flag; 4] = [
    Flag::Obstruction,
    Flag::ManualRotation,
    Flag::BadTarget,
    Flag::VoltageMissing,
];

/// Status flags cleared by a 0→1 edge of control bit 14 (PSX-CTL-14-1): bits 5, 10, 11, 12
/// and 13 (bit 1 is the family's drag flag).
const CLEARED_BY_BIT_14: [Flag; 5] = [
    Flag::Aborted,
    Flag::Obstruction,
    Flag::ManualRotation,
    Flag::BadTarget,
    Flag::VoltageMissing,
];

fn ms(v: i64) -> Micros {
    u64::try_from(v.max(0)).unwrap_or(0).saturating_mul(1000)
}

impl Drive<'_> {
    /// A stored value by parameter id, its delivery value when never written (3.1).
    pub(super) fn val(&self, id: &str) -> i64 {
        self.values
            .get(id)
            .copied()
            .or_else(|| self.fam.by_id(id).and_then(|e| e.default))
            .unwrap_or(0)
    }

    /// Copies the working values read on every step out of the map; called whenever the
    /// map changes (manual 3.1 ISDU 118, 142–145, 162).
    pub(super) fn refresh_hot(&mut self) {
        let ids = &self.fam.ids;
        self.hot = Hot {
            timeout: self.val(&ids.timeout),
            speed_positioning: self.val(&ids.speed_positioning),
            speed_manual: self.val(&ids.speed_manual),
            speed_ccw: self.val(&ids.speed_ccw),
            speed_cw: self.val(&ids.speed_cw),
            reversal_pause: self.val(&ids.reversal_pause),
        };
    }

    fn val_opt(&self, id: Option<&str>) -> i64 {
        id.map_or(0, |id| self.val(id))
    }

    /// ISDU 163 or 166 in ms (PSX-ERRATUM-017: raw × 5 ms).
    pub(super) fn five_ms(&self, raw: i64) -> i64 {
        if self.fam.options.five_ms {
            raw.saturating_mul(5)
        } else {
            raw
        }
    }

    /// The bus command of the control word and target in force (manual 3.5, 4.4–4.6).
    pub(super) fn bus_command(&self) -> Command {
        let c = self.fam.controls;
        let w = self.control;
        // PSX-VER-CLEAR: before software 249 bit 14 is reserved like bits 13 and 15.
        let old = self.identity.software < self.fam.format2_software;
        Command {
            manual_up: w & c.manual_up != 0,
            manual_down: w & c.manual_down != 0,
            // PSX-CTL-2-1; an ISDU 112 write transfers its target (PSX-CMD-009).
            transfer: w & c.transfer != 0 || self.transfer_pulse,
            // PSX-CTL-4-1.
            release: w & c.release != 0,
            // PSX-CMD-008, PSX-RUN-007.
            no_loop: w & c.no_loop != 0,
            toggle: false,
            // PSX-CTL-13-1, PSX-CTL-15-1.
            reserved: w & c.must_be_zero != 0 || (old && w & c.clear_errors != 0),
            target: self.target,
        }
    }

    /// Applies a process output image (manual 3.3.1, 4.4–4.6).
    pub(super) fn apply_output(&mut self, now: Micros, out: &Output) {
        match *out {
            Output::TimeStamp { control, stamp } => self.stamp_input(now, control.0, stamp),
            Output::ControlTarget {
                control_word,
                target,
            } => self.set_control(now, control_word, i64::from(target), None),
            Output::SpeedControlTarget {
                target_speed,
                control_word,
                target,
            } => self.set_control(
                now,
                control_word,
                i64::from(target),
                Some(i64::from(target_speed)),
            ),
        }
    }

    /// Whether the process-data speed is valid for the run the control word orders
    /// (PSX-VEL-006, PSX-VEL-007; PSX-ERRATUM-028 "model-range").
    fn speed_valid(&self) -> bool {
        let ts = &self.rules.protocol().target_speed;
        let s = self.pd_speed;
        if s == ts.use_parameter_value {
            return true;
        }
        let manual =
            self.control & (self.fam.controls.manual_up | self.fam.controls.manual_down) != 0;
        let range = if manual {
            &self.fam.manual_speeds
        } else {
            &self.fam.positioning_speeds
        };
        s > 0 && range.contains(s)
    }

    /// A control word and target from formats 1 and 2 (manual 4.5, 4.6).
    fn set_control(&mut self, now: Micros, word: u16, target: i64, speed: Option<i64>) {
        let old = self.control;
        self.control = word;
        self.target = target;
        if let Some(s) = speed {
            self.pd_speed = s;
            if !self.speed_valid() {
                // PSX-VEL-007: no run starts, an active run is aborted, bit 12 is set.
                self.core.put_flag(Flag::BadTarget, true);
                if self.core.run_kind().is_some() {
                    self.core.halt(now);
                }
                self.after_core(now);
                return;
            }
        }
        self.control_changed(now, old);
    }

    /// The control word in force changed from `old` (manual 3.5).
    pub(super) fn control_changed(&mut self, now: Micros, old: u16) {
        let c = self.fam.controls;
        let w = self.control;
        let rising = |bit: u16| w & bit != 0 && old & bit == 0;
        // PSX-CTL-14-1, PSX-VER-CLEAR: a 0→1 edge of bit 14 clears the error bits.
        if rising(c.clear_errors) && self.identity.software >= self.fam.format2_software {
            for f in CLEARED_BY_BIT_14 {
                self.core.put_flag(f, false);
            }
            // PSX-STS-1-RESET-2.
            self.drag = false;
        }
        // PSX-JOG-004: setting the release cancels a jog.
        if w & c.release != 0 && self.jog_active() {
            self.stop_jog(now);
        }
        // PSX-ADJ-009, PSX-ADJ-010: readjustment needs bit 10 and a drive without brake.
        let readjust = i64::from(w & c.readjust != 0 && self.fam.brake.is_none());
        if self.core.get(Setting::Readjust) != readjust {
            let _ = self.core.set(now, Setting::Readjust, readjust);
        }
        self.forward(now);
        // PSX-CTL-7-1: a 0→1 edge of bit 7 with the release runs the initial reference loop.
        if rising(c.reference_loop) && w & c.release != 0 {
            self.start_reference_loop(now, false);
        }
        self.update_jog(now);
        self.after_core(now);
    }

    /// Whether a jog (step, wait for the brake, continuous) is in progress (5.10).
    fn jog_active(&self) -> bool {
        matches!(
            self.family_run,
            FamilyRun::Step(_) | FamilyRun::Continuous(_)
        ) || matches!(self.deferred, Some((_, Deferred::Step(_))))
    }

    fn brake_closed(&self) -> bool {
        self.fam.brake.is_some() && !self.brake_open
    }

    /// Passes the bus command to the core when it changed, deciding with the PSx3xx rules
    /// whether it starts a run (manual 4.4–4.6, 5.3):
    ///
    /// - a transferred target other than the valid one starts a run (PSX-CMD-001,
    ///   PSX-CMD-003, PSX-OBST-003);
    /// - the same target starts only after the release was withdrawn and set again
    ///   (PSX-OBST-004 … PSX-OBST-007);
    /// - setting the release starts a run to a target transferred without release
    ///   (PSX-CMD-005, PSX-CMD-010), not to one already run to (PSX-OBST-006).
    pub(super) fn forward(&mut self, now: Micros) {
        let mut cmd = self.bus_command();
        // PSX-CMD-007: a target transferred during a manual run ends it; the manual bits
        // still set count as withdrawn until they change.
        let bits = cmd.manual_dir_signed();
        match self.manual_masked {
            Some(d) if d == bits => {
                cmd.manual_up = false;
                cmd.manual_down = false;
            }
            Some(_) => self.manual_masked = None,
            None => {}
        }
        // PSX-CTL-4-1: jogs run without the release; words without it leave them alone.
        if self.jog_active() && !cmd.release {
            return;
        }
        if cmd == self.last_cmd && !self.transfer_pulse {
            return;
        }
        let last = self.last_cmd;
        let edge = cmd.release && !last.release;
        if edge {
            self.armed = true;
        }
        let transfer_now = cmd.transfer && (!last.transfer || cmd.target != last.target || edge);
        let dir = cmd.manual_dir_signed();
        let valid = self.core.axis().target();
        let starts = if cmd.reserved || !cmd.release {
            false
        } else if dir == 0 {
            (transfer_now && (Some(cmd.target) != valid || self.armed))
                || (edge && self.pending_transfer && valid.is_some())
        } else if transfer_now {
            // PSX-CMD-007: the transferred target is approached at once.
            self.manual_masked = Some(dir);
            cmd.manual_up = false;
            cmd.manual_down = false;
            true
        } else {
            // PSX-CTL-0-1, PSX-CTL-1-1: on the edge of the release or of the manual bit.
            self.manual_dir != Some(dir) && (edge || last.manual_dir_signed() != dir)
        };
        if !cmd.release && transfer_now {
            self.pending_transfer = true;
        }
        // PSX-BRAKE-003, PSX-BRAKE-007: a run from standstill first waits for the brake.
        if starts && self.brake_closed() && self.core.run_kind().is_none() {
            if self.deferred.is_none() {
                let wait = self.val_opt(self.fam.ids.brake_start.as_deref());
                self.deferred = Some((now.saturating_add(ms(wait)), Deferred::Command));
            }
            return;
        }
        if matches!(self.deferred, Some((_, Deferred::Command))) {
            self.deferred = None;
        }
        self.send(now, cmd, starts);
    }

    /// Sends a command to the core, shaping the edges it sees (manual 5.3).
    fn send(&mut self, now: Micros, cmd: Command, starts: bool) {
        let last = self.last_cmd;
        if cmd.release && cmd.manual_dir_signed() == 0 && !cmd.reserved {
            let plain = Command {
                manual_up: false,
                manual_down: false,
                ..cmd
            };
            if starts {
                // PSX-CMD-007: a target during a manual run ends it and is approached at once.
                self.core.supersede_manual(now);
                self.core.assume_command(Command {
                    release: false,
                    transfer: false,
                    ..plain
                });
            } else {
                self.core.assume_command(Command {
                    release: true,
                    transfer: last.transfer,
                    target: last.target,
                    ..plain
                });
            }
        }
        self.snapshot();
        self.core.command(now, cmd);
        self.last_cmd = cmd;
        self.after_core(now);
        if self.transfer_pulse {
            self.transfer_pulse = false;
            let mut again = self.bus_command();
            if self.manual_masked.is_some() {
                again.manual_up = false;
                again.manual_down = false;
            }
            self.snapshot();
            self.core.command(now, again);
            self.last_cmd = again;
            self.after_core(now);
        }
    }

    // ------------------------------------------------------------------ time stamps

    /// A format 0 image: control code and time stamp (manual 3.3.1, 4.4; PSX-TS-001 …
    /// PSX-TS-008).
    fn stamp_input(&mut self, now: Micros, code: u8, stamp: Stamp) {
        let ts = self.rules.timestamp();
        let mut meaning = stamp.meaning(ts);
        // PSX-LED-006: a valid stamp in the image keeps the orange LED dark.
        self.stamp_streaming = meaning.is_valid();
        if meaning == StampMeaning::Reserved {
            // PSX-ERRATUM-061.
            meaning = match self.fam.options.stamp_reserved {
                ReservedStamp::Ignored => return,
                ReservedStamp::AsInactive => StampMeaning::Inactive,
                ReservedStamp::Clamped => StampMeaning::of(ts, ts.max_valid),
            };
        }
        match meaning {
            StampMeaning::Inactive => {
                // PSX-TS-005: the pending stamp fires once the field turns 0x3FFF; its delay
                // counts from its own reception (PSX-ERRATUM-064).
                if let Some(p) = self.stamp.take() {
                    let from = if self.fam.options.stamp_from_last {
                        p.received
                    } else {
                        now
                    };
                    self.stamp_due = Some((from.saturating_add(u64::from(p.delay_us)), p.code));
                }
            }
            StampMeaning::Immediate { .. } if self.fam.options.stamp_immediate => {
                // PSX-TS-006, PSX-TS-007: executed on reception.
                self.stamp = None;
                self.stamp_due = None;
                self.fire(now, code);
            }
            StampMeaning::Immediate { .. } | StampMeaning::Delayed { .. } => {
                // PSX-TS-004: a new valid stamp replaces the pending one.
                let delay_us = match meaning {
                    StampMeaning::Delayed { delay_us } => delay_us,
                    _ => 0,
                };
                self.stamp = Some(PendingStamp {
                    code,
                    received: now,
                    delay_us,
                });
                self.stamp_due = None;
                self.event(now, Event::StampPending { code, delay_us });
            }
            StampMeaning::Reserved => {}
        }
        self.fire_due(now);
    }

    fn fire_due(&mut self, now: Micros) {
        if let Some((t, code)) = self.stamp_due {
            if t <= now {
                self.stamp_due = None;
                self.fire(now, code);
            }
        }
    }

    /// A stamp fires its control code (PSX-TS-008, PSX-PD-011, PSX-PD-012): the code's bits
    /// replace those of the mask in the control word; the others stay as ISDU 110 set them.
    fn fire(&mut self, now: Micros, code: u8) {
        let ts = self.rules.timestamp();
        let Some(cmd) = ts.command(code) else {
            return;
        };
        let mut word = cmd.control_word;
        if cmd.action == RunAction::Position && self.fam.options.code3_release_only {
            // PSX-ERRATUM-054 reading "release-only".
            word &= self.fam.controls.release;
        }
        let mask = ts.control_word_mask;
        let old = self.control;
        self.control = (old & !mask) | (word & mask);
        // PSX-LED-005: the orange LED acknowledges the stamp with its dark phase.
        self.stamp_fired_at = Some(now);
        self.event(now, Event::StampFired { code });
        self.control_changed(now, old);
    }

    // ------------------------------------------------------------------ jog

    /// Jog inputs by the table of 5.10: (forward, reverse, continuous allowed).
    fn jog_inputs(&self) -> (bool, bool, bool) {
        let c = self.fam.controls;
        let w = self.control;
        let bit4 = w & c.release != 0;
        let bit5 = w & c.key_release != 0;
        let bus = self.link_up;
        // PSX-JOG-001, PSX-JOG-002, PSX-JOG-003: bit 4 wins over bit 5.
        let keys = self.keys_fitted && (!bus || (!bit4 && bit5));
        // PSX-JOG-011: the jog bits with bits 4 and 5 reset.
        let bits = bus && !bit4 && !bit5;
        let forward = (keys && self.keys.forward) || (bits && w & c.jog_forward != 0);
        let reverse = (keys && self.keys.reverse) || (bits && w & c.jog_reverse != 0);
        // PSX-JOG-007, PSX-JOG-012: continuous only with bit 3, always without the bus.
        let continuous = !bus || w & c.continuous != 0;
        (forward, reverse, continuous)
    }

    /// When a held jog input turns into a continuous run (PSX-JOG-006).
    pub(super) fn jog_deadline(&self) -> Option<Micros> {
        match self.jog {
            JogMode::Held { since, .. } if self.jog_inputs().2 => {
                let wait = self.five_ms(self.val(&self.fam.ids.jog_wait));
                Some(since.saturating_add(ms(wait)).max(self.clock))
            }
            _ => None,
        }
    }

    /// The jog state machine (manual 5.10).
    pub(super) fn update_jog(&mut self, now: Micros) {
        if !self.core.powered() {
            self.jog = JogMode::Idle;
            return;
        }
        let (forward, reverse, continuous) = self.jog_inputs();
        if forward && reverse {
            // PSX-JOG-009: both keys cancel a jog; a new one needs both released.
            if self.jog_active() {
                self.stop_jog(now);
            }
            self.jog = JogMode::Blocked;
            return;
        }
        let dir: i8 = match (forward, reverse) {
            (true, false) => 1,
            (false, true) => -1,
            _ => 0,
        };
        for _ in 0..3 {
            let next = match self.jog {
                JogMode::Blocked if dir == 0 => JogMode::Idle,
                JogMode::Blocked => JogMode::Blocked,
                JogMode::Idle if dir != 0 => {
                    // PSX-JOG-005: a press runs one step of ISDU 135.
                    if self.start_jog_step(now, dir) {
                        JogMode::Step { dir, since: now }
                    } else {
                        JogMode::Held { dir, since: now }
                    }
                }
                JogMode::Idle => JogMode::Idle,
                JogMode::Step { dir: d, since } => {
                    // The step completes even when the input is released early (PSX-JOG-005).
                    let waiting = matches!(self.deferred, Some((_, Deferred::Step(x))) if x == d);
                    if self.family_run == FamilyRun::Step(d) || waiting {
                        JogMode::Step { dir: d, since }
                    } else if dir == d {
                        JogMode::Held { dir: d, since }
                    } else {
                        JogMode::Idle
                    }
                }
                JogMode::Held { dir: d, since } if dir == d => {
                    let wait = self.five_ms(self.val(&self.fam.ids.jog_wait));
                    if continuous && now >= since.saturating_add(ms(wait)) {
                        // PSX-JOG-006: held longer than ISDU 163, a continuous run follows.
                        self.start_continuous(now, d);
                        JogMode::Continuous { dir: d }
                    } else {
                        JogMode::Held { dir: d, since }
                    }
                }
                JogMode::Held { .. } => JogMode::Idle,
                JogMode::Continuous { dir: d } => {
                    if dir != d || !continuous {
                        self.stop_jog(now);
                        JogMode::Idle
                    } else if self.family_run != FamilyRun::Continuous(d) {
                        // Ended by the core (block, voltage): nothing until released.
                        JogMode::Held {
                            dir: d,
                            since: Micros::MAX,
                        }
                    } else {
                        JogMode::Continuous { dir: d }
                    }
                }
            };
            let changed = next != self.jog;
            self.jog = next;
            if !changed {
                break;
            }
        }
    }

    fn start_jog_step(&mut self, now: Micros, dir: i8) -> bool {
        if self.brake_closed() && self.core.run_kind().is_none() {
            let wait = self.val_opt(self.fam.ids.brake_start.as_deref());
            self.deferred = Some((now.saturating_add(ms(wait)), Deferred::Step(dir)));
            return true;
        }
        let steps = self.val(&self.fam.ids.jog_step);
        self.update_speeds_for(FamilyRun::Step(dir));
        self.snapshot();
        if self.core.start_step(now, dir, steps) {
            self.family_run = FamilyRun::Step(dir);
            // PSX-STS-5-RESET-1: a new run command.
            self.core.put_flag(Flag::Aborted, false);
            self.event(
                now,
                Event::Jog {
                    dir,
                    continuous: false,
                },
            );
            self.after_core(now);
            true
        } else {
            self.after_core(now);
            false
        }
    }

    fn start_continuous(&mut self, now: Micros, dir: i8) {
        let cmd = Command {
            manual_up: dir > 0,
            manual_down: dir < 0,
            release: true,
            target: self.last_cmd.target,
            ..Command::default()
        };
        self.update_speeds_for(FamilyRun::Continuous(dir));
        self.snapshot();
        self.core.assume_command(Command {
            release: false,
            ..self.last_cmd
        });
        self.core.command(now, cmd);
        self.last_cmd = cmd;
        // A refused manual run (the error bit allows only the reference loop,
        // PSX-STS-9-BLOCK) leaves the run in progress what it was.
        if self.core.run_kind() != Some(RunKind::Manual) {
            self.after_core(now);
            return;
        }
        self.family_run = FamilyRun::Continuous(dir);
        self.event(
            now,
            Event::Jog {
                dir,
                continuous: true,
            },
        );
        self.after_core(now);
    }

    /// Stops a jog with the deceleration, without status bit 5 (PSX-JOG-004, PSX-JOG-009).
    pub(super) fn stop_jog(&mut self, now: Micros) {
        if matches!(self.deferred, Some((_, Deferred::Step(_)))) {
            self.deferred = None;
        }
        match self.family_run {
            FamilyRun::Step(_) => {
                self.core.halt(now);
            }
            FamilyRun::Continuous(_) => {
                let stop = Command {
                    release: true,
                    target: self.last_cmd.target,
                    ..Command::default()
                };
                self.core.command(now, stop);
                let off = Command {
                    release: false,
                    ..stop
                };
                self.core.command(now, off);
                self.last_cmd = off;
            }
            _ => {}
        }
        self.family_run = FamilyRun::None;
        self.jog = JogMode::Idle;
        self.after_core(now);
    }

    // ------------------------------------------------------------------ reference loop

    /// Starts the initial reference loop: 5/8 turn against the loop direction, then back in
    /// loop direction at the manual speed (PSX-CTL-7-1); after ISDU 193 = -1 / -2 the centre
    /// run follows (PSX-CMD-012, PSX-CMD-013).
    pub(super) fn start_reference_loop(&mut self, now: Micros, then_centre: bool) {
        let dir: i8 = if self.val(&self.loop_direction_id()) == 0 {
            1
        } else {
            -1
        };
        let [n, d] = self.fam.loop_turns;
        let ipr = self.core.axis().increments_per_rotation();
        let distance = if d == 0 {
            0.0
        } else {
            (ipr * n as f64 / d as f64).round()
        };
        let distance = if distance.is_finite() {
            distance as i64
        } else {
            0
        };
        self.update_speeds_for(FamilyRun::ReferenceLoop { then_centre });
        if self.core.start_reference_loop(now, dir, distance) {
            self.family_run = FamilyRun::ReferenceLoop { then_centre };
            self.event(now, Event::ReferenceLoop { started: true });
        }
        self.after_core(now);
    }

    fn loop_direction_id(&self) -> String {
        self.fam
            .entries
            .iter()
            .find(|e| e.role == Role::LoopDirection)
            .map(|e| e.id.clone())
            .unwrap_or_default()
    }

    // ------------------------------------------------------------------ core events

    /// Drains the core's events and applies the PSx3xx rules they trigger (manual 3.4).
    pub(super) fn after_core(&mut self, now: Micros) {
        while let Some((at, e)) = self.core.poll_event() {
            match &e {
                CoreEvent::RunStarted {
                    kind, waypoints, ..
                } => self.on_run_started(at, *kind, waypoints),
                CoreEvent::RunEnded { kind, outcome, .. } => self.on_run_ended(at, *kind, *outcome),
                _ => {}
            }
            self.event(at, Event::Core(e));
        }
        if self.pending_reset {
            self.pending_reset = false;
            self.restart(now);
        }
    }

    fn on_run_started(&mut self, at: Micros, kind: RunKind, waypoints: &[i64]) {
        // PSX-STS-1-RESET-1: a new run command resets the drag error.
        self.drag = false;
        self.correction_rpm = 0;
        // PSX-STS-14-RESET-1..3, PSX-STS-15-RESET-1..3.
        self.core.put_flag(Flag::UpperLimit, false);
        self.core.put_flag(Flag::LowerLimit, false);
        self.run_started_at = at;
        self.max_torque = 0;
        self.brake_close_at = None;
        // A run to another target than the safe position is not the time-out's run (the
        // safe run may have waited for the brake and been dropped meanwhile).
        if let FamilyRun::Safe(safe) = self.family_run {
            if self.core.run_target() != Some(safe) {
                self.family_run = FamilyRun::None;
            }
        }
        let family_hook = matches!(
            self.family_run,
            FamilyRun::ReferenceLoop { .. } | FamilyRun::Step(_)
        );
        match kind {
            RunKind::Manual if waypoints.is_empty() => {
                for f in KEPT_BY_MANUAL_RUN {
                    self.core.put_flag(f, self.flags_before.get(f));
                }
                self.manual_dir = Some(self.last_cmd.manual_dir_signed());
            }
            RunKind::Positioning | RunKind::Readjust | RunKind::Centre if !family_hook => {
                self.armed = false;
                self.pending_transfer = false;
                let axis = self.core.axis();
                self.ideal = Some(Ideal {
                    kin: self.core.kinematics(),
                    waypoints: waypoints.iter().map(|w| axis.to_rot(*w)).collect(),
                    leg: 0,
                    top_checked: false,
                });
            }
            _ => {}
        }
    }

    fn on_run_ended(&mut self, at: Micros, kind: RunKind, outcome: Outcome) {
        self.ended = self.ended.wrapping_add(1);
        self.ideal = None;
        if kind == RunKind::Manual && outcome != Outcome::LimitReached {
            self.manual_dir = None;
        }
        match self.family_run {
            FamilyRun::Step(_) if kind == RunKind::Manual => {
                if outcome == Outcome::Reached {
                    // A jog step never sets bit 0 (PSX-JOG-005).
                    self.core.settle_run(false);
                }
                self.family_run = FamilyRun::None;
            }
            FamilyRun::Continuous(_)
                if kind == RunKind::Manual && outcome != Outcome::LimitReached =>
            {
                self.family_run = FamilyRun::None;
            }
            FamilyRun::ReferenceLoop { then_centre } => {
                self.family_run = FamilyRun::None;
                self.event(at, Event::ReferenceLoop { started: false });
                if outcome == Outcome::Reached {
                    // PSX-STS-0-SET-2, PSX-STS-8-RESET-2, PSX-STS-9-RESET-1,
                    // PSX-STS-10-RESET-2, PSX-STS-11-RESET-2.
                    self.core.settle_run(true);
                    for f in [
                        Flag::AgainstLoop,
                        Flag::Error,
                        Flag::Obstruction,
                        Flag::ManualRotation,
                    ] {
                        self.core.put_flag(f, false);
                    }
                    if then_centre {
                        // PSX-CMD-012, PSX-CMD-013, PSX-ISDU-193-MIDRANGE.
                        self.update_speeds_for(FamilyRun::None);
                        self.core.start_centre_run(at);
                    }
                }
            }
            FamilyRun::Safe(_) => self.family_run = FamilyRun::None,
            _ => {}
        }
        if outcome == Outcome::Missed {
            // PSX-STS-9-SET-2: the end position deviates from the absolute encoder.
            self.core.put_flag(Flag::Obstruction, false);
            self.core.put_flag(Flag::Error, true);
        }
    }

    // ------------------------------------------------------------------ per step

    /// The family's rules between two core steps (manual chapters 4–5).
    pub(super) fn tick_rules(&mut self, now: Micros) {
        self.update_drag();
        self.update_torque(now);
        self.fire_due(now);
        self.deferred_due(now);
        self.brake_due(now);
        self.watchdog_due(now);
        self.update_jog(now);
        self.check_encoder();
        self.check_reentry();
        self.check_readjust(now);
        self.update_speeds();
        self.after_core(now);
    }

    /// The flags and run count before the next core action (manual 3.4).
    pub(super) fn snapshot(&mut self) {
        self.flags_before = self.core.flags();
        self.ended_before = self.ended;
    }

    /// PSX-POS-001, PSX-STS-9-SET-1: the encoder measures 256 revolutions ending at the
    /// mapping end, 3 more than the usable range at each end; the error bit means leaving
    /// them (the core flags leaving the usable range, which the PSx3xx still measures).
    pub(super) fn check_encoder(&mut self) {
        if !self.core.powered() {
            return;
        }
        let inside = self.encoder_inside();
        let rose = self.core.flags().get(Flag::Error) && !self.flags_before.get(Flag::Error);
        if rose && inside && !self.fault_injected && self.ended == self.ended_before {
            self.core.put_flag(Flag::Error, false);
        }
        if self.in_encoder && !inside {
            self.core.put_flag(Flag::Error, true);
        }
        self.in_encoder = inside;
    }

    /// Whether the actual position lies in the encoder's 256 revolutions (PSX-POS-001).
    pub(super) fn encoder_inside(&self) -> bool {
        let axis = self.core.axis();
        let end = axis.values().mapping_end;
        let low = end.saturating_sub(axis.scale(self.fam.encoder_span));
        (low..=end).contains(&self.core.actual())
    }

    /// PSX-STS-0-SET-3: back within the window after manual displacement sets bit 0 only
    /// with the readjustment enabled (control bits 4 and 10); the core sets it in any case.
    pub(super) fn check_reentry(&mut self) {
        let c = self.fam.controls;
        let enabled = self.control & c.release != 0 && self.control & c.readjust != 0;
        let rose = self.core.flags().get(Flag::Reached) && !self.flags_before.get(Flag::Reached);
        if rose && !enabled && self.ended == self.ended_before && self.core.run_kind().is_none() {
            self.core.put_flag(Flag::Reached, false);
        }
    }

    fn deferred_due(&mut self, now: Micros) {
        let Some((t, what)) = self.deferred else {
            return;
        };
        if t > now {
            return;
        }
        self.deferred = None;
        self.brake_open = true;
        self.brake_close_at = None;
        self.event(now, Event::Brake { open: true });
        match what {
            Deferred::Command => {
                let before = self.core.run_kind();
                self.forward(now);
                let c = self.fam.controls;
                let steps_bit = self.control & c.free_run != 0 && self.control & c.release != 0;
                let snap = self.fam.brake.is_some_and(|b| b.hold_open);
                let wanted = steps_bit || (snap && self.fam.options.brake_steps_always);
                if before.is_none() && wanted {
                    if let Some(target) = self.core.run_target() {
                        // PSX-CTL-11-1, PSX-CTL-11-2: breaking-free steps in both directions
                        // before the run (PSX-ERRATUM-023 "both-directions").
                        let n = self.val_opt(self.fam.ids.free_steps.as_deref());
                        let x = self.core.actual();
                        let d = if target >= x { 1 } else { -1 };
                        let points = if self.fam.options.brake_both_directions {
                            vec![x - d * n, x]
                        } else {
                            vec![x - d * n]
                        };
                        self.core.insert_waypoints(&points);
                        if let Some(ideal) = &mut self.ideal {
                            let axis = self.core.axis();
                            for (i, p) in points.iter().enumerate() {
                                let at = i.min(ideal.waypoints.len());
                                ideal.waypoints.insert(at, axis.to_rot(*p));
                            }
                        }
                    }
                }
            }
            Deferred::Step(dir) => {
                if !self.start_jog_step(now, dir) {
                    self.jog = JogMode::Held { dir, since: now };
                }
            }
        }
        self.after_core(now);
    }

    fn brake_due(&mut self, now: Micros) {
        let Some(brake) = self.fam.brake else {
            return;
        };
        if !self.brake_open || self.deferred.is_some() {
            return;
        }
        let idle = self.core.run_kind().is_none();
        match self.brake_close_at {
            None if idle => {
                // PSX-BRAKE-005: the snap brake stays open ISDU 165 after the run;
                // PSX-BRAKE-007: the holding brake closes at the end of every run.
                let hold = if brake.hold_open {
                    ms(self.val_opt(self.fam.ids.brake_end.as_deref()))
                } else {
                    0
                };
                self.brake_close_at = Some(now.saturating_add(hold));
                if hold == 0 {
                    self.brake_due(now);
                }
            }
            Some(t) if t <= now => {
                self.brake_close_at = None;
                if idle {
                    self.brake_open = false;
                    self.event(now, Event::Brake { open: false });
                }
            }
            _ => {}
        }
    }

    /// When the master time-out strikes (PSX-TIMEOUT-003, PSX-TIMEOUT-006).
    pub(super) fn watchdog(&self) -> Option<Micros> {
        let limit = self.hot.timeout;
        (limit > 0 && !self.timed_out && self.core.powered())
            .then(|| self.last_rx.saturating_add(ms(limit)))
    }

    fn watchdog_due(&mut self, now: Micros) {
        if self.watchdog().is_none_or(|t| t > now) {
            return;
        }
        self.timed_out = true;
        let c = self.fam.controls;
        let old = self.control;
        let run_before = self.family_run;
        let action = if self.val(&self.fam.ids.timeout_config) == 2 {
            // PSX-TIMEOUT-005: run to ISDU 138, from standstill or during a run.
            let safe = self.val(&self.fam.ids.safe_position);
            // DECISION: the safe position is approached without loop, so that any position
            // within the limits can be the safe one.
            self.control = (old & !(c.manual_up | c.manual_down | c.key_release))
                | c.release
                | c.transfer
                | c.no_loop;
            self.target = safe;
            self.transfer_pulse = true;
            self.armed = true;
            self.family_run = FamilyRun::Safe(safe);
            RunAction::SafePosition
        } else {
            // PSX-TIMEOUT-004: the run is cancelled (as a withdrawn release).
            self.control = old & !c.release;
            RunAction::Abort
        };
        self.event(now, Event::Timeout { action });
        if self.jog_active() {
            self.stop_jog(now);
        }
        self.control_changed(now, old);
        // A run that waits for the brake (5.12, 5.13) is still the run to the safe position.
        // Where the safe position was not taken (the error bit allows only the reference
        // loop, PSX-STS-9-BLOCK), the run in progress goes on as what it was.
        if let FamilyRun::Safe(safe) = self.family_run {
            let started =
                self.core.axis().target() == Some(safe) && self.core.run_target() == Some(safe);
            if !started && self.deferred.is_none() {
                self.family_run = match run_before {
                    FamilyRun::ReferenceLoop { .. } if self.core.run_target().is_some() => {
                        run_before
                    }
                    _ => FamilyRun::None,
                };
            }
        }
    }

    /// Readjustment in both directions with control bit 6 (PSX-ADJ-004): the core readjusts
    /// only against the loop; the family adds the loop direction.
    pub(super) fn check_readjust(&mut self, now: Micros) {
        let c = self.fam.controls;
        let w = self.control;
        let enabled = w & c.release != 0
            && w & c.readjust != 0
            && w & c.no_loop != 0
            && self.fam.brake.is_none();
        let rose = self.core.flags().get(Flag::ManualRotation)
            && !self.flags_before.get(Flag::ManualRotation);
        if enabled && rose && self.core.run_kind().is_none() {
            self.snapshot();
            self.core.readjust(now, true);
            self.after_core(now);
        }
    }

    // ------------------------------------------------------------------ speeds, drag, torque

    /// The speed limits in force for the next core step (PSX-VEL-001, PSX-VEL-002,
    /// PSX-VEL-005, PSX-VEL-006, PSX-VEL-008, PSX-CTL-12-1).
    pub(super) fn update_speeds(&mut self) {
        self.update_speeds_for(self.family_run);
    }

    fn update_speeds_for(&mut self, run: FamilyRun) {
        let hot = self.hot;
        let (cw, ccw) = (hot.speed_cw, hot.speed_ccw);
        // PSX-ISDU-123-MEANING: direction 0 turns clockwise for increasing positions.
        let up_is_cw = self.core.get(Setting::Direction) == 0;
        let (up, down) = if up_is_cw { (cw, ccw) } else { (ccw, cw) };
        let vel = self.core.kinematics().vel;
        let cap = if vel > 0.0 {
            up
        } else if vel < 0.0 {
            down
        } else {
            up.min(down)
        };
        let ts = &self.rules.protocol().target_speed;
        let pd = (self.active_format == ts.format && self.pd_speed > ts.use_parameter_value)
            .then_some(self.pd_speed);
        let manual_isdu = hot.speed_manual;
        let hook_manual = matches!(
            run,
            FamilyRun::Step(_) | FamilyRun::Continuous(_) | FamilyRun::ReferenceLoop { .. }
        );
        let (pos_base, man_base) = if hook_manual {
            (manual_isdu, manual_isdu)
        } else {
            (
                pd.unwrap_or(hot.speed_positioning),
                pd.unwrap_or(manual_isdu),
            )
        };
        self.base_speed_rpm = pos_base.min(cap).max(0);
        let top = self
            .fam
            .positioning_speeds
            .max()
            .unwrap_or(pos_base)
            .min(cap);
        let bottom = self.fam.positioning_speeds.min().unwrap_or(0).min(top);
        let pos = if self.correction_rpm != 0 {
            (self.base_speed_rpm + self.correction_rpm).clamp(bottom, top.max(bottom))
        } else {
            self.base_speed_rpm
        };
        let man = man_base.min(cap).max(0);
        let now = self.clock;
        if self.core.get(Setting::PositioningSpeed) != pos {
            let _ = self.core.set(now, Setting::PositioningSpeed, pos);
        }
        if self.core.get(Setting::ManualSpeed) != man {
            let _ = self.core.set(now, Setting::ManualSpeed, man);
        }
        // PSX-ISDU-162-REVERSE: the idle period before a reversal.
        self.core.set_reversal_pause(hot.reversal_pause);
    }

    /// The computed set position and the drag error (PSX-STS-1-SET-1, PSX-STS-1-SET-2,
    /// PSX-ERRATUM-010), and the drag error correction of control bit 12 (PSX-CTL-12-1,
    /// PSX-CTL-12-2).
    fn update_drag(&mut self) {
        // The computed position waits with the drive for the idle period of a reversal
        // (PSX-ISDU-162-REVERSE).
        if self.core.reversal_pending() {
            self.correction_rpm = 0;
            return;
        }
        let Some(mut ideal) = self.ideal.take() else {
            self.correction_rpm = 0;
            return;
        };
        let cfg = self.core.config();
        let dt = cfg.tick_us as f64 / 1e6;
        let s = self.core.settings().drive;
        let ramps = Ramps {
            vmax: profile::rps(self.base_speed_rpm.max(0) as f64),
            accel: profile::rps(s.acceleration.max(1) as f64),
            decel: profile::rps(s.deceleration.max(1) as f64),
            blend: cfg.blend,
        };
        let Some(goal) = ideal.waypoints.get(ideal.leg).copied() else {
            return;
        };
        let before = ideal.kin.vel.abs();
        let step = profile::approach(ideal.kin, goal, &ramps, dt);
        ideal.kin = step.kin;
        if step.arrived && ideal.leg + 1 < ideal.waypoints.len() {
            ideal.leg += 1;
        }
        let actual = self.core.kinematics();
        let ipr = self.core.axis().increments_per_rotation();
        let drag_steps = (ideal.kin.pos - actual.pos).abs() * ipr;
        let limit = self.val(&self.fam.ids.drag_error) as f64;
        if self.fam.options.drag_by_position && drag_steps > limit {
            self.drag = true;
        }
        let v = ideal.kin.vel.abs();
        if !ideal.top_checked && ramps.vmax > 0.0 && v >= ramps.vmax * (1.0 - 1e-9) {
            ideal.top_checked = true;
            if self.fam.options.drag_by_speed && actual.vel.abs() < v - 2.0 * ramps.accel * dt {
                self.drag = true;
            }
        }
        let c = self.fam.controls;
        let decelerating = v + 1e-12 < before;
        self.correction_rpm = if self.control & c.drag_correction != 0 && !decelerating {
            let sign = if ideal.kin.vel >= 0.0 { 1.0 } else { -1.0 };
            // DECISION: the correction closes the gap within about 1 s.
            let rpm = profile::rpm((ideal.kin.pos - actual.pos) * sign).round();
            if rpm.is_finite() {
                rpm as i64
            } else {
                0
            }
        } else {
            0
        };
        self.ideal = Some(ideal);
    }

    /// ISDU 68 and 69 (PSX-ISDU-68-UNIT, PSX-ISDU-69-PHASES).
    fn update_torque(&mut self, now: Micros) {
        let t = self.torque_now();
        let start = ms(self.core.settings().drive.startup_time_ms);
        let running = self.core.run_kind().is_some() && self.core.run_target().is_some()
            || self.manual_dir.is_some();
        if running && now.saturating_sub(self.run_started_at) >= start {
            self.max_torque = self.max_torque.max(t);
        }
    }

    /// The torque now, cNm: the load, limited by the torque limit while a run drives the
    /// motor and by the holding torque at standstill (DECISION: the manual gives no model).
    pub(super) fn torque_now(&self) -> i64 {
        let load = i64::from(self.core.environment().load_cnm);
        match self.core.holding_torque() {
            Some(h) => load.min(h),
            None => load.min(self.core.torque_limit()),
        }
    }
}

/// The manual direction of a command as +1 / −1 / 0 (manual 3.5 bits 0, 1).
trait ManualDir {
    fn manual_dir_signed(&self) -> i8;
}

impl ManualDir for Command {
    fn manual_dir_signed(&self) -> i8 {
        match (self.manual_up, self.manual_down) {
            (true, false) => 1,
            (false, true) => -1,
            _ => 0,
        }
    }
}
