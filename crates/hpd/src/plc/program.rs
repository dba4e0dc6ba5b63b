//! Whole PLC programs (manual 3.8.1, 4.1): at most 128 bytes / 64 instructions from address 0,
//! no gaps, ending with END; FIN honoured only as one of the first three instructions.

use super::codec::{Instr, Operands, PlcCodec, PlcError};
use super::listing::ListingError;
use drivespec_spec::hpd::{OperandForm, Operation};

/// A decoded program: instructions with their byte addresses, up to and including END.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Program {
    /// (address, instruction).
    pub instrs: Vec<(usize, Instr)>,
}

/// Something in a program the drive ignores or refuses (manual 3.8.1).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ProgramIssue {
    /// A FIN after the first three instructions or after another instruction: a no-op.
    #[error(
        "FIN at {address:#04x} is ignored: FIN counts only as one of the first three instructions"
    )]
    FinIgnored {
        /// Its address.
        address: usize,
    },
    /// An arithmetic operand that is a byte parameter.
    #[error("arithmetic at {address:#04x} uses byte parameter {param}, which the PLC refuses")]
    ByteOperand {
        /// Address of the instruction.
        address: usize,
        /// The parameter (`Pr31`).
        param: String,
    },
    /// The program does not end with END.
    #[error("the program does not end with END")]
    NoEnd,
    /// More instructions than the PLC holds.
    #[error("{count} instructions (arithmetic counts twice), more than the {limit} the PLC holds")]
    TooManyInstructions {
        /// Instructions counted (arithmetic counts as two).
        count: usize,
        /// The limit.
        limit: usize,
    },
}

impl PlcCodec {
    /// Decodes a program from the PLC area bytes; stops after END.
    pub fn decode_program(&self, bytes: &[u8]) -> Result<Program, PlcError> {
        let area = usize::from(self.plc().area_bytes);
        let bytes = bytes.get(..area.min(bytes.len())).unwrap_or(bytes);
        let mut instrs = Vec::new();
        let mut at = 0;
        while at < bytes.len() {
            let (instr, len) = self.decode(bytes.get(at..).unwrap_or(&[]), at)?;
            instrs.push((at, instr));
            at += len;
            if self.is_end(&instr) {
                return Ok(Program { instrs });
            }
        }
        Err(PlcError::NoEnd { limit: bytes.len() })
    }

    /// The bytes of a program.
    pub fn encode_program(&self, program: &Program) -> Result<Vec<u8>, PlcError> {
        let mut out = Vec::with_capacity(usize::from(self.plc().area_bytes));
        for (_, instr) in &program.instrs {
            self.encode(instr, &mut out)?;
        }
        let limit = usize::from(self.plc().area_bytes);
        if out.len() > limit {
            return Err(PlcError::TooLong {
                bytes: out.len(),
                limit,
            });
        }
        Ok(out)
    }

    /// Parses a listing: one instruction per line; `;` or `#` start a comment; blank lines
    /// and a leading address column (`00:` or `0x00`) are allowed.
    pub fn parse_listing(&self, text: &str) -> Result<Program, ListingError> {
        let mut instrs = Vec::new();
        let mut at = 0;
        for (i, raw) in text.lines().enumerate() {
            let line = raw.split([';', '#']).next().unwrap_or("").trim();
            let line = match line.split_once(':') {
                Some((addr, rest))
                    if addr
                        .trim()
                        .trim_start_matches("0x")
                        .chars()
                        .all(|c| c.is_ascii_hexdigit()) =>
                {
                    rest.trim()
                }
                _ => line,
            };
            if line.is_empty() {
                continue;
            }
            let instr = self.parse_line(line, i + 1)?;
            instrs.push((at, instr));
            at += self.length(instr.code).unwrap_or(2);
        }
        Ok(Program { instrs })
    }

    /// The listing of a program, one `address: instruction` line each.
    pub fn format_program(&self, program: &Program) -> String {
        program
            .instrs
            .iter()
            .map(|(a, i)| format!("{a:02X}: {}\n", self.format(i)))
            .collect()
    }

