//! PROFINET RT frames (Ethertype 0x8892, or UDP port 0x8892 for RT_CLASS_UDP), IEC 61158-6-10
//! "FrameID" ranges and APDU status.
//!
//! A frame is `FrameID (2) | data`. Cyclic frames end with the APDU status
//! `CycleCounter (2) | DataStatus (1) | TransferStatus (1)` at the very end of the Ethernet
//! payload; the bytes between the FrameID and the APDU status are the C_SDU (IO data with
//! IOPS/IOCS) followed by padding up to the minimum frame size. The C_SDU length is only known
//! from the Connect (IOCRBlockReq `DataLength`), so [`CyclicFrame::data`] gives the whole
//! span and [`CyclicFrame::c_sdu`] cuts it to a known length. A captured FCS is assumed absent.
//!
//! Parsing borrows the frame, never allocates and never panics.

use crate::bytes::{Reader, Truncated};
use std::fmt;

/// A PROFINET FrameID (IEC 61158-6-10, FrameID table).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct FrameId(pub u16);

impl fmt::Display for FrameId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{:#06x}", self.0)
    }
}

/// The cyclic classes by FrameID range (IEC 61158-6-10 FrameID table; names of the editions
/// up to V2.2, with the later names in the docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CyclicClass {
    /// 0x0100–0x0FFF: RT_CLASS_3 (isochronous); 0x0700–0x0FFF redundant.
    Class3 {
        /// In the redundant sub-range.
        redundant: bool,
    },
    /// 0x8000–0xBFFF: RT_CLASS_2 (later editions: RT_CLASS_1 unicast 0x8000–0xBBFF,
    /// multicast 0xBC00–0xBFFF).
    Class2 {
        /// In the multicast sub-range 0xBC00–0xBFFF.
        multicast: bool,
    },
    /// 0xC000–0xFBFF: RT_CLASS_1 (legacy) or RT_CLASS_UDP; multicast 0xF800–0xFBFF.
    Class1 {
        /// In the multicast sub-range 0xF800–0xFBFF.
        multicast: bool,
    },
}

/// What a FrameID says a frame is (IEC 61158-6-10 FrameID table).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum FrameClass {
    /// 0x0020–0x0021 (with follow-up) and 0x0080–0x0081: PTCP RTSync.
    PtcpSync {
        /// 0x0020–0x0021: a FollowUp frame follows.
        follow_up: bool,
    },
    /// Cyclic data with an APDU status.
    Cyclic(CyclicClass),
    /// 0xFC01: alarm, high priority.
    AlarmHigh,
    /// 0xFE01: alarm, low priority.
    AlarmLow,
    /// 0xFEFC: DCP Hello.
    DcpHello,
    /// 0xFEFD: DCP Get/Set.
    DcpGetSet,
    /// 0xFEFE: DCP Identify request (multicast).
    DcpIdentifyRequest,
    /// 0xFEFF: DCP Identify response.
    DcpIdentifyResponse,
    /// 0xFF00–0xFF01: PTCP Announce.
    PtcpAnnounce,
    /// 0xFF20–0xFF21: PTCP FollowUp.
    PtcpFollowUp,
    /// 0xFF40–0xFF43: PTCP Delay.
    PtcpDelay,
    /// 0xFF80–0xFF8F: fragmentation (FRAG_PDU).
    Fragment,
    /// Any other acyclic FrameID (0xFC00–0xFEFF not listed above: RSI, secured alarms …).
    OtherAcyclic,
    /// A reserved FrameID.
    Reserved,
}

impl FrameClass {
    /// Whether this is any DCP frame.
    pub fn is_dcp(self) -> bool {
        matches!(
            self,
            FrameClass::DcpHello
                | FrameClass::DcpGetSet
                | FrameClass::DcpIdentifyRequest
                | FrameClass::DcpIdentifyResponse
        )
    }

    /// Whether this is any PTCP frame.
    pub fn is_ptcp(self) -> bool {
        matches!(
            self,
            FrameClass::PtcpSync { .. }
                | FrameClass::PtcpAnnounce
                | FrameClass::PtcpFollowUp
                | FrameClass::PtcpDelay
        )
    }
}

