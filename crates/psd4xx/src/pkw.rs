//! The PKW parameter channel (manual 3.8): the 8-byte block PKE | IND | PWE inside the process
//! data, its command, response and error codes, and typed requests and replies.
//!
//! - [`Pkw`] is the faithful representation of one block: AK (4 bits), SPM, PNU (11 bits),
//!   IND and PWE as on the wire. Every block decodes, unknown codes included, and re-encodes
//!   to the same bytes. [`PkwRequest`] and [`PkwResponse`] are the two directions.
//! - [`CommandCode`], [`ResponseCode`] and [`ErrorCode`] are open enums whose names come from
//!   the spec's tables ([`PkwRules::commands`] …).
//! - [`Request`] and [`Reply`] are what a block means: read, write (word or double word by the
//!   parameter's type), array element, count, value, error. [`PkwRules::request`] and
//!   [`PkwRules::encode_request`] convert; canonical blocks round-trip.
//! - The `--pkw` mini-syntax ([`PkwRules::parse_request`], [`PkwRules::parse_reply`]) is
//!   documented on [`RequestError`].
//!
//! Field positions (PKE bit ranges, the PWE word of 16-bit values, the IND layout) come from
//! the spec and the [`Options`]. Nothing here panics; parsing allocates nothing.

use crate::error::{DecodeError, EmitError, RequestError};
use crate::rules::Options;
use crate::value::{param_phrase, shown, Params, Width};
use crate::wire::{PkwFields, PkwLayout};

use drivespec_positioner::{open_enum, CodeEntry, CodeTable, WireCode};
use drivespec_spec::psd4xx::{
    BitRange, IndLayout, PkwOp, PkwValue, Protocol, StringAccess, WordFill, WordPosition,
};
use serde::{Deserialize, Serialize};

mod syntax;

pub use syntax::parse_number;

open_enum! {
    /// A PKW command code AK, controller → drive (manual 3.8 "Command code").
    pub struct CommandCode(u8);
    /// The command codes of the spec table, by name (manual 3.8).
    pub struct CommandCodes {
        /// 0: no command.
        no_command = "no-command",
        /// 1: require parameter value.
        read = "read",
        /// 2: change parameter value (word).
        write_word = "write-word",
        /// 3: change parameter value (double word).
        write_dword = "write-dword",
        /// 6: require parameter value (array).
        read_array = "read-array",
        /// 7: change parameter value (array word).
        write_array_word = "write-array-word",
        /// 8: change parameter value (array double word).
        write_array_dword = "write-array-dword",
        /// 9: require number of array elements.
        count_array = "count-array",
    }
}

open_enum! {
    /// A PKW response code AK, drive → controller (manual 3.8 "Response code").
    pub struct ResponseCode(u8);
    /// The response codes of the spec table, by name (manual 3.8).
    pub struct ResponseCodes {
        /// 0: no response.
        no_response = "no-response",
        /// 1: transfer parameter value (word).
        value_word = "value-word",
        /// 2: transfer parameter value (double word).
        value_dword = "value-dword",
        /// 4: transfer parameter value (array word).
        value_array_word = "value-array-word",
        /// 5: transfer parameter value (array double word).
        value_array_dword = "value-array-dword",
        /// 6: transfer number of array elements.
        array_count = "array-count",
        /// 7: command cannot be executed.
        cannot_execute = "cannot-execute",
    }
}

open_enum! {
    /// A PKW error code, in PWE of response 7 (manual 3.8 "Error code"); the whole 32-bit PWE
    /// so that any value re-encodes unchanged.
    pub struct ErrorCode(u32);
    /// The error codes of the spec table, by name (manual 3.8).
    pub struct ErrorCodes {
        /// 0: parameter number not permitted.
        unknown_parameter = "unknown-parameter",
        /// 1: parameter value cannot be changed.
        read_only = "read-only",
        /// 2: lower or upper limit value exceeded.
        out_of_range = "out-of-range",
        /// 3: error in the subindex.
        bad_subindex = "bad-subindex",
        /// 4: no array.
        no_array = "no-array",
        /// 5: incorrect data type.
        wrong_type = "wrong-type",
        /// 6: setting not permitted (only resetting).
        reset_only = "reset-only",
        /// 17: order cannot be executed in the current operating state.
        operating_state = "operating-state",
        /// 18: other error.
        other = "other",
    }
}

