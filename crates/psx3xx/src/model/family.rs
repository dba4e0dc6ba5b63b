//! The PSx3xx family description for the positioning core, built from the spec (manual 3.1,
//! 3.2, 3.4, 3.5, chapters 4–5): the role of every ISDU entry, the control-word bits, the
//! core's numbers for one gearbox model, and the erratum readings chosen.
//!
//! Entries are found by the ids the spec's protocol tables name (`"142"` is the positioning
//! speed because `motion.positioning_speed_param = "142"`), the process-data fields' `params`,
//! and for the few entries no table names, by the manual's designation.

use super::config::{BrakeKind, DriveConfig};
use super::error::ModelError;
use drivespec_positioner::axis::{
    AxisConfig, Delivery, LimitRatio, LimitsAfterMappingEnd, Rounding,
};
use drivespec_positioner::config::{Backoff, LoopRules, Ramp, VoltageRules};
use drivespec_positioner::machine::{DriveSettings, Setting, Settings};
use drivespec_positioner::{AxisValues, BitMap, CoreConfig, Flag};
use drivespec_spec::psx3xx::Protocol;
use drivespec_spec::{Access, DataType, Family, Ranges};
use std::sync::Arc;

/// What an ISDU entry is to the model (manual 3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Role {
    /// A setting held by the positioning core (ISDU 67, 123–131, 146–148, 152–155, 159–161,
    /// 181, 182).
    Core(Setting),
    /// UMot filter ISDU 166, raw × 5 ms under PSX-ERRATUM-017.
    Filter,
    /// Loop length ISDU 132 (the core keeps it signed by the loop direction).
    LoopLength,
    /// Loop direction ISDU 134.
    LoopDirection,
    /// A stored number the family reads when it needs it.
    Stored,
    /// Status word ISDU 64.
    Status,
    /// Actual speed ISDU 65.
    Rpm,
    /// Actual torque ISDU 68.
    Torque,
    /// Largest torque of the last run ISDU 69.
    MaxTorque,
    /// Control supply voltage ISDU 70.
    ControlVoltage,
    /// Motor supply voltage ISDU 71.
    MotorVoltage,
    /// Device temperature ISDU 72.
    Temperature,
    /// Production date ISDU 77.
    ProductionDate,
    /// Serial number ISDU 78.
    SerialNumber,
    /// Device model code ISDU 79.
    ModelCode,
    /// Software version ISDU 80.
    Software,
    /// Control word ISDU 110.
    Control,
    /// Target position ISDU 112.
    Target,
    /// Process data format ISDU 116.
    Format,
    /// ISDU 2, Direct Parameter SystemCommand and ISDU 193.
    Command,
    /// A Direct Parameter page 1 entry (ISDU 0 sub n = address n − 1).
    Direct(u8),
    /// A text entry (ISDU 16–24).
    Text(TextKind),
}

/// The text entries of the identification block (manual 3.1 ISDU 16–24).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum TextKind {
    /// A fixed text (ISDU 16, 17, 20) or the writable tag (ISDU 24): its delivery text.
    Fixed,
    /// ISDU 18: product name of the gearbox type.
    ProductName,
    /// ISDU 19: product ID.
    ProductId,
    /// ISDU 21: serial number as text.
    SerialText,
    /// ISDU 22: hardware version.
    Hardware,
    /// ISDU 23: firmware version.
    Firmware,
}

/// One ISDU entry as the model uses it (manual 3.1).
#[derive(Debug, Clone)]
pub(crate) struct Entry {
    pub id: String,
    pub number: u16,
    pub subindex: u8,
    pub data_type: DataType,
    pub access: Access,
    pub saved: bool,
    pub default: Option<i64>,
    pub default_text: Option<String>,
    /// The model's range; None where the state decides (131, 132, 153, 128–130).
    pub range: Option<Ranges>,
    pub role: Role,
}

/// Ids of the entries the model acts on (manual 3.1).
#[derive(Debug, Clone)]
pub(crate) struct Ids {
    pub format: String,
    pub timeout: String,
    pub timeout_config: String,
    pub safe_position: String,
    pub drag_error: String,
    pub jog_step: String,
    pub jog_wait: String,
    pub speed_positioning: String,
    pub speed_manual: String,
    pub speed_ccw: String,
    pub speed_cw: String,
    pub free_steps: Option<String>,
    pub brake_start: Option<String>,
    pub brake_end: Option<String>,
    pub locks: String,
    /// Idle period for direction change ISDU 162 (PSX-ISDU-162-REVERSE).
    pub reversal_pause: String,
}

