//! The motor and the operating modes that turn it (manual 3.3 Pr0, Pr5–Pr15, Pr28, b40.2–b40.7,
//! b40.12, b40.13, b41.0–b41.3; 3.6 Pr6; 3.6.3 jog, test profile and wiring test; 3.6.4
//! positioner; appendix F): an ideal shaft whose speed follows the speed-loop reference within
//! the ramps, and whose position integrates the speed.
//!
//! The motor runs in the "slow operating mode" slot of appendix F (every 2.048 ms from
//! power-up) and only while something moves or is about to. Its state lives in the
//! parameters (Pr0, Pr6, Pr7, Pr28, Pr60:61, Pr62:63, b41.0–b41.3, b70.7, b70.8) plus the
//! fraction of a step and the profile being generated; a master's write of Pr62:63 moves the
//! motor position.
//!
//! Decisions where the manual is silent, each marked DECISION below. Nothing here panics;
//! the cost of one slot is constant.

use super::drive::Drive;
use super::layout::sign_extend;
use super::names;
use crate::line::Micros;
use crate::memory::{BitAddr, ParamMap, Slot};
use drivespec_spec::hpd::Protocol;

/// Position steps per motor revolution (manual 3.6.4, HPD-FORMULA-017).
const STEPS_PER_REV: f64 = 4096.0;
/// Microseconds per minute: rpm × µs / this = revolutions.
const US_PER_MIN: f64 = 60_000_000.0;
/// Ramp parameters count ms per 1000 rpm (manual 3.3 Pr8–Pr12, 3.6.4 Pr51: s/krpm, 0.001 s).
const RPM_PER_RAMP: f64 = 1000.0;
/// Microseconds per ramp unit (0.001 s).
const US_PER_RAMP_UNIT: f64 = 1000.0;
/// Microseconds per unit of the mode-8 pause Pr54 (manual 3.6.3: tenths of a second).
const US_PER_PAUSE_UNIT: Micros = 100_000;

/// How the motor uses the freedom the manual leaves it (3.3: ramps are limits; 3.6.4: the
/// profile start is "not generated on a constant time base").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MotionStyle {
    /// Time from a command to the start of the motion it asks for (µs).
    pub start_latency_us: Micros,
    /// Share of the steepest ramp the parameters allow that the motor uses, in percent.
    pub ramp_percent: u32,
}

impl Default for MotionStyle {
    /// No latency, the steepest ramp the parameters allow.
    fn default() -> MotionStyle {
        MotionStyle {
            start_latency_us: 0,
            ramp_percent: 100,
        }
    }
}

/// The parameters and bits the motor reads and writes, resolved once from the spec.
#[derive(Debug, Clone)]
pub(super) struct MotorLayout {
    tick_us: Micros,
    speed: Slot,
    internal: Slot,
    reserved: Slot,
    main: Slot,
    /// Pr8..Pr12.
    ramps: [Slot; 5],
    overspeed: Slot,
    window_high: Slot,
    window_low: Slot,
    shaft: Slot,
    p50: Slot,
    p51: Slot,
    p52: Slot,
    p53: Slot,
    p54: Slot,
    p56: Slot,
    p57: Slot,
    reference: Slot,
    position: Slot,
    increment: Slot,
    pb40: u8,
    pb41: u8,
    pb70: u8,
    pub(super) style: MotionStyle,
}

