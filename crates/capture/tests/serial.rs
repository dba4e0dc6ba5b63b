//! Serial recordings (raw, socat dumps, our text format, USER0 and RTAC captures) become
//! chunks that the HPD line decoder turns back into the messages that were recorded.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_capture::link::LinkType;
use drivespec_capture::serial::{Dir, Origin, SerialChunk, SerialError, SerialReader};
use drivespec_capture::write::{PcapNgWriter, PcapWriter};
use drivespec_hpd::{Data, FrameRules, LineDecoder, LineEvent, Message};
use drivespec_spec::Spec;
use proptest::prelude::*;
use std::fmt::Write as _;
use std::io::Write;

fn rules() -> FrameRules {
    FrameRules::from_spec(&Spec::builtin().unwrap()).unwrap()
}

/// A request and its answer, as line bytes.
fn exchange(rules: &FrameRules) -> Vec<(Dir, Vec<u8>, Message)> {
    let req = Message::ReadParam {
        addr: 1,
        lun: 2,
        par: 64,
    };
    let res = Message::Response {
        addr: 1,
        par: 64,
        data: Data::new(&[0x12, 0x34]).unwrap(),
    };
    let write = Message::WriteParam {
        addr: 3,
        par: 10,
        data: Data::new(&[0x02, 0x7e, 0x01]).unwrap(),
    };
    [(Dir::Tx, req), (Dir::Rx, res), (Dir::Tx, write)]
        .into_iter()
        .map(|(d, m)| (d, m.to_bytes(rules).unwrap(), m))
        .collect()
}

fn read(bytes: &[u8]) -> (Vec<SerialChunk>, Vec<String>) {
    let mut chunks = Vec::new();
    let mut errors = Vec::new();
    for item in SerialReader::open(bytes).unwrap() {
        match item {
            Ok(c) => chunks.push(c),
            Err(e) => errors.push(e.to_string()),
        }
    }
    (chunks, errors)
}

/// Feeds chunks to the HPD line decoder; returns the messages.
fn decode(rules: &FrameRules, chunks: &[SerialChunk]) -> Vec<Message> {
    let mut dec = LineDecoder::new(rules.clone());
    let mut out = Vec::new();
    let mut sink = |e: LineEvent| {
        if let LineEvent::Frame(f) = e {
            out.push(f.message);
        }
    };
    for c in chunks {
        dec.feed(&c.bytes, c.time, &mut sink);
    }
    dec.finish(&mut sink);
    out
}

fn socat_dump(frames: &[(Dir, Vec<u8>, Message)]) -> String {
    let mut s = String::new();
    let mut offset = [0usize; 2];
    for (i, (dir, bytes, _)) in frames.iter().enumerate() {
        let side = usize::from(*dir == Dir::Rx);
        writeln!(
            s,
            "{} 2024/01/02 10:00:00.{:06}123  length={} from={} to={}",
            dir.symbol(),
            1000 + i,
            bytes.len(),
            offset[side],
            offset[side] + bytes.len() - 1
        )
        .unwrap();
        offset[side] += bytes.len();
        for line in bytes.chunks(16) {
            let hex: String = line.iter().map(|b| format!(" {b:02x}")).collect();
            let ascii: String = line
                .iter()
                .map(|&b| if b.is_ascii_graphic() { b as char } else { '.' })
                .collect();
            writeln!(s, "{hex:<48}  {ascii}").unwrap();
        }
        writeln!(s, "--").unwrap();
    }
    s
}

#[test]
fn socat_dumps_decode_to_the_recorded_messages() {
    let rules = rules();
    let frames = exchange(&rules);
    let dump = socat_dump(&frames);
    let (chunks, errors) = read(dump.as_bytes());
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(chunks.len(), 3);
    assert_eq!(chunks[0].dir, Some(Dir::Tx));
    assert_eq!(chunks[1].dir, Some(Dir::Rx));
    assert_eq!(chunks[0].origin, Origin::Line(1));
    // 2024-01-02T10:00:00Z = 1704189600 s; the dump has 9 fraction digits.
    assert_eq!(chunks[1].time, Some(1_704_189_600_001_001));
    let messages: Vec<_> = frames.iter().map(|f| f.2).collect();
    assert_eq!(decode(&rules, &chunks), messages);
}

