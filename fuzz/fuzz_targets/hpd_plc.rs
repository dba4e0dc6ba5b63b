//! cargo-fuzz target `hpd_plc`: see `drivespec_fuzz_targets::hpd::plc`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::hpd::plc(data));
