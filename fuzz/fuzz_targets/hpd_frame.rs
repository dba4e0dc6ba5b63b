//! cargo-fuzz target `hpd_frame`: see `drivespec_fuzz_targets::hpd::frame`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::hpd::frame(data));
