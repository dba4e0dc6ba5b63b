//! `hpd/param/...` and `hpd/bit/...`: every parameter with a serial address read and
//! written at both range edges and one beyond (per operating mode where the range depends on
//! it), read-only parameters refusing writes, byte/word/double-word accesses, and every bit
//! set and cleared with a bit change on its byte (manual 3.3, 3.6, 4.1, 4.2).

use super::cases::{bit_value, sign_for, BitRef, CaseB, Gen};
use super::names;
use super::step::Compare;
use crate::case::Role;
use drivespec_hpd::memory::{BitAddr, Slot};
use drivespec_hpd::{Data, Message};
use drivespec_spec::{Level, Parameter};

pub(crate) fn generate(g: &mut Gen) {
    let params: Vec<&Parameter> = g
        .family
        .parameters
        .iter()
        .filter(|p| p.address.is_some() && p.size.is_some())
        .collect();
    for p in &params {
        param_cases(g, p);
    }
    widths(g);
    for p in &params {
        bit_cases(g, p);
    }
    bit_extras(g);
}

/// Whether the text of a requirement states the range `r` (`100..500`, `-10000..10000`).
fn states_range(text: &str, lo: i64, hi: i64) -> bool {
    text.contains(&format!("{lo}..{hi}")) || text.contains(&format!("{lo}...{hi}"))
}

fn param_cases(g: &mut Gen, p: &Parameter) {
    let Some(slot) = g.slot(p) else { return };
    let is_bits = g.family.bitfields_of(&p.id).next().is_some();
    let cmp = g.compare_for(p, None);

    let mut cb = CaseB::new(
        format!("hpd/param/{}/read", p.id),
        format!(
            "read {} ({}) at address {:#04x}, {} byte(s)",
            p.id, p.name, slot.addr, slot.size
        ),
        &["HPD-SERIAL-015"],
    );
    if p.access == drivespec_spec::Access::R {
        cb.reqs(g.linked(p, |t| t.contains("read-only")));
    }
    match open_value(g, p) {
        Some((bounds, requirement)) => {
            cb.description = format!(
                "{}; the manual does not fix its value: {}..={} accepted and reported",
                cb.description, bounds.1, bounds.2
            );
            g.read_open(&mut cb, slot, bounds, &requirement, &p.id);
        }
        None => {
            // The start state is the delivery state (commissioned for the serial line), so
            // the read compares the factory value the manual states.
            cb.reqs(g.linked(p, |t| t.contains("factory value")));
            g.read(&mut cb, Role::Check, slot, cmp, &p.id);
        }
    }
    g.push(cb);

    if !p.access.writable() {
        refused(g, p, slot, cmp);
        return;
    }
    if is_bits {
        return;
    }
    edges(g, p, slot, None);
    let modes = Gen::ranged_modes(p);
    for m in modes {
        let read_only = p
            .modes
            .iter()
            .any(|e| e.modes.contains(&m) && e.access.is_some_and(|a| !a.writable()));
        if read_only {
            refused_in_mode(g, p, slot, m);
        } else {
            edges(g, p, slot, Some(m));
        }
    }
}

/// The bounds of a read whose value the manual does not fix, with the requirement the
/// point belongs to: a read-only parameter the drive does not change by itself and whose value
/// the manual does not give (Pr25, the software version code: 3.3 names no code), and a
/// delivery value the manual prints two ways (names::TWO_WAY_DEFAULT).
fn open_value(g: &Gen, p: &Parameter) -> Option<((u32, i64, i64), String)> {
    let unfixed = p.access == drivespec_spec::Access::R && !p.live && p.default.is_none();
    if !unfixed && p.id != names::TWO_WAY_DEFAULT {
        return None;
    }
    let (min, max) = match g.range_in(p, None) {
        Some(r) => (r.min()?, r.max()?),
        None => p.data_type.bounds()?,
    };
    let requirement = if unfixed {
        g.linked(p, |t| t.contains("read-only"))
    } else {
        g.linked(p, |t| t.contains("delivery value"))
    }
    .into_iter()
    .next()?;
    Some(((0, min, max), requirement))
}

