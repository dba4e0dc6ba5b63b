//! cargo-fuzz target `psd4xx_model`: see `drivespec_fuzz_targets::psd4xx::model`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::psd4xx::model(data));
