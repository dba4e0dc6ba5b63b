//! Process images described field by field in the spec's words (manual 3.3, 3.4, 3.5, 4.4,
//! 4.6.4), for `drivespec decode psx3xx` in text and JSON.
//!
//! # JSON shape
//!
//! Stable: fields are only ever added. Optional keys are left out when absent.
//!
//! ```text
//! {
//!   "direction": "out" | "in",
//!   "format": 0 | 1 | 2,                 // output images only (ISDU 116)
//!   "image": "time-stamp" | "six-byte" | "eight-byte" | "input",
//!   "length": 6,                         // bytes
//!   "byte_order": "big-endian" | "little-endian",
//!   "bytes": "00 14 00 00 C8 00",
//!   "fields": [{
//!     "name": "control_word",            // spec field name
//!     "offset": 0, "length": 2,          // the word holding the field
//!     "bits": [2, 15],                   // first and last bit, for fields sharing a word
//!     "value": 20,                       // raw value (signed where the field is)
//!     "param": "110", "param_name": "Control word", "unit": "rpm",
//!     "word": {"bitfield", "word", "set": [{"bit", "name", "reserved"?}],
//!              "must_be_zero": [bit], "undefined": [bit], "value"?: {"name", "meaning"}},
//!     "time_stamp": {"kind": "inactive" | "immediate" | "delayed" | "reserved",
//!                    "delay_us"?: 40000, "text": "executes in 40.000 ms"},
//!     "command": {"code", "name"?, "action"?, "control_word"?, "meaning"?},
//!     "text": "one line"
//!   }],
//!   "warnings": ["control_word: must-be-zero bit 13 is set", ...],
//!   "summary": "one line"
//! }
//! ```
//!
//! Nothing here panics; allocation is bounded by the image and the spec tables.

use crate::error::ImageError;
use crate::rules::{names, Rules};
use crate::timestamp::{ms, StampMeaning};
use crate::wire::{FieldLayout, Image, ImageLayout};
use drivespec_positioner::{decode_bits, BitsDecoded, ByteOrder};
use drivespec_spec::hex::to_hex;
use drivespec_spec::psx3xx::{Direction, RunAction};
use drivespec_spec::DeviceModel;
use serde::Serialize;
use std::fmt;

/// A process image described (manual 3.3); see the module doc for the JSON shape.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Explained {
    /// `out` or `in`.
    pub direction: Direction,
    /// ISDU 116 format of an output image.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub format: Option<u8>,
    /// The spec's image name.
    pub image: String,
    /// Image length in bytes.
    pub length: usize,
    /// Byte order setting used.
    pub byte_order: ByteOrder,
    /// The bytes, hex.
    pub bytes: String,
    /// The fields in image order.
    pub fields: Vec<FieldExplained>,
    /// Must-be-zero bits set, reserved stamps, invalid speeds.
    pub warnings: Vec<String>,
    /// The image in one line.
    pub summary: String,
}

/// One field described (manual 3.3).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldExplained {
    /// Spec field name.
    pub name: String,
    /// Offset of the word holding the field.
    pub offset: usize,
    /// Length of the word in bytes.
    pub length: usize,
    /// First and last bit, when the field shares its word.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bits: Option<[u32; 2]>,
    /// Raw value.
    pub value: i64,
    /// Main ISDU parameter.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub param: Option<String>,
    /// Its name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub param_name: Option<String>,
    /// Its unit.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unit: Option<String>,
    /// Bits set, for status and control words.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub word: Option<BitsDecoded>,
    /// Meaning of a time stamp.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub time_stamp: Option<StampExplained>,
    /// Meaning of a time-stamp control code.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub command: Option<CommandExplained>,
    /// The field in one line.
    pub text: String,
}

/// A time stamp's meaning (manual 3.3.1).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StampExplained {
    /// Kind and delay.
    #[serde(flatten)]
    pub meaning: StampMeaning,
    /// In words.
    pub text: String,
}

/// A time-stamp control code's meaning (manual 3.3.1 bits 0–1).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CommandExplained {
    /// The code.
    pub code: u8,
    /// Spec name.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// What the drive does when the stamp fires.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub action: Option<RunAction>,
    /// Control-word bits the code stands for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub control_word: Option<u16>,
    /// One line.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub meaning: Option<String>,
}

