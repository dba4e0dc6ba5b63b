//! What the model knows about the drive, resolved once from the spec: parameter slots, access,
//! ranges, defaults, bit masks, command bits, the saved-image mask, the line tables and the
//! appendix G program (manual 4.2, 3.3, 3.4, 3.6, 3.8.1, chapter 4).

use super::error::ModelError;
use super::motor::{MotionStyle, MotorLayout, PositionCommand};
use super::names;
use crate::line::Micros;
use crate::memory::{BitAddr, Memory, ParamMap, Slot};
use crate::plc::{PlcRuntime, Program};
use crate::rules::FrameRules;
use drivespec_spec::hpd::{Alarm, Assignment, BaudRate, Protocol};
use drivespec_spec::{
    Access, DataType, Family, FamilyId, Parameter, Ranges, Readings, RuleAction, Spec,
};

/// A `[[parameter.mode]]` entry: range and default in some operating modes (manual 3.6).
#[derive(Debug, Clone)]
pub(super) struct ModeEntry {
    pub(super) modes: Vec<u32>,
    pub(super) range: Option<Ranges>,
    pub(super) default: Option<i64>,
    /// Writable in these modes (HPD-MODE-2-003: Pr55 is read-only in mode 2).
    pub(super) writable: bool,
}

/// One parameter with a serial slot (manual 4.2).
#[derive(Debug, Clone)]
pub(super) struct Param {
    pub(super) slot: Slot,
    pub(super) signed: bool,
    pub(super) writable: bool,
    pub(super) saved: bool,
    pub(super) is_bits: bool,
    /// Delivery value: the parameter's own, or built from its bits' defaults.
    pub(super) default: Option<i64>,
    /// Allowed raw values (the type's bounds when the manual gives none).
    pub(super) range: Option<Ranges>,
    /// Type bounds.
    pub(super) bounds: Option<Ranges>,
    pub(super) modes: Vec<ModeEntry>,
}

impl Param {
    /// The raw bytes as the parameter's value (two's complement when signed).
    pub(super) fn value(&self, raw: u32) -> i64 {
        if self.signed {
            sign_extend(raw, self.slot.size)
        } else {
            i64::from(raw)
        }
    }

    /// The mode entry for operating mode `mode`, if any.
    pub(super) fn mode(&self, mode: u32) -> Option<&ModeEntry> {
        self.modes.iter().find(|m| m.modes.contains(&mode))
    }
}

/// `raw` as a two's-complement value of `size` bytes.
pub(super) fn sign_extend(raw: u32, size: u8) -> i64 {
    let shift = 32 - 8 * u32::from(size.clamp(1, 4));
    i64::from(((raw << shift) as i32) >> shift)
}

/// Bits of one bitfield the master cannot change (bits.toml `access`, `must_be_zero`).
#[derive(Debug, Clone)]
pub(super) struct BitLayout {
    pub(super) param: usize,
    pub(super) modes: Vec<u32>,
    pub(super) readonly: u32,
    pub(super) must_be_zero: u32,
}

/// What a command bit does (manual 3.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum CommandKind {
    /// b42.3: re-initialise the serial line.
    Reinit,
    /// b99.10: alarm reset.
    AlarmReset,
    /// b99.11: operating-mode defaults.
    ModeDefaults,
    /// b99.12: all defaults and the appendix G program.
    Defaults,
    /// b99.14: save the PLC program.
    SavePlc,
    /// b99.15: save the parameters.
    SaveParams,
    /// A position command of modes 9–11 (b70.2, b70.10–b70.12).
    Position(PositionCommand),
    /// A command whose effect needs what the model has not (analogue input, current sensors).
    Other,
}

/// A command bit (bits.toml rules with trigger `command-executed`).
#[derive(Debug, Clone)]
pub(super) struct Command {
    pub(super) bit: BitAddr,
    /// Operating modes the bit is a command in (empty: all).
    pub(super) modes: Vec<u32>,
    pub(super) kind: CommandKind,
}

