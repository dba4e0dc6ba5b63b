//! cargo-fuzz target `hpd_line`: see `drivespec_fuzz_targets::hpd::line`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::hpd::line(data));
