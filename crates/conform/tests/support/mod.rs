//! Shared test support: running a suite against a legal variant (`legal`). The variants and
//! mutants themselves are the crate `drivespec-implementations`.
#![allow(
    dead_code,
    missing_docs,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

pub mod legal;