impl MotorLayout {
    /// Resolves the motor's parameters from the spec (appendix F slot, 3.3, 3.6 tables).
    pub(super) fn new(
        protocol: &Protocol,
        map: &ParamMap,
        style: MotionStyle,
    ) -> Result<MotorLayout, String> {
        let tick_us = protocol
            .task_slots
            .iter()
            .find(|s| s.tasks.iter().any(|t| t == names::TASK_SLOW_MODE))
            .map(|s| Micros::from(s.period_us))
            .filter(|p| *p > 0)
            .ok_or_else(|| format!("no appendix F slot runs the {}", names::TASK_SLOW_MODE))?;
        let slot = |n: u8| {
            map.slot(n)
                .ok_or_else(|| format!("Pr{n} has no serial address"))
        };
        let double = |n: u8| {
            slot(n).map(|s| Slot {
                addr: s.addr,
                size: 4,
            })
        };
        Ok(MotorLayout {
            tick_us,
            speed: slot(0)?,
            internal: slot(5)?,
            reserved: slot(6)?,
            main: slot(7)?,
            ramps: [slot(8)?, slot(9)?, slot(10)?, slot(11)?, slot(12)?],
            overspeed: slot(13)?,
            window_high: slot(14)?,
            window_low: slot(15)?,
            shaft: slot(28)?,
            p50: slot(50)?,
            p51: slot(51)?,
            p52: slot(52)?,
            p53: slot(53)?,
            p54: slot(54)?,
            p56: slot(56)?,
            p57: slot(57)?,
            reference: double(60)?,
            position: double(62)?,
            increment: double(64)?,
            pb40: slot(40)?.addr,
            pb41: slot(41)?.addr,
            pb70: slot(70)?.addr,
            style,
        })
    }
}

/// Bit `y` of the bit parameter at serial address `addr`.
fn bit(addr: u8, y: u8) -> BitAddr {
    BitAddr {
        byte: addr.wrapping_add(y / 8),
        mask: 1 << (y % 8),
    }
}

/// A positioning profile being generated (manual 3.6.4).
#[derive(Debug, Clone, Default)]
struct Profile {
    /// When the motion starts (start latency).
    start_at: Micros,
    /// Reference position at the start (steps).
    from: f64,
    /// Steps to go, signed by the direction (b70.4).
    distance: f64,
    /// Steps done so far (≥ 0).
    done: f64,
    /// Profile speed now (rpm, ≥ 0).
    speed: f64,
    /// Acceleration (rpm/µs), fixed at the start.
    accel: f64,
    /// Deceleration (rpm/µs), fixed at the start.
    decel: f64,
    /// Steady speed (rpm), fixed at the start.
    top: f64,
}

/// The mode-8 test profile between its strokes (manual 3.6.3).
#[derive(Debug, Clone, Copy, PartialEq)]
struct TestProfile {
    /// Direction of the next stroke: 1.0 at positive speed, -1.0 at negative speed.
    next: f64,
    /// When the pause at 0 rpm after a stroke ends; `None` while a stroke runs.
    resume_at: Option<Micros>,
}

/// The motor's own state beyond the parameters.
#[derive(Debug, Clone, Default)]
pub(super) struct Motor {
    /// Shaft speed (rpm).
    speed: f64,
    /// Motor position (steps).
    position: f64,
    /// Position reference of the position loop (steps).
    reference: f64,
    /// The whole steps last written to Pr62:63 and Pr60:61 (a master's write is seen as a
    /// change).
    written: (i64, i64),
    /// Pr7 was last taken from Pr5.
    main_from_internal: bool,
    /// The speed reference while b40.3 freezes it.
    frozen: Option<f64>,
    profile: Option<Profile>,
    /// The mode-8 test profile, from b70.0 until it or b40.2 drops.
    test: Option<TestProfile>,
    /// Mode 12 has oriented the spindle since b40.2 last rose.
    oriented: bool,
    /// b70.8 as last seen (a profile starts on its rise).
    start_seen: bool,
    /// When a jog or speed request was first seen (start latency), by its sign.
    request_since: Option<(Micros, i8)>,
    pub(super) next_tick: Option<Micros>,
}

impl Drive {
    fn mem_i(&self, s: Slot) -> i64 {
        sign_extend(self.working.get(s.addr, s.size), s.size)
    }

    fn mem_set(&mut self, s: Slot, v: i64) {
        self.working.set(s.addr, s.size, v as u32);
    }

