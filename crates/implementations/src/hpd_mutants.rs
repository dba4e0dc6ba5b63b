//! The HPD mutants: the reference drive with one planted deviation (a wrapper around `Drive`,
//! or an erratum reading other than the adopted one), shared by the mutation test
//! (`hpd_mutants.rs`) and the fuzzer tests (`crates/fuzz/tests/fuzz_*.rs`).

use crate::{hpd_target, spec};
use drivespec_hpd::model::{Drive, DriveConfig, Output};
use drivespec_hpd::params::Target;
use drivespec_hpd::{decode, parse, AckEnd, Data, FrameRules, Message, MessageKind, Status};
use drivespec_link::Micros;
use drivespec_sim::SimDevice;
use drivespec_spec::{FamilyId, Readings};

fn rules() -> FrameRules {
    FrameRules::from_spec(spec()).expect("the built-in spec has the HPD frame rules")
}

/// The planted deviations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    ChecksumOffByOne,
    AnswersBroadcasts,
    IgnoresRanges,
    WrongBitChangeByte,
    AnswersForeignAddress,
    IgnoresTimeout,
    AckWithChecksum,
    BigEndian,
    NoStuffing,
    ReadOnlyWritable,
    /// Pr23 and Pr24 take a master's write.
    AlarmsWritable,
    PlcWritableWhileRunning,
    /// A FIN after another instruction copies its input like a leading one.
    FinAnywhere,
    /// A write of Pb99 (the PLC run bit, written by every set-up that stops the PLC) is
    /// taken but not acknowledged.
    SilentSetupWrite,
    /// Timer 2 (Pr93) counts down two per PLC scan.
    FastTimer,
    /// The digital inputs are never read: b90.0..b90.7 keep their start state.
    DeafInputs,
    /// The volatile user flags of Pb91 survive power-up.
    KeepsVolatileFlags,
    /// Every answer delayed by 25 ms whatever Pr26, as if every code were code 4 (4 table
    /// note (*)).
    AnswersLate,
    /// END is taken only with a zero second byte; an END with any other second byte is
    /// passed over like `LD 99.13`, so the instructions behind it run.
    EndNeedsZeroByte,
    /// Pr35 shows the torque request before the current limit: 150.0 % of peak while the
    /// shaft turns.
    TorqueBeyondPeak,
    /// Pr35 shows the torque request before the current limit Pr19: 95.0 % of peak while the
    /// shaft turns, within the peak but above a limit of 90.0 %.
    TorqueBeyondLimit,
    /// b41.5 (hardware enable status) always reads 0.
    EnableStatusNeverSet,
    /// b41.12 (drive enabled) shows the hardware enable alone, whatever b40.9.
    EnabledIgnoresSoftwareEnable,
    /// b70.5 in mode 9 shows only the present servo error: the drive clears it in its next
    /// 49.152 ms slot (appendix F, the slowest) when the position error lies within Pr56.
    ServoErrorNotLatched,
    /// A write of Pr66 while a mode-9 profile executes (b70.7 = 1) abandons the profile, as
    /// if the profile generator lost its working data (the drive drops to mode 0).
    ReservedWriteStopsProfile,
    /// An erratum reading instead of the adopted one.
    Reading(&'static str, &'static str),
}

/// The answer delay of Pr26 = 4 (4 table note (*)), which `AnswersLate` adds on every code.
const ANSWER_DELAY_US: Micros = 25_000;

/// The slot in which `ServoErrorNotLatched` clears b70.5 (appendix F, speed windows manager).
const SERVO_SLOT_US: Micros = 49_152;

/// What `TorqueBeyondPeak` shows in Pr35 while the shaft turns: 150.0 % of peak.
const UNLIMITED_TORQUE: i64 = 1500;

/// What `TorqueBeyondLimit` shows in Pr35 while the shaft turns: 95.0 % of peak.
const UNLIMITED_CURRENT: i64 = 950;

