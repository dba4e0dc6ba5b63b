//! The pico-PLC interpreter (manual 3.8.1): one scan reads the inputs, updates the timers,
//! runs the program once and writes the outputs, every 6.144 ms; FIN copies run every 512 µs.
//!
//! Operands the manual leaves undefined (a parameter without a serial slot, a bit beyond the
//! parameter's width, division by zero, a byte parameter in arithmetic) make the instruction
//! a no-op. Nothing here panics or allocates per scan.

use super::codec::{Instr, Operands, PlcCodec};
use super::program::Program;
use crate::memory::{BitAddr, Memory, ParamMap, Slot};
use crate::rules::RulesError;
use drivespec_spec::hpd::{Operation, ScanStep};
use drivespec_spec::{FamilyId, Readings, Spec};

/// What b99.3 means (erratum option `b99-3`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ZeroFlag {
    /// 1 when the result is zero.
    SetWhenZero,
    /// 1 when the result differs from zero.
    SetWhenNonZero,
}

/// The PLC's rules, resolved from the spec into serial addresses.
#[derive(Debug, Clone)]
pub struct PlcRuntime {
    codec: PlcCodec,
    map: ParamMap,
    scan_us: u32,
    fin_period_us: u32,
    scan_order: Vec<ScanStep>,
    run_bit: BitAddr,
    dword_force: BitAddr,
    dword_force_reset: bool,
    negative: BitAddr,
    zero: BitAddr,
    zero_flag: ZeroFlag,
    requires_stack: bool,
    div_remainder_high: bool,
    /// FIN disable bits disable at 1 (erratum option `fin-disable`).
    fin_disabled_at: bool,
    /// b99.0/b99.1 follow the timer in the same update (erratum option `timer-flag`).
    timer_flag_same_update: bool,
    constant_result_discarded: bool,
    dword_param: [bool; 256],
    forbidden: [bool; 256],
    /// Values of the constants Pr71–Pr79 (3.8.1), which table 4.2 gives no address.
    constant: [Option<i64>; 256],
    timers: Vec<(Slot, BitAddr)>,
    fin_slots: Vec<FinSlot>,
    fin_targets: Vec<u8>,
    inputs: Vec<(u8, BitAddr)>,
    outputs: Vec<(u8, BitAddr)>,
}

#[derive(Debug, Clone, Copy)]
struct FinSlot {
    index: usize,
    input: u8,
    disable: BitAddr,
}

/// The PLC's own state between scans: the one-bit stack.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PlcState {
    /// The stack bit.
    pub stack: bool,
}

