//! The logic of every fuzz target, as plain functions over bytes.
//!
//! The cargo-fuzz targets in `fuzz_targets/` call these; `tests/replay.rs` runs them on every
//! file under `corpus/<target>/` so plain `cargo test` on stable replays the corpora and the
//! crashes kept as regression files. Each function panics only when an invariant breaks:
//! that is the finding. Every `expect` names its invariant: the built-in spec loads (checked by
//! `drivespec spec check` in CI), and what a codec or model decoded or built encodes again.
#![allow(
    clippy::panic,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing
)]

pub mod capture;
pub mod check;
pub mod hpd;
mod ops;
pub mod pd;
pub mod profinet;
pub mod psd4xx;
pub mod psx3xx;
pub mod script;
pub mod select;

/// A fuzz target: its name and the function it runs on each input.
pub type Target = (&'static str, fn(&[u8]));

/// Every fuzz target by name, with its function.
pub const TARGETS: &[Target] = &[
    ("hpd_frame", hpd::frame),
    ("hpd_line", hpd::line),
    ("hpd_plc", hpd::plc),
    ("hpd_roundtrip", hpd::roundtrip),
    ("hpd_model", hpd::model),
    ("psd4xx_image", pd::psd4xx_image),
    ("psd4xx_pkw", pd::psd4xx_pkw),
    ("psd4xx_record", pd::psd4xx_record),
    ("psx3xx_image", pd::psx3xx_image),
    ("psx3xx_isdu", pd::psx3xx_isdu),
    ("psx3xx_direct", pd::psx3xx_direct),
    ("capture_pcap", capture::pcap),
    ("capture_frame", capture::frame),
    ("capture_pnio", capture::pnio),
    ("capture_serial", capture::serial),
    ("capture_iolink", capture::iolink),
    ("psd4xx_model", psd4xx::model),
    ("psx3xx_model", psx3xx::model),
    ("check_hpd", check::hpd),
    ("check_profinet", check::profinet),
    ("check_iolink", check::iolink),
    ("check_psd4xx", check::psd4xx),
    ("script_psd4xx", script::psd4xx),
    ("script_psx3xx", script::psx3xx),
    ("select_pattern", select::pattern),
    ("select_expectations", select::expectations),
    ("profinet_device", profinet::device),
];
