//! pcap / pcapng reading: writer round trips, every prefix of a capture, corrupt framing,
//! gzip input, and no panic on any bytes.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_capture::pcap::{CaptureError, Options};
use drivespec_capture::write::{InterfaceSpec, PcapNgWriter, PcapWriter};
use drivespec_capture::{CaptureReader, Endian, Format, LinkType, Record};
use flate2::write::GzEncoder;
use proptest::prelude::*;
use std::io::Write;

/// Reads every record, then the error if any.
fn read_all(bytes: &[u8]) -> (Vec<Record>, Option<CaptureError>) {
    let mut reader = match CaptureReader::new(bytes) {
        Ok(r) => r,
        Err(e) => return (Vec::new(), Some(e)),
    };
    let mut records = Vec::new();
    for item in &mut reader {
        match item {
            Ok(r) => records.push(r),
            Err(e) => return (records, Some(e)),
        }
    }
    (records, None)
}

fn packets() -> Vec<(u64, Vec<u8>)> {
    vec![
        (1_704_189_600_000_001, vec![0xaa; 60]),
        (1_704_189_600_000_250, (0..=255).collect()),
        (1_704_189_601_999_999, vec![1, 2, 3]),
        (1_704_189_602_000_000, Vec::new()),
    ]
}

fn pcap(endian: Endian, nanos: bool) -> Vec<u8> {
    let mut w =
        PcapWriter::with_format(Vec::new(), LinkType::ETHERNET, 65535, endian, nanos).unwrap();
    for (t, d) in packets() {
        w.write_packet(t, &d).unwrap();
    }
    w.into_inner().unwrap()
}

fn pcapng(endian: Endian) -> Vec<u8> {
    let mut w = PcapNgWriter::with_endian(Vec::new(), endian).unwrap();
    let eth = w.add_interface(LinkType::ETHERNET).unwrap();
    let serial = w
        .add_interface_with(InterfaceSpec {
            link_type: LinkType::USER0,
            snaplen: 0,
            tsresol: 9,
            tsoffset: 1_700_000_000,
            name: Some("ttyS0".into()),
        })
        .unwrap();
    let binary = w
        .add_interface_with(InterfaceSpec {
            tsresol: 0x80 | 20,
            ..InterfaceSpec::new(LinkType::LINUX_SLL)
        })
        .unwrap();
    for (i, (t, d)) in packets().into_iter().enumerate() {
        let iface = [eth, serial, binary][i % 3];
        w.write_packet(iface, t, &d).unwrap();
        if i == 1 {
            // An Interface Statistics Block to skip (pcapng draft 4.6): if_id, ts high, low.
            w.write_block(5, &[0; 12]).unwrap();
        }
    }
    w.into_inner().unwrap()
}

#[test]
fn pcap_round_trips_in_both_byte_orders_and_resolutions() {
    for endian in [Endian::Little, Endian::Big] {
        for nanos in [false, true] {
            let bytes = pcap(endian, nanos);
            let reader = CaptureReader::new(&bytes[..]).unwrap();
            assert_eq!(
                reader.format(),
                Format::Pcap {
                    endian,
                    nanos,
                    modified: false
                }
            );
            let (records, err) = read_all(&bytes);
            assert!(err.is_none(), "{err:?}");
            assert_eq!(records.len(), 4);
            for (i, (r, (t, d))) in records.iter().zip(packets()).enumerate() {
                assert_eq!(r.number, i as u64 + 1);
                assert_eq!(r.time, Some(t));
                assert_eq!(r.data, d);
                assert_eq!(r.orig_len as usize, d.len());
                assert_eq!(r.link_type, LinkType::ETHERNET);
                assert_eq!(r.interface, 0);
            }
            assert_eq!(records[0].offset, 24);
            assert_eq!(records[1].offset, 24 + 16 + 60);
        }
    }
}

