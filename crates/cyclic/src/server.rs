//! The device side of `drivespec-cyclic/1` for a sans-IO model: the built-in PSD4xx or PSx3xx
//! reference drive, or a test wrapper around one with a planted deviation.
//!
//! [`Server::handle_line`] turns one request line into one reply line; [`Server::serve`] runs
//! that loop over any reader and writer (a TCP stream, stdin/stdout). Times are µs since the
//! last `RESET`; an earlier time than the last one counts as now (the model never goes back).
//! A server borrows what its device borrows (the PSx3xx drive borrows the spec: `Server<'s>`);
//! the PSD4xx drive owns everything (`Server<'static>`).

use super::wire::{Env, Reply, Request, VERSION};
use drivespec_positioner::{EnvChange, Micros};
use drivespec_psd4xx::model::{Drive, RecordAnswer, RecordFailure, RecordRequest};
use drivespec_psx3xx::isdu::{Request as IsduRequest, Response};
use drivespec_psx3xx::model::{Drive as PsxDrive, JogKeys, LinkEvent as PsxLink};
use drivespec_spec::FamilyId;
use std::io::{BufRead, Write};

/// A device model the server drives.
pub trait CyclicDevice<'s>: Send {
    /// One output image at `now`; the input image that answers it.
    fn cycle(&mut self, now: Micros, image: &[u8]) -> Result<Vec<u8>, String>;
    /// Lets time pass until `now`.
    fn advance(&mut self, now: Micros);
    /// A PSD4xx acyclic record at `now` (3.2.2); None when the device does not answer.
    /// Devices without records keep the default, which never answers.
    fn record(
        &mut self,
        now: Micros,
        req: RecordRequest,
    ) -> Option<Result<RecordAnswer, RecordFailure>> {
        let _ = (now, req);
        None
    }
    /// A PSx3xx ISDU request at `now` (3.1): `DATA`, `WRITTEN`, `ISDU-ERROR NAME` or
    /// `SILENT`. Devices without ISDU access keep the default, an `ERR` reply.
    fn isdu(&mut self, now: Micros, req: IsduRequest) -> Reply {
        let _ = (now, req);
        Reply::Err("no ISDU access on this device".to_owned())
    }
    /// An environment injection at `now`; false when not supported.
    fn env(&mut self, now: Micros, env: Env) -> bool;
    /// A copy in the same state.
    fn clone_box(&self) -> Box<dyn CyclicDevice<'s> + 's>;
}

/// The positioning-core change an injection names; None for `power-cycle`, `link` and
/// `keys`, which each family handles itself.
pub fn env_change(env: Env) -> Option<EnvChange> {
    Some(match env {
        Env::Jam(on) => EnvChange::Jam { on },
        Env::Displace(by) => EnvChange::Displace { by },
        Env::MotorVoltage(dv) => EnvChange::MotorVoltage { dv },
        Env::MissSteps(by) => EnvChange::MissSteps { by },
        Env::Temperature(celsius) => EnvChange::Temperature { celsius },
        Env::ControlVoltage(dv) => EnvChange::ControlVoltage { dv },
        Env::LoadTorque(cnm) => EnvChange::LoadTorque { cnm },
        Env::BackDrive(rpm) => EnvChange::BackDrive { rpm },
        Env::Block(at) => EnvChange::Block { at },
        Env::ClearBlocks => EnvChange::ClearBlocks,
        Env::PositionFault => EnvChange::PositionFault,
        Env::PowerCycle | Env::Link(_) | Env::Keys { .. } => return None,
    })
}

impl CyclicDevice<'static> for Drive {
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
            Env::Link(e) => self.handle_link(now, e),
            Env::Keys { .. } => return false,
            other => match env_change(other) {
                Some(change) => self.handle_env(now, change),
                None => return false,
            },
        }
        while self.poll_event().is_some() {}
        true
    }

    fn clone_box(&self) -> Box<dyn CyclicDevice<'static> + 'static> {
        Box::new(self.clone())
    }
}

/// The ErrorType of an ISDU refusal as the wire names it: the spec's name, else hex.
fn isdu_reply(drive: &PsxDrive<'_>, response: Response) -> Reply {
    match response {
        Response::Read { data } => Reply::Data(data),
        Response::Write => Reply::Written,
        Response::Error { error } => {
            Reply::IsduError(drive.rules().error_types().named(error).to_string())
        }
    }
}

