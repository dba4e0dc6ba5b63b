//! IO-Link master logs of a PSx3xx (instruction manual 4.4–4.6 sequences built with the
//! codec) in both forms of `crates/capture/IOLINK-LOG.md`, with faults planted on request.
//!
//! Port 1 runs process data format 1: the master reads ISDU 116 and writes ISDU 131, starts a
//! positioning run with control word 0x14 (4.5.1), saves (ISDU 2 = 161), and writes the
//! referencing value behind guard 126 (3.1). Port 2 runs format 0 with a time-stamp
//! positioning (4.4.1). The drive's side follows the manual: running bit and speed while
//! moving, target reached inside the window at the end.

use super::SynthError;
use drivespec_capture::iolink::{Access, IoLinkEvent, IoLinkKind, IsduResult};
use drivespec_psx3xx::{ByteOrder, Input, Output, Rules, Stamp, TsCode};
use drivespec_spec::hex::to_hex_lower;
use drivespec_spec::Spec;

/// A fault to plant in a generated IO-Link log, with the violations it must give.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PsxFault {
    /// A process output of 5 bytes (no format has 5).
    OutputLength,
    /// The output switches to format 2 (8 bytes) without ISDU 116, save and reset.
    FormatChange,
    /// ISDU 131 = 500 (outside 1..100) answered with success.
    RangeAccepted,
    /// A write to read-only ISDU 64 refused with 0x8030 instead of 0x8023.
    WrongErrorType,
    /// ISDU 2 = 99 (no such command) answered with success.
    BadCommand,
    /// The referencing value written behind guard 126 = 0 reads back.
    GuardIgnored,
    /// Reserved control bit 15 set.
    ReservedControlBit,
    /// A time stamp of 16375 (neither valid nor inactive).
    InvalidStamp,
    /// Speed with the running bit clear for 40 samples.
    SpeedWithoutRunning,
    /// The time-stamp run starts while the stamp is still being sent.
    StampEarly,
    /// The time-stamp run starts as the stamp turns inactive, before its delay ran out.
    StampDelayShort,
}

impl PsxFault {
    /// Every fault.
    pub const ALL: [PsxFault; 11] = [
        PsxFault::OutputLength,
        PsxFault::FormatChange,
        PsxFault::RangeAccepted,
        PsxFault::WrongErrorType,
        PsxFault::BadCommand,
        PsxFault::GuardIgnored,
        PsxFault::ReservedControlBit,
        PsxFault::InvalidStamp,
        PsxFault::SpeedWithoutRunning,
        PsxFault::StampEarly,
        PsxFault::StampDelayShort,
    ];

    /// The violations (requirement ID, count) the fault gives.
    pub fn expected(self) -> &'static [(&'static str, u64)] {
        match self {
            PsxFault::OutputLength => &[("PSX-PD-001", 1)],
            PsxFault::FormatChange => &[("PSX-PD-010", 1)],
            PsxFault::RangeAccepted => &[("PSX-ISDU-131-RANGE", 1)],
            PsxFault::WrongErrorType => &[("PSX-DP-ERR-003", 1)],
            PsxFault::BadCommand => &[("PSX-CMD-011", 1)],
            PsxFault::GuardIgnored => &[("PSX-GUARD-126-SUPPRESS", 1)],
            PsxFault::ReservedControlBit => &[("PSX-CTL-15-1", 1)],
            PsxFault::InvalidStamp => &[("PSX-TS-003", 1)],
            PsxFault::SpeedWithoutRunning => &[("PSX-STS-6-SET-1", 1)],
            PsxFault::StampEarly => &[("PSX-TS-005", 1)],
            PsxFault::StampDelayShort => &[("PSX-TS-001", 1)],
        }
    }
}

/// Start of generated logs (2024-01-02T10:00:00Z, µs).
pub const START: u64 = 1_704_189_600_000_000;
/// Process data cycle of generated logs (µs).
pub const CYCLE_US: u64 = 2000;

