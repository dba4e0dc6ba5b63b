//! Benchmarks of the conformance run, printed as rows for the README's
//! performance table:
//!
//! 1. the full HPD suite against the built-in model (`--dut sim`, virtual time): wall time,
//!    cases/s and simulated time per wall second, reports written;
//! 2. the full PSx3xx suite against the built-in model on virtual time, on the default model
//!    (reports written) and on every model of the spec;
//! 3. the full HPD suite against the served model on a pseudo-terminal (`drivespec sim hpd
//!    --pty` in-process, `--dut serial:`): real time;
//! 4. the serial transport: the runner's own time per exchange over a pty next to the line
//!    time the same bytes need at each Pr26 bit rate (bytes × 11 bits / baud) plus the drive's
//!    answer delay. The runner's time is each answered exchange's step time from the report
//!    minus a raw round trip (the same request written and the answer read straight on the
//!    port: the pty and the served model);
//! 5. the same exchanges over TCP on loopback.
//!
//! Run: `cargo run --release -p drivespec-conform --example bench_conform [-- REPEATS]`.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

use drivespec_conform::dut::Dut;
use drivespec_conform::report::Status;
use drivespec_conform::{run, Progress, Summary};
use drivespec_sim::{DeviceOptions, Options, Stop};
use drivespec_spec::{FamilyId, Spec};
use std::io::{Read, Write};
use std::sync::Arc;
use std::time::{Duration, Instant};

fn conform(spec: &Spec, dut: Dut, cases: &[&str], reports: Option<&std::path::Path>) -> Summary {
    conform_family(spec, FamilyId::Hpd, None, dut, cases, reports)
}

fn conform_family(
    spec: &Spec,
    family: FamilyId,
    model: Option<&str>,
    dut: Dut,
    cases: &[&str],
    reports: Option<&std::path::Path>,
) -> Summary {
    let opts = drivespec_conform::Options {
        families: vec![family],
        settings: drivespec_conform::suite::Settings {
            model: model.map(str::to_owned),
            ..drivespec_conform::suite::Settings::default()
        },
        dut,
        case: cases.iter().map(|s| (*s).to_owned()).collect(),
        progress: Progress::Quiet,
        no_reports: reports.is_none(),
        report_dir: reports.map(|p| p.to_path_buf()).unwrap_or_default(),
        ..drivespec_conform::Options::default()
    };
    run(spec, &opts, &mut std::io::sink()).unwrap()
}

fn count(s: &Summary) -> String {
    let c = s.report.summary;
    format!(
        "{} passed, {} failed, {} skipped",
        c.passed, c.failed, c.skipped
    )
}

fn median(v: &mut [f64]) -> f64 {
    v.sort_by(|a, b| a.total_cmp(b));
    v.get(v.len() / 2).copied().unwrap_or(0.0)
}

fn hex_len(h: &str) -> usize {
    h.split_whitespace().count()
}

/// Answered exchanges of the parameter cases on `dut`: how many, median step time (µs) and
/// median bytes (request + answer).
fn exchanges(spec: &Spec, dut: &Dut, runs: usize) -> (usize, f64, f64) {
    let mut steps = Vec::new();
    let mut sizes = Vec::new();
    for _ in 0..runs {
        let s = conform(spec, dut.clone(), &["hpd/param"], None);
        for c in &s.report.cases {
            for (a, b) in c.evidence.iter().zip(c.evidence.iter().skip(1)) {
                let (Some(sent), Some(got)) = (&a.sent, &a.got) else {
                    continue;
                };
                if got.hex.is_empty() || a.ok == Some(false) {
                    continue;
                }
                steps.push(b.at_us.saturating_sub(a.at_us) as f64);
                sizes.push((hex_len(sent) + hex_len(&got.hex)) as f64);
            }
        }
    }
    (steps.len(), median(&mut steps), median(&mut sizes))
}