#[test]
fn pcapng_round_trips_with_several_interfaces_resolutions_and_offsets() {
    for endian in [Endian::Little, Endian::Big] {
        let bytes = pcapng(endian);
        let mut reader = CaptureReader::new(&bytes[..]).unwrap();
        assert_eq!(reader.format(), Format::PcapNg { endian });
        let mut records = Vec::new();
        while let Some(r) = reader.next_record().unwrap() {
            records.push(r.to_record());
        }
        assert_eq!(reader.skipped_blocks(), 1);
        assert_eq!(reader.interfaces().len(), 3);
        assert_eq!(reader.interfaces()[1].name.as_deref(), Some("ttyS0"));
        assert_eq!(reader.interfaces()[1].tsresol, 9);
        assert_eq!(reader.interfaces()[1].tsoffset, 1_700_000_000);
        let links = [LinkType::ETHERNET, LinkType::USER0, LinkType::LINUX_SLL];
        for (i, (r, (t, d))) in records.iter().zip(packets()).enumerate() {
            assert_eq!(r.interface as usize, i % 3);
            assert_eq!(r.link_type, links[i % 3]);
            assert_eq!(r.data, d);
            // Binary 2^-20 s units lose nothing at µs only when the time is representable;
            // allow the one-microsecond rounding of that interface.
            let got = r.time.unwrap();
            assert!(got.abs_diff(t) <= 1, "record {i}: {got} vs {t}");
            if i % 3 != 2 {
                assert_eq!(got, t);
            }
        }
    }
}

#[test]
fn simple_packet_blocks_take_the_first_interface_and_have_no_time() {
    let mut w = PcapNgWriter::new(Vec::new()).unwrap();
    w.add_interface_with(InterfaceSpec {
        snaplen: 4,
        ..InterfaceSpec::new(LinkType::ETHERNET)
    })
    .unwrap();
    w.write_simple_packet(&[9, 8, 7, 6, 5, 4]).unwrap();
    let (records, err) = read_all(&w.into_inner().unwrap());
    assert!(err.is_none());
    assert_eq!(records[0].time, None);
    assert_eq!(records[0].orig_len, 6);
    assert_eq!(
        records[0].data,
        vec![9, 8, 7, 6],
        "cut to the snapshot length"
    );
}

#[test]
fn a_new_section_redeclares_interfaces() {
    let mut w = PcapNgWriter::new(Vec::new()).unwrap();
    w.add_interface(LinkType::ETHERNET).unwrap();
    w.write_packet(0, 5, &[1]).unwrap();
    w.new_section().unwrap();
    w.add_interface(LinkType::USER0).unwrap();
    w.write_packet(0, 6, &[2]).unwrap();
    let (records, err) = read_all(&w.into_inner().unwrap());
    assert!(err.is_none());
    assert_eq!(records.len(), 2);
    assert_eq!(records[1].link_type, LinkType::USER0);
}

#[test]
fn gzip_input_is_detected_and_read() {
    let plain = pcapng(Endian::Little);
    let mut gz = GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(&plain).unwrap();
    let compressed = gz.finish().unwrap();
    let reader = CaptureReader::new(&compressed[..]).unwrap();
    assert!(reader.gzip());
    let (records, err) = read_all(&compressed);
    assert!(err.is_none());
    assert_eq!(records, read_all(&plain).0);
}

#[test]
fn a_corrupt_gzip_stream_is_a_read_error() {
    let plain = pcap(Endian::Little, false);
    let mut gz = GzEncoder::new(Vec::new(), flate2::Compression::default());
    gz.write_all(&plain).unwrap();
    let mut compressed = gz.finish().unwrap();
    let n = compressed.len();
    compressed.truncate(n - 20);
    let (_, err) = read_all(&compressed);
    assert!(
        matches!(err, Some(CaptureError::Read(ref e)) if e.gzip),
        "{err:?}"
    );
}

