//! `hpd/frame/...`: framing and every message type (manual 4.1), stuffing, corrupt frames,
//! foreign addresses and time-outs.

use super::cases::{CaseB, Gen};
use super::names;
use super::step::{Action, Compare};
use crate::case::Role;
use drivespec_hpd::memory::Slot;
use drivespec_hpd::{Data, Message, MessageKind};

/// The fields after STX with a checksum (`None`: the correct one), stuffed, behind STX.
pub fn frame(g: &Gen, fields: &[u8], chk: Option<u8>) -> Vec<u8> {
    let sum = fields.iter().fold(0u8, |s, b| s.wrapping_add(*b));
    let mut out = vec![g.rules.stx];
    for b in fields.iter().copied().chain([chk.unwrap_or(sum)]) {
        out.push(b);
        if b == g.rules.stx {
            out.push(g.rules.stuff);
        }
    }
    out
}

/// CMD+ADDR of `kind` for drive `addr`.
pub(crate) fn cmd_addr(g: &Gen, kind: MessageKind, addr: u8) -> u8 {
    g.rules.join(g.rules.code(kind), addr)
}

pub(crate) fn generate(g: &mut Gen) {
    let (Some(ranged), Some(scratch), Some(flag)) = (
        g.slot_of(names::RANGED),
        g.slot_of(names::SCRATCH),
        g.bit_ref(names::USER_FLAG),
    ) else {
        g.errors
            .push("frame cases: Pr33, Pr80 or b90.8 missing".to_owned());
        return;
    };
    let own = g.addr;
    let read = Message::ReadParam {
        addr: own,
        lun: ranged.size,
        par: ranged.addr,
    };
    let read_bytes = g.bytes(&read);
    let value = g.rng.range(1, 0x7000);
    message_types(g, ranged, scratch, &flag, value);
    stuffing(g, scratch);
    corrupt(g, ranged, scratch, value);
    timing(g, ranged, &read_bytes);
    foreign(g, ranged, scratch, value);
}

fn still_answers(g: &mut Gen, cb: &mut CaseB, slot: Slot) {
    g.read(
        cb,
        Role::Check,
        slot,
        Compare::Exact,
        "Pr33 (the drive still answers)",
    );
}

/// Pr80 is read back unchanged, then restored.
fn unchanged(g: &mut Gen, cb: &mut CaseB, scratch: Slot) {
    g.read(cb, Role::Check, scratch, Compare::Exact, "Pr80 (unchanged)");
    g.restore(cb, scratch, "Pr80");
}

