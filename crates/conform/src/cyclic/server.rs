//! The device side of `drivespec-cyclic/1` for a sans-IO model: the built-in PSD4xx reference
//! drive, or a test wrapper around it with a planted deviation.
//!
//! [`Server::handle_line`] turns one request line into one reply line; [`Server::serve`] runs
//! that loop over any reader and writer (a TCP stream, stdin/stdout). Times are µs since the
//! last `RESET`; an earlier time than the last one counts as now (the model never goes back).

use super::wire::{Env, Reply, Request, VERSION};
use drivespec_positioner::{EnvChange, Micros};
use drivespec_psd4xx::model::{Drive, RecordAnswer, RecordFailure, RecordRequest};
use std::io::{BufRead, Write};

/// A device model the server drives.
pub trait CyclicDevice: Send {
    /// One output image at `now`; the input image that answers it.
    fn cycle(&mut self, now: Micros, image: &[u8]) -> Result<Vec<u8>, String>;
    /// Lets time pass until `now`.
    fn advance(&mut self, now: Micros);
    /// An acyclic record at `now`; None when the device does not answer.
    fn record(
        &mut self,
        now: Micros,
        req: RecordRequest,
    ) -> Option<Result<RecordAnswer, RecordFailure>>;
    /// An environment injection at `now`; false when not supported.
    fn env(&mut self, now: Micros, env: Env) -> bool;
    /// A copy in the same state.
    fn clone_box(&self) -> Box<dyn CyclicDevice>;
}

impl CyclicDevice for Drive {
    fn cycle(&mut self, now: Micros, image: &[u8]) -> Result<Vec<u8>, String> {
        self.handle_image(now, image).map_err(|e| e.to_string())?;
        let mut last = None;
        while let Some((_, input)) = self.poll_input() {
            last = Some(input);
        }
        match last {
            Some(i) => i.to_bytes(self.rules()).map_err(|e| e.to_string()),
            // Switched off: the bus sees the idle image.
            None => Ok(self.input_image()),
        }
    }

    fn advance(&mut self, now: Micros) {
        Drive::advance(self, now);
    }

    fn record(
        &mut self,
        now: Micros,
        req: RecordRequest,
    ) -> Option<Result<RecordAnswer, RecordFailure>> {
        self.handle_record(now, req);
        let mut last = None;
        while let Some(r) = self.poll_record() {
            last = Some(r.result);
        }
        last
    }

    fn env(&mut self, now: Micros, env: Env) -> bool {
        match env {
            Env::PowerCycle => self.power_cycle(now),
            Env::Jam(on) => self.handle_env(now, EnvChange::Jam { on }),
            Env::Displace(by) => self.handle_env(now, EnvChange::Displace { by }),
            Env::MotorVoltage(dv) => self.handle_env(now, EnvChange::MotorVoltage { dv }),
            Env::MissSteps(by) => self.handle_env(now, EnvChange::MissSteps { by }),
            Env::Temperature(celsius) => self.handle_env(now, EnvChange::Temperature { celsius }),
            Env::Link(e) => self.handle_link(now, e),
        }
        while self.poll_event().is_some() {}
        true
    }

    fn clone_box(&self) -> Box<dyn CyclicDevice> {
        Box::new(self.clone())
    }
}

/// Serves one device over `drivespec-cyclic/1`.
pub struct Server {
    name: String,
    family: String,
    start: Box<dyn CyclicDevice>,
    device: Box<dyn CyclicDevice>,
}

impl Server {
    /// A server for `device` (its state now is what `RESET` restores), of `family`, named
    /// `name` in its `HELLO`.
    pub fn new(name: &str, family: &str, device: Box<dyn CyclicDevice>) -> Server {
        Server {
            name: name.to_owned(),
            family: family.to_owned(),
            start: device.clone_box(),
            device,
        }
    }

    /// Answers one request.
    pub fn handle(&mut self, req: Request) -> Reply {
        match req {
            Request::Hello {
                version, family, ..
            } => {
                if version != VERSION {
                    return Reply::Err(format!("version {version} not supported (1)"));
                }
                if family != self.family {
                    return Reply::Err(format!("family {family} not served ({})", self.family));
                }
                Reply::Hello {
                    version: VERSION,
                    name: self.name.clone(),
                }
            }
            Request::Reset => {
                self.device = self.start.clone_box();
                Reply::Ok
            }
            Request::Cycle { t, image } => match self.device.cycle(t, &image) {
                Ok(b) => Reply::In(b),
                Err(e) => Reply::Err(e),
            },
            Request::Advance { t } => {
                self.device.advance(t);
                Reply::Ok
            }
            Request::Read { t, index } => {
                record_reply(self.device.record(t, RecordRequest::Read { index }))
            }
            Request::Write { t, index, data } => {
                record_reply(self.device.record(t, RecordRequest::Write { index, data }))
            }
            Request::Env { t, env } => {
                if self.device.env(t, env) {
                    Reply::Ok
                } else {
                    Reply::Unsupported
                }
            }
        }
    }

    /// Answers one request line (without `\n`) with one reply line (without `\n`).
    pub fn handle_line(&mut self, line: &str) -> String {
        match Request::parse(line.trim_end_matches('\r')) {
            Ok(r) => self.handle(r).to_string(),
            Err(e) => Reply::Err(e.to_string()).to_string(),
        }
    }

    /// Serves lines from `input` until it ends, replies to `output` (flushed per line).
    pub fn serve(&mut self, input: impl BufRead, mut output: impl Write) -> std::io::Result<()> {
        for line in input.lines() {
            let mut reply = self.handle_line(&line?);
            // One write per reply: no small-packet delays on sockets.
            reply.push('\n');
            output.write_all(reply.as_bytes())?;
            output.flush()?;
        }
        Ok(())
    }
}

fn record_reply(r: Option<Result<RecordAnswer, RecordFailure>>) -> Reply {
    match r {
        None => Reply::Silent,
        Some(Ok(RecordAnswer::Data { bytes })) => Reply::Data(bytes),
        Some(Ok(RecordAnswer::Written)) => Reply::Written,
        Some(Ok(RecordAnswer::Ignored)) => Reply::Ignored,
        Some(Err(RecordFailure::Malformed { .. })) => Reply::Malformed,
        Some(Err(RecordFailure::Refused { error })) => Reply::Refused(error.0),
    }
}
