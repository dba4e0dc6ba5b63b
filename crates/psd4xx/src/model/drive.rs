//! The PSD4xx reference drive: process images, PKW server, records, parameters, connection and
//! power on top of the positioning core (manual 3.2–3.9, chapter 4).

use super::config::DriveConfig;
use super::error::ModelError;
use super::family::{Entry, PsdFamily, Role};
use super::io::{Event, LinkEvent, RecordAnswer, RecordFailure, RecordRequest, RecordResponse};
use crate::pkw::{PkwRequest, PkwResponse, Reply};
use crate::record::{RecordRead, RecordValue, RecordWrite};
use crate::{DecodeError, ErrorCode, Input, Options, Output, Rules, Width};
use drivespec_positioner::machine::{Command, Setting, Settings};
use drivespec_positioner::{ByteOrder, EnvChange, Micros, Positioner};
use drivespec_spec::psd4xx::{IndLayout, PkwOp, WordFill, WordPosition};
use drivespec_spec::{DataType, FamilyId, Readings, Spec};
use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;

/// Most undrained outputs kept per queue; older ones are dropped (bounded memory) (3.2–3.9).
pub const MAX_QUEUED: usize = 4096;

#[derive(Debug, Clone)]
struct Identity {
    address_switch: i64,
    production_date: i64,
    serial_number: i64,
    model_number: i64,
    model_string: Vec<u8>,
    version: i64,
}

/// A reference PSD4xx drive on virtual time (manual 3.2–3.9, chapter 4).
///
/// Inputs: output images ([`Drive::handle_image`], [`Drive::handle_output`]), records
/// ([`Drive::handle_record`]), connection events ([`Drive::handle_link`]), environment changes
/// ([`Drive::handle_env`]) and time ([`Drive::advance`]), each with a virtual timestamp in µs.
/// Outputs are drained with [`Drive::poll_input`] (one input image per output image handled),
/// [`Drive::poll_record`] and [`Drive::poll_event`]; [`Drive::poll_timeout`] says when to call
/// [`Drive::advance`] next. Time never goes backwards: an earlier timestamp counts as now.
#[derive(Debug, Clone)]
pub struct Drive {
    fam: Arc<PsdFamily>,
    rules: Arc<Rules>,
    core: Positioner,
    plain: BTreeMap<u32, i64>,
    saved: BTreeMap<u32, i64>,
    identity: Identity,
    station_name: String,
    address_in_force: i64,
    pkw_last: Option<PkwRequest>,
    pkw_response: PkwResponse,
    pending_reset: bool,
    connected: bool,
    iops_good: bool,
    last_rx: Micros,
    watchdog_us: Option<u64>,
    in_force: Output,
    clock: Micros,
    inputs: VecDeque<(Micros, Input)>,
    records: VecDeque<RecordResponse>,
    events: VecDeque<(Micros, Event)>,
}

fn push_bounded<T>(q: &mut VecDeque<T>, v: T) {
    if q.len() >= MAX_QUEUED {
        q.pop_front();
    }
    q.push_back(v);
}

/// The codec options of the erratum readings in force (PSD-ERRATUM-050, -053, -054).
fn options(spec: &Spec, readings: &Readings) -> Result<Options, ModelError> {
    let family = spec.family(FamilyId::Psd4xx);
    let mut o = Options::manual(spec)?;
    match readings.reading(family, "psd-byte-order") {
        Some("little-endian") => o.byte_order = ByteOrder::LittleEndian,
        Some("big-endian") => o.byte_order = ByteOrder::BigEndian,
        _ => {}
    }
    match readings.reading(family, "psd-pkw-word") {
        Some("low-word-zero") => {
            (o.word_position, o.word_fill) = (WordPosition::Low, WordFill::Zero)
        }
        Some("low-word-sign") => {
            (o.word_position, o.word_fill) = (WordPosition::Low, WordFill::SignExtend)
        }
        Some("high-word") => (o.word_position, o.word_fill) = (WordPosition::High, WordFill::Zero),
        _ => {}
    }
    match readings.reading(family, "psd-pkw-ind") {
        Some("word") => o.ind_layout = IndLayout::Word,
        Some("high-byte") => o.ind_layout = IndLayout::HighByte,
        _ => {}
    }
    Ok(o)
}