fn message_types(
    g: &mut Gen,
    ranged: Slot,
    scratch: Slot,
    flag: &super::cases::BitRef,
    value: i64,
) {
    let own = g.addr;
    let mut cb = CaseB::new(
        "hpd/frame/read-parameter",
        "CMD 4 read of Pr33: the drive answers CMD 1 with LUN, PAR and the data",
        &["HPD-FRAME-014", "HPD-FRAME-010", "HPD-SERIAL-017"],
    );
    g.read(&mut cb, Role::Check, ranged, Compare::Exact, "Pr33");
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/frame/write-parameter",
        "CMD 5 write of Pr80 is acknowledged with [STX][001+ADDR] and taken",
        &["HPD-FRAME-015", "HPD-FRAME-011"],
    );
    g.write(&mut cb, Role::Check, scratch, value, "Pr80");
    g.read(&mut cb, Role::Check, scratch, Compare::Exact, "Pr80");
    g.restore(&mut cb, scratch, "Pr80");
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/frame/bit-change",
        "CMD 6 sets and clears user flag b90.8 (PAR = address + 1, mask with 0 at the bit)",
        &["HPD-FRAME-016", "HPD-FRAME-017", "HPD-FRAME-018"],
    );
    let cmp = g.compare_for(flag.param, None);
    g.bit(&mut cb, Role::Check, flag, true);
    g.read(&mut cb, Role::Check, flag.slot, cmp, "Pb90");
    g.bit(&mut cb, Role::Check, flag, false);
    g.read(&mut cb, Role::Check, flag.slot, cmp, "Pb90");
    g.restore(&mut cb, flag.slot, "Pb90");
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/frame/read-plc",
        "CMD 2 reads 4 bytes of the PLC program at address 0",
        &["HPD-FRAME-012", "HPD-FRAME-010", "HPD-FRAME-022"],
    );
    let msg = Message::ReadPlc {
        addr: own,
        lun: 4,
        par: 0,
    };
    g.msg(
        &mut cb,
        Role::Check,
        msg,
        Compare::Exact,
        "read PLC bytes 0x00-0x03",
    );
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/frame/write-plc",
        "CMD 3 writes the first instruction again while the PLC is stopped; acknowledged",
        &["HPD-FRAME-013", "HPD-FRAME-011", "HPD-BIT-99-13"],
    );
    g.stop_plc(&mut cb);
    let first: Vec<u8> = g.baseline.plc_area().iter().take(2).copied().collect();
    if let Some(data) = Data::new(&first) {
        let msg = Message::WritePlc {
            addr: own,
            par: 0,
            data,
        };
        g.msg(
            &mut cb,
            Role::Check,
            msg,
            Compare::Exact,
            "write PLC bytes 0x00-0x01",
        );
    }
    let msg = Message::ReadPlc {
        addr: own,
        lun: 2,
        par: 0,
    };
    g.msg(
        &mut cb,
        Role::Check,
        msg,
        Compare::Exact,
        "read PLC bytes 0x00-0x01",
    );
    g.restore_pb99(&mut cb);
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/frame/broadcast",
        "CMD 7 with ADDR 0 writes Pr80 in every drive; nobody answers",
        &["HPD-FRAME-019", "HPD-SERIAL-013"],
    );
    if let Some(data) = Data::from_value(value, scratch.size) {
        let msg = Message::Broadcast {
            par: scratch.addr,
            data,
        };
        g.msg(
            &mut cb,
            Role::Check,
            msg,
            Compare::Exact,
            format!("broadcast Pr80 = {value}"),
        );
    }
    g.read(&mut cb, Role::Check, scratch, Compare::Exact, "Pr80");
    g.restore(&mut cb, scratch, "Pr80");
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/frame/drive-response-ignored",
        "a CMD 1 answer sent by the master (full and short form) gets no answer",
        &["HPD-SERIAL-001"],
    );
    if let Some(data) = Data::from_value(value, 2) {
        let msg = Message::Response {
            addr: own,
            par: ranged.addr,
            data,
        };
        let b = g.bytes(&msg);
        g.raw(
            &mut cb,
            Role::Check,
            b,
            "send a CMD 1 data answer to the drive",
            &["HPD-SERIAL-001"],
        );
    }
    let ack = g.bytes(&Message::Ack { addr: own });
    g.raw(
        &mut cb,
        Role::Check,
        ack,
        "send a short acknowledge to the drive",
        &["HPD-SERIAL-001"],
    );
    still_answers(g, &mut cb, ranged);
    g.push(cb);

    for lun in 1..=4u8 {
        let mut cb = CaseB::new(
            format!("hpd/frame/read-lun-{lun}"),
            format!("CMD 4 with LUN {lun} at the address of Pr33 answers {lun} byte(s)"),
            &["HPD-FRAME-007", "HPD-SERIAL-017"],
        );
        let msg = Message::ReadParam {
            addr: own,
            lun,
            par: ranged.addr,
        };
        g.msg(
            &mut cb,
            Role::Check,
            msg,
            Compare::Exact,
            format!("read {lun} byte(s) at Pr33"),
        );
        g.push(cb);
    }
}

