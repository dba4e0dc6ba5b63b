//! cargo-fuzz target `capture_iolink`: see `drivespec_fuzz_targets::capture::iolink`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::capture::iolink(data));