/// Masks of the control word bits (manual 3.5).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Controls {
    pub manual_up: u16,
    pub manual_down: u16,
    pub transfer: u16,
    pub continuous: u16,
    pub release: u16,
    pub key_release: u16,
    pub no_loop: u16,
    pub reference_loop: u16,
    pub jog_forward: u16,
    pub jog_reverse: u16,
    pub readjust: u16,
    pub free_run: u16,
    pub drag_correction: u16,
    pub clear_errors: u16,
    pub must_be_zero: u16,
}

/// The readings of the manual's contradictions the model follows (spec `[[erratum]]`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Options {
    /// PSX-ERRATUM-010: bit 1 by a missed speed after the acceleration.
    pub drag_by_speed: bool,
    /// PSX-ERRATUM-010: bit 1 by a position difference over ISDU 133.
    pub drag_by_position: bool,
    /// PSX-ERRATUM-017: ISDU 163 and 166 count in 5 ms steps.
    pub five_ms: bool,
    /// PSX-ERRATUM-052: stamps below 2000 fire on reception.
    pub stamp_immediate: bool,
    /// PSX-ERRATUM-061: what a reserved stamp value is.
    pub stamp_reserved: ReservedStamp,
    /// PSX-ERRATUM-064: the delay counts from the last valid stamp (true) or the marker.
    pub stamp_from_last: bool,
    /// PSX-ERRATUM-057: the breaking-free steps run on every run of a snap-brake drive.
    pub brake_steps_always: bool,
    /// PSX-ERRATUM-023: the breaking-free steps run in both directions (true) or against the
    /// run direction only.
    pub brake_both_directions: bool,
    /// PSX-ERRATUM-059: ISDU 2 = 130 also runs the reference loop and the centre run.
    pub cmd130_centre: bool,
    /// PSX-ERRATUM-015: ISDU 153 may exceed the table at reduced speed.
    pub torque_speed_dependent: bool,
    /// PSX-ERRATUM-063: the bound of 5.2 is rounded (true) or truncated.
    pub torque_round: bool,
    /// PSX-ERRATUM-022: ISDU 19 names the series (true) or prints "PSE".
    pub product_id_series: bool,
    /// PSX-ERRATUM-009: ProcessDataOut always reads 0x10.
    pub pd_out_fixed: bool,
    /// PSX-ERRATUM-054: control code 3 stands for release only.
    pub code3_release_only: bool,
    /// PSX-ERRATUM-056: ISDU 127 holds physical − written (user = physical − ISDU 127).
    pub reference_negated: bool,
    /// PSX-ERRATUM-011: ISDU 65 and 72 (and the input image's speed) are unsigned.
    pub measurements_unsigned: bool,
    /// PSX-ERRATUM-051: the control code sits in the two most significant bits of the
    /// time-stamp word, the stamp in the low 14.
    pub stamp_high_bits: bool,
}

/// How a reserved stamp value is taken (PSX-ERRATUM-061).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum ReservedStamp {
    /// Neither replaces nor fires the pending stamp.
    Ignored,
    /// Counts as the inactive marker.
    AsInactive,
    /// Taken as the largest valid stamp.
    Clamped,
}

/// The brake of the drive, if any (manual 5.12, 5.13).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct BrakeRules {
    pub kind: BrakeKind,
    /// The brake stays open ISDU 165 after a run (snap brake) or closes at once (holding).
    pub hold_open: bool,
}

/// Numbers of the 5.2 torque formula for the model (3.2 table, 5.2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct TorqueRule {
    /// Rated torque: the model's largest ISDU 153, cNm.
    pub rated_cnm: i64,
    /// Rated (maximum) speed: the model's largest ISDU 142, rpm.
    pub max_speed_rpm: i64,
    /// The model's largest ISDU 152, cNm.
    pub start_max_cnm: i64,
    /// The model's smallest ISDU 153, cNm.
    pub min_cnm: i64,
}

