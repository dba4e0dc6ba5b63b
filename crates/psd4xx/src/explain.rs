//! Every field of a PSD4xx image by name, in words and as JSON (manual 3.5–3.8): the PKW
//! block's meaning ("read par 44 (Positioning window)", "error 2 (out-of-range): …"), the
//! control or status word with each bit set by name and the must-be-zero violations, the other
//! values with their units, and notes on anything a conforming peer would not send.
//!
//! # JSON shape (stable: keys are only ever added)
//!
//! Keys marked `?` are left out when absent.
//!
//! ```text
//! Explanation = {
//!   "direction": "out" | "in",
//!   "length": 14 | 16,
//!   "byte_order": "big-endian" | "little-endian",      // of the values not inverted
//!   "bytes": "10 2C 00 …",                             // the image, hex
//!   "fields": [Field],                                 // offset order, every field
//!   "pkw": Pkw,
//!   "notes": [string]                                  // control/status anomalies; may be []
//! }
//! Field = {
//!   "name": "pke" | "ind" | "pwe" | "control" | "target" | "status" | "speed" | "actual",
//!   "label": "Control word",                           // the manual's designation
//!   "offset": 8, "length": 2,
//!   "byte_order": "little-endian",                     // of this field
//!   "bytes": "14 00",
//!   "raw": 20,                                         // unsigned value of the bytes
//!   "value": 20,                                       // two's complement for signed fields
//!   "param"?: Param,                                   // the corresponding parameter (3.5)
//!   "pke"?: {"ak", "spm", "pnu"},                      // field pke only
//!   "bits"?: Bits,                                     // fields control and status only
//!   "text": "0x0014: bit 2 Transfer target value, …"   // the meaning column of the text form
//! }
//! Param = {"id": "44", "number": 44, "name": "Positioning window", "type": "u16", "unit"?}
//! Bits = {"bitfield": "control", "word": 20, "set": [{"bit", "name", "reserved"?}],
//!         "must_be_zero": [bit], "undefined": [bit], "value"?: {"name", "meaning"}}
//! Pkw = {
//!   "direction": "out" | "in",                         // request or response
//!   "ak": Code,                                        // command or response code
//!   "spm": bool, "pnu": 44, "ind": 0, "pwe": 0,         // raw fields
//!   "param"?: Param,                                   // absent for PNUs not in the spec
//!   "request"?: {"op": "none" | "read" | "write" | "count", "pnu"?, "index"?, "width"?, "value"?},
//!   "reply"?: {"kind": "none" | "value" | "count" | "error", "pnu"?, "index"?, "width"?,
//!              "value"?, "count"?, "error"?},
//!   "text"?: "PSD4",                                   // a string segment (3.3 par. 13)
//!   "error"?: Code,                                    // response 7: the error code
//!   "summary": "read par 44 (Positioning window)",
//!   "notes": [string]                                  // PKW anomalies; may be []
//! }
//! Code = {"code": 1, "name"?: "read", "label"?: "Require parameter value"}
//! ```
//!
//! `width` is `"word"` or `"dword"`; `value` is the parameter value (two's complement for
//! signed parameters). Explaining allocates only for the result, bounded by the spec tables.

use crate::error::DecodeError;
use crate::pkw::{PkwRequest, PkwResponse, PkwRules, Reply, Request};
use crate::repr::Direction;
use crate::rules::Rules;
use crate::value::{shown, Width};
use crate::Pkw;
use drivespec_positioner::{decode_bits, BitsDecoded, ByteOrder, Named, WireCode};
use drivespec_spec::hex::to_hex;
use drivespec_spec::Parameter;
use serde::Serialize;
use std::fmt;

/// An image explained field by field (manual 3.5–3.8); see the module docs for the JSON.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Explanation {
    /// Output (controller → drive) or input image.
    pub direction: Direction,
    /// Length in bytes.
    pub length: usize,
    /// Byte order of the values that are not inverted.
    pub byte_order: ByteOrder,
    /// The image, hex.
    pub bytes: String,
    /// Every field, in offset order.
    pub fields: Vec<FieldExplained>,
    /// The PKW block.
    pub pkw: PkwExplained,
    /// Control or status word anomalies.
    pub notes: Vec<String>,
}

