//! Benchmark of the PSx3xx reference drive on virtual time: simulated seconds per
//! wall-clock second for positioning runs, (a) with a master sending one process output
//! image per bus cycle and reading the input image back, as `drivespec sim-run psx3xx` (1 ms)
//! and an IO-Link master at the device's MinCycleTime (8 ms, ISDU 0 sub 3) do, and (b) with
//! the drive left to itself between commands (`advance` straight to the end of the run).
//!
//! `cargo run --release -p drivespec-psx3xx --example bench_psx3xx_sim [RUNS]` (default 200).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_psx3xx::model::{Drive, DriveConfig};
use drivespec_psx3xx::Output;
use drivespec_spec::Spec;
use std::hint::black_box;
use std::time::Instant;

/// The gearbox model of the runs (manual 3.2).
const MODEL: &str = "PSE312-8";

/// Targets of one positioning cycle in format 1 (400 steps per revolution, delivery
/// position 51200, limits 1200 … 101200), with and against the reference loop.
const TARGETS: [i32; 4] = [55000, 52000, 58000, 51200];

fn image(control_word: u16, target: i32) -> Output {
    Output::ControlTarget {
        control_word,
        target,
    }
}

/// One positioning cycle with an output image every `cycle_us`; returns the simulated µs.
fn cycled(drive: &mut Drive, now: &mut u64, cycle_us: u64) -> u64 {
    let start = *now;
    for target in TARGETS {
        for control in [0x10, 0x14] {
            drive.handle_output(*now, &image(control, target)).unwrap();
            while drive.poll_input().is_some() {}
            *now += cycle_us;
        }
        loop {
            drive.handle_output(*now, &image(0x14, target)).unwrap();
            while drive.poll_input().is_some() {}
            while drive.poll_event().is_some() {}
            black_box(drive.input());
            *now += cycle_us;
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
    for target in TARGETS {
        for control in [0x10, 0x14] {
            drive.handle_output(*now, &image(control, target)).unwrap();
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

/// Time this thread has spent on a CPU, from Linux's schedstat (first field, ns); None
/// elsewhere. The machine is shared, so the figure per CPU second is the stable one.
fn cpu_seconds() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    let ns: f64 = text.split_whitespace().next()?.parse().ok()?;
    Some(ns / 1e9)
}

fn main() {
    let runs: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(200);
    let spec = Spec::builtin().expect("built-in spec");
    let modes: [(&str, Option<u64>); 3] = [
        ("1 ms bus cycles", Some(1000)),
        ("8 ms bus cycles", Some(8000)),
        ("advance only", None),
    ];
    for (name, cycle) in modes {
        let mut drive = Drive::new(&spec, DriveConfig::new(MODEL)).expect(MODEL);
        let mut now = 0u64;
        let started = Instant::now();
        let cpu_started = cpu_seconds();
        let mut simulated = 0u64;
        for _ in 0..runs {
            simulated += match cycle {
                Some(us) => cycled(&mut drive, &mut now, us),
                None => free(&mut drive, &mut now),
            };
        }
        let wall = started.elapsed().as_secs_f64();
        let cpu = cpu_seconds()
            .zip(cpu_started)
            .map(|(end, start)| end - start);
        let sim_s = simulated as f64 / 1e6;
        let per_cpu = cpu.map_or_else(String::new, |c| {
            format!(", {:.0} per CPU s ({c:.3} CPU s)", sim_s / c)
        });
        println!(
            "{MODEL} positioning runs, {name}: {sim_s:.0} simulated s in {wall:.3} wall s = \
             {:.0} simulated s per wall s{per_cpu} ({} runs of {:.1} s)",
            sim_s / wall,
            runs * TARGETS.len(),
            sim_s / (runs * TARGETS.len()) as f64
        );
    }
}
