//! The PSD4xx conformance suite (manual 3.2–3.9, chapter 4): cases generated from the spec's
//! parameter, protocol, bit and vector tables and run over the cyclic-exchange protocol
//! ([`crate::cyclic`]) against the reference drive model as oracle.
//!
//! Case groups (IDs `psd4xx/<group>/...`):
//!
//! | group | what |
//! | --- | --- |
//! | `pkw` | every parameter read; writes at both range edges, one beyond and around each gap of the range; back-up across a power cycle; read-only writes (error 1); unknown PNUs (error 0); standstill-only writes during a run (error 17); par. 13 segments and count; "no command"/"no response"; the response held until the next command; every error code |
//! | `record` | every parameter read (2/4 bytes, the string); writes of 3/5 bytes with control byte 1, ignored with control byte 0, wrong lengths, unknown indices |
//! | `sequence` | the spec's `sequence` vectors, step for step |
//! | `position` | positioning with and without loop in both directions, manual runs, release withdrawal, a new target during a run |
//! | `status` | status bits after power-on, at the target, toggle echo, obstruction, incorrect target, the motor voltage at the UMot limit |
//! | `par96` | every par. 96 command and rejected values, with a power cycle after; -4 with the run command still sent |
//! | `limits`, `window`, `mapping`, `torque`, `speed`, `image` | the scenario files: end-limit bits, the positioning window, the mapping and scaling of 4.7/4.8, torque limits, a speed change during a run, the process image layout |
//!
//! Every cycle's input image of the device under test is compared with the reference's: PKW
//! block and status word exactly, position and speed within the case's declared tolerance, a
//! time tolerance in cycles; motion cases by the properties of the run
//! ([`crate::cyclic_session`]). A PKW read of a live value is judged by the device's own
//! process data around the read (3.6, the value of the moment); the standstill-only
//! parameters (spec `conditions`) are written during a run and must answer error 17; a case
//! failing against the adopted reading of an erratum bearing on it passes when it passes
//! against another reading, reporting which; points the manual leaves open are reported, not
//! judged.

pub mod cases;
mod profinet;
mod scenario;
mod session;

pub use profinet::ProfinetPeer;
pub use session::{Psd4xx, Psd4xxSession};

use crate::case::CaseInfo;
use crate::cyclic::{Peer, Server};
use crate::dut::Dut;
use crate::suite::{Session, Settings, SetupError, Suite};
use cases::PsdCase;
use drivespec_psd4xx::model::{Drive, DriveConfig};
use drivespec_sim::reference::{self, Reference};
use drivespec_spec::{Family, FamilyId, Readings, Spec};
use profinet::StartRecords;

/// The device model `--model` selects when none is given.
pub use drivespec_sim::reference::PSD4XX_DEFAULT_MODEL as DEFAULT_MODEL;

/// Every PSD4xx scenario whose setup or steps do not read, naming file, scenario, step and
/// key (`drivespec spec check`).
pub fn check_scenarios(spec: &Spec) -> Vec<drivespec_spec::Problem> {
    drivespec_spec::check_scenarios::<scenario::Setup, scenario::ScenarioStep>(
        spec.family(FamilyId::Psd4xx),
    )
}

/// Bus cycle of the runner (µs): one output image and one input image per cycle.
pub const CYCLE_US: u64 = 10_000;

/// The PSD4xx suite for one device model.
pub struct Psd4xxSuite<'s> {
    spec: &'s Spec,
    family: &'s Family,
    reference: Reference<'s, Drive>,
    infos: Vec<CaseInfo>,
    cases: Vec<PsdCase>,
}

impl<'s> Psd4xxSuite<'s> {
    /// Generates the cases for `settings.model` (default [`DEFAULT_MODEL`]).
    pub fn new(spec: &'s Spec, settings: &Settings) -> Result<Psd4xxSuite<'s>, SetupError> {
        let family = spec.family(FamilyId::Psd4xx);
        let reference = reference::psd4xx(spec, settings.model.as_deref())?;
        let (infos, cases) =
            cases::generate(family, reference.model, &reference.drive).map_err(SetupError::Spec)?;
        Ok(Psd4xxSuite {
            spec,
            family,
            reference,
            infos,
            cases,
        })
    }

    /// The device model the cases are for.
    pub fn model(&self) -> &str {
        &self.reference.model.id
    }

    /// The reference drive as every case expects the device at its start.
    pub fn reference(&self) -> &Drive {
        &self.reference.drive
    }

    /// A server on the reference drive (what `sim` runs, and what tests serve over tcp).
    pub fn server(&self) -> Server<'static> {
        self.reference.server(FamilyId::Psd4xx)
    }

    /// Opens a session on a peer of the caller's (tests, embedding tools).
    pub fn session<'a>(&'a self, peer: Box<dyn Peer + 'a>) -> impl Session + 'a {
        self.cyclic_session(peer)
    }

