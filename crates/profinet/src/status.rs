//! PNIOStatus values this stack sends and recognises (IEC 61158-6-10 "PNIOStatus":
//! ErrorCode, ErrorDecode, ErrorCode1, ErrorCode2). For ErrorDecode PNIO, ErrorCode1 names
//! the faulty block and ErrorCode2 the faulty field, numbered from BlockType = 0 in the
//! block's field order.

use drivespec_capture::pnio::PnioStatus;

/// ErrorCode of an IODConnectRes.
pub const CONNECT: u8 = 0xDB;
/// ErrorCode of an IODReleaseRes.
pub const RELEASE: u8 = 0xDC;
/// ErrorCode of an IODControlRes.
pub const CONTROL: u8 = 0xDD;
/// ErrorCode of an IODReadRes.
pub const READ: u8 = 0xDE;
/// ErrorCode of an IODWriteRes.
pub const WRITE: u8 = 0xDF;
/// ErrorCode of an RTA error (alarm abort).
pub const RTA_ERROR: u8 = 0xCF;
/// ErrorDecode PNIORW (record services; ErrorCode1 is class and code).
pub const PNIORW: u8 = 0x80;
/// ErrorDecode PNIO.
pub const PNIO: u8 = 0x81;

/// ErrorCode1 for ErrorDecode PNIO.
pub mod code1 {
    /// Faulty ARBlockReq.
    pub const AR_BLOCK: u8 = 0x01;
    /// Faulty IOCRBlockReq.
    pub const IOCR_BLOCK: u8 = 0x02;
    /// Faulty ExpectedSubmoduleBlockReq.
    pub const EXPECTED_BLOCK: u8 = 0x03;
    /// Faulty AlarmCRBlockReq.
    pub const ALARM_CR_BLOCK: u8 = 0x04;
    /// Faulty IODControlReq (ControlBlockConnect).
    pub const CONTROL_BLOCK: u8 = 0x14;
    /// Faulty IODReleaseReq.
    pub const RELEASE_BLOCK: u8 = 0x28;
    /// CMDEV (state machine of the device).
    pub const CMDEV: u8 = 0x3D;
    /// CMRPC (the RPC server of the device).
    pub const CMRPC: u8 = 0x40;
    /// RTA_ERR_CLS_PROTOCOL (alarm aborts).
    pub const RTA_PROTOCOL: u8 = 0xFD;
}

/// ErrorCode2 values for CMDEV, CMRPC and RTA_ERR_CLS_PROTOCOL.
pub mod code2 {
    /// CMDEV: state conflict.
    pub const STATE_CONFLICT: u8 = 0x00;
    /// CMRPC: ArgsLength invalid.
    pub const ARGS_LENGTH: u8 = 0x00;
    /// CMRPC: unknown blocks.
    pub const UNKNOWN_BLOCKS: u8 = 0x01;
    /// CMRPC: IOCR missing.
    pub const IOCR_MISSING: u8 = 0x02;
    /// CMRPC: wrong AlarmCRBlockReq or ARBlockReq count.
    pub const WRONG_BLOCK_COUNT: u8 = 0x03;
    /// CMRPC: out of AR resources.
    pub const NO_AR_RESOURCES: u8 = 0x04;
    /// CMRPC: AR UUID unknown.
    pub const AR_UUID_UNKNOWN: u8 = 0x05;
    /// RTA: AR consumer DHT expired (the watchdog).
    pub const DHT_EXPIRED: u8 = 0x05;
    /// RTA: AR CMI timeout.
    pub const CMI_TIMEOUT: u8 = 0x06;
    /// RTA: abort request of the AR's user.
    pub const ABORT_REQ: u8 = 0x0D;
    /// RTA: release indication received.
    pub const RELEASE_IND: u8 = 0x0F;
    /// RTA: link down.
    pub const LINK_DOWN: u8 = 0x1B;
    /// RTA: DCP station name changed.
    pub const NAME_CHANGED: u8 = 0x1F;
}

/// ErrorCode1 for ErrorDecode PNIORW: class (high nibble) and code.
pub mod rw {
    /// Access: invalid index.
    pub const INVALID_INDEX: u8 = 0xB0;
    /// Access: write length error.
    pub const WRITE_LENGTH: u8 = 0xB1;
    /// Access: invalid slot/subslot.
    pub const INVALID_SLOT: u8 = 0xB2;
    /// Access: state conflict.
    pub const STATE_CONFLICT: u8 = 0xB5;
    /// Access: access denied.
    pub const ACCESS_DENIED: u8 = 0xB6;
    /// Access: invalid range.
    pub const INVALID_RANGE: u8 = 0xB7;
    /// Access: invalid parameter.
    pub const INVALID_PARAMETER: u8 = 0xB8;
}

/// A PNIOStatus from its four bytes.
pub const fn status(code: u8, decode: u8, code1: u8, code2: u8) -> PnioStatus {
    PnioStatus {
        code,
        decode,
        code1,
        code2,
    }
}

/// A Connect refused for field `field` of the block `block` (ErrorCode1).
pub const fn connect_field(block: u8, field: u8) -> PnioStatus {
    status(CONNECT, PNIO, block, field)
}

/// The ERR-RTA status of an AR aborted for `reason` (RTA_ERR_CLS_PROTOCOL ErrorCode2).
pub const fn abort(reason: u8) -> PnioStatus {
    status(RTA_ERROR, PNIO, code1::RTA_PROTOCOL, reason)
}
