//! `hpd/broadcast`, `hpd/plc`, `hpd/cmd`, `hpd/baud` and `hpd/vector`: broadcasts, PLC
//! upload and read-back, command bits with their preconditions, every Pr26 code with its
//! time-out, and the spec's golden vectors (manual 3.4, 3.8.1, 4, 4.1).

use super::cases::{bit_value, sign_for, BitRef, CaseB, Gen};
use super::names;
use super::step::{Action, Compare, Step};
use crate::case::Role;
use drivespec_hpd::memory::Slot;
use drivespec_hpd::params::Target;
use drivespec_hpd::plc::Operands;
use drivespec_hpd::{parse, Data, Message};
use drivespec_spec::hex::parse_hex;
use drivespec_spec::{Level, Vector, VectorKind, VectorResult};
use std::collections::BTreeMap;

pub(crate) fn generate(g: &mut Gen) {
    broadcast(g);
    plc(g);
    commands(g);
    baud(g);
    vectors(g);
    plc_vectors(g);
    timers(g);
    power_up(g);
    hardware_enable(g);
}

/// Another address than the device's own, picked by the seed.
fn other_address(g: &mut Gen) -> u8 {
    let max = i64::from(g.rules.addr_max);
    let pick = g.rng.range(1, max.max(1));
    let a = (i64::from(g.addr) + pick) % (max + 1);
    u8::try_from(a).unwrap_or(0)
}

fn broadcast(g: &mut Gen) {
    let (Some(scratch), Some(high), Some(ranged), Some(ro)) = (
        g.slot_of(names::SCRATCH),
        g.slot_of(names::SCRATCH_HIGH),
        g.slot_of(names::RANGED),
        g.slot_of(names::READ_ONLY),
    ) else {
        return;
    };
    let bcast = |g: &mut Gen, cb: &mut CaseB, slot: Slot, value: i64, what: &str| {
        if let Some(data) = Data::from_value(value, slot.size) {
            let msg = Message::Broadcast {
                par: slot.addr,
                data,
            };
            g.msg(
                cb,
                Role::Check,
                msg,
                Compare::Exact,
                format!("broadcast {what} = {value}"),
            );
        }
    };
    let value = g.rng.range(-0x4000_0000, 0x3FFF_FFFF);
    let mut cb = CaseB::new(
        "hpd/broadcast/dword",
        "a LUN-4 broadcast writes Pr80:81 as a double word; nobody answers",
        &["HPD-FRAME-019", "HPD-SERIAL-013", "HPD-PAR-006"],
    );
    let d = Slot {
        addr: scratch.addr,
        size: 4,
    };
    bcast(g, &mut cb, d, value, "Pr80:81");
    g.read(&mut cb, Role::Check, d, Compare::Exact, "Pr80:81");
    g.restore(&mut cb, scratch, "Pr80");
    g.restore(&mut cb, high, "Pr81");
    g.push(cb);

    if let Some(p) = g.param(names::RANGED) {
        if let Some(max) = g.range_in(p, None).and_then(|r| r.max()) {
            let mut cb = CaseB::new(
                "hpd/broadcast/out-of-range",
                format!(
                    "a broadcast of Pr33 = {} (above its range) is not taken",
                    max + 1
                ),
                &["HPD-PAR-009", "HPD-SERIAL-013"],
            );
            cb.level(Level::Should);
            bcast(g, &mut cb, ranged, max + 1, "Pr33");
            g.read(
                &mut cb,
                Role::Check,
                ranged,
                Compare::Exact,
                "Pr33 (unchanged)",
            );
            g.restore(&mut cb, ranged, "Pr33");
            g.push(cb);
        }
    }

    let mut cb = CaseB::new(
        "hpd/broadcast/read-only",
        "a broadcast to the read-only Pr25 is not taken",
        &["HPD-PAR-037", "HPD-SERIAL-013"],
    );
    let v = sign_for(ro, g.base(ro) ^ 1, g.family);
    g.save(&mut cb, ro, "Pr25");
    bcast(g, &mut cb, ro, v, "Pr25");
    g.read(
        &mut cb,
        Role::Check,
        ro,
        Compare::Unchanged,
        "Pr25 (unchanged)",
    );
    g.push(cb);

    let other = other_address(g);
    let own = g.addr;
    let value = g.rng.range(1, 0x7000);
    let mut cb = CaseB::new(
        "hpd/broadcast/any-address",
        format!("a drive at address {other} takes a broadcast (ADDR 0) and does not answer it"),
        &["HPD-SERIAL-003", "HPD-SERIAL-013", "HPD-FRAME-019"],
    );
    g.readdress(&mut cb, Role::Setup, own, other);
    bcast(g, &mut cb, scratch, value, "Pr80");
    g.read_at(&mut cb, Role::Check, other, scratch, Compare::Exact, "Pr80");
    g.restore_at(&mut cb, other, scratch, "Pr80");
    g.readdress(&mut cb, Role::Cleanup, other, own);
    restore_line(g, &mut cb);
    g.push(cb);
}

/// Cleanup after a re-addressing or re-initialisation: Pb42 and Pb99 as at the start.
fn restore_line(g: &mut Gen, cb: &mut CaseB) {
    if let Some(pb42) = g.slot_of("Pb42") {
        g.restore(cb, pb42, "Pb42");
    }
    g.restore_pb99(cb);
}

/// Lengths of the instructions in `bytes` (manual 4.1: 2 or 4 bytes; unknown codes: 2).
fn instruction_lengths(g: &Gen, bytes: &[u8]) -> Vec<usize> {
    let mask = g.protocol.plc.encoding.code_mask;
    let mut out = Vec::new();
    let mut at = 0;
    while let Some(b0) = bytes.get(at) {
        let n = g.codec.length(b0 & mask).unwrap_or(2).max(1);
        let n = n.min(bytes.len() - at);
        out.push(n);
        at += n;
    }
    out
}

/// Writes `bytes` to the PLC area from `at`, one whole instruction per message (HPD-FRAME-022).
fn upload(g: &mut Gen, cb: &mut CaseB, role: Role, at: u8, bytes: &[u8]) {
    let own = g.addr;
    upload_to(g, cb, role, own, at, bytes);
}

/// `upload` to the drive at `drive`.
fn upload_to(g: &mut Gen, cb: &mut CaseB, role: Role, drive: u8, at: u8, bytes: &[u8]) {
    let own = drive;
    let mut off = 0usize;
    for n in instruction_lengths(g, bytes) {
        let chunk = bytes.get(off..off + n).unwrap_or(&[]);
        let par = at.wrapping_add(u8::try_from(off).unwrap_or(0));
        off += n;
        let Some(data) = Data::new(chunk) else {
            continue;
        };
        let msg = Message::WritePlc {
            addr: own,
            par,
            data,
        };
        g.msg(
            cb,
            role,
            msg,
            Compare::Exact,
            format!("write {n} PLC byte(s) at {par:#04x}"),
        );
    }
}

/// Reads `len` PLC bytes from `at` in chunks of 4.
fn read_plc(g: &mut Gen, cb: &mut CaseB, at: u8, len: usize) {
    let own = g.addr;
    let mut off = 0usize;
    while off < len {
        let n = (len - off).min(4);
        let par = at.wrapping_add(u8::try_from(off).unwrap_or(0));
        let msg = Message::ReadPlc {
            addr: own,
            lun: u8::try_from(n).unwrap_or(4),
            par,
        };
        g.msg(
            cb,
            Role::Check,
            msg,
            Compare::Exact,
            format!("read {n} PLC byte(s) at {par:#04x}"),
        );
        off += n;
    }
}