    /// Whether `instr` is END.
    pub fn is_end(&self, instr: &Instr) -> bool {
        matches!(instr.operands, Operands::None { .. })
            && self
                .plc()
                .instruction(instr.code)
                .is_some_and(|i| i.operands == OperandForm::None)
    }

    /// Whether `instr` is an arithmetic instruction.
    pub fn is_arith(&self, instr: &Instr) -> bool {
        self.plc().instruction(instr.code).is_some_and(|i| {
            matches!(
                i.operation,
                Operation::Add | Operation::Sub | Operation::Mul | Operation::Div
            )
        })
    }

    /// What the drive will ignore or refuse in `program` (manual 3.8.1).
    pub fn check(&self, program: &Program) -> Vec<ProgramIssue> {
        let plc = self.plc();
        let fin = &plc.fast_inputs;
        let mut issues = Vec::new();
        let mut leading = true;
        let mut count = 0usize;
        for (index, (address, instr)) in program.instrs.iter().enumerate() {
            count += if self.is_arith(instr) { 2 } else { 1 };
            match instr.operands {
                Operands::Fin { .. } => {
                    let honoured = leading
                        && index < usize::from(fin.max_count)
                        && *address <= usize::from(fin.last_address);
                    if !honoured {
                        issues.push(ProgramIssue::FinIgnored { address: *address });
                    }
                }
                Operands::Arith { pa, pb, pc, .. } => {
                    leading = false;
                    for p in [pa, pb, pc] {
                        let name = format!("Pr{p}");
                        let forbidden = plc
                            .arithmetic
                            .forbidden_params
                            .iter()
                            .any(|f| f == &name || f == &format!("Pb{p}"));
                        if forbidden {
                            issues.push(ProgramIssue::ByteOperand {
                                address: *address,
                                param: name,
                            });
                        }
                    }
                }
                _ => leading = false,
            }
        }
        if !program.instrs.last().is_some_and(|(_, i)| self.is_end(i)) {
            issues.push(ProgramIssue::NoEnd);
        }
        let limit = usize::from(plc.max_instructions);
        if count > limit {
            issues.push(ProgramIssue::TooManyInstructions { count, limit });
        }
        issues
    }
}

/// What a program reads and writes (manual 3.8.1): bits as `bNN.y`, words as `PrN`, in
/// program order without repeats.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct Effects {
    /// Bits and words the program reads.
    pub reads: Vec<String>,
    /// Bits and words the program writes.
    pub writes: Vec<String>,
}

impl PlcCodec {
    /// The bits and words `program` reads and writes.
    pub fn effects(&self, program: &Program) -> Effects {
        let mut fx = Effects::default();
        let add = |list: &mut Vec<String>, item: String| {
            if !list.contains(&item) {
                list.push(item);
            }
        };
        let ignored: Vec<usize> = self
            .check(program)
            .iter()
            .filter_map(|i| match i {
                ProgramIssue::FinIgnored { address } => Some(*address),
                _ => None,
            })
            .collect();
        for (address, instr) in &program.instrs {
            let Some(spec) = self.plc().instruction(instr.code) else {
                continue;
            };
            if ignored.contains(address) {
                continue;
            }
            match instr.operands {
                Operands::Bit { pa, y } => {
                    let bit = format!("b{pa}.{y}");
                    match spec.operation {
                        Operation::Out | Operation::Set | Operation::Reset => {
                            add(&mut fx.writes, bit)
                        }
                        _ => add(&mut fx.reads, bit),
                    }
                }
                Operands::Arith { pa, pb, pc, .. } => {
                    add(&mut fx.reads, format!("Pr{pa}"));
                    add(&mut fx.reads, format!("Pr{pb}"));
                    add(&mut fx.writes, format!("Pr{pc}"));
                }
                Operands::Fin { y, n, .. } => {
                    if let Some(target) = self.plc().fast_inputs.targets.get(usize::from(n & 1)) {
                        let number = target.trim_start_matches(|c: char| c.is_ascii_alphabetic());
                        add(&mut fx.writes, format!("b{number}.{y}"));
                    }
                }
                Operands::None { .. } => {}
            }
        }
        fx
    }
}
