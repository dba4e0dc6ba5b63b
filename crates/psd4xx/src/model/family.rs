//! The PSD4xx family description for the positioning core, built from the spec (manual 3.3,
//! 3.4, 3.6, 3.7, chapter 4): the role of every parameter, the control-word bits, the core's
//! numbers for one device model, and the erratum readings chosen.
//!
//! Parameters are found by the ids the spec's `protocol.positioning` tables name (`"53"` is the
//! positioning speed because `velocity.positioning_param = "53"`), the process-data fields'
//! `param`, and for the few status queries no table names, by the manual's designation.

use super::config::DriveConfig;
use super::error::ModelError;
use drivespec_positioner::axis::{
    AxisConfig, Delivery, LimitRatio, LimitsAfterMappingEnd, Rounding,
};
use drivespec_positioner::config::{Backoff, LoopRules, Ramp, VoltageRules};
use drivespec_positioner::machine::{DriveSettings, Setting, Settings};
use drivespec_positioner::{AxisValues, BitMap, CoreConfig, Flag};
use drivespec_spec::psd4xx::{Direction, Protocol, SideEffectKind, StopRamp};
use drivespec_spec::{Access, DataType, DeviceModel, Family, FamilyId, Ranges, Spec};
use std::sync::Arc;

/// What a parameter is to the model (manual 3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    /// A setting of the positioning core (3.3).
    Setting(Setting),
    /// Status word (par. 1).
    Status,
    /// Actual speed (par. 2).
    Speed,
    /// Control word (par. 32), written by process data only.
    Control,
    /// Target value (par. 33), written by process data only.
    Target,
    /// The delivery-state command (par. 96).
    Command,
    /// Motor supply voltage (par. 7).
    MotorVoltage,
    /// Control supply voltage (par. 6).
    ControlVoltage,
    /// Device temperature (par. 8).
    Temperature,
    /// Actual current (par. 4).
    Current,
    /// Maximum current of the last run (par. 5).
    MaxCurrent,
    /// Address switch (par. 9).
    AddressSwitch,
    /// Production date (par. 10).
    ProductionDate,
    /// Serial number (par. 11).
    SerialNumber,
    /// Model number (par. 12).
    ModelNumber,
    /// Model string (par. 13).
    ModelString,
    /// Software version (par. 14).
    Version,
    /// A stored value with no effect on the motion (par. 80–89, 92).
    Plain,
}

/// One parameter of table 3.3 as the model uses it.
#[derive(Debug, Clone)]
pub(crate) struct Entry {
    pub number: u32,
    pub data_type: DataType,
    pub access: Access,
    pub saved: bool,
    pub standstill: bool,
    /// Static range from tables 3.3/3.4; None where the core checks a state-dependent range.
    pub range: Option<Ranges>,
    pub default: Option<i64>,
    pub role: Role,
}

/// Masks of the control word bits (manual 3.7).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Controls {
    pub manual_up: u16,
    pub manual_down: u16,
    pub transfer: u16,
    pub release: u16,
    pub no_loop: u16,
    pub toggle: u16,
    pub must_be_zero: u16,
}

/// The par. 96 values by their spec names (manual 3.3 par. 96).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Commands {
    pub reset: i64,
    pub delivery_centre: i64,
    pub user_centre: i64,
    pub delivery_clear_name: i64,
    pub user: i64,
    pub delivery: i64,
    pub save: i64,
}

/// Everything the model reads from the spec for one device model.
#[derive(Debug, Clone)]
pub(crate) struct PsdFamily {
    pub core: Arc<CoreConfig>,
    pub entries: Vec<Entry>,
    pub controls: Controls,
    pub commands: Commands,
    pub address_param: u32,
    pub factory: Settings,
    pub model_id: String,
    /// A lost connection sets status bit 5 like a withdrawn release (erratum PSD-ERRATUM-063).
    pub loss_sets_aborted: bool,
}

fn spec_err(what: impl Into<String>) -> ModelError {
    ModelError::Spec { what: what.into() }
}

