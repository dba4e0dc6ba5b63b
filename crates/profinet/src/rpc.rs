//! DCE/RPC connectionless PDUs (C706 12.5: the 80-byte header and the body) as PNIO-CM sends
//! them over UDP; decoding is `drivespec_capture::dcerpc`.

use crate::buf::{len16, Buf};
use drivespec_capture::dcerpc::{flags1, DataRep, Header, PacketType, Uuid};
use drivespec_capture::Endian;

/// The PNIO-CM interface version (IEC 61158-6-10 "RPC": 1).
pub const INTERFACE_VERSION: u32 = 1;

/// "No hint" for the interface and activity hints (C706 12.5.2.12).
pub const NO_HINT: u16 = 0xFFFF;

/// The data representation sent: little-endian integers, ASCII, IEEE floats (C706 14.1).
pub const DREP: DataRep = DataRep {
    integer: Endian::Little,
    character: 0,
    float: 0,
};

fn uuid(b: &mut Buf, u: Uuid, order: Endian) {
    let mut v = u.0;
    if order == Endian::Little {
        for range in [0..4, 4..6, 6..8] {
            if let Some(f) = v.get_mut(range) {
                f.reverse();
            }
        }
    }
    b.bytes(&v);
}

/// A connectionless PDU: `header` (its `body_len` is taken from `body`) and `body`.
pub fn encode(header: &Header, body: &[u8]) -> Vec<u8> {
    let order = header.drep.integer;
    let d0 = match order {
        Endian::Big => 0x00,
        Endian::Little => 0x10,
    } | (header.drep.character & 0x0f);
    let mut b = Buf::default();
    b.u8(header.version)
        .u8(header.ptype.0)
        .u8(header.flags1)
        .u8(header.flags2)
        .u8(d0)
        .u8(header.drep.float)
        .u8(0)
        .u8((header.serial >> 8) as u8);
    uuid(&mut b, header.object, order);
    uuid(&mut b, header.interface, order);
    uuid(&mut b, header.activity, order);
    b.u32(header.server_boot, order)
        .u32(header.interface_version, order)
        .u32(header.sequence, order)
        .u16(header.opnum, order)
        .u16(header.interface_hint, order)
        .u16(header.activity_hint, order)
        .u16(len16(body.len()), order)
        .u16(header.fragment, order)
        .u8(header.auth_proto)
        .u8((header.serial & 0xff) as u8)
        .bytes(body);
    b.0
}

/// The header of a request (idempotent, not fragmented) on `interface` to `object`.
pub fn request_header(
    object: Uuid,
    interface: Uuid,
    activity: Uuid,
    sequence: u32,
    opnum: u16,
) -> Header {
    Header {
        version: 4,
        ptype: PacketType::REQUEST,
        flags1: flags1::IDEMPOTENT,
        flags2: 0,
        drep: DREP,
        serial: 0,
        object,
        interface,
        activity,
        server_boot: 0,
        interface_version: INTERFACE_VERSION,
        sequence,
        opnum,
        interface_hint: NO_HINT,
        activity_hint: NO_HINT,
        body_len: 0,
        fragment: 0,
        auth_proto: 0,
    }
}

/// The header of the response to `request` (same activity, sequence and opnum; last
/// fragment, no FACK), from a server booted at `server_boot`.
pub fn response_header(request: &Header, server_boot: u32) -> Header {
    Header {
        ptype: PacketType::RESPONSE,
        flags1: flags1::LAST_FRAG | flags1::NO_FACK,
        drep: DREP,
        server_boot,
        ..*request
    }
}
