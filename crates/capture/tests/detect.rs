//! Format detection: every format from its first bytes, through gzip too, with the evidence.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_capture::write::{PcapNgWriter, PcapWriter};
use drivespec_capture::{detect, Endian, Format, Input, LinkType};
use proptest::prelude::*;
use std::io::{Read, Write};

fn samples() -> Vec<(Vec<u8>, Format, &'static str)> {
    let pcap = |endian, nanos| {
        PcapWriter::with_format(Vec::new(), LinkType::ETHERNET, 0, endian, nanos)
            .unwrap()
            .into_inner()
            .unwrap()
    };
    let ng = |endian| {
        PcapNgWriter::with_endian(Vec::new(), endian)
            .unwrap()
            .into_inner()
            .unwrap()
    };
    vec![
        (
            pcap(Endian::Little, false),
            Format::Pcap {
                endian: Endian::Little,
                nanos: false,
                modified: false,
            },
            "pcap magic d4c3b2a1",
        ),
        (
            pcap(Endian::Big, true),
            Format::Pcap {
                endian: Endian::Big,
                nanos: true,
                modified: false,
            },
            "pcap magic a1b23c4d",
        ),
        (
            vec![0x34, 0xcd, 0xb2, 0xa1],
            Format::Pcap {
                endian: Endian::Little,
                nanos: false,
                modified: true,
            },
            "pcap magic 34cdb2a1",
        ),
        (
            ng(Endian::Little),
            Format::PcapNg {
                endian: Endian::Little,
            },
            "byte-order magic 4d3c2b1a",
        ),
        (
            ng(Endian::Big),
            Format::PcapNg {
                endian: Endian::Big,
            },
            "byte-order magic 1a2b3c4d",
        ),
        (
            b"> 2024/01/02 10:00:00.123456  length=5 from=0 to=4\n 01 02 03 04 05\n--\n".to_vec(),
            Format::Socat,
            "socat header line",
        ),
        (
            b"# serial\n\n0 > 02 41 00\n".to_vec(),
            Format::SerialText,
            "serial text line `0 > 02 41 00`",
        ),
        (
            b"\n{\"kind\":\"pd\",\"out\":\"01\"}\n".to_vec(),
            Format::JsonLines,
            "JSON object line",
        ),
        (
            b"time,port,kind,out,in\n0,1,pd,01,02\n".to_vec(),
            Format::Csv,
            "CSV header `time,port,kind,out,in`",
        ),
        (
            b"\xef\xbb\xbf{\"kind\":\"pd\",\"out\":\"01\"}\n".to_vec(),
            Format::JsonLines,
            "JSON object line",
        ),
        (vec![0x02, 0x41, 0x01, 0x40, 0x82], Format::Raw, "not text"),
        (
            b"hello\n".to_vec(),
            Format::UnknownText,
            "none of the text layouts",
        ),
        (vec![0xff, 0xfe, b'{', 0], Format::UnknownText, "UTF-16"),
        (Vec::new(), Format::Raw, "empty input"),
    ]
}

#[test]
fn every_format_is_detected_with_its_evidence() {
    for (bytes, format, evidence) in samples() {
        let d = detect(&bytes);
        assert_eq!(d.format, format, "{d}");
        assert!(d.reason.contains(evidence), "{d}");
        assert!(!d.gzip);
        assert_eq!(d.head, bytes[..bytes.len().min(16)]);
    }
}

#[test]
fn gzip_is_seen_and_looked_through() {
    for (bytes, format, evidence) in samples() {
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        gz.write_all(&bytes).unwrap();
        let compressed = gz.finish().unwrap();
        assert_eq!(detect(&compressed).format, Format::Gzip);
        let mut input = Input::open(&compressed[..]).unwrap();
        let d = input.detection().clone();
        assert!(d.gzip);
        assert_eq!(d.format, format, "{d}");
        assert!(d.reason.contains(evidence));
        assert!(d.to_string().starts_with("gzip-compressed "), "{d}");
        let mut all = Vec::new();
        input.read_to_end(&mut all).unwrap();
        assert_eq!(all, bytes, "the peeked bytes are delivered too");
        assert_eq!(input.position(), bytes.len() as u64);
    }
}

#[test]
fn a_long_first_line_is_still_text() {
    let mut text = String::from("0 > ");
    while text.len() < 5000 {
        text.push_str("02 ");
    }
    text.push('\n');
    assert_eq!(detect(text.as_bytes()).format, Format::SerialText);
    // Through `Input`, only the first 4096 bytes are looked at: no line end in sight.
    let input = Input::open(text.as_bytes()).unwrap();
    assert_eq!(input.detection().format, Format::SerialText);
}

proptest! {
    #[test]
    fn detection_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..5000)) {
        let d = detect(&bytes);
        let _ = d.to_string();
        if let Ok(mut input) = Input::open(&bytes[..]) {
            let mut all = Vec::new();
            input.read_to_end(&mut all).unwrap_or_default();
        }
    }
}
