//! cargo-fuzz target `capture_serial`: see `drivespec_fuzz_targets::capture::serial`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::capture::serial(data));
