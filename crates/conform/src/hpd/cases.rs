//! Building HPD cases: the vocabulary (read, write, bit change, set-up and clean-up of the
//! PLC, the operating mode and the serial address) and the requirements each step exercises.

use super::names;
use super::step::{Action, Compare, HpdCase, Step};
use crate::case::{CaseInfo, Role};
use crate::rng::Rng;
use drivespec_hpd::memory::{BitAddr, ParamMap, Slot};
use drivespec_hpd::model::Drive;
use drivespec_hpd::params::Target;
use drivespec_hpd::plc::PlcCodec;
use drivespec_hpd::{Data, FrameRules, Message, MessageKind};
use drivespec_spec::hpd::Protocol;
use drivespec_spec::{Family, FamilyId, Level, Parameter, Ranges, Spec};
use std::collections::BTreeSet;

/// A case being written.
pub struct CaseB {
    pub(crate) id: String,
    pub(crate) description: String,
    pub(crate) explicit: Vec<String>,
    /// The steps so far.
    pub steps: Vec<Step>,
    pub(crate) needs_power_cycle: bool,
    pub(crate) touched: Vec<Slot>,
    pub(crate) level: Option<Level>,
}

impl CaseB {
    /// An empty case with its id, description and requirement IDs.
    pub fn new(id: impl Into<String>, description: impl Into<String>, reqs: &[&str]) -> CaseB {
        CaseB {
            id: id.into(),
            description: description.into(),
            explicit: reqs.iter().map(|r| (*r).to_owned()).collect(),
            steps: Vec::new(),
            needs_power_cycle: false,
            touched: Vec::new(),
            level: None,
        }
    }

    /// Adds requirements of the case itself.
    pub(crate) fn reqs(&mut self, reqs: impl IntoIterator<Item = String>) {
        for r in reqs {
            if !self.explicit.contains(&r) {
                self.explicit.push(r);
            }
        }
    }

    /// Declares the case's level instead of deriving it from its requirements.
    pub(crate) fn level(&mut self, level: Level) {
        self.level = Some(level);
    }

    /// A step that is not a message.
    pub(crate) fn action(
        &mut self,
        role: Role,
        action: Action,
        text: impl Into<String>,
        reqs: &[&str],
    ) {
        if matches!(action, Action::PowerCycle {}) {
            self.needs_power_cycle = true;
        }
        self.steps.push(Step {
            role,
            action,
            golden: None,
            text: text.into(),
            requirements: reqs.iter().map(|r| (*r).to_owned()).collect(),
        });
    }

    /// Switches the drive off and on (a check step).
    pub(crate) fn power_cycle(&mut self) {
        self.action(
            Role::Check,
            Action::PowerCycle {},
            "switch the drive off and on",
            &[],
        );
    }

    /// Sends `head`, the first 3 bytes of a read of Pr33, then pauses with `pause`
    /// (manual 4.1: a message must be complete within the Pr26 time-out).
    pub(crate) fn split_read(
        &mut self,
        head: &[u8],
        pause: Action,
        text: impl Into<String>,
        reqs: &[&str],
    ) {
        self.action(
            Role::Check,
            Action::Send {
                bytes: head.to_vec(),
            },
            "send the first 3 bytes of a read of Pr33",
            &[],
        );
        self.action(Role::Check, pause, text, reqs);
    }
}

/// Everything fixed while cases are generated.
pub struct Gen<'s> {
    /// The HPD family of the spec.
    pub family: &'s Family,
    /// Its protocol table (manual chapter 4).
    pub protocol: &'s Protocol,
    /// The framing rules (manual 4.1).
    pub rules: FrameRules,
    pub(crate) map: ParamMap,
    /// The PLC instruction codec (manual appendix G).
    pub codec: PlcCodec,
    pub(crate) baseline: Drive,
    pub(crate) model: Option<&'s drivespec_spec::DeviceModel>,
    /// The device's own address (Pr27).
    pub addr: u8,
    pub(crate) rng: Rng,
    pub(crate) cases: Vec<(CaseInfo, HpdCase)>,
    /// Messages that could not be built, with the reason.
    pub errors: Vec<String>,
    /// Pb99 and the PLC run bit b99.13.
    pub(crate) run: (Slot, BitAddr),
}

