//! Sequences for the PSD4xx fuzz target, from the spec: PKW commands with every command code
//! (the undefined ones too), parameter numbers in and out of the table, values at, inside and
//! beyond each model's range, array commands on scalars, wrong widths, handshake violations
//! (a new command before "no command"), control words with reserved bits and invalid bit
//! combinations, targets inside and outside the end limits or needing a loop past a limit,
//! manual runs, scaling changes in the middle of a run, records with right and wrong lengths
//! and control bytes, environment injections and time passing without a bus cycle
//! (manual 3.2–3.9, chapter 4).
//!
//! A sequence mixes 1 to 5 templates, so that parameter changes, motion commands and
//! environment changes interleave. Every value is drawn from the seeded [`Rng`] only; every
//! requirement ID a step names is checked against the spec when the generator is built.

use crate::cyclic_target::env_kind;
use crate::engine::{self, below, chance, pick, templates};
use crate::replay::{Action, Step};
use drivespec_conform::cyclic::Env;
use drivespec_conform::psd4xx::cases::{control, control_bit};
use drivespec_conform::psd4xx::Psd4xxSuite;
use drivespec_psd4xx::model::LinkEvent;
use drivespec_psd4xx::step::{PkwBlock, Step as PsdStep};
use drivespec_psd4xx::{PkwRequest, PkwRules, RecordRules, RecordWrite, Request, Width};
use drivespec_sim::rng::Rng;
use drivespec_spec::{Family, Parameter};

/// Most steps in one sequence.
const MAX_STEPS: usize = 40;

/// Most cycles a wait for running or standstill takes (15 s of bus time at 10 ms).
const WAIT_MAX: u32 = 1_500;

templates! {
    /// Templates and their weights.
    Read = 8, Write = 8, OutOfRange = 6, ReadOnly = 4, UnknownPnu = 3, AnyAk = 5, IndOnScalar = 3,
    BadSubindex = 2, WrongType = 3, Spm = 2, Handshake = 6, Par96 = 2, Reserved = 4, Invalid = 4,
    Toggle = 4, Position = 8, BeyondLimits = 3, LoopPastLimit = 2, Manual = 5, ReleaseWithdrawn = 4,
    NewTarget = 4, TransferWithoutRelease = 2, Scaling = 3, RecordRead = 5, RecordWrite = 5,
    RecordBad = 4, Environment = 6, Obstruction = 3, Advance = 2
}

/// A parameter as the generator uses it.
#[derive(Debug, Clone)]
struct Param {
    pnu: u16,
    width: Option<Width>,
    writable: bool,
    /// Range for the model (raw), None for strings and open ranges.
    range: Option<(i64, i64)>,
    /// Smallest and largest raw value of the data type.
    bounds: Option<(i64, i64)>,
    /// Array elements.
    elements: Option<u16>,
}

/// The control words and bits used, by their spec names (3.7, 4.1).
#[derive(Debug, Clone, Copy)]
struct Controls {
    run: u16,
    direct: u16,
    up: u16,
    down: u16,
    release: u16,
    stop: u16,
    transfer: u16,
    toggle: u16,
    reserved: u16,
}

/// The generator for one suite (model).
pub(crate) struct PsdGen {
    pkw: PkwRules,
    record: RecordRules,
    params: Vec<Param>,
    ctl: Controls,
    /// Command codes of the spec table.
    known_ak: Vec<u8>,
    ak_max: u8,
    pnu_max: u16,
    /// End limits (par 43, par 42) at delivery, raw.
    limits: (i64, i64),
    /// Reference loop (par 45) at delivery.
    loop_len: i64,
    /// The injections the device takes (by name, as on the `ENV` line).
    envs: Vec<String>,
}

/// One injection of each kind the generator sends, with a harmless value: what is probed
/// before a run (the injections are optional in `drivespec-cyclic/1`).
pub(crate) const ENV_KINDS: [Env; 8] = [
    Env::Jam(false),
    Env::Displace(0),
    Env::MotorVoltage(240),
    Env::MissSteps(0),
    Env::Temperature(25),
    Env::Link(LinkEvent::Connected),
    Env::LoadTorque(0),
    Env::PowerCycle,
];

