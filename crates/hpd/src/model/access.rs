//! Writing and reading parameters (manual 4.1, 4.2, 3.3, 3.6): which serial writes the drive
//! takes, and direct access for tests and simulators.
//!
//! Decisions where the manual is silent, each marked DECISION below: a refused write changes
//! nothing and is acknowledged, or not answered under the `silent` reading of HPD-ERRATUM-069
//! (see `serial.rs`); a write must cover whole parameters
//! (one, or several consecutive ones such as a double word), a bit change may address any
//! byte of one parameter.

use super::drive::Drive;
use super::error::ModelError;
use super::layout::sign_extend;
use crate::line::Micros;
use crate::memory::{BitAddr, Memory};
use crate::params::Target;
use drivespec_spec::Ranges;
use std::sync::Arc;

impl Drive {
    /// Pr31, the operating mode in force (manual 3.6).
    pub(super) fn mode(&self) -> u32 {
        let s = self.layout.named.mode;
        self.working.get(s.addr, s.size)
    }

    /// Whether security b99.7 blocks serial writes and commands (HPD-ERRATUM-011 reading).
    pub(super) fn secured(&self) -> bool {
        self.layout.options.security_serial && self.working.bit(self.layout.named.security)
    }

    /// A parameter write or broadcast of `bytes` at serial address `par` (manual 4.1 CMD 5, 7);
    /// returns whether the drive took it.
    pub(super) fn write_bytes(&mut self, par: u8, bytes: &[u8]) -> bool {
        let layout = Arc::clone(&self.layout);
        let start = usize::from(par);
        let Some(end) = start.checked_add(bytes.len()).filter(|e| *e <= 256) else {
            return false;
        };
        let mut updates = Vec::new();
        let mut at = start;
        while at < end {
            // DECISION: bytes that are not whole parameters of table 4.2 are ignored.
            let Some((index, p)) = layout.owner(at) else {
                return false;
            };
            let size = usize::from(p.slot.size);
            if usize::from(p.slot.addr) != at || at + size > end {
                return false;
            }
            let raw = bytes
                .get(at - start..at - start + size)
                .unwrap_or(&[])
                .iter()
                .rev()
                .fold(0u32, |v, b| v << 8 | u32::from(*b));
            let Some(new) = self.accept(index, raw) else {
                return false;
            };
            updates.push((p.slot, new));
            at += size;
        }
        for (slot, raw) in updates {
            self.working.set(slot.addr, slot.size, raw);
        }
        true
    }

    /// A bit change on the byte at `par` (HPD-FRAME-017, HPD-FRAME-018); returns whether the
    /// drive took it.
    pub(super) fn bit_change(&mut self, par: u8, mask: u8, value: u8) -> bool {
        let layout = Arc::clone(&self.layout);
        let Some((index, p)) = layout.owner(usize::from(par)) else {
            return false;
        };
        let old = self.working.get(p.slot.addr, p.slot.size);
        let shift = 8 * u32::from(par.saturating_sub(p.slot.addr));
        let byte = (old >> shift) as u8;
        let byte = (byte & mask) | (value & !mask);
        let raw = (old & !(0xFF << shift)) | u32::from(byte) << shift;
        match self.accept(index, raw) {
            Some(new) => {
                self.working.set(p.slot.addr, p.slot.size, new);
                true
            }
            None => false,
        }
    }

    /// The value parameter `index` takes when the master writes `raw`, None when refused.
    fn accept(&self, index: usize, raw: u32) -> Option<u32> {
        let layout = &self.layout;
        let p = layout.params.get(index)?;
        let old = self.working.get(p.slot.addr, p.slot.size);
        // HPD-PAR-053, HPD-PAR-024, HPD-PAR-025, HPD-PAR-034: read-only parameters
        // cannot be written. DECISION: the write is ignored.
        if !p.writable {
            return None;
        }
        // HPD-MODE-2-003, HPD-MODE-10-005: a parameter read-only in the mode in force.
        if p.mode(self.mode()).is_some_and(|m| !m.writable) {
            return None;
        }
        if self.locked_by_profile(p.slot) {
            return None;
        }
        // HPD-BIT-99-7, HPD-BIT-99-7-SELF: with security on, only b99.7 itself can change.
        if self.secured() {
            let sec = layout.named.security;
            let offset = sec.byte.checked_sub(p.slot.addr)?;
            if offset >= p.slot.size {
                return None;
            }
            let bit = u32::from(sec.mask) << (8 * u32::from(offset));
            return Some((old & !bit) | (raw & bit));
        }
        if p.is_bits {
            // Bits the drive owns (inputs, flags, status) keep their value; HPD-BIT-40-15:
            // bits that must remain 0 stay 0.
            let (readonly, zero) = layout.fixed_bits(index, self.mode());
            return Some(((raw & !readonly) | (old & readonly)) & !zero);
        }
        // HPD-PAR-009, HPD-MODE-005: values inside the range (per operating mode for
        // Pr50–Pr69) are taken. DECISION: a value outside the range is ignored, not clamped.
        let value = p.value(raw);
        if self.range_of(index).is_some_and(|r| !r.contains(value)) {
            return None;
        }
        Some(raw)
    }

