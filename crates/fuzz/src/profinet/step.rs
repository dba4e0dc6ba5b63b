//! The inputs of PROFINET-layer fuzzing (README "Replay files", layer `profinet`): one DCP
//! request, one Connect, one record call or one cyclic frame each, with the fields the
//! mutations change (IEC 61158-6-10: DCP, PNIO-CM, RT class 1).

use serde::{Deserialize, Serialize};

/// One input at the PROFINET layer (key `do` in a replay file).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "do", rename_all = "kebab-case", deny_unknown_fields)]
pub enum PnStep {
    /// A DCP Identify request to the Identify multicast address with these blocks
    /// (IEC 61158-6-10 "IdentifyReqBlock"), as hex.
    DcpIdentify {
        /// The blocks after the DCP header.
        #[serde(with = "drivespec_positioner::step::hex_text")]
        blocks: Vec<u8>,
    },
    /// A DCP Set request to the device with these blocks ("SetReqBlock").
    DcpSet {
        /// The blocks after the DCP header.
        #[serde(with = "drivespec_positioner::step::hex_text")]
        blocks: Vec<u8>,
    },
    /// A DCP Get request to the device with these option pairs ("GetReqBlock").
    DcpGet {
        /// The option/suboption pairs after the DCP header.
        #[serde(with = "drivespec_positioner::step::hex_text")]
        blocks: Vec<u8>,
    },
    /// A Connect ("IODConnectReq") with these IOCR and module fields, after a DCP Identify
    /// of the station; an AR the device accepts is released at once.
    Connect {
        /// SendClockFactor of both IOCRs (31.25 µs units).
        send_clock_factor: u16,
        /// ReductionRatio of both IOCRs.
        reduction_ratio: u16,
        /// DataHoldFactor (and WatchdogFactor) of both IOCRs.
        data_hold_factor: u16,
        /// DataLength (C_SDU length) of both IOCRs.
        data_length: u16,
        /// Data length of the input submodule in the expected submodules and the input IOCR.
        input_length: u16,
        /// Data length of the output submodule in the expected submodules and the output
        /// IOCR.
        output_length: u16,
        /// ModuleIdentNumber of the output module.
        module_ident: u32,
        /// SubmoduleIdentNumber of the output submodule.
        submodule_ident: u32,
    },
    /// A record Read ("IODReadReq") in an AR of the fuzzer's.
    RecordRead {
        /// Slot.
        slot: u16,
        /// Subslot.
        subslot: u16,
        /// Record index.
        index: u16,
    },
    /// A record Write ("IODWriteReq") in an AR of the fuzzer's.
    RecordWrite {
        /// Slot.
        slot: u16,
        /// Subslot.
        subslot: u16,
        /// Record index.
        index: u16,
        /// The record data, as hex.
        #[serde(with = "drivespec_positioner::step::hex_text")]
        data: Vec<u8>,
    },
    /// One cyclic frame on the output CR of an AR of the fuzzer's.
    Rt {
        /// CycleCounter.
        cycle_counter: u16,
        /// DataStatus.
        data_status: u8,
        /// TransferStatus.
        transfer_status: u8,
        /// The byte every IOxS of the C_SDU carries (and every data byte).
        ioxs: u8,
        /// C_SDU length.
        length: u16,
    },
}

impl PnStep {
    /// The step's `do` key.
    pub fn name(&self) -> &'static str {
        match self {
            PnStep::DcpIdentify { .. } => "dcp-identify",
            PnStep::DcpSet { .. } => "dcp-set",
            PnStep::DcpGet { .. } => "dcp-get",
            PnStep::Connect { .. } => "connect",
            PnStep::RecordRead { .. } => "record-read",
            PnStep::RecordWrite { .. } => "record-write",
            PnStep::Rt { .. } => "rt",
        }
    }

    /// The bytes minimisation may shorten: DCP blocks, record data.
    pub fn bytes(&self) -> Option<&[u8]> {
        match self {
            PnStep::DcpIdentify { blocks }
            | PnStep::DcpSet { blocks }
            | PnStep::DcpGet { blocks } => Some(blocks),
            PnStep::RecordWrite { data, .. } => Some(data),
            _ => None,
        }
    }

    /// The same step with other bytes (DCP blocks, record data).
    pub fn with_bytes(&self, new: Vec<u8>) -> PnStep {
        match self {
            PnStep::DcpIdentify { .. } => PnStep::DcpIdentify { blocks: new },
            PnStep::DcpSet { .. } => PnStep::DcpSet { blocks: new },
            PnStep::DcpGet { .. } => PnStep::DcpGet { blocks: new },
            PnStep::RecordWrite {
                slot,
                subslot,
                index,
                ..
            } => PnStep::RecordWrite {
                slot: *slot,
                subslot: *subslot,
                index: *index,
                data: new,
            },
            other => other.clone(),
        }
    }
}
