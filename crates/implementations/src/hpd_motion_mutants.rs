//! HPD motion mutants: the reference drive with one planted deviation of its motor, its
//! operating modes or the status it reports about them (manual 3.3, 3.6), for the
//! `hpd/motion` checks (`hpd_mutants.rs`).

use crate::{hpd_target, spec};
use drivespec_hpd::model::{Drive, DriveConfig, MotionStyle, Output};
use drivespec_hpd::params::Target;
use drivespec_hpd::{parse, Data, FrameRules, Message};
use drivespec_link::Micros;
use drivespec_sim::SimDevice;
use drivespec_spec::FamilyId;

/// The planted deviations.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Ramps three times steeper than Pr8–Pr12 and Pr51 allow.
    SteepRamps,
    /// Ramps five times slower than the parameters ask.
    SlowRamps,
    /// Pr0 reports 1.5 times the speed in mode 8 (the jog runs too fast).
    FastJog,
    /// Pr6 reads 0 whatever the mode requests.
    NoModeRequest,
    /// Bit `.0` of Pb41 reads inverted.
    Bit41(u32),
    /// Pr7 reads 0 although b40.12 = 1 and b40.13 = 0.
    MainNotInternal,
    /// b70.4 is ignored: profiles always run forward.
    ReverseIgnored,
    /// A profile runs 2 % fewer steps than Pr64:65.
    ShortProfile,
    /// b70.7 reads 0 in mode 9.
    NeverBusy,
    /// Pr60:61 read as a double word reads 0 in mode 9.
    NoReference,
    /// Reset type 1 (b70.10) keeps the positions.
    ResetIgnored,
    /// Pr52 takes a write while a profile executes.
    ProfileUnlocked,
    /// b70.2 leaves Pr64:65 as it is.
    IncrementKept,
    /// The wiring test ends with code 0 although b40.9 = 1.
    WiringNoError,
    /// The mode defaults b99.11 leave Pb70 as it is.
    DefaultsKeepFlags,
    /// Reset types 1 and 3 do nothing in mode 11.
    ResetsIgnoredInMode11,
    /// Reset type 1 runs in mode 10 with the axis locked.
    ResetWhileLocked,
    /// Pr62:63 counts 1000 steps a revolution in mode 9.
    ThousandStepsPerRev,
    /// The spindle stops 300 steps past Pr54.
    OrientationOvershoot,
    /// b70.5 reads 1 in mode 12 with b40.2 = 1, whatever the position error.
    ServoErrorStuck,
    /// The mode-8 test profile takes Pr53 = 3 for 1: it starts at positive speed.
    TestStartForward,
    /// The mode-8 test profile does not pause between its strokes (Pr54 taken as 0).
    TestNoPause,
    /// The mode-8 test profile runs at the jog speed Pr50 instead of Pr51.
    TestAtJogSpeed,
}

/// A drive with a deviation of its motion.
#[derive(Clone)]
pub struct MotionMutant {
    inner: Drive,
    kind: Kind,
    rules: FrameRules,
    /// b70.3 as last seen in mode 8 (`WiringNoError`).
    testing: bool,
    /// The last request read the PLC area, whose answers are not parameter values.
    plc_read: bool,
}

/// Serial address of parameter `id`.
fn addr(id: &str) -> u8 {
    let a = spec()
        .family(FamilyId::Hpd)
        .parameter(id)
        .and_then(|p| p.address)
        .expect("a parameter of the built-in table with a serial address");
    u8::try_from(a).expect("serial addresses are bytes (manual 4.1)")
}

impl MotionMutant {
    /// The reference drive, commissioned at address 0, with the deviation `kind`.
    pub fn new(kind: Kind) -> MotionMutant {
        let ramp_percent = match kind {
            Kind::SteepRamps => 300,
            Kind::SlowRamps => 20,
            _ => 100,
        };
        let config = DriveConfig::commissioned(0).with_motion(MotionStyle {
            start_latency_us: 0,
            ramp_percent,
        });
        MotionMutant {
            inner: Drive::new(spec(), config)
                .expect("the built-in spec builds the reference drive"),
            kind,
            rules: FrameRules::from_spec(spec())
                .expect("the built-in spec has the HPD frame rules"),
            testing: false,
            plc_read: false,
        }
    }

    fn value(&self, name: &str) -> i64 {
        self.inner.value(&hpd_target(name)).unwrap_or(0)
    }

    fn mode(&self) -> i64 {
        self.value("Pr31")
    }