/// Requirement IDs of each template (checked against the spec in [`PsdGen::new`]).
fn reqs(t: Template) -> &'static [&'static str] {
    match t {
        Template::Read => &["PSD-PKW-011", "PSD-PKW-012", "PSD-PKW-038"],
        Template::Write => &["PSD-PKW-013", "PSD-PKW-014", "PSD-PKW-032", "PSD-PKW-034"],
        Template::OutOfRange => &["PSD-PKW-025", "PSD-PAR-RANGE-001", "PSD-PKW-022"],
        Template::ReadOnly => &["PSD-PKW-024", "PSD-PAR-READONLY-001"],
        Template::UnknownPnu => &["PSD-PKW-023", "PSD-PKW-019"],
        Template::AnyAk => &["PSD-PKW-009", "PSD-PKW-019", "PSD-PKW-031"],
        Template::IndOnScalar => &["PSD-PKW-027"],
        Template::BadSubindex => &["PSD-PKW-026", "PSD-PKW-020"],
        Template::WrongType => &["PSD-PKW-028"],
        Template::Spm => &["PSD-PKW-010"],
        Template::Handshake => &["PSD-PKW-003", "PSD-PKW-004", "PSD-PKW-005", "PSD-PKW-007"],
        Template::Par96 => &[
            "PSD-PAR-96-001",
            "PSD-PAR-96-005",
            "PSD-PAR-96-006",
            "PSD-PAR-96-007",
            "PSD-PAR-96-008",
        ],
        Template::Reserved => &["PSD-CTL-ZERO-001", "PSD-CTL-3-001", "PSD-CTL-7-001"],
        Template::Invalid => &["PSD-RUN-011", "PSD-STS-5-SET-2"],
        Template::Toggle => &["PSD-CTL-13-001", "PSD-STS-2-SET-1", "PSD-STS-2-RESET-1"],
        Template::Position => &[
            "PSD-POS-001",
            "PSD-POS-007",
            "PSD-POS-017",
            "PSD-STS-0-SET-1",
        ],
        Template::BeyondLimits => &["PSD-STS-12-SET-1", "PSD-STS-0-RESET-3"],
        Template::LoopPastLimit => &["PSD-STS-12-SET-2", "PSD-POS-016"],
        Template::Manual => &["PSD-RUN-004", "PSD-RUN-005", "PSD-RUN-006", "PSD-RUN-007"],
        Template::ReleaseWithdrawn => &["PSD-RUN-001", "PSD-CTL-4-003", "PSD-STS-5-SET-1"],
        Template::NewTarget => &["PSD-POS-002", "PSD-POS-003"],
        Template::TransferWithoutRelease => &["PSD-POS-004", "PSD-POS-005", "PSD-POS-006"],
        Template::Scaling => &["PSD-MAP-014", "PSD-MAP-015", "PSD-PKW-030"],
        Template::RecordRead => &["PSD-REC-001", "PSD-REC-008", "PSD-REC-009"],
        Template::RecordWrite => &["PSD-REC-003", "PSD-REC-004", "PSD-REC-005"],
        Template::RecordBad => &["PSD-REC-002", "PSD-REC-006", "PSD-REC-007"],
        Template::Environment => &[
            "PSD-OBST-001",
            "PSD-STS-10-SET-1",
            "PSD-STS-4-RESET-1",
            "PSD-STS-7-SET-1",
            "PSD-OUT-002",
            "PSD-ABORT-002",
            "PSD-STS-8-SET-1",
        ],
        Template::Obstruction => &["PSD-OBST-001", "PSD-STS-10-SET-1", "PSD-STS-10-RESET-1"],
        Template::Advance => &["PSD-ABORT-001"],
    }
}

fn class(t: Template) -> &'static str {
    match t {
        Template::Read => "pkw-read",
        Template::Write => "pkw-write",
        Template::OutOfRange => "pkw-write-out-of-range",
        Template::ReadOnly => "pkw-write-read-only",
        Template::UnknownPnu => "pkw-unknown-pnu",
        Template::AnyAk => "pkw-any-command-code",
        Template::IndOnScalar => "pkw-array-command-on-scalar",
        Template::BadSubindex => "pkw-bad-subindex",
        Template::WrongType => "pkw-wrong-width",
        Template::Spm => "pkw-spm-set",
        Template::Handshake => "pkw-handshake-violation",
        Template::Par96 => "pkw-par96",
        Template::Reserved => "control-reserved-bits",
        Template::Invalid => "control-invalid-combination",
        Template::Toggle => "control-toggle",
        Template::Position => "position",
        Template::BeyondLimits => "target-beyond-limits",
        Template::LoopPastLimit => "target-loop-past-limit",
        Template::Manual => "manual-run",
        Template::ReleaseWithdrawn => "release-withdrawn",
        Template::NewTarget => "new-target-during-run",
        Template::TransferWithoutRelease => "transfer-without-release",
        Template::Scaling => "scaling-change",
        Template::RecordRead => "record-read",
        Template::RecordWrite => "record-write",
        Template::RecordBad => "record-malformed",
        Template::Environment => "environment",
        Template::Obstruction => "obstruction",
        Template::Advance => "advance-time",
    }
}