/// The start bytes of the PLC area from `at`, at least `len` and up to a whole instruction.
fn plc_base(g: &Gen, at: usize, len: usize) -> Vec<u8> {
    let area: Vec<u8> = g.baseline.plc_area().iter().skip(at).copied().collect();
    let mut n = 0;
    for l in instruction_lengths(g, &area) {
        if n >= len {
            break;
        }
        n += l;
    }
    area.into_iter().take(n.max(len)).collect()
}

/// A listing assembled to bytes.
fn assemble(g: &Gen, lines: &[&str]) -> Option<Vec<u8>> {
    let text = lines.join("\n");
    let program = g.codec.parse_listing(&text).ok()?;
    g.codec.encode_program(&program).ok()
}

/// The second byte given to END by `hpd/plc/end-second-byte`: any non-zero value, all bits
/// set so that no bit of it may count (manual 4.1: "the second byte of END is not used").
const END_SECOND_BYTE: u8 = 0xFF;

/// A listing assembled to bytes, its first END carrying `second` in the byte 4.1 leaves
/// unused.
fn assemble_with_end_byte(g: &Gen, lines: &[&str], second: u8) -> Option<Vec<u8>> {
    let text = lines.join("\n");
    let mut program = g.codec.parse_listing(&text).ok()?;
    let end = program
        .instrs
        .iter_mut()
        .map(|(_, i)| i)
        .find(|i| g.codec.is_end(i))?;
    if let Operands::None { spare1, .. } = &mut end.operands {
        *spare1 = second;
    }
    g.codec.encode_program(&program).ok()
}

/// Steps of a case that uploads `program` with the PLC stopped and `flag` cleared, starts
/// the PLC and reads `flag` after three scans (set by the program), then restores the PLC
/// area, the flag and Pb99; the read checks `requirement` first, when given.
fn run_program(
    g: &mut Gen,
    cb: &mut CaseB,
    program: &[u8],
    flag: &BitRef,
    requirement: Option<&str>,
) {
    let first = g.protocol.plc.first_address;
    let original = plc_base(g, usize::from(first), program.len());
    let scan = u64::from(g.protocol.plc.scan_us);
    g.stop_plc(cb);
    g.bit(cb, Role::Setup, flag, false);
    upload(g, cb, Role::Setup, first, program);
    let run = g.run;
    let start = g.base(run.0);
    g.write(
        cb,
        Role::Setup,
        run.0,
        i64::from(start),
        "Pb99 (PLC running)",
    );
    cb.action(
        Role::Check,
        Action::Listen { us: 3 * scan },
        "listen for three PLC scans",
        &["HPD-PLC-004"],
    );
    let cmp = match g.compare_for(flag.param, None) {
        Compare::Mask(m) => Compare::Mask(m | bit_value(flag.slot, flag.at)),
        c => c,
    };
    g.read(cb, Role::Check, flag.slot, cmp, "Pb90");
    if let (Some(r), Some(step)) = (requirement, cb.steps.last_mut()) {
        step.requirements.insert(0, r.to_owned());
    }
    g.stop_plc(cb);
    if let Some(s) = cb.steps.last_mut() {
        s.role = Role::Cleanup;
    }
    upload(g, cb, Role::Cleanup, first, &original);
    g.restore(cb, flag.slot, "Pb90");
    g.restore_pb99(cb);
}

fn plc(g: &mut Gen) {
    let own = g.addr;
    let area = usize::from(g.protocol.plc.area_bytes);
    let first = g.protocol.plc.first_address;
    let last = g.protocol.plc.last_address;

    let mut cb = CaseB::new(
        "hpd/plc/read-area",
        format!("read the whole PLC area {first:#04x}-{last:#04x} in LUN-4 pieces"),
        &["HPD-PLC-038", "HPD-FRAME-022", "HPD-FRAME-012"],
    );
    read_plc(g, &mut cb, first, area);
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/plc/read-past-end",
        "PLC reads reaching past the area (2 bytes at the last address, 1 byte after it) get no answer",
        &["HPD-FRAME-022", "HPD-PLC-038", "HPD-SERIAL-012"],
    );
    for (lun, par) in [(2u8, last), (1, last.wrapping_add(1))] {
        let msg = Message::ReadPlc {
            addr: own,
            lun,
            par,
        };
        let b = g.bytes(&msg);
        g.raw(
            &mut cb,
            Role::Check,
            b,
            format!("read {lun} PLC byte(s) at {par:#04x}"),
            &["HPD-FRAME-022"],
        );
    }
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/plc/write-past-end",
        "a PLC write reaching past the area gets no answer and changes nothing",
        &["HPD-FRAME-022", "HPD-PLC-038", "HPD-SERIAL-012"],
    );
    g.stop_plc(&mut cb);
    if let Some(data) = Data::new(&[0x0F, 0x00]) {
        let msg = Message::WritePlc {
            addr: own,
            par: last,
            data,
        };
        let b = g.bytes(&msg);
        g.raw(
            &mut cb,
            Role::Check,
            b,
            format!("write 2 PLC bytes at {last:#04x}"),
            &["HPD-FRAME-022"],
        );
    }
    read_plc(g, &mut cb, last, 1);
    g.restore_pb99(&mut cb);
    g.push(cb);

    // Upload a program, read it back, run it.
    let flag = names::USER_FLAG;
    let Some(flag_ref) = g.bit_ref(flag) else {
        return;
    };
    let run_bit = g.protocol.plc.run_bit.trim_start_matches('b').to_owned();
    let flag_num = flag.trim_start_matches('b').to_owned();
    let lines = [
        format!("LD {run_bit}"),
        format!("OUT {flag_num}"),
        "END".to_owned(),
    ];
    let line_refs: Vec<&str> = lines.iter().map(String::as_str).collect();
    let Some(program) = assemble(g, &line_refs) else {
        g.errors
            .push("hpd/plc: the test program does not assemble".to_owned());
        return;
    };
    let original = plc_base(g, usize::from(first), program.len());

    let mut cb = CaseB::new(
        "hpd/plc/upload",
        format!(
            "upload `{}` with the PLC stopped and read it back",
            lines.join("; ")
        ),
        &[
            "HPD-FRAME-013",
            "HPD-BIT-99-13",
            "HPD-PLC-045",
            "HPD-PLC-047",
            "HPD-PLC-039",
            "HPD-PLC-041",
        ],
    );
    g.stop_plc(&mut cb);
    upload(g, &mut cb, Role::Check, first, &program);
    read_plc(g, &mut cb, first, program.len());
    upload(g, &mut cb, Role::Cleanup, first, &original);
    g.restore_pb99(&mut cb);
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/plc/upload-while-running",
        "PLC instructions written while the PLC runs (b99.13 = 1) are not taken",
        &["HPD-BIT-99-13"],
    );
    upload(g, &mut cb, Role::Check, first, &program);
    read_plc(g, &mut cb, first, program.len());
    g.stop_plc(&mut cb);
    if let Some(s) = cb.steps.last_mut() {
        s.role = Role::Cleanup;
    }
    upload(g, &mut cb, Role::Cleanup, first, &original);
    g.restore_pb99(&mut cb);
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/plc/run",
        format!(
            "the uploaded program `{}` runs once b99.13 = 1 and sets {flag} within a few scans",
            lines.join("; ")
        ),
        &["HPD-BIT-99-13", "HPD-PLC-004", "HPD-PLC-009", "HPD-PLC-011"],
    );
    run_program(g, &mut cb, &program, &flag_ref, None);
    g.push(cb);

    // HPD-PLC-043: END with a non-zero second byte still ends the program; the
    // instructions behind it would clear the flag again.
    let mut lines = lines.to_vec();
    lines.extend([
        format!("LD {run_bit}"),
        format!("OUTN {flag_num}"),
        "END".to_owned(),
    ]);
    let line_refs: Vec<&str> = lines.iter().map(String::as_str).collect();
    let Some(program) = assemble_with_end_byte(g, &line_refs, END_SECOND_BYTE) else {
        g.errors
            .push("hpd/plc: the END test program does not assemble".to_owned());
        return;
    };
    let mut cb = CaseB::new(
        "hpd/plc/end-second-byte",
        format!(
            "`{}` with {END_SECOND_BYTE:#04x} in the second byte of the first END: the \
             program ends there and {flag} stays set",
            lines.join("; ")
        ),
        &["HPD-PLC-043"],
    );
    run_program(g, &mut cb, &program, &flag_ref, Some("HPD-PLC-043"));
    g.push(cb);
}

