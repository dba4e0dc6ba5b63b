//! cargo-fuzz target `capture_pnio`: see `drivespec_fuzz_targets::capture::pnio`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::capture::pnio(data));