struct Log<'r> {
    rules: &'r Rules<'r>,
    order: ByteOrder,
    now: u64,
    events: Vec<IoLinkEvent>,
}

impl Log<'_> {
    fn push(&mut self, port: u8, kind: IoLinkKind) {
        let line = self.events.len() as u64 + 1;
        self.events.push(IoLinkEvent {
            line,
            time: Some(self.now),
            port: Some(port),
            kind,
        });
        self.now += 500;
    }

    fn isdu(&mut self, port: u8, write: Option<&[u8]>, index: u16, result: IsduResult) {
        let (access, data) = match write {
            Some(d) => (Access::Write, d.to_vec()),
            None => (Access::Read, Vec::new()),
        };
        self.push(
            port,
            IoLinkKind::IsduRequest {
                access,
                index,
                subindex: 0,
                data,
            },
        );
        self.now += 3000;
        self.push(
            port,
            IoLinkKind::IsduResponse {
                index: Some(index),
                subindex: None,
                result,
            },
        );
    }

    fn pd(&mut self, port: u8, out: Vec<u8>, inp: &Input) -> Result<(), SynthError> {
        let input = inp
            .to_bytes(self.rules, self.order)
            .map_err(|e| SynthError(e.to_string()))?;
        self.push(
            port,
            IoLinkKind::ProcessData {
                out: Some(out),
                input: Some(input),
            },
        );
        self.now += CYCLE_US - 500;
        Ok(())
    }

    fn out(&self, o: Output) -> Result<Vec<u8>, SynthError> {
        o.to_bytes(self.rules, self.order)
            .map_err(|e| SynthError(e.to_string()))
    }
}

