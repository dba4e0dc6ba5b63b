//! `--pty`: a pseudo-terminal (Unix). The served device holds the master side; the slave's
//! path (`/dev/pts/N`) is what a client opens, with any serial library (the `serialport`
//! crate, pyserial, a PLC driver), so real serial code is exercised.
//!
//! The slave starts in raw mode at the drive's bit rate. The device keeps its own descriptor
//! of the slave open, so clients can open and close the path any number of times and the
//! master never sees a hang-up. The client's termios settings are visible from the master:
//! the bit rate it set is checked against the drive's (see `drivespec-sim`). A pseudo-terminal
//! moves bytes at memory speed whatever bit rate is set: there is no line time.

use crate::port::{readable, Got, Port, PortError};
use rustix::fd::OwnedFd;
use rustix::fs::{Mode, OFlags};
use rustix::io::Errno;
use rustix::pty::{grantpt, openpt, ptsname, unlockpt, OpenptFlags};
use rustix::termios::{tcgetattr, tcsetattr, OptionalActions};
use std::time::Duration;

/// A pseudo-terminal whose slave path clients open as a serial port.
#[derive(Debug)]
pub struct Pty {
    master: OwnedFd,
    /// Held open so the master never sees a hang-up between clients.
    _slave: OwnedFd,
    path: String,
}

impl Pty {
    /// Creates a pseudo-terminal, its slave in raw mode at `bit_rate` when given.
    pub fn open(bit_rate: Option<u32>) -> Result<Pty, PortError> {
        let fail = |step: &str, e: Errno| PortError::Open {
            what: "a pseudo-terminal".to_owned(),
            reason: format!("{step}: {e}"),
        };
        let master = openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY | OpenptFlags::CLOEXEC)
            .map_err(|e| fail("posix_openpt", e))?;
        grantpt(&master).map_err(|e| fail("grantpt", e))?;
        unlockpt(&master).map_err(|e| fail("unlockpt", e))?;
        let name = ptsname(&master, Vec::new()).map_err(|e| fail("ptsname", e))?;
        let slave = rustix::fs::open(
            name.as_c_str(),
            OFlags::RDWR | OFlags::NOCTTY | OFlags::CLOEXEC,
            Mode::empty(),
        )
        .map_err(|e| fail("open the slave", e))?;
        // Raw: no echo, no line editing, no CR/LF translation; 8 data bits.
        let mut t = tcgetattr(&slave).map_err(|e| fail("tcgetattr", e))?;
        t.make_raw();
        if let Some(bps) = bit_rate {
            t.set_speed(bps).map_err(|e| fail("set the bit rate", e))?;
        }
        tcsetattr(&slave, OptionalActions::Now, &t).map_err(|e| fail("tcsetattr", e))?;
        rustix::io::ioctl_fionbio(&master, true).map_err(|e| fail("non-blocking", e))?;
        let path = name
            .into_string()
            .map_err(|_| fail("the slave path", Errno::ILSEQ))?;
        Ok(Pty {
            master,
            _slave: slave,
            path,
        })
    }

    /// The slave's path (`/dev/pts/N`): what clients open.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// The bit rate the client set on the slave.
    pub fn bit_rate(&self) -> Option<u32> {
        tcgetattr(&self.master).ok().map(|t| t.output_speed())
    }

    /// The master side as a port for one served stream.
    pub fn port(&self) -> Result<PtyPort<'_>, PortError> {
        Ok(PtyPort { pty: self })
    }
}

/// The master side of a [`Pty`] as a port.
pub struct PtyPort<'p> {
    pty: &'p Pty,
}

impl Port for PtyPort<'_> {
    fn read(&mut self, buf: &mut [u8], wait: Duration) -> Result<Got, PortError> {
        if !readable(&self.pty.master, wait, "pseudo-terminal")? {
            return Ok(Got::Idle);
        }
        match rustix::io::read(&self.pty.master, buf) {
            Ok(0) => Ok(Got::Idle),
            Ok(n) => Ok(Got::Bytes(n)),
            Err(Errno::AGAIN | Errno::INTR) => Ok(Got::Idle),
            // No slave open at all (cannot happen while we hold one): wait, do not spin.
            Err(Errno::IO) => {
                std::thread::sleep(wait);
                Ok(Got::Idle)
            }
            Err(e) => Err(PortError::Io {
                what: "pseudo-terminal",
                reason: e.to_string(),
            }),
        }
    }

    fn write(&mut self, bytes: &[u8]) -> Result<bool, PortError> {
        let mut rest = bytes;
        while !rest.is_empty() {
            match rustix::io::write(&self.pty.master, rest) {
                Ok(n) => rest = rest.get(n..).unwrap_or(&[]),
                Err(Errno::INTR) => {}
                // The client does not read and the terminal's buffer is full: the rest is
                // lost, as on a line nobody listens to.
                Err(Errno::AGAIN) => return Ok(true),
                Err(e) => {
                    return Err(PortError::Io {
                        what: "pseudo-terminal",
                        reason: e.to_string(),
                    })
                }
            }
        }
        Ok(true)
    }

    fn bit_rate(&self) -> Option<u32> {
        self.pty.bit_rate()
    }
}
