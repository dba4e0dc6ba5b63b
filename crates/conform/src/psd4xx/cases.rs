//! Case generation for the PSD4xx suite: data-driven from the spec's parameter table (ranges
//! per model), PKW command and error tables, control-word values and `sequence` vectors, plus
//! hand-written positioning and status cases.

use super::scenario::{self, Judge, ScenarioStep, Setup, SpecStep, Target, TargetName};
use crate::case::{CaseInfo, Role};
use crate::cyclic::Env;
use drivespec_positioner::script::kebab;
use drivespec_positioner::step::{read_sequence, StateValue, Wait};
use drivespec_psd4xx::model::{Drive, LinkEvent};
use drivespec_psd4xx::step::{Direction, Event, PsdSequence, Step};
use drivespec_psd4xx::{PkwRequest, PkwRules, RecordWrite, Request, Rules, Width};
use drivespec_spec::{Access, DeviceModel, Family, FamilyId, Level, Parameter, VectorKind};

/// Cycles a PKW command is repeated beyond the longest save before the case moves on
/// (PSD-PKW-002).
pub(crate) const PKW_MAX_CYCLES: u32 = 8;

/// One step of a case.
pub type StepDef = crate::cyclic_session::StepDef<Step>;

pub use crate::cyclic_session::{OpenPoint, Tolerance, MOTION};

/// Tolerance of the PKW and record cases: the answer may come one cycle late.
pub const EXCHANGE: Tolerance = Tolerance {
    cycles: 1,
    position: 0,
    speed: 0,
    motion: false,
};

/// The requirements that state a parameter's row of tables 3.3 and 3.4 (data type, range,
/// delivery value, back-up), by parameter number: each is judged by the parameter's reads
/// (the delivery value exactly, or type and length where the manual gives an example), its
/// writes at the range edges and in the gaps of the range, and its back-up case.
const ROW: &[(u32, &[&str])] = &[
    (1, &["PSD-PAR-1-001"]),
    (2, &["PSD-PAR-2-001"]),
    (3, &["PSD-PAR-3-001", "PSD-MAP-003"]),
    (4, &["PSD-PAR-4-001"]),
    (5, &["PSD-PAR-5-001"]),
    (6, &["PSD-PAR-6-001"]),
    (7, &["PSD-PAR-7-001"]),
    (8, &["PSD-PAR-8-001"]),
    (9, &["PSD-PAR-9-001"]),
    (10, &["PSD-PAR-10-001"]),
    (11, &["PSD-PAR-11-001"]),
    (12, &["PSD-PAR-12-001"]),
    (14, &["PSD-PAR-14-001"]),
    (32, &["PSD-PAR-32-002", "PSD-PAR-DELIVERY-001"]),
    (33, &["PSD-PAR-33-002", "PSD-PAR-DELIVERY-001"]),
    (37, &["PSD-PAR-37-002", "PSD-PAR-DELIVERY-001"]),
    (
        38,
        &["PSD-PAR-38-001", "PSD-MAP-025", "PSD-PAR-DELIVERY-001"],
    ),
    (
        39,
        &["PSD-PAR-38-001", "PSD-MAP-025", "PSD-PAR-DELIVERY-001"],
    ),
    (40, &["PSD-PAR-40-001", "PSD-PAR-DELIVERY-001"]),
    (
        41,
        &[
            "PSD-PAR-41-003",
            "PSD-MODEL-P41",
            "PSD-MAP-006",
            "PSD-MAP-029",
            "PSD-PAR-DELIVERY-001",
        ],
    ),
    (
        42,
        &[
            "PSD-PAR-41-003",
            "PSD-MODEL-P42",
            "PSD-MAP-003",
            "PSD-PAR-DELIVERY-001",
        ],
    ),
    (
        43,
        &[
            "PSD-PAR-41-003",
            "PSD-MODEL-P43",
            "PSD-MAP-003",
            "PSD-MAP-029",
            "PSD-PAR-DELIVERY-001",
        ],
    ),
    (44, &["PSD-PAR-44-002", "PSD-PAR-DELIVERY-001"]),
    (45, &["PSD-PAR-45-003", "PSD-PAR-DELIVERY-001"]),
    (47, &["PSD-PAR-47-001", "PSD-PAR-DELIVERY-001"]),
    (
        53,
        &[
            "PSD-PAR-53-001",
            "PSD-MODEL-P53",
            "PSD-PAR-MODEL-001",
            "PSD-PAR-DELIVERY-001",
        ],
    ),
    (
        56,
        &[
            "PSD-PAR-56-001",
            "PSD-MODEL-P56",
            "PSD-PAR-MODEL-001",
            "PSD-PAR-DELIVERY-001",
        ],
    ),
    (57, &["PSD-PAR-57-001", "PSD-PAR-DELIVERY-001"]),
    (
        58,
        &[
            "PSD-PAR-58-001",
            "PSD-MODEL-P58",
            "PSD-PAR-MODEL-001",
            "PSD-PAR-DELIVERY-001",
        ],
    ),
    (
        59,
        &[
            "PSD-PAR-59-001",
            "PSD-MODEL-P59",
            "PSD-PAR-MODEL-001",
            "PSD-PAR-DELIVERY-001",
        ],
    ),
    (
        63,
        &[
            "PSD-PAR-63-001",
            "PSD-MODEL-P63",
            "PSD-PAR-MODEL-001",
            "PSD-PAR-DELIVERY-001",
        ],
    ),
    (
        64,
        &["PSD-MODEL-P64", "PSD-PAR-MODEL-001", "PSD-PAR-DELIVERY-001"],
    ),
    (
        65,
        &[
            "PSD-PAR-65-001",
            "PSD-MODEL-P65",
            "PSD-PAR-MODEL-001",
            "PSD-PAR-DELIVERY-001",
        ],
    ),
    (
        66,
        &["PSD-MODEL-P66", "PSD-PAR-MODEL-001", "PSD-PAR-DELIVERY-001"],
    ),
    (70, &["PSD-PAR-70-001", "PSD-PAR-DELIVERY-001"]),
    (71, &["PSD-PAR-71-001", "PSD-PAR-DELIVERY-001"]),
    (72, &["PSD-PAR-72-001", "PSD-PAR-DELIVERY-001"]),
    (76, &["PSD-PAR-76-001", "PSD-PAR-DELIVERY-001"]),
    (80, &["PSD-PAR-80-001", "PSD-PAR-DELIVERY-001"]),
    (81, &["PSD-PAR-80-001", "PSD-PAR-DELIVERY-001"]),
    (82, &["PSD-PAR-80-001", "PSD-PAR-DELIVERY-001"]),
    (83, &["PSD-PAR-80-001", "PSD-PAR-DELIVERY-001"]),
    (84, &["PSD-PAR-80-001", "PSD-PAR-DELIVERY-001"]),
    (85, &["PSD-PAR-80-001", "PSD-PAR-DELIVERY-001"]),
    (86, &["PSD-PAR-80-001", "PSD-PAR-DELIVERY-001"]),
    (87, &["PSD-PAR-80-001", "PSD-PAR-DELIVERY-001"]),
    (88, &["PSD-PAR-80-001", "PSD-PAR-DELIVERY-001"]),
    (89, &["PSD-PAR-80-001", "PSD-PAR-DELIVERY-001"]),
    (90, &["PSD-PAR-90-001", "PSD-PAR-DELIVERY-001"]),
    (91, &["PSD-PAR-91-001", "PSD-PAR-DELIVERY-001"]),
];