/// Whether the drive holds `p` at the value a case read before: not a value it changes by
/// itself, or an alarm code while no case raises an alarm (manual 3.3 Pr23, Pr24).
fn holds_still(p: &Parameter) -> bool {
    !p.live || names::ALARMS.contains(&p.id.as_str())
}

/// A write to a read-only parameter is acknowledged and changes nothing: the value read
/// before the write is read after it (where the drive does not change it by itself).
fn refused(g: &mut Gen, p: &Parameter, slot: Slot, cmp: Compare) {
    let base = g.base(slot);
    let value = sign_for(slot, base ^ 1, g.family);
    let mut cb = CaseB::new(
        format!("hpd/param/{}/write-refused", p.id),
        format!("{} is read-only: a write of {value} is not taken", p.id),
        &["HPD-SERIAL-015"],
    );
    let read_only = g.linked(p, |t| t.contains("read-only"));
    cb.reqs(read_only.iter().cloned());
    let cmp = if holds_still(p) {
        g.save(&mut cb, slot, &p.id);
        Compare::Unchanged
    } else {
        cmp
    };
    g.write(&mut cb, Role::Check, slot, value, &p.id);
    g.read(
        &mut cb,
        Role::Check,
        slot,
        cmp,
        &format!("{} (unchanged)", p.id),
    );
    if let (Some(step), Some(r)) = (cb.steps.last_mut(), read_only.first()) {
        step.requirements.insert(0, r.clone());
    }
    g.push(cb);
}

/// A write to a parameter that is read-only in operating mode `mode` (Pr55 in mode 2, manual
/// 3.6.2) is not taken: the value read in that mode before the write is read after it.
fn refused_in_mode(g: &mut Gen, p: &Parameter, slot: Slot, mode: u32) {
    let (Some(range), Some(ms)) = (g.range_in(p, Some(mode)), g.slot_of(names::OPERATING_MODE))
    else {
        return;
    };
    let mode_text = format!("mode {mode}");
    let read_only = g.linked(p, |t| t.contains("read-only") && t.contains(&mode_text));
    for (name, value) in [("min", range.min()), ("max", range.max())] {
        let Some(value) = value else { continue };
        let mut cb = CaseB::new(
            format!("hpd/param/{}/mode-{mode}/{name}", p.id),
            format!(
                "{} is read-only in operating mode {mode}: a write of {value}, the {name} of its range {range}, is not taken",
                p.id
            ),
            &["HPD-SERIAL-015", "HPD-MODE-005"],
        );
        cb.reqs(read_only.iter().cloned());
        g.stop_plc(&mut cb);
        g.write(&mut cb, Role::Setup, ms, i64::from(mode), "Pr31");
        g.save(&mut cb, slot, &p.id);
        g.write(&mut cb, Role::Check, slot, value, &p.id);
        g.read(
            &mut cb,
            Role::Check,
            slot,
            Compare::Unchanged,
            &format!("{} (unchanged)", p.id),
        );
        if let (Some(step), Some(r)) = (cb.steps.last_mut(), read_only.first()) {
            step.requirements.insert(0, r.clone());
        }
        g.restore(&mut cb, ms, "Pr31");
        g.restore_pb99(&mut cb);
        g.push(cb);
    }
}