/// Command bits: (bit name, mode it is a command in).
fn command_bits(g: &Gen) -> Vec<(String, Option<u32>)> {
    let mut out = Vec::new();
    for bf in &g.family.bitfields {
        let Some(p) = g.param(&bf.param) else {
            continue;
        };
        for b in &bf.bits {
            if b.rules.iter().any(|r| r.trigger == names::TRIGGER_COMMAND) {
                let name = format!("b{}.{}", p.number, b.bit);
                match bf.modes.first() {
                    Some(m) => out.push((name, Some(*m))),
                    None => out.push((name, None)),
                }
            }
        }
    }
    out
}

fn commands(g: &mut Gen) {
    let own = g.addr;
    let defaults_bit = g.protocol.plc.default_bit.clone();
    let reinit_bit = g.protocol.serial_setup.reinit_bit.clone();
    let mode_slot = g.slot_of(names::OPERATING_MODE);
    let ext = g.bit_ref(names::EXTENDED_MENU);
    let (pb99, run) = g.run;

    // Every command bit clears itself once taken (HPD-CMD-SELF-CLEAR).
    for (name, mode) in command_bits(g) {
        if name == defaults_bit {
            continue;
        }
        let Some(r) = g.bit_ref(&name) else { continue };
        let needs_ext = name == reinit_bit || r.param.id == "Pb94";
        let id = match mode {
            Some(m) => format!("hpd/cmd/{name}/mode-{m}/self-clear"),
            None => format!("hpd/cmd/{name}/self-clear"),
        };
        let mut cb = CaseB::new(
            id,
            format!("command bit {name} reads 0 again once the drive has taken it"),
            &["HPD-CMD-SELF-CLEAR"],
        );
        let rule_reqs: Vec<String> = g
            .family
            .bitfields_of(&r.param.id)
            .flat_map(|bf| bf.bits.iter())
            .filter(|b| b.bit == r.bit)
            .flat_map(|b| b.rules.iter().map(|x| x.requirement.clone()))
            .collect();
        cb.reqs(rule_reqs);
        let mut v99 = g.base(pb99) & !bit_value(pb99, run);
        if needs_ext {
            if let Some(e) = ext {
                v99 |= bit_value(pb99, e.at);
                cb.reqs(["HPD-CMD-002".to_owned()]);
            }
        }
        g.write(
            &mut cb,
            Role::Setup,
            pb99,
            i64::from(v99),
            "Pb99 (PLC stopped)",
        );
        if let (Some(m), Some(ms)) = (mode, mode_slot) {
            g.write(&mut cb, Role::Setup, ms, i64::from(m), "Pr31");
        }
        g.bit(&mut cb, Role::Check, &r, true);
        let cmp = match g.compare_for(r.param, mode) {
            Compare::Mask(m) => Compare::Mask(m | bit_value(r.slot, r.at)),
            c => c,
        };
        g.read(&mut cb, Role::Check, r.slot, cmp, &r.param.id);
        g.restore(&mut cb, r.slot, &r.param.id);
        if let (Some(_), Some(ms)) = (mode, mode_slot) {
            g.restore(&mut cb, ms, "Pr31");
        }
        g.restore_pb99(&mut cb);
        g.push(cb);
    }

    let (Some(scratch), Some(with_default), Some(defaults)) = (
        g.slot_of(names::SCRATCH),
        g.slot_of(names::WITH_DEFAULT),
        g.bit_ref(&defaults_bit),
    ) else {
        return;
    };
    let value = g.rng.range(1, 0x7000);
    // A value of Pr2 inside its range, other than its start value.
    let base2 = sign_for(with_default, g.base(with_default), g.family);
    let (lo2, hi2) = g
        .param(names::WITH_DEFAULT)
        .and_then(|p| g.range_in(p, None))
        .and_then(|r| Some((r.min()?, r.max()?)))
        .unwrap_or((0, 100));
    let mut v2 = g.rng.range(lo2, hi2);
    if v2 == base2 {
        v2 = if v2 > lo2 { v2 - 1 } else { v2 + 1 };
    }

    // b99.12 is refused while the PLC runs (HPD-CMD-009).
    let mut cb = CaseB::new(
        format!("hpd/cmd/{defaults_bit}/refused-plc-running"),
        format!("the default-values command {defaults_bit} is refused while the PLC runs: Pr2 keeps {v2}"),
        &["HPD-CMD-009"],
    );
    g.write(&mut cb, Role::Setup, with_default, v2, "Pr2");
    g.bit(&mut cb, Role::Check, &defaults, true);
    g.read(&mut cb, Role::Check, with_default, Compare::Exact, "Pr2");
    g.restore(&mut cb, with_default, "Pr2");
    g.restore_pb99(&mut cb);
    g.push(cb);

    // b99.12 with the PLC stopped: defaults, b40.14 = 0 silences the line (power cycle).
    let mut cb = CaseB::new(
        format!("hpd/cmd/{defaults_bit}/defaults"),
        format!("{defaults_bit} with the PLC stopped restores the defaults, b40.14 = 0 included: the line falls silent until power-up"),
        &["HPD-CMD-008", "HPD-CMD-009", "HPD-BIT-40-14-DEFAULT", "HPD-PAR-018"],
    );
    g.stop_plc(&mut cb);
    g.write(&mut cb, Role::Setup, with_default, v2, "Pr2");
    g.bit(&mut cb, Role::Check, &defaults, true);
    g.raw_read(
        &mut cb,
        own,
        with_default,
        "read Pr2: no answer, the line is disabled",
        &["HPD-BIT-40-14-DEFAULT", "HPD-BIT-40-14"],
    );
    cb.power_cycle();
    g.read(
        &mut cb,
        Role::Check,
        with_default,
        Compare::Exact,
        "Pr2 (the saved value)",
    );
    g.restore_pb99(&mut cb);
    g.push(cb);

    // b40.14 = 0 disables the line until power-up.
    if let Some(enable) = g.bit_ref(&g.protocol.serial_setup.enable_bit.clone()) {
        let name = g.protocol.serial_setup.enable_bit.clone();
        let mut cb = CaseB::new(
            format!("hpd/cmd/{name}/clear"),
            format!("clearing {name} disables the serial line (the bit change itself is acknowledged); power-up enables it again"),
            &["HPD-BIT-40-14"],
        );
        g.bit(&mut cb, Role::Check, &enable, false);
        g.raw_read(
            &mut cb,
            own,
            scratch,
            "read Pr80: no answer",
            &["HPD-BIT-40-14"],
        );
        cb.power_cycle();
        g.read(&mut cb, Role::Check, scratch, Compare::Exact, "Pr80");
        g.push(cb);
    }

    // Saving parameters and the PLC program (HPD-PAR-018, HPD-CMD-011, HPD-CMD-012).
    let save = g.protocol.serial_setup.save_bit.clone();
    if let Some(save_ref) = g.bit_ref(&save) {
        let later = value ^ 0x55;
        let mut cb = CaseB::new(
            format!("hpd/cmd/{save}/save"),
            format!("{save} stores Pr80 = {value}; after power-up Pr80 is {value} again although it was changed"),
            &["HPD-CMD-012", "HPD-PAR-018"],
        );
        g.write(&mut cb, Role::Setup, scratch, value, "Pr80");
        g.bit(&mut cb, Role::Check, &save_ref, true);
        g.write(
            &mut cb,
            Role::Check,
            scratch,
            later,
            "Pr80 (working value only)",
        );
        cb.power_cycle();
        g.read(&mut cb, Role::Check, scratch, Compare::Exact, "Pr80");
        g.restore(&mut cb, scratch, "Pr80");
        g.bit(&mut cb, Role::Cleanup, &save_ref, true);
        g.push(cb);

        let mut cb = CaseB::new(
            format!("hpd/cmd/{save}/not-saved"),
            "a written value not stored with b99.15 is lost at power-up",
            &["HPD-PAR-018"],
        );
        g.write(
            &mut cb,
            Role::Check,
            scratch,
            value,
            "Pr80 (working value only)",
        );
        cb.power_cycle();
        g.read(
            &mut cb,
            Role::Check,
            scratch,
            Compare::Exact,
            "Pr80 (the saved value)",
        );
        g.restore(&mut cb, scratch, "Pr80");
        g.push(cb);
    }
    let save_plc = g.protocol.plc.save_bit.clone();
    let first = g.protocol.plc.first_address;
    let other = assemble(g, &["LDN 90.9", "END"]);
    if let (Some(save_ref), Some(program)) = (g.bit_ref(&save_plc), other) {
        let original = plc_base(g, usize::from(first), program.len());
        let mut cb = CaseB::new(
            format!("hpd/cmd/{save_plc}/save"),
            format!("{save_plc} stores the PLC program: it is still there after power-up"),
            &["HPD-CMD-011", "HPD-PAR-018"],
        );
        g.stop_plc(&mut cb);
        upload(g, &mut cb, Role::Setup, first, &program);
        g.bit(&mut cb, Role::Check, &save_ref, true);
        cb.power_cycle();
        read_plc(g, &mut cb, first, program.len());
        g.stop_plc(&mut cb);
        if let Some(s) = cb.steps.last_mut() {
            s.role = Role::Cleanup;
        }
        upload(g, &mut cb, Role::Cleanup, first, &original);
        g.bit(&mut cb, Role::Cleanup, &save_ref, true);
        g.restore_pb99(&mut cb);
        g.push(cb);

        let mut cb = CaseB::new(
            format!("hpd/cmd/{save_plc}/not-saved"),
            "PLC instructions not stored with b99.14 are lost at power-up",
            &["HPD-PAR-018"],
        );
        g.stop_plc(&mut cb);
        upload(g, &mut cb, Role::Check, first, &program);
        cb.power_cycle();
        read_plc(g, &mut cb, first, program.len());
        g.push(cb);
    }

    mode_defaults(g);

    // b99.10 clears Pr23 and Pr24 (HPD-CMD-005).
    if let Some(reset) = g.bit_ref(names::ALARM_RESET) {
        let mut cb = CaseB::new(
            format!("hpd/cmd/{}/alarm-reset", names::ALARM_RESET),
            "the alarm reset b99.10 leaves Pr23 and Pr24 at 0",
            &["HPD-CMD-005", "HPD-ALARM-001", "HPD-ALARM-003"],
        );
        g.bit(&mut cb, Role::Check, &reset, true);
        for id in names::ALARMS {
            if let Some(s) = g.slot_of(id) {
                g.read(&mut cb, Role::Check, s, Compare::Exact, id);
            }
        }
        g.restore_pb99(&mut cb);
        g.push(cb);
    }

    // Security b99.7 (HPD-BIT-99-7, HPD-BIT-99-7-SELF).
    if let Some(sec) = g.bit_ref(names::SECURITY) {
        let mut cb = CaseB::new(
            format!("hpd/cmd/{}/blocks-writes", names::SECURITY),
            "with security b99.7 = 1 a write of Pr80 is not taken; b99.7 itself can be cleared, then the write is taken",
            &["HPD-BIT-99-7", "HPD-BIT-99-7-SELF", "HPD-CMD-001"],
        );
        g.bit(&mut cb, Role::Check, &sec, true);
        g.write(&mut cb, Role::Check, scratch, value, "Pr80");
        g.read(
            &mut cb,
            Role::Check,
            scratch,
            Compare::Exact,
            "Pr80 (unchanged)",
        );
        g.bit(&mut cb, Role::Check, &sec, false);
        g.write(&mut cb, Role::Check, scratch, value, "Pr80");
        g.read(&mut cb, Role::Check, scratch, Compare::Exact, "Pr80");
        g.restore_pb99(&mut cb);
        g.restore_pb99(&mut cb);
        g.restore(&mut cb, scratch, "Pr80");
        g.push(cb);
    }

    // b42.3 needs b99.6 (HPD-CMD-002); with it the new address takes effect (HPD-BIT-42-3).
    let (Some(pr27), Some(reinit), Some(ranged)) = (
        g.slot_of(&g.protocol.serial_setup.address_param.clone()),
        g.bit_ref(&reinit_bit),
        g.slot_of(names::RANGED),
    ) else {
        return;
    };
    let other = other_address(g);
    let mut cb = CaseB::new(
        format!("hpd/cmd/{reinit_bit}/needs-extended-menu"),
        format!("{reinit_bit} with b99.6 = 0 is refused: after Pr27 = {other} the drive still answers at {own}"),
        &["HPD-CMD-002", "HPD-BIT-42-3"],
    );
    g.stop_plc(&mut cb);
    g.write(&mut cb, Role::Setup, pr27, i64::from(other), "Pr27");
    g.bit(&mut cb, Role::Check, &reinit, true);
    g.read(&mut cb, Role::Check, ranged, Compare::Exact, "Pr33");
    g.raw_read(
        &mut cb,
        other,
        ranged,
        format!("read Pr33 from drive {other}: no answer"),
        &["HPD-SERIAL-003"],
    );
    g.restore(&mut cb, pr27, "Pr27");
    restore_line(g, &mut cb);
    g.push(cb);

    let mut cb = CaseB::new(
        format!("hpd/cmd/{reinit_bit}/readdress"),
        format!("Pr27 = {other}, b99.6 = 1 and {reinit_bit}: the drive answers at {other} and no longer at {own}"),
        &["HPD-BIT-42-3", "HPD-PAR-038", "HPD-SERIAL-003", "HPD-SERIAL-009", "HPD-SERIAL-002"],
    );
    g.readdress(&mut cb, Role::Setup, own, other);
    g.raw_read(
        &mut cb,
        own,
        ranged,
        format!("read Pr33 from drive {own}: no answer"),
        &["HPD-SERIAL-003"],
    );
    g.read_at(&mut cb, Role::Check, other, ranged, Compare::Exact, "Pr33");
    g.readdress(&mut cb, Role::Cleanup, other, own);
    restore_line(g, &mut cb);
    g.push(cb);
}

