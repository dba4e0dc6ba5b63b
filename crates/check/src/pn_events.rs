//! Events of a PROFINET capture a commissioning engineer wants to see, each with frame, time
//! and meaning in words: alarm notifications and ERR-RTA-PDUs (IEC 61158-6-10 RTA-PDU), DCP
//! name conflicts, renames during an AR and Set requests without answer (IEC 61158-6-10
//! DCP). Memory is bounded: at most [`MAX_PENDING_SETS`] open DCP Sets and
//! [`MAX_NAMES`] station names are remembered.

use crate::pnio_names::PnioNames;
use crate::report::{Evidence, Recorder, Where};
use drivespec_capture::pnio::PnioStatus;
use drivespec_capture::rt::{AlarmHeader, DcpHeader};
use drivespec_spec::hex::{encode, Case};
use std::collections::{HashMap, HashSet, VecDeque};

/// Most DCP Set requests waiting for their answer.
pub const MAX_PENDING_SETS: usize = 64;
/// Most NameOfStation values remembered from Identify answers.
pub const MAX_NAMES: usize = 1024;
/// Capture time (µs) after a DCP Set request without which its missing answer is not
/// reported (the capture may end before the station could answer).
pub const SET_ANSWER_US: u64 = 1_000_000;

/// Why an alarm notification is listed and not a violation.
const ALARM_REASON: &str = "an IO device reports events of its submodules by alarm notifications; the alarm is information, not a breach (IEC 61158-6-10 AlarmNotification-PDU)";

/// Why an ERR-RTA-PDU after a Release or the other side's abort is no finding.
const CLOSING_REASON: &str = "the AR was released or aborted by the other side just before: each side closes its alarm endpoints with an ERR-RTA-PDU (IEC 61158-6-10 RTA-PDU)";

/// DCP ServiceID Set, Identify (IEC 61158-6-10 DCP).
const DCP_SET: u8 = 4;
const DCP_IDENTIFY: u8 = 5;
/// DCP option Device properties, suboption NameOfStation.
const NAME_OF_STATION: (u8, u8) = (2, 2);
/// RTA-PDU types DATA and ERR (PDUType bits 0–3).
const RTA_DATA: u8 = 1;
const RTA_ERR: u8 = 4;
/// BlockType of an AlarmNotification (high, low).
const ALARM_NOTIFICATION: [u16; 2] = [0x0001, 0x0002];

/// Where a frame came from, as the events see it.
#[derive(Debug, Clone, Copy)]
pub struct Frame {
    /// Where it is in the capture.
    pub at: Where,
    /// Source MAC.
    pub src: [u8; 6],
    /// Destination MAC.
    pub dst: [u8; 6],
}

#[derive(Debug, Clone)]
struct PendingSet {
    xid: u32,
    requester: [u8; 6],
    target: [u8; 6],
    what: String,
    at: Where,
}

/// The event recognisers of a PROFINET capture.
#[derive(Debug, Clone)]
pub struct PnEvents {
    names: &'static PnioNames,
    sets: VecDeque<PendingSet>,
    stations: HashMap<String, [u8; 6]>,
    conflicts: HashSet<String>,
}

/// `aa:bb:cc:dd:ee:ff`.
pub fn mac(m: &[u8; 6]) -> String {
    encode(m, Case::Lower, ":")
}

fn subject(f: &Frame) -> String {
    format!("{} → {}", mac(&f.src), mac(&f.dst))
}

fn be16(b: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_be_bytes([*b.get(at)?, *b.get(at + 1)?]))
}

fn be32(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_be_bytes([
        *b.get(at)?,
        *b.get(at + 1)?,
        *b.get(at + 2)?,
        *b.get(at + 3)?,
    ]))
}

/// The DCP blocks of a PDU as (option, suboption, data).
fn dcp_blocks(mut b: &[u8]) -> Vec<(u8, u8, &[u8])> {
    let mut out = Vec::new();
    while let (Some(&opt), Some(&sub), Some(len)) = (b.first(), b.get(1), be16(b, 2)) {
        let len = usize::from(len);
        let Some(data) = b.get(4..4 + len) else {
            break;
        };
        out.push((opt, sub, data));
        let next = 4 + len + len % 2;
        b = b.get(next..).unwrap_or(&[]);
    }
    out
}

/// The NameOfStation in DCP blocks (after the BlockInfo or BlockQualifier word).
fn station_name(blocks: &[(u8, u8, &[u8])]) -> Option<String> {
    blocks
        .iter()
        .find(|(o, s, _)| (*o, *s) == NAME_OF_STATION)
        .and_then(|(_, _, d)| d.get(2..))
        .map(|n| String::from_utf8_lossy(n).into_owned())
}

/// Lists an event the standard allows: an allowed state that ends where it begins.
fn event(rec: &mut Recorder, id: &str, subject: &str, at: Where, message: String, reason: &str) {
    if let Some(i) = rec.allowed(id, subject, at, message, reason) {
        rec.ended(i, at);
    }
}

impl PnEvents {
    /// Recognisers naming PNIOStatus values and alarm types with `names`.
    pub fn new(names: &'static PnioNames) -> PnEvents {
        PnEvents {
            names,
            sets: VecDeque::new(),
            stations: HashMap::new(),
            conflicts: HashSet::new(),
        }
    }

    /// A PNIOStatus in words.
    pub fn status(&self, s: PnioStatus) -> String {
        self.names.status(s)
    }

