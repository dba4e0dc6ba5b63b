//! The status of the positioning core as named flags, and their bit numbers in a family's
//! status word (PSD4xx manual 3.6; PSx3xx manual 3.4).
//!
//! The core sets and resets [`Flag`]s; a [`BitMap`] places them in the wire word. The bit
//! numbers are never typed here: [`BitMap::from_bitfield`] finds each flag's bit as the bit of
//! the spec bitfield whose rules carry a requirement ID the family names (e.g. "the bit with
//! rule PSD-STS-10-SET-1 is the obstruction flag"), and priorities (PSD-STS-0-PRIO: bit 0 over
//! bit 10) come from the rules' `priority_over`.

use drivespec_spec::Bitfield;
use serde::{Deserialize, Serialize};
use std::fmt;

/// One status flag of the positioning core (PSD4xx 3.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Flag {
    /// Target position reached (PSD bit 0) (3.6).
    Reached,
    /// Echo of the control word's toggle bit (PSD bit 2) (3.6).
    Toggle,
    /// Motor supply in range (PSD bit 4) (3.6).
    MotorOk,
    /// Positioning run aborted (PSD bit 5) (3.6).
    Aborted,
    /// Drive is running (PSD bit 6) (3.6).
    Running,
    /// Temperature too high (PSD bit 7) (3.6).
    OverTemp,
    /// Last run against the loop direction, lash may be present (PSD bit 8) (3.6).
    AgainstLoop,
    /// Internal position error (PSD bit 9) (3.6).
    Error,
    /// Positioning error: obstruction or target missed twice (PSD bit 10) (3.6).
    Obstruction,
    /// Rotated externally at standstill (PSD bit 11) (3.6).
    ManualRotation,
    /// Incorrect target value (PSD bit 12) (3.6).
    BadTarget,
    /// Motor voltage was missing (PSD bit 13) (3.6).
    VoltageMissing,
    /// At or beyond the upper limit (PSD bit 14) (3.6).
    UpperLimit,
    /// At or beyond the lower limit (PSD bit 15) (3.6).
    LowerLimit,
}

impl Flag {
    /// Every flag, in the order of the PSD4xx status word (3.6).
    pub const ALL: [Flag; 14] = [
        Flag::Reached,
        Flag::Toggle,
        Flag::MotorOk,
        Flag::Aborted,
        Flag::Running,
        Flag::OverTemp,
        Flag::AgainstLoop,
        Flag::Error,
        Flag::Obstruction,
        Flag::ManualRotation,
        Flag::BadTarget,
        Flag::VoltageMissing,
        Flag::UpperLimit,
        Flag::LowerLimit,
    ];

    fn mask(self) -> u16 {
        1 << (self as u16)
    }

    /// Kebab-case name (PSD4xx 3.6).
    pub fn as_str(self) -> &'static str {
        match self {
            Flag::Reached => "reached",
            Flag::Toggle => "toggle",
            Flag::MotorOk => "motor-ok",
            Flag::Aborted => "aborted",
            Flag::Running => "running",
            Flag::OverTemp => "over-temp",
            Flag::AgainstLoop => "against-loop",
            Flag::Error => "error",
            Flag::Obstruction => "obstruction",
            Flag::ManualRotation => "manual-rotation",
            Flag::BadTarget => "bad-target",
            Flag::VoltageMissing => "voltage-missing",
            Flag::UpperLimit => "upper-limit",
            Flag::LowerLimit => "lower-limit",
        }
    }
}

impl fmt::Display for Flag {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A set of [`Flag`]s (PSD4xx 3.6).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Flags(u16);

impl Flags {
    /// Whether `f` is set (PSD4xx 3.6).
    pub fn get(self, f: Flag) -> bool {
        self.0 & f.mask() != 0
    }

    /// Sets or resets `f` (PSD4xx 3.6).
    pub fn put(&mut self, f: Flag, on: bool) {
        if on {
            self.0 |= f.mask();
        } else {
            self.0 &= !f.mask();
        }
    }

    /// The flags set, in [`Flag::ALL`] order (PSD4xx 3.6).
    pub fn iter(self) -> impl Iterator<Item = Flag> {
        Flag::ALL.into_iter().filter(move |f| self.get(*f))
    }
}

/// Why a bit map cannot be built from a spec bitfield (PSD4xx 3.6).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum BitMapError {
    /// No bit of the bitfield has a rule with this requirement ID (3.6).
    #[error("bitfield {bitfield}: no bit has a rule with requirement {requirement}")]
    NoRule {
        /// Bitfield id.
        bitfield: String,
        /// The requirement ID looked for.
        requirement: String,
    },
    /// Two flags map to the same bit (3.6).
    #[error("bitfield {bitfield}: bit {bit} named for two flags")]
    Shared {
        /// Bitfield id.
        bitfield: String,
        /// The bit.
        bit: u32,
    },
}

/// Bit numbers of the flags in a family's status word, and the priorities between them
/// (PSD4xx 3.6, PSD-STS-0-PRIO).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct BitMap {
    bits: Vec<(Flag, u32)>,
    priorities: Vec<(Flag, Flag)>,
}

impl BitMap {
    /// Finds each flag's bit as the bit whose rules include the given requirement ID, and the
    /// priorities from the rules' `priority_over` (PSD4xx 3.6).
    pub fn from_bitfield(bf: &Bitfield, flags: &[(Flag, &str)]) -> Result<BitMap, BitMapError> {
        let mut bits: Vec<(Flag, u32)> = Vec::with_capacity(flags.len());
        for (flag, req) in flags {
            let bit = bf
                .bits
                .iter()
                .find(|b| b.rules.iter().any(|r| r.requirement == *req))
                .map(|b| b.bit)
                .ok_or_else(|| BitMapError::NoRule {
                    bitfield: bf.id.clone(),
                    requirement: (*req).to_owned(),
                })?;
            if bits.iter().any(|(_, b)| *b == bit) {
                return Err(BitMapError::Shared {
                    bitfield: bf.id.clone(),
                    bit,
                });
            }
            bits.push((*flag, bit));
        }
        let mut priorities = Vec::new();
        for (winner, bit) in &bits {
            let Some(b) = bf.bit(*bit) else { continue };
            for rule in &b.rules {
                for lost in &rule.priority_over {
                    if let Some((loser, _)) = bits.iter().find(|(_, n)| n == lost) {
                        if !priorities.contains(&(*winner, *loser)) {
                            priorities.push((*winner, *loser));
                        }
                    }
                }
            }
        }
        Ok(BitMap { bits, priorities })
    }

    /// The bit of a flag, None when the family has no such bit (PSD4xx 3.6).
    pub fn bit(&self, flag: Flag) -> Option<u32> {
        self.bits.iter().find(|(f, _)| *f == flag).map(|(_, b)| *b)
    }

    /// Pairs (winner, loser) where the winner has priority when both would be set
    /// (PSD-STS-0-PRIO).
    pub fn priorities(&self) -> &[(Flag, Flag)] {
        &self.priorities
    }

    /// The status word of a set of flags (PSD4xx 3.6).
    pub fn word(&self, flags: Flags) -> u64 {
        self.bits
            .iter()
            .filter(|(f, b)| flags.get(*f) && *b < 64)
            .fold(0, |w, (_, b)| w | 1u64 << b)
    }

    /// The flags of a status word (PSD4xx 3.6).
    pub fn flags(&self, word: u64) -> Flags {
        let mut flags = Flags::default();
        for (f, b) in &self.bits {
            if *b < 64 && word >> b & 1 == 1 {
                flags.put(*f, true);
            }
        }
        flags
    }
}