/// Bits and slots the model acts on.
#[derive(Debug, Clone)]
pub(super) struct Named {
    pub(super) enable: BitAddr,
    pub(super) security: BitAddr,
    pub(super) extended_menu: BitAddr,
    pub(super) reserved_reference: BitAddr,
    pub(super) idc_trigger: BitAddr,
    pub(super) healthy: Option<BitAddr>,
    /// The hardware enable status bit (b41.5).
    pub(super) hardware_enable: Option<BitAddr>,
    /// The drive enabled bit (b41.12).
    pub(super) drive_enabled: Option<BitAddr>,
    /// The hardware enable input, as a mask of the inputs.
    pub(super) enable_input: u16,
    /// The software enable bit (b40.9).
    pub(super) software_enable: BitAddr,
    pub(super) baud: Slot,
    pub(super) address: Slot,
    pub(super) alarm: Slot,
    pub(super) last_alarm: Slot,
    pub(super) mode: Slot,
    pub(super) idc_target: Slot,
    pub(super) idc_value: Slot,
}

/// The erratum readings that change the model's behaviour.
#[derive(Debug, Clone, Copy)]
pub(super) struct Options {
    /// Command bits clear themselves (HPD-ERRATUM-012).
    pub(super) self_clear: bool,
    /// b99.14 is refused on checksum alarms too (HPD-ERRATUM-013).
    pub(super) plc_save_checked: bool,
    /// Security b99.7 also blocks serial writes and commands (HPD-ERRATUM-011).
    pub(super) security_serial: bool,
    /// Pr31 accepts any byte (HPD-ERRATUM-014).
    pub(super) mode_any_byte: bool,
    /// A refused write is not answered (HPD-ERRATUM-069).
    pub(super) refusal_silent: bool,
}

/// The serial set-up of manual 4.1 (`protocol.serial_setup`).
#[derive(Debug, Clone)]
pub(super) struct Setup {
    pub(super) steps: Vec<Assignment>,
    pub(super) baud_param: String,
    pub(super) address_param: String,
    pub(super) reinit: BitAddr,
    pub(super) save: BitAddr,
}

/// Inter-drive communication (manual 3.8.2 example 10).
#[derive(Debug, Clone, Copy)]
pub(super) struct IdcRules {
    pub(super) baud_code: u8,
    pub(super) lun: u8,
    pub(super) receiver_sets_trigger: bool,
}

/// Everything fixed about a model drive.
#[derive(Debug, Clone)]
pub(super) struct Layout {
    pub(super) rules: FrameRules,
    pub(super) runtime: PlcRuntime,
    pub(super) map: ParamMap,
    pub(super) params: Vec<Param>,
    /// Index into `params` of the parameter holding each serial address.
    owner: Vec<Option<usize>>,
    pub(super) bitfields: Vec<BitLayout>,
    pub(super) commands: Vec<Command>,
    pub(super) power_on_reset: Vec<BitAddr>,
    /// Bits kept by the parameter save b99.15, per serial address.
    pub(super) saved_mask: [u8; 256],
    /// Working memory as delivered.
    pub(super) factory: Memory,
    /// The appendix G program, filled to the PLC area size.
    pub(super) default_program: Vec<u8>,
    pub(super) plc_first: u8,
    pub(super) plc_len: usize,
    pub(super) empty_program: Program,
    pub(super) named: Named,
    pub(super) options: Options,
    pub(super) alarms: Vec<Alarm>,
    pub(super) baud_rates: Vec<BaudRate>,
    pub(super) idc: IdcRules,
    pub(super) setup: Setup,
    pub(super) scan_us: Micros,
    pub(super) fin_us: Micros,
    pub(super) motor: MotorLayout,
}

fn spec_error(what: impl Into<String>) -> ModelError {
    ModelError::Spec { what: what.into() }
}