impl PlcRuntime {
    /// Resolves the PLC rules of the spec with the erratum readings in force.
    pub fn from_spec(spec: &Spec, readings: &Readings) -> Result<PlcRuntime, RulesError> {
        let family = spec.family(FamilyId::Hpd);
        let p = family.hpd().ok_or(RulesError::NoProtocol)?;
        let codec = PlcCodec::from_spec(spec).ok_or(RulesError::NoProtocol)?;
        let map = ParamMap::from_spec(spec);
        let plc = &p.plc;
        let bit = |text: &str| -> Result<BitAddr, RulesError> {
            let (n, y) = ParamMap::parse_bit(text).ok_or(RulesError::Frame {
                what: "a PLC bit reference is malformed",
            })?;
            map.bit(n, y).ok_or(RulesError::Frame {
                what: "a PLC bit has no serial address",
            })
        };
        let numbers = |names: &[String]| {
            let mut set = [false; 256];
            for n in names.iter().filter_map(|s| ParamMap::parse_param(s)) {
                if let Some(slot) = set.get_mut(usize::from(n)) {
                    *slot = true;
                }
            }
            set
        };
        let a = &plc.arithmetic;
        let zero_flag = match readings.reading(family, &a.zero_bit_option) {
            Some("nonzero") => ZeroFlag::SetWhenNonZero,
            _ => ZeroFlag::SetWhenZero,
        };
        // Erratum options (HPD-ERRATUM-051, 054, 059, 068): the adopted reading unless chosen.
        let reading = |option: &str| readings.reading(family, option);
        let mut dword_param = numbers(&a.dword_params);
        if reading("dword-pr69") == Some("pr60-68") {
            let last = a.dword_params.last().and_then(|s| ParamMap::parse_param(s));
            if let Some(slot) = last.and_then(|n| dword_param.get_mut(usize::from(n))) {
                *slot = false;
            }
        }
        let div_remainder_high =
            a.div_remainder_in_high_word && reading("div-remainder") != Some("quotient32");
        let fin_disabled_at = reading("fin-disable") != Some("zero-disables");
        let timer_flag_same_update = reading("timer-flag") != Some("next-update");
        let mut constant = [None; 256];
        for c in &plc.constants {
            if let Some(slot) =
                ParamMap::parse_param(&c.param).and_then(|n| constant.get_mut(usize::from(n)))
            {
                *slot = Some(c.value);
            }
        }
        let mut timers = Vec::new();
        for t in &plc.timers {
            let n = ParamMap::parse_param(&t.param).ok_or(RulesError::Frame {
                what: "timer parameter malformed",
            })?;
            let slot = map.slot(n).ok_or(RulesError::Frame {
                what: "timer parameter has no serial address",
            })?;
            timers.push((slot, bit(&t.status_bit)?));
        }
        let mut fin_slots = Vec::new();
        for s in &plc.fast_inputs.slots {
            fin_slots.push(FinSlot {
                index: usize::from(s.index.saturating_sub(1)),
                input: s.input,
                disable: bit(&s.disable_bit)?,
            });
        }
        let fin_targets = plc
            .fast_inputs
            .targets
            .iter()
            .filter_map(|t| ParamMap::parse_param(t))
            .collect();
        let points =
            |pts: &[drivespec_spec::hpd::IoPoint]| -> Result<Vec<(u8, BitAddr)>, RulesError> {
                pts.iter().map(|pt| Ok((pt.index, bit(&pt.bit)?))).collect()
            };
        Ok(PlcRuntime {
            scan_us: plc.scan_us,
            fin_period_us: plc.fast_inputs.period_us,
            scan_order: plc.scan_order.clone(),
            run_bit: bit(&plc.run_bit)?,
            dword_force: bit(&a.dword_force_bit)?,
            dword_force_reset: a.dword_force_auto_reset,
            negative: bit(&a.negative_bit)?,
            zero: bit(&a.zero_bit)?,
            zero_flag,
            requires_stack: a.requires_stack,
            div_remainder_high,
            fin_disabled_at,
            timer_flag_same_update,
            constant_result_discarded: a.constant_result_discarded,
            dword_param,
            forbidden: numbers(&a.forbidden_params),
            constant,
            timers,
            fin_slots,
            fin_targets,
            inputs: points(&p.io.inputs)?,
            outputs: points(&p.io.outputs)?,
            codec,
            map,
        })
    }

    /// The instruction codec.
    pub fn codec(&self) -> &PlcCodec {
        &self.codec
    }

    /// Scan period in µs (6144).
    pub fn scan_us(&self) -> u32 {
        self.scan_us
    }

    /// FIN copy period in µs (512).
    pub fn fin_period_us(&self) -> u32 {
        self.fin_period_us
    }

    /// Whether the PLC runs (b99.13 = 1).
    pub fn running(&self, mem: &Memory) -> bool {
        mem.bit(self.run_bit)
    }

    /// One scan: inputs (bit i = digital input i) in, outputs (bit j = digital output j) out.
    pub fn scan(
        &self,
        state: &mut PlcState,
        mem: &mut Memory,
        program: &Program,
        inputs: u16,
    ) -> u16 {
        let mut outputs = 0;
        for step in &self.scan_order {
            match step {
                ScanStep::ReadInputs => {
                    for (i, b) in &self.inputs {
                        mem.set_bit(*b, inputs >> i & 1 == 1);
                    }
                }
                ScanStep::UpdateTimers => {
                    for (slot, status) in &self.timers {
                        let old = mem.get(slot.addr, slot.size);
                        let new = old.saturating_sub(1);
                        mem.set(slot.addr, slot.size, new);
                        let expired = if self.timer_flag_same_update {
                            new == 0
                        } else {
                            old == 0
                        };
                        mem.set_bit(*status, expired);
                    }
                }
                ScanStep::RunProgram => {
                    if self.running(mem) {
                        self.run(state, mem, program);
                    }
                }
                ScanStep::WriteOutputs => {
                    for (j, b) in &self.outputs {
                        if mem.bit(*b) {
                            outputs |= 1u16.checked_shl(u32::from(*j)).unwrap_or(0);
                        }
                    }
                }
            }
        }
        outputs
    }

    /// The FIN copies (manual 3.8.1): the first three instructions, if FIN, copy inputs 1–3.
    pub fn fast_inputs(&self, mem: &mut Memory, program: &Program, inputs: u16) {
        if !self.running(mem) {
            return;
        }
        for slot in &self.fin_slots {
            let Some((_, instr)) = program.instrs.get(slot.index) else {
                return;
            };
            let Operands::Fin { y, n, .. } = instr.operands else {
                return;
            };
            if mem.bit(slot.disable) == self.fin_disabled_at {
                continue;
            }
            let Some(target) = self.fin_targets.get(usize::from(n & 1)) else {
                continue;
            };
            let Some(b) = self.map.bit(*target, y) else {
                continue;
            };
            let level = inputs >> slot.input & 1 == 1;
            mem.set_bit(b, level != (n & 2 != 0));
        }
    }

