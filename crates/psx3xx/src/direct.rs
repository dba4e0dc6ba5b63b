//! IO-Link Direct Parameter page 1 as the PSx3xx reports it through ISDU 0 (manual 3.1
//! ISDU 0; IEC 61131-9 B.1): decoding page bytes into named fields and building the page a
//! device of a model and output format reports.
//!
//! Every meaning comes from `protocol.direct_parameters` and `protocol.device_id`: the
//! MinCycleTime time bases (0x44 = time base 1, multiplier 4 = 8.0 ms), the M-sequence codes,
//! the ProcessDataIn/Out length encoding (BYTE = 1: octets = length + 1, derived from the
//! `pd_length` rows; BYTE = 0: bits), the vendor ID and the device ID
//! (model code × 100 + format suffix 01/02/04).
//!
//! JSON shape of [`DirectPage`] (fields absent when the bytes do not cover them):
//! `{"first_address", "bytes", "entries": [{"address", "subindex", "param", "name", "raw",
//! "fields": [{"name", "value", "meaning"}], "delivery"?, "text"}], "min_cycle_time_us"?,
//! "isdu"?, "operate_code"?, "operate_type"?, "operate_od_octets"?, "preoperate_code"?,
//! "preoperate_type"?, "preoperate_od_octets"?, "revision_major"?, "revision_minor"?,
//! "pd_in_octets"?, "pd_in_bits"?, "pd_in_sio"?, "pd_out_octets"?, "pd_out_bits"?,
//! "pd_out_sio"?, "pd_out_format"?, "vendor_id"?, "device_id"?, "model_code"?,
//! "device_id_format"?, "warnings": [text]}`.
//!
//! Nothing here panics; allocation is bounded by the page size.

use crate::error::DirectError;
use crate::rules::Rules;
use crate::timestamp::ms;
use drivespec_spec::hex::to_hex;
use drivespec_spec::psx3xx::DirectParameter;
use serde::Serialize;
use std::fmt;

/// IO-Link names of the page entries and their bit fields the decoder uses (IEC 61131-9 B.1).
pub mod names {
    /// Address 0x02 (IEC 61131-9 B.1).
    pub const MIN_CYCLE_TIME: &str = "MinCycleTime";
    /// Address 0x03 (IEC 61131-9 B.1).
    pub const M_SEQUENCE: &str = "M-sequenceCapability";
    /// Address 0x04 (IEC 61131-9 B.1).
    pub const REVISION: &str = "RevisionID";
    /// Address 0x05 (IEC 61131-9 B.1).
    pub const PD_IN: &str = "ProcessDataIn";
    /// Address 0x06 (IEC 61131-9 B.1).
    pub const PD_OUT: &str = "ProcessDataOut";
    /// Addresses 0x07–0x08, most significant first (IEC 61131-9 B.1).
    pub const VENDOR_ID: &str = "VendorID";
    /// Addresses 0x09–0x0B, most significant first (IEC 61131-9 B.1).
    pub const DEVICE_ID: &str = "DeviceID";
    /// MinCycleTime multiplier (IEC 61131-9 B.1).
    pub const MULTIPLIER: &str = "multiplier";
    /// MinCycleTime time base (IEC 61131-9 B.1).
    pub const TIME_BASE: &str = "time_base";
    /// M-sequence capability: ISDU supported (IEC 61131-9 B.1).
    pub const ISDU: &str = "isdu";
    /// M-sequence capability: OPERATE code (also the `m_sequence` mode name) (IEC 61131-9 B.1).
    pub const OPERATE: &str = "operate";
    /// M-sequence capability: PREOPERATE code (also the `m_sequence` mode name) (IEC 61131-9 B.1).
    pub const PREOPERATE: &str = "preoperate";
    /// RevisionID major (IEC 61131-9 B.1).
    pub const MAJOR: &str = "major";
    /// RevisionID minor (IEC 61131-9 B.1).
    pub const MINOR: &str = "minor";
    /// ProcessDataIn/Out length (IEC 61131-9 B.1).
    pub const LENGTH: &str = "length";
    /// ProcessDataIn/Out SIO (IEC 61131-9 B.1).
    pub const SIO: &str = "sio";
    /// ProcessDataIn/Out BYTE (IEC 61131-9 B.1).
    pub const BYTE: &str = "byte";
}

/// One bit field of an entry (IEC 61131-9 B.1).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct DpFieldValue {
    /// Spec field name.
    pub name: String,
    /// Its value.
    pub value: u32,
    /// What the spec says the field is.
    pub meaning: String,
}

