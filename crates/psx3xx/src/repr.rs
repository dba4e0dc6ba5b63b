//! Typed process images (manual 3.3.1 output formats 0, 1, 2; 3.3.2 input) and builders from
//! named fields.
//!
//! [`Output`] and [`Input`] are parsed from and emitted to bytes through the spec's layouts
//! ([`crate::wire`]) with a byte order setting. Which output kind an ISDU 116 format has is
//! decided by its field names in the spec. Parsing requires the exact image length:
//! shorter input is `Truncated { need, have }`, longer is `TrailingData`.

use crate::error::{BuildError, EmitError, ImageError};
use crate::rules::{names, Rules};
use crate::timestamp::Stamp;
use crate::wire::{Image, ImageLayout};
use drivespec_positioner::ByteOrder;
use serde::Serialize;

drivespec_positioner::open_enum! {
    /// Control code of the time-stamp image, bits 0–1 (manual 3.3.1); names from
    /// `protocol.timestamp.command`.
    pub struct TsCode(u8);
    /// The control codes looked up by spec name (manual 3.3.1).
    pub struct TsCodes {
        /// 0: abort the run.
        abort = "abort",
        /// 1: manual run to larger values.
        manual_forward = "manual-forward",
        /// 2: manual run to smaller values.
        manual_reverse = "manual-reverse",
        /// 3: positioning run to the ISDU 112 target.
        position = "position",
    }
}

/// A field name and the Rust type holding it (signedness, bits) (manual 3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slot {
    /// Spec field name.
    pub name: &'static str,
    /// The Rust type is signed.
    pub signed: bool,
    /// Bits of the Rust type.
    pub bits: u32,
}

impl Slot {
    /// A slot (manual 3.3 field tables).
    pub const fn new(name: &'static str, signed: bool, bits: u32) -> Slot {
        Slot { name, signed, bits }
    }
}

/// The three process output layouts (manual 3.3.1), told apart by their spec field names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum OutputKind {
    /// Control code and time stamp (manual 3.3.1 "time stamp function").
    TimeStamp,
    /// Control word and target (manual 3.3.1 "6 bytes of output data").
    ControlTarget,
    /// Target speed, control word and target (manual 3.3.1 "8 bytes of output data").
    SpeedControlTarget,
}

const TS_SLOTS: &[Slot] = &[
    Slot::new(names::CONTROL, false, 8),
    Slot::new(names::STAMP, false, 16),
];
const CT_SLOTS: &[Slot] = &[
    Slot::new(names::CONTROL_WORD, false, 16),
    Slot::new(names::TARGET, true, 32),
];
const SCT_SLOTS: &[Slot] = &[
    Slot::new(names::TARGET_SPEED, true, 16),
    Slot::new(names::CONTROL_WORD, false, 16),
    Slot::new(names::TARGET, true, 32),
];

impl OutputKind {
    /// All kinds (manual 3.3).
    pub const ALL: [OutputKind; 3] = [
        OutputKind::TimeStamp,
        OutputKind::ControlTarget,
        OutputKind::SpeedControlTarget,
    ];

    /// The spec field names of the kind (manual 3.3.1).
    pub fn field_names(self) -> &'static [&'static str] {
        match self {
            OutputKind::TimeStamp => &[names::CONTROL, names::STAMP],
            OutputKind::ControlTarget => &[names::CONTROL_WORD, names::TARGET],
            OutputKind::SpeedControlTarget => {
                &[names::TARGET_SPEED, names::CONTROL_WORD, names::TARGET]
            }
        }
    }

    /// The fields with their Rust types.
    pub(crate) fn slots(self) -> &'static [Slot] {
        match self {
            OutputKind::TimeStamp => TS_SLOTS,
            OutputKind::ControlTarget => CT_SLOTS,
            OutputKind::SpeedControlTarget => SCT_SLOTS,
        }
    }
}

/// Process output data, master to device (manual 3.3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Output {
    /// Format 0: control code and time stamp (manual 3.3.1, 4.4).
    TimeStamp {
        /// Control code (bits 0–1).
        control: TsCode,
        /// Time stamp (bits 2–15).
        stamp: Stamp,
    },
    /// Format 1: control word and target position (manual 3.3.1, 4.5).
    ControlTarget {
        /// Control word ISDU 110.
        control_word: u16,
        /// Target position ISDU 112.
        target: i32,
    },
    /// Format 2: target speed, control word and target position (manual 3.3.1, 4.6).
    SpeedControlTarget {
        /// Target speed in rpm, 0 = use ISDU 142/145.
        target_speed: i16,
        /// Control word ISDU 110.
        control_word: u16,
        /// Target position ISDU 112.
        target: i32,
    },
}