/// A value whose `WriteParam`/`Response` at `slot` has the checksum STX (or None).
fn value_with_checksum(g: &Gen, slot: Slot, kind: MessageKind) -> Option<i64> {
    (1..0x7FFFi64).find(|v| {
        let Some(d) = Data::from_value(*v, slot.size) else {
            return false;
        };
        let fields = [cmd_addr(g, kind, g.addr), slot.size, slot.addr];
        let sum = fields
            .iter()
            .chain(d.as_slice())
            .fold(0u8, |s, b| s.wrapping_add(*b));
        sum == g.rules.stx && !d.as_slice().contains(&g.rules.stx)
    })
}

fn stuffing(g: &mut Gen, scratch: Slot) {
    let stx = i64::from(g.rules.stx);
    let mut cb = CaseB::new(
        "hpd/frame/stuffing/request-data",
        "a data byte $7E in a write is followed by $00, which is not counted in LUN",
        &["HPD-FRAME-003", "HPD-FRAME-004"],
    );
    g.write(&mut cb, Role::Check, scratch, stx, "Pr80");
    g.read(&mut cb, Role::Check, scratch, Compare::Exact, "Pr80");
    g.restore(&mut cb, scratch, "Pr80");
    g.push(cb);

    if let Some(v) = value_with_checksum(g, scratch, MessageKind::WriteParam) {
        let mut cb = CaseB::new(
            "hpd/frame/stuffing/request-checksum",
            format!("a write of Pr80 = {v} has the checksum $7E, which is stuffed too"),
            &["HPD-FRAME-003", "HPD-FRAME-004", "HPD-FRAME-009"],
        );
        g.write(&mut cb, Role::Check, scratch, v, "Pr80");
        g.read(&mut cb, Role::Check, scratch, Compare::Exact, "Pr80");
        g.restore(&mut cb, scratch, "Pr80");
        g.push(cb);
    }

    let mut cb = CaseB::new(
        "hpd/frame/stuffing/response-data",
        "the drive stuffs a data byte $7E in its answer",
        &["HPD-FRAME-003"],
    );
    g.write(&mut cb, Role::Setup, scratch, stx, "Pr80");
    g.read(&mut cb, Role::Check, scratch, Compare::Exact, "Pr80");
    g.restore(&mut cb, scratch, "Pr80");
    g.push(cb);

    if let Some(v) = value_with_checksum(g, scratch, MessageKind::Response) {
        let mut cb = CaseB::new(
            "hpd/frame/stuffing/response-checksum",
            format!("the answer with Pr80 = {v} has the checksum $7E, which the drive stuffs (4.1 case 1)"),
            &["HPD-FRAME-003", "HPD-FRAME-009"],
        );
        g.write(&mut cb, Role::Setup, scratch, v, "Pr80");
        g.read(&mut cb, Role::Check, scratch, Compare::Exact, "Pr80");
        g.restore(&mut cb, scratch, "Pr80");
        g.push(cb);
    }
}

