//! Messages described in the spec's words (manual 4.1, 4.2): which parameter a PAR names,
//! the value with its unit, the bits a bit change touches, the PLC instructions written.
//!
//! The JSON form (`serde`) is part of the CLI contract: fields are only ever added.

use crate::plc::PlcCodec;
use crate::repr::{Data, Message};
use crate::rules::FrameRules;
use drivespec_spec::hex::to_hex;
use drivespec_spec::{Family, Parameter};
use serde::Serialize;

/// One message, described.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Explained {
    /// Message type name from the spec (`read-parameter`, …).
    #[serde(rename = "type")]
    pub kind: String,
    /// CMD code.
    pub cmd: u8,
    /// Drive address (0 for broadcasts).
    pub addr: u8,
    /// LUN (absent for a short acknowledge).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lun: Option<u8>,
    /// PAR (absent for a short acknowledge).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub par: Option<u8>,
    /// Data bytes, hex.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub data: Option<String>,
    /// The parameter PAR names (`Pr7`, `Pr64:65`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub parameter: Option<String>,
    /// Its name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// Raw value of the data.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub value: Option<i64>,
    /// Value as shown on the keypad, with unit (`25.3 %`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub shown: Option<String>,
    /// Bits a bit change sets or clears.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub bits: Vec<BitWrite>,
    /// PLC instructions in the data, as listing lines.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub instructions: Vec<String>,
    /// The rule of the manual the message breaks, if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub breaks: Option<Breach>,
    /// The whole message in one sentence.
    pub summary: String,
}

/// A rule of the manual a message breaks.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Breach {
    /// Requirement ID.
    pub requirement: &'static str,
    /// What is wrong.
    pub text: String,
}

/// One bit written by a bit change.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct BitWrite {
    /// `b99.14`.
    pub bit: String,
    /// Its name from the spec.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// New value.
    pub value: u8,
}

/// HPD-PLC-038 when PLC bytes `par`…`par + len − 1` lie outside the program area (4.1, 4.2).
fn outside_area(plc: Option<&PlcCodec>, par: u8, len: usize) -> Option<Breach> {
    plc?.outside_area(par, len).map(|o| Breach {
        requirement: "HPD-PLC-038",
        text: o.to_string(),
    })
}

/// Describes `msg` with the HPD family's parameters and PLC instruction set; `request` is
/// the request an answer follows, which tells whether its PAR is a PLC or parameter address.
pub fn explain(
    family: &Family,
    rules: &FrameRules,
    plc: Option<&PlcCodec>,
    msg: &Message,
    request: Option<&Message>,
) -> Explained {
    let kind = msg.kind();
    let type_name = kind.spec_name().to_owned();
    let mut e = Explained {
        kind: type_name,
        cmd: rules.code(kind),
        addr: msg.addr(),
        lun: None,
        par: None,
        data: None,
        parameter: None,
        name: None,
        value: None,
        shown: None,
        bits: Vec::new(),
        instructions: Vec::new(),
        breaks: None,
        summary: String::new(),
    };
    let drive = msg.addr();
    match *msg {
        Message::Ack { .. } => e.summary = format!("drive {drive} acknowledges"),
        Message::ReadParam { lun, par, .. } => {
            e.lun = Some(lun);
            e.par = Some(par);
            let what = name_param(family, &mut e, par, lun);
            e.summary = format!("read {what} from drive {drive}");
        }
        Message::ReadPlc { lun, par, .. } => {
            e.lun = Some(lun);
            e.par = Some(par);
            e.breaks = outside_area(plc, par, usize::from(lun));
            e.summary = format!("read {lun} PLC byte(s) at {par:#04x} from drive {drive}");
        }
        Message::Response { par, data, .. } if matches!(request, Some(Message::ReadPlc { .. })) => {
            e.lun = Some(data.len());
            e.par = Some(par);
            e.data = Some(to_hex(data.as_slice()));
            e.instructions = instructions(plc, par, &data);
            let listing = listing(&e.instructions);
            e.summary = format!("drive {drive} answers PLC bytes at {par:#04x}{listing}");
        }
        Message::Response { par, data, .. }
        | Message::WriteParam { par, data, .. }
        | Message::Broadcast { par, data } => {
            e.lun = Some(data.len());
            e.par = Some(par);
            e.data = Some(to_hex(data.as_slice()));
            let what = name_param(family, &mut e, par, data.len());
            let value = value_text(family, &mut e, par, &data);
            e.summary = match msg {
                Message::Response { .. } => format!("drive {drive} answers {what} = {value}"),
                Message::WriteParam { .. } => format!("write {what} = {value} to drive {drive}"),
                _ => format!("broadcast {what} = {value} to all drives"),
            };
        }
        Message::WritePlc { par, data, .. } => {
            e.lun = Some(data.len());
            e.par = Some(par);
            e.data = Some(to_hex(data.as_slice()));
            e.instructions = instructions(plc, par, &data);
            e.breaks = outside_area(plc, par, usize::from(data.len()));
            let listing = listing(&e.instructions);
            e.summary = format!("write PLC bytes at {par:#04x} on drive {drive}{listing}");
        }
        Message::BitChange {
            par, mask, value, ..
        } => {
            e.lun = Some(rules.bit_change_lun);
            e.par = Some(par);
            e.data = Some(to_hex(&[mask, value]));
            let owner = family.parameter_at_address(u32::from(par));
            if let Some(p) = owner {
                e.parameter = Some(p.id.clone());
                e.name = Some(p.name.clone());
            }
            let offset = owner
                .and_then(|p| p.address)
                .map_or(0, |a| u32::from(par).saturating_sub(a))
                * 8;
            for i in 0..8u32 {
                if mask >> i & 1 == 0 {
                    let bit = offset + i;
                    let (label, name) = match owner {
                        Some(p) => (format!("b{}.{bit}", p.number), bit_name(family, p, bit)),
                        None => (format!("{par:#04x}.{i}"), None),
                    };
                    e.bits.push(BitWrite {
                        bit: label,
                        name,
                        value: value >> i & 1,
                    });
                }
            }
            let list: Vec<String> = e
                .bits
                .iter()
                .map(|b| match &b.name {
                    Some(n) => format!("{} = {} ({n})", b.bit, b.value),
                    None => format!("{} = {}", b.bit, b.value),
                })
                .collect();
            e.summary = format!("set {} on drive {drive}", list.join(", "));
        }
    }
    e
}

