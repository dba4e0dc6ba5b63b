//! cargo-fuzz target `check_profinet`: see `drivespec_fuzz_targets::check::profinet`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::check::profinet(data));