    /// Whether `bytes` set bit `bit` (8..15) of Pb70 with a bit change.
    fn sets_b70(&self, bytes: &[u8], bit: u32) -> bool {
        let Ok(Message::BitChange {
            par, mask, value, ..
        }) = parse(&self.rules, bytes)
        else {
            return false;
        };
        let byte =
            addr("Pb70") + u8::try_from(bit / 8).expect("callers name bits of the 16-bit Pb70");
        let m = 1u8 << (bit % 8);
        par == byte && mask & m == 0 && value & m != 0
    }

    fn rx(&mut self, now: Micros, bytes: &[u8]) {
        let mode9 = self.mode() == 9;
        match parse(&self.rules, bytes) {
            Ok(Message::ReadPlc { .. }) => self.plc_read = true,
            Ok(Message::ReadParam { .. }) => self.plc_read = false,
            _ => {}
        }
        match self.kind {
            Kind::ReverseIgnored if mode9 && self.sets_b70(bytes, 8) => {
                let dir = hpd_target("b70.4");
                let kept = self.value("b70.4");
                let _ = self.inner.set_value(now, &dir, 0);
                self.inner.handle_rx(now, bytes);
                self.inner.advance(now + 2_048);
                let _ = self.inner.set_value(now + 2_048, &dir, kept);
            }
            Kind::ShortProfile if mode9 && self.sets_b70(bytes, 8) => {
                let inc = hpd_target("Pr64:65");
                let kept = self.inner.value(&inc).unwrap_or(0);
                let _ = self.inner.set_value(now, &inc, kept * 98 / 100);
                self.inner.handle_rx(now, bytes);
                self.inner.advance(now + 2_048);
                let _ = self.inner.set_value(now + 2_048, &inc, kept);
            }
            Kind::ResetIgnored | Kind::IncrementKept
                if mode9
                    && self.sets_b70(
                        bytes,
                        if self.kind == Kind::ResetIgnored {
                            10
                        } else {
                            2
                        },
                    ) =>
            {
                let kept: Vec<(Target<'static>, i64)> = ["Pr60:61", "Pr62:63", "Pr64:65"]
                    .iter()
                    .map(|id| {
                        let t = hpd_target(id);
                        let v = self.inner.value(&t).unwrap_or(0);
                        (t, v)
                    })
                    .collect();
                self.inner.handle_rx(now, bytes);
                for (t, v) in kept {
                    let _ = self.inner.set_value(now, &t, v);
                }
            }
            Kind::ProfileUnlocked if mode9 && self.value("b70.7") == 1 => {
                self.inner.handle_rx(now, bytes);
                if let Ok(Message::WriteParam { par, data, .. }) = parse(&self.rules, bytes) {
                    if par == addr("Pr52") && data.len() == 2 {
                        let t = hpd_target("Pr52");
                        let _ = self.inner.set_value(now, &t, t.value(&data));
                    }
                }
            }
            Kind::ResetsIgnoredInMode11
                if self.mode() == 11 && (self.sets_b70(bytes, 10) || self.sets_b70(bytes, 12)) =>
            {
                let kept: Vec<(Target<'static>, i64)> = ["Pr60:61", "Pr62:63"]
                    .iter()
                    .map(|id| (hpd_target(id), self.value(id)))
                    .collect();
                self.inner.handle_rx(now, bytes);
                for (t, v) in kept {
                    let _ = self.inner.set_value(now, &t, v);
                }
            }
            Kind::ResetWhileLocked if self.mode() == 10 && self.sets_b70(bytes, 10) => {
                let lock = hpd_target("b70.8");
                let kept = self.value("b70.8");
                let _ = self.inner.set_value(now, &lock, 0);
                self.inner.handle_rx(now, bytes);
                let _ = self.inner.set_value(now, &lock, kept);
            }
            Kind::TestStartForward | Kind::TestNoPause | Kind::TestAtJogSpeed
                if self.mode() == 8 && self.sets_b70(bytes, 0) =>
            {
                let (name, v) = match self.kind {
                    Kind::TestStartForward if self.value("Pr53") == 3 => ("Pr53", 1),
                    Kind::TestStartForward => ("Pr53", self.value("Pr53")),
                    Kind::TestNoPause => ("Pr54", 0),
                    _ => ("Pr51", self.value("Pr50")),
                };
                let _ = self.inner.set_value(now, &hpd_target(name), v);
                self.inner.handle_rx(now, bytes);
            }
            Kind::DefaultsKeepFlags
                if [9, 10, 11].contains(&self.mode()) && self.sets_b99_11(bytes) =>
            {
                let flags = hpd_target("Pb70");
                let kept = self.value("Pb70");
                self.inner.handle_rx(now, bytes);
                let _ = self.inner.set_value(now, &flags, kept);
            }
            _ => self.inner.handle_rx(now, bytes),
        }
        self.watch_wiring(now);
    }

    /// Whether `bytes` set b99.11 with a bit change.
    fn sets_b99_11(&self, bytes: &[u8]) -> bool {
        let Ok(Message::BitChange {
            par, mask, value, ..
        }) = parse(&self.rules, bytes)
        else {
            return false;
        };
        par == addr("Pb99") + 1 && mask & 0x08 == 0 && value & 0x08 != 0
    }

    /// `WiringNoError`: when b70.3 drops in mode 8, Pr56 shows 0.
    fn watch_wiring(&mut self, now: Micros) {
        if self.kind != Kind::WiringNoError {
            return;
        }
        let testing = self.mode() == 8 && self.value("b70.3") == 1;
        if self.testing && !testing && self.value("Pr57") == 0 {
            let _ = self.inner.set_value(now, &hpd_target("Pr56"), 0);
        }
        self.testing = testing;
    }

    /// The deviation applied to a response.
    fn tx(&self, bytes: Vec<u8>) -> Vec<u8> {
        let Ok(Message::Response { addr: a, par, data }) = parse(&self.rules, &bytes) else {
            return bytes;
        };
        if self.plc_read {
            return bytes;
        }
        let mode = self.mode();
        let signed = |d: &Data| {
            let shift = 32 - 8 * u32::from(d.len());
            i64::from((d.signed() << shift) >> shift)
        };
        let new: Option<i64> = match self.kind {
            Kind::FastJog if mode == 8 && par == addr("Pr0") => Some(signed(&data) * 3 / 2),
            Kind::NoModeRequest if par == addr("Pr6") => Some(0),
            Kind::Bit41(b) if par == addr("Pb41") => Some(i64::from(data.unsigned() ^ (1 << b))),
            Kind::MainNotInternal if par == addr("Pr7") => Some(0),
            Kind::NeverBusy if mode == 9 && par == addr("Pb70") => {
                Some(i64::from(data.unsigned() & !(1 << 7)))
            }
            Kind::NoReference if mode == 9 && par == addr("Pr60") && data.len() == 4 => Some(0),
            Kind::ThousandStepsPerRev if mode == 9 && par == addr("Pr62") && data.len() == 4 => {
                Some(signed(&data) * 1000 / 4096)
            }
            Kind::ServoErrorStuck
                if mode == 12 && self.value("b40.2") == 1 && par == addr("Pb70") =>
            {
                Some(i64::from(data.unsigned() | 1 << 5))
            }
            Kind::OrientationOvershoot if mode == 12 && par == addr("Pr28") => {
                Some((signed(&data) + 300).rem_euclid(4096))
            }
            _ => None,
        };
        match new.and_then(|v| Data::from_value(v, data.len())) {
            Some(data) => Message::Response { addr: a, par, data }
                .to_bytes(&self.rules)
                .expect("a message of the spec's frame rules encodes"),
            None => bytes,
        }
    }
}

impl SimDevice for MotionMutant {
    fn handle_rx(&mut self, now: Micros, bytes: &[u8]) {
        self.rx(now, bytes);
    }
    fn advance(&mut self, now: Micros) {
        self.inner.advance(now);
        self.watch_wiring(now);
    }
    fn poll_output(&mut self) -> Option<Output> {
        match self.inner.poll_output()? {
            Output::Transmit { at, bytes } => Some(Output::Transmit {
                at,
                bytes: self.tx(bytes),
            }),
            o => Some(o),
        }
    }
    fn power_cycle(&mut self, now: Micros) {
        self.inner.power_cycle(now);
    }
    fn clone_box(&self) -> Box<dyn SimDevice> {
        Box::new(self.clone())
    }
    fn set_inputs(&mut self, now: Micros, inputs: u16) -> bool {
        self.inner.set_inputs(now, inputs);
        true
    }
}

/// A motion mutant with what it breaks.
pub struct Case {
    /// One line.
    pub name: &'static str,
    /// The deviation.
    pub kind: Kind,
    /// The requirement the deviation breaks, cited first by the cases in `must_fail`.
    pub first: &'static str,
    /// Every requirement the deviation breaks: every failing case must cite one.
    pub breaks: &'static [&'static str],
    /// Conformance cases that must fail, citing `first` first.
    pub must_fail: &'static [&'static str],
}

