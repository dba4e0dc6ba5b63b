//! The positioning core as a sans-IO state machine on virtual time (PSD4xx manual 3.6, 3.7,
//! chapter 4; PSx3xx 3.4, 3.5, chapters 4–5).
//!
//! Feed it typed control commands ([`Positioner::command`]), parameter writes
//! ([`Positioner::set`]), environment changes ([`Positioner::env`]) and the passing of time
//! ([`Positioner::advance`]); read the status flags, position and speed, and drain
//! [`Positioner::poll_event`]. Physics runs in fixed steps of `tick_us` on a grid counted from
//! time 0, so results do not depend on how the caller slices time; inputs between steps act at
//! once on the state and move the shaft from the next step. Nothing reads a clock, spawns a
//! thread or panics; memory is bounded (events are capped at [`MAX_EVENTS`]).
//!
//! Every rule names its requirement ID from `spec/psd4xx`. Decisions where the manuals are
//! silent are marked DECISION.

use crate::axis::{Axis, AxisError, AxisValues};
use crate::config::{Backoff, CoreConfig, Ramp};
use crate::env::{EnvChange, Environment, Wall, MAX_ENV_ENTRIES};
use crate::profile::{self, Kinematics, Ramps};
use crate::status::{Flag, Flags};
use serde::{Deserialize, Serialize};
use std::collections::VecDeque;
use std::sync::Arc;

mod hooks;

/// Virtual time in microseconds (chapter 4).
pub type Micros = u64;

/// Most events kept undrained; older ones are dropped (chapter 4).
pub const MAX_EVENTS: usize = 4096;

/// A control command as the core sees it, decoded from a family's control word and target
/// (PSD4xx 3.7, 4.1, 4.2.3).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Command {
    /// Manual run to larger values (PSD control bit 0) (3.7).
    pub manual_up: bool,
    /// Manual run to smaller values (PSD control bit 1) (3.7).
    pub manual_down: bool,
    /// Transfer the target value (PSD control bit 2) (3.7).
    pub transfer: bool,
    /// Release (PSD control bit 4) (3.7).
    pub release: bool,
    /// Run without reference loop (PSD control bit 6) (3.7).
    pub no_loop: bool,
    /// Toggle bit (PSD control bit 13) (3.7).
    pub toggle: bool,
    /// A reserved bit that must be 0 is set (PSD-CTL-ZERO-001).
    pub reserved: bool,
    /// Target value in user increments (PSD par. 33).
    pub target: i64,
}

impl Command {
    fn same_word(&self, other: &Command) -> bool {
        Command { target: 0, ..*self }
            == Command {
                target: 0,
                ..*other
            }
    }

    fn manual_dir(&self) -> i8 {
        match (self.manual_up, self.manual_down) {
            (true, false) => 1,
            (false, true) => -1,
            _ => 0,
        }
    }
}

/// Parameters of the core other than the position settings (PSD4xx 3.3 par. 47–91).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct DriveSettings {
    /// Readjustment at standstill, 0 or 1 (par. 47).
    pub readjust: i64,
    /// Maximum speed of positioning runs, rpm (par. 53).
    pub positioning_speed: i64,
    /// Maximum speed of manual runs, rpm (par. 56).
    pub manual_speed: i64,
    /// Speed limit for aborting a run, % (par. 57).
    pub block_speed_percent: i64,
    /// Acceleration, rpm/s (par. 58).
    pub acceleration: i64,
    /// Deceleration, rpm/s (par. 59).
    pub deceleration: i64,
    /// Maximum start-up torque, cNm (par. 63).
    pub startup_torque: i64,
    /// Maximum torque, cNm (par. 64).
    pub operating_torque: i64,
    /// Holding torque at end of run, cNm (par. 65).
    pub end_hold_torque: i64,
    /// Maximum holding torque, cNm (par. 66).
    pub hold_torque: i64,
    /// Time below the speed limit before the run aborts, ms (par. 70).
    pub block_time_ms: i64,
    /// Duration of the start-up torque, ms (par. 71).
    pub startup_time_ms: i64,
    /// Duration of the end-of-run holding torque, ms (par. 72).
    pub end_hold_time_ms: i64,
    /// Averaging time of the motor voltage, ms (par. 76).
    pub umot_filter_ms: i64,
    /// UMot limit, 0.1 V (par. 90).
    pub umot_limit: i64,
    /// Temperature limit, °C (par. 91).
    pub temp_limit: i64,
}

/// All settings of the core (PSD4xx 3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Settings {
    /// Position settings (par. 37–45).
    pub axis: AxisValues,
    /// The rest (par. 47–91).
    pub drive: DriveSettings,
}

impl Settings {
    /// The value of one setting; None for [`Setting::Actual`], which is not stored (3.3).
    pub fn get(&self, s: Setting) -> Option<i64> {
        let a = &self.axis;
        let d = &self.drive;
        Some(match s {
            Setting::Direction => a.direction,
            Setting::Numerator => a.numerator,
            Setting::Denominator => a.denominator,
            Setting::Reference => a.reference,
            Setting::MappingEnd => a.mapping_end,
            Setting::UpperLimit => a.upper_limit,
            Setting::LowerLimit => a.lower_limit,
            Setting::Window => a.window,
            Setting::LoopLength => a.loop_length,
            Setting::Actual => return None,
            Setting::Readjust => d.readjust,
            Setting::PositioningSpeed => d.positioning_speed,
            Setting::ManualSpeed => d.manual_speed,
            Setting::BlockSpeedPercent => d.block_speed_percent,
            Setting::Acceleration => d.acceleration,
            Setting::Deceleration => d.deceleration,
            Setting::StartupTorque => d.startup_torque,
            Setting::OperatingTorque => d.operating_torque,
            Setting::EndHoldTorque => d.end_hold_torque,
            Setting::HoldTorque => d.hold_torque,
            Setting::BlockTime => d.block_time_ms,
            Setting::StartupTime => d.startup_time_ms,
            Setting::EndHoldTime => d.end_hold_time_ms,
            Setting::UmotFilter => d.umot_filter_ms,
            Setting::UmotLimit => d.umot_limit,
            Setting::TempLimit => d.temp_limit,
        })
    }

    /// Sets one setting without checks or cascades (an image being assembled, 3.3); the
    /// actual value is ignored.
    pub fn put(&mut self, s: Setting, v: i64) {
        let a = &mut self.axis;
        let d = &mut self.drive;
        match s {
            Setting::Direction => a.direction = v,
            Setting::Numerator => a.numerator = v,
            Setting::Denominator => a.denominator = v,
            Setting::Reference => a.reference = v,
            Setting::MappingEnd => a.mapping_end = v,
            Setting::UpperLimit => a.upper_limit = v,
            Setting::LowerLimit => a.lower_limit = v,
            Setting::Window => a.window = v,
            Setting::LoopLength => a.loop_length = v,
            Setting::Actual => {}
            Setting::Readjust => d.readjust = v,
            Setting::PositioningSpeed => d.positioning_speed = v,
            Setting::ManualSpeed => d.manual_speed = v,
            Setting::BlockSpeedPercent => d.block_speed_percent = v,
            Setting::Acceleration => d.acceleration = v,
            Setting::Deceleration => d.deceleration = v,
            Setting::StartupTorque => d.startup_torque = v,
            Setting::OperatingTorque => d.operating_torque = v,
            Setting::EndHoldTorque => d.end_hold_torque = v,
            Setting::HoldTorque => d.hold_torque = v,
            Setting::BlockTime => d.block_time_ms = v,
            Setting::StartupTime => d.startup_time_ms = v,
            Setting::EndHoldTime => d.end_hold_time_ms = v,
            Setting::UmotFilter => d.umot_filter_ms = v,
            Setting::UmotLimit => d.umot_limit = v,
            Setting::TempLimit => d.temp_limit = v,
        }
    }
}

