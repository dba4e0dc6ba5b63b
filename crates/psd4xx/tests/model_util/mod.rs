//! Helpers shared by the drive model tests: the spec, a drive on a virtual clock driven one
//! millisecond at a time, status-bit helpers and a readable trace.
#![allow(dead_code)]

use drivespec_positioner::{EnvChange, Flag, Micros};
use drivespec_psd4xx::model::{Drive, DriveConfig, Event, LinkEvent, RecordRequest};
use drivespec_psd4xx::{Output, Rules};
use drivespec_spec::{Family, FamilyId, Readings, Spec};
use std::fmt::Write as _;
use std::sync::OnceLock;

pub fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

pub fn family() -> &'static Family {
    spec().family(FamilyId::Psd4xx)
}

pub fn readings(choices: &[(&str, &str)]) -> Readings {
    let mut r = Readings::default();
    for (o, v) in choices {
        r.choose(family(), o, v).unwrap();
    }
    r
}

pub const MS: Micros = 1000;

/// One sample of a trace: time, position, speed, status word.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sample {
    pub t: Micros,
    pub actual: i64,
    pub speed: i64,
    pub status: u16,
}

/// A drive with a controller that sends one output image per millisecond.
pub struct Sim {
    pub drive: Drive,
    pub now: Micros,
    pub control: u16,
    pub target: i32,
    pub trace: Vec<Sample>,
    pub record: bool,
    /// The PKW block sent in every cycle.
    pub pkw: Option<drivespec_psd4xx::PkwRequest>,
}

impl Sim {
    pub fn new(model: &str) -> Sim {
        Sim::with(DriveConfig::new(model))
    }

    pub fn with(config: DriveConfig) -> Sim {
        let drive = Drive::new(spec(), config).unwrap();
        let mut s = Sim {
            drive,
            now: 0,
            control: 0,
            target: 0,
            trace: Vec::new(),
            record: false,
            pkw: None,
        };
        s.cycle();
        s
    }

    pub fn rules(&self) -> &Rules {
        self.drive.rules()
    }

    fn image(&self) -> Output {
        let idle = Output::idle(self.drive.rules());
        Output {
            control: self.control,
            target: self.target,
            pkw: self.pkw.unwrap_or(idle.pkw),
        }
    }

    /// One bus cycle at the current time: the output image goes out.
    pub fn cycle(&mut self) {
        let out = self.image();
        self.drive.handle_output(self.now, &out);
        while self.drive.poll_input().is_some() {}
        if self.record {
            self.trace.push(self.sample());
        }
    }

    pub fn sample(&self) -> Sample {
        let i = self.drive.input();
        Sample {
            t: self.now,
            actual: i64::from(i.actual),
            speed: i64::from(i.speed),
            status: i.status,
        }
    }

    /// Sets control word and target and sends them at once.
    pub fn send(&mut self, control: u16, target: i32) {
        self.control = control;
        self.target = target;
        self.cycle();
    }

    pub fn control(&mut self, control: u16) {
        self.control = control;
        self.cycle();
    }

    /// `ms` bus cycles of 1 ms.
    pub fn step(&mut self, ms: u64) {
        for _ in 0..ms {
            self.now += MS;
            self.cycle();
        }
    }

    /// Steps until `pred` holds; false after `max_ms`.
    pub fn until(&mut self, max_ms: u64, mut pred: impl FnMut(&Sim) -> bool) -> bool {
        for _ in 0..max_ms {
            if pred(self) {
                return true;
            }
            self.step(1);
        }
        pred(self)
    }

    /// Speed of the shaft in rpm, unrounded.
    pub fn rpm(&self) -> f64 {
        self.drive.core().kinematics().vel * 60.0
    }

    /// Steps `ms` times and returns the unrounded speed after each step (rpm).
    pub fn speeds(&mut self, ms: u64) -> Vec<f64> {
        (0..ms)
            .map(|_| {
                self.step(1);
                self.rpm()
            })
            .collect()
    }