/// The row requirements of parameter `number` ([`ROW`]).
fn row(number: u32) -> &'static [&'static str] {
    ROW.iter()
        .find(|(n, _)| *n == number)
        .map_or(&[], |(_, r)| r)
}

/// `reqs` followed by the row requirements of parameter `number`.
fn with_row<'a>(reqs: &[&'a str], number: u32) -> Vec<&'a str> {
    let mut all = reqs.to_vec();
    all.extend_from_slice(row(number));
    all
}

/// A generated case.
#[derive(Debug, Clone, PartialEq)]
pub struct PsdCase {
    /// The steps.
    pub steps: Vec<StepDef>,
    /// Tolerances.
    pub tol: Tolerance,
    /// Whether the report gets a position/speed/status plot.
    pub plot: bool,
    /// The point the manual leaves open in a motion case.
    pub open: Option<OpenPoint>,
}

struct Gen<'a> {
    family: &'a Family,
    model: &'a DeviceModel,
    pkw: &'a PkwRules,
    drive_rules: &'a Rules,
    errors: Vec<String>,
    out: Vec<(CaseInfo, PsdCase)>,
}

/// Control-word values by their spec name (bitfield `control`, 4.1).
pub fn control(family: &Family, name: &str) -> Result<u16, String> {
    family
        .bitfield("control")
        .and_then(|b| b.values.iter().find(|v| v.name == name))
        .and_then(|v| u16::try_from(v.value).ok())
        .ok_or_else(|| format!("no control-word value {name:?} in bitfield control"))
}

/// The control bit named `name` as a mask (bitfield `control`, 3.7).
pub fn control_bit(family: &Family, name: &str) -> Result<u16, String> {
    family
        .bitfield("control")
        .and_then(|b| b.bits.iter().find(|x| x.name == name))
        .and_then(|x| 1u16.checked_shl(x.bit))
        .ok_or_else(|| format!("no control bit {name:?}"))
}

fn step(role: Role, text: impl Into<String>, action: Step) -> StepDef {
    StepDef {
        role,
        text: text.into(),
        action,
    }
}

/// The control voltage switched off and on, then five cycles to settle (3.3 par 96).
fn power_cycle(steps: &mut Vec<StepDef>) {
    steps.push(step(
        Role::Check,
        "power cycle",
        Step::Env {
            env: Env::PowerCycle.to_string(),
        },
    ));
    steps.push(step(Role::Check, "settle", Step::Hold { cycles: 5 }));
}