/// A drive with a deviation.
#[derive(Clone)]
pub struct Mutant {
    inner: Drive,
    kind: Kind,
    rules: FrameRules,
    /// Bytes held back by `IgnoresTimeout`.
    held: Vec<u8>,
    /// Extra outputs the wrapper adds.
    extra: Vec<Output>,
    /// `SilentSetupWrite`: the next acknowledge is dropped.
    drop_ack: bool,
    /// `ServoErrorNotLatched`: since when b70.5 has been 1.
    servo_since: Option<Micros>,
}

impl Mutant {
    /// The reference drive, commissioned at address 0, with the deviation `kind`.
    pub fn new(kind: Kind) -> Mutant {
        let mut readings = Readings::default();
        if let Kind::Reading(option, reading) = kind {
            readings
                .choose(spec().family(FamilyId::Hpd), option, reading)
                .expect("an option and reading of the built-in errata");
        }
        let inner = Drive::new(spec(), DriveConfig::commissioned(0).with_readings(readings))
            .expect("the built-in spec builds the reference drive");
        Mutant {
            inner,
            kind,
            rules: rules(),
            held: Vec::new(),
            extra: Vec::new(),
            drop_ack: false,
            servo_since: None,
        }
    }

    fn own(&self) -> u8 {
        self.inner.line().map_or(0, |l| l.address)
    }

    /// The single message a chunk holds, if it is exactly one.
    fn single(&self, bytes: &[u8]) -> Option<Message> {
        match decode(&self.rules, bytes, AckEnd::NextByte) {
            Ok(Status::Complete(d)) if d.len == bytes.len() => Some(d.message),
            _ => None,
        }
    }

    fn mode(&self) -> u32 {
        let family = spec().family(FamilyId::Hpd);
        family
            .parameter("Pr31")
            .and_then(|m| self.inner.value(&Target::Param(m)).ok())
            .unwrap_or(0) as u32
    }

    /// Whether `p` is read-only in the operating mode in force (Pr55 in mode 2).
    fn read_only_in_mode(&self, p: &drivespec_spec::Parameter) -> bool {
        let mode = self.mode();
        p.modes
            .iter()
            .any(|e| e.modes.contains(&mode) && e.access.is_some_and(|a| !a.writable()))
    }

    fn value_in_range(&self, p: &drivespec_spec::Parameter, v: i64) -> bool {
        let family = spec().family(FamilyId::Hpd);
        let mode = self.mode();
        let range = p
            .modes
            .iter()
            .find(|e| e.modes.contains(&mode))
            .and_then(|e| e.range.clone())
            .or_else(|| family.resolve(p, None).range);
        range.is_none_or(|r| r.contains(v))
    }

    /// Writes a value as a keypad would, when the deviation says the drive takes it.
    fn force(&mut self, now: Micros, par: u8, data: &Data) {
        let family = spec().family(FamilyId::Hpd);
        let Some(p) = family.parameter_at_address(u32::from(par)) else {
            return;
        };
        if p.address != Some(u32::from(par)) || p.size != Some(u32::from(data.len())) {
            return;
        }
        if family.bitfields_of(&p.id).next().is_some() {
            return;
        }
        let t = Target::Param(p);
        let v = t.value(data);
        let take = match self.kind {
            Kind::IgnoresRanges => p.access.writable() && !self.value_in_range(p, v),
            Kind::ReadOnlyWritable => !p.access.writable() || self.read_only_in_mode(p),
            Kind::AlarmsWritable => ["Pr23", "Pr24"].contains(&p.id.as_str()),
            _ => false,
        };
        if take {
            let _ = self.inner.set_value(now, &t, v);
        }
    }