fn corrupt(g: &mut Gen, ranged: Slot, scratch: Slot, value: i64) {
    let own = g.addr;
    let d = Data::from_value(value, scratch.size)
        .map(|d| d.as_slice().to_vec())
        .unwrap_or_default();
    let plc: Vec<u8> = g.baseline.plc_area().iter().take(2).copied().collect();
    let kinds: [(&str, MessageKind, Vec<u8>, bool); 6] = [
        (
            "read-parameter",
            MessageKind::ReadParam,
            vec![ranged.size, ranged.addr],
            false,
        ),
        (
            "write-parameter",
            MessageKind::WriteParam,
            [vec![scratch.size, scratch.addr], d.clone()].concat(),
            true,
        ),
        (
            "bit-change",
            MessageKind::BitChange,
            vec![2, scratch.addr, 0xFE, 0x01],
            true,
        ),
        ("read-plc", MessageKind::ReadPlc, vec![2, 0], false),
        (
            "write-plc",
            MessageKind::WritePlc,
            [vec![2, 0], plc].concat(),
            false,
        ),
        (
            "broadcast",
            MessageKind::Broadcast,
            [vec![scratch.size, scratch.addr], d.clone()].concat(),
            true,
        ),
    ];
    for (name, kind, rest, writes) in kinds {
        let addr = if kind == MessageKind::Broadcast {
            0
        } else {
            own
        };
        let fields: Vec<u8> = [vec![cmd_addr(g, kind, addr)], rest].concat();
        let good = fields.iter().fold(0u8, |s, b| s.wrapping_add(*b));
        let mut cb = CaseB::new(
            format!("hpd/frame/checksum-bad/{name}"),
            format!(
                "a {} message with the checksum off by one gets no answer and changes nothing",
                kind.spec_name()
            ),
            &["HPD-SERIAL-012", "HPD-FRAME-009", "HPD-FRAME-020"],
        );
        if kind == MessageKind::WritePlc {
            g.stop_plc(&mut cb);
        }
        let bytes = frame(g, &fields, Some(good.wrapping_add(1)));
        g.raw(
            &mut cb,
            Role::Check,
            bytes,
            "send it with checksum + 1",
            &["HPD-SERIAL-012", "HPD-FRAME-009"],
        );
        if writes {
            unchanged(g, &mut cb, scratch);
        } else {
            still_answers(g, &mut cb, ranged);
        }
        if kind == MessageKind::WritePlc {
            g.restore_pb99(&mut cb);
        }
        g.push(cb);
    }

    let read_rest = [ranged.size, ranged.addr];
    let bad = |g: &mut Gen, id: &str, text: &str, fields: Vec<u8>, reqs: &[&str], check: Slot| {
        let mut cb = CaseB::new(format!("hpd/frame/{id}"), text, reqs);
        let bytes = frame(g, &fields, None);
        g.raw(&mut cb, Role::Check, bytes, text.to_owned(), reqs);
        if check == scratch {
            unchanged(g, &mut cb, scratch);
        } else {
            still_answers(g, &mut cb, ranged);
        }
        g.push(cb);
    };
    bad(
        g,
        "cmd-addr-zero",
        "a message with CMD+ADDR = 0 gets no answer",
        [vec![0], read_rest.to_vec()].concat(),
        &["HPD-FRAME-005", "HPD-FRAME-021", "HPD-SERIAL-012"],
        ranged,
    );
    if own != 0 {
        bad(
            g,
            "cmd-zero",
            "a message with CMD 0 gets no answer",
            [vec![g.rules.join(0, own)], read_rest.to_vec()].concat(),
            &["HPD-FRAME-021", "HPD-SERIAL-012"],
            ranged,
        );
    }
    let rd = cmd_addr(g, MessageKind::ReadParam, own);
    let wr = cmd_addr(g, MessageKind::WriteParam, own);
    let bc = cmd_addr(g, MessageKind::BitChange, own);
    bad(
        g,
        "lun-zero",
        "a read with LUN 0 gets no answer",
        vec![rd, 0, ranged.addr],
        &["HPD-FRAME-007", "HPD-SERIAL-012"],
        ranged,
    );
    bad(
        g,
        "lun-five",
        "a read with LUN 5 gets no answer",
        vec![rd, 5, ranged.addr],
        &["HPD-FRAME-007", "HPD-SERIAL-012"],
        ranged,
    );
    bad(
        g,
        "write-lun-five",
        "a write with LUN 5 and five data bytes gets no answer and changes nothing",
        vec![wr, 5, scratch.addr, 1, 2, 3, 4, 5],
        &["HPD-FRAME-007", "HPD-SERIAL-012"],
        scratch,
    );
    for lun in [1u8, 3] {
        let mut fields = vec![bc, lun, scratch.addr, 0xFE];
        if lun == 3 {
            fields.extend([0x01, 0x00]);
        }
        bad(
            g,
            &format!("bit-change-lun-{lun}"),
            &format!(
                "a bit change with LUN {lun} (it must be 2) gets no answer and changes nothing"
            ),
            fields,
            &["HPD-FRAME-016", "HPD-SERIAL-012"],
            scratch,
        );
    }
    let mut fields = vec![
        g.rules.join(g.rules.code(MessageKind::Broadcast), 1),
        scratch.size,
        scratch.addr,
    ];
    fields.extend(&d);
    bad(
        g,
        "broadcast-addr-nonzero",
        "a broadcast with ADDR 1 is not a broadcast: no answer, nothing written",
        fields,
        &["HPD-FRAME-019", "HPD-SERIAL-012"],
        scratch,
    );

    // A $7E field without its stuffing byte, and a $7E followed by a wrong byte.
    let stx = g.rules.stx;
    let unstuffed = {
        let fields = [wr, 2, scratch.addr, stx, 0];
        let sum = fields.iter().fold(0u8, |s, b| s.wrapping_add(*b));
        let mut b = vec![stx];
        b.extend(fields);
        b.push(sum);
        b
    };
    let mut cb = CaseB::new(
        "hpd/frame/unstuffed-7e",
        "a write whose data byte $7E is not followed by $00 gets no answer and changes nothing",
        &["HPD-FRAME-003", "HPD-SERIAL-012"],
    );
    g.raw(
        &mut cb,
        Role::Check,
        unstuffed,
        "send Pr80 = $7E without stuffing",
        &["HPD-FRAME-003", "HPD-SERIAL-012"],
    );
    unchanged(g, &mut cb, scratch);
    g.push(cb);

    let wrong = {
        let fields = [wr, 2, scratch.addr, stx, 0];
        let sum = fields.iter().fold(0u8, |s, b| s.wrapping_add(*b));
        vec![stx, wr, 2, scratch.addr, stx, 0x01, 0, sum]
    };
    let mut cb = CaseB::new(
        "hpd/frame/stuffing-wrong-byte",
        "a $7E inside a message followed by $01 instead of $00 is an error: no answer",
        &["HPD-FRAME-003", "HPD-FRAME-004", "HPD-SERIAL-012"],
    );
    g.raw(
        &mut cb,
        Role::Check,
        wrong,
        "send $7E $01 inside a write",
        &["HPD-FRAME-004", "HPD-SERIAL-012"],
    );
    unchanged(g, &mut cb, scratch);
    g.push(cb);
}