/// Every motion mutant.
pub fn motion_mutants() -> Vec<Case> {
    const SPEED: &[&str] = &[
        "HPD-MODE-8-001",
        "HPD-MODE-8-005",
        "HPD-MODE-002",
        "HPD-PAR-026",
        "HPD-PAR-027",
        "HPD-FORMULA-016",
        "HPD-MODE-9-001",
        "HPD-MODE-12-001",
    ];
    let mut out = vec![
        Case {
            name: "ramps steeper than the parameters",
            kind: Kind::SteepRamps,
            first: "HPD-PAR-026",
            breaks: &["HPD-PAR-026", "HPD-PAR-027", "HPD-MODE-9-001"],
            must_fail: &["hpd/motion/mode-8/jog-forward"],
        },
        Case {
            name: "ramps steeper than the parameters, seen on the stop ramp",
            kind: Kind::SteepRamps,
            first: "HPD-PAR-027",
            breaks: &["HPD-PAR-026", "HPD-PAR-027", "HPD-MODE-9-001"],
            must_fail: &["hpd/motion/stop-ramp"],
        },
        Case {
            name: "ramps slower than the written-down bound",
            kind: Kind::SlowRamps,
            first: "HPD-FORMULA-016",
            breaks: SPEED,
            must_fail: &["hpd/motion/mode-8/jog-forward"],
        },
        Case {
            name: "Pr0 reports 1.5 × the speed in mode 8, seen on the jog",
            kind: Kind::FastJog,
            first: "HPD-MODE-8-001",
            breaks: SPEED,
            must_fail: &["hpd/motion/mode-8/jog-forward"],
        },
        Case {
            name: "Pr0 reports 1.5 × the speed in mode 8, seen with b40.2 = 0",
            kind: Kind::FastJog,
            first: "HPD-MODE-002",
            breaks: SPEED,
            must_fail: &["hpd/motion/reference-select"],
        },
        Case {
            name: "Pr6 does not show the mode's request",
            kind: Kind::NoModeRequest,
            first: "HPD-MODE-001",
            breaks: &["HPD-MODE-001"],
            must_fail: &["hpd/motion/mode-8/jog-forward"],
        },
        Case {
            name: "Pr7 does not follow Pr5",
            kind: Kind::MainNotInternal,
            first: "HPD-FORMULA-007",
            breaks: &["HPD-FORMULA-007"],
            must_fail: &["hpd/motion/reference-select"],
        },
        Case {
            name: "profiles ignore b70.4",
            kind: Kind::ReverseIgnored,
            first: "HPD-MODE-9-002",
            breaks: &["HPD-MODE-9-002", "HPD-MODE-9-001", "HPD-MODE-POSITION"],
            must_fail: &["hpd/motion/mode-9/profile-reverse"],
        },
        Case {
            name: "profiles stop 2 % short",
            kind: Kind::ShortProfile,
            first: "HPD-MODE-9-001",
            breaks: &["HPD-MODE-9-001", "HPD-MODE-POSITION"],
            must_fail: &["hpd/motion/mode-9/profile-forward"],
        },
        Case {
            name: "b70.7 never set",
            kind: Kind::NeverBusy,
            first: "HPD-MODE-9-PROFILE-BUSY",
            breaks: &["HPD-MODE-9-PROFILE-BUSY"],
            must_fail: &[
                "hpd/motion/mode-9/profile-forward",
                "hpd/motion/mode-9/locked-while-busy",
            ],
        },
        Case {
            name: "Pr60:61 not the position reference",
            kind: Kind::NoReference,
            first: "HPD-MODE-POSITION",
            breaks: &["HPD-MODE-POSITION"],
            must_fail: &["hpd/motion/mode-9/profile-forward"],
        },
        Case {
            name: "reset type 1 ignored",
            kind: Kind::ResetIgnored,
            first: "HPD-MODE-9-006",
            breaks: &["HPD-MODE-9-006"],
            must_fail: &["hpd/motion/mode-9/profile-forward"],
        },
        Case {
            name: "Pr52 writable during a profile",
            kind: Kind::ProfileUnlocked,
            first: "HPD-PAR-059",
            breaks: &["HPD-PAR-059"],
            must_fail: &["hpd/motion/mode-9/locked-while-busy"],
        },
        Case {
            name: "b70.2 keeps Pr64:65",
            kind: Kind::IncrementKept,
            first: "HPD-MODE-9-005",
            breaks: &["HPD-MODE-9-005"],
            must_fail: &["hpd/motion/mode-9/b70.2-clears-increment"],
        },
        Case {
            name: "wiring test reports no error with b40.9 = 1",
            kind: Kind::WiringNoError,
            first: "HPD-MODE-8-004",
            breaks: &["HPD-MODE-8-004"],
            must_fail: &["hpd/motion/mode-8/wiring-test-enabled"],
        },
        Case {
            name: "b99.11 keeps b70.6 in mode 9",
            kind: Kind::DefaultsKeepFlags,
            first: "HPD-MODE-9-007",
            breaks: &["HPD-MODE-9-007", "HPD-MODE-10-008"],
            must_fail: &["hpd/motion/mode-9/feed-forward-default"],
        },
        Case {
            name: "b99.11 keeps b70.6 in mode 10",
            kind: Kind::DefaultsKeepFlags,
            first: "HPD-MODE-10-008",
            breaks: &["HPD-MODE-9-007", "HPD-MODE-10-008"],
            must_fail: &["hpd/motion/mode-10/feed-forward-default"],
        },
        Case {
            name: "reset types ignored in mode 11",
            kind: Kind::ResetsIgnoredInMode11,
            first: "HPD-MODE-11-004",
            breaks: &["HPD-MODE-11-004"],
            must_fail: &["hpd/motion/mode-11/resets"],
        },
        Case {
            name: "reset type 1 with the axis locked in mode 10",
            kind: Kind::ResetWhileLocked,
            first: "HPD-MODE-10-007",
            breaks: &["HPD-MODE-10-007"],
            must_fail: &["hpd/motion/mode-10/reset-only-released"],
        },
        Case {
            name: "1000 position steps a revolution",
            kind: Kind::ThousandStepsPerRev,
            first: "HPD-FORMULA-017",
            breaks: &["HPD-FORMULA-017", "HPD-MODE-9-001", "HPD-MODE-POSITION"],
            must_fail: &["hpd/motion/mode-9/profile-forward"],
        },
        Case {
            name: "spindle stops 300 steps past Pr54",
            kind: Kind::OrientationOvershoot,
            first: "HPD-MODE-12-001",
            breaks: &["HPD-MODE-12-001"],
            must_fail: &["hpd/motion/mode-12/orientation"],
        },
        Case {
            name: "mode-8 test profile starts forward with Pr53 = 3",
            kind: Kind::TestStartForward,
            first: "HPD-MODE-8-006",
            breaks: &["HPD-MODE-8-006"],
            must_fail: &["hpd/motion/mode-8/profile-start-3"],
        },
        Case {
            name: "mode-8 test profile without its Pr54 pause",
            kind: Kind::TestNoPause,
            first: "HPD-MODE-8-005",
            breaks: &["HPD-MODE-8-005"],
            must_fail: &[
                "hpd/motion/mode-8/profile-start-1",
                "hpd/motion/mode-8/profile-start-3",
            ],
        },
        Case {
            name: "mode-8 test profile at the jog speed Pr50",
            kind: Kind::TestAtJogSpeed,
            first: "HPD-MODE-8-005",
            breaks: &["HPD-MODE-8-005"],
            must_fail: &["hpd/motion/mode-8/profile-start-2"],
        },
        Case {
            name: "b70.5 reads 1 in mode 12 with the loop closed",
            kind: Kind::ServoErrorStuck,
            first: "HPD-MODE-12-SERVO-ERROR",
            breaks: &["HPD-MODE-12-SERVO-ERROR"],
            must_fail: &["hpd/motion/mode-12/orientation"],
        },
    ];
    for (bit, name, first) in [
        (0, "b41.0 inverted", "HPD-BIT-41-0"),
        (1, "b41.1 inverted", "HPD-BIT-41-1"),
        (2, "b41.2 inverted", "HPD-BIT-41-2"),
        (3, "b41.3 inverted", "HPD-BIT-41-3"),
    ] {
        out.push(Case {
            name,
            kind: Kind::Bit41(bit),
            first,
            breaks: match bit {
                0 => &["HPD-BIT-41-0"],
                1 => &["HPD-BIT-41-1"],
                2 => &["HPD-BIT-41-2"],
                _ => &["HPD-BIT-41-3"],
            },
            must_fail: &["hpd/motion/mode-8/jog-forward"],
        });
    }
    out
}