fn clamp_to(t: DataType, v: i64) -> i64 {
    match t.bounds() {
        Some((lo, hi)) => v.clamp(lo, hi),
        None => v,
    }
}

impl Drive {
    /// A drive of the configured model, switched on at time 0 in the delivery state (manual
    /// 3.3, 3.4, 2.2).
    pub fn new(spec: &Spec, config: DriveConfig) -> Result<Drive, ModelError> {
        let fam = PsdFamily::build(spec, &config)?;
        let rules = Rules::with_options(spec, options(spec, &config.readings)?)?;
        let core = Positioner::new(
            Arc::clone(&fam.core),
            fam.factory,
            config.environment.clone(),
        );
        let mut plain = BTreeMap::new();
        let mut saved = BTreeMap::new();
        for e in &fam.entries {
            if e.role == Role::Plain {
                plain.insert(e.number, e.default.unwrap_or(0));
            }
            if e.saved {
                let v = match e.role {
                    Role::Setting(s) => fam.factory.get(s),
                    _ => e.default,
                };
                if let Some(v) = v {
                    saved.insert(e.number, v);
                }
            }
        }
        let model_string = config
            .model_string
            .clone()
            .unwrap_or_else(|| {
                let base: String = fam.model_id.chars().take_while(|c| *c != '-').collect();
                format!("{base}-PN-x")
            })
            .into_bytes();
        let idle = Output::idle(&rules);
        let address_in_force = saved.get(&fam.address_param).copied().unwrap_or(0);
        let mut drive = Drive {
            pkw_response: Input::idle(&rules).pkw,
            fam: Arc::new(fam),
            rules: Arc::new(rules),
            core,
            plain,
            saved,
            identity: Identity {
                address_switch: i64::from(config.address_switch),
                production_date: i64::from(config.production_date),
                serial_number: i64::from(config.serial_number),
                model_number: i64::from(config.model_number),
                model_string,
                version: i64::from(config.version),
            },
            station_name: config.station_name.clone(),
            address_in_force,
            pkw_last: None,
            pending_reset: false,
            connected: config.connected,
            iops_good: true,
            last_rx: 0,
            watchdog_us: config.watchdog_us,
            in_force: idle,
            clock: 0,
            inputs: VecDeque::new(),
            records: VecDeque::new(),
            events: VecDeque::new(),
        };
        drive.drain_core();
        Ok(drive)
    }

    // ------------------------------------------------------------------ views

    /// The positioning core (manual chapter 4).
    pub fn core(&self) -> &Positioner {
        &self.core
    }

    /// The codec tables in force (manual 3.5, 3.8).
    pub fn rules(&self) -> &Rules {
        &self.rules
    }

    /// Current virtual time in µs (3.2–3.9).
    pub fn now(&self) -> Micros {
        self.clock
    }

    /// The outputs in force: the last valid output image, or zeros (manual 3.9).
    pub fn outputs_in_force(&self) -> &Output {
        &self.in_force
    }

    /// Whether the controller is connected (manual 3.9, 4.9).
    pub fn connected(&self) -> bool {
        self.connected
    }

    /// The input image the drive sends now (manual 3.5.2).
    pub fn input(&self) -> Input {
        if !self.core.powered() {
            return Input::idle(&self.rules);
        }
        Input {
            pkw: self.pkw_response,
            status: u16::try_from(self.core.status_word() & 0xFFFF).unwrap_or(0),
            speed: i16::try_from(clamp_to(DataType::I16, self.core.speed_rpm())).unwrap_or(0),
            actual: i32::try_from(clamp_to(DataType::I32, self.core.actual())).unwrap_or(0),
        }
    }

    /// The input image as bytes (manual 3.5.2).
    pub fn input_image(&self) -> Vec<u8> {
        self.input()
            .to_bytes(&self.rules)
            .unwrap_or_else(|_| vec![0; Input::buffer_len(&self.rules)])
    }

    /// The value of parameter `pnu` as a PKW read would give it now (manual 3.3), or the
    /// error code of the read.
    pub fn parameter(&self, pnu: u16) -> Result<i64, ErrorCode> {
        let codes = self.rules.pkw().error_codes();
        let e = self
            .fam
            .entry(u32::from(pnu))
            .ok_or(codes.unknown_parameter)?;
        self.value(e).ok_or(codes.wrong_type)
    }