/// One setting of the core, named by role rather than by parameter number (PSD4xx 3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Setting {
    /// Direction of rotation (par. 37).
    Direction,
    /// Numerator (par. 38).
    Numerator,
    /// Denominator (par. 39).
    Denominator,
    /// Referencing value (par. 40).
    Reference,
    /// Upper mapping end (par. 41).
    MappingEnd,
    /// Upper limit (par. 42).
    UpperLimit,
    /// Lower limit (par. 43).
    LowerLimit,
    /// Positioning window (par. 44).
    Window,
    /// Length of loop (par. 45).
    LoopLength,
    /// Actual value (par. 3): writing references the position.
    Actual,
    /// Readjustment (par. 47).
    Readjust,
    /// Positioning speed (par. 53).
    PositioningSpeed,
    /// Manual speed (par. 56).
    ManualSpeed,
    /// Speed limit for aborting a run (par. 57).
    BlockSpeedPercent,
    /// Acceleration (par. 58).
    Acceleration,
    /// Deceleration (par. 59).
    Deceleration,
    /// Start-up torque (par. 63).
    StartupTorque,
    /// Operating torque (par. 64).
    OperatingTorque,
    /// End-of-run holding torque (par. 65).
    EndHoldTorque,
    /// Holding torque (par. 66).
    HoldTorque,
    /// Time below the speed limit (par. 70).
    BlockTime,
    /// Start-up torque time (par. 71).
    StartupTime,
    /// End-of-run holding time (par. 72).
    EndHoldTime,
    /// Motor voltage filter (par. 76).
    UmotFilter,
    /// UMot limit (par. 90).
    UmotLimit,
    /// Temperature limit (par. 91).
    TempLimit,
}

/// Why a setting is refused (PSD4xx 3.3; PKW error 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SetError {
    /// The position arithmetic refuses the value (chapter 4).
    #[error(transparent)]
    Axis(#[from] AxisError),
}

/// What kind of run moves the drive (PSD4xx 4.1, 4.2.3, 4.6, 3.3 par. 96).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RunKind {
    /// A positioning run to a transferred target (4.1).
    Positioning,
    /// A manual run (4.2.3).
    Manual,
    /// A readjustment after manual displacement (4.6).
    Readjust,
    /// The run to the middle of the measuring range after a delivery or user state (par. 96).
    Centre,
}

/// How a run ended (PSD4xx 3.6, chapter 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Outcome {
    /// The target was reached within the positioning window (3.6).
    Reached,
    /// Release withdrawn or an invalid control combination (3.6 bit 5).
    Aborted,
    /// A manual run was ended by its command.
    Stopped,
    /// Aborted because the drive stalled (3.6 bit 10).
    Obstructed,
    /// The second positioning also ended outside the window (3.6 bit 10).
    Missed,
    /// A manual run stopped at an end limit.
    LimitReached,
    /// The motor voltage left its range (3.6 bit 13).
    VoltageLost,
    /// An internal position error (3.6 bit 9).
    Fault,
    /// Replaced by another run (a manual run during a positioning run, 4.1).
    Superseded,
}

/// Why a run command did not start a run (PSD4xx 3.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Refusal {
    /// The target or its reference loop lies outside the limits (3.6 bit 12).
    BadTarget,
    /// The motor voltage is out of range (3.6 bit 13).
    NoMotorVoltage,
    /// The error bit is set (3.6 bit 9).
    Error,
    /// A manual run is active; positioning needs a standstill first (4.2.3 notice).
    ManualActive,
}

/// Something the core did, for traces (PSD4xx chapter 4).
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "core", rename_all = "kebab-case")]
pub enum CoreEvent {
    /// A run started (chapter 4).
    RunStarted {
        /// Kind of run.
        kind: RunKind,
        /// Target (positioning) or None (manual).
        target: Option<i64>,
        /// Positions the run passes through, the target last (reference loop).
        waypoints: Vec<i64>,
    },
    /// A run command was not executed (chapter 4).
    Refused {
        /// Why.
        reason: Refusal,
    },
    /// The automatic second positioning started (4.2.1).
    SecondAttempt {
        /// Position after the first attempt.
        actual: i64,
    },
    /// A run ended (chapter 4).
    RunEnded {
        /// Kind of run.
        kind: RunKind,
        /// How.
        outcome: Outcome,
        /// Position at the end.
        actual: i64,
    },
    /// The device was switched on or reset (chapter 4).
    PowerOn,
    /// The device was switched off (chapter 4).
    PowerOff,
}

#[derive(Debug, Clone, PartialEq)]
struct Plan {
    kind: RunKind,
    target: i64,
    waypoints: Vec<i64>,
    leg: usize,
    attempt: u32,
    no_loop: bool,
    /// Direction of the final approach: +1, −1 or 0.
    approach: i8,
}

#[derive(Debug, Clone, PartialEq)]
enum Motion {
    Idle,
    Positioning(Plan),
    Manual { dir: i8, at_limit: bool },
    Stopping { rate: f64, after_manual: bool },
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Hold {
    EndOfRun { until: Micros },
    Standing,
}

/// The motor voltage measurement averaged over par. 76 (PSD4xx 3.3 par. 76).
#[derive(Debug, Clone, PartialEq)]
struct Filter {
    samples: VecDeque<u16>,
    sum: u64,
    cap: usize,
    /// How many samples at the back equal the last one (at most all of them).
    run: usize,
}

impl Filter {
    fn new(cap: usize, value: u16) -> Filter {
        let mut f = Filter {
            samples: VecDeque::new(),
            sum: 0,
            cap: cap.max(1),
            run: 0,
        };
        f.push(value);
        f
    }

    fn push(&mut self, v: u16) {
        while self.samples.len() >= self.cap {
            if let Some(old) = self.samples.pop_front() {
                self.sum = self.sum.saturating_sub(u64::from(old));
            }
        }
        let same = self.samples.back() == Some(&v);
        self.samples.push_back(v);
        self.sum = self.sum.saturating_add(u64::from(v));
        self.run = if same {
            self.run.saturating_add(1).min(self.samples.len())
        } else {
            1
        };
    }

    fn resize(&mut self, cap: usize) {
        self.cap = cap.max(1);
        while self.samples.len() > self.cap {
            if let Some(old) = self.samples.pop_front() {
                self.sum = self.sum.saturating_sub(u64::from(old));
            }
        }
        self.run = self.run.min(self.samples.len());
    }

    fn value(&self) -> i64 {
        let n = self.samples.len().max(1) as u64;
        i64::try_from(self.sum / n).unwrap_or(0)
    }

    /// Whether every sample equals `v`, in constant time.
    fn settled(&self, v: u16) -> bool {
        self.samples.is_empty()
            || (self.samples.back() == Some(&v) && self.run >= self.samples.len())
    }
}

/// The positioning core of one drive (PSD4xx chapter 4; PSx3xx chapters 4–5).
#[derive(Debug, Clone)]
pub struct Positioner {
    cfg: Arc<CoreConfig>,
    axis: Axis,
    par: DriveSettings,
    env: Environment,
    clock: Micros,
    next_tick: Micros,
    powered: bool,
    kin: Kinematics,
    motion: Motion,
    flags: Flags,
    prev: Command,
    centre: Option<Command>,
    completed_ok: bool,
    was_inside: bool,
    hold_upper: bool,
    hold_lower: bool,
    in_encoder: bool,
    stall_us: u64,
    run_started: Micros,
    hold: Hold,
    filter: Filter,
    events: VecDeque<(Micros, CoreEvent)>,
    /// Idle period before the direction of rotation reverses, µs (PSx3xx ISDU 162); 0: none.
    reversal_pause_us: u64,
    /// Direction of the last movement: +1, −1, 0 before the first.
    last_dir: i8,
    /// When the shaft last came to a stop.
    stopped_at: Micros,
    /// The last step held the shaft for the idle period of a reversal.
    pausing: bool,
}

fn ms_to_ticks(ms: i64, tick_us: u64) -> usize {
    let us = u64::try_from(ms.max(1)).unwrap_or(1).saturating_mul(1000);
    usize::try_from(us / tick_us.max(1)).unwrap_or(1).max(1)
}

impl Positioner {
    /// A drive switched on at time 0 with the given settings, the shaft at the family's start
    /// position (PSD4xx 2.2, 3.6 bit 8).
    pub fn new(cfg: Arc<CoreConfig>, settings: Settings, env: Environment) -> Positioner {
        let mut axis = Axis::new(Arc::clone(&cfg.axis));
        axis.load(settings.axis);
        let start = {
            let base = cfg.axis.base_increments.max(1) as f64;
            cfg.start_position as f64 / base
        };
        let filter = Filter::new(
            ms_to_ticks(settings.drive.umot_filter_ms, cfg.tick_us),
            env.motor_dv,
        );
        let mut p = Positioner {
            axis,
            par: settings.drive,
            env,
            clock: 0,
            next_tick: 0,
            powered: false,
            kin: Kinematics {
                pos: start,
                vel: 0.0,
            },
            motion: Motion::Idle,
            flags: Flags::default(),
            prev: Command::default(),
            centre: None,
            completed_ok: false,
            was_inside: false,
            hold_upper: false,
            hold_lower: false,
            in_encoder: true,
            stall_us: 0,
            run_started: 0,
            hold: Hold::Standing,
            filter,
            events: VecDeque::new(),
            reversal_pause_us: 0,
            last_dir: 0,
            stopped_at: 0,
            pausing: false,
            cfg,
        };
        if p.env.control_dv > 0 {
            p.power_on(0);
        }
        p
    }

