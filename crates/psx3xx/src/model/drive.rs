//! The PSx3xx reference drive: process images, ISDU server, IO-Link communication, jog keys,
//! environment and power on top of the positioning core (manual chapters 3–5).

use super::config::{BrakeKind, DriveConfig};
use super::error::ModelError;
use super::family::PsxFamily;
use super::io::{Event, IsduAnswer, JogKeys, LedLight, Leds, LinkEvent, RunState};
use crate::guard::Guards;
use crate::{ImageError, Input, Output, Rules};
use drivespec_positioner::machine::Command;
use drivespec_positioner::profile::Kinematics;
use drivespec_positioner::{ByteOrder, EnvChange, Flag, Flags, Micros, Positioner, RunKind};
use drivespec_spec::{FamilyId, Spec};
use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;

/// Most undrained outputs kept per queue; older ones are dropped (bounded memory).
pub const MAX_QUEUED: usize = 4096;

/// Identification values of one device (manual 3.1 ISDU 22, 23, 77, 78, 80).
#[derive(Debug, Clone)]
pub(super) struct Identity {
    pub production_date: i64,
    pub serial_number: i64,
    pub software: i64,
    pub hardware: String,
    pub firmware: String,
}

/// A valid time stamp waiting for the inactive marker (manual 3.3.1, 4.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct PendingStamp {
    pub code: u8,
    pub received: Micros,
    pub delay_us: u32,
}

/// A run started by the family through a core hook, or by the time-out (manual 5.9, 5.10).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum FamilyRun {
    None,
    /// A jog step (5.10).
    Step(i8),
    /// A continuous jog (5.10).
    Continuous(i8),
    /// The initial reference loop, then the centre run if asked (3.5 bit 7, ISDU 193).
    ReferenceLoop {
        then_centre: bool,
    },
    /// The run to the safe position (5.9 case 3).
    Safe(i64),
}

/// The jog state machine (manual 5.10).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum JogMode {
    /// No jog input held since the last release.
    Idle,
    /// A single step runs; the input was pressed at `since`.
    Step { dir: i8, since: Micros },
    /// The step is done and the input still held since `since`.
    Held { dir: i8, since: Micros },
    /// A continuous jog runs.
    Continuous { dir: i8 },
    /// Both inputs were pressed: nothing runs until both are released.
    Blocked,
}

/// What waits for the brake to open (manual 5.12, 5.13).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Deferred {
    /// The bus command in force.
    Command,
    /// A jog step.
    Step(i8),
}

/// The computed set position of a positioning run for the drag error (manual 5.8).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Ideal {
    pub kin: Kinematics,
    pub waypoints: Vec<f64>,
    pub leg: usize,
    pub top_checked: bool,
}

/// Stored values the drive reads on every step, kept apart from the map of working values
/// and refreshed whenever those change (manual 3.1 ISDU 118, 142–145, 162).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(super) struct Hot {
    pub timeout: i64,
    pub speed_positioning: i64,
    pub speed_manual: i64,
    pub speed_ccw: i64,
    pub speed_cw: i64,
    pub reversal_pause: i64,
}