/// One PKW block as on the wire (manual 3.8 "PKW format", "PKE format").
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Pkw<C> {
    /// AK: command or response code (PKE bits 12–15).
    pub ak: C,
    /// SPM: toggle bit for spontaneous messages (PKE bit 11; not implemented by the drive).
    pub spm: bool,
    /// PNU: parameter number (PKE bits 0–10).
    pub pnu: u16,
    /// IND: subindex word.
    pub ind: u16,
    /// PWE: parameter value, 32 bits.
    pub pwe: u32,
}

/// A PKW block controller → drive (manual 3.8).
pub type PkwRequest = Pkw<CommandCode>;
/// A PKW block drive → controller (manual 3.8).
pub type PkwResponse = Pkw<ResponseCode>;

impl<C: WireCode + From<u8> + Into<u8>> Pkw<C> {
    /// Parses exactly one 8-byte PKW block (manual 3.8 "PKW format").
    pub fn parse(rules: &PkwRules, bytes: &[u8]) -> Result<Pkw<C>, DecodeError> {
        rules.block.module.check_len(bytes.len())?;
        Ok(Pkw::read_from(rules, &rules.block.pkw, bytes))
    }

    /// Number of bytes `emit` writes (8) (manual 3.8).
    pub fn buffer_len(rules: &PkwRules) -> usize {
        rules.block.module.length
    }

    /// Writes the block; returns the bytes written (manual 3.8).
    pub fn emit(&self, rules: &PkwRules, out: &mut [u8]) -> Result<usize, EmitError> {
        let need = Pkw::<C>::buffer_len(rules);
        let have = out.len();
        let out = out
            .get_mut(..need)
            .ok_or(EmitError::Buffer { need, have })?;
        self.write_to(rules, &rules.block.pkw, out)?;
        Ok(need)
    }

    /// The block as bytes (manual 3.8).
    pub fn to_bytes(&self, rules: &PkwRules) -> Result<Vec<u8>, EmitError> {
        let mut out = vec![0; Pkw::<C>::buffer_len(rules)];
        self.emit(rules, &mut out)?;
        Ok(out)
    }

    /// The block from its three words (manual 3.8).
    pub fn from_words(rules: &PkwRules, pke: u16, ind: u16, pwe: u32) -> Pkw<C> {
        let (ak, spm, pnu) = rules.split_pke(pke);
        Pkw {
            ak: C::from(ak),
            spm,
            pnu,
            ind,
            pwe,
        }
    }

    /// The PKE word; `FieldRange` when AK or PNU do not fit their bits (manual 3.8).
    pub fn pke(&self, rules: &PkwRules) -> Result<u16, EmitError> {
        rules.join_pke(self.ak.into(), self.spm, self.pnu)
    }

    pub(crate) fn read_from(rules: &PkwRules, f: &PkwFields, bytes: &[u8]) -> Pkw<C> {
        let get = |field: drivespec_positioner::Field| field.read_unsigned(bytes).unwrap_or(0);
        Pkw::from_words(
            rules,
            get(f.pke) as u16,
            get(f.ind) as u16,
            get(f.pwe) as u32,
        )
    }

    pub(crate) fn write_to(
        &self,
        rules: &PkwRules,
        f: &PkwFields,
        out: &mut [u8],
    ) -> Result<(), EmitError> {
        let pke = self.pke(rules)?;
        let need = f.pke.end().max(f.ind.end()).max(f.pwe.end());
        let buffer = EmitError::Buffer {
            need,
            have: out.len(),
        };
        f.pke
            .write_unsigned(out, u64::from(pke))
            .map_err(|_| buffer)?;
        f.ind
            .write_unsigned(out, u64::from(self.ind))
            .map_err(|_| buffer)?;
        f.pwe
            .write_unsigned(out, u64::from(self.pwe))
            .map_err(|_| buffer)?;
        Ok(())
    }
}

/// What a request block asks (manual 3.8 "Command code"), without wire details.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "op", rename_all = "kebab-case")]
pub enum Request {
    /// No command (AK 0): the drive answers "no response".
    None,
    /// Read a parameter, or an array element when `index` is given.
    Read {
        /// Parameter number.
        pnu: u16,
        /// Array subindex (IND), for the array command.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        index: Option<u16>,
    },
    /// Write a parameter value, or an array element when `index` is given.
    Write {
        /// Parameter number.
        pnu: u16,
        /// Array subindex (IND), for the array commands.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        index: Option<u16>,
        /// Word or double word command.
        width: Width,
        /// The value (two's complement for signed parameters).
        value: i64,
    },
    /// Read the number of array elements.
    Count {
        /// Parameter number.
        pnu: u16,
    },
}

