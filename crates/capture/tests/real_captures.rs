//! Real PROFINET captures from `shared/captures/` (when that folder exists): every file reads
//! without error, and the frame counts per file match `real_captures.toml`.
//!
//! Set `DRIVESPEC_CAPTURES` to read another folder; set `DRIVESPEC_PRINT_COUNTS=1` to print
//! the counts as TOML (to update the expectations after checking them).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_capture::profinet::{Counts, Decoder, Events, PnEventKind};
use drivespec_capture::CaptureReader;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Expectations {
    #[allow(dead_code)]
    note: String,
    file: Vec<Expected>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Expected {
    name: String,
    records: u64,
    rt_cyclic: u64,
    dcp: u64,
    pnio_cm: u64,
    pnio_cm_port: u64,
    cm_messages: u64,
    errors: u64,
    #[allow(dead_code)]
    tshark_pn_rt: Option<u64>,
    #[allow(dead_code)]
    tshark_pn_dcp: Option<u64>,
    #[allow(dead_code)]
    tshark_pn_io: Option<u64>,
    #[allow(dead_code)]
    tshark_dcerpc: Option<u64>,
    #[allow(dead_code)]
    tshark_pnio_cm: Option<u64>,
    #[allow(dead_code)]
    note: Option<String>,
}

fn captures_dir() -> PathBuf {
    match std::env::var_os("DRIVESPEC_CAPTURES") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/captures"),
    }
}

fn count(path: &Path) -> Counts {
    let file = std::fs::File::open(path).unwrap();
    let mut reader = CaptureReader::new(std::io::BufReader::new(file))
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut decoder = Decoder::default();
    let mut counts = Counts::default();
    loop {
        match reader.next_record() {
            Ok(Some(r)) => counts.add(&decoder.decode(r.link_type, r.data)),
            Ok(None) => break,
            Err(e) => panic!("{}: {e}", path.display()),
        }
    }
    counts
}

#[test]
fn real_captures_read_and_match_the_expected_counts() {
    let dir = captures_dir();
    if !dir.is_dir() {
        println!("skipped: no capture folder at {}", dir.display());
        return;
    }
    let mut found: BTreeMap<String, Counts> = BTreeMap::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.ends_with(".pcap") || name.ends_with(".pcapng") {
            found.insert(name, count(&path));
        }
    }
    if std::env::var_os("DRIVESPEC_PRINT_COUNTS").is_some() {
        for (name, c) in &found {
            println!(
                "[[file]]\nname = \"{name}\"\nrecords = {}\nrt_cyclic = {}\ndcp = {}\npnio_cm = {}\npnio_cm_port = {}\ncm_messages = {}\nerrors = {}\n# alarm {} ptcp {} rt_other {} other {}\n",
                c.records, c.rt_cyclic, c.dcp, c.pnio_cm, c.pnio_cm_port, c.cm_messages, c.errors, c.alarm, c.ptcp, c.rt_other, c.other
            );
        }
    }
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/real_captures.toml"),
    )
    .unwrap();
    let expected: Expectations = toml::from_str(&text).unwrap();
    let mut mismatches = Vec::new();
    for e in &expected.file {
        let Some(c) = found.get(&e.name) else {
            println!("skipped: {} is not in {}", e.name, dir.display());
            continue;
        };
        let got = (
            c.records,
            c.rt_cyclic,
            c.dcp,
            c.pnio_cm,
            c.pnio_cm_port,
            c.cm_messages,
            c.errors,
        );
        let want = (
            e.records,
            e.rt_cyclic,
            e.dcp,
            e.pnio_cm,
            e.pnio_cm_port,
            e.cm_messages,
            e.errors,
        );
        if got != want {
            mismatches.push(format!(
                "{}: (records, rt_cyclic, dcp, pnio_cm, pnio_cm_port, cm_messages, errors) = {got:?}, expected {want:?}",
                e.name
            ));
        }
    }
    for name in found.keys() {
        if !expected.file.iter().any(|e| &e.name == name) {
            mismatches.push(format!("{name}: no expectations recorded"));
        }
    }
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
}

#[test]
fn real_captures_give_events_without_malformed_frames_also_gzip_compressed() {
    let dir = captures_dir();
    if !dir.is_dir() {
        println!("skipped: no capture folder at {}", dir.display());
        return;
    }
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if !(name.ends_with(".pcap") || name.ends_with(".pcapng")) {
            continue;
        }
        let bytes = std::fs::read(&path).unwrap();
        let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
        std::io::Write::write_all(&mut gz, &bytes).unwrap();
        let compressed = gz.finish().unwrap();
        let mut runs = Vec::new();
        for input in [&bytes, &compressed] {
            let mut events = Events::new(CaptureReader::new(&input[..]).unwrap());
            let mut n = 0;
            for e in &mut events {
                let e = e.unwrap_or_else(|e| panic!("{name}: {e}"));
                assert!(
                    !matches!(e.kind, PnEventKind::Malformed { .. }),
                    "{name}: record {} {:?}",
                    e.record,
                    e.kind
                );
                n += 1;
            }
            runs.push((n, events.counts()));
        }
        assert_eq!(runs[0], runs[1], "{name}: gzip changes nothing");
    }
}