/// Everything the model reads from the spec for one gearbox model.
#[derive(Debug, Clone)]
pub(crate) struct PsxFamily {
    pub core: Arc<CoreConfig>,
    pub entries: Vec<Entry>,
    pub ids: Ids,
    pub controls: Controls,
    pub options: Options,
    /// Status bit of the drag error (3.4 bit 1).
    pub drag_bit: u16,
    /// Status bits of the jog keys (3.4 bits 3 and 2).
    pub forward_key_bit: u16,
    pub reverse_key_bit: u16,
    /// The delivery settings of the core.
    pub factory: Settings,
    pub model_id: String,
    pub model_code: i64,
    pub brake: Option<BrakeRules>,
    pub torque: TorqueRule,
    /// Ranges of ISDU 142 and 145 for the model (4.6.4 validity of the PD speed).
    pub positioning_speeds: Ranges,
    pub manual_speeds: Ranges,
    /// Fixed bounds of the mapping end in base steps (204800, PSX-MAP-004).
    pub mapping_span: i64,
    /// The absolute encoder's range below the mapping end in base steps: 256 revolutions of
    /// 400 steps (PSX-POS-001, PSX-ERRATUM-018).
    pub encoder_span: i64,
    /// The initial reference loop in turns, [numerator, denominator] (3.5 bit 7).
    pub loop_turns: [i64; 2],
    /// Software version from which format 2 and control bit 14 exist (1.6).
    pub format2_software: i64,
    /// The dark phase of the orange LED that acknowledges a fired time stamp, µs (3.3.1,
    /// the spec's `dark-<n>ms` pattern; PSX-LED-005).
    pub stamp_ack_dark_us: u64,
}

fn spec_err(what: impl Into<String>) -> ModelError {
    ModelError::Spec { what: what.into() }
}

fn by_name<'f>(family: &'f Family, name: &str) -> Result<&'f str, ModelError> {
    family
        .parameters
        .iter()
        .find(|p| p.name == name)
        .map(|p| p.id.as_str())
        .ok_or_else(|| spec_err(format!("no parameter named {name:?}")))
}

fn bit(n: u32) -> u16 {
    1u16.checked_shl(n).unwrap_or(0)
}

/// Whether a model id matches a spec model pattern (`PSx30x-14`, `PSE34xx`): `x` stands for one
/// character, a trailing `xx` for one or more; a pattern without a shaft suffix fits both
/// shafts (manual 3.2 naming, PSX-MODEL-NAMES).
fn pattern_matches(pattern: &str, id: &str) -> bool {
    let id_main = match (pattern.contains('-'), id.split_once('-')) {
        (false, Some((main, _))) => main,
        _ => id,
    };
    let p: Vec<char> = pattern.chars().collect();
    let s: Vec<char> = id_main.chars().collect();
    if let Some(stem) = pattern.strip_suffix("xx") {
        let stem: Vec<char> = stem.chars().collect();
        return s.len() > stem.len()
            && stem
                .iter()
                .zip(&s)
                .all(|(a, b)| *a == 'x' || a.eq_ignore_ascii_case(b));
    }
    p.len() == s.len()
        && p.iter()
            .zip(&s)
            .all(|(a, b)| *a == 'x' || a.eq_ignore_ascii_case(b))
}

