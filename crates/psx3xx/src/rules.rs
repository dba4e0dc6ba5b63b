//! The spec's PSx3xx tables, read and checked once (manual 3.1, 3.3; IEC 61131-9 annex B, C).
//!
//! [`Rules`] borrows the family and its protocol tables and precomputes what the codecs need:
//! the layouts of the three output formats and the input image, the time-stamp control codes,
//! the ISDU ErrorTypes and the situations they answer. Names are the contract with `spec/`
//! (field names such as `control_word`, error case names such as `value-out-of-range`); every
//! number comes from the spec.

use crate::error::RulesError;
use crate::isdu::{CaseRule, ErrorCase, ErrorType, ErrorTypes};
use crate::repr::{OutputKind, Slot, TsCode, TsCodes};
use crate::wire::{FieldLayout, ImageLayout};
use drivespec_positioner::{ByteOrder, CodeEntry, CodeTable};
use drivespec_spec::psx3xx::{Protocol, Timestamp};
use drivespec_spec::{Bitfield, Family, FamilyId, Spec};

/// Spec names of the process-image fields the typed representations use (manual 3.3).
pub mod names {
    /// Format 0: control code, bits 0–1 (manual 3.3.1).
    pub const CONTROL: &str = "control";
    /// Format 0: time stamp, bits 2–15 (manual 3.3.1).
    pub const STAMP: &str = "stamp";
    /// Formats 1, 2: control word ISDU 110 (manual 3.3.1).
    pub const CONTROL_WORD: &str = "control_word";
    /// Formats 1, 2: target position ISDU 112 (manual 3.3.1).
    pub const TARGET: &str = "target";
    /// Format 2: target speed (manual 3.3.1, 4.6.4).
    pub const TARGET_SPEED: &str = "target_speed";
    /// Input: status word ISDU 64 (manual 3.3.2).
    pub const STATUS: &str = "status";
    /// Input: actual speed ISDU 65 (manual 3.3.2).
    pub const RPM: &str = "rpm";
    /// Input: actual position ISDU 67 (manual 3.3.2).
    pub const ACTUAL: &str = "actual";
}

/// The input image's fields and the Rust types that hold them (manual 3.3.2).
pub(crate) const INPUT_SLOTS: &[Slot] = &[
    Slot::new(names::STATUS, false, 16),
    Slot::new(names::RPM, true, 16),
    Slot::new(names::ACTUAL, true, 32),
];

/// One output format: its ISDU 116 value, kind and layout (manual 3.3.1).
#[derive(Debug, Clone, PartialEq)]
pub struct OutputLayout {
    /// ISDU 116 value.
    pub format: u8,
    /// Which typed representation it has.
    pub kind: OutputKind,
    /// Field layout.
    pub layout: ImageLayout,
}

/// The PSx3xx tables of the spec, checked for what the codecs need (manual 3.1, 3.3).
#[derive(Debug, Clone)]
pub struct Rules<'s> {
    pub(crate) family: &'s Family,
    pub(crate) protocol: &'s Protocol,
    pub(crate) wire: ByteOrder,
    pub(crate) swapped: ByteOrder,
    pub(crate) outputs: Vec<OutputLayout>,
    pub(crate) input: ImageLayout,
    pub(crate) ts_codes: CodeTable<TsCode>,
    pub(crate) ts_known: TsCodes,
    pub(crate) errors: CodeTable<ErrorType>,
    pub(crate) error_known: ErrorTypes,
    pub(crate) cases: Vec<CaseRule>,
    pub(crate) pd_octet_offset: u32,
}

/// Whether a spec field fits the Rust type of its slot.
fn fits(f: &FieldLayout, slot: &Slot) -> bool {
    if f.signed() {
        slot.signed && f.bits() <= slot.bits
    } else if slot.signed {
        f.bits() < slot.bits
    } else {
        f.bits() <= slot.bits
    }
}

/// Checks that `layout` has exactly the fields of `slots`, each fitting its type.
fn check_slots(layout: &ImageLayout, slots: &[Slot]) -> Result<(), RulesError> {
    let bad = |what: String| RulesError::Image {
        image: layout.name().to_owned(),
        what,
    };
    if layout.fields().len() != slots.len() {
        return Err(bad(format!(
            "fields {} where {} are expected",
            layout.field_names(),
            slots.iter().map(|s| s.name).collect::<Vec<_>>().join(", ")
        )));
    }
    for slot in slots {
        let f = layout
            .field(slot.name)
            .ok_or_else(|| bad(format!("no field {}", slot.name)))?;
        if !fits(f, slot) {
            return Err(bad(format!(
                "field {} ({} bits, {}) does not fit a {}{}",
                slot.name,
                f.bits(),
                f.data_type().as_str(),
                if slot.signed { "i" } else { "u" },
                slot.bits
            )));
        }
    }
    Ok(())
}