/// What a response block says (manual 3.8 "Response code", "Error code").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Reply {
    /// No response (AK 0).
    None,
    /// A parameter value, or an array element when `index` is given.
    Value {
        /// Parameter number.
        pnu: u16,
        /// Array subindex (IND), for array responses.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        index: Option<u16>,
        /// Word or double word response.
        width: Width,
        /// The value (two's complement for signed parameters).
        value: i64,
    },
    /// The number of array elements.
    Count {
        /// Parameter number.
        pnu: u16,
        /// Number of elements.
        count: u32,
    },
    /// The command cannot be executed (response 7).
    Error {
        /// Parameter number, as in the command.
        pnu: u16,
        /// Subindex, as in the command.
        index: u16,
        /// Error code in PWE.
        error: ErrorCode,
    },
}

/// How a response relates to a command (manual 3.8 command table, positive/negative columns).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Verdict {
    /// A positive response the command allows.
    Positive,
    /// A negative response the command allows.
    Negative,
    /// The command does not allow this response.
    NotAllowed,
    /// The command code is not in the spec's table.
    UnknownCommand,
}

/// One command code with its meaning (manual 3.8 "Command code").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CommandInfo {
    /// The code.
    pub code: CommandCode,
    /// What it does.
    pub op: PkwOp,
    /// Value kind a write carries.
    pub value: Option<PkwValue>,
    /// IND selects an array element.
    pub array: bool,
    /// Positive responses.
    pub positive: Vec<ResponseCode>,
    /// Negative responses.
    pub negative: Vec<ResponseCode>,
}

/// The PKW tables and settings (manual 3.8), self-contained (no borrow of the spec).
#[derive(Debug, Clone)]
pub struct PkwRules {
    block: PkwLayout,
    ak: BitRange,
    spm: BitRange,
    pnu: BitRange,
    word_position: WordPosition,
    word_fill: WordFill,
    ind_layout: IndLayout,
    commands: CodeTable<CommandCode>,
    responses: CodeTable<ResponseCode>,
    errors: CodeTable<ErrorCode>,
    command_codes: CommandCodes,
    response_codes: ResponseCodes,
    error_codes: ErrorCodes,
    info: Vec<CommandInfo>,
    kinds: Vec<(ResponseCode, PkwValue)>,
    echo_commands: Vec<CommandCode>,
    echo_pnu: bool,
    echo_ind: bool,
    echo_pwe: bool,
    response_as_read: bool,
    strings: Vec<StringAccess>,
    params: Params,
}

fn table_err(table: &'static str, what: impl Into<String>) -> crate::RulesError {
    crate::RulesError::Table {
        table,
        what: what.into(),
    }
}