impl FrameId {
    /// Alarm high priority.
    pub const ALARM_HIGH: FrameId = FrameId(0xFC01);
    /// Alarm low priority.
    pub const ALARM_LOW: FrameId = FrameId(0xFE01);
    /// DCP Hello.
    pub const DCP_HELLO: FrameId = FrameId(0xFEFC);
    /// DCP Get/Set.
    pub const DCP_GET_SET: FrameId = FrameId(0xFEFD);
    /// DCP Identify request.
    pub const DCP_IDENTIFY_REQ: FrameId = FrameId(0xFEFE);
    /// DCP Identify response.
    pub const DCP_IDENTIFY_RES: FrameId = FrameId(0xFEFF);

    /// The class of this FrameID.
    pub fn class(self) -> FrameClass {
        match self.0 {
            0x0020..=0x0021 => FrameClass::PtcpSync { follow_up: true },
            0x0080..=0x0081 => FrameClass::PtcpSync { follow_up: false },
            0x0100..=0x0FFF => FrameClass::Cyclic(CyclicClass::Class3 {
                redundant: self.0 >= 0x0700,
            }),
            0x8000..=0xBFFF => FrameClass::Cyclic(CyclicClass::Class2 {
                multicast: self.0 >= 0xBC00,
            }),
            0xC000..=0xFBFF => FrameClass::Cyclic(CyclicClass::Class1 {
                multicast: self.0 >= 0xF800,
            }),
            0xFC01 => FrameClass::AlarmHigh,
            0xFE01 => FrameClass::AlarmLow,
            0xFEFC => FrameClass::DcpHello,
            0xFEFD => FrameClass::DcpGetSet,
            0xFEFE => FrameClass::DcpIdentifyRequest,
            0xFEFF => FrameClass::DcpIdentifyResponse,
            0xFC00..=0xFEFF => FrameClass::OtherAcyclic,
            0xFF00..=0xFF01 => FrameClass::PtcpAnnounce,
            0xFF20..=0xFF21 => FrameClass::PtcpFollowUp,
            0xFF40..=0xFF43 => FrameClass::PtcpDelay,
            0xFF80..=0xFF8F => FrameClass::Fragment,
            _ => FrameClass::Reserved,
        }
    }
}

/// Why an RT frame cannot be read (our doc: module `rt`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum RtError {
    /// The frame ends inside a field.
    #[error("PROFINET RT: {0}")]
    Truncated(#[from] Truncated),
    /// The frame is not of the class the accessor needs.
    #[error("frame {frame_id} is {class:?}, not {expected}")]
    WrongClass {
        /// The FrameID.
        frame_id: FrameId,
        /// Its class.
        class: FrameClass,
        /// What was asked for.
        expected: &'static str,
    },
    /// A known C_SDU length longer than the data between FrameID and APDU status.
    #[error("C_SDU of {expected} bytes expected, frame {frame_id} has only {available}")]
    CsduTooLong {
        /// The FrameID.
        frame_id: FrameId,
        /// Length from the Connect.
        expected: usize,
        /// Bytes between FrameID and APDU status.
        available: usize,
    },
}

/// A PROFINET RT frame: FrameID and the bytes after it (IEC 61158-6-10).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RtFrame<'a> {
    /// The FrameID.
    pub frame_id: FrameId,
    /// Bytes after the FrameID, to the end of the captured payload.
    pub body: &'a [u8],
}

/// DataStatus of the APDU status (IEC 61158-6-10 "DataStatus" bits).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct DataStatus(pub u8);

impl DataStatus {
    /// Bit 0 State: 1 primary, 0 backup.
    pub fn primary(self) -> bool {
        self.0 & 0x01 != 0
    }
    /// Bit 1 Redundancy.
    pub fn redundancy(self) -> bool {
        self.0 & 0x02 != 0
    }
    /// Bit 2 DataValid.
    pub fn data_valid(self) -> bool {
        self.0 & 0x04 != 0
    }
    /// Bit 4 ProviderState: 1 run, 0 stop.
    pub fn provider_run(self) -> bool {
        self.0 & 0x10 != 0
    }
    /// Bit 5 StationProblemIndicator: 1 normal operation, 0 problem detected.
    pub fn station_ok(self) -> bool {
        self.0 & 0x20 != 0
    }
    /// Bit 7 Ignore: 1 the frame is to be ignored.
    pub fn ignore(self) -> bool {
        self.0 & 0x80 != 0
    }
    /// Reserved bits 3 and 6.
    pub fn reserved(self) -> u8 {
        self.0 & 0x48
    }
}

impl fmt::Display for DataStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{:#04x} ({}, {}, {}, {}{})",
            self.0,
            if self.primary() { "primary" } else { "backup" },
            if self.data_valid() {
                "valid"
            } else {
                "invalid"
            },
            if self.provider_run() { "run" } else { "stop" },
            if self.station_ok() { "ok" } else { "problem" },
            if self.ignore() { ", ignore" } else { "" }
        )
    }
}