    // ------------------------------------------------------------------ views

    /// The family description (PSD4xx chapter 4).
    pub fn config(&self) -> &CoreConfig {
        &self.cfg
    }

    /// Current virtual time (µs) (chapter 4).
    pub fn now(&self) -> Micros {
        self.clock
    }

    /// Whether the device is switched on (control voltage present) (chapter 4).
    pub fn powered(&self) -> bool {
        self.powered
    }

    /// The status flags (PSD4xx 3.6).
    pub fn flags(&self) -> Flags {
        self.flags
    }

    /// The status word in the family's layout (PSD4xx 3.6, par. 1).
    pub fn status_word(&self) -> u64 {
        self.cfg.bits.word(self.flags)
    }

    /// Actual position in user increments (PSD par. 3).
    pub fn actual(&self) -> i64 {
        self.axis.actual(self.kin.pos)
    }

    /// Actual speed in rpm, positive toward larger values (PSD par. 2).
    pub fn speed_rpm(&self) -> i64 {
        let v = profile::rpm(self.kin.vel).round();
        if v.is_finite() {
            v as i64
        } else {
            0
        }
    }

    /// Shaft position and speed in rotations and rotations per second (chapter 4).
    pub fn kinematics(&self) -> Kinematics {
        self.kin
    }

    /// The position arithmetic and the valid target (PSD4xx 4.7).
    pub fn axis(&self) -> &Axis {
        &self.axis
    }

    /// The environment in force (chapter 4).
    pub fn environment(&self) -> &Environment {
        &self.env
    }

    /// The motor voltage as measured (averaged over par. 76), 0.1 V (PSD par. 7).
    pub fn motor_voltage(&self) -> i64 {
        self.filter.value()
    }

    /// The kind of the run in progress, None at standstill (PSD4xx chapter 4).
    pub fn run_kind(&self) -> Option<RunKind> {
        match &self.motion {
            Motion::Idle => None,
            Motion::Positioning(p) => Some(p.kind),
            Motion::Manual { .. } => Some(RunKind::Manual),
            Motion::Stopping { after_manual, .. } => Some(if *after_manual {
                RunKind::Manual
            } else {
                RunKind::Positioning
            }),
        }
    }

    /// The target the run in progress heads for, if it is a positioning run (chapter 4).
    pub fn run_target(&self) -> Option<i64> {
        match &self.motion {
            Motion::Positioning(p) => Some(p.target),
            _ => None,
        }
    }

    /// Whether the drive is at a standstill for writes that need one (PSD-PAR-3-003,
    /// PSD-PAR-37-003): no run in progress and the shaft not moved by the motor; a manual
    /// run held at an end limit counts as standstill.
    pub fn is_standstill(&self) -> bool {
        match self.motion {
            Motion::Idle => true,
            Motion::Manual { at_limit, .. } => at_limit && self.kin.vel == 0.0,
            _ => false,
        }
    }

    /// The holding torque applied now in cNm, None while a run drives the motor (PSD-OBST-003,
    /// PSD-PAR-65-001, PSD-PAR-66-001).
    pub fn holding_torque(&self) -> Option<i64> {
        if !self.is_standstill() {
            return None;
        }
        Some(match self.hold {
            Hold::EndOfRun { .. } => self.par.end_hold_torque,
            Hold::Standing => self.par.hold_torque,
        })
    }

    /// The torque limit of the motor now in cNm: start-up torque during par. 71 after a run
    /// begins, the operating torque after it (PSD-TRQ-001, PSD-TRQ-002, PSD-PAR-71-001).
    pub fn torque_limit(&self) -> i64 {
        let startup_us = u64::try_from(self.par.startup_time_ms.max(0))
            .unwrap_or(0)
            .saturating_mul(1000);
        if self.clock.saturating_sub(self.run_started) < startup_us {
            self.par.startup_torque
        } else {
            self.par.operating_torque
        }
    }

    /// All settings (PSD4xx 3.3).
    pub fn settings(&self) -> Settings {
        Settings {
            axis: self.axis.values(),
            drive: self.par,
        }
    }

    /// One setting's value; the actual value for [`Setting::Actual`] (PSD4xx 3.3).
    pub fn get(&self, s: Setting) -> i64 {
        self.settings().get(s).unwrap_or_else(|| self.actual())
    }

    /// The next virtual time at which something happens by itself, None when nothing will
    /// change until the next input (quinn-proto `poll_timeout`).
    pub fn poll_timeout(&self) -> Option<Micros> {
        if !self.powered {
            return None;
        }
        let busy = self.motion != Motion::Idle
            || self.kin.vel != 0.0
            || self.env.back_drive_rpm != 0
            || matches!(self.hold, Hold::EndOfRun { .. })
            || !self.filter.settled(self.env.motor_dv);
        busy.then_some(self.next_tick)
    }

    /// The next event, oldest first (chapter 4).
    pub fn poll_event(&mut self) -> Option<(Micros, CoreEvent)> {
        self.events.pop_front()
    }

    fn emit(&mut self, e: CoreEvent) {
        if self.events.len() >= MAX_EVENTS {
            self.events.pop_front();
        }
        self.events.push_back((self.clock, e));
    }

    // ------------------------------------------------------------------ power

    /// Switches the device on (or resets it) at `now` (PSD4xx 2.2; PSD-STS-8-SET-1,
    /// PSD-STS-8-SET-2, PSD-STS-9-RESET-1): runs end, the outputs count as 0 (3.9 power-on),
    /// no target is valid, lash is assumed present.
    pub fn power_on(&mut self, now: Micros) {
        self.clock = self.clock.max(now);
        self.powered = true;
        self.motion = Motion::Idle;
        self.kin.vel = 0.0;
        self.flags = Flags::default();
        // PSD-STS-8-SET-1, PSD-STS-8-SET-2: lash not yet eliminated after power-on or reset.
        self.flags.put(Flag::AgainstLoop, true);
        self.prev = Command::default();
        self.centre = None;
        self.completed_ok = false;
        self.was_inside = false;
        self.hold_upper = false;
        self.hold_lower = false;
        self.stall_us = 0;
        self.hold = Hold::Standing;
        // DECISION: no target is valid after power-on (3.7 bit 2 speaks of the last
        // transmitted target; none has been transmitted yet).
        self.axis.set_target(None);
        self.filter = Filter::new(
            ms_to_ticks(self.par.umot_filter_ms, self.cfg.tick_us),
            self.env.motor_dv,
        );
        self.in_encoder = self.inside_encoder();
        self.supply_flags();
        self.standstill_checks();
        self.emit(CoreEvent::PowerOn);
    }

    /// Switches the device off at `now`: the motor stops driving at once (chapter 4).
    pub fn power_off(&mut self, now: Micros) {
        self.advance(now);
        if !self.powered {
            return;
        }
        self.powered = false;
        self.motion = Motion::Idle;
        self.kin.vel = 0.0;
        self.emit(CoreEvent::PowerOff);
    }

    // ------------------------------------------------------------------ time

    /// Runs the physics up to `now` (PSD4xx chapter 4). Time never goes backwards: an earlier
    /// `now` does nothing.
    pub fn advance(&mut self, now: Micros) {
        while self.next_tick <= now {
            self.tick();
        }
        self.clock = self.clock.max(now);
    }

    fn dt(&self) -> f64 {
        self.cfg.tick_us as f64 / 1e6
    }

    /// Ramps of a run (PSD-VEL-001..PSD-VEL-004, PSD-VEL-008, PSD-VEL-009).
    fn ramps(&self, speed_rpm: i64) -> Ramps {
        Ramps {
            vmax: profile::rps(speed_rpm.max(0) as f64),
            accel: profile::rps(self.par.acceleration.max(1) as f64),
            decel: profile::rps(self.par.deceleration.max(1) as f64),
            blend: self.cfg.blend,
        }
    }

    fn ramp_rate(&self, ramp: Ramp) -> f64 {
        match ramp {
            Ramp::Parameter => profile::rps(self.par.deceleration.max(1) as f64),
            Ramp::Maximum => profile::rps(self.cfg.max_deceleration.max(1.0)),
        }
    }

