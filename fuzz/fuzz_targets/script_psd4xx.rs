//! cargo-fuzz target `script_psd4xx`: see `drivespec_fuzz_targets::script::psd4xx`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::script::psd4xx(data));