    /// After anything the drive takes (a message, a scan, a command): wakes the motor when it
    /// has something to do, on the appendix F grid from power-up.
    pub(super) fn wake_motor(&mut self) {
        if self.motor.next_tick.is_some() || !self.motor_busy() {
            return;
        }
        let tick = self.layout.motor.tick_us;
        let slots = self.clock.saturating_sub(self.epoch) / tick + 1;
        self.motor.next_tick = self.epoch.checked_add(slots.saturating_mul(tick));
    }

    /// Whether the motor moves or a command asks it to.
    fn motor_busy(&self) -> bool {
        let m = &self.motor;
        m.speed != 0.0
            || m.profile.is_some()
            || m.test.is_some()
            || self.testing()
            || self.request() != 0.0
            || self.start_pending()
            || self.wiring_pending()
            || self.orientation_pending()
    }

    /// A rise of b70.8 in mode 9 not yet taken.
    fn start_pending(&self) -> bool {
        let ml = &self.layout.motor;
        self.mode() == names::MODE_POSITIONER
            && self.working.bit(bit(ml.pb70, names::B70_START))
            && !self.motor.start_seen
    }

    /// The speed the active operating mode requests (manual 3.6, Pr6), rpm.
    fn mode_request(&self) -> f64 {
        let ml = &self.layout.motor;
        let b70 = |y| self.working.bit(bit(ml.pb70, y));
        match self.mode() {
            // HPD-MODE-8-001: b70.1 forward, b70.2 reverse at Pr50, with b70.0 = 0.
            // DECISION: both jog bits at once request nothing.
            names::MODE_MAINTENANCE if !b70(names::B70_TEST_PROFILE) => {
                let v = self.mem_i(ml.p50) as f64;
                match (b70(names::B70_JOG_FORWARD), b70(names::B70_JOG_REVERSE)) {
                    (true, false) => v,
                    (false, true) => -v,
                    _ => 0.0,
                }
            }
            // HPD-MODE-8-005: with b70.0 = 1 the test profile's speed.
            names::MODE_MAINTENANCE | names::MODE_POSITIONER | names::MODE_ORIENTATION => self
                .motor
                .profile
                .as_ref()
                .map_or(0.0, |p| p.speed * p.distance.signum()),
            _ => 0.0,
        }
    }

    /// The main reference Pr7 (manual 3.3 Pr2–Pr5, HPD-FORMULA-007): Pr5 with b40.12 = 1
    /// and b40.13 = 0; otherwise what the analogue or frequency input gives, as last measured
    /// ([`Drive::set_value`] of Pr7). DECISION: nothing is connected to those inputs, so
    /// leaving the internal reference brings Pr7 back to 0.
    fn main_reference(&self) -> i64 {
        let ml = &self.layout.motor;
        if self.internal_reference() {
            self.mem_i(ml.internal)
        } else if self.motor.main_from_internal {
            0
        } else {
            self.mem_i(ml.main)
        }
    }

    /// Whether Pr7 follows Pr5: b40.12 = 1 and b40.13 = 0 (manual 3.3 Pr5).
    fn internal_reference(&self) -> bool {
        let ml = &self.layout.motor;
        self.working.bit(bit(ml.pb40, names::B40_DIGITAL))
            && !self.working.bit(bit(ml.pb40, names::B40_FREQUENCY))
    }

    /// The speed-loop reference (HPD-MODE-002): Pr6 with b40.2 = 1, Pr7 with b40.2 = 0.
    fn request(&self) -> f64 {
        let ml = &self.layout.motor;
        if self.working.bit(bit(ml.pb40, names::B40_RESERVED)) {
            self.mode_request()
        } else {
            self.main_reference() as f64
        }
    }

