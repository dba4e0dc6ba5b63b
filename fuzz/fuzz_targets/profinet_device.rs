//! cargo-fuzz target `profinet_device`: see `drivespec_fuzz_targets::profinet::device`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::profinet::device(data));
