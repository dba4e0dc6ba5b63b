//! cargo-fuzz target `select_pattern`: see `drivespec_fuzz_targets::select::pattern`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::select::pattern(data));
