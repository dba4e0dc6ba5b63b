//! cargo-fuzz target `psx3xx_isdu`: see `drivespec_fuzz_targets::pd::psx3xx_isdu`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::pd::psx3xx_isdu(data));
