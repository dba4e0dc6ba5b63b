//! Fuzz harnesses of the capture readers and decoders (drivespec-capture: pcap/pcapng,
//! PROFINET RT, DCE/RPC, PNIO-CM, serial recordings, IO-Link logs).

use drivespec_capture::dcerpc::{self, PacketType, Reassembler, ReassemblyLimits};
use drivespec_capture::iolink::{CsvReader, IoLinkReader, JsonLinesReader};
use drivespec_capture::link::parse_link;
use drivespec_capture::pcap::{CaptureError, Options};
use drivespec_capture::pnio;
use drivespec_capture::profinet::{Counts, Decoder, Events};
use drivespec_capture::rt::RtFrame;
use drivespec_capture::serial::{SerialReader, SocatReader, TextReader};
use drivespec_capture::{detect, CaptureReader, Endian, Format, LinkType};

/// pcap/pcapng reader: never panics, ends, numbers records from 1 with rising offsets inside
/// the input, yields nothing after an error; the PROFINET events of the same bytes agree.
pub fn pcap(data: &[u8]) {
    let _ = detect(data).to_string();
    let options = Options {
        max_block: 1 << 16,
        max_interfaces: 64,
    };
    let Ok(mut reader) = CaptureReader::with_options(data, options) else {
        return;
    };
    // Offsets count decompressed bytes when the input is gzip.
    let bound = if reader.gzip() {
        u64::MAX
    } else {
        data.len() as u64
    };
    let mut decoder = Decoder::default();
    let mut counts = Counts::default();
    let mut last = 0u64;
    loop {
        match reader.next_record() {
            Ok(Some(r)) => {
                assert_eq!(r.number, counts.records + 1);
                assert!(r.offset >= last && r.offset < bound);
                assert!(r.data.len() as u64 <= bound);
                last = r.offset;
                counts.add(&decoder.decode(r.link_type, r.data));
            }
            Ok(None) => break,
            Err(e) => {
                let _ = e.to_string();
                if let CaptureError::Truncated { offset, .. } = e {
                    assert!(offset >= last && offset <= bound);
                }
                assert!(matches!(reader.next_record(), Ok(None)));
                break;
            }
        }
    }
    if let Ok(reader) = CaptureReader::with_options(data, options) {
        let mut events = Events::new(reader);
        for _ in &mut events {}
        assert_eq!(events.counts(), counts);
    }
}

/// One frame through every link type and the PROFINET decoders: never panics; a cyclic frame's
/// data, APDU status and FrameID add up to its payload.
pub fn frame(data: &[u8]) {
    for link in [
        LinkType::ETHERNET,
        LinkType::LINUX_SLL,
        LinkType::LINUX_SLL2,
        LinkType::RAW,
    ] {
        if let Ok(f) = parse_link(link, data) {
            assert_eq!(f.header_len + f.payload.len(), data.len());
        }
        let _ = Decoder::default().decode(link, data);
    }
    if let Ok(f) = RtFrame::parse(data) {
        if let Ok(c) = f.cyclic() {
            assert_eq!(2 + c.data.len() + 4, data.len());
            assert_eq!(
                c.c_sdu(c.data.len()).expect("a decoded C_SDU re-encodes"),
                c.data
            );
            assert!(c.c_sdu(c.data.len() + 1).is_err());
        }
        let _ = (f.dcp(), f.alarm(), f.fragment());
    }
}

/// DCE/RPC and PNIO-CM: the first byte picks packet type, opnum and byte order; the rest is a
/// PNIO-CM body and a DCE/RPC PDU. Never panics; reassembly stays within its limits.
pub fn pnio(data: &[u8]) {
    let Some((&selector, rest)) = data.split_first() else {
        return;
    };
    let ptype = if selector & 1 == 0 {
        PacketType::REQUEST
    } else {
        PacketType::RESPONSE
    };
    let order = if selector & 2 == 0 {
        Endian::Big
    } else {
        Endian::Little
    };
    if let Ok(m) = pnio::decode_body(ptype, u16::from(selector >> 2), order, rest) {
        assert!(m.ndr.args_length as usize <= rest.len());
        let _ = m.unknown_blocks().count();
    }
    let limits = ReassemblyLimits {
        max_message: 512,
        max_fragments: 8,
        max_pending: 2,
    };
    let mut r = Reassembler::new(limits);
    for piece in rest.chunks(usize::from(selector).max(81)) {
        if let Ok(p) = dcerpc::parse(piece) {
            assert_eq!(p.body.len(), usize::from(p.header.body_len));
            if let Ok(Some(m)) = r.push(&p) {
                assert!(m.body.len() <= 512);
                let _ = pnio::decode(&m);
            }
        }
        assert!(r.pending() <= 2);
    }
}

/// Serial recordings: never panics, always ends; raw chunks add up to the (uncompressed)
/// input.
pub fn serial(data: &[u8]) {
    if let Ok(reader) = SerialReader::open(data) {
        let raw = matches!(reader, SerialReader::Raw(_)) && detect(data).format != Format::Gzip;
        let mut total = 0usize;
        for c in reader.flatten() {
            total += c.bytes.len();
        }
        if raw {
            assert_eq!(total, data.len());
        }
    }
    for _ in SocatReader::new(data) {}
    for _ in TextReader::new(data) {}
}

/// IO-Link logs: never panics, always ends; errors and events name lines in order.
pub fn iolink(data: &[u8]) {
    if let Ok(reader) = IoLinkReader::open(data) {
        assert!(matches!(
            detect(data).format,
            Format::JsonLines | Format::Csv | Format::Gzip
        ));
        let mut last = 0;
        for e in reader.flatten() {
            assert!(e.line > last);
            last = e.line;
        }
    }
    for _ in JsonLinesReader::new(data) {}
    for _ in CsvReader::new(data) {}
}