impl Gen<'_> {
    fn push(&mut self, id: String, reqs: &[&str], description: String, case: PsdCase) {
        let mut requirements: Vec<String> = Vec::new();
        let mut level = Level::Informative;
        for r in reqs {
            match self.family.requirement(r) {
                Some(q) => {
                    level = level.min(q.level);
                    requirements.push(q.id.clone());
                }
                None => self.errors.push(format!("{id}: unknown requirement {r}")),
            }
        }
        requirements.sort();
        requirements.dedup();
        let steps = case.steps.iter().map(|s| s.text.clone()).collect();
        self.out.push((
            CaseInfo {
                id,
                family: FamilyId::Psd4xx,
                requirements,
                level,
                description,
                steps,
            },
            case,
        ));
    }

    fn request(&mut self, r: Request) -> PkwRequest {
        match self.pkw.encode_request(&r) {
            Ok(p) => p,
            Err(e) => {
                self.errors.push(format!("cannot encode {r:?}: {e}"));
                PkwRequest::default()
            }
        }
    }

    fn none(&mut self) -> PkwRequest {
        self.request(Request::None)
    }

    /// A PKW command, the response held for 3 cycles, then "no command".
    fn exchange(&mut self, steps: &mut Vec<StepDef>, role: Role, text: &str, r: Request) {
        let req = self.request(r);
        let none = self.none();
        steps.push(step(role, text, Step::Pkw { pkw: req.into() }));
        steps.push(step(
            role,
            "command repeated: the response is held",
            Step::Hold { cycles: 3 },
        ));
        steps.push(step(
            role,
            "no command: no response",
            Step::Pkw { pkw: none.into() },
        ));
        steps.push(step(role, "no response held", Step::Hold { cycles: 2 }));
    }

    fn range(&self, p: &Parameter) -> Option<(i64, i64)> {
        let r = self.family.resolve(p, Some(self.model)).range?;
        Some((r.min()?, r.max()?))
    }

    fn width(p: &Parameter) -> Option<Width> {
        Width::of_type(p.data_type)
    }

    fn pkw_cases(&mut self) {
        let params: Vec<&Parameter> = self.family.parameters.iter().collect();
        for p in params {
            let Ok(pnu) = u16::try_from(p.number) else {
                continue;
            };
            let num = p.number;
            if let Some(n) = p.array {
                // Par. 13: segments, one past the end, count.
                for i in 0..=n {
                    let Ok(index) = u16::try_from(i) else {
                        continue;
                    };
                    let mut steps = Vec::new();
                    let text = format!("read par {num} element {i}");
                    self.exchange(
                        &mut steps,
                        Role::Check,
                        &text,
                        Request::Read {
                            pnu,
                            index: Some(index),
                        },
                    );
                    let (id, reqs): (String, &[&str]) = if i < n {
                        (
                            format!("psd4xx/pkw/array/{num}/element-{i}"),
                            &[
                                "PSD-PKW-015",
                                "PSD-PKW-020",
                                "PSD-PKW-035",
                                "PSD-PKW-036",
                                "PSD-PKW-037",
                            ],
                        )
                    } else {
                        (
                            format!("psd4xx/pkw/array/{num}/bad-subindex"),
                            &["PSD-PKW-026", "PSD-PKW-019", "PSD-PKW-022"],
                        )
                    };
                    self.push(
                        id,
                        reqs,
                        text,
                        PsdCase {
                            steps,
                            tol: EXCHANGE,
                            plot: false,
                            open: None,
                        },
                    );
                }
                let mut steps = Vec::new();
                self.exchange(
                    &mut steps,
                    Role::Check,
                    "number of elements",
                    Request::Count { pnu },
                );
                self.push(
                    format!("psd4xx/pkw/array/{num}/count"),
                    &["PSD-PKW-018"],
                    format!("command 9 on par {num}: number of elements"),
                    PsdCase {
                        steps,
                        tol: EXCHANGE,
                        plot: false,
                        open: None,
                    },
                );
                continue;
            }
            // Read.
            let mut steps = Vec::new();
            self.exchange(
                &mut steps,
                Role::Check,
                &format!("read par {num}"),
                Request::Read { pnu, index: None },
            );
            let mut reqs = vec![
                "PSD-PKW-001",
                "PSD-PKW-011",
                "PSD-PKW-012",
                "PSD-PKW-006",
                "PSD-PKW-008",
                "PSD-PKW-009",
                "PSD-PKW-021",
            ];
            if Self::width(p) == Some(Width::Word) {
                reqs.push("PSD-PKW-038");
            }
            reqs.extend_from_slice(row(num));
            self.push(
                format!("psd4xx/pkw/read/{num}"),
                &reqs,
                format!("read par {num} ({}) through PKW", p.name),
                PsdCase {
                    steps,
                    tol: EXCHANGE,
                    plot: false,
                    open: None,
                },
            );
            let Some(width) = Self::width(p) else {
                continue;
            };
            if !p.access.writable() {
                let mut steps = Vec::new();
                self.exchange(
                    &mut steps,
                    Role::Check,
                    &format!("write par {num}"),
                    Request::Write {
                        pnu,
                        index: None,
                        width,
                        value: 0,
                    },
                );
                let reqs: &[&str] = if p.access == Access::Pd {
                    &["PSD-PKW-024", "PSD-PD-009"]
                } else {
                    &["PSD-PKW-024", "PSD-PAR-READONLY-001"]
                };
                self.push(
                    format!("psd4xx/pkw/write/{num}/read-only"),
                    reqs,
                    format!("write to par {num} ({}): error 1", p.name),
                    PsdCase {
                        steps,
                        tol: EXCHANGE,
                        plot: false,
                        open: None,
                    },
                );
                continue;
            }
            if num == 96 {
                continue; // the par96 group
            }
            let Some((min, max)) = self.range(p) else {
                continue;
            };
            let (tlo, thi) = p.data_type.bounds().unwrap_or((i64::MIN, i64::MAX));
            let mut edges = vec![("min".to_owned(), min, true), ("max".to_owned(), max, true)];
            if min > tlo {
                edges.push(("below-min".to_owned(), min - 1, false));
            }
            if max < thi {
                edges.push(("above-max".to_owned(), max + 1, false));
            }
            edges.extend(self.gaps(p));
            for (name, value, ok) in edges {
                let mut steps = Vec::new();
                self.exchange(
                    &mut steps,
                    Role::Check,
                    &format!("write par {num} = {value}"),
                    Request::Write {
                        pnu,
                        index: None,
                        width,
                        value,
                    },
                );
                self.exchange(
                    &mut steps,
                    Role::Check,
                    &format!("read par {num} back"),
                    Request::Read { pnu, index: None },
                );
                let reqs: &[&str] = match (ok, width) {
                    (true, Width::Word) => {
                        &["PSD-PKW-013", "PSD-PKW-032", "PSD-PKW-033", "PSD-PKW-034"]
                    }
                    (true, Width::Dword) => {
                        &["PSD-PKW-014", "PSD-PKW-032", "PSD-PKW-033", "PSD-PKW-034"]
                    }
                    (false, _) => &[
                        "PSD-PKW-025",
                        "PSD-PAR-RANGE-001",
                        "PSD-PKW-019",
                        "PSD-PKW-022",
                    ],
                };
                self.push(
                    format!("psd4xx/pkw/write/{num}/{name}"),
                    &with_row(reqs, num),
                    format!(
                        "write {value} to par {num} ({}) on {}",
                        p.name, self.model.id
                    ),
                    PsdCase {
                        steps,
                        tol: EXCHANGE,
                        plot: false,
                        open: None,
                    },
                );
            }
            // Wrong data type (PSD-PKW-028).
            let other = match width {
                Width::Word => Width::Dword,
                Width::Dword => Width::Word,
            };
            let mut steps = Vec::new();
            self.exchange(
                &mut steps,
                Role::Check,
                &format!("write par {num} with the other width"),
                Request::Write {
                    pnu,
                    index: None,
                    width: other,
                    value: 0,
                },
            );
            self.push(
                format!("psd4xx/pkw/error/wrong-type/{num}"),
                &["PSD-PKW-028", "PSD-PKW-019"],
                format!(
                    "a {} write command to par {num}: error 5",
                    if other == Width::Word {
                        "word"
                    } else {
                        "double-word"
                    }
                ),
                PsdCase {
                    steps,
                    tol: EXCHANGE,
                    plot: false,
                    open: None,
                },
            );
        }
        // Unknown parameter numbers.
        let max = self.pkw.pnu_max();
        for pnu in [0u16, 15, 99, max] {
            if self
                .family
                .parameters
                .iter()
                .any(|p| p.number == u32::from(pnu))
            {
                continue;
            }
            let mut steps = Vec::new();
            self.exchange(
                &mut steps,
                Role::Check,
                &format!("read par {pnu}"),
                Request::Read { pnu, index: None },
            );
            self.push(
                format!("psd4xx/pkw/unknown/{pnu}"),
                &["PSD-PKW-023", "PSD-PKW-019", "PSD-PKW-022"],
                format!("read of the unknown par {pnu}: error 0"),
                PsdCase {
                    steps,
                    tol: EXCHANGE,
                    plot: false,
                    open: None,
                },
            );
        }
    }

    /// The values around each gap of a range of several intervals (par 45: -9 … 9 but 0):
    /// the inner edges are accepted, the values just inside a gap refused (error 2).
    fn gaps(&self, p: &Parameter) -> Vec<(String, i64, bool)> {
        let Some(r) = self.family.resolve(p, Some(self.model)).range else {
            return Vec::new();
        };
        let name = |what: &str, v: i64| {
            if v < 0 {
                format!("{what}-minus-{}", v.unsigned_abs())
            } else {
                format!("{what}-{v}")
            }
        };
        let mut intervals = r.intervals().to_vec();
        intervals.sort_unstable();
        let mut out = Vec::new();
        for w in intervals.windows(2) {
            let [[_, below], [above, _]] = *w else {
                continue;
            };
            if above.saturating_sub(below) < 2 {
                continue;
            }
            out.push((name("edge", below), below, true));
            out.push((name("gap", below + 1), below + 1, false));
            if above - 1 > below + 1 {
                out.push((name("gap", above - 1), above - 1, false));
            }
            out.push((name("edge", above), above, true));
        }
        out.dedup_by_key(|(n, _, _)| n.clone());
        out
    }

    /// One case per parameter the manual marks backed up (table 3.3, column Back-up): a value
    /// other than the delivery value written, saved with par 96 = 1, a power cycle, the value
    /// read back. Judged as the par 96 cases are, by the order of the answers: saving can take
    /// up to 1 s (4.7), the command is repeated until answered.
    fn backup_cases(&mut self) {
        let params: Vec<&Parameter> = self
            .family
            .parameters
            .iter()
            .filter(|p| p.saved == Some(true) && p.access.writable() && p.number != 96)
            .collect();
        for p in params {
            let (Ok(pnu), Some(width), Some((min, max))) =
                (u16::try_from(p.number), Self::width(p), self.range(p))
            else {
                continue;
            };
            let num = p.number;
            let default = self.family.resolve(p, Some(self.model)).default;
            let value = if default == Some(max) { min } else { max };
            let mut steps = Vec::new();
            self.exchange(
                &mut steps,
                Role::Check,
                &format!("write par {num} = {value}"),
                Request::Write {
                    pnu,
                    index: None,
                    width,
                    value,
                },
            );
            self.write_pkw(&mut steps, 96, 1);
            power_cycle(&mut steps);
            self.exchange(
                &mut steps,
                Role::Check,
                &format!("read par {num} after power-up"),
                Request::Read { pnu, index: None },
            );
            self.push(
                format!("psd4xx/pkw/backup/{num}"),
                &with_row(&["PSD-PAR-SAVE-001", "PSD-PAR-96-007"], num),
                format!(
                    "par {num} ({}) = {value}, saved, power cycle: the value is kept",
                    p.name
                ),
                PsdCase {
                    steps,
                    tol: MOTION,
                    plot: false,
                    open: None,
                },
            );
        }
    }

    fn pkw_rules_cases(&mut self) {
        let none = self.none();
        // An undefined command code.
        let undefined = (0..=self.pkw.ak_max())
            .map(drivespec_psd4xx::CommandCode::from)
            .find(|c| self.pkw.command_info(*c).is_none());
        if let Some(ak) = undefined {
            let req = PkwRequest {
                ak,
                spm: false,
                pnu: 44,
                ind: 0,
                pwe: 0,
            };
            self.push(
                "psd4xx/pkw/error/undefined-command".to_owned(),
                &["PSD-PKW-031", "PSD-PKW-019"],
                format!("command code {} (not in the table): error 18", u8::from(ak)),
                PsdCase {
                    steps: vec![
                        step(
                            Role::Check,
                            "undefined command on par 44",
                            Step::Pkw { pkw: req.into() },
                        ),
                        step(Role::Check, "hold", Step::Hold { cycles: 2 }),
                        step(Role::Check, "no command", Step::Pkw { pkw: none.into() }),
                    ],
                    tol: EXCHANGE,
                    plot: false,
                    open: None,
                },
            );
        }
    }

    /// One case per parameter that may be written only at a standstill (spec `conditions`
    /// `standstill`, 3.3): a run to half the upper limit (par 42), the parameter written with
    /// its delivery value while the drive runs: error 17 (3.8), the requirement of the
    /// parameter's standstill rule cited with PSD-PKW-030.
    fn standstill_cases(&mut self) -> Result<(), String> {
        let run = control(self.family, "release-and-transfer")?;
        let upper = self
            .family
            .parameter("42")
            .and_then(|p| self.family.resolve(p, Some(self.model)).default)
            .ok_or("par 42 has no delivery value")?;
        let target = i32::try_from(upper / 2).map_err(|e| format!("par 42 / 2: {e}"))?;
        let params: Vec<&Parameter> = self
            .family
            .parameters
            .iter()
            .filter(|p| p.has_condition("standstill") && p.access.writable())
            .collect();
        for p in params {
            let (Ok(pnu), Some(width)) = (u16::try_from(p.number), Self::width(p)) else {
                continue;
            };
            let num = p.number;
            let value = self
                .family
                .resolve(p, Some(self.model))
                .default
                .or_else(|| self.range(p).map(|r| r.0))
                .unwrap_or(0);
            let mut steps = vec![
                step(
                    Role::Setup,
                    format!("control {run:#06x}, target {target}"),
                    Step::Process {
                        control: Some(run),
                        target: Some(target),
                    },
                ),
                step(
                    Role::Setup,
                    "until running",
                    Step::Until {
                        running: true,
                        max: 200,
                    },
                ),
            ];
            self.exchange(
                &mut steps,
                Role::Check,
                &format!("write par {num} = {value} while running"),
                Request::Write {
                    pnu,
                    index: None,
                    width,
                    value,
                },
            );
            let mut reqs: Vec<String> = vec!["PSD-PKW-030".to_owned(), "PSD-PKW-019".to_owned()];
            reqs.extend(
                self.family
                    .requirements
                    .iter()
                    .filter(|r| {
                        r.params.contains(&p.id)
                            && r.text.contains("only be written at a standstill")
                    })
                    .map(|r| r.id.clone()),
            );
            let reqs: Vec<&str> = reqs.iter().map(String::as_str).collect();
            self.push(
                format!("psd4xx/pkw/error/operating-state/{num}"),
                &reqs,
                format!(
                    "write par {num} ({}) during a run: error 17, it may be written only at a standstill",
                    p.name
                ),
                PsdCase {
                    steps,
                    tol: MOTION,
                    plot: false,
                    open: None,
                },
            );
        }
        Ok(())
    }

    /// The motor voltage exactly at the UMot limit (par 90's delivery value): 3.6 sets bit 4
    /// above the limit and bit 13 below it, and says nothing of the limit itself; the case
    /// reports which bits the device shows.
    fn umot_limit_case(&mut self) -> Result<(), String> {
        let p90 = self.family.parameter("90").ok_or("no par 90")?;
        let limit = self
            .family
            .resolve(p90, Some(self.model))
            .default
            .ok_or("par 90 has no delivery value")?;
        let bits = status_bit(self.family, "Power supply to motor available")?
            | status_bit(self.family, "Motor voltage was missing")?;
        let steps = vec![
            step(
                Role::Check,
                format!("motor voltage {limit} (par 90)"),
                Step::Env {
                    env: Env::MotorVoltage(
                        u16::try_from(limit).map_err(|e| format!("par 90: {e}"))?,
                    )
                    .to_string(),
                },
            ),
            step(Role::Check, "settle", Step::Hold { cycles: 50 }),
        ];
        self.push(
            "psd4xx/status/umot-at-limit".to_owned(),
            &["PSD-STS-4-SET-1", "PSD-STS-13-SET-1"],
            format!("the motor voltage exactly at the UMot limit (par 90 = {limit}): bits 4 and 13 are open"),
            PsdCase {
                steps,
                tol: MOTION,
                plot: false,
                open: Some(OpenPoint {
                    requirement: "PSD-STS-4-SET-1".to_owned(),
                    text: format!(
                        "motor voltage equal to the UMot limit ({limit}): 3.6 sets bit 4 above the limit and bit 13 below it, the limit itself is open"
                    ),
                    bits,
                    movement: false,
                }),
            },
        );
        Ok(())
    }

    fn record_write(&self, index: u16, control: u8, value: i64) -> Result<Step, String> {
        let p = self
            .family
            .parameters
            .iter()
            .find(|p| p.number == u32::from(index))
            .ok_or_else(|| format!("no par {index}"))?;
        let width = Self::width(p).ok_or_else(|| format!("par {index} has no width"))?;
        let rules = self.drive_rules.record();
        let data = RecordWrite {
            index,
            control,
            width,
            value,
        }
        .to_bytes(rules)
        .map_err(|e| format!("record write {index}: {e}"))?;
        Ok(Step::RecordWrite { index, hex: data })
    }
}

