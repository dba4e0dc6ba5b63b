//! Shared test support: the HPD mutants (`mutants`) and the reference drive on a TCP port
//! (`reference_server`, behind `faulty_relay.py`). Each test file uses only part of it.
#![allow(
    dead_code,
    missing_docs,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

pub mod mutants;
pub mod reference_server;
