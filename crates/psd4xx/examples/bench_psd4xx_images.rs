//! Benchmark of PSD4xx process-image decoding (bus description 3.5, 3.8): typed parse of
//! output and input images, and the full field-by-field explanation.
//!
//! `cargo run --release -p drivespec-psd4xx --example bench_psd4xx_images [MILLIONS]` (default 4).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_psd4xx::{explain, Direction, ImageBuilder, Input, Output, Rules};
use drivespec_spec::Spec;
use std::hint::black_box;
use std::time::Instant;

fn main() {
    let millions: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(4);
    let spec = Spec::builtin().expect("built-in spec");
    let rules = Rules::from_spec(&spec).expect("PSD4xx rules");
    let mut images = Vec::new();
    for i in 0..256i64 {
        let mut out = ImageBuilder::new(&rules, Direction::Out);
        out.set("control", 0x14)
            .unwrap()
            .set("target", i * 1000 - 100_000)
            .unwrap()
            .pkw(&format!("read:{}", 37 + i % 8))
            .unwrap();
        let mut inp = ImageBuilder::new(&rules, Direction::In);
        inp.set("status", 0x0051 | (i & 0x4))
            .unwrap()
            .set("speed", i - 128)
            .unwrap()
            .set("actual", i * 997)
            .unwrap();
        images.push((out.into_bytes(), inp.into_bytes()));
    }
    let n = millions * 1_000_000;
    let started = Instant::now();
    let mut sum = 0i64;
    for k in 0..n {
        let (o, i) = &images[k & 255];
        let out = Output::parse(&rules, o).unwrap();
        let inp = Input::parse(&rules, i).unwrap();
        sum = sum
            .wrapping_add(i64::from(out.target))
            .wrapping_add(i64::from(inp.actual));
    }
    let typed = started.elapsed().as_secs_f64();
    black_box(sum);
    let m = n / 20;
    let started = Instant::now();
    for k in 0..m {
        let (o, i) = &images[k & 255];
        black_box(explain(&rules, Direction::Out, o).unwrap());
        black_box(explain(&rules, Direction::In, i).unwrap());
    }
    let explained = started.elapsed().as_secs_f64();
    println!(
        "psd4xx images: typed parse {:.1} M images/s ({} output+input pairs in {typed:.2} s); explain {:.0} k images/s",
        2.0 * n as f64 / typed / 1e6,
        n,
        2.0 * m as f64 / explained / 1e3
    );
}
