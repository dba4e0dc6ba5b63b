//! The PSD4xx's PROFINET identity, read from `spec/psd4xx/protocol.toml` (`[protocol.profinet]`
//! and the module lengths of 3.2.1): what DCP answers, the submodules a Connect expects, the
//! PNIO object UUID and the I&M0 record. Every field is public so a caller can override a
//! number (e.g. the vendor ID of a real device) after reading the spec.

use crate::buf::{len16, Buf};
use crate::cm::IM0_BLOCK;
use drivespec_capture::dcerpc::Uuid;
use drivespec_capture::pnio::{
    BlockHeader, DataDescription, ExpectedModule, ExpectedSubmodule, ExpectedSubmoduleBlockReq,
};
use drivespec_spec::psd4xx::PnIm0;
use drivespec_spec::{FamilyId, Spec};

/// Why the identity cannot be read (our doc: module `identity`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum IdentityError {
    /// The spec has no PSD4xx protocol table.
    #[error("the spec has no PSD4xx protocol table")]
    NoProtocol,
}

/// A module with one IO submodule (3.2.1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IoModule {
    /// SlotNumber.
    pub slot: u16,
    /// SubslotNumber.
    pub subslot: u16,
    /// ModuleIdentNumber.
    pub module_ident: u32,
    /// SubmoduleIdentNumber.
    pub submodule_ident: u32,
    /// Data length in bytes (3.5: 14 output, 16 input).
    pub length: u16,
}

/// The PROFINET identity of a PSD4xx (our doc: module `identity`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Identity {
    /// VendorID.
    pub vendor_id: u16,
    /// DeviceID.
    pub device_id: u16,
    /// Vendor name (DCP DeviceVendor).
    pub vendor_name: String,
    /// DCP DeviceRole.
    pub device_role: u8,
    /// Instance of the object UUID.
    pub instance: u16,
    /// Slot of the DAP.
    pub dap_slot: u16,
    /// ModuleIdentNumber of the DAP.
    pub dap_module_ident: u32,
    /// Subslot and SubmoduleIdentNumber of each DAP submodule (no IO data).
    pub dap_submodules: Vec<(u16, u32)>,
    /// The output module (controller → drive).
    pub output: IoModule,
    /// The input module (drive → controller).
    pub input: IoModule,
    /// I&M0 fields.
    pub im0: PnIm0,
}

/// The PNIO object UUID prefix (IEC 61158-6-10 "Object UUID": DEA00000-6C97-11D1-8271-).
const OBJECT_PREFIX: [u8; 10] = [0xDE, 0xA0, 0x00, 0x00, 0x6C, 0x97, 0x11, 0xD1, 0x82, 0x71];

/// SubmoduleProperties type: no IO (0), input (1), output (2) (IEC 61158-6-10).
const NO_IO: u16 = 0;
const INPUT: u16 = 1;
const OUTPUT: u16 = 2;

impl Identity {
    /// The identity the spec gives (manual 2.1, 3.2.1; `[protocol.profinet]`).
    pub fn from_spec(spec: &Spec) -> Result<Identity, IdentityError> {
        let p = spec
            .family(FamilyId::Psd4xx)
            .psd4xx()
            .ok_or(IdentityError::NoProtocol)?;
        let pn = &p.profinet;
        let module = |m: &drivespec_spec::psd4xx::PnModule, len: usize| IoModule {
            slot: m.slot,
            subslot: m.subslot,
            module_ident: m.module_ident,
            submodule_ident: m.submodule_ident,
            length: len16(len),
        };
        Ok(Identity {
            vendor_id: pn.vendor_id,
            device_id: pn.device_id,
            vendor_name: pn.vendor_name.clone(),
            device_role: pn.device_role,
            instance: pn.instance,
            dap_slot: pn.dap.slot,
            dap_module_ident: pn.dap.module_ident,
            dap_submodules: pn
                .dap
                .submodule
                .iter()
                .map(|s| (s.subslot, s.ident))
                .collect(),
            output: module(&pn.output, p.process_data.output.length),
            input: module(&pn.input, p.process_data.input.length),
            im0: pn.im0.clone(),
        })
    }

