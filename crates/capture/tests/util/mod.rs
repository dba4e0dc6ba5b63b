//! Frame builders for the tests: Ethernet, IPv4/UDP, DCE/RPC and PNIO-CM blocks, written
//! field by field from the layouts cited in the crate docs.
#![allow(dead_code, clippy::unwrap_used, clippy::indexing_slicing)]

use drivespec_capture::Endian;

pub const MAC_A: [u8; 6] = [0x00, 0x0e, 0xcf, 0x01, 0x02, 0x03];
pub const MAC_B: [u8; 6] = [0x00, 0x1b, 0x1b, 0x0a, 0x0b, 0x0c];

/// Ethernet II: dst, src, tags (TPID, TCI), ethertype, payload.
pub fn ethernet(tags: &[(u16, u16)], ethertype: u16, payload: &[u8]) -> Vec<u8> {
    let mut f = Vec::new();
    f.extend_from_slice(&MAC_B);
    f.extend_from_slice(&MAC_A);
    for (tpid, tci) in tags {
        f.extend_from_slice(&tpid.to_be_bytes());
        f.extend_from_slice(&tci.to_be_bytes());
    }
    f.extend_from_slice(&ethertype.to_be_bytes());
    f.extend_from_slice(payload);
    f
}

/// Pads an Ethernet frame to the 60-byte minimum (without FCS).
pub fn pad60(mut f: Vec<u8>) -> Vec<u8> {
    while f.len() < 60 {
        f.push(0);
    }
    f
}

/// IPv4 + UDP around `payload` (no options, checksums zero).
pub fn ipv4_udp(src: [u8; 4], dst: [u8; 4], sport: u16, dport: u16, payload: &[u8]) -> Vec<u8> {
    let total = 20 + 8 + payload.len();
    let mut p = vec![0x45, 0];
    p.extend_from_slice(&(total as u16).to_be_bytes());
    p.extend_from_slice(&[0x12, 0x34, 0x00, 0x00, 64, 17, 0, 0]);
    p.extend_from_slice(&src);
    p.extend_from_slice(&dst);
    p.extend_from_slice(&sport.to_be_bytes());
    p.extend_from_slice(&dport.to_be_bytes());
    p.extend_from_slice(&((8 + payload.len()) as u16).to_be_bytes());
    p.extend_from_slice(&[0, 0]);
    p.extend_from_slice(payload);
    p
}

/// A canonical UUID written with its first three fields in `order`.
pub fn uuid_bytes(canonical: [u8; 16], order: Endian) -> Vec<u8> {
    let mut b = canonical.to_vec();
    if order == Endian::Little {
        b[0..4].reverse();
        b[4..6].reverse();
        b[6..8].reverse();
    }
    b
}

pub const PNIO_DEVICE: [u8; 16] = [
    0xDE, 0xA0, 0x00, 0x01, 0x6C, 0x97, 0x11, 0xD1, 0x82, 0x71, 0x00, 0xA0, 0x24, 0x42, 0xDF, 0x7D,
];
pub const ACTIVITY: [u8; 16] = [
    0x11, 0x22, 0x33, 0x44, 0x55, 0x66, 0x77, 0x88, 0x99, 0xaa, 0xbb, 0xcc, 0xdd, 0xee, 0xff, 0x00,
];
pub const AR_UUID: [u8; 16] = [
    0xa0, 0xa1, 0xa2, 0xa3, 0xa4, 0xa5, 0xa6, 0xa7, 0xa8, 0xa9, 0xaa, 0xab, 0xac, 0xad, 0xae, 0xaf,
];

/// Fields of a DCE/RPC connectionless header that tests vary.
#[derive(Clone, Copy)]
pub struct Rpc {
    pub order: Endian,
    pub ptype: u8,
    pub flags1: u8,
    pub opnum: u16,
    pub sequence: u32,
    pub fragment: u16,
}

