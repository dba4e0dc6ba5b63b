//! PSD4xx legal variants: the reference drive changed only where the manual leaves the
//! choice to the implementation (4.3 fixes maxima of acceleration and deceleration, not a
//! profile; chapter 3 fixes no reaction time), as a second team's drive would behave.

use crate::{psd4xx_bit, spec};
use drivespec_cyclic::{CyclicDevice, Env};
use drivespec_positioner::Micros;
use drivespec_psd4xx::model::{Drive, DriveConfig, RecordAnswer, RecordFailure, RecordRequest};
use drivespec_psd4xx::{Input, Output, PkwResponse, Request, Width};
use drivespec_spec::FamilyId;
use std::collections::VecDeque;

/// A freedom the manual leaves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A new control word or target takes effect this many µs later.
    StartLatency(Micros),
    /// Status bit 0 is reported this many µs after the drive has arrived (an encoder check).
    ReachedLater(Micros),
    /// A save (par 96 = 1) is answered this many µs after the command came (4.7: "can take up
    /// to 1 second"); meanwhile the drive answers "no response".
    SlowSave(Micros),
    /// Identity and measured values (spec `per_device`) of its own: another serial number,
    /// production date, version, temperature, current.
    OwnValues,
    /// The other reading (second field) of a selectable erratum (first field, spec `option`).
    Reading(&'static str, &'static str),
    /// A motor voltage exactly at the UMot limit (par 90) counts as this many 0.1 V above it
    /// (3.6 leaves the limit itself open).
    UmotAtLimit(i16),
    /// The shaft follows the trapezoid through a filter of its own (4.3 fixes only the maximum
    /// acceleration and deceleration and a deceleration "successively reduced"): the run is
    /// reported ended, and live values are read, from the filtered motion.
    Shaft(Filter),
    /// A run command refused for want of motor voltage (status bit 13) starts once the
    /// voltage is back while the release stays set (3.3 par 90 and 3.6 bit 13 do not say
    /// whether the command is dropped): the release is withdrawn for one cycle and set again,
    /// which starts the run to the last target (4.1).
    DeferredRun,
}

/// How the shaft follows the drive's trapezoid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Filter {
    /// The mean over this many bus cycles: an S-curve. The trapezoid averaged over a window
    /// of T is the jerk-limited profile whose acceleration rises to the maximum of par 38/39
    /// in T and falls back in T (jerk = maximum / T), never above it, and ends at the same
    /// position without overshoot (the smoothing filter servo drives put behind their
    /// trapezoid generator).
    Mean(usize),
    /// A first-order lag with this time constant (µs): a braking tail of its own.
    Lag(Micros),
}

/// The shaft of a [`Kind::Shaft`] variant: its own position and speed, and the status word it
/// holds while it still moves after the trapezoid has ended.
#[derive(Clone, Default)]
struct Shaft {
    /// Position (increments) and speed (rpm).
    pos: f64,
    speed: f64,
    /// The trapezoid's last samples (position, speed), newest last.
    samples: VecDeque<(f64, f64)>,
    /// The trapezoid's sample of the cycle before.
    before: Option<(f64, f64)>,
    last: Option<Micros>,
    /// The status word of the last cycle the trapezoid ran.
    running_status: Option<u16>,
    /// The PKW response as the drive gave it, and as the variant answers it.
    pkw: Option<(PkwResponse, PkwResponse)>,
}

