//! PNIO-CM: the PROFINET IO context manager calls carried by DCE/RPC (IEC 61158-6-10
//! "RPC" and "Block" coding): the NDR header (`ArgsMaximum`/`PNIOStatus`, `ArgsLength` and
//! the conformant array), then blocks `BlockType (2) | BlockLength (2) | BlockVersionHigh (1)
//! | BlockVersionLow (1) | body`, big-endian whatever the RPC data representation.
//!
//! Decoded blocks: Connect (ARBlockReq/Res, IOCRBlockReq/Res, ExpectedSubmoduleBlockReq),
//! record Read/Write (IODReadReqHeader/ResHeader, IODWriteReqHeader/ResHeader, with the record
//! data that follows the header block), and the control blocks (PrmEnd, ApplicationReady,
//! Release, …). Any other block is kept as [`Block::Unknown`], skipped by its length, and
//! listed by [`CmMessage::unknown_blocks`]; [`alarm_cr_req`], [`alarm_cr_res`] and
//! [`module_diff`] read the AlarmCR and ModuleDiff blocks among them, and
//! [`alarm_notification`] the notification in an alarm frame's var part.
//!
//! Element counts from the wire never size an allocation: every element is read from the
//! body, so memory is bounded by the body. Decoding never panics.

use crate::bytes::{Endian, Reader, Truncated};
use crate::dcerpc::{Message, PacketType, Uuid};
use crate::rt::FrameId;
use std::fmt;

/// PNIO-CM block types (IEC 61158-6-10 "BlockType").
pub mod block_type {
    /// IODWriteReqHeader.
    pub const WRITE_REQ: u16 = 0x0008;
    /// IODReadReqHeader.
    pub const READ_REQ: u16 = 0x0009;
    /// IODWriteResHeader.
    pub const WRITE_RES: u16 = 0x8008;
    /// IODReadResHeader.
    pub const READ_RES: u16 = 0x8009;
    /// ARBlockReq.
    pub const AR_REQ: u16 = 0x0101;
    /// ARBlockRes.
    pub const AR_RES: u16 = 0x8101;
    /// IOCRBlockReq.
    pub const IOCR_REQ: u16 = 0x0102;
    /// IOCRBlockRes.
    pub const IOCR_RES: u16 = 0x8102;
    /// AlarmCRBlockReq.
    pub const ALARM_CR_REQ: u16 = 0x0103;
    /// AlarmCRBlockRes.
    pub const ALARM_CR_RES: u16 = 0x8103;
    /// ExpectedSubmoduleBlockReq.
    pub const EXPECTED_SUBMODULE_REQ: u16 = 0x0104;
    /// ModuleDiffBlock.
    pub const MODULE_DIFF: u16 = 0x8104;
}

/// The PNIO-CM operation, from the RPC opnum (IEC 61158-6-10 "RPC operations").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Operation {
    /// 0: Connect.
    Connect,
    /// 1: Release.
    Release,
    /// 2: Read.
    Read,
    /// 3: Write.
    Write,
    /// 4: Control.
    Control,
    /// 5: Read Implicit.
    ReadImplicit,
    /// Any other opnum.
    Other(u16),
}

impl Operation {
    /// The operation of an opnum.
    pub fn from_opnum(opnum: u16) -> Operation {
        match opnum {
            0 => Operation::Connect,
            1 => Operation::Release,
            2 => Operation::Read,
            3 => Operation::Write,
            4 => Operation::Control,
            5 => Operation::ReadImplicit,
            n => Operation::Other(n),
        }
    }
}

/// PNIOStatus: ErrorCode, ErrorDecode, ErrorCode1, ErrorCode2 (IEC 61158-6-10 "PNIOStatus").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct PnioStatus {
    /// ErrorCode (0x81 PNIO, 0xDE/0xDF read/write error …).
    pub code: u8,
    /// ErrorDecode (0x80 PNIORW, 0x81 PNIO …).
    pub decode: u8,
    /// ErrorCode1.
    pub code1: u8,
    /// ErrorCode2.
    pub code2: u8,
}

impl PnioStatus {
    fn from_u32(v: u32) -> PnioStatus {
        let [code, decode, code1, code2] = v.to_be_bytes();
        PnioStatus {
            code,
            decode,
            code1,
            code2,
        }
    }

    /// Whether all four bytes are zero (OK).
    pub fn is_ok(&self) -> bool {
        *self == PnioStatus::default()
    }
}

impl fmt::Display for PnioStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:02x}{:02x}{:02x}{:02x}",
            self.code, self.decode, self.code1, self.code2
        )
    }
}

/// Request or response.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Direction {
    /// An RPC request.
    Request,
    /// An RPC response.
    Response,
}