/// A reference PSx3xx drive on virtual time (manual chapters 3–5).
///
/// Inputs: process output images ([`Drive::handle_image`], [`Drive::handle_output`]), ISDU
/// requests ([`Drive::handle_isdu`]), IO-Link communication events ([`Drive::handle_link`]),
/// jog keys ([`Drive::handle_keys`]), environment changes ([`Drive::handle_env`]) and time
/// ([`Drive::advance`]), each with a virtual timestamp in µs. Outputs are drained with
/// [`Drive::poll_input`] (one process input image per output image handled),
/// [`Drive::poll_isdu`] and [`Drive::poll_event`]; [`Drive::poll_timeout`] says when to call
/// [`Drive::advance`] next. Time never goes backwards: an earlier timestamp counts as now.
#[derive(Debug, Clone)]
pub struct Drive<'s> {
    pub(super) fam: Arc<PsxFamily>,
    pub(super) rules: Rules<'s>,
    pub(super) guards: Guards,
    pub(super) core: Positioner,
    pub(super) order: ByteOrder,
    /// Working values of stored numeric entries, by parameter id.
    pub(super) values: BTreeMap<String, i64>,
    /// The working values read on every step ([`Drive::refresh_hot`]).
    pub(super) hot: Hot,
    /// Working values of writable text entries.
    pub(super) texts: BTreeMap<String, String>,
    /// The EEPROM image of the saved entries.
    pub(super) saved: BTreeMap<String, i64>,
    pub(super) identity: Identity,
    pub(super) active_format: u8,
    pub(super) control: u16,
    pub(super) target: i64,
    pub(super) pd_speed: i64,
    pub(super) transfer_pulse: bool,
    pub(super) stamp: Option<PendingStamp>,
    pub(super) stamp_due: Option<(Micros, u8)>,
    /// The last format 0 image carried a valid stamp (PSX-LED-006).
    pub(super) stamp_streaming: bool,
    /// When the last time stamp fired (PSX-LED-005).
    pub(super) stamp_fired_at: Option<Micros>,
    pub(super) last_cmd: Command,
    pub(super) armed: bool,
    pub(super) pending_transfer: bool,
    pub(super) flags_before: Flags,
    /// Runs ended so far, and at the last snapshot (PSX-STS-0-SET-3).
    pub(super) ended: u64,
    pub(super) ended_before: u64,
    /// The shaft lies within the 256 revolutions of the encoder (PSX-POS-001).
    pub(super) in_encoder: bool,
    /// The last environment change was an internal position fault (PSX-STS-9-SET-1).
    pub(super) fault_injected: bool,
    pub(super) manual_dir: Option<i8>,
    /// Manual bits of the control word overridden by a target transfer (PSX-CMD-007).
    pub(super) manual_masked: Option<i8>,
    pub(super) link_up: bool,
    pub(super) last_rx: Micros,
    pub(super) timed_out: bool,
    pub(super) keys: JogKeys,
    pub(super) jog: JogMode,
    pub(super) family_run: FamilyRun,
    pub(super) deferred: Option<(Micros, Deferred)>,
    pub(super) brake_open: bool,
    pub(super) brake_close_at: Option<Micros>,
    pub(super) ideal: Option<Ideal>,
    pub(super) drag: bool,
    pub(super) base_speed_rpm: i64,
    pub(super) correction_rpm: i64,
    pub(super) run_started_at: Micros,
    pub(super) keys_fitted: bool,
    pub(super) max_torque: i64,
    pub(super) pending_reset: bool,
    pub(super) clock: Micros,
    pub(super) inputs: VecDeque<(Micros, Input)>,
    pub(super) answers: VecDeque<IsduAnswer>,
    pub(super) events: VecDeque<(Micros, Event)>,
}

pub(super) fn push_bounded<T>(q: &mut VecDeque<T>, v: T) {
    if q.len() >= MAX_QUEUED {
        q.pop_front();
    }
    q.push_back(v);
}

/// The process-data byte order of the reading in force (PSX-ERRATUM-050).
fn byte_order(rules: &Rules<'_>, config: &DriveConfig) -> ByteOrder {
    match config.readings.reading(rules.family(), "psx-pd-byte-order") {
        Some("little-endian") => ByteOrder::LittleEndian,
        Some("big-endian") => ByteOrder::BigEndian,
        _ => rules.wire_order(),
    }
}