fn number(family: &Family, id: &str) -> Result<u32, ModelError> {
    family
        .parameter(id)
        .map(|p| p.number)
        .ok_or_else(|| spec_err(format!("no parameter {id}")))
}

fn by_name(family: &Family, name: &str) -> Result<u32, ModelError> {
    family
        .parameters
        .iter()
        .find(|p| p.name == name)
        .map(|p| p.number)
        .ok_or_else(|| spec_err(format!("no parameter named {name:?}")))
}

impl PsdFamily {
    /// Reads the family for the model of `config` (manual 3.3, 3.4, chapter 4).
    pub fn build(spec: &Spec, config: &DriveConfig) -> Result<PsdFamily, ModelError> {
        let family = spec.family(FamilyId::Psd4xx);
        let p = family
            .psd4xx()
            .ok_or_else(|| spec_err("no PSD4xx protocol"))?;
        let model = family
            .model(&config.model)
            .ok_or_else(|| ModelError::UnknownModel {
                model: config.model.clone(),
                known: family.model_ids(),
            })?;
        let reading = |option: &str, adopted: &'static str| {
            config
                .readings
                .reading_or(family, option, adopted)
                .to_owned()
        };
        let roles = roles(family, p)?;
        let pos = &p.positioning;
        let numerator_id = pos.scaling.numerator_param.as_str();
        let par38_standstill = reading("par38-standstill", "both") == "both";

        let mut entries = Vec::with_capacity(family.parameters.len());
        for param in &family.parameters {
            let role = roles
                .iter()
                .find(|(n, _)| *n == param.number)
                .map_or(Role::Plain, |(_, r)| *r);
            let resolved = family.resolve(param, Some(model));
            let mut range = resolved.range;
            let mut default = resolved.default;
            override_model_values(config, family, model, &param.id, &mut range, &mut default);
            let mut standstill = param.has_condition("standstill");
            if param.id == numerator_id && !par38_standstill {
                // Erratum PSD-ERRATUM-016 reading "par-39-only".
                standstill = false;
            }
            // PSD-PAR-44-003, PSD-PAR-45-003: these ranges scale with the resolution; the
            // core checks them (erratum PSD-ERRATUM-024).
            if matches!(
                role,
                Role::Setting(Setting::Window) | Role::Setting(Setting::LoopLength)
            ) {
                range = None;
            }
            entries.push(Entry {
                number: param.number,
                data_type: param.data_type,
                access: param.access,
                saved: param.saved == Some(true),
                standstill,
                range,
                default,
                role,
            });
        }

        let mut factory = Settings {
            axis: AxisValues {
                direction: 0,
                numerator: 1,
                denominator: 1,
                reference: 0,
                mapping_end: 0,
                upper_limit: 0,
                lower_limit: 0,
                window: 1,
                loop_length: 0,
            },
            drive: DriveSettings::default(),
        };
        for e in &entries {
            if let (Role::Setting(s), Some(d)) = (e.role, e.default) {
                factory.put(s, d);
            }
        }
        let default_of = |s: Setting| -> Result<i64, ModelError> {
            factory
                .get(s)
                .ok_or_else(|| spec_err(format!("no delivery value for {s:?}")))
        };
        let has_default = |s: Setting| {
            entries
                .iter()
                .any(|e| e.role == Role::Setting(s) && e.default.is_some())
        };
        for s in [
            Setting::MappingEnd,
            Setting::UpperLimit,
            Setting::LowerLimit,
            Setting::Numerator,
            Setting::Denominator,
        ] {
            if !has_default(s) {
                return Err(spec_err(format!("no delivery value for {s:?}")));
            }
        }