    fn tick(&mut self) {
        let t = self.next_tick;
        let dt_us = self.cfg.tick_us.max(1);
        self.clock = self.clock.max(t);
        self.next_tick = t.saturating_add(dt_us);
        if !self.powered {
            return;
        }
        let dt = self.dt();
        self.filter.push(self.env.motor_dv);
        self.supply_flags();
        if let Hold::EndOfRun { until } = self.hold {
            if t >= until {
                self.hold = Hold::Standing;
            }
        }

        let before = self.kin;
        let mut arrived = false;
        let driving;
        let mut next = match &self.motion {
            Motion::Idle => {
                driving = false;
                let v = profile::rps(f64::from(self.env.back_drive_rpm));
                Kinematics {
                    pos: before.pos + v * dt,
                    vel: v,
                }
            }
            Motion::Positioning(plan) => {
                driving = true;
                let goal = plan
                    .waypoints
                    .get(plan.leg)
                    .map_or(before.pos, |w| self.axis.to_rot(*w));
                let s =
                    profile::approach(before, goal, &self.ramps(self.par.positioning_speed), dt);
                arrived = s.arrived;
                s.kin
            }
            Motion::Manual { dir, .. } => {
                driving = true;
                let (lo, hi) = self.limits();
                // A manual run ends at the limit in its direction (PSD-VEL-008: braking with
                // par. 59 at an end position); beyond it, it does not move further out.
                let goal = if *dir > 0 {
                    self.axis.to_rot(hi).max(before.pos)
                } else {
                    self.axis.to_rot(lo).min(before.pos)
                };
                let s = profile::approach(before, goal, &self.ramps(self.par.manual_speed), dt);
                arrived = s.arrived;
                s.kin
            }
            Motion::Stopping { rate, .. } => {
                driving = true;
                let s = profile::brake(before, *rate, dt);
                arrived = s.arrived;
                s.kin
            }
        };
        // PSX-ISDU-162-REVERSE: a driven run that would turn against the last movement first
        // stands for the idle period, counted from the stop.
        self.pausing = driving && self.reversing_too_soon(before, next, t);
        if self.pausing {
            next = before;
        }
        let commanded = next.vel;

        // Physical constraints: a jammed shaft, load above the torque limit, hard blocks.
        let mut stalled = false;
        let load_stall = driving && i64::from(self.env.load_cnm) > self.torque_limit();
        if self.env.jammed || load_stall {
            if next.pos != before.pos || next.vel != 0.0 {
                stalled = driving;
            }
            next = Kinematics {
                pos: before.pos,
                vel: 0.0,
            };
        }
        for w in &self.env.walls {
            if w.upper && next.pos > w.at {
                next.pos = w.at.max(before.pos.min(w.at));
                next.vel = next.vel.min(0.0);
                stalled = driving;
            } else if !w.upper && next.pos < w.at {
                next.pos = w.at.min(before.pos.max(w.at));
                next.vel = next.vel.max(0.0);
                stalled = driving;
            }
        }
        if stalled {
            arrived = false;
        }
        // The direction the motor last drove, and when the shaft came to rest.
        if driving && next.vel != 0.0 {
            self.last_dir = if next.vel > 0.0 { 1 } else { -1 };
        } else if next.vel == 0.0 && before.vel != 0.0 {
            self.stopped_at = t;
        }
        self.kin = next;
        // PSD-STS-6-SET-1, PSD-STS-6-RESET-1: running while the shaft rotates.
        self.flags.put(Flag::Running, self.kin.vel != 0.0);

        // PSD-STS-9-SET-1: the position leaves the range the absolute encoder covers.
        let inside = self.inside_encoder();
        if self.in_encoder && !inside {
            self.fault();
        }
        self.in_encoder = inside;

        let active_run = matches!(
            self.motion,
            Motion::Positioning(_)
                | Motion::Manual {
                    at_limit: false,
                    ..
                }
        );
        // PSD-OBST-007: speed below par. 57 % of the demanded speed for longer than par. 70.
        if active_run {
            let demanded = commanded.abs();
            let limit = demanded * self.par.block_speed_percent.max(0) as f64 / 100.0;
            if demanded > 0.0 && self.kin.vel.abs() < limit {
                self.stall_us = self.stall_us.saturating_add(dt_us);
            } else {
                self.stall_us = 0;
            }
            let block_us = u64::try_from(self.par.block_time_ms.max(0))
                .unwrap_or(0)
                .saturating_mul(1000);
            if self.stall_us > block_us {
                self.stall_us = 0;
                self.obstructed();
                self.finish_tick();
                return;
            }
            // PSD-STS-13-SET-2, PSD-PAR-90-003: the voltage leaves the run window.
            if !self.run_voltage_ok() {
                self.flags.put(Flag::VoltageMissing, true);
                self.end_run_emergency(Outcome::VoltageLost);
                self.finish_tick();
                return;
            }
        } else {
            self.stall_us = 0;
        }

        match &mut self.motion {
            Motion::Positioning(_) if arrived => self.arrival(),
            Motion::Manual { dir, at_limit } => {
                let dir = *dir;
                if arrived && !*at_limit {
                    *at_limit = true;
                    self.manual_at_limit(dir);
                } else if !arrived && *at_limit && self.kin.vel != 0.0 {
                    *at_limit = false;
                }
            }
            Motion::Stopping { .. } if arrived => {
                self.motion = Motion::Idle;
                self.hold = self.end_hold();
            }
            _ => {}
        }
        self.finish_tick();
    }

    /// Whether the step from `before` to `next` at `t` starts a movement against the last
    /// one before the idle period since the stop has passed (PSx3xx ISDU 162).
    fn reversing_too_soon(&self, before: Kinematics, next: Kinematics, t: Micros) -> bool {
        if self.reversal_pause_us == 0 || before.vel != 0.0 || self.last_dir == 0 {
            return false;
        }
        let against =
            (next.vel > 0.0 && self.last_dir < 0) || (next.vel < 0.0 && self.last_dir > 0);
        against && t < self.stopped_at.saturating_add(self.reversal_pause_us)
    }

    /// Sets the idle period before a reversal of the direction of rotation, ms; 0 reverses
    /// at once (PSx3xx 3.1 ISDU 162, PSX-ISDU-162-REVERSE).
    pub fn set_reversal_pause(&mut self, ms: i64) {
        self.reversal_pause_us = u64::try_from(ms).unwrap_or(0).saturating_mul(1000);
    }

    /// Whether the drive stands waiting for the idle period before a reversal (PSx3xx 3.1
    /// ISDU 162).
    pub fn reversal_pending(&self) -> bool {
        self.pausing && self.run_kind().is_some()
    }

    fn finish_tick(&mut self) {
        self.flags.put(Flag::Running, self.kin.vel != 0.0);
        self.standstill_checks();
        self.normalize();
    }

    fn end_hold(&self) -> Hold {
        let us = u64::try_from(self.par.end_hold_time_ms.max(0))
            .unwrap_or(0)
            .saturating_mul(1000);
        Hold::EndOfRun {
            until: self.clock.saturating_add(us),
        }
    }

    fn limits(&self) -> (i64, i64) {
        let v = self.axis.values();
        (v.lower_limit, v.upper_limit)
    }

    fn inside_encoder(&self) -> bool {
        let (lo, hi) = self.axis.position_range();
        let a = self.actual();
        a >= lo.saturating_sub(1) && a <= hi.saturating_add(1)
    }

    // ------------------------------------------------------------------ supply

    fn start_voltage_ok(&self) -> bool {
        // PSD-PAR-90-002, PSD-STS-13-SET-1 (erratum PSD-ERRATUM-006 "or"): above par. 90 and
        // below 30 V.
        let v = self.filter.value();
        v > self.par.umot_limit && v < self.cfg.voltage.upper
    }

    fn run_voltage_ok(&self) -> bool {
        let v = self.filter.value();
        let min = self.cfg.voltage.run_minimum.unwrap_or(self.par.umot_limit);
        v >= min && v <= self.cfg.voltage.upper
    }

    fn supply_flags(&mut self) {
        let v = self.filter.value();
        // PSD-STS-4-SET-1: above par. 90 and below 30 V; PSD-STS-4-RESET-1: below or above.
        // At exactly one of the limits the flag keeps its state (the manual uses strict words).
        if v > self.par.umot_limit && v < self.cfg.voltage.upper {
            self.flags.put(Flag::MotorOk, true);
        } else if v < self.par.umot_limit || v > self.cfg.voltage.upper {
            self.flags.put(Flag::MotorOk, false);
        }
        // PSD-STS-7-SET-1 / PSD-STS-7-RESET-1: above par. 91, below par. 91 − 5 °C.
        let c = i64::from(self.env.celsius);
        if c > self.par.temp_limit {
            self.flags.put(Flag::OverTemp, true);
        } else if c < self.par.temp_limit - self.cfg.temperature_hysteresis {
            self.flags.put(Flag::OverTemp, false);
        }
    }