impl Layout {
    /// Resolves everything from the spec with the erratum readings in force.
    pub(super) fn new(
        spec: &Spec,
        readings: &Readings,
        style: MotionStyle,
    ) -> Result<Layout, ModelError> {
        let family = spec.family(FamilyId::Hpd);
        let protocol = family
            .hpd()
            .ok_or_else(|| spec_error("no HPD protocol table"))?;
        let rules = FrameRules::from_spec(spec)?;
        let runtime = PlcRuntime::from_spec(spec, readings)?;
        let map = ParamMap::from_spec(spec);
        let bit = |text: &str| -> Result<BitAddr, ModelError> {
            ParamMap::parse_bit(text)
                .and_then(|(n, y)| map.bit(n, y))
                .ok_or_else(|| spec_error(format!("bit {text} has no serial address")))
        };
        let slot = |text: &str| -> Result<Slot, ModelError> {
            ParamMap::parse_param(text)
                .and_then(|n| map.slot(n))
                .ok_or_else(|| spec_error(format!("{text} has no serial address")))
        };

        let mut params = Vec::new();
        let mut owner = vec![None; 256];
        let mut numbers = Vec::new();
        for p in &family.parameters {
            let Some(param) = resolve_param(family, p) else {
                continue;
            };
            let index = params.len();
            for i in 0..param.slot.size {
                let at = usize::from(param.slot.addr) + usize::from(i);
                if let Some(o) = owner.get_mut(at) {
                    *o = Some(index);
                }
            }
            numbers.push((p.id.clone(), index));
            params.push(param);
        }
        let index_of = |id: &str| numbers.iter().find(|(n, _)| n == id).map(|(_, i)| *i);

        let setup_spec = &protocol.serial_setup;
        let plc = &protocol.plc;
        let named = Named {
            enable: bit(&setup_spec.enable_bit)?,
            security: bit(&protocol.commands.security_bit)?,
            extended_menu: bit(&protocol.commands.extended_menu_bit)?,
            reserved_reference: bit(&protocol.commands.mode_defaults_requires_clear)?,
            idc_trigger: bit(&protocol.idc.trigger_bit)?,
            healthy: None,
            hardware_enable: None,
            drive_enabled: None,
            enable_input: 1u16
                .checked_shl(u32::from(protocol.io.enable_input))
                .unwrap_or(0),
            software_enable: bit(&protocol.io.software_enable_bit)?,
            baud: slot(&setup_spec.baud_param)?,
            address: slot(&setup_spec.address_param)?,
            alarm: slot(&protocol.commands.alarm_param)?,
            last_alarm: slot(&protocol.commands.last_alarm_param)?,
            mode: slot(&protocol.commands.mode_param)?,
            idc_target: slot(&protocol.idc.address_param)?,
            idc_value: slot(&protocol.idc.value_param)?,
        };
        let setup = Setup {
            steps: setup_spec.steps.clone(),
            baud_param: setup_spec.baud_param.clone(),
            address_param: setup_spec.address_param.clone(),
            reinit: bit(&setup_spec.reinit_bit)?,
            save: bit(&setup_spec.save_bit)?,
        };
        let kinds = [
            (setup.reinit, CommandKind::Reinit),
            (
                bit(&protocol.commands.alarm_reset_bit)?,
                CommandKind::AlarmReset,
            ),
            (
                bit(&protocol.commands.mode_defaults_bit)?,
                CommandKind::ModeDefaults,
            ),
            (bit(&plc.default_bit)?, CommandKind::Defaults),
            (bit(&plc.save_bit)?, CommandKind::SavePlc),
            (setup.save, CommandKind::SaveParams),
        ];

        let mut bitfields = Vec::new();
        let mut commands = Vec::new();
        let mut power_on_reset = Vec::new();
        let mut healthy = None;
        let mut hardware_enable = None;
        let mut drive_enabled = None;
        for bf in &family.bitfields {
            let Some(p) = family.parameter(&bf.param) else {
                continue;
            };
            let (Some(index), Ok(number)) = (index_of(&p.id), u8::try_from(p.number)) else {
                continue;
            };
            let mut layout = BitLayout {
                param: index,
                modes: bf.modes.clone(),
                readonly: 0,
                must_be_zero: 0,
            };
            for b in &bf.bits {
                let mask = 1u32.checked_shl(b.bit).unwrap_or(0);
                if b.access == Some(Access::R) {
                    layout.readonly |= mask;
                }
                if b.must_be_zero {
                    layout.must_be_zero |= mask;
                }
                let Some(addr) = u8::try_from(b.bit).ok().and_then(|y| map.bit(number, y)) else {
                    continue;
                };
                for rule in &b.rules {
                    match (rule.trigger.as_str(), rule.action) {
                        (names::TRIGGER_COMMAND, _) => {
                            let kind = kinds
                                .iter()
                                .find(|(k, _)| *k == addr && bf.modes.is_empty())
                                .map(|(_, kind)| *kind)
                                .or_else(|| position_command(&bf.modes, b.bit))
                                .unwrap_or(CommandKind::Other);
                            commands.push(Command {
                                bit: addr,
                                modes: bf.modes.clone(),
                                kind,
                            });
                        }
                        (names::TRIGGER_POWER_ON, RuleAction::Reset) => power_on_reset.push(addr),
                        (names::TRIGGER_ALARM_RAISED, RuleAction::Reset) => healthy = Some(addr),
                        (names::TRIGGER_HARDWARE_ENABLE, RuleAction::Set) => {
                            hardware_enable = Some(addr);
                        }
                        (names::TRIGGER_DRIVE_ENABLED, RuleAction::Set) => {
                            drive_enabled = Some(addr);
                        }
                        _ => {}
                    }
                }
            }
            bitfields.push(layout);
        }
        for (addr, kind) in kinds {
            if !commands.iter().any(|c| c.bit == addr && c.kind == kind) {
                return Err(spec_error(format!(
                    "{kind:?} command bit {addr:?} has no `command-executed` rule in the bits"
                )));
            }
        }
        let named = Named {
            healthy,
            hardware_enable,
            drive_enabled,
            ..named
        };

        let mut saved_mask = [0u8; 256];
        let mut factory = Memory::default();
        for (index, p) in params.iter().enumerate() {
            factory.set(p.slot.addr, p.slot.size, p.default.unwrap_or(0) as u32);
            if !p.saved {
                continue;
            }
            let mut keep = u32::MAX;
            for b in bitfields.iter().filter(|b| b.param == index) {
                keep &= !b.readonly;
            }
            for i in 0..p.slot.size {
                let at = usize::from(p.slot.addr) + usize::from(i);
                if let Some(m) = saved_mask.get_mut(at) {
                    *m = (keep >> (8 * u32::from(i))) as u8;
                }
            }
        }
        for b in commands
            .iter()
            .map(|c| c.bit)
            .chain(power_on_reset.iter().copied())
        {
            if let Some(m) = saved_mask.get_mut(usize::from(b.byte)) {
                *m &= !b.mask;
            }
        }

        let plc_len = usize::from(plc.last_address)
            .checked_sub(usize::from(plc.first_address))
            .map(|n| n + 1)
            .filter(|n| *n == usize::from(plc.area_bytes))
            .ok_or_else(|| spec_error("PLC area size does not match its addresses"))?;
        let default_program = assemble(&runtime, protocol, plc_len)?;

        let readings_of = |option: &str| readings.reading(family, option).map(str::to_owned);
        let options = Options {
            self_clear: readings_of(names::OPTION_SELF_CLEAR).as_deref()
                != Some(names::READING_LATCHED),
            plc_save_checked: readings_of(names::OPTION_PLC_SAVE).as_deref()
                == Some(names::READING_BOTH),
            security_serial: readings_of(names::OPTION_SECURITY).as_deref()
                != Some(names::READING_KEYPAD_ONLY),
            mode_any_byte: readings_of(names::OPTION_MODE_RANGE).as_deref()
                == Some(names::READING_ANY_BYTE),
            refusal_silent: readings_of(names::OPTION_REFUSED_WRITE).as_deref()
                == Some(names::READING_SILENT),
        };
        let idc_cmd = rules.code(crate::rules::MessageKind::Broadcast);
        if protocol.idc.cmd != idc_cmd {
            return Err(spec_error("the IDC command is not the broadcast message"));
        }
        let motor = MotorLayout::new(protocol, &map, style).map_err(spec_error)?;
        Ok(Layout {
            motor,
            scan_us: Micros::from(runtime.scan_us()),
            fin_us: Micros::from(runtime.fin_period_us()),
            rules,
            runtime,
            map,
            params,
            owner,
            bitfields,
            commands,
            power_on_reset,
            saved_mask,
            factory,
            default_program,
            plc_first: plc.first_address,
            plc_len,
            empty_program: Program { instrs: Vec::new() },
            named,
            options,
            alarms: protocol.alarms.clone(),
            baud_rates: protocol.baud_rates.clone(),
            idc: IdcRules {
                baud_code: protocol.idc.baud_code,
                lun: protocol.idc.lun,
                receiver_sets_trigger: protocol.idc.receiver_sets_trigger,
            },
            setup,
        })
    }