/// The NDR header before the blocks (IEC 61158-6-10 "IODConnectReq", "IODConnectRes" …).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NdrHeader {
    /// ArgsMaximum (requests).
    pub args_maximum: Option<u32>,
    /// PNIOStatus (responses).
    pub status: Option<PnioStatus>,
    /// ArgsLength: bytes of blocks.
    pub args_length: u32,
    /// Conformant array MaximumCount.
    pub maximum_count: u32,
    /// Conformant array Offset.
    pub offset: u32,
    /// Conformant array ActualCount.
    pub actual_count: u32,
}

/// The common block header (IEC 61158-6-10 "BlockHeader").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BlockHeader {
    /// BlockType.
    pub block_type: u16,
    /// BlockLength (bytes after this field, version included).
    pub length: u16,
    /// BlockVersionHigh.
    pub version_high: u8,
    /// BlockVersionLow.
    pub version_low: u8,
    /// Offset of the block in the RPC body.
    pub offset: usize,
}

/// ARBlockReq (IEC 61158-6-10 "ARBlockReq").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ArBlockReq {
    /// Block header.
    pub header: BlockHeader,
    /// ARType (1 IOCAR, 6 supervisor, 0x10 IOCAR RT_CLASS_3, 0x20 IOCAR-SR).
    pub ar_type: u16,
    /// ARUUID.
    pub ar_uuid: Uuid,
    /// SessionKey.
    pub session_key: u16,
    /// CMInitiatorMacAdd.
    pub initiator_mac: [u8; 6],
    /// CMInitiatorObjectUUID.
    pub initiator_object: Uuid,
    /// ARProperties.
    pub properties: u32,
    /// CMInitiatorActivityTimeoutFactor (units of 100 ms).
    pub activity_timeout_factor: u16,
    /// InitiatorUDPRTPort.
    pub udp_rt_port: u16,
    /// CMInitiatorStationName.
    pub station_name: String,
}

/// ARBlockRes (IEC 61158-6-10 "ARBlockRes").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ArBlockRes {
    /// Block header.
    pub header: BlockHeader,
    /// ARType.
    pub ar_type: u16,
    /// ARUUID.
    pub ar_uuid: Uuid,
    /// SessionKey.
    pub session_key: u16,
    /// CMResponderMacAdd.
    pub responder_mac: [u8; 6],
    /// ResponderUDPRTPort.
    pub udp_rt_port: u16,
}

/// One IODataObject or IOCS entry of an IOCR: where a submodule's data or consumer status
/// sits in the C_SDU (IEC 61158-6-10 "IOCRBlockReq").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameOffset {
    /// SlotNumber.
    pub slot: u16,
    /// SubslotNumber.
    pub subslot: u16,
    /// IODataObjectFrameOffset or IOCSFrameOffset.
    pub frame_offset: u16,
}

/// The objects of one API in an IOCR (IEC 61158-6-10 "IOCRBlockReq").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IocrApi {
    /// API.
    pub api: u32,
    /// IODataObjects.
    pub data_objects: Vec<FrameOffset>,
    /// IOCS entries.
    pub iocs: Vec<FrameOffset>,
}

/// IOCRBlockReq (IEC 61158-6-10 "IOCRBlockReq").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IocrBlockReq {
    /// Block header.
    pub header: BlockHeader,
    /// IOCRType (1 input, 2 output, 3 multicast provider, 4 multicast consumer).
    pub iocr_type: u16,
    /// IOCRReference.
    pub reference: u16,
    /// LT (0x8892).
    pub lt: u16,
    /// IOCRProperties (bits 0–3: RTClass).
    pub properties: u32,
    /// DataLength: the C_SDU length.
    pub data_length: u16,
    /// FrameID (may be assigned by the response).
    pub frame_id: FrameId,
    /// SendClockFactor (units of 31.25 µs).
    pub send_clock_factor: u16,
    /// ReductionRatio.
    pub reduction_ratio: u16,
    /// Phase.
    pub phase: u16,
    /// Sequence.
    pub sequence: u16,
    /// FrameSendOffset.
    pub frame_send_offset: u32,
    /// WatchdogFactor.
    pub watchdog_factor: u16,
    /// DataHoldFactor.
    pub data_hold_factor: u16,
    /// IOCRTagHeader.
    pub tag_header: u16,
    /// IOCRMulticastMACAdd.
    pub multicast_mac: [u8; 6],
    /// Per-API objects.
    pub apis: Vec<IocrApi>,
}

impl IocrBlockReq {
    /// RTClass from IOCRProperties (1, 2, 3, 4 = RT_CLASS_UDP).
    pub fn rt_class(&self) -> u8 {
        (self.properties & 0x0f) as u8
    }

    /// Cycle time in microseconds: SendClockFactor × ReductionRatio × 31.25 µs.
    pub fn cycle_micros(&self) -> u64 {
        u64::from(self.send_clock_factor) * u64::from(self.reduction_ratio) * 3125 / 100
    }
}

/// IOCRBlockRes (IEC 61158-6-10 "IOCRBlockRes").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct IocrBlockRes {
    /// Block header.
    pub header: BlockHeader,
    /// IOCRType.
    pub iocr_type: u16,
    /// IOCRReference.
    pub reference: u16,
    /// FrameID assigned.
    pub frame_id: FrameId,
}

