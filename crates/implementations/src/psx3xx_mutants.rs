//! The PSx3xx mutants: the reference drive with one planted deviation (a wrapper around
//! `psx3xx::model::Drive`, served over the cyclic protocol in-process), shared by the mutation
//! test (`psx3xx_mutants.rs`) and the fuzzer test (`crates/fuzz/tests/fuzz_psx3xx.rs`).

use crate::{mask, spec};
use drivespec_cyclic::{CyclicDevice, Env, Reply};
use drivespec_positioner::Micros;
use drivespec_psx3xx::isdu::{Request, Target, Value};
use drivespec_psx3xx::model::{BrakeKind, Drive};
use drivespec_psx3xx::{Guards, Output, Stamp};
use drivespec_spec::{Access, Readings};

/// The 3-revolution safety margin at the delivery scaling, steps (5.5 comment 1).
const MARGIN: i64 = 1200;
/// The encoder's 256 revolutions at the delivery scaling, steps (5.5, 5.6.1).
const ENCODER: i64 = 102_400;

/// The time-stamp control code of a positioning run (3.3.1).
const POSITIONING_CODE: u8 = 3;

/// The planted deviations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A guard's suppress value is acknowledged but ignored.
    GuardIgnored,
    /// A delayed time stamp is executed while valid stamps keep coming.
    StampWhileActive,
    /// Format 2 speed 0 runs at half of ISDU 142 instead of ISDU 142.
    SpeedZeroNoFallback,
    /// IDX_NOTAVAIL answered as SUBIDX_NOTAVAIL.
    WrongErrorType,
    /// Writes to read-only entries are acknowledged (and dropped).
    ReadOnlyWritable,
    /// Out-of-range writes are acknowledged (and dropped).
    RangeIgnored,
    /// ISDU 116 takes effect at once (saved and reset behind the master's back).
    FormatSwitchImmediate,
    /// Status bit 7 (temperature) is never reported.
    TemperatureBitMissing,
    /// A power cycle loses the saved values (factory settings restored).
    SavedLostOnPowerCycle,
    /// The device ID always carries the suffix of format 1.
    DeviceIdWrongPerFormat,
    /// Control bit 6 (run without loop) is ignored.
    NoLoopIgnored,
    /// ISDU 118 writes are taken as 0 (time-out off).
    TimeoutIgnored,
    /// The jog key inputs are not seen.
    JogKeysIgnored,
    /// Length overrun and underrun ErrorTypes swapped.
    LengthErrorsSwapped,
    /// ISDU 2 values that are no command are acknowledged.
    CommandValueAccepted,
    /// Control bit 14 (clear error bits) is ignored.
    ClearErrorsIgnored,
    /// Status bits 14 and 15 (positive and negative range limit) swapped.
    LimitBitsSwapped,
    /// Not a deviation: out-of-range writes answered with PAR_VALGTLIM as hex, an ErrorType
    /// the spec accepts for them (IEC 61131-9 C.2.10).
    AcceptableVariant,
    /// ISDU reads of the actual position come 5 steps off: within the motion cases' position
    /// tolerance, not within the exact ISDU cases.
    LivePositionOffset,
    /// Control code 3 with the stamp 0x3FFF is executed at once when the code changes.
    InactiveStampRuns,
    /// Turning against the loop after a run stopped by withdrawing the release readjusts.
    ReadjustAfterAbort,
    /// Control bit 10 is taken as set: the release alone enables the readjustment.
    ReadjustBitIgnored,
    /// With control bits 4 and 5 both set, the jog keys are active (bit 5 wins).
    JogKeysWithRelease,
    /// A jog run goes on when the release replaces the jog release, until it stops by itself.
    JogKeptOnRelease,
    /// A target in a safety margin runs to the nearest limit instead of being refused.
    MarginTargetToLimit,
    /// Limit writes into the 3-revolution safety margins are acknowledged (and dropped).
    LimitIntoMarginAccepted,
    /// The status word is sent least significant byte first, the other values most
    /// significant byte first.
    StatusBytesSwapped,
    /// A drive with a snap brake readjusts: turned out of the positioning window at
    /// standstill with control bits 4 and 10 set, it runs back to its target.
    BrakeReadjusts,
}