        let mapping = &pos.mapping;
        let lower_offset = if mapping.lower_offset_from_model_defaults {
            // PSD-MAP-029: geared models: the model's mapping end minus its lower limit.
            default_of(Setting::MappingEnd)? - default_of(Setting::LowerLimit)?
        } else {
            mapping.lower_offset
        };
        let range_of = |s: Setting| -> Option<Vec<[i64; 2]>> {
            let param = family.parameters.iter().find(|q| {
                roles
                    .iter()
                    .any(|(n, r)| *n == q.number && *r == Role::Setting(s))
            })?;
            family
                .resolve(param, Some(model))
                .range
                .map(|r| r.intervals().to_vec())
        };
        let window_range = range_of(Setting::Window)
            .and_then(|r| Some([r.first()?[0], r.last()?[1]]))
            .ok_or_else(|| spec_err("no range for the positioning window"))?;
        let loop_range =
            range_of(Setting::LoopLength).ok_or_else(|| spec_err("no range for the loop"))?;
        let limits_follow = reading(
            "psd-limits-after-mapping-end",
            if mapping.limits_follow_mapping_end {
                "full-new-range"
            } else {
                "absolute-delivery-values"
            },
        ) == "full-new-range";
        let axis = AxisConfig {
            base_increments: pos.scaling.base_increments_per_rotation,
            upper_margin: mapping.upper_margin,
            lower_offset,
            factor_range: [pos.scaling.factor_min, pos.scaling.factor_max],
            // The spec's `Scaling::scale` rounds toward zero.
            rounding: Rounding::TowardZero,
            delivery: Delivery {
                mapping_end: default_of(Setting::MappingEnd)?,
                upper_limit: default_of(Setting::UpperLimit)?,
                lower_limit: default_of(Setting::LowerLimit)?,
                reference: default_of(Setting::Reference)?,
                window: default_of(Setting::Window)?,
                loop_length: default_of(Setting::LoopLength)?,
                numerator: default_of(Setting::Numerator)?,
                denominator: default_of(Setting::Denominator)?,
                direction: default_of(Setting::Direction)?,
            },
            window_range,
            scale_window_range: true,
            loop_range,
            scale_loop_range: true,
            // Erratum PSD-ERRATUM-007, adopted "den-over-num" (no option).
            upper_limit_ratio: LimitRatio::DenOverNum,
            limits_after_mapping_end: if limits_follow {
                LimitsAfterMappingEnd::FullNewRange
            } else {
                LimitsAfterMappingEnd::Delivery
            },
        };

        let status = family
            .bitfield("status")
            .ok_or_else(|| spec_err("no status bitfield"))?;
        let bits = BitMap::from_bitfield(
            status,
            &[
                (Flag::Reached, "PSD-STS-0-SET-1"),
                (Flag::Toggle, "PSD-STS-2-SET-1"),
                (Flag::MotorOk, "PSD-STS-4-SET-1"),
                (Flag::Aborted, "PSD-STS-5-SET-1"),
                (Flag::Running, "PSD-STS-6-SET-1"),
                (Flag::OverTemp, "PSD-STS-7-SET-1"),
                (Flag::AgainstLoop, "PSD-STS-8-SET-1"),
                (Flag::Error, "PSD-STS-9-SET-1"),
                (Flag::Obstruction, "PSD-STS-10-SET-1"),
                (Flag::ManualRotation, "PSD-STS-11-SET-1"),
                (Flag::BadTarget, "PSD-STS-12-SET-1"),
                (Flag::VoltageMissing, "PSD-STS-13-SET-1"),
                (Flag::UpperLimit, "PSD-STS-14-SET-1"),
                (Flag::LowerLimit, "PSD-STS-15-SET-1"),
            ],
        )?;
        check_bits(&bits, p)?;

