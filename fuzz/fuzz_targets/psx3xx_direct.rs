//! cargo-fuzz target `psx3xx_direct`: see `drivespec_fuzz_targets::pd::psx3xx_direct`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::pd::psx3xx_direct(data));
