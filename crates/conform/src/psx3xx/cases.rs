//! Case generation for the PSx3xx suite: data-driven from the spec's ISDU table (ranges per
//! model, access, data types), the ErrorType cases, the guard entries, the ISDU 2 / 193
//! commands, the three process-data formats, the time-stamp and target-speed tables and the
//! time-out table, the spec's `sequence` vectors ([`sequence`]), plus hand-written status,
//! time-out and positioning sequences (manual 3–5).

mod brake;
mod scenario;
mod sequence;

use crate::case::{CaseInfo, Role};
use crate::cyclic::Env;
use crate::cyclic_session::env_request;
use drivespec_psx3xx::guard::Guards;
use drivespec_psx3xx::isdu::{Target, Value};
use drivespec_psx3xx::model::Drive;
use drivespec_psx3xx::step::Step;
use drivespec_psx3xx::{Output, Rules, Stamp, TsCode};
use drivespec_spec::psx3xx::Brake;
use drivespec_spec::{Access, DataType, DeviceModel, Family, FamilyId, Level, Parameter, Readings};

/// ISDU entries the hand-written sequences use (manual 3.1 table); every value, range and
/// code they carry is read from the spec.
mod isdu {
    /// ISDU 12, device access locks (bit 0: parameter write lock).
    pub const LOCKS: &str = "12";
    /// ISDU 67, actual position.
    pub const ACTUAL: &str = "67";
    /// ISDU 135, jog increment: the saved entry the save and lock cases change.
    pub const PROBE: &str = "135";
    /// ISDU 193, delivery state and save command.
    pub const DELIVERY_STATE: &str = "193";
    /// ISDU 2, IO-Link standard command (write only).
    pub const STANDARD_COMMAND: &str = "2";
}

/// One step of a case.
pub type StepDef = crate::cyclic_session::StepDef<Step>;

pub use crate::cyclic_session::{OpenPoint, Still, Tolerance, MOTION};

/// Tolerance of the ISDU cases: every cycle and every live value exact.
pub const EXACT: Tolerance = Tolerance {
    cycles: 0,
    position: 0,
    speed: 0,
    motion: false,
};

/// A generated case.
#[derive(Debug, Clone, PartialEq)]
pub struct PsxCase {
    /// The output the master sends before the first `Out` step: all zero in the delivery
    /// format.
    pub start: Output,
    /// The steps.
    pub steps: Vec<StepDef>,
    /// Tolerances.
    pub tol: Tolerance,
    /// Whether the report gets a position/speed/status plot.
    pub plot: bool,
    /// The point of a motion case the manual leaves open, if any.
    pub open: Option<OpenPoint>,
    /// The step the device must stand still through, if any.
    pub still: Option<Still>,
    /// Why the case does not apply to the drive's brake option, if it does not (5.4).
    pub not_applicable: Option<String>,
}

impl PsxCase {
    /// A case judged exactly, cycle by cycle, starting from `start`.
    pub fn exact(start: Output, steps: Vec<StepDef>) -> Self {
        Self::judged(start, steps, EXACT, false)
    }

    /// A motion case, judged by its envelope and plotted, starting from `start`.
    pub fn motion(start: Output, steps: Vec<StepDef>) -> Self {
        Self::judged(start, steps, MOTION, true)
    }

    fn judged(start: Output, steps: Vec<StepDef>, tol: Tolerance, plot: bool) -> Self {
        Self {
            start,
            steps,
            tol,
            plot,
            open: None,
            still: None,
            not_applicable: None,
        }
    }
}

/// A process output in the format of `out`, then one cycle (manual 3.3.1).
pub(crate) fn pd_out(out: Output) -> Step {
    match out {
        Output::TimeStamp { control, stamp } => Step::PdOut {
            format: 0,
            control: u16::from(control.0),
            target: 0,
            speed: 0,
            stamp: stamp.0,
        },
        Output::ControlTarget {
            control_word,
            target,
        } => Step::PdOut {
            format: 1,
            control: control_word,
            target,
            speed: 0,
            stamp: 0,
        },
        Output::SpeedControlTarget {
            target_speed,
            control_word,
            target,
        } => Step::PdOut {
            format: 2,
            control: control_word,
            target,
            speed: target_speed,
            stamp: 0,
        },
    }
}

/// An environment change in its protocol text form.
fn env(change: Env) -> Step {
    Step::Env {
        env: change.to_string(),
    }
}

fn step(role: Role, text: impl Into<String>, action: Step) -> StepDef {
    StepDef {
        role,
        text: text.into(),
        action,
    }
}

/// The rule that a new format takes effect only after a save and a restart.
const FORMAT_SWITCH: &str = "PSX-PD-010";

/// Cycles a status is held before the next change: more than twice the motion tolerance, so
/// a missing bit cannot hide behind the time tolerance.
const SETTLE: u32 = 10;

/// Most cycles a run is waited for (8 ms each: 80 s).
const RUN_MAX: u32 = 10_000;

struct Gen<'a, 's> {
    family: &'a Family,
    /// The spec's record of the drive's brake option, None without brake (5.11–5.13).
    brake: Option<&'a Brake>,
    model: &'a DeviceModel,
    rules: &'a Rules<'s>,
    base: &'a Drive<'s>,
    cycle_us: u64,
    errors: Vec<String>,
    out: Vec<(CaseInfo, PsxCase)>,
}

/// The ISDU address of a parameter (manual 3.1).
fn address(p: &Parameter) -> Option<(u16, u8)> {
    Some((
        u16::try_from(p.number).ok()?,
        u8::try_from(p.subindex.unwrap_or(0)).ok()?,
    ))
}

/// The octets of an entry's data type, None for strings (manual 3.1).
fn width(t: DataType) -> Option<usize> {
    t.width().and_then(|w| usize::try_from(w).ok())
}