/// A bit of a parameter by name: the parameter, its slot, the bit number and byte address.
#[derive(Debug, Clone, Copy)]
pub struct BitRef<'s> {
    /// The parameter.
    pub param: &'s Parameter,
    /// Its slot in the drive's memory.
    pub slot: Slot,
    /// The bit number.
    pub bit: u32,
    pub(crate) at: BitAddr,
}

/// Why the HPD cases or fuzz sequences cannot be generated from the spec.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum GenError {
    /// The spec has no HPD protocol table.
    #[error("no HPD protocol table")]
    NoProtocol,
    /// The framing rules cannot be read from the spec.
    #[error(transparent)]
    Rules(#[from] drivespec_hpd::RulesError),
    /// The spec has no PLC tables (manual appendix G).
    #[error("no PLC tables")]
    NoPlc,
    /// The protocol table's PLC run bit is not a bit of the spec.
    #[error("PLC run bit {0:?} is not a bit of the spec")]
    RunBit(String),
    /// The reference drive cannot be built from the spec.
    #[error(transparent)]
    Model(#[from] drivespec_hpd::model::ModelError),
    /// Cases that cannot be built (a message the spec's values do not encode).
    #[error("{} problem(s) generating HPD cases, first: {}", .0.len(), .0.first().map_or("", String::as_str))]
    Cases(Vec<String>),
}

impl<'s> Gen<'s> {
    /// The generator over `spec` for a device like `baseline` at `addr`, drawing from `seed`.
    pub fn new(
        spec: &'s Spec,
        baseline: Drive,
        model: Option<&'s drivespec_spec::DeviceModel>,
        addr: u8,
        seed: u64,
    ) -> Result<Gen<'s>, GenError> {
        let family = spec.family(FamilyId::Hpd);
        let protocol = family.hpd().ok_or(GenError::NoProtocol)?;
        let rules = FrameRules::from_spec(spec)?;
        let codec = PlcCodec::from_spec(spec).ok_or(GenError::NoPlc)?;
        let map = ParamMap::from_spec(spec);
        let mut g = Gen {
            family,
            protocol,
            rules,
            map,
            codec,
            baseline,
            model,
            addr,
            rng: Rng::new(seed),
            cases: Vec::new(),
            errors: Vec::new(),
            run: (Slot { addr: 0, size: 0 }, BitAddr { byte: 0, mask: 0 }),
        };
        let run = g
            .bit_ref(&protocol.plc.run_bit)
            .ok_or_else(|| GenError::RunBit(protocol.plc.run_bit.clone()))?;
        g.run = (run.slot, run.at);
        Ok(g)
    }

    // ------------------------------------------------------------------ lookups

    /// A parameter by id (`Pr33`, `Pb99`).
    pub fn param(&self, id: &str) -> Option<&'s Parameter> {
        self.family.parameter(id)
    }

    /// Serial slot of a parameter.
    pub fn slot(&self, p: &Parameter) -> Option<Slot> {
        let addr = u8::try_from(p.address?).ok()?;
        let size = u8::try_from(p.size?).ok()?;
        Some(Slot { addr, size })
    }

    /// Slot of a parameter by id.
    pub fn slot_of(&self, id: &str) -> Option<Slot> {
        self.param(id).and_then(|p| self.slot(p))
    }

    /// A bit by name (`b99.13`).
    pub fn bit_ref(&self, name: &str) -> Option<BitRef<'s>> {
        let target = Target::parse(self.family, name).ok()?;
        let Target::Bit(param, bit) = target else {
            return None;
        };
        let slot = self.slot(param)?;
        let (n, y) = ParamMap::parse_bit(name)?;
        let at = self.map.bit(n, y)?;
        Some(BitRef {
            param,
            slot,
            bit,
            at,
        })
    }

    /// The raw start value of a slot (the reference drive as commissioned).
    pub fn base(&self, slot: Slot) -> u32 {
        self.baseline.memory().get(slot.addr, slot.size)
    }

    /// The range of a parameter in operating mode `mode` (manual 3.3, 3.6).
    pub fn range_in(&self, p: &Parameter, mode: Option<u32>) -> Option<Ranges> {
        if let Some(m) = mode {
            if let Some(r) = p
                .modes
                .iter()
                .find(|e| e.modes.contains(&m))
                .and_then(|e| e.range.clone())
            {
                return Some(r);
            }
        }
        self.family.resolve(p, self.model).range
    }

    /// The operating modes in which `p` has a range of its own (manual 3.6).
    pub fn ranged_modes(p: &Parameter) -> Vec<u32> {
        p.modes
            .iter()
            .filter(|m| m.range.is_some())
            .flat_map(|m| m.modes.iter().copied())
            .collect()
    }

    /// The requirement IDs in the spec (so cases never cite a missing one).
    pub fn known(&self, id: &str) -> bool {
        self.family.requirement(id).is_some()
    }

    /// Must/should requirements that name `p` and whose text satisfies `pred`.
    pub fn linked(&self, p: &Parameter, pred: impl Fn(&str) -> bool) -> Vec<String> {
        self.family
            .requirements
            .iter()
            .filter(|r| r.level != Level::Informative && r.params.contains(&p.id) && pred(&r.text))
            .map(|r| r.id.clone())
            .collect()
    }

    // ------------------------------------------------------------------ messages

    pub(crate) fn bytes(&mut self, msg: &Message) -> Vec<u8> {
        match msg.to_bytes(&self.rules) {
            Ok(b) => b,
            Err(e) => {
                self.errors.push(format!("{msg:?}: {e}"));
                Vec::new()
            }
        }
    }

    /// Requirements a correct request of this kind exercises (manual 4.1 table), with the
    /// answer the reference gives. A write's answer is only the acknowledge, so its rule
    /// (HPD-FRAME-011) comes first: a missing or malformed acknowledge breaks it.
    fn auto_reqs(&self, msg: &Message, bytes: &[u8]) -> Vec<&'static str> {
        let mut r: Vec<&'static str> = match msg.kind() {
            MessageKind::WriteParam | MessageKind::BitChange | MessageKind::WritePlc => {
                vec!["HPD-FRAME-011", "HPD-FRAME-001", "HPD-FRAME-006"]
            }
            _ => vec!["HPD-FRAME-001", "HPD-FRAME-006"],
        };
        match msg.kind() {
            MessageKind::ReadParam => r.extend([
                "HPD-FRAME-014",
                "HPD-FRAME-010",
                "HPD-FRAME-009",
                "HPD-FRAME-008",
                "HPD-SERIAL-017",
                "HPD-SERIAL-015",
            ]),
            MessageKind::WriteParam => {
                r.extend(["HPD-FRAME-015", "HPD-FRAME-008", "HPD-SERIAL-015"])
            }
            MessageKind::BitChange => r.extend(["HPD-FRAME-016", "HPD-FRAME-017", "HPD-FRAME-018"]),
            MessageKind::ReadPlc => r.extend([
                "HPD-FRAME-012",
                "HPD-FRAME-010",
                "HPD-FRAME-009",
                "HPD-FRAME-022",
            ]),
            MessageKind::WritePlc => r.extend(["HPD-FRAME-013", "HPD-FRAME-022"]),
            MessageKind::Broadcast => r.extend(["HPD-FRAME-019", "HPD-SERIAL-013"]),
            MessageKind::Response => r.push("HPD-SERIAL-001"),
        }
        let multi = match msg {
            Message::ReadParam { lun, .. } | Message::ReadPlc { lun, .. } => *lun > 1,
            Message::WriteParam { data, .. } | Message::Broadcast { data, .. } => data.len() > 1,
            _ => false,
        };
        if multi {
            r.push("HPD-SERIAL-016");
        }
        if bytes
            .windows(2)
            .skip(1)
            .any(|w| w == [self.rules.stx, self.rules.stuff])
        {
            r.extend(["HPD-FRAME-003", "HPD-FRAME-004"]);
        }
        r
    }

    /// A message step with the requirements it exercises.
    pub fn msg(
        &mut self,
        cb: &mut CaseB,
        role: Role,
        msg: Message,
        compare: Compare,
        text: impl Into<String>,
    ) {
        let bytes = self.bytes(&msg);
        let reqs = self.auto_reqs(&msg, &bytes);
        if let Message::WriteParam { par, data, .. } | Message::Broadcast { par, data } = msg {
            self.touch(cb, par, data.len());
        }
        if let Message::BitChange { par, .. } = msg {
            self.touch(cb, par, 1);
        }
        cb.steps.push(Step {
            role,
            action: Action::Exchange {
                bytes,
                compare,
                silence_ok: false,
            },
            golden: None,
            text: text.into(),
            requirements: reqs.iter().map(|s| (*s).to_owned()).collect(),
        });
    }

    /// Raw bytes (malformed frames) with the requirements given.
    pub fn raw(
        &mut self,
        cb: &mut CaseB,
        role: Role,
        bytes: Vec<u8>,
        text: impl Into<String>,
        reqs: &[&str],
    ) {
        let mut reqs: Vec<&str> = reqs.to_vec();
        // A well-formed request exercises what its message type does.
        if let Ok(m) = drivespec_hpd::parse(&self.rules, &bytes) {
            if m.is_request() {
                for r in self.auto_reqs(&m, &bytes) {
                    if !reqs.contains(&r) {
                        reqs.push(r);
                    }
                }
            }
        }
        cb.steps.push(Step {
            role,
            action: Action::Exchange {
                bytes,
                compare: Compare::Exact,
                silence_ok: false,
            },
            golden: None,
            text: text.into(),
            requirements: reqs.iter().map(|s| (*s).to_owned()).collect(),
        });
    }

    /// A read of `slot` addressed to drive `addr`, as raw bytes with the requirements given
    /// (a read the drive must not answer).
    pub(crate) fn raw_read(
        &mut self,
        cb: &mut CaseB,
        addr: u8,
        slot: Slot,
        text: impl Into<String>,
        reqs: &[&str],
    ) {
        let msg = Message::ReadParam {
            addr,
            lun: slot.size,
            par: slot.addr,
        };
        let bytes = self.bytes(&msg);
        self.raw(cb, Role::Check, bytes, text, reqs);
    }

    fn touch(&self, cb: &mut CaseB, par: u8, len: u8) {
        for i in 0..len {
            let Some(a) = par.checked_add(i) else { break };
            if let Some(p) = self.family.parameter_at_address(u32::from(a)) {
                if let Some(s) = self.slot(p) {
                    if !cb.touched.contains(&s) {
                        cb.touched.push(s);
                    }
                }
            }
        }
    }

    /// Read `slot` from the drive at `at`.
    pub(crate) fn read_at(
        &mut self,
        cb: &mut CaseB,
        role: Role,
        at: u8,
        slot: Slot,
        compare: Compare,
        what: &str,
    ) {
        let msg = Message::ReadParam {
            addr: at,
            lun: slot.size,
            par: slot.addr,
        };
        self.msg(
            cb,
            role,
            msg,
            compare,
            format!("read {what} from drive {at}"),
        );
    }

    /// Read `slot` from the device.
    pub(crate) fn read(
        &mut self,
        cb: &mut CaseB,
        role: Role,
        slot: Slot,
        compare: Compare,
        what: &str,
    ) {
        self.read_at(cb, role, self.addr, slot, compare, what);
    }

    /// Write raw `value` to `slot` of the drive at `at`.
    pub(crate) fn write_at(
        &mut self,
        cb: &mut CaseB,
        role: Role,
        at: u8,
        slot: Slot,
        value: i64,
        what: &str,
    ) {
        let Some(data) = Data::from_value(value, slot.size) else {
            self.errors
                .push(format!("{}: {what} = {value} does not fit", cb.id));
            return;
        };
        let msg = Message::WriteParam {
            addr: at,
            par: slot.addr,
            data,
        };
        self.msg(
            cb,
            role,
            msg,
            Compare::Exact,
            format!("write {what} = {value} to drive {at}"),
        );
    }

    /// Write raw `value` to `slot` of the device.
    pub(crate) fn write(&mut self, cb: &mut CaseB, role: Role, slot: Slot, value: i64, what: &str) {
        self.write_at(cb, role, self.addr, slot, value, what);
    }

    /// Set or clear one bit with a bit change (manual 4.1 CMD 6).
    pub fn bit(&mut self, cb: &mut CaseB, role: Role, b: &BitRef<'_>, value: bool) {
        self.bit_at(cb, role, self.addr, b, value);
    }

    pub(crate) fn bit_at(
        &mut self,
        cb: &mut CaseB,
        role: Role,
        at: u8,
        b: &BitRef<'_>,
        value: bool,
    ) {
        let Some((par, mask, bits)) =
            drivespec_hpd::params::bit_change(self.family, b.slot.addr, b.bit, value)
        else {
            self.errors.push(format!(
                "{}: no bit change for b{}.{}",
                cb.id, b.param.number, b.bit
            ));
            return;
        };
        let msg = Message::BitChange {
            addr: at,
            par,
            mask,
            value: bits,
        };
        let name = format!("b{}.{}", b.param.number, b.bit);
        self.msg(
            cb,
            role,
            msg,
            Compare::Exact,
            format!("set {name} = {} on drive {at}", u8::from(value)),
        );
    }

    /// How to compare a read of parameter `p` (in operating mode `mode`).
    pub fn compare_for(&self, p: &Parameter, mode: Option<u32>) -> Compare {
        let width = p.size.unwrap_or(2).min(4) * 8;
        let all = if width >= 32 {
            u32::MAX
        } else {
            (1u32 << width) - 1
        };
        let is_timer = self.protocol.plc.timers.iter().any(|t| t.param == p.id);
        if is_timer {
            // Timers count down every scan (manual 3.8.1): ± 64 scans (about 0.4 s).
            return Compare::Near(64);
        }
        let copies = self.drive_copies(p);
        if !p.live && copies == 0 {
            return Compare::Exact;
        }
        if self.family.bitfields_of(&p.id).next().is_some() {
            // Bits the drive sets itself (access r) are not compared.
            let mut drive_owned = 0u32;
            for bf in self.family.bitfields_of(&p.id) {
                let applies = bf.modes.is_empty() || mode.is_some_and(|m| bf.modes.contains(&m));
                if !applies {
                    continue;
                }
                for b in &bf.bits {
                    if b.access == Some(drivespec_spec::Access::R) {
                        drive_owned |= 1u32.checked_shl(b.bit).unwrap_or(0);
                    }
                }
            }
            return Compare::Mask(all & !drive_owned & !copies);
        }
        if !p.live {
            return Compare::Mask(all & !copies);
        }
        if p.access.writable() {
            Compare::Exact
        } else {
            Compare::Mask(0)
        }
    }

    /// Bits of `p` the default program (appendix G) copies from bits the drive sets itself
    /// (`LD 41.2` then `OUT 91.2`): they show the drive's status, which the manual fixes only
    /// through conditions the case does not control (speed window, erratum readings), so
    /// reads do not compare them.
    pub(crate) fn drive_copies(&self, p: &Parameter) -> u32 {
        let mut copies = 0u32;
        for w in self.protocol.default_program.windows(2) {
            let [load, out] = w else { continue };
            let (Some(src), Some(dst)) = (
                load.listing.strip_prefix("LD "),
                out.listing
                    .strip_prefix("OUT ")
                    .or_else(|| out.listing.strip_prefix("OUTN ")),
            ) else {
                continue;
            };
            let (Some(src), Some(dst)) = (
                self.bit_ref(&format!("b{}", src.trim())),
                self.bit_ref(&format!("b{}", dst.trim())),
            ) else {
                continue;
            };
            if dst.param.id != p.id || !self.drive_owned(&src) {
                continue;
            }
            copies |= bit_value(dst.slot, dst.at);
        }
        copies
    }

    /// Whether the drive alone sets bit `b` (a read-only parameter, or a bit of access r).
    fn drive_owned(&self, b: &BitRef<'_>) -> bool {
        if !b.param.access.writable() {
            return true;
        }
        self.family.bitfields_of(&b.param.id).any(|bf| {
            bf.bits
                .iter()
                .any(|x| x.bit == b.bit && x.access == Some(drivespec_spec::Access::R))
        })
    }

    // ------------------------------------------------------------------ state

    /// Setup: stop the PLC (b99.13 = 0, manual 3.2: the default program drives Pr5, Pr92 and
    /// bits of Pb40 and Pb91 while it runs), with a word write of Pb99.
    pub fn stop_plc(&mut self, cb: &mut CaseB) {
        let (slot, at) = self.run;
        let value = self.base(slot) & !bit_value(slot, at);
        self.write(
            cb,
            Role::Setup,
            slot,
            i64::from(value),
            "Pb99 (PLC stopped)",
        );
    }

    /// Cleanup: Pb99 as the device had it at the start (PLC running).
    pub(crate) fn restore_pb99(&mut self, cb: &mut CaseB) {
        let (slot, _) = self.run;
        self.restore(cb, slot, "Pb99");
    }

    /// Cleanup: a parameter back to the value the device had at the start.
    pub(crate) fn restore(&mut self, cb: &mut CaseB, slot: Slot, what: &str) {
        self.restore_at(cb, self.addr, slot, what);
    }

    /// Cleanup: a parameter of the drive at `at` back to the value the device had at the
    /// start of the case (read by a `save` step that [`Gen::push`] puts first), written to the
    /// reference too.
    pub(crate) fn restore_at(&mut self, cb: &mut CaseB, at: u8, slot: Slot, what: &str) {
        self.touch(cb, slot.addr, slot.size);
        cb.action(
            Role::Cleanup,
            Action::Restore {
                addr: at,
                par: slot.addr,
                lun: slot.size,
            },
            format!("write back the {what} the device had to drive {at}"),
            &["HPD-FRAME-015", "HPD-FRAME-011"],
        );
    }

    /// Setup: reads `slot` from the device and keeps its value (for a later
    /// [`Compare::Unchanged`] read or a restore).
    pub(crate) fn save(&mut self, cb: &mut CaseB, slot: Slot, what: &str) {
        cb.action(
            Role::Setup,
            Action::Save {
                addr: self.addr,
                par: slot.addr,
                lun: slot.size,
            },
            format!("read {what} and keep the device's value"),
            &["HPD-FRAME-010", "HPD-FRAME-014"],
        );
    }

    /// Read `slot`, whose value the manual does not fix, and report what the device shows:
    /// the value within `min..=max`, the bits under `mask` as the reference's;
    /// `requirement` is the point the finding belongs to.
    pub(crate) fn read_open(
        &mut self,
        cb: &mut CaseB,
        slot: Slot,
        (mask, min, max): (u32, i64, i64),
        requirement: &str,
        what: &str,
    ) {
        self.read(
            cb,
            Role::Check,
            slot,
            Compare::Open { mask, min, max },
            what,
        );
        if let Some(step) = cb.steps.last_mut() {
            step.requirements.insert(0, requirement.to_owned());
        }
    }

    /// Re-addresses the device from `from` to `to` (manual 4.1 set-up: Pr27, b99.6 for b42.3,
    /// then b42.3 cleared and set), with word writes. Leaves the PLC stopped and b99.6 = 1.
    pub(crate) fn readdress(&mut self, cb: &mut CaseB, role: Role, from: u8, to: u8) {
        let (Some(pr27), Some(pb42), Some(reinit), Some(ext)) = (
            self.slot_of(&self.protocol.serial_setup.address_param),
            self.slot_of("Pb42"),
            self.bit_ref(&self.protocol.serial_setup.reinit_bit),
            self.bit_ref(names::EXTENDED_MENU),
        ) else {
            self.errors
                .push(format!("{}: serial set-up parameters missing", cb.id));
            return;
        };
        let (pb99, run) = self.run;
        self.write_at(cb, role, from, pr27, i64::from(to), "Pr27");
        let v99 = (self.base(pb99) & !bit_value(pb99, run)) | bit_value(pb99, ext.at);
        self.write_at(
            cb,
            role,
            from,
            pb99,
            i64::from(v99),
            "Pb99 (b99.6 = 1, PLC stopped)",
        );
        // b42.3 cleared first: a drive that keeps a command bit until the master clears it
        // (HPD-ERRATUM-012) sees the command only on a change to 1.
        let v42 = self.base(pb42) & !bit_value(pb42, reinit.at);
        self.write_at(
            cb,
            role,
            from,
            pb42,
            i64::from(v42),
            "Pb42 (b42.3 = 0, so the next write sets it)",
        );
        let v42 = v42 | bit_value(pb42, reinit.at);
        self.write_at(
            cb,
            role,
            from,
            pb42,
            i64::from(v42),
            "Pb42 (b42.3 = 1: re-initialise the line)",
        );
    }

    // ------------------------------------------------------------------ finishing

    /// Adds the case, first reading every parameter its clean-up restores (the device's own
    /// values, written back at the end).
    pub(crate) fn push(&mut self, mut cb: CaseB) {
        let mut kept: Vec<(u8, u8)> = Vec::new();
        for s in &cb.steps {
            if let Action::Restore { par, lun, .. } = s.action {
                if !kept.contains(&(par, lun)) {
                    kept.push((par, lun));
                }
            }
        }
        let saves: Vec<Step> = kept
            .into_iter()
            .map(|(par, lun)| {
                let what = self
                    .family
                    .parameter_at_address(u32::from(par))
                    .map_or_else(|| format!("address {par:#04x}"), |p| p.id.clone());
                Step {
                    role: Role::Setup,
                    action: Action::Save {
                        addr: self.addr,
                        par,
                        lun,
                    },
                    golden: None,
                    text: format!("read {what} to write it back at the end"),
                    requirements: vec!["HPD-FRAME-010".to_owned(), "HPD-FRAME-014".to_owned()],
                }
            })
            .collect();
        cb.steps.splice(0..0, saves);
        let mut reqs: BTreeSet<String> = cb.explicit.iter().cloned().collect();
        for s in cb.steps.iter().filter(|s| s.role != Role::Cleanup) {
            reqs.extend(s.requirements.iter().cloned());
        }
        let reqs: Vec<String> = reqs.into_iter().filter(|r| self.known(r)).collect();
        for r in &cb.explicit {
            if !self.known(r) {
                self.errors
                    .push(format!("{}: unknown requirement {r}", cb.id));
            }
        }
        let level = cb.level.unwrap_or_else(|| {
            let levels: Vec<Level> = cb
                .explicit
                .iter()
                .filter_map(|r| self.family.requirement(r))
                .map(|r| r.level)
                .collect();
            if levels.is_empty() || levels.contains(&Level::Must) {
                Level::Must
            } else {
                Level::Should
            }
        });
        let info = CaseInfo {
            id: cb.id,
            family: FamilyId::Hpd,
            requirements: reqs,
            level,
            description: cb.description,
            steps: cb
                .steps
                .iter()
                .map(|s| match s.role {
                    Role::Setup => format!("setup: {}", s.text),
                    Role::Check => s.text.clone(),
                    Role::Cleanup => format!("cleanup: {}", s.text),
                })
                .collect(),
        };
        let case = HpdCase {
            steps: cb.steps,
            needs_power_cycle: cb.needs_power_cycle,
            touched: cb.touched,
            checks: cb.explicit.into_iter().filter(|r| self.known(r)).collect(),
        };
        self.cases.push((info, case));
    }
}

