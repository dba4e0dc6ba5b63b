//! Test support: the mutants of the conformance tests (`crates/conform/tests/support`), which
//! the fuzzer must catch too, the checks the tests of both cyclic families share (`cyclic`),
//! and the reference drive on a TCP port (`reference_server`, behind `faulty_relay.py`). Each test file uses only part of it.
#![allow(
    dead_code,
    missing_docs,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

pub mod cyclic;
#[path = "../../../conform/tests/support/mutants.rs"]
pub mod mutants;
#[path = "../../../conform/tests/support/psd4xx_mutants.rs"]
pub mod psd4xx_mutants;
#[path = "../../../conform/tests/support/psx3xx_mutants.rs"]
pub mod psx3xx_mutants;
pub mod reference_server;