    /// The value of parameter `pnu` in the EEPROM image, None for parameters not backed up
    /// (PSD-PAR-SAVE-001, PSD-PAR-SAVE-002).
    pub fn saved_value(&self, pnu: u16) -> Option<i64> {
        self.saved.get(&u32::from(pnu)).copied()
    }

    /// The device address in force: par. 92 as saved at the last power-up (PSD-PAR-92-002).
    pub fn address_in_force(&self) -> i64 {
        self.address_in_force
    }

    /// The PROFINET station name (manual 2.1; cleared by par. 96 = -3).
    pub fn station_name(&self) -> &str {
        &self.station_name
    }

    // ------------------------------------------------------------------ time and outputs

    /// Runs the drive up to `now` (manual chapter 4), including the connection watchdog (4.9).
    pub fn advance(&mut self, now: Micros) {
        if let (Some(w), true) = (self.watchdog_us, self.connected) {
            let deadline = self.last_rx.saturating_add(w);
            if deadline <= now {
                self.core.advance(deadline);
                self.clock = self.clock.max(deadline);
                self.lose(deadline);
            }
        }
        self.core.advance(now);
        self.clock = self.clock.max(now);
        self.drain_core();
    }

    /// When the drive next changes by itself (quinn-proto `poll_timeout`).
    pub fn poll_timeout(&self) -> Option<Micros> {
        let watchdog = match (self.watchdog_us, self.connected) {
            (Some(w), true) => Some(self.last_rx.saturating_add(w)),
            _ => None,
        };
        match (self.core.poll_timeout(), watchdog) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }

    /// The next input image produced in answer to an output image, oldest first (3.5.2).
    pub fn poll_input(&mut self) -> Option<(Micros, Input)> {
        self.inputs.pop_front()
    }

    /// The next record answer, oldest first (3.2.2).
    pub fn poll_record(&mut self) -> Option<RecordResponse> {
        self.records.pop_front()
    }

    /// The next trace event, oldest first (3.2–3.9).
    pub fn poll_event(&mut self) -> Option<(Micros, Event)> {
        self.events.pop_front()
    }

    fn event(&mut self, at: Micros, e: Event) {
        push_bounded(&mut self.events, (at, e));
    }

    fn drain_core(&mut self) {
        while let Some((at, e)) = self.core.poll_event() {
            push_bounded(&mut self.events, (at, Event::Core(e)));
        }
    }

    // ------------------------------------------------------------------ inputs

    /// An output image (14 bytes) received at `now` (manual 3.5.1); an input image answers it.
    pub fn handle_image(&mut self, now: Micros, bytes: &[u8]) -> Result<(), DecodeError> {
        let out = Output::parse(&self.rules, bytes)?;
        self.handle_output(now, &out);
        Ok(())
    }

    /// A typed output image received at `now` (manual 3.5.1). Ignored while the connection is
    /// down or IOPS is bad: the outputs in force stay (3.9).
    pub fn handle_output(&mut self, now: Micros, out: &Output) {
        self.advance(now);
        let now = self.clock;
        if self.core.powered() && self.connected && self.iops_good {
            self.last_rx = now;
            self.apply(now, *out);
        }
        if self.core.powered() {
            let input = self.input();
            push_bounded(&mut self.inputs, (now, input));
        }
        self.drain_core();
    }

    fn decode_control(&self, out: &Output) -> Command {
        let c = self.fam.controls;
        let w = out.control;
        Command {
            manual_up: w & c.manual_up != 0,
            manual_down: w & c.manual_down != 0,
            transfer: w & c.transfer != 0,
            release: w & c.release != 0,
            no_loop: w & c.no_loop != 0,
            toggle: w & c.toggle != 0,
            reserved: w & c.must_be_zero != 0,
            target: i64::from(out.target),
        }
    }

    fn apply(&mut self, now: Micros, out: Output) {
        self.in_force = out;
        self.pkw_request(now, out.pkw);
        if self.take_reset(now) {
            return;
        }
        let cmd = self.decode_control(&out);
        self.core.command(now, cmd);
    }