/// A DataDescription of an expected submodule (IEC 61158-6-10 "ExpectedSubmoduleBlockReq").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DataDescription {
    /// SubmoduleDataLength.
    pub data_length: u16,
    /// LengthIOPS.
    pub iops_length: u8,
    /// LengthIOCS.
    pub iocs_length: u8,
}

/// An expected submodule (IEC 61158-6-10 "ExpectedSubmoduleBlockReq").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExpectedSubmodule {
    /// SubslotNumber.
    pub subslot: u16,
    /// SubmoduleIdentNumber.
    pub ident: u32,
    /// SubmoduleProperties (bits 0–1: type 0 none, 1 input, 2 output, 3 both).
    pub properties: u16,
    /// Input data description (DataDescription 1).
    pub input: Option<DataDescription>,
    /// Output data description (DataDescription 2).
    pub output: Option<DataDescription>,
}

/// One API/slot entry of an ExpectedSubmoduleBlockReq.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExpectedModule {
    /// API.
    pub api: u32,
    /// SlotNumber.
    pub slot: u16,
    /// ModuleIdentNumber.
    pub ident: u32,
    /// ModuleProperties.
    pub properties: u16,
    /// Submodules.
    pub submodules: Vec<ExpectedSubmodule>,
}

/// ExpectedSubmoduleBlockReq (IEC 61158-6-10 "ExpectedSubmoduleBlockReq").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ExpectedSubmoduleBlockReq {
    /// Block header.
    pub header: BlockHeader,
    /// Modules by API and slot.
    pub modules: Vec<ExpectedModule>,
}

/// IODReadReqHeader or IODWriteReqHeader, with the written record data (IEC 61158-6-10).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordRequest {
    /// Block header.
    pub header: BlockHeader,
    /// SeqNumber.
    pub sequence: u16,
    /// ARUUID.
    pub ar_uuid: Uuid,
    /// API.
    pub api: u32,
    /// SlotNumber.
    pub slot: u16,
    /// SubslotNumber.
    pub subslot: u16,
    /// Index.
    pub index: u16,
    /// RecordDataLength (read: the most bytes wanted).
    pub record_data_length: u32,
    /// TargetARUUID (read requests).
    pub target_ar_uuid: Option<Uuid>,
    /// The record data (write requests; empty for reads).
    pub data: Vec<u8>,
}

/// IODReadResHeader or IODWriteResHeader, with the read record data (IEC 61158-6-10).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordResponse {
    /// Block header.
    pub header: BlockHeader,
    /// SeqNumber.
    pub sequence: u16,
    /// ARUUID.
    pub ar_uuid: Uuid,
    /// API.
    pub api: u32,
    /// SlotNumber.
    pub slot: u16,
    /// SubslotNumber.
    pub subslot: u16,
    /// Index.
    pub index: u16,
    /// RecordDataLength.
    pub record_data_length: u32,
    /// AdditionalValue1.
    pub additional_value1: u16,
    /// AdditionalValue2.
    pub additional_value2: u16,
    /// PNIOStatus (write responses).
    pub status: Option<PnioStatus>,
    /// The record data (read responses; empty for writes).
    pub data: Vec<u8>,
}

/// Which control block (IEC 61158-6-10 "BlockType" 0x0110–0x0118 and responses).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ControlKind {
    /// 0x0110: IODControlReq PrmEnd.
    PrmEnd,
    /// 0x0111: IODControlReq Plug PrmEnd.
    PlugPrmEnd,
    /// 0x0112: IOXControlReq ApplicationReady.
    ApplicationReady,
    /// 0x0113: IOXControlReq Plug ApplicationReady.
    PlugApplicationReady,
    /// 0x0114: IODReleaseReq.
    Release,
    /// 0x0116: IOXControlReq ReadyForCompanion.
    ReadyForCompanion,
    /// 0x0117: IOXControlReq ReadyForRT_CLASS_3.
    ReadyForRtc3,
    /// 0x0118: PrmBeginReq.
    PrmBegin,
}

impl ControlKind {
    fn from_block_type(t: u16) -> Option<ControlKind> {
        Some(match t & 0x7fff {
            0x0110 => ControlKind::PrmEnd,
            0x0111 => ControlKind::PlugPrmEnd,
            0x0112 => ControlKind::ApplicationReady,
            0x0113 => ControlKind::PlugApplicationReady,
            0x0114 => ControlKind::Release,
            0x0116 => ControlKind::ReadyForCompanion,
            0x0117 => ControlKind::ReadyForRtc3,
            0x0118 => ControlKind::PrmBegin,
            _ => return None,
        })
    }
}

