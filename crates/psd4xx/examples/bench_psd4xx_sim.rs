//! Benchmark of the PSD4xx reference drive on virtual time: simulated seconds per
//! wall-clock second for positioning runs, (a) with a controller sending one output image per
//! 1 ms bus cycle and reading the input image back, as `drivespec sim-run` and the
//! conformance runner do, and (b) with the drive left to itself between commands
//! (`advance` straight to the end of the run).
//!
//! `cargo run --release -p drivespec-psd4xx --example bench_psd4xx_sim [RUNS]` (default 200).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_psd4xx::model::{Drive, DriveConfig};
use drivespec_psd4xx::Output;
use drivespec_spec::Spec;
use std::hint::black_box;
use std::time::Instant;

/// Targets of one positioning cycle (PSD 426: 63 rpm, 400 increments per rotation), with
/// and against the reference loop.
const TARGETS: [i32; 4] = [4000, 1000, 6000, 0];

/// One positioning cycle, 1 ms bus cycles; returns the simulated µs.
fn cycled(drive: &mut Drive, now: &mut u64) -> u64 {
    let start = *now;
    let idle = Output::idle(drive.rules());
    for target in TARGETS {
        for control in [0x10, 0x14] {
            let out = Output {
                control,
                target,
                ..idle
            };
            drive.handle_output(*now, &out);
            while drive.poll_input().is_some() {}
            *now += 1000;
        }
        loop {
            let out = Output {
                control: 0x14,
                target,
                ..idle
            };
            drive.handle_output(*now, &out);
            while drive.poll_input().is_some() {}
            while drive.poll_event().is_some() {}
            black_box(drive.input());
            *now += 1000;
            if drive.poll_timeout().is_none() {
                break;
            }
        }
    }
    *now - start
}

/// The same cycle with one image per command and `advance` to the end of each run.
fn free(drive: &mut Drive, now: &mut u64) -> u64 {
    let start = *now;
    let idle = Output::idle(drive.rules());
    for target in TARGETS {
        for control in [0x10, 0x14] {
            let out = Output {
                control,
                target,
                ..idle
            };
            drive.handle_output(*now, &out);
            *now += 1000;
        }
        while let Some(t) = drive.poll_timeout() {
            *now = t.max(*now);
            drive.advance(*now);
            while drive.poll_event().is_some() {}
        }
        while drive.poll_input().is_some() {}
    }
    black_box(drive.input());
    *now - start
}

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(200);
    let spec = Spec::builtin().expect("built-in spec");
    for (name, f) in [
        ("1 ms bus cycles", cycled as fn(&mut Drive, &mut u64) -> u64),
        ("advance only", free),
    ] {
        let mut drive = Drive::new(&spec, DriveConfig::new("PSD426")).expect("PSD426");
        let mut now = 0u64;
        let started = Instant::now();
        let mut simulated = 0u64;
        for _ in 0..runs {
            simulated += f(&mut drive, &mut now);
        }
        let wall = started.elapsed().as_secs_f64();
        let sim_s = simulated as f64 / 1e6;
        println!(
            "PSD426 positioning runs, {name}: {sim_s:.0} simulated s in {wall:.3} wall s = \
             {:.0} simulated s per wall s ({} runs of {:.1} s)",
            sim_s / wall,
            runs * TARGETS.len(),
            sim_s / (runs * TARGETS.len()) as f64
        );
    }
}