    /// A connection event at `now` (manual 3.9, 4.9).
    pub fn handle_link(&mut self, now: Micros, ev: LinkEvent) {
        self.advance(now);
        let now = self.clock;
        match ev {
            LinkEvent::Connected => {
                self.connected = true;
                self.last_rx = now;
            }
            LinkEvent::Lost => {
                if self.connected {
                    self.lose(now);
                }
            }
            LinkEvent::IopsBad => self.iops_good = false,
            LinkEvent::IopsGood => self.iops_good = true,
        }
        self.event(now, Event::Link(ev));
        self.drain_core();
    }

    /// PSD-OUT-002, PSD-ABORT-002: the outputs become 0 and a run in progress aborts.
    fn lose(&mut self, now: Micros) {
        self.connected = false;
        if !self.fam.loss_sets_aborted {
            // Erratum PSD-ERRATUM-063 reading "internal-resume": the abort leaves bit 5.
            self.core.halt(now);
        }
        let zero = Output::idle(&self.rules);
        if self.core.powered() {
            self.apply(now, zero);
        }
    }

    /// An environment change at `now` (supplies, temperature, obstructions, external rotation,
    /// faults). A control voltage of 0 switches the drive off, a later one on again (3.2–3.9).
    pub fn handle_env(&mut self, now: Micros, change: EnvChange) {
        self.advance(now);
        let now = self.clock;
        if let EnvChange::ControlVoltage { dv } = change {
            let was = self.core.powered();
            if dv > 0 && !was {
                self.power_up_state(now);
            }
            self.core.env(now, change);
            if dv == 0 && was {
                self.pkw_last = None;
                self.pkw_response = Input::idle(&self.rules).pkw;
            }
        } else {
            self.core.env(now, change);
        }
        self.drain_core();
    }

    /// Switches the control voltage off and on again at `now` (manual 3.3 par. 96 = -6 does
    /// the same): working values are lost, the EEPROM image is loaded (PSD-PAR-SAVE-001).
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

    /// What power-up loads (3.9 power-on: outputs 0; PSD-PAR-SAVE-001: the EEPROM image).
    fn power_up_state(&mut self, now: Micros) {
        self.restore(now, false);
        self.address_in_force = self
            .saved
            .get(&self.fam.address_param)
            .copied()
            .unwrap_or(0);
        self.pkw_last = None;
        self.pkw_response = Input::idle(&self.rules).pkw;
        self.in_force = Output::idle(&self.rules);
    }

    fn take_reset(&mut self, now: Micros) -> bool {
        if !self.pending_reset {
            return false;
        }
        self.pending_reset = false;
        // PSD-PAR-96-001: as if the control voltage were switched off and on. The request
        // that ordered it stays answered (it is not executed again).
        let last = self.pkw_last;
        let response = self.pkw_response;
        self.core.power_off(now);
        self.power_up_state(now);
        self.core.power_on(now);
        self.pkw_last = last;
        self.pkw_response = response;
        self.drain_core();
        true
    }

    // ------------------------------------------------------------------ parameters

    fn value(&self, e: &Entry) -> Option<i64> {
        let env = self.core.environment();
        let v = match e.role {
            Role::Setting(s) => self.core.get(s),
            Role::Status => i64::try_from(self.core.status_word() & 0xFFFF).unwrap_or(0),
            Role::Speed => self.core.speed_rpm(),
            Role::Control => i64::from(self.in_force.control),
            Role::Target => self.core.axis().target().unwrap_or(0),
            // DECISION: par. 96 reads 0 (the manual gives its values for writing only).
            Role::Command => 0,
            Role::MotorVoltage => self.core.motor_voltage(),
            Role::ControlVoltage => i64::from(env.control_dv),
            Role::Temperature => i64::from(env.celsius),
            // DECISION: motor currents are not modelled; they read 0.
            Role::Current | Role::MaxCurrent => 0,
            Role::AddressSwitch => self.identity.address_switch,
            Role::ProductionDate => self.identity.production_date,
            Role::SerialNumber => self.identity.serial_number,
            Role::ModelNumber => self.identity.model_number,
            Role::Version => self.identity.version,
            Role::ModelString => return None,
            Role::Plain => self.plain.get(&e.number).copied().unwrap_or(0),
        };
        Some(clamp_to(e.data_type, v))
    }

    fn working(&self, e: &Entry) -> Option<i64> {
        match e.role {
            Role::Setting(Setting::Actual) => None,
            Role::Setting(s) => Some(self.core.get(s)),
            Role::Plain => self.plain.get(&e.number).copied(),
            _ => None,
        }
    }