/// The events of a generated log (see the module docs) with `faults` planted.
pub fn psx_log(spec: &Spec, faults: &[PsxFault]) -> Result<Vec<IoLinkEvent>, SynthError> {
    let rules = Rules::from_spec(spec).map_err(|e| SynthError(e.to_string()))?;
    let order = rules.wire_order();
    let mut log = Log {
        rules: &rules,
        order,
        now: START,
        events: Vec::new(),
    };
    let has = |f: PsxFault| faults.contains(&f);
    let ok = || IsduResult::Data(Vec::new());
    // Port 1, format 1 (4.5.1).
    log.isdu(1, None, 116, IsduResult::Data(vec![1]));
    log.isdu(1, Some(&10u16.to_be_bytes()), 131, ok());
    if has(PsxFault::RangeAccepted) {
        log.isdu(1, Some(&500u16.to_be_bytes()), 131, ok());
        log.isdu(1, Some(&10u16.to_be_bytes()), 131, ok());
    }
    if has(PsxFault::WrongErrorType) {
        log.isdu(1, Some(&[0, 0]), 64, IsduResult::Error(0x8030));
    } else {
        log.isdu(1, Some(&[0, 0]), 64, IsduResult::Error(0x8023));
    }
    let mut inp = Input {
        status: 0x0010,
        rpm: 0,
        actual: 1000,
    };
    let idle = log.out(Output::ControlTarget {
        control_word: 0,
        target: 0,
    })?;
    for _ in 0..10 {
        log.pd(1, idle.clone(), &inp)?;
    }
    let target = 3000;
    let mut control = 0x14u16;
    if has(PsxFault::ReservedControlBit) {
        control |= 1 << 15;
    }
    let run = log.out(Output::ControlTarget {
        control_word: control,
        target,
    })?;
    let mut speed_fault = 0;
    while inp.actual < target {
        log.pd(1, run.clone(), &inp)?;
        inp.actual = (inp.actual + 20).min(target);
        inp.rpm = 30;
        inp.status = 0x0050;
        if has(PsxFault::SpeedWithoutRunning) && speed_fault < 40 {
            inp.status &= !(1 << 6);
            speed_fault += 1;
        }
    }
    inp.rpm = 0;
    inp.status = 0x0011;
    for _ in 0..10 {
        log.pd(1, run.clone(), &inp)?;
    }
    if has(PsxFault::OutputLength) {
        log.pd(1, vec![0, 0x14, 0, 0, 0x0b], &inp)?;
    }
    if has(PsxFault::FormatChange) {
        let f2 = log.out(Output::SpeedControlTarget {
            target_speed: 0,
            control_word: 0x14,
            target,
        })?;
        log.pd(1, f2, &inp)?;
    }
    log.isdu(1, Some(&[161]), 2, ok());
    if has(PsxFault::BadCommand) {
        log.isdu(1, Some(&[99]), 2, ok());
    }
    // Guard 126 (3.1): the referencing value written after 126 = 0 is dropped.
    log.isdu(1, Some(&4000i32.to_be_bytes()), 127, ok());
    log.isdu(1, Some(&[0]), 126, ok());
    log.isdu(1, Some(&5000i32.to_be_bytes()), 127, ok());
    let back = if has(PsxFault::GuardIgnored) {
        5000i32
    } else {
        4000
    };
    log.isdu(1, None, 127, IsduResult::Data(back.to_be_bytes().to_vec()));
    log.isdu(1, None, 131, IsduResult::Data(10u16.to_be_bytes().to_vec()));
    // Port 2, format 0 (4.4.1): stamp inactive, code 3 with a stamp, stamp inactive.
    let ts = rules.timestamp();
    let inactive = Stamp::inactive(ts);
    let stamp = if has(PsxFault::InvalidStamp) {
        Stamp(16375)
    } else {
        Stamp(10000)
    };
    let mut inp2 = Input {
        status: 0x0011,
        rpm: 0,
        actual: 51200,
    };
    // The drive starts once the delay after the last valid stamp has passed (4.4).
    let delay = stamp.meaning(ts).delay_us().map(u64::from);
    let mut due = None;
    for (block, (code, s, n)) in [
        (0u8, inactive, 5),
        (3, inactive, 5),
        (3, stamp, 5),
        (3, inactive, 30),
    ]
    .into_iter()
    .enumerate()
    {
        let out = log.out(Output::TimeStamp {
            control: TsCode(code),
            stamp: s,
        })?;
        for i in 0..n {
            let start = match block {
                2 => has(PsxFault::StampEarly) && i == 2,
                3 => {
                    (has(PsxFault::StampDelayShort) && i == 0) || due.is_some_and(|d| log.now >= d)
                }
                _ => false,
            };
            if start || inp2.status & 0x0040 != 0 {
                inp2.status = 0x0050;
                inp2.rpm = 60;
                inp2.actual += 40;
            }
            if block == 2 {
                due = delay.map(|d| log.now + d);
            }
            log.pd(2, out.clone(), &inp2)?;
        }
    }
    inp2.rpm = 0;
    inp2.status = 0x0011;
    let out = log.out(Output::TimeStamp {
        control: TsCode(0),
        stamp: inactive,
    })?;
    log.pd(2, out, &inp2)?;
    Ok(log.events)
}