impl PsxFamily {
    /// Reads the family for the model of `config` (manual 3.1, 3.2, chapters 4–5).
    pub fn build(family: &Family, config: &DriveConfig) -> Result<PsxFamily, ModelError> {
        let p = family
            .psx3xx()
            .ok_or_else(|| spec_err("no PSx3xx protocol"))?;
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
        let options = Options {
            drag_by_speed: reading("psx-drag-error-rule", "both") != "position",
            drag_by_position: reading("psx-drag-error-rule", "both") != "speed",
            five_ms: reading("psx-5ms-steps", "5ms-steps") == "5ms-steps",
            stamp_immediate: reading("psx-ts-immediate", "on-reception") == "on-reception",
            stamp_reserved: match reading("psx-ts-reserved", "ignored").as_str() {
                "as-inactive" => ReservedStamp::AsInactive,
                "clamped" => ReservedStamp::Clamped,
                _ => ReservedStamp::Ignored,
            },
            stamp_from_last: reading("psx-ts-reference", "last-stamp") == "last-stamp",
            brake_steps_always: reading("psx-brake-free-run", "wait-always-steps-with-bit-11")
                == "always",
            // PSX-ERRATUM-023 has no option: the adopted reading "both-directions".
            brake_both_directions: true,
            cmd130_centre: reading("psx-cmd-130", "like-193-2") == "like-193-minus-2",
            torque_speed_dependent: reading("psx-torque-speed-extension", "speed-dependent")
                == "speed-dependent",
            torque_round: reading("psx-torque-rounding", "truncate") == "round",
            product_id_series: reading("psx-product-id", "series") == "series",
            pd_out_fixed: reading("psx-pd-out-length", "format-dependent") == "fixed-16",
            code3_release_only: reading("psx-ts-code3", "release-and-transfer") == "release-only",
            reference_negated: reading("psx-ref-sign", "written-minus-physical")
                == "physical-minus-written",
            measurements_unsigned: reading("psx-signed-measurements", "signed") == "unsigned",
            stamp_high_bits: reading("psx-ts-bit-layout", "low-bits") == "high-bits",
        };

        let brake = match config.brake {
            None => None,
            Some(kind) => {
                let rule = p
                    .brakes
                    .iter()
                    .find(|b| b.kind == kind.spec_name())
                    .filter(|b| b.models.iter().any(|m| pattern_matches(m, &model.id)))
                    .ok_or_else(|| ModelError::NoSuchBrake {
                        model: model.id.clone(),
                        brake: kind.spec_name(),
                    })?;
                Some(BrakeRules {
                    kind,
                    hold_open: rule.end_wait_param.is_some(),
                })
            }
        };
        let snap = p
            .brakes
            .iter()
            .find(|b| b.kind == BrakeKind::Snap.spec_name());

        let m = &p.motion;
        let mp = &p.mapping;
        let ids = Ids {
            format: p.format_select.param.clone(),
            timeout: p.timeout.timeout_param.clone(),
            timeout_config: p.timeout.config_param.clone(),
            safe_position: p.timeout.safe_position_param.clone(),
            drag_error: m.drag_error_param.clone(),
            jog_step: p.jog.step_param.clone(),
            jog_wait: p.jog.wait_param.clone(),
            speed_positioning: m.positioning_speed_param.clone(),
            speed_manual: m.manual_speed_param.clone(),
            speed_ccw: m.ccw_speed_param.clone(),
            speed_cw: m.cw_speed_param.clone(),
            free_steps: snap.and_then(|b| b.free_steps_param.clone()),
            brake_start: snap.and_then(|b| b.start_wait_param.clone()),
            brake_end: snap.and_then(|b| b.end_wait_param.clone()),
            locks: by_name(family, "Device access locks")?.to_owned(),
            reversal_pause: by_name(family, "Idle period for direction change")?.to_owned(),
        };

        let roles = roles(family, p)?;
        let state_ranges = [
            m.window_param.as_str(),
            m.loop_length_param.as_str(),
            m.torque_param.as_str(),
            mp.upper_mapping_end_param.as_str(),
            mp.upper_limit_param.as_str(),
            mp.lower_limit_param.as_str(),
        ];
        let mut entries = Vec::with_capacity(family.parameters.len());
        for param in &family.parameters {
            let role = roles
                .iter()
                .find(|(id, _)| *id == param.id)
                .map_or(Role::Stored, |(_, r)| *r);
            let resolved = family.resolve(param, Some(model));
            let number = u16::try_from(param.number)
                .map_err(|_| spec_err(format!("ISDU index {} too large", param.number)))?;
            let subindex = u8::try_from(param.subindex.unwrap_or(0))
                .map_err(|_| spec_err(format!("ISDU {} sub-index too large", param.id)))?;
            let range = if state_ranges.contains(&param.id.as_str()) {
                None
            } else {
                resolved.range
            };
            entries.push(Entry {
                id: param.id.clone(),
                number,
                subindex,
                data_type: param.data_type,
                access: param.access,
                saved: param.saved == Some(true),
                default: resolved.default,
                default_text: param.default_text.clone(),
                range,
                role,
            });
        }

        let default_of = |id: &str| -> Result<i64, ModelError> {
            entries
                .iter()
                .find(|e| e.id == id)
                .and_then(|e| e.default)
                .ok_or_else(|| spec_err(format!("no delivery value for ISDU {id}")))
        };
        let range_of = |id: &str| -> Result<Ranges, ModelError> {
            family
                .parameter(id)
                .and_then(|q| family.resolve(q, Some(model)).range)
                .ok_or_else(|| spec_err(format!("no range for ISDU {id}")))
        };

        let loop_sign = if default_of(&m.loop_direction_param)? == 0 {
            1
        } else {
            -1
        };
        let loop_default = default_of(&m.loop_length_param)? * loop_sign;
        let mut loop_range: Vec<[i64; 2]> = Vec::new();
        for [lo, hi] in range_of(&m.loop_length_param)?.intervals() {
            // The core keeps the loop length signed by the loop direction (PSX-ERRATUM-014).
            if *lo == 0 && *hi == 0 {
                loop_range.push([0, 0]);
            } else {
                loop_range.push([-*hi, -*lo]);
                loop_range.push([*lo, *hi]);
            }
        }
        let window_range = {
            let r = range_of(&m.window_param)?;
            [
                r.min().ok_or_else(|| spec_err("empty window range"))?,
                r.max().ok_or_else(|| spec_err("empty window range"))?,
            ]
        };
        let c = &p.constants;
        let [fmin, fmax] = c.scaling_factor_range;
        let axis = AxisConfig {
            base_increments: i64::from(mp.scaling_base),
            upper_margin: i64::from(mp.upper_margin_steps),
            lower_offset: i64::from(mp.lower_offset_steps),
            factor_range: [i64::from(fmin), i64::from(fmax)],
            // 5.6.4: bounds scaled by den/num are rounded to the nearest integer.
            rounding: Rounding::Nearest,
            delivery: Delivery {
                mapping_end: default_of(&mp.upper_mapping_end_param)?,
                upper_limit: default_of(&mp.upper_limit_param)?,
                lower_limit: default_of(&mp.lower_limit_param)?,
                reference: default_of(&mp.reference_param)?,
                window: default_of(&m.window_param)?,
                loop_length: loop_default,
                numerator: default_of(&mp.numerator_param)?,
                denominator: default_of(&mp.denominator_param)?,
                direction: default_of(&m.direction_param)?,
            },
            window_range,
            // PSX-ERRATUM-019 adopted "default-scaling": the ranges scale with den/num.
            scale_window_range: true,
            loop_range,
            scale_loop_range: true,
            upper_limit_ratio: LimitRatio::DenOverNum,
            // PSX-ERRATUM-026 adopted "relative": limits follow the mapping end.
            limits_after_mapping_end: LimitsAfterMappingEnd::FullNewRange,
        };

        let status = family
            .bitfield("status")
            .ok_or_else(|| spec_err("no status bitfield"))?;
        let bits = BitMap::from_bitfield(
            status,
            &[
                (Flag::Reached, "PSX-STS-0-SET-1"),
                (Flag::MotorOk, "PSX-STS-4-SET-1"),
                (Flag::Aborted, "PSX-STS-5-SET-1"),
                (Flag::Running, "PSX-STS-6-SET-1"),
                (Flag::OverTemp, "PSX-STS-7-SET-1"),
                (Flag::AgainstLoop, "PSX-STS-8-SET-1"),
                (Flag::Error, "PSX-STS-9-SET-1"),
                (Flag::Obstruction, "PSX-STS-10-SET-1"),
                (Flag::ManualRotation, "PSX-STS-11-SET-1"),
                (Flag::BadTarget, "PSX-STS-12-SET-1"),
                (Flag::VoltageMissing, "PSX-STS-13-SET-1"),
                (Flag::UpperLimit, "PSX-STS-14-SET-1"),
                (Flag::LowerLimit, "PSX-STS-15-SET-1"),
            ],
        )?;
        if bits.bit(Flag::Obstruction) != Some(m.block_status_bit) {
            return Err(spec_err(
                "motion.block_status_bit is not the bit of PSX-STS-10-SET-1",
            ));
        }
        let drag_bit = status
            .bits
            .iter()
            .find(|b| b.rules.iter().any(|r| r.requirement == "PSX-STS-1-SET-2"))
            .map(|b| bit(b.bit))
            .ok_or_else(|| spec_err("no drag-error bit (PSX-STS-1-SET-2)"))?;

        let decel_max = range_of(&m.deceleration_param)?
            .max()
            .ok_or_else(|| spec_err("empty deceleration range"))?;
        let start = config.start_position.unwrap_or(c.delivery_position);
        let [turn_n, turn_d] = m.reference_loop_turns;
        let core = CoreConfig {
            axis: Arc::new(axis),
            bits,
            // No PSx3xx bit has priority over another; an obstruction inside the window counts
            // as reached (PSX-REF-004).
            priority_exclusive: true,
            loop_rules: LoopRules {
                // 4.2 case 2: overrun by the loop length ISDU 132.
                overshoot_is_loop_length: true,
                // ISDU 134 = 0 "forwards": a positive core loop approaches upwards.
                positive_approaches_up: true,
                // 4.2 case 3: back to target − loop length.
                backoff: Backoff::LoopLength,
                fixed_rotations: [i64::from(turn_n), i64::from(turn_d)],
                // DECISION: the PSx3xx manual knows no second positioning; a missed target
                // is an encoder deviation (PSX-STS-9-SET-2).
                attempts: 1,
            },
            // 5.1: the deceleration ISDU 148 applies to all runs.
            stop_ramp: Ramp::Parameter,
            emergency_ramp: Ramp::Maximum,
            max_deceleration: decel_max as f64,
            voltage: VoltageRules {
                upper: i64::from(c.motor_voltage_max_dv),
                // PSX-STS-13-SET-2: the corridor of bit 4 applies during runs too.
                run_minimum: None,
            },
            temperature_hysteresis: i64::from(c.temperature_hysteresis_c),
            aborted_on_manual_stop: reading("psx-sts5-manual-abort", "any-run") == "any-run",
            // PSX-STS-11-SET-1: any rotation beyond the window at standstill.
            manual_rotation_always: true,
            // DECISION: the manual gives no rule for bits 0 and 1 together; no manual run.
            both_manual_invalid: false,
            // ISDU 132 = 0 is "no loop", which readjusts both ways like control bit 6.
            adjust_both_without_loop: true,
            tick_us: 1000,
            blend: 0.5,
            start_position: start,
        };

        let mut factory = Settings {
            axis: AxisValues {
                direction: core.axis.delivery.direction,
                numerator: core.axis.delivery.numerator,
                denominator: core.axis.delivery.denominator,
                reference: core.axis.delivery.reference,
                mapping_end: core.axis.delivery.mapping_end,
                upper_limit: core.axis.delivery.upper_limit,
                lower_limit: core.axis.delivery.lower_limit,
                window: core.axis.delivery.window,
                loop_length: core.axis.delivery.loop_length,
            },
            drive: DriveSettings::default(),
        };
        for e in &entries {
            if let (Role::Core(s), Some(d)) = (e.role, e.default) {
                factory.put(s, d);
            }
        }
        let five = if options.five_ms { 5 } else { 1 };
        factory.put(Setting::UmotFilter, default_of(&filter_id(family)?)? * five);
        factory.put(
            Setting::PositioningSpeed,
            default_of(&m.positioning_speed_param)?,
        );
        factory.put(Setting::ManualSpeed, default_of(&m.manual_speed_param)?);
        factory.put(Setting::Readjust, 0);

        let jog = &p.jog;
        let controls = controls(family, p)?;
        let model_code = config.model_code.map_or_else(
            || {
                model
                    .attribute("device_model_code")
                    .map(|v| v as i64)
                    .ok_or_else(|| spec_err(format!("model {} has no device_model_code", model.id)))
            },
            |c| Ok(i64::from(c)),
        )?;
        let max_of = |id: &str| -> Result<i64, ModelError> {
            range_of(id)?
                .max()
                .ok_or_else(|| spec_err(format!("empty range of ISDU {id}")))
        };
        let torque = TorqueRule {
            rated_cnm: max_of(&m.torque_param)?,
            max_speed_rpm: max_of(&m.positioning_speed_param)?,
            start_max_cnm: max_of(&m.start_torque_param)?,
            min_cnm: range_of(&m.torque_param)?
                .min()
                .ok_or_else(|| spec_err("empty torque range"))?,
        };
        Ok(PsxFamily {
            core: Arc::new(core),
            entries,
            ids,
            controls,
            options,
            drag_bit,
            forward_key_bit: bit(jog.forward_key_status_bit),
            reverse_key_bit: bit(jog.reverse_key_status_bit),
            factory,
            model_id: model.id.clone(),
            model_code,
            brake,
            torque,
            positioning_speeds: range_of(&m.positioning_speed_param)?,
            manual_speeds: range_of(&m.manual_speed_param)?,
            mapping_span: i64::from(mp.mapping_end_span_steps),
            encoder_span: i64::from(c.encoder_revolutions) * i64::from(mp.scaling_base),
            loop_turns: [i64::from(turn_n), i64::from(turn_d)],
            format2_software: i64::from(c.format2_min_software),
            stamp_ack_dark_us: stamp_ack_dark_us(p)?,
        })
    }