    /// PSD-PAR-SAVE-001: the backed-up parameters go to the EEPROM image.
    fn save(&mut self, now: Micros) {
        let fam = Arc::clone(&self.fam);
        for e in fam.entries.iter().filter(|e| e.saved) {
            if let Some(v) = self.working(e) {
                self.saved.insert(e.number, v);
            }
        }
        self.event(now, Event::Saved);
    }

    /// Loads the delivery values (PSD-PAR-DELIVERY-001) or the EEPROM image into the working
    /// parameters, without recalculation cascades.
    fn restore(&mut self, now: Micros, delivery: bool) {
        let fam = Arc::clone(&self.fam);
        let mut settings: Settings = self.core.settings();
        for e in &fam.entries {
            let value = if delivery {
                match e.role {
                    Role::Setting(s) => fam.factory.get(s),
                    _ => e.default,
                }
            } else if e.saved {
                self.saved.get(&e.number).copied()
            } else {
                None
            };
            let Some(v) = value else { continue };
            match e.role {
                Role::Setting(s) => settings.put(s, v),
                Role::Plain => {
                    self.plain.insert(e.number, v);
                }
                _ => {}
            }
        }
        self.core.load(now, &settings);
        self.event(now, Event::Restored { delivery });
    }

    /// Writes parameter `pnu` at `now` as a PKW or record write would (manual 3.3, 3.8
    /// error codes); the oracle's direct access.
    pub fn write_parameter(&mut self, now: Micros, pnu: u16, value: i64) -> Result<(), ErrorCode> {
        self.advance(now);
        let now = self.clock;
        let codes = *self.rules.pkw().error_codes();
        let e = self
            .fam
            .entry(u32::from(pnu))
            .cloned()
            .ok_or(codes.unknown_parameter)?;
        let r = self.write_value(now, &e, value);
        self.take_reset(now);
        self.drain_core();
        r
    }

    fn write_value(&mut self, now: Micros, e: &Entry, value: i64) -> Result<(), ErrorCode> {
        let codes = *self.rules.pkw().error_codes();
        // PSD-PAR-READONLY-001, PSD-PD-009: read-only and process-data parameters.
        if !e.access.writable() {
            return Err(codes.read_only);
        }
        // PSD-PAR-RANGE-001, PSD-PKW-025: tables 3.3 and 3.4.
        if let Some(r) = &e.range {
            if !r.contains(value) {
                return Err(codes.out_of_range);
            }
        }
        if let Some((lo, hi)) = e.data_type.bounds() {
            if !(lo..=hi).contains(&value) {
                return Err(codes.out_of_range);
            }
        }
        // PSD-PKW-030, PSD-PAR-3-003, PSD-PAR-37-003, PSD-PAR-38-002, PSD-PAR-40-002,
        // PSD-PAR-41-002: writes that need a standstill.
        if e.standstill && !self.core.is_standstill() {
            return Err(codes.operating_state);
        }
        match e.role {
            Role::Setting(s) => self
                .core
                .set(now, s, value)
                .map_err(|_| codes.out_of_range)?,
            Role::Plain => {
                self.plain.insert(e.number, value);
            }
            Role::Command => self.command96(now, value)?,
            _ => return Err(codes.read_only),
        }
        let pnu = u16::try_from(e.number).unwrap_or(u16::MAX);
        self.event(now, Event::ParameterWritten { pnu, value });
        Ok(())
    }

