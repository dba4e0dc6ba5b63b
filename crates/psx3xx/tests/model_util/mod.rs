//! Helpers shared by the PSx3xx drive model tests: the spec, a master that sends one process
//! image per IO-Link cycle on a virtual clock, ISDU access, status-bit helpers and a readable
//! trace.
#![allow(dead_code)]

use drivespec_positioner::{EnvChange, Micros};
use drivespec_psx3xx::isdu::{Response, Value};
use drivespec_psx3xx::model::{Drive, DriveConfig, JogKeys, LinkEvent, RunState};
use drivespec_psx3xx::{Output, Rules, Stamp, TsCode};
use drivespec_spec::{Family, FamilyId, Readings, Spec};
use std::fmt::Write as _;
use std::sync::OnceLock;

pub fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

pub fn family() -> &'static Family {
    spec().family(FamilyId::Psx3xx)
}

pub fn readings(choices: &[(&str, &str)]) -> Readings {
    let mut r = Readings::default();
    for (o, v) in choices {
        r.choose(family(), o, v).unwrap();
    }
    r
}

pub const MS: Micros = 1000;
/// The IO-Link cycle of the tests: the device's MinCycleTime 8 ms (3.1 ISDU 0 sub 3).
pub const CYCLE: Micros = 8 * MS;

/// One sample of a trace: time, position, speed, status word, run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sample {
    pub t: Micros,
    pub actual: i64,
    pub rpm: i64,
    pub status: u16,
    pub run: &'static str,
}

/// A drive with a master that sends its process output image once per cycle.
pub struct Sim {
    pub drive: Drive<'static>,
    pub now: Micros,
    /// The image sent every cycle; None: the master sends nothing.
    pub out: Option<Output>,
    pub trace: Vec<Sample>,
    pub record: bool,
}

pub fn bit(status: u16, n: u32) -> bool {
    status >> n & 1 == 1
}

impl Sim {
    pub fn new(model: &str) -> Sim {
        Sim::with(DriveConfig::new(model))
    }

    pub fn with(config: DriveConfig) -> Sim {
        Sim {
            drive: Drive::new(spec(), config).unwrap(),
            now: 0,
            out: None,
            trace: Vec::new(),
            record: false,
        }
    }

    pub fn rules(&self) -> &Rules<'static> {
        self.drive.rules()
    }

    /// Sets the format 1 image and sends it at once.
    pub fn f1(&mut self, control_word: u16, target: i32) {
        self.send(Output::ControlTarget {
            control_word,
            target,
        });
    }

    /// Sets the format 2 image and sends it at once.
    pub fn f2(&mut self, target_speed: i16, control_word: u16, target: i32) {
        self.send(Output::SpeedControlTarget {
            target_speed,
            control_word,
            target,
        });
    }

    /// Sets the format 0 image and sends it at once.
    pub fn f0(&mut self, control: u8, stamp: u16) {
        self.send(Output::TimeStamp {
            control: TsCode(control),
            stamp: Stamp(stamp),
        });
    }

    pub fn send(&mut self, out: Output) {
        self.out = Some(out);
        self.drive.handle_output(self.now, &out).unwrap();
        self.sample();
    }

    pub fn write(&mut self, index: u16, value: i64) -> Response {
        let v = Value::Int(value);
        let r = self.drive.write(self.now, index, 0, &v).unwrap();
        self.sample();
        r
    }

    pub fn write_ok(&mut self, index: u16, value: i64) {
        let r = self.write(index, value);
        assert_eq!(r, Response::Write, "write ISDU {index} = {value}");
    }

    pub fn read(&self, index: u16) -> i64 {
        match self.drive.read(index, 0).unwrap() {
            Value::Int(v) => v,
            other => panic!("ISDU {index} reads {other:?}"),
        }
    }

    pub fn env(&mut self, change: EnvChange) {
        self.drive.handle_env(self.now, change);
        self.sample();
    }

    pub fn keys(&mut self, keys: JogKeys) {
        self.drive.handle_keys(self.now, keys);
        self.sample();
    }

    pub fn link(&mut self, ev: LinkEvent) {
        self.drive.handle_link(self.now, ev);
    }

    /// Runs `ms` milliseconds, the master sending its image every cycle while the link is up.
    pub fn run_ms(&mut self, ms: u64) {
        let end = self.now + ms * MS;
        while self.now < end {
            let step = (CYCLE - self.now % CYCLE).min(end - self.now);
            let next = self.now + step;
            if self.record {
                let mut t = self.now;
                while t + MS <= next {
                    t += MS;
                    self.drive.advance(t);
                    self.now = t;
                    self.sample();
                }
            }
            self.now = next;
            self.drive.advance(self.now);
            if self.now % CYCLE == 0 && self.drive.link_up() {
                if let Some(out) = self.out {
                    self.drive.handle_output(self.now, &out).unwrap();
                }
            }
            while self.drive.poll_input().is_some() {}
            while self.drive.poll_isdu().is_some() {}
            self.sample();
        }
    }

    /// Runs until `pred` holds, at most `max_ms`; returns the elapsed ms or panics.
    pub fn until(&mut self, max_ms: u64, pred: impl Fn(&Drive) -> bool) -> u64 {
        let start = self.now;
        while !pred(&self.drive) {
            assert!(
                self.now - start < max_ms * MS,
                "condition not reached in {max_ms} ms (run {:?}, actual {}, status {:#06x})",
                self.drive.run_state(),
                self.actual(),
                self.status()
            );
            self.run_ms(1);
        }
        (self.now - start) / MS
    }

    /// Runs until the drive stands still and no timer is due (at most `max_ms`).
    pub fn settle(&mut self, max_ms: u64) {
        self.until(max_ms, |d| d.run_state() == RunState::Idle);
        self.run_ms(20);
    }

    pub fn actual(&self) -> i64 {
        self.drive.core().actual()
    }

    pub fn status(&self) -> u16 {
        self.drive.status_word()
    }

    pub fn bit(&self, n: u32) -> bool {
        bit(self.status(), n)
    }

    pub fn run(&self) -> &'static str {
        self.drive.run_state().name()
    }

    pub fn sample(&mut self) {
        if !self.record {
            return;
        }
        let s = Sample {
            t: self.now,
            actual: self.actual(),
            rpm: self.drive.core().speed_rpm(),
            status: self.status(),
            run: self.run(),
        };
        if self
            .trace
            .last()
            .map(|l| (l.actual, l.rpm, l.status, l.run))
            != Some((s.actual, s.rpm, s.status, s.run))
        {
            self.trace.push(s);
        }
    }

    /// The trace thinned to changes of the status word or run and every `every_ms`.
    pub fn trace_text(&self, every_ms: u64) -> String {
        let mut out = String::from("    t/ms   actual    rpm  status  run\n");
        let mut last: Option<&Sample> = None;
        for s in &self.trace {
            let keep = match last {
                None => true,
                Some(l) => {
                    l.status != s.status || l.run != s.run || s.t / MS >= l.t / MS + every_ms
                }
            };
            if keep {
                let _ = writeln!(
                    out,
                    "{:>8} {:>8} {:>6}  {:#06x}  {}",
                    s.t / MS,
                    s.actual,
                    s.rpm,
                    s.status,
                    s.run
                );
                last = Some(s);
            }
        }
        if let Some(s) = self.trace.last().filter(|s| last.map(|l| l.t) != Some(s.t)) {
            let _ = writeln!(
                out,
                "{:>8} {:>8} {:>6}  {:#06x}  {}",
                s.t / MS,
                s.actual,
                s.rpm,
                s.status,
                s.run
            );
        }
        out
    }
}