/// Range edges and one beyond, in operating mode `mode` (None: the start mode).
fn edges(g: &mut Gen, p: &Parameter, slot: Slot, mode: Option<u32>) {
    let Some(range) = g.range_in(p, mode) else {
        return;
    };
    let Some((tmin, tmax)) = p.data_type.bounds() else {
        return;
    };
    let (Some(lo), Some(hi)) = (range.min(), range.max()) else {
        return;
    };
    let mode_slot = g.slot_of(names::OPERATING_MODE);
    let mut values: Vec<(String, i64, bool)> =
        vec![("min".into(), lo, true), ("max".into(), hi, true)];
    if lo > tmin {
        values.push(("below-min".into(), lo - 1, false));
    }
    if hi < tmax {
        values.push(("above-max".into(), hi + 1, false));
    }
    // Gaps between the intervals of a range (Pr31: 0..2 or 8..12).
    let intervals = range.intervals();
    for w in intervals.windows(2) {
        if let [[_, a_hi], [b_lo, _]] = w {
            if a_hi + 1 < *b_lo {
                values.push((format!("gap-{}", a_hi + 1), a_hi + 1, false));
            }
        }
    }
    let prefix = match mode {
        Some(m) => format!("hpd/param/{}/mode-{m}", p.id),
        None => format!("hpd/param/{}", p.id),
    };
    let cmp = g.compare_for(p, mode);
    for (name, value, inside) in values {
        let where_ = mode
            .map(|m| format!(" in operating mode {m}"))
            .unwrap_or_default();
        let what = if inside {
            format!(
                "{} takes {value}, the {name} of its range {range}{where_}",
                p.id
            )
        } else {
            format!(
                "{} keeps its value when written {value}, outside its range {range}{where_}",
                p.id
            )
        };
        let mut cb = CaseB::new(
            format!("{prefix}/{name}"),
            what,
            &["HPD-PAR-009", "HPD-SERIAL-015"],
        );
        cb.reqs(g.linked(p, |t| states_range(t, lo, hi)));
        if mode.is_some() {
            cb.reqs(["HPD-MODE-005".to_owned()]);
        }
        if !inside {
            // The manual does not say what happens to values outside the range (HPD-PAR-009
            // note); the reference ignores them.
            cb.level(Level::Should);
        }
        g.stop_plc(&mut cb);
        if let (Some(m), Some(ms)) = (mode, mode_slot) {
            g.write(&mut cb, Role::Setup, ms, i64::from(m), "Pr31");
        }
        g.write(&mut cb, Role::Check, slot, value, &p.id);
        g.read(&mut cb, Role::Check, slot, cmp, &p.id);
        g.restore(&mut cb, slot, &p.id);
        if let (Some(_), Some(ms)) = (mode, mode_slot) {
            g.restore(&mut cb, ms, "Pr31");
        }
        g.restore_pb99(&mut cb);
        g.push(cb);
    }
}