fn timing(g: &mut Gen, ranged: Slot, read: &[u8]) {
    let head: Vec<u8> = read.iter().take(3).copied().collect();
    let tail: Vec<u8> = read.iter().skip(3).copied().collect();

    let mut cb = CaseB::new(
        "hpd/frame/truncated",
        "a read that stops after 3 bytes gets no answer; after the time-out the next read is answered",
        &["HPD-BAUD-003", "HPD-FRAME-020"],
    );
    cb.split_read(
        &head,
        Action::ListenTimeout {},
        "listen past the message time-out (no answer)",
        &["HPD-FRAME-020"],
    );
    still_answers(g, &mut cb, ranged);
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/frame/timeout-split",
        "a read split by a pause longer than the Pr26 time-out is dropped: no answer to either part",
        &["HPD-BAUD-002", "HPD-BAUD-003", "HPD-FRAME-020"],
    );
    cb.split_read(
        &head,
        Action::ListenTimeout {},
        "wait past the message time-out",
        &["HPD-BAUD-002"],
    );
    g.raw(
        &mut cb,
        Role::Check,
        tail.clone(),
        "send the rest of the read",
        &["HPD-BAUD-003", "HPD-FRAME-020"],
    );
    still_answers(g, &mut cb, ranged);
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/frame/split-within-timeout",
        "a read split by a pause of half the time-out is complete in time and answered",
        &["HPD-BAUD-002", "HPD-FRAME-020"],
    );
    cb.split_read(
        &head,
        Action::ListenHalfTimeout {},
        "wait half the message time-out",
        &["HPD-BAUD-002"],
    );
    let reqs = [
        "HPD-FRAME-020",
        "HPD-FRAME-014",
        "HPD-FRAME-010",
        "HPD-FRAME-009",
        "HPD-SERIAL-017",
        "HPD-SERIAL-016",
    ];
    g.raw(
        &mut cb,
        Role::Check,
        tail,
        "send the rest: the drive answers",
        &reqs,
    );
    g.push(cb);

    let mut cb = CaseB::new(
        "hpd/frame/byte-by-byte",
        "a read sent one byte at a time is answered",
        &["HPD-FRAME-001"],
    );
    let n = read.len();
    for (i, b) in read.iter().enumerate() {
        if i + 1 < n {
            cb.action(
                Role::Check,
                Action::Send { bytes: vec![*b] },
                format!("send byte {i}: {b:02X}"),
                &[],
            );
        } else {
            g.raw(
                &mut cb,
                Role::Check,
                vec![*b],
                format!("send byte {i}: {b:02X}; the drive answers"),
                &[
                    "HPD-FRAME-014",
                    "HPD-FRAME-010",
                    "HPD-FRAME-009",
                    "HPD-SERIAL-017",
                    "HPD-SERIAL-016",
                ],
            );
        }
    }
    g.push(cb);

    let stx = g.rules.stx;
    let len = g.rng.range(1, 8);
    let garbage: Vec<u8> = (0..len)
        .map(|_| {
            let b = g.rng.byte();
            if b == stx {
                0x55
            } else {
                b
            }
        })
        .collect();
    let hex = drivespec_spec::hex::to_hex(&garbage);
    let mut cb = CaseB::new(
        "hpd/frame/garbage-before",
        format!("{len} byte(s) of noise ({hex}) before a read: the drive waits for STX and answers the read"),
        &["HPD-BAUD-003"],
    );
    let bytes = [garbage, read.to_vec()].concat();
    g.raw(
        &mut cb,
        Role::Check,
        bytes,
        "send noise and a read of Pr33 in one chunk",
        &[
            "HPD-BAUD-003",
            "HPD-FRAME-002",
            "HPD-FRAME-014",
            "HPD-FRAME-010",
            "HPD-FRAME-009",
            "HPD-SERIAL-017",
            "HPD-SERIAL-016",
        ],
    );
    g.push(cb);
}