#[test]
fn every_gzip_member_is_read_and_bytes_after_them_are_a_read_error_at_their_place() {
    let plain = pcapng(Endian::Little);
    let (all, _) = read_all(&plain);
    // The file split in two members (RFC 1952 2.2) reads as one stream.
    let cut = plain.len() / 2;
    let mut two = Vec::new();
    for part in [&plain[..cut], &plain[cut..]] {
        let mut gz = GzEncoder::new(Vec::new(), flate2::Compression::default());
        gz.write_all(part).unwrap();
        two.extend(gz.finish().unwrap());
    }
    let (records, err) = read_all(&two);
    assert!(err.is_none(), "{err:?}");
    assert_eq!(records, all);
    // Garbage after them: every record is read, then the error names the place.
    let members = two.len() as u64;
    two.extend_from_slice(b"garbage here");
    let (records, err) = read_all(&two);
    assert_eq!(records, all);
    let Some(CaptureError::Read(e)) = err else {
        panic!("{err:?}")
    };
    assert!(e.gzip);
    assert_eq!(e.offset, plain.len() as u64, "{e}");
    let tail = e
        .source
        .get_ref()
        .and_then(|s| s.downcast_ref::<drivespec_capture::GzipTail>())
        .copied();
    assert_eq!(
        tail,
        Some(drivespec_capture::GzipTail {
            members: 2,
            offset: members
        })
    );
}

/// Offsets where a record or block starts or the file ends: cuts there leave a valid file.
fn boundaries(bytes: &[u8], first: u64) -> Vec<u64> {
    let (records, _) = read_all(bytes);
    let mut b: Vec<u64> = records.iter().map(|r| r.offset).collect();
    b.push(first);
    b.push(bytes.len() as u64);
    b
}

fn check_prefixes(bytes: &[u8], header: u64, block_starts: &[u64]) {
    let (all, err) = read_all(bytes);
    assert!(err.is_none());
    for cut in 0..bytes.len() {
        let (records, err) = read_all(&bytes[..cut]);
        let cut = cut as u64;
        // The records wholly before the cut.
        let before: Vec<_> = all
            .iter()
            .filter(|r| {
                let next = block_starts
                    .iter()
                    .copied()
                    .filter(|&s| s > r.offset)
                    .min()
                    .unwrap();
                next <= cut
            })
            .cloned()
            .collect();
        assert_eq!(records, before, "cut at {cut}");
        if cut == 0 {
            assert!(
                matches!(err, Some(CaptureError::NotACapture { .. })),
                "{err:?}"
            );
            continue;
        }
        if block_starts.contains(&cut) && cut >= header {
            assert!(err.is_none(), "cut at boundary {cut}: {err:?}");
            continue;
        }
        let start = block_starts
            .iter()
            .copied()
            .filter(|&s| s <= cut)
            .max()
            .unwrap_or(0);
        let start = if cut < header { 0 } else { start };
        match err {
            Some(CaptureError::Truncated { offset, record, .. }) => {
                assert_eq!(offset, start, "cut at {cut}");
                assert_eq!(record, records.len() as u64 + 1);
            }
            other => panic!("cut at {cut}: {other:?}"),
        }
        let text = read_all(&bytes[..cut as usize]).1.unwrap().to_string();
        assert!(text.contains(&format!("byte {start}")), "{text}");
    }
}

#[test]
fn every_prefix_of_a_pcap_gives_the_records_before_the_cut_and_a_truncation_error() {
    for endian in [Endian::Little, Endian::Big] {
        let bytes = pcap(endian, false);
        let starts = boundaries(&bytes, 24);
        check_prefixes(&bytes, 24, &starts);
    }
}

