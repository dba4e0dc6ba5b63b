//! cargo-fuzz target `psd4xx_pkw`: see `drivespec_fuzz_targets::pd::psd4xx_pkw`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::pd::psd4xx_pkw(data));
