//! The listing form of PLC instructions (manual 3.8.1, appendix G): `LD 90.1`, `ORN 90.10`,
//! `ADD 92,78,92`, `FIN 3,1`, `END`.

use super::codec::{Instr, Operands, PlcCodec};
use drivespec_spec::hpd::OperandForm;
use drivespec_spec::quote::quote;
use std::fmt::Write as _;

/// Why a listing line is not an instruction.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum ListingError {
    /// Unknown mnemonic.
    #[error("line {line}: unknown instruction {}", quote(.mnemonic))]
    Mnemonic {
        /// 1-based line.
        line: usize,
        /// The word found.
        mnemonic: String,
    },
    /// Operands not of the instruction's form.
    #[error("line {line}: {} takes {expected}, found {}", quote(.mnemonic), quote(.found))]
    Operands {
        /// 1-based line.
        line: usize,
        /// The instruction.
        mnemonic: String,
        /// The form expected.
        expected: &'static str,
        /// The text found.
        found: String,
    },
}

impl PlcCodec {
    /// Parses one listing line (without comment); `line` numbers errors.
    pub fn parse_line(&self, text: &str, line: usize) -> Result<Instr, ListingError> {
        let text = text.trim();
        let (word, rest) = text.split_once(char::is_whitespace).unwrap_or((text, ""));
        let spec = self
            .plc()
            .by_mnemonic(word)
            .ok_or_else(|| ListingError::Mnemonic {
                line,
                mnemonic: word.to_owned(),
            })?;
        let syntax = &self.plc().listing;
        let bad = |expected: &'static str| ListingError::Operands {
            line,
            mnemonic: spec.mnemonic.clone(),
            expected,
            found: rest.trim().to_owned(),
        };
        let numbers = |expected: &'static str, count: usize| -> Result<Vec<u8>, ListingError> {
            let mut t = rest.trim().to_owned();
            for sep in &syntax.accepted_separators {
                t = t.replace(sep.as_str(), " ");
            }
            let parts: Vec<u8> = t
                .split_whitespace()
                .map(str::parse::<u8>)
                .collect::<Result<_, _>>()
                .map_err(|_| bad(expected))?;
            if parts.len() == count {
                Ok(parts)
            } else {
                Err(bad(expected))
            }
        };
        let operands = match spec.operands {
            OperandForm::Bit => {
                let (pa, y) = rest
                    .trim()
                    .split_once(syntax.bit_separator.as_str())
                    .ok_or_else(|| bad("Pa.y"))?;
                let pa = pa.trim().parse().map_err(|_| bad("Pa.y"))?;
                let y: u8 = y.trim().parse().map_err(|_| bad("Pa.y"))?;
                if y > self.plc().encoding.y_mask {
                    return Err(bad("Pa.y with y in 0..=15"));
                }
                Operands::Bit { pa, y }
            }
            OperandForm::Arith => match numbers("Pa,Pb,Pc", 3)?.as_slice() {
                [pa, pb, pc] => Operands::Arith {
                    pa: *pa,
                    pb: *pb,
                    pc: *pc,
                    spare: 0,
                },
                _ => return Err(bad("Pa,Pb,Pc")),
            },
            OperandForm::Fin => match numbers("y,n", 2)?.as_slice() {
                [y, n] if *n <= 3 => Operands::Fin {
                    y: *y,
                    n: *n,
                    spare: 0,
                },
                _ => return Err(bad("y,n with n in 0..=3")),
            },
            OperandForm::None => {
                if !rest.trim().is_empty() {
                    return Err(bad("no operand"));
                }
                Operands::None {
                    spare: 0,
                    spare1: self.plc().encoding.unused_fill,
                }
            }
        };
        Ok(Instr {
            code: spec.code,
            operands,
        })
    }

    /// The canonical listing line of an instruction.
    pub fn format(&self, instr: &Instr) -> String {
        let syntax = &self.plc().listing;
        let sep = syntax.operand_separator.as_str();
        let mut s = self.mnemonic(instr.code).to_owned();
        let _ = match instr.operands {
            Operands::Bit { pa, y } => write!(s, " {pa}{}{y}", syntax.bit_separator),
            Operands::Arith { pa, pb, pc, .. } => write!(s, " {pa}{sep}{pb}{sep}{pc}"),
            Operands::Fin { y, n, .. } => write!(s, " {y}{sep}{n}"),
            Operands::None { .. } => Ok(()),
        };
        s
    }
}
