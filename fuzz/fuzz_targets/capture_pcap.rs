//! cargo-fuzz target `capture_pcap`: see `drivespec_fuzz_targets::capture::pcap`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz_targets::capture::pcap(data));
