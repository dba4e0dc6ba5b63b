//! The HPD conformance suite (manual chapter 4, 3.3–3.4, 3.6, 3.8): cases generated from the
//! spec's parameter, bit, protocol and vector tables, run against the reference drive model
//! as oracle.
//!
//! Case groups (IDs `hpd/<group>/...`):
//!
//! | group | what |
//! | --- | --- |
//! | `frame` | every message type, LUN 1–4, stuffing, corrupt frames, foreign addresses, time-outs |
//! | `param` | every parameter with a serial address: read, range edges and one beyond (per operating mode), read-only writes, byte/word/double-word access |
//! | `bit` | every bit set and cleared with a bit change on its byte; read-only and must-be-zero bits |
//! | `broadcast` | broadcasts taken and never answered, at any address |
//! | `plc` | PLC area read, upload and read-back, writes while running, programs run; the spec's `hpd-plc` vectors |
//! | `cmd` | command bits: self-clearing, preconditions (b99.7, b99.6, b99.13, b40.2), saves across power-up |
//! | `baud` | every Pr26 code: re-initialisation, bit rate, time-out, answer delay |
//! | `vector` | the spec's `hpd-frame` vectors, at their drive address |
//! | `motion` | the motor turned by jog, the speed reference and the mode 9 profile, judged by envelopes; the wiring test |

mod attribute;
mod behaviour;
pub mod cases;
pub mod frame;
mod motion;
mod moves;
pub mod names;
mod params;
mod readings;
mod session;
pub mod step;

pub use cases::GenError;
pub use session::HpdSession;

use crate::case::CaseInfo;
use crate::dut::Dut;
use crate::link::{ExecLink, Link, SerialLink, TcpLink};
use crate::suite::{Session, Settings, SetupError, Suite};
use drivespec_hpd::model::{Drive, DriveConfig};
use drivespec_hpd::plc::PlcCodec;
use drivespec_hpd::FrameRules;
use drivespec_sim::SimLink;
use drivespec_spec::hpd::Protocol;
use drivespec_spec::{Family, FamilyId, Spec};
use step::HpdCase;

/// The HPD suite: cases for one device address, bit rate and seed.
pub struct HpdSuite<'s> {
    spec: &'s Spec,
    protocol: &'s Protocol,
    settings: Settings,
    baseline: Drive,
    /// How the reference drives are built (start state; readings are per session).
    config: DriveConfig,
    /// The errata a device may read either way, and the readings made strict.
    readings: readings::ReadingRules<'s>,
    infos: Vec<CaseInfo>,
    cases: Vec<HpdCase>,
    rules: FrameRules,
    codec: PlcCodec,
    model: Option<String>,
}

impl<'s> HpdSuite<'s> {
    /// Generates the cases from the spec for a device commissioned at `settings.address`
    /// with the Pr26 code of `settings.bit_rate` (default: Pr26's delivery value).
    pub fn new(spec: &'s Spec, settings: &Settings) -> Result<HpdSuite<'s>, SetupError> {
        let family = spec.family(FamilyId::Hpd);
        let protocol = family.hpd().ok_or(GenError::NoProtocol)?;
        let model = match &settings.model {
            Some(m) => Some(family.model(m).ok_or_else(|| {
                let known: Vec<&str> = family.models.iter().map(|m| m.id.as_str()).collect();
                SetupError::Usage(format!(
                    "unknown HPD model {m:?}; known: {}",
                    known.join(", ")
                ))
            })?),
            None => None,
        };
        let max = protocol.frame.addr_range[1];
        if settings.address > max {
            return Err(SetupError::Usage(format!(
                "address {} outside 0..={max} (Pr27)",
                settings.address
            )));
        }
        let code = match settings.bit_rate {
            Some(bps) => Some(
                protocol
                    .baud_rates
                    .iter()
                    .find(|b| b.bps == bps && b.mode == drivespec_spec::hpd::BaudMode::Standard)
                    .map(|b| b.code)
                    .ok_or_else(|| {
                        let known: Vec<String> = protocol
                            .baud_rates
                            .iter()
                            .map(|b| b.bps.to_string())
                            .collect();
                        SetupError::Usage(format!(
                            "{bps} b/s is not an HPD bit rate (Pr26 table: {})",
                            known.join(", ")
                        ))
                    })?,
            ),
            None => None,
        };
        let config = match code {
            Some(c) => DriveConfig::commissioned_at(c, settings.address),
            None => DriveConfig::commissioned(settings.address),
        };
        let readings = readings::ReadingRules::new(spec, family, &settings.readings)?;
        let baseline = Drive::new(spec, config.clone()).map_err(GenError::from)?;
        let mut g = cases::Gen::new(
            spec,
            baseline.clone(),
            model,
            settings.address,
            settings.seed,
        )?;
        frame::generate(&mut g);
        params::generate(&mut g);
        behaviour::generate(&mut g);
        moves::generate(&mut g);
        if !g.errors.is_empty() {
            return Err(GenError::Cases(g.errors).into());
        }
        let rules = g.rules.clone();
        let codec = g.codec.clone();
        let (infos, cases) = g.cases.into_iter().unzip();
        Ok(HpdSuite {
            spec,
            protocol,
            settings: settings.clone(),
            baseline,
            config,
            readings,
            infos,
            cases,
            rules,
            codec,
            model: model.map(|m| m.id.clone()),
        })
    }

    /// The HPD family of the spec.
    pub fn family(&self) -> &'s Family {
        self.spec.family(FamilyId::Hpd)
    }

