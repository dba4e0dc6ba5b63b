//! The HPD parameter memory by serial address (manual 4.2) and the PLC area (4.1).

use drivespec_spec::{Family, FamilyId, Spec};

/// Where a parameter lives: serial address and byte count (manual 4.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slot {
    /// Serial address.
    pub addr: u8,
    /// Bytes (1, 2 or 4).
    pub size: u8,
}

/// A bit of a parameter: byte address and mask.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BitAddr {
    /// Serial address of the byte holding the bit.
    pub byte: u8,
    /// The bit within that byte.
    pub mask: u8,
}

/// Parameter numbers to serial slots, from the spec (manual 4.2).
#[derive(Debug, Clone)]
pub struct ParamMap {
    slots: [Option<Slot>; 256],
}

impl ParamMap {
    /// Reads every HPD parameter's address and length from the spec.
    pub fn from_spec(spec: &Spec) -> ParamMap {
        ParamMap::from_family(spec.family(FamilyId::Hpd))
    }

    /// Reads every parameter's address and length from the HPD family.
    pub fn from_family(family: &Family) -> ParamMap {
        let mut slots = [None; 256];
        for p in &family.parameters {
            let (Some(addr), Some(size)) = (p.address, p.size) else {
                continue;
            };
            let (Ok(addr), Ok(size)) = (u8::try_from(addr), u8::try_from(size)) else {
                continue;
            };
            if let Some(slot) = usize::try_from(p.number)
                .ok()
                .and_then(|n| slots.get_mut(n))
            {
                *slot = Some(Slot { addr, size });
            }
        }
        ParamMap { slots }
    }

    /// The slot of parameter number `n`.
    pub fn slot(&self, n: u8) -> Option<Slot> {
        self.slots.get(usize::from(n)).copied().flatten()
    }

    /// Bit `y` of parameter `n` (bits 8–15 in the byte at address + 1).
    pub fn bit(&self, n: u8, y: u8) -> Option<BitAddr> {
        let s = self.slot(n)?;
        let byte_in = y / 8;
        if byte_in >= s.size {
            return None;
        }
        Some(BitAddr {
            byte: s.addr.checked_add(byte_in)?,
            mask: 1 << (y % 8),
        })
    }

    /// Parses `b99.13` / `Pb99.13` into parameter number and bit.
    pub fn parse_bit(text: &str) -> Option<(u8, u8)> {
        let t = text
            .trim()
            .trim_start_matches(|c: char| c.is_ascii_alphabetic());
        let (n, y) = t.split_once('.')?;
        Some((n.parse().ok()?, y.parse().ok()?))
    }

    /// Parses `Pr92` / `Pb40` / `92` into a parameter number.
    pub fn parse_param(text: &str) -> Option<u8> {
        text.trim()
            .trim_start_matches(|c: char| c.is_ascii_alphabetic())
            .parse()
            .ok()
    }
}

/// 256 bytes of parameter memory addressed by serial address; values little-endian.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Memory {
    bytes: [u8; 256],
}

impl Default for Memory {
    fn default() -> Self {
        Memory { bytes: [0; 256] }
    }
}

impl Memory {
    /// `len` bytes (≤ 4) at `addr` as an unsigned value; bytes past 0xFF read as 0.
    pub fn get(&self, addr: u8, len: u8) -> u32 {
        (0..len.min(4)).fold(0u32, |v, i| {
            let b = usize::from(addr)
                .checked_add(usize::from(i))
                .and_then(|a| self.bytes.get(a))
                .copied()
                .unwrap_or(0);
            v | u32::from(b) << (8 * u32::from(i))
        })
    }

    /// `len` bytes at `addr`, sign-extended.
    pub fn get_signed(&self, addr: u8, len: u8) -> i32 {
        let len = len.clamp(1, 4);
        let shift = 32 - 8 * u32::from(len);
        ((self.get(addr, len) << shift) as i32) >> shift
    }

    /// Writes the low `len` bytes of `value` at `addr`; bytes past 0xFF are dropped.
    pub fn set(&mut self, addr: u8, len: u8, value: u32) {
        for i in 0..len.min(4) {
            if let Some(b) = usize::from(addr)
                .checked_add(usize::from(i))
                .and_then(|a| self.bytes.get_mut(a))
            {
                *b = (value >> (8 * u32::from(i))) as u8;
            }
        }
    }

    /// One bit.
    pub fn bit(&self, b: BitAddr) -> bool {
        self.bytes
            .get(usize::from(b.byte))
            .is_some_and(|v| v & b.mask != 0)
    }

    /// Sets or clears one bit.
    pub fn set_bit(&mut self, b: BitAddr, on: bool) {
        if let Some(v) = self.bytes.get_mut(usize::from(b.byte)) {
            if on {
                *v |= b.mask;
            } else {
                *v &= !b.mask;
            }
        }
    }

    /// Applies a bit-change message: bits where `mask` is 0 take their value from `value`.
    pub fn bit_change(&mut self, addr: u8, mask: u8, value: u8) {
        if let Some(v) = self.bytes.get_mut(usize::from(addr)) {
            *v = (*v & mask) | (value & !mask);
        }
    }

    /// All 256 bytes.
    pub fn bytes(&self) -> &[u8; 256] {
        &self.bytes
    }
}
