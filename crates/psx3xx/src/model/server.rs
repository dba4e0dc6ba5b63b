//! The ISDU server of the PSx3xx drive model (manual 3.1; IEC 61131-9 annex C): reads and
//! writes of the object directory with the model's own checks, guard entries, the ISDU 2 and
//! ISDU 193 commands, and the EEPROM image kept apart from the working values.

use super::drive::Drive;
use super::family::{Entry, Role, TextKind};
use super::io::{Event, IsduAnswer};
use crate::isdu::{Accepted, ErrorCase, Rejection, Request, Response, Target, Value};
use crate::WriteFate;
use drivespec_positioner::machine::{Setting, Settings};
use drivespec_positioner::Micros;
use drivespec_spec::psx3xx::{FormatEffect, StateCommand};
use drivespec_spec::{DataType, DeviceModel};
use std::sync::Arc;

fn clamp_to(t: DataType, v: i64) -> i64 {
    match t.bounds() {
        Some((lo, hi)) => v.clamp(lo, hi),
        None => v,
    }
}

impl<'s> Drive<'s> {
    fn device_model(&self) -> Option<&'s DeviceModel> {
        self.rules.family().model(&self.fam.model_id)
    }

    fn loop_sign(&self) -> i64 {
        let id = self
            .fam
            .entries
            .iter()
            .find(|e| e.role == Role::LoopDirection)
            .map(|e| e.id.as_str())
            .unwrap_or_default();
        if self.val(id) == 0 {
            1
        } else {
            -1
        }
    }

    /// A core setting as ISDU shows it and back (the mapping is its own inverse): under
    /// PSX-ERRATUM-056 reading "physical-minus-written" ISDU 127 holds physical − written,
    /// the negative of the core's referencing value (written − physical) (PSX-POS-009).
    fn isdu_view(&self, s: Setting, v: i64) -> i64 {
        if s == Setting::Reference && self.fam.options.reference_negated {
            v.saturating_neg()
        } else {
            v
        }
    }

    // ------------------------------------------------------------------ requests

    /// An ISDU request received at `now` (manual 3.1); the answer is queued for
    /// [`Drive::poll_isdu`]. Nothing is answered while the communication is down or the drive
    /// is off.
    pub fn handle_isdu(&mut self, now: Micros, req: Request) {
        let _ = self.isdu(now, req);
    }

    fn isdu(&mut self, now: Micros, req: Request) -> Option<IsduAnswer> {
        self.advance(now);
        let now = self.clock;
        if !self.core.powered() || !self.link_up {
            return None;
        }
        self.received(now);
        let (index, subindex) = req.address();
        let (response, suppressed) = match &req {
            Request::Read { .. } => (self.isdu_read(index, subindex), false),
            Request::Write { data, .. } => self.isdu_write(now, index, subindex, data),
        };
        let answer = IsduAnswer {
            at: now,
            index,
            subindex,
            response,
            suppressed,
        };
        super::drive::push_bounded(&mut self.answers, answer.clone());
        self.after_core(now);
        Some(answer)
    }

    /// Reads an entry as an ISDU read would now (manual 3.1): the value, or the refusal.
    pub fn read(&self, index: u16, subindex: u8) -> Result<Value, Rejection> {
        let accepted = self.rules.check_read(index, subindex)?;
        Ok(match &accepted.target {
            Target::Entry { param } => self.entry_value(&param.id),
            Target::Record { entries, .. } => {
                Value::Record(entries.iter().map(|p| self.entry_value(&p.id)).collect())
            }
        })
    }

    /// The value of an entry by parameter id as a read gives it (manual 3.1); `Int(0)` for
    /// an id the spec does not have.
    pub fn value(&self, id: &str) -> Value {
        self.entry_value(id)
    }

    fn isdu_read(&self, index: u16, subindex: u8) -> Response {
        let target = match self.rules.isdu_target(index, subindex) {
            Ok(t) => t,
            Err(r) => return r.response(),
        };
        match self.read(index, subindex) {
            Ok(value) => match self.rules.encode_value(&target, &value) {
                Ok(data) => Response::Read { data },
                Err(e) => self
                    .rules
                    .reject(ErrorCase::ValueOutOfRange, e.to_string())
                    .response(),
            },
            Err(r) => r.response(),
        }
    }

    /// Writes an entry at `now` as an ISDU write would, the octets encoded from `value`
    /// (manual 3.1); the answer is also queued. None while the drive does not answer.
    pub fn write(
        &mut self,
        now: Micros,
        index: u16,
        subindex: u8,
        value: &Value,
    ) -> Option<Response> {
        let encoded = self
            .rules
            .isdu_target(index, subindex)
            .map_err(|r| r.response())
            .and_then(|t| {
                self.rules.encode_value(&t, value).map_err(|e| {
                    self.rules
                        .reject(ErrorCase::ValueOutOfRange, e.to_string())
                        .response()
                })
            });
        let data = match encoded {
            Ok(d) => d,
            Err(r) => return Some(r),
        };
        self.isdu(
            now,
            Request::Write {
                index,
                subindex,
                data,
            },
        )
        .map(|a| a.response)
    }

    fn isdu_write(
        &mut self,
        now: Micros,
        index: u16,
        subindex: u8,
        data: &[u8],
    ) -> (Response, bool) {
        match self.check_and_write(now, index, subindex, data) {
            Ok(fate) => (Response::Write, fate),
            Err(r) => (r.response(), false),
        }
    }

    fn check_and_write(
        &mut self,
        now: Micros,
        index: u16,
        subindex: u8,
        data: &[u8],
    ) -> Result<bool, Rejection> {
        let model = self.device_model();
        let accepted = match self.rules.check_write(index, subindex, data, model) {
            Ok(a) => a,
            Err(r) if r.case == ErrorCase::ValueOutOfRange => {
                // Ranges that depend on the state are checked below (131, 132, 153, 128–130).
                let state_range = self
                    .fam
                    .entry(index, subindex)
                    .is_some_and(|e| e.range.is_none() && e.data_type.width().is_some());
                if !state_range {
                    return Err(r);
                }
                let target = self.rules.isdu_target(index, subindex)?;
                let value = self
                    .rules
                    .decode_value(&target, data)
                    .map_err(|_| r.clone())?;
                Accepted {
                    target,
                    value: Some(value),
                    command: None,
                }
            }
            Err(r) => return Err(r),
        };
        let Target::Entry { param } = accepted.target else {
            return Err(self.rules.reject(
                ErrorCase::WriteReadOnly,
                format!("index {index}: a record write is not offered"),
            ));
        };
        let entry = self.fam.by_id(&param.id).cloned().ok_or_else(|| {
            self.rules.reject(
                ErrorCase::IndexNotAvailable,
                format!("no entry {}", param.id),
            )
        })?;
        let value = accepted.value.unwrap_or(Value::Int(0));
        // PSX-DP-ERR-008: the parameter write lock; ISDU 12 itself and the standard commands
        // stay writable (DECISION: IO-Link locks parameters, not system commands).
        let lock = self.val(&self.fam.ids.locks);
        if lock & 1 == 1 && entry.id != self.fam.ids.locks && entry.role != Role::Command {
            return Err(self.rules.reject(
                ErrorCase::WriteLocked,
                format!("ISDU {} while ISDU 12 locks parameter writes", entry.id),
            ));
        }
        // PSX-PD-005: format 2 only from software 249.
        if entry.role == Role::Format
            && value == Value::Int(i64::from(self.rules.protocol().target_speed.format))
            && self.identity.software < self.fam.format2_software
        {
            return Err(self.rules.reject(
                ErrorCase::FormatNotSupported,
                format!("format 2 needs software {}", self.fam.format2_software),
            ));
        }
        // PSX-VER-CLEAR: bit 14 of the control word is reserved before software 249.
        if entry.role == Role::Control
            && self.identity.software < self.fam.format2_software
            && matches!(value, Value::Int(v) if v & i64::from(self.fam.controls.clear_errors) != 0)
        {
            return Err(self.rules.reject(
                ErrorCase::ReservedBitsSet,
                "control bit 14 before software 249",
            ));
        }
        let number = match value {
            Value::Int(v) => Some(v),
            _ => None,
        };
        // PSX-GUARD-66-SUPPRESS, PSX-GUARD-109-SUPPRESS, PSX-GUARD-111-SUPPRESS,
        // PSX-GUARD-126-SUPPRESS, PSX-GUARD-ONESHOT (PSX-ERRATUM-004).
        if let WriteFate::Suppressed { guard } = self.guards.on_write(&entry.id, number) {
            self.event(now, Event::Suppressed { index, guard });
            return Ok(true);
        }
        self.apply_write(now, &entry, &value, accepted.command)?;
        // Position settings move the encoder window with them (PSX-POS-005 … PSX-POS-009).
        self.in_encoder = self.encoder_inside();
        self.event(
            now,
            Event::Written {
                index,
                subindex,
                value,
            },
        );
        self.refresh_hot();
        self.update_speeds();
        self.after_core(now);
        Ok(false)
    }

    /// Writes a core setting; a refusal of the position arithmetic becomes `case`.
    fn core_set(
        &mut self,
        now: Micros,
        s: Setting,
        v: i64,
        case: ErrorCase,
        id: &str,
    ) -> Result<(), Rejection> {
        self.core
            .set(now, s, v)
            .map_err(|e| self.rules.reject(case, format!("ISDU {id}: {e}")))
    }

    /// Carries out a checked write (manual 3.1, 5.5, 5.6).
    fn apply_write(
        &mut self,
        now: Micros,
        e: &Entry,
        value: &Value,
        command: Option<&'s StateCommand>,
    ) -> Result<(), Rejection> {
        if let (Role::Text(_), Value::Text(t)) = (e.role, value) {
            self.texts.insert(e.id.clone(), t.clone());
            return Ok(());
        }
        let Value::Int(v) = *value else {
            return Err(self.rules.reject(
                ErrorCase::ValueOutOfRange,
                format!("ISDU {} takes a number", e.id),
            ));
        };
        let id = e.id.as_str();
        match e.role {
            Role::Core(Setting::MappingEnd) => {
                // PSX-MAP-004: 1 + ref <= end <= 204800 x den/num - 1 + ref, with ref the
                // core's written − physical shift under either reading of PSX-ERRATUM-056
                // (the bounds keep their physical place).
                let ref_ = self.core.get(Setting::Reference);
                let span = self.core.axis().scale(self.fam.mapping_span);
                let (lo, hi) = (
                    ref_.saturating_add(1),
                    span.saturating_sub(1).saturating_add(ref_),
                );
                if !(lo..=hi).contains(&v) {
                    return Err(self.rules.reject(
                        ErrorCase::ValueInconsistent,
                        format!("ISDU {id} = {v} outside {lo}..={hi}"),
                    ));
                }
                // PSX-MAP-002, PSX-MAP-003, PSX-POS-006.
                self.core_set(
                    now,
                    Setting::MappingEnd,
                    v,
                    ErrorCase::ValueInconsistent,
                    id,
                )?;
            }
            Role::Core(s @ (Setting::UpperLimit | Setting::LowerLimit)) => {
                // PSX-MAP-005.
                self.core_set(now, s, v, ErrorCase::ValueInconsistent, id)?;
            }
            Role::Core(Setting::OperatingTorque) => {
                // PSX-TRQ-003 (PSX-ERRATUM-015, PSX-ERRATUM-063).
                let max = self.torque_bound();
                if !(self.fam.torque.min_cnm..=max).contains(&v) {
                    return Err(self.rules.reject(
                        ErrorCase::ValueOutOfRange,
                        format!(
                            "ISDU {id} = {v} outside {}..={max}",
                            self.fam.torque.min_cnm
                        ),
                    ));
                }
                let _ = self.core.set(now, Setting::OperatingTorque, v);
            }
            Role::Core(s) => {
                // PSX-POS-005, PSX-POS-007, PSX-POS-008, PSX-POS-009, PSX-ISDU-131-SCALE.
                let v = self.isdu_view(s, v);
                self.core_set(now, s, v, ErrorCase::ValueOutOfRange, id)?;
                self.snapshot();
            }
            Role::Filter => {
                // PSX-ISDU-166-FILTER: averaged over ISDU 166 x 5 ms.
                self.values.insert(e.id.clone(), v);
                let ms = self.five_ms(v);
                let _ = self.core.set(now, Setting::UmotFilter, ms);
            }
            Role::LoopLength => {
                // PSX-ISDU-132-ZERO; the loop range scales with the resolution.
                let signed = v.saturating_mul(self.loop_sign());
                self.core_set(
                    now,
                    Setting::LoopLength,
                    signed,
                    ErrorCase::ValueOutOfRange,
                    id,
                )?;
            }
            Role::LoopDirection => {
                // PSX-ISDU-134-MEANING.
                self.values.insert(e.id.clone(), v);
                let l = self.core.get(Setting::LoopLength).abs() * self.loop_sign();
                let _ = self.core.set(now, Setting::LoopLength, l);
            }
            Role::Control => {
                let old = self.control;
                self.control = u16::try_from(v).unwrap_or(0);
                self.control_changed(now, old);
            }
            Role::Target => {
                self.target = v;
                self.transfer_pulse = true;
                let old = self.control;
                self.control_changed(now, old);
            }
            Role::Command => {
                if let Some(c) = command {
                    self.run_command(now, c);
                }
            }
            Role::Stored | Role::Format | Role::Direct(_) => {
                self.values.insert(e.id.clone(), v);
            }
            _ => {
                return Err(self
                    .rules
                    .reject(ErrorCase::WriteReadOnly, format!("ISDU {id} is read-only")))
            }
        }
        Ok(())
    }

    /// The largest ISDU 153 now (PSX-TRQ-003; PSX-ERRATUM-015, PSX-ERRATUM-063).
    fn torque_bound(&self) -> i64 {
        let t = self.fam.torque;
        if !self.fam.options.torque_speed_dependent {
            return t.rated_cnm;
        }
        let ids = &self.fam.ids;
        let set = self
            .val(&ids.speed_positioning)
            .max(self.val(&ids.speed_manual))
            .max(1);
        let num = t.rated_cnm.saturating_mul(t.max_speed_rpm);
        let formula = if self.fam.options.torque_round {
            (num + set / 2) / set
        } else {
            num / set
        };
        formula.min(t.start_max_cnm).max(t.rated_cnm)
    }

    // ------------------------------------------------------------------ values

    fn entry_value(&self, id: &str) -> Value {
        let Some(e) = self.fam.by_id(id) else {
            return Value::Int(0);
        };
        if let Role::Text(kind) = e.role {
            return Value::Text(self.text(e, kind));
        }
        Value::Int(clamp_to(e.data_type, self.number(e)))
    }

    fn text(&self, e: &Entry, kind: TextKind) -> String {
        match kind {
            TextKind::Fixed => self
                .texts
                .get(&e.id)
                .cloned()
                .or_else(|| e.default_text.clone())
                .unwrap_or_default(),
            // PSX-ISDU-18-TEXT (DECISION: the model id with "-IO", as "PSE312-8-IO").
            TextKind::ProductName => format!("{}-IO", self.fam.model_id),
            // PSX-ISDU-19-TEXT (PSX-ERRATUM-022).
            TextKind::ProductId => {
                if self.fam.options.product_id_series {
                    self.fam.series()
                } else {
                    "PSE".to_owned()
                }
            }
            // PSX-ISDU-21-TEXT.
            TextKind::SerialText => format!("{:05}", self.identity.serial_number),
            TextKind::Hardware => self.identity.hardware.clone(),
            TextKind::Firmware => self.identity.firmware.clone(),
        }
    }

    /// The raw number of a numeric entry now (manual 3.1).
    fn number(&self, e: &Entry) -> i64 {
        let env = self.core.environment();
        match e.role {
            Role::Core(s) => self.isdu_view(s, self.core.get(s)),
            Role::LoopLength => self.core.get(Setting::LoopLength).abs(),
            Role::Filter | Role::LoopDirection | Role::Stored | Role::Format => self.val(&e.id),
            Role::Status => i64::from(self.status_word()),
            // PSX-ISDU-65-UNIT (PSX-ERRATUM-011).
            Role::Rpm => self.reported_rpm(self.core.speed_rpm()),
            Role::Torque => self.torque_now(),
            Role::MaxTorque => self.max_torque,
            // PSX-ISDU-70-UNIT, PSX-ISDU-72-UNIT.
            Role::ControlVoltage => i64::from(env.control_dv),
            Role::MotorVoltage => self.core.motor_voltage(),
            Role::Temperature => self.reported_celsius(i64::from(env.celsius)),
            Role::ProductionDate => self.identity.production_date,
            Role::SerialNumber => self.identity.serial_number,
            // PSX-ISDU-79-CODES.
            Role::ModelCode => self.fam.model_code,
            Role::Software => self.identity.software,
            Role::Control => i64::from(self.control),
            Role::Target => self.target,
            // PSX-CMD-016, PSX-CMD-017 (DECISION: a save takes no virtual time; the EEPROM is
            // always correct).
            Role::Command => 0,
            Role::Direct(address) => self.direct_byte(e, address),
            Role::Text(_) => 0,
        }
    }

    /// ISDU 65 as the drive reports it (PSX-ISDU-65-UNIT): signed under the adopted reading
    /// of PSX-ERRATUM-011; under "unsigned" by its magnitude (DECISION: an unsigned speed
    /// carries no direction).
    pub(super) fn reported_rpm(&self, rpm: i64) -> i64 {
        if self.fam.options.measurements_unsigned {
            rpm.saturating_abs()
        } else {
            rpm
        }
    }

    /// ISDU 72 as the drive reports it (PSX-ISDU-72-UNIT): signed under the adopted reading
    /// of PSX-ERRATUM-011; under "unsigned" a temperature below 0 °C reads 0 (DECISION).
    fn reported_celsius(&self, celsius: i64) -> i64 {
        if self.fam.options.measurements_unsigned {
            celsius.max(0)
        } else {
            celsius
        }
    }

    /// A byte of Direct Parameter page 1 (PSX-DP-001 … PSX-DP-009).
    fn direct_byte(&self, e: &Entry, address: u8) -> i64 {
        if e.access.writable() {
            return self.val(&e.id);
        }
        let dp = &self.rules.protocol().direct_parameters;
        let is_pd_out = dp
            .entries
            .iter()
            .any(|d| d.address == address && d.name == "ProcessDataOut");
        if is_pd_out && self.fam.options.pd_out_fixed {
            // PSX-ERRATUM-009 reading "fixed-16".
            return dp
                .entries
                .iter()
                .find(|d| d.address == address)
                .and_then(|d| d.delivery)
                .map_or(0, i64::from);
        }
        let code = u32::try_from(self.fam.model_code).unwrap_or(0);
        self.rules
            .direct_page(self.active_format, code)
            .ok()
            .and_then(|page| page.get(usize::from(address)).copied())
            .map_or(0, i64::from)
    }

    // ------------------------------------------------------------------ EEPROM and commands

    /// The EEPROM image of a new device: every saved entry at its delivery value
    /// (PSX-PAR-DEFAULTS).
    pub(super) fn factory_image(&mut self) {
        let fam = Arc::clone(&self.fam);
        self.saved.clear();
        for e in fam.entries.iter().filter(|e| e.saved) {
            if let Some(d) = e.default {
                self.saved.insert(e.id.clone(), d);
            }
        }
    }

    /// Loads the EEPROM image into the working values, as every start does; entries that are
    /// not saved take their delivery values (PSX-PAR-SAVED, PSX-PAR-NOT-SAVED, PSX-PD-010,
    /// PSX-ISDU-112-DEFAULT).
    pub(super) fn boot_values(&mut self) {
        let fam = Arc::clone(&self.fam);
        self.values.clear();
        self.texts.clear();
        let mut settings: Settings = fam.factory;
        for e in &fam.entries {
            let v = if e.saved {
                self.saved.get(&e.id).copied().or(e.default)
            } else {
                e.default
            };
            let Some(v) = v else { continue };
            match e.role {
                Role::Core(s) => settings.put(s, self.isdu_view(s, v)),
                Role::LoopLength => settings.put(Setting::LoopLength, v),
                Role::Filter | Role::LoopDirection | Role::Stored | Role::Format => {
                    self.values.insert(e.id.clone(), v);
                }
                _ => {}
            }
        }
        self.refresh_hot();
        let sign = self.loop_sign();
        settings.axis.loop_length = settings.axis.loop_length.abs() * sign;
        let filter = fam
            .entries
            .iter()
            .find(|e| e.role == Role::Filter)
            .map_or(0, |e| self.val(&e.id));
        settings.put(Setting::UmotFilter, self.five_ms(filter));
        settings.put(Setting::Readjust, 0);
        let now = self.clock;
        self.core.load(now, &settings);
        let format_id = fam.ids.format.clone();
        self.active_format = u8::try_from(self.val(&format_id))
            .ok()
            .filter(|f| self.rules.output(*f).is_some())
            .unwrap_or_else(|| self.rules.default_format());
    }

    /// PSX-PAR-SAVED, PSX-CMD-018: the saved entries go to the EEPROM image.
    pub(super) fn save(&mut self, now: Micros) {
        let fam = Arc::clone(&self.fam);
        for e in fam.entries.iter().filter(|e| e.saved) {
            if let Value::Int(v) = self.entry_value(&e.id) {
                self.saved.insert(e.id.clone(), v);
            }
        }
        self.event(now, Event::Saved);
    }

    /// Every writable entry to its delivery value, keeping the process-data format when
    /// asked (PSX-PAR-DEFAULTS, PSX-CMD-015). DECISION: control word and target keep their
    /// values (they are commands, and a change would move the drive).
    fn restore_delivery(&mut self, now: Micros, keep_format: bool) {
        let fam = Arc::clone(&self.fam);
        let format = self.val(&fam.ids.format);
        for e in &fam.entries {
            if matches!(
                e.role,
                Role::Filter | Role::LoopDirection | Role::Stored | Role::Format
            ) {
                if let Some(d) = e.default {
                    self.values.insert(e.id.clone(), d);
                }
            }
        }
        if keep_format {
            self.values.insert(fam.ids.format.clone(), format);
        }
        self.refresh_hot();
        self.texts.clear();
        let mut settings = fam.factory;
        settings.axis.loop_length = settings.axis.loop_length.abs() * self.loop_sign();
        settings.put(Setting::Readjust, self.core.get(Setting::Readjust));
        self.core.load(now, &settings);
        self.update_speeds();
        self.event(now, Event::Restored { delivery: true });
    }

    /// An ISDU 2 or ISDU 193 command (PSX-CMD-011 … PSX-CMD-015).
    fn run_command(&mut self, now: Micros, c: &StateCommand) {
        // PSX-ERRATUM-059 reading "like-193-minus-2" for ISDU 2 = 130.
        let extra = c.name == "restore-factory" && self.fam.options.cmd130_centre;
        if c.defaults {
            self.restore_delivery(now, c.format != FormatEffect::Default);
        }
        if c.save {
            self.save(now);
        }
        if c.reset {
            // Done after the answer is queued (handle_isdu).
            self.pending_reset = true;
        }
        let centre = c.centre_run || extra;
        if c.reference_loop || extra {
            self.start_reference_loop(now, centre);
        } else if centre {
            self.core.start_centre_run(now);
        }
    }
}