/// The events as JSON lines (IOLINK-LOG.md).
pub fn to_jsonl(events: &[IoLinkEvent]) -> String {
    let mut s = String::new();
    for e in events {
        let mut o = serde_json::Map::new();
        if let Some(t) = e.time {
            o.insert("time".into(), t.into());
        }
        if let Some(p) = e.port {
            o.insert("port".into(), p.into());
        }
        match &e.kind {
            IoLinkKind::ProcessData { out, input } => {
                o.insert("kind".into(), "pd".into());
                if let Some(b) = out {
                    o.insert("out".into(), to_hex_lower(b).into());
                }
                if let Some(b) = input {
                    o.insert("in".into(), to_hex_lower(b).into());
                }
            }
            IoLinkKind::IsduRequest {
                access,
                index,
                subindex,
                data,
            } => {
                o.insert("kind".into(), "isdu_req".into());
                o.insert(
                    "rw".into(),
                    match access {
                        Access::Read => "read",
                        Access::Write => "write",
                    }
                    .into(),
                );
                o.insert("index".into(), (*index).into());
                o.insert("subindex".into(), (*subindex).into());
                if *access == Access::Write {
                    o.insert("data".into(), to_hex_lower(data).into());
                }
            }
            IoLinkKind::IsduResponse {
                index,
                subindex,
                result,
            } => {
                o.insert("kind".into(), "isdu_res".into());
                if let Some(i) = index {
                    o.insert("index".into(), (*i).into());
                }
                if let Some(s) = subindex {
                    o.insert("subindex".into(), (*s).into());
                }
                match result {
                    IsduResult::Data(d) => {
                        o.insert("data".into(), to_hex_lower(d).into());
                    }
                    IsduResult::Error(c) => {
                        o.insert("error".into(), format!("{c:#06x}").into());
                    }
                }
            }
            IoLinkKind::PortEvent {
                code,
                qualifier,
                text,
            } => {
                o.insert("kind".into(), "event".into());
                o.insert("code".into(), format!("{code:#06x}").into());
                if let Some(q) = qualifier {
                    o.insert("qualifier".into(), (*q).into());
                }
                if let Some(t) = text {
                    o.insert("text".into(), t.clone().into());
                }
            }
            _ => continue,
        }
        s.push_str(&serde_json::Value::Object(o).to_string());
        s.push('\n');
    }
    s
}

/// The events as CSV with every column (IOLINK-LOG.md).
pub fn to_csv(events: &[IoLinkEvent]) -> String {
    let mut s =
        String::from("time,port,kind,out,in,rw,index,subindex,data,error,code,qualifier,text\n");
    for e in events {
        let mut cells: [String; 13] = Default::default();
        let [time, port, kind, out, inp, rw, index, subindex, data, error, code, qualifier, text] =
            &mut cells;
        if let Some(t) = e.time {
            *time = t.to_string();
        }
        if let Some(p) = e.port {
            *port = p.to_string();
        }
        match &e.kind {
            IoLinkKind::ProcessData { out: o, input } => {
                *kind = "pd".into();
                *out = o.as_deref().map(to_hex_lower).unwrap_or_default();
                *inp = input.as_deref().map(to_hex_lower).unwrap_or_default();
            }
            IoLinkKind::IsduRequest {
                access,
                index: i,
                subindex: si,
                data: d,
            } => {
                *kind = "isdu_req".into();
                *rw = match access {
                    Access::Read => "read".into(),
                    Access::Write => "write".into(),
                };
                *index = i.to_string();
                *subindex = si.to_string();
                if *access == Access::Write {
                    *data = to_hex_lower(d);
                }
            }
            IoLinkKind::IsduResponse {
                index: i,
                subindex: si,
                result,
            } => {
                *kind = "isdu_res".into();
                *index = i.map(|v| v.to_string()).unwrap_or_default();
                *subindex = si.map(|v| v.to_string()).unwrap_or_default();
                match result {
                    IsduResult::Data(d) => *data = to_hex_lower(d),
                    IsduResult::Error(c) => *error = format!("{c:#06x}"),
                }
            }
            IoLinkKind::PortEvent {
                code: c,
                qualifier: q,
                text: t,
            } => {
                *kind = "event".into();
                *code = format!("{c:#06x}");
                *qualifier = q.map(|v| v.to_string()).unwrap_or_default();
                *text = t
                    .as_deref()
                    .map(|t| format!("\"{}\"", t.replace('"', "\"\"")))
                    .unwrap_or_default();
            }
            _ => continue,
        }
        s.push_str(&cells.join(","));
        s.push('\n');
    }
    s
}