/// One field of an image (manual 3.5).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldExplained {
    /// Spec key.
    pub name: String,
    /// The manual's designation.
    pub label: String,
    /// Offset of the first byte.
    pub offset: usize,
    /// Length in bytes.
    pub length: usize,
    /// Byte order of this field.
    pub byte_order: ByteOrder,
    /// The field's bytes, hex.
    pub bytes: String,
    /// Unsigned value.
    pub raw: u64,
    /// Value as the field's type.
    pub value: i64,
    /// The corresponding parameter.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub param: Option<ParamRef>,
    /// PKE split into AK, SPM, PNU (field `pke`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pke: Option<PkeParts>,
    /// Bits by name (fields `control` and `status`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bits: Option<BitsDecoded>,
    /// The meaning in words.
    pub text: String,
}

/// A parameter named by a field or a PNU (manual 3.3).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct ParamRef {
    /// Spec id.
    pub id: String,
    /// Parameter number.
    pub number: u32,
    /// The manual's designation.
    pub name: String,
    /// Spec type (`u16`, `i32`, `bits16`, `string` …).
    #[serde(rename = "type")]
    pub data_type: &'static str,
    /// Unit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unit: Option<String>,
}

impl ParamRef {
    fn of(p: &Parameter) -> ParamRef {
        ParamRef {
            id: p.id.clone(),
            number: p.number,
            name: p.name.clone(),
            data_type: p.data_type.as_str(),
            unit: p.unit.clone(),
        }
    }
}

/// PKE split into its bit ranges (manual 3.8 PKE format).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct PkeParts {
    /// Command or response code.
    pub ak: u8,
    /// Spontaneous-message toggle bit.
    pub spm: bool,
    /// Parameter number.
    pub pnu: u16,
}

/// A wire code with its spec name and label when the spec lists it (manual 3.8).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct CodeInfo {
    /// The code.
    pub code: u64,
    /// The spec name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// The manual's designation or meaning.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub label: Option<String>,
}

impl<C: WireCode> From<Named<'_, C>> for CodeInfo {
    fn from(n: Named<'_, C>) -> CodeInfo {
        CodeInfo {
            code: n.code().to_u64(),
            name: n.name().map(str::to_owned),
            label: n.label().map(str::to_owned),
        }
    }
}

/// The PKW block explained (manual 3.8).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PkwExplained {
    /// `out`: a request; `in`: a response.
    pub direction: Direction,
    /// Command or response code.
    pub ak: CodeInfo,
    /// Spontaneous-message toggle bit (not implemented by the drive).
    pub spm: bool,
    /// Parameter number.
    pub pnu: u16,
    /// Subindex word.
    pub ind: u16,
    /// Parameter value word.
    pub pwe: u32,
    /// The parameter PNU names.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub param: Option<ParamRef>,
    /// What the request asks (known command codes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub request: Option<Request>,
    /// What the response says (known response codes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reply: Option<Reply>,
    /// Characters of a string segment (3.3 par. 13).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub text: Option<String>,
    /// The error code of response 7.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<CodeInfo>,
    /// The block in one sentence.
    pub summary: String,
    /// What a conforming peer would not send.
    pub notes: Vec<String>,
}