impl<'s> CyclicDevice<'s> for PsxDrive<'s> {
    fn cycle(&mut self, now: Micros, image: &[u8]) -> Result<Vec<u8>, String> {
        self.handle_image(now, image).map_err(|e| e.to_string())?;
        let mut last = None;
        while let Some((_, input)) = self.poll_input() {
            last = Some(input);
        }
        match last {
            Some(i) => i
                .to_bytes(self.rules(), self.byte_order())
                .map_err(|e| e.to_string()),
            // Switched off or not communicating: the image the drive holds.
            None => Ok(self.input_image()),
        }
    }

    fn advance(&mut self, now: Micros) {
        PsxDrive::advance(self, now);
    }

    fn isdu(&mut self, now: Micros, req: IsduRequest) -> Reply {
        self.handle_isdu(now, req);
        let mut last = None;
        while let Some(a) = self.poll_isdu() {
            last = Some(a.response);
        }
        match last {
            Some(r) => isdu_reply(self, r),
            None => Reply::Silent,
        }
    }

    fn env(&mut self, now: Micros, env: Env) -> bool {
        match env {
            Env::PowerCycle => self.power_cycle(now),
            Env::Link(e) => match e {
                drivespec_psd4xx::model::LinkEvent::Lost => self.handle_link(now, PsxLink::Lost),
                drivespec_psd4xx::model::LinkEvent::Connected => {
                    self.handle_link(now, PsxLink::Connected)
                }
                // IOPS is PROFINET's; IO-Link has no such state.
                _ => return false,
            },
            Env::Keys { forward, reverse } => self.handle_keys(now, JogKeys { forward, reverse }),
            other => match env_change(other) {
                Some(change) => self.handle_env(now, change),
                None => return false,
            },
        }
        while self.poll_event().is_some() {}
        true
    }

    fn clone_box(&self) -> Box<dyn CyclicDevice<'s> + 's> {
        Box::new(self.clone())
    }
}

/// The most virtual time one request may move the clock on (µs, one hour): the model
/// simulates every tick it is advanced, so a peer sending an absurd time must not hold the
/// server for days.
pub const MAX_STEP_US: u64 = 3_600_000_000;

/// Serves one device over `drivespec-cyclic/1`.
pub struct Server<'s> {
    name: String,
    family: String,
    start: Box<dyn CyclicDevice<'s> + 's>,
    device: Box<dyn CyclicDevice<'s> + 's>,
    /// The latest time a request carried since the last `RESET`.
    clock: u64,
}