impl<'s> Drive<'s> {
    /// A drive of the configured model, switched on at time 0 in the delivery state (manual
    /// 3.1, 3.2, 4.1).
    pub fn new(spec: &'s Spec, config: DriveConfig) -> Result<Drive<'s>, ModelError> {
        let family = spec.family(FamilyId::Psx3xx);
        let fam = PsxFamily::build(family, &config)?;
        let rules = Rules::from_family(family)?;
        let guards = Guards::from_rules(&rules, &config.readings)?;
        let core = Positioner::new(
            Arc::clone(&fam.core),
            fam.factory,
            config.environment.clone(),
        );
        let identity = Identity {
            production_date: i64::from(config.production_date),
            serial_number: i64::from(config.serial_number),
            software: config
                .software_version
                .map_or(fam.format2_software, i64::from),
            hardware: config.hardware_version.clone(),
            firmware: config.firmware_version.clone(),
        };
        let order = byte_order(&rules, &config);
        let mut drive = Drive {
            fam: Arc::new(fam),
            rules,
            guards,
            core,
            order,
            values: BTreeMap::new(),
            hot: Hot::default(),
            texts: BTreeMap::new(),
            saved: BTreeMap::new(),
            identity,
            active_format: 0,
            control: 0,
            target: 0,
            pd_speed: 0,
            transfer_pulse: false,
            stamp: None,
            stamp_due: None,
            stamp_streaming: false,
            stamp_fired_at: None,
            last_cmd: Command::default(),
            armed: false,
            pending_transfer: false,
            flags_before: Flags::default(),
            ended: 0,
            ended_before: 0,
            in_encoder: true,
            fault_injected: false,
            manual_dir: None,
            manual_masked: None,
            link_up: config.connected,
            last_rx: 0,
            timed_out: false,
            keys: JogKeys::NONE,
            jog: JogMode::Idle,
            family_run: FamilyRun::None,
            deferred: None,
            brake_open: false,
            brake_close_at: None,
            ideal: None,
            drag: false,
            base_speed_rpm: 0,
            correction_rpm: 0,
            run_started_at: 0,
            keys_fitted: config.jog_keys,
            max_torque: 0,
            pending_reset: false,
            clock: 0,
            inputs: VecDeque::new(),
            answers: VecDeque::new(),
            events: VecDeque::new(),
        };
        drive.factory_image();
        drive.boot_values();
        drive.update_speeds();
        drive.after_core(0);
        Ok(drive)
    }

    // ------------------------------------------------------------------ views

    /// The positioning core (manual chapters 4–5).
    pub fn core(&self) -> &Positioner {
        &self.core
    }

    /// The codec tables in force (manual 3.1, 3.3).
    pub fn rules(&self) -> &Rules<'s> {
        &self.rules
    }

    /// The gearbox model's id (manual 3.2).
    pub fn model_id(&self) -> &str {
        &self.fam.model_id
    }

    /// The process-data byte order the drive uses (manual 3.3.2; PSX-ERRATUM-050).
    pub fn byte_order(&self) -> ByteOrder {
        self.order
    }

    /// Current virtual time in µs (chapter 4).
    pub fn now(&self) -> Micros {
        self.clock
    }

    /// The process-data format in force, read from the EEPROM at the last start (PSX-PD-010).
    pub fn active_format(&self) -> u8 {
        self.active_format
    }

    /// The IO-Link device ID the drive reports: model code × 100 + the format's suffix
    /// (PSX-DP-007, PSX-DP-008).
    pub fn device_id(&self) -> Option<u32> {
        let code = u32::try_from(self.fam.model_code).ok()?;
        self.rules
            .protocol()
            .device_id_for(code, self.active_format)
    }

    /// Whether the IO-Link master is communicating (manual 5.9, 5.10 table).
    pub fn link_up(&self) -> bool {
        self.link_up
    }

    /// The jog key inputs (manual 5.10).
    pub fn keys(&self) -> JogKeys {
        self.keys
    }

    /// The control word in force (ISDU 110; in format 0 with the fired control code, 3.3.1).
    pub fn control_word(&self) -> u16 {
        self.control
    }

    /// The target in force (ISDU 112, manual 3.3.1).
    pub fn target(&self) -> i64 {
        self.target
    }

    /// The brake option of the drive, None without brake (manual 5.11–5.13).
    pub fn brake(&self) -> Option<BrakeKind> {
        self.fam.brake.map(|b| b.kind)
    }

    /// Whether the brake is open (manual 5.12, 5.13); false for drives without brake.
    pub fn brake_open(&self) -> bool {
        self.brake_open
    }

    /// The status word ISDU 64 (manual 3.4): the core's bits, the drag error bit 1 and the
    /// jog key bits 2 and 3.
    pub fn status_word(&self) -> u16 {
        if !self.core.powered() {
            return 0;
        }
        let mut w = u16::try_from(self.core.status_word() & 0xFFFF).unwrap_or(0);
        // PSX-STS-1-SET-1, PSX-STS-1-SET-2.
        if self.drag {
            w |= self.fam.drag_bit;
        }
        // PSX-STS-2-SET-1 / PSX-STS-2-RESET-1, PSX-STS-3-SET-1 / PSX-STS-3-RESET-1.
        if self.keys.forward {
            w |= self.fam.forward_key_bit;
        }
        if self.keys.reverse {
            w |= self.fam.reverse_key_bit;
        }
        w
    }