/// ControlCommand bits (IEC 61158-6-10 "ControlCommand").
pub mod control_command {
    /// PrmEnd.
    pub const PRM_END: u16 = 0x0001;
    /// ApplicationReady.
    pub const APPLICATION_READY: u16 = 0x0002;
    /// Release.
    pub const RELEASE: u16 = 0x0004;
    /// Done (in responses).
    pub const DONE: u16 = 0x0008;
    /// ReadyForCompanion.
    pub const READY_FOR_COMPANION: u16 = 0x0010;
    /// ReadyForRT_CLASS_3.
    pub const READY_FOR_RTC3: u16 = 0x0020;
    /// PrmBegin.
    pub const PRM_BEGIN: u16 = 0x0040;
}

/// A control block (IEC 61158-6-10 "IODControlReq", "IOXControlReq", "IODReleaseReq" and
/// their responses).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ControlBlock {
    /// Block header.
    pub header: BlockHeader,
    /// Which control block.
    pub kind: ControlKind,
    /// A response block (BlockType with bit 15 set).
    pub response: bool,
    /// ARUUID.
    pub ar_uuid: Uuid,
    /// SessionKey.
    pub session_key: u16,
    /// ControlCommand.
    pub command: u16,
    /// ControlBlockProperties.
    pub properties: u16,
}

/// A block this crate does not decode, skipped by its length.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownBlock {
    /// Block header.
    pub header: BlockHeader,
    /// Its body after the version bytes.
    pub body: Vec<u8>,
}

/// A PNIO-CM block (IEC 61158-6-10 "Block coding").
#[derive(Debug, Clone, PartialEq, Eq)]
#[non_exhaustive]
pub enum Block {
    /// ARBlockReq.
    ArReq(ArBlockReq),
    /// ARBlockRes.
    ArRes(ArBlockRes),
    /// IOCRBlockReq.
    IocrReq(IocrBlockReq),
    /// IOCRBlockRes.
    IocrRes(IocrBlockRes),
    /// ExpectedSubmoduleBlockReq.
    ExpectedSubmodules(ExpectedSubmoduleBlockReq),
    /// IODReadReqHeader.
    ReadReq(RecordRequest),
    /// IODReadResHeader with the record data.
    ReadRes(RecordResponse),
    /// IODWriteReqHeader with the record data.
    WriteReq(RecordRequest),
    /// IODWriteResHeader.
    WriteRes(RecordResponse),
    /// A control block.
    Control(ControlBlock),
    /// Any other block, skipped by its length.
    Unknown(UnknownBlock),
}

impl Block {
    /// The block header.
    pub fn header(&self) -> &BlockHeader {
        match self {
            Block::ArReq(b) => &b.header,
            Block::ArRes(b) => &b.header,
            Block::IocrReq(b) => &b.header,
            Block::IocrRes(b) => &b.header,
            Block::ExpectedSubmodules(b) => &b.header,
            Block::ReadReq(b) | Block::WriteReq(b) => &b.header,
            Block::ReadRes(b) | Block::WriteRes(b) => &b.header,
            Block::Control(b) => &b.header,
            Block::Unknown(b) => &b.header,
        }
    }
}

/// A decoded PNIO-CM call or answer (IEC 61158-6-10 "RPC").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CmMessage {
    /// The operation.
    pub operation: Operation,
    /// Request or response.
    pub direction: Direction,
    /// The NDR header.
    pub ndr: NdrHeader,
    /// The blocks, in order.
    pub blocks: Vec<Block>,
}

impl CmMessage {
    /// The blocks that were skipped as unknown.
    pub fn unknown_blocks(&self) -> impl Iterator<Item = &UnknownBlock> {
        self.blocks.iter().filter_map(|b| match b {
            Block::Unknown(u) => Some(u),
            _ => None,
        })
    }
}

/// Why a PNIO-CM body cannot be decoded (our doc: module `pnio`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum PnioError {
    /// A field does not fit (offsets count from the start of the RPC body).
    #[error("PNIO-CM {what}: {source}")]
    Truncated {
        /// The structure being read.
        what: &'static str,
        /// Where and how much.
        #[source]
        source: Truncated,
    },
    /// Only requests and responses carry PNIO-CM bodies.
    #[error("DCE/RPC {0} carries no PNIO-CM body")]
    NotACall(PacketType),
    /// ArgsLength is more than the body holds.
    #[error("ArgsLength {declared} with {available} byte(s) of blocks")]
    ArgsLength {
        /// ArgsLength.
        declared: u32,
        /// Bytes after the NDR header.
        available: usize,
    },
    /// A block's length is below 2 or beyond the arguments.
    #[error("block {block_type:#06x} at byte {offset}: BlockLength {length} with {available} byte(s) left")]
    BlockLength {
        /// Offset of the block.
        offset: usize,
        /// BlockType.
        block_type: u16,
        /// BlockLength.
        length: u16,
        /// Bytes left after the BlockLength field.
        available: usize,
    },
    /// RecordDataLength is more than follows the header block.
    #[error("record index {index:#06x} at byte {offset}: RecordDataLength {declared} with {available} byte(s) left")]
    RecordData {
        /// Offset of the header block.
        offset: usize,
        /// Index.
        index: u16,
        /// RecordDataLength.
        declared: u32,
        /// Bytes after the header block.
        available: usize,
    },
}