/// The raw value of `slot` as the signed or unsigned number of its parameter.
pub fn sign_for(slot: Slot, raw: u32, family: &Family) -> i64 {
    let signed = family
        .parameter_at_address(u32::from(slot.addr))
        .is_some_and(|p| p.data_type.signed());
    if !signed {
        return i64::from(raw);
    }
    let shift = 32 - 8 * u32::from(slot.size.clamp(1, 4));
    i64::from(((raw << shift) as i32) >> shift)
}

/// The bit `at` as a mask over the raw value of `slot`.
pub(crate) fn bit_value(slot: Slot, at: BitAddr) -> u32 {
    let shift = 8 * u32::from(at.byte.saturating_sub(slot.addr));
    u32::from(at.mask).checked_shl(shift).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::suite::SetupError;

    #[test]
    fn generation_errors_name_what_is_missing() {
        let e = GenError::Cases(vec!["first".into(), "second".into()]);
        assert_eq!(
            e.to_string(),
            "2 problem(s) generating HPD cases, first: first"
        );
        let e = SetupError::from(GenError::RunBit("b99.x".into()));
        assert_eq!(
            e.to_string(),
            "spec: PLC run bit \"b99.x\" is not a bit of the spec"
        );
        assert_eq!(
            SetupError::from(GenError::NoProtocol).to_string(),
            "spec: no HPD protocol table"
        );
    }
}
