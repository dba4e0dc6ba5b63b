//! Shared test support: the HPD mutants (`mutants`), the PSD4xx mutants (`psd4xx_mutants`),
//! the PSx3xx mutants (`psx3xx_mutants`) (the fuzzer's tests in `crates/fuzz` use these three
//! too) and the variants. Each test file uses only part of it.
#![allow(
    dead_code,
    missing_docs,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

pub mod hpd_motion_mutants;
pub mod hpd_variants;
pub mod legal;
pub mod mutants;
pub mod psd4xx_mutants;
pub mod psd4xx_variants;
pub mod psx3xx_mutants;
pub mod psx3xx_variants;
