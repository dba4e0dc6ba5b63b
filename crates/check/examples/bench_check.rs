//! Throughput and peak memory of `drivespec check` on synthetic PROFINET captures written by
//! the capture crate's writer (four PSD4xx at 1 ms, found by the search), next to tshark on
//! the same file when it is installed.
//!
//! `cargo run --release -p drivespec-check --example bench_check [MB…]` (default: 100 1024).
//! Files are generated into the temp folder and deleted afterwards. Peak memory is the
//! process's VmHWM (Linux), read after each size: when it does not grow with the file, memory
//! is independent of the file size. `DRIVESPEC_BENCH_KEEP=1` keeps the files.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_check::run::{check_path, RunOptions};
use drivespec_check::synth::profinet::bulk_capture;
use std::io::BufWriter;
use std::process::Command;
use std::time::Instant;

fn vm_hwm_kb() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn main() {
    let spec = drivespec_spec::Spec::builtin().expect("spec");
    let sizes: Vec<u64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let sizes = if sizes.is_empty() {
        vec![100, 1024]
    } else {
        sizes
    };
    for mb in sizes {
        let path =
            std::env::temp_dir().join(format!("drivespec-bench-{}-{mb}.pcap", std::process::id()));
        let t = Instant::now();
        let file = std::fs::File::create(&path).expect("temp file");
        let frames =
            bulk_capture(BufWriter::with_capacity(1 << 20, file), mb << 20, 4).expect("write");
        let bytes = std::fs::metadata(&path).map(|m| m.len()).unwrap_or(0);
        println!(
            "generated {:.1} MB, {frames} frames in {:.1} s",
            bytes as f64 / 1e6,
            t.elapsed().as_secs_f64()
        );
        let t = Instant::now();
        let r = check_path(&spec, &path, &RunOptions::default(), &mut |_| {}).expect("check");
        let secs = t.elapsed().as_secs_f64();
        let records = r.frames.get("records").copied().unwrap_or(0);
        println!(
            "drivespec check: {records} frames in {secs:.2} s = {:.2} M frames/s, {:.0} MB/s; {} drive(s) found, {} violation(s); peak memory (VmHWM) {} kB",
            records as f64 / secs / 1e6,
            bytes as f64 / secs / 1e6,
            r.drives.len(),
            r.violation_count,
            vm_hwm_kb().map_or("?".into(), |k| k.to_string())
        );
        let has_tshark = Command::new("tshark")
            .arg("--version")
            .output()
            .is_ok_and(|o| o.status.success());
        if has_tshark {
            let t = Instant::now();
            let out = Command::new("sh")
                .arg("-c")
                .arg(format!(
                    "tshark -r {} -Y pn_io -T fields -e frame.number | wc -l",
                    path.display()
                ))
                .output()
                .expect("tshark");
            let secs_t = t.elapsed().as_secs_f64();
            let n: u64 = String::from_utf8_lossy(&out.stdout)
                .trim()
                .parse()
                .unwrap_or(0);
            println!(
                "tshark -Y pn_io: {n} frames in {secs_t:.2} s = {:.3} M frames/s, {:.1} MB/s; drivespec is {:.1}x faster",
                n as f64 / secs_t / 1e6,
                bytes as f64 / secs_t / 1e6,
                secs_t / secs
            );
        } else {
            println!("tshark not installed: no comparison");
        }
        if std::env::var_os("DRIVESPEC_BENCH_KEEP").is_some() {
            println!("kept {}", path.display());
        } else {
            let _ = std::fs::remove_file(&path);
        }
    }
}
