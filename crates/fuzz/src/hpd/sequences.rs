//! HPD sequences from the spec (manual chapter 4, 3.3–3.4, 3.8.1): valid requests for every
//! parameter at, inside and beyond its range, malformed frames, bit changes, commands, PLC
//! programs good and bad, the conformance suite's own cases as seeds, and environment
//! changes where the transport offers them. Each step carries its generator class (README
//! "What is generated (HPD)") and the requirement IDs it exercises.
//!
//! The generator draws only from the [`Rng`] it is given; nothing here reads a clock or the
//! device. Nothing panics: a message that cannot be built is skipped.

use crate::engine::{self, below, chance, pick, templates};
use crate::replay::{self, Step};
use drivespec_conform::case::Role;
use drivespec_conform::hpd::cases::{BitRef, CaseB, Gen, GenError};
use drivespec_conform::hpd::frame::frame;
use drivespec_conform::hpd::names;
use drivespec_conform::hpd::step::{Action, Compare, Step as SuiteStep};
use drivespec_conform::hpd::HpdSuite;

/// The suite's motion cases (`hpd/motion`).
const MOTION: &str = "hpd/motion/";
use drivespec_conform::link::{Caps, Micros};
use drivespec_hpd::memory::Slot;
use drivespec_hpd::plc::{Instr, Operands};
use drivespec_hpd::{Data, Message, MessageKind};
use drivespec_sim::rng::Rng;
use drivespec_spec::hpd::{OperandForm, Operation};
use drivespec_spec::{Access, Parameter};

/// Most steps in one sequence.
const MAX_STEPS: usize = 48;

/// A bit of a parameter, with what the spec says about it.
#[derive(Debug, Clone)]
struct Bit<'s> {
    r: BitRef<'s>,
    /// The drive owns it (access r) or the parameter is read-only.
    read_only: bool,
    /// A reserved bit the master must keep 0.
    must_be_zero: bool,
    /// A command bit (trigger `command-executed`, manual 3.4).
    command: bool,
    /// Requirements of its set/reset rules.
    reqs: Vec<&'s str>,
}

templates! {
    /// The templates a sequence is made of, with their weights (README "What is generated (HPD)").
    Read = 9, Write = 14, ModeWrite = 4, ReadOnlyWrite = 4, Bit = 8, RawBit = 3, Command = 6,
    Broadcast = 4, Foreign = 4, BadChecksum = 4, BadStuffing = 4, Truncated = 3, OverLong = 3,
    WrongLun = 3, Split = 5, Noise = 3, PlcRead = 3, PlcProgram = 7, PlcWriteRunning = 2,
    Inputs = 3, PowerCycle = 1, Listen = 2, Dword = 3
}