    /// The parameter holding serial address `addr`, with its index.
    pub(super) fn owner(&self, addr: usize) -> Option<(usize, &Param)> {
        let index = (*self.owner.get(addr)?)?;
        Some((index, self.params.get(index)?))
    }

    /// Bits of parameter `index` the master cannot change in mode `mode`: (read-only, must be 0).
    pub(super) fn fixed_bits(&self, index: usize, mode: u32) -> (u32, u32) {
        self.bitfields
            .iter()
            .filter(|b| b.param == index && (b.modes.is_empty() || b.modes.contains(&mode)))
            .fold((0, 0), |(r, z), b| (r | b.readonly, z | b.must_be_zero))
    }

    /// The Pr26 entry for `code` (manual 4 table).
    pub(super) fn baud(&self, code: u8) -> Option<&BaudRate> {
        self.baud_rates.iter().find(|b| b.code == code)
    }

    /// The alarm entry for `code` (manual 3.3 table).
    pub(super) fn alarm(&self, code: u8) -> Option<&Alarm> {
        self.alarms.iter().find(|a| a.code == code)
    }
}

/// The position command bit `y` of Pb70 is in the modes of its bitfield (manual 3.6.4–3.6.6).
fn position_command(modes: &[u32], y: u32) -> Option<CommandKind> {
    if !modes.iter().any(|m| names::POSITION_MODES.contains(m)) {
        return None;
    }
    let [clear, zero, shaft, to_motor] = names::POSITION_COMMAND_BITS.map(u32::from);
    let kind = match y {
        _ if y == clear && modes.contains(&names::MODE_POSITIONER) => {
            PositionCommand::ClearIncrement
        }
        _ if y == zero => PositionCommand::Zero,
        _ if y == shaft => PositionCommand::Shaft,
        _ if y == to_motor => PositionCommand::ReferenceToMotor,
        _ => return None,
    };
    Some(CommandKind::Position(kind))
}