/// One decoded page entry (manual 3.1 ISDU 0).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct DpEntry {
    /// Page address.
    pub address: u8,
    /// ISDU 0 sub-index.
    pub subindex: u8,
    /// Parameter id (`0.3`).
    pub param: String,
    /// IO-Link name.
    pub name: String,
    /// The byte.
    pub raw: u8,
    /// Bit fields.
    pub fields: Vec<DpFieldValue>,
    /// The manual's delivery byte, where it gives one and it does not vary.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delivery: Option<u8>,
    /// The entry decoded, one line.
    pub text: String,
}

/// Direct Parameter page 1 bytes, decoded (manual 3.1 ISDU 0; IEC 61131-9 B.1).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Default)]
pub struct DirectPage {
    /// Address of the first byte.
    pub first_address: u8,
    /// The bytes, hex.
    pub bytes: String,
    /// The entries covered.
    pub entries: Vec<DpEntry>,
    /// MinCycleTime, µs.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_cycle_time_us: Option<u32>,
    /// ISDU supported.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub isdu: Option<bool>,
    /// OPERATE M-sequence code.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub operate_code: Option<u32>,
    /// OPERATE M-sequence type.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub operate_type: Option<String>,
    /// On-request data octets in OPERATE.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub operate_od_octets: Option<u32>,
    /// PREOPERATE M-sequence code.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preoperate_code: Option<u32>,
    /// PREOPERATE M-sequence type.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preoperate_type: Option<String>,
    /// On-request data octets in PREOPERATE.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub preoperate_od_octets: Option<u32>,
    /// IO-Link revision, major.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub revision_major: Option<u32>,
    /// IO-Link revision, minor.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub revision_minor: Option<u32>,
    /// Process input length in octets (BYTE = 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pd_in_octets: Option<u32>,
    /// Process input length in bits (BYTE = 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pd_in_bits: Option<u32>,
    /// SIO mode supported.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pd_in_sio: Option<bool>,
    /// Process output length in octets (BYTE = 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pd_out_octets: Option<u32>,
    /// Process output length in bits (BYTE = 0).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pd_out_bits: Option<u32>,
    /// SIO flag of ProcessDataOut.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pd_out_sio: Option<bool>,
    /// The output format (ISDU 116) the ProcessDataOut byte stands for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pd_out_format: Option<u8>,
    /// Vendor ID.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vendor_id: Option<u32>,
    /// Device ID.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub device_id: Option<u32>,
    /// Model code (ISDU 79) in the device ID.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub model_code: Option<u32>,
    /// Output format the device ID's suffix stands for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub device_id_format: Option<u8>,
    /// Disagreements with the spec: delivery values, formats that do not match.
    pub warnings: Vec<String>,
}

/// The value of a bit field of an entry.
fn field_value(e: &DirectParameter, raw: u8, name: &str) -> Option<u32> {
    let f = e.fields.iter().find(|f| f.name == name)?;
    let mask = 1u32.checked_shl(f.bits).map_or(u32::MAX, |m| m - 1);
    Some(u32::from(raw).checked_shr(f.bit).unwrap_or(0) & mask)
}

/// The first address past the page.
fn page_end(rules: &Rules<'_>) -> usize {
    rules
        .protocol
        .direct_parameters
        .entries
        .iter()
        .map(|e| usize::from(e.address) + 1)
        .max()
        .unwrap_or(0)
}

/// Combines the bytes of the entries whose name starts with `prefix`, lowest address first;
/// None unless all of them are covered.
fn multi_byte(page: &DirectPage, prefix: &str, entries: &[DirectParameter]) -> Option<u32> {
    let mut parts: Vec<&DirectParameter> = entries
        .iter()
        .filter(|e| e.name.starts_with(prefix))
        .collect();
    parts.sort_by_key(|e| e.address);
    if parts.is_empty() || parts.len() > 4 {
        return None;
    }
    parts.iter().try_fold(0u32, |acc, e| {
        let raw = page.entries.iter().find(|d| d.address == e.address)?.raw;
        Some((acc << 8) | u32::from(raw))
    })
}