/// A model the snap brake is offered for (manual 5.12: PSx31x-14), the default's sibling.
pub const SNAP_BRAKE_MODEL: &str = "PSE312-14";

impl Kind {
    /// The model and brake option the mutant is built with, None for the default model
    /// without brake: a run against it declares them (`--model`, `--brake`).
    pub fn brake(self) -> Option<(&'static str, BrakeKind)> {
        match self {
            Kind::BrakeReadjusts => Some((SNAP_BRAKE_MODEL, BrakeKind::Snap)),
            _ => None,
        }
    }
}

/// The reference drive with one planted deviation.
#[derive(Clone)]
pub struct Mutant<'s> {
    drive: Drive<'s>,
    kind: Kind,
    /// The time stamp armed last (time-stamp mutant).
    armed: Option<(u8, u16)>,
    /// The last format-0 output (inactive-stamp mutant).
    last_stamp: Option<(u8, u16)>,
    /// The control word passed to the drive last.
    last_control: u16,
    /// The jog control word kept while the jog runs (jog mutant).
    kept_jog: Option<u16>,
    /// The target in force and the one a readjustment runs to instead while the master keeps
    /// it (brake mutant: a target one step off is a new one, 4.5).
    readjust_to: Option<(i32, i32)>,
}

fn control_bit(drive: &Drive<'_>, name: &str) -> u16 {
    mask(drive.rules().bitfield("control"), name)
}

fn status_bit(drive: &Drive<'_>, name: &str) -> u16 {
    mask(drive.rules().status_bits(), name)
}

fn int(drive: &Drive<'_>, id: &str) -> i64 {
    match drive.value(id) {
        Value::Int(v) => v,
        other => panic!("{id} is {other:?}"),
    }
}

fn error_name(
    drive: &Drive<'_>,
    pick: fn(&drivespec_psx3xx::ErrorTypes) -> drivespec_psx3xx::ErrorType,
) -> String {
    let rules = drive.rules();
    rules
        .error_types()
        .named(pick(rules.error_known()))
        .to_string()
}

impl Mutant<'static> {
    pub fn new(kind: Kind) -> Mutant<'static> {
        let (model, brake) = kind.brake().unzip();
        // The default model, or the fixed model that may have the kind's brake (`Kind::brake`).
        let reference = drivespec_sim::reference::psx3xx(spec(), model, brake)
            .expect("a model and brake the built-in spec offers");
        Mutant {
            drive: reference.drive,
            kind,
            armed: None,
            last_stamp: None,
            last_control: 0,
            kept_jog: None,
            readjust_to: None,
        }
    }
}

impl<'s> Mutant<'s> {
    fn param_of(&self, index: u16, subindex: u8) -> Option<&'s drivespec_spec::Parameter> {
        match self.drive.rules().isdu_target(index, subindex).ok()? {
            Target::Entry { param } => Some(param),
            Target::Record { .. } => None,
        }
    }

    fn number(data: &[u8]) -> i64 {
        data.iter().fold(0i64, |a, b| (a << 8) | i64::from(*b))
    }

    /// A signed value, most significant octet first.
    fn signed(data: &[u8]) -> i64 {
        let first = data.first().map_or(0, |b| i64::from(*b as i8));
        data.iter()
            .skip(1)
            .fold(first, |a, b| (a << 8) | i64::from(*b))
    }

    /// The control-word deviations: bit 10 forced, bit 4 dropped beside bit 5, a jog word
    /// kept, a target in a safety margin moved to the limit.
    fn adjust_control(&mut self, out: &mut Output) {
        let release = control_bit(&self.drive, "Release");
        let keys = control_bit(&self.drive, "Release jog operation with keys");
        let (word, target) = match out {
            Output::ControlTarget {
                control_word,
                target,
            }
            | Output::SpeedControlTarget {
                control_word,
                target,
                ..
            } => (control_word, target),
            Output::TimeStamp { .. } => return,
        };
        if let Some((kept, instead)) = self.readjust_to {
            if *target == kept {
                *target = instead;
            } else {
                self.readjust_to = None;
            }
        }
        match self.kind {
            Kind::ReadjustBitIgnored if *word & release != 0 => {
                *word |= control_bit(&self.drive, "Readjustment");
            }
            Kind::JogKeysWithRelease if *word & (release | keys) == release | keys => {
                *word &= !release;
            }
            Kind::JogKeptOnRelease => {
                let jog = self.last_control & keys != 0 && self.last_control & release == 0;
                let running =
                    self.drive.status_word() & status_bit(&self.drive, "Drive is running") != 0;
                if jog && running && *word & release != 0 && *word & keys == 0 {
                    self.kept_jog = Some(self.last_control);
                }
                if let Some(kept) = self.kept_jog {
                    *word = kept;
                }
            }
            Kind::MarginTargetToLimit => {
                let (end, upper, lower) = (
                    int(&self.drive, "128"),
                    int(&self.drive, "129"),
                    int(&self.drive, "130"),
                );
                let margin = end - upper;
                let t = i64::from(*target);
                let transferred = *word & control_bit(&self.drive, "Transfer target values") != 0;
                let limit = if transferred && t > upper && t <= end {
                    Some(upper)
                } else if transferred && t < lower && t >= lower - margin {
                    Some(lower)
                } else {
                    None
                };
                if let Some(l) = limit.and_then(|l| i32::try_from(l).ok()) {
                    *target = l;
                }
            }
            _ => {}
        }
        self.last_control = *word;
    }
}