    /// Par. 96 (manual 3.3 par. 96).
    fn command96(&mut self, now: Micros, v: i64) -> Result<(), ErrorCode> {
        let c = self.fam.commands;
        let codes = *self.rules.pkw().error_codes();
        // DECISION: changing the whole parameter set needs a standstill (error 17 otherwise,
        // like the standstill-only parameters); saving and resetting are always possible.
        let restores = [
            c.delivery_centre,
            c.user_centre,
            c.delivery_clear_name,
            c.user,
            c.delivery,
        ];
        if restores.contains(&v) && !self.core.is_standstill() {
            return Err(codes.operating_state);
        }
        if v == c.reset {
            // PSD-PAR-96-001 (done after the answer, see take_reset).
            self.pending_reset = true;
        } else if v == c.save {
            // PSD-PAR-96-007, PSD-PAR-96-009 (DECISION: saving takes no virtual time; the
            // manual gives only an upper bound of 1 s).
            self.save(now);
        } else if v == c.delivery_centre {
            // PSD-PAR-96-002.
            self.restore(now, true);
            self.save(now);
            self.core.start_centre_run(now);
        } else if v == c.user_centre {
            // PSD-PAR-96-003.
            self.restore(now, false);
            self.core.start_centre_run(now);
        } else if v == c.delivery_clear_name {
            // PSD-PAR-96-004.
            self.restore(now, true);
            self.save(now);
            self.station_name.clear();
            self.event(now, Event::StationNameCleared);
        } else if v == c.user {
            // PSD-PAR-96-005.
            self.restore(now, false);
        } else if v == c.delivery {
            // PSD-PAR-96-006.
            self.restore(now, true);
        } else {
            // PSD-PAR-96-008.
            return Err(codes.out_of_range);
        }
        Ok(())
    }

    // ------------------------------------------------------------------ PKW

    /// PSD-PKW-003, PSD-PKW-004, PSD-PKW-007: one command at a time, answered once and held
    /// until the controller sends another block.
    fn pkw_request(&mut self, now: Micros, req: PkwRequest) {
        if self.pkw_last == Some(req) {
            return;
        }
        self.pkw_last = Some(req);
        self.pkw_response = self.pkw_answer(now, &req);
    }

    fn pkw_answer(&mut self, now: Micros, req: &PkwRequest) -> PkwResponse {
        let rules = Arc::clone(&self.rules);
        let pr = rules.pkw();
        let codes = *pr.error_codes();
        let error = |e: ErrorCode| PkwResponse {
            ak: pr.response_codes().cannot_execute,
            spm: false,
            pnu: req.pnu,
            ind: req.ind,
            pwe: e.0,
        };
        let encode = |r: Reply| pr.encode_reply(&r).unwrap_or_else(|_| error(codes.other));
        // DECISION: a command code the table does not list is answered with error 18.
        let Some(info) = pr.command_info(req.ak) else {
            return error(codes.other);
        };
        // PSD-PKW-006: command 0 is answered with response 0.
        if info.op == PkwOp::None {
            return encode(Reply::None);
        }
        let pnu = req.pnu;
        // PSD-PKW-023: an unknown parameter number.
        let Some(e) = self.fam.entry(u32::from(pnu)).cloned() else {
            return error(codes.unknown_parameter);
        };
        let elements = pr.elements(pnu);
        match info.op {
            PkwOp::None => encode(Reply::None),
            // PSD-PKW-018.
            PkwOp::Count => match elements {
                Some(n) => encode(Reply::Count {
                    pnu,
                    count: u32::from(n),
                }),
                None => error(codes.no_array),
            },
            PkwOp::Read if info.array => {
                // PSD-PKW-015, PSD-PKW-027, PSD-PKW-026, PSD-PKW-035.
                let Some(n) = elements else {
                    return error(codes.no_array);
                };
                let index = pr.subindex(req.ind);
                if index >= n {
                    return error(codes.bad_subindex);
                }
                let Some(width) = pr.element_width(pnu) else {
                    return error(codes.other);
                };
                let value = if e.role == Role::ModelString {
                    self.segment(pnu, index)
                } else {
                    self.value(&e).unwrap_or(0)
                };
                encode(Reply::Value {
                    pnu,
                    index: Some(index),
                    width,
                    value,
                })
            }
            PkwOp::Read => {
                // PSD-PKW-012; DECISION: a scalar read of an array parameter is error 5.
                let (Some(width), Some(value)) = (pr.width(pnu), self.value(&e)) else {
                    return error(codes.wrong_type);
                };
                encode(Reply::Value {
                    pnu,
                    index: None,
                    width,
                    value,
                })
            }
            PkwOp::Write => {
                // PSD-PKW-024.
                if !e.access.writable() {
                    return error(codes.read_only);
                }
                // PSD-PKW-027.
                if info.array && elements.is_none() {
                    return error(codes.no_array);
                }
                // PSD-PKW-028: a word command for a double word or the other way round.
                let width = match info.value {
                    Some(drivespec_spec::psd4xx::PkwValue::Word)
                    | Some(drivespec_spec::psd4xx::PkwValue::ArrayWord) => Width::Word,
                    _ => Width::Dword,
                };
                if pr.width(pnu) != Some(width) {
                    return error(codes.wrong_type);
                }
                let value = pr.value_of(pnu, req.pwe, width);
                if let Err(code) = self.write_value(now, &e, value) {
                    return error(code);
                }
                // PSD-PKW-032, PSD-PKW-033, PSD-PKW-034: answered like a read, with PNU, IND
                // and PWE as in the command.
                let Some(ak) = pr.expected_response(req) else {
                    return error(codes.other);
                };
                PkwResponse {
                    ak,
                    spm: false,
                    pnu,
                    ind: req.ind,
                    pwe: req.pwe,
                }
            }
        }
    }

