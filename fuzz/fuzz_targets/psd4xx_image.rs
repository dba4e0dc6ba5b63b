//! cargo-fuzz target `psd4xx_image`: see `drivespec_fuzz_targets::pd::psd4xx_image`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::pd::psd4xx_image(data));
