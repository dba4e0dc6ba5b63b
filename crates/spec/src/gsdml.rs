//! A GSDML V2.35 device description (ISO 15745-4 profile "PROFINET Device Profile") written
//! from the PSD4xx spec: the identity of `[protocol.profinet]`, the DAP, the 14-byte output
//! and 16-byte input modules of bus description 3.5 (control word and status as bit lists,
//! "UseAsBits"), and one parameter record per writable parameter (3.2.2: a control byte, then
//! the value).
//!
//! The rules the document follows (tested in `tests/gsdml.rs`): it is well-formed XML in the
//! GSDML namespace; every `ID` is unique; every `TextId` used is defined once in the
//! `ExternalTextList`; every `ModuleItemTarget` names a `ModuleItem`; the IO data of each
//! module is exactly as long as its module in 3.5, with the fields at their offsets; each
//! record is 1 control byte plus the value (3.2.2 lengths); `AllowedValues` and
//! `DefaultValue` come from the parameter table for the model chosen. Allocation is bounded
//! by the spec's size; nothing panics.

use crate::psd4xx::{Field, Module, PnModule};
use crate::{DataType, DeviceModel, Family, Parameter};
use drivespec_report::escape;
use std::fmt::Write as _;

/// Smallest send clock the device accepts, in units of 31.25 µs (GSDML `MinDeviceInterval`,
/// `SendClock`). A choice: 32 is the 1 ms send clock PROFINET RT class 1 controllers use by
/// default; the manual names no cycle time.
const SEND_CLOCK: u32 = 32;

/// Reduction ratios offered for RT class 1 at that send clock (IEC 61158-6-10 allows powers of
/// two from 1 to 512), giving cycles of 1 ms to 512 ms.
const REDUCTION_RATIOS: &str = "1 2 4 8 16 32 64 128 256 512";

/// Why no GSDML can be written.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum GsdmlError {
    /// The family has no PROFINET protocol tables (only PSD4xx has them).
    #[error("family {0} is not a PROFINET device")]
    NotProfinet(String),
}

