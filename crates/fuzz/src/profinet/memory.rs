//! A device in memory on a virtual clock as a [`PnWire`]: `fuzz psd4xx --layer profinet
//! --dut sim` and the tests. Waiting costs nothing, and the same inputs give the same frames.

use super::exec::{PnWire, PnWireError};
use drivespec_profinet::eth::Mac;
use drivespec_profinet::udp::Ipv4;
use drivespec_profinet::SansIo;
use std::time::Duration;

/// Most frames one [`PnWire::recv`] hands on (a device flooding frames cannot keep the
/// caller from its timers).
const MAX_BATCH: usize = 64;

/// A sans-IO device joined to the fuzzer by a lossless virtual wire (our doc: module
/// `memory`).
pub struct MemoryWire<S> {
    make: Box<dyn Fn() -> S>,
    device: S,
    now: Duration,
    station: (Mac, Ipv4),
    target: String,
    what: String,
}

impl<S: SansIo> MemoryWire<S> {
    /// The device `make` builds (again at each restart), named `target`, reached from
    /// `station` (the fuzzer's MAC and IP); `what` names it in reports.
    pub fn new(
        make: Box<dyn Fn() -> S>,
        station: (Mac, Ipv4),
        target: &str,
        what: &str,
    ) -> MemoryWire<S> {
        MemoryWire {
            device: make(),
            make,
            now: Duration::ZERO,
            station,
            target: target.to_owned(),
            what: what.to_owned(),
        }
    }
}

impl<S: SansIo> PnWire for MemoryWire<S> {
    fn station(&self) -> (Mac, Ipv4) {
        self.station
    }

    fn target(&self) -> &str {
        &self.target
    }

    fn describe(&self) -> String {
        self.what.clone()
    }

    fn now(&mut self) -> Duration {
        self.now
    }

    fn send(&mut self, frame: &[u8]) -> Result<(), PnWireError> {
        self.device.handle_frame(self.now, frame);
        Ok(())
    }

    fn recv(&mut self, until: Duration) -> Result<Vec<(Duration, Vec<u8>)>, PnWireError> {
        let mut out = Vec::new();
        loop {
            while out.len() < MAX_BATCH {
                let Some(f) = self.device.poll_transmit(self.now) else {
                    break;
                };
                out.push((self.now, f));
            }
            if !out.is_empty() || self.now >= until {
                return Ok(out);
            }
            let next = self.device.poll_timeout().unwrap_or(until);
            self.now = next.max(self.now + Duration::from_micros(1)).min(until);
            self.device.handle_timeout(self.now);
        }
    }

    fn can_restart(&self) -> bool {
        true
    }

    fn restart(&mut self) {
        self.device = (self.make)();
        self.now = Duration::ZERO;
    }

    fn virtual_time(&self) -> bool {
        true
    }
}