    fn rx(&mut self, now: Micros, bytes: &[u8]) {
        let own = self.own();
        let msg = self.single(bytes);
        match (self.kind, msg) {
            (
                Kind::WrongBitChangeByte,
                Some(Message::BitChange {
                    addr,
                    par,
                    mask,
                    value,
                }),
            ) => {
                let family = spec().family(FamilyId::Hpd);
                let high = family
                    .parameter_at_address(u32::from(par))
                    .is_some_and(|p| p.address.is_some_and(|a| a + 1 == u32::from(par)));
                if high {
                    let m = Message::BitChange {
                        addr,
                        par: par - 1,
                        mask,
                        value,
                    };
                    self.inner.handle_rx(
                        now,
                        &m.to_bytes(&self.rules)
                            .expect("a message of the spec's frame rules encodes"),
                    );
                    return;
                }
            }
            (Kind::AnswersForeignAddress, Some(m))
                if m.is_request() && m.kind() != MessageKind::Broadcast && m.addr() != own =>
            {
                let m = match m {
                    Message::ReadParam { lun, par, .. } => Message::ReadParam {
                        addr: own,
                        lun,
                        par,
                    },
                    Message::ReadPlc { lun, par, .. } => Message::ReadPlc {
                        addr: own,
                        lun,
                        par,
                    },
                    Message::WriteParam { par, data, .. } => Message::WriteParam {
                        addr: own,
                        par,
                        data,
                    },
                    Message::WritePlc { par, data, .. } => Message::WritePlc {
                        addr: own,
                        par,
                        data,
                    },
                    Message::BitChange {
                        par, mask, value, ..
                    } => Message::BitChange {
                        addr: own,
                        par,
                        mask,
                        value,
                    },
                    other => other,
                };
                self.inner.handle_rx(
                    now,
                    &m.to_bytes(&self.rules)
                        .expect("a message of the spec's frame rules encodes"),
                );
                return;
            }
            (Kind::AnswersBroadcasts, Some(Message::Broadcast { .. })) => {
                self.inner.handle_rx(now, bytes);
                let ack = Message::Ack { addr: own }
                    .to_bytes(&self.rules)
                    .expect("a message of the spec's frame rules encodes");
                self.extra.push(Output::Transmit {
                    at: now,
                    bytes: ack,
                });
                return;
            }
            (
                Kind::IgnoresRanges | Kind::ReadOnlyWritable | Kind::AlarmsWritable,
                Some(Message::WriteParam { addr, par, data }),
            ) if addr == own => {
                self.inner.handle_rx(now, bytes);
                self.force(now, par, &data);
                return;
            }
            (
                Kind::IgnoresRanges | Kind::ReadOnlyWritable,
                Some(Message::Broadcast { par, data }),
            ) => {
                self.inner.handle_rx(now, bytes);
                self.force(now, par, &data);
                return;
            }
            (Kind::SilentSetupWrite, Some(Message::WriteParam { addr, par, .. }))
                if addr == own
                    && spec()
                        .family(FamilyId::Hpd)
                        .parameter("Pb99")
                        .and_then(|p| p.address)
                        == Some(u32::from(par)) =>
            {
                self.drop_ack = true;
            }
            (Kind::ReservedWriteStopsProfile, Some(Message::WriteParam { addr, par, .. }))
                if addr == own
                    && spec()
                        .family(FamilyId::Hpd)
                        .parameter("Pr66")
                        .and_then(|p| p.address)
                        == Some(u32::from(par)) =>
            {
                let busy = hpd_target("b70.7");
                let running = self.inner.value(&busy).unwrap_or(0) != 0;
                self.inner.handle_rx(now, bytes);
                if running {
                    let mode = hpd_target("Pr31");
                    let _ = self.inner.set_value(now, &mode, 0);
                }
                return;
            }
            (Kind::EndNeedsZeroByte, Some(Message::WritePlc { addr, par, data }))
                if addr == own =>
            {
                let codec = drivespec_hpd::plc::PlcCodec::from_spec(spec())
                    .expect("the built-in spec has the PLC instruction table");
                let passed_over =
                    codec
                        .decode(data.as_slice(), usize::from(par))
                        .is_ok_and(|(i, _)| {
                            codec.is_end(&i)
                                && matches!(
                                    i.operands,
                                    drivespec_hpd::plc::Operands::None { spare1, .. } if spare1 != 0
                                )
                        });
                if passed_over {
                    let mut ld = Vec::new();
                    let program = codec
                        .parse_listing("LD 99.13")
                        .expect("an instruction of the built-in table");
                    for (_, i) in &program.instrs {
                        codec
                            .encode(i, &mut ld)
                            .expect("an instruction that parsed encodes");
                    }
                    let m = Message::WritePlc {
                        addr,
                        par,
                        data: Data::new(&ld).expect("one instruction fits a message"),
                    };
                    self.inner.handle_rx(
                        now,
                        &m.to_bytes(&self.rules)
                            .expect("a message of the spec's frame rules encodes"),
                    );
                    return;
                }
            }
            (Kind::PlcWritableWhileRunning, Some(Message::WritePlc { addr, .. }))
                if addr == own =>
            {
                let run = hpd_target("b99.13");
                let running = self.inner.value(&run).unwrap_or(0);
                let _ = self.inner.set_value(now, &run, 0);
                self.inner.handle_rx(now, bytes);
                let _ = self.inner.set_value(now, &run, running);
                return;
            }
            _ => {}
        }
        if self.kind == Kind::IgnoresTimeout {
            // Frames are only delivered once complete: a pause never drops them.
            self.held.extend_from_slice(bytes);
            loop {
                match decode(&self.rules, &self.held, AckEnd::NextByte) {
                    Ok(Status::Complete(d)) => {
                        let frame: Vec<u8> = self.held.drain(..d.len).collect();
                        self.inner.handle_rx(now, &frame);
                    }
                    Ok(Status::Incomplete { .. }) => break,
                    Err(e) => {
                        let junk: Vec<u8> =
                            self.held.drain(..e.skip.min(self.held.len())).collect();
                        self.inner.handle_rx(now, &junk);
                    }
                }
                if self.held.is_empty() {
                    break;
                }
            }
            return;
        }
        self.inner.handle_rx(now, bytes);
    }

