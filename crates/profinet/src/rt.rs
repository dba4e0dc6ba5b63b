//! RT frames (IEC 61158-6-10): cyclic class 1 frames (FrameID, C_SDU, APDU status) and
//! acyclic alarm frames (RTA-PDU). Decoding is `drivespec_capture::rt`.

use crate::buf::{len16, Buf};
use drivespec_capture::pnio::PnioStatus;
use drivespec_capture::rt::FrameId;

/// The smallest C_SDU of a frame without VLAN tag (IEC 61158-6-10: 40 bytes, so that the
/// frame reaches 64 bytes).
pub const MIN_C_SDU: usize = 40;

/// The largest C_SDU (IEC 61158-6-10 "C_SDU": 1440 bytes).
pub const MAX_C_SDU: usize = 1440;

/// IOxS values (IEC 61158-6-10 "IOxS": bit 7 DataState).
pub mod ioxs {
    /// Good.
    pub const GOOD: u8 = 0x80;
    /// Bad, detected by the subslot.
    pub const BAD: u8 = 0x00;
}

/// DataStatus bits (IEC 61158-6-10 "DataStatus").
pub mod data_status {
    /// State: primary.
    pub const PRIMARY: u8 = 0x01;
    /// DataValid.
    pub const DATA_VALID: u8 = 0x04;
    /// ProviderState: run.
    pub const RUN: u8 = 0x10;
    /// StationProblemIndicator: normal operation.
    pub const STATION_OK: u8 = 0x20;
    /// A provider in RUN with valid data and no problem (0x35).
    pub const GOOD_RUN: u8 = PRIMARY | DATA_VALID | RUN | STATION_OK;
    /// The same provider in STOP (0x25).
    pub const GOOD_STOP: u8 = PRIMARY | DATA_VALID | STATION_OK;
}

/// Time of one CycleCounter unit and one SendClockFactor unit (IEC 61158-6-10: 31.25 µs).
pub const COUNT_NS: u64 = 31_250;

/// A cyclic frame's RT payload: FrameID, the C_SDU padded to [`MIN_C_SDU`], APDU status.
pub fn cyclic(frame_id: FrameId, c_sdu: &[u8], cycle_counter: u16, data_status: u8) -> Vec<u8> {
    let mut b = Buf::default();
    b.be16(frame_id.0).bytes(c_sdu);
    for _ in c_sdu.len()..MIN_C_SDU {
        b.u8(0);
    }
    b.be16(cycle_counter).u8(data_status).u8(0);
    b.0
}

/// PDUType values of the RTA-PDU (IEC 61158-6-10 "PDU-Type": type in bits 0–3, version 1 in
/// bits 4–7).
pub mod pdu_type {
    /// DATA-RTA-PDU.
    pub const DATA: u8 = 0x11;
    /// NACK-RTA-PDU.
    pub const NACK: u8 = 0x12;
    /// ACK-RTA-PDU.
    pub const ACK: u8 = 0x13;
    /// ERR-RTA-PDU.
    pub const ERR: u8 = 0x14;
}

/// An alarm frame's RT payload (FrameID 0xFE01 low or 0xFC01 high): the RTA-PDU header
/// (destination and source endpoint, PDUType, AddFlags, SendSeqNum, AckSeqNum, VarPartLen)
/// and `var_part`.
pub fn alarm(
    frame_id: FrameId,
    dst_endpoint: u16,
    src_endpoint: u16,
    pdu_type: u8,
    send_seq: u16,
    ack_seq: u16,
    var_part: &[u8],
) -> Vec<u8> {
    let mut b = Buf::default();
    b.be16(frame_id.0)
        .be16(dst_endpoint)
        .be16(src_endpoint)
        .u8(pdu_type)
        .u8(0x01)
        .be16(send_seq)
        .be16(ack_seq)
        .be16(len16(var_part.len()))
        .bytes(var_part);
    b.0
}

/// The ERR-RTA-PDU that aborts an AR with `status` (IEC 61158-6-10 "ERR-RTA-PDU": the
/// PNIOStatus as var part), as RT payload on the low-priority alarm FrameID.
pub fn abort(dst_endpoint: u16, src_endpoint: u16, status: PnioStatus) -> Vec<u8> {
    let s = [status.code, status.decode, status.code1, status.code2];
    alarm(
        FrameId::ALARM_LOW,
        dst_endpoint,
        src_endpoint,
        pdu_type::ERR,
        0xFFFF,
        0xFFFE,
        &s,
    )
}