/// b99.11 loads the defaults of the operating mode, only with b40.2 = 0 (HPD-CMD-007).
fn mode_defaults(g: &mut Gen) {
    let (Some(mode_slot), Some(cmd), Some(reserved)) = (
        g.slot_of(names::OPERATING_MODE),
        g.bit_ref(names::MODE_DEFAULTS),
        g.bit_ref(names::RESERVED_REFERENCE),
    ) else {
        return;
    };
    // The first writable parameter with a default in some operating mode.
    let pick = g.family.parameters.iter().find_map(|p| {
        if !p.access.writable() || p.live {
            return None;
        }
        p.modes.iter().find_map(|m| {
            let d = m.default?;
            let mode = *m.modes.first()?;
            Some((p, mode, d))
        })
    });
    let Some((p, mode, default)) = pick else {
        return;
    };
    let Some(slot) = g.slot(p) else { return };
    let range = g.range_in(p, Some(mode));
    let value = if range.as_ref().is_none_or(|r| r.contains(default + 1)) {
        default + 1
    } else {
        default - 1
    };
    for refused in [false, true] {
        let id = if refused {
            format!(
                "hpd/cmd/{}/refused-{}",
                names::MODE_DEFAULTS,
                names::RESERVED_REFERENCE
            )
        } else {
            format!("hpd/cmd/{}/mode-defaults", names::MODE_DEFAULTS)
        };
        let text = if refused {
            format!(
                "with {} = 1 the mode-defaults command is refused: {} keeps {value}",
                names::RESERVED_REFERENCE,
                p.id
            )
        } else {
            format!(
                "in mode {mode} the mode-defaults command sets {} back to {default}",
                p.id
            )
        };
        let mut cb = CaseB::new(id, text, &["HPD-CMD-007", "HPD-MODE-005"]);
        g.stop_plc(&mut cb);
        g.write(&mut cb, Role::Setup, mode_slot, i64::from(mode), "Pr31");
        g.write(&mut cb, Role::Setup, slot, value, &p.id);
        if refused {
            g.bit(&mut cb, Role::Setup, &reserved, true);
        }
        g.bit(&mut cb, Role::Check, &cmd, true);
        g.read(&mut cb, Role::Check, slot, Compare::Exact, &p.id);
        if refused {
            g.restore(&mut cb, reserved.slot, "Pb40");
        }
        g.restore(&mut cb, slot, &p.id);
        g.restore(&mut cb, mode_slot, "Pr31");
        g.restore_pb99(&mut cb);
        g.push(cb);
    }
}