/// Explains an output (`Out`) or input (`In`) image (manual 3.5).
pub fn explain(
    rules: &Rules,
    direction: Direction,
    bytes: &[u8],
) -> Result<Explanation, DecodeError> {
    let module = direction.module(rules);
    module.check_len(bytes.len())?;
    let pkw = match direction {
        Direction::Out => explain_request(
            rules.pkw(),
            Pkw::read_from(rules.pkw(), pkw_of(rules, direction), bytes),
        ),
        Direction::In => explain_response(
            rules.pkw(),
            Pkw::read_from(rules.pkw(), pkw_of(rules, direction), bytes),
        ),
    };
    let mut notes = Vec::new();
    let mut fields = Vec::with_capacity(module.fields.len());
    for f in &module.fields {
        let raw = f.field.read_unsigned(bytes).unwrap_or(0);
        let value = if f.signed {
            f.field.read_signed(bytes).unwrap_or(0)
        } else {
            i64::try_from(raw).unwrap_or(i64::MAX)
        };
        let param = f
            .param
            .as_deref()
            .and_then(|id| rules.params().iter().find(|p| p.id == id));
        let bitfield = match f.name.as_str() {
            "control" => Some(rules.control_bits()),
            "status" => Some(rules.status_bits()),
            _ => None,
        };
        let bits = bitfield.map(|b| decode_bits(b, raw));
        let pke = (f.name == "pke").then(|| {
            let (ak, spm, pnu) = rules.pkw().split_pke(raw as u16);
            PkeParts { ak, spm, pnu }
        });
        let text = match (&bits, &pke) {
            (Some(b), _) => {
                if !b.must_be_zero.is_empty() {
                    notes.push(format!(
                        "{}: reserved {} set; the controller must keep {} 0 ({})",
                        f.label.to_lowercase(),
                        bit_list(&b.must_be_zero),
                        if b.must_be_zero.len() == 1 {
                            "it"
                        } else {
                            "them"
                        },
                        bitfield.map_or("3.7", |bf| bf.source.as_str()),
                    ));
                }
                if !b.undefined.is_empty() {
                    notes.push(format!(
                        "{}: {} set but not described by the spec",
                        f.label.to_lowercase(),
                        bit_list(&b.undefined)
                    ));
                }
                b.to_string()
            }
            (None, Some(p)) => format!(
                "AK {} ({}), SPM {}, PNU {}",
                p.ak,
                match direction {
                    Direction::Out => rules.pkw().commands().named(p.ak.into()).to_string(),
                    Direction::In => rules.pkw().responses().named(p.ak.into()).to_string(),
                },
                u8::from(p.spm),
                p.pnu
            ),
            (None, None) if f.name == "pwe" => format!("0x{raw:08X}"),
            (None, None) => shown(param, value),
        };
        fields.push(FieldExplained {
            name: f.name.clone(),
            label: f.label.clone(),
            offset: f.field.offset(),
            length: f.field.len(),
            byte_order: f.field.order(),
            bytes: to_hex(f.field.bytes(bytes).unwrap_or(&[])),
            raw,
            value,
            param: param.map(ParamRef::of),
            pke,
            bits,
            text,
        });
    }
    Ok(Explanation {
        direction,
        length: module.length,
        byte_order: rules.options().byte_order,
        bytes: to_hex(bytes),
        fields,
        pkw,
        notes,
    })
}

fn pkw_of(rules: &Rules, direction: Direction) -> &crate::wire::PkwFields {
    match direction {
        Direction::Out => &rules.layout().output.pkw,
        Direction::In => &rules.layout().input.pkw,
    }
}

fn bit_list(bits: &[u32]) -> String {
    let list: Vec<String> = bits.iter().map(u32::to_string).collect();
    format!(
        "bit{} {}",
        if bits.len() == 1 { "" } else { "s" },
        list.join(", ")
    )
}

/// Explains a standalone 8-byte PKW block: a request (`Out`) or a response (`In`) (3.8).
pub fn explain_pkw(
    rules: &Rules,
    direction: Direction,
    bytes: &[u8],
) -> Result<PkwExplained, DecodeError> {
    let pkw = rules.pkw();
    Ok(match direction {
        Direction::Out => explain_request(pkw, PkwRequest::parse(pkw, bytes)?),
        Direction::In => explain_response(pkw, PkwResponse::parse(pkw, bytes)?),
    })
}