/// Byte, word and double-word accesses (manual 4.1, 4.2, 3.8.1).
fn widths(g: &mut Gen) {
    let own = g.addr;
    // Double words: pairs of word parameters at consecutive addresses inside the runs the
    // spec lists as successive (3.8.1: Pr50..Pr69, Pr80..Pr89).
    let runs: Vec<(u32, u32)> = g
        .protocol
        .plc
        .arithmetic
        .successive
        .iter()
        .filter_map(|[a, b]| Some((g.param(a)?.number, g.param(b)?.number)))
        .collect();
    let in_runs = |n: u32| {
        runs.iter()
            .any(|(a, b)| (*a..=*b).contains(&n) && (*a..=*b).contains(&(n + 1)))
    };
    let pairs: Vec<(&Parameter, &Parameter)> = g
        .family
        .parameters
        .iter()
        .filter_map(|lo| {
            let (a, s) = (lo.address?, lo.size?);
            if s != 2 || lo.number % 2 != 0 || !lo.access.writable() || !in_runs(lo.number) {
                return None;
            }
            let hi = g.family.parameter_at_address(a + 2)?;
            (hi.size == Some(2) && hi.number == lo.number + 1 && hi.access.writable())
                .then_some((lo, hi))
        })
        .collect();
    for (lo, hi) in pairs {
        let (Some(ls), Some(hs)) = (g.slot(lo), g.slot(hi)) else {
            continue;
        };
        let value = g.rng.range(-0x4000_0000, 0x3FFF_FFFF);
        let id = format!("{}:{}", lo.id, hi.number);
        let mut cb = CaseB::new(
            format!("hpd/param/{id}/dword"),
            format!("write and read {id} as one double word (LUN 4, low word first) = {value}"),
            &["HPD-PAR-006", "HPD-SERIAL-016"],
        );
        if lo.number >= 80 {
            cb.reqs(["HPD-PLC-028".to_owned()]);
        }
        let dslot = Slot {
            addr: ls.addr,
            size: 4,
        };
        g.stop_plc(&mut cb);
        g.write(&mut cb, Role::Check, dslot, value, &id);
        let cmp = g.compare_for(lo, None);
        g.read(&mut cb, Role::Check, dslot, cmp, &id);
        g.restore(&mut cb, ls, &lo.id);
        g.restore(&mut cb, hs, &hi.id);
        g.restore_pb99(&mut cb);
        g.push(cb);
    }

    // Part of a word: a 1-byte write at the address of a word parameter is not a whole
    // parameter (DECISION of the reference: ignored, acknowledged).
    if let (Some(ranged), Some(scratch)) = (g.slot_of(names::RANGED), g.slot_of(names::SCRATCH)) {
        let mut cb = CaseB::new(
            "hpd/param/Pr80/byte-write",
            "a 1-byte write at the address of the word Pr80 covers half a parameter and is not taken",
            &["HPD-SERIAL-015", "HPD-FRAME-007"],
        );
        cb.level(Level::Should);
        if let Some(data) = Data::new(&[0x5A]) {
            let msg = Message::WriteParam {
                addr: own,
                par: scratch.addr,
                data,
            };
            g.msg(
                &mut cb,
                Role::Check,
                msg,
                Compare::Exact,
                "write 1 byte $5A at Pr80",
            );
        }
        g.read(&mut cb, Role::Check, scratch, Compare::Exact, "Pr80");
        g.restore(&mut cb, scratch, "Pr80");
        g.push(cb);

        let mut cb = CaseB::new(
            "hpd/param/Pr33/high-byte-write",
            "a 1-byte write at the high byte of Pr33 is not a parameter address and is not taken",
            &["HPD-SERIAL-015", "HPD-FRAME-008"],
        );
        cb.level(Level::Should);
        if let Some(data) = Data::new(&[0x01]) {
            let msg = Message::WriteParam {
                addr: own,
                par: ranged.addr.wrapping_add(1),
                data,
            };
            g.msg(
                &mut cb,
                Role::Check,
                msg,
                Compare::Exact,
                "write 1 byte $01 at the address of Pr33 + 1",
            );
        }
        g.read(&mut cb, Role::Check, ranged, Compare::Exact, "Pr33");
        g.restore(&mut cb, ranged, "Pr33");
        g.push(cb);
    }
    // Two byte parameters at consecutive addresses written with one LUN-2 message.
    let byte_pair = g.family.parameters.iter().find_map(|p| {
        let a = p.address?;
        let next = g.family.parameter_at_address(a + 1)?;
        (p.size == Some(1)
            && next.size == Some(1)
            && next.address == Some(a + 1)
            && p.access.writable()
            && next.access.writable()
            && p.id != names::OPERATING_MODE
            && g.family.bitfields_of(&p.id).next().is_none()
            && g.family.bitfields_of(&next.id).next().is_none()
            && !p.has_condition("restart")
            && !next.has_condition("restart"))
        .then_some((p, next))
    });
    if let Some((a, b)) = byte_pair {
        if let (Some(sa), Some(sb)) = (g.slot(a), g.slot(b)) {
            let (va, vb) = (g.rng.range(1, 60), g.rng.range(2, 60));
            let (va, vb) = (
                g.range_in(a, None)
                    .and_then(|r| r.min())
                    .unwrap_or(0)
                    .max(va.min(g.range_in(a, None).and_then(|r| r.max()).unwrap_or(va))),
                g.range_in(b, None)
                    .and_then(|r| r.min())
                    .unwrap_or(0)
                    .max(vb.min(g.range_in(b, None).and_then(|r| r.max()).unwrap_or(vb))),
            );
            let mut cb = CaseB::new(
                format!("hpd/param/{}+{}/word-write", a.id, b.id),
                format!(
                    "one LUN-2 write covers the byte parameters {} = {va} and {} = {vb}",
                    a.id, b.id
                ),
                &["HPD-SERIAL-015", "HPD-FRAME-007"],
            );
            cb.level(Level::Should);
            let both = Slot {
                addr: sa.addr,
                size: 2,
            };
            g.stop_plc(&mut cb);
            g.write(
                &mut cb,
                Role::Check,
                both,
                va | vb << 8,
                &format!("{}+{}", a.id, b.id),
            );
            g.read(
                &mut cb,
                Role::Check,
                both,
                Compare::Exact,
                &format!("{}+{}", a.id, b.id),
            );
            g.restore(&mut cb, sa, &a.id);
            g.restore(&mut cb, sb, &b.id);
            g.restore_pb99(&mut cb);
            g.push(cb);
        }
    }
}