#[test]
fn socat_output_as_socat_prints_it() {
    // Captured from `socat -x -v` (socat 1.7.4), with the date changed.
    let dump = "\
> 2024/01/02 10:26:32.000512295  length=34 from=0 to=33
 48 65 6c 6c 6f 02 7e 01 61 62 63 64 65 66 67 68  Hello.~.abcdefgh
 69 6a 6b 6c 6d 6e 6f 70 71 72 73 74 75 76 77 78  ijklmnopqrstuvwx
 79 7a                                            yz
--
< 2024/01/02 10:26:32.000514422  length=6 from=34 to=39
 78 34 31 78 30 61                                x41x0a
--
";
    let (chunks, errors) = read(dump.as_bytes());
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(
        chunks[0].bytes,
        b"Hello\x02\x7e\x01abcdefghijklmnopqrstuvwxyz"
    );
    assert_eq!(chunks[1].bytes, b"x41x0a");
    assert_eq!(chunks[1].origin, Origin::Line(6));
}

#[test]
fn socat_errors_name_the_line_and_reading_goes_on() {
    let dump = "\
> 2024/01/02 10:00:00.000001  length=3 from=0 to=2
 02 41
--
> 2024/01/02 10:00:00.000002  length=2 from=3 to=4
 02 zz
 more junk
--
< 2024/01/02 10:00:00.000003  length=2 from=0 to=1
 02 21
--
";
    let (chunks, errors) = read(dump.as_bytes());
    assert_eq!(chunks.len(), 1);
    assert_eq!(chunks[0].bytes, vec![0x02, 0x21]);
    assert_eq!(errors.len(), 2, "{errors:?}");
    assert!(
        errors[0].contains("line 1") && errors[0].contains("length=3"),
        "{}",
        errors[0]
    );
    assert!(
        errors[1].contains("line 4") && errors[1].contains("1 byte"),
        "{}",
        errors[1]
    );
}

#[test]
fn our_text_format_decodes_to_the_recorded_messages() {
    let rules = rules();
    let frames = exchange(&rules);
    let mut text = String::from("# drivespec serial text\n# TIME DIR HEX\n\n");
    for (i, (dir, bytes, _)) in frames.iter().enumerate() {
        let hex: Vec<String> = bytes.iter().map(|b| format!("{b:02X}")).collect();
        let time = if i == 2 {
            "2024-01-02T10:00:00.005Z".to_string()
        } else {
            (i * 1500).to_string()
        };
        writeln!(text, "{time} {} {}", dir.symbol(), hex.join(" ")).unwrap();
    }
    let (chunks, errors) = read(text.as_bytes());
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(chunks[1].time, Some(1500));
    assert_eq!(chunks[2].time, Some(1_704_189_600_005_000));
    assert_eq!(chunks[0].origin, Origin::Line(4));
    let messages: Vec<_> = frames.iter().map(|f| f.2).collect();
    assert_eq!(decode(&rules, &chunks), messages);

    let bad = "0 > 02 41\n1 x 02\n2 < 0\n- - 02:21\n";
    let (chunks, errors) = read(bad.as_bytes());
    assert_eq!(chunks.len(), 2);
    assert_eq!((chunks[1].time, chunks[1].dir), (None, None));
    assert_eq!(
        errors,
        vec![
            "serial text line 2: direction must be >, < or -",
            "serial text line 3: bytes must be hex digit pairs"
        ]
    );
}

#[test]
fn raw_recordings_are_chunked() {
    let rules = rules();
    let frames = exchange(&rules);
    let mut raw = Vec::new();
    for _ in 0..400 {
        for (_, b, _) in &frames {
            raw.extend_from_slice(b);
        }
    }
    let (chunks, errors) = read(&raw);
    assert!(errors.is_empty());
    assert!(chunks.len() > 1);
    assert_eq!(chunks[1].origin, Origin::Byte(4096));
    assert!(chunks.iter().all(|c| c.time.is_none() && c.dir.is_none()));
    assert_eq!(decode(&rules, &chunks).len(), 1200);
}

