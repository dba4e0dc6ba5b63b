//! cargo-fuzz target `check_psd4xx`: see `drivespec_fuzz::check::psd4xx`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz::check::psd4xx(data));