    /// The entry of an ISDU index and sub-index (manual 3.1).
    pub fn entry(&self, number: u16, subindex: u8) -> Option<&Entry> {
        self.entries
            .iter()
            .find(|e| e.number == number && e.subindex == subindex)
    }

    /// The entry with a parameter id (manual 3.1).
    pub fn by_id(&self, id: &str) -> Option<&Entry> {
        self.entries.iter().find(|e| e.id == id)
    }

    /// The model's series (`PSE`, `PSS`, `PSW`) for ISDU 19 (PSX-ERRATUM-022).
    pub fn series(&self) -> String {
        self.model_id.chars().take(3).collect()
    }
}

/// The acknowledge dark phase of the orange LED from its `dark-<n>ms` pattern (3.3.1).
fn stamp_ack_dark_us(p: &Protocol) -> Result<u64, ModelError> {
    p.leds
        .iter()
        .filter(|l| l.colour == "orange")
        .flat_map(|l| &l.states)
        .find_map(|s| {
            s.pattern
                .strip_prefix("dark-")
                .and_then(|ms| ms.strip_suffix("ms"))
                .and_then(|ms| ms.parse::<u64>().ok())
        })
        .map(|ms| ms.saturating_mul(1000))
        .ok_or_else(|| spec_err("no dark-<n>ms state of the orange LED"))
}