        let loop_t = &pos.reference_loop;
        let backoff = reading(
            "psd-loop-backoff",
            if loop_t.overshoot_is_loop_length {
                "loop-length"
            } else {
                "fixed-five-eighths"
            },
        );
        let direction = reading(
            "psd-loop-direction",
            if loop_t.positive_approach == Direction::Increasing {
                "positive-approaches-upward"
            } else {
                "as-printed"
            },
        );
        let stop = reading(
            "psd-stop-ramp",
            match pos.velocity.stop_ramp {
                StopRamp::Parameter => "parameter",
                StopRamp::Maximum => "maximum",
            },
        );
        let decel_max = range_of(Setting::Deceleration)
            .and_then(|r| r.iter().map(|[_, hi]| *hi).max())
            .ok_or_else(|| spec_err("no range for the deceleration"))?;
        let core = CoreConfig {
            axis: Arc::new(axis),
            bits,
            priority_exclusive: reading("psd-bit0-priority", "exclusive") == "exclusive",
            loop_rules: LoopRules {
                overshoot_is_loop_length: backoff == "loop-length",
                positive_approaches_up: direction == "positive-approaches-upward",
                backoff: if backoff == "loop-length" {
                    Backoff::LoopLength
                } else {
                    Backoff::FixedFromCurrent
                },
                fixed_rotations: loop_t.default_length_rotations,
                attempts: loop_t.attempts,
            },
            stop_ramp: if stop == "maximum" {
                Ramp::Maximum
            } else {
                Ramp::Parameter
            },
            emergency_ramp: Ramp::Maximum,
            max_deceleration: decel_max as f64,
            voltage: VoltageRules {
                upper: pos.motor_voltage.upper_limit,
                run_minimum: (reading("psd-run-voltage", "run-17v5") == "run-17v5")
                    .then_some(pos.motor_voltage.run_minimum),
            },
            temperature_hysteresis: pos.temperature.hysteresis_c,
            aborted_on_manual_stop: reading("psd-bit5-manual-run", "positioning-only") == "any-run",
            manual_rotation_always: reading("psd-bit11-readjust", "always") == "always",
            both_manual_invalid: reading("psd-ctl-0x13", "either") == "either",
            adjust_both_without_loop: pos.adjustment.both_directions_without_loop,
            tick_us: 1000,
            blend: 0.5,
            start_position: config.start_position.unwrap_or(mapping.default_position),
        };

        Ok(PsdFamily {
            controls: controls(family, p, &core.bits)?,
            commands: commands(family, &pos.save.param)?,
            address_param: number(family, &p.device_name.eeprom_param)?,
            core: Arc::new(core),
            entries,
            factory,
            model_id: model.id.clone(),
            loss_sets_aborted: reading("psd-master-failure", "release-edge") == "release-edge",
        })
    }

    /// The entry of parameter `pnu` (manual 3.3).
    pub fn entry(&self, pnu: u32) -> Option<&Entry> {
        self.entries.iter().find(|e| e.number == pnu)
    }
}

/// Model values that depend on a selectable erratum reading (PSD-ERRATUM-011, -012, -013).
fn override_model_values(
    config: &DriveConfig,
    family: &Family,
    model: &DeviceModel,
    id: &str,
    range: &mut Option<Ranges>,
    default: &mut Option<i64>,
) {
    let chosen =
        |option: &str, reading: &str| config.readings.reading(family, option) == Some(reading);
    let Some(p) = family.psd4xx() else { return };
    let t = &p.positioning;
    let resolved = |pid: &str| {
        family
            .parameter(pid)
            .map(|q| family.resolve(q, Some(model)))
    };
    // PSD-ERRATUM-012 / PSD-ERRATUM-013: the start-up torque minimum equal to the operating
    // torque minimum (DECISION: the erratum's model named by id).
    let raise_min = (model.id == "PSD481-8H14H" && chosen("psd481-par63-min", "thirty-six"))
        || (model.id == "PSD428-14H" && chosen("psd428-par63-min", "equal-minima"));
    if raise_min && id == t.torque.startup_param {
        if let (Some(r), Some(min)) = (
            range.as_ref(),
            resolved(&t.torque.operating_param)
                .and_then(|x| x.range)
                .and_then(|r| r.min()),
        ) {
            if let Some(max) = r.max() {
                *range = Some(Ranges::new(min, max));
            }
        }
    }
    // PSD-ERRATUM-011 reading "symmetric": the PSD 403/413 lower limit is −upper limit.
    if model.id == "PSD403-8H14H"
        && chosen("psd403-lower-limit", "symmetric")
        && id == t.mapping.lower_limit_param
    {
        if let Some(upper) = resolved(&t.mapping.upper_limit_param).and_then(|x| x.default) {
            *default = Some(-upper);
        }
    }
}

