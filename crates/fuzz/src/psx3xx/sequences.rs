//! Sequences for the PSx3xx fuzz target, from the spec: ISDU indices and sub-indices in and
//! out of the table, values at, inside and beyond each model's range (and in range gaps),
//! writes to read-only entries and with wrong lengths, guard-entry sequences, the ISDU 2 and
//! ISDU 193 commands (and values that are none), saves and power cycles, process-data format
//! switches (ISDU 116, save, reset), positioning runs in the active format, control words with
//! reserved bits, the 8-byte format's speed values (0 falls back to ISDU 142, range edges,
//! invalid values, changes during a run), time-stamp edge values (0, the last immediate and
//! first delayed stamp, the largest valid, the reserved values, inactive; valid stamps sent
//! cyclically), jog keys and other environment injections, and the master falling silent
//! (manual 3.1–3.4, 4, 5).
//!
//! A sequence mixes 1 to 4 templates. The generator follows the process-data format the
//! sequence makes active (working, saved and active ISDU 116, as the command table says), so
//! every output image is in the format the drive expects. Every value is drawn from the seeded
//! [`Rng`] only; every requirement ID a step names is checked against the spec when the
//! generator is built.

use crate::engine::{self, below, chance, pick, templates};
use crate::replay::{Action, Step};
use drivespec_conform::cyclic::Env;
use drivespec_conform::psx3xx::Psx3xxSuite;
use drivespec_psd4xx::model::LinkEvent;
use drivespec_psx3xx::isdu::{Target, Value};
use drivespec_psx3xx::step::Step as PsxStep;
use drivespec_psx3xx::{Guards, Rules};
use drivespec_sim::rng::Rng;
use drivespec_spec::psx3xx::{FormatEffect, StateCommand};
use drivespec_spec::{Access, Family, Readings};

/// Most steps in one sequence.
const MAX_STEPS: usize = 40;

/// Most cycles a wait for running or standstill takes.
const WAIT_MAX: u32 = 1_500;

/// ISDU 182, temperature limit (°C): the temperatures injected lie around it.
const TEMPERATURE_LIMIT: &str = "182";
/// ISDU 135, jog increment: the saved entry the save template changes.
const PROBE: &str = "135";
/// ISDU 12, device access locks: never written (a lock would refuse the format switches).
const LOCKS: &str = "12";
/// ISDU 2, IO-Link standard command.
const STANDARD_COMMAND: &str = "2";
/// ISDU 193, delivery state and save command.
const DELIVERY_STATE: &str = "193";

templates! {
    /// Templates and their weights.
    Read = 6, Write = 8, OutOfRange = 6, ReadOnly = 4, UnknownIndex = 3, UnknownSubindex = 3,
    Length = 3, Guard = 5, StandardCommand = 4, DeliveryState = 3, SavePowerCycle = 4,
    FormatSwitch = 4, Position = 7, Control = 5, Speed = 6, Stamp = 7, Keys = 4, Environment = 6,
    Silence = 4
}

/// Requirement IDs of each template (checked against the spec in [`PsxGen::new`]).
fn reqs(t: Template) -> &'static [&'static str] {
    match t {
        Template::Read => &["PSX-DP-009", "PSX-DP-ERR-007"],
        Template::Write => &["PSX-PAR-DEFAULTS"],
        Template::OutOfRange => &["PSX-DP-ERR-004"],
        Template::ReadOnly => &["PSX-DP-ERR-003"],
        Template::UnknownIndex => &["PSX-DP-ERR-001"],
        Template::UnknownSubindex => &["PSX-DP-ERR-002"],
        Template::Length => &["PSX-DP-ERR-006"],
        Template::Guard => &["PSX-GUARD-ONESHOT"],
        Template::StandardCommand => &["PSX-DP-ERR-005", "PSX-CMD-018", "PSX-PAR-SAVED"],
        Template::DeliveryState => &[
            "PSX-ISDU-193-RANGE",
            "PSX-CMD-014",
            "PSX-CMD-017",
            "PSX-PAR-DEFAULTS",
        ],
        Template::SavePowerCycle => &["PSX-CMD-018", "PSX-PAR-SAVED", "PSX-PAR-NOT-SAVED"],
        Template::FormatSwitch => &["PSX-PD-001", "PSX-PD-010", "PSX-DP-007", "PSX-DP-008"],
        Template::Position => &[
            "PSX-PD-003",
            "PSX-PD-004",
            "PSX-CMD-001",
            "PSX-RUN-001",
            "PSX-STS-12-SET-1",
        ],
        Template::Control => &[
            "PSX-CTL-WORDS",
            "PSX-CTL-13-1",
            "PSX-CTL-15-1",
            "PSX-CTL-14-1",
            "PSX-CMD-002",
            "PSX-RUN-007",
        ],
        Template::Speed => &[
            "PSX-VEL-005",
            "PSX-VEL-006",
            "PSX-VEL-007",
            "PSX-VEL-008",
            "PSX-CMD-019",
        ],
        Template::Stamp => &[
            "PSX-TS-001",
            "PSX-TS-002",
            "PSX-TS-003",
            "PSX-TS-004",
            "PSX-TS-005",
            "PSX-TS-006",
            "PSX-TS-009",
            "PSX-TS-010",
            "PSX-TS-011",
        ],
        Template::Keys => &[
            "PSX-JOG-005",
            "PSX-JOG-006",
            "PSX-STS-2-SET-1",
            "PSX-STS-3-SET-1",
        ],
        Template::Environment => &[
            "PSX-STS-7-SET-1",
            "PSX-STS-4-RESET-1",
            "PSX-STS-10-SET-1",
            "PSX-STS-11-SET-1",
            "PSX-STS-13-SET-1",
        ],
        Template::Silence => &[
            "PSX-TIMEOUT-001",
            "PSX-TIMEOUT-002",
            "PSX-TIMEOUT-003",
            "PSX-TIMEOUT-004",
            "PSX-TIMEOUT-005",
            "PSX-TIMEOUT-006",
        ],
    }
}

