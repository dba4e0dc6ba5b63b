//! Frame counts of `drivespec check` on the real captures in `shared/captures/` equal
//! Wireshark's: cyclic RT frames, DCP frames and PNIO-CM calls per file, counted by `tshark`
//! with display filters that select the same frames.
//!
//! Runs when both the capture folder (or `DRIVESPEC_CAPTURES`) and `tshark` are there; says
//! "skipped" otherwise. The filters:
//! - cyclic RT: `pn_rt.frame_id` in 0x0100–0x0FFF (RT_CLASS_3) or 0x8000–0xFBFF
//!   (RT_CLASS_2, RT_CLASS_1), the ranges of IEC 61158-6-10 table "FrameID";
//! - DCP: `pn_dcp`;
//! - PNIO-CM: DCE/RPC requests and responses (`dcerpc.pkt_type` 0 or 2) of the PNIO
//!   interfaces (`dea0000N-6c97-11d1-8271-00a02442df7d`), a fragmented call counted once at
//!   its last fragment (the checker counts reassembled calls). Wireshark 4.0's `pn_io` filter
//!   does not match PNIO-CM over UDP, so it cannot serve here.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_check::run::{check_path, RunOptions};
use std::path::{Path, PathBuf};
use std::process::Command;

const CYCLIC: &str = "pn_rt.frame_id >= 0x0100 && pn_rt.frame_id <= 0x0fff \
                      || pn_rt.frame_id >= 0x8000 && pn_rt.frame_id <= 0xfbff";
const DCP: &str = "pn_dcp";
const DCERPC: &str = "dcerpc.pkt_type == 0 || dcerpc.pkt_type == 2";
const PNIO_UUID_TAIL: &str = "-6c97-11d1-8271-00a02442df7d";

fn captures_dir() -> PathBuf {
    match std::env::var_os("DRIVESPEC_CAPTURES") {
        Some(d) => PathBuf::from(d),
        None => Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/captures"),
    }
}

fn tshark(file: &Path, filter: &str, fields: &[&str]) -> Vec<String> {
    let mut cmd = Command::new("tshark");
    cmd.arg("-n").arg("-r").arg(file).arg("-Y").arg(filter);
    if !fields.is_empty() {
        cmd.args(["-T", "fields", "-E", "separator=,"]);
        for f in fields {
            cmd.args(["-e", f]);
        }
    }
    let out = cmd.output().unwrap();
    assert!(out.status.success(), "tshark failed on {}", file.display());
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::to_owned)
        .collect()
}

/// PNIO-CM calls as the checker counts them: one per unfragmented PDU or last fragment.
fn tshark_cm(file: &Path) -> u64 {
    let rows = tshark(
        file,
        DCERPC,
        &[
            "dcerpc.dg_if_id",
            "dcerpc.dg_flags1_frag",
            "dcerpc.dg_flags1_last_frag",
        ],
    );
    let mut n = 0;
    for row in rows {
        let cols: Vec<&str> = row.split(',').collect();
        let [uuid, frag, last] = cols[..] else {
            continue;
        };
        let pnio = uuid.starts_with("dea0000") && uuid.ends_with(PNIO_UUID_TAIL);
        if pnio && !(frag == "1" && last == "0") {
            n += 1;
        }
    }
    n
}

#[test]
fn frame_counts_equal_tsharks() {
    let dir = captures_dir();
    if !dir.is_dir() {
        println!("skipped: no capture folder at {}", dir.display());
        return;
    }
    if Command::new("tshark").arg("-v").output().is_err() {
        println!("skipped: tshark is not installed");
        return;
    }
    let spec = drivespec_spec::Spec::builtin().unwrap();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let n = p.file_name().unwrap().to_string_lossy().to_string();
            n.ends_with(".pcap") || n.ends_with(".pcapng")
        })
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no captures in {}", dir.display());
    let mut mismatches = Vec::new();
    for file in &files {
        let name = file.file_name().unwrap().to_string_lossy().to_string();
        let report = check_path(&spec, file, &RunOptions::default(), &mut |_| {}).unwrap();
        let ours = |kind: &str| report.frames.get(kind).copied().unwrap_or(0);
        let theirs = [
            ("rt-cyclic", tshark(file, CYCLIC, &[]).len() as u64),
            ("dcp", tshark(file, DCP, &[]).len() as u64),
            ("pnio-cm", tshark_cm(file)),
        ];
        for (kind, count) in theirs {
            println!("{name}: {kind} drivespec {} tshark {count}", ours(kind));
            if ours(kind) != count {
                mismatches.push(format!(
                    "{name}: {kind}: drivespec {} tshark {count}",
                    ours(kind)
                ));
            }
        }
    }
    assert!(mismatches.is_empty(), "{}", mismatches.join("\n"));
}