fn main() {
    let repeats: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(5);
    let spec = Arc::new(Spec::builtin().unwrap());
    let dir = std::env::temp_dir().join(format!("drivespec-bench-sim-{}", std::process::id()));

    // 1. The full suite on virtual time, reports written.
    let mut walls = Vec::new();
    let mut last = None;
    for _ in 0..repeats {
        let t = Instant::now();
        let s = conform(&spec, Dut::default(), &[], Some(&dir));
        walls.push(t.elapsed().as_secs_f64());
        last = Some(s);
    }
    let s = last.unwrap();
    let wall = median(&mut walls);
    let cases = s.report.summary.total as f64;
    let simulated: u64 = s.report.cases.iter().map(|c| c.elapsed_us).sum();
    println!(
        "| `drivespec conform hpd` against `--dut sim` (virtual time), {} cases, reports written | {:.0} ms, {:.0} cases/s, {:.0} s simulated per wall second ({:.1} s simulated) | `cargo run --release -p drivespec-conform --example bench_conform` |",
        s.report.summary.total,
        wall * 1e3,
        cases / wall,
        simulated as f64 / 1e6 / wall,
        simulated as f64 / 1e6
    );
    println!("    ({}; median of {repeats})", count(&s));

    // 2. The PSx3xx suite on virtual time: the default model with reports, then every model.
    let mut walls = Vec::new();
    let mut last = None;
    for _ in 0..repeats {
        let t = Instant::now();
        let s = conform_family(
            &spec,
            FamilyId::Psx3xx,
            None,
            Dut::default(),
            &[],
            Some(&dir),
        );
        walls.push(t.elapsed().as_secs_f64());
        last = Some(s);
    }
    let s = last.unwrap();
    let wall = median(&mut walls);
    let simulated: u64 = s.report.cases.iter().map(|c| c.elapsed_us).sum();
    println!(
        "| `drivespec conform psx3xx` against `--dut sim` (virtual time, {}), {} cases, reports written | {:.0} ms, {:.0} cases/s, {:.0} s simulated per wall second ({:.1} s simulated) | `cargo run --release -p drivespec-conform --example bench_conform` |",
        s.report
            .run
            .model
            .clone()
            .unwrap_or_else(|| drivespec_conform::psx3xx::DEFAULT_MODEL.to_owned()),
        s.report.summary.total,
        wall * 1e3,
        s.report.summary.total as f64 / wall,
        simulated as f64 / 1e6 / wall,
        simulated as f64 / 1e6
    );
    println!("    ({}; median of {repeats})", count(&s));
    let models: Vec<String> = spec
        .family(FamilyId::Psx3xx)
        .models
        .iter()
        .map(|m| m.id.clone())
        .collect();
    let t = Instant::now();
    let (mut total, mut failed) = (0, 0);
    for m in &models {
        let s = conform_family(&spec, FamilyId::Psx3xx, Some(m), Dut::default(), &[], None);
        total += s.report.summary.total;
        failed += s.report.summary.failed;
    }
    let wall = t.elapsed().as_secs_f64();
    println!(
        "| `drivespec conform psx3xx --model M` for each of the {} models, no reports | {:.1} s, {:.0} cases/s ({total} cases, {failed} failed) | same |",
        models.len(),
        wall,
        total as f64 / wall
    );

    // 3. The full HPD suite against the served model on a pty, real time.
    let dev =
        drivespec_sim::device(spec.clone(), FamilyId::Hpd, &DeviceOptions::default()).unwrap();
    let pty = drivespec_sim::Pty::open(dev.bit_rate()).unwrap();
    let path = pty.path().to_owned();
    let stop = Stop::new();
    let server = {
        let stop = stop.clone();
        std::thread::spawn(move || {
            let opts = Options {
                time_limit: Some(Duration::from_secs(600)),
                ..Options::default()
            };
            drivespec_sim::serve_pty(&pty, dev, &opts, &stop, &mut std::io::sink())
        })
    };
    let dut = Dut::Serial {
        path: path.clone(),
        baud: None,
    };
    let t = Instant::now();
    let full = conform(&spec, dut.clone(), &[], None);
    let wall = t.elapsed().as_secs_f64();
    let failed: Vec<&str> = full
        .report
        .cases
        .iter()
        .filter(|c| c.status == Status::Fail)
        .map(|c| c.id.as_str())
        .collect();
    println!(
        "| `drivespec conform hpd --dut serial:PTY` against `drivespec sim hpd --pty`, {} cases, real time | {:.1} s, {:.0} cases/s | same |",
        full.report.summary.total,
        wall,
        full.report.summary.total as f64 / wall
    );
    println!("    ({}; failed: {failed:?})", count(&full));

    // 4a. Raw round trips on the same pty: read Pr33 (5 bytes) and its answer (7 bytes).
    let mut port = serialport::new(&path, 57_600)
        .parity(serialport::Parity::Even)
        .timeout(Duration::from_millis(100))
        .open()
        .unwrap();
    let read = [0x7E, 0x80, 0x02, 0xC6, 0x48];
    let mut raw = Vec::new();
    let mut buf = [0u8; 64];
    for _ in 0..2000 {
        let t = Instant::now();
        port.write_all(&read).unwrap();
        port.flush().unwrap();
        let mut got = 0;
        while got < 7 {
            got += port.read(&mut buf).unwrap_or(0);
        }
        raw.push(t.elapsed().as_secs_f64() * 1e6);
    }
    drop(port);
    let raw_us = median(&mut raw);

    // 4b. The runner's answered exchanges: every parameter case (reads, writes, edges).
    let (n, step_us, bytes) = exchanges(&spec, &dut, repeats.min(3));
    let own = (step_us - raw_us).max(0.0);
    stop.stop();
    let stats = server.join().unwrap().unwrap();
    let all = step_us;
    println!(
        "| serial transport over a pty: one answered exchange (median of {n}, {bytes:.0} bytes) | {step_us:.0} µs, of which {raw_us:.0} µs pty + served model (raw round trip), {own:.0} µs the runner's own | same |"
    );
    let protocol = spec.family(FamilyId::Hpd).hpd().unwrap();
    let bits = f64::from(protocol.character.bits_per_char);
    let mut worst: f64 = 0.0;
    for b in &protocol.baud_rates {
        let line = bytes * bits * 1e6 / f64::from(b.bps);
        let delay = f64::from(b.answer_delay_ms.unwrap_or(0)) * 1000.0;
        let share = own / (line + delay) * 100.0;
        let with_sim = all / (line + delay) * 100.0;
        worst = worst.max(share);
        println!(
            "| runner overhead vs line time, Pr26 = {} ({} b/s{}) | line {:.2} ms{} for {bytes:.0} bytes; runner {own:.0} µs = {share:.1} % ({with_sim:.1} % with pty and model) | same |",
            b.code,
            b.bps,
            if b.answer_delay_ms.is_some() { ", delayed" } else { "" },
            line / 1e3,
            if delay > 0.0 {
                format!(" + {:.0} ms answer delay", delay / 1e3)
            } else {
                String::new()
            },
        );
    }
    println!(
        "    runner adds at most {worst:.1} % to line time + answer delay ({}); served: {} messages",
        if worst <= 10.0 { "≤ 10 %: met" } else { "> 10 %: NOT met" },
        stats.sent
    );

    // 5. The same exchanges over TCP on loopback (`drivespec sim hpd --listen`).
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let dev =
        drivespec_sim::device(spec.clone(), FamilyId::Hpd, &DeviceOptions::default()).unwrap();
    let stop = Stop::new();
    let server = {
        let stop = stop.clone();
        std::thread::spawn(move || {
            let opts = Options {
                time_limit: Some(Duration::from_secs(600)),
                ..Options::default()
            };
            drivespec_sim::serve_tcp(listener, dev, &opts, &stop, &mut std::io::sink())
        })
    };
    let tcp = Dut::Tcp {
        addr: addr.to_string(),
    };
    let (n, step_us, bytes) = exchanges(&spec, &tcp, repeats.min(3));
    stop.stop();
    server.join().unwrap().unwrap();
    println!(
        "| tcp transport on loopback against `drivespec sim hpd --listen`: one answered exchange (median of {n}, {bytes:.0} bytes) | {step_us:.0} µs, runner and served model | same |"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
