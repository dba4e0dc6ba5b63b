//! The PSD4xx conformance suite (manual 3.2–3.9, chapter 4): cases generated from the spec's
//! parameter, protocol, bit and vector tables and run over the cyclic-exchange protocol
//! ([`crate::cyclic`]) against the reference drive model as oracle.
//!
//! Case groups (IDs `psd4xx/<group>/...`):
//!
//! | group | what |
//! | --- | --- |
//! | `pkw` | every parameter read; writes at both range edges and one beyond; read-only writes (error 1); unknown PNUs (error 0); par. 13 segments and count; "no command"/"no response"; the response held until the next command; every error code |
//! | `record` | every parameter read (2/4 bytes, the string); writes of 3/5 bytes with control byte 1, ignored with control byte 0, wrong lengths, unknown indices |
//! | `sequence` | the spec's `sequence` vectors, step for step |
//! | `position` | positioning with and without loop in both directions, manual runs, release withdrawal, a new target during a run |
//! | `status` | status bits after power-on, at the target, toggle echo, obstruction, incorrect target |
//! | `par96` | every par. 96 command and rejected values, with a power cycle after |
//!
//! Every cycle's input image of the device under test is compared with the reference's: PKW
//! block and status word exactly; position and speed within the case's declared tolerance,
//! and a time tolerance in cycles for the motion cases.

pub(crate) mod cases;
pub(crate) mod fuzz;
mod session;

pub use session::Psd4xxSession;

use crate::case::CaseInfo;
use crate::cyclic::{LinkPeer, LocalPeer, Peer, Server};
use crate::dut::Dut;
use crate::link::{ExecLink, SerialLink, TcpLink};
use crate::suite::{Session, Settings, SetupError, Suite};
use cases::PsdCase;
use drivespec_psd4xx::model::Drive;
use drivespec_sim::reference::{self, Reference};
use drivespec_spec::{Family, FamilyId, Spec};

/// The device model `--model` selects when none is given.
pub use drivespec_sim::reference::PSD4XX_DEFAULT_MODEL as DEFAULT_MODEL;

/// Bus cycle of the runner (µs): one output image and one input image per cycle.
pub const CYCLE_US: u64 = 10_000;

/// The PSD4xx suite for one device model.
pub struct Psd4xxSuite<'s> {
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
    pub fn session(&self, peer: Box<dyn Peer>) -> Psd4xxSession<'_, 's> {
        Psd4xxSession::new(self, peer)
    }

    pub(crate) fn family(&self) -> &'s Family {
        self.family
    }

    pub(crate) fn case(&self, index: usize) -> Option<(&CaseInfo, &PsdCase)> {
        Some((self.infos.get(index)?, self.cases.get(index)?))
    }

    pub(crate) fn peer(&self, dut: &Dut) -> Result<Box<dyn Peer>, SetupError> {
        // Real peers get 2 s per reply (a process may take a while to start).
        const TIMEOUT_US: u64 = 2_000_000;
        Ok(match dut {
            Dut::Sim { .. } => Box::new(LocalPeer::new(
                &format!("sim:{}", self.reference.model.id),
                self.server(),
            )),
            Dut::Serial { path, baud } => {
                // The cyclic protocol is plain text: 8N1.
                let character = drivespec_spec::hpd::CharacterFormat {
                    source: "drivespec-cyclic/1".to_owned(),
                    start_bits: 1,
                    data_bits: 8,
                    parity: drivespec_spec::hpd::Parity::None,
                    stop_bits: 1,
                    bits_per_char: 10,
                };
                Box::new(LinkPeer::new(
                    Box::new(SerialLink::open(path, baud.unwrap_or(115_200), &character)?),
                    TIMEOUT_US,
                ))
            }
            Dut::Tcp { addr } => {
                Box::new(LinkPeer::new(Box::new(TcpLink::connect(addr)?), TIMEOUT_US))
            }
            Dut::Exec { argv } => {
                Box::new(LinkPeer::new(Box::new(ExecLink::spawn(argv)?), TIMEOUT_US))
            }
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
        let mut s = self.session(peer);
        s.hello().map_err(SetupError::Usage)?;
        Ok(Box::new(s))
    }
}