    /// What the three LEDs show now (manual 2.6, 3.3.1); all dark while the drive is off.
    pub fn leds(&self) -> Leds {
        if !self.core.powered() {
            return Leds {
                green: LedLight::Off,
                orange: LedLight::Off,
                yellow: LedLight::Off,
            };
        }
        // PSX-LED-001, PSX-LED-002.
        let green = if self.link_up {
            LedLight::On90Percent
        } else {
            LedLight::Off
        };
        // PSX-LED-003: lit in the time-stamp format, dark in formats 1 and 2; PSX-LED-005: a
        // fired stamp is acknowledged by a dark phase; PSX-LED-006: dark while valid stamps
        // keep arriving.
        let acknowledging = self
            .stamp_fired_at
            .is_some_and(|t| self.clock < t.saturating_add(self.fam.stamp_ack_dark_us));
        let orange = if self.active_format == self.rules.timestamp().format
            && !acknowledging
            && !(self.link_up && self.stamp_streaming)
        {
            LedLight::On
        } else {
            LedLight::Off
        };
        // PSX-LED-004.
        let yellow = if self.core.environment().motor_dv > 0 {
            LedLight::On
        } else {
            LedLight::Off
        };
        Leds {
            green,
            orange,
            yellow,
        }
    }

    /// Whether a status flag of the core is set (manual 3.4).
    pub fn flag(&self, flag: Flag) -> bool {
        self.core.flags().get(flag)
    }

    /// Whether the drag error bit is set (PSX-STS-1-SET-1, PSX-STS-1-SET-2).
    pub fn drag_error(&self) -> bool {
        self.drag
    }

    /// What moves the drive now (manual chapters 4–5).
    pub fn run_state(&self) -> RunState {
        if self.deferred.is_some() {
            return RunState::BrakeWait;
        }
        let kind = self.core.run_kind();
        match self.family_run {
            FamilyRun::Step(dir) if kind.is_some() => return RunState::JogStep { dir },
            FamilyRun::Continuous(dir) if kind.is_some() => return RunState::JogContinuous { dir },
            FamilyRun::ReferenceLoop { .. } if kind.is_some() => return RunState::ReferenceLoop,
            FamilyRun::Safe(target) if self.core.run_target().is_some() => {
                return RunState::SafePosition { target }
            }
            _ => {}
        }
        match (kind, self.core.run_target()) {
            (None, _) => RunState::Idle,
            (Some(RunKind::Positioning), Some(target)) => RunState::Positioning { target },
            (Some(RunKind::Readjust), Some(target)) => RunState::Readjust { target },
            (Some(RunKind::Centre), Some(target)) => RunState::Centre { target },
            (Some(RunKind::Manual), _) => match self.manual_dir {
                Some(dir) => RunState::Manual { dir },
                None => RunState::Stopping,
            },
            _ => RunState::Stopping,
        }
    }

    /// The speed limit in force for the run in progress, rpm: the requested speed capped by
    /// ISDU 143/144 (PSX-VEL-001, PSX-VEL-002, PSX-VEL-005, PSX-VEL-006).
    pub fn set_speed_rpm(&self) -> i64 {
        let s = self.core.settings().drive;
        match self.run_state() {
            RunState::Manual { .. } | RunState::JogContinuous { .. } => s.manual_speed,
            _ => s.positioning_speed,
        }
    }

    /// The process input image the drive sends now (manual 3.3.2).
    pub fn input(&self) -> Input {
        if !self.core.powered() {
            return Input::default();
        }
        Input {
            status: self.status_word(),
            // PSX-ERRATUM-011: the input's speed is ISDU 65 (3.3.2).
            rpm: i16::try_from(
                self.reported_rpm(self.core.speed_rpm())
                    .clamp(i64::from(i16::MIN), i64::from(i16::MAX)),
            )
            .unwrap_or(0),
            actual: i32::try_from(
                self.core
                    .actual()
                    .clamp(i64::from(i32::MIN), i64::from(i32::MAX)),
            )
            .unwrap_or(0),
        }
    }

    /// The process input image as bytes in the drive's byte order (manual 3.3.2).
    pub fn input_image(&self) -> Vec<u8> {
        self.input()
            .to_bytes(&self.rules, self.order)
            .unwrap_or_else(|_| vec![0; Input::buffer_len(&self.rules)])
    }

