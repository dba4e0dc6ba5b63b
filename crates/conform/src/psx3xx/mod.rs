//! The PSx3xx conformance suite (manual chapters 3–5): cases generated from the spec's ISDU,
//! protocol, bit and model tables and run over the cyclic-exchange protocol
//! ([`crate::cyclic`]: process images each IO-Link cycle, `ISDU-READ`/`ISDU-WRITE` between
//! cycles) against the reference drive model as oracle.
//!
//! Case groups (IDs `psx3xx/<group>/...`):
//!
//! | group | what |
//! | --- | --- |
//! | `isdu` | every index and sub-index of the table read; writes at both range edges, one beyond and in range gaps, read back; read-only writes; unknown indices and sub-indices; length overrun and underrun; the write lock of ISDU 12 |
//! | `guard` | every guard entry: the directly following write dropped, writes without it and after the allow value executed, another write ending the suppression, not saved |
//! | `command` | every ISDU 2 and ISDU 193 command with working and saved values across a power cycle; values that are no command; unsaved values lost, saved ones kept; entries never saved |
//! | `format` | the three process-data formats: switch effective only after save and reset, device ID per format, a run in each format, the 8-byte speed rules (0 uses ISDU 142, given, changed, invalid, manual) |
//! | `timestamp` | time-stamp runs: executed the stamp's delay after the field turns inactive, not while valid stamps keep coming, edge values, manual runs and cancel, without loop, ISDU control |
//! | `status` | status bits after power-on, at the target, release withdrawn and cleared, motor voltage, temperature, displacement, target outside the limits, against the loop, jog keys, obstruction, position fault |
//! | `timeout` | ISDU 118/137: time-out off, cancel, safe position, the reserved value |
//! | `position` | runs with and without loop both ways, new target, transfer then release, manual runs, jog by key and by control bit |
//!
//! Every cycle's input image is compared with the reference's: status word exactly, position
//! and speed within the case's declared tolerance; every ISDU and injection reply exactly,
//! except the live speed and position read by ISDU in a motion case, which must lie between
//! the device's own process-data images around the read (within the case's tolerance).

pub mod cases;
mod session;

pub use session::{output, Psx3xx, Psx3xxSession};

use crate::case::CaseInfo;
use crate::cyclic::{Peer, Server};
use crate::dut::Dut;
use crate::suite::{Session, Settings, SetupError, Suite};
use cases::PsxCase;
use drivespec_psx3xx::model::Drive;
use drivespec_sim::reference::{self, Reference};
use drivespec_spec::{Family, FamilyId, Spec};

/// The device model `--model` selects when none is given.
pub use drivespec_sim::reference::PSX3XX_DEFAULT_MODEL as DEFAULT_MODEL;

/// The PSx3xx suite for one device model.
pub struct Psx3xxSuite<'s> {
    family: &'s Family,
    reference: Reference<'s, Drive<'s>>,
    cycle_us: u64,
    infos: Vec<CaseInfo>,
    cases: Vec<PsxCase>,
}

impl<'s> Psx3xxSuite<'s> {
    /// Generates the cases for `settings.model` (default [`DEFAULT_MODEL`]) with the brake
    /// option `settings.brake` (manual 5.11–5.13).
    pub fn new(spec: &'s Spec, settings: &Settings) -> Result<Psx3xxSuite<'s>, SetupError> {
        let family = spec.family(FamilyId::Psx3xx);
        let reference = reference::psx3xx(spec, settings.model.as_deref(), settings.brake)?;
        let cycle_us = min_cycle_us(&reference.drive)?;
        let (infos, cases) = cases::generate(family, reference.model, &reference.drive, cycle_us)
            .map_err(|e| SetupError::Spec(e.to_string()))?;
        Ok(Psx3xxSuite {
            family,
            reference,
            cycle_us,
            infos,
            cases,
        })
    }

    /// The device model the cases are for.
    pub fn model(&self) -> &str {
        &self.reference.model.id
    }

    /// The reference drive as every case expects the device at its start.
    pub fn reference(&self) -> &Drive<'s> {
        &self.reference.drive
    }

    /// The IO-Link cycle of the runner (µs): the device's MinCycleTime (PSX-DP-001).
    pub fn cycle_us(&self) -> u64 {
        self.cycle_us
    }

    /// A server on the reference drive (what `sim` runs, and what tests serve over tcp).
    pub fn server(&self) -> Server<'s> {
        self.reference.server(FamilyId::Psx3xx)
    }

    /// Opens a session on a peer of the caller's (tests, embedding tools).
    pub fn session<'a>(&'a self, peer: Box<dyn Peer + 'a>) -> impl Session + 'a {
        self.cyclic_session(peer)
    }

    /// A session on `peer` with the family's own operations (greeting, injections, fuzzing).
    pub fn cyclic_session<'a>(&'a self, peer: Box<dyn Peer + 'a>) -> Psx3xxSession<'a, 's> {
        Psx3xxSession::new(Psx3xx::new(self), peer)
    }

    /// The PSx3xx family of the spec.
    pub fn family(&self) -> &'s Family {
        self.family
    }

    pub(crate) fn case(&self, index: usize) -> Option<(&CaseInfo, &PsxCase)> {
        Some((self.infos.get(index)?, self.cases.get(index)?))
    }

    /// The peer of the device under test `dut` (`sim`: the suite's reference drive).
    pub fn peer(&self, dut: &Dut) -> Result<Box<dyn Peer + '_>, SetupError> {
        crate::cyclic_session::peer(dut, &self.reference.model.id, || self.server())
    }
}

/// The MinCycleTime of Direct Parameter page 1 in µs (PSX-DP-001).
fn min_cycle_us(drive: &Drive<'_>) -> Result<u64, SetupError> {
    let rules = drive.rules();
    let code = match drive.value(&rules.protocol().device_id.model_param) {
        drivespec_psx3xx::isdu::Value::Int(c) => u32::try_from(c).unwrap_or(0),
        _ => 0,
    };
    let page = rules
        .direct_page(drive.active_format(), code)
        .and_then(|bytes| rules.decode_direct(0, &bytes))
        .map_err(|e| SetupError::Spec(format!("Direct Parameter page: {e}")))?;
    page.min_cycle_time_us
        .map(u64::from)
        .filter(|us| *us > 0)
        .ok_or_else(|| SetupError::Spec("no MinCycleTime in the Direct Parameter page".to_owned()))
}

impl Suite for Psx3xxSuite<'_> {
    fn family(&self) -> FamilyId {
        FamilyId::Psx3xx
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

    /// The units of the input image's `actual` and `rpm` fields' parameters.
    fn plot_units(&self) -> Option<crate::report::PlotUnits> {
        use drivespec_psx3xx::rules::names;
        let fields = &self.reference().rules().protocol().process_input.fields;
        let param = |name: &str| {
            fields
                .iter()
                .find(|f| f.name == name)
                .and_then(|f| f.params.first())
                .map(String::as_str)
        };
        Some(crate::report::PlotUnits::of(
            FamilyId::Psx3xx,
            self.family,
            param(names::ACTUAL),
            param(names::RPM),
        ))
    }
}