impl<'a, 's> Gen<'a, 's> {
    fn push(&mut self, id: String, reqs: &[String], description: String, case: PsxCase) {
        let mut reqs = reqs.to_vec();
        // A case that writes ISDU 116 relies on the format switching only after a restart.
        let format = self.rules.protocol().format_select.param.as_str();
        let format_index = self
            .family
            .parameters
            .iter()
            .find(|p| p.id == format)
            .and_then(address);
        let writes_format = case.steps.iter().any(|s| match &s.action {
            Step::IsduWrite {
                index, subindex, ..
            } => format_index == Some((*index, *subindex)),
            _ => false,
        });
        if writes_format {
            reqs.push(FORMAT_SWITCH.to_owned());
        }
        for s in &case.steps {
            if let Step::Env { env } = &s.action {
                if let Err(e) = env_request(0, env) {
                    self.errors.push(format!("{id}: step {:?}: {e}", s.text));
                }
            }
        }
        let mut requirements: Vec<String> = Vec::new();
        let mut level = Level::Informative;
        for r in &reqs {
            match self.family.requirement(r) {
                Some(q) => {
                    level = level.min(q.level);
                    requirements.push(q.id.clone());
                }
                None => self.errors.push(format!("{id}: unknown requirement {r}")),
            }
        }
        if requirements.is_empty() {
            self.errors.push(format!("{id}: no requirement"));
        }
        requirements.sort();
        requirements.dedup();
        let mut case = case;
        if case.tol.motion {
            case.not_applicable = self.not_applicable(&requirements);
        }
        let steps = case.steps.iter().map(|s| s.text.clone()).collect();
        self.out.push((
            CaseInfo {
                id,
                family: FamilyId::Psx3xx,
                requirements,
                level,
                description,
                steps,
            },
            case,
        ));
    }

    fn case(&mut self, id: &str, reqs: &[&str], description: &str, steps: Vec<StepDef>) {
        let reqs: Vec<String> = reqs.iter().map(|r| (*r).to_owned()).collect();
        self.push(
            format!("psx3xx/{id}"),
            &reqs,
            description.to_owned(),
            PsxCase::exact(self.idle(self.rules.default_format()), steps),
        );
    }

    fn motion(&mut self, id: &str, reqs: &[&str], description: &str, steps: Vec<StepDef>) {
        let reqs: Vec<String> = reqs.iter().map(|r| (*r).to_owned()).collect();
        self.push(
            format!("psx3xx/{id}"),
            &reqs,
            description.to_owned(),
            PsxCase::motion(self.idle(self.rules.default_format()), steps),
        );
    }