    /// A session on `peer` with the family's own operations (greeting, injections, fuzzing).
    pub fn cyclic_session<'a>(&'a self, peer: Box<dyn Peer + 'a>) -> Psd4xxSession<'a, 's> {
        Psd4xxSession::new(Psd4xx::new(self), peer)
    }

    /// The reference drive following `reading` of erratum option `option` instead of the
    /// adopted one, as a server.
    pub(crate) fn reading_server(&self, option: &str, reading: &str) -> Option<Server<'static>> {
        let mut readings = Readings::default();
        readings.choose(self.family, option, reading).ok()?;
        let config = DriveConfig::new(&self.reference.model.id).with_readings(readings);
        let drive = Drive::new(self.spec, config).ok()?;
        Some(Server::new(
            &format!(
                "drivespec reference {} ({option}={reading})",
                self.reference.model.id
            ),
            FamilyId::Psd4xx.as_str(),
            Box::new(drive),
        ))
    }

    /// The PSD4xx family of the spec.
    pub fn family(&self) -> &'s Family {
        self.family
    }

    pub(crate) fn case(&self, index: usize) -> Option<(&CaseInfo, &PsdCase)> {
        Some((self.infos.get(index)?, self.cases.get(index)?))
    }

    /// The peer of the device under test `dut` (`sim`: the suite's reference drive).
    pub fn peer(&self, dut: &Dut) -> Result<Box<dyn Peer>, SetupError> {
        if let Dut::Profinet { iface, name } = dut {
            let identity = drivespec_profinet::Identity::from_spec(self.spec)
                .map_err(|e| SetupError::Spec(e.to_string()))?;
            let start = self.start_records().map_err(SetupError::Spec)?;
            return Ok(Box::new(ProfinetPeer::open(iface, name, identity, start)?));
        }
        crate::cyclic_session::peer(dut, &self.reference.model.id, || self.server())
    }

    /// What brings a drive on the network to the state every case expects at its start
    /// (3.3 par. 96): a reset as switching the control voltage off and on (a run stops), the
    /// delivery state saved and the move to the middle of the range (the reference's start
    /// position), then a reset again (the status word of power-on).
    fn start_records(&self) -> Result<StartRecords, String> {
        let p = self
            .family
            .psd4xx()
            .ok_or_else(|| format!("{}: no PSD4xx protocol", self.family.id()))?;
        let pos = &p.positioning;
        let drive = &self.reference.drive;
        let save = &pos.save.param;
        let param = self
            .family
            .parameter(save)
            .ok_or_else(|| format!("no par {save}"))?;
        let index = u16::try_from(param.number).map_err(|e| format!("par {save}: {e}"))?;
        let width = drivespec_psd4xx::Width::of_type(param.data_type)
            .ok_or_else(|| format!("par {save} has no width"))?;
        let command = |name: &str| -> Result<(u16, Vec<u8>), String> {
            let value = param
                .values
                .iter()
                .find(|v| v.name == name)
                .ok_or_else(|| format!("par {save} has no value {name}"))?
                .value;
            let data = drivespec_psd4xx::RecordWrite {
                index,
                control: 1,
                width,
                value,
            }
            .to_bytes(drive.rules().record())
            .map_err(|e| format!("record write of par {save}: {e}"))?;
            Ok((index, data))
        };
        let number = |key: &str| {
            self.family
                .parameter(key)
                .and_then(|p| u16::try_from(p.number).ok())
                .and_then(|n| drive.parameter(n).ok())
                .ok_or_else(|| format!("the reference has no par {key}"))
        };
        let start = number(&pos.mapping.actual_param)?;
        let window = number(&pos.reference_loop.window_param)?;
        let running = cases::status_bit(self.family, "Drive is running")?;
        let rules = drive.rules().clone();
        Ok(StartRecords {
            restart: command("reset")?,
            centre: command("delivery-state-and-centre")?,
            settled: Box::new(move |image| {
                drivespec_psd4xx::Input::parse(&rules, image).is_ok_and(|i| {
                    i.status & running == 0
                        && i.speed == 0
                        && (i64::from(i.actual) - start).abs() <= window
                })
            }),
        })
    }
}

impl Suite for Psd4xxSuite<'_> {
    fn family(&self) -> FamilyId {
        FamilyId::Psd4xx
    }

    fn cases(&self) -> &[CaseInfo] {
        &self.infos
    }

    fn open(&self, dut: &Dut) -> Result<Box<dyn Session + '_>, SetupError> {
        let peer = self.peer(dut)?;
        let mut s = self.cyclic_session(peer);
        s.hello().map_err(SetupError::Usage)?;
        Ok(Box::new(s))
    }

    /// The units of the input image's `actual` and `speed` fields' parameters.
    fn plot_units(&self) -> Option<crate::report::PlotUnits> {
        let drivespec_spec::Protocol::Psd4xx(proto) = &self.family.protocol else {
            return None;
        };
        let fields = &proto.process_data.input.fields;
        let param = |name: &str| {
            fields
                .iter()
                .find(|f| f.name == name)
                .and_then(|f| f.param.as_deref())
        };
        Some(crate::report::PlotUnits::of(
            FamilyId::Psd4xx,
            self.family,
            param("actual"),
            param("speed"),
        ))
    }
}