    /// Segment `index` of the model string (PSD-PKW-035..037): 4 bytes, first character most
    /// significant, zero-filled.
    fn segment(&self, pnu: u16, index: u16) -> i64 {
        let Some(s) = self.rules.pkw().string_access(pnu) else {
            return 0;
        };
        let n = s.segment_bytes;
        let start = usize::from(index).saturating_mul(n);
        let mut v: u32 = 0;
        for i in 0..n.min(4) {
            let b = self
                .identity
                .model_string
                .get(start + i)
                .copied()
                .unwrap_or(0);
            let shift = if s.first_char_most_significant {
                8 * (n.min(4) - 1 - i)
            } else {
                8 * i
            };
            v |= u32::from(b) << shift;
        }
        i64::from(v)
    }

    // ------------------------------------------------------------------ records

    /// An acyclic request at `now` (manual 3.2.2); the answer is queued for
    /// [`Drive::poll_record`]. A switched-off drive does not answer.
    pub fn handle_record(&mut self, now: Micros, req: RecordRequest) {
        self.advance(now);
        let now = self.clock;
        if !self.core.powered() {
            return;
        }
        let (index, result) = match req {
            RecordRequest::Read { index } => (index, self.record_read(index)),
            RecordRequest::Write { index, data } => (index, self.record_write(now, index, &data)),
        };
        push_bounded(
            &mut self.records,
            RecordResponse {
                at: now,
                index,
                result,
            },
        );
        self.take_reset(now);
        self.drain_core();
    }

    fn record_read(&self, index: u16) -> Result<RecordAnswer, RecordFailure> {
        let codes = self.rules.pkw().error_codes();
        let refused = |error| RecordFailure::Refused { error };
        // PSD-REC-001, PSD-REC-002.
        let e = self
            .fam
            .entry(u32::from(index))
            .ok_or(refused(codes.unknown_parameter))?;
        let value = if e.role == Role::ModelString {
            // PSD-REC-010: the whole string.
            RecordValue::Text(self.identity.model_string.clone())
        } else {
            // PSD-REC-008, PSD-REC-009.
            let width = Width::of_type(e.data_type).ok_or(refused(codes.wrong_type))?;
            let value = self.value(e).ok_or(refused(codes.wrong_type))?;
            RecordValue::Number { width, value }
        };
        let bytes = RecordRead { index, value }
            .to_bytes(self.rules.record())
            .map_err(|_| refused(codes.other))?;
        Ok(RecordAnswer::Data { bytes })
    }

    fn record_write(
        &mut self,
        now: Micros,
        index: u16,
        data: &[u8],
    ) -> Result<RecordAnswer, RecordFailure> {
        let codes = *self.rules.pkw().error_codes();
        let refused = |error| RecordFailure::Refused { error };
        let e = self
            .fam
            .entry(u32::from(index))
            .cloned()
            .ok_or(refused(codes.unknown_parameter))?;
        if !e.access.writable() {
            return Err(refused(codes.read_only));
        }
        // PSD-REC-003, PSD-REC-006, PSD-REC-007: control byte and value.
        let w = RecordWrite::parse(self.rules.record(), index, data)
            .map_err(|error| RecordFailure::Malformed { error })?;
        // PSD-REC-004, PSD-REC-005: control byte 0 ignores the write.
        if !w.executes(self.rules.record()) {
            return Ok(RecordAnswer::Ignored);
        }
        self.write_value(now, &e, w.value).map_err(refused)?;
        Ok(RecordAnswer::Written)
    }
}
