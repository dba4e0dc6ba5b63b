//! Cycle jitter and CPU of the PSD4xx suite over PROFINET (README "Performance"):
//! `drivespec conform psd4xx --dut profinet:IFACE/NAME` against `drivespec sim psd4xx
//! --profinet IFACE` in two network namespaces joined by a veth pair, recorded with
//! `dumpcap`. For each side it prints the gaps between its cyclic frames on the AR of the
//! case (after the last Connect; mean, p99, max against the 1 ms send clock) and the CPU its
//! process used per 1,000 cyclic frames it sent.
//!
//! Needs root (namespaces, raw sockets) and dumpcap:
//! `cargo build --release --bin drivespec && cargo run --release -p drivespec-cli --example
//! bench_profinet [-- BINARY [CASE]]` (default `target/release/drivespec` and a 10 s
//! positioning sequence).
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::indexing_slicing)]

use drivespec_capture::dcerpc::{self, PacketType, PNIO_PORT};
use drivespec_capture::ip::parse_ipv4_udp;
use drivespec_capture::link::{ethertype, parse_ethernet};
use drivespec_capture::pcap::CaptureReader;
use drivespec_capture::rt::{FrameClass, RtFrame};
use drivespec_testkit::netns::{NetnsPair, NsChild};
use std::collections::BTreeMap;
use std::time::Duration;

/// Clock ticks per second of `/proc/PID/stat` (`getconf CLK_TCK` on Linux).
const TICKS: u64 = 100;

/// User + system CPU of process `pid` in ticks, while it lives.
fn cpu_ticks(pid: u32) -> Option<u64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    // Fields 14 and 15 of proc(5), counted from the state (field 3) here.
    Some(f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?)
}

fn stats(name: &str, times: &[u64], cpu: u64) {
    let mut gaps: Vec<u64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    gaps.sort_unstable();
    let n = gaps.len().max(1);
    let mean = gaps.iter().sum::<u64>() / n as u64;
    let p99 = gaps.get(n * 99 / 100).copied().unwrap_or(0);
    let max = gaps.last().copied().unwrap_or(0);
    let per_k = cpu * 1000 * 1000 / TICKS / (times.len().max(1) as u64);
    println!(
        "{name:<10} {:>6} frames  gap mean {mean} µs  p99 {p99} µs  max {max} µs  CPU {per_k} ms per 1,000 cycles",
        times.len()
    );
}

fn main() {
    let mut args = std::env::args().skip(1);
    let bin = args
        .next()
        .unwrap_or_else(|| "target/release/drivespec".to_owned());
    let case = args
        .next()
        .unwrap_or_else(|| "psd4xx/sequence/seq-loop-case-2".to_owned());
    let bin = std::fs::canonicalize(&bin).expect("the drivespec binary");
    let bin = bin.to_str().unwrap();
    let pair = NetnsPair::create().expect("network namespaces (run as root)");
    let dir = std::env::temp_dir().join(format!("drivespec-bench-pn-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pcap = dir.join("run.pcapng");
    let mut dumpcap = pair.b.command("dumpcap");
    dumpcap
        .args(["-i", &pair.b.iface, "-a", "duration:120", "-q", "-w"])
        .arg(&pcap);
    let mut dumpcap = NsChild::spawn_piped(dumpcap);
    dumpcap.wait_err_line("Capturing on");
    let mut sim = pair.a.command(bin);
    sim.args([
        "sim",
        "psd4xx",
        "--profinet",
        &pair.a.iface,
        "--name",
        "psd-sim",
    ])
    .stderr(std::process::Stdio::null());
    let mut sim = NsChild::spawn(sim);
    sim.wait_line("profinet:");
    let sim_pid = sim.id();
    let mut conform = pair.b.command(bin);
    conform
        .args([
            "conform",
            "psd4xx",
            "--quiet",
            "--case",
            &case,
            "--report-dir",
        ])
        .arg(dir.join("reports"))
        .arg("--dut")
        .arg(format!("profinet:{}/psd-sim", pair.b.iface))
        .stdout(std::process::Stdio::null());
    let mut conform = conform.spawn().expect("run conform");
    let (mut conform_cpu, mut sim_cpu) = (0, 0);
    while conform.try_wait().expect("wait").is_none() {
        conform_cpu = cpu_ticks(conform.id()).unwrap_or(conform_cpu);
        sim_cpu = cpu_ticks(sim_pid).unwrap_or(sim_cpu);
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(500));
    drop(sim);
    let _ = dumpcap.interrupt();
    let file = std::fs::File::open(&pcap).expect("the recording");
    let mut r = CaptureReader::new(std::io::BufReader::new(file)).expect("pcapng");
    let mut by_src: BTreeMap<[u8; 6], Vec<u64>> = BTreeMap::new();
    let mut ctl_mac = None;
    while let Some(rec) = r.next_record().expect("a record") {
        let (Some(t), Ok(l)) = (rec.time, parse_ethernet(rec.data)) else {
            continue;
        };
        let Some(src) = l.src else { continue };
        let payload = l.payload;
        if l.ethertype == ethertype::IPV4 {
            let connect = parse_ipv4_udp(payload)
                .ok()
                .filter(|u| u.dst_port == PNIO_PORT)
                .and_then(|u| dcerpc::parse(u.payload).ok())
                .is_some_and(|p| p.header.ptype == PacketType::REQUEST && p.header.opnum == 0);
            if connect {
                // A new AR: the gaps count from here.
                by_src.clear();
                ctl_mac = Some(src);
            }
        } else if l.ethertype == ethertype::PROFINET
            && RtFrame::parse(payload)
                .is_ok_and(|f| matches!(f.frame_id.class(), FrameClass::Cyclic(_)))
        {
            by_src.entry(src).or_default().push(t);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    println!("case {case}, send clock 1 ms, on the AR of the case:");
    for (src, times) in &by_src {
        if Some(*src) == ctl_mac {
            stats("controller", times, conform_cpu);
        } else {
            stats("device", times, sim_cpu);
        }
    }
}