impl<'s> CyclicDevice<'s> for Mutant<'s> {
    fn cycle(&mut self, now: Micros, image: &[u8]) -> Result<Vec<u8>, String> {
        let rules = self.drive.rules().clone();
        let order = self.drive.byte_order();
        let mut out = Output::parse(&rules, self.drive.active_format(), order, image)
            .map_err(|e| e.to_string())?;
        let mut repeated = false;
        if let Output::TimeStamp { control, stamp } = &mut out {
            if self.kind == Kind::StampWhileActive && self.armed == Some((control.0, stamp.0)) {
                *stamp = Stamp::inactive(rules.timestamp());
                repeated = true;
            }
        }
        if let Output::TimeStamp { control, stamp } = &mut out {
            let inactive = Stamp::inactive(rules.timestamp());
            let now_seen = (control.0, stamp.0);
            if self.kind == Kind::InactiveStampRuns
                && stamp.0 == inactive.0
                && control.0 == POSITIONING_CODE
                && self
                    .last_stamp
                    .is_some_and(|(c, st)| st == inactive.0 && c != control.0)
            {
                *stamp = Stamp(0);
            }
            self.last_stamp = Some(now_seen);
        }
        self.adjust_control(&mut out);
        let mask = match self.kind {
            Kind::NoLoopIgnored => control_bit(&self.drive, "Run without loop"),
            Kind::ClearErrorsIgnored => control_bit(&self.drive, "Clear error bits"),
            _ => 0,
        };
        match &mut out {
            Output::ControlTarget { control_word, .. } => *control_word &= !mask,
            Output::SpeedControlTarget {
                control_word,
                target_speed,
                ..
            } => {
                *control_word &= !mask;
                if self.kind == Kind::SpeedZeroNoFallback && *target_speed == 0 {
                    let half = int(&self.drive, "142") / 2;
                    *target_speed = i16::try_from(half.max(1)).unwrap_or(i16::MAX);
                }
            }
            Output::TimeStamp { .. } => {}
        }
        self.drive
            .handle_output(now, &out)
            .map_err(|e| e.to_string())?;
        let mut last = None;
        while let Some((_, i)) = self.drive.poll_input() {
            last = Some(i);
        }
        if let (Kind::StampWhileActive, Output::TimeStamp { control, stamp }, false) =
            (self.kind, out, repeated)
        {
            let ts = rules.timestamp();
            let m = stamp.meaning(ts);
            if m.is_valid() && !m.is_immediate() {
                // Armed at once, and a repetition of the same stamp does not re-arm it.
                self.armed = Some((control.0, stamp.0));
                let release = Output::TimeStamp {
                    control,
                    stamp: Stamp::inactive(ts),
                };
                self.drive
                    .handle_output(now, &release)
                    .map_err(|e| e.to_string())?;
                while self.drive.poll_input().is_some() {}
            } else {
                self.armed = None;
            }
        }
        let mut input = last.unwrap_or_else(|| self.drive.input());
        if input.status & status_bit(&self.drive, "Drive is running") == 0 && input.rpm == 0 {
            self.kept_jog = None;
        }
        if self.kind == Kind::StatusBytesSwapped {
            input.status = input.status.swap_bytes();
        }
        if self.kind == Kind::TemperatureBitMissing {
            input.status &= !status_bit(&self.drive, "Temperature exceeded");
        }
        if self.kind == Kind::LimitBitsSwapped {
            let up = status_bit(&self.drive, "Positive range limit");
            let down = status_bit(&self.drive, "Negative range limit");
            let (u, d) = (input.status & up != 0, input.status & down != 0);
            input.status &= !(up | down);
            if u {
                input.status |= down;
            }
            if d {
                input.status |= up;
            }
        }
        input.to_bytes(&rules, order).map_err(|e| e.to_string())
    }

    fn advance(&mut self, now: Micros) {
        CyclicDevice::advance(&mut self.drive, now);
    }

    fn isdu(&mut self, now: Micros, req: Request) -> Reply {
        let rules = self.drive.rules().clone();
        let (index, subindex) = req.address();
        let param = self.param_of(index, subindex);
        let mut req = req;
        if let Request::Write { data, .. } = &mut req {
            match self.kind {
                Kind::GuardIgnored => {
                    let guards = Guards::from_rules(&rules, &Readings::default())
                        .expect("the built-in guard entries");
                    let hit = guards.guards().iter().any(|g| {
                        param.is_some_and(|p| {
                            p.id == g.guard
                                && p.data_type.width().map(|w| w as usize) == Some(data.len())
                        }) && Self::number(data) == g.suppress
                    });
                    if hit {
                        return Reply::Written;
                    }
                }
                Kind::ReadOnlyWritable if param.is_some_and(|p| p.access == Access::R) => {
                    return Reply::Written;
                }
                Kind::LimitIntoMarginAccepted
                    if param.is_some_and(|p| p.id == "129" || p.id == "130") =>
                {
                    let end = int(&self.drive, "128");
                    let v = Self::signed(data);
                    let upper = v > end - MARGIN && v <= end;
                    let lower = v >= end - ENCODER && v < end - ENCODER + MARGIN;
                    if upper || lower {
                        return Reply::Written;
                    }
                }
                Kind::TimeoutIgnored
                    if param.is_some_and(|p| p.id == rules.protocol().timeout.timeout_param) =>
                {
                    data.iter_mut().for_each(|b| *b = 0);
                }
                _ => {}
            }
        }
        let write = matches!(req, Request::Write { .. });
        let reply = CyclicDevice::isdu(&mut self.drive, now, req);
        let name = match &reply {
            Reply::IsduError(n) => n.clone(),
            _ => String::new(),
        };
        match self.kind {
            Kind::WrongErrorType if name == error_name(&self.drive, |k| k.idx_notavail) => {
                Reply::IsduError(error_name(&self.drive, |k| k.subidx_notavail))
            }
            Kind::LengthErrorsSwapped if name == error_name(&self.drive, |k| k.val_lenovrrun) => {
                Reply::IsduError(error_name(&self.drive, |k| k.val_lenundrun))
            }
            Kind::LengthErrorsSwapped if name == error_name(&self.drive, |k| k.val_lenundrun) => {
                Reply::IsduError(error_name(&self.drive, |k| k.val_lenovrrun))
            }
            Kind::RangeIgnored if name == error_name(&self.drive, |k| k.par_valoutofrng) => {
                Reply::Written
            }
            Kind::CommandValueAccepted if name == error_name(&self.drive, |k| k.func_notavail) => {
                Reply::Written
            }
            Kind::LivePositionOffset
                if !write && param.is_some_and(|p| p.id == "67") && subindex == 0 =>
            {
                match reply {
                    Reply::Data(d) if d.len() == 4 => {
                        let v = i32::from_be_bytes([d[0], d[1], d[2], d[3]]) + 5;
                        Reply::Data(v.to_be_bytes().to_vec())
                    }
                    other => other,
                }
            }
            Kind::AcceptableVariant if name == error_name(&self.drive, |k| k.par_valoutofrng) => {
                let above = rules
                    .error_types()
                    .code("PAR_VALGTLIM")
                    .expect("an ErrorType of the built-in table");
                Reply::IsduError(format!("0x{:04X}", above.0))
            }
            Kind::FormatSwitchImmediate
                if write
                    && reply == Reply::Written
                    && param.is_some_and(|p| p.id == rules.protocol().format_select.param) =>
            {
                let _ = self.drive.write(now, 2, 0, &Value::Int(161));
                let _ = self.drive.write(now, 2, 0, &Value::Int(128));
                while self.drive.poll_isdu().is_some() {}
                while self.drive.poll_event().is_some() {}
                reply
            }
            Kind::DeviceIdWrongPerFormat
                if !write && index == rules.protocol().direct_parameters.isdu_index =>
            {
                let dp = &rules.protocol().direct_parameters;
                let entry = dp.entries.iter().find(|e| {
                    e.name.starts_with("DeviceID") && e.address + dp.subindex_offset == subindex
                });
                match (entry, &reply) {
                    (Some(e), Reply::Data(_)) => u32::try_from(int(&self.drive, "79"))
                        .ok()
                        .and_then(|code| rules.direct_page(rules.default_format(), code).ok())
                        .and_then(|page| page.get(usize::from(e.address)).copied())
                        .map_or(reply, |b| Reply::Data(vec![b])),
                    _ => reply,
                }
            }
            _ => reply,
        }
    }

    fn env(&mut self, now: Micros, env: Env) -> bool {
        match (self.kind, env) {
            (Kind::ReadjustAfterAbort, Env::Displace(n)) => {
                let aborted = self.drive.status_word()
                    & status_bit(&self.drive, "Positioning run aborted")
                    != 0;
                let ok = CyclicDevice::env(&mut self.drive, now, env);
                let enabled =
                    control_bit(&self.drive, "Release") | control_bit(&self.drive, "Readjustment");
                let forwards = int(&self.drive, "134") == 0;
                let against = (n < 0) == forwards;
                let target = i32::try_from(self.drive.target()).ok();
                if let (true, Some(target)) = (
                    ok && aborted && against && self.last_control & enabled == enabled,
                    target,
                ) {
                    let transfer = control_bit(&self.drive, "Transfer target values");
                    for control_word in
                        [self.last_control & !transfer, self.last_control | transfer]
                    {
                        let out = Output::ControlTarget {
                            control_word,
                            target,
                        };
                        if self.drive.handle_output(now, &out).is_err() {
                            break;
                        }
                    }
                    while self.drive.poll_input().is_some() {}
                }
                ok
            }
            (Kind::BrakeReadjusts, Env::Displace(_)) => {
                let ok = CyclicDevice::env(&mut self.drive, now, env);
                let enabled =
                    control_bit(&self.drive, "Release") | control_bit(&self.drive, "Readjustment");
                let still =
                    self.drive.status_word() & status_bit(&self.drive, "Drive is running") == 0;
                let target = self.drive.target();
                let off =
                    (i64::from(self.drive.input().actual) - target).abs() > int(&self.drive, "131");
                let kept = i32::try_from(target).ok();
                if let (true, Some(kept)) = (
                    ok && still && off && self.last_control & enabled == enabled,
                    kept,
                ) {
                    let instead = kept.saturating_add(1);
                    self.readjust_to = Some((kept, instead));
                    let out = Output::ControlTarget {
                        control_word: self.last_control,
                        target: instead,
                    };
                    if self.drive.handle_output(now, &out).is_ok() {
                        while self.drive.poll_input().is_some() {}
                    }
                }
                ok
            }
            (Kind::JogKeysIgnored, Env::Keys { .. }) => true,
            (Kind::SavedLostOnPowerCycle, Env::PowerCycle) => {
                let ok = CyclicDevice::env(&mut self.drive, now, env);
                let _ = self.drive.write(now, 2, 0, &Value::Int(130));
                while self.drive.poll_isdu().is_some() {}
                while self.drive.poll_event().is_some() {}
                ok
            }
            _ => CyclicDevice::env(&mut self.drive, now, env),
        }
    }

    fn clone_box(&self) -> Box<dyn CyclicDevice<'s> + 's> {
        Box::new(self.clone())
    }
}

