//! cargo-fuzz target `check_iolink`: see `drivespec_fuzz_targets::check::iolink`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::check::iolink(data));
