//! Benchmark of PSx3xx process-image decoding (instruction manual 3.3): typed parse of the
//! three output formats and the input image, and the full field-by-field explanation.
//!
//! `cargo run --release -p drivespec-psx3xx --example bench_psx3xx_images [MILLIONS]` (default 4).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_psx3xx::{explain_input, explain_output, Input, Output, Rules};
use drivespec_spec::Spec;
use std::hint::black_box;
use std::time::Instant;

fn main() {
    let millions: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(4);
    let spec = Spec::builtin().expect("built-in spec");
    let rules = Rules::from_spec(&spec).expect("PSx3xx rules");
    let order = rules.wire_order();
    let mut images: Vec<(u8, Vec<u8>, Vec<u8>)> = Vec::new();
    for i in 0..256i64 {
        let format = (i % 3) as u8;
        let fields: Vec<(&str, i64)> = match format {
            0 => vec![("control", i % 4), ("stamp", 2000 + i)],
            1 => vec![("control_word", 0x14), ("target", i * 1000)],
            _ => vec![
                ("target_speed", 100 + i),
                ("control_word", 0x14),
                ("target", i * 1000),
            ],
        };
        let out = Output::from_fields(&rules, format, &fields)
            .unwrap()
            .to_bytes(&rules, order)
            .unwrap();
        let inp = Input::from_fields(
            &rules,
            &[("status", 0x11), ("rpm", i - 128), ("actual", i * 997)],
        )
        .unwrap()
        .to_bytes(&rules, order)
        .unwrap();
        images.push((format, out, inp));
    }
    let n = millions * 1_000_000;
    let started = Instant::now();
    for k in 0..n {
        let (format, o, i) = &images[k & 255];
        black_box(Output::parse(&rules, *format, order, o).unwrap());
        black_box(Input::parse(&rules, order, i).unwrap());
    }
    let typed = started.elapsed().as_secs_f64();
    let m = n / 20;
    let started = Instant::now();
    for k in 0..m {
        let (format, o, i) = &images[k & 255];
        black_box(explain_output(&rules, *format, order, None, o).unwrap());
        black_box(explain_input(&rules, order, None, i).unwrap());
    }
    let explained = started.elapsed().as_secs_f64();
    println!(
        "psx3xx images: typed parse {:.1} M images/s ({} output+input pairs in {typed:.2} s); explain {:.0} k images/s",
        2.0 * n as f64 / typed / 1e6,
        n,
        2.0 * m as f64 / explained / 1e3
    );
}