impl<'s> Rules<'s> {
    /// Reads the PSx3xx tables of a spec (manual 3.1, 3.3).
    pub fn from_spec(spec: &'s Spec) -> Result<Rules<'s>, RulesError> {
        Rules::from_family(spec.family(FamilyId::Psx3xx))
    }

    /// Reads the tables of the PSx3xx family (manual 3.1, 3.3).
    pub fn from_family(family: &'s Family) -> Result<Rules<'s>, RulesError> {
        let protocol = family.psx3xx().ok_or(RulesError::NoProtocol)?;
        let wire = ByteOrder::from(protocol.byte_order.wire);
        let swapped = ByteOrder::from(protocol.byte_order.swapped_by_some_masters);
        let mut outputs: Vec<OutputLayout> = Vec::new();
        for image in &protocol.process_outputs {
            let layout = ImageLayout::from_spec(image, wire)?;
            let format = image.format.ok_or_else(|| RulesError::Image {
                image: image.name.clone(),
                what: "an output image without a format".into(),
            })?;
            let kind = OutputKind::ALL
                .into_iter()
                .find(|k| {
                    let names = k.field_names();
                    names.len() == layout.fields().len()
                        && names.iter().all(|n| layout.field(n).is_some())
                })
                .ok_or_else(|| RulesError::Image {
                    image: image.name.clone(),
                    what: format!("fields {} match no output kind", layout.field_names()),
                })?;
            check_slots(&layout, kind.slots())?;
            if outputs.iter().any(|o| o.format == format || o.kind == kind) {
                return Err(RulesError::Image {
                    image: image.name.clone(),
                    what: format!("format {format} or its kind listed twice"),
                });
            }
            outputs.push(OutputLayout {
                format,
                kind,
                layout,
            });
        }
        for kind in OutputKind::ALL {
            if outputs.iter().all(|o| o.kind != kind) {
                return Err(RulesError::Table {
                    table: "protocol.process_output",
                    what: format!("no image with the fields {}", kind.field_names().join(", ")),
                });
            }
        }
        let input = ImageLayout::from_spec(&protocol.process_input, wire)?;
        check_slots(&input, INPUT_SLOTS)?;
        let ts = &protocol.timestamp;
        let ts_image = outputs
            .iter()
            .find(|o| o.kind == OutputKind::TimeStamp)
            .filter(|o| o.format == ts.format)
            .ok_or_else(|| RulesError::Table {
                table: "protocol.timestamp",
                what: format!("format {} is not the time-stamp image", ts.format),
            })?;
        let stamp_bits = ts_image
            .layout
            .field(names::STAMP)
            .map_or(0, FieldLayout::bits);
        if stamp_bits != ts.bits || ts.inactive > (1u32 << ts.bits.min(31)) - 1 {
            return Err(RulesError::Table {
                table: "protocol.timestamp",
                what: format!(
                    "a {}-bit stamp with inactive marker {:#x} in a {stamp_bits}-bit field",
                    ts.bits, ts.inactive
                ),
            });
        }
        let ts_codes = CodeTable::new(
            "protocol.timestamp.command",
            ts.commands
                .iter()
                .map(|c| CodeEntry::new(TsCode(c.code), &c.name, &c.meaning, &c.source)),
        )?;
        let ts_known = TsCodes::from_table(&ts_codes)?;
        let errors = CodeTable::new(
            "protocol.isdu_errors.code",
            protocol.isdu_errors.codes.iter().map(|c| {
                CodeEntry::new(
                    ErrorType(c.code),
                    &c.name,
                    &c.meaning,
                    &protocol.isdu_errors.source,
                )
            }),
        )?;
        let error_known = ErrorTypes::from_table(&errors)?;
        let mut cases = Vec::new();
        for case in ErrorCase::ALL {
            let row = protocol
                .isdu_errors
                .cases
                .iter()
                .find(|c| c.case == case.spec_name())
                .ok_or_else(|| RulesError::Table {
                    table: "protocol.isdu_errors.case",
                    what: format!("no case {:?}", case.spec_name()),
                })?;
            cases.push(CaseRule {
                case,
                code: ErrorType(row.code),
                acceptable: row.acceptable.iter().map(|c| ErrorType(*c)).collect(),
                params: row.params.clone(),
                text: row.text.clone(),
                source: row.source.clone(),
            });
        }
        let pd_octet_offset = octet_offset(protocol, &outputs, &input)?;
        Ok(Rules {
            family,
            protocol,
            wire,
            swapped,
            outputs,
            input,
            ts_codes,
            ts_known,
            errors,
            error_known,
            cases,
            pd_octet_offset,
        })
    }

    /// The family (parameters, bitfields, models, errata) (manual 3.1, 3.3).
    pub fn family(&self) -> &'s Family {
        self.family
    }

    /// The protocol tables (manual 3.1, 3.3).
    pub fn protocol(&self) -> &'s Protocol {
        self.protocol
    }

    /// The byte order on the wire, the default setting (manual 3.3.2; PSX-ERRATUM-050).
    pub fn wire_order(&self) -> ByteOrder {
        self.wire
    }

    /// The order some masters present instead (manual 3.3.2 note).
    pub fn swapped_order(&self) -> ByteOrder {
        self.swapped
    }