    pub(crate) fn protocol(&self) -> &'s Protocol {
        self.protocol
    }

    /// The reference drive as the cases expect the device at the start.
    pub fn reference(&self) -> &Drive {
        &self.baseline
    }

    /// Case `index` with its steps (the fuzzer's seeds).
    pub fn case(&self, index: usize) -> Option<(&CaseInfo, &HpdCase)> {
        Some((self.infos.get(index)?, self.cases.get(index)?))
    }

    /// The settings the suite was generated for.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }

    /// The spec the suite was generated from.
    pub fn spec(&self) -> &'s Spec {
        self.spec
    }

    /// The device model the suite was generated for, by id.
    pub fn model_id(&self) -> Option<&str> {
        self.model.as_deref()
    }

    /// Opens the transport `dut` names, on the suite's reference drive for `sim`.
    pub fn link(&self, dut: &Dut) -> Result<Box<dyn Link>, SetupError> {
        self.open_link(dut)
    }

    /// Opens a session on a link of the caller's (tests, embedding tools).
    pub fn session(&self, link: Box<dyn Link>) -> HpdSession<'_, 's> {
        let slack = self
            .settings
            .slack_us
            .unwrap_or(if link.caps().virtual_time {
                1_000
            } else {
                30_000
            });
        HpdSession::new(self, link, slack)
    }

    fn open_link(&self, dut: &Dut) -> Result<Box<dyn Link>, SetupError> {
        Ok(match dut {
            Dut::Sim { model } => {
                let name = match model.as_ref().or(self.model.as_ref()) {
                    Some(m) => format!("sim:{m}"),
                    None => "sim".to_owned(),
                };
                Box::new(SimLink::new(name, Box::new(self.baseline.clone())))
            }
            Dut::Serial { path, baud } => {
                let bps = match baud {
                    Some(b) => *b,
                    None => self.baseline.line().map_or(57_600, |l| l.bps),
                };
                Box::new(SerialLink::open(path, bps, &self.protocol().character)?)
            }
            Dut::Tcp { addr } => Box::new(TcpLink::connect(addr)?),
            Dut::Exec { argv } => Box::new(ExecLink::spawn(argv)?),
            Dut::Profinet { .. } => return Err(crate::cyclic_session::profinet_is_psd4xx()),
        })
    }
}

impl Suite for HpdSuite<'_> {
    fn family(&self) -> FamilyId {
        FamilyId::Hpd
    }

    fn cases(&self) -> &[CaseInfo] {
        &self.infos
    }

    fn open(&self, dut: &Dut) -> Result<Box<dyn Session + '_>, SetupError> {
        let link = self.open_link(dut)?;
        Ok(Box::new(self.session(link)))
    }
}