/// The role of every parameter the tables name (manual 3.3, 3.5, chapter 4).
fn roles(family: &Family, p: &Protocol) -> Result<Vec<(u32, Role)>, ModelError> {
    let pos = &p.positioning;
    let mut out = Vec::new();
    let mut add = |id: &str, role: Role| -> Result<(), ModelError> {
        out.push((number(family, id)?, role));
        Ok(())
    };
    let s = |x: Setting| Role::Setting(x);
    add(&pos.scaling.numerator_param, s(Setting::Numerator))?;
    add(&pos.scaling.denominator_param, s(Setting::Denominator))?;
    add(&pos.mapping.param, s(Setting::MappingEnd))?;
    add(&pos.mapping.upper_limit_param, s(Setting::UpperLimit))?;
    add(&pos.mapping.lower_limit_param, s(Setting::LowerLimit))?;
    add(&pos.mapping.reference_param, s(Setting::Reference))?;
    add(&pos.mapping.actual_param, s(Setting::Actual))?;
    add(&pos.reference_loop.length_param, s(Setting::LoopLength))?;
    add(&pos.reference_loop.window_param, s(Setting::Window))?;
    add(
        &pos.velocity.positioning_param,
        s(Setting::PositioningSpeed),
    )?;
    add(&pos.velocity.manual_param, s(Setting::ManualSpeed))?;
    add(&pos.velocity.acceleration_param, s(Setting::Acceleration))?;
    add(&pos.velocity.deceleration_param, s(Setting::Deceleration))?;
    add(&pos.torque.startup_param, s(Setting::StartupTorque))?;
    add(&pos.torque.operating_param, s(Setting::OperatingTorque))?;
    add(&pos.torque.startup_time_param, s(Setting::StartupTime))?;
    add(&pos.torque.end_holding_param, s(Setting::EndHoldTorque))?;
    add(&pos.torque.end_holding_time_param, s(Setting::EndHoldTime))?;
    add(&pos.torque.holding_param, s(Setting::HoldTorque))?;
    add(&pos.motor_voltage.limit_param, s(Setting::UmotLimit))?;
    add(&pos.motor_voltage.filter_param, s(Setting::UmotFilter))?;
    add(&pos.temperature.limit_param, s(Setting::TempLimit))?;
    add(&pos.temperature.measured_param, Role::Temperature)?;
    add(
        &pos.obstruction.speed_limit_param,
        s(Setting::BlockSpeedPercent),
    )?;
    add(&pos.obstruction.time_param, s(Setting::BlockTime))?;
    add(&pos.adjustment.enable_param, s(Setting::Readjust))?;
    add(&pos.save.param, Role::Command)?;
    // PSD-MAP-012: the parameter whose change resets the referencing value is the direction.
    let direction = pos
        .side_effects
        .iter()
        .find(|e| {
            e.effect == SideEffectKind::Reset && e.affected.contains(&pos.mapping.reference_param)
        })
        .and_then(|e| e.changed.first())
        .ok_or_else(|| spec_err("no side effect names the direction of rotation"))?;
    add(direction, s(Setting::Direction))?;
    for (module, field, role) in [
        (&p.process_data.input, "status", Role::Status),
        (&p.process_data.input, "speed", Role::Speed),
        (&p.process_data.output, "control", Role::Control),
        (&p.process_data.output, "target", Role::Target),
    ] {
        let id = module
            .field(field)
            .and_then(|f| f.param.as_deref())
            .ok_or_else(|| spec_err(format!("process data field {field} names no parameter")))?;
        add(id, role)?;
    }
    add(&p.device_name.switch_param, Role::AddressSwitch)?;
    for (name, role) in [
        ("U motor", Role::MotorVoltage),
        ("U control", Role::ControlVoltage),
        ("Actual current", Role::Current),
        ("Max. current during last run", Role::MaxCurrent),
        ("Production date", Role::ProductionDate),
        ("Serial number", Role::SerialNumber),
        ("Device model (as number)", Role::ModelNumber),
        ("Device model (as string)", Role::ModelString),
        ("Version", Role::Version),
    ] {
        out.push((by_name(family, name)?, role));
    }
    Ok(out)
}

