//! cargo-fuzz target `capture_frame`: see `drivespec_fuzz_targets::capture::frame`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::capture::frame(data));