/// Describes an output image of ISDU 116 `format` (manual 3.3.1); `model` enables the
/// per-model speed range of format 2 (manual 4.6.4, 3.2).
pub fn explain_output(
    rules: &Rules<'_>,
    format: u8,
    order: ByteOrder,
    model: Option<&DeviceModel>,
    bytes: &[u8],
) -> Result<Explained, ImageError> {
    let out = rules
        .output(format)
        .ok_or(ImageError::UnknownFormat { format })?;
    crate::repr::Output::parse(rules, format, order, bytes)?;
    Ok(explain(rules, &out.layout, order, model, bytes))
}

/// Describes an input image (manual 3.3.2, 3.4).
pub fn explain_input(
    rules: &Rules<'_>,
    order: ByteOrder,
    model: Option<&DeviceModel>,
    bytes: &[u8],
) -> Result<Explained, ImageError> {
    crate::repr::Input::parse(rules, order, bytes)?;
    Ok(explain(rules, rules.input(), order, model, bytes))
}

/// Describes image bytes already checked to have the layout's length.
fn explain(
    rules: &Rules<'_>,
    layout: &ImageLayout,
    order: ByteOrder,
    model: Option<&DeviceModel>,
    bytes: &[u8],
) -> Explained {
    let image = Image::new_unchecked(bytes, layout, order);
    let mut warnings = Vec::new();
    let fields: Vec<FieldExplained> = layout
        .fields()
        .iter()
        .map(|f| field(rules, layout, f, &image, model, &mut warnings))
        .collect();
    let summary = summary(layout, &fields);
    Explained {
        direction: layout.direction(),
        format: layout.format(),
        image: layout.name().to_owned(),
        length: layout.length(),
        byte_order: order,
        bytes: to_hex(image.bytes()),
        fields,
        warnings,
        summary,
    }
}

fn field(
    rules: &Rules<'_>,
    layout: &ImageLayout,
    f: &FieldLayout,
    image: &Image<'_, &[u8]>,
    model: Option<&DeviceModel>,
    warnings: &mut Vec<String>,
) -> FieldExplained {
    let family = rules.family();
    let value = image.get(f.name()).unwrap_or(0);
    let param = f.params().first().and_then(|id| family.parameter(id));
    let mut e = FieldExplained {
        name: f.name().to_owned(),
        offset: f.offset(),
        length: f.len(),
        bits: f
            .is_sub_word()
            .then(|| [f.bit(), f.bit() + f.bits().saturating_sub(1)]),
        value,
        param: param.map(|p| p.id.clone()),
        param_name: param.map(|p| p.name.clone()),
        unit: param.and_then(|p| p.unit.clone()),
        word: None,
        time_stamp: None,
        command: None,
        text: value.to_string(),
    };
    let ts = rules.timestamp();
    let in_ts_image = layout.format() == Some(ts.format);
    if let Some(b) = f.bitfield().and_then(|id| rules.bitfield(id)) {
        let d = decode_bits(b, u64::try_from(value).unwrap_or(0));
        for bit in &d.must_be_zero {
            warnings.push(format!("{}: must-be-zero bit {bit} is set", f.name()));
        }
        for bit in &d.undefined {
            warnings.push(format!("{}: bit {bit} is not described", f.name()));
        }
        e.text = d.to_string();
        e.word = Some(d);
    } else if in_ts_image && f.name() == names::STAMP {
        let meaning = StampMeaning::of(ts, u32::try_from(value).unwrap_or(u32::MAX));
        if meaning == StampMeaning::Reserved {
            warnings.push(format!(
                "stamp: {value} is neither a valid stamp (0..={}) nor the inactive marker {:#x}",
                ts.max_valid, ts.inactive
            ));
        }
        let text = meaning.to_string();
        e.text = format!("{value}: {text}");
        e.time_stamp = Some(StampExplained { meaning, text });
    } else if in_ts_image && f.name() == names::CONTROL {
        let code = u8::try_from(value).unwrap_or(u8::MAX);
        let c = ts.command(code);
        e.text = match c {
            Some(c) => format!(
                "{code} {}: {} (control word 0x{:04X})",
                c.name, c.meaning, c.control_word
            ),
            None => format!("{code}: not a control code of the spec"),
        };
        e.command = Some(CommandExplained {
            code,
            name: c.map(|c| c.name.clone()),
            action: c.map(|c| c.action),
            control_word: c.map(|c| c.control_word),
            meaning: c.map(|c| c.meaning.clone()),
        });
    } else if f.name() == names::TARGET_SPEED {
        let speed = &rules.protocol().target_speed;
        let positioning = family.parameter(&speed.positioning_param);
        let manual = family.parameter(&speed.manual_param);
        let unit = e.unit.clone().unwrap_or_default();
        if value == speed.use_parameter_value {
            e.text = format!(
                "{value}: use ISDU {} (positioning) / ISDU {} (manual run)",
                speed.positioning_param, speed.manual_param
            );
        } else {
            e.text = format!("{value} {unit}").trim_end().to_owned();
            let bad: Vec<String> = [positioning, manual]
                .into_iter()
                .flatten()
                .filter_map(|p| {
                    let r = family.resolve(p, model).range?;
                    (!r.contains(value)).then(|| format!("ISDU {} range {r}", p.id))
                })
                .collect();
            if !bad.is_empty() {
                warnings.push(format!(
                    "target_speed: {value} is outside {} (status bit {} would be set)",
                    bad.join(" and "),
                    speed.invalid_status_bit
                ));
                e.text.push_str(" (invalid)");
            }
        }
    } else {
        let mut text = value.to_string();
        if let Some(u) = &e.unit {
            text = format!("{text} {u}");
        }
        if let Some(p) = param {
            text = format!("{text} ({} ISDU {})", p.name, p.id);
        }
        e.text = text;
    }
    e
}

