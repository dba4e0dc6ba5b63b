//! cargo-fuzz target `check_profinet`: see `drivespec_fuzz::check::profinet`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz::check::profinet(data));
