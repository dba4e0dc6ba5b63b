//! One implementation served on stdin/stdout, as an `exec:` device under test: an HPD drive
//! on the serial line bytes (manual 4.1) in real time, as `drivespec sim hpd --stdio` serves
//! the reference; a cyclic one on `drivespec-cyclic/1`, as `drivespec sim psd4xx|psx3xx
//! --stdio` does.

use crate::catalogue::{self, Device};
use drivespec_cyclic::Server;
use drivespec_hpd::model::Output;
use drivespec_link::Micros;
use drivespec_sim::{Emitted, Options, ServedDevice, SimDevice, Stop};
use drivespec_spec::hex::to_hex;
use drivespec_spec::FamilyId;
use std::time::Duration;

/// How often an HPD implementation is given time while nothing else is due: it has no
/// timer of its own to report, so its answers and PLC scans come within this of their time.
const HPD_TICK_US: Micros = 500;

/// Why an implementation cannot be served.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// No implementation of the family has that name.
    #[error("no {family} implementation is called {name:?}")]
    Unknown {
        /// The family.
        family: FamilyId,
        /// The name asked for.
        name: String,
    },
    /// Serving failed.
    #[error(transparent)]
    Serve(#[from] drivespec_sim::ServeError),
}

/// Serves the implementation of `family` called `name` on stdin/stdout until stdin ends or
/// `time_limit` has passed.
pub fn serve_stdio(family: FamilyId, name: &str, time_limit: Duration) -> Result<(), ServeError> {
    let device = catalogue::device(family, name).ok_or_else(|| ServeError::Unknown {
        family,
        name: name.to_owned(),
    })?;
    let opts = Options {
        time_limit: Some(time_limit),
        check_bit_rate: false,
        ..Options::default()
    };
    let stop = Stop::new();
    let mut log = std::io::sink();
    match device {
        Device::Hpd(d) => {
            let served = Served {
                name: name.to_owned(),
                device: d,
                now: 0,
            };
            drivespec_sim::serve_stdio(Box::new(served), &opts, &stop, &mut log)?;
        }
        Device::Cyclic(d) => {
            let mut server = Server::new(name, family.as_str(), d);
            drivespec_sim::serve_cyclic_stdio(&mut server, &opts, &stop, &mut log)?;
        }
    }
    Ok(())
}

/// An HPD implementation behind the simulator's serving loop.
struct Served {
    name: String,
    device: Box<dyn SimDevice>,
    /// The time it was last given.
    now: Micros,
}

impl ServedDevice for Served {
    fn describe(&self) -> String {
        format!("HPD implementation {}", self.name)
    }
    fn handle_rx(&mut self, now: Micros, bytes: &[u8]) {
        self.now = self.now.max(now);
        self.device.handle_rx(now, bytes);
    }
    fn advance(&mut self, now: Micros) {
        self.now = self.now.max(now);
        self.device.advance(now);
    }
    fn poll_output(&mut self) -> Option<Emitted> {
        loop {
            match self.device.poll_output()? {
                Output::Transmit { at, bytes } => return Some(Emitted::Line { at, bytes }),
                Output::DigitalOutputs { .. } => continue,
            }
        }
    }
    fn poll_timeout(&self) -> Option<Micros> {
        Some(self.now + HPD_TICK_US)
    }
    fn bit_rate(&self) -> Option<u32> {
        None
    }
    fn corrupt(&self, _bytes: &[u8]) -> Option<Vec<u8>> {
        None
    }
    fn explain(&mut self, _now: Micros, bytes: &[u8], _from_device: bool) -> String {
        to_hex(bytes)
    }
}