fn baud(g: &mut Gen) {
    let (Some(pr26), Some(pb42), Some(reinit), Some(ext), Some(ranged)) = (
        g.slot_of(&g.protocol.serial_setup.baud_param.clone()),
        g.slot_of("Pb42"),
        g.bit_ref(&g.protocol.serial_setup.reinit_bit.clone()),
        g.bit_ref(names::EXTENDED_MENU),
        g.slot_of(names::RANGED),
    ) else {
        return;
    };
    let (pb99, run) = g.run;
    let read = Message::ReadParam {
        addr: g.addr,
        lun: ranged.size,
        par: ranged.addr,
    };
    let read_bytes = g.bytes(&read);
    let head: Vec<u8> = read_bytes.iter().take(3).copied().collect();
    let tail: Vec<u8> = read_bytes.iter().skip(3).copied().collect();
    let rates = g.protocol.baud_rates.clone();
    for rate in rates {
        let code = rate.code;
        let mut cb = CaseB::new(
            format!("hpd/baud/code-{code}"),
            format!(
                "Pr26 = {code} ({} b/s{}): after b42.3 the drive answers at the new rate and drops a message not complete within {} ms",
                rate.bps,
                match rate.answer_delay_ms {
                    Some(d) => format!(", answers delayed {d} ms"),
                    None => String::new(),
                },
                rate.timeout_ms
            ),
            &["HPD-BAUD-001", "HPD-BAUD-002", "HPD-BAUD-003", "HPD-BIT-42-3", "HPD-PAR-038"],
        );
        if rate.answer_delay_ms.is_some() {
            cb.reqs(["HPD-BAUD-004".to_owned()]);
        }
        if rate.mode == drivespec_spec::hpd::BaudMode::Idc {
            cb.reqs(["HPD-BAUD-005".to_owned()]);
        }
        let v99 = (g.base(pb99) & !bit_value(pb99, run)) | bit_value(pb99, ext.at);
        let v42 = g.base(pb42) | bit_value(pb42, reinit.at);
        g.write(
            &mut cb,
            Role::Setup,
            pb99,
            i64::from(v99),
            "Pb99 (b99.6 = 1, PLC stopped)",
        );
        g.write(&mut cb, Role::Setup, pr26, i64::from(code), "Pr26");
        g.write(
            &mut cb,
            Role::Setup,
            pb42,
            i64::from(v42),
            "Pb42 (b42.3 = 1)",
        );
        cb.action(
            Role::Setup,
            Action::BitRate {},
            format!("switch the line to {} b/s", rate.bps),
            &[],
        );
        g.read(&mut cb, Role::Check, pr26, Compare::Exact, "Pr26");
        cb.split_read(
            &head,
            Action::ListenTimeout {},
            format!("wait past the {} ms time-out", rate.timeout_ms),
            &["HPD-BAUD-002"],
        );
        g.raw(
            &mut cb,
            Role::Check,
            tail.clone(),
            "send the rest: no answer",
            &["HPD-BAUD-003", "HPD-FRAME-020"],
        );
        g.read(&mut cb, Role::Check, ranged, Compare::Exact, "Pr33");
        cb.split_read(
            &head,
            Action::ListenHalfTimeout {},
            format!("wait {} ms, half the time-out", rate.timeout_ms / 2),
            &["HPD-BAUD-002"],
        );
        g.raw(
            &mut cb,
            Role::Check,
            tail.clone(),
            "send the rest: the drive answers",
            &[
                "HPD-BAUD-002",
                "HPD-FRAME-010",
                "HPD-FRAME-009",
                "HPD-FRAME-014",
                "HPD-SERIAL-017",
                "HPD-SERIAL-016",
            ],
        );
        g.restore(&mut cb, pr26, "Pr26");
        g.write(
            &mut cb,
            Role::Cleanup,
            pb42,
            i64::from(v42),
            "Pb42 (b42.3 = 1)",
        );
        cb.action(
            Role::Cleanup,
            Action::BitRate {},
            "switch the line back",
            &[],
        );
        g.restore(&mut cb, pb42, "Pb42");
        g.restore_pb99(&mut cb);
        g.push(cb);
    }
}

