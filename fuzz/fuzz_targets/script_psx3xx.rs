//! cargo-fuzz target `script_psx3xx`: see `drivespec_fuzz_targets::script::psx3xx`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::script::psx3xx(data));