fn explain_request(rules: &PkwRules, b: PkwRequest) -> PkwExplained {
    let request = rules.request(&b);
    let mut notes = Vec::new();
    let info = rules.command_info(b.ak);
    let name = rules.commands().named(b.ak).to_string();
    match (request, info) {
        (Some(r), Some(info)) => {
            if let Ok(canon) = rules.encode_request(&r) {
                let word = matches!(
                    r,
                    Request::Write {
                        width: Width::Word,
                        ..
                    }
                );
                unused_fields(&b, &canon, &name, word, &mut notes);
            }
            if let Request::Write { pnu, width, .. } = r {
                width_note(rules, pnu, width, info.array, &mut notes);
            }
            match r {
                Request::Read {
                    pnu,
                    index: Some(i),
                }
                | Request::Write {
                    pnu,
                    index: Some(i),
                    ..
                } => array_note(rules, pnu, Some(i), &mut notes),
                Request::Count { pnu } => array_note(rules, pnu, None, &mut notes),
                _ => {}
            }
        }
        _ => notes.push(format!(
            "AK {} is not a command code of the spec (3.8)",
            b.ak.0
        )),
    }
    common_notes(
        rules,
        b.spm,
        b.pnu,
        request != Some(Request::None),
        &mut notes,
    );
    PkwExplained {
        direction: Direction::Out,
        ak: rules.commands().named(b.ak).into(),
        spm: b.spm,
        pnu: b.pnu,
        ind: b.ind,
        pwe: b.pwe,
        param: param_ref(rules, b.pnu, request != Some(Request::None)),
        text: match request {
            Some(Request::Write {
                pnu,
                index: Some(_),
                ..
            }) => rules.segment_text(pnu, b.pwe),
            _ => None,
        },
        request,
        reply: None,
        error: None,
        summary: rules.describe_request(&b),
        notes,
    }
}

fn explain_response(rules: &PkwRules, b: PkwResponse) -> PkwExplained {
    let reply = rules.reply(&b);
    let mut notes = Vec::new();
    match reply {
        None => notes.push(format!(
            "AK {} is not a response code of the spec (3.8)",
            b.ak.0
        )),
        Some(r) => {
            if let Ok(canon) = rules.encode_reply(&r) {
                let word = matches!(
                    r,
                    Reply::Value {
                        width: Width::Word,
                        ..
                    }
                );
                let name = rules.responses().named(b.ak).to_string();
                unused_fields(&b, &canon, &name, word, &mut notes);
            }
            if let Reply::Value {
                pnu, width, index, ..
            } = r
            {
                width_note(rules, pnu, width, index.is_some(), &mut notes);
            }
            if let Reply::Error { error, .. } = r {
                if !rules.errors().contains(error) {
                    notes.push(format!(
                        "error {} is not in the spec's error table (3.8)",
                        error.0
                    ));
                }
            }
        }
    }
    let used = !matches!(reply, Some(Reply::None));
    common_notes(rules, b.spm, b.pnu, used, &mut notes);
    PkwExplained {
        direction: Direction::In,
        ak: rules.responses().named(b.ak).into(),
        spm: b.spm,
        pnu: b.pnu,
        ind: b.ind,
        pwe: b.pwe,
        param: param_ref(rules, b.pnu, used),
        text: match reply {
            Some(Reply::Value { pnu, .. }) => rules.segment_text(pnu, b.pwe),
            _ => None,
        },
        error: match reply {
            Some(Reply::Error { error, .. }) => Some(rules.errors().named(error).into()),
            _ => None,
        },
        reply,
        request: None,
        summary: rules.describe_response(&b),
        notes,
    }
}

fn param_ref(rules: &PkwRules, pnu: u16, used: bool) -> Option<ParamRef> {
    used.then(|| rules.params().get(u32::from(pnu)).map(ParamRef::of))
        .flatten()
}

