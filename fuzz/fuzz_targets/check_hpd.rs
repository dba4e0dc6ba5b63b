//! cargo-fuzz target `check_hpd`: see `drivespec_fuzz::check::hpd`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz::check::hpd(data));