/// The spec's `hpd-frame` vectors, run against the device at the vector's address.
fn vectors(g: &mut Gen) {
    let own = g.addr;
    let vectors: Vec<&Vector> = g
        .family
        .vectors
        .iter()
        .filter(|v| v.kind == VectorKind::HpdFrame)
        .collect();
    for v in vectors {
        let Some(body) = v.hpd_frame() else {
            continue;
        };
        let Ok(request) = parse_hex(&body.input.request) else {
            g.errors
                .push(format!("vector {}: request is not hex", v.id));
            continue;
        };
        let golden = match &body.expect.response {
            Some(h) => match parse_hex(h) {
                Ok(b) => b,
                Err(_) => {
                    g.errors
                        .push(format!("vector {}: response is not hex", v.id));
                    continue;
                }
            },
            None => Vec::new(),
        };
        let msg = parse(&g.rules, &request).ok();
        let at = body
            .input
            .drive_addr
            .or(body.input.addr)
            .and_then(|a| u8::try_from(a).ok())
            .filter(|a| *a <= g.rules.addr_max)
            .unwrap_or(own);
        let mut cb = CaseB::new(
            format!("hpd/vector/{}", v.id),
            format!(
                "{} ({}): {}",
                v.description,
                v.source,
                result_text(v.result)
            ),
            &[],
        );
        cb.reqs(v.requirements.iter().cloned());
        if v.result == VectorResult::Acceptable {
            cb.level(Level::Should);
        }
        if at != own {
            g.readdress(&mut cb, Role::Setup, own, at);
        }
        let name = body.input.param.as_deref().or(body.input.target.as_deref());
        let target = name.and_then(|n| Target::parse(g.family, n).ok());
        let want = body.expect.value.or(body.input.value);
        let mut compare = Compare::Exact;
        let mut touched: Vec<Slot> = Vec::new();
        let stop = matches!(msg, Some(Message::WritePlc { .. })) && at == own;
        if stop {
            g.stop_plc(&mut cb);
        }
        if let (Some(Message::ReadParam { .. }), Some(t), Some(w)) = (msg, target, want) {
            match (t.param().access.writable(), g.slot(t.param())) {
                (true, Some(slot)) => {
                    g.write_at(&mut cb, Role::Setup, at, slot, w, &t.param().id);
                    touched.push(slot);
                }
                _ => compare = g.compare_for(t.param(), None),
            }
        }
        let golden = (compare == Compare::Exact).then_some(golden);
        let reqs: Vec<String> = v.requirements.clone();
        cb.steps.push(Step {
            role: Role::Check,
            action: Action::Exchange {
                bytes: request.clone(),
                compare,
                silence_ok: v.result == VectorResult::Acceptable,
            },
            golden,
            text: format!("send {}", drivespec_spec::hex::to_hex(&request)),
            requirements: reqs,
        });
        // What the request may have changed goes back.
        match msg {
            Some(Message::WriteParam { par, data, .. } | Message::Broadcast { par, data }) => {
                for i in 0..data.len() {
                    if let Some(p) = g.family.parameter_at_address(u32::from(par) + u32::from(i)) {
                        if let Some(s) = g.slot(p) {
                            if !touched.contains(&s) {
                                touched.push(s);
                            }
                        }
                    }
                }
            }
            Some(Message::BitChange { par, .. }) => {
                if let Some(s) = g
                    .family
                    .parameter_at_address(u32::from(par))
                    .and_then(|p| g.slot(p))
                {
                    touched.push(s);
                }
            }
            Some(Message::WritePlc { par, data, .. }) => {
                let original = plc_base(g, usize::from(par), usize::from(data.len()));
                upload_to(g, &mut cb, Role::Cleanup, at, par, &original);
            }
            _ => {}
        }
        for s in &touched {
            g.restore_at(&mut cb, at, *s, "what the vector changed");
            cb.touched.push(*s);
        }
        if at != own {
            g.readdress(&mut cb, Role::Cleanup, at, own);
            restore_line(g, &mut cb);
        } else if stop || touched.iter().any(|s| s.addr == g.run.0.addr) {
            g.restore_pb99(&mut cb);
        }
        g.push(cb);
    }
}

fn result_text(r: VectorResult) -> &'static str {
    match r {
        VectorResult::Valid => "valid",
        VectorResult::Invalid => "invalid, no answer",
        VectorResult::Acceptable => "acceptable either way",
    }
}