    /// Keeps Pr6, Pr7 and b41.0–b41.3 in line with the motor (manual 3.3).
    pub(super) fn refresh_motor_status(&mut self) {
        let ml = self.layout.motor.clone();
        if self.mode() != names::MODE_ORIENTATION
            || !self.working.bit(bit(ml.pb40, names::B40_RESERVED))
        {
            self.motor.oriented = false;
        }
        let main = self.main_reference();
        self.mem_set(ml.main, main);
        self.motor.main_from_internal = self.internal_reference();
        let request = self.mode_request().round() as i64;
        self.mem_set(ml.reserved, request);
        let speed = self.mem_i(ml.speed);
        let reference = if self.working.bit(bit(ml.pb40, names::B40_RESERVED)) {
            request
        } else {
            main
        };
        let high = self.mem_i(ml.window_high);
        let low = self.mem_i(ml.window_low);
        // HPD-BIT-41-1: absolute window on the speed (b40.7 = 1), else on the speed error.
        let windowed = if self.working.bit(bit(ml.pb40, names::B40_ABSOLUTE_WINDOW)) {
            speed
        } else {
            reference - speed
        };
        let w = &mut self.working;
        // HPD-BIT-41-0, HPD-BIT-41-2, HPD-BIT-41-3.
        w.set_bit(
            bit(ml.pb41, 0),
            speed.abs() > sign_extend(w.get(ml.overspeed.addr, ml.overspeed.size), 2),
        );
        w.set_bit(bit(ml.pb41, 1), low < windowed && windowed < high);
        w.set_bit(bit(ml.pb41, 2), speed == 0);
        w.set_bit(bit(ml.pb41, 3), speed > 0);
    }

    /// The motor's next slot, if it is awake.
    pub(super) fn next_motor(&self) -> Option<Micros> {
        self.motor.next_tick
    }

    /// One slot of the slow operating mode at `t` (appendix F).
    pub(super) fn motor_tick(&mut self, t: Micros) {
        let ml = self.layout.motor.clone();
        let dt = ml.tick_us as f64;
        self.adopt_written_positions();
        self.wiring_test();
        self.start_profile(t);
        let mode = self.mode();
        let b40 = |d: &Drive, y| d.working.bit(bit(ml.pb40, y));
        let orienting = mode == names::MODE_ORIENTATION && b40(self, names::B40_RESERVED);
        let testing = self.testing();
        // DECISION: leaving mode 9, or mode 12 and its b40.2, or in mode 8 b70.0 or b40.2,
        // abandons a profile; the speed loop then ramps the motor down.
        if mode != names::MODE_POSITIONER && !orienting && !testing {
            self.motor.profile = None;
        }
        if !testing {
            self.motor.test = None;
        }
        if !orienting {
            self.motor.oriented = false;
        }
        self.start_orientation(t);
        self.test_stroke(t);
        let positioning = self.motor.profile.is_some();
        if positioning {
            self.profile_step(t, dt);
        } else {
            let mut target = self.request();
            // HPD-BIT-40-3: a frozen reference keeps its value.
            if b40(self, names::B40_FREEZE) {
                target = *self.motor.frozen.get_or_insert(target);
            } else {
                self.motor.frozen = None;
            }
            let target = self.delayed(t, target);
            // HPD-BIT-40-4, -5, -6, HPD-PAR-027: stroke ends and stop ramp down on Pr12.
            let stop = b40(self, names::B40_STOP)
                || (target < 0.0 && b40(self, names::B40_LEFT_END))
                || (target > 0.0 && b40(self, names::B40_RIGHT_END));
            let (target, stop) = if stop { (0.0, true) } else { (target, false) };
            let old = self.motor.speed;
            let new = self.ramped(old, target, stop, dt);
            self.motor.speed = new;
            let moved = (old + new) / 2.0 * dt * STEPS_PER_REV / US_PER_MIN;
            self.motor.position += moved;
            self.motor.reference = self.motor.position;
        }
        // HPD-MODE-12-SERVO-ERROR: in mode 12 b70.5 is 0 while the position error (none for
        // the ideal loop) is within Pr56.
        if mode == names::MODE_ORIENTATION {
            self.working
                .set_bit(bit(ml.pb70, names::B70_SERVO_ERROR), false);
        }
        self.write_motor();
        self.refresh_motor_status();
        self.motor.next_tick = None;
        if self.motor_busy() {
            self.motor.next_tick = t.checked_add(ml.tick_us);
        }
    }