    /// The EEPROM value of a saved entry, None for entries that are not saved
    /// (PSX-PAR-SAVED, PSX-PAR-NOT-SAVED).
    pub fn saved_value(&self, id: &str) -> Option<i64> {
        self.saved.get(id).copied()
    }

    // ------------------------------------------------------------------ outputs

    /// The next process input image, sent in answer to an output image (3.3.2).
    pub fn poll_input(&mut self) -> Option<(Micros, Input)> {
        self.inputs.pop_front()
    }

    /// The next ISDU answer, oldest first (3.1).
    pub fn poll_isdu(&mut self) -> Option<IsduAnswer> {
        self.answers.pop_front()
    }

    /// The next trace event, oldest first (chapters 3–5).
    pub fn poll_event(&mut self) -> Option<(Micros, Event)> {
        self.events.pop_front()
    }

    pub(super) fn event(&mut self, at: Micros, e: Event) {
        push_bounded(&mut self.events, (at, e));
    }

    // ------------------------------------------------------------------ time

    /// The next virtual time at which the drive changes by itself, None when nothing happens
    /// until the next input (quinn-proto `poll_timeout`).
    pub fn poll_timeout(&self) -> Option<Micros> {
        let timers = [
            self.core.poll_timeout(),
            self.stamp_due.map(|(t, _)| t),
            self.deferred.map(|(t, _)| t),
            self.brake_close_at.filter(|_| self.brake_open),
            self.jog_deadline(),
            self.watchdog(),
        ];
        timers.into_iter().flatten().min()
    }

    /// Runs the drive up to `now` (manual chapters 4–5): the physics one core step at a time
    /// with the family's rules between steps, time stamps, brake, jog and time-out timers.
    pub fn advance(&mut self, now: Micros) {
        while let Some(t) = self.poll_timeout().filter(|t| *t <= now) {
            let t = t.max(self.clock);
            self.snapshot();
            self.core.advance(t);
            self.clock = self.clock.max(t);
            self.after_core(t);
            self.tick_rules(t);
            if self.poll_timeout().is_some_and(|n| n <= t) {
                // Every timer moves on when it is handled; one that does not must not stall
                // the loop (defensive, not expected).
                break;
            }
        }
        self.snapshot();
        self.core.advance(now);
        self.clock = self.clock.max(now);
        self.after_core(self.clock);
    }

    // ------------------------------------------------------------------ inputs

    /// A process output image in the active format received at `now` (manual 3.3.1); an
    /// input image answers it.
    pub fn handle_image(&mut self, now: Micros, bytes: &[u8]) -> Result<(), ImageError> {
        let out = match self.high_bit_stamp_word(bytes) {
            Some(moved) => Output::parse(&self.rules, self.active_format, self.order, &moved)?,
            None => Output::parse(&self.rules, self.active_format, self.order, bytes)?,
        };
        self.handle_output(now, &out)
    }

    /// The time-stamp image with its sub-word fields moved to the spec's bit positions when
    /// the bits are numbered from the first transmitted bit (PSX-ERRATUM-051 reading
    /// "high-bits": control code in the two most significant bits, stamp in the low 14;
    /// PSX-PD-002). None when the image is taken as it is.
    fn high_bit_stamp_word(&self, bytes: &[u8]) -> Option<Vec<u8>> {
        if !self.fam.options.stamp_high_bits || self.active_format != self.rules.timestamp().format
        {
            return None;
        }
        let layout = &self.rules.output(self.active_format)?.layout;
        let wire = layout.wire_order();
        let mut moved = bytes.to_vec();
        for f in layout.fields().iter().filter(|f| f.is_sub_word()) {
            let word = f.read_word(bytes, self.order, wire)?;
            let width = u32::try_from(f.len().saturating_mul(8)).ok()?;
            let from = width.checked_sub(f.bit())?.checked_sub(f.bits())?;
            let mask = 1u64.checked_shl(f.bits()).map_or(u64::MAX, |m| m - 1);
            let value = word.checked_shr(from).unwrap_or(0) & mask;
            f.write(&mut moved, self.order, wire, i64::try_from(value).ok()?)
                .ok()?;
        }
        Some(moved)
    }

