//! PLC instructions as bytes (manual 4.1): code in b0–b3 of byte 0, operands per the
//! instruction's form. Bits the manual leaves unused are kept, so any byte string that
//! decodes re-encodes to the same bytes.

use drivespec_spec::hpd::{OperandForm, Plc};

/// Why PLC bytes or text are not a valid instruction or program (manual 3.8.1, 4.1).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PlcError {
    /// The bytes end inside an instruction.
    #[error("instruction at {address:#04x} needs {need} bytes, {have} left")]
    Truncated {
        /// Program address of the instruction.
        address: usize,
        /// Its length.
        need: usize,
        /// Bytes left.
        have: usize,
    },
    /// No instruction has this code.
    #[error("no instruction has code {code}")]
    UnknownCode {
        /// The code.
        code: u8,
    },
    /// The program does not end with END.
    #[error("program has no END within {limit} bytes")]
    NoEnd {
        /// Bytes searched.
        limit: usize,
    },
    /// The program is larger than the PLC area.
    #[error("program of {bytes} bytes exceeds the {limit}-byte PLC area")]
    TooLong {
        /// Bytes of the program.
        bytes: usize,
        /// Size of the area.
        limit: usize,
    },
    /// An operand out of range for its field.
    #[error("{what} {value} out of range 0..={max}")]
    Operand {
        /// Which operand.
        what: &'static str,
        /// Value given.
        value: u32,
        /// Largest allowed.
        max: u32,
    },
}

/// Operands of an instruction, in the form its code prescribes (manual 4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Operands {
    /// `Pa.y`: bit y of parameter Pa.
    Bit {
        /// Parameter number.
        pa: u8,
        /// Bit number.
        y: u8,
    },
    /// `Pa,Pb,Pc`.
    Arith {
        /// First operand.
        pa: u8,
        /// Second operand.
        pb: u8,
        /// Result.
        pc: u8,
        /// The unused high nibble of byte 0.
        spare: u8,
    },
    /// `FIN y,n`: n bit 0 selects Pb40/Pb70, n bit 1 inverts the input.
    Fin {
        /// Bit of the target parameter.
        y: u8,
        /// 0…3.
        n: u8,
        /// Unused bits of byte 0 above the invert bit.
        spare: u8,
    },
    /// END.
    None {
        /// The unused high nibble of byte 0.
        spare: u8,
        /// The unused byte 1.
        spare1: u8,
    },
}

/// One PLC instruction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Instr {
    /// Instruction code (b0–b3 of byte 0).
    pub code: u8,
    /// Operands.
    pub operands: Operands,
}

/// PLC bytes addressed outside the program area (3.8.1, 4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct OutsideArea {
    /// First byte addressed.
    pub first: u8,
    /// Last byte addressed.
    pub last: usize,
    /// First byte of the area.
    pub area_first: u8,
    /// Last byte of the area.
    pub area_last: u8,
}

impl std::fmt::Display for OutsideArea {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "PLC bytes 0x{:02X}-0x{:02X} lie outside the PLC area 0x{:02X}-0x{:02X}",
            self.first, self.last, self.area_first, self.area_last
        )
    }
}

/// Encodes and decodes PLC instructions with the spec's instruction table.
#[derive(Debug, Clone)]
pub struct PlcCodec {
    plc: Plc,
}

impl PlcCodec {
    /// Reads the instruction set from the spec (manual 4.1).
    pub fn from_spec(spec: &drivespec_spec::Spec) -> Option<PlcCodec> {
        let p = spec.family(drivespec_spec::FamilyId::Hpd).hpd()?;
        Some(PlcCodec { plc: p.plc.clone() })
    }

    /// The spec's PLC table.
    pub fn plc(&self) -> &Plc {
        &self.plc
    }