/// A mutant and what it must break.
pub struct Case {
    pub kind: Kind,
    pub name: &'static str,
    /// Case ID globs of which at least one case each must fail.
    pub must_fail: &'static [&'static str],
    /// The requirements the deviation breaks; every failing case must cite one.
    pub breaks: &'static [&'static str],
}

/// The mutants the conformance suite and the fuzzer must catch.
pub fn mutants() -> Vec<Case> {
    vec![
        Case {
            kind: Kind::GuardIgnored,
            name: "guard entry ignored",
            must_fail: &["psx3xx/guard/*/suppress"],
            breaks: &[
                "PSX-GUARD-66-SUPPRESS",
                "PSX-GUARD-109-SUPPRESS",
                "PSX-GUARD-111-SUPPRESS",
                "PSX-GUARD-126-SUPPRESS",
                "PSX-GUARD-ONESHOT",
            ],
        },
        Case {
            kind: Kind::StampWhileActive,
            name: "time stamp executed while active",
            must_fail: &["psx3xx/timestamp/not-while-active"],
            breaks: &["PSX-TS-004", "PSX-TS-005"],
        },
        Case {
            kind: Kind::SpeedZeroNoFallback,
            name: "8-byte speed 0 not falling back to ISDU 142",
            must_fail: &["psx3xx/format/2/speed-zero"],
            breaks: &["PSX-VEL-006"],
        },
        Case {
            kind: Kind::WrongErrorType,
            name: "wrong ErrorType for unknown indices",
            must_fail: &["psx3xx/isdu/unknown-index/*"],
            breaks: &["PSX-DP-ERR-001"],
        },
        Case {
            kind: Kind::ReadOnlyWritable,
            name: "read-only entries writable",
            must_fail: &["psx3xx/isdu/read-only/64"],
            breaks: &["PSX-DP-ERR-003"],
        },
        Case {
            kind: Kind::RangeIgnored,
            name: "range ignored",
            must_fail: &["psx3xx/isdu/write/135/above-max", "psx3xx/timeout/reserved"],
            breaks: &[
                "PSX-DP-ERR-004",
                "PSX-ISDU-*-RANGE",
                "PSX-TIMEOUT-007",
                "PSX-POS-001",
            ],
        },
        Case {
            kind: Kind::FormatSwitchImmediate,
            name: "format switch immediate",
            must_fail: &["psx3xx/format/0/switch", "psx3xx/format/2/unsaved"],
            breaks: &["PSX-PD-010", "PSX-DP-008"],
        },
        Case {
            kind: Kind::TemperatureBitMissing,
            name: "status bit 7 (temperature) missing",
            must_fail: &["psx3xx/status/temperature"],
            breaks: &["PSX-STS-7-SET-1"],
        },
        Case {
            kind: Kind::SavedLostOnPowerCycle,
            name: "saved value lost on power cycle",
            must_fail: &["psx3xx/command/saved-kept"],
            breaks: &["PSX-PAR-SAVED", "PSX-CMD-018"],
        },
        Case {
            kind: Kind::DeviceIdWrongPerFormat,
            name: "device ID wrong per format",
            must_fail: &["psx3xx/format/0/switch", "psx3xx/format/2/switch"],
            breaks: &["PSX-DP-007"],
        },
        Case {
            kind: Kind::NoLoopIgnored,
            name: "control bit 6 (no loop) ignored",
            must_fail: &["psx3xx/position/no-loop-down"],
            breaks: &["PSX-CMD-008", "PSX-RUN-007", "PSX-TS-012", "PSX-ADJ-004"],
        },
        Case {
            kind: Kind::TimeoutIgnored,
            name: "ISDU 118 time-out ignored",
            must_fail: &["psx3xx/timeout/cancel", "psx3xx/timeout/safe-position"],
            breaks: &[
                "PSX-TIMEOUT-003",
                "PSX-TIMEOUT-004",
                "PSX-TIMEOUT-005",
                "PSX-ISDU-118-RANGE",
            ],
        },
        Case {
            kind: Kind::JogKeysIgnored,
            name: "jog keys ignored",
            must_fail: &["psx3xx/status/jog-keys", "psx3xx/position/jog-step"],
            breaks: &[
                "PSX-STS-2-SET-1",
                "PSX-STS-3-SET-1",
                "PSX-JOG-005",
                "PSX-JOG-006",
                "PSX-JOG-010",
            ],
        },
        Case {
            kind: Kind::LengthErrorsSwapped,
            name: "length overrun and underrun swapped",
            must_fail: &["psx3xx/isdu/length/*/overrun"],
            breaks: &["PSX-DP-ERR-006"],
        },
        Case {
            kind: Kind::CommandValueAccepted,
            name: "ISDU 2 accepts values that are no command",
            must_fail: &["psx3xx/command/2/invalid-*"],
            breaks: &["PSX-DP-ERR-005"],
        },
        Case {
            kind: Kind::LimitBitsSwapped,
            name: "status bits 14 and 15 (range limits) swapped",
            must_fail: &["psx3xx/status/upper-limit", "psx3xx/status/lower-limit"],
            breaks: &["PSX-STS-14-*", "PSX-STS-15-*"],
        },
        Case {
            kind: Kind::ClearErrorsIgnored,
            name: "control bit 14 (clear error bits) ignored",
            must_fail: &["psx3xx/status/release-withdrawn"],
            breaks: &["PSX-CTL-14-1", "PSX-STS-5-RESET-2"],
        },
    ]
}