    /// The request as the motor takes it: a new non-zero request starts after the start
    /// latency of the motion style.
    fn delayed(&mut self, t: Micros, target: f64) -> f64 {
        let sign = target.signum() as i8;
        let latency = self.layout.motor.style.start_latency_us;
        match self.motor.request_since {
            Some((_, s)) if s == sign => {}
            _ => self.motor.request_since = Some((t, sign)),
        }
        match self.motor.request_since {
            // The motor keeps its speed until the latency has passed.
            Some((since, _)) if target != 0.0 && t < since.saturating_add(latency) => {
                self.motor.speed
            }
            _ => target,
        }
    }

    /// The speed after one slot of `dt` µs towards `target` (HPD-PAR-026: Pr8 accelerating
    /// and Pr9 decelerating at positive speed, Pr10 and Pr11 at negative speed; HPD-PAR-027:
    /// Pr12 on a stop).
    fn ramped(&self, speed: f64, target: f64, stop: bool, dt: f64) -> f64 {
        let ml = &self.layout.motor;
        let ramp = |i: usize| {
            let units = ml
                .ramps
                .get(i)
                .map_or(1, |s| self.working.get(s.addr, s.size))
                .max(1);
            RPM_PER_RAMP / (f64::from(units) * US_PER_RAMP_UNIT) * f64::from(ml.style.ramp_percent)
                / 100.0
        };
        let rising = target > speed;
        let index = match (speed > 0.0 || (speed == 0.0 && target > 0.0), rising) {
            (_, _) if stop => 4,
            (true, true) => 0,
            (true, false) => 1,
            (false, false) => 2,
            (false, true) => 3,
        };
        let step = ramp(index) * dt;
        // A change of sign ends at 0 in this slot; the next one accelerates on its own ramp.
        let bound = if speed != 0.0 && target.signum() != speed.signum() {
            0.0
        } else {
            target
        };
        if rising {
            (speed + step).min(bound)
        } else {
            (speed - step).max(bound)
        }
    }

    /// A master's write of Pr62:63 or Pr60:61 moves the motor or the reference position.
    fn adopt_written_positions(&mut self) {
        let ml = self.layout.motor.clone();
        if !names::POSITION_MODES.contains(&self.mode()) {
            return;
        }
        let pos = self.mem_i(ml.position);
        let reference = self.mem_i(ml.reference);
        if pos != self.motor.written.0 {
            self.motor.position = pos as f64;
        }
        if reference != self.motor.written.1 {
            self.motor.reference = reference as f64;
        }
    }

    /// Pr0, Pr28 and, in the position modes, Pr60:61 and Pr62:63 from the motor.
    fn write_motor(&mut self) {
        let ml = self.layout.motor.clone();
        self.mem_set(ml.speed, self.motor.speed.round() as i64);
        let steps = self.motor.position.floor() as i64;
        self.mem_set(ml.shaft, steps.rem_euclid(STEPS_PER_REV as i64));
        if names::POSITION_MODES.contains(&self.mode()) {
            let reference = self.motor.reference.floor() as i64;
            let (p, r) = (i64::from(steps as i32), i64::from(reference as i32));
            self.mem_set(ml.position, p);
            self.mem_set(ml.reference, r);
            self.motor.written = (p, r);
        }
    }