impl PsdGen {
    /// The generator for the suite's model, sending only the injections of the kinds in
    /// `envs` ([`crate::cyclic_target::env_kind`]); an error names what the spec lacks.
    pub(crate) fn new(suite: &Psd4xxSuite<'_>, envs: Vec<String>) -> Result<PsdGen, String> {
        let family: &Family = suite.family();
        let rules = suite.reference().rules();
        let model = family
            .model(suite.model())
            .ok_or_else(|| format!("no model {}", suite.model()))?;
        engine::requirements_known(family, TEMPLATES.iter().flat_map(|(t, _)| reqs(*t)))?;
        let params: Vec<Param> = family
            .parameters
            .iter()
            .filter_map(|p: &Parameter| {
                let pnu = u16::try_from(p.number).ok()?;
                let r = family.resolve(p, Some(model)).range;
                Some(Param {
                    pnu,
                    width: Width::of_type(p.data_type),
                    writable: p.access.writable(),
                    range: r.and_then(|r| Some((r.min()?, r.max()?))),
                    bounds: p.data_type.bounds(),
                    elements: p.array.and_then(|n| u16::try_from(n).ok()),
                })
            })
            .collect();
        let value_of = |n: &str| -> Result<i64, String> {
            let p = family.parameter(n).ok_or_else(|| format!("no par {n}"))?;
            family
                .resolve(p, Some(model))
                .default
                .ok_or_else(|| format!("par {n} has no delivery value for {}", model.id))
        };
        let reserved = family
            .bitfield("control")
            .map(|b| {
                b.bits
                    .iter()
                    .filter(|x| x.reserved)
                    .filter_map(|x| 1u16.checked_shl(x.bit))
                    .fold(0u16, |a, m| a | m)
            })
            .unwrap_or(0);
        let ctl = Controls {
            run: control(family, "release-and-transfer")?,
            direct: control(family, "release-and-transfer-without-loop")?,
            up: control(family, "manual-run-larger")?,
            down: control(family, "manual-run-smaller")?,
            release: control(family, "release")?,
            stop: control(family, "stop")?,
            transfer: control_bit(family, "Transfer target value")?,
            toggle: control_bit(family, "Toggle bit")?,
            reserved,
        };
        let pkw = rules.pkw().clone();
        let known_ak: Vec<u8> = (0..=pkw.ak_max())
            .filter(|ak| pkw.command_info((*ak).into()).is_some())
            .collect();
        Ok(PsdGen {
            ak_max: pkw.ak_max(),
            pnu_max: pkw.pnu_max(),
            pkw,
            record: rules.record().clone(),
            params,
            ctl,
            known_ak,
            limits: (value_of("43")?, value_of("42")?),
            loop_len: value_of("45")?,
            envs,
        })
    }

    /// The next sequence.
    pub(crate) fn sequence(&self, rng: &mut Rng) -> Vec<Step> {
        let mut out = Vec::new();
        let n = rng.range(1, 5);
        for _ in 0..n {
            let t = self.template(rng);
            self.action(rng, t, &mut out);
        }
        out.truncate(MAX_STEPS);
        out
    }

    /// Whether the device takes injections of `kind`.
    fn takes(&self, kind: &str) -> bool {
        self.envs.iter().any(|k| k == kind)
    }

    fn template(&self, rng: &mut Rng) -> Template {
        let usable = |t: Template| match t {
            Template::Environment => !self.envs.is_empty(),
            Template::Obstruction => self.takes("jam"),
            _ => true,
        };
        engine::weighted(rng, TEMPLATES, usable, Template::Read)
    }

    fn push(&self, out: &mut Vec<Step>, t: Template, step: PsdStep, text: String) {
        out.push(Step {
            action: Action::Psd4xx(step),
            class: class(t).to_owned(),
            text,
            requirements: reqs(t).iter().map(|s| (*s).to_owned()).collect(),
        });
    }