fn shifted(what: &'static str, base: usize) -> impl Fn(Truncated) -> PnioError {
    move |t| PnioError::Truncated {
        what,
        source: Truncated {
            offset: base + t.offset,
            ..t
        },
    }
}

/// Decodes a reassembled DCE/RPC message as PNIO-CM.
pub fn decode(message: &Message) -> Result<CmMessage, PnioError> {
    decode_body(
        message.header.ptype,
        message.header.opnum,
        message.header.drep.integer,
        &message.body,
    )
}

/// Decodes a PNIO-CM body given the RPC packet type, opnum and integer byte order.
pub fn decode_body(
    ptype: PacketType,
    opnum: u16,
    order: Endian,
    body: &[u8],
) -> Result<CmMessage, PnioError> {
    let direction = match ptype {
        PacketType::REQUEST => Direction::Request,
        PacketType::RESPONSE => Direction::Response,
        other => return Err(PnioError::NotACall(other)),
    };
    let mut r = Reader::new(body);
    let err = shifted("NDR header", 0);
    let first = r.u32(order).map_err(&err)?;
    let args_length = r.u32(order).map_err(&err)?;
    let maximum_count = r.u32(order).map_err(&err)?;
    let offset = r.u32(order).map_err(&err)?;
    let actual_count = r.u32(order).map_err(&err)?;
    let (args_maximum, status) = match direction {
        Direction::Request => (Some(first), None),
        Direction::Response => (None, Some(PnioStatus::from_u32(first))),
    };
    let base = r.pos();
    let rest = r.rest();
    let args = usize::try_from(args_length)
        .ok()
        .and_then(|n| rest.get(..n))
        .ok_or(PnioError::ArgsLength {
            declared: args_length,
            available: rest.len(),
        })?;
    Ok(CmMessage {
        operation: Operation::from_opnum(opnum),
        direction,
        ndr: NdrHeader {
            args_maximum,
            status,
            args_length,
            maximum_count,
            offset,
            actual_count,
        },
        blocks: decode_blocks(args, base)?,
    })
}

/// Decodes a sequence of blocks; `base` is the offset of `bytes` in the RPC body.
pub fn decode_blocks(bytes: &[u8], base: usize) -> Result<Vec<Block>, PnioError> {
    let mut blocks = Vec::new();
    let mut r = Reader::new(bytes);
    while r.remaining() > 0 {
        let at = base + r.pos();
        let err = shifted("block header", base);
        let block_type = r.be16().map_err(&err)?;
        let length = r.be16().map_err(&err)?;
        let available = r.remaining();
        if length < 2 || usize::from(length) > available {
            return Err(PnioError::BlockLength {
                offset: at,
                block_type,
                length,
                available,
            });
        }
        let version_high = r.u8().map_err(&err)?;
        let version_low = r.u8().map_err(&err)?;
        let header = BlockHeader {
            block_type,
            length,
            version_high,
            version_low,
            offset: at,
        };
        let body_base = base + r.pos();
        let body = r.take(usize::from(length) - 2).map_err(&err)?;
        let block = decode_block(header, body, body_base)?;
        // Record data follows the header block of write requests and read responses.
        let block = match block {
            Block::WriteReq(mut req) => {
                req.data = record_data(&mut r, at, req.index, req.record_data_length)?;
                Block::WriteReq(req)
            }
            Block::ReadRes(mut res) => {
                res.data = record_data(&mut r, at, res.index, res.record_data_length)?;
                Block::ReadRes(res)
            }
            other => other,
        };
        blocks.push(block);
    }
    Ok(blocks)
}

fn record_data(
    r: &mut Reader<'_>,
    offset: usize,
    index: u16,
    declared: u32,
) -> Result<Vec<u8>, PnioError> {
    let available = r.remaining();
    let n = usize::try_from(declared)
        .ok()
        .filter(|&n| n <= available)
        .ok_or(PnioError::RecordData {
            offset,
            index,
            declared,
            available,
        })?;
    let bytes = r.take(n).map_err(shifted("record data", 0))?;
    Ok(bytes.to_vec())
}

fn mac(r: &mut Reader<'_>) -> Result<[u8; 6], Truncated> {
    r.array::<6>()
}

fn uuid(r: &mut Reader<'_>) -> Result<Uuid, Truncated> {
    Uuid::read(r, Endian::Big)
}