    /// HPD-MODE-9-001, HPD-MODE-9-002: a rise of b70.8 in mode 9 with b40.2 = 1 starts a
    /// profile of Pr64:65 steps in the direction of b70.4.
    fn start_profile(&mut self, t: Micros) {
        let ml = self.layout.motor.clone();
        let start = self.working.bit(bit(ml.pb70, names::B70_START));
        if self.mode() != names::MODE_POSITIONER || self.motor.profile.is_some() {
            self.motor.start_seen = start;
            return;
        }
        let rise = start && !self.motor.start_seen;
        self.motor.start_seen = start;
        if !rise || !self.working.bit(bit(ml.pb40, names::B40_RESERVED)) {
            return;
        }
        let steps = self.mem_i(ml.increment);
        // DECISION: an increment that is not positive (3.6.4: "must be always positive")
        // runs no profile; b70.8 is cleared as at the end of one.
        if steps <= 0 {
            self.working.set_bit(bit(ml.pb70, names::B70_START), false);
            return;
        }
        let dir = if self.working.bit(bit(ml.pb70, names::B70_DIRECTION)) {
            -1.0
        } else {
            1.0
        };
        let accel = self.ramp_of(ml.p51);
        let top = (self.mem_i(ml.p52).abs() as f64).max(1.0);
        self.motor.profile = Some(Profile {
            start_at: t.saturating_add(ml.style.start_latency_us),
            from: self.motor.reference,
            distance: dir * steps as f64,
            accel,
            decel: accel,
            top,
            ..Profile::default()
        });
        // HPD-MODE-9-PROFILE-BUSY.
        self.working.set_bit(bit(ml.pb70, names::B70_BUSY), true);
    }

    /// One slot of the trapezoidal profile (manual 3.6.4: acceleration Pr51, speed Pr52):
    /// the reference position moves, the motor follows it (an ideal position loop).
    fn profile_step(&mut self, t: Micros, dt: f64) {
        let ml = self.layout.motor.clone();
        let Some(mut p) = self.motor.profile.take() else {
            return;
        };
        if t < p.start_at {
            self.motor.profile = Some(p);
            return;
        }
        let (accel, decel, top) = (p.accel, p.decel, p.top);
        let total = p.distance.abs();
        let left = total - p.done;
        let per_rpm_us = STEPS_PER_REV / US_PER_MIN;
        let old = p.speed;
        // The highest speed from which the distance left after this slot (at about the
        // present speed) can still be braked.
        let rest = (left - old * dt * per_rpm_us).max(0.0);
        let brakeable = (2.0 * decel * rest / per_rpm_us).sqrt();
        // At least one slot's speed change, so that the profile ends.
        let mut new = (old + accel * dt)
            .min(top)
            .min(brakeable)
            .max(old - decel * dt)
            .max(accel.min(decel) * dt);
        let mut moved = (old + new) / 2.0 * dt * per_rpm_us;
        let finished = moved >= left;
        if finished {
            moved = left;
            new = 0.0;
        }
        p.done += moved;
        p.speed = new;
        let dir = p.distance.signum();
        self.motor.reference = if finished {
            p.from + p.distance
        } else {
            p.from + dir * p.done
        };
        self.motor.position = self.motor.reference;
        self.motor.speed = dir * new;
        // HPD-MODE-8-005: the pause of Pr54 tenths of a second at 0 rpm after a stroke.
        let tenths = u64::try_from(self.mem_i(ml.p54)).unwrap_or(0);
        if let Some(test) = self.motor.test.as_mut().filter(|_| finished) {
            test.resume_at = Some(t.saturating_add(tenths.saturating_mul(US_PER_PAUSE_UNIT)));
        }
        if finished && self.mode() == names::MODE_POSITIONER {
            // HPD-MODE-9-PROFILE-BUSY, HPD-MODE-9-START-CLEAR: both bits drop at the end.
            self.working.set_bit(bit(ml.pb70, names::B70_BUSY), false);
            self.working.set_bit(bit(ml.pb70, names::B70_START), false);
            self.motor.start_seen = false;
        }
        if !finished {
            self.motor.profile = Some(p);
        }
    }