/// The spec's `hpd-plc` vectors whose inputs the serial line can set: upload, set, run one
/// scan, read the results.
fn plc_vectors(g: &mut Gen) {
    let vectors: Vec<&Vector> = g
        .family
        .vectors
        .iter()
        .filter(|v| v.kind == VectorKind::HpdPlc)
        .collect();
    let first = g.protocol.plc.first_address;
    let scan = u64::from(g.protocol.plc.scan_us);
    let run_name = g.protocol.plc.run_bit.clone();
    for v in vectors {
        let Some(body) = v.hpd_plc() else {
            continue;
        };
        let lines: Vec<&str> = body.input.program.iter().map(String::as_str).collect();
        let Some(program) = assemble(g, &lines) else {
            continue;
        };
        let scans = body.input.scans.unwrap_or(1);
        if !(1..=4).contains(&scans) {
            continue;
        }
        let table = |t: &Option<BTreeMap<String, i64>>| -> Vec<(String, i64)> {
            t.iter()
                .flat_map(|t| t.iter().map(|(k, x)| (k.clone(), *x)))
                .collect()
        };
        let expect = |t: &Option<BTreeMap<String, i64>>| -> Vec<String> {
            t.iter().flat_map(|t| t.keys().cloned()).collect()
        };
        let params = table(&body.input.params);
        // The physical inputs (b90.0..b90.7, manual 3.8.1) are applied as inputs; the
        // transport must be able to drive them.
        let (inputs, bits): (Vec<_>, Vec<_>) = table(&body.input.bits)
            .into_iter()
            .partition(|(k, _)| physical_input(g, k).is_some());
        // Everything else set must be writable over the line.
        let settable = params.iter().all(|(k, _)| {
            g.param(k)
                .is_some_and(|p| p.access.writable() && p.address.is_some())
        }) && bits.iter().all(|(k, _)| {
            g.family
                .bitfields
                .iter()
                .filter(|bf| g.bit_ref(k).is_some_and(|r| r.param.id == bf.param))
                .flat_map(|bf| bf.bits.iter())
                .filter(|b| g.bit_ref(k).is_some_and(|r| r.bit == b.bit))
                .all(|b| b.access != Some(drivespec_spec::Access::R))
                && g.bit_ref(k).is_some_and(|r| r.param.access.writable())
        });
        if !settable || bits.iter().any(|(k, _)| *k == run_name) {
            continue;
        }
        let mut cb = CaseB::new(
            format!("hpd/plc/vector/{}", v.id),
            format!(
                "{} ({}): upload, set the inputs over the line, run {scans} scan(s), read back",
                v.description, v.source
            ),
            &[],
        );
        // The vector's own requirements first: a result that differs breaks them.
        cb.reqs(v.requirements.iter().cloned());
        cb.reqs(["HPD-BIT-99-13".to_owned()]);
        let original = plc_base(g, usize::from(first), program.len());
        g.stop_plc(&mut cb);
        upload(g, &mut cb, Role::Setup, first, &program);
        let mut restore: Vec<Slot> = Vec::new();
        for (k, val) in &params {
            if let Some(s) = g.slot_of(k) {
                g.write(&mut cb, Role::Setup, s, *val, k);
                restore.push(s);
            }
        }
        for (k, val) in &bits {
            if let Some(r) = g.bit_ref(k) {
                g.bit(&mut cb, Role::Setup, &r, *val != 0);
                if !restore.contains(&r.slot) {
                    restore.push(r.slot);
                }
            }
        }
        let start_inputs = g.baseline.digital_inputs();
        if !inputs.is_empty() {
            // The results depend on the drive reading its inputs into b90.0..b90.7.
            cb.reqs(["HPD-BIT-90-INPUTS".to_owned()]);
            let mut value = start_inputs;
            for (k, val) in &inputs {
                if let Some(i) = physical_input(g, k) {
                    let b = 1u16.checked_shl(u32::from(i)).unwrap_or(0);
                    value = if *val != 0 { value | b } else { value & !b };
                }
            }
            cb.action(
                Role::Setup,
                Action::Inputs { value },
                format!("apply the digital inputs {value:#06x}"),
                &["HPD-BIT-90-INPUTS"],
            );
        }
        let Some(run) = g.bit_ref(&run_name) else {
            continue;
        };
        g.bit(&mut cb, Role::Setup, &run, true);
        cb.action(
            Role::Check,
            Action::Listen {
                us: scans.unsigned_abs() * scan,
            },
            format!("let {scans} PLC scan(s) run"),
            &["HPD-PLC-004"],
        );
        g.bit(&mut cb, Role::Check, &run, false);
        let mut reads: Vec<String> = expect(&body.expect.params);
        for b in expect(&body.expect.bits) {
            if let Some(r) = g.bit_ref(&b) {
                if !reads.contains(&r.param.id) {
                    reads.push(r.param.id.clone());
                }
            }
        }
        for k in &reads {
            if let (Some(p), Some(s)) = (g.param(k), g.slot_of(k)) {
                let cmp = if g.protocol.plc.timers.iter().any(|t| t.param == p.id) {
                    g.compare_for(p, None)
                } else {
                    Compare::Exact
                };
                g.read(&mut cb, Role::Check, s, cmp, k);
                if p.access.writable() && !restore.contains(&s) {
                    restore.push(s);
                }
            }
        }
        for d in expect(&body.expect.dwords) {
            let lo = d.split(':').next().unwrap_or("");
            if let Some(s) = g.slot_of(lo) {
                let dw = Slot {
                    addr: s.addr,
                    size: 4,
                };
                g.read(&mut cb, Role::Check, dw, Compare::Exact, &d);
            }
        }
        upload(g, &mut cb, Role::Cleanup, first, &original);
        if !inputs.is_empty() {
            cb.action(
                Role::Cleanup,
                Action::Inputs {
                    value: start_inputs,
                },
                "the digital inputs as at the start",
                &[],
            );
        }
        for s in restore {
            g.restore(&mut cb, s, "what the program or the vector changed");
        }
        g.restore_pb99(&mut cb);
        g.push(cb);
    }
}

/// The digital input a bit name stands for (`b90.3` is input 3), when it is one of the
/// physical inputs (manual 3.8.1 b90.0..b90.7, the spec's PLC inputs table).
fn physical_input(g: &Gen, name: &str) -> Option<u8> {
    g.protocol
        .io
        .inputs
        .iter()
        .find(|p| p.bit == name)
        .map(|p| p.index)
}

/// The two PLC timers (manual 3.8.1 Pr92, Pr93, b99.0, b99.1): loaded over the line with
/// the PLC running, each counts one per 6.144 ms scan and raises its flag once it reaches
/// 0. The reads fall at least ten scans away from either expiry, so the scan phase and the
/// answer time do not decide them; counts are compared within ± `TIMER_SLACK_SCANS`.
fn timers(g: &mut Gen) {
    let timers = g.protocol.plc.timers.clone();
    let (Some(t1), Some(t2)) = (timers.first(), timers.get(1)) else {
        return;
    };
    let (Some(s1), Some(s2), Some(f1), Some(f2)) = (
        g.slot_of(&t1.param),
        g.slot_of(&t2.param),
        g.bit_ref(&t1.status_bit),
        g.bit_ref(&t2.status_bit),
    ) else {
        return;
    };
    // Timer 1 runs 100 scans (about 614 ms, the manual's example), timer 2 half as long.
    let (n1, n2) = (100i64, 50i64);
    let scan = u64::from(t1.base_us);
    let flags = Compare::Mask(bit_value(f1.slot, f1.at) | bit_value(f2.slot, f2.at));
    let near = Compare::Near(TIMER_SLACK_SCANS);
    let mut cb = CaseB::new(
        "hpd/plc/timers",
        format!(
            "{} = {n1} and {} = {n2} count one per scan: both flags 0 while counting, {} = 0 with {} = 1 after {n2} scans, {} = 0 with {} = 1 after {n1}",
            t1.param, t2.param, t2.param, t2.status_bit, t1.param, t1.status_bit
        ),
        &[TIMER_1, TIMER_2, "HPD-TIMER-003", "HPD-TIMER-004"],
    );
    let (p1, p2) = (t1.param.clone(), t2.param.clone());
    g.write(&mut cb, Role::Check, s1, n1, &p1);
    g.write(&mut cb, Role::Check, s2, n2, &p2);
    g.read(
        &mut cb,
        Role::Check,
        f1.slot,
        flags,
        "Pb99 (both timers counting)",
    );
    // The read at about 25 scans, half-way through timer 2.
    cb.action(
        Role::Check,
        Action::Listen { us: 25 * scan },
        "listen for 25 scans",
        &[],
    );
    g.read(&mut cb, Role::Check, s2, near, &p2);
    lead(&mut cb, TIMER_2);
    g.read(&mut cb, Role::Check, s1, near, &p1);
    lead(&mut cb, TIMER_1);
    // At about 65 scans: timer 2 has elapsed, timer 1 still counts.
    cb.action(
        Role::Check,
        Action::Listen { us: 40 * scan },
        "listen for 40 more scans",
        &[],
    );
    g.read(&mut cb, Role::Check, s2, Compare::Exact, &p2);
    lead(&mut cb, TIMER_2);
    g.read(
        &mut cb,
        Role::Check,
        f1.slot,
        flags,
        "Pb99 (timer 2 elapsed)",
    );
    // At about 125 scans: both have elapsed.
    cb.action(
        Role::Check,
        Action::Listen { us: 60 * scan },
        "listen for 60 more scans",
        &[],
    );
    g.read(&mut cb, Role::Check, s1, Compare::Exact, &p1);
    lead(&mut cb, TIMER_1);
    g.read(&mut cb, Role::Check, f1.slot, flags, "Pb99 (both elapsed)");
    g.restore(&mut cb, s1, &p1);
    g.restore(&mut cb, s2, &p2);
    g.push(cb);
}