/// Bits of the status word by their spec name (bitfield `status`, 3.6).
pub(crate) fn status_bit(family: &Family, name: &str) -> Result<u16, String> {
    family
        .bitfield("status")
        .and_then(|b| b.bits.iter().find(|x| x.name == name))
        .and_then(|x| 1u16.checked_shl(x.bit))
        .ok_or_else(|| format!("no status bit {name:?}"))
}

impl Gen<'_> {
    fn record_cases(&mut self) -> Result<(), String> {
        let params: Vec<&Parameter> = self.family.parameters.iter().collect();
        let execute = self.drive_rules.record().control_ignore().wrapping_add(1);
        let ignore = self.drive_rules.record().control_ignore();
        for p in params {
            let Ok(index) = u16::try_from(p.number) else {
                continue;
            };
            let num = p.number;
            let width = Self::width(p);
            let read_reqs: &[&str] = match (p.array.is_some(), width) {
                (true, _) => &["PSD-REC-001", "PSD-REC-002", "PSD-REC-010"],
                (false, Some(Width::Word)) => &["PSD-REC-001", "PSD-REC-002", "PSD-REC-008"],
                _ => &["PSD-REC-001", "PSD-REC-002", "PSD-REC-009"],
            };
            self.push(
                format!("psd4xx/record/read/{num}"),
                &with_row(read_reqs, num),
                format!("read record {num} ({})", p.name),
                PsdCase {
                    steps: vec![step(
                        Role::Check,
                        format!("read record {num}"),
                        Step::RecordRead { index },
                    )],
                    tol: EXCHANGE,
                    plot: false,
                    open: None,
                },
            );
            let Some(width) = width else { continue };
            if p.array.is_some() || num == 96 {
                continue;
            }
            if !p.access.writable() {
                let w = self.record_write(index, execute, 0)?;
                self.push(
                    format!("psd4xx/record/write/{num}/read-only"),
                    &["PSD-REC-001", "PSD-PAR-READONLY-001"],
                    format!("record write to the read-only par {num}: refused"),
                    PsdCase {
                        steps: vec![step(Role::Check, format!("write record {num}"), w)],
                        tol: EXCHANGE,
                        plot: false,
                        open: None,
                    },
                );
                continue;
            }
            let Some((min, max)) = self.range(p) else {
                continue;
            };
            let size: &str = if width == Width::Word {
                "PSD-REC-006"
            } else {
                "PSD-REC-007"
            };
            let read = Step::RecordRead { index };
            let w = self.record_write(index, execute, min)?;
            self.push(
                format!("psd4xx/record/write/{num}/execute"),
                &["PSD-REC-003", "PSD-REC-005", size],
                format!("record write par {num} = {min} with control byte {execute}, read back"),
                PsdCase {
                    steps: vec![
                        step(Role::Check, format!("write record {num} = {min}"), w),
                        step(Role::Check, format!("read record {num}"), read.clone()),
                    ],
                    tol: EXCHANGE,
                    plot: false,
                    open: None,
                },
            );
            let w = self.record_write(index, ignore, max)?;
            self.push(
                format!("psd4xx/record/write/{num}/control-0"),
                &["PSD-REC-004", "PSD-REC-003", size],
                format!("record write par {num} = {max} with control byte {ignore}: ignored"),
                PsdCase {
                    steps: vec![
                        step(
                            Role::Check,
                            format!("write record {num} = {max}, control {ignore}"),
                            w,
                        ),
                        step(
                            Role::Check,
                            format!("read record {num}: unchanged"),
                            read.clone(),
                        ),
                    ],
                    tol: EXCHANGE,
                    plot: false,
                    open: None,
                },
            );
            if let Step::RecordWrite { hex: data, .. } = self.record_write(index, execute, min)? {
                let short = data
                    .get(..data.len().saturating_sub(1))
                    .unwrap_or(&[])
                    .to_vec();
                self.push(
                    format!("psd4xx/record/write/{num}/short"),
                    &[size],
                    format!("record write par {num} one byte short: malformed"),
                    PsdCase {
                        steps: vec![
                            step(
                                Role::Check,
                                format!("write record {num}, {} bytes", short.len()),
                                Step::RecordWrite { index, hex: short },
                            ),
                            step(Role::Check, format!("read record {num}: unchanged"), read),
                        ],
                        tol: EXCHANGE,
                        plot: false,
                        open: None,
                    },
                );
            }
        }
        for index in [0u16, 99] {
            self.push(
                format!("psd4xx/record/unknown/{index}"),
                &["PSD-REC-002"],
                format!("read record {index} (no such parameter): refused"),
                PsdCase {
                    steps: vec![step(
                        Role::Check,
                        format!("read record {index}"),
                        Step::RecordRead { index },
                    )],
                    tol: EXCHANGE,
                    plot: false,
                    open: None,
                },
            );
        }
        Ok(())
    }

    fn write_pkw(&mut self, steps: &mut Vec<StepDef>, pnu: u16, value: i64) {
        let width = self
            .family
            .parameters
            .iter()
            .find(|p| p.number == u32::from(pnu))
            .and_then(Self::width)
            .unwrap_or(Width::Word);
        let req = self.request(Request::Write {
            pnu,
            index: None,
            width,
            value,
        });
        let none = self.none();
        steps.push(step(
            Role::Setup,
            format!("write par {pnu} = {value}"),
            Step::Pkw { pkw: req.into() },
        ));
        steps.push(step(
            Role::Setup,
            "no command",
            Step::Pkw { pkw: none.into() },
        ));
    }

    fn sequence_cases(&mut self) {
        let vectors: Vec<_> = self
            .family
            .vectors
            .iter()
            .filter(|v| v.kind == VectorKind::Sequence)
            .collect();
        let window_default = self
            .family
            .parameter("44")
            .and_then(|p| self.family.resolve(p, Some(self.model)).default)
            .unwrap_or(2);
        'vectors: for v in vectors {
            if v.model
                .as_deref()
                .is_some_and(|m| self.family.model(m).map(|x| &x.id) != Some(&self.model.id))
            {
                continue;
            }
            let seq = match read_sequence::<PsdSequence>(v) {
                Ok(seq) => seq,
                Err(e) => {
                    self.errors.push(format!("{}: {e}", v.id));
                    continue;
                }
            };
            let mut steps = Vec::new();
            let mut window = window_default;
            let mut keys: Vec<(&String, &StateValue)> = seq.input.state.iter().collect();
            keys.sort_by_key(|(k, _)| (k.as_str() != "41", k.parse::<u32>().unwrap_or(0)));
            for (k, value) in keys {
                let (Ok(pnu), Some(value)) = (k.parse::<u16>(), value.int()) else {
                    continue 'vectors; // strings (par 13) and live values need recipes
                };
                if pnu == 1 || pnu == 2 {
                    continue 'vectors;
                }
                if pnu == 44 {
                    window = value;
                }
                if pnu == 3 && value == 0 {
                    continue;
                }
                self.write_pkw(&mut steps, pnu, value);
            }
            if seq.input.steps.is_empty() {
                continue;
            }
            for (n, s) in seq.input.steps.iter().enumerate() {
                let mut jam = false;
                if let Some(e) = s.event {
                    let env = match e {
                        Event::PowerOn => Env::PowerCycle,
                        Event::ObstructionDetected => {
                            jam = true;
                            Env::Jam(true)
                        }
                        Event::ManualRotationAtStandstill => {
                            let d = s.distance.unwrap_or(0);
                            Env::Displace(match s.direction {
                                Some(Direction::Decreasing) => -d,
                                _ => d,
                            })
                        }
                        Event::MotorVoltageOutOfRange => Env::MotorVoltage(100),
                        Event::MotorVoltageInRange => Env::MotorVoltage(240),
                        Event::PositionOutsideWindowAfterRun => Env::MissSteps(window + 1),
                        Event::ConnectionInterrupted => Env::Link(LinkEvent::Lost),
                        Event::ConnectionRestored => Env::Link(LinkEvent::Connected),
                        Event::IopsBad => Env::Link(LinkEvent::IopsBad),
                    };
                    steps.push(step(
                        Role::Check,
                        format!("step {n}: {}", kebab(&e)),
                        Step::Env {
                            env: env.to_string(),
                        },
                    ));
                }
                let (control, target) = (s.control, s.target);
                if let Some(o) = s.target_offset {
                    steps.push(step(
                        Role::Check,
                        format!("step {n}: target = actual {o:+}"),
                        Step::Offset { control, offset: o },
                    ));
                } else {
                    let text = match (control, target) {
                        (Some(c), Some(t)) => format!("step {n}: control {c:#06x}, target {t}"),
                        (Some(c), None) => format!("step {n}: control {c:#06x}"),
                        (None, Some(t)) => format!("step {n}: target {t}"),
                        (None, None) => format!("step {n}: one cycle"),
                    };
                    steps.push(step(Role::Check, text, Step::Process { control, target }));
                }
                let wait = match s.wait {
                    Wait::Running => Step::Until {
                        running: true,
                        max: 1_000,
                    },
                    Wait::Standstill => Step::Until {
                        running: false,
                        max: 12_000,
                    },
                    Wait::Settle => Step::Hold { cycles: 50 },
                };
                steps.push(step(
                    Role::Check,
                    format!("step {n}: wait {}", kebab(&s.wait)),
                    wait,
                ));
                if jam {
                    steps.push(step(
                        Role::Check,
                        format!("step {n}: obstruction removed"),
                        Step::Env {
                            env: Env::Jam(false).to_string(),
                        },
                    ));
                }
            }
            steps.push(step(Role::Check, "settle", Step::Hold { cycles: 10 }));
            let reqs: Vec<&str> = v.requirements.iter().map(String::as_str).collect();
            self.push(
                format!("psd4xx/sequence/{}", v.id),
                &reqs,
                v.description.clone(),
                PsdCase {
                    steps,
                    tol: MOTION,
                    plot: true,
                    open: None,
                },
            );
        }
    }

    /// The cases of the scenario files, each step resolved against the spec.
    fn scenario_cases(&mut self) {
        let f = self.family;
        for sc in &f.scenarios {
            let typed = match sc.typed::<Setup, ScenarioStep>() {
                Ok(t) => t,
                Err(e) => {
                    self.errors
                        .push(format!("{}: scenario {:?}: {e}", sc.file, sc.id));
                    continue;
                }
            };
            let mut steps = Vec::new();
            for (n, s) in typed.steps.iter().enumerate() {
                match self.resolve(s) {
                    Ok(d) => steps.push(d),
                    Err(e) => self.errors.push(format!(
                        "{}: scenario {:?}: steps[{}]: {e}",
                        sc.file,
                        sc.id,
                        n.saturating_add(1)
                    )),
                }
            }
            let reqs: Vec<&str> = sc.requirements.iter().map(String::as_str).collect();
            let tol = match typed.setup.judge {
                Judge::Exact => EXCHANGE,
                Judge::Motion => MOTION,
            };
            let open = typed
                .setup
                .open
                .as_ref()
                .map(|o| OpenPoint::of_scenario(&o.requirement, &o.text, &o.bits, o.movement));
            if let Some(o) = &open {
                if f.requirement(&o.requirement).is_none() {
                    self.errors.push(format!(
                        "{}: scenario {:?}: unknown requirement {} of the open point",
                        sc.file, sc.id, o.requirement
                    ));
                }
            }
            self.push(
                format!("psd4xx/{}", sc.id),
                &reqs,
                sc.description.clone(),
                PsdCase {
                    steps,
                    tol,
                    plot: typed.setup.plot,
                    open,
                },
            );
        }
    }

    /// A scenario step as the suite runs it.
    fn resolve(&mut self, s: &ScenarioStep) -> Result<StepDef, String> {
        let action = match &s.action {
            scenario::Action::Step(step) => step.clone(),
            scenario::Action::Spec(spec) => self.spec_step(spec)?,
        };
        let text = match (&s.text, &action) {
            (Some(t), _) => t.clone(),
            (None, Step::Process { control, target }) => match (control, target) {
                (Some(c), Some(t)) => format!("control {c:#06x}, target {t}"),
                (Some(c), None) => format!("control {c:#06x}"),
                (None, Some(t)) => format!("target {t}"),
                (None, None) => "one cycle".to_owned(),
            },
            (None, Step::Until { running: true, .. }) => "until running".to_owned(),
            (None, Step::Until { running: false, .. }) => "until standstill".to_owned(),
            (None, Step::Hold { cycles }) => format!("{cycles} cycles"),
            (None, other) => return Err(format!("a `{}` step needs `text`", other.name())),
        };
        Ok(step(s.role.into(), text, action))
    }

    fn pnu(&self, par: &str) -> Result<u16, String> {
        self.family
            .parameter(par)
            .and_then(|p| u16::try_from(p.number).ok())
            .ok_or_else(|| format!("no par {par:?}"))
    }

    fn spec_step(&mut self, spec: &SpecStep) -> Result<Step, String> {
        Ok(match spec {
            SpecStep::Control { control: c, target } => {
                let mut value = 0u16;
                for part in c.split('|').map(str::trim) {
                    value |= match part.parse::<u16>() {
                        Ok(n) => n,
                        Err(_) => control(self.family, part)
                            .or_else(|_| control_bit(self.family, part))?,
                    };
                }
                Step::Process {
                    control: Some(value),
                    target: target.map(|t| match t {
                        Target::Value(v) => v,
                        Target::Named(TargetName::TypeMax) => i32::MAX,
                    }),
                }
            }
            SpecStep::PkwRead { par, index } => {
                let pnu = self.pnu(par)?;
                Step::Pkw {
                    pkw: self.request(Request::Read { pnu, index: *index }).into(),
                }
            }
            SpecStep::PkwNone {} => Step::Pkw {
                pkw: self.none().into(),
            },
            SpecStep::PkwWriteDefault { par } => {
                let p = self
                    .family
                    .parameter(par)
                    .ok_or_else(|| format!("no par {par:?}"))?;
                let width = Self::width(p).ok_or_else(|| format!("par {par} has no width"))?;
                let value = self
                    .family
                    .resolve(p, Some(self.model))
                    .default
                    .unwrap_or(0);
                let pnu = self.pnu(par)?;
                Step::Pkw {
                    pkw: self
                        .request(Request::Write {
                            pnu,
                            index: None,
                            width,
                            value,
                        })
                        .into(),
                }
            }
            SpecStep::RecordSet { par, value } => {
                let execute = self.drive_rules.record().control_ignore().wrapping_add(1);
                self.record_write(self.pnu(par)?, execute, *value)?
            }
        })
    }

    fn par96_cases(&mut self) -> Result<(), String> {
        let Some(p44) = self.family.parameter("44") else {
            return Err("no par 44".to_owned());
        };
        let (min, max) = self.range(p44).ok_or("par 44 has no range")?;
        let default = self
            .family
            .resolve(p44, Some(self.model))
            .default
            .unwrap_or(min);
        // Two values apart from the delivery value: one saved, one only in the working set.
        let (saved, working) = if default.saturating_add(2) <= max {
            (default + 1, default + 2)
        } else if default.saturating_sub(2) >= min {
            (default - 1, default - 2)
        } else {
            return Err("par 44 has no room for two changed values".to_owned());
        };
        let read44 = Request::Read {
            pnu: 44,
            index: None,
        };
        // -5 and -4 move to the middle of the range, where the drive already stands: whether
        // that is a run (status bits of a run, a reference loop) the manual does not say.
        let run_bits = [
            "Target position reached",
            "Drive is running",
            "Run in opposite direction to loop",
        ]
        .iter()
        .map(|n| status_bit(self.family, n))
        .collect::<Result<Vec<u16>, String>>()?
        .into_iter()
        .fold(0, |a, b| a | b);
        let centre: std::collections::BTreeMap<i64, OpenPoint> = [(-5i64, "PSD-PAR-96-002"), (-4, "PSD-PAR-96-003")]
            .into_iter()
            .map(|(v, requirement)| {
                (v, OpenPoint {
                    requirement: requirement.to_owned(),
                    text: format!("par 96 = {v} with the drive at the middle of the range already: the manual does not say whether the move there is a run (the status bits of a run, a reference loop)"),
                    bits: run_bits,
                    movement: true,
                })
            })
            .collect();
        for (v, reqs) in [
            (-6i64, &["PSD-PAR-96-001"][..]),
            (-5, &["PSD-PAR-96-002"][..]),
            (-4, &["PSD-PAR-96-003"][..]),
            (-3, &["PSD-PAR-96-004"][..]),
            (-2, &["PSD-PAR-96-005"][..]),
            (-1, &["PSD-PAR-96-006"][..]),
            (1, &["PSD-PAR-96-007", "PSD-PAR-96-009"][..]),
            (0, &["PSD-PAR-96-008"][..]),
            (2, &["PSD-PAR-96-008"][..]),
            (-7, &["PSD-PAR-96-008"][..]),
        ] {
            let mut steps = Vec::new();
            self.write_pkw(&mut steps, 44, saved);
            self.write_pkw(&mut steps, 96, 1);
            self.write_pkw(&mut steps, 44, working);
            let req = Request::Write {
                pnu: 96,
                index: None,
                width: Width::Word,
                value: v,
            };
            self.exchange(&mut steps, Role::Check, &format!("write par 96 = {v}"), req);
            steps.push(step(
                Role::Check,
                "until standstill",
                Step::Until {
                    running: false,
                    max: 12_000,
                },
            ));
            self.exchange(&mut steps, Role::Check, "read par 44", read44);
            power_cycle(&mut steps);
            self.exchange(
                &mut steps,
                Role::Check,
                "read par 44 after power-up",
                read44,
            );
            let name = if v < 0 {
                format!("minus-{}", -v)
            } else {
                v.to_string()
            };
            self.push(
                format!("psd4xx/par96/{name}"),
                reqs,
                format!("par 44 saved and changed again, par 96 = {v}, read back, power cycle, read back"),
                PsdCase {
                    steps,
                    tol: MOTION,
                    plot: false,
                    open: centre.get(&v).cloned(),
                },
            );
        }
        self.par96_centre_case(run_bits)
    }

    /// The move to the middle of the range (par 96 = -4) away from a target reached by a run
    /// while the controller goes on sending that run command: the unchanged control word is
    /// ignored (PSD-PAR-96-010) and the old target is not approached again afterwards
    /// (PSD-PAR-96-012). The working values are saved first, so -4 restores them.
    fn par96_centre_case(&mut self, run_bits: u16) -> Result<(), String> {
        /// The target of the run before par 96 = -4 (increments), away from the middle.
        const AWAY: i32 = 4000;
        let run = control(self.family, "release-and-transfer")?;
        let mut steps = Vec::new();
        self.write_pkw(&mut steps, 96, 1);
        steps.push(step(
            Role::Setup,
            format!("control {run:#06x}, target {AWAY}"),
            Step::Process {
                control: Some(run),
                target: Some(AWAY),
            },
        ));
        for (text, running) in [("until running", true), ("until standstill", false)] {
            steps.push(step(
                Role::Setup,
                text,
                Step::Until {
                    running,
                    max: 12_000,
                },
            ));
        }
        self.exchange(
            &mut steps,
            Role::Check,
            "write par 96 = -4, the run command still sent",
            Request::Write {
                pnu: 96,
                index: None,
                width: Width::Word,
                value: -4,
            },
        );
        steps.push(step(
            Role::Check,
            "until standstill",
            Step::Until {
                running: false,
                max: 12_000,
            },
        ));
        steps.push(step(Role::Check, "settle", Step::Hold { cycles: 50 }));
        self.push(
            "psd4xx/par96/minus-4/run-command-held".to_owned(),
            &[
                "PSD-PAR-96-010",
                "PSD-PAR-96-012",
                "PSD-PAR-96-003",
                "PSD-PKW-003",
            ],
            format!("a run to {AWAY}, then par 96 = -4 with the run command still sent: the drive moves to the middle of the range and stays there"),
            PsdCase {
                steps,
                tol: MOTION,
                plot: true,
                open: Some(OpenPoint {
                    requirement: "PSD-PAR-96-003".to_owned(),
                    text: "par 96 = -4: the manual does not say whether the move to the middle of the range is a run (the status bits of a run, a reference loop)".to_owned(),
                    bits: run_bits,
                    movement: true,
                }),
            },
        );
        Ok(())
    }
}

/// Every case of the suite for `model`, in run order.
pub(crate) fn generate(
    family: &Family,
    model: &DeviceModel,
    drive: &Drive,
) -> Result<(Vec<CaseInfo>, Vec<PsdCase>), String> {
    let rules = drive.rules();
    let mut g = Gen {
        family,
        model,
        pkw: rules.pkw(),
        drive_rules: rules,
        errors: Vec::new(),
        out: Vec::new(),
    };
    g.pkw_cases();
    g.pkw_rules_cases();
    g.backup_cases();
    g.standstill_cases()?;
    g.umot_limit_case()?;
    g.record_cases()?;
    g.sequence_cases();
    g.scenario_cases();
    g.par96_cases()?;
    for (info, case) in &g.out {
        for s in &case.steps {
            if let Step::Env { env } = &s.action {
                if crate::cyclic_session::env_request(0, env).is_err() {
                    g.errors
                        .push(format!("{}: env {env:?} is not an injection", info.id));
                }
            }
        }
    }
    if let Some(first) = g.errors.first() {
        return Err(format!(
            "{} problem(s) generating PSD4xx cases, first: {first}; all: {}",
            g.errors.len(),
            g.errors.join("; ")
        ));
    }
    Ok(g.out.into_iter().unzip())
}
