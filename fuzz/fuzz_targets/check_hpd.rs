//! cargo-fuzz target `check_hpd`: see `drivespec_fuzz_targets::check::hpd`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::check::hpd(data));