    /// Steps until idle and returns (lowest, highest) position passed.
    pub fn span_until_idle(&mut self) -> (i64, i64) {
        let (mut lo, mut hi) = (self.actual(), self.actual());
        let ok = self.until(600_000, |s| {
            lo = lo.min(s.actual());
            hi = hi.max(s.actual());
            s.idle()
        });
        assert!(ok, "never stopped: {}", self.describe());
        (lo, hi)
    }

    pub fn running(&self) -> bool {
        self.bit(6)
    }

    /// No run in progress and the shaft at rest.
    pub fn idle(&self) -> bool {
        self.drive.core().is_standstill() && self.drive.core().speed_rpm() == 0
    }

    pub fn wait_running(&mut self) {
        assert!(
            self.until(10_000, |s| s.running()),
            "never ran: {}",
            self.describe()
        );
    }

    pub fn wait_idle(&mut self) {
        assert!(
            self.until(600_000, |s| s.idle()),
            "never stopped: {}",
            self.describe()
        );
    }

    pub fn env(&mut self, change: EnvChange) {
        self.drive.handle_env(self.now, change);
    }

    pub fn link(&mut self, ev: LinkEvent) {
        self.drive.handle_link(self.now, ev);
    }

    pub fn status(&self) -> u16 {
        self.drive.input().status
    }

    pub fn bit(&self, n: u32) -> bool {
        self.status() >> n & 1 == 1
    }

    pub fn flag(&self, f: Flag) -> bool {
        self.drive.core().flags().get(f)
    }

    pub fn actual(&self) -> i64 {
        self.drive.core().actual()
    }

    pub fn par(&self, pnu: u16) -> i64 {
        self.drive.parameter(pnu).unwrap()
    }

    pub fn write(&mut self, pnu: u16, value: i64) {
        self.drive
            .write_parameter(self.now, pnu, value)
            .unwrap_or_else(|e| panic!("write par {pnu} = {value}: error {}", e.0));
    }

    pub fn try_write(&mut self, pnu: u16, value: i64) -> Result<(), u32> {
        self.drive
            .write_parameter(self.now, pnu, value)
            .map_err(|e| e.0)
    }

    pub fn record(&mut self, req: RecordRequest) -> drivespec_psd4xx::model::RecordResponse {
        self.drive.handle_record(self.now, req);
        self.drive.poll_record().unwrap()
    }

    pub fn events(&mut self) -> Vec<Event> {
        std::iter::from_fn(|| self.drive.poll_event())
            .map(|(_, e)| e)
            .collect()
    }

    /// Status bits set, as numbers.
    pub fn bits(&self) -> Vec<u32> {
        (0..16).filter(|b| self.bit(*b)).collect()
    }

    pub fn describe(&self) -> String {
        format!(
            "t={} ms actual={} speed={} status={:#06x} bits={:?} run={:?}",
            self.now / MS,
            self.actual(),
            self.drive.core().speed_rpm(),
            self.status(),
            self.bits(),
            self.drive.core().run_kind()
        )
    }
}

/// A trace as text: one line per sample where something changed, plus every `every_ms`.
pub fn render(trace: &[Sample], every_ms: u64) -> String {
    let mut out = String::from("    t/ms     actual   rpm  status  bits\n");
    let mut last: Option<Sample> = None;
    for s in trace {
        let changed = match last {
            None => true,
            Some(l) => l.status != s.status || (l.speed == 0) != (s.speed == 0),
        };
        if changed || (s.t / MS) % every_ms == 0 {
            let bits: Vec<String> = (0..16)
                .filter(|b| s.status >> b & 1 == 1)
                .map(|b| b.to_string())
                .collect();
            let _ = writeln!(
                out,
                "{:>8} {:>10} {:>5}  {:#06x}  {}",
                s.t / MS,
                s.actual,
                s.speed,
                s.status,
                bits.join(",")
            );
        }
        last = Some(*s);
    }
    out
}