impl<'s> Server<'s> {
    /// A server for `device` (its state now is what `RESET` restores), of `family`, named
    /// `name` in its `HELLO`.
    pub fn new(name: &str, family: &str, device: Box<dyn CyclicDevice<'s> + 's>) -> Server<'s> {
        Server {
            name: name.to_owned(),
            family: family.to_owned(),
            start: device.clone_box(),
            device,
            clock: 0,
        }
    }

    /// Whether the family served speaks ISDU (PSx3xx) rather than records (PSD4xx).
    fn isdu_family(&self) -> bool {
        self.family == FamilyId::Psx3xx.as_str()
    }

    /// Answers one request; a time more than [`MAX_STEP_US`] after the latest one is refused
    /// with `ERR`.
    pub fn handle(&mut self, req: Request) -> Reply {
        if let Some(t) = req.time() {
            if t.saturating_sub(self.clock) > MAX_STEP_US {
                return Reply::Err(format!(
                    "time {t} is more than {MAX_STEP_US} µs after the latest ({})",
                    self.clock
                ));
            }
            self.clock = self.clock.max(t);
        }
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
                self.clock = 0;
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
            Request::Read { .. } | Request::Write { .. } if self.isdu_family() => {
                Reply::Err("records are PSD4xx requests; PSx3xx uses ISDU-READ/ISDU-WRITE".into())
            }
            Request::IsduRead { .. } | Request::IsduWrite { .. } if !self.isdu_family() => {
                Reply::Err(format!("no ISDU access on {}; use READ/WRITE", self.family))
            }
            Request::Read { t, index } => {
                record_reply(self.device.record(t, RecordRequest::Read { index }))
            }
            Request::Write { t, index, data } => {
                record_reply(self.device.record(t, RecordRequest::Write { index, data }))
            }
            Request::IsduRead { t, index, subindex } => {
                self.device.isdu(t, IsduRequest::Read { index, subindex })
            }
            Request::IsduWrite {
                t,
                index,
                subindex,
                data,
            } => self.device.isdu(
                t,
                IsduRequest::Write {
                    index,
                    subindex,
                    data,
                },
            ),
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

#[cfg(test)]
mod tests {
    use super::Server;
    use drivespec_spec::{FamilyId, Spec};

    fn psx3xx(spec: &Spec) -> Server<'_> {
        let config = drivespec_psx3xx::model::DriveConfig::new("PSE312-8");
        let drive =
            drivespec_psx3xx::model::Drive::new(spec, config).unwrap_or_else(|e| panic!("{e}"));
        Server::new(
            "drivespec reference PSE312-8",
            FamilyId::Psx3xx.as_str(),
            Box::new(drive),
        )
    }

    fn psd4xx(spec: &Spec) -> Server<'static> {
        let config = drivespec_psd4xx::model::DriveConfig::new("PSD401-5V");
        let drive =
            drivespec_psd4xx::model::Drive::new(spec, config).unwrap_or_else(|e| panic!("{e}"));
        Server::new(
            "drivespec reference PSD401-5V",
            FamilyId::Psd4xx.as_str(),
            Box::new(drive),
        )
    }

    #[test]
    fn a_psx3xx_server_answers_isdu_and_refuses_records() {
        let spec = Spec::builtin().unwrap_or_else(|e| panic!("{e:?}"));
        let mut s = psx3xx(&spec);
        let mut ask = |line: &str| s.handle_line(line);
        assert_eq!(
            ask("HELLO drivespec-cyclic 1 psx3xx PSE312-8"),
            "HELLO drivespec-cyclic 1 drivespec reference PSE312-8"
        );
        assert!(ask("HELLO drivespec-cyclic 1 psd4xx PSD401-5V").starts_with("ERR"));
        assert_eq!(ask("RESET"), "OK");
        assert_eq!(ask("ISDU-READ 0 1 0"), "ISDU-ERROR IDX_NOTAVAIL");
        assert_eq!(ask("ISDU-READ 0 116 0"), "DATA 01");
        assert_eq!(ask("ISDU-WRITE 0 116 0 -"), "ISDU-ERROR VAL_LENUNDRUN");
        assert_eq!(ask("ISDU-WRITE 0 116 0 0102"), "ISDU-ERROR VAL_LENOVRRUN");
        assert!(ask("READ 0 44").starts_with("ERR"));
        assert_eq!(ask("ENV 0 keys forward"), "OK");
        // Status bit 3 (forward key) in the input image; format 1 output of 6 bytes.
        assert_eq!(ask("CYCLE 8000 000000000000"), "IN 011800000000C800");
        assert!(ask("CYCLE 16000 00").starts_with("ERR"));
        assert_eq!(ask("ENV 16000 link iops-bad"), "UNSUPPORTED");
        assert_eq!(ask("ENV 16000 link lost"), "OK");
        assert_eq!(ask("ISDU-READ 24000 116 0"), "SILENT");
        assert_eq!(ask("ENV 24000 power-cycle 0"), "OK");
        assert!(ask("ISDU-READ x").starts_with("ERR"));
        assert_eq!(ask("RESET"), "OK");
        assert_eq!(ask("ISDU-READ 0 116 0"), "DATA 01");
    }

    #[test]
    fn a_psd4xx_server_refuses_isdu_and_keys() {
        let spec = Spec::builtin().unwrap_or_else(|e| panic!("{e:?}"));
        let mut s = psd4xx(&spec);
        assert_eq!(s.handle_line("RESET"), "OK");
        assert!(s.handle_line("ISDU-READ 0 116 0").starts_with("ERR"));
        assert_eq!(s.handle_line("ENV 0 keys both"), "UNSUPPORTED");
        assert_eq!(s.handle_line("ENV 0 control-voltage 240"), "OK");
        assert!(s.handle_line("READ 0 44").starts_with("DATA"));
    }

    #[test]
    fn a_time_jump_beyond_the_bound_is_refused_not_simulated() {
        let spec = Spec::builtin().unwrap_or_else(|e| panic!("{e:?}"));
        let mut s = psd4xx(&spec);
        assert_eq!(s.handle_line("RESET"), "OK");
        assert!(s
            .handle_line("ADVANCE 18446744073709551615")
            .starts_with("ERR"));
        let step = super::MAX_STEP_US;
        assert_eq!(
            s.handle_line(&format!("ADVANCE {}", step + 1)),
            format!(
                "ERR time {} is more than {step} µs after the latest (0)",
                step + 1
            )
        );
        assert_eq!(s.handle_line("ADVANCE 1000"), "OK");
        assert!(s
            .handle_line(&format!("READ {} 44", step + 1000))
            .starts_with("DATA"));
        assert_eq!(s.handle_line("RESET"), "OK");
        assert!(s
            .handle_line(&format!("ADVANCE {}", step + 1))
            .starts_with("ERR"));
    }
}