impl Rpc {
    pub fn request(opnum: u16, order: Endian) -> Rpc {
        Rpc {
            order,
            ptype: 0,
            flags1: 0x20,
            opnum,
            sequence: 7,
            fragment: 0,
        }
    }

    pub fn response(opnum: u16, order: Endian) -> Rpc {
        Rpc {
            ptype: 2,
            ..Rpc::request(opnum, order)
        }
    }

    /// The 80-byte header followed by `body` (C706 12.5.1).
    pub fn pdu(&self, body: &[u8]) -> Vec<u8> {
        let o = self.order;
        let u16b = |v: u16| match o {
            Endian::Big => v.to_be_bytes().to_vec(),
            Endian::Little => v.to_le_bytes().to_vec(),
        };
        let u32b = |v: u32| match o {
            Endian::Big => v.to_be_bytes().to_vec(),
            Endian::Little => v.to_le_bytes().to_vec(),
        };
        let mut p = vec![4, self.ptype, self.flags1, 0];
        p.extend_from_slice(&[if o == Endian::Little { 0x10 } else { 0x00 }, 0, 0]);
        p.push(0); // serial_hi
        p.extend(uuid_bytes([0xde; 16], o)); // object
        p.extend(uuid_bytes(PNIO_DEVICE, o));
        p.extend(uuid_bytes(ACTIVITY, o));
        p.extend(u32b(0)); // server boot
        p.extend(u32b(1)); // interface version
        p.extend(u32b(self.sequence));
        p.extend(u16b(self.opnum));
        p.extend(u16b(0xffff));
        p.extend(u16b(0xffff));
        p.extend(u16b(body.len() as u16));
        p.extend(u16b(self.fragment));
        p.push(0); // auth proto
        p.push(0); // serial_lo
        assert_eq!(p.len(), 80);
        p.extend_from_slice(body);
        p
    }
}

/// NDR request header (ArgsMaximum, ArgsLength, MaximumCount, Offset, ActualCount) + blocks.
pub fn ndr_request(order: Endian, blocks: &[u8]) -> Vec<u8> {
    let n = blocks.len() as u32;
    let mut b = Vec::new();
    for v in [4096, n, 4096, 0, n] {
        b.extend(match order {
            Endian::Big => u32::to_be_bytes(v),
            Endian::Little => u32::to_le_bytes(v),
        });
    }
    b.extend_from_slice(blocks);
    b
}

/// NDR response header (PNIOStatus, ArgsLength, MaximumCount, Offset, ActualCount) + blocks.
pub fn ndr_response(order: Endian, status: [u8; 4], blocks: &[u8]) -> Vec<u8> {
    let n = blocks.len() as u32;
    let mut b = Vec::new();
    let st = u32::from_be_bytes(status);
    for v in [st, n, 4096, 0, n] {
        b.extend(match order {
            Endian::Big => u32::to_be_bytes(v),
            Endian::Little => u32::to_le_bytes(v),
        });
    }
    b.extend_from_slice(blocks);
    b
}

/// A block: BlockType, BlockLength (= body + 2), version 1.0, body.
pub fn block(block_type: u16, body: &[u8]) -> Vec<u8> {
    let mut b = block_type.to_be_bytes().to_vec();
    b.extend_from_slice(&((body.len() + 2) as u16).to_be_bytes());
    b.extend_from_slice(&[1, 0]);
    b.extend_from_slice(body);
    b
}

/// Big-endian field writer.
#[derive(Default)]
pub struct Be(pub Vec<u8>);

impl Be {
    pub fn u8(mut self, v: u8) -> Be {
        self.0.push(v);
        self
    }
    pub fn u16(mut self, v: u16) -> Be {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    pub fn u32(mut self, v: u32) -> Be {
        self.0.extend_from_slice(&v.to_be_bytes());
        self
    }
    pub fn bytes(mut self, v: &[u8]) -> Be {
        self.0.extend_from_slice(v);
        self
    }
}
