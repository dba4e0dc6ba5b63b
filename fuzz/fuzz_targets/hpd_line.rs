//! cargo-fuzz target `hpd_line`: see `drivespec_fuzz::hpd::line`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz::hpd::line(data));