    fn pkw_step(&self, out: &mut Vec<Step>, t: Template, p: PkwRequest) {
        let text = self.pkw.describe_request(&p);
        self.push(
            out,
            t,
            PsdStep::Pkw {
                pkw: PkwBlock {
                    ak: p.ak.0,
                    spm: p.spm,
                    pnu: p.pnu,
                    ind: p.ind,
                    pwe: p.pwe,
                },
            },
            text,
        );
    }

    /// A request as a block; None when the spec cannot encode it.
    fn encode(&self, r: &Request) -> Option<PkwRequest> {
        self.pkw.encode_request(r).ok()
    }

    /// A command, held for a few cycles, then (mostly) "no command" and its answer held: the
    /// handshake of 3.8.
    fn command(&self, rng: &mut Rng, out: &mut Vec<Step>, t: Template, p: PkwRequest) {
        self.pkw_step(out, t, p);
        let cycles = u32::try_from(rng.range(1, 8)).unwrap_or(1);
        self.hold(out, t, cycles);
        if chance(rng, 80) {
            if let Some(none) = self.encode(&Request::None) {
                self.pkw_step(out, t, none);
                self.hold(out, t, 2);
            }
        }
    }

    fn hold(&self, out: &mut Vec<Step>, t: Template, cycles: u32) {
        self.push(
            out,
            t,
            PsdStep::Hold { cycles },
            format!("{cycles} cycle(s)"),
        );
    }

    fn process(&self, out: &mut Vec<Step>, t: Template, control: u16, target: Option<i32>) {
        let text = match target {
            Some(x) => format!("control {control:#06x}, target {x}"),
            None => format!("control {control:#06x}"),
        };
        self.push(
            out,
            t,
            PsdStep::Process {
                control: Some(control),
                target,
            },
            text,
        );
    }

    fn offset(&self, out: &mut Vec<Step>, t: Template, control: u16, offset: i64) {
        self.push(
            out,
            t,
            PsdStep::Offset {
                control: Some(control),
                offset,
            },
            format!("control {control:#06x}, target actual {offset:+}"),
        );
    }

    fn until(&self, out: &mut Vec<Step>, t: Template, running: bool) {
        self.push(
            out,
            t,
            PsdStep::Until {
                running,
                max: WAIT_MAX,
            },
            if running {
                "until running".to_owned()
            } else {
                "until standstill".to_owned()
            },
        );
    }

    fn param(&self, rng: &mut Rng, f: impl Fn(&Param) -> bool) -> Option<Param> {
        let c: Vec<&Param> = self.params.iter().filter(|p| f(p)).collect();
        pick(rng, &c).map(|p| (*p).clone())
    }

    /// A value at, inside or next to the range edges.
    fn in_range(rng: &mut Rng, (lo, hi): (i64, i64)) -> i64 {
        match rng.range(0, 3) {
            0 => lo,
            1 => hi,
            _ => rng.range(lo, hi),
        }
    }

    /// A short positioning distance (increments), either direction.
    fn distance(rng: &mut Rng) -> i64 {
        let d = match rng.range(0, 3) {
            0 => rng.range(1, 100),
            1 => rng.range(100, 2_000),
            _ => rng.range(2_000, 8_000),
        };
        if chance(rng, 50) {
            -d
        } else {
            d
        }
    }

