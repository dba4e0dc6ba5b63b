//! cargo-fuzz target `select_expectations`: see `drivespec_fuzz_targets::select::expectations`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::select::expectations(data));