/// Mutants of behaviour only the suite's hand-written cases reach (a run aborted and the
/// shaft turned, a jog switched to a positioning release, a target in a safety margin, a
/// format switch before a control code): the fuzzer's bounded random runs do not.
pub fn suite_mutants() -> Vec<Case> {
    vec![
        Case {
            kind: Kind::InactiveStampRuns,
            name: "stamp 0x3FFF executed as a time stamp",
            must_fail: &["psx3xx/timestamp/inactive-value"],
            breaks: &["PSX-TS-002"],
        },
        Case {
            kind: Kind::ReadjustAfterAbort,
            name: "readjustment after a run stopped by the release",
            must_fail: &["psx3xx/position/readjust-after-abort"],
            breaks: &["PSX-ADJ-008"],
        },
        Case {
            kind: Kind::ReadjustBitIgnored,
            name: "readjustment without control bit 10",
            must_fail: &["psx3xx/position/readjust-disabled"],
            breaks: &["PSX-ADJ-009"],
        },
        Case {
            kind: Kind::JogKeysWithRelease,
            name: "jog keys active beside the release",
            must_fail: &["psx3xx/position/jog-with-release"],
            breaks: &["PSX-JOG-003"],
        },
        Case {
            kind: Kind::JogKeptOnRelease,
            name: "jog run kept when the release replaces the jog release",
            must_fail: &["psx3xx/position/jog-release-switched"],
            breaks: &["PSX-JOG-004"],
        },
        Case {
            kind: Kind::MarginTargetToLimit,
            name: "target in a safety margin run to the limit",
            must_fail: &["psx3xx/position/safety-margin"],
            breaks: &["PSX-MAP-001", "PSX-STS-12-SET-1"],
        },
        Case {
            kind: Kind::LimitIntoMarginAccepted,
            name: "limits into the safety margins acknowledged",
            must_fail: &["psx3xx/position/measuring-range"],
            breaks: &["PSX-POS-001", "PSX-MAP-005", "PSX-DP-ERR-004"],
        },
        Case {
            kind: Kind::BrakeReadjusts,
            name: "drive with a snap brake readjusting",
            must_fail: &["psx3xx/brake/no-readjustment-*"],
            breaks: &["PSX-ADJ-010"],
        },
        Case {
            kind: Kind::StatusBytesSwapped,
            name: "status word least significant byte first",
            must_fail: &["psx3xx/status/byte-order"],
            breaks: &["PSX-PD-008"],
        },
    ]
}
