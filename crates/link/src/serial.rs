//! `serial:PATH?baud=N`: a real serial line, 8 data bits, even parity, 1 stop bit (HPD manual
//! 4.1; the character format comes from the spec's protocol table).

use super::{Caps, Chunk, Link, LinkError, Micros, Recovered, WallClock};
use drivespec_spec::hpd::{CharacterFormat, Parity};
use serialport::{DataBits, SerialPort, StopBits};
use std::io::{ErrorKind, Read, Write};
use std::time::Duration;

/// Waits shorter than this are polls (Linux's default timer slack for a normal thread).
pub(super) const TIMER_SLACK: Duration = Duration::from_micros(60);

/// A serial port to the device under test.
pub struct SerialLink {
    path: String,
    bps: u32,
    format: (DataBits, serialport::Parity, StopBits),
    port: Option<Box<dyn SerialPort>>,
    clock: WallClock,
}

impl SerialLink {
    /// Opens `path` at `bps` with the character format of the spec (4.1: 8E1).
    pub fn open(
        path: &str,
        bps: u32,
        character: &CharacterFormat,
    ) -> Result<SerialLink, LinkError> {
        let bad = |reason: String| LinkError::Open {
            what: format!("serial:{path}"),
            reason,
        };
        let data = match character.data_bits {
            5 => DataBits::Five,
            6 => DataBits::Six,
            7 => DataBits::Seven,
            8 => DataBits::Eight,
            n => return Err(bad(format!("{n} data bits"))),
        };
        let parity = match character.parity {
            Parity::Even => serialport::Parity::Even,
            Parity::Odd => serialport::Parity::Odd,
            Parity::None => serialport::Parity::None,
        };
        let stop = match character.stop_bits {
            1 => StopBits::One,
            2 => StopBits::Two,
            n => return Err(bad(format!("{n} stop bits"))),
        };
        let format = (data, parity, stop);
        let port = open(path, bps, format).map_err(bad)?;
        Ok(SerialLink {
            path: path.to_owned(),
            bps,
            format,
            port: Some(port),
            clock: WallClock::start(),
        })
    }

    fn port(&mut self) -> Result<&mut Box<dyn SerialPort>, LinkError> {
        self.port.as_mut().ok_or(LinkError::Closed {
            detail: String::new(),
        })
    }
}

fn open(
    path: &str,
    bps: u32,
    (data, parity, stop): (DataBits, serialport::Parity, StopBits),
) -> Result<Box<dyn SerialPort>, String> {
    serialport::new(path, bps)
        .data_bits(data)
        .parity(parity)
        .stop_bits(stop)
        .flow_control(serialport::FlowControl::None)
        .timeout(Duration::from_millis(10))
        .open()
        .map_err(|e| e.to_string())
}

impl Link for SerialLink {
    fn describe(&self) -> String {
        format!("serial:{}?baud={}", self.path, self.bps)
    }

    fn caps(&self) -> Caps {
        Caps::default()
    }

    fn now(&mut self) -> Micros {
        self.clock.now()
    }

    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        let p = self.port()?;
        p.write_all(bytes)
            .and_then(|()| p.flush())
            .map_err(|e| LinkError::io(&e))
    }

    fn recv(
        &mut self,
        deadline: Micros,
        enough: &mut dyn FnMut(&[u8]) -> bool,
    ) -> Result<Vec<Chunk>, LinkError> {
        let clock = self.clock;
        let mut chunks = Vec::new();
        let mut all = Vec::new();
        let mut buf = [0u8; 256];
        while let Some(left) = clock.until(deadline) {
            let p = self.port()?;
            // A wait shorter than the kernel's timer slack (50 µs) would sleep for the slack:
            // such a check for late bytes polls without waiting instead.
            let wait = if left < TIMER_SLACK {
                Duration::ZERO
            } else {
                left
            };
            p.set_timeout(wait)
                .map_err(|e| LinkError::Io(e.to_string()))?;
            match p.read(&mut buf) {
                Ok(0) => {}
                Ok(n) => {
                    let bytes = buf.get(..n).unwrap_or(&[]).to_vec();
                    all.extend_from_slice(&bytes);
                    chunks.push(Chunk {
                        at: clock.now(),
                        bytes,
                    });
                    if all.len() >= crate::MAX_RECV || enough(&all) {
                        break;
                    }
                }
                Err(e) if matches!(e.kind(), ErrorKind::TimedOut | ErrorKind::WouldBlock) => {}
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => {
                    self.port = None;
                    return Err(LinkError::io(&e));
                }
            }
        }
        Ok(chunks)
    }

    fn set_bit_rate(&mut self, bps: u32) -> Result<(), LinkError> {
        let p = self.port()?;
        p.flush().map_err(|e| LinkError::io(&e))?;
        p.set_baud_rate(bps)
            .map_err(|e| LinkError::Io(e.to_string()))?;
        self.bps = bps;
        Ok(())
    }

    fn recover(&mut self) -> Result<Recovered, LinkError> {
        self.port = None;
        let port = open(&self.path, self.bps, self.format).map_err(|reason| LinkError::Open {
            what: format!("serial:{}", self.path),
            reason,
        })?;
        self.port = Some(port);
        Ok(Recovered::Same)
    }
}
