//! The small generated recordings committed under `corpus/captures/`: they are what the
//! generators produce (regenerate with `DRIVESPEC_WRITE_CAPTURES=1 cargo test -p
//! drivespec-check --test corpus_captures`), and checking each file through the same path as
//! `drivespec check` gives the violations listed in `corpus/captures/expected.toml`.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_check::run::{check_path, RunOptions};
use drivespec_check::synth::{iolink, profinet, serial};
use drivespec_spec::Spec;
use flate2::read::GzDecoder;
use flate2::write::GzEncoder;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::path::{Path, PathBuf};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    #[allow(dead_code)]
    note: String,
    capture: Vec<Entry>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Entry {
    name: String,
    description: String,
    #[serde(default)]
    baud: Option<u32>,
    family: String,
    drives: usize,
    #[serde(default)]
    truncated: bool,
    violations: BTreeMap<String, u64>,
}

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../corpus/captures")
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = GzEncoder::new(Vec::new(), flate2::Compression::best());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

fn gunzip(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    GzDecoder::new(bytes).read_to_end(&mut out).unwrap();
    out
}

/// Every committed recording, generated afresh (uncompressed content).
fn generated(spec: &Spec) -> Vec<(&'static str, Vec<u8>)> {
    let hpd_clean = serial::hpd_session(spec, &[]).unwrap();
    let hpd_faults = serial::hpd_session(
        spec,
        &[
            serial::HpdFault::CorruptAnswered,
            serial::HpdFault::WrongReadBack,
            serial::HpdFault::AnsweredBroadcast,
            serial::HpdFault::SlowRequest,
            serial::HpdFault::UploadWithoutEnd,
        ],
    )
    .unwrap();
    let psd_clean = profinet::psd_capture(spec, &profinet::PsdScenario::default()).unwrap();
    let psd_faults = profinet::psd_capture(
        spec,
        &profinet::PsdScenario {
            faults: vec![
                profinet::PsdFault::WriteEchoWrong,
                profinet::PsdFault::ToggleNotEchoed,
                profinet::PsdFault::RecordReadLength,
                profinet::PsdFault::CycleCounterOff,
            ],
            ..profinet::PsdScenario::default()
        },
    )
    .unwrap();
    let psd_search = profinet::psd_capture(
        spec,
        &profinet::PsdScenario {
            connect: false,
            faults: vec![profinet::PsdFault::AbortNotSignalled],
            ..profinet::PsdScenario::default()
        },
    )
    .unwrap();
    let mut truncated = psd_faults.clone();
    truncated.truncate(truncated.len() / 2 + 7);
    let psx_clean = iolink::psx_log(spec, &[]).unwrap();
    let psx_faults = iolink::psx_log(
        spec,
        &[
            iolink::PsxFault::RangeAccepted,
            iolink::PsxFault::GuardIgnored,
            iolink::PsxFault::InvalidStamp,
            iolink::PsxFault::BadCommand,
        ],
    )
    .unwrap();
    vec![
        ("hpd-clean.txt", serial::to_text(&hpd_clean).into_bytes()),
        ("hpd-clean.socat", serial::to_socat(&hpd_clean).into_bytes()),
        ("hpd-clean.raw", serial::to_raw(&hpd_clean)),
        ("hpd-faults.txt", serial::to_text(&hpd_faults).into_bytes()),
        (
            "hpd-faults.user0.pcap",
            serial::to_pcap_user0(&hpd_faults).unwrap(),
        ),
        (
            "hpd-faults.rtac.pcap",
            serial::to_pcap_rtac(&hpd_faults).unwrap(),
        ),
        ("psd4xx-clean.pcap.gz", psd_clean),
        ("psd4xx-faults.pcap.gz", psd_faults),
        ("psd4xx-search.pcap.gz", psd_search),
        ("psd4xx-truncated.pcap.gz", truncated),
        (
            "psx3xx-clean.jsonl",
            iolink::to_jsonl(&psx_clean).into_bytes(),
        ),
        ("psx3xx-clean.csv", iolink::to_csv(&psx_clean).into_bytes()),
        (
            "psx3xx-faults.jsonl",
            iolink::to_jsonl(&psx_faults).into_bytes(),
        ),
    ]
}

#[test]
fn committed_recordings_are_what_the_generators_write() {
    let spec = Spec::builtin().unwrap();
    let write = std::env::var_os("DRIVESPEC_WRITE_CAPTURES").is_some();
    for (name, bytes) in generated(&spec) {
        let path = dir().join(name);
        if write {
            let stored = if name.ends_with(".gz") {
                gzip(&bytes)
            } else {
                bytes.clone()
            };
            std::fs::write(&path, stored).unwrap();
        }
        let committed = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let content = if name.ends_with(".gz") {
            gunzip(&committed)
        } else {
            committed
        };
        assert!(
            content == bytes,
            "{name} differs from what the generator writes"
        );
    }
}

#[test]
fn committed_recordings_give_the_expected_violations() {
    let spec = Spec::builtin().unwrap();
    let text = std::fs::read_to_string(dir().join("expected.toml")).unwrap();
    let manifest: Manifest = toml::from_str(&text).unwrap();
    let mut problems = Vec::new();
    for e in &manifest.capture {
        assert!(!e.description.is_empty());
        let mut options = RunOptions::default();
        options.hpd.baud = e.baud;
        let r = check_path(&spec, &dir().join(&e.name), &options, &mut |_| {}).unwrap();
        let found: BTreeMap<String, u64> = r
            .counts()
            .into_iter()
            .map(|(k, v)| (k.to_owned(), v))
            .collect();
        if found != e.violations
            || r.family != e.family
            || r.drives.len() != e.drives
            || r.error.is_some() != e.truncated
        {
            problems.push(format!(
                "{}: family {} drives {} error {:?} violations {found:?}",
                e.name,
                r.family,
                r.drives.len(),
                r.error
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