/// The PLC instructions in `data` written or read at PLC address `par` (whole ones only).
fn instructions(plc: Option<&PlcCodec>, par: u8, data: &Data) -> Vec<String> {
    let mut out = Vec::new();
    let Some(codec) = plc else { return out };
    let mut at = 0;
    while let Some(rest) = data.as_slice().get(at..).filter(|r| !r.is_empty()) {
        match codec.decode(rest, usize::from(par) + at) {
            Ok((instr, len)) => {
                out.push(codec.format(&instr));
                at += len;
            }
            Err(_) => break,
        }
    }
    out
}

fn listing(instructions: &[String]) -> String {
    if instructions.is_empty() {
        String::new()
    } else {
        format!(": {}", instructions.join(", "))
    }
}

/// Fills parameter id and name for PAR/LUN; returns how to call it in a sentence.
fn name_param(family: &Family, e: &mut Explained, par: u8, lun: u8) -> String {
    let Some(p) = family.parameter_at_address(u32::from(par)) else {
        return format!("address {par:#04x}");
    };
    let double = lun == 4 && p.size == Some(2);
    let id = match (double, family.parameter_at_address(u32::from(par) + 2)) {
        (true, Some(high)) => format!("{}:{}", p.id, high.number),
        _ => p.id.clone(),
    };
    e.parameter = Some(id.clone());
    e.name = Some(p.name.clone());
    format!("{id} ({})", p.name)
}

/// Fills value and shown value; returns the shown value.
fn value_text(family: &Family, e: &mut Explained, par: u8, data: &Data) -> String {
    let Some(p) = family.parameter_at_address(u32::from(par)) else {
        let v = i64::from(data.unsigned());
        e.value = Some(v);
        return v.to_string();
    };
    let signed = p.data_type.signed() || data.len() == 4;
    let raw = if signed {
        i64::from(data.signed())
    } else {
        i64::from(data.unsigned())
    };
    e.value = Some(raw);
    let shown = shown(p, raw);
    e.shown = Some(shown.clone());
    shown
}

/// A raw value as the keypad shows it, with unit: `253` → `25.3 %`.
pub fn shown(p: &Parameter, raw: i64) -> String {
    let mut s = match p.scale {
        Some(scale) if scale != 1.0 => {
            let decimals = (-scale.log10()).ceil().clamp(0.0, 6.0) as usize;
            format!("{:.*}", decimals, p.display_value(raw))
        }
        _ => raw.to_string(),
    };
    if let Some(named) = p.value_named(raw) {
        s.push_str(&format!(" ({})", named.name));
    }
    if let Some(u) = &p.unit {
        s = format!("{s} {u}");
    }
    s
}

fn bit_name(family: &Family, p: &Parameter, bit: u32) -> Option<String> {
    family
        .bitfields_of(&p.id)
        .find_map(|b| b.bit(bit))
        .map(|b| b.name.clone())
}