    // ------------------------------------------------------------------ flag rules

    /// Bits with priority win (PSD-STS-0-PRIO, erratum PSD-ERRATUM-019).
    fn normalize(&mut self) {
        if !self.cfg.priority_exclusive {
            return;
        }
        for (winner, loser) in self.cfg.bits.priorities() {
            if self.flags.get(*winner) && self.flags.get(*loser) {
                self.flags.put(*loser, false);
            }
        }
    }

    fn set_reached(&mut self, also_obstruction: bool) {
        self.flags.put(Flag::Reached, true);
        if also_obstruction && !self.cfg.priority_exclusive {
            self.flags.put(Flag::Obstruction, true);
        }
    }

    /// Resets done by every new run command (PSD-STS-5-RESET-1, PSD-STS-10-RESET-1,
    /// PSD-STS-11-RESET-1, PSD-STS-12-RESET-1, PSD-STS-14-RESET-1 exception ends).
    fn run_command_resets(&mut self) {
        for f in [
            Flag::Aborted,
            Flag::Obstruction,
            Flag::ManualRotation,
            Flag::BadTarget,
        ] {
            self.flags.put(f, false);
        }
        self.hold_upper = false;
        self.hold_lower = false;
    }

    fn loop_dir(&self) -> i8 {
        let l = self.axis.values().loop_length;
        let up: i8 = if self.cfg.loop_rules.positive_approaches_up {
            1
        } else {
            -1
        };
        match l.signum() {
            1 => up,
            -1 => -up,
            _ => 0,
        }
    }

    /// Status bits that follow the position at standstill (PSD4xx 3.6 bits 0, 11, 14, 15; 4.6).
    fn standstill_checks(&mut self) {
        if !self.powered {
            return;
        }
        let actual = self.actual();
        let (lo, hi) = self.limits();
        let window = self.axis.values().window;
        let standing = matches!(self.motion, Motion::Idle);

        // PSD-STS-14-SET-3 / PSD-STS-15-SET-3: pushed beyond a limit at standstill.
        if standing && actual > hi {
            self.flags.put(Flag::UpperLimit, true);
        }
        if standing && actual < lo {
            self.flags.put(Flag::LowerLimit, true);
        }
        // PSD-STS-14-RESET-1 / PSD-STS-15-RESET-1, with the exception after a manual run that
        // stopped at the limit within the window.
        if self.hold_upper && actual.abs_diff(hi) > window.unsigned_abs() {
            self.hold_upper = false;
        }
        if self.hold_lower && actual.abs_diff(lo) > window.unsigned_abs() {
            self.hold_lower = false;
        }
        if (lo..=hi).contains(&actual) {
            if !self.hold_upper {
                self.flags.put(Flag::UpperLimit, false);
            }
            if !self.hold_lower {
                self.flags.put(Flag::LowerLimit, false);
            }
        }

        let Some(target) = self.axis.target() else {
            self.was_inside = false;
            return;
        };
        let inside = actual.abs_diff(target) <= window.unsigned_abs();
        // PSD-STS-0-RESET-4: rotated out of the window while not in operation. Bit 0 never
        // stands for a position outside the window.
        if !inside && standing {
            self.flags.put(Flag::Reached, false);
        }
        if !standing || !self.completed_ok {
            self.was_inside = inside;
            return;
        }
        if self.was_inside && !inside {
            self.window_left(actual, target);
        } else if !self.was_inside && inside {
            // PSD-STS-0-SET-3: back within the window after manual rotation.
            self.set_reached(false);
        }
        self.was_inside = inside;
    }

    /// The position has just left the window at standstill after a completed run (4.6).
    fn window_left(&mut self, actual: i64, target: i64) {
        let loop_dir = self.loop_dir();
        let away = (actual - target).signum() as i8;
        // PSD-ADJ-001, PSD-ADJ-004 (both directions without loop), PSD-ADJ-003 (not in the
        // loop direction), PSD-ADJ-010 (release and par. 47 needed).
        let against = if loop_dir == 0 {
            self.cfg.adjust_both_without_loop
        } else {
            away == -loop_dir
        };
        let will_adjust = against && self.prev.release && self.par.readjust == 1;
        // PSD-STS-11-SET-1 (erratum PSD-ERRATUM-022 "always"); PSD-ADJ-003 for the loop
        // direction.
        if self.cfg.manual_rotation_always || !will_adjust {
            self.flags.put(Flag::ManualRotation, true);
        }
        if !will_adjust {
            return;
        }
        // PSD-ADJ-005, PSD-ADJ-006: the adjustment starts when the window is left, with the
        // motor voltage in range; PSD-STS-10-SET-3, PSD-STS-13-SET-3 otherwise, and
        // PSD-ADJ-008: no later attempt when the voltage returns.
        if self.flags.get(Flag::MotorOk) && self.start_voltage_ok() {
            self.start_positioning(target, false, RunKind::Readjust);
        } else {
            self.flags.put(Flag::Obstruction, true);
            self.flags.put(Flag::VoltageMissing, true);
        }
    }

    // ------------------------------------------------------------------ runs

    /// The positions a run to `target` passes through from `from` (PSD4xx 4.2.1 cases 1–3,
    /// 4.2.2), and the direction of the final approach.
    fn plan(&self, from: i64, target: i64, no_loop: bool) -> (Vec<i64>, i8) {
        let dir = self.loop_dir();
        let direct = |from: i64| (vec![target], (target - from).signum() as i8);
        // PSD-POS-017: control bit 6 approaches directly; PSD-PAR-45-001: loop 0 = no loop.
        if no_loop || dir == 0 {
            return direct(from);
        }
        let rules = self.cfg.loop_rules;
        let fixed = {
            let [n, d] = rules.fixed_rotations;
            let ipr = self.axis.increments_per_rotation();
            let len = if d == 0 {
                0.0
            } else {
                ipr * n as f64 / d as f64
            };
            len.round() as i64
        };
        let len = if rules.overshoot_is_loop_length {
            self.axis.values().loop_length.abs()
        } else {
            fixed
        };
        let d = (target - from) * i64::from(dir);
        let back = |p: i64, by: i64| p - i64::from(dir) * by;
        if d < 0 {
            // PSD-POS-011 (case 2): past the target by the loop, then in the loop direction.
            return (vec![back(target, len), target], dir);
        }
        let lash = self.flags.get(Flag::AgainstLoop);
        if lash && d <= len {
            // PSD-POS-012 (case 3): back off so that the final approach covers the loop
            // (erratum PSD-ERRATUM-055).
            let first = match rules.backoff {
                Backoff::LoopLength => back(target, len),
                Backoff::FixedFromCurrent => back(from, fixed),
            };
            return (vec![first, target], dir);
        }
        // PSD-POS-010 (case 1): a target ahead in the loop direction is approached directly.
        (vec![target], if d == 0 { 0 } else { dir })
    }

    /// Checks a target and its loop against the limits (PSD-STS-12-SET-1, PSD-STS-12-SET-2,
    /// PSD-POS-016).
    fn target_ok(&self, target: i64, no_loop: bool) -> bool {
        let (lo, hi) = self.limits();
        if !(lo..=hi).contains(&target) {
            return false;
        }
        let (waypoints, _) = self.plan(self.actual(), target, no_loop);
        waypoints.iter().all(|w| (lo..=hi).contains(w))
    }

    /// Accepts a transferred target (PSD-CTL-2-001); false when it is invalid.
    fn transfer(&mut self, target: i64, no_loop: bool) -> bool {
        if !self.target_ok(target, no_loop) {
            // PSD-STS-12-SET-1, PSD-STS-12-SET-2, PSD-STS-0-RESET-3.
            self.flags.put(Flag::BadTarget, true);
            self.flags.put(Flag::Reached, false);
            return false;
        }
        self.axis.set_target(Some(target));
        // PSD-STS-0-RESET-1: a target outside the window of the actual position.
        let window = self.axis.values().window;
        if self.actual().abs_diff(target) > window.unsigned_abs() {
            self.flags.put(Flag::Reached, false);
        }
        true
    }

    fn refuse(&mut self, reason: Refusal) {
        self.emit(CoreEvent::Refused { reason });
    }