/// Process input data, device to master (manual 3.3.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize)]
pub struct Input {
    /// Status word ISDU 64.
    pub status: u16,
    /// Actual speed ISDU 65, rpm.
    pub rpm: i16,
    /// Actual position ISDU 67.
    pub actual: i32,
}

/// Parses `text` as a value of `field`: decimal, `0x` hex or `0b` binary (optionally
/// negative), or a name the spec gives the field's values (time-stamp command names, named
/// control words) (manual 3.3.1, 3.5).
pub fn parse_field_value(
    rules: &Rules<'_>,
    layout: &ImageLayout,
    field: &str,
    text: &str,
) -> Result<i64, BuildError> {
    let f = layout
        .field(field)
        .ok_or_else(|| BuildError::UnknownField {
            field: field.to_owned(),
            image: layout.name().to_owned(),
            known: layout.field_names(),
        })?;
    let t = text.trim();
    let (neg, digits) = match t.strip_prefix('-') {
        Some(rest) => (true, rest),
        None => (false, t),
    };
    let lower = digits.to_ascii_lowercase();
    let number = if let Some(h) = lower.strip_prefix("0x") {
        drivespec_spec::hex::parse_hex_digits(&h.replace('_', ""))
    } else if let Some(b) = lower.strip_prefix("0b") {
        i64::from_str_radix(&b.replace('_', ""), 2).ok()
    } else {
        lower.replace('_', "").parse::<i64>().ok()
    };
    if let Some(n) = number {
        return Ok(if neg { n.saturating_neg() } else { n });
    }
    let named = if f.name() == names::CONTROL && layout.format() == Some(rules.timestamp().format) {
        rules.ts_codes().code(t).map(|c| i64::from(c.0))
    } else {
        f.bitfield()
            .and_then(|id| rules.bitfield(id))
            .and_then(|b| b.values.iter().find(|v| v.name.eq_ignore_ascii_case(t)))
            .map(|v| v.value)
    };
    named.ok_or_else(|| BuildError::BadValue {
        field: field.to_owned(),
        text: text.to_owned(),
    })
}

/// Parses `name=value` assignments for the fields of `layout` (manual 3.3), for builders and
/// the command line.
pub fn parse_assignments<S: AsRef<str>>(
    rules: &Rules<'_>,
    layout: &ImageLayout,
    items: &[S],
) -> Result<Vec<(String, i64)>, BuildError> {
    let mut out: Vec<(String, i64)> = Vec::with_capacity(items.len());
    for item in items {
        let item = item.as_ref();
        let Some((name, value)) = item.split_once('=') else {
            return Err(BuildError::BadValue {
                field: item.to_owned(),
                text: String::new(),
            });
        };
        let name = name.trim();
        let v = parse_field_value(rules, layout, name, value)?;
        out.push((name.to_owned(), v));
    }
    Ok(out)
}

/// Collects named values for `layout`, filling neutral values from the spec where a field
/// has one (target speed 0 = use the ISDU value; stamp = inactive marker).
fn collect<S: AsRef<str>>(
    rules: &Rules<'_>,
    layout: &ImageLayout,
    fields: &[(S, i64)],
) -> Result<Vec<u8>, BuildError> {
    let mut buf = vec![0u8; layout.length()];
    let mut image = Image::new_unchecked(&mut buf[..], layout, rules.wire);
    for (i, (name, _)) in fields.iter().enumerate() {
        let name = name.as_ref();
        if layout.field(name).is_none() {
            return Err(BuildError::UnknownField {
                field: name.to_owned(),
                image: layout.name().to_owned(),
                known: layout.field_names(),
            });
        }
        if fields
            .iter()
            .take(i)
            .any(|(other, _)| other.as_ref() == name)
        {
            return Err(BuildError::DuplicateField {
                field: name.to_owned(),
            });
        }
    }
    for f in layout.fields() {
        let given = fields
            .iter()
            .find(|(n, _)| n.as_ref() == f.name())
            .map(|(_, v)| *v);
        let neutral = match f.name() {
            names::TARGET_SPEED => Some(rules.protocol.target_speed.use_parameter_value),
            names::STAMP => Some(i64::from(rules.timestamp().inactive)),
            _ => None,
        };
        let value = given.or(neutral).ok_or_else(|| BuildError::MissingField {
            field: f.name().to_owned(),
            image: layout.name().to_owned(),
        })?;
        image.set(f.name(), value)?;
    }
    Ok(buf)
}

