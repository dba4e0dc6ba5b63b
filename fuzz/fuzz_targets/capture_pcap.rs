//! cargo-fuzz target `capture_pcap`: see `drivespec_fuzz::capture::pcap`.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| drivespec_fuzz::capture::pcap(data));