/// A parameter with a serial slot, its access, range and default.
fn resolve_param(family: &Family, p: &Parameter) -> Option<Param> {
    let addr = u8::try_from(p.address?).ok()?;
    let size = u8::try_from(p.size?).ok()?;
    let resolved = family.resolve(p, None);
    let is_bits = matches!(
        p.data_type,
        DataType::Bits8 | DataType::Bits16 | DataType::Bits32
    );
    let default = resolved.default.or_else(|| {
        if !is_bits {
            return None;
        }
        let mut any = false;
        let mut word = 0i64;
        for bf in family.bitfields_of(&p.id).filter(|b| b.modes.is_empty()) {
            for b in &bf.bits {
                if let Some(d) = b.default {
                    any = true;
                    if d != 0 && b.bit < 32 {
                        word |= 1 << b.bit;
                    }
                }
            }
        }
        any.then_some(word)
    });
    Some(Param {
        slot: Slot { addr, size },
        signed: p.data_type.signed(),
        writable: p.access.writable(),
        saved: p.saved == Some(true),
        is_bits,
        default,
        range: resolved.range,
        bounds: p.data_type.bounds().map(|(lo, hi)| Ranges::new(lo, hi)),
        modes: p
            .modes
            .iter()
            .map(|m| ModeEntry {
                modes: m.modes.clone(),
                range: m.range.clone(),
                default: m.default,
                writable: m.access.is_none_or(|a| a.writable()),
            })
            .collect(),
    })
}

/// The appendix G program as PLC area bytes (`protocol.default_program`), filled to `len`.
fn assemble(runtime: &PlcRuntime, protocol: &Protocol, len: usize) -> Result<Vec<u8>, ModelError> {
    let codec = runtime.codec();
    let mut out = Vec::with_capacity(len);
    for (i, line) in protocol.default_program.iter().enumerate() {
        let bad = |what: String| ModelError::DefaultProgram { line: i + 1, what };
        if usize::from(line.address) != out.len() {
            return Err(bad(format!(
                "address {:#04x} where the instruction starts at {:#04x}",
                line.address,
                out.len()
            )));
        }
        let instr = codec
            .parse_line(&line.listing, i + 1)
            .map_err(|e| bad(e.to_string()))?;
        codec
            .encode(&instr, &mut out)
            .map_err(|e| bad(e.to_string()))?;
    }
    if out.len() > len {
        return Err(ModelError::DefaultProgram {
            line: protocol.default_program.len(),
            what: format!("{} bytes exceed the {len}-byte PLC area", out.len()),
        });
    }
    out.resize(len, protocol.plc.encoding.unused_fill);
    Ok(out)
}
