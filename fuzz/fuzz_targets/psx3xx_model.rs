//! cargo-fuzz target `psx3xx_model`: see `drivespec_fuzz_targets::psx3xx::model`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::psx3xx::model(data));
