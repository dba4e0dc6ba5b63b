//! One family's conformance suite: its cases and how to run them on a device under test.
//!
//! A family plugs in by implementing [`Suite`] (the case list, opening a session on a
//! `--dut`) and [`Session`] (running one case against the device and the family's reference
//! model). The runner, selection, expectations and reports are shared. HPD is implemented in
//! [`crate::hpd`]; PSD4xx ([`crate::psd4xx`]) and PSx3xx ([`crate::psx3xx`]) run their
//! reference models over the cyclic exchange of [`crate::cyclic`] on the same
//! [`crate::link::Link`] transports.

use crate::case::{CaseInfo, CaseRun};
use crate::dut::Dut;
use crate::link::{LinkError, Micros};
use drivespec_sim::reference::BrakeKind;
use drivespec_spec::{FamilyId, Spec};

/// How cases are generated and sessions opened.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Settings {
    /// Serial/bus address of the device under test (HPD Pr27).
    pub address: u8,
    /// Seed of the values cases pick.
    pub seed: u64,
    /// Device model (`--model`, or the `sim:MODEL` suffix).
    pub model: Option<String>,
    /// Extra time allowed for an answer on real transports (µs); None: per transport.
    pub slack_us: Option<Micros>,
    /// Bit rate of the line (serial `?baud=`); None: the delivery value.
    pub bit_rate: Option<u32>,
    /// The PSx3xx brake option of the device (`--brake`; manual 5.11–5.13): an ordering
    /// option no ISDU entry reports. None: no brake.
    pub brake: Option<BrakeKind>,
    /// Erratum readings made strict (`--reading OPTION=READING`): the only admissible
    /// reading of that erratum; every reading of the others is accepted.
    pub readings: Vec<(String, String)>,
}

/// Why a suite or a session cannot be set up.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SetupError {
    /// The transport cannot be opened.
    #[error(transparent)]
    Link(#[from] LinkError),
    /// The options do not fit the family (unknown model, address out of range, …).
    #[error("{0}")]
    Usage(String),
    /// The spec lacks what the suite needs.
    #[error("spec: {0}")]
    Spec(String),
    /// The spec lacks what the HPD cases or fuzz sequences need.
    #[error("spec: {0}")]
    Hpd(#[from] crate::hpd::GenError),
}

impl From<drivespec_sim::reference::ReferenceError> for SetupError {
    fn from(e: drivespec_sim::reference::ReferenceError) -> SetupError {
        match e {
            drivespec_sim::reference::ReferenceError::UnknownModel { .. }
            | drivespec_sim::reference::ReferenceError::NoSuchBrake { .. } => {
                SetupError::Usage(e.to_string())
            }
            other => SetupError::Spec(other.to_string()),
        }
    }
}

/// The cases of one family.
pub trait Suite {
    /// The family.
    fn family(&self) -> FamilyId;

    /// Every case, in run order.
    fn cases(&self) -> &[CaseInfo];

    /// Opens a session on the device under test.
    fn open(&self, dut: &Dut) -> Result<Box<dyn Session + '_>, SetupError>;

    /// The units of the position and speed its motion cases plot; None for a family
    /// without plots.
    fn plot_units(&self) -> Option<crate::report::PlotUnits> {
        None
    }
}

/// A connection to one device under test with its reference model.
pub trait Session {
    /// The device under test, one line.
    fn describe(&self) -> String;

    /// Runs case `index` of the suite; never panics, always returns (bounded in time).
    fn run(&mut self, index: usize) -> CaseRun;
}

/// The suite of `family`, generated from the spec.
pub fn suite<'s>(
    spec: &'s Spec,
    family: FamilyId,
    settings: &Settings,
) -> Result<Box<dyn Suite + 's>, SetupError> {
    if let (Some(b), false) = (settings.brake, family == FamilyId::Psx3xx) {
        return Err(SetupError::Usage(format!(
            "--brake {}: the brake is an option of the psx3xx drives, not of {family}",
            b.spec_name()
        )));
    }
    match family {
        FamilyId::Hpd => Ok(Box::new(crate::hpd::HpdSuite::new(spec, settings)?)),
        FamilyId::Psd4xx => Ok(Box::new(crate::psd4xx::Psd4xxSuite::new(spec, settings)?)),
        FamilyId::Psx3xx => Ok(Box::new(crate::psx3xx::Psx3xxSuite::new(spec, settings)?)),
    }
}