impl Shaft {
    /// The shaft after the trapezoid's sample `(pos, speed)` at `now`.
    fn follow(&mut self, filter: Filter, now: Micros, pos: f64, speed: f64) {
        // A position that changes without motion is a new frame (par 3, 38-41 written): the
        // shaft has not moved, its position shifts with the frame.
        if let Some((p, _)) = self
            .before
            .filter(|(p, v)| *v == 0.0 && speed == 0.0 && *p != pos)
        {
            let shift = pos - p;
            self.pos += shift;
            for s in &mut self.samples {
                s.0 += shift;
            }
        }
        self.before = Some((pos, speed));
        // The first sample: the shaft stands where the drive starts.
        if self.last.is_none() {
            self.snap(pos, speed);
        }
        match filter {
            Filter::Mean(n) => {
                self.samples.push_back((pos, speed));
                while self.samples.len() > n.max(1) {
                    self.samples.pop_front();
                }
                let k = self.samples.len().max(1) as f64;
                self.pos = self.samples.iter().map(|s| s.0).sum::<f64>() / k;
                self.speed = self.samples.iter().map(|s| s.1).sum::<f64>() / k;
            }
            Filter::Lag(tau) => {
                let dt = now.saturating_sub(self.last.unwrap_or(now)) as f64;
                let a = 1.0 - (-dt / tau.max(1) as f64).exp();
                self.pos += a * (pos - self.pos);
                self.speed += a * (speed - self.speed);
            }
        }
        self.last = Some(now);
        // Within half an increment and half an rpm the shaft stands on the trapezoid's end.
        if (pos - self.pos).abs() < 0.5 && (speed - self.speed).abs() < 0.5 {
            self.snap(pos, speed);
        }
    }

    /// The shaft where the trapezoid is (power-up, a displacement by hand): the trapezoid's
    /// sample too, so the next one is no new frame.
    fn snap(&mut self, pos: f64, speed: f64) {
        self.pos = pos;
        self.speed = speed;
        self.before = Some((pos, speed));
        self.samples.clear();
        self.samples.push_back((pos, speed));
    }

    fn settled(&self, pos: f64, speed: f64) -> bool {
        self.pos == pos && self.speed == speed
    }
}

/// The reference PSD 401 with the freedom `kind` taken.
#[derive(Clone)]
pub struct Variant {
    kind: Kind,
    drive: Drive,
    /// Control word and target in force, and the changes still to take effect (due, control,
    /// target).
    applied: (u16, i32),
    pending: VecDeque<(Micros, u16, i32)>,
    last_seen: (u16, i32),
    /// Since when bit 0 has been set by the drive.
    reached_since: Option<Micros>,
    /// Since when the save command in force came.
    saving_since: Option<Micros>,
    shaft: Shaft,
    /// The control word and status word of the cycle before.
    last: (u16, u16),
    /// Whether a run command was refused for want of motor voltage, the release still set.
    refused: bool,
    /// Cycles left of the release withdrawn and set again that start a refused run.
    restart: u8,
}

impl Variant {
    /// The variant `kind`.
    pub fn new(kind: Kind) -> Variant {
        let mut readings = drivespec_spec::Readings::default();
        if let Kind::Reading(option, reading) = kind {
            readings
                .choose(spec().family(FamilyId::Psd4xx), option, reading)
                .expect("an option and reading of the built-in errata");
        }
        let config = DriveConfig::new("PSD401-5V").with_readings(readings);
        let drive =
            Drive::new(spec(), config).expect("the built-in spec builds the reference drive");
        Variant {
            kind,
            drive,
            applied: (0, 0),
            pending: VecDeque::new(),
            last_seen: (0, 0),
            reached_since: None,
            saving_since: None,
            shaft: Shaft::default(),
            last: (0, 0),
            refused: false,
            restart: 0,
        }
    }
}

/// Whether parameter `number` is the device's own value (spec `per_device`).
fn per_device(number: u16) -> bool {
    spec()
        .family(FamilyId::Psd4xx)
        .parameters
        .iter()
        .any(|p| p.per_device && p.number == u32::from(number))
}

fn reached_bit() -> u16 {
    psd4xx_bit("status", "Target position reached")
}