    /// The device's PNIO object UUID: the prefix, then instance, DeviceID, VendorID.
    pub fn object_uuid(&self) -> Uuid {
        let mut u = [0u8; 16];
        let tail = [self.instance, self.device_id, self.vendor_id];
        for (i, b) in OBJECT_PREFIX
            .iter()
            .copied()
            .chain(tail.iter().flat_map(|v| v.to_be_bytes()))
            .enumerate()
        {
            if let Some(x) = u.get_mut(i) {
                *x = b;
            }
        }
        Uuid(u)
    }

    /// Every (slot, subslot) the device has.
    pub fn subslots(&self) -> Vec<(u16, u16)> {
        let mut v: Vec<(u16, u16)> = self
            .dap_submodules
            .iter()
            .map(|(s, _)| (self.dap_slot, *s))
            .collect();
        v.push((self.output.slot, self.output.subslot));
        v.push((self.input.slot, self.input.subslot));
        v
    }

    /// The ExpectedSubmoduleBlockReq of a Connect for this device: the DAP and its
    /// submodules, the output module, the input module (API 0; IOPS and IOCS of one byte).
    pub fn expected_submodules(&self) -> ExpectedSubmoduleBlockReq {
        let none = |len: u16| DataDescription {
            data_length: len,
            iops_length: 1,
            iocs_length: 1,
        };
        let dap = ExpectedModule {
            api: 0,
            slot: self.dap_slot,
            ident: self.dap_module_ident,
            properties: 0,
            submodules: self
                .dap_submodules
                .iter()
                .map(|(subslot, ident)| ExpectedSubmodule {
                    subslot: *subslot,
                    ident: *ident,
                    properties: NO_IO,
                    input: Some(none(0)),
                    output: None,
                })
                .collect(),
        };
        let io = |m: &IoModule, output: bool| ExpectedModule {
            api: 0,
            slot: m.slot,
            ident: m.module_ident,
            properties: 0,
            submodules: vec![ExpectedSubmodule {
                subslot: m.subslot,
                ident: m.submodule_ident,
                properties: if output { OUTPUT } else { INPUT },
                input: (!output).then(|| none(m.length)),
                output: output.then(|| none(m.length)),
            }],
        };
        ExpectedSubmoduleBlockReq {
            header: BlockHeader {
                block_type: drivespec_capture::pnio::block_type::EXPECTED_SUBMODULE_REQ,
                length: 0,
                version_high: 1,
                version_low: 0,
                offset: 0,
            },
            modules: vec![dap, io(&self.output, true), io(&self.input, false)],
        }
    }

    /// The I&M0 record (IEC 61158-6-10 "I&M0", BlockType 0x0020): VendorID, OrderID (20
    /// characters), IM_Serial_Number (16), the revisions, profile, version and supported list.
    pub fn im0_record(&self, order_id: &str, serial: &str) -> Vec<u8> {
        let fixed = |s: &str, n: usize| {
            let mut v: Vec<u8> = s
                .bytes()
                .filter(|c| (0x20..0x7f).contains(c))
                .take(n)
                .collect();
            v.resize(n, b' ');
            v
        };
        let mut body = Buf::default();
        body.be16(self.vendor_id)
            .bytes(&fixed(order_id, 20))
            .bytes(&fixed(serial, 16))
            .be16(self.im0.hardware_revision)
            .u8(u8::try_from(self.im0.software_prefix).unwrap_or(b'V'))
            .bytes(&self.im0.software_revision)
            .be16(self.im0.revision_counter)
            .be16(self.im0.profile_id)
            .be16(self.im0.profile_specific_type)
            .bytes(&self.im0.version)
            .be16(self.im0.supported);
        let mut b = Buf::default();
        b.be16(IM0_BLOCK)
            .be16(len16(body.len() + 2))
            .u8(1)
            .u8(0)
            .bytes(&body.0);
        b.0
    }
}
