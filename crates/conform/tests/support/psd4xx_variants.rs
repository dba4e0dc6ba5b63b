//! PSD4xx legal variants: the reference drive changed only where the manual leaves the
//! choice to the implementation (4.3 fixes maxima of acceleration and deceleration, not a
//! profile; chapter 3 fixes no reaction time), as a second team's drive would behave.

use super::mutants::spec;
use drivespec_conform::cyclic::{CyclicDevice, Env};
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
}

impl Variant {
    /// The variant `kind`.
    pub fn new(kind: Kind) -> Variant {
        let mut readings = drivespec_spec::Readings::default();
        if let Kind::Reading(option, reading) = kind {
            readings
                .choose(spec().family(FamilyId::Psd4xx), option, reading)
                .unwrap();
        }
        let config = DriveConfig::new("PSD401-5V").with_readings(readings);
        let drive = Drive::new(spec(), config).unwrap();
        Variant {
            kind,
            drive,
            applied: (0, 0),
            pending: VecDeque::new(),
            last_seen: (0, 0),
            reached_since: None,
            saving_since: None,
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
    let b = spec().family(FamilyId::Psd4xx).bitfield("status").unwrap();
    1 << b
        .bits
        .iter()
        .find(|x| x.name == "Target position reached")
        .unwrap()
        .bit
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
        let bytes = self.drive.cycle(now, &out.to_bytes(&rules).unwrap())?;
        let mut input = Input::parse(&rules, &bytes).map_err(|e| e.to_string())?;
        if let Kind::SlowSave(us) = self.kind {
            let save = rules
                .pkw()
                .encode_request(&Request::Write {
                    pnu: 96,
                    index: None,
                    width: Width::Word,
                    value: 1,
                })
                .unwrap();
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
        if self.kind == Kind::OwnValues
            && input.pkw.ak != rules.pkw().response_codes().cannot_execute
            && input.pkw.ak != rules.pkw().response_codes().no_response
            && per_device(input.pkw.pnu)
        {
            input.pkw.pwe ^= 0x0001_0005 & if input.pkw.pwe > 0xFFFF { !0 } else { 0xFFFF };
        }
        Ok(input.to_bytes(&rules).unwrap())
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
        self.drive.env(now, env)
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
        ("U_mot at the limit counts as above", Kind::UmotAtLimit(1)),
        ("U_mot at the limit counts as below", Kind::UmotAtLimit(-1)),
        (
            "par 38 writable while running",
            Kind::Reading("par38-standstill", "par-39-only"),
        ),
        ("identity and measurements of its own", Kind::OwnValues),
    ]
}