    /// The acceleration a ramp parameter in ms per 1000 rpm allows (rpm/µs), as the motion
    /// style uses it.
    fn ramp_of(&self, slot: Slot) -> f64 {
        let units = self.working.get(slot.addr, slot.size).max(1);
        RPM_PER_RAMP / (f64::from(units) * US_PER_RAMP_UNIT)
            * f64::from(self.layout.motor.style.ramp_percent)
            / 100.0
    }

    /// Whether the mode-8 test profile is asked for: b70.0 = 1 with b40.2 = 1 (manual 3.6.3).
    fn testing(&self) -> bool {
        let ml = &self.layout.motor;
        self.mode() == names::MODE_MAINTENANCE
            && self.working.bit(bit(ml.pb40, names::B40_RESERVED))
            && self.working.bit(bit(ml.pb70, names::B70_TEST_PROFILE))
    }

    /// HPD-MODE-8-005, HPD-MODE-8-006: the strokes of the mode-8 test profile. The first,
    /// when b70.0 rises with b40.2 = 1, by the starting point Pr53 (1: Pr52 revolutions at
    /// positive speed, 2: Pr52 / 2 at positive speed, 3: Pr52 at negative speed); each one
    /// after it Pr52 revolutions the other way, once the pause after the last has passed. A
    /// stroke is a trapezoid at Pr51 rpm that ends on its distance ("no overrun").
    /// DECISION: the manual gives the profile no ramps; it accelerates on the speed loop's
    /// ramps Pr8 (positive speed) or Pr10 (negative) and decelerates on Pr9 or Pr11, as the
    /// motion style uses them. Any other starting point starts as 1; a distance
    /// below 0 counts as 0.
    fn test_stroke(&mut self, t: Micros) {
        if !self.testing() || self.motor.profile.is_some() {
            return;
        }
        let ml = self.layout.motor.clone();
        let revs = self.mem_i(ml.p52).max(0) as f64;
        let (dir, revs, start_at) = match self.motor.test {
            None => {
                let (dir, revs) = match self.mem_i(ml.p53) {
                    names::START_HALF_FORWARD => (1.0, revs / 2.0),
                    names::START_REVERSE => (-1.0, revs),
                    _ => (1.0, revs),
                };
                (dir, revs, t.saturating_add(ml.style.start_latency_us))
            }
            Some(TestProfile {
                next,
                resume_at: Some(at),
            }) if t >= at => (next, revs, t),
            Some(_) => return,
        };
        let [up, down, up_reverse, down_reverse, _] = ml.ramps;
        let (accel, decel) = if dir > 0.0 {
            (up, down)
        } else {
            (up_reverse, down_reverse)
        };
        self.motor.profile = Some(Profile {
            start_at,
            from: self.motor.position,
            distance: dir * revs * STEPS_PER_REV,
            accel: self.ramp_of(accel),
            decel: self.ramp_of(decel),
            top: (self.mem_i(ml.p51).abs() as f64).max(1.0),
            ..Profile::default()
        });
        self.motor.test = Some(TestProfile {
            next: -dir,
            resume_at: None,
        });
    }

    /// Mode 12 waits for its orientation: b40.2 = 1 and not oriented yet.
    fn orientation_pending(&self) -> bool {
        let ml = &self.layout.motor;
        self.mode() == names::MODE_ORIENTATION
            && self.working.bit(bit(ml.pb40, names::B40_RESERVED))
            && !self.motor.oriented
    }

    /// HPD-MODE-12-001: with b40.2 = 1 mode 12 reaches Pr50 on the ramp Pr52, turns at that
    /// speed to the shaft position Pr54 and closes the position loop there. DECISION: it
    /// turns forward, at least one revolution, so that the speed is reached first.
    fn start_orientation(&mut self, t: Micros) {
        if !self.orientation_pending() || self.motor.profile.is_some() {
            return;
        }
        let ml = self.layout.motor.clone();
        self.motor.oriented = true;
        let rev = STEPS_PER_REV as i64;
        let shaft = self.motor.position.floor() as i64;
        let to = self.mem_i(ml.p54).rem_euclid(rev);
        let distance = (to - shaft).rem_euclid(rev) + rev;
        let accel = self.ramp_of(ml.p52);
        let top = (self.mem_i(ml.p50).abs() as f64).max(1.0);
        self.motor.profile = Some(Profile {
            start_at: t.saturating_add(ml.style.start_latency_us),
            from: shaft as f64,
            distance: distance as f64,
            accel,
            decel: accel,
            top,
            ..Profile::default()
        });
    }