    /// The allowed raw values of parameter `index` now (manual 3.3, 3.6).
    fn range_of(&self, index: usize) -> Option<&Ranges> {
        let layout = &self.layout;
        let p = layout.params.get(index)?;
        // HPD-MODE-001: Pr31 takes the documented modes, or any byte (HPD-ERRATUM-014).
        if p.slot == layout.named.mode && layout.options.mode_any_byte {
            return p.bounds.as_ref();
        }
        match p.mode(self.mode()).and_then(|m| m.range.as_ref()) {
            Some(r) => Some(r),
            None => p.range.as_ref(),
        }
    }

    /// Writes PLC area bytes (HPD-FRAME-013).
    pub(super) fn write_plc(&mut self, range: std::ops::Range<usize>, bytes: &[u8]) {
        // HPD-BIT-99-13: instructions change only while the PLC is stopped.
        // DECISION: a PLC write while b99.13 = 1 is ignored (and acknowledged).
        if self.layout.runtime.running(&self.working) {
            return;
        }
        // DECISION: security b99.7 protects the PLC program as it protects parameters.
        if self.secured() {
            return;
        }
        if let Some(dst) = self.plc.get_mut(range) {
            if dst.len() == bytes.len() {
                dst.copy_from_slice(bytes);
            }
        }
        // The program is decoded again whenever the area changes (manual 3.8.1).
        self.recache_program();
    }

    /// The working value of a parameter, double word or bit (manual 4.2, 3.8.1).
    pub fn value(&self, target: &Target) -> Result<i64, ModelError> {
        read(&self.working, target)
    }

    /// The value in the parameter save image (manual 3.4 b99.15).
    pub fn saved_value(&self, target: &Target) -> Result<i64, ModelError> {
        read(&self.saved, target)
    }

    /// Sets a working value at `now` directly, as the drive's own measurements or its keypad
    /// would: no serial access rule applies (manual 3.1, 3.3). A command set this way runs.
    pub fn set_value(
        &mut self,
        now: Micros,
        target: &Target,
        value: i64,
    ) -> Result<(), ModelError> {
        self.advance(now);
        let (addr, size) = target.address()?;
        match *target {
            Target::Bit(p, bit) => {
                let byte = u8::try_from(bit / 8)
                    .ok()
                    .and_then(|b| addr.checked_add(b))
                    .ok_or_else(|| ModelError::Spec {
                        what: format!("bit {bit} of {} lies past address 0xFF", p.id),
                    })?;
                let mask = 1u8 << (bit % 8);
                self.working.set_bit(BitAddr { byte, mask }, value != 0);
            }
            _ => self.working.set(addr, size, value as u32),
        }
        self.service(self.clock);
        Ok(())
    }

    /// Raises alarm `code` at `now` (manual 3.3): Pr23 and Pr24 show it until the alarm reset.
    pub fn raise_alarm(&mut self, now: Micros, code: u8) -> Result<(), ModelError> {
        self.advance(now);
        if code == 0 || self.layout.alarm(code).is_none() {
            return Err(ModelError::Alarm { code });
        }
        // HPD-ALARM-001, HPD-ALARM-003: Pr23 shows the active alarm, Pr24 keeps the last one.
        self.set_alarms(code, code);
        self.service(self.clock);
        Ok(())
    }

    /// Sets Pr23 and Pr24.
    pub(super) fn set_alarms(&mut self, active: u8, last: u8) {
        let n = &self.layout.named;
        let (a, l) = (n.alarm, n.last_alarm);
        self.working.set(a.addr, a.size, u32::from(active));
        self.working.set(l.addr, l.size, u32::from(last));
    }
}

/// A parameter, double word or bit from `mem`, signed as the parameter is.
fn read(mem: &Memory, target: &Target) -> Result<i64, ModelError> {
    let (addr, size) = target.address()?;
    let raw = mem.get(addr, size);
    Ok(match *target {
        Target::Bit(_, bit) => i64::from(raw.checked_shr(bit).unwrap_or(0) & 1),
        Target::Double(..) => sign_extend(raw, 4),
        Target::Param(p) if p.data_type.signed() => sign_extend(raw, size),
        Target::Param(_) => i64::from(raw),
    })
}
