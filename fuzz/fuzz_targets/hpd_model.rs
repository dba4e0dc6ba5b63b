//! cargo-fuzz target `hpd_model`: see `drivespec_fuzz_targets::hpd::model`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::hpd::model(data));