    /// An alarm frame: a notification is listed (PN-ALARM-001); an ERR-RTA-PDU, which
    /// aborts the AR `ar` (its description, when known), is a finding (PN-ALARM-002), or
    /// listed when the AR was already `closed` (released or aborted by the other side).
    pub fn alarm(
        &self,
        rec: &mut Recorder,
        f: &Frame,
        h: &AlarmHeader<'_>,
        ar: Option<String>,
        closed: bool,
    ) {
        let subj = subject(f);
        let ar = ar.unwrap_or_else(|| "no Connect of these stations was seen".to_owned());
        match h.pdu_type & 0x0f {
            RTA_ERR => {
                let Some(v) = be32(h.var_part, 0) else {
                    return;
                };
                let [code, decode, code1, code2] = v.to_be_bytes();
                let s = PnioStatus {
                    code,
                    decode,
                    code1,
                    code2,
                };
                let message = format!(
                    "alarm endpoint {:#06x} → {:#06x} ends the AR ({ar}): {}",
                    h.src_endpoint,
                    h.dst_endpoint,
                    self.names.status(s)
                );
                if closed {
                    event(rec, "PN-ALARM-002", &subj, f.at, message, CLOSING_REASON);
                } else {
                    rec.violation(
                        "PN-ALARM-002",
                        &subj,
                        f.at,
                        message,
                        Evidence::none().with("pnio_status", s.to_string()),
                    );
                }
            }
            RTA_DATA => {
                let v = h.var_part;
                let (Some(block), Some(kind), Some(api), Some(slot), Some(subslot)) =
                    (be16(v, 0), be16(v, 6), be32(v, 8), be16(v, 12), be16(v, 14))
                else {
                    return;
                };
                if !ALARM_NOTIFICATION.contains(&block) {
                    return;
                }
                let priority = if block == 0x0001 { "high" } else { "low" };
                event(
                    rec,
                    "PN-ALARM-001",
                    &subj,
                    f.at,
                    format!(
                        "alarm {} ({priority} priority) for API {api}, slot {slot}, subslot {subslot:#06x} (AR {ar})",
                        self.names.alarm_type(kind)
                    ),
                    ALARM_REASON,
                );
            }
            _ => {}
        }
    }

    /// A DCP frame: Identify answers are checked for a NameOfStation answered by two
    /// stations (PN-DCP-001); a Set request waits for its answer (PN-DCP-002) and, when it
    /// renames a station in the running AR `ar` of its target, is a finding (PN-DCP-003).
    pub fn dcp(&mut self, rec: &mut Recorder, f: &Frame, h: &DcpHeader<'_>, ar: Option<String>) {
        let blocks = dcp_blocks(h.blocks);
        match (h.service_id, h.service_type) {
            (DCP_IDENTIFY, 1) => {
                let Some(name) = station_name(&blocks) else {
                    return;
                };
                match self.stations.get(&name) {
                    Some(first) if *first != f.src => {
                        if self.conflicts.insert(name.clone()) {
                            rec.violation(
                                "PN-DCP-001",
                                &subject(f),
                                f.at,
                                format!(
                                    "two stations answer DCP Identify for NameOfStation \"{name}\": {} and {}",
                                    mac(first),
                                    mac(&f.src)
                                ),
                                Evidence::none().with("name_of_station", name.clone()),
                            );
                        }
                    }
                    Some(_) => {}
                    None => {
                        if self.stations.len() < MAX_NAMES {
                            self.stations.insert(name, f.src);
                        }
                    }
                }
            }
            (DCP_SET, 0) => {
                let name = station_name(&blocks);
                let what = blocks
                    .iter()
                    .map(|(o, s, _)| format!("option {o}.{s}"))
                    .collect::<Vec<_>>()
                    .join(", ");
                if let (Some(n), Some(ar)) = (&name, ar) {
                    rec.violation(
                        "PN-DCP-003",
                        &subject(f),
                        f.at,
                        format!(
                            "DCP Set renames {} to \"{n}\" while its AR runs ({ar})",
                            mac(&f.dst)
                        ),
                        Evidence::none().with("name_of_station", n.clone()),
                    );
                }
                if self.sets.len() >= MAX_PENDING_SETS {
                    self.sets.pop_front();
                }
                self.sets.push_back(PendingSet {
                    xid: h.xid,
                    requester: f.src,
                    target: f.dst,
                    what: match name {
                        Some(n) => format!("NameOfStation \"{n}\""),
                        None => what,
                    },
                    at: f.at,
                });
            }
            (DCP_SET, _) => {
                self.sets
                    .retain(|p| !(p.xid == h.xid && p.target == f.src && p.requester == f.dst));
            }
            _ => {}
        }
    }

    /// Ends the capture at time `end`: DCP Sets with at least [`SET_ANSWER_US`] of capture
    /// after them and no answer are findings (PN-DCP-002).
    pub fn finish(&mut self, rec: &mut Recorder, end: Option<u64>) {
        for p in std::mem::take(&mut self.sets) {
            let waited = match (p.at.time, end) {
                (Some(a), Some(e)) => e.saturating_sub(a) >= SET_ANSWER_US,
                _ => false,
            };
            if waited {
                rec.violation(
                    "PN-DCP-002",
                    &format!("{} → {}", mac(&p.requester), mac(&p.target)),
                    p.at,
                    format!(
                        "DCP Set ({}, Xid {:#010x}) not answered by {} in the {} s of capture after it",
                        p.what,
                        p.xid,
                        mac(&p.target),
                        SET_ANSWER_US / 1_000_000
                    ),
                    Evidence::none(),
                );
            }
        }
    }
}
