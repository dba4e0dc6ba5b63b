//! cargo-fuzz target `capture_iolink`: see `drivespec_fuzz::capture::iolink`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz::capture::iolink(data));