    /// Ends a positioning run that a refused run command replaces (DECISION: a target that was
    /// accepted but cannot be run to stops the old run with par. 59).
    fn stop_superseded(&mut self) {
        if let Motion::Positioning(p) = &self.motion {
            let kind = p.kind;
            self.motion = Motion::Stopping {
                rate: self.ramp_rate(Ramp::Parameter),
                after_manual: false,
            };
            self.completed_ok = false;
            let actual = self.actual();
            self.emit(CoreEvent::RunEnded {
                kind,
                outcome: Outcome::Superseded,
                actual,
            });
        }
    }

    fn start_positioning(&mut self, target: i64, no_loop: bool, kind: RunKind) -> bool {
        // PSD-STS-9-NORUN: no runs while the error bit is set.
        if self.flags.get(Flag::Error) {
            self.refuse(Refusal::Error);
            return false;
        }
        if kind != RunKind::Readjust {
            // PSD-PAR-90-002, PSD-STS-13-SET-1 / PSD-STS-13-RESET-1, PSD-RUN-012.
            if !self.start_voltage_ok() {
                self.flags.put(Flag::VoltageMissing, true);
                self.refuse(Refusal::NoMotorVoltage);
                self.stop_superseded();
                return false;
            }
            self.flags.put(Flag::VoltageMissing, false);
        }
        let x = self.actual();
        if !self.target_ok(target, no_loop) {
            self.flags.put(Flag::BadTarget, true);
            self.flags.put(Flag::Reached, false);
            self.refuse(Refusal::BadTarget);
            return false;
        }
        let window = self.axis.values().window.unsigned_abs();
        let lash = self.flags.get(Flag::AgainstLoop) && !no_loop && self.loop_dir() != 0;
        if self.motion == Motion::Idle && !lash && x.abs_diff(target) <= window {
            // DECISION: a target already within the window at standstill is reached without
            // moving (PSD-STS-0-SET-1).
            self.set_reached(false);
            self.completed_ok = true;
            self.was_inside = true;
            self.emit(CoreEvent::RunEnded {
                kind,
                outcome: Outcome::Reached,
                actual: x,
            });
            return true;
        }
        let (waypoints, approach) = self.plan(x, target, no_loop);
        // PSD-STS-8-RESET-1 / PSD-STS-8-SET-3.
        let dir = self.loop_dir();
        if self.axis.values().loop_length == 0 {
            self.flags.put(Flag::AgainstLoop, false);
        } else if (target - x).signum() as i8 == -dir {
            self.flags.put(Flag::AgainstLoop, true);
        }
        if x.abs_diff(target) > window {
            self.flags.put(Flag::Reached, false);
        }
        self.completed_ok = false;
        if self.kin.vel == 0.0 {
            self.run_started = self.clock;
        }
        self.stall_us = 0;
        self.emit(CoreEvent::RunStarted {
            kind,
            target: Some(target),
            waypoints: waypoints.clone(),
        });
        self.motion = Motion::Positioning(Plan {
            kind,
            target,
            waypoints,
            leg: 0,
            attempt: 1,
            no_loop,
            approach,
        });
        true
    }

    fn start_manual(&mut self, dir: i8) {
        if self.flags.get(Flag::Error) {
            self.refuse(Refusal::Error);
            return;
        }
        self.run_command_resets();
        if !self.start_voltage_ok() {
            self.flags.put(Flag::VoltageMissing, true);
            self.refuse(Refusal::NoMotorVoltage);
            self.stop_superseded();
            return;
        }
        self.flags.put(Flag::VoltageMissing, false);
        // PSD-STS-0-RESET-2: a manual run resets bit 0.
        self.flags.put(Flag::Reached, false);
        // PSD-STS-8-RESET-1 / PSD-STS-8-SET-4.
        let loop_dir = self.loop_dir();
        if loop_dir == 0 {
            self.flags.put(Flag::AgainstLoop, false);
        } else if dir == -loop_dir {
            self.flags.put(Flag::AgainstLoop, true);
        }
        self.completed_ok = false;
        self.centre = None;
        if let Motion::Positioning(p) = &self.motion {
            // PSD-RUN-002, PSD-RUN-003: the positioning run ends, the manual run continues
            // from its speed (no bit 5: the release was not withdrawn).
            let kind = p.kind;
            let actual = self.actual();
            self.emit(CoreEvent::RunEnded {
                kind,
                outcome: Outcome::Superseded,
                actual,
            });
        }
        if self.kin.vel == 0.0 {
            self.run_started = self.clock;
        }
        self.stall_us = 0;
        self.motion = Motion::Manual {
            dir,
            at_limit: false,
        };
        self.emit(CoreEvent::RunStarted {
            kind: RunKind::Manual,
            target: None,
            waypoints: Vec::new(),
        });
    }

    fn manual_at_limit(&mut self, dir: i8) {
        // PSD-STS-14-SET-1 / PSD-STS-15-SET-1: a manual run reaches a limit; the bit stays
        // until the next run command while within the window (PSD-STS-14-RESET-1).
        let (lo, hi) = self.limits();
        let limit = if dir > 0 { hi } else { lo };
        if dir > 0 {
            self.flags.put(Flag::UpperLimit, true);
            self.hold_upper = true;
        } else {
            self.flags.put(Flag::LowerLimit, true);
            self.hold_lower = true;
        }
        // PSD-STS-0-SET-2: bit 0 only when the limit reached is the target.
        if self.axis.target() == Some(limit) {
            self.set_reached(false);
        }
        let actual = self.actual();
        self.emit(CoreEvent::RunEnded {
            kind: RunKind::Manual,
            outcome: Outcome::LimitReached,
            actual,
        });
    }

    /// A positioning run reached its current waypoint (PSD4xx 4.2.1).
    fn arrival(&mut self) {
        let Motion::Positioning(plan) = &mut self.motion else {
            return;
        };
        if plan.leg + 1 < plan.waypoints.len() {
            plan.leg += 1;
            return;
        }
        let plan = plan.clone();
        // Lost steps armed by the environment land the shaft short of the target.
        if !self.env.missed.is_empty() {
            let by = self.env.missed.remove(0);
            let dir = if plan.approach == 0 {
                1
            } else {
                i64::from(plan.approach)
            };
            self.kin.pos -= self.axis.length_to_rot(by.saturating_mul(dir));
        }
        let actual = self.actual();
        let window = self.axis.values().window.unsigned_abs();
        // PSD-POS-013: the position is compared with the absolute encoder.
        if actual.abs_diff(plan.target) <= window {
            self.finish_reached(&plan, false);
            return;
        }
        if plan.attempt < self.cfg.loop_rules.attempts {
            // PSD-POS-014: a second positioning starts automatically.
            let (waypoints, approach) = self.plan(actual, plan.target, plan.no_loop);
            self.emit(CoreEvent::SecondAttempt { actual });
            self.motion = Motion::Positioning(Plan {
                waypoints,
                approach,
                leg: 0,
                attempt: plan.attempt + 1,
                ..plan
            });
            return;
        }
        // PSD-STS-10-SET-2: outside the window again after the second positioning.
        self.flags.put(Flag::Obstruction, true);
        self.motion = Motion::Idle;
        self.completed_ok = false;
        self.hold = self.end_hold();
        self.emit(CoreEvent::RunEnded {
            kind: plan.kind,
            outcome: Outcome::Missed,
            actual,
        });
    }

    fn finish_reached(&mut self, plan: &Plan, obstruction: bool) {
        // PSD-STS-0-SET-1 (PSD-STS-0-SET-4 for a readjustment).
        self.set_reached(obstruction);
        // PSD-STS-8-RESET-2: reached in the loop direction.
        let loop_dir = self.loop_dir();
        if loop_dir != 0 && plan.approach == loop_dir {
            self.flags.put(Flag::AgainstLoop, false);
        }
        self.completed_ok = true;
        self.was_inside = true;
        self.motion = Motion::Idle;
        self.kin.vel = 0.0;
        self.hold = self.end_hold();
        if plan.kind == RunKind::Centre {
            self.centre = None;
        }
        let actual = self.actual();
        self.emit(CoreEvent::RunEnded {
            kind: plan.kind,
            outcome: Outcome::Reached,
            actual,
        });
    }