/// Checks the exact length of an image.
fn exact(layout: &ImageLayout, bytes: &[u8]) -> Result<(), ImageError> {
    let length = layout.length();
    match bytes.len() {
        n if n < length => Err(ImageError::Truncated {
            need: length,
            have: n,
        }),
        n if n > length => Err(ImageError::TrailingData {
            length,
            extra: n - length,
        }),
        _ => Ok(()),
    }
}

/// A value read through a layout the rules checked to fit `T`.
fn narrow<T: TryFrom<i64> + Default>(v: Option<i64>) -> T {
    v.and_then(|v| T::try_from(v).ok()).unwrap_or_default()
}

impl Output {
    /// The layout kind (manual 3.3).
    pub fn kind(&self) -> OutputKind {
        match self {
            Output::TimeStamp { .. } => OutputKind::TimeStamp,
            Output::ControlTarget { .. } => OutputKind::ControlTarget,
            Output::SpeedControlTarget { .. } => OutputKind::SpeedControlTarget,
        }
    }

    /// The ISDU 116 format of this kind in the spec (manual 3.3.1).
    pub fn format(&self, rules: &Rules<'_>) -> Option<u8> {
        rules.output_of(self.kind()).map(|o| o.format)
    }

    /// The fields by spec name, in image order (manual 3.3.1).
    pub fn values(&self) -> Vec<(&'static str, i64)> {
        match *self {
            Output::TimeStamp { control, stamp } => vec![
                (names::CONTROL, i64::from(control.0)),
                (names::STAMP, i64::from(stamp.0)),
            ],
            Output::ControlTarget {
                control_word,
                target,
            } => vec![
                (names::CONTROL_WORD, i64::from(control_word)),
                (names::TARGET, i64::from(target)),
            ],
            Output::SpeedControlTarget {
                target_speed,
                control_word,
                target,
            } => vec![
                (names::TARGET_SPEED, i64::from(target_speed)),
                (names::CONTROL_WORD, i64::from(control_word)),
                (names::TARGET, i64::from(target)),
            ],
        }
    }

    /// The control word, for formats 1 and 2 (manual 3.3).
    pub fn control_word(&self) -> Option<u16> {
        match *self {
            Output::ControlTarget { control_word, .. }
            | Output::SpeedControlTarget { control_word, .. } => Some(control_word),
            Output::TimeStamp { .. } => None,
        }
    }

    /// The target position, for formats 1 and 2 (manual 3.3).
    pub fn target(&self) -> Option<i32> {
        match *self {
            Output::ControlTarget { target, .. } | Output::SpeedControlTarget { target, .. } => {
                Some(target)
            }
            Output::TimeStamp { .. } => None,
        }
    }

    /// Reads an output image of ISDU 116 `format` from exactly its bytes (manual 3.3.1).
    pub fn parse(
        rules: &Rules<'_>,
        format: u8,
        order: ByteOrder,
        bytes: &[u8],
    ) -> Result<Output, ImageError> {
        let out = rules
            .output(format)
            .ok_or(ImageError::UnknownFormat { format })?;
        exact(&out.layout, bytes)?;
        let image = Image::new_checked(bytes, &out.layout, order)?;
        Ok(Output::read(out.kind, &image))
    }

    fn read<T: AsRef<[u8]>>(kind: OutputKind, image: &Image<'_, T>) -> Output {
        let get = |n| image.get(n);
        match kind {
            OutputKind::TimeStamp => Output::TimeStamp {
                control: TsCode(narrow(get(names::CONTROL))),
                stamp: Stamp(narrow(get(names::STAMP))),
            },
            OutputKind::ControlTarget => Output::ControlTarget {
                control_word: narrow(get(names::CONTROL_WORD)),
                target: narrow(get(names::TARGET)),
            },
            OutputKind::SpeedControlTarget => Output::SpeedControlTarget {
                target_speed: narrow(get(names::TARGET_SPEED)),
                control_word: narrow(get(names::CONTROL_WORD)),
                target: narrow(get(names::TARGET)),
            },
        }
    }

