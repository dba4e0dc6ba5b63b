//! cargo-fuzz target `hpd_roundtrip`: see `drivespec_fuzz_targets::hpd::roundtrip`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::hpd::roundtrip(data));