#[test]
fn every_prefix_of_a_pcapng_gives_the_records_before_the_cut_and_a_truncation_error() {
    for endian in [Endian::Little, Endian::Big] {
        let bytes = pcapng(endian);
        // Block starts: SHB (0), IDBs, EPBs, the ISB; walk the block lengths.
        let mut starts = Vec::new();
        let mut at = 0usize;
        while at < bytes.len() {
            starts.push(at as u64);
            let len = &bytes[at + 4..at + 8];
            let len = match endian {
                Endian::Little => u32::from_le_bytes(len.try_into().unwrap()),
                Endian::Big => u32::from_be_bytes(len.try_into().unwrap()),
            };
            at += len as usize;
        }
        starts.push(bytes.len() as u64);
        check_prefixes(&bytes, 28, &starts);
    }
}

fn le32(bytes: &mut [u8], at: usize, v: u32) {
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

#[test]
fn bad_block_lengths_are_named_with_their_offset() {
    let good = pcapng(Endian::Little);
    // The first EPB follows the SHB (28) and three IDBs.
    let (records, _) = read_all(&good);
    let epb = records[1].offset as usize;

    for (what, length) in [("not a multiple of 4", 61u32), ("below the minimum", 8)] {
        let mut bytes = good.clone();
        le32(&mut bytes, epb + 4, length);
        let (got, err) = read_all(&bytes);
        assert_eq!(got.len(), 1, "{what}");
        match err {
            Some(CaptureError::BadBlockLength {
                offset,
                record,
                length: l,
                ..
            }) => {
                assert_eq!((offset, record, l), (epb as u64, 2, length), "{what}");
            }
            other => panic!("{what}: {other:?}"),
        }
    }

    // Header and trailer disagree.
    let mut bytes = good.clone();
    let len = u32::from_le_bytes(bytes[epb + 4..epb + 8].try_into().unwrap()) as usize;
    le32(&mut bytes, epb + len - 4, 1000);
    let (got, err) = read_all(&bytes);
    assert_eq!(got.len(), 1);
    assert!(
        matches!(err, Some(CaptureError::BadBlockLength { offset, trailer: Some(1000), .. }) if offset == epb as u64),
        "{err:?}"
    );

    // Captured length beyond the block.
    let mut bytes = good.clone();
    le32(&mut bytes, epb + 20, 5000);
    let (_, err) = read_all(&bytes);
    assert!(
        matches!(
            err,
            Some(CaptureError::BadCapturedLength { captured: 5000, .. })
        ),
        "{err:?}"
    );

    // A length beyond the limit.
    let mut bytes = good.clone();
    le32(&mut bytes, epb + 4, 0x4000_0000);
    let (_, err) = read_all(&bytes);
    assert!(
        matches!(err, Some(CaptureError::TooLarge { .. })),
        "{err:?}"
    );

    // An unknown interface.
    let mut bytes = good;
    le32(&mut bytes, epb + 8, 9);
    let (_, err) = read_all(&bytes);
    assert!(
        matches!(
            err,
            Some(CaptureError::UnknownInterface {
                interface: 9,
                declared: 3,
                ..
            })
        ),
        "{err:?}"
    );
}

#[test]
fn an_oversized_pcap_record_is_refused_not_buffered() {
    let mut bytes = pcap(Endian::Little, false);
    le32(&mut bytes, 24 + 8, 0x7fff_ffff);
    let (records, err) = read_all(&bytes);
    assert!(records.is_empty());
    assert!(
        matches!(
            err,
            Some(CaptureError::TooLarge {
                offset: 24,
                record: 1,
                ..
            })
        ),
        "{err:?}"
    );
}

#[test]
fn records_larger_than_the_initial_buffer_are_read() {
    let big = vec![0x5a; 200_000];
    let mut w = PcapNgWriter::new(Vec::new()).unwrap();
    w.add_interface(LinkType::ETHERNET).unwrap();
    w.write_packet(0, 1, &big).unwrap();
    w.write_packet(0, 2, &[1, 2]).unwrap();
    let bytes = w.into_inner().unwrap();
    let (records, err) = read_all(&bytes);
    assert!(err.is_none(), "{err:?}");
    assert_eq!(records[0].data, big);
    // With a smaller limit the same block is refused.
    let options = Options {
        max_block: 100_000,
        ..Options::default()
    };
    let mut reader = CaptureReader::with_options(&bytes[..], options).unwrap();
    assert!(matches!(
        reader.next_record(),
        Err(CaptureError::TooLarge { .. })
    ));
    assert!(
        reader.next_record().unwrap().is_none(),
        "fused after an error"
    );
}

#[test]
fn not_a_capture_says_what_it_saw() {
    let err = CaptureReader::new(&b"hello world\n"[..]).unwrap_err();
    let text = err.to_string();
    assert!(text.contains("not a pcap"), "{text}");
    assert!(text.contains("68656c6c6f"), "{text}");
}

fn no_panic(bytes: &[u8]) {
    if let Ok(mut reader) = CaptureReader::new(bytes) {
        let mut n = 0;
        let mut last = 0;
        while let Ok(Some(r)) = reader.next_record() {
            assert!(r.offset >= last);
            last = r.offset;
            n += 1;
            assert!(n <= bytes.len());
        }
    }
}

proptest! {
    #[test]
    fn any_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..512)) {
        no_panic(&bytes);
    }

    #[test]
    fn any_bytes_after_a_magic_never_panic(
        magic in 0usize..3,
        bytes in proptest::collection::vec(any::<u8>(), 0..512),
    ) {
        let mut input = match magic {
            0 => vec![0xd4, 0xc3, 0xb2, 0xa1],
            1 => vec![0x0a, 0x0d, 0x0d, 0x0a, 28, 0, 0, 0, 0x4d, 0x3c, 0x2b, 0x1a],
            _ => vec![0x0a, 0x0d, 0x0d, 0x0a, 0, 0, 0, 28, 0x1a, 0x2b, 0x3c, 0x4d],
        };
        input.extend(bytes);
        no_panic(&input);
    }

    #[test]
    fn mutated_captures_never_panic(
        which in 0usize..3,
        flips in proptest::collection::vec((any::<usize>(), any::<u8>()), 1..8),
    ) {
        let mut bytes = match which {
            0 => pcap(Endian::Little, false),
            1 => pcapng(Endian::Little),
            _ => pcapng(Endian::Big),
        };
        let n = bytes.len();
        for (at, v) in flips {
            bytes[at % n] = v;
        }
        no_panic(&bytes);
    }

    #[test]
    fn written_records_read_back(
        records in proptest::collection::vec(
            (0u64..4_000_000_000_000_000, proptest::collection::vec(any::<u8>(), 0..100)),
            0..12,
        ),
        ng in any::<bool>(),
        big in any::<bool>(),
    ) {
        let endian = if big { Endian::Big } else { Endian::Little };
        let bytes = if ng {
            let mut w = PcapNgWriter::with_endian(Vec::new(), endian).unwrap();
            w.add_interface(LinkType::ETHERNET).unwrap();
            w.add_interface_with(InterfaceSpec { tsresol: 9, ..InterfaceSpec::new(LinkType::USER0) }).unwrap();
            for (i, (t, d)) in records.iter().enumerate() {
                w.write_packet((i % 2) as u32, *t, d).unwrap();
            }
            w.into_inner().unwrap()
        } else {
            let mut w = PcapWriter::with_format(Vec::new(), LinkType::USER0, 0, endian, false).unwrap();
            for (t, d) in &records {
                w.write_packet(*t, d).unwrap();
            }
            w.into_inner().unwrap()
        };
        let (got, err) = read_all(&bytes);
        prop_assert!(err.is_none());
        prop_assert_eq!(got.len(), records.len());
        for (r, (t, d)) in got.iter().zip(&records) {
            prop_assert_eq!(r.time, Some(*t));
            prop_assert_eq!(&r.data, d);
        }
    }
}