    /// Bytes `emit` writes: the image length of the kind's format (manual 3.3.1).
    pub fn buffer_len(&self, rules: &Rules<'_>) -> usize {
        rules
            .output_of(self.kind())
            .map_or(0, |o| o.layout.length())
    }

    /// Writes the image in `order`; returns the bytes written (manual 3.3.1).
    pub fn emit(
        &self,
        rules: &Rules<'_>,
        order: ByteOrder,
        out: &mut [u8],
    ) -> Result<usize, EmitError> {
        let Some(o) = rules.output_of(self.kind()) else {
            return Ok(0);
        };
        let need = o.layout.length();
        let have = out.len();
        let buf = out
            .get_mut(..need)
            .ok_or(EmitError::Buffer { need, have })?;
        buf.fill(0);
        let mut image = Image::new_unchecked(buf, &o.layout, order);
        for (name, value) in self.values() {
            image.set(name, value)?;
        }
        Ok(need)
    }

    /// The image as bytes in `order` (manual 3.3.1).
    pub fn to_bytes(&self, rules: &Rules<'_>, order: ByteOrder) -> Result<Vec<u8>, EmitError> {
        let mut buf = vec![0u8; self.buffer_len(rules)];
        let n = self.emit(rules, order, &mut buf)?;
        buf.truncate(n);
        Ok(buf)
    }

    /// Builds the output of ISDU 116 `format` from named fields (manual 3.3.1); the target
    /// speed defaults to "use the ISDU value" and the stamp to the inactive marker.
    pub fn from_fields<S: AsRef<str>>(
        rules: &Rules<'_>,
        format: u8,
        fields: &[(S, i64)],
    ) -> Result<Output, BuildError> {
        let out = rules
            .output(format)
            .ok_or(BuildError::UnknownFormat { format })?;
        let buf = collect(rules, &out.layout, fields)?;
        let image = Image::new_unchecked(&buf[..], &out.layout, rules.wire);
        Ok(Output::read(out.kind, &image))
    }
}

impl Input {
    /// The fields by spec name, in image order (manual 3.3.2).
    pub fn values(&self) -> Vec<(&'static str, i64)> {
        vec![
            (names::STATUS, i64::from(self.status)),
            (names::RPM, i64::from(self.rpm)),
            (names::ACTUAL, i64::from(self.actual)),
        ]
    }

    /// Reads the input image from exactly its bytes (manual 3.3.2).
    pub fn parse(rules: &Rules<'_>, order: ByteOrder, bytes: &[u8]) -> Result<Input, ImageError> {
        exact(&rules.input, bytes)?;
        let image = Image::new_checked(bytes, &rules.input, order)?;
        Ok(Input::read(&image))
    }

    fn read<T: AsRef<[u8]>>(image: &Image<'_, T>) -> Input {
        Input {
            status: narrow(image.get(names::STATUS)),
            rpm: narrow(image.get(names::RPM)),
            actual: narrow(image.get(names::ACTUAL)),
        }
    }

    /// Bytes `emit` writes (manual 3.3.2).
    pub fn buffer_len(rules: &Rules<'_>) -> usize {
        rules.input.length()
    }

    /// Writes the image in `order`; returns the bytes written (manual 3.3.2).
    pub fn emit(
        &self,
        rules: &Rules<'_>,
        order: ByteOrder,
        out: &mut [u8],
    ) -> Result<usize, EmitError> {
        let need = rules.input.length();
        let have = out.len();
        let buf = out
            .get_mut(..need)
            .ok_or(EmitError::Buffer { need, have })?;
        buf.fill(0);
        let mut image = Image::new_unchecked(buf, &rules.input, order);
        for (name, value) in self.values() {
            image.set(name, value)?;
        }
        Ok(need)
    }

    /// The image as bytes in `order` (manual 3.3.2).
    pub fn to_bytes(&self, rules: &Rules<'_>, order: ByteOrder) -> Result<Vec<u8>, EmitError> {
        let mut buf = vec![0u8; rules.input.length()];
        let n = self.emit(rules, order, &mut buf)?;
        buf.truncate(n);
        Ok(buf)
    }

    /// Builds the input image from named fields, all required (manual 3.3.2).
    pub fn from_fields<S: AsRef<str>>(
        rules: &Rules<'_>,
        fields: &[(S, i64)],
    ) -> Result<Input, BuildError> {
        let buf = collect(rules, &rules.input, fields)?;
        let image = Image::new_unchecked(&buf[..], &rules.input, rules.wire);
        Ok(Input::read(&image))
    }
}