/// The HPD sequence generator.
pub(crate) struct HpdGen<'a, 's> {
    g: Gen<'s>,
    suite: &'a HpdSuite<'s>,
    caps: Caps,
    /// Compare every answer byte for byte (virtual time: live values agree too).
    exact: bool,
    params: Vec<(&'s Parameter, Slot)>,
    writable: Vec<(&'s Parameter, Slot)>,
    moded: Vec<(&'s Parameter, Slot)>,
    read_only: Vec<(&'s Parameter, Slot)>,
    bits: Vec<Bit<'s>>,
    /// Parameter numbers that are words (arithmetic operands).
    words: Vec<u8>,
    /// Parameter numbers arithmetic results may go to.
    results: Vec<u8>,
    /// Byte parameters arithmetic must not use (HPD-PLC-026).
    forbidden: Vec<u8>,
    /// Double-word slots (successive word pairs, manual 3.8.1).
    pairs: Vec<Slot>,
    /// Suite cases used as seeds (indices), PLC vector cases apart.
    seeds: Vec<usize>,
    plc_vectors: Vec<usize>,
    /// The PLC run bit as (parameter number, bit).
    run_bit: (u8, u8),
    /// The dword-force bit (b94.0).
    dword_bit: Option<BitRef<'s>>,
    /// Number of digital inputs.
    inputs: u32,
    scan_us: Micros,
    /// Largest value of a drive address.
    addr_max: u8,
}

fn parse_bit(name: &str) -> Option<(u8, u8)> {
    let (p, y) = name.trim_start_matches(['b', 'P']).split_once('.')?;
    Some((p.parse().ok()?, y.parse().ok()?))
}

impl<'a, 's> HpdGen<'a, 's> {
    /// A generator for the device the suite was made for, on a transport with `caps`.
    pub(crate) fn new(suite: &'a HpdSuite<'s>, caps: Caps) -> Result<HpdGen<'a, 's>, GenError> {
        let spec = suite.spec();
        let family = suite.family();
        let model = suite.model_id().and_then(|m| family.model(m));
        let settings = suite.settings();
        let g = Gen::new(
            spec,
            suite.reference().clone(),
            model,
            settings.address,
            settings.seed,
        )?;
        let protocol = g.protocol;
        let params: Vec<(&Parameter, Slot)> = family
            .parameters
            .iter()
            .filter_map(|p| Some((p, g.slot(p)?)))
            .collect();
        let is_bits = |p: &Parameter| family.bitfields_of(&p.id).next().is_some();
        let writable: Vec<_> = params
            .iter()
            .filter(|(p, _)| p.access.writable() && !is_bits(p))
            .copied()
            .collect();
        let moded: Vec<_> = writable
            .iter()
            .filter(|(p, _)| p.modes.iter().any(|m| m.range.is_some()))
            .copied()
            .collect();
        let read_only: Vec<_> = params
            .iter()
            .filter(|(p, _)| !p.access.writable())
            .copied()
            .collect();
        let mut bits: Vec<Bit> = Vec::new();
        for bf in &family.bitfields {
            let Some(p) = family.parameter(&bf.param) else {
                continue;
            };
            for b in &bf.bits {
                let name = format!("b{}.{}", p.number, b.bit);
                let Some(r) = g.bit_ref(&name) else { continue };
                if bits.iter().any(|x| x.r.slot == r.slot && x.r.bit == r.bit) {
                    continue;
                }
                bits.push(Bit {
                    r,
                    read_only: b.access == Some(Access::R) || !p.access.writable(),
                    must_be_zero: b.must_be_zero,
                    command: b
                        .rules
                        .iter()
                        .any(|rule| rule.trigger == names::TRIGGER_COMMAND),
                    reqs: b
                        .rules
                        .iter()
                        .map(|rule| rule.requirement.as_str())
                        .collect(),
                });
            }
        }
        let number = |id: &str| {
            family
                .parameter(id)
                .and_then(|p| u8::try_from(p.number).ok())
        };
        let words: Vec<u8> = params
            .iter()
            .filter(|(p, s)| s.size == 2 && p.id.starts_with("Pr"))
            .filter_map(|(p, _)| u8::try_from(p.number).ok())
            .collect();
        let arith = &protocol.plc.arithmetic;
        let mut results: Vec<u8> = protocol
            .plc
            .free_words
            .iter()
            .chain(arith.dword_params.iter())
            .filter_map(|id| number(id))
            .collect();
        results.extend(
            protocol
                .plc
                .constants
                .iter()
                .filter_map(|c| number(&c.param)),
        );
        let forbidden: Vec<u8> = arith
            .forbidden_params
            .iter()
            .filter_map(|id| number(id))
            .collect();
        let runs: Vec<(u32, u32)> = arith
            .successive
            .iter()
            .filter_map(|[a, b]| Some((family.parameter(a)?.number, family.parameter(b)?.number)))
            .collect();
        let pairs: Vec<Slot> = params
            .iter()
            .filter(|(p, s)| {
                s.size == 2
                    && p.number % 2 == 0
                    && runs.iter().any(|(a, b)| (*a..*b).contains(&p.number))
            })
            .map(|(_, s)| Slot {
                addr: s.addr,
                size: 4,
            })
            .collect();
        let mut seeds = Vec::new();
        let mut plc_vectors = Vec::new();
        let mut i = 0;
        while let Some((info, case)) = suite.case(i) {
            if !case.needs_power_cycle || caps.power_cycle {
                // Motion cases wait for the motor (seconds of real time per watch) and judge
                // the motion by its envelope, which no mutated step keeps: not seeds.
                if info.id.starts_with("hpd/plc/vector/") {
                    plc_vectors.push(i);
                } else if !info.id.starts_with("hpd/vector/") && !info.id.starts_with(MOTION) {
                    seeds.push(i);
                }
            }
            i += 1;
        }
        let run_bit = parse_bit(&protocol.plc.run_bit)
            .ok_or_else(|| GenError::RunBit(protocol.plc.run_bit.clone()))?;
        let dword_bit = g.bit_ref(&arith.dword_force_bit);
        let inputs = u32::try_from(protocol.io.inputs.len()).unwrap_or(8).min(16);
        let scan_us = Micros::from(protocol.plc.scan_us);
        let addr_max = g.rules.addr_max;
        Ok(HpdGen {
            exact: caps.virtual_time,
            g,
            suite,
            caps,
            params,
            writable,
            moded,
            read_only,
            bits,
            words,
            results,
            forbidden,
            pairs,
            seeds,
            plc_vectors,
            run_bit,
            dword_bit,
            inputs,
            scan_us,
            addr_max,
        })
    }

    /// The liveness probe: a read of Pr33, a parameter that is neither live nor driven by
    /// the default PLC program (manual 3.3).
    pub(crate) fn probe(&mut self) -> Vec<Step> {
        let mut out = Vec::new();
        if let Some(slot) = self.g.slot_of(names::RANGED) {
            self.read_slot(&mut out, "probe", slot, "Pr33 (liveness probe)");
        }
        out
    }

    // ---------------------------------------------------------------- building steps

    /// A suite step as a fuzz step of `class`; with `exact`, every exchange compares exactly.
    fn conv(&self, s: SuiteStep, class: &str) -> Step {
        let action = match s.action {
            Action::Exchange {
                bytes, silence_ok, ..
            } if self.exact => Action::Exchange {
                bytes,
                compare: Compare::Exact,
                silence_ok,
            },
            other => other,
        };
        Step {
            action: replay::Action::Hpd(action),
            class: class.to_owned(),
            text: s.text,
            requirements: s.requirements,
        }
    }

    fn take(&mut self, out: &mut Vec<Step>, cb: CaseB, class: &str) {
        for s in cb.steps {
            out.push(self.conv(s, class));
        }
        self.g.errors.clear();
    }

    fn msg(&mut self, out: &mut Vec<Step>, class: &str, m: Message, cmp: Compare, text: String) {
        let mut cb = CaseB::new("hpd/fuzz", "", &[]);
        self.g.msg(&mut cb, Role::Check, m, cmp, text);
        self.take(out, cb, class);
    }

    fn raw(
        &mut self,
        out: &mut Vec<Step>,
        class: &str,
        bytes: Vec<u8>,
        text: String,
        reqs: &[&str],
    ) {
        if bytes.is_empty() {
            return;
        }
        let mut cb = CaseB::new("hpd/fuzz", "", &[]);
        self.g.raw(&mut cb, Role::Check, bytes, text, reqs);
        self.take(out, cb, class);
    }

    fn step(&self, out: &mut Vec<Step>, class: &str, action: Action, text: String, reqs: &[&str]) {
        out.push(Step {
            action: replay::Action::Hpd(action),
            class: class.to_owned(),
            text,
            requirements: reqs.iter().map(|r| (*r).to_owned()).collect(),
        });
    }

    fn own(&self) -> u8 {
        self.g.addr
    }

    /// Adds requirement IDs (those the spec has) to the last step.
    fn tag<'x>(&self, out: &mut [Step], reqs: impl IntoIterator<Item = &'x str>) {
        let Some(last) = out.last_mut() else { return };
        for r in reqs {
            if self.g.known(r) && !last.requirements.iter().any(|x| x == r) {
                last.requirements.push(r.to_owned());
            }
        }
    }

    /// Requirements that name parameter `p` (must and should).
    fn linked(&self, p: &Parameter) -> Vec<String> {
        self.g.linked(p, |_| true)
    }

    fn bytes_of(&self, m: &Message) -> Vec<u8> {
        m.to_bytes(&self.g.rules).unwrap_or_default()
    }

    /// The fields of a message between STX and the checksum, unstuffed.
    fn fields(&self, m: &Message) -> Vec<u8> {
        let b = self.bytes_of(m);
        let (stx, stuff) = (self.g.rules.stx, self.g.rules.stuff);
        let mut out = Vec::new();
        let mut it = b.iter().skip(1).peekable();
        while let Some(&x) = it.next() {
            out.push(x);
            if x == stx && it.peek() == Some(&&stuff) {
                it.next();
            }
        }
        out.pop();
        out
    }

    fn compare_of(&self, slot: Slot) -> Compare {
        match self.g.family.parameter_at_address(u32::from(slot.addr)) {
            Some(p)
                if p.address == Some(u32::from(slot.addr))
                    && p.size == Some(u32::from(slot.size)) =>
            {
                self.g.compare_for(p, None)
            }
            _ => Compare::Exact,
        }
    }

    fn read_slot(&mut self, out: &mut Vec<Step>, class: &str, slot: Slot, what: &str) {
        let m = Message::ReadParam {
            addr: self.own(),
            lun: slot.size,
            par: slot.addr,
        };
        let cmp = self.compare_of(slot);
        self.msg(out, class, m, cmp, format!("read {what}"));
    }

    fn write_slot(&mut self, out: &mut Vec<Step>, class: &str, slot: Slot, value: i64, what: &str) {
        if let Some(data) = Data::from_value(value, slot.size) {
            let m = Message::WriteParam {
                addr: self.own(),
                par: slot.addr,
                data,
            };
            self.msg(
                out,
                class,
                m,
                Compare::Exact,
                format!("write {what} = {value}"),
            );
        }
    }

    fn bit_step(&mut self, out: &mut Vec<Step>, class: &str, b: &BitRef<'s>, value: bool) {
        let mut cb = CaseB::new("hpd/fuzz", "", &[]);
        self.g.bit(&mut cb, Role::Check, b, value);
        self.take(out, cb, class);
    }

    fn stop_plc(&mut self, out: &mut Vec<Step>) {
        let mut cb = CaseB::new("hpd/fuzz", "", &[]);
        self.g.stop_plc(&mut cb);
        self.take(out, cb, "plc-run-stop");
    }

    fn run_bit_ref(&self) -> Option<BitRef<'s>> {
        self.g
            .bit_ref(&format!("b{}.{}", self.run_bit.0, self.run_bit.1))
    }

    // ---------------------------------------------------------------- values

    /// A value for `p`: inside its range, at an edge, beyond it, or one with $7E bytes;
    /// with the class it belongs to.
    fn value(&mut self, rng: &mut Rng, p: &Parameter, mode: Option<u32>) -> (i64, &'static str) {
        let (tmin, tmax) = p.data_type.bounds().unwrap_or((-32768, 32767));
        let range = self.g.range_in(p, mode);
        let r = rng.range(0, 99);
        let v = match &range {
            Some(range) if r < 35 => {
                let iv = pick(rng, range.intervals())
                    .copied()
                    .unwrap_or([tmin, tmax]);
                rng.range(iv[0], iv[1])
            }
            Some(range) if r < 55 => {
                let edges: Vec<i64> = range
                    .intervals()
                    .iter()
                    .flat_map(|[a, b]| [*a, *b])
                    .collect();
                pick(rng, &edges).copied().unwrap_or(tmin)
            }
            Some(range) if r < 85 => {
                let mut beyond: Vec<i64> = vec![tmin, tmax];
                if let Some(lo) = range.min() {
                    beyond.push(lo.saturating_sub(1));
                }
                if let Some(hi) = range.max() {
                    beyond.push(hi.saturating_add(1));
                }
                for w in range.intervals().windows(2) {
                    if let [[_, a_hi], [b_lo, _]] = w {
                        if a_hi + 1 < *b_lo {
                            beyond.push(rng.range(a_hi + 1, b_lo - 1));
                        }
                    }
                }
                pick(rng, &beyond).copied().unwrap_or(tmax)
            }
            None if r < 85 => rng.range(tmin, tmax),
            _ => {
                let special = [0x7E, 0x7E7E, -130, 0x7E00, 0, -1, 1, 0x7E7E_7E7E];
                pick(rng, &special).copied().unwrap_or(0)
            }
        };
        let v = v.clamp(tmin, tmax);
        let class = match &range {
            Some(range) if !range.contains(v) => "out-of-range-write",
            Some(range) if range.intervals().iter().any(|[a, b]| v == *a || v == *b) => {
                "boundary-write"
            }
            _ => "valid-write",
        };
        (v, class)
    }

    /// A well-formed request to this drive, for corrupting.
    fn request(&mut self, rng: &mut Rng) -> Message {
        let own = self.own();
        let fallback = Message::ReadParam {
            addr: own,
            lun: 2,
            par: self.g.slot_of(names::RANGED).map_or(0, |s| s.addr),
        };
        match rng.range(0, 5) {
            0 => pick(rng, &self.params)
                .map(|(_, s)| Message::ReadParam {
                    addr: own,
                    lun: s.size,
                    par: s.addr,
                })
                .unwrap_or(fallback),
            1 | 2 => {
                let Some((p, s)) = pick(rng, &self.writable).copied() else {
                    return fallback;
                };
                let (v, _) = self.value(rng, p, None);
                match Data::from_value(v, s.size) {
                    Some(data) => Message::WriteParam {
                        addr: own,
                        par: s.addr,
                        data,
                    },
                    None => fallback,
                }
            }
            3 => {
                let Some(b) = pick(rng, &self.bits).cloned() else {
                    return fallback;
                };
                match drivespec_hpd::params::bit_change(
                    self.g.family,
                    b.r.slot.addr,
                    b.r.bit,
                    chance(rng, 50),
                ) {
                    Some((par, mask, value)) => Message::BitChange {
                        addr: own,
                        par,
                        mask,
                        value,
                    },
                    None => fallback,
                }
            }
            4 => Message::ReadPlc {
                addr: own,
                lun: u8::try_from(rng.range(1, 4)).unwrap_or(2),
                par: u8::try_from(rng.range(0, 62) * 2).unwrap_or(0),
            },
            _ => {
                let Some((p, s)) = pick(rng, &self.writable).copied() else {
                    return fallback;
                };
                let (v, _) = self.value(rng, p, None);
                match Data::from_value(v, s.size) {
                    Some(data) => Message::Broadcast { par: s.addr, data },
                    None => fallback,
                }
            }
        }
    }

    // ---------------------------------------------------------------- sequences

    /// The next sequence.
    pub(crate) fn sequence(&mut self, rng: &mut Rng) -> Vec<Step> {
        let mut out = Vec::new();
        if chance(rng, 25) {
            self.stop_plc(&mut out);
        }
        if chance(rng, 22) {
            self.seed(rng, &mut out);
        }
        let actions = rng.range(1, 5);
        for _ in 0..actions {
            let t = self.template(rng);
            self.action(rng, t, &mut out);
        }
        if chance(rng, 15) {
            self.mutate(rng, &mut out);
        }
        if out.is_empty() {
            self.action(rng, Template::Read, &mut out);
        }
        out.truncate(MAX_STEPS);
        out
    }

    fn template(&self, rng: &mut Rng) -> Template {
        let usable = |t: Template| match t {
            Template::Inputs => self.caps.inputs,
            Template::PowerCycle => self.caps.power_cycle,
            _ => true,
        };
        engine::weighted(rng, TEMPLATES, usable, Template::Read)
    }

    fn action(&mut self, rng: &mut Rng, t: Template, out: &mut Vec<Step>) {
        match t {
            Template::Read => self.t_read(rng, out),
            Template::Write => self.t_write(rng, out, None),
            Template::ModeWrite => self.t_mode_write(rng, out),
            Template::ReadOnlyWrite => self.t_read_only(rng, out),
            Template::Bit => self.t_bit(rng, out),
            Template::RawBit => self.t_raw_bit(rng, out),
            Template::Command => self.t_command(rng, out),
            Template::Broadcast => self.t_broadcast(rng, out),
            Template::Foreign => self.t_foreign(rng, out),
            Template::BadChecksum => self.t_bad_checksum(rng, out),
            Template::BadStuffing => self.t_bad_stuffing(rng, out),
            Template::Truncated => self.t_truncated(rng, out),
            Template::OverLong => self.t_over_long(rng, out),
            Template::WrongLun => self.t_wrong_lun(rng, out),
            Template::Split => self.t_split(rng, out),
            Template::Noise => self.t_noise(rng, out),
            Template::PlcRead => self.t_plc_read(rng, out),
            Template::PlcProgram => self.t_plc_program(rng, out),
            Template::PlcWriteRunning => self.t_plc_write_running(rng, out),
            Template::Inputs => self.t_inputs(rng, out),
            Template::PowerCycle => {
                self.step(
                    out,
                    "power-cycle",
                    Action::PowerCycle {},
                    "switch the drive off and on".to_owned(),
                    &["HPD-PAR-018"],
                );
                self.t_read(rng, out);
            }
            Template::Listen => {
                let us = Micros::try_from(rng.range(1, 4)).unwrap_or(1) * self.scan_us;
                self.step(
                    out,
                    "listen",
                    Action::Listen { us },
                    format!("listen {us} µs (nothing may come)"),
                    &["HPD-SERIAL-001"],
                );
            }
            Template::Dword => self.t_dword(rng, out),
        }
    }

    /// A suite case as a seed: its steps, all judged; PLC vector cases with new values.
    fn seed(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let vector = chance(rng, 40) && !self.plc_vectors.is_empty();
        let pool = if vector {
            &self.plc_vectors
        } else {
            &self.seeds
        };
        let Some(&i) = pick(rng, pool) else { return };
        let suite = self.suite;
        let Some((info, case)) = suite.case(i) else {
            return;
        };
        let class = if vector { "plc-vector" } else { "suite-case" };
        for s in &case.steps {
            let check = s.role == Role::Check;
            let mut s = self.conv(s.clone(), class);
            if check {
                for r in &info.requirements {
                    if !s.requirements.contains(r) {
                        s.requirements.push(r.clone());
                    }
                }
            }
            s.text = format!("{}: {}", info.id, s.text);
            if vector && chance(rng, 30) {
                self.revalue(rng, &mut s);
            }
            out.push(s);
        }
    }

    /// A write step with another value (same parameter, same length).
    fn revalue(&mut self, rng: &mut Rng, s: &mut Step) {
        let Some(bytes) = s.action.bytes() else {
            return;
        };
        let Ok(Message::WriteParam { addr, par, data }) =
            drivespec_hpd::parse(&self.g.rules, bytes)
        else {
            return;
        };
        let v = match rng.range(0, 3) {
            0 => 0,
            1 => rng.range(-4, 4),
            _ => rng.range(-40_000, 40_000),
        };
        if let Some(d) = Data::from_value(v, data.len()) {
            let m = Message::WriteParam { addr, par, data: d };
            let b = self.bytes_of(&m);
            if !b.is_empty() {
                s.action = s.action.with_bytes(b);
                s.class = "plc-vector-revalued".to_owned();
                s.text = format!("{} (value changed to {v})", s.text);
            }
        }
    }

    fn t_read(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        if chance(rng, 80) {
            if let Some((p, s)) = pick(rng, &self.params).copied() {
                self.read_slot(out, "valid-read", s, &p.id);
            }
        } else {
            // Any address, any length 1-4: unmapped bytes, halves of words, across parameters.
            let par = rng.byte();
            let lun = u8::try_from(rng.range(1, 4)).unwrap_or(1);
            let m = Message::ReadParam {
                addr: self.own(),
                lun,
                par,
            };
            self.msg(
                out,
                "odd-read",
                m,
                Compare::Exact,
                format!("read {lun} byte(s) at {par:#04x}"),
            );
        }
    }

    fn t_write(&mut self, rng: &mut Rng, out: &mut Vec<Step>, mode: Option<u32>) {
        let pool = if mode.is_some() {
            &self.moded
        } else {
            &self.writable
        };
        let Some((p, s)) = pick(rng, pool).copied() else {
            return;
        };
        let (v, class) = self.value(rng, p, mode);
        self.write_slot(out, class, s, v, &p.id);
        let linked = self.linked(p);
        self.tag(
            out,
            linked.iter().map(String::as_str).chain(["HPD-PAR-009"]),
        );
        if chance(rng, 75) {
            self.read_slot(out, "valid-read", s, &p.id);
        }
    }

    /// Operating mode first, then a parameter whose range depends on it (manual 3.6).
    fn t_mode_write(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let Some((p, s)) = pick(rng, &self.moded).copied() else {
            return;
        };
        let modes = Gen::ranged_modes(p);
        let (Some(&mode), Some(ms)) = (pick(rng, &modes), self.g.slot_of(names::OPERATING_MODE))
        else {
            return;
        };
        if chance(rng, 40) {
            // An operating mode outside Pr31's range or in its gaps (manual 3.3, 3.6).
            if let Some(pm) = self.g.param(names::OPERATING_MODE) {
                let (v, class) = self.value(rng, pm, None);
                self.write_slot(out, class, ms, v, "Pr31");
                let linked = self.linked(pm);
                self.tag(
                    out,
                    linked.iter().map(String::as_str).chain(["HPD-PAR-009"]),
                );
                self.read_slot(out, "valid-read", ms, "Pr31");
                return;
            }
        }
        self.write_slot(out, "mode-change", ms, i64::from(mode), "Pr31");
        let (v, class) = self.value(rng, p, Some(mode));
        self.write_slot(out, class, s, v, &p.id);
        self.read_slot(out, "valid-read", s, &p.id);
    }

    fn t_read_only(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let Some((p, s)) = pick(rng, &self.read_only).copied() else {
            return;
        };
        let base = self.g.base(s);
        let v = drivespec_conform::hpd::cases::sign_for(
            s,
            base ^ (1 + u32::from(rng.byte())),
            self.g.family,
        );
        self.write_slot(out, "read-only-write", s, v, &p.id);
        let linked = self.linked(p);
        self.tag(out, linked.iter().map(String::as_str));
        self.read_slot(out, "valid-read", s, &p.id);
    }

    fn t_bit(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let Some(b) = pick(rng, &self.bits).cloned() else {
            return;
        };
        let class = if b.read_only || b.must_be_zero {
            "read-only-bit"
        } else if b.command {
            "command"
        } else {
            "bit-change"
        };
        self.bit_step(out, class, &b.r, chance(rng, 60));
        self.tag(out, b.reqs.iter().copied());
        if chance(rng, 80) {
            self.read_slot(out, "valid-read", b.r.slot, &b.r.param.id);
        }
    }

    /// A bit change with any mask and value on a parameter byte (both bytes of words).
    fn t_raw_bit(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let Some((p, s)) = pick(rng, &self.params).copied() else {
            return;
        };
        let off = u8::try_from(below(rng, usize::from(s.size))).unwrap_or(0);
        let m = Message::BitChange {
            addr: self.own(),
            par: s.addr.wrapping_add(off),
            mask: rng.byte(),
            value: rng.byte(),
        };
        let text = format!("bit change on byte {off} of {}", p.id);
        self.msg(out, "bit-change-raw", m, Compare::Exact, text);
        self.read_slot(out, "valid-read", s, &p.id);
    }

    /// A command bit (manual 3.4), with or without its preconditions, then Pb99 and the
    /// alarms read back.
    fn t_command(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let commands: Vec<Bit> = self.bits.iter().filter(|b| b.command).cloned().collect();
        let Some(c) = pick(rng, &commands).cloned() else {
            return;
        };
        for pre in [
            names::EXTENDED_MENU,
            names::SECURITY,
            names::RESERVED_REFERENCE,
        ] {
            if chance(rng, 25) {
                if let Some(r) = self.g.bit_ref(pre) {
                    self.bit_step(out, "command-precondition", &r, chance(rng, 70));
                }
            }
        }
        self.bit_step(out, "command", &c.r, true);
        self.tag(out, c.reqs.iter().copied().chain(["HPD-CMD-SELF-CLEAR"]));
        if chance(rng, 50) {
            self.step(
                out,
                "listen",
                Action::Listen { us: self.scan_us },
                "listen one PLC scan".to_owned(),
                &[],
            );
        }
        self.read_slot(out, "valid-read", c.r.slot, &c.r.param.id);
        if chance(rng, 40) {
            for id in names::ALARMS {
                if let Some(s) = self.g.slot_of(id) {
                    self.read_slot(out, "valid-read", s, id);
                }
            }
        }
        if chance(rng, 30) {
            if let Some((p, s)) = pick(rng, &self.writable).copied() {
                let (v, class) = self.value(rng, p, None);
                self.write_slot(out, class, s, v, &p.id);
                self.read_slot(out, "valid-read", s, &p.id);
            }
        }
    }

    fn t_broadcast(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let (slot, v, what, p) = if chance(rng, 25) && !self.pairs.is_empty() {
            let Some(s) = pick(rng, &self.pairs).copied() else {
                return;
            };
            (
                s,
                rng.range(-0x4000_0000, 0x3FFF_FFFF),
                "double word".to_owned(),
                None,
            )
        } else {
            let Some((p, s)) = pick(rng, &self.writable).copied() else {
                return;
            };
            let (v, _) = self.value(rng, p, None);
            (s, v, p.id.clone(), Some(p))
        };
        let Some(data) = Data::from_value(v, slot.size) else {
            return;
        };
        let m = Message::Broadcast {
            par: slot.addr,
            data,
        };
        self.msg(
            out,
            "broadcast",
            m,
            Compare::Exact,
            format!("broadcast {what} = {v}"),
        );
        if chance(rng, 80) {
            let what = p.map_or_else(|| "the double word".to_owned(), |p| p.id.clone());
            self.read_slot(out, "valid-read", slot, &what);
        }
    }

    fn foreign_address(&self, rng: &mut Rng) -> u8 {
        let own = self.own();
        let max = i64::from(self.addr_max);
        let a = (i64::from(own) + rng.range(1, max.max(1))) % (max + 1);
        u8::try_from(a).unwrap_or(0)
    }

    fn readdress(&self, m: Message, to: u8) -> Message {
        match m {
            Message::ReadParam { lun, par, .. } => Message::ReadParam { addr: to, lun, par },
            Message::ReadPlc { lun, par, .. } => Message::ReadPlc { addr: to, lun, par },
            Message::WriteParam { par, data, .. } => Message::WriteParam {
                addr: to,
                par,
                data,
            },
            Message::WritePlc { par, data, .. } => Message::WritePlc {
                addr: to,
                par,
                data,
            },
            Message::BitChange {
                par, mask, value, ..
            } => Message::BitChange {
                addr: to,
                par,
                mask,
                value,
            },
            other => other,
        }
    }

    fn t_foreign(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let m = self.request(rng);
        if m.kind() == MessageKind::Broadcast {
            // A broadcast with a drive address is no broadcast (manual 4.1 CMD 7).
            let fields = self.fields(&m);
            let mut f = fields;
            let cmd = self.g.rules.code(MessageKind::Broadcast);
            if let Some(first) = f.first_mut() {
                *first = self.g.rules.join(cmd, self.foreign_address(rng).max(1));
            }
            let bytes = frame(&self.g, &f, None);
            self.raw(
                out,
                "foreign-address",
                bytes,
                "a broadcast with a drive address".to_owned(),
                &["HPD-FRAME-019", "HPD-SERIAL-012"],
            );
        } else {
            let to = self.foreign_address(rng);
            let m = self.readdress(m, to);
            let b = self.bytes_of(&m);
            self.raw(
                out,
                "foreign-address",
                b,
                format!("a {} for drive {to}", m.kind().spec_name()),
                &["HPD-SERIAL-003"],
            );
        }
        if chance(rng, 50) {
            self.t_read(rng, out);
        }
    }

    fn t_bad_checksum(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let m = self.request(rng);
        let fields = self.fields(&m);
        let good = fields.iter().fold(0u8, |s, b| s.wrapping_add(*b));
        let delta = u8::try_from(rng.range(1, 255)).unwrap_or(1);
        let bytes = frame(&self.g, &fields, Some(good.wrapping_add(delta)));
        self.raw(
            out,
            "bad-checksum",
            bytes,
            format!("a {} with checksum + {delta}", m.kind().spec_name()),
            &["HPD-SERIAL-012", "HPD-FRAME-009"],
        );
        self.after_corrupt(rng, &m, out);
    }

    /// After a corrupted request: read what it would have changed (or anything).
    fn after_corrupt(&mut self, rng: &mut Rng, m: &Message, out: &mut Vec<Step>) {
        match m {
            Message::WriteParam { par, data, .. } | Message::Broadcast { par, data } => {
                let slot = Slot {
                    addr: *par,
                    size: data.len(),
                };
                self.read_slot(out, "valid-read", slot, &format!("{par:#04x} (unchanged)"));
            }
            Message::BitChange { par, .. } => {
                let slot = Slot {
                    addr: *par,
                    size: 1,
                };
                self.read_slot(out, "valid-read", slot, &format!("{par:#04x} (unchanged)"));
            }
            _ => {
                if chance(rng, 50) {
                    self.t_read(rng, out);
                }
            }
        }
    }

    fn t_bad_stuffing(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let stx = self.g.rules.stx;
        let stuff = self.g.rules.stuff;
        // A write whose data holds $7E, so there is something to stuff.
        let Some((p, s)) = pick(rng, &self.writable).copied() else {
            return;
        };
        let v = if s.size == 1 { 0x7E } else { 0x7E7E };
        let Some(data) = Data::from_value(v, s.size) else {
            return;
        };
        let m = Message::WriteParam {
            addr: self.own(),
            par: s.addr,
            data,
        };
        let mut body = self.fields(&m);
        let sum = body.iter().fold(0u8, |a, b| a.wrapping_add(*b));
        body.push(sum);
        let how = rng.range(0, 3);
        let first_stx = body.iter().position(|b| *b == stx);
        let first_other = body.iter().position(|b| *b != stx);
        let mut bytes = vec![stx];
        for (i, &b) in body.iter().enumerate() {
            bytes.push(b);
            let extra = match how {
                // No stuffing at all.
                0 => None,
                // $01 instead of $00 after the first $7E.
                1 if b == stx => Some(if Some(i) == first_stx { 0x01 } else { stuff }),
                // A stuffing byte after a byte that is not $7E.
                2 if Some(i) == first_other => Some(stuff),
                2 if b == stx => Some(stuff),
                // Only the first $7E left unstuffed.
                3 if b == stx && Some(i) != first_stx => Some(stuff),
                _ => None,
            };
            if let Some(x) = extra {
                bytes.push(x);
            }
        }
        let text = match how {
            0 => "a write with $7E data and no stuffing",
            1 => "a write with $7E followed by $01",
            2 => "a write with a stuffing byte after a byte that is not $7E",
            _ => "a write whose first $7E is not stuffed",
        };
        self.raw(
            out,
            "bad-stuffing",
            bytes,
            format!("{text} ({})", p.id),
            &["HPD-FRAME-003", "HPD-FRAME-004", "HPD-SERIAL-012"],
        );
        self.read_slot(out, "valid-read", s, &format!("{} (unchanged)", p.id));
    }

    fn t_truncated(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let m = self.request(rng);
        let b = self.bytes_of(&m);
        let k = below(rng, b.len().saturating_sub(1)).max(1);
        let head: Vec<u8> = b.iter().take(k).copied().collect();
        let text = format!("the first {k} byte(s) of a {}", m.kind().spec_name());
        if chance(rng, 50) {
            self.raw(
                out,
                "truncated",
                head,
                text,
                &["HPD-BAUD-003", "HPD-FRAME-020"],
            );
        } else {
            self.step(out, "truncated", Action::Send { bytes: head }, text, &[]);
            self.step(
                out,
                "truncated",
                Action::ListenTimeout {},
                "listen past the message time-out".to_owned(),
                &["HPD-FRAME-020", "HPD-BAUD-003"],
            );
        }
        self.t_read(rng, out);
    }

    fn t_over_long(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let m = self.request(rng);
        let b = self.bytes_of(&m);
        match rng.range(0, 2) {
            0 => {
                // More data bytes than LUN says, with a checksum over all of them.
                let mut fields = self.fields(&m);
                let extra = rng.range(1, 4);
                for _ in 0..extra {
                    fields.push(rng.byte());
                }
                let bytes = frame(&self.g, &fields, None);
                self.raw(
                    out,
                    "over-long",
                    bytes,
                    format!(
                        "a {} with {extra} byte(s) more than LUN",
                        m.kind().spec_name()
                    ),
                    &["HPD-FRAME-007", "HPD-SERIAL-012"],
                );
            }
            1 => {
                // A good frame and noise right after it, in one chunk.
                let mut bytes = b;
                for _ in 0..rng.range(1, 6) {
                    bytes.push(rng.byte());
                }
                self.raw(
                    out,
                    "over-long",
                    bytes,
                    format!("a {} followed by noise", m.kind().spec_name()),
                    &["HPD-BAUD-003"],
                );
            }
            _ => {
                // Two requests back to back in one chunk.
                let m2 = self.request(rng);
                let mut bytes = b;
                bytes.extend(self.bytes_of(&m2));
                self.raw(
                    out,
                    "over-long",
                    bytes,
                    format!(
                        "a {} and a {} in one chunk",
                        m.kind().spec_name(),
                        m2.kind().spec_name()
                    ),
                    &["HPD-FRAME-001"],
                );
            }
        }
        self.after_corrupt(rng, &m, out);
    }

    fn t_wrong_lun(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let own = self.own();
        let Some((p, s)) = pick(rng, &self.params).copied() else {
            return;
        };
        let lun = match rng.range(0, 3) {
            0 => 0u8,
            1 => u8::try_from(rng.range(5, 8)).unwrap_or(5),
            _ => rng.byte(),
        };
        let (kind, mut fields) = match rng.range(0, 2) {
            0 => (MessageKind::ReadParam, vec![lun, s.addr]),
            1 => {
                let mut f = vec![lun, s.addr];
                for _ in 0..usize::from(lun).min(8) {
                    f.push(rng.byte());
                }
                (MessageKind::WriteParam, f)
            }
            _ => {
                let lun = if chance(rng, 50) { 1 } else { 3 };
                let mut f = vec![lun, s.addr, 0xFE];
                if lun == 3 {
                    f.extend([0x01, 0x00]);
                }
                (MessageKind::BitChange, f)
            }
        };
        let cmd = self.g.rules.join(self.g.rules.code(kind), own);
        fields.insert(0, cmd);
        let bytes = frame(&self.g, &fields, None);
        self.raw(
            out,
            "wrong-lun",
            bytes,
            format!(
                "a {} of {} with LUN {}",
                kind.spec_name(),
                p.id,
                fields.get(1).copied().unwrap_or(0)
            ),
            &["HPD-FRAME-007", "HPD-SERIAL-012"],
        );
        self.read_slot(out, "valid-read", s, &format!("{} (unchanged)", p.id));
    }

    /// A request split in two, with a pause across, within or around the time-out.
    fn t_split(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let m = self.request(rng);
        let b = self.bytes_of(&m);
        if b.len() < 2 {
            return;
        }
        let k = below(rng, b.len() - 1) + 1;
        let head: Vec<u8> = b.iter().take(k).copied().collect();
        let tail: Vec<u8> = b.iter().skip(k).copied().collect();
        let name = m.kind().spec_name();
        let (class, pause, text, reqs): (&str, Action, &str, &[&str]) = match rng.range(0, 2) {
            0 => (
                "split-timeout",
                Action::ListenTimeout {},
                "wait past the message time-out",
                &["HPD-BAUD-002", "HPD-BAUD-003", "HPD-FRAME-020"],
            ),
            1 => (
                "split-within",
                Action::ListenHalfTimeout {},
                "wait half the message time-out",
                &["HPD-BAUD-002", "HPD-FRAME-020"],
            ),
            _ => (
                "split-random",
                Action::Listen {
                    us: Micros::try_from(rng.range(100, 16_000)).unwrap_or(1000),
                },
                "wait a random time",
                &["HPD-BAUD-002"],
            ),
        };
        self.step(
            out,
            class,
            Action::Send { bytes: head },
            format!("the first {k} byte(s) of a {name}"),
            &[],
        );
        self.step(out, class, pause, text.to_owned(), reqs);
        self.raw(out, class, tail, format!("the rest of the {name}"), reqs);
        self.after_corrupt(rng, &m, out);
    }

    fn t_noise(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let n = rng.range(1, 12);
        let stx_ok = chance(rng, 30);
        let mut bytes: Vec<u8> = (0..n)
            .map(|_| {
                let b = rng.byte();
                if b == self.g.rules.stx && !stx_ok {
                    0x55
                } else {
                    b
                }
            })
            .collect();
        let with_read = chance(rng, 50);
        if with_read {
            let m = self.request(rng);
            bytes.extend(self.bytes_of(&m));
        }
        self.raw(
            out,
            "noise",
            bytes,
            format!(
                "{n} byte(s) of noise{}",
                if with_read { " and a request" } else { "" }
            ),
            &["HPD-BAUD-003", "HPD-FRAME-002"],
        );
        if !with_read {
            self.step(
                out,
                "noise",
                Action::ListenTimeout {},
                "let the noise time out".to_owned(),
                &["HPD-FRAME-020"],
            );
        }
        self.t_read(rng, out);
    }

    fn t_plc_read(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let last = self.g.protocol.plc.last_address;
        let lun = match rng.range(0, 9) {
            0 => 0,
            1 => u8::try_from(rng.range(5, 9)).unwrap_or(5),
            _ => u8::try_from(rng.range(1, 4)).unwrap_or(2),
        };
        let par = if chance(rng, 80) {
            u8::try_from(rng.range(0, i64::from(last) / 2) * 2).unwrap_or(0)
        } else {
            u8::try_from(rng.range(i64::from(last).saturating_sub(4), 0xFF)).unwrap_or(last)
        };
        let m = Message::ReadPlc {
            addr: self.own(),
            lun,
            par,
        };
        if lun == 0 || lun > 4 {
            // LUN outside 1..4 is no message the codec builds: by hand.
            let cmd = self
                .g
                .rules
                .join(self.g.rules.code(MessageKind::ReadPlc), self.own());
            let bytes = frame(&self.g, &[cmd, lun, par], None);
            self.raw(
                out,
                "plc-read",
                bytes,
                format!("read {lun} PLC byte(s) at {par:#04x}"),
                &["HPD-FRAME-007", "HPD-FRAME-022"],
            );
            return;
        }
        self.msg(
            out,
            "plc-read",
            m,
            Compare::Exact,
            format!("read {lun} PLC byte(s) at {par:#04x}"),
        );
    }

    /// A random instruction of form `form` (or any but END).
    fn instr(&mut self, rng: &mut Rng, bad_operands: bool) -> Option<Instr> {
        let codec = &self.g.codec;
        let choices: Vec<(u8, OperandForm, Operation)> = codec
            .plc()
            .instructions
            .iter()
            .filter(|i| !matches!(i.operands, OperandForm::None | OperandForm::Fin))
            .map(|i| (i.code, i.operands, i.operation))
            .collect();
        // Arithmetic two times in five: the PLC's words, double words and flags (3.8.1).
        let arith: Vec<(u8, OperandForm, Operation)> = choices
            .iter()
            .filter(|c| c.1 == OperandForm::Arith)
            .copied()
            .collect();
        let pool = if !bad_operands && chance(rng, 40) && !arith.is_empty() {
            &arith
        } else {
            &choices
        };
        let (code, form, op) = pick(rng, pool).copied()?;
        let user = self.g.bit_ref(names::USER_FLAG);
        let operands = match form {
            OperandForm::Bit => {
                let writes = matches!(op, Operation::Out | Operation::Set | Operation::Reset);
                let (pa, y) = if bad_operands {
                    (rng.byte(), u8::try_from(rng.range(0, 15)).unwrap_or(0))
                } else if writes {
                    // User flags and outputs the program may drive (manual 3.8.1 b90.8-15).
                    match user {
                        Some(u) if chance(rng, 70) => (
                            u8::try_from(u.param.number).unwrap_or(90),
                            u8::try_from(rng.range(8, 15)).unwrap_or(8),
                        ),
                        _ => {
                            let b = pick(rng, &self.bits).cloned()?;
                            (
                                u8::try_from(b.r.param.number).unwrap_or(0),
                                u8::try_from(b.r.bit).unwrap_or(0),
                            )
                        }
                    }
                } else {
                    let b = pick(rng, &self.bits).cloned()?;
                    (
                        u8::try_from(b.r.param.number).unwrap_or(0),
                        u8::try_from(b.r.bit).unwrap_or(0),
                    )
                };
                Operands::Bit { pa, y }
            }
            OperandForm::Arith => {
                let word = |rng: &mut Rng, pool: &[u8]| pick(rng, pool).copied().unwrap_or(80);
                let (pa, pb, pc) = if bad_operands {
                    if chance(rng, 50) && !self.forbidden.is_empty() {
                        let f = word(rng, &self.forbidden);
                        let w = word(rng, &self.results);
                        match rng.range(0, 2) {
                            0 => (f, w, w),
                            1 => (w, f, w),
                            _ => (w, w, f),
                        }
                    } else {
                        (rng.byte(), rng.byte(), rng.byte())
                    }
                } else {
                    let a = if chance(rng, 50) {
                        word(rng, &self.results)
                    } else {
                        word(rng, &self.words)
                    };
                    let b = if chance(rng, 50) {
                        word(rng, &self.results)
                    } else {
                        word(rng, &self.words)
                    };
                    (a, b, word(rng, &self.results))
                };
                let spare = if bad_operands && chance(rng, 30) {
                    u8::try_from(rng.range(1, 15)).unwrap_or(1)
                } else {
                    0
                };
                Operands::Arith { pa, pb, pc, spare }
            }
            _ => return None,
        };
        Some(Instr { code, operands })
    }

    fn instr_of(&self, op: OperandForm) -> Option<u8> {
        self.g
            .codec
            .plc()
            .instructions
            .iter()
            .find(|i| i.operands == op)
            .map(|i| i.code)
    }

    /// A program, good or bad (manual 3.8.1): the bytes, its class, and what it is.
    fn program(
        &mut self,
        rng: &mut Rng,
    ) -> (Vec<u8>, &'static str, String, &'static [&'static str]) {
        let area = usize::from(self.g.protocol.plc.area_bytes);
        let end_code = self.instr_of(OperandForm::None);
        let fin_code = self.instr_of(OperandForm::Fin);
        let ld = self
            .g
            .codec
            .plc()
            .instructions
            .iter()
            .find(|i| i.operation == Operation::Load && !i.invert)
            .map(|i| i.code);
        let mut instrs: Vec<Instr> = Vec::new();
        let kind = rng.range(0, 9);
        let (class, what, reqs): (&str, &str, &'static [&'static str]) = match kind {
            0 => (
                "plc-bad-program",
                "FIN after other instructions",
                &["HPD-PLC-030", "HPD-PLC-032"],
            ),
            1 => ("plc-bad-program", "no END", &["HPD-PLC-045"]),
            2 => (
                "plc-bad-program",
                "more than 64 instructions",
                &["HPD-PLC-003", "HPD-PLC-045"],
            ),
            3 => (
                "plc-bad-program",
                "arithmetic on byte parameters or unknown operands",
                &["HPD-PLC-026", "HPD-PLC-046"],
            ),
            4 => ("plc-bad-program", "random bytes", &["HPD-PLC-039"]),
            _ => ("plc-upload", "a program", &["HPD-PLC-039", "HPD-PLC-045"]),
        };
        if kind == 4 {
            let n = rng.range(2, 16) * 2;
            let bytes: Vec<u8> = (0..n).map(|_| rng.byte()).collect();
            return (bytes, class, what.to_owned(), reqs);
        }
        // Leading FIN instructions (HPD-PLC-030).
        if let Some(fin) = fin_code {
            if kind != 2 && chance(rng, 30) {
                for _ in 0..rng.range(1, 3) {
                    instrs.push(Instr {
                        code: fin,
                        operands: Operands::Fin {
                            y: u8::try_from(rng.range(0, 15)).unwrap_or(0),
                            n: u8::try_from(rng.range(0, 3)).unwrap_or(0),
                            spare: 0,
                        },
                    });
                }
            }
        }
        // The stack at 1 while the PLC runs: arithmetic needs it (manual 3.8.1).
        if let Some(ld) = ld {
            instrs.push(Instr {
                code: ld,
                operands: Operands::Bit {
                    pa: self.run_bit.0,
                    y: self.run_bit.1,
                },
            });
        }
        let body = if kind == 2 { 70 } else { rng.range(1, 6) };
        for _ in 0..body {
            if let Some(i) = self.instr(rng, kind == 3) {
                instrs.push(i);
            }
        }
        if kind == 0 {
            if let Some(fin) = fin_code {
                let first = instrs
                    .iter()
                    .position(|i| !matches!(i.operands, Operands::Fin { .. }))
                    .unwrap_or(0);
                let at =
                    (first + 1 + below(rng, instrs.len().saturating_sub(first))).min(instrs.len());
                let fin = Instr {
                    code: fin,
                    operands: Operands::Fin {
                        y: u8::try_from(rng.range(0, 15)).unwrap_or(0),
                        n: u8::try_from(rng.range(0, 3)).unwrap_or(0),
                        spare: 0,
                    },
                };
                instrs.insert(at, fin);
            }
        }
        if kind != 1 && kind != 2 {
            if let Some(end) = end_code {
                let spare = if kind == 3 && chance(rng, 50) {
                    rng.byte()
                } else {
                    0
                };
                instrs.push(Instr {
                    code: end,
                    operands: Operands::None {
                        spare: 0,
                        spare1: spare,
                    },
                });
            }
        }
        let mut bytes = Vec::new();
        for i in &instrs {
            if self.g.codec.encode(i, &mut bytes).is_err() {
                continue;
            }
            if bytes.len() >= area {
                break;
            }
        }
        bytes.truncate(area);
        (bytes, class, what.to_owned(), reqs)
    }

    /// Writes `bytes` into the PLC area from 0, instruction by instruction (or in other
    /// pieces, which HPD-FRAME-022 forbids).
    fn upload(&mut self, rng: &mut Rng, out: &mut Vec<Step>, bytes: &[u8], class: &str) {
        let mask = self.g.protocol.plc.encoding.code_mask;
        let odd = chance(rng, 15);
        // Long programs go two 2-byte instructions per message (still whole instructions).
        let pack = bytes.len() > 40;
        let mut at = 0usize;
        while at < bytes.len() {
            let len_at = |i: usize| {
                let b0 = bytes.get(i).copied().unwrap_or(0);
                self.g.codec.length(b0 & mask).unwrap_or(2)
            };
            let n = if odd {
                usize::try_from(rng.range(1, 4)).unwrap_or(2)
            } else if pack && len_at(at) == 2 && len_at(at + 2) == 2 {
                4
            } else {
                len_at(at)
            };
            let n = n.min(bytes.len() - at).max(1);
            let chunk: Vec<u8> = bytes.iter().skip(at).take(n).copied().collect();
            let par = u8::try_from(at).unwrap_or(u8::MAX);
            at += n;
            let Some(data) = Data::new(&chunk) else {
                continue;
            };
            let m = Message::WritePlc {
                addr: self.own(),
                par,
                data,
            };
            let c = if odd { "plc-bad-upload" } else { class };
            self.msg(
                out,
                c,
                m,
                Compare::Exact,
                format!("write {n} PLC byte(s) at {par:#04x}"),
            );
        }
    }

    /// Stop, upload, set operands, run some scans, stop, read results and the area back.
    fn t_plc_program(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let (bytes, class, what, reqs) = self.program(rng);
        if !chance(rng, 10) {
            self.stop_plc(out);
        }
        let from = out.len();
        self.upload(rng, out, &bytes, class);
        for s in out.iter_mut().skip(from) {
            for r in reqs.iter().chain(&["HPD-BIT-99-13"]) {
                if self.g.known(r) && !s.requirements.iter().any(|x| x == r) {
                    s.requirements.push((*r).to_owned());
                }
            }
        }
        let program = self.g.codec.decode_program(&bytes).ok();
        let fx = program.as_ref().map(|p| self.g.codec.effects(p));
        // Operands.
        if let Some(fx) = &fx {
            for r in fx.reads.iter().filter(|r| r.starts_with("Pr")).take(3) {
                if let Some(s) = self.g.slot_of(r) {
                    let v = match rng.range(0, 4) {
                        0 => 0,
                        1 => rng.range(-3, 3),
                        2 => rng.range(-32768, 32767),
                        _ => rng.range(1, 5000),
                    };
                    self.write_slot(out, "plc-operand", s, v, r);
                }
            }
        }
        let dword = chance(rng, 50);
        if let (Some(b), true) = (self.dword_bit, dword) {
            self.bit_step(out, "plc-operand", &b, true);
        }
        if let Some(run) = self.run_bit_ref() {
            self.bit_step(out, "plc-run-stop", &run, true);
            let scans = Micros::try_from(rng.range(1, 4)).unwrap_or(1);
            self.step(
                out,
                "listen",
                Action::Listen {
                    us: scans * self.scan_us,
                },
                format!("let {scans} PLC scan(s) of {what} run"),
                &["HPD-PLC-004"],
            );
            if chance(rng, 80) {
                self.bit_step(out, "plc-run-stop", &run, false);
            }
        }
        if let Some(fx) = &fx {
            let mut read: Vec<Slot> = Vec::new();
            for w in fx.writes.iter() {
                let slot = if w.starts_with("Pr") {
                    self.g.slot_of(w)
                } else {
                    parse_bit(w).and_then(|(n, _)| self.g.slot_of(&format!("Pb{n}")))
                };
                if let Some(s) = slot {
                    // Results of double-word arithmetic read as double words (HPD-PLC-015).
                    let pair = Slot {
                        addr: s.addr,
                        size: 4,
                    };
                    let s = if s.size == 2 && (dword || self.pairs.contains(&pair)) {
                        pair
                    } else {
                        s
                    };
                    if !read.contains(&s) {
                        read.push(s);
                    }
                }
            }
            for s in read.into_iter().take(4) {
                self.read_slot(out, "valid-read", s, &format!("{:#04x}", s.addr));
            }
        }
        if let Some(pb99) = self.g.slot_of("Pb99") {
            self.read_slot(out, "valid-read", pb99, "Pb99 (PLC flags)");
        }
        if chance(rng, 50) {
            let n = bytes.len().min(8);
            let mut at = 0usize;
            while at < n {
                let lun = (n - at).min(4);
                let m = Message::ReadPlc {
                    addr: self.own(),
                    lun: u8::try_from(lun).unwrap_or(4),
                    par: u8::try_from(at).unwrap_or(0),
                };
                self.msg(
                    out,
                    "plc-read",
                    m,
                    Compare::Exact,
                    format!("read back PLC bytes at {at:#04x}"),
                );
                at += lun;
            }
        }
    }

    fn t_plc_write_running(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let Some(i) = self.instr(rng, false) else {
            return;
        };
        let mut bytes = Vec::new();
        if self.g.codec.encode(&i, &mut bytes).is_err() {
            return;
        }
        let at = u8::try_from(rng.range(0, 20) * 2).unwrap_or(0);
        let Some(data) = Data::new(&bytes) else {
            return;
        };
        let m = Message::WritePlc {
            addr: self.own(),
            par: at,
            data,
        };
        self.msg(
            out,
            "plc-write-running",
            m,
            Compare::Exact,
            format!("write an instruction at {at:#04x} (PLC as it is)"),
        );
        let lun = data.len();
        let m = Message::ReadPlc {
            addr: self.own(),
            lun,
            par: at,
        };
        self.msg(
            out,
            "plc-read",
            m,
            Compare::Exact,
            format!("read PLC bytes at {at:#04x}"),
        );
    }

    /// Digital inputs changed (sim), some time, then the bits that show them.
    fn t_inputs(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let max = (1i64 << self.inputs) - 1;
        let value = u16::try_from(rng.range(0, max)).unwrap_or(0);
        self.step(
            out,
            "inputs",
            Action::Inputs { value },
            format!("digital inputs = {value:#06x}"),
            &["HPD-PLC-004"],
        );
        let us = if chance(rng, 50) {
            self.scan_us
        } else {
            Micros::try_from(rng.range(300, 20_000)).unwrap_or(1000)
        };
        self.step(
            out,
            "listen",
            Action::Listen { us },
            format!("listen {us} µs"),
            &[],
        );
        for id in [
            self.g.protocol.io.input_param.clone(),
            self.g.protocol.io.output_param.clone(),
            "Pb40".to_owned(),
            "Pb70".to_owned(),
        ] {
            if chance(rng, 60) {
                if let Some(s) = self.g.slot_of(&id) {
                    self.read_slot(out, "valid-read", s, &id);
                }
            }
        }
    }

    fn t_dword(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        let Some(s) = pick(rng, &self.pairs).copied() else {
            return;
        };
        if chance(rng, 60) {
            let v = match rng.range(0, 3) {
                0 => rng.range(-0x8000_0000, 0x7FFF_FFFF),
                1 => 0x7E7E_7E7E,
                _ => rng.range(-70_000, 70_000),
            };
            self.write_slot(
                out,
                "dword",
                s,
                v,
                &format!("double word at {:#04x}", s.addr),
            );
        }
        self.read_slot(out, "dword", s, &format!("double word at {:#04x}", s.addr));
    }

    /// One random change to a sequence: bytes of a message, or its order.
    fn mutate(&mut self, rng: &mut Rng, out: &mut Vec<Step>) {
        if out.is_empty() {
            return;
        }
        let i = below(rng, out.len());
        match rng.range(0, 5) {
            0 | 1 => {
                let Some(s) = out.get_mut(i) else { return };
                let Some(bytes) = s.action.bytes().map(<[u8]>::to_vec) else {
                    return;
                };
                let mut b = bytes;
                if b.is_empty() {
                    return;
                }
                let j = below(rng, b.len());
                let what = match rng.range(0, 3) {
                    0 => {
                        if let Some(x) = b.get_mut(j) {
                            *x ^= 1 << rng.range(0, 7);
                        }
                        "a bit flipped"
                    }
                    1 => {
                        if let Some(x) = b.get_mut(j) {
                            *x = rng.byte();
                        }
                        "a byte replaced"
                    }
                    2 => {
                        b.insert(j, rng.byte());
                        "a byte inserted"
                    }
                    _ => {
                        b.remove(j);
                        "a byte removed"
                    }
                };
                if b.is_empty() {
                    return;
                }
                s.action = s.action.with_bytes(b);
                s.class = "mutated-bytes".to_owned();
                s.text = format!("{} ({what} at {j})", s.text);
            }
            2 => {
                if out.len() > 1 {
                    out.remove(i);
                }
            }
            3 => {
                if let Some(s) = out.get(i).cloned() {
                    out.insert(i, s);
                }
            }
            _ => {
                if i + 1 < out.len() {
                    out.swap(i, i + 1);
                }
            }
        }
    }
}