fn foreign(g: &mut Gen, ranged: Slot, scratch: Slot, value: i64) {
    let own = g.addr;
    let max = g.rules.addr_max;
    for other in (0..=max).filter(|a| *a != own) {
        let mut cb = CaseB::new(
            format!("hpd/frame/foreign-address/{other}"),
            format!("a read addressed to drive {other} gets no answer from drive {own}"),
            &["HPD-SERIAL-003", "HPD-SERIAL-002"],
        );
        g.raw_read(
            &mut cb,
            other,
            ranged,
            format!("read Pr33 from drive {other}"),
            &["HPD-SERIAL-003"],
        );
        g.push(cb);
    }
    let other = if own == max { 0 } else { own + 1 };
    let mut cb = CaseB::new(
        "hpd/frame/foreign-address-write",
        format!("a write addressed to drive {other} is neither answered nor taken by drive {own}"),
        &["HPD-SERIAL-003"],
    );
    if let Some(data) = Data::from_value(value, scratch.size) {
        let msg = Message::WriteParam {
            addr: other,
            par: scratch.addr,
            data,
        };
        let b = g.bytes(&msg);
        g.raw(
            &mut cb,
            Role::Check,
            b,
            format!("write Pr80 = {value} to drive {other}"),
            &["HPD-SERIAL-003"],
        );
    }
    unchanged(g, &mut cb, scratch);
    g.push(cb);
}