fn summary(layout: &ImageLayout, fields: &[FieldExplained]) -> String {
    let parts: Vec<String> = fields
        .iter()
        .map(|f| {
            if let Some(w) = &f.word {
                let names: Vec<&str> = w.set.iter().map(|b| b.name.as_str()).collect();
                let named = w
                    .value
                    .as_ref()
                    .map(|v| format!(" {}", v.name))
                    .unwrap_or_default();
                if names.is_empty() {
                    format!("{} 0x{:04X}{named}", f.name, f.value)
                } else {
                    format!("{} 0x{:04X}{named} [{}]", f.name, f.value, names.join(", "))
                }
            } else if let Some(c) = &f.command {
                format!(
                    "{} {}",
                    f.name,
                    c.name.clone().unwrap_or_else(|| c.code.to_string())
                )
            } else if let Some(t) = &f.time_stamp {
                match t.meaning.delay_us() {
                    Some(us) => format!("{} {} ({})", f.name, f.value, ms(us)),
                    None => format!("{} {} ({})", f.name, f.value, kind(&t.meaning)),
                }
            } else {
                format!("{} {}", f.name, f.value)
            }
        })
        .collect();
    let what = match layout.format() {
        Some(fmt) => format!("output format {fmt} ({})", layout.name()),
        None => format!("{} image", layout.name()),
    };
    format!("{what}: {}", parts.join(", "))
}

fn kind(m: &StampMeaning) -> &'static str {
    match m {
        StampMeaning::Inactive => "inactive",
        StampMeaning::Reserved => "reserved",
        StampMeaning::Immediate { .. } => "immediate",
        StampMeaning::Delayed { .. } => "delayed",
    }
}

impl fmt::Display for Explained {
    /// A header line with the image and bytes, one line per field, then the warnings.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let dir = match self.direction {
            Direction::Out => "process output",
            Direction::In => "process input",
        };
        match self.format {
            Some(fmt) => write!(f, "{dir} format {fmt}")?,
            None => f.write_str(dir)?,
        }
        write!(
            f,
            " ({}, {} bytes, {}): {}",
            self.image, self.length, self.byte_order, self.bytes
        )?;
        let width = self.fields.iter().map(|x| x.name.len()).max().unwrap_or(0);
        for x in &self.fields {
            let last = x.offset + x.length.saturating_sub(1);
            let mut at = format!("bytes {}-{last}", x.offset);
            if let Some([lo, hi]) = x.bits {
                at.push_str(&format!(" bits {lo}-{hi}"));
            }
            write!(f, "\n  {:<width$}  {at:<19} {}", x.name, x.text)?;
        }
        for w in &self.warnings {
            write!(f, "\n  warning: {w}")?;
        }
        Ok(())
    }
}

/// Describes a typed output (manual 3.3.1), for `drivespec encode psx3xx`.
pub fn explain_value(
    rules: &Rules<'_>,
    output: &crate::repr::Output,
    order: ByteOrder,
    model: Option<&DeviceModel>,
) -> Result<Explained, crate::error::EmitError> {
    let bytes = output.to_bytes(rules, order)?;
    let layout = rules
        .output_of(output.kind())
        .map_or(rules.input(), |o| &o.layout);
    Ok(explain(rules, layout, order, model, &bytes))
}