    /// `FinAnywhere`: while the PLC runs, every FIN that follows another instruction copies
    /// its input (the k-th FIN input k, inverted when n bit 1 is set) into b40.y or b70.y.
    fn late_fins(&mut self, now: Micros) {
        let family = spec().family(FamilyId::Hpd);
        let run = hpd_target("b99.13");
        if self.inner.value(&run).unwrap_or(0) == 0 {
            return;
        }
        let codec = drivespec_hpd::plc::PlcCodec::from_spec(spec())
            .expect("the built-in spec has the PLC instruction table");
        let Ok(program) = codec.decode_program(self.inner.plc_area()) else {
            return;
        };
        let mut other_before = false;
        let mut k = 0;
        for (_, instr) in &program.instrs {
            let drivespec_hpd::plc::Operands::Fin { y, n, .. } = instr.operands else {
                other_before = true;
                continue;
            };
            k += 1;
            if !other_before {
                continue;
            }
            let input = hpd_target(&format!("b90.{k}"));
            let level = self.inner.value(&input).unwrap_or(0) != 0;
            let param = if n & 1 == 0 { 40 } else { 70 };
            let Ok(out) = Target::parse(family, &format!("b{param}.{y}")) else {
                continue;
            };
            let _ = self
                .inner
                .set_value(now, &out, i64::from(level != (n & 2 != 0)));
        }
    }