    /// HPD-MODE-8-004: b70.3 in mode 8 runs the wiring test; with b40.9 = 1 (or the drive
    /// disabled through the hardware enable, which the model never gets) it ends at once with
    /// code 1, shown in Pr56 when Pr57 = 0, and b70.3 drops (HPD-MODE-8-003).
    fn wiring_test(&mut self) {
        let ml = self.layout.motor.clone();
        let test = bit(ml.pb70, names::B70_WIRING_TEST);
        if self.mode() != names::MODE_MAINTENANCE || !self.working.bit(test) {
            return;
        }
        self.working.set_bit(test, false);
        if self.mem_i(ml.p57) == 0 {
            self.mem_set(ml.p56, names::WIRING_DISABLED);
        }
    }

    /// Whether b70.3 waits for the wiring test in mode 8.
    fn wiring_pending(&self) -> bool {
        let ml = &self.layout.motor;
        self.mode() == names::MODE_MAINTENANCE
            && self.working.bit(bit(ml.pb70, names::B70_WIRING_TEST))
    }

    /// The position commands of modes 9–11 (HPD-MODE-9-006, HPD-MODE-9-005): accepted only
    /// with no profile executing.
    pub(super) fn position_command(&mut self, kind: PositionCommand) {
        let ml = self.layout.motor.clone();
        if self.motor.profile.is_some() {
            return;
        }
        // HPD-MODE-10-007: in mode 10 the reset needs the axis released (b70.8 = 0).
        if self.mode() == names::MODE_LOCKING && self.working.bit(bit(ml.pb70, names::B70_START)) {
            return;
        }
        self.adopt_written_positions();
        match kind {
            PositionCommand::ClearIncrement => self.mem_set(ml.increment, 0),
            PositionCommand::Zero => {
                self.motor.position = 0.0;
                self.motor.reference = 0.0;
            }
            PositionCommand::Shaft => {
                let shaft = self.mem_i(ml.shaft) as f64;
                self.motor.position = shaft;
                self.motor.reference = shaft;
            }
            PositionCommand::ReferenceToMotor => self.motor.reference = self.motor.position,
        }
        if kind != PositionCommand::ClearIncrement {
            self.write_motor();
        }
    }

    /// HPD-PAR-059: while a profile executes in mode 9 its parameters Pr51 and Pr52 cannot
    /// be changed (Pr64:65 can).
    pub(super) fn locked_by_profile(&self, slot: Slot) -> bool {
        let ml = &self.layout.motor;
        self.motor.profile.is_some()
            && self.mode() == names::MODE_POSITIONER
            && (slot == ml.p51 || slot == ml.p52)
    }

    /// The motor at rest, as after power-up.
    pub(super) fn reset_motor(&mut self) {
        self.motor = Motor::default();
        let ml = &self.layout.motor;
        let written = (self.mem_i(ml.position), self.mem_i(ml.reference));
        self.motor.position = written.0 as f64;
        self.motor.reference = written.1 as f64;
        self.motor.written = written;
    }
}

/// A position command of modes 9–11 (manual 3.6.4–3.6.6 b70.2, b70.10–b70.12).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum PositionCommand {
    /// b70.2 in mode 9: Pr64:65 = 0.
    ClearIncrement,
    /// Reset type 1: motor and reference position 0.
    Zero,
    /// Reset type 2: both to the absolute shaft position Pr28.
    Shaft,
    /// Reset type 3: the reference to the motor position.
    ReferenceToMotor,
}