impl Rules<'_> {
    /// Decodes page bytes starting at page address `first` (manual 3.1 ISDU 0; IEC 61131-9
    /// B.1).
    pub fn decode_direct(&self, first: u8, bytes: &[u8]) -> Result<DirectPage, DirectError> {
        let dp = &self.protocol.direct_parameters;
        let end = page_end(self);
        if usize::from(first).saturating_add(bytes.len()) > end {
            return Err(DirectError::PastEnd {
                first,
                len: bytes.len(),
                end,
            });
        }
        let mut page = DirectPage {
            first_address: first,
            bytes: to_hex(bytes),
            ..DirectPage::default()
        };
        for (address, raw) in (first..).zip(bytes.iter().copied()) {
            let Some(e) = dp.entries.iter().find(|e| e.address == address) else {
                continue;
            };
            let fields = e
                .fields
                .iter()
                .map(|f| DpFieldValue {
                    name: f.name.clone(),
                    value: field_value(e, raw, &f.name).unwrap_or(0),
                    meaning: f.meaning.clone(),
                })
                .collect();
            let delivery = e.delivery.filter(|_| !e.varies);
            if let Some(d) = delivery.filter(|d| *d != raw) {
                page.warnings.push(format!(
                    "{} = 0x{raw:02X}, the manual delivers 0x{d:02X}",
                    e.name
                ));
            }
            let text = self.entry_text(&mut page, e, raw);
            page.entries.push(DpEntry {
                address,
                subindex: address.saturating_add(dp.subindex_offset),
                param: e.param.clone(),
                name: e.name.clone(),
                raw,
                fields,
                delivery,
                text,
            });
        }
        page.vendor_id = multi_byte(&page, names::VENDOR_ID, &dp.entries);
        if let Some(v) = page
            .vendor_id
            .filter(|v| *v != u32::from(self.protocol.device_id.vendor_id))
        {
            page.warnings.push(format!(
                "vendor ID 0x{v:04X}, the spec has 0x{:04X}",
                self.protocol.device_id.vendor_id
            ));
        }
        let ids = &self.protocol.device_id;
        let octets = dp
            .entries
            .iter()
            .filter(|e| e.name.starts_with(names::DEVICE_ID))
            .count();
        if u32::try_from(octets).ok() == Some(ids.octets) {
            page.device_id = multi_byte(&page, names::DEVICE_ID, &dp.entries);
        }
        if let Some(id) = page.device_id {
            let suffix = id.checked_rem(ids.multiplier);
            page.model_code = id.checked_div(ids.multiplier);
            page.device_id_format = ids
                .suffixes
                .iter()
                .find(|s| Some(s.suffix) == suffix)
                .map(|s| s.format);
            if page.device_id_format.is_none() {
                page.warnings.push(format!(
                    "device ID {id} ends with {:02}, no format suffix",
                    suffix.unwrap_or(0)
                ));
            }
        }
        if let (Some(a), Some(b)) = (page.pd_out_format, page.device_id_format) {
            if a != b {
                page.warnings.push(format!(
                    "ProcessDataOut stands for format {a}, the device ID for format {b}"
                ));
            }
        }
        Ok(page)
    }

    /// Fills the page's decoded fields from one entry; returns its one-line text.
    fn entry_text(&self, page: &mut DirectPage, e: &DirectParameter, raw: u8) -> String {
        let dp = &self.protocol.direct_parameters;
        let get = |name: &str| field_value(e, raw, name);
        match e.name.as_str() {
            names::MIN_CYCLE_TIME => {
                let (Some(base), Some(m)) = (get(names::TIME_BASE), get(names::MULTIPLIER)) else {
                    return e.meaning.clone();
                };
                let b = dp
                    .cycle_time_bases
                    .iter()
                    .find(|b| u32::from(b.code) == base);
                page.min_cycle_time_us =
                    b.and_then(|b| b.step_us.checked_mul(m)?.checked_add(b.offset_us));
                match page.min_cycle_time_us {
                    Some(us) => format!("{} (time base {base}, multiplier {m})", ms(us)),
                    None => format!("reserved time base {base}"),
                }
            }
            names::M_SEQUENCE => {
                page.isdu = get(names::ISDU).map(|v| v == 1);
                let mode = |mode: &str, code: Option<u32>| {
                    let row = dp
                        .m_sequences
                        .iter()
                        .find(|m| m.mode == mode && Some(u32::from(m.code)) == code);
                    (
                        code,
                        row.map(|r| r.m_type.clone()),
                        row.map(|r| r.od_octets),
                    )
                };
                (page.operate_code, page.operate_type, page.operate_od_octets) =
                    mode(names::OPERATE, get(names::OPERATE));
                (
                    page.preoperate_code,
                    page.preoperate_type,
                    page.preoperate_od_octets,
                ) = mode(names::PREOPERATE, get(names::PREOPERATE));
                let kind = |t: &Option<String>, od: Option<u32>| match (t, od) {
                    (Some(t), Some(od)) => format!("{t}, {od} octets on-request data"),
                    _ => "unknown code".to_owned(),
                };
                format!(
                    "ISDU {}; OPERATE {} ({}); PREOPERATE {} ({})",
                    if page.isdu == Some(true) {
                        "supported"
                    } else {
                        "not supported"
                    },
                    page.operate_code.unwrap_or(0),
                    kind(&page.operate_type, page.operate_od_octets),
                    page.preoperate_code.unwrap_or(0),
                    kind(&page.preoperate_type, page.preoperate_od_octets),
                )
            }
            names::REVISION => {
                page.revision_major = get(names::MAJOR);
                page.revision_minor = get(names::MINOR);
                format!(
                    "IO-Link revision {}.{}",
                    page.revision_major.unwrap_or(0),
                    page.revision_minor.unwrap_or(0)
                )
            }
            names::PD_IN | names::PD_OUT => {
                let byte = get(names::BYTE) == Some(1);
                let sio = get(names::SIO).map(|v| v == 1);
                let len = get(names::LENGTH).unwrap_or(0);
                let octets = byte.then(|| len.saturating_add(self.pd_octet_offset));
                let bits = (!byte).then_some(len);
                let text = match (octets, bits) {
                    (Some(o), _) => format!("{o} octets"),
                    (_, Some(b)) => format!("{b} bits"),
                    _ => String::new(),
                };
                if e.name == names::PD_IN {
                    (page.pd_in_octets, page.pd_in_bits, page.pd_in_sio) = (octets, bits, sio);
                    return format!("process input {text}");
                }
                (page.pd_out_octets, page.pd_out_bits, page.pd_out_sio) = (octets, bits, sio);
                page.pd_out_format = dp
                    .pd_lengths
                    .iter()
                    .find(|p| p.pd_out == raw)
                    .map(|p| p.format);
                match page.pd_out_format {
                    Some(f) => format!("process output {text} (format {f})"),
                    None => format!("process output {text} (no format has it)"),
                }
            }
            _ => match e.delivery.filter(|_| !e.varies) {
                Some(d) if d != raw => format!("{} (the manual delivers 0x{d:02X})", e.meaning),
                _ => e.meaning.clone(),
            },
        }
    }

    /// The page a device reports for ISDU 116 `format` and model code ISDU 79 (manual 3.1
    /// ISDU 0, ISDU 116): delivery bytes, the format's ProcessDataIn/Out, the device ID;
    /// master-written entries read 0.
    pub fn direct_page(&self, format: u8, model_code: u32) -> Result<Vec<u8>, DirectError> {
        let dp = &self.protocol.direct_parameters;
        let lengths = dp
            .pd_lengths
            .iter()
            .find(|p| p.format == format)
            .ok_or(DirectError::UnknownFormat { format })?;
        let ids = &self.protocol.device_id;
        let id = self
            .protocol
            .device_id_for(model_code, format)
            .filter(|id| ids.octets >= 4 || u64::from(*id) < 1u64 << (8 * ids.octets))
            .ok_or(DirectError::DeviceId {
                model_code,
                octets: ids.octets,
            })?;
        let mut id_parts: Vec<&DirectParameter> = dp
            .entries
            .iter()
            .filter(|e| e.name.starts_with(names::DEVICE_ID))
            .collect();
        id_parts.sort_by_key(|e| std::cmp::Reverse(e.address));
        let mut page = vec![0u8; page_end(self)];
        for e in &dp.entries {
            let byte = match e.name.as_str() {
                names::PD_OUT => lengths.pd_out,
                names::PD_IN => lengths.pd_in,
                n if n.starts_with(names::DEVICE_ID) => {
                    let pos = id_parts
                        .iter()
                        .position(|p| p.address == e.address)
                        .and_then(|p| u32::try_from(p).ok())
                        .unwrap_or(0);
                    id.checked_shr(8 * pos).map_or(0, |v| (v & 0xFF) as u8)
                }
                _ => e.delivery.unwrap_or(0),
            };
            if let Some(slot) = page.get_mut(usize::from(e.address)) {
                *slot = byte;
            }
        }
        Ok(page)
    }
}

impl fmt::Display for DirectPage {
    /// One line per entry: `0x02 MinCycleTime 0x44 8.000 ms (time base 1, multiplier 4)`,
    /// then the warnings.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Direct Parameter page 1 from 0x{:02X}: {}",
            self.first_address, self.bytes
        )?;
        let width = self.entries.iter().map(|e| e.name.len()).max().unwrap_or(0);
        for e in &self.entries {
            write!(
                f,
                "\n  0x{:02X} {:<width$}  0x{:02X}  {}",
                e.address, e.name, e.raw, e.text
            )?;
        }
        if let Some(v) = self.vendor_id {
            write!(f, "\n  vendor ID {v} (0x{v:04X})")?;
        }
        if let Some(id) = self.device_id {
            write!(f, "\n  device ID {id}")?;
            if let (Some(m), Some(fmt)) = (self.model_code, self.device_id_format) {
                write!(f, " = model {m}, format {fmt}")?;
            }
        }
        for w in &self.warnings {
            write!(f, "\n  warning: {w}")?;
        }
        Ok(())
    }
}