    fn param(&mut self, id: &str) -> Option<&'a Parameter> {
        let p = self.family.parameters.iter().find(|p| p.id == id);
        if p.is_none() {
            self.errors.push(format!("no parameter {id}"));
        }
        p
    }

    /// Requirements whose `params` name the entry (spec `requirement.params`).
    fn reqs_of(&self, id: &str) -> Vec<String> {
        self.family
            .requirements
            .iter()
            .filter(|r| r.params.iter().any(|p| p == id))
            .map(|r| r.id.clone())
            .collect()
    }

    fn has_req(&self, id: &str) -> bool {
        self.family.requirement(id).is_some()
    }

    fn range(&self, p: &Parameter) -> Option<Vec<[i64; 2]>> {
        let r = self.family.resolve(p, Some(self.model)).range?;
        Some(r.intervals().to_vec())
    }

    fn default_of(&self, p: &Parameter) -> Option<i64> {
        self.family.resolve(p, Some(self.model)).default
    }

    /// The all-zero output of a format (manual 3.3.1); in format 0 the stamp is inactive.
    fn idle(&self, format: u8) -> Output {
        match format {
            0 => Output::TimeStamp {
                control: TsCode(0),
                stamp: self.inactive(),
            },
            1 => Output::ControlTarget {
                control_word: 0,
                target: 0,
            },
            _ => Output::SpeedControlTarget {
                target_speed: 0,
                control_word: 0,
                target: 0,
            },
        }
    }

    fn inactive(&self) -> Stamp {
        Stamp::inactive(self.rules.timestamp())
    }

    fn read(&mut self, id: &str) -> Option<StepDef> {
        let p = self.param(id)?;
        let (index, subindex) = address(p)?;
        Some(step(
            Role::Check,
            format!("ISDU read {id} ({})", p.name),
            Step::IsduRead { index, subindex },
        ))
    }

    /// The octets of `value` for an entry, None when the data type cannot hold it.
    fn encode(&self, p: &Parameter, value: i64) -> Option<Vec<u8>> {
        let (index, subindex) = address(p)?;
        let target: Target<'_> = self.rules.isdu_target(index, subindex).ok()?;
        self.rules.encode_value(&target, &Value::Int(value)).ok()
    }

    fn write(&mut self, role: Role, id: &str, value: i64) -> Option<StepDef> {
        let p = self.param(id)?;
        let (index, subindex) = address(p)?;
        let Some(data) = self.encode(p, value) else {
            self.errors
                .push(format!("ISDU {id} cannot hold the value {value}"));
            return None;
        };
        Some(step(
            role,
            format!("ISDU write {id} ({}) = {value}", p.name),
            Step::IsduWrite {
                index,
                subindex,
                data,
            },
        ))
    }

    /// The reference's value of an entry at the start of every case.
    fn value(&self, id: &str) -> i64 {
        match self.base.value(id) {
            Value::Int(v) => v,
            _ => 0,
        }
    }

    fn control(&mut self, name: &str) -> u16 {
        let v = self
            .family
            .bitfield("control")
            .and_then(|b| b.values.iter().find(|v| v.name == name))
            .and_then(|v| u16::try_from(v.value).ok());
        v.unwrap_or_else(|| {
            self.errors.push(format!(
                "no control-word value {name:?} in bitfield control"
            ));
            0
        })
    }

    /// A `control` bitfield value or bit by name (3.3.2).
    fn control_named(&mut self, name: &str) -> u16 {
        let bitfield = self.family.bitfield("control");
        let value = bitfield
            .and_then(|b| b.values.iter().find(|v| v.name == name))
            .and_then(|v| u16::try_from(v.value).ok());
        let bit = bitfield
            .and_then(|b| b.bits.iter().find(|x| x.name == name))
            .and_then(|x| 1u16.checked_shl(x.bit));
        value.or(bit).unwrap_or_else(|| {
            self.errors.push(format!(
                "no control-word value or bit {name:?} in bitfield control"
            ));
            0
        })
    }

    fn f1(&self, control_word: u16, target: i64) -> Step {
        pd_out(Output::ControlTarget {
            control_word,
            target: i32::try_from(target).unwrap_or(0),
        })
    }

    fn f2(&self, target_speed: i16, control_word: u16, target: i64) -> Step {
        pd_out(Output::SpeedControlTarget {
            target_speed,
            control_word,
            target: i32::try_from(target).unwrap_or(0),
        })
    }

    fn f0(&self, code: u8, stamp: Stamp) -> Step {
        pd_out(Output::TimeStamp {
            control: TsCode(code),
            stamp,
        })
    }

    fn until(running: bool) -> Step {
        Step::Until {
            running,
            max: RUN_MAX,
        }
    }

    /// Cycles covering `ms` of bus time.
    fn cycles_for(&self, ms: u64) -> u32 {
        u32::try_from(ms.saturating_mul(1000).div_ceil(self.cycle_us.max(1))).unwrap_or(u32::MAX)
    }

    // ------------------------------------------------------------------ isdu

    fn isdu_cases(&mut self) {
        let params: Vec<&Parameter> = self.family.parameters.iter().collect();
        let err_ro = "PSX-DP-ERR-003";
        let err_range = "PSX-DP-ERR-004";
        let err_wo = "PSX-DP-ERR-007";
        let mut record_indices: Vec<u16> = Vec::new();
        for p in &params {
            let Some((index, subindex)) = address(p) else {
                continue;
            };
            let mut reqs = self.reqs_of(&p.id);
            if !p.access.readable() {
                reqs.push(err_wo.to_owned());
            }
            if index == self.rules.protocol().direct_parameters.isdu_index {
                reqs.push("PSX-DP-009".to_owned());
            }
            if reqs.is_empty() {
                // Entries no requirement names: the delivery value of the table (3.1).
                reqs.push("PSX-PAR-DEFAULTS".to_owned());
            }
            if subindex > 0 && !record_indices.contains(&index) {
                record_indices.push(index);
            }
            self.push(
                format!("psx3xx/isdu/read/{}", p.id),
                &reqs,
                format!("ISDU read of {} ({}) after power-on", p.id, p.name),
                PsxCase::exact(
                    self.idle(self.rules.default_format()),
                    vec![step(
                        Role::Check,
                        format!("ISDU read {index}.{subindex}"),
                        Step::IsduRead { index, subindex },
                    )],
                ),
            );
            if p.access == Access::R {
                let len = width(p.data_type).unwrap_or(1);
                let mut reqs = self.reqs_of(&p.id);
                reqs.push(err_ro.to_owned());
                self.push(
                    format!("psx3xx/isdu/read-only/{}", p.id),
                    &reqs,
                    format!("a write to the read-only {} ({}) is refused", p.id, p.name),
                    PsxCase::exact(
                        self.idle(1),
                        vec![
                            step(
                                Role::Check,
                                format!("ISDU write {index}.{subindex} with {len} zero octet(s)"),
                                Step::IsduWrite {
                                    index,
                                    subindex,
                                    data: vec![0; len],
                                },
                            ),
                            step(
                                Role::Check,
                                "read back: unchanged",
                                Step::IsduRead { index, subindex },
                            ),
                        ],
                    ),
                );
            }
            if p.access.writable() {
                self.range_cases(p, err_range);
            }
        }
        for index in record_indices {
            self.case(
                &format!("isdu/read/{index}/all"),
                &["PSX-DP-009"],
                &format!("ISDU read of the whole record {index} (sub-index 0)"),
                vec![step(
                    Role::Check,
                    format!("ISDU read {index}.0"),
                    Step::IsduRead { index, subindex: 0 },
                )],
            );
        }
        self.unknown_cases(&params);
        self.length_cases();
        self.lock_case();
    }

    /// Writes at both range edges and one beyond, each read back (manual 3.1, 3.2).
    fn range_cases(&mut self, p: &Parameter, err_range: &str) {
        // Only declared ranges (3.1, 3.2); a data type's own limits are no range rule.
        if p.range.is_none() && !p.range_model {
            return;
        }
        let Some(intervals) = self.range(p) else {
            return;
        };
        let (Some(first), Some(last)) = (intervals.first(), intervals.last()) else {
            return;
        };
        let (min, max) = (first[0], last[1]);
        let mut values = vec![
            ("min".to_owned(), min, false),
            ("max".to_owned(), max, false),
            ("below-min".to_owned(), min.saturating_sub(1), true),
            ("above-max".to_owned(), max.saturating_add(1), true),
        ];
        for w in intervals.windows(2) {
            if let [a, b] = w {
                let v = a[1].saturating_add(1);
                if b[0] > v {
                    values.push((format!("gap-{v}"), v, true));
                }
            }
        }
        let range_req = range_requirement(&p.id);
        for (name, v, beyond) in values {
            let Some(data) = self.encode(p, v) else {
                continue;
            };
            let Some((index, subindex)) = address(p) else {
                continue;
            };
            // The range rule, and everything the spec says about the entry (a write
            // exercises it).
            let mut reqs = self.reqs_of(&p.id);
            if self.has_req(&range_req) {
                reqs.push(range_req.clone());
            }
            if beyond {
                reqs.push(err_range.to_owned());
            }
            if reqs.is_empty() {
                reqs.push("PSX-PAR-DEFAULTS".to_owned());
            }
            let mut steps = vec![step(
                Role::Check,
                format!("ISDU write {} = {v}", p.id),
                Step::IsduWrite {
                    index,
                    subindex,
                    data,
                },
            )];
            if p.access.readable() {
                steps.push(step(
                    Role::Check,
                    "read back",
                    Step::IsduRead { index, subindex },
                ));
            }
            steps.push(step(Role::Check, "two cycles", Step::Hold { cycles: 2 }));
            self.push(
                format!("psx3xx/isdu/write/{}/{name}", p.id),
                &reqs,
                format!(
                    "ISDU write of {} ({}) = {v} ({name} of the range){}",
                    p.id,
                    p.name,
                    if beyond { ": refused, value kept" } else { "" }
                ),
                PsxCase::exact(self.idle(self.rules.default_format()), steps),
            );
        }
    }

    /// Indices and sub-indices the table does not have (IEC 61131-9 C.2.3, C.2.4).
    fn unknown_cases(&mut self, params: &[&Parameter]) {
        let used: Vec<u16> = params
            .iter()
            .filter_map(|p| address(p).map(|a| a.0))
            .collect();
        let mut unknown: Vec<u16> = Vec::new();
        for i in 1..=u16::MAX {
            if !used.contains(&i) && !unknown.contains(&i) {
                unknown.push(i);
                if unknown.len() == 2 {
                    break;
                }
            }
        }
        if let Some(m) = used.iter().max() {
            if let Some(next) = m.checked_add(1) {
                unknown.push(next);
            }
        }
        if !used.contains(&u16::MAX) {
            unknown.push(u16::MAX);
        }
        unknown.dedup();
        for index in unknown {
            self.case(
                &format!("isdu/unknown-index/{index}"),
                &["PSX-DP-ERR-001"],
                &format!("ISDU read and write of index {index}, which the device does not have"),
                vec![
                    step(
                        Role::Check,
                        format!("ISDU read {index}.0"),
                        Step::IsduRead { index, subindex: 0 },
                    ),
                    step(
                        Role::Check,
                        format!("ISDU write {index}.0 = 00 01"),
                        Step::IsduWrite {
                            index,
                            subindex: 0,
                            data: vec![0, 1],
                        },
                    ),
                ],
            );
        }
        // A nonzero sub-index on single-value entries, one past the last of a record.
        let mut subs: Vec<(u16, u8)> = Vec::new();
        for p in params {
            let Some((index, sub)) = address(p) else {
                continue;
            };
            if sub == 0 && subs.iter().all(|(_, s)| *s != 1) && p.access.writable() {
                subs.push((index, 1));
            }
            if sub == 0
                && p.access == Access::R
                && !subs.iter().any(|(i, _)| *i == index)
                && subs.len() < 2
            {
                subs.push((index, 1));
            }
        }
        let mut last: Option<(u16, u8)> = None;
        for p in params {
            if let Some((index, sub)) = address(p) {
                if sub > 0 && last.is_none_or(|(i, s)| i != index || s < sub) {
                    last = Some((index, sub));
                }
            }
        }
        if let Some((index, sub)) = last {
            if let Some(next) = sub.checked_add(1) {
                subs.push((index, next));
            }
        }
        for (index, subindex) in subs {
            self.case(
                &format!("isdu/unknown-subindex/{index}.{subindex}"),
                &["PSX-DP-ERR-002"],
                &format!("ISDU read and write of sub-index {subindex} of index {index}"),
                vec![
                    step(
                        Role::Check,
                        format!("ISDU read {index}.{subindex}"),
                        Step::IsduRead { index, subindex },
                    ),
                    step(
                        Role::Check,
                        format!("ISDU write {index}.{subindex} = 00"),
                        Step::IsduWrite {
                            index,
                            subindex,
                            data: vec![0],
                        },
                    ),
                ],
            );
        }
    }

    /// Writes one octet too long and too short for every numeric width (IEC 61131-9 C.2.12,
    /// C.2.13).
    fn length_cases(&mut self) {
        let mut widths: Vec<usize> = Vec::new();
        let params: Vec<&Parameter> = self.family.parameters.iter().collect();
        for p in params {
            let Some(w) = width(p.data_type) else {
                continue;
            };
            if !p.access.writable() || !p.access.readable() || widths.contains(&w) {
                continue;
            }
            let Some((index, subindex)) = address(p) else {
                continue;
            };
            let Some(good) = self.default_of(p).and_then(|d| self.encode(p, d)) else {
                continue;
            };
            widths.push(w);
            let mut long = vec![0u8];
            long.extend(&good);
            let short: Vec<u8> = good.iter().skip(1).copied().collect();
            let mut cases = vec![("overrun", long)];
            if !short.is_empty() {
                cases.push(("underrun", short));
            }
            for (name, data) in cases {
                self.case(
                    &format!("isdu/length/{}/{name}", p.id),
                    &["PSX-DP-ERR-006"],
                    &format!(
                        "ISDU write of {} ({}, {w} octet(s)) with {} octet(s): refused",
                        p.id,
                        p.name,
                        data.len()
                    ),
                    vec![
                        step(
                            Role::Check,
                            format!("ISDU write {index}.{subindex} with {} octet(s)", data.len()),
                            Step::IsduWrite {
                                index,
                                subindex,
                                data,
                            },
                        ),
                        step(
                            Role::Check,
                            "read back: unchanged",
                            Step::IsduRead { index, subindex },
                        ),
                    ],
                );
            }
        }
    }

    /// The parameter write lock of ISDU 12 bit 0 (IEC 61131-9 B.2.4).
    fn lock_case(&mut self) {
        let jog = isdu::PROBE;
        let Some(p) = self.param(jog) else {
            return;
        };
        let Some(max) = self.range(p).and_then(|r| r.last().map(|i| i[1])) else {
            return;
        };
        let steps: Vec<StepDef> = [
            self.write(Role::Setup, isdu::LOCKS, 1),
            self.write(Role::Check, jog, max),
            self.read(jog),
            self.write(Role::Check, isdu::LOCKS, 0),
            self.write(Role::Check, jog, max),
            self.read(jog),
        ]
        .into_iter()
        .flatten()
        .collect();
        self.case(
            "isdu/write-lock",
            &["PSX-DP-ERR-008", "PSX-ISDU-12-BITS"],
            "with ISDU 12 bit 0 set a parameter write is refused; ISDU 12 stays writable",
            steps,
        );
    }

    // ------------------------------------------------------------------ guard

    fn guard_cases(&mut self) {
        let guards = match Guards::from_rules(self.rules, &Readings::default()) {
            Ok(g) => g,
            Err(e) => {
                self.errors.push(format!("guard entries: {e}"));
                return;
            }
        };
        let other = isdu::PROBE;
        for g in guards.guards().to_vec() {
            let prefix = g
                .requirement
                .strip_suffix("-SUPPRESS")
                .unwrap_or(&g.requirement)
                .to_owned();
            let allow_req = format!("{prefix}-ALLOW");
            let volatile_req = format!("{prefix}-VOLATILE");
            let new = self.value(&g.guarded).saturating_add(4);
            let allow_value = g.allow.unwrap_or(1);
            let suppress: Vec<StepDef> = [
                self.read(&g.guarded),
                self.write(Role::Check, &g.guard, g.suppress),
                self.write(Role::Check, &g.guarded, new),
                self.read(&g.guarded),
                Some(step(Role::Check, "two cycles", Step::Hold { cycles: 2 })),
            ]
            .into_iter()
            .flatten()
            .collect();
            self.case(
                &format!("guard/{}/suppress", g.guard),
                &[&g.requirement, "PSX-GUARD-ONESHOT"],
                &format!(
                    "ISDU {} = {} drops the directly following write of ISDU {}",
                    g.guard, g.suppress, g.guarded
                ),
                suppress,
            );
            let allow: Vec<StepDef> = [
                self.write(Role::Check, &g.guarded, new),
                self.read(&g.guarded),
                Some(step(Role::Check, "two cycles", Step::Hold { cycles: 2 })),
            ]
            .into_iter()
            .flatten()
            .collect();
            self.case(
                &format!("guard/{}/allow", g.guard),
                &[&allow_req],
                &format!(
                    "a write of ISDU {} without ISDU {} = {} before it is executed",
                    g.guarded, g.guard, g.suppress
                ),
                allow,
            );
            let allowed_value: Vec<StepDef> = [
                self.write(Role::Check, &g.guard, allow_value),
                self.write(Role::Check, &g.guarded, new),
                self.read(&g.guarded),
            ]
            .into_iter()
            .flatten()
            .collect();
            self.case(
                &format!("guard/{}/allow-value", g.guard),
                &[&allow_req],
                &format!(
                    "ISDU {} = {allow_value} lets the following write of ISDU {} through",
                    g.guard, g.guarded
                ),
                allowed_value,
            );
            let other_value = self.value(other).saturating_add(1);
            let oneshot: Vec<StepDef> = [
                self.write(Role::Check, &g.guard, g.suppress),
                self.write(Role::Check, other, other_value),
                self.write(Role::Check, &g.guarded, new),
                self.read(&g.guarded),
            ]
            .into_iter()
            .flatten()
            .collect();
            self.case(
                &format!("guard/{}/one-shot", g.guard),
                &["PSX-GUARD-ONESHOT", &allow_req],
                &format!(
                    "another write between ISDU {} = {} and ISDU {} ends the suppression",
                    g.guard, g.suppress, g.guarded
                ),
                oneshot,
            );
            let mut volatile: Vec<StepDef> = self.read(&g.guard).into_iter().collect();
            volatile.extend(self.saved_across_power_cycle(&g.guard, allow_value));
            self.case(
                &format!("guard/{}/volatile", g.guard),
                &[&volatile_req, "PSX-PAR-NOT-SAVED"],
                &format!(
                    "ISDU {} is delivered as its delivery value after a save and a power cycle",
                    g.guard
                ),
                volatile,
            );
        }
    }

    /// Write `value` to `id`, save (ISDU 193 = 1), wait for the save to finish, cycle the
    /// power and read `id` back (manual 3.1).
    fn saved_across_power_cycle(&mut self, id: &str, value: i64) -> Vec<StepDef> {
        [
            self.write(Role::Check, id, value),
            self.save(Role::Check),
            self.saved(Role::Check),
            Some(step(Role::Check, "power cycle", env(Env::PowerCycle))),
            self.read(id),
        ]
        .into_iter()
        .flatten()
        .collect()
    }

    /// The write that saves the working values (ISDU 193 = 1, PSX-CMD-014), from the spec's
    /// command table.
    fn save(&mut self, role: Role) -> Option<StepDef> {
        let value = self
            .rules
            .protocol()
            .commands
            .commands
            .iter()
            .find(|c| c.param == isdu::DELIVERY_STATE && c.save && !c.defaults)
            .map(|c| c.value);
        let Some(value) = value else {
            self.errors
                .push("no save command of ISDU 193 in the command table".to_owned());
            return None;
        };
        self.write(role, isdu::DELIVERY_STATE, value)
    }

    /// ISDU 193 read once a cycle until it reads 0, within the longest save (3.1: "≠ 0 →
    /// Save is still running … (saving can take up to 2000ms)"; 5.5 comment 8).
    fn saved(&mut self, role: Role) -> Option<StepDef> {
        let p = self.param(isdu::DELIVERY_STATE)?;
        let (index, subindex) = address(p)?;
        Some(step(
            role,
            format!(
                "ISDU read {index} until the save is finished (0), at most {} ms",
                self.save_ms()
            ),
            Step::IsduPoll {
                index,
                subindex,
                max: self.cycles_for(self.save_ms()),
            },
        ))
    }

    fn save_ms(&self) -> u64 {
        u64::from(self.rules.protocol().commands.save_max_ms)
    }

    // ------------------------------------------------------------------ command

    fn command_cases(&mut self) {
        let probe = isdu::PROBE;
        let Some(p) = self.param(probe) else {
            return;
        };
        let Some(probe_value) = self.range(p).and_then(|r| r.last().map(|i| i[1])) else {
            return;
        };
        let format_param = self.rules.protocol().format_select.param.clone();
        let commands = self.rules.protocol().commands.commands.clone();
        let save_cycles = self.cycles_for(self.save_ms());
        for c in &commands {
            let mut reqs = self.reqs_of(&c.param);
            reqs.extend(["PSX-PAR-SAVED", "PSX-DP-007"].map(str::to_owned));
            let mut steps: Vec<StepDef> = [
                self.write(Role::Setup, probe, probe_value),
                self.write(Role::Setup, &format_param, 0),
                self.write(Role::Check, &c.param, c.value),
                Some(step(
                    Role::Check,
                    "saving or running",
                    Step::Hold {
                        cycles: save_cycles,
                    },
                )),
                Some(step(
                    Role::Check,
                    "until standstill",
                    Step::Until {
                        running: false,
                        max: RUN_MAX,
                    },
                )),
            ]
            .into_iter()
            .flatten()
            .collect();
            let readable = self
                .family
                .parameters
                .iter()
                .any(|p| p.id == c.param && p.access.readable());
            if readable {
                steps.extend(self.read(&c.param));
            }
            steps.extend(
                [
                    self.read(probe),
                    self.read(&format_param),
                    Some(step(Role::Check, "power cycle", env(Env::PowerCycle))),
                    self.read(probe),
                    self.read(&format_param),
                ]
                .into_iter()
                .flatten(),
            );
            steps.extend(self.device_id_reads());
            let reqs: Vec<&str> = reqs.iter().map(String::as_str).collect();
            let id = format!("command/{}/{}", c.param, c.name);
            let description = format!(
                "ISDU {} = {} ({}): {}; working and saved values across a power cycle",
                c.param, c.value, c.name, c.meaning
            );
            // A command that moves the drive (reference loop, mid-range run) is judged by
            // the properties of the run (4.2, 5.14), not cycle by cycle.
            if c.reference_loop || c.centre_run {
                self.motion(&id, &reqs, &description, steps);
            } else {
                self.case(&id, &reqs, &description, steps);
            }
        }
        // Values that are not commands: 0, the type's top, one above each command and one
        // beyond each end of ISDU 193's range.
        let standard: Vec<i64> = commands
            .iter()
            .filter(|c| c.param == isdu::STANDARD_COMMAND)
            .map(|c| c.value)
            .collect();
        let mut not_commands: Vec<i64> = vec![0, i64::from(u8::MAX)];
        for v in &standard {
            let next = v.saturating_add(1);
            if !standard.contains(&next) && !not_commands.contains(&next) {
                not_commands.push(next);
            }
        }
        not_commands.sort_unstable();
        let states: Vec<i64> = commands
            .iter()
            .filter(|c| c.param == isdu::DELIVERY_STATE)
            .map(|c| c.value)
            .collect();
        let (lo, hi) = (
            states.iter().min().copied().unwrap_or(0),
            states.iter().max().copied().unwrap_or(0),
        );
        for (param, values, reqs) in [
            (isdu::STANDARD_COMMAND, not_commands, vec!["PSX-DP-ERR-005"]),
            (
                isdu::DELIVERY_STATE,
                vec![lo.saturating_sub(1), hi.saturating_add(1)],
                vec!["PSX-ISDU-193-RANGE", "PSX-DP-ERR-004"],
            ),
        ] {
            for v in values {
                let steps: Vec<StepDef> = [
                    self.write(Role::Check, param, v),
                    Some(step(Role::Check, "two cycles", Step::Hold { cycles: 2 })),
                ]
                .into_iter()
                .flatten()
                .collect();
                self.case(
                    &format!("command/{param}/invalid-{v}"),
                    &reqs,
                    &format!("ISDU {param} = {v} is no command: refused"),
                    steps,
                );
            }
        }
        // Working values are lost in a power cycle unless saved.
        let lost: Vec<StepDef> = [
            self.write(Role::Check, probe, probe_value),
            self.read(probe),
            Some(step(Role::Check, "power cycle", env(Env::PowerCycle))),
            self.read(probe),
        ]
        .into_iter()
        .flatten()
        .collect();
        self.case(
            "command/unsaved-lost",
            &["PSX-CMD-018", "PSX-PAR-SAVED"],
            "a written value without a save is lost in a power cycle",
            lost,
        );
        let kept = self.saved_across_power_cycle(probe, probe_value);
        self.case(
            "command/saved-kept",
            &["PSX-CMD-018", "PSX-PAR-SAVED", "PSX-CMD-014", "PSX-CMD-017"],
            "a value saved with ISDU 193 = 1 survives a power cycle",
            kept,
        );
        // Entries that are never saved.
        let params: Vec<&Parameter> = self.family.parameters.iter().collect();
        for p in params {
            if p.saved != Some(false) || !p.access.writable() || p.id == isdu::DELIVERY_STATE {
                continue;
            }
            // The top of a declared range, else a small step from the delivery value (a
            // control word of transfer bit 2 only).
            let declared = p.range.is_some() || p.range_model;
            let top = self.range(p).and_then(|r| r.last().map(|i| i[1]));
            let Some(v) = top
                .filter(|_| declared)
                .or_else(|| self.default_of(p).map(|d| d.saturating_add(4)))
            else {
                continue;
            };
            let steps = self.saved_across_power_cycle(&p.id, v);
            self.case(
                &format!("command/not-saved/{}", p.id),
                &["PSX-PAR-NOT-SAVED"],
                &format!(
                    "ISDU {} ({}) is not saved: after a save and a power cycle it holds its delivery value",
                    p.id, p.name
                ),
                steps,
            );
        }
    }

    /// Reads of the DeviceID octets of Direct Parameter page 1 (ISDU 0; PSX-DP-007).
    fn device_id_reads(&self) -> Vec<StepDef> {
        let dp = &self.rules.protocol().direct_parameters;
        dp.entries
            .iter()
            .filter(|e| e.name.starts_with("DeviceID"))
            .filter_map(|e| {
                let subindex = e.address.checked_add(dp.subindex_offset)?;
                Some(step(
                    Role::Check,
                    format!("ISDU read {}.{subindex} ({})", dp.isdu_index, e.name),
                    Step::IsduRead {
                        index: dp.isdu_index,
                        subindex,
                    },
                ))
            })
            .collect()
    }

    // ------------------------------------------------------------------ format

    /// Steps that make `format` the active one: write, save, device reset (PSX-PD-010).
    fn switch_to(&mut self, format: u8, role: Role) -> Vec<StepDef> {
        let param = self.rules.protocol().format_select.param.clone();
        let reset = self
            .rules
            .protocol()
            .commands
            .commands
            .iter()
            .find(|c| c.reset && !c.defaults && !c.save)
            .map(|c| (c.param.clone(), c.value));
        let Some((reset_param, reset_value)) = reset else {
            self.errors.push("no device-reset command".to_owned());
            return Vec::new();
        };
        let mut steps: Vec<StepDef> = [
            self.write(role, &param, i64::from(format)),
            self.save(role),
            self.saved(role),
            self.write(role, &reset_param, reset_value),
        ]
        .into_iter()
        .flatten()
        .collect();
        steps.push(step(
            role,
            format!("format {format} idle output"),
            pd_out(self.idle(format)),
        ));
        steps
    }

    fn format_cases(&mut self) {
        let param = self.rules.protocol().format_select.param.clone();
        let formats: Vec<u8> = self.rules.outputs().iter().map(|o| o.format).collect();
        let start = self.value(isdu::ACTUAL);
        for &f in &formats {
            let mut steps = self.device_id_reads();
            steps.extend(self.write(Role::Check, &param, i64::from(f)));
            steps.extend(self.read(&param));
            steps.push(step(
                Role::Check,
                "cycles in the old format",
                Step::Hold { cycles: 2 },
            ));
            steps.extend(self.device_id_reads());
            steps.extend(self.switch_to(f, Role::Check));
            steps.push(step(
                Role::Check,
                "cycles in the new format",
                Step::Hold { cycles: 2 },
            ));
            steps.extend(self.device_id_reads());
            let mut reqs = vec![
                "PSX-PD-001",
                "PSX-PD-010",
                "PSX-DP-005",
                "PSX-DP-007",
                "PSX-DP-008",
                "PSX-PD-007",
            ];
            if f == 2 {
                reqs.push("PSX-PD-005");
            }
            self.case(
                &format!("format/{f}/switch"),
                &reqs,
                &format!(
                    "ISDU 116 = {f} takes effect, with its device ID, only after a save and a device reset"
                ),
                steps,
            );
            let unsaved: Vec<StepDef> = [
                self.write(Role::Check, &param, i64::from(f)),
                Some(step(Role::Check, "power cycle", env(Env::PowerCycle))),
                self.read(&param),
                Some(step(
                    Role::Check,
                    "cycles in format 1",
                    Step::Hold { cycles: 2 },
                )),
            ]
            .into_iter()
            .flatten()
            .chain(self.device_id_reads())
            .collect();
            self.case(
                &format!("format/{f}/unsaved"),
                &["PSX-PD-010", "PSX-CMD-018", "PSX-DP-008"],
                &format!("ISDU 116 = {f} without a save is lost in a power cycle"),
                unsaved,
            );
        }
        // A positioning run in every format.
        let transfer = self.control("release-and-transfer");
        let target = start.saturating_add(4000);
        let f1 = vec![
            step(Role::Check, "0x14 to start+4000", self.f1(transfer, target)),
            step(Role::Check, "until running", Self::until(true)),
            step(Role::Check, "until standstill", Self::until(false)),
        ];
        self.motion(
            "format/1/positioning",
            &["PSX-PD-003", "PSX-CMD-001", "PSX-STS-0-SET-1"],
            "format 1: control word 0x14 and a target start a positioning run",
            f1,
        );
        let mut f2 = self.switch_to(2, Role::Setup);
        f2.extend([
            step(
                Role::Check,
                "speed 0, 0x14 to start+4000",
                self.f2(0, transfer, target),
            ),
            step(Role::Check, "until running", Self::until(true)),
            step(Role::Check, "until standstill", Self::until(false)),
        ]);
        self.motion(
            "format/2/speed-zero",
            &["PSX-PD-004", "PSX-VEL-006", "PSX-VEL-001", "PSX-CMD-001"],
            "format 2: speed 0 in the process data runs at ISDU 142",
            f2,
        );
        self.speed_cases(start, transfer);
        let mut f0 = self.switch_to(0, Role::Setup);
        f0.extend(self.stamp_run(target, 3, 10_000));
        self.motion(
            "format/0/positioning",
            &["PSX-PD-002", "PSX-PD-011", "PSX-TS-010"],
            "format 0: a target through ISDU 112 and control code 3 with a time stamp",
            f0,
        );
    }

    /// The 8-byte format's speed rules (manual 3.3.1; PSX-VEL-005..008).
    fn speed_cases(&mut self, start: i64, transfer: u16) {
        let positioning = self.rules.protocol().target_speed.positioning_param.clone();
        let Some(p) = self.param(&positioning) else {
            return;
        };
        let Some(intervals) = self.range(p) else {
            return;
        };
        let (Some(lo), Some(hi)) = (
            intervals.first().map(|i| i[0]),
            intervals.last().map(|i| i[1]),
        ) else {
            return;
        };
        let mid = (lo + hi) / 2;
        let low = i16::try_from(lo.max(1)).unwrap_or(1);
        let fast = i16::try_from(mid).unwrap_or(1);
        let target = start.saturating_add(8000);
        let mut given = self.switch_to(2, Role::Setup);
        given.extend(
            [
                Some(step(
                    Role::Check,
                    format!("speed {low}, 0x14 to start+8000"),
                    self.f2(low, transfer, target),
                )),
                Some(step(Role::Check, "until running", Self::until(true))),
                Some(step(Role::Check, "running", Step::Hold { cycles: 20 })),
                Some(step(
                    Role::Check,
                    format!("speed {fast} during the run"),
                    self.f2(fast, transfer, target),
                )),
                Some(step(Role::Check, "until standstill", Self::until(false))),
                self.read(&positioning),
            ]
            .into_iter()
            .flatten(),
        );
        self.motion(
            "format/2/speed-given",
            &["PSX-VEL-005", "PSX-VEL-008", "PSX-PD-004"],
            "format 2: the process-data speed is used instead of ISDU 142, also when changed during a run; ISDU 142 stays",
            given,
        );
        let bad = i16::try_from(hi.saturating_add(1)).unwrap_or(i16::MAX);
        let mut invalid = self.switch_to(2, Role::Setup);
        invalid.extend([
            step(
                Role::Check,
                format!("speed {bad} (above the range), 0x14 to start+8000"),
                self.f2(bad, transfer, target),
            ),
            step(Role::Check, "no run", Step::Hold { cycles: 10 }),
            step(
                Role::Check,
                format!("speed {fast}: the run starts"),
                self.f2(fast, transfer, target),
            ),
            step(Role::Check, "until running", Self::until(true)),
            step(
                Role::Check,
                format!("speed {bad} during the run: aborted"),
                self.f2(bad, transfer, target),
            ),
            step(Role::Check, "until standstill", Self::until(false)),
        ]);
        self.motion(
            "format/2/speed-invalid",
            &["PSX-VEL-007", "PSX-STS-12-SET-2"],
            "format 2: an invalid speed starts no run, aborts a running one and sets status bit 12",
            invalid,
        );
        let manual = self.control("release-manual-run-larger");
        let release = self.control("release");
        let mut man = self.switch_to(2, Role::Setup);
        man.extend([
            step(
                Role::Check,
                format!("0x11 with speed {low}"),
                self.f2(low, manual, 0),
            ),
            step(Role::Check, "until running", Self::until(true)),
            step(Role::Check, "manual run", Step::Hold { cycles: 25 }),
            step(Role::Check, "0x10: stop", self.f2(low, release, 0)),
            step(Role::Check, "until standstill", Self::until(false)),
        ]);
        self.motion(
            "format/2/manual",
            &["PSX-CMD-019", "PSX-VEL-005"],
            "format 2: a manual run with 0x11 runs at the process-data speed",
            man,
        );
    }

    // ------------------------------------------------------------------ timestamp

    /// The time-stamp positioning sequence of 4.4 (PSX-TS-010).
    fn stamp_run(&mut self, target: i64, code: u8, stamp: u16) -> Vec<StepDef> {
        let target_param = self.rules.timestamp().target_param.clone();
        let inactive = self.inactive();
        let mut steps = vec![step(Role::Check, "stamp inactive", self.f0(0, inactive))];
        if code == 3 {
            steps.extend(self.write(Role::Check, &target_param, target));
        }
        steps.extend([
            step(
                Role::Check,
                format!("code {code}, stamp {stamp}"),
                self.f0(code, Stamp(stamp)),
            ),
            step(Role::Check, "stamp inactive", self.f0(code, inactive)),
            step(Role::Check, "until running", Self::until(true)),
            step(Role::Check, "until standstill", Self::until(false)),
        ]);
        steps
    }

    fn timestamp_cases(&mut self) {
        let ts = self.rules.timestamp().clone();
        let start = self.value(isdu::ACTUAL);
        let target = start.saturating_add(3000);
        let inactive = self.inactive();
        let target_param = ts.target_param.clone();
        let cw_param = ts.control_word_param.clone();
        let edges = [
            ("max-valid", ts.max_valid, vec!["PSX-TS-003", "PSX-TS-001"]),
            (
                "last-immediate",
                ts.immediate_below.saturating_sub(1),
                vec!["PSX-TS-006"],
            ),
            (
                "first-delayed",
                ts.immediate_below,
                vec!["PSX-TS-006", "PSX-TS-001"],
            ),
            ("zero", 0, vec!["PSX-TS-006"]),
        ];
        for (name, stamp, reqs) in edges {
            let mut steps = self.switch_to(0, Role::Setup);
            steps.extend(self.stamp_run(target, 3, u16::try_from(stamp).unwrap_or(0)));
            self.motion(
                &format!("timestamp/edge/{name}"),
                &reqs,
                &format!("time stamp {stamp} with control code 3 (stamp inactive after it)"),
                steps,
            );
        }
        let mut steps = self.switch_to(0, Role::Setup);
        steps.extend(self.stamp_run(target, 3, 10_000));
        self.motion(
            "timestamp/position",
            &["PSX-TS-010", "PSX-TS-005", "PSX-TS-008", "PSX-TS-001"],
            "positioning by time stamp: executed the stamp's delay after the field turns inactive",
            steps,
        );
        let mut steps = self.switch_to(0, Role::Setup);
        steps.push(step(Role::Check, "stamp inactive", self.f0(0, inactive)));
        steps.extend(self.write(Role::Check, &target_param, target));
        steps.extend([
            step(
                Role::Check,
                format!("code 3, stamp {}: no new time stamp", inactive.0),
                self.f0(3, inactive),
            ),
            step(Role::Check, "nothing runs", Step::Hold { cycles: 30 }),
            step(Role::Check, "code 3, stamp 2500", self.f0(3, Stamp(2500))),
            step(Role::Check, "stamp inactive", self.f0(3, inactive)),
            step(Role::Check, "until running", Self::until(true)),
            step(Role::Check, "until standstill", Self::until(false)),
        ]);
        self.motion(
            "timestamp/inactive-value",
            &["PSX-TS-002"],
            "the stamp value 0x3FFF is no time stamp: a control code with it runs nothing; a valid stamp then runs when the field turns inactive",
            steps,
        );
        let mut steps = self.switch_to(0, Role::Setup);
        steps.push(step(Role::Check, "stamp inactive", self.f0(0, inactive)));
        steps.extend(self.write(Role::Check, &target_param, target));
        steps.extend([
            step(Role::Check, "code 3, stamp 2500", self.f0(3, Stamp(2500))),
            step(
                Role::Check,
                "the valid stamp repeated: nothing runs",
                Step::Hold { cycles: 30 },
            ),
            step(Role::Check, "code 3, stamp 3000", self.f0(3, Stamp(3000))),
            step(Role::Check, "still nothing", Step::Hold { cycles: 10 }),
            step(Role::Check, "stamp inactive", self.f0(3, inactive)),
            step(Role::Check, "until running", Self::until(true)),
            step(Role::Check, "until standstill", Self::until(false)),
        ]);
        self.motion(
            "timestamp/not-while-active",
            &["PSX-TS-004", "PSX-TS-005"],
            "a valid stamp sent cyclically causes no action; the last one runs after the field turns inactive",
            steps,
        );
        for (code, name) in [(1u8, "forward"), (2, "reverse")] {
            let mut steps = self.switch_to(0, Role::Setup);
            steps.extend([
                step(Role::Check, "stamp inactive", self.f0(0, inactive)),
                step(
                    Role::Check,
                    format!("code {code}, stamp 5000"),
                    self.f0(code, Stamp(5000)),
                ),
                step(Role::Check, "stamp inactive", self.f0(code, inactive)),
                step(Role::Check, "until running", Self::until(true)),
                step(Role::Check, "manual run", Step::Hold { cycles: 25 }),
                step(Role::Check, "code 0, stamp 0: cancel", self.f0(0, Stamp(0))),
                step(Role::Check, "until standstill", Self::until(false)),
            ]);
            self.motion(
                &format!("timestamp/manual-{name}"),
                &["PSX-TS-011", "PSX-TS-007", "PSX-PD-011"],
                &format!("a manual run {name} by time stamp, cancelled by code 0 with stamp 0"),
                steps,
            );
        }
        let no_loop = self.control("run-without-loop");
        let back = start.saturating_sub(3000);
        let mut steps = self.switch_to(0, Role::Setup);
        steps.extend(self.write(Role::Check, &cw_param, i64::from(no_loop)));
        steps.extend(self.stamp_run(back, 3, 5000));
        self.motion(
            "timestamp/without-loop",
            &["PSX-TS-012", "PSX-PD-012", "PSX-RUN-007"],
            "control bit 6 set through ISDU 110, then a time-stamp positioning against the loop direction runs without loop",
            steps,
        );
        let release = self.control("release");
        let mut steps = self.switch_to(0, Role::Setup);
        steps.push(step(Role::Check, "stamp inactive", self.f0(0, inactive)));
        steps.extend(self.write(Role::Check, &cw_param, i64::from(release)));
        steps.extend(self.write(Role::Check, &target_param, target));
        steps.extend([
            step(Role::Check, "until running", Self::until(true)),
            step(Role::Check, "until standstill", Self::until(false)),
        ]);
        self.motion(
            "timestamp/isdu-control",
            &["PSX-PD-013", "PSX-CMD-009"],
            "with the stamp inactive, ISDU 110 = 0x10 and a target in ISDU 112 start a run",
            steps,
        );
    }
}