fn decode_block(header: BlockHeader, body: &[u8], base: usize) -> Result<Block, PnioError> {
    let mut r = Reader::new(body);
    let t = header.block_type;
    let name: &'static str = match t {
        block_type::AR_REQ => "ARBlockReq",
        block_type::AR_RES => "ARBlockRes",
        block_type::IOCR_REQ => "IOCRBlockReq",
        block_type::IOCR_RES => "IOCRBlockRes",
        block_type::EXPECTED_SUBMODULE_REQ => "ExpectedSubmoduleBlockReq",
        block_type::READ_REQ => "IODReadReqHeader",
        block_type::WRITE_REQ => "IODWriteReqHeader",
        block_type::READ_RES => "IODReadResHeader",
        block_type::WRITE_RES => "IODWriteResHeader",
        _ if ControlKind::from_block_type(t).is_some() => "control block",
        _ => {
            return Ok(Block::Unknown(UnknownBlock {
                header,
                body: body.to_vec(),
            }))
        }
    };
    let result = (|| -> Result<Block, Truncated> {
        Ok(match t {
            block_type::AR_REQ => {
                let ar_type = r.be16()?;
                let ar_uuid = uuid(&mut r)?;
                let session_key = r.be16()?;
                let initiator_mac = mac(&mut r)?;
                let initiator_object = uuid(&mut r)?;
                let properties = r.be32()?;
                let activity_timeout_factor = r.be16()?;
                let udp_rt_port = r.be16()?;
                let name_len = r.be16()?;
                let station_name =
                    String::from_utf8_lossy(r.take(usize::from(name_len))?).into_owned();
                Block::ArReq(ArBlockReq {
                    header,
                    ar_type,
                    ar_uuid,
                    session_key,
                    initiator_mac,
                    initiator_object,
                    properties,
                    activity_timeout_factor,
                    udp_rt_port,
                    station_name,
                })
            }
            block_type::AR_RES => Block::ArRes(ArBlockRes {
                header,
                ar_type: r.be16()?,
                ar_uuid: uuid(&mut r)?,
                session_key: r.be16()?,
                responder_mac: mac(&mut r)?,
                udp_rt_port: r.be16()?,
            }),
            block_type::IOCR_REQ => {
                let iocr_type = r.be16()?;
                let reference = r.be16()?;
                let lt = r.be16()?;
                let properties = r.be32()?;
                let data_length = r.be16()?;
                let frame_id = FrameId(r.be16()?);
                let send_clock_factor = r.be16()?;
                let reduction_ratio = r.be16()?;
                let phase = r.be16()?;
                let sequence = r.be16()?;
                let frame_send_offset = r.be32()?;
                let watchdog_factor = r.be16()?;
                let data_hold_factor = r.be16()?;
                let tag_header = r.be16()?;
                let multicast_mac = mac(&mut r)?;
                let n_apis = r.be16()?;
                let mut apis = Vec::new();
                for _ in 0..n_apis {
                    let api = r.be32()?;
                    let mut data_objects = Vec::new();
                    for _ in 0..r.be16()? {
                        data_objects.push(frame_offset(&mut r)?);
                    }
                    let mut iocs = Vec::new();
                    for _ in 0..r.be16()? {
                        iocs.push(frame_offset(&mut r)?);
                    }
                    apis.push(IocrApi {
                        api,
                        data_objects,
                        iocs,
                    });
                }
                Block::IocrReq(IocrBlockReq {
                    header,
                    iocr_type,
                    reference,
                    lt,
                    properties,
                    data_length,
                    frame_id,
                    send_clock_factor,
                    reduction_ratio,
                    phase,
                    sequence,
                    frame_send_offset,
                    watchdog_factor,
                    data_hold_factor,
                    tag_header,
                    multicast_mac,
                    apis,
                })
            }
            block_type::IOCR_RES => Block::IocrRes(IocrBlockRes {
                header,
                iocr_type: r.be16()?,
                reference: r.be16()?,
                frame_id: FrameId(r.be16()?),
            }),
            block_type::EXPECTED_SUBMODULE_REQ => {
                let mut modules = Vec::new();
                for _ in 0..r.be16()? {
                    let api = r.be32()?;
                    let slot = r.be16()?;
                    let ident = r.be32()?;
                    let properties = r.be16()?;
                    let mut submodules = Vec::new();
                    for _ in 0..r.be16()? {
                        submodules.push(expected_submodule(&mut r)?);
                    }
                    modules.push(ExpectedModule {
                        api,
                        slot,
                        ident,
                        properties,
                        submodules,
                    });
                }
                Block::ExpectedSubmodules(ExpectedSubmoduleBlockReq { header, modules })
            }
            block_type::READ_REQ | block_type::WRITE_REQ => {
                let sequence = r.be16()?;
                let ar_uuid = uuid(&mut r)?;
                let api = r.be32()?;
                let slot = r.be16()?;
                let subslot = r.be16()?;
                r.skip(2)?;
                let index = r.be16()?;
                let record_data_length = r.be32()?;
                let target_ar_uuid = if t == block_type::READ_REQ && r.remaining() >= 16 {
                    Some(uuid(&mut r)?)
                } else {
                    None
                };
                let req = RecordRequest {
                    header,
                    sequence,
                    ar_uuid,
                    api,
                    slot,
                    subslot,
                    index,
                    record_data_length,
                    target_ar_uuid,
                    data: Vec::new(),
                };
                if t == block_type::READ_REQ {
                    Block::ReadReq(req)
                } else {
                    Block::WriteReq(req)
                }
            }
            block_type::READ_RES | block_type::WRITE_RES => {
                let sequence = r.be16()?;
                let ar_uuid = uuid(&mut r)?;
                let api = r.be32()?;
                let slot = r.be16()?;
                let subslot = r.be16()?;
                r.skip(2)?;
                let index = r.be16()?;
                let record_data_length = r.be32()?;
                let additional_value1 = r.be16()?;
                let additional_value2 = r.be16()?;
                let status = if t == block_type::WRITE_RES {
                    Some(PnioStatus::from_u32(r.be32()?))
                } else {
                    None
                };
                let res = RecordResponse {
                    header,
                    sequence,
                    ar_uuid,
                    api,
                    slot,
                    subslot,
                    index,
                    record_data_length,
                    additional_value1,
                    additional_value2,
                    status,
                    data: Vec::new(),
                };
                if t == block_type::READ_RES {
                    Block::ReadRes(res)
                } else {
                    Block::WriteRes(res)
                }
            }
            _ => {
                let kind = ControlKind::from_block_type(t).unwrap_or(ControlKind::PrmEnd);
                r.skip(2)?;
                let ar_uuid = uuid(&mut r)?;
                let session_key = r.be16()?;
                r.skip(2)?;
                let command = r.be16()?;
                let properties = r.be16()?;
                Block::Control(ControlBlock {
                    header,
                    kind,
                    response: t & 0x8000 != 0,
                    ar_uuid,
                    session_key,
                    command,
                    properties,
                })
            }
        })
    })();
    result.map_err(shifted(name, base))
}