fn class(t: Template) -> &'static str {
    match t {
        Template::Read => "isdu-read",
        Template::Write => "isdu-write",
        Template::OutOfRange => "isdu-write-out-of-range",
        Template::ReadOnly => "isdu-write-read-only",
        Template::UnknownIndex => "isdu-unknown-index",
        Template::UnknownSubindex => "isdu-unknown-subindex",
        Template::Length => "isdu-wrong-length",
        Template::Guard => "guard-entry",
        Template::StandardCommand => "standard-command",
        Template::DeliveryState => "delivery-state",
        Template::SavePowerCycle => "save-power-cycle",
        Template::FormatSwitch => "format-switch",
        Template::Position => "position",
        Template::Control => "control-word",
        Template::Speed => "format-2-speed",
        Template::Stamp => "time-stamp",
        Template::Keys => "jog-keys",
        Template::Environment => "environment",
        Template::Silence => "master-silent",
    }
}

/// An ISDU entry as the generator uses it.
#[derive(Debug, Clone)]
struct Entry {
    id: String,
    name: String,
    index: u16,
    subindex: u8,
    readable: bool,
    writable: bool,
    read_only: bool,
    /// Octets of the data type (None: strings).
    width: Option<usize>,
    /// Declared range for the model (intervals), None when the entry has none.
    range: Option<Vec<[i64; 2]>>,
    /// The entry's own range requirement (`PSX-ISDU-<id>-RANGE`), when the spec has one.
    range_req: Option<String>,
}

/// The process-data format as the master's sequence leaves it (manual 3.1 ISDU 116, 193).
#[derive(Debug, Clone, Copy)]
struct Formats {
    /// Format the drive runs (its output image).
    active: u8,
    /// Working value of ISDU 116.
    working: u8,
    /// Saved value of ISDU 116.
    saved: u8,
}

/// The control words and bits used, by their spec names (3.3.1, 4).
#[derive(Debug, Clone, Copy)]
struct Controls {
    run: u16,
    release: u16,
    transfer_only: u16,
    up: u16,
    down: u16,
    no_loop: u16,
    jog_keys: u16,
    jog_up: u16,
    jog_down: u16,
    clear: u16,
    reserved: u16,
}

/// The generator for one suite (model).
pub(crate) struct PsxGen<'s> {
    rules: Rules<'s>,
    entries: Vec<Entry>,
    guards: Guards,
    commands: Vec<StateCommand>,
    ctl: Controls,
    format_param: String,
    formats: Vec<u8>,
    default_format: u8,
    /// Actual position after power-on, and the limits (ISDU 130, 129) at delivery.
    start: i64,
    limits: (i64, i64),
    /// The positioning speed range (ISDU 142) for the model.
    speed: (i64, i64),
    /// Cycles a save takes at most.
    save_cycles: u32,
    /// Cycles of a short and a long key press (ISDU 163 wait, 5 ms steps).
    key_cycles: (u32, u32),
    /// The temperature limit (ISDU 182) at delivery.
    temperature_limit: i64,
    /// The injections the device takes (by name, as on the `ENV` line).
    envs: Vec<String>,
}

/// One injection of each kind the generator sends, with a harmless value: what is probed
/// before a run (the injections are optional in `drivespec-cyclic/1`).
pub(crate) const ENV_KINDS: [Env; 8] = [
    Env::Keys {
        forward: false,
        reverse: false,
    },
    Env::Temperature(25),
    Env::MotorVoltage(240),
    Env::Jam(false),
    Env::Displace(0),
    Env::Link(LinkEvent::Connected),
    Env::LoadTorque(0),
    Env::PowerCycle,
];

/// One entry of the time-stamp output (format 0): code and stamp.
type StampOut = (u8, u16);

