//! DCP, the discovery and configuration protocol (IEC 61158-6-10 "DCP"): the header
//! (ServiceID, ServiceType, Xid, ResponseDelay, DCPDataLength) and the blocks (Option,
//! Suboption, DCPBlockLength, BlockInfo or BlockQualifier, data, padded to even length).
//! Decoding is `drivespec_capture::rt` (`RtFrame::dcp`, `DcpHeader::iter_blocks`).

use crate::buf::{len16, Buf};
use drivespec_capture::rt::FrameId;

/// ServiceID values (IEC 61158-6-10 "DCP ServiceID").
pub mod service {
    /// Get.
    pub const GET: u8 = 3;
    /// Set.
    pub const SET: u8 = 4;
    /// Identify.
    pub const IDENTIFY: u8 = 5;
    /// Hello.
    pub const HELLO: u8 = 6;
}

/// ServiceType values (IEC 61158-6-10 "DCP ServiceType").
pub mod service_type {
    /// Request.
    pub const REQUEST: u8 = 0;
    /// Response, success.
    pub const SUCCESS: u8 = 1;
    /// Response, request not supported.
    pub const NOT_SUPPORTED: u8 = 5;
}

/// Option and suboption pairs (IEC 61158-6-10 "DCP Option", "Suboption").
pub mod opt {
    /// IP: MAC address.
    pub const IP_MAC: (u8, u8) = (1, 1);
    /// IP: IP parameter (address, mask, gateway).
    pub const IP_PARAMETER: (u8, u8) = (1, 2);
    /// Device properties: DeviceVendor (type of station).
    pub const DEVICE_VENDOR: (u8, u8) = (2, 1);
    /// Device properties: NameOfStation.
    pub const NAME_OF_STATION: (u8, u8) = (2, 2);
    /// Device properties: DeviceID (VendorID, DeviceID).
    pub const DEVICE_ID: (u8, u8) = (2, 3);
    /// Device properties: DeviceRole.
    pub const DEVICE_ROLE: (u8, u8) = (2, 4);
    /// Device properties: DeviceOptions (the supported option pairs).
    pub const DEVICE_OPTIONS: (u8, u8) = (2, 5);
    /// Device properties: AliasName.
    pub const ALIAS_NAME: (u8, u8) = (2, 6);
    /// Control: Start transaction.
    pub const CONTROL_START: (u8, u8) = (5, 1);
    /// Control: Stop transaction.
    pub const CONTROL_STOP: (u8, u8) = (5, 2);
    /// Control: Signal (flash the LED).
    pub const CONTROL_SIGNAL: (u8, u8) = (5, 3);
    /// Control: Response (in Set responses: option, suboption, BlockError).
    pub const CONTROL_RESPONSE: (u8, u8) = (5, 4);
    /// Control: FactoryReset.
    pub const CONTROL_FACTORY_RESET: (u8, u8) = (5, 5);
    /// DeviceInitiative.
    pub const DEVICE_INITIATIVE: (u8, u8) = (6, 1);
    /// All selector (Identify all).
    pub const ALL: (u8, u8) = (0xFF, 0xFF);
}

/// BlockError of a Control Response block (IEC 61158-6-10 "DCP BlockError").
pub mod block_error {
    /// No error.
    pub const OK: u8 = 0;
    /// Option not supported.
    pub const OPTION: u8 = 1;
    /// Suboption not supported or no data set available.
    pub const SUBOPTION: u8 = 2;
    /// Suboption not set.
    pub const NOT_SET: u8 = 3;
    /// SET not possible by local reasons.
    pub const LOCAL: u8 = 5;
}

/// BlockInfo of the IP parameter block: IP set (bit 0) (IEC 61158-6-10 "DCP BlockInfo").
pub const IP_SET: u16 = 0x0001;

/// BlockQualifier of a Set: store permanently (bit 0) (IEC 61158-6-10 "BlockQualifier").
pub const PERMANENT: u16 = 0x0001;

/// The DCP blocks of a PDU being encoded.
#[derive(Debug, Default, Clone)]
pub struct DcpBlocks(Buf);

impl DcpBlocks {
    /// No blocks yet.
    pub fn new() -> DcpBlocks {
        DcpBlocks::default()
    }

    /// A block with a BlockInfo (responses) or BlockQualifier (Set requests) before `data`.
    pub fn with_info(
        &mut self,
        (option, suboption): (u8, u8),
        info: u16,
        data: &[u8],
    ) -> &mut DcpBlocks {
        self.0
            .u8(option)
            .u8(suboption)
            .be16(len16(data.len() + 2))
            .be16(info)
            .bytes(data);
        self.pad(data.len() + 2)
    }

    /// A block with only data (Identify filters, Get request lists).
    pub fn plain(&mut self, (option, suboption): (u8, u8), data: &[u8]) -> &mut DcpBlocks {
        self.0
            .u8(option)
            .u8(suboption)
            .be16(len16(data.len()))
            .bytes(data);
        self.pad(data.len())
    }

    fn pad(&mut self, len: usize) -> &mut DcpBlocks {
        if len % 2 == 1 {
            self.0.u8(0);
        }
        self
    }

    /// Whether nothing was added.
    pub fn is_empty(&self) -> bool {
        self.0.len() == 0
    }

    /// The encoded blocks.
    pub fn into_bytes(self) -> Vec<u8> {
        self.0 .0
    }
}

/// A DCP PDU as RT payload: FrameID, header and blocks (padding after an odd last block is
/// not counted in DCPDataLength).
pub fn pdu(
    frame_id: FrameId,
    service_id: u8,
    service_type: u8,
    xid: u32,
    response_delay: u16,
    blocks: &[u8],
) -> Vec<u8> {
    let mut b = Buf::default();
    b.be16(frame_id.0)
        .u8(service_id)
        .u8(service_type)
        .be32(xid)
        .be16(response_delay)
        .be16(len16(blocks.len()))
        .bytes(blocks);
    b.0
}

/// IP parameter data: address, mask, gateway.
pub fn ip_parameter(ip: [u8; 4], mask: [u8; 4], gateway: [u8; 4]) -> Vec<u8> {
    let mut v = Vec::with_capacity(12);
    v.extend_from_slice(&ip);
    v.extend_from_slice(&mask);
    v.extend_from_slice(&gateway);
    v
}

/// Whether `name` is a valid NameOfStation (IEC 61158-6-10 "NameOfStation", after RFC 5890
/// labels): 1–240 characters, labels of 1–63 of `a-z 0-9 -`, not starting or ending with
/// `-`, not of the form `n.n.n.n`, not starting with `port-xyz`.
pub fn valid_station_name(name: &[u8]) -> bool {
    if name.is_empty() || name.len() > 240 {
        return false;
    }
    let labels: Vec<&[u8]> = name.split(|c| *c == b'.').collect();
    let label_ok = |l: &&[u8]| {
        !l.is_empty()
            && l.len() <= 63
            && l.iter()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == b'-')
            && l.first() != Some(&b'-')
            && l.last() != Some(&b'-')
    };
    let ip_like = labels.len() == 4 && labels.iter().all(|l| l.iter().all(u8::is_ascii_digit));
    labels.iter().all(label_ok) && !ip_like && !name.starts_with(b"port-")
}