fn frame_offset(r: &mut Reader<'_>) -> Result<FrameOffset, Truncated> {
    Ok(FrameOffset {
        slot: r.be16()?,
        subslot: r.be16()?,
        frame_offset: r.be16()?,
    })
}

fn expected_submodule(r: &mut Reader<'_>) -> Result<ExpectedSubmodule, Truncated> {
    let subslot = r.be16()?;
    let ident = r.be32()?;
    let properties = r.be16()?;
    let count = if properties & 0x3 == 3 { 2 } else { 1 };
    let mut input = None;
    let mut output = None;
    for _ in 0..count {
        let kind = r.be16()?;
        let d = DataDescription {
            data_length: r.be16()?,
            iops_length: r.u8()?,
            iocs_length: r.u8()?,
        };
        if kind == 2 {
            output = Some(d);
        } else {
            input = Some(d);
        }
    }
    Ok(ExpectedSubmodule {
        subslot,
        ident,
        properties,
        input,
        output,
    })
}

/// AlarmCRBlockReq (IEC 61158-6-10 "AlarmCRBlockReq"), read from a block kept as
/// [`Block::Unknown`] by [`alarm_cr_req`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AlarmCrBlockReq {
    /// AlarmCRType (1).
    pub alarm_cr_type: u16,
    /// LT (0x8892).
    pub lt: u16,
    /// AlarmCRProperties.
    pub properties: u32,
    /// RTATimeoutFactor (units of 100 ms).
    pub rta_timeout_factor: u16,
    /// RTARetries.
    pub rta_retries: u16,
    /// LocalAlarmReference of the initiator.
    pub local_alarm_reference: u16,
    /// MaxAlarmDataLength.
    pub max_alarm_data_length: u16,
    /// AlarmCRTagHeaderHigh.
    pub tag_header_high: u16,
    /// AlarmCRTagHeaderLow.
    pub tag_header_low: u16,
}

/// AlarmCRBlockRes (IEC 61158-6-10 "AlarmCRBlockRes"), read by [`alarm_cr_res`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AlarmCrBlockRes {
    /// AlarmCRType (1).
    pub alarm_cr_type: u16,
    /// LocalAlarmReference of the responder.
    pub local_alarm_reference: u16,
    /// MaxAlarmDataLength.
    pub max_alarm_data_length: u16,
}

/// One submodule of a [`ModuleDiff`] (IEC 61158-6-10 "ModuleDiffBlock").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DiffSubmodule {
    /// SubslotNumber.
    pub subslot: u16,
    /// SubmoduleIdentNumber of the real submodule.
    pub ident: u32,
    /// SubmoduleState (format 1: bits 11–14 IdentInfo, 7–10 ARInfo).
    pub state: u16,
}

/// One module of a [`ModuleDiff`] (IEC 61158-6-10 "ModuleDiffBlock").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DiffModule {
    /// API.
    pub api: u32,
    /// SlotNumber.
    pub slot: u16,
    /// ModuleIdentNumber of the real module.
    pub ident: u32,
    /// ModuleState (0 no module, 1 wrong module, 2 proper module, 3 substitute).
    pub state: u16,
    /// The submodules that differ.
    pub submodules: Vec<DiffSubmodule>,
}