    fn action(&self, rng: &mut Rng, t: Template, out: &mut Vec<Step>) {
        let c = self.ctl;
        match t {
            Template::Read => {
                if let Some(p) = self.param(rng, |p| p.elements.is_none()) {
                    if let Some(r) = self.encode(&Request::Read {
                        pnu: p.pnu,
                        index: None,
                    }) {
                        self.command(rng, out, t, r);
                    }
                }
            }
            Template::Write | Template::OutOfRange => {
                let Some(p) = self.param(rng, |p| {
                    p.writable && p.range.is_some() && p.width.is_some() && p.pnu != 96
                }) else {
                    return;
                };
                let (Some((lo, hi)), Some(width)) = (p.range, p.width) else {
                    return;
                };
                let value = if t == Template::Write {
                    Self::in_range(rng, (lo, hi))
                } else {
                    let (tlo, thi) = p.bounds.unwrap_or((i64::MIN, i64::MAX));
                    match rng.range(0, 3) {
                        0 if lo > tlo => lo - 1,
                        1 if hi < thi => hi + 1,
                        2 => thi,
                        _ => tlo,
                    }
                };
                if let Some(r) = self.encode(&Request::Write {
                    pnu: p.pnu,
                    index: None,
                    width,
                    value,
                }) {
                    self.command(rng, out, t, r);
                    if chance(rng, 50) {
                        if let Some(r) = self.encode(&Request::Read {
                            pnu: p.pnu,
                            index: None,
                        }) {
                            self.command(rng, out, t, r);
                        }
                    }
                }
            }
            Template::ReadOnly => {
                let Some(p) = self.param(rng, |p| !p.writable && p.width.is_some()) else {
                    return;
                };
                if let Some(r) = self.encode(&Request::Write {
                    pnu: p.pnu,
                    index: None,
                    width: p.width.unwrap_or(Width::Word),
                    value: rng.range(0, 100),
                }) {
                    self.command(rng, out, t, r);
                }
            }
            Template::UnknownPnu => {
                let mut pnu = u16::try_from(rng.range(0, i64::from(self.pnu_max))).unwrap_or(0);
                if chance(rng, 30) {
                    pnu = self.pnu_max;
                }
                if self.params.iter().any(|p| p.pnu == pnu) {
                    pnu = self.pnu_max;
                }
                if let Some(r) = self.encode(&Request::Read { pnu, index: None }) {
                    self.command(rng, out, t, r);
                }
            }
            Template::AnyAk => {
                let ak = if chance(rng, 60) {
                    let undefined: Vec<u8> = (0..=self.ak_max)
                        .filter(|a| !self.known_ak.contains(a))
                        .collect();
                    pick(rng, &undefined).copied().unwrap_or(self.ak_max)
                } else {
                    u8::try_from(rng.range(0, i64::from(self.ak_max))).unwrap_or(0)
                };
                let pnu = self.param(rng, |_| true).map_or(self.pnu_max, |p| p.pnu);
                let p = PkwRequest {
                    ak: ak.into(),
                    spm: false,
                    pnu,
                    ind: u16::try_from(rng.range(0, 4)).unwrap_or(0),
                    pwe: u32::try_from(rng.range(0, 0xFFFF)).unwrap_or(0),
                };
                self.command(rng, out, t, p);
            }
            Template::IndOnScalar => {
                if let Some(p) = self.param(rng, |p| p.elements.is_none() && p.width.is_some()) {
                    let index = Some(u16::try_from(rng.range(0, 4)).unwrap_or(0));
                    let r = if chance(rng, 50) {
                        Request::Read { pnu: p.pnu, index }
                    } else {
                        Request::Write {
                            pnu: p.pnu,
                            index,
                            width: p.width.unwrap_or(Width::Word),
                            value: 1,
                        }
                    };
                    if let Some(r) = self.encode(&r) {
                        self.command(rng, out, t, r);
                    }
                }
            }
            Template::BadSubindex => {
                if let Some(p) = self.param(rng, |p| p.elements.is_some()) {
                    let n = p.elements.unwrap_or(0);
                    let index = if chance(rng, 50) {
                        n
                    } else {
                        u16::try_from(rng.range(i64::from(n), i64::from(n) + 40)).unwrap_or(n)
                    };
                    let r = if chance(rng, 70) {
                        Request::Read {
                            pnu: p.pnu,
                            index: Some(index),
                        }
                    } else {
                        Request::Count { pnu: p.pnu }
                    };
                    if let Some(r) = self.encode(&r) {
                        self.command(rng, out, t, r);
                    }
                }
            }
            Template::WrongType => {
                if let Some(p) = self.param(rng, |p| p.writable && p.width.is_some()) {
                    let width = match p.width {
                        Some(Width::Word) => Width::Dword,
                        _ => Width::Word,
                    };
                    if let Some(r) = self.encode(&Request::Write {
                        pnu: p.pnu,
                        index: None,
                        width,
                        value: 0,
                    }) {
                        self.command(rng, out, t, r);
                    }
                }
            }
            Template::Spm => {
                if let Some(p) = self.param(rng, |p| p.elements.is_none()) {
                    if let Some(mut r) = self.encode(&Request::Read {
                        pnu: p.pnu,
                        index: None,
                    }) {
                        r.spm = true;
                        self.command(rng, out, t, r);
                    }
                }
            }
            Template::Handshake => {
                // Two or three commands back to back, each held, never "no command" between.
                let k = rng.range(2, 3);
                for _ in 0..k {
                    let Some(p) = self.param(rng, |p| p.elements.is_none()) else {
                        return;
                    };
                    let r = match (p.writable, p.range, p.width) {
                        (true, Some(range), Some(width)) if chance(rng, 50) && p.pnu != 96 => {
                            Request::Write {
                                pnu: p.pnu,
                                index: None,
                                width,
                                value: Self::in_range(rng, range),
                            }
                        }
                        _ => Request::Read {
                            pnu: p.pnu,
                            index: None,
                        },
                    };
                    if let Some(r) = self.encode(&r) {
                        self.pkw_step(out, t, r);
                        let cycles = u32::try_from(rng.range(1, 6)).unwrap_or(1);
                        self.hold(out, t, cycles);
                    }
                }
            }
            Template::Par96 => {
                // A parameter changed and saved (par 96 = 1), maybe changed again, then a par
                // 96 command (or a refused value), and the parameter read back.
                let Some(p) = self.param(rng, |p| {
                    p.writable && p.range.is_some() && p.width.is_some() && p.pnu != 96
                }) else {
                    return;
                };
                let (Some(range), Some(width)) = (p.range, p.width) else {
                    return;
                };
                let write = |pnu: u16, width: Width, value: i64| {
                    self.encode(&Request::Write {
                        pnu,
                        index: None,
                        width,
                        value,
                    })
                };
                let none = self.encode(&Request::None);
                let send = |out: &mut Vec<Step>, r: Option<PkwRequest>| {
                    if let (Some(r), Some(none)) = (r, none) {
                        self.pkw_step(out, t, r);
                        self.pkw_step(out, t, none);
                    }
                };
                send(out, write(p.pnu, width, Self::in_range(rng, range)));
                send(out, write(96, Width::Word, 1));
                if chance(rng, 50) {
                    send(out, write(p.pnu, width, Self::in_range(rng, range)));
                }
                let value = match rng.range(0, 9) {
                    0 => 0,
                    1 => 2,
                    2 => -7,
                    3 => 1,
                    _ => rng.range(-6, -1),
                };
                send(out, write(96, Width::Word, value));
                self.until(out, t, false);
                send(
                    out,
                    self.encode(&Request::Read {
                        pnu: p.pnu,
                        index: None,
                    }),
                );
            }
            Template::Reserved => {
                let bits: Vec<u16> = (0..16)
                    .filter_map(|b| 1u16.checked_shl(b))
                    .filter(|m| c.reserved & m != 0)
                    .collect();
                let extra = pick(rng, &bits).copied().unwrap_or(0);
                let base = *pick(rng, &[0, c.release, c.run, c.up]).unwrap_or(&0);
                let all = if chance(rng, 20) { c.reserved } else { extra };
                self.offset(out, t, base | all, Self::distance(rng));
                self.hold(out, t, u32::try_from(rng.range(2, 20)).unwrap_or(2));
            }
            Template::Invalid => {
                let word = *pick(
                    rng,
                    &[
                        c.up | c.down | c.release,
                        c.up | c.down,
                        c.up | c.run,
                        c.down | c.run,
                        c.up | c.down | c.run,
                        c.up | c.direct,
                    ],
                )
                .unwrap_or(&(c.up | c.down));
                if chance(rng, 50) {
                    self.offset(out, t, c.run, Self::distance(rng));
                    self.until(out, t, true);
                }
                self.offset(out, t, word, Self::distance(rng));
                self.hold(out, t, u32::try_from(rng.range(2, 30)).unwrap_or(2));
                self.process(out, t, c.stop, None);
            }
            Template::Toggle => {
                let base = *pick(rng, &[0, c.release, c.run]).unwrap_or(&0);
                for _ in 0..rng.range(1, 4) {
                    let on = if chance(rng, 50) { c.toggle } else { 0 };
                    self.process(out, t, base | on, None);
                }
            }
            Template::Position => {
                let word = if chance(rng, 70) { c.run } else { c.direct };
                self.offset(out, t, word, Self::distance(rng));
                if chance(rng, 80) {
                    self.until(out, t, true);
                    self.until(out, t, false);
                } else {
                    self.hold(out, t, u32::try_from(rng.range(1, 40)).unwrap_or(1));
                }
            }
            Template::BeyondLimits => {
                let (lo, hi) = self.limits;
                let target = match rng.range(0, 3) {
                    0 => hi.saturating_add(rng.range(1, 1_000)),
                    1 => lo.saturating_sub(rng.range(1, 1_000)),
                    2 => i64::from(i32::MAX),
                    _ => i64::from(i32::MIN),
                };
                let target = i32::try_from(target).unwrap_or(i32::MAX);
                self.process(out, t, c.run, Some(target));
                self.hold(out, t, u32::try_from(rng.range(2, 20)).unwrap_or(2));
            }
            Template::LoopPastLimit => {
                // The loop runs past the limit on the side it approaches from.
                let (lo, hi) = self.limits;
                let edge = if self.loop_len >= 0 { lo } else { hi };
                let inside = rng.range(0, self.loop_len.abs().saturating_sub(1).max(0));
                let target = if self.loop_len >= 0 {
                    edge.saturating_add(inside)
                } else {
                    edge.saturating_sub(inside)
                };
                let target = i32::try_from(target).unwrap_or(i32::MAX);
                self.process(out, t, c.run, Some(target));
                self.hold(out, t, u32::try_from(rng.range(2, 20)).unwrap_or(2));
            }
            Template::Manual => {
                let word = if chance(rng, 50) { c.up } else { c.down };
                self.process(out, t, word, None);
                self.until(out, t, true);
                self.hold(out, t, u32::try_from(rng.range(1, 50)).unwrap_or(1));
                let end = if chance(rng, 50) { c.release } else { c.stop };
                self.process(out, t, end, None);
                self.until(out, t, false);
            }
            Template::ReleaseWithdrawn => {
                self.offset(out, t, c.run, 8_000 * if chance(rng, 50) { 1 } else { -1 });
                self.until(out, t, true);
                self.hold(out, t, u32::try_from(rng.range(1, 20)).unwrap_or(1));
                self.process(out, t, c.stop, None);
                self.until(out, t, false);
            }
            Template::NewTarget => {
                self.offset(out, t, c.run, 8_000);
                self.until(out, t, true);
                self.hold(out, t, u32::try_from(rng.range(1, 15)).unwrap_or(1));
                self.offset(out, t, c.run, Self::distance(rng));
                self.until(out, t, false);
            }
            Template::TransferWithoutRelease => {
                self.offset(out, t, c.transfer, Self::distance(rng));
                self.hold(out, t, u32::try_from(rng.range(1, 5)).unwrap_or(1));
                self.process(out, t, c.release, None);
                self.until(out, t, true);
                self.until(out, t, false);
            }
            Template::Scaling => {
                // Par 37-41 (direction, factors, offset, mapping end), at a standstill or
                // in the middle of a run.
                let running = chance(rng, 50);
                if running {
                    self.offset(out, t, c.run, 8_000);
                    self.until(out, t, true);
                }
                let Some(p) = self.param(rng, |p| {
                    (37..=41).contains(&p.pnu) && p.writable && p.range.is_some()
                }) else {
                    return;
                };
                let (Some(range), Some(width)) = (p.range, p.width) else {
                    return;
                };
                if let Some(r) = self.encode(&Request::Write {
                    pnu: p.pnu,
                    index: None,
                    width,
                    value: Self::in_range(rng, range),
                }) {
                    self.command(rng, out, t, r);
                }
                if running {
                    self.until(out, t, false);
                }
            }
            Template::RecordRead => {
                let index = match self.param(rng, |_| true) {
                    Some(p) if chance(rng, 85) => p.pnu,
                    _ => self.pnu_max,
                };
                self.push(
                    out,
                    t,
                    PsdStep::RecordRead { index },
                    format!("record read {index}"),
                );
            }
            Template::RecordWrite => {
                let Some(p) = self.param(rng, |p| {
                    p.writable && p.range.is_some() && p.width.is_some() && p.pnu != 96
                }) else {
                    return;
                };
                let (Some(range), Some(width)) = (p.range, p.width) else {
                    return;
                };
                let control = match rng.range(0, 3) {
                    0 => self.record.control_ignore(),
                    1 => rng.byte(),
                    _ => 1,
                };
                let value = if chance(rng, 75) {
                    Self::in_range(rng, range)
                } else {
                    range.1.saturating_add(1)
                };
                let w = RecordWrite {
                    index: p.pnu,
                    control,
                    width,
                    value,
                };
                if let Ok(data) = w.to_bytes(&self.record) {
                    self.record_write(out, t, p.pnu, data);
                    if chance(rng, 50) {
                        self.push(
                            out,
                            t,
                            PsdStep::RecordRead { index: p.pnu },
                            format!("record read {}", p.pnu),
                        );
                    }
                }
            }
            Template::RecordBad => {
                let Some(p) = self.param(rng, |p| p.width.is_some()) else {
                    return;
                };
                let good = self.record.write_len(p.width.unwrap_or(Width::Word));
                // At least one byte: an empty write is no `WRITE` line at all.
                let len = match rng.range(0, 3) {
                    0 => 1,
                    1 => good.saturating_sub(1),
                    2 => good.saturating_add(1),
                    _ => below(rng, 12),
                }
                .max(1);
                let data: Vec<u8> = (0..len)
                    .map(|i| if i == 0 { 1 } else { rng.byte() })
                    .collect();
                let index = if chance(rng, 80) { p.pnu } else { self.pnu_max };
                self.record_write(out, t, index, data);
            }
            Template::Environment => {
                let mut env = match rng.range(0, 12) {
                    0 => Env::Jam(true),
                    1 => Env::Jam(false),
                    2 => Env::Displace(Self::distance(rng)),
                    3 => Env::MotorVoltage(u16::try_from(rng.range(100, 300)).unwrap_or(240)),
                    4 => Env::MissSteps(rng.range(-50, 50)),
                    5 => Env::Temperature(i16::try_from(rng.range(-20, 95)).unwrap_or(25)),
                    6 => Env::Link(LinkEvent::Lost),
                    7 => Env::Link(LinkEvent::Connected),
                    8 => Env::Link(LinkEvent::IopsBad),
                    9 => Env::Link(LinkEvent::IopsGood),
                    10 => Env::LoadTorque(u16::try_from(rng.range(0, 200)).unwrap_or(0)),
                    _ => Env::PowerCycle,
                };
                if !self.takes(&env_kind(&env.to_string())) {
                    let Some(other) = ENV_KINDS
                        .iter()
                        .find(|e| self.takes(&env_kind(&e.to_string())))
                        .copied()
                    else {
                        return;
                    };
                    env = other;
                }
                if chance(rng, 50) {
                    self.offset(out, t, c.run, Self::distance(rng));
                    self.until(out, t, true);
                }
                self.push(
                    out,
                    t,
                    PsdStep::Env {
                        env: env.to_string(),
                    },
                    format!("env {env}"),
                );
                self.hold(out, t, u32::try_from(rng.range(1, 30)).unwrap_or(1));
                if chance(rng, 50) {
                    self.until(out, t, false);
                }
            }
            Template::Obstruction => {
                if chance(rng, 30) {
                    self.push(
                        out,
                        t,
                        PsdStep::Env {
                            env: Env::Jam(true).to_string(),
                        },
                        "env jam 1".to_owned(),
                    );
                }
                let word = *pick(rng, &[c.run, c.direct, c.up, c.down]).unwrap_or(&c.run);
                self.offset(out, t, word, 8_000);
                self.until(out, t, true);
                self.push(
                    out,
                    t,
                    PsdStep::Env {
                        env: Env::Jam(true).to_string(),
                    },
                    "env jam 1".to_owned(),
                );
                self.until(out, t, false);
                self.hold(out, t, u32::try_from(rng.range(1, 20)).unwrap_or(1));
                self.push(
                    out,
                    t,
                    PsdStep::Env {
                        env: Env::Jam(false).to_string(),
                    },
                    "env jam 0".to_owned(),
                );
                if chance(rng, 50) {
                    self.offset(out, t, c.run, Self::distance(rng));
                    self.until(out, t, false);
                }
            }
            Template::Advance => {
                let us = u64::try_from(rng.range(1, 3_000_000)).unwrap_or(1);
                self.push(
                    out,
                    t,
                    PsdStep::Advance { us },
                    format!("{} ms without a bus cycle", us / 1000),
                );
                self.hold(out, t, u32::try_from(rng.range(1, 5)).unwrap_or(1));
            }
        }
    }

    fn record_write(&self, out: &mut Vec<Step>, t: Template, index: u16, data: Vec<u8>) {
        let text = format!("record write {index}: {} byte(s)", data.len());
        self.push(out, t, PsdStep::RecordWrite { index, hex: data }, text);
    }
}