    /// The deviation applied to what the drive sends.
    fn tx(&self, bytes: Vec<u8>) -> Vec<u8> {
        let stx = self.rules.stx;
        let stuffed = |fields: &[u8], chk: u8| {
            let mut out = vec![stx];
            for b in fields.iter().copied().chain([chk]) {
                out.push(b);
                if b == stx {
                    out.push(self.rules.stuff);
                }
            }
            out
        };
        let Ok(msg) = parse(&self.rules, &bytes) else {
            return bytes;
        };
        match (self.kind, msg) {
            (Kind::ChecksumOffByOne, Message::Response { addr, par, data }) => {
                let fields: Vec<u8> = [self.rules.join(1, addr), data.len(), par]
                    .into_iter()
                    .chain(data.as_slice().iter().copied())
                    .collect();
                let sum = fields.iter().fold(0u8, |s, b| s.wrapping_add(*b));
                stuffed(&fields, sum.wrapping_add(1))
            }
            (Kind::BigEndian, Message::Response { addr, par, data }) if data.len() > 1 => {
                let mut rev = data.as_slice().to_vec();
                rev.reverse();
                let m = Message::Response {
                    addr,
                    par,
                    data: Data::new(&rev)
                        .expect("no longer than the data of the message it came from"),
                };
                m.to_bytes(&self.rules)
                    .expect("a message of the spec's frame rules encodes")
            }
            (Kind::EnableStatusNeverSet, Message::Response { addr, par, data })
                if spec()
                    .family(FamilyId::Hpd)
                    .parameter("Pb41")
                    .and_then(|p| p.address)
                    == Some(u32::from(par)) =>
            {
                let mut d = data.as_slice().to_vec();
                if let Some(low) = d.first_mut() {
                    *low &= !(1 << 5);
                }
                let m = Message::Response {
                    addr,
                    par,
                    data: Data::new(&d)
                        .expect("no longer than the data of the message it came from"),
                };
                m.to_bytes(&self.rules)
                    .expect("a message of the spec's frame rules encodes")
            }
            (Kind::EnabledIgnoresSoftwareEnable, Message::Response { addr, par, data })
                if spec()
                    .family(FamilyId::Hpd)
                    .parameter("Pb41")
                    .and_then(|p| p.address)
                    == Some(u32::from(par))
                    && data.len() == 2 =>
            {
                let mut d = data.as_slice().to_vec();
                let hardware = d.first().is_some_and(|low| low & (1 << 5) != 0);
                if let Some(high) = d.get_mut(1) {
                    *high = if hardware {
                        *high | (1 << 4)
                    } else {
                        *high & !(1 << 4)
                    };
                }
                let m = Message::Response {
                    addr,
                    par,
                    data: Data::new(&d)
                        .expect("no longer than the data of the message it came from"),
                };
                m.to_bytes(&self.rules)
                    .expect("a message of the spec's frame rules encodes")
            }
            (Kind::AckWithChecksum, Message::Ack { .. }) => {
                let mut b = bytes.clone();
                let chk = b.get(1).copied().unwrap_or(0);
                b.push(chk);
                b
            }
            (Kind::NoStuffing, _) => {
                let mut out = Vec::new();
                let mut prev_stx = false;
                for (i, b) in bytes.iter().enumerate() {
                    if prev_stx && *b == self.rules.stuff && i > 1 {
                        prev_stx = false;
                        continue;
                    }
                    prev_stx = *b == stx && i > 0;
                    out.push(*b);
                }
                out
            }
            _ => bytes,
        }
    }
}