    /// The run stalled for longer than par. 70 (PSD-OBST-001, PSD-STS-10-SET-1).
    fn obstructed(&mut self) {
        let actual = self.actual();
        let kind = self.run_kind().unwrap_or(RunKind::Positioning);
        if let Motion::Positioning(plan) = &self.motion {
            let plan = plan.clone();
            // PSD-OBST-009, PSD-STS-0-PRIO: an obstruction inside the window is not
            // recognised; bit 0 wins over bit 10.
            if actual.abs_diff(plan.target) <= self.axis.values().window.unsigned_abs() {
                self.finish_reached(&plan, true);
                return;
            }
        }
        self.flags.put(Flag::Obstruction, true);
        self.motion = Motion::Idle;
        self.kin.vel = 0.0;
        self.completed_ok = false;
        self.centre = None;
        // PSD-OBST-003: holding torque par. 66 after an obstruction.
        self.hold = Hold::Standing;
        self.emit(CoreEvent::RunEnded {
            kind,
            outcome: Outcome::Obstructed,
            actual,
        });
    }

    fn end_run_emergency(&mut self, outcome: Outcome) {
        let Some(kind) = self.run_kind() else { return };
        self.motion = Motion::Stopping {
            rate: self.ramp_rate(self.cfg.emergency_ramp),
            after_manual: kind == RunKind::Manual,
        };
        self.completed_ok = false;
        self.centre = None;
        let actual = self.actual();
        self.emit(CoreEvent::RunEnded {
            kind,
            outcome,
            actual,
        });
    }

    fn fault(&mut self) {
        // PSD-STS-9-SET-1.
        self.flags.put(Flag::Error, true);
        if matches!(self.motion, Motion::Positioning(_) | Motion::Manual { .. }) {
            self.end_run_emergency(Outcome::Fault);
        }
    }

    /// Release withdrawn (PSD-RUN-001, PSD-CTL-4-003, PSD-STS-5-SET-1, PSD-RUN-007).
    fn withdraw(&mut self) {
        match &self.motion {
            Motion::Positioning(p) => {
                let kind = p.kind;
                self.flags.put(Flag::Aborted, true);
                self.motion = Motion::Stopping {
                    rate: self.ramp_rate(self.cfg.stop_ramp),
                    after_manual: false,
                };
                self.completed_ok = false;
                self.centre = None;
                let actual = self.actual();
                self.emit(CoreEvent::RunEnded {
                    kind,
                    outcome: Outcome::Aborted,
                    actual,
                });
            }
            Motion::Manual { .. } => {
                // Erratum PSD-ERRATUM-018: bit 5 only for positioning runs unless chosen.
                if self.cfg.aborted_on_manual_stop {
                    self.flags.put(Flag::Aborted, true);
                }
                self.stop_manual();
            }
            _ => {}
        }
    }

    /// Manual bits cleared (PSD-RUN-006): brake with par. 59, no bit 5.
    fn stop_manual(&mut self) {
        if let Motion::Manual { at_limit, .. } = self.motion {
            self.motion = if at_limit && self.kin.vel == 0.0 {
                Motion::Idle
            } else {
                Motion::Stopping {
                    rate: self.ramp_rate(self.cfg.stop_ramp),
                    after_manual: true,
                }
            };
            if !at_limit {
                let actual = self.actual();
                self.emit(CoreEvent::RunEnded {
                    kind: RunKind::Manual,
                    outcome: Outcome::Stopped,
                    actual,
                });
            }
        }
    }

    /// Stops any run with the stop ramp without setting the aborted flag (erratum
    /// PSD-ERRATUM-063 reading "internal-resume").
    pub fn halt(&mut self, now: Micros) {
        self.advance(now);
        if let Some(kind) = self.run_kind() {
            if !matches!(self.motion, Motion::Stopping { .. }) {
                self.motion = Motion::Stopping {
                    rate: self.ramp_rate(self.cfg.stop_ramp),
                    after_manual: kind == RunKind::Manual,
                };
                self.completed_ok = false;
                self.centre = None;
                let actual = self.actual();
                self.emit(CoreEvent::RunEnded {
                    kind,
                    outcome: Outcome::Aborted,
                    actual,
                });
            }
        }
    }

    /// Starts the positioning run to the middle of the measuring range that follows a delivery
    /// or user state (PSD-PAR-96-002, PSD-PAR-96-003). While it runs, commands equal to the one
    /// in force are ignored and a changed one aborts it (PSD-PAR-96-010, PSD-PAR-96-011).
    /// DECISION: the middle of the range the mapping end gives, kept within the limits, run
    /// without loop; it becomes the valid target.
    pub fn start_centre_run(&mut self, now: Micros) -> bool {
        self.advance(now);
        if !self.powered {
            return false;
        }
        let (lo, hi) = self.axis.position_range();
        let mid = i64::try_from((i128::from(lo) + i128::from(hi)) / 2).unwrap_or(0);
        let (llo, lhi) = self.limits();
        let target = if llo <= lhi { mid.clamp(llo, lhi) } else { mid };
        self.run_command_resets();
        self.axis.set_target(Some(target));
        let started = self.start_positioning(target, true, RunKind::Centre);
        if started && matches!(self.motion, Motion::Positioning(_)) {
            self.centre = Some(self.prev);
        }
        self.normalize();
        started
    }

    // ------------------------------------------------------------------ commands

    /// A control command received at `now` (PSD4xx 3.7, 4.1, 4.2.3, 4.5).
    ///
    /// Runs start on edges, not on repetitions of the same cyclic data: a release 0→1 edge
    /// (PSD-POS-005), or a transfer (bit 2 set and its edge or a changed target) of a target
    /// other than the valid one (PSD-POS-001, PSD-POS-002, PSD-OBST-004); the same target
    /// after an obstruction needs the release edge (PSD-OBST-005).
    pub fn command(&mut self, now: Micros, cmd: Command) {
        self.advance(now);
        if !self.powered {
            return;
        }
        // PSD-STS-2-SET-1, PSD-STS-2-RESET-1, PSD-CTL-13-001: the toggle bit is echoed.
        self.flags.put(Flag::Toggle, cmd.toggle);
        let mut prev = self.prev;
        if let Some(word) = self.centre {
            // PSD-PAR-96-010: the command in force is ignored during the centre run.
            if word.same_word(&cmd) {
                self.prev = cmd;
                return;
            }
            // PSD-PAR-96-011: a changed control word aborts it (with bit 5 when the change
            // withdraws the release, PSD-STS-5-SET-1).
            self.centre = None;
            if !cmd.release {
                self.withdraw();
            }
            if let Motion::Positioning(p) = &self.motion {
                if p.kind == RunKind::Centre {
                    self.motion = Motion::Stopping {
                        rate: self.ramp_rate(self.cfg.stop_ramp),
                        after_manual: false,
                    };
                    let actual = self.actual();
                    self.emit(CoreEvent::RunEnded {
                        kind: RunKind::Centre,
                        outcome: Outcome::Aborted,
                        actual,
                    });
                }
            }
            prev = word;
        }
        // PSD-CTL-3-001, PSD-CTL-5-001, PSD-CTL-7-001, PSD-CTL-14-001, PSD-CTL-ZERO-001,
        // PSD-RUN-011: reserved bits or both manual bits are an invalid combination.
        let invalid =
            cmd.reserved || (cmd.manual_up && cmd.manual_down && self.cfg.both_manual_invalid);
        if invalid {
            match &self.motion {
                Motion::Positioning(p) => {
                    // PSD-STS-5-SET-2: a positioning run aborted by an invalid combination.
                    let kind = p.kind;
                    self.flags.put(Flag::Aborted, true);
                    self.motion = Motion::Stopping {
                        rate: self.ramp_rate(self.cfg.emergency_ramp),
                        after_manual: false,
                    };
                    self.completed_ok = false;
                    let actual = self.actual();
                    self.emit(CoreEvent::RunEnded {
                        kind,
                        outcome: Outcome::Aborted,
                        actual,
                    });
                }
                Motion::Manual { .. } => self.stop_manual(),
                _ => {}
            }
            // DECISION: an invalid word is not accepted; the next valid word is compared with
            // "nothing released".
            self.prev = Command {
                target: cmd.target,
                toggle: cmd.toggle,
                ..Command::default()
            };
            self.normalize();
            return;
        }
        let release_edge = cmd.release && !prev.release;
        if !cmd.release {
            // PSD-RUN-012: runs are executed only while the release is set.
            self.withdraw();
        }
        let transfer =
            cmd.transfer && (!prev.transfer || cmd.target != prev.target || release_edge);
        let dir = cmd.manual_dir();
        if cmd.release && dir != 0 {
            if transfer {
                // DECISION: bit 2 with a manual bit accepts the target, no positioning starts.
                self.transfer(cmd.target, cmd.no_loop);
            }
            // PSD-RUN-004, PSD-RUN-005: a manual run starts on the edge of its bit or of the
            // release; a held word does not restart one that ended (obstruction, error).
            let same = matches!(self.motion, Motion::Manual { dir: d, .. } if d == dir);
            if !same && (release_edge || prev.manual_dir() != dir) {
                self.start_manual(dir);
            }
            self.prev = cmd;
            self.normalize();
            return;
        }
        let manual_busy = matches!(
            self.motion,
            Motion::Manual { .. }
                | Motion::Stopping {
                    after_manual: true,
                    ..
                }
        );
        if cmd.release && matches!(self.motion, Motion::Manual { .. }) {
            // PSD-RUN-006: 0x10 stops a manual run.
            self.stop_manual();
        }
        let old_valid = self.axis.target();
        let run = cmd.release
            && ((release_edge && (transfer || old_valid.is_some()))
                || (transfer && Some(cmd.target) != old_valid));
        if run && manual_busy {
            // PSD-RUN-008 / PSD-RUN-009: positioning needs a standstill after a manual run.
            if transfer {
                self.transfer(cmd.target, cmd.no_loop);
            }
            self.refuse(Refusal::ManualActive);
            self.prev = cmd;
            self.normalize();
            return;
        }
        if run {
            if self.flags.get(Flag::Error) {
                self.refuse(Refusal::Error);
            } else {
                self.run_command_resets();
                let ok = if transfer {
                    self.transfer(cmd.target, cmd.no_loop)
                } else {
                    true
                };
                match (ok, self.axis.target()) {
                    (true, Some(t)) => {
                        // PSD-CTL-2-002, PSD-CTL-2-003, PSD-POS-001, PSD-POS-005.
                        self.start_positioning(t, cmd.no_loop, RunKind::Positioning);
                    }
                    _ => self.refuse(Refusal::BadTarget),
                }
            }
        } else if transfer {
            // PSD-POS-004: transfer without release, no run.
            self.transfer(cmd.target, cmd.no_loop);
        }
        self.prev = cmd;
        self.standstill_checks();
        self.normalize();
    }