impl<'s> PsxGen<'s> {
    /// The generator for the suite's model, sending only the injections of the kinds in
    /// `envs` (their names on the `ENV` line); an error names what the spec lacks.
    pub(crate) fn new(suite: &Psx3xxSuite<'s>, envs: Vec<String>) -> Result<PsxGen<'s>, String> {
        let family: &Family = suite.family();
        let rules = suite.reference().rules().clone();
        let model = family
            .model(suite.model())
            .ok_or_else(|| format!("no model {}", suite.model()))?;
        engine::requirements_known(family, TEMPLATES.iter().flat_map(|(t, _)| reqs(*t)))?;
        let entries: Vec<Entry> = family
            .parameters
            .iter()
            .filter_map(|p| {
                let index = u16::try_from(p.number).ok()?;
                let subindex = u8::try_from(p.subindex.unwrap_or(0)).ok()?;
                let declared = p.range.is_some() || p.range_model;
                let range = family
                    .resolve(p, Some(model))
                    .range
                    .filter(|_| declared)
                    .map(|r| r.intervals().to_vec());
                let range_req = format!("PSX-ISDU-{}-RANGE", p.id);
                Some(Entry {
                    id: p.id.clone(),
                    name: p.name.clone(),
                    index,
                    subindex,
                    readable: p.access.readable(),
                    writable: p.access.writable(),
                    read_only: p.access == Access::R,
                    width: p.data_type.width().and_then(|w| usize::try_from(w).ok()),
                    range,
                    range_req: family.requirement(&range_req).map(|r| r.id.clone()),
                })
            })
            .collect();
        let guards = Guards::from_rules(&rules, &Readings::default()).map_err(|e| e.to_string())?;
        if let Some(g) = guards
            .guards()
            .iter()
            .find(|g| family.requirement(&g.requirement).is_none())
        {
            return Err(format!(
                "guard {} names no requirement of the spec",
                g.guard
            ));
        }
        let value = |id: &str| match suite.reference().value(id) {
            Value::Int(v) => Ok(v),
            other => Err(format!("ISDU {id} is {other:?}, not a number")),
        };
        let control = |name: &str| -> Result<u16, String> {
            family
                .bitfield("control")
                .and_then(|b| b.values.iter().find(|v| v.name == name))
                .and_then(|v| u16::try_from(v.value).ok())
                .ok_or_else(|| format!("no control-word value {name:?}"))
        };
        let bit = |name: &str| -> Result<u16, String> {
            family
                .bitfield("control")
                .and_then(|b| b.bits.iter().find(|x| x.name == name))
                .and_then(|x| 1u16.checked_shl(x.bit))
                .ok_or_else(|| format!("no control bit {name:?}"))
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
            run: control("release-and-transfer")?,
            release: control("release")?,
            transfer_only: control("transfer-without-release")?,
            up: control("release-manual-run-larger")?,
            down: control("release-manual-run-smaller")?,
            no_loop: bit("Run without loop")?,
            jog_keys: bit("Release jog operation with keys")?,
            jog_up: bit("Jog to larger values")?,
            jog_down: bit("Jog to smaller values")?,
            clear: bit("Clear error bits")?,
            reserved,
        };
        let protocol = rules.protocol();
        let positioning = &protocol.target_speed.positioning_param;
        let speed = entries
            .iter()
            .find(|e| &e.id == positioning)
            .and_then(|e| e.range.as_ref())
            .and_then(|r| Some((r.first()?[0], r.last()?[1])))
            .ok_or_else(|| format!("no range of ISDU {positioning}"))?;
        let cycle_us = suite.cycle_us().max(1);
        let save_cycles = u32::try_from(
            u64::from(protocol.commands.save_max_ms)
                .saturating_mul(1000)
                .div_ceil(cycle_us),
        )
        .unwrap_or(u32::MAX);
        // The wait before a held key turns into a manual run, in 5 ms steps (5.10).
        let wait_cycles = u32::try_from(
            value(&protocol.jog.wait_param)?
                .saturating_mul(5_000)
                .div_euclid(cycle_as_i64(cycle_us)),
        )
        .unwrap_or(1);
        Ok(PsxGen {
            format_param: protocol.format_select.param.clone(),
            formats: rules.outputs().iter().map(|o| o.format).collect(),
            default_format: rules.default_format(),
            commands: protocol.commands.commands.clone(),
            start: value(&protocol.mapping.actual_param)?,
            limits: (
                value(&protocol.mapping.lower_limit_param)?,
                value(&protocol.mapping.upper_limit_param)?,
            ),
            speed,
            save_cycles,
            key_cycles: (1, wait_cycles.saturating_add(10)),
            temperature_limit: value(TEMPERATURE_LIMIT)?,
            rules,
            entries,
            guards,
            ctl,
            envs,
        })
    }

    /// The next sequence.
    pub(crate) fn sequence(&self, rng: &mut Rng) -> Vec<Step> {
        let mut out = Vec::new();
        let d = self.default_format;
        let mut f = Formats {
            active: d,
            working: d,
            saved: d,
        };
        let n = rng.range(1, 4);
        for _ in 0..n {
            let t = self.template(rng);
            self.action(rng, t, &mut f, &mut out);
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
            Template::Keys => self.takes("keys"),
            Template::Environment => !self.envs.is_empty(),
            _ => true,
        };
        engine::weighted(rng, TEMPLATES, usable, Template::Read)
    }

    fn push(&self, out: &mut Vec<Step>, t: Template, step: PsxStep, text: String) {
        self.push_with(out, t, step, text, &[]);
    }

    fn push_with(
        &self,
        out: &mut Vec<Step>,
        t: Template,
        step: PsxStep,
        text: String,
        extra: &[String],
    ) {
        let mut requirements: Vec<String> = reqs(t).iter().map(|s| (*s).to_owned()).collect();
        requirements.extend(extra.iter().cloned());
        requirements.dedup();
        out.push(Step {
            action: Action::Psx3xx(step),
            class: class(t).to_owned(),
            text,
            requirements,
        });
    }

    fn entry(&self, id: &str) -> Option<&Entry> {
        self.entries.iter().find(|e| e.id == id)
    }

    /// One of the entries that pass `f`.
    fn pick_entry(&self, rng: &mut Rng, f: impl Fn(&Entry) -> bool) -> Option<&Entry> {
        let list: Vec<&Entry> = self.entries.iter().filter(|e| f(e)).collect();
        pick(rng, &list).copied()
    }

    /// The octets of `value` for an entry, None when its data type cannot hold it.
    fn encode(&self, e: &Entry, value: i64) -> Option<Vec<u8>> {
        let target: Target<'_> = self.rules.isdu_target(e.index, e.subindex).ok()?;
        self.rules.encode_value(&target, &Value::Int(value)).ok()
    }

    fn read(&self, out: &mut Vec<Step>, t: Template, e: &Entry) {
        self.push(
            out,
            t,
            PsxStep::IsduRead {
                index: e.index,
                subindex: e.subindex,
            },
            format!("ISDU read {}.{} ({})", e.index, e.subindex, e.name),
        );
    }

    /// A write of `value`; false when the data type cannot hold it.
    fn write(&self, out: &mut Vec<Step>, t: Template, e: &Entry, value: i64) -> bool {
        let Some(data) = self.encode(e, value) else {
            return false;
        };
        let extra: Vec<String> = e.range_req.iter().cloned().collect();
        self.push_with(
            out,
            t,
            PsxStep::IsduWrite {
                index: e.index,
                subindex: e.subindex,
                data,
            },
            format!(
                "ISDU write {}.{} ({}) = {value}",
                e.index, e.subindex, e.name
            ),
            &extra,
        );
        true
    }

    fn write_id(&self, out: &mut Vec<Step>, t: Template, id: &str, value: i64) -> bool {
        match self.entry(id) {
            Some(e) => self.write(out, t, e, value),
            None => false,
        }
    }

    fn hold(&self, out: &mut Vec<Step>, t: Template, cycles: u32) {
        self.push(
            out,
            t,
            PsxStep::Hold { cycles },
            format!("{cycles} cycle(s)"),
        );
    }

    fn until(&self, out: &mut Vec<Step>, t: Template, running: bool) {
        self.push(
            out,
            t,
            PsxStep::Until {
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

    fn env(&self, out: &mut Vec<Step>, t: Template, env: Env) {
        self.push(
            out,
            t,
            PsxStep::Env {
                env: env.to_string(),
            },
            format!("env {env}"),
        );
    }

    /// Process data in format 1 or 2 (`speed` only in format 2).
    fn pd(&self, out: &mut Vec<Step>, t: Template, f: u8, control: u16, target: i64, speed: i16) {
        let target = i32::try_from(target).unwrap_or(if target < 0 { i32::MIN } else { i32::MAX });
        let text = if f == 2 {
            format!("format 2: speed {speed} control {control:#06x} target {target}")
        } else {
            format!("format {f}: control {control:#06x} target {target}")
        };
        self.push(
            out,
            t,
            PsxStep::PdOut {
                format: f,
                control,
                target,
                speed: if f == 2 { speed } else { 0 },
                stamp: 0,
            },
            text,
        );
    }

    /// Process data in format 0: a time-stamp code and stamp.
    fn stamp(&self, out: &mut Vec<Step>, t: Template, (code, stamp): StampOut) {
        self.push(
            out,
            t,
            PsxStep::PdOut {
                format: 0,
                control: u16::from(code),
                target: 0,
                speed: 0,
                stamp,
            },
            format!("format 0: code {code} stamp {stamp}"),
        );
    }

    fn inactive(&self) -> u16 {
        u16::try_from(self.rules.timestamp().inactive).unwrap_or(u16::MAX)
    }

    /// The all-zero output of the active format (format 0: the stamp inactive).
    fn idle(&self, out: &mut Vec<Step>, t: Template, f: u8) {
        if f == 0 {
            self.stamp(out, t, (0, self.inactive()));
        } else {
            self.pd(out, t, f, 0, 0, 0);
        }
    }

    /// A target near the start position, inside the limits.
    fn target(&self, rng: &mut Rng) -> i64 {
        let (lo, hi) = self.limits;
        let d = rng.range(-8_000, 8_000);
        self.start.saturating_add(d).clamp(lo.min(hi), hi.max(lo))
    }

    /// Applies a command of the table to the formats (manual 3.1 ISDU 2, 193).
    fn command_effect(c: &StateCommand, f: &mut Formats, default: u8) {
        if c.defaults && c.format == FormatEffect::Default {
            f.working = default;
        }
        if c.save {
            f.saved = f.working;
        }
        if c.reset {
            f.active = f.saved;
            f.working = f.saved;
        }
    }

    /// A power cycle or a device reset: the saved format becomes active; the output image
    /// follows at once.
    fn restarted(&self, out: &mut Vec<Step>, t: Template, f: &mut Formats) {
        f.active = f.saved;
        f.working = f.saved;
        self.idle(out, t, f.active);
    }

    /// The device-reset command of the table (ISDU 2 = 128).
    fn reset_command(&self) -> Option<&StateCommand> {
        self.commands
            .iter()
            .find(|c| c.reset && !c.defaults && !c.save)
    }

    /// The save command of ISDU 193 (= 1).
    fn save_command(&self) -> Option<&StateCommand> {
        self.commands
            .iter()
            .find(|c| c.param == DELIVERY_STATE && c.save && !c.defaults)
    }

    /// Steps that make `to` the active format: write, save, wait, reset or power cycle
    /// (PSX-PD-010).
    fn switch(&self, rng: &mut Rng, out: &mut Vec<Step>, t: Template, to: u8, f: &mut Formats) {
        let (Some(save), Some(reset)) = (self.save_command(), self.reset_command()) else {
            return;
        };
        // A save still running from before would refuse the write.
        self.hold(out, t, self.save_cycles);
        if !self.write_id(out, t, &self.format_param, i64::from(to)) {
            return;
        }
        f.working = to;
        self.write_id(out, t, &save.param, save.value);
        f.saved = to;
        self.hold(out, t, self.save_cycles);
        if self.takes("power-cycle") && chance(rng, 40) {
            self.env(out, t, Env::PowerCycle);
        } else {
            self.write_id(out, t, &reset.param, reset.value);
        }
        self.restarted(out, t, f);
    }

    fn action(&self, rng: &mut Rng, t: Template, f: &mut Formats, out: &mut Vec<Step>) {
        let c = self.ctl;
        let fp = self.format_param.clone();
        match t {
            Template::Read => {
                if let Some(e) = self.pick_entry(rng, |_| true) {
                    let e = e.clone();
                    self.read(out, t, &e);
                }
            }
            Template::Write => {
                // Never the format (its own template), the commands, the locks or the
                // Direct Parameter page.
                let Some(e) = self.pick_entry(rng, |e| {
                    e.writable
                        && e.range.is_some()
                        && e.index != 0
                        && ![fp.as_str(), LOCKS, STANDARD_COMMAND, DELIVERY_STATE]
                            .contains(&e.id.as_str())
                }) else {
                    return;
                };
                let e = e.clone();
                let Some(r) = e.range.clone() else {
                    return;
                };
                let Some(iv) = pick(rng, &r).copied() else {
                    return;
                };
                let v = match rng.range(0, 2) {
                    0 => iv[0],
                    1 => iv[1],
                    _ => rng.range(iv[0], iv[1]),
                };
                if self.write(out, t, &e, v) {
                    if e.readable && chance(rng, 70) {
                        self.read(out, t, &e);
                    }
                    if chance(rng, 30) {
                        self.hold(out, t, 2);
                    }
                }
            }
            Template::OutOfRange => {
                let Some(e) = self.pick_entry(rng, |e| {
                    e.writable && e.range.is_some() && e.index != 0 && e.id != LOCKS
                }) else {
                    return;
                };
                let e = e.clone();
                let Some(r) = e.range.clone() else {
                    return;
                };
                let (Some(first), Some(last)) = (r.first(), r.last()) else {
                    return;
                };
                let mut values = vec![
                    first[0].saturating_sub(1),
                    last[1].saturating_add(1),
                    first[0].saturating_sub(rng.range(2, 1_000)),
                    last[1].saturating_add(rng.range(2, 1_000)),
                ];
                for w in r.windows(2) {
                    if let [a, b] = w {
                        if b[0] > a[1].saturating_add(1) {
                            values.push(rng.range(a[1].saturating_add(1), b[0].saturating_sub(1)));
                        }
                    }
                }
                let v = pick(rng, &values).copied().unwrap_or(0);
                if self.write(out, t, &e, v) && e.readable {
                    self.read(out, t, &e);
                }
            }
            Template::ReadOnly => {
                let Some(e) = self.pick_entry(rng, |e| e.read_only && e.width.is_some()) else {
                    return;
                };
                let e = e.clone();
                let len = e.width.unwrap_or(1);
                let data: Vec<u8> = (0..len).map(|_| rng.byte()).collect();
                self.push(
                    out,
                    t,
                    PsxStep::IsduWrite {
                        index: e.index,
                        subindex: e.subindex,
                        data,
                    },
                    format!(
                        "ISDU write {}.{} ({}, read-only)",
                        e.index, e.subindex, e.name
                    ),
                );
                if chance(rng, 60) {
                    self.read(out, t, &e);
                }
            }
            Template::UnknownIndex => {
                // A few draws at most: the table leaves most indices free.
                let Some(index) = (0..64)
                    .map(|_| match rng.range(0, 2) {
                        0 => u16::try_from(rng.range(1, 300)).unwrap_or(1),
                        1 => u16::try_from(rng.range(300, i64::from(u16::MAX))).unwrap_or(1),
                        _ => u16::MAX,
                    })
                    .find(|i| !self.entries.iter().any(|e| e.index == *i))
                else {
                    return;
                };
                let subindex = if chance(rng, 80) { 0 } else { rng.byte() };
                if chance(rng, 50) {
                    self.push(
                        out,
                        t,
                        PsxStep::IsduRead { index, subindex },
                        format!("ISDU read {index}.{subindex} (not in the table)"),
                    );
                } else {
                    let len = rng.range(1, 4);
                    let data: Vec<u8> = (0..len).map(|_| rng.byte()).collect();
                    self.push(
                        out,
                        t,
                        PsxStep::IsduWrite {
                            index,
                            subindex,
                            data,
                        },
                        format!("ISDU write {index}.{subindex} (not in the table)"),
                    );
                }
            }
            Template::UnknownSubindex => {
                let Some(e) = self.pick_entry(rng, |e| e.index != 0) else {
                    return;
                };
                let index = e.index;
                let used: Vec<u8> = self
                    .entries
                    .iter()
                    .filter(|x| x.index == index)
                    .map(|x| x.subindex)
                    .collect();
                // Sub-index 0 of a record reads the whole record: never "unknown".
                let first = rng.byte().max(1);
                let Some(subindex) = (0..=u8::MAX)
                    .map(|k| first.wrapping_add(k).max(1))
                    .find(|x| !used.contains(x))
                else {
                    return;
                };
                if chance(rng, 50) {
                    self.push(
                        out,
                        t,
                        PsxStep::IsduRead { index, subindex },
                        format!("ISDU read {index}.{subindex} (no such sub-index)"),
                    );
                } else {
                    let len = e.width.unwrap_or(2);
                    let data: Vec<u8> = (0..len).map(|_| rng.byte()).collect();
                    self.push(
                        out,
                        t,
                        PsxStep::IsduWrite {
                            index,
                            subindex,
                            data,
                        },
                        format!("ISDU write {index}.{subindex} (no such sub-index)"),
                    );
                }
            }
            Template::Length => {
                let Some(e) = self.pick_entry(rng, |e| {
                    e.writable && e.width.is_some() && e.index != 0 && e.id != LOCKS
                }) else {
                    return;
                };
                let e = e.clone();
                let w = e.width.unwrap_or(1);
                let len = match rng.range(0, 2) {
                    0 => w.saturating_add(1),
                    1 => w.saturating_sub(1),
                    _ => w.saturating_add(below(rng, 6)).saturating_add(2),
                }
                .max(1);
                if len == w {
                    return;
                }
                let data: Vec<u8> = (0..len).map(|_| rng.byte()).collect();
                self.push(
                    out,
                    t,
                    PsxStep::IsduWrite {
                        index: e.index,
                        subindex: e.subindex,
                        data,
                    },
                    format!(
                        "ISDU write {}.{} ({}) with {len} octet(s) for {w}",
                        e.index, e.subindex, e.name
                    ),
                );
                if e.readable {
                    self.read(out, t, &e);
                }
            }
            Template::Guard => {
                let Some(g) = pick(rng, self.guards.guards()).cloned() else {
                    return;
                };
                if g.guarded == fp {
                    return;
                }
                let (Some(guard), Some(guarded)) = (self.entry(&g.guard), self.entry(&g.guarded))
                else {
                    return;
                };
                let (guard, guarded) = (guard.clone(), guarded.clone());
                let extra = vec![g.requirement.clone()];
                let value = match rng.range(0, 3) {
                    0 | 1 => g.suppress,
                    2 => g.allow.unwrap_or(1),
                    _ => rng.range(-2, 3),
                };
                if let Some(data) = self.encode(&guard, value) {
                    self.push_with(
                        out,
                        t,
                        PsxStep::IsduWrite {
                            index: guard.index,
                            subindex: guard.subindex,
                            data,
                        },
                        format!("ISDU write {} (guard) = {value}", guard.id),
                        &extra,
                    );
                }
                if chance(rng, 30) {
                    if let Some(p) = self.entry(PROBE).cloned() {
                        let v = p.range.as_ref().and_then(|r| r.last()).map_or(1, |i| i[1]);
                        self.write(out, t, &p, v);
                    }
                }
                if chance(rng, 20) {
                    self.hold(out, t, 2);
                }
                let base = guarded
                    .range
                    .as_ref()
                    .and_then(|r| r.first())
                    .map_or(0, |i| i[0]);
                let top = guarded
                    .range
                    .as_ref()
                    .and_then(|r| r.last())
                    .map_or(1_000, |i| i[1]);
                let v = rng.range(base, top.min(base.saturating_add(100_000)));
                if let Some(data) = self.encode(&guarded, v) {
                    self.push_with(
                        out,
                        t,
                        PsxStep::IsduWrite {
                            index: guarded.index,
                            subindex: guarded.subindex,
                            data,
                        },
                        format!("ISDU write {} (guarded) = {v}", guarded.id),
                        &extra,
                    );
                }
                if guarded.readable {
                    self.read(out, t, &guarded);
                }
                if chance(rng, 30) {
                    self.hold(out, t, 3);
                }
            }
            Template::StandardCommand => {
                let known: Vec<&StateCommand> = self
                    .commands
                    .iter()
                    .filter(|x| x.param == STANDARD_COMMAND)
                    .collect();
                let cmd = if chance(rng, 60) {
                    pick(rng, &known).copied()
                } else {
                    None
                };
                let value = match cmd {
                    Some(x) => x.value,
                    None => {
                        let v = i64::from(rng.byte());
                        if known.iter().any(|x| x.value == v) {
                            0
                        } else {
                            v
                        }
                    }
                };
                if !self.write_id(out, t, STANDARD_COMMAND, value) {
                    return;
                }
                if let Some(x) = cmd {
                    Self::command_effect(x, f, self.default_format);
                    if x.reset {
                        self.idle(out, t, f.active);
                    }
                    if x.save {
                        self.hold(out, t, self.save_cycles);
                    }
                    if x.reference_loop || x.centre_run {
                        self.until(out, t, false);
                    }
                }
                if let Some(p) = self.entry(PROBE).cloned() {
                    self.read(out, t, &p);
                }
            }
            Template::DeliveryState => {
                let known: Vec<&StateCommand> = self
                    .commands
                    .iter()
                    .filter(|x| x.param == DELIVERY_STATE)
                    .collect();
                let lo = known.iter().map(|x| x.value).min().unwrap_or(0);
                let hi = known.iter().map(|x| x.value).max().unwrap_or(0);
                let value = if chance(rng, 75) {
                    pick(rng, &known).map_or(0, |x| x.value)
                } else if chance(rng, 50) {
                    lo.saturating_sub(rng.range(1, 3))
                } else {
                    hi.saturating_add(rng.range(1, 3))
                };
                if !self.write_id(out, t, DELIVERY_STATE, value) {
                    return;
                }
                if let Some(x) = known.iter().find(|x| x.value == value) {
                    Self::command_effect(x, f, self.default_format);
                    if x.reset {
                        self.idle(out, t, f.active);
                    }
                    if x.reference_loop || x.centre_run {
                        self.until(out, t, true);
                        self.until(out, t, false);
                    }
                }
                self.push(
                    out,
                    t,
                    PsxStep::IsduRead {
                        index: self.entry(DELIVERY_STATE).map_or(193, |e| e.index),
                        subindex: 0,
                    },
                    "ISDU read 193 (saving?)".to_owned(),
                );
                let k = if chance(rng, 50) {
                    self.save_cycles
                } else {
                    u32::try_from(rng.range(1, 20)).unwrap_or(1)
                };
                self.hold(out, t, k);
                self.push(
                    out,
                    t,
                    PsxStep::IsduRead {
                        index: self.entry(DELIVERY_STATE).map_or(193, |e| e.index),
                        subindex: 0,
                    },
                    "ISDU read 193".to_owned(),
                );
            }
            Template::SavePowerCycle => {
                // A saved and a never-saved entry changed, maybe saved, then a power cycle (or
                // a device reset), and both read back.
                let Some(save) = self.save_command() else {
                    return;
                };
                let saved = self.pick_entry(rng, |e| {
                    e.writable
                        && e.readable
                        && e.range.is_some()
                        && e.index != 0
                        && ![fp.as_str(), LOCKS, STANDARD_COMMAND, DELIVERY_STATE]
                            .contains(&e.id.as_str())
                });
                let Some(e) = saved.cloned() else {
                    return;
                };
                let top = e.range.as_ref().and_then(|r| r.last()).map_or(0, |i| i[1]);
                self.write(out, t, &e, top);
                if chance(rng, 70) {
                    self.write_id(out, t, &save.param, save.value);
                    f.saved = f.working;
                    self.hold(out, t, self.save_cycles);
                }
                if self.takes("power-cycle") && chance(rng, 70) {
                    self.env(out, t, Env::PowerCycle);
                    self.restarted(out, t, f);
                } else if let Some(r) = self.reset_command() {
                    self.write_id(out, t, &r.param, r.value);
                    self.restarted(out, t, f);
                }
                self.read(out, t, &e);
            }
            Template::FormatSwitch => {
                let to = pick(rng, &self.formats).copied().unwrap_or(1);
                if chance(rng, 25) {
                    // Written but not saved: lost in the restart.
                    self.hold(out, t, self.save_cycles);
                    if self.write_id(out, t, &fp, i64::from(to)) {
                        f.working = to;
                        self.hold(out, t, 2);
                        if self.takes("power-cycle") {
                            self.env(out, t, Env::PowerCycle);
                        } else if let Some(r) = self.reset_command() {
                            self.write_id(out, t, &r.param, r.value);
                        }
                        self.restarted(out, t, f);
                    }
                } else {
                    self.switch(rng, out, t, to, f);
                }
                self.hold(out, t, 2);
                let dp = &self.rules.protocol().direct_parameters;
                for e in dp.entries.iter().filter(|e| e.name.starts_with("DeviceID")) {
                    if let Some(sub) = e.address.checked_add(dp.subindex_offset) {
                        self.push(
                            out,
                            t,
                            PsxStep::IsduRead {
                                index: dp.isdu_index,
                                subindex: sub,
                            },
                            format!("ISDU read {}.{sub} ({})", dp.isdu_index, e.name),
                        );
                    }
                }
                if let Some(e) = self.entry(&fp).cloned() {
                    self.read(out, t, &e);
                }
            }
            Template::Position => {
                let target = if chance(rng, 85) {
                    self.target(rng)
                } else {
                    let (lo, hi) = self.limits;
                    match rng.range(0, 3) {
                        0 => hi.saturating_add(rng.range(1, 1_000)),
                        1 => lo.saturating_sub(rng.range(1, 1_000)),
                        2 => i64::from(i32::MAX),
                        _ => i64::from(i32::MIN),
                    }
                };
                if f.active == 0 {
                    self.stamp_run(rng, out, t, target, 3, 2_500);
                } else {
                    let word = if chance(rng, 70) {
                        c.run
                    } else {
                        c.run | c.no_loop
                    };
                    self.pd(out, t, f.active, word, target, 0);
                    if chance(rng, 80) {
                        self.until(out, t, true);
                        self.until(out, t, false);
                    } else {
                        self.hold(out, t, u32::try_from(rng.range(1, 40)).unwrap_or(1));
                        self.pd(out, t, f.active, 0, target, 0);
                        self.until(out, t, false);
                    }
                }
            }
            Template::Control if f.active != 0 && chance(rng, 35) => {
                // A run aborted by withdrawing the release (status bit 5), then a 0->1 edge of
                // "clear error bits" (or none).
                self.pd(out, t, f.active, c.run, self.target(rng), 0);
                self.until(out, t, true);
                self.hold(out, t, u32::try_from(rng.range(1, 10)).unwrap_or(1));
                self.pd(out, t, f.active, 0, self.start, 0);
                self.until(out, t, false);
                let word = if chance(rng, 80) { c.clear } else { 0 };
                self.pd(out, t, f.active, word, self.start, 0);
                self.hold(out, t, u32::try_from(rng.range(2, 12)).unwrap_or(2));
            }
            Template::Control => {
                if f.active == 0 {
                    // Format 0: the control word goes through ISDU 110.
                    let cw = self.rules.timestamp().control_word_param.clone();
                    let word =
                        *pick(rng, &[0, c.release, c.no_loop, c.reserved, c.clear]).unwrap_or(&0);
                    if self.write_id(out, t, &cw, i64::from(word)) {
                        self.hold(out, t, u32::try_from(rng.range(1, 10)).unwrap_or(1));
                        self.write_id(out, t, &cw, 0);
                        self.until(out, t, false);
                    }
                    return;
                }
                let target = self.target(rng);
                let reserved: Vec<u16> = (0..16)
                    .filter_map(|b| 1u16.checked_shl(b))
                    .filter(|m| c.reserved & m != 0)
                    .collect();
                let base = *pick(
                    rng,
                    &[
                        0,
                        c.release,
                        c.run,
                        c.up,
                        c.down,
                        c.transfer_only,
                        c.run | c.no_loop,
                        c.up | c.down,
                        c.jog_up,
                        c.jog_down,
                        c.jog_keys,
                    ],
                )
                .unwrap_or(&0);
                let extra = match rng.range(0, 3) {
                    0 => pick(rng, &reserved).copied().unwrap_or(0),
                    1 => c.reserved,
                    2 => u16::try_from(rng.range(0, i64::from(u16::MAX))).unwrap_or(0),
                    _ => 0,
                };
                self.pd(out, t, f.active, base | extra, target, 0);
                self.hold(out, t, u32::try_from(rng.range(2, 30)).unwrap_or(2));
                if chance(rng, 40) {
                    // A clear-error edge.
                    self.pd(out, t, f.active, c.clear, target, 0);
                    self.hold(out, t, 2);
                }
                self.pd(out, t, f.active, 0, target, 0);
                self.until(out, t, false);
            }
            Template::Speed => {
                if f.active != 2 {
                    if !self.formats.contains(&2) {
                        return;
                    }
                    self.switch(rng, out, t, 2, f);
                    if f.active != 2 {
                        return;
                    }
                }
                let (lo, hi) = self.speed;
                let clamp =
                    |v: i64| i16::try_from(v).unwrap_or(if v < 0 { i16::MIN } else { i16::MAX });
                let values = [
                    0,
                    0,
                    lo,
                    hi,
                    rng.range(lo, hi),
                    hi.saturating_add(1),
                    lo.saturating_sub(1),
                    -1,
                    i64::from(i16::MAX),
                    i64::from(i16::MIN),
                ];
                let speed = clamp(pick(rng, &values).copied().unwrap_or(0));
                let target = self.target(rng);
                let word = *pick(rng, &[c.run, c.run, c.up, c.down]).unwrap_or(&c.run);
                self.pd(out, t, 2, word, target, speed);
                self.until(out, t, true);
                if chance(rng, 40) {
                    self.hold(out, t, u32::try_from(rng.range(1, 20)).unwrap_or(1));
                    let other = clamp(pick(rng, &values).copied().unwrap_or(0));
                    self.pd(out, t, 2, word, target, other);
                }
                self.hold(out, t, u32::try_from(rng.range(1, 30)).unwrap_or(1));
                if word != c.run {
                    self.pd(out, t, 2, c.release, target, speed);
                }
                self.until(out, t, false);
            }
            Template::Stamp => {
                if f.active != 0 {
                    if !self.formats.contains(&0) {
                        return;
                    }
                    self.switch(rng, out, t, 0, f);
                    if f.active != 0 {
                        return;
                    }
                }
                let ts = self.rules.timestamp();
                let u = |v: u32| u16::try_from(v).unwrap_or(u16::MAX);
                let reserved = rng.range(
                    i64::from(ts.max_valid).saturating_add(1),
                    i64::from(ts.inactive).saturating_sub(1),
                );
                let delayed = rng.range(i64::from(ts.immediate_below), i64::from(ts.max_valid));
                let stamps = [
                    0,
                    1,
                    u16::try_from(delayed).unwrap_or(0),
                    u16::try_from(delayed).unwrap_or(0),
                    u(ts.immediate_below.saturating_sub(1)),
                    u(ts.immediate_below),
                    u(ts.max_valid),
                    u16::try_from(reserved).unwrap_or(0),
                    u(ts.inactive),
                    u16::try_from(rng.range(0, i64::from(ts.max_valid))).unwrap_or(0),
                ];
                let stamp = pick(rng, &stamps).copied().unwrap_or(0);
                let code = u8::try_from(rng.range(0, 3)).unwrap_or(3);
                let target = self.target(rng);
                self.stamp_run(rng, out, t, target, code, stamp);
            }
            Template::Keys => {
                if f.active != 0 && chance(rng, 60) {
                    let word = *pick(rng, &[c.jog_keys, 0, c.release]).unwrap_or(&0);
                    self.pd(out, t, f.active, word, self.start, 0);
                }
                let (forward, reverse) = *pick(rng, &[(true, false), (false, true), (true, true)])
                    .unwrap_or(&(true, false));
                self.env(out, t, Env::Keys { forward, reverse });
                let k = if chance(rng, 50) {
                    self.key_cycles.0
                } else {
                    self.key_cycles.1
                };
                self.hold(out, t, k);
                self.env(
                    out,
                    t,
                    Env::Keys {
                        forward: false,
                        reverse: false,
                    },
                );
                self.until(out, t, false);
            }
            Template::Environment => {
                let env = match rng.range(0, 9) {
                    0 => {
                        let l = self.temperature_limit;
                        let any = rng.range(-20, 95);
                        let c = *pick(rng, &[l - 1, l, l + 1, l + 10, any]).unwrap_or(&l);
                        Env::Temperature(i16::try_from(c).unwrap_or(25))
                    }
                    1 => Env::MotorVoltage(u16::try_from(rng.range(100, 320)).unwrap_or(240)),
                    2 => Env::Jam(true),
                    3 => Env::Jam(false),
                    4 => Env::Displace(rng.range(-2_000, 2_000)),
                    5 => Env::Link(LinkEvent::Lost),
                    6 => Env::Link(LinkEvent::Connected),
                    7 => Env::LoadTorque(u16::try_from(rng.range(0, 200)).unwrap_or(0)),
                    _ => Env::PowerCycle,
                };
                let kind = env.to_string();
                let kind = kind.split(' ').next().unwrap_or_default();
                if !self.takes(kind) {
                    return;
                }
                if f.active != 0 && chance(rng, 50) {
                    self.pd(out, t, f.active, c.run, self.target(rng), 0);
                    self.until(out, t, true);
                }
                self.env(out, t, env);
                if env == Env::PowerCycle {
                    self.restarted(out, t, f);
                }
                self.hold(out, t, u32::try_from(rng.range(1, 30)).unwrap_or(1));
                if env == Env::Link(LinkEvent::Lost) {
                    // The master comes back: the following templates need ISDU access.
                    self.env(out, t, Env::Link(LinkEvent::Connected));
                    self.hold(out, t, 2);
                }
                if chance(rng, 50) {
                    self.until(out, t, false);
                }
            }
            Template::Silence => {
                // The master time-out (ISDU 118) and what happens then (ISDU 137, 138), maybe
                // with a run under way, then the master falls silent.
                let to = self.rules.protocol().timeout.clone();
                for id in [&to.timeout_param, &to.config_param, &to.safe_position_param] {
                    let Some(e) = self.entry(id).cloned() else {
                        continue;
                    };
                    let Some(r) = e.range.clone() else {
                        continue;
                    };
                    if chance(rng, 40) && id != &to.timeout_param {
                        continue;
                    }
                    let (Some(first), Some(last)) = (r.first(), r.last()) else {
                        continue;
                    };
                    let v = match rng.range(0, 4) {
                        0 => first[0],
                        1 => last[1],
                        2 => last[1].saturating_add(1),
                        _ => rng.range(first[0], last[1].min(first[0].saturating_add(2_000))),
                    };
                    if self.write(out, t, &e, v) && chance(rng, 60) {
                        self.read(out, t, &e);
                    }
                }
                if f.active != 0 && chance(rng, 40) {
                    self.pd(out, t, f.active, c.run, self.target(rng), 0);
                    self.until(out, t, true);
                }
                let us = u64::try_from(rng.range(1, 3_000_000)).unwrap_or(1);
                self.push(
                    out,
                    t,
                    PsxStep::Advance { us },
                    format!("{} ms without a bus cycle", us / 1000),
                );
                self.hold(out, t, u32::try_from(rng.range(1, 5)).unwrap_or(1));
                if chance(rng, 50) {
                    self.until(out, t, false);
                }
            }
        }
    }

    /// A time-stamp command (manual 4.4): the stamp inactive, the target through ISDU 112
    /// for a positioning, the stamp (sometimes repeated or replaced while valid), the stamp
    /// inactive, and the run.
    fn stamp_run(
        &self,
        rng: &mut Rng,
        out: &mut Vec<Step>,
        t: Template,
        target: i64,
        code: u8,
        stamp: u16,
    ) {
        let inactive = self.inactive();
        self.stamp(out, t, (0, inactive));
        if code == 3 {
            let param = self.rules.timestamp().target_param.clone();
            self.write_id(out, t, &param, target);
        }
        self.stamp(out, t, (code, stamp));
        if chance(rng, 60) {
            // Valid stamps sent cyclically: nothing runs until the field turns inactive.
            self.hold(out, t, u32::try_from(rng.range(2, 20)).unwrap_or(2));
            if chance(rng, 50) {
                let next = u16::try_from(rng.range(0, 12_000)).unwrap_or(0);
                self.stamp(out, t, (code, next));
            }
        }
        self.stamp(out, t, (code, inactive));
        self.until(out, t, true);
        if code == 3 {
            self.until(out, t, false);
        } else {
            self.hold(out, t, u32::try_from(rng.range(1, 25)).unwrap_or(1));
            self.stamp(out, t, (0, 0));
            self.until(out, t, false);
        }
    }
}

/// A cycle time as a divisor.
fn cycle_as_i64(us: u64) -> i64 {
    i64::try_from(us).unwrap_or(i64::MAX).max(1)
}