/// ModuleDiffBlock (IEC 61158-6-10 "ModuleDiffBlock"), read by [`module_diff`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModuleDiff {
    /// The modules that differ from the expected ones.
    pub modules: Vec<DiffModule>,
}

fn typed<T>(
    block: &UnknownBlock,
    want: u16,
    name: &'static str,
    read: impl FnOnce(&mut Reader<'_>) -> Result<T, Truncated>,
) -> Option<Result<T, PnioError>> {
    if block.header.block_type != want {
        return None;
    }
    let mut r = Reader::new(&block.body);
    Some(read(&mut r).map_err(shifted(name, block.header.offset + 6)))
}

/// Reads an AlarmCRBlockReq kept as [`Block::Unknown`]; `None` for another block type.
pub fn alarm_cr_req(block: &UnknownBlock) -> Option<Result<AlarmCrBlockReq, PnioError>> {
    typed(block, block_type::ALARM_CR_REQ, "AlarmCRBlockReq", |r| {
        Ok(AlarmCrBlockReq {
            alarm_cr_type: r.be16()?,
            lt: r.be16()?,
            properties: r.be32()?,
            rta_timeout_factor: r.be16()?,
            rta_retries: r.be16()?,
            local_alarm_reference: r.be16()?,
            max_alarm_data_length: r.be16()?,
            tag_header_high: r.be16()?,
            tag_header_low: r.be16()?,
        })
    })
}

/// Reads an AlarmCRBlockRes kept as [`Block::Unknown`]; `None` for another block type.
pub fn alarm_cr_res(block: &UnknownBlock) -> Option<Result<AlarmCrBlockRes, PnioError>> {
    typed(block, block_type::ALARM_CR_RES, "AlarmCRBlockRes", |r| {
        Ok(AlarmCrBlockRes {
            alarm_cr_type: r.be16()?,
            local_alarm_reference: r.be16()?,
            max_alarm_data_length: r.be16()?,
        })
    })
}

/// Reads a ModuleDiffBlock kept as [`Block::Unknown`]; `None` for another block type. Counts
/// never size an allocation: every element is read from the body.
pub fn module_diff(block: &UnknownBlock) -> Option<Result<ModuleDiff, PnioError>> {
    typed(block, block_type::MODULE_DIFF, "ModuleDiffBlock", |r| {
        let mut modules = Vec::new();
        for _ in 0..r.be16()? {
            let api = r.be32()?;
            for _ in 0..r.be16()? {
                let slot = r.be16()?;
                let ident = r.be32()?;
                let state = r.be16()?;
                let mut submodules = Vec::new();
                for _ in 0..r.be16()? {
                    submodules.push(DiffSubmodule {
                        subslot: r.be16()?,
                        ident: r.be32()?,
                        state: r.be16()?,
                    });
                }
                modules.push(DiffModule {
                    api,
                    slot,
                    ident,
                    state,
                    submodules,
                });
            }
        }
        Ok(ModuleDiff { modules })
    })
}

/// An alarm notification (IEC 61158-6-10 "AlarmNotification-PDU": BlockType 0x0001 low or
/// 0x0002 high, AlarmType, API, slot, subslot, idents, AlarmSpecifier, then the items).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct AlarmNote {
    /// BlockType (0x0001 low, 0x0002 high).
    pub block_type: u16,
    /// AlarmType (1 diagnosis, 2 process, …).
    pub alarm_type: u16,
    /// API.
    pub api: u32,
    /// SlotNumber.
    pub slot: u16,
    /// SubslotNumber.
    pub subslot: u16,
    /// ModuleIdentNumber.
    pub module_ident: u32,
    /// SubmoduleIdentNumber.
    pub submodule_ident: u32,
    /// AlarmSpecifier (sequence number, channel or manufacturer diagnosis, …).
    pub specifier: u16,
    /// The alarm items after the specifier, to the end of the block.
    pub items: Vec<u8>,
}

/// Reads the AlarmNotification block at the start of an RTA var part (IEC 61158-6-10
/// DATA-RTA-PDU); `None` for another block or one that does not fit.
pub fn alarm_notification(var: &[u8]) -> Option<AlarmNote> {
    let mut r = Reader::new(var);
    let block_type = r.be16().ok()?;
    if !matches!(block_type, 0x0001 | 0x0002) {
        return None;
    }
    let len = usize::from(r.be16().ok()?);
    let body = r.take(len).ok()?;
    let mut r = Reader::new(body);
    r.skip(2).ok()?;
    let read = |r: &mut Reader<'_>| -> Result<AlarmNote, Truncated> {
        Ok(AlarmNote {
            block_type,
            alarm_type: r.be16()?,
            api: r.be32()?,
            slot: r.be16()?,
            subslot: r.be16()?,
            module_ident: r.be32()?,
            submodule_ident: r.be32()?,
            specifier: r.be16()?,
            items: r.rest().to_vec(),
        })
    };
    read(&mut r).ok()
}