/// The requirement of timer 1 (Pr92) counting down (3.8.1).
const TIMER_1: &str = "HPD-TIMER-001";
/// The requirement of timer 2 (Pr93) counting down (3.8.1).
const TIMER_2: &str = "HPD-TIMER-002";

/// The last step of `cb` checks `requirement` first: a count read of one timer.
fn lead(cb: &mut CaseB, requirement: &str) {
    if let Some(step) = cb.steps.last_mut() {
        step.requirements.retain(|r| r != requirement);
        step.requirements.insert(0, requirement.to_owned());
    }
}

/// How many scans a timer count read over the line may differ from the reference's: the
/// request's and the answer's transit plus an answer delay inside the manual's bounds
/// (about 50 ms at 6.144 ms a scan).
const TIMER_SLACK_SCANS: i64 = 8;

/// What power-up clears and what the parameter save keeps of the user bits (manual 3.8.1
/// Pb91, Pb94, b90.8..b90.15): the volatile bits read 0 after power-up, a saved user flag
/// is still set.
fn power_up(g: &mut Gen) {
    let volatile: [(&[&str], &str); 2] = [
        (&names::VOLATILE_FLAGS, "HPD-BIT-91-POWER-ON"),
        (&names::POWER_UP_CLEARED, "HPD-BIT-94-POWER-ON"),
    ];
    for (bits, requirement) in volatile {
        let refs: Vec<_> = bits.iter().filter_map(|n| g.bit_ref(n)).collect();
        let Some(first) = refs.first() else { continue };
        let slot = first.slot;
        let param = first.param.id.clone();
        let mut mask = 0u32;
        for r in &refs {
            mask |= bit_value(r.slot, r.at);
        }
        let mut cb = CaseB::new(
            format!("hpd/cmd/power-up/{param}"),
            format!(
                "{} set over the line read 0 after the drive is switched off and on",
                bits.join(", ")
            ),
            &[requirement],
        );
        for r in &refs {
            g.bit(&mut cb, Role::Setup, r, true);
        }
        cb.power_cycle();
        g.read(
            &mut cb,
            Role::Check,
            slot,
            Compare::Mask(mask),
            &format!("{param} (bits cleared at power-up)"),
        );
        g.push(cb);
    }

    let save = g.protocol.serial_setup.save_bit.clone();
    let (Some(save_ref), Some(flag)) = (g.bit_ref(&save), g.bit_ref(names::SAVED_FLAG)) else {
        return;
    };
    let mut cb = CaseB::new(
        format!("hpd/cmd/{save}/user-flags"),
        format!(
            "{save} stores the user flag {} = 1: after power-up it is 1 again although it was cleared",
            names::SAVED_FLAG
        ),
        &["HPD-BIT-90-USER", "HPD-CMD-012", "HPD-PAR-018"],
    );
    g.bit(&mut cb, Role::Setup, &flag, true);
    g.bit(&mut cb, Role::Check, &save_ref, true);
    g.bit(&mut cb, Role::Check, &flag, false);
    cb.power_cycle();
    let user = bit_value(flag.slot, flag.at);
    g.read(
        &mut cb,
        Role::Check,
        flag.slot,
        Compare::Mask(user),
        "Pb90 (the saved user flag)",
    );
    g.restore(&mut cb, flag.slot, "Pb90");
    g.bit(&mut cb, Role::Cleanup, &save_ref, true);
    g.push(cb);
}

/// HPD-BIT-41-5 and HPD-BIT-41-12 (manual 3.3 b41.5, b41.12, b40.9; 3.8.1 "b90.0 = drive
/// enable"): b41.5 shows the hardware enable input; b41.12 is 1 with the input applied and
/// b40.9 = 1, and 0 with either withdrawn. The manual does not say which task of appendix F
/// updates them; each read waits two periods of the slowest task slot, which covers every
/// slot.
fn hardware_enable(g: &mut Gen) {
    let io = &g.protocol.io;
    let (Some(enable), Some(status), Some(enabled), Some(software)) = (
        io.inputs
            .iter()
            .find(|i| i.index == io.enable_input)
            .map(|i| i.bit.clone()),
        g.bit_ref(names::HARDWARE_ENABLE),
        g.bit_ref(names::DRIVE_ENABLED),
        g.bit_ref(&io.software_enable_bit),
    ) else {
        return;
    };
    let Some(mask) = 1u16.checked_shl(u32::from(io.enable_input)) else {
        return;
    };
    let sw = io.software_enable_bit.clone();
    let wait = 2 * g
        .protocol
        .task_slots
        .iter()
        .map(|s| u64::from(s.period_us))
        .max()
        .unwrap_or(u64::from(g.protocol.plc.scan_us));
    let start = g.baseline.digital_inputs();
    let inputs = |cb: &mut CaseB, value: u16, what: &str| {
        cb.action(
            Role::Setup,
            Action::Inputs { value },
            format!("hardware enable input {enable} {what}: inputs {value:#06x}"),
            &[],
        );
    };
    // Waits, then reads `bit` (only it compared) checking `requirement`.
    let read = |g: &mut Gen, cb: &mut CaseB, bit: &BitRef, requirement: &str| {
        cb.action(
            Role::Setup,
            Action::Listen { us: wait },
            "listen for two periods of the slowest task slot",
            &[],
        );
        let cmp = Compare::Mask(bit_value(bit.slot, bit.at));
        g.read(cb, Role::Check, bit.slot, cmp, bit.param.id.as_str());
        if let Some(step) = cb.steps.last_mut() {
            step.requirements.insert(0, requirement.to_owned());
        }
    };

    let mut cb = CaseB::new(
        "hpd/bit/b41.5/hardware-enable",
        format!(
            "{} follows the hardware enable input {enable}: 1 with the input applied, 0 with it removed",
            names::HARDWARE_ENABLE
        ),
        &["HPD-BIT-41-5"],
    );
    for (value, what) in [(start | mask, "applied"), (start & !mask, "removed")] {
        inputs(&mut cb, value, what);
        read(g, &mut cb, &status, "HPD-BIT-41-5");
    }
    cb.action(
        Role::Cleanup,
        Action::Inputs { value: start },
        "the digital inputs as at the start",
        &[],
    );
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/bit/b41.12/drive-enabled",
        format!(
            "{} is 1 with the hardware enable input {enable} applied and {sw} = 1, 0 after {sw} = 0, and 0 with {sw} = 1 and the input removed",
            names::DRIVE_ENABLED
        ),
        &["HPD-BIT-41-12"],
    );
    g.bit(&mut cb, Role::Setup, &software, true);
    inputs(&mut cb, start | mask, "applied");
    read(g, &mut cb, &enabled, "HPD-BIT-41-12");
    g.bit(&mut cb, Role::Setup, &software, false);
    read(g, &mut cb, &enabled, "HPD-BIT-41-12");
    g.bit(&mut cb, Role::Setup, &software, true);
    inputs(&mut cb, start & !mask, "removed");
    read(g, &mut cb, &enabled, "HPD-BIT-41-12");
    cb.action(
        Role::Cleanup,
        Action::Inputs { value: start },
        "the digital inputs as at the start",
        &[],
    );
    g.restore(&mut cb, software.slot, software.param.id.as_str());
    g.push(cb);
}