    /// The delivery process-data format, ISDU 116 (manual 3.1, 3.3.1).
    pub fn default_format(&self) -> u8 {
        self.protocol.format_select.default
    }

    /// The output formats in spec order (manual 3.3.1).
    pub fn outputs(&self) -> &[OutputLayout] {
        &self.outputs
    }

    /// The output format with an ISDU 116 value (manual 3.3.1).
    pub fn output(&self, format: u8) -> Option<&OutputLayout> {
        self.outputs.iter().find(|o| o.format == format)
    }

    /// The output format of a kind (manual 3.3.1).
    pub fn output_of(&self, kind: OutputKind) -> Option<&OutputLayout> {
        self.outputs.iter().find(|o| o.kind == kind)
    }

    /// The input image (manual 3.3.2).
    pub fn input(&self) -> &ImageLayout {
        &self.input
    }

    /// The time-stamp rules (manual 3.3.1).
    pub fn timestamp(&self) -> &'s Timestamp {
        &self.protocol.timestamp
    }

    /// The time-stamp control codes with their spec names (manual 3.3.1 bits 0–1).
    pub fn ts_codes(&self) -> &CodeTable<TsCode> {
        &self.ts_codes
    }

    /// The four control codes by name (manual 3.3.1).
    pub fn ts_known(&self) -> &TsCodes {
        &self.ts_known
    }

    /// The ISDU ErrorTypes with their IO-Link names (IEC 61131-9 annex C).
    pub fn error_types(&self) -> &CodeTable<ErrorType> {
        &self.errors
    }

    /// The ErrorTypes the adopted cases use, by IO-Link name (IEC 61131-9 annex C).
    pub fn error_known(&self) -> &ErrorTypes {
        &self.error_known
    }

    /// A bitfield by id (`status`, `control`; manual 3.4, 3.5).
    pub fn bitfield(&self, id: &str) -> Option<&'s Bitfield> {
        self.family.bitfield(id)
    }

    /// The status bitfield of the input image (manual 3.4).
    pub fn status_bits(&self) -> Option<&'s Bitfield> {
        self.bitfield(self.input.field(names::STATUS)?.bitfield()?)
    }

    /// Octets = length code + this, for BYTE = 1 in ProcessDataIn/Out (IEC 61131-9 B.1.6),
    /// derived from the spec's `pd_length` table and image lengths.
    pub fn pd_octet_offset(&self) -> u32 {
        self.pd_octet_offset
    }
}

/// The offset between an octet-counted PD length code and the octets, from the spec's
/// `pd_length` rows and the image lengths; rows counted in bits must give the image's bits.
fn octet_offset(
    protocol: &Protocol,
    outputs: &[OutputLayout],
    input: &ImageLayout,
) -> Result<u32, RulesError> {
    let dp = &protocol.direct_parameters;
    let entry = |name: &str| dp.entries.iter().find(|e| e.name == name);
    let field = |entry: Option<&drivespec_spec::psx3xx::DirectParameter>, name: &str| {
        entry
            .and_then(|e| e.fields.iter().find(|f| f.name == name))
            .map(|f| (f.bit, f.bits))
    };
    let pd_in = entry(crate::direct::names::PD_IN);
    let (Some(len), Some(byte)) = (
        field(pd_in, crate::direct::names::LENGTH),
        field(pd_in, crate::direct::names::BYTE),
    ) else {
        return Err(RulesError::Table {
            table: "protocol.direct_parameters",
            what: "ProcessDataIn needs the fields length and byte".into(),
        });
    };
    let code = |raw: u8, (bit, bits): (u32, u32)| {
        u32::from(raw).checked_shr(bit).unwrap_or(0) & ((1u32 << bits.min(31)) - 1)
    };
    let mut offset: Option<u32> = None;
    let mut check = |raw: u8, length: usize| -> Result<(), RulesError> {
        let n = code(raw, len);
        let octets = u32::try_from(length).unwrap_or(u32::MAX);
        let ok = if code(raw, byte) == 1 {
            let o = octets.checked_sub(n);
            let same = o.is_some() && (offset.is_none() || offset == o);
            offset = offset.or(o);
            same
        } else {
            octets.checked_mul(8) == Some(n)
        };
        if ok {
            Ok(())
        } else {
            Err(RulesError::Table {
                table: "protocol.direct_parameters.pd_length",
                what: format!("length byte {raw:#04x} does not match {length} octets"),
            })
        }
    };
    for row in &dp.pd_lengths {
        let out = outputs
            .iter()
            .find(|o| o.format == row.format)
            .ok_or_else(|| RulesError::Table {
                table: "protocol.direct_parameters.pd_length",
                what: format!("format {} has no output image", row.format),
            })?;
        check(row.pd_out, out.layout.length())?;
        check(row.pd_in, input.length())?;
    }
    offset.ok_or(RulesError::Table {
        table: "protocol.direct_parameters.pd_length",
        what: "no length counted in octets".into(),
    })
}