/// Bits of `p` the cases may not touch: command bits (tested under `hpd/cmd`).
fn is_command(b: &drivespec_spec::BitfieldBit) -> bool {
    b.rules.iter().any(|r| r.trigger == names::TRIGGER_COMMAND)
}

fn bit_cases(g: &mut Gen, p: &Parameter) {
    let Some(slot) = g.slot(p) else { return };
    if !p.access.writable() {
        return;
    }
    let bitfields: Vec<&drivespec_spec::Bitfield> = g.family.bitfields_of(&p.id).collect();
    let enable = g.bit_ref(&g.protocol.serial_setup.enable_bit);
    let run = g.run;
    for bf in bitfields {
        let modes: Vec<Option<u32>> = if bf.modes.is_empty() {
            vec![None]
        } else {
            bf.modes.iter().copied().map(Some).collect()
        };
        for mode in modes {
            for b in &bf.bits {
                if is_command(b) || (b.reserved && !b.must_be_zero) {
                    continue;
                }
                let name = format!("b{}.{}", p.number, b.bit);
                let Some(r) = g.bit_ref(&name) else { continue };
                let readonly = b.access == Some(drivespec_spec::Access::R) || b.must_be_zero;
                let is_run = r.at == run.1;
                if enable.is_some_and(|e| e.at == r.at) {
                    // Clearing b40.14 silences the line (HPD-BIT-40-14): under hpd/cmd.
                    continue;
                }
                let actions: Vec<bool> = if readonly {
                    let now = g.base(slot) & bit_value(slot, r.at) != 0;
                    vec![!now]
                } else {
                    vec![true, false]
                };
                for value in actions {
                    one_bit(g, p, &r, b, mode, value, readonly, is_run);
                }
            }
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn one_bit(
    g: &mut Gen,
    p: &Parameter,
    r: &BitRef,
    b: &drivespec_spec::BitfieldBit,
    mode: Option<u32>,
    value: bool,
    readonly: bool,
    is_run: bool,
) {
    let name = format!("b{}.{}", p.number, b.bit);
    let verb = match (value, readonly) {
        (true, false) => "set",
        (false, false) => "clear",
        (true, true) => "set-refused",
        (false, true) => "clear-refused",
    };
    let prefix = match mode {
        Some(m) => format!("hpd/bit/{name}/mode-{m}"),
        None => format!("hpd/bit/{name}"),
    };
    let half = if b.bit >= 8 { "high" } else { "low" };
    let text = if readonly {
        format!(
            "{name} ({}) cannot be {}: a bit change on the {half} byte leaves it",
            b.name,
            if value { "set" } else { "cleared" }
        )
    } else {
        format!(
            "{name} ({}) is {} with a bit change on the {half} byte of {}",
            b.name,
            if value { "set" } else { "cleared" },
            p.id
        )
    };
    // The byte PAR names (CMD 6) is what a bit of the high byte checks first.
    let cmd6 = if b.bit >= 8 {
        ["HPD-FRAME-018", "HPD-FRAME-017"]
    } else {
        ["HPD-FRAME-017", "HPD-FRAME-018"]
    };
    let mut cb = CaseB::new(format!("{prefix}/{verb}"), text, &cmd6);
    let own_req = format!("HPD-BIT-{}-{}", p.number, b.bit);
    if g.known(&own_req) {
        cb.reqs([own_req]);
    }
    if b.must_be_zero {
        cb.reqs(
            ["HPD-BIT-40-15".to_owned()]
                .into_iter()
                .filter(|r| g.known(r)),
        );
    }
    if mode.is_some() {
        cb.reqs(["HPD-MODE-005".to_owned()]);
    }
    if p.id == names::ALARMS[0] {
        cb.level(Level::Should);
    }
    let mode_slot = g.slot_of(names::OPERATING_MODE);
    let Some(slot) = g.slot(p) else { return };
    if !is_run {
        g.stop_plc(&mut cb);
    }
    if let (Some(m), Some(ms)) = (mode, mode_slot) {
        g.write(&mut cb, Role::Setup, ms, i64::from(m), "Pr31");
    }
    if !readonly {
        // Start from the opposite value so that the change shows.
        g.bit(&mut cb, Role::Setup, r, !value);
    }
    g.bit(&mut cb, Role::Check, r, value);
    let cmp = match g.compare_for(p, mode) {
        Compare::Mask(m) => Compare::Mask(m | bit_in_value(slot, r.at)),
        c => c,
    };
    let ends_by_itself = b
        .rules
        .iter()
        .find(|rule| rule.trigger == names::TRIGGER_TEST_FINISHED);
    match (ends_by_itself, value, p.data_type.bounds()) {
        (Some(rule), true, Some((lo, hi))) => {
            // The drive clears the bit when the test ends, after a time the manual does not
            // give: the bit is read either way and reported.
            let all = match cmp {
                Compare::Mask(m) => m,
                _ => u32::MAX,
            };
            let mask = all & !bit_in_value(slot, r.at);
            let rule_req = rule.requirement.clone();
            g.read_open(&mut cb, slot, (mask, lo, hi), &rule_req, &p.id);
        }
        _ => g.read(&mut cb, Role::Check, slot, cmp, &p.id),
    }
    g.restore(&mut cb, slot, &p.id);
    if let (Some(_), Some(ms)) = (mode, mode_slot) {
        g.restore(&mut cb, ms, "Pr31");
    }
    g.restore_pb99(&mut cb);
    g.push(cb);
}

fn bit_in_value(slot: Slot, at: BitAddr) -> u32 {
    bit_value(slot, at)
}

/// Bit changes with several bits, none, and value bits outside the mask (manual 4.1 CMD 6).
fn bit_extras(g: &mut Gen) {
    let Some(flag) = g.bit_ref(names::USER_FLAG) else {
        return;
    };
    let own = g.addr;
    let slot = flag.slot;
    let cmp = g.compare_for(flag.param, None);
    let par = flag.at.byte;
    let variants: [(&str, &str, u8, u8); 3] = [
        (
            "several",
            "a bit change with three 0s in the mask changes three user flags at once",
            0b1110_0011,
            0b0001_0100,
        ),
        (
            "no-change",
            "a bit change with mask $FF changes nothing and is acknowledged",
            0xFF,
            0xFF,
        ),
        (
            "value-outside-mask",
            "value bits where the mask is 1 are ignored",
            0b1111_1101,
            0b1111_1111,
        ),
    ];
    for (name, text, mask, value) in variants {
        let mut cb = CaseB::new(
            format!("hpd/bit/{}/{name}", flag.param.id),
            text,
            &["HPD-FRAME-017"],
        );
        g.stop_plc(&mut cb);
        let msg = Message::BitChange {
            addr: own,
            par,
            mask,
            value,
        };
        g.msg(
            &mut cb,
            Role::Check,
            msg,
            Compare::Exact,
            format!("bit change at {par:#04x}: mask {mask:08b}, value {value:08b}"),
        );
        g.read(&mut cb, Role::Check, slot, cmp, &flag.param.id);
        g.restore(&mut cb, slot, &flag.param.id);
        g.restore_pb99(&mut cb);
        g.push(cb);
    }
}