impl Variant {
    /// The input image of a [`Kind::Shaft`] variant: position and speed of its own shaft;
    /// while the shaft still moves after the trapezoid ended, the status word of the run;
    /// a read of the status word, speed or actual value answered with its own value of the
    /// moment and held while the command is repeated.
    fn shaft_input(
        &mut self,
        filter: Filter,
        now: Micros,
        rules: &drivespec_psd4xx::Rules,
        input: &mut Input,
    ) {
        let (pos, speed) = (f64::from(input.actual), f64::from(input.speed));
        self.shaft.follow(filter, now, pos, speed);
        let running = input.status & running_bit() != 0;
        if running {
            self.shaft.running_status = Some(input.status);
        } else if self.shaft.settled(pos, speed) {
            self.shaft.running_status = None;
        } else if let Some(status) = self.shaft.running_status {
            input.status = status;
        }
        input.actual = self.shaft.pos.round() as i32;
        input.speed = self.shaft.speed.round() as i16;
        let raw = input.pkw;
        if let Some((_, answer)) = self.shaft.pkw.filter(|(b, _)| *b == raw) {
            input.pkw = answer;
            return;
        }
        let pkw = rules.pkw();
        if let Some(drivespec_psd4xx::Reply::Value {
            pnu,
            index: None,
            width,
            ..
        }) = pkw.reply(&raw)
        {
            let own = match pnu {
                1 => Some(i64::from(input.status)),
                2 => Some(i64::from(input.speed)),
                3 => Some(i64::from(input.actual)),
                _ => None,
            };
            if let Some(value) = own {
                let reply = drivespec_psd4xx::Reply::Value {
                    pnu,
                    index: None,
                    width,
                    value,
                };
                if let Ok(r) = pkw.encode_reply(&reply) {
                    input.pkw = r;
                }
            }
        }
        self.shaft.pkw = Some((raw, input.pkw));
    }
}

fn running_bit() -> u16 {
    psd4xx_bit("status", "Drive is running")
}