impl SimDevice for Mutant {
    fn handle_rx(&mut self, now: Micros, bytes: &[u8]) {
        self.rx(now, bytes);
    }
    fn advance(&mut self, now: Micros) {
        let timer = hpd_target("Pr93");
        let before = self.inner.value(&timer).unwrap_or(0);
        self.inner.advance(now);
        if self.kind == Kind::FinAnywhere {
            self.late_fins(now);
        }
        if self.kind == Kind::ServoErrorNotLatched && self.mode() == 9 {
            let servo = hpd_target("b70.5");
            if self.inner.value(&servo).unwrap_or(0) == 0 {
                self.servo_since = None;
            } else {
                let since = *self.servo_since.get_or_insert(now);
                if now.saturating_sub(since) >= SERVO_SLOT_US {
                    let _ = self.inner.set_value(now, &servo, 0);
                    self.servo_since = None;
                }
            }
        }
        let shown = match self.kind {
            Kind::TorqueBeyondPeak => Some(UNLIMITED_TORQUE),
            Kind::TorqueBeyondLimit => Some(UNLIMITED_CURRENT),
            _ => None,
        };
        if let Some(shown) = shown {
            let speed = hpd_target("Pr0");
            let torque = hpd_target("Pr35");
            let turning = self.inner.value(&speed).unwrap_or(0) != 0;
            let _ = self
                .inner
                .set_value(now, &torque, if turning { shown } else { 0 });
        }
        if self.kind == Kind::FastTimer {
            let after = self.inner.value(&timer).unwrap_or(0);
            if after < before && after > 0 {
                let _ = self
                    .inner
                    .set_value(now, &timer, (after - (before - after)).max(0));
            }
        }
    }
    fn poll_output(&mut self) -> Option<Output> {
        if !self.extra.is_empty() {
            return Some(self.extra.remove(0));
        }
        match self.inner.poll_output()? {
            Output::Transmit { at, bytes } => {
                let at = if self.kind == Kind::AnswersLate {
                    at + ANSWER_DELAY_US
                } else {
                    at
                };
                if self.drop_ack && matches!(parse(&self.rules, &bytes), Ok(Message::Ack { .. })) {
                    self.drop_ack = false;
                    return self.poll_output();
                }
                Some(Output::Transmit {
                    at,
                    bytes: self.tx(bytes),
                })
            }
            o => Some(o),
        }
    }
    fn power_cycle(&mut self, now: Micros) {
        self.held.clear();
        let flags = hpd_target("Pb91");
        let kept = self.inner.value(&flags).unwrap_or(0);
        self.inner.power_cycle(now);
        if self.kind == Kind::KeepsVolatileFlags {
            let _ = self.inner.set_value(now, &flags, kept & 0xFF00);
        }
    }
    fn clone_box(&self) -> Box<dyn SimDevice> {
        Box::new(self.clone())
    }
    fn set_inputs(&mut self, now: Micros, inputs: u16) -> bool {
        if self.kind != Kind::DeafInputs {
            self.inner.set_inputs(now, inputs);
        }
        true
    }
}

/// The readings a mutant is judged under: for another reading of an erratum, the adopted
/// one made strict (`--reading OPTION=ADOPTED`), since by default every reading is legal.
pub fn strict_readings(kind: Kind) -> Vec<(String, String)> {
    let Kind::Reading(option, _) = kind else {
        return Vec::new();
    };
    let e = spec()
        .family(FamilyId::Hpd)
        .errata
        .iter()
        .find(|e| e.option.as_deref() == Some(option))
        .expect("an option of the built-in errata");
    vec![(option.to_owned(), e.adopted.clone())]
}

/// A mutant with what it breaks.
pub struct Case {
    /// One line.
    pub name: &'static str,
    /// The deviation.
    pub kind: Kind,
    /// Requirements the deviation breaks: every failing case must cite one.
    pub breaks: Vec<String>,
    /// Conformance cases that must fail.
    pub must_fail: &'static [&'static str],
}