#[test]
fn user0_and_rtac_captures() {
    let rules = rules();
    let frames = exchange(&rules);

    let mut w = PcapWriter::new(Vec::new(), LinkType::USER0, 0).unwrap();
    for (i, (_, b, _)) in frames.iter().enumerate() {
        w.write_packet(10 + i as u64, b).unwrap();
    }
    let (chunks, errors) = read(&w.into_inner().unwrap());
    assert!(errors.is_empty());
    assert_eq!(chunks[2].time, Some(12));
    assert_eq!(chunks[2].origin, Origin::Record(3));
    let messages: Vec<_> = frames.iter().map(|f| f.2).collect();
    assert_eq!(decode(&rules, &chunks), messages);

    // RTAC: 12-byte header (seconds, microseconds, event type, control lines, footer).
    let mut w = PcapNgWriter::new(Vec::new()).unwrap();
    w.add_interface(LinkType::RTAC_SERIAL).unwrap();
    let mut status = vec![0, 0, 0, 1, 0, 0, 0, 2, 0x00, 0x19, 0, 0];
    w.write_packet(0, 5, &status).unwrap(); // STATUS_CHANGE: skipped
    for (i, (dir, b, _)) in frames.iter().enumerate() {
        let event = if *dir == Dir::Tx { 0x01 } else { 0x02 };
        let mut rec = vec![0, 0, 0, 1, 0, 0, 0, i as u8, event, 0x19, 0, 0];
        rec.extend_from_slice(b);
        w.write_packet(0, 100 + i as u64, &rec).unwrap();
    }
    status.truncate(5);
    w.write_packet(0, 200, &status).unwrap(); // too short for the header
    let bytes = w.into_inner().unwrap();
    let (chunks, errors) = read(&bytes);
    assert_eq!(
        errors,
        vec!["record 5: RTAC serial record of 5 byte(s), shorter than its 12-byte header"]
    );
    assert_eq!(chunks.len(), 3);
    assert_eq!(chunks[1].dir, Some(Dir::Rx));
    assert_eq!(chunks[0].origin, Origin::Record(2));
    assert_eq!(decode(&rules, &chunks), messages);
    let mut reader = SerialReader::open(&bytes[..]).unwrap();
    for _ in &mut reader {}
    let SerialReader::Pcap(p) = reader else {
        panic!()
    };
    assert_eq!(p.skipped(), 1);

    // An Ethernet capture holds no serial data.
    let mut w = PcapWriter::new(Vec::new(), LinkType::ETHERNET, 0).unwrap();
    w.write_packet(1, &[0; 60]).unwrap();
    let (chunks, errors) = read(&w.into_inner().unwrap());
    assert!(chunks.is_empty());
    assert!(
        errors[0].contains("ETHERNET (1) carries no serial data"),
        "{errors:?}"
    );
}

#[test]
fn gzip_text_and_non_serial_input() {
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(b"0 > 02 41\n").unwrap();
    let (chunks, errors) = read(&gz.finish().unwrap());
    assert!(errors.is_empty());
    assert_eq!(chunks[0].bytes, vec![0x02, 0x41]);
    assert!(matches!(
        SerialReader::open(&b"{\"kind\":\"pd\"}\n"[..]),
        Err(SerialError::NotSerial(_))
    ));
}

proptest! {
    #[test]
    fn any_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
        if let Ok(reader) = SerialReader::open(&bytes[..]) {
            let mut total = 0usize;
            for c in reader.flatten() {
                total += c.bytes.len();
            }
            prop_assert!(total <= bytes.len() * 2);
        }
    }

    #[test]
    fn any_text_lines_never_panic(lines in proptest::collection::vec("[<>\\- 0-9a-fA-FT:Z./=lengthfromt#\\-]{0,60}", 0..20)) {
        let text = lines.join("\n");
        for prefix in ["", "> 2024/01/02 10:00:00.1  length=3 from=0 to=2\n"] {
            let input = format!("{prefix}{text}");
            if let Ok(reader) = SerialReader::open(input.as_bytes()) {
                for _ in reader {}
            }
        }
    }

    #[test]
    fn chunks_reproduce_the_recorded_bytes(
        chunks in proptest::collection::vec((any::<bool>(), proptest::collection::vec(any::<u8>(), 1..40)), 1..10),
    ) {
        let frames: Vec<(Dir, Vec<u8>, Message)> = chunks
            .iter()
            .map(|(tx, b)| (if *tx { Dir::Tx } else { Dir::Rx }, b.clone(), Message::Ack { addr: 0 }))
            .collect();
        let (got, errors) = read(socat_dump(&frames).as_bytes());
        prop_assert!(errors.is_empty());
        prop_assert_eq!(got.len(), frames.len());
        for (g, (d, b, _)) in got.iter().zip(&frames) {
            prop_assert_eq!(&g.bytes, b);
            prop_assert_eq!(g.dir, Some(*d));
        }
    }
}