impl CyclicDevice<'static> for Variant {
    fn cycle(&mut self, now: Micros, image: &[u8]) -> Result<Vec<u8>, String> {
        let rules = self.drive.rules().clone();
        let mut out = Output::parse(&rules, image).map_err(|e| e.to_string())?;
        if let Kind::StartLatency(us) = self.kind {
            let seen = (out.control, out.target);
            if seen != self.last_seen {
                self.pending
                    .push_back((now.saturating_add(us), seen.0, seen.1));
                self.last_seen = seen;
            }
            while self.pending.front().is_some_and(|p| p.0 <= now) {
                if let Some((_, c, t)) = self.pending.pop_front() {
                    self.applied = (c, t);
                }
            }
            (out.control, out.target) = self.applied;
        }
        let release = psd4xx_bit("control", "Release");
        let sent = out.control;
        if self.restart == 2 {
            out.control &= !release;
        }
        self.restart = self.restart.saturating_sub(1);
        let bytes = self.drive.cycle(
            now,
            &out.to_bytes(&rules)
                .expect("an image of the spec's layout encodes"),
        )?;
        let mut input = Input::parse(&rules, &bytes).map_err(|e| e.to_string())?;
        if self.kind == Kind::DeferredRun {
            let missing = psd4xx_bit("status", "Motor voltage was missing");
            let command = sent != self.last.0 && sent & release != 0;
            if sent & release == 0 || input.status & running_bit() != 0 {
                self.refused = false;
            } else if command && input.status & missing != 0 && self.last.1 & missing == 0 {
                self.refused = true;
            } else if self.refused
                && input.status & psd4xx_bit("status", "Power supply to motor available") != 0
            {
                self.refused = false;
                self.restart = 2;
            }
            self.last = (sent, input.status);
        }
        if let Kind::SlowSave(us) = self.kind {
            let save = rules
                .pkw()
                .encode_request(&Request::Write {
                    pnu: 96,
                    index: None,
                    width: Width::Word,
                    value: 1,
                })
                .expect("par 96 is a writable word of the built-in table");
            if out.pkw == save {
                let since = *self.saving_since.get_or_insert(now);
                if now.saturating_sub(since) < us {
                    input.pkw = PkwResponse::default();
                }
            } else {
                self.saving_since = None;
            }
        }
        if let Kind::ReachedLater(us) = self.kind {
            let bit = reached_bit();
            if input.status & bit != 0 {
                let since = *self.reached_since.get_or_insert(now);
                if now.saturating_sub(since) < us {
                    input.status &= !bit;
                }
            } else {
                self.reached_since = None;
            }
        }
        if let Kind::Shaft(filter) = self.kind {
            self.shaft_input(filter, now, &rules, &mut input);
        }
        if self.kind == Kind::OwnValues
            && input.pkw.ak != rules.pkw().response_codes().cannot_execute
            && input.pkw.ak != rules.pkw().response_codes().no_response
            && per_device(input.pkw.pnu)
        {
            input.pkw.pwe ^= 0x0001_0005 & if input.pkw.pwe > 0xFFFF { !0 } else { 0xFFFF };
        }
        Ok(input
            .to_bytes(&rules)
            .expect("an image of the spec's layout encodes"))
    }

    fn advance(&mut self, now: Micros) {
        CyclicDevice::advance(&mut self.drive, now);
    }

    fn record(
        &mut self,
        now: Micros,
        req: RecordRequest,
    ) -> Option<Result<RecordAnswer, RecordFailure>> {
        let index = match &req {
            RecordRequest::Read { index } => Some(*index),
            RecordRequest::Write { .. } => None,
        };
        match (self.kind, self.drive.record(now, req)) {
            (Kind::OwnValues, Some(Ok(RecordAnswer::Data { mut bytes })))
                if index.is_some_and(per_device) =>
            {
                if let Some(b) = bytes.first_mut() {
                    *b ^= 0x01;
                }
                Some(Ok(RecordAnswer::Data { bytes }))
            }
            (_, r) => r,
        }
    }

    fn env(&mut self, now: Micros, env: Env) -> bool {
        let env = match (self.kind, env) {
            (Kind::UmotAtLimit(by), Env::MotorVoltage(v))
                if self.drive.parameter(90).ok() == Some(i64::from(v)) =>
            {
                Env::MotorVoltage(v.saturating_add_signed(by))
            }
            (_, e) => e,
        };
        let taken = self.drive.env(now, env);
        if matches!(self.kind, Kind::Shaft(_)) {
            let i = self.drive.input();
            self.shaft.snap(f64::from(i.actual), f64::from(i.speed));
        }
        taken
    }

    fn clone_box(&self) -> Box<dyn CyclicDevice<'static>> {
        Box::new(self.clone())
    }
}

/// Every PSD4xx legal variant with its name.
pub fn variants() -> Vec<(&'static str, Kind)> {
    vec![
        ("start latency 1 ms", Kind::StartLatency(1_000)),
        ("start latency 3 ms", Kind::StartLatency(3_000)),
        ("start latency 10 ms", Kind::StartLatency(10_000)),
        ("start latency 30 ms", Kind::StartLatency(30_000)),
        ("bit 0 10 ms after arrival", Kind::ReachedLater(10_000)),
        ("save answered after 900 ms", Kind::SlowSave(900_000)),
        ("save answered after 1 s", Kind::SlowSave(1_000_000)),
        ("S-curve (mean over 50 ms)", Kind::Shaft(Filter::Mean(5))),
        ("braking tail 22 ms", Kind::Shaft(Filter::Lag(22_000))),
        ("braking tail 18 ms", Kind::Shaft(Filter::Lag(18_000))),
        ("U_mot at the limit counts as above", Kind::UmotAtLimit(1)),
        ("U_mot at the limit counts as below", Kind::UmotAtLimit(-1)),
        (
            "par 38 writable while running",
            Kind::Reading("par38-standstill", "par-39-only"),
        ),
        ("identity and measurements of its own", Kind::OwnValues),
        ("run refused without U_mot deferred", Kind::DeferredRun),
    ]
}