    // ------------------------------------------------------------------ environment

    /// An environment change at `now` (PSD4xx 3.3 par. 6–8, 3.6, 4.5, 4.6, 4.10).
    pub fn env(&mut self, now: Micros, change: EnvChange) {
        self.advance(now);
        match change {
            EnvChange::MotorVoltage { dv } => self.env.motor_dv = dv,
            EnvChange::ControlVoltage { dv } => {
                self.env.control_dv = dv;
                // DECISION: the manual gives no minimum control voltage; 0 is off.
                if dv == 0 {
                    self.power_off(now);
                } else if !self.powered {
                    self.power_on(now);
                }
            }
            EnvChange::Temperature { celsius } => {
                self.env.celsius = celsius;
                if self.powered {
                    self.supply_flags();
                }
            }
            EnvChange::LoadTorque { cnm } => self.env.load_cnm = cnm,
            EnvChange::Jam { on } => self.env.jammed = on,
            EnvChange::Block { at } => {
                if self.env.walls.len() < MAX_ENV_ENTRIES {
                    let rot = self.axis.to_rot(at);
                    self.env.walls.push(Wall {
                        at: rot,
                        upper: rot >= self.kin.pos,
                    });
                }
            }
            EnvChange::ClearBlocks => self.env.walls.clear(),
            EnvChange::Displace { by } => {
                // PSD-MAP-023-like: the measuring system follows every rotation of the shaft.
                self.kin.pos += self.axis.length_to_rot(by);
                let inside = self.inside_encoder();
                if self.powered && self.in_encoder && !inside {
                    self.fault();
                }
                self.in_encoder = inside;
            }
            EnvChange::BackDrive { rpm } => self.env.back_drive_rpm = rpm,
            EnvChange::MissSteps { by } => {
                if self.env.missed.len() < MAX_ENV_ENTRIES {
                    self.env.missed.push(by);
                }
            }
            EnvChange::PositionFault => {
                if self.powered {
                    self.fault();
                }
            }
        }
        if self.powered {
            self.standstill_checks();
            self.normalize();
        }
    }

    // ------------------------------------------------------------------ settings

    /// Writes one setting at `now` (PSD4xx 3.3, 4.7 cascades). Static ranges (table 3.3/3.4)
    /// and the standstill condition are the family's to check; the core refuses what the
    /// position arithmetic does not permit (PSD-MAP-007, PSD-MAP-028, PSD-PAR-44-003,
    /// PSD-PAR-45-003).
    pub fn set(&mut self, now: Micros, s: Setting, value: i64) -> Result<(), SetError> {
        self.advance(now);
        let a = self.axis.values();
        match s {
            // PSD-MAP-012.
            Setting::Direction => {
                self.kin.pos = self.axis.set_direction(value, self.kin.pos)?;
                self.in_encoder = self.inside_encoder();
            }
            // PSD-MAP-014.
            Setting::Numerator => self.axis.set_scaling(value, a.denominator)?,
            Setting::Denominator => self.axis.set_scaling(a.numerator, value)?,
            // PSD-MAP-015, PSD-MAP-020.
            Setting::Reference => self.axis.set_reference(value),
            // PSD-MAP-007, PSD-MAP-013.
            Setting::MappingEnd => {
                let actual = self.actual();
                self.axis.set_mapping_end(value, actual)?;
                self.in_encoder = self.inside_encoder();
            }
            Setting::UpperLimit => self.axis.set_upper_limit(value)?,
            Setting::LowerLimit => self.axis.set_lower_limit(value)?,
            Setting::Window => self.axis.set_window(value)?,
            Setting::LoopLength => self.axis.set_loop_length(value)?,
            // PSD-MAP-021, PSD-MAP-022.
            Setting::Actual => self.axis.set_actual(value, self.kin.pos),
            Setting::Readjust => self.par.readjust = value,
            Setting::PositioningSpeed => self.par.positioning_speed = value,
            Setting::ManualSpeed => self.par.manual_speed = value,
            Setting::BlockSpeedPercent => self.par.block_speed_percent = value,
            Setting::Acceleration => self.par.acceleration = value,
            Setting::Deceleration => self.par.deceleration = value,
            Setting::StartupTorque => self.par.startup_torque = value,
            Setting::OperatingTorque => self.par.operating_torque = value,
            Setting::EndHoldTorque => self.par.end_hold_torque = value,
            Setting::HoldTorque => self.par.hold_torque = value,
            Setting::BlockTime => self.par.block_time_ms = value,
            Setting::StartupTime => self.par.startup_time_ms = value,
            Setting::EndHoldTime => self.par.end_hold_time_ms = value,
            Setting::UmotFilter => {
                self.par.umot_filter_ms = value;
                self.filter.resize(ms_to_ticks(value, self.cfg.tick_us));
            }
            Setting::UmotLimit => self.par.umot_limit = value,
            Setting::TempLimit => self.par.temp_limit = value,
        }
        self.after_change();
        Ok(())
    }

    /// Loads all settings at once without cascades (PSD par. 96 delivery or user state).
    pub fn load(&mut self, now: Micros, s: &Settings) {
        self.advance(now);
        self.axis.load(s.axis);
        self.par = s.drive;
        self.filter
            .resize(ms_to_ticks(self.par.umot_filter_ms, self.cfg.tick_us));
        self.in_encoder = self.inside_encoder();
        self.after_change();
    }

    fn after_change(&mut self) {
        if !self.powered {
            return;
        }
        let actual = self.actual();
        let (lo, hi) = self.limits();
        // PSD-STS-14-SET-2 / PSD-STS-15-SET-2: a limit moved past the position.
        if actual > hi {
            self.flags.put(Flag::UpperLimit, true);
        }
        if actual < lo {
            self.flags.put(Flag::LowerLimit, true);
        }
        self.supply_flags();
        self.standstill_checks();
        self.normalize();
    }
}

#[cfg(test)]
mod tests {
    use super::Filter;
    use proptest::prelude::*;

    proptest! {
        /// The constant-time `settled` agrees with comparing every sample (par. 76 filter).
        #[test]
        fn filter_settled_matches_every_sample(
            cap in 1usize..12,
            ops in proptest::collection::vec((0u16..3, 0usize..14, any::<bool>()), 0..80),
        ) {
            let mut f = Filter::new(cap, 1);
            for (v, new_cap, resize) in ops {
                if resize {
                    f.resize(new_cap);
                } else {
                    f.push(v);
                }
                for probe in 0..3 {
                    prop_assert_eq!(f.settled(probe), f.samples.iter().all(|s| *s == probe));
                }
            }
        }
    }
}