impl PkwRules {
    /// Reads the PKW tables of the spec (manual 3.8) with the settings of `options`.
    pub fn from_protocol(
        p: &Protocol,
        params: Params,
        options: &Options,
    ) -> Result<PkwRules, crate::RulesError> {
        use crate::RulesError;
        let pkw = &p.pkw;
        let bit = |name: &'static str| {
            pkw.pke_bit(name)
                .cloned()
                .ok_or(RulesError::PkeBits { what: name })
        };
        let (ak, spm, pnu) = (bit("ak")?, bit("spm")?, bit("pnu")?);
        let mut used = 0u32;
        for b in [&ak, &spm, &pnu] {
            if b.width == 0 || b.lsb + b.width > 16 {
                return Err(RulesError::PkeBits {
                    what: "a range lies outside the 16-bit PKE",
                });
            }
            let mask = b.value_mask() << b.lsb;
            if used & mask != 0 {
                return Err(RulesError::PkeBits {
                    what: "ranges overlap",
                });
            }
            used |= mask;
        }
        if ak.width > 8 || spm.width != 1 {
            return Err(RulesError::PkeBits {
                what: "AK must fit a byte and SPM be one bit",
            });
        }
        let commands = CodeTable::new(
            "PKW command",
            pkw.commands
                .iter()
                .map(|c| CodeEntry::new(CommandCode(c.code), &c.name, &c.label, &c.source)),
        )?;
        let responses = CodeTable::new(
            "PKW response",
            pkw.responses
                .iter()
                .map(|r| CodeEntry::new(ResponseCode(r.code), &r.name, &r.label, &r.source)),
        )?;
        let errors = CodeTable::new(
            "PKW error",
            pkw.errors.iter().map(|e| {
                CodeEntry::new(ErrorCode(u32::from(e.code)), &e.name, &e.meaning, &e.source)
            }),
        )?;
        let mut info = Vec::with_capacity(pkw.commands.len());
        for c in &pkw.commands {
            let codes = |list: &[u8]| -> Result<Vec<ResponseCode>, RulesError> {
                list.iter()
                    .map(|r| {
                        let code = ResponseCode(*r);
                        if responses.contains(code) {
                            Ok(code)
                        } else {
                            Err(table_err(
                                "PKW command",
                                format!("command {} names unknown response {r}", c.code),
                            ))
                        }
                    })
                    .collect()
            };
            if u64::from(c.code) > u64::from(ak.value_mask()) {
                return Err(table_err(
                    "PKW command",
                    format!("code {} does not fit AK", c.code),
                ));
            }
            info.push(CommandInfo {
                code: CommandCode(c.code),
                op: c.op,
                value: c.value,
                array: c.array,
                positive: codes(&c.positive)?,
                negative: codes(&c.negative)?,
            });
        }
        let kinds = pkw
            .responses
            .iter()
            .map(|r| (ResponseCode(r.code), r.value))
            .collect();
        let mut echo_commands = Vec::new();
        for code in &pkw.echo.commands {
            match info.iter().find(|i| i.code.0 == *code) {
                Some(i) if i.op == PkwOp::Write => echo_commands.push(i.code),
                _ => {
                    return Err(table_err(
                        "PKW echo",
                        format!("command {code} is not a write command"),
                    ))
                }
            }
        }
        let copied = |name: &str| pkw.echo.copied.iter().any(|c| c == name);
        if let Some(other) = pkw
            .echo
            .copied
            .iter()
            .find(|c| !matches!(c.as_str(), "pnu" | "ind" | "pwe"))
        {
            return Err(table_err("PKW echo", format!("unknown field {other:?}")));
        }
        for s in &pkw.string_access {
            if s.segment_bytes == 0 || s.segment_bytes > 4 {
                return Err(table_err(
                    "PKW string access",
                    format!("par {}: segment of {} bytes", s.param, s.segment_bytes),
                ));
            }
        }
        Ok(PkwRules {
            block: crate::wire::PkwLayout::from_protocol(p, &params, options)?,
            command_codes: CommandCodes::from_table(&commands)?,
            response_codes: ResponseCodes::from_table(&responses)?,
            error_codes: ErrorCodes::from_table(&errors)?,
            ak,
            spm,
            pnu,
            word_position: options.word_position,
            word_fill: options.word_fill,
            ind_layout: options.ind_layout,
            commands,
            responses,
            errors,
            info,
            kinds,
            echo_commands,
            echo_pnu: copied("pnu"),
            echo_ind: copied("ind"),
            echo_pwe: copied("pwe"),
            response_as_read: pkw.echo.response_as_read,
            strings: pkw.string_access.clone(),
            params,
        })
    }

    /// The command table (manual 3.8 "Command code").
    pub fn commands(&self) -> &CodeTable<CommandCode> {
        &self.commands
    }

    /// The response table (manual 3.8 "Response code").
    pub fn responses(&self) -> &CodeTable<ResponseCode> {
        &self.responses
    }

    /// The error table (manual 3.8 "Error code").
    pub fn errors(&self) -> &CodeTable<ErrorCode> {
        &self.errors
    }

    /// The command codes by name (manual 3.8).
    pub fn command_codes(&self) -> &CommandCodes {
        &self.command_codes
    }

    /// The response codes by name (manual 3.8).
    pub fn response_codes(&self) -> &ResponseCodes {
        &self.response_codes
    }

    /// The error codes by name (manual 3.8).
    pub fn error_codes(&self) -> &ErrorCodes {
        &self.error_codes
    }

    /// The meaning of a command code, None for codes the spec does not list (manual 3.8).
    pub fn command_info(&self, code: CommandCode) -> Option<&CommandInfo> {
        self.info.iter().find(|i| i.code == code)
    }

    /// What the PWE of a response code holds (manual 3.8 "Response code").
    pub fn response_kind(&self, code: ResponseCode) -> Option<PkwValue> {
        self.kinds.iter().find(|(c, _)| *c == code).map(|(_, k)| *k)
    }

    /// The parameter table (manual 3.3).
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The layout of the standalone 8-byte block (manual 3.8 "PKW format").
    pub fn block(&self) -> &PkwLayout {
        &self.block
    }

    /// Largest PNU (11 bits: 2047, manual 3.8 PKE format).
    pub fn pnu_max(&self) -> u16 {
        u16::try_from(self.pnu.value_mask()).unwrap_or(u16::MAX)
    }

    /// Largest AK (4 bits: 15) (manual 3.8).
    pub fn ak_max(&self) -> u8 {
        u8::try_from(self.ak.value_mask()).unwrap_or(u8::MAX)
    }

    /// Splits PKE into AK, SPM, PNU (manual 3.8 PKE format).
    pub fn split_pke(&self, pke: u16) -> (u8, bool, u16) {
        let w = u32::from(pke);
        (
            self.ak.get(w) as u8,
            self.spm.get(w) != 0,
            self.pnu.get(w) as u16,
        )
    }

    /// Joins AK, SPM, PNU into PKE; `FieldRange` when a value does not fit (manual 3.8).
    pub fn join_pke(&self, ak: u8, spm: bool, pnu: u16) -> Result<u16, EmitError> {
        let check = |field: &'static str, r: &BitRange, v: u32| {
            if v > r.value_mask() {
                Err(EmitError::FieldRange {
                    field,
                    value: u64::from(v),
                    max: u64::from(r.value_mask()),
                })
            } else {
                Ok(())
            }
        };
        check("ak", &self.ak, u32::from(ak))?;
        check("pnu", &self.pnu, u32::from(pnu))?;
        let w = self.ak.put(0, u32::from(ak));
        let w = self.spm.put(w, u32::from(spm));
        let w = self.pnu.put(w, u32::from(pnu));
        Ok(w as u16)
    }

    /// The subindex carried in IND (erratum PSD-ERRATUM-054 layout).
    pub fn subindex(&self, ind: u16) -> u16 {
        match self.ind_layout {
            IndLayout::Word => ind,
            IndLayout::HighByte => ind >> 8,
            IndLayout::LowByte => ind & 0xFF,
        }
    }

    /// Largest subindex IND can carry (manual 3.8).
    pub fn index_max(&self) -> u16 {
        match self.ind_layout {
            IndLayout::Word => u16::MAX,
            IndLayout::HighByte | IndLayout::LowByte => 0xFF,
        }
    }

    /// IND for a subindex, None when it does not fit (erratum PSD-ERRATUM-054).
    pub fn ind_for(&self, index: u16) -> Option<u16> {
        if index > self.index_max() {
            return None;
        }
        Some(match self.ind_layout {
            IndLayout::Word | IndLayout::LowByte => index,
            IndLayout::HighByte => index << 8,
        })
    }

    /// The raw bits of a value of `width` in PWE (erratum PSD-ERRATUM-053 word position).
    pub fn raw_of(&self, pwe: u32, width: Width) -> u32 {
        match (width, self.word_position) {
            (Width::Dword, _) => pwe,
            (Width::Word, WordPosition::Low) => pwe & 0xFFFF,
            (Width::Word, WordPosition::High) => pwe >> 16,
        }
    }

    /// PWE carrying raw bits of `width`; `negative` fills the other word with 0xFFFF when the
    /// spec says sign-extend (erratum PSD-ERRATUM-053).
    pub fn pwe_of(&self, raw: u32, width: Width, negative: bool) -> u32 {
        if width == Width::Dword {
            return raw;
        }
        let fill = match self.word_fill {
            WordFill::SignExtend if negative => 0xFFFF,
            _ => 0,
        };
        match self.word_position {
            WordPosition::Low => fill << 16 | (raw & 0xFFFF),
            WordPosition::High => (raw & 0xFFFF) << 16 | fill,
        }
    }

    /// The value of a PWE of `width` for parameter `pnu` (signed by its type; manual 3.3, 3.8).
    pub fn value_of(&self, pnu: u16, pwe: u32, width: Width) -> i64 {
        let signed = self.params.signed(u32::from(pnu)).unwrap_or(false);
        width.to_value(self.raw_of(pwe, width), signed)
    }

    /// PWE for a value of `width` for parameter `pnu`; the range follows the parameter's type (manual 3.8).
    pub fn pwe_for(&self, pnu: u16, value: i64, width: Width) -> Result<u32, RequestError> {
        let signed = self.params.signed(u32::from(pnu));
        let raw = width
            .to_raw(value, signed)
            .map_err(|(min, max)| RequestError::ValueRange { value, min, max })?;
        Ok(self.pwe_of(raw, width, value < 0))
    }

    /// The width of a parameter (manual 3.3 type: word for 16-bit, double word for 32-bit).
    pub fn width(&self, pnu: u16) -> Option<Width> {
        self.params.width(u32::from(pnu))
    }

    /// The width of one array element: the string segment (3.3 par. 13) or the type's width.
    pub fn element_width(&self, pnu: u16) -> Option<Width> {
        match self.string_access(pnu) {
            Some(s) => {
                Width::from_bits(u32::try_from(s.segment_bytes * 8).ok()?).or(Some(Width::Dword))
            }
            None => self.width(pnu),
        }
    }

    /// Number of array elements: the segments of a string (3.3 par. 13) or the parameter's
    /// `array` count; None for scalars and unknown parameters (manual 3.8 IND).
    pub fn elements(&self, pnu: u16) -> Option<u16> {
        if let Some(s) = self.string_access(pnu) {
            return Some(s.segments);
        }
        self.params
            .get(u32::from(pnu))?
            .array
            .and_then(|n| u16::try_from(n).ok())
    }

    /// The segment rule of a string parameter read through PKW (3.3 par. 13).
    pub fn string_access(&self, pnu: u16) -> Option<&StringAccess> {
        let id = self.params.get(u32::from(pnu))?.id.as_str();
        self.strings.iter().find(|s| s.param == id)
    }

    /// The characters of a string segment in PWE, up to the first 0 (3.3 par. 13).
    pub fn segment_text(&self, pnu: u16, pwe: u32) -> Option<String> {
        let s = self.string_access(pnu)?;
        let bytes = if s.first_char_most_significant {
            pwe.to_be_bytes()
        } else {
            pwe.to_le_bytes()
        };
        let skip = 4usize.saturating_sub(s.segment_bytes);
        let seg = if s.first_char_most_significant {
            bytes.get(skip..)?
        } else {
            bytes.get(..s.segment_bytes)?
        };
        let text: String = seg
            .iter()
            .take_while(|b| **b != 0)
            .map(|b| {
                if b.is_ascii_graphic() || *b == b' ' {
                    char::from(*b)
                } else {
                    char::REPLACEMENT_CHARACTER
                }
            })
            .collect();
        Some(text)
    }

    fn find_command(&self, op: PkwOp, array: bool, value: Option<PkwValue>) -> Option<CommandCode> {
        self.info
            .iter()
            .find(|i| i.op == op && (op == PkwOp::Count || i.array == array) && i.value == value)
            .map(|i| i.code)
    }

    fn find_response(&self, kind: PkwValue) -> Option<ResponseCode> {
        self.kinds.iter().find(|(_, k)| *k == kind).map(|(c, _)| *c)
    }

    fn value_kind(width: Width, array: bool) -> PkwValue {
        match (width, array) {
            (Width::Word, false) => PkwValue::Word,
            (Width::Dword, false) => PkwValue::Dword,
            (Width::Word, true) => PkwValue::ArrayWord,
            (Width::Dword, true) => PkwValue::ArrayDword,
        }
    }

    fn kind_width(kind: PkwValue) -> Option<(Width, bool)> {
        match kind {
            PkwValue::Word => Some((Width::Word, false)),
            PkwValue::Dword => Some((Width::Dword, false)),
            PkwValue::ArrayWord => Some((Width::Word, true)),
            PkwValue::ArrayDword => Some((Width::Dword, true)),
            _ => None,
        }
    }

    /// What a request block asks; None for a command code the spec does not list (3.8).
    pub fn request(&self, pkw: &PkwRequest) -> Option<Request> {
        let info = self.command_info(pkw.ak)?;
        let index = info.array.then(|| self.subindex(pkw.ind));
        Some(match info.op {
            PkwOp::None => Request::None,
            PkwOp::Read => Request::Read {
                pnu: pkw.pnu,
                index,
            },
            PkwOp::Count => Request::Count { pnu: pkw.pnu },
            PkwOp::Write => {
                let (width, _) = Self::kind_width(info.value?)?;
                Request::Write {
                    pnu: pkw.pnu,
                    index,
                    width,
                    value: self.value_of(pkw.pnu, pkw.pwe, width),
                }
            }
        })
    }

    /// The canonical block of a request: unused fields 0, SPM 0 (manual 3.8).
    pub fn encode_request(&self, r: &Request) -> Result<PkwRequest, RequestError> {
        let no_code = |what: &str| RequestError::NoCode {
            what: what.to_owned(),
        };
        let (ak, pnu, index, pwe) = match *r {
            Request::None => (self.command_codes.no_command, 0, None, 0),
            Request::Read { pnu, index } => {
                let code = self
                    .find_command(PkwOp::Read, index.is_some(), None)
                    .ok_or_else(|| no_code("a read"))?;
                (code, pnu, index, 0)
            }
            Request::Count { pnu } => {
                let code = self
                    .find_command(PkwOp::Count, true, None)
                    .ok_or_else(|| no_code("a count"))?;
                (code, pnu, None, 0)
            }
            Request::Write {
                pnu,
                index,
                width,
                value,
            } => {
                let kind = Self::value_kind(width, index.is_some());
                let code = self
                    .find_command(PkwOp::Write, index.is_some(), Some(kind))
                    .ok_or_else(|| no_code(&format!("a {width} write")))?;
                (code, pnu, index, self.pwe_for(pnu, value, width)?)
            }
        };
        self.block_of(ak, pnu, index, pwe)
    }

    fn block_of<C>(
        &self,
        ak: C,
        pnu: u16,
        index: Option<u16>,
        pwe: u32,
    ) -> Result<Pkw<C>, RequestError> {
        if pnu > self.pnu_max() {
            return Err(RequestError::PnuRange {
                pnu: i64::from(pnu),
                max: u64::from(self.pnu_max()),
            });
        }
        let ind = match index {
            None => 0,
            Some(i) => self.ind_for(i).ok_or(RequestError::IndexRange {
                index: i64::from(i),
                max: u64::from(self.index_max()),
            })?,
        };
        Ok(Pkw {
            ak,
            spm: false,
            pnu,
            ind,
            pwe,
        })
    }

    /// What a response block says; None for a response code the spec does not list (3.8).
    pub fn reply(&self, pkw: &PkwResponse) -> Option<Reply> {
        let kind = self.response_kind(pkw.ak)?;
        Some(match kind {
            PkwValue::None => Reply::None,
            PkwValue::Count => Reply::Count {
                pnu: pkw.pnu,
                count: pkw.pwe,
            },
            PkwValue::Error => Reply::Error {
                pnu: pkw.pnu,
                index: self.subindex(pkw.ind),
                error: ErrorCode(pkw.pwe),
            },
            PkwValue::Word | PkwValue::Dword | PkwValue::ArrayWord | PkwValue::ArrayDword => {
                let (width, array) = Self::kind_width(kind)?;
                Reply::Value {
                    pnu: pkw.pnu,
                    index: array.then(|| self.subindex(pkw.ind)),
                    width,
                    value: self.value_of(pkw.pnu, pkw.pwe, width),
                }
            }
        })
    }

    /// The canonical block of a reply (manual 3.8).
    pub fn encode_reply(&self, r: &Reply) -> Result<PkwResponse, RequestError> {
        let code = |kind: PkwValue| {
            self.find_response(kind)
                .ok_or_else(|| RequestError::NoCode {
                    what: format!("a {kind:?} response"),
                })
        };
        match *r {
            Reply::None => self.block_of(self.response_codes.no_response, 0, None, 0),
            Reply::Count { pnu, count } => self.block_of(code(PkwValue::Count)?, pnu, None, count),
            Reply::Error { pnu, index, error } => {
                self.block_of(code(PkwValue::Error)?, pnu, Some(index), error.0)
            }
            Reply::Value {
                pnu,
                index,
                width,
                value,
            } => {
                let kind = Self::value_kind(width, index.is_some());
                let pwe = self.pwe_for(pnu, value, width)?;
                self.block_of(code(kind)?, pnu, index, pwe)
            }
        }
    }

    /// The positive response a conforming drive gives, by the parameter's width (3.8: the
    /// answer to a write is the answer to a read); None when the parameter is unknown.
    pub fn expected_response(&self, req: &PkwRequest) -> Option<ResponseCode> {
        let info = self.command_info(req.ak)?;
        let kind = match info.op {
            PkwOp::None => PkwValue::None,
            PkwOp::Count => PkwValue::Count,
            PkwOp::Read | PkwOp::Write => {
                if info.op == PkwOp::Write && !self.response_as_read {
                    info.value?
                } else if info.array {
                    Self::value_kind(self.element_width(req.pnu)?, true)
                } else {
                    Self::value_kind(self.width(req.pnu)?, false)
                }
            }
        };
        let code = self.find_response(kind)?;
        (info.positive.contains(&code) || info.op == PkwOp::None).then_some(code)
    }

    /// Whether the command allows the response code (manual 3.8 command table).
    pub fn verdict(&self, command: CommandCode, response: ResponseCode) -> Verdict {
        match self.command_info(command) {
            None => Verdict::UnknownCommand,
            Some(i) if i.positive.contains(&response) => Verdict::Positive,
            Some(i) if i.negative.contains(&response) => Verdict::Negative,
            Some(_) => Verdict::NotAllowed,
        }
    }

    /// Whether `resp` is the drive's answer to `req`: anything but "no response", for the same
    /// PNU (and subindex for array commands). Whether the command allows it is
    /// [`PkwRules::verdict`] (manual 3.8).
    pub fn answers(&self, req: &PkwRequest, resp: &PkwResponse) -> bool {
        if resp.ak == self.response_codes.no_response || resp.pnu != req.pnu {
            return false;
        }
        match self.command_info(req.ak) {
            Some(i) if i.array && i.op != PkwOp::Count => {
                self.subindex(resp.ind) == self.subindex(req.ind)
            }
            _ => true,
        }
    }

    /// The echo rule of a positive answer to a write: PNU, IND, PWE as in the command
    /// (manual 3.8 last paragraph). None when the rule does not apply.
    pub fn echo_holds(&self, req: &PkwRequest, resp: &PkwResponse) -> Option<bool> {
        if !self.echo_commands.contains(&req.ak)
            || self.verdict(req.ak, resp.ak) != Verdict::Positive
        {
            return None;
        }
        Some(
            (!self.echo_pnu || req.pnu == resp.pnu)
                && (!self.echo_ind || req.ind == resp.ind)
                && (!self.echo_pwe || req.pwe == resp.pwe),
        )
    }

    /// The request in words: `read par 44 (Positioning window)` (manual 3.8).
    pub fn describe_request(&self, pkw: &PkwRequest) -> String {
        let par = param_phrase(&self.params, u32::from(pkw.pnu));
        let p = self.params.get(u32::from(pkw.pnu));
        match self.request(pkw) {
            None => format!("unknown command {} for {par}", self.commands.named(pkw.ak)),
            Some(Request::None) => "no command".to_owned(),
            Some(Request::Read { index: None, .. }) => format!("read {par}"),
            Some(Request::Read { index: Some(i), .. }) => format!("read {par} element {i}"),
            Some(Request::Count { .. }) => format!("read the number of elements of {par}"),
            Some(Request::Write {
                index,
                width,
                value,
                ..
            }) => {
                let at = index.map(|i| format!(" element {i}")).unwrap_or_default();
                format!("write {par}{at} = {} ({width})", shown(p, value))
            }
        }
    }

    /// The response in words: `par 44 (Positioning window) = 2 (word)`,
    /// `par 44 (…): error 2 (out-of-range): lower or upper limit value exceeded` (manual 3.8).
    pub fn describe_response(&self, pkw: &PkwResponse) -> String {
        let par = param_phrase(&self.params, u32::from(pkw.pnu));
        let p = self.params.get(u32::from(pkw.pnu));
        match self.reply(pkw) {
            None => format!(
                "unknown response {} for {par}",
                self.responses.named(pkw.ak)
            ),
            Some(Reply::None) => "no response".to_owned(),
            Some(Reply::Count { count, .. }) => format!("{par} has {count} elements"),
            Some(Reply::Error { error, .. }) => {
                let named = self.errors.named(error);
                match named.label() {
                    Some(meaning) => format!("{par}: error {} ({named}): {meaning}", error.0),
                    None => format!("{par}: error {} (not in the error table)", error.0),
                }
            }
            Some(Reply::Value {
                index,
                width,
                value,
                ..
            }) => {
                let at = index.map(|i| format!(" element {i}")).unwrap_or_default();
                match self.segment_text(pkw.pnu, pkw.pwe) {
                    Some(text) => format!("{par}{at} = 0x{:08X} {text:?}", pkw.pwe),
                    None => format!("{par}{at} = {} ({width})", shown(p, value)),
                }
            }
        }
    }
}