    /// Runs the program once.
    fn run(&self, state: &mut PlcState, mem: &mut Memory, program: &Program) {
        for (_, instr) in &program.instrs {
            if self.codec.is_end(instr) {
                return;
            }
            self.exec(state, mem, instr);
        }
    }

    fn exec(&self, state: &mut PlcState, mem: &mut Memory, instr: &Instr) {
        let Some(spec) = self.codec.plc().instruction(instr.code) else {
            return;
        };
        match instr.operands {
            Operands::Bit { pa, y } => {
                let Some(b) = self.map.bit(pa, y) else { return };
                let bit = mem.bit(b) != spec.invert;
                match spec.operation {
                    Operation::Load => state.stack = bit,
                    Operation::And => state.stack &= bit,
                    Operation::Or => state.stack |= bit,
                    Operation::Out => mem.set_bit(b, state.stack != spec.invert),
                    Operation::Set if state.stack => mem.set_bit(b, true),
                    Operation::Reset if state.stack => mem.set_bit(b, false),
                    _ => {}
                }
            }
            Operands::Arith { pa, pb, pc, .. } => {
                if self.requires_stack && !state.stack {
                    return;
                }
                self.arith(mem, spec.operation, pa, pb, pc);
            }
            // FIN copies run on their own period; END ends the scan.
            Operands::Fin { .. } | Operands::None { .. } => {}
        }
    }

    fn arith(&self, mem: &mut Memory, op: Operation, pa: u8, pb: u8, pc: u8) {
        let forced = mem.bit(self.dword_force);
        let is = |set: &[bool; 256], n: u8| set.get(usize::from(n)).copied().unwrap_or(false);
        let constant = |n: u8| self.constant.get(usize::from(n)).copied().flatten();
        if [pa, pb, pc].iter().any(|n| is(&self.forbidden, *n)) {
            return;
        }
        let dword = |n: u8| forced || is(&self.dword_param, n);
        let read = |n: u8| -> Option<i64> {
            if let Some(c) = constant(n) {
                return Some(c);
            }
            let s = self.map.slot(n)?;
            Some(i64::from(if dword(n) {
                mem.get_signed(s.addr, 4)
            } else {
                mem.get_signed(s.addr, 2)
            }))
        };
        let (Some(a), Some(b)) = (read(pa), read(pb)) else {
            return;
        };
        // A result written to a constant only sets the flags (3.8.1).
        let out = match (constant(pc), self.map.slot(pc)) {
            (Some(_), _) if self.constant_result_discarded => None,
            (_, Some(slot)) => Some(slot),
            _ => return,
        };
        let wide = dword(pc);
        let (result, high) = match op {
            Operation::Add => (a.wrapping_add(b), None),
            Operation::Sub => (a.wrapping_sub(b), None),
            Operation::Mul => (a.wrapping_mul(b), None),
            Operation::Div if b == 0 => return,
            Operation::Div if wide && self.div_remainder_high => {
                (a.wrapping_div(b), Some(a.wrapping_rem(b)))
            }
            Operation::Div => (a.wrapping_div(b), None),
            _ => return,
        };
        let stored = match (wide, high) {
            (true, Some(rem)) => {
                let q = result as i16;
                if let Some(out) = out {
                    mem.set(out.addr, 2, u32::from(q as u16));
                    mem.set(out.addr.wrapping_add(2), 2, u32::from(rem as i16 as u16));
                }
                i64::from(q)
            }
            (true, None) => {
                let v = result as i32;
                if let Some(out) = out {
                    mem.set(out.addr, 4, v as u32);
                }
                i64::from(v)
            }
            (false, _) => {
                let v = result as i16;
                if let Some(out) = out {
                    mem.set(out.addr, 2, u32::from(v as u16));
                }
                i64::from(v)
            }
        };
        mem.set_bit(self.negative, stored < 0);
        let zero_set = match self.zero_flag {
            ZeroFlag::SetWhenZero => stored == 0,
            ZeroFlag::SetWhenNonZero => stored != 0,
        };
        mem.set_bit(self.zero, zero_set);
        if forced && self.dword_force_reset {
            mem.set_bit(self.dword_force, false);
        }
    }
}