    /// The PLC bytes `at`…`at + len − 1` when they reach outside the program area (3.8.1,
    /// 4.1: 0x00–0x7F); `None` inside it.
    pub fn outside_area(&self, at: u8, len: usize) -> Option<OutsideArea> {
        let last = usize::from(at) + len.max(1) - 1;
        (at < self.plc.first_address || last > usize::from(self.plc.last_address)).then_some(
            OutsideArea {
                first: at,
                last,
                area_first: self.plc.first_address,
                area_last: self.plc.last_address,
            },
        )
    }

    /// Length in bytes of the instruction with `code`.
    pub fn length(&self, code: u8) -> Option<usize> {
        self.plc.instruction(code).map(|i| usize::from(i.length))
    }

    /// Decodes the instruction at the start of `bytes` (at program `address`); returns it and its length.
    pub fn decode(&self, bytes: &[u8], address: usize) -> Result<(Instr, usize), PlcError> {
        let e = &self.plc.encoding;
        let b0 = *bytes.first().ok_or(PlcError::Truncated {
            address,
            need: 2,
            have: 0,
        })?;
        let code = b0 & e.code_mask;
        let spec = self
            .plc
            .instruction(code)
            .ok_or(PlcError::UnknownCode { code })?;
        let need = usize::from(spec.length);
        let raw = bytes.get(..need).ok_or(PlcError::Truncated {
            address,
            need,
            have: bytes.len(),
        })?;
        let byte = |i: usize| raw.get(i).copied().unwrap_or(0);
        let high = (b0 >> e.y_shift) & e.y_mask;
        let fin = &self.plc.fast_inputs;
        let operands = match spec.operands {
            OperandForm::Bit => Operands::Bit {
                pa: byte(1),
                y: high,
            },
            OperandForm::Arith => Operands::Arith {
                pa: byte(1),
                pb: byte(2),
                pc: byte(3),
                spare: high,
            },
            OperandForm::Fin => {
                let sel = (b0 >> fin.select_bit) & 1;
                let inv = (b0 >> fin.invert_bit) & 1;
                let used = (1u8 << fin.select_bit) | (1u8 << fin.invert_bit) | e.code_mask;
                Operands::Fin {
                    y: byte(1),
                    n: sel | (inv << 1),
                    spare: b0 & !used,
                }
            }
            OperandForm::None => Operands::None {
                spare: high,
                spare1: byte(1),
            },
        };
        Ok((Instr { code, operands }, need))
    }

    /// Appends the bytes of `instr` to `out`.
    pub fn encode(&self, instr: &Instr, out: &mut Vec<u8>) -> Result<(), PlcError> {
        let e = &self.plc.encoding;
        let code = instr.code & e.code_mask;
        let nibble = |what: &'static str, v: u8| -> Result<u8, PlcError> {
            if v > e.y_mask {
                return Err(PlcError::Operand {
                    what,
                    value: u32::from(v),
                    max: u32::from(e.y_mask),
                });
            }
            Ok(v << e.y_shift)
        };
        match instr.operands {
            Operands::Bit { pa, y } => out.extend([code | nibble("bit", y)?, pa]),
            Operands::Arith { pa, pb, pc, spare } => {
                out.extend([code | nibble("spare", spare)?, pa, pb, pc])
            }
            Operands::Fin { y, n, spare } => {
                let fin = &self.plc.fast_inputs;
                if n > 3 {
                    return Err(PlcError::Operand {
                        what: "FIN n",
                        value: u32::from(n),
                        max: 3,
                    });
                }
                let b0 =
                    code | spare | ((n & 1) << fin.select_bit) | ((n >> 1 & 1) << fin.invert_bit);
                out.extend([b0, y]);
            }
            Operands::None { spare, spare1 } => {
                out.extend([code | nibble("spare", spare)?, spare1])
            }
        }
        Ok(())
    }

    /// The mnemonic of `code`.
    pub fn mnemonic(&self, code: u8) -> &str {
        self.plc
            .instruction(code)
            .map_or("?", |i| i.mnemonic.as_str())
    }
}
