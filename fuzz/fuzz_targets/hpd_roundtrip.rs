//! cargo-fuzz target `hpd_roundtrip`: see `drivespec_fuzz::hpd::roundtrip`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz::hpd::roundtrip(data));
