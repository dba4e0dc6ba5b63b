//! Benchmark of the HPD line decoder (manual 4.1) on a large synthetic capture of mixed
//! valid, corrupt and stuffed traffic.
//!
//! `cargo run --release -p drivespec-hpd --example bench_line [MEGABYTES]` (default 128).
//! Prints MB/s and frames/s for one core; the figures go in the README's performance table.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_hpd::{Data, FrameRules, LineDecoder, LineEvent, Message};
use drivespec_spec::Spec;
use std::time::Instant;

/// A small deterministic generator (xorshift) so every run decodes the same bytes.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn byte(&mut self) -> u8 {
        self.next() as u8
    }
}

/// Requests with their answers, 1 in 16 corrupted, 1 in 8 carrying a stuffed 0x7E, plus noise.
fn capture(rules: &FrameRules, size: usize) -> Vec<u8> {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let mut out = Vec::with_capacity(size + 64);
    while out.len() < size {
        let addr = rng.byte() % 32;
        let par = rng.byte();
        let stuffed = rng.byte() % 8 == 0;
        let value = if stuffed {
            [0x7E, rng.byte()]
        } else {
            [rng.byte(), rng.byte()]
        };
        let data = Data::new(&value).unwrap();
        let pair = match rng.byte() % 3 {
            0 => [
                Message::ReadParam { addr, lun: 2, par },
                Message::Response { addr, par, data },
            ],
            1 => [
                Message::WriteParam { addr, par, data },
                Message::Ack { addr },
            ],
            _ => [
                Message::BitChange {
                    addr,
                    par,
                    mask: 0xBF,
                    value: 0x40,
                },
                Message::Ack { addr },
            ],
        };
        for m in pair {
            let start = out.len();
            out.extend(m.to_bytes(rules).unwrap());
            if rng.byte() % 16 == 0 {
                let i = start + 1 + usize::from(rng.byte()) % (out.len() - start - 1);
                out[i] ^= 0x01;
            }
        }
        if rng.byte() % 32 == 0 {
            for _ in 0..rng.byte() % 6 {
                out.push(rng.byte());
            }
        }
    }
    out
}

/// Nanoseconds this thread has run on a CPU (Linux `/proc/thread-self/schedstat`), so the
/// figure means "one core" even when other processes share the machine.
fn cpu_ns() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    text.split_whitespace().next()?.parse().ok()
}

fn main() {
    let mb: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(128);
    let spec = Spec::builtin().expect("built-in spec");
    let rules = FrameRules::from_spec(&spec).expect("HPD rules");
    let bytes = capture(&rules, mb << 20);
    let mut best = f64::MAX;
    let mut best_cpu = f64::MAX;
    let (mut frames, mut discards) = (0u64, 0u64);
    for _ in 0..3 {
        let mut dec = LineDecoder::new(rules.clone());
        (frames, discards) = (0, 0);
        let started = Instant::now();
        let cpu_started = cpu_ns();
        let mut sink = |e: LineEvent| match e {
            LineEvent::Frame(_) => frames += 1,
            LineEvent::Discarded(_) => discards += 1,
        };
        for chunk in bytes.chunks(64 << 10) {
            dec.feed(chunk, None, &mut sink);
        }
        dec.finish(&mut sink);
        best = best.min(started.elapsed().as_secs_f64());
        if let (Some(a), Some(b)) = (cpu_started, cpu_ns()) {
            best_cpu = best_cpu.min(b.saturating_sub(a) as f64 / 1e9);
        }
    }
    let mbytes = bytes.len() as f64 / 1e6;
    println!(
        "hpd line decoder: {:.0} MB, {frames} frames, {discards} discards; wall {:.3} s = {:.0} MB/s, {:.1} M frames/s; on-CPU {:.3} s = {:.0} MB/s, {:.1} M frames/s per core (best of 3)",
        mbytes,
        best,
        mbytes / best,
        frames as f64 / best / 1e6,
        best_cpu,
        mbytes / best_cpu,
        frames as f64 / best_cpu / 1e6
    );
}
