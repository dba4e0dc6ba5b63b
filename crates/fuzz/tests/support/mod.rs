//! Test support: the checks the tests of both cyclic families share (`cyclic`) and the
//! reference drive on a TCP port (`reference_server`, behind `faulty_relay.py`). The mutants
//! the fuzzer must catch are the crate `drivespec-implementations`. Each test file uses only
//! part of it.
#![allow(
    dead_code,
    missing_docs,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

pub mod cyclic;
pub mod reference_server;