/// The APDU status at the end of a cyclic frame (IEC 61158-6-10 "APDU_Status").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ApduStatus {
    /// CycleCounter (units of 31.25 µs).
    pub cycle_counter: u16,
    /// DataStatus.
    pub data_status: DataStatus,
    /// TransferStatus (0: OK).
    pub transfer_status: u8,
}

/// A cyclic frame split into data and APDU status (IEC 61158-6-10).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CyclicFrame<'a> {
    /// The FrameID.
    pub frame_id: FrameId,
    /// Its cyclic class.
    pub class: CyclicClass,
    /// C_SDU and padding: everything between FrameID and APDU status.
    pub data: &'a [u8],
    /// The APDU status.
    pub apdu: ApduStatus,
}

impl<'a> CyclicFrame<'a> {
    /// The C_SDU of a known length (IOCRBlockReq `DataLength`), without padding.
    pub fn c_sdu(&self, len: usize) -> Result<&'a [u8], RtError> {
        self.data.get(..len).ok_or(RtError::CsduTooLong {
            frame_id: self.frame_id,
            expected: len,
            available: self.data.len(),
        })
    }

    /// The padding after a C_SDU of a known length.
    pub fn padding(&self, len: usize) -> Result<&'a [u8], RtError> {
        self.c_sdu(len)?;
        Ok(self.data.get(len..).unwrap_or(&[]))
    }
}

/// The DCP header (IEC 61158-6-10 "DCP": ServiceID, ServiceType, Xid, ResponseDelay,
/// DCPDataLength).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DcpHeader<'a> {
    /// ServiceID (3 Get, 4 Set, 5 Identify, 6 Hello).
    pub service_id: u8,
    /// ServiceType (0 request, 1 response success, 5 response not supported).
    pub service_type: u8,
    /// Transaction id.
    pub xid: u32,
    /// ResponseDelayFactor (identify request) or reserved.
    pub response_delay: u16,
    /// DCPDataLength.
    pub data_length: u16,
    /// The blocks (DCPDataLength bytes, or what was captured).
    pub blocks: &'a [u8],
}

/// One DCP block (IEC 61158-6-10 "DCP": Option, Suboption, DCPBlockLength, then
/// BlockInfo or BlockQualifier where the service has one, and the data).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DcpBlock<'a> {
    /// Option (1 IP, 2 device properties, 5 control, 6 device initiative, 0xFF all).
    pub option: u8,
    /// Suboption.
    pub suboption: u8,
    /// The DCPBlockLength bytes after the length field (BlockInfo or BlockQualifier first,
    /// where present).
    pub data: &'a [u8],
}

/// The blocks of a DCP PDU, each padded to an even length (our doc: module `rt`). Ends at
/// the first block that does not fit.
#[derive(Debug, Clone)]
pub struct DcpBlocks<'a> {
    rest: &'a [u8],
}

impl<'a> Iterator for DcpBlocks<'a> {
    type Item = Result<DcpBlock<'a>, Truncated>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.rest.is_empty() {
            return None;
        }
        let mut r = Reader::new(self.rest);
        let block = (|| {
            let option = r.u8()?;
            let suboption = r.u8()?;
            let len = usize::from(r.be16()?);
            let data = r.take(len)?;
            if len % 2 == 1 && r.remaining() > 0 {
                r.skip(1)?;
            }
            Ok(DcpBlock {
                option,
                suboption,
                data,
            })
        })();
        match block {
            Ok(b) => {
                self.rest = r.rest();
                Some(Ok(b))
            }
            Err(e) => {
                self.rest = &[];
                Some(Err(e))
            }
        }
    }
}

impl<'a> DcpHeader<'a> {
    /// The blocks after the header.
    pub fn iter_blocks(&self) -> DcpBlocks<'a> {
        DcpBlocks { rest: self.blocks }
    }
}

/// The RTA-PDU header of an alarm frame (IEC 61158-6-10 "RTA-PDU").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AlarmHeader<'a> {
    /// AlarmDstEndpoint.
    pub dst_endpoint: u16,
    /// AlarmSrcEndpoint.
    pub src_endpoint: u16,
    /// PDUType: type in bits 0–3 (1 DATA, 2 NACK, 3 ACK, 4 ERR), version in bits 4–7.
    pub pdu_type: u8,
    /// AddFlags.
    pub add_flags: u8,
    /// SendSeqNum.
    pub send_seq: u16,
    /// AckSeqNum.
    pub ack_seq: u16,
    /// VarPartLen.
    pub var_part_len: u16,
    /// The var part (VarPartLen bytes, or what was captured).
    pub var_part: &'a [u8],
}