fn filter_id(family: &Family) -> Result<String, ModelError> {
    by_name(family, "UMot filter").map(str::to_owned)
}

/// The role of every entry the tables or names identify (manual 3.1, 3.3, chapters 4–5).
fn roles(family: &Family, p: &Protocol) -> Result<Vec<(String, Role)>, ModelError> {
    let m = &p.motion;
    let mp = &p.mapping;
    let mut out: Vec<(String, Role)> = Vec::new();
    let mut add = |id: &str, role: Role| -> Result<(), ModelError> {
        if family.parameter(id).is_none() {
            return Err(spec_err(format!("no parameter {id}")));
        }
        out.push((id.to_owned(), role));
        Ok(())
    };
    let s = Role::Core;
    add(&m.direction_param, s(Setting::Direction))?;
    add(&mp.numerator_param, s(Setting::Numerator))?;
    add(&mp.denominator_param, s(Setting::Denominator))?;
    add(&mp.reference_param, s(Setting::Reference))?;
    add(&mp.upper_mapping_end_param, s(Setting::MappingEnd))?;
    add(&mp.upper_limit_param, s(Setting::UpperLimit))?;
    add(&mp.lower_limit_param, s(Setting::LowerLimit))?;
    add(&mp.actual_param, s(Setting::Actual))?;
    add(&m.window_param, s(Setting::Window))?;
    add(&m.loop_length_param, Role::LoopLength)?;
    add(&m.loop_direction_param, Role::LoopDirection)?;
    add(&m.acceleration_param, s(Setting::Acceleration))?;
    add(&m.deceleration_param, s(Setting::Deceleration))?;
    add(&m.start_torque_param, s(Setting::StartupTorque))?;
    add(&m.start_time_param, s(Setting::StartupTime))?;
    add(&m.torque_param, s(Setting::OperatingTorque))?;
    add(&m.holding_torque_param, s(Setting::HoldTorque))?;
    add(&m.end_holding_torque_param, s(Setting::EndHoldTorque))?;
    add(&m.end_holding_time_param, s(Setting::EndHoldTime))?;
    add(&m.block_speed_param, s(Setting::BlockSpeedPercent))?;
    add(&m.block_time_param, s(Setting::BlockTime))?;
    add(by_name(family, "UMot limit")?, s(Setting::UmotLimit))?;
    add(by_name(family, "Temperature limit")?, s(Setting::TempLimit))?;
    add(by_name(family, "UMot filter")?, Role::Filter)?;
    add(&p.timestamp.control_word_param, Role::Control)?;
    add(&p.timestamp.target_param, Role::Target)?;
    add(&p.format_select.param, Role::Format)?;
    let mut commands: Vec<&str> = Vec::new();
    for c in &p.commands.commands {
        if !commands.contains(&c.param.as_str()) {
            commands.push(&c.param);
        }
    }
    for id in commands {
        add(id, Role::Command)?;
    }
    let dp = &p.direct_parameters;
    for e in &dp.entries {
        let role = if e.name == "SystemCommand" {
            Role::Command
        } else {
            Role::Direct(e.address)
        };
        add(&e.param, role)?;
    }
    for (field, role) in [("status", Role::Status), ("rpm", Role::Rpm)] {
        let id = p
            .process_input
            .field(field)
            .and_then(|f| f.params.first())
            .ok_or_else(|| spec_err(format!("input field {field} names no parameter")))?;
        add(id, role)?;
    }
    add(&p.device_id.model_param, Role::ModelCode)?;
    for (name, role) in [
        ("Actual torque", Role::Torque),
        ("Maximum torque on last run", Role::MaxTorque),
        ("U control", Role::ControlVoltage),
        ("U motor", Role::MotorVoltage),
        ("Device temperature", Role::Temperature),
        ("Production date", Role::ProductionDate),
        ("Serial number", Role::SerialNumber),
        ("Software version", Role::Software),
        ("Vendor name", Role::Text(TextKind::Fixed)),
        ("Vendor text", Role::Text(TextKind::Fixed)),
        ("Product name", Role::Text(TextKind::ProductName)),
        ("Product-ID", Role::Text(TextKind::ProductId)),
        ("Product text", Role::Text(TextKind::Fixed)),
        ("Serial number (text)", Role::Text(TextKind::SerialText)),
        ("Hardware version", Role::Text(TextKind::Hardware)),
        ("Firmware version", Role::Text(TextKind::Firmware)),
        ("Application specific tag", Role::Text(TextKind::Fixed)),
    ] {
        add(by_name(family, name)?, role)?;
    }
    Ok(out)
}