/// Why the PSx3xx cases cannot be generated from the spec.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub(crate) enum GenerateError {
    /// The spec lacks what cases need: the first problem and how many there are.
    #[error("{first} ({count} problem(s))")]
    Spec {
        /// The first problem.
        first: String,
        /// How many.
        count: usize,
    },
    /// Two cases have the same id.
    #[error("duplicate case id {id}")]
    DuplicateId {
        /// The id.
        id: String,
    },
}

/// Every case for `model`, in run order; `base` is the reference drive at power-on and
/// `cycle_us` the bus cycle.
pub(crate) fn generate<'s>(
    family: &Family,
    model: &DeviceModel,
    base: &Drive<'s>,
    cycle_us: u64,
) -> Result<(Vec<CaseInfo>, Vec<PsxCase>), GenerateError> {
    let brake = base.brake().and_then(|kind| {
        family
            .psx3xx()
            .and_then(|p| p.brakes.iter().find(|b| b.kind == kind.spec_name()))
    });
    let mut g = Gen {
        family,
        brake,
        model,
        rules: base.rules(),
        base,
        cycle_us,
        errors: Vec::new(),
        out: Vec::new(),
    };
    g.isdu_cases();
    g.guard_cases();
    g.command_cases();
    g.format_cases();
    g.timestamp_cases();
    g.scenario_cases();
    g.sequence_cases();
    g.brake_cases();
    if let Some(e) = g.errors.first() {
        return Err(GenerateError::Spec {
            first: e.clone(),
            count: g.errors.len(),
        });
    }
    let mut seen = std::collections::BTreeSet::new();
    for (info, _) in &g.out {
        if !seen.insert(info.id.clone()) {
            return Err(GenerateError::DuplicateId {
                id: info.id.clone(),
            });
        }
    }
    Ok(g.out.into_iter().unzip())
}

/// The requirement that an ISDU entry accepts only its range (3.1 value ranges, 3.2 model
/// ranges): `PSX-ISDU-<id>-RANGE`.
pub(crate) fn range_requirement(id: &str) -> String {
    format!("PSX-ISDU-{id}-RANGE")
}