/// The GSDML document for `family` (PSD4xx), with parameter ranges and defaults of `model`.
pub fn psd4xx(family: &Family, model: &DeviceModel) -> Result<String, GsdmlError> {
    let Some(proto) = family.psd4xx() else {
        return Err(GsdmlError::NotProfinet(family.id().as_str().to_owned()));
    };
    let pn = &proto.profinet;
    let pd = &proto.process_data;
    let mut w = Writer::default();
    w.raw("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
    let _ = writeln!(
        w.out,
        "<!-- Written by drivespec from spec/psd4xx ({}; model {}). Identity: {}. -->",
        family.info.manual, model.id, pn.source
    );
    w.open(
        "ISO15745Profile",
        &[
            ("xmlns", "http://www.profibus.com/GSDML/2003/11/DeviceProfile"),
            ("xmlns:xsi", "http://www.w3.org/2001/XMLSchema-instance"),
            (
                "xsi:schemaLocation",
                "http://www.profibus.com/GSDML/2003/11/DeviceProfile ..\\xsd\\GSDML-DeviceProfile-V2.35.xsd",
            ),
        ],
    );
    profile_header(&mut w);
    w.open("ProfileBody", &[]);
    w.open(
        "DeviceIdentity",
        &[
            ("VendorID", &format!("0x{:04X}", pn.vendor_id)),
            ("DeviceID", &format!("0x{:04X}", pn.device_id)),
        ],
    );
    let info = w.text("IDT_INFO_Device", &family.info.name);
    w.empty("InfoText", &[("TextId", &info)]);
    w.empty("VendorName", &[("Value", &pn.vendor_name)]);
    w.close("DeviceIdentity");
    w.open("DeviceFunction", &[]);
    w.empty(
        "Family",
        &[
            ("MainFamily", "Drives"),
            ("ProductFamily", &family.info.name),
        ],
    );
    w.close("DeviceFunction");
    w.open("ApplicationProcess", &[]);
    dap(&mut w, family, model);
    w.open("ModuleList", &[]);
    io_module(
        &mut w,
        family,
        model,
        &pn.output,
        &pd.output,
        Direction::Output,
    );
    io_module(
        &mut w,
        family,
        model,
        &pn.input,
        &pd.input,
        Direction::Input,
    );
    w.close("ModuleList");
    w.open("ExternalTextList", &[]);
    w.open("PrimaryLanguage", &[]);
    let texts = std::mem::take(&mut w.texts);
    for (id, value) in &texts {
        w.empty("Text", &[("TextId", id), ("Value", value)]);
    }
    w.close("PrimaryLanguage");
    w.close("ExternalTextList");
    w.close("ApplicationProcess");
    w.close("ProfileBody");
    w.close("ISO15745Profile");
    Ok(w.out)
}

fn profile_header(w: &mut Writer) {
    w.open("ProfileHeader", &[]);
    for (tag, value) in [
        ("ProfileIdentification", "PROFINET Device Profile"),
        ("ProfileRevision", "1.00"),
        ("ProfileName", "Device Profile for PROFINET Devices"),
        ("ProfileSource", "PROFIBUS Nutzerorganisation e. V. (PNO)"),
        ("ProfileClassID", "Device"),
    ] {
        w.leaf(tag, value);
    }
    w.open("ISO15745Reference", &[]);
    w.leaf("ISO15745Part", "4");
    w.leaf("ISO15745Edition", "1");
    w.leaf("ProfileTechnology", "GSDML");
    w.close("ISO15745Reference");
    w.close("ProfileHeader");
}

fn dap(w: &mut Writer, family: &Family, model: &DeviceModel) {
    let Some(proto) = family.psd4xx() else { return };
    let pn = &proto.profinet;
    let pd = &proto.process_data;
    let slots = [pn.dap.slot, pn.output.slot, pn.input.slot];
    let (lo, hi) = (
        slots.iter().min().copied().unwrap_or(0),
        slots.iter().max().copied().unwrap_or(0),
    );
    w.open("DeviceAccessPointList", &[]);
    w.open(
        "DeviceAccessPointItem",
        &[
            ("ID", "DAP"),
            ("PhysicalSlots", &format!("{lo}..{hi}")),
            ("ModuleIdentNumber", &hex32(pn.dap.module_ident)),
            ("MinDeviceInterval", &SEND_CLOCK.to_string()),
            ("DNS_CompatibleName", &default_name(proto)),
            ("FixedInSlots", &pn.dap.slot.to_string()),
            ("ObjectUUID_LocalIndex", &pn.instance.to_string()),
            ("RequiredSchemaVersion", "V2.35"),
            ("CheckDeviceID_Allowed", "true"),
            ("NameOfStationNotTransferable", "false"),
            ("LLDP_NoD_Supported", "true"),
            ("ResetToFactoryModes", "2"),
        ],
    );
    let name = w.text("IDT_NAME_DAP", &model.name);
    let info = w.text(
        "IDT_INFO_DAP",
        &format!(
            "{} ({}), PROFINET IO RT{}",
            model.name,
            family.info.title,
            if pd.rt_only { " only" } else { "" }
        ),
    );
    module_info(w, &name, &info, Some(&pn.vendor_name));
    w.empty(
        "CertificationInfo",
        &[("ConformanceClass", "A"), ("NetloadClass", "I")],
    );
    // With IOPS and IOCS: each submodule adds one byte to each frame it has data in, and the
    // IOxS of the DAP's submodules ride in the input frame (IEC 61158-6-10 "IOCR").
    let dap_subs = pn.dap.submodule.len();
    let max_in = pd.input.length + 1 + 1 + dap_subs;
    let max_out = pd.output.length + 1 + 1 + dap_subs;
    w.empty(
        "IOConfigData",
        &[
            ("MaxInputLength", &max_in.to_string()),
            ("MaxOutputLength", &max_out.to_string()),
        ],
    );
    w.open("UseableModules", &[]);
    for m in [&pn.output, &pn.input] {
        let slot = m.slot.to_string();
        w.empty(
            "ModuleItemRef",
            &[
                ("ModuleItemTarget", &module_id(m)),
                ("AllowedInSlots", &slot),
                ("FixedInSlots", &slot),
            ],
        );
    }
    w.close("UseableModules");
    w.open("VirtualSubmoduleList", &[]);
    let mut system = Vec::new();
    for s in &pn.dap.submodule {
        if s.subslot >= 0x8000 {
            system.push(s);
            continue;
        }
        w.open(
            "VirtualSubmoduleItem",
            &[
                ("ID", &format!("DAP_{:04X}", s.subslot)),
                ("SubmoduleIdentNumber", &hex32(s.ident)),
                ("Writeable_IM_Records", "1 2 3"),
                ("MayIssueProcessAlarm", "false"),
            ],
        );
        w.empty("IOData", &[]);
        let n = w.text(&format!("IDT_NAME_DAP_{:04X}", s.subslot), &s.name);
        module_info(w, &n, &n, None);
        w.close("VirtualSubmoduleItem");
    }
    w.close("VirtualSubmoduleList");
    w.open("SystemDefinedSubmoduleList", &[]);
    for s in system {
        let id = format!("DAP_{:04X}", s.subslot);
        let text = w.text(&format!("IDT_NAME_{id}"), &s.name);
        if s.subslot & 0xFF00 == 0x8000 && s.subslot & 0x00FF == 0 {
            w.open(
                "InterfaceSubmoduleItem",
                &[
                    ("ID", &id),
                    ("SubslotNumber", &s.subslot.to_string()),
                    ("SubmoduleIdentNumber", &hex32(s.ident)),
                    ("TextId", &text),
                    ("SupportedRT_Classes", "RT_CLASS_1"),
                    ("SupportedProtocols", "LLDP"),
                ],
            );
            w.open("ApplicationRelations", &[("StartupMode", "Advanced")]);
            w.empty(
                "TimingProperties",
                &[
                    ("SendClock", &SEND_CLOCK.to_string()),
                    ("ReductionRatio", REDUCTION_RATIOS),
                ],
            );
            w.close("ApplicationRelations");
            w.close("InterfaceSubmoduleItem");
        } else {
            w.open(
                "PortSubmoduleItem",
                &[
                    ("ID", &id),
                    ("SubslotNumber", &s.subslot.to_string()),
                    ("SubmoduleIdentNumber", &hex32(s.ident)),
                    ("TextId", &text),
                    ("MaxPortRxDelay", "350"),
                    ("MaxPortTxDelay", "160"),
                ],
            );
            w.open("MAUTypeList", &[]);
            // MAU type 16: 100BASE-TXFD (IEC 61158-6-10 "MAUType").
            w.empty("MAUTypeItem", &[("Value", "16")]);
            w.close("MAUTypeList");
            w.close("PortSubmoduleItem");
        }
    }
    w.close("SystemDefinedSubmoduleList");
    w.close("DeviceAccessPointItem");
    w.close("DeviceAccessPointList");
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum Direction {
    Output,
    Input,
}

fn module_id(m: &PnModule) -> String {
    format!("MOD_{:08X}", m.module_ident)
}

fn io_module(
    w: &mut Writer,
    family: &Family,
    model: &DeviceModel,
    ident: &PnModule,
    module: &Module,
    dir: Direction,
) {
    let id = module_id(ident);
    w.open(
        "ModuleItem",
        &[
            ("ID", &id),
            ("ModuleIdentNumber", &hex32(ident.module_ident)),
        ],
    );
    let name = w.text(&format!("IDT_NAME_{id}"), &ident.name);
    let info = w.text(
        &format!("IDT_INFO_{id}"),
        &format!(
            "{} bytes, bus description {}; fixed assignment",
            module.length, module.source
        ),
    );
    module_info(w, &name, &info, None);
    w.open("VirtualSubmoduleList", &[]);
    w.open(
        "VirtualSubmoduleItem",
        &[
            ("ID", &format!("{id}_SUB")),
            ("SubmoduleIdentNumber", &hex32(ident.submodule_ident)),
            ("MayIssueProcessAlarm", "false"),
        ],
    );
    w.open("IOData", &[]);
    let tag = match dir {
        Direction::Output => "Output",
        Direction::Input => "Input",
    };
    w.open(tag, &[("Consistency", "All items consistency")]);
    for f in &module.fields {
        data_item(w, family, &id, f);
    }
    w.close(tag);
    w.close("IOData");
    if dir == Direction::Output {
        records(w, family, model);
    }
    module_info(w, &name, &info, None);
    w.close("VirtualSubmoduleItem");
    w.close("VirtualSubmoduleList");
    w.close("ModuleItem");
}

/// One `DataItem` for a field of 3.5; fields that are a bit list (control word, status) are
/// `UseAsBits` with one `BitDataItem` per bit of their bitfield.
fn data_item(w: &mut Writer, family: &Family, module: &str, f: &Field) {
    let data_type = match (f.length, f.signed) {
        (1, false) => "Unsigned8",
        (1, true) => "Integer8",
        (2, false) => "Unsigned16",
        (2, true) => "Integer16",
        (4, false) => "Unsigned32",
        (4, true) => "Integer32",
        _ => "OctetString",
    };
    let bits: Vec<_> = f
        .param
        .as_deref()
        .map(|p| family.bitfields_of(p).flat_map(|b| &b.bits).collect())
        .unwrap_or_default();
    let mut label = match &f.param {
        Some(p) => format!("{} (par. {p}; bus description {})", f.label, f.source),
        None => format!("{} (bus description {})", f.label, f.source),
    };
    if !bits.is_empty() && f.inverted {
        label.push_str(
            "; bits 0-7 in the first byte, 8-15 in the second (byte order inverted against \
             the other fields)",
        );
    }
    let text = w.text(&format!("IDT_{module}_{}", f.name), &label);
    let length = f.length.to_string();
    let mut attrs = vec![("DataType", data_type), ("TextId", text.as_str())];
    if data_type == "OctetString" {
        attrs.push(("Length", &length));
    }
    if bits.is_empty() {
        w.empty("DataItem", &attrs);
        return;
    }
    attrs.push(("UseAsBits", "true"));
    w.open("DataItem", &attrs);
    // Bus description 3.5 notice: with UseAsBits the byte order of these words is inverted
    // against the other fields; BitOffset is the manual's bit number.
    for b in bits {
        let t = w.text(
            &format!("IDT_{module}_{}_BIT{}", f.name, b.bit),
            &format!("Bit {}: {}", b.bit, b.name),
        );
        w.empty(
            "BitDataItem",
            &[("BitOffset", &b.bit.to_string()), ("TextId", &t)],
        );
    }
    w.close("DataItem");
}

/// One `ParameterRecordDataItem` per writable numeric parameter with a delivery value (the
/// configuration a controller may write at start-up; 3.2.2): index = parameter number,
/// a control byte (0: the drive ignores the write and keeps its EEPROM value) and the value.
fn records(w: &mut Writer, family: &Family, model: &DeviceModel) {
    let Some(proto) = family.psd4xx() else { return };
    let rec = &proto.record;
    let params: Vec<(&Parameter, String, i64, usize)> = family
        .parameters
        .iter()
        .filter(|p| p.access.writable() && p.subindex.is_none())
        .filter_map(|p| {
            let r = family.resolve(p, Some(model));
            let width = p.data_type.width()?;
            let length = rec.length_for(width * 8)?.write;
            Some((p, allowed(&r.range?), r.default?, length))
        })
        .collect();
    if params.is_empty() {
        return;
    }
    w.open("RecordDataList", &[]);
    for (p, allowed, default, length) in params {
        w.open(
            "ParameterRecordDataItem",
            &[
                ("Index", &p.number.to_string()),
                ("Length", &length.to_string()),
            ],
        );
        let name = w.text(
            &format!("IDT_REC_{}", p.number),
            &format!("{} (par. {}; {})", p.name, p.number, p.source),
        );
        w.empty("Name", &[("TextId", &name)]);
        let ctl = w.text(
            &format!("IDT_REC_{}_CTL", p.number),
            "Control byte: 0 keeps the drive's value, 1 writes this one (3.2.2)",
        );
        w.empty(
            "Ref",
            &[
                ("DataType", "Unsigned8"),
                ("ByteOffset", "0"),
                ("DefaultValue", &rec.control_byte_ignore.to_string()),
                ("AllowedValues", "0..1"),
                ("TextId", &ctl),
            ],
        );
        let value = w.text(
            &format!("IDT_REC_{}_VAL", p.number),
            &match &p.unit {
                Some(u) => format!("{} in {u}", p.name),
                None => p.name.clone(),
            },
        );
        w.empty(
            "Ref",
            &[
                ("DataType", gsdml_type(p.data_type)),
                ("ByteOffset", &rec.control_byte_length.to_string()),
                ("DefaultValue", &default.to_string()),
                ("AllowedValues", &allowed),
                ("TextId", &value),
            ],
        );
        w.close("ParameterRecordDataItem");
    }
    w.close("RecordDataList");
}

fn gsdml_type(t: DataType) -> &'static str {
    match t {
        DataType::U8 | DataType::Bits8 => "Unsigned8",
        DataType::I8 => "Integer8",
        DataType::U16 | DataType::Bits16 => "Unsigned16",
        DataType::I16 => "Integer16",
        DataType::U32 | DataType::Bits32 => "Unsigned32",
        DataType::I32 => "Integer32",
        DataType::String => "VisibleString",
    }
}

/// GSDML `AllowedValues`: `lo..hi` intervals and single values, space-separated.
fn allowed(r: &crate::Ranges) -> String {
    r.intervals()
        .iter()
        .map(|[lo, hi]| {
            if lo == hi {
                lo.to_string()
            } else {
                format!("{lo}..{hi}")
            }
        })
        .collect::<Vec<_>>()
        .join(" ")
}

fn module_info(w: &mut Writer, name: &str, info: &str, vendor: Option<&str>) {
    w.open("ModuleInfo", &[]);
    w.empty("Name", &[("TextId", name)]);
    w.empty("InfoText", &[("TextId", info)]);
    if let Some(v) = vendor {
        w.empty("VendorName", &[("Value", v)]);
    }
    w.close("ModuleInfo");
}

/// The name of station a device has at the delivery address-switch setting (2.1).
fn default_name(proto: &crate::psd4xx::Protocol) -> String {
    let n = &proto.device_name;
    format!(
        "{}{:0w$}",
        n.prefix,
        n.delivery_switch_setting,
        w = n.switch_digits
    )
}

fn hex32(v: u32) -> String {
    format!("0x{v:08X}")
}

/// An indenting XML writer that collects the texts of the `ExternalTextList`.
#[derive(Default)]
struct Writer {
    out: String,
    depth: usize,
    texts: Vec<(String, String)>,
}

impl Writer {
    fn raw(&mut self, s: &str) {
        self.out.push_str(s);
    }

    fn start(&mut self, tag: &str, attrs: &[(&str, &str)]) {
        self.out.push_str(&"  ".repeat(self.depth));
        self.out.push('<');
        self.out.push_str(tag);
        for (k, v) in attrs {
            let _ = write!(self.out, " {k}=\"{}\"", escape(v));
        }
    }

    fn open(&mut self, tag: &str, attrs: &[(&str, &str)]) {
        self.start(tag, attrs);
        self.out.push_str(">\n");
        self.depth += 1;
    }

    fn empty(&mut self, tag: &str, attrs: &[(&str, &str)]) {
        self.start(tag, attrs);
        self.out.push_str("/>\n");
    }

    fn leaf(&mut self, tag: &str, value: &str) {
        self.start(tag, &[]);
        let _ = writeln!(self.out, ">{}</{tag}>", escape(value));
    }

    fn close(&mut self, tag: &str) {
        self.depth = self.depth.saturating_sub(1);
        let _ = writeln!(self.out, "{}</{tag}>", "  ".repeat(self.depth));
    }

    /// Defines text `id` (once) and returns the id.
    fn text(&mut self, id: &str, value: &str) -> String {
        if !self.texts.iter().any(|(i, _)| i == id) {
            self.texts.push((id.to_owned(), value.to_owned()));
        }
        id.to_owned()
    }
}