/// The control word masks (3.5), from the spec's protocol tables and bitfield (3.5, 5.10).
fn controls(family: &Family, p: &Protocol) -> Result<Controls, ModelError> {
    let control = family
        .bitfield("control")
        .ok_or_else(|| spec_err("no control bitfield"))?;
    let word = |name: &str| -> Result<u16, ModelError> {
        control
            .values
            .iter()
            .find(|v| v.name == name)
            .and_then(|v| u16::try_from(v.value).ok())
            .ok_or_else(|| spec_err(format!("no control word value {name}")))
    };
    let m = &p.motion;
    let j = &p.jog;
    let release = bit(m.release_bit);
    let clear_errors = control
        .bits
        .iter()
        .find(|b| b.name.starts_with("Clear error"))
        .map(|b| bit(b.bit))
        .ok_or_else(|| spec_err("no clear-error bit in the control word"))?;
    let free_run = p.brakes.iter().find_map(|b| b.free_run_bit).map_or(0, bit);
    Ok(Controls {
        manual_up: word("release-manual-run-larger")? & !release,
        manual_down: word("release-manual-run-smaller")? & !release,
        transfer: bit(m.transfer_bit),
        continuous: bit(j.continuous_bit),
        release,
        key_release: bit(j.key_release_bit),
        no_loop: bit(m.no_loop_bit),
        reference_loop: bit(m.reference_loop_bit),
        jog_forward: bit(j.forward_bit),
        jog_reverse: bit(j.reverse_bit),
        readjust: bit(m.readjust_bit),
        free_run,
        drag_correction: bit(m.drag_correction_bit),
        clear_errors,
        must_be_zero: u16::try_from(control.must_be_zero_mask() & 0xFFFF).unwrap_or(0),
    })
}

#[cfg(test)]
mod tests {
    use super::pattern_matches;

    #[test]
    fn brake_patterns_match_model_ids() {
        assert!(pattern_matches("PSx30x-14", "PSE301-14"));
        assert!(!pattern_matches("PSx30x-14", "PSE301-8"));
        assert!(pattern_matches("PSx32x", "PSS322-14"));
        assert!(pattern_matches("PSE34xx", "PSE3410-14"));
        assert!(!pattern_matches("PSE34xx", "PSE335-14"));
        assert!(!pattern_matches("PSx33x", "PSE3310-14"));
    }
}