    /// A typed process output received at `now` (manual 3.3.1). An output of another format
    /// than the active one is refused; nothing is received while the communication is down.
    pub fn handle_output(&mut self, now: Micros, out: &Output) -> Result<(), ImageError> {
        let format = out.format(&self.rules).unwrap_or(u8::MAX);
        if format != self.active_format {
            return Err(ImageError::UnknownFormat { format });
        }
        self.advance(now);
        let now = self.clock;
        if !self.core.powered() || !self.link_up {
            return Ok(());
        }
        self.received(now);
        self.apply_output(now, out);
        let input = self.input();
        push_bounded(&mut self.inputs, (now, input));
        Ok(())
    }

    /// A message from the master arrived: the time-out restarts (PSX-TIMEOUT-003).
    pub(super) fn received(&mut self, now: Micros) {
        self.last_rx = now;
        self.timed_out = false;
    }

    /// An IO-Link communication event at `now` (manual 5.9, 5.10).
    pub fn handle_link(&mut self, now: Micros, ev: LinkEvent) {
        self.advance(now);
        let now = self.clock;
        match ev {
            LinkEvent::Connected => {
                self.link_up = true;
                self.received(now);
            }
            LinkEvent::Lost => self.link_up = false,
        }
        self.event(now, Event::Link(ev));
        self.update_jog(now);
        self.after_core(now);
    }

    /// The jog key inputs change at `now` (manual 2.5.3, 5.10); ignored without the jog
    /// keys option.
    pub fn handle_keys(&mut self, now: Micros, keys: JogKeys) {
        self.advance(now);
        let now = self.clock;
        if !self.keys_fitted || keys == self.keys {
            return;
        }
        self.keys = keys;
        self.event(now, Event::Keys(keys));
        self.update_jog(now);
        self.after_core(now);
    }

    /// An environment change at `now` (supplies, temperature, obstructions, external
    /// rotation, faults). A control voltage of 0 switches the drive off, a later one on again.
    pub fn handle_env(&mut self, now: Micros, change: EnvChange) {
        self.advance(now);
        let now = self.clock;
        if let EnvChange::ControlVoltage { dv } = change {
            let was = self.core.powered();
            if dv > 0 && !was {
                self.boot_values();
            }
            self.core.env(now, change);
            if dv > 0 && !was {
                self.started(now);
            }
        } else {
            self.snapshot();
            self.fault_injected = change == EnvChange::PositionFault;
            self.core.env(now, change);
        }
        self.after_core(now);
        self.check_encoder();
        self.fault_injected = false;
        self.check_reentry();
        self.check_readjust(now);
        self.after_core(now);
    }

    /// Switches the control voltage off and on again at `now`: working values are lost, the
    /// EEPROM image and its process-data format are loaded (PSX-CMD-018, PSX-PD-010).
    pub fn power_cycle(&mut self, now: Micros) {
        let dv = self.core.environment().control_dv;
        self.handle_env(now, EnvChange::ControlVoltage { dv: 0 });
        self.handle_env(
            now,
            EnvChange::ControlVoltage {
                dv: if dv == 0 { 240 } else { dv },
            },
        );
    }

    /// Restarts the device at `now` as ISDU 2 = 128 does (PSX-CMD-011, PSX-PD-010).
    pub(super) fn restart(&mut self, now: Micros) {
        self.core.power_off(now);
        self.boot_values();
        self.core.power_on(now);
        self.started(now);
        self.after_core(now);
    }

    /// What every start leaves: outputs 0, no stamp, no jog, the format of the EEPROM.
    fn started(&mut self, now: Micros) {
        self.control = 0;
        self.target = 0;
        self.pd_speed = 0;
        self.transfer_pulse = false;
        self.stamp = None;
        self.stamp_due = None;
        self.stamp_streaming = false;
        self.stamp_fired_at = None;
        self.last_cmd = Command::default();
        self.armed = false;
        self.pending_transfer = false;
        self.manual_dir = None;
        self.manual_masked = None;
        self.timed_out = false;
        self.last_rx = now;
        self.jog = JogMode::Idle;
        self.family_run = FamilyRun::None;
        self.deferred = None;
        self.brake_open = false;
        self.brake_close_at = None;
        self.ideal = None;
        self.drag = false;
        self.in_encoder = self.encoder_inside();
        self.guards.reset();
        self.update_speeds();
        let format = self.active_format;
        self.event(now, Event::Restarted { format });
    }
}