/// The FRAG_PDU header (IEC 61158-6-10 fragmentation: FragDataLength, FragStatus).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FragmentHeader<'a> {
    /// FragDataLength, in units of 8 bytes.
    pub data_length: u8,
    /// FragStatus bit 7: more fragments follow.
    pub more_follows: bool,
    /// FragStatus bits 0–5: fragment number.
    pub number: u8,
    /// The fragment data.
    pub data: &'a [u8],
}

impl<'a> RtFrame<'a> {
    /// Reads the FrameID of an RT payload (after the Ethertype, or a UDP payload).
    pub fn parse(payload: &'a [u8]) -> Result<RtFrame<'a>, RtError> {
        let mut r = Reader::new(payload);
        let frame_id = FrameId(r.be16()?);
        Ok(RtFrame {
            frame_id,
            body: r.rest(),
        })
    }

    /// The class of the FrameID.
    pub fn class(&self) -> FrameClass {
        self.frame_id.class()
    }

    fn wrong(&self, expected: &'static str) -> RtError {
        RtError::WrongClass {
            frame_id: self.frame_id,
            class: self.class(),
            expected,
        }
    }

    /// Splits a cyclic frame into data and APDU status.
    pub fn cyclic(&self) -> Result<CyclicFrame<'a>, RtError> {
        let FrameClass::Cyclic(class) = self.class() else {
            return Err(self.wrong("cyclic"));
        };
        let split = self.body.len().checked_sub(4).ok_or(Truncated {
            offset: 2,
            need: 4,
            have: self.body.len(),
        })?;
        let (data, status) = self.body.split_at(split);
        let mut r = Reader::new(status);
        let cycle_counter = r.be16()?;
        let data_status = DataStatus(r.u8()?);
        let transfer_status = r.u8()?;
        Ok(CyclicFrame {
            frame_id: self.frame_id,
            class,
            data,
            apdu: ApduStatus {
                cycle_counter,
                data_status,
                transfer_status,
            },
        })
    }

    /// Reads the DCP header.
    pub fn dcp(&self) -> Result<DcpHeader<'a>, RtError> {
        if !self.class().is_dcp() {
            return Err(self.wrong("DCP"));
        }
        let mut r = Reader::new(self.body);
        let service_id = r.u8()?;
        let service_type = r.u8()?;
        let xid = r.be32()?;
        let response_delay = r.be16()?;
        let data_length = r.be16()?;
        let rest = r.rest();
        let blocks = rest.get(..usize::from(data_length)).unwrap_or(rest);
        Ok(DcpHeader {
            service_id,
            service_type,
            xid,
            response_delay,
            data_length,
            blocks,
        })
    }

    /// Reads the RTA-PDU header of an alarm frame.
    pub fn alarm(&self) -> Result<AlarmHeader<'a>, RtError> {
        if !matches!(self.class(), FrameClass::AlarmHigh | FrameClass::AlarmLow) {
            return Err(self.wrong("alarm"));
        }
        let mut r = Reader::new(self.body);
        let dst_endpoint = r.be16()?;
        let src_endpoint = r.be16()?;
        let pdu_type = r.u8()?;
        let add_flags = r.u8()?;
        let send_seq = r.be16()?;
        let ack_seq = r.be16()?;
        let var_part_len = r.be16()?;
        let rest = r.rest();
        let var_part = rest.get(..usize::from(var_part_len)).unwrap_or(rest);
        Ok(AlarmHeader {
            dst_endpoint,
            src_endpoint,
            pdu_type,
            add_flags,
            send_seq,
            ack_seq,
            var_part_len,
            var_part,
        })
    }

    /// Reads the FRAG_PDU header.
    pub fn fragment(&self) -> Result<FragmentHeader<'a>, RtError> {
        if self.class() != FrameClass::Fragment {
            return Err(self.wrong("fragment"));
        }
        let mut r = Reader::new(self.body);
        let data_length = r.u8()?;
        let status = r.u8()?;
        Ok(FragmentHeader {
            data_length,
            more_follows: status & 0x80 != 0,
            number: status & 0x3f,
            data: r.rest(),
        })
    }
}