/// Every mutant.
pub fn mutants() -> Vec<Case> {
    let read_only: Vec<String> = spec()
        .family(FamilyId::Hpd)
        .requirements
        .iter()
        .filter(|r| r.text.contains("read-only"))
        .map(|r| r.id.clone())
        .collect();
    let v = |ids: &[&str]| ids.iter().map(|s| (*s).to_owned()).collect::<Vec<_>>();
    vec![
        Case {
            name: "checksum off by one",
            kind: Kind::ChecksumOffByOne,
            breaks: v(&["HPD-FRAME-009"]),
            must_fail: &["hpd/frame/read-parameter", "hpd/plc/read-area"],
        },
        Case {
            name: "answers broadcasts",
            kind: Kind::AnswersBroadcasts,
            breaks: v(&["HPD-SERIAL-013"]),
            must_fail: &["hpd/frame/broadcast", "hpd/broadcast/dword"],
        },
        Case {
            name: "ignores ranges",
            kind: Kind::IgnoresRanges,
            breaks: v(&["HPD-PAR-009"]),
            must_fail: &[
                "hpd/param/Pr33/above-max",
                "hpd/param/Pr50/mode-12/above-max",
                "hpd/broadcast/out-of-range",
            ],
        },
        Case {
            name: "wrong bit-change byte",
            kind: Kind::WrongBitChangeByte,
            breaks: v(&["HPD-FRAME-018"]),
            must_fail: &["hpd/bit/b90.8/set", "hpd/bit/b40.9/clear"],
        },
        Case {
            name: "DIV remainder lost",
            kind: Kind::Reading("div-remainder", "quotient32"),
            breaks: v(&["HPD-PLC-025"]),
            must_fail: &["hpd/plc/vector/plc-div-79-77-80-dword"],
        },
        Case {
            name: "answers a foreign address",
            kind: Kind::AnswersForeignAddress,
            breaks: v(&["HPD-SERIAL-003"]),
            must_fail: &[
                "hpd/frame/foreign-address/5",
                "hpd/frame/foreign-address-write",
            ],
        },
        Case {
            name: "ignores the time-out",
            kind: Kind::IgnoresTimeout,
            breaks: v(&["HPD-BAUD-003", "HPD-FRAME-020"]),
            must_fail: &["hpd/frame/timeout-split", "hpd/baud/code-0"],
        },
        Case {
            name: "acknowledge with checksum",
            kind: Kind::AckWithChecksum,
            breaks: v(&["HPD-FRAME-011"]),
            must_fail: &["hpd/frame/write-parameter"],
        },
        Case {
            name: "big-endian data",
            kind: Kind::BigEndian,
            breaks: v(&["HPD-SERIAL-016"]),
            must_fail: &["hpd/frame/read-lun-2", "hpd/vector/serial-case-8"],
        },
        Case {
            name: "answers not stuffed",
            kind: Kind::NoStuffing,
            breaks: v(&["HPD-FRAME-003"]),
            must_fail: &[
                "hpd/frame/stuffing/response-checksum",
                "hpd/vector/serial-case-1",
            ],
        },
        Case {
            name: "read-only parameters writable",
            kind: Kind::ReadOnlyWritable,
            breaks: read_only,
            must_fail: &[
                "hpd/param/Pr25/write-refused",
                "hpd/param/Pr23/write-refused",
                "hpd/param/Pr55/mode-2/max",
            ],
        },
        Case {
            name: "alarm codes writable",
            kind: Kind::AlarmsWritable,
            breaks: v(&["HPD-ALARM-010"]),
            must_fail: &[
                "hpd/param/Pr23/write-refused",
                "hpd/param/Pr24/write-refused",
            ],
        },
        Case {
            name: "PLC writable while running",
            kind: Kind::PlcWritableWhileRunning,
            breaks: v(&["HPD-BIT-99-13"]),
            must_fail: &["hpd/plc/upload-while-running"],
        },
        Case {
            name: "FIN obeyed after other instructions",
            kind: Kind::FinAnywhere,
            breaks: v(&["HPD-PLC-032"]),
            must_fail: &["hpd/plc/vector/plc-fin-after-other-inverted"],
        },
        Case {
            name: "set-up write of Pb99 not answered",
            kind: Kind::SilentSetupWrite,
            breaks: v(&["HPD-FRAME-011"]),
            must_fail: &["hpd/param/Pr33/min", "hpd/bit/b90.8/set"],
        },
        Case {
            name: "timer 2 counts two per scan",
            kind: Kind::FastTimer,
            breaks: v(&["HPD-TIMER-002", "HPD-TIMER-004"]),
            must_fail: &["hpd/plc/timers"],
        },
        Case {
            name: "digital inputs never read",
            kind: Kind::DeafInputs,
            breaks: v(&["HPD-BIT-90-INPUTS", "HPD-BIT-41-5", "HPD-BIT-41-12"]),
            must_fail: &[
                "hpd/plc/vector/plc-ld-out",
                "hpd/plc/vector/plc-default-limits-enabled-closed",
            ],
        },
        Case {
            name: "volatile user flags survive power-up",
            kind: Kind::KeepsVolatileFlags,
            breaks: v(&["HPD-BIT-91-POWER-ON"]),
            must_fail: &["hpd/cmd/power-up/Pb91"],
        },
        Case {
            name: "every answer 25 ms late",
            kind: Kind::AnswersLate,
            breaks: v(&["HPD-BAUD-004"]),
            must_fail: &["hpd/frame/read-parameter", "hpd/param/Pr33/min"],
        },
        Case {
            name: "END with a non-zero second byte passed over",
            kind: Kind::EndNeedsZeroByte,
            breaks: v(&["HPD-PLC-043"]),
            must_fail: &["hpd/plc/end-second-byte"],
        },
        Case {
            name: "Pr35 beyond the peak while turning",
            kind: Kind::TorqueBeyondPeak,
            breaks: v(&["HPD-PAR-048", "HPD-PAR-033"]),
            must_fail: &[
                "hpd/motion/mode-8/jog-forward",
                "hpd/motion/mode-8/jog-reverse",
            ],
        },
        Case {
            name: "Pr35 beyond the current limit Pr19 while turning",
            kind: Kind::TorqueBeyondLimit,
            breaks: v(&["HPD-PAR-033"]),
            must_fail: &[
                "hpd/motion/mode-8/jog-forward",
                "hpd/motion/mode-8/jog-reverse",
            ],
        },
        Case {
            name: "b41.5 never set",
            kind: Kind::EnableStatusNeverSet,
            breaks: v(&["HPD-BIT-41-5"]),
            must_fail: &["hpd/bit/b41.5/hardware-enable"],
        },
        Case {
            name: "b41.12 ignores b40.9",
            kind: Kind::EnabledIgnoresSoftwareEnable,
            breaks: v(&["HPD-BIT-41-12"]),
            must_fail: &["hpd/bit/b41.12/drive-enabled"],
        },
        Case {
            name: "Pr66 write stops a running profile",
            kind: Kind::ReservedWriteStopsProfile,
            breaks: v(&["HPD-MODE-9-008"]),
            must_fail: &["hpd/motion/mode-9/reserved-while-busy"],
        },
        Case {
            name: "b70.5 not latched in mode 9",
            kind: Kind::ServoErrorNotLatched,
            breaks: v(&["HPD-MODE-SERVO-ERROR-LATCH"]),
            must_fail: &["hpd/motion/mode-9/servo-error-latched"],
        },
        Case {
            name: "command bits stay set",
            kind: Kind::Reading("command-self-clear", "latched"),
            breaks: v(&["HPD-CMD-SELF-CLEAR"]),
            must_fail: &["hpd/cmd/b99.10/self-clear"],
        },
        Case {
            name: "security only on the keypad",
            kind: Kind::Reading("b99-7-scope", "keypad-only"),
            breaks: v(&["HPD-BIT-99-7"]),
            must_fail: &["hpd/cmd/b99.7/blocks-writes"],
        },
        Case {
            name: "Pr31 takes any byte",
            kind: Kind::Reading("pr31-range", "byte"),
            breaks: v(&["HPD-PAR-009"]),
            must_fail: &["hpd/param/Pr31/gap-3", "hpd/param/Pr31/above-max"],
        },
        Case {
            name: "b99.3 set for non-zero results",
            kind: Kind::Reading("b99-3", "nonzero"),
            breaks: v(&[
                "HPD-PLC-021",
                "HPD-BIT-99-3",
                "HPD-PLC-013",
                "HPD-PLC-017",
                "HPD-PLC-025",
                "HPD-PLC-015",
            ]),
            must_fail: &["hpd/plc/vector/plc-div-79-77-80-dword"],
        },
    ]
}