/// The status bits the positioning tables name agree with the bit map (3.6, 4.2.1, 4.5, 4.6).
fn check_bits(bits: &BitMap, p: &Protocol) -> Result<(), ModelError> {
    let pos = &p.positioning;
    let want = [
        (Flag::Obstruction, pos.obstruction.status_bit),
        (
            Flag::Obstruction,
            pos.reference_loop.attempts_exhausted_status_bit,
        ),
        (Flag::ManualRotation, pos.adjustment.manual_rotation_bit),
        (Flag::MotorOk, pos.adjustment.voltage_bit),
    ];
    for (flag, bit) in want {
        if bits.bit(flag) != Some(bit) {
            return Err(spec_err(format!(
                "status bit {bit} of the positioning tables is not the {flag} bit"
            )));
        }
    }
    let no_voltage: Vec<Option<u32>> = [Flag::Obstruction, Flag::VoltageMissing]
        .iter()
        .map(|f| bits.bit(*f))
        .collect();
    for b in &pos.adjustment.no_voltage_bits {
        if !no_voltage.contains(&Some(*b)) {
            return Err(spec_err(format!(
                "adjustment no-voltage bit {b} is neither the obstruction nor the voltage bit"
            )));
        }
    }
    Ok(())
}

/// The control word masks (3.7), from the spec's bits and documented words (4.1, 4.2.3).
fn controls(family: &Family, p: &Protocol, bits: &BitMap) -> Result<Controls, ModelError> {
    let control = family
        .bitfield("control")
        .ok_or_else(|| spec_err("no control bitfield"))?;
    let status = family
        .bitfield("status")
        .ok_or_else(|| spec_err("no status bitfield"))?;
    let pos = &p.positioning;
    let bit = |n: u32| 1u16.checked_shl(n).unwrap_or(0);
    let release = bit(pos.adjustment.release_bit);
    let word = |name: &str| -> Result<u16, ModelError> {
        control
            .values
            .iter()
            .find(|v| v.name == name)
            .and_then(|v| u16::try_from(v.value).ok())
            .ok_or_else(|| spec_err(format!("no control word value {name}")))
    };
    let toggle_name = bits
        .bit(Flag::Toggle)
        .and_then(|b| status.bit(b))
        .map(|b| b.name.clone())
        .ok_or_else(|| spec_err("no toggle bit in the status word"))?;
    let toggle = control
        .bits
        .iter()
        .find(|b| b.name == toggle_name)
        .map(|b| bit(b.bit))
        .ok_or_else(|| spec_err("no toggle bit in the control word"))?;
    Ok(Controls {
        manual_up: word("manual-run-larger")? & !release,
        manual_down: word("manual-run-smaller")? & !release,
        transfer: word("transfer-without-release")?,
        release,
        no_loop: bit(pos.reference_loop.no_loop_control_bit),
        toggle,
        must_be_zero: u16::try_from(control.must_be_zero_mask() & 0xFFFF).unwrap_or(0),
    })
}

/// The par. 96 values by name (3.3 par. 96).
fn commands(family: &Family, id: &str) -> Result<Commands, ModelError> {
    let param = family
        .parameter(id)
        .ok_or_else(|| spec_err(format!("no parameter {id}")))?;
    let v = |name: &str| -> Result<i64, ModelError> {
        param
            .values
            .iter()
            .find(|v| v.name == name)
            .map(|v| v.value)
            .ok_or_else(|| spec_err(format!("par {id} has no value {name}")))
    };
    Ok(Commands {
        reset: v("reset")?,
        delivery_centre: v("delivery-state-and-centre")?,
        user_centre: v("user-state-and-centre")?,
        delivery_clear_name: v("delivery-state-clear-name")?,
        user: v("user-state")?,
        delivery: v("delivery-state")?,
        save: v("save")?,
    })
}