fn common_notes(rules: &PkwRules, spm: bool, pnu: u16, used: bool, notes: &mut Vec<String>) {
    if spm {
        notes.push("SPM set: spontaneous messages are not implemented (3.8)".to_owned());
    }
    if used && rules.params().get(u32::from(pnu)).is_none() {
        notes.push(format!("par {pnu} is not in the parameter table (3.3)"));
    }
}

/// Notes on fields the code does not use but that are not 0 (or not the canonical fill of a
/// 16-bit value, erratum PSD-ERRATUM-053).
fn unused_fields<C>(
    got: &Pkw<C>,
    canon: &Pkw<C>,
    name: &str,
    word_value: bool,
    notes: &mut Vec<String>,
) {
    if got.pnu != canon.pnu {
        notes.push(format!("PNU {} is not used by {name}", got.pnu));
    }
    if got.ind != canon.ind {
        notes.push(format!("IND 0x{:04X} is not used by {name}", got.ind));
    }
    if got.pwe != canon.pwe {
        notes.push(if word_value {
            format!(
                "PWE 0x{:08X}: the unused word of a 16-bit value should make it 0x{:08X} \
                 (erratum PSD-ERRATUM-053)",
                got.pwe, canon.pwe
            )
        } else {
            format!("PWE 0x{:08X} is not used by {name}", got.pwe)
        });
    }
}

/// Notes an array access the drive should refuse: beyond the elements (error 3) or on a
/// parameter that is no array (error 4).
fn array_note(rules: &PkwRules, pnu: u16, index: Option<u16>, notes: &mut Vec<String>) {
    let known = rules.params().get(u32::from(pnu)).is_some();
    match (rules.elements(pnu), index) {
        (Some(n), Some(i)) if i >= n => notes.push(format!(
            "index {i} is beyond the {n} elements of par {pnu} (3.8 error 3 \"error in the subindex\")"
        )),
        (None, _) if known => notes.push(format!(
            "par {pnu} is not an array (3.8 error 4 \"no array\")"
        )),
        _ => {}
    }
}

fn width_note(rules: &PkwRules, pnu: u16, width: Width, array: bool, notes: &mut Vec<String>) {
    let natural = if array {
        rules.element_width(pnu)
    } else {
        rules.width(pnu)
    };
    if let Some(n) = natural.filter(|n| *n != width) {
        notes.push(format!(
            "par {pnu} is a {} value but the block carries a {width} (3.8 error 5 \"incorrect data type\")",
            n
        ));
    }
}

impl fmt::Display for Explanation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} image, {} bytes, {}",
            self.direction, self.length, self.byte_order
        )?;
        for field in self
            .fields
            .iter()
            .filter(|x| x.byte_order != self.byte_order)
        {
            write!(f, "; {} {}", field.label, field.byte_order)?;
        }
        if self.fields.iter().any(|x| x.byte_order != self.byte_order) {
            f.write_str(" (3.5 UseAsBits)")?;
        }
        writeln!(f)?;
        writeln!(f, "  {}", self.bytes)?;
        let span =
            |x: &FieldExplained| format!("{}-{}", x.offset, x.offset + x.length.saturating_sub(1));
        let w_span = self.fields.iter().map(|x| span(x).len()).max().unwrap_or(0);
        let w_label = self.fields.iter().map(|x| x.label.len()).max().unwrap_or(0);
        let w_bytes = self.fields.iter().map(|x| x.bytes.len()).max().unwrap_or(0);
        for x in &self.fields {
            writeln!(
                f,
                "  {:<w_span$}  {:<w_label$}  {:<w_bytes$}  {}",
                span(x),
                x.label,
                x.bytes,
                x.text
            )?;
        }
        write!(f, "{}", self.pkw)?;
        for n in &self.notes {
            writeln!(f, "  note: {n}")?;
        }
        Ok(())
    }
}

impl fmt::Display for PkwExplained {
    /// `  PKW: read par 44 (Positioning window)` and one `  note:` line per note.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "  PKW: {}", self.summary)?;
        for n in &self.notes {
            writeln!(f, "  note: {n}")?;
        }
        Ok(())
    }
}
