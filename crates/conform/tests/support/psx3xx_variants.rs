//! PSx3xx legal variants: the reference drive changed only where the manual leaves the
//! choice to the implementation (chapter 5 fixes no reaction time; 3.1 gives identification
//! values as examples), as a second team's drive would behave.

use super::mutants::spec;
use drivespec_conform::cyclic::{CyclicDevice, Env, Reply};
use drivespec_conform::psx3xx::Psx3xxSuite;
use drivespec_conform::suite::Settings;
use drivespec_positioner::Micros;
use drivespec_psx3xx::isdu::Request;
use drivespec_psx3xx::model::Drive;
use drivespec_psx3xx::Output;
use drivespec_spec::FamilyId;
use std::collections::VecDeque;

/// A freedom the manual leaves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A new process output takes effect this many µs later.
    StartLatency(Micros),
    /// Identification values (spec `per_device`) of its own.
    OwnValues,
}

/// The reference drive with the freedom `kind` taken.
#[derive(Clone)]
pub struct Variant<'s> {
    drive: Drive<'s>,
    kind: Kind,
    /// The output image in force and the images still to take effect (due, image).
    applied: Option<Vec<u8>>,
    pending: VecDeque<(Micros, Vec<u8>)>,
}

impl Variant<'static> {
    /// The variant `kind`.
    pub fn new(kind: Kind) -> Variant<'static> {
        let suite = Psx3xxSuite::new(spec(), &Settings::default()).unwrap();
        Variant {
            drive: suite.reference().clone(),
            kind,
            applied: None,
            pending: VecDeque::new(),
        }
    }
}

impl<'s> CyclicDevice<'s> for Variant<'s> {
    fn cycle(&mut self, now: Micros, image: &[u8]) -> Result<Vec<u8>, String> {
        let rules = self.drive.rules().clone();
        let order = self.drive.byte_order();
        let mut image = image.to_vec();
        if let Kind::StartLatency(us) = self.kind {
            let last = self.pending.back().map(|p| &p.1).or(self.applied.as_ref());
            if last != Some(&image) {
                self.pending
                    .push_back((now.saturating_add(us), image.clone()));
            }
            while self.pending.front().is_some_and(|p| p.0 <= now) {
                self.applied = self.pending.pop_front().map(|p| p.1);
            }
            match &self.applied {
                Some(a) => image.clone_from(a),
                None => return self.idle(now),
            }
        }
        // An image of the format before a switch (3.3.1) is taken as its bytes in the new one.
        let out = match Output::parse(&rules, self.drive.active_format(), order, &image) {
            Ok(o) => o,
            Err(_) => return self.idle(now),
        };
        self.drive
            .handle_output(now, &out)
            .map_err(|e| e.to_string())?;
        let mut last = None;
        while let Some((_, i)) = self.drive.poll_input() {
            last = Some(i);
        }
        let input = last.unwrap_or_else(|| self.drive.input());
        input.to_bytes(&rules, order).map_err(|e| e.to_string())
    }

    fn advance(&mut self, now: Micros) {
        CyclicDevice::advance(&mut self.drive, now);
    }

    fn isdu(&mut self, now: Micros, req: Request) -> Reply {
        let (index, _) = req.address();
        let read = matches!(req, Request::Read { .. });
        match CyclicDevice::isdu(&mut self.drive, now, req) {
            Reply::Data(mut d) if self.kind == Kind::OwnValues && read && per_device(index) => {
                // Another serial number, date or version: digits stay digits.
                if let Some(b) = d.last_mut() {
                    *b = if b.is_ascii_digit() {
                        b'0' + (*b - b'0' + 1) % 10
                    } else {
                        *b ^ 1
                    };
                }
                Reply::Data(d)
            }
            other => other,
        }
    }

    fn env(&mut self, now: Micros, env: Env) -> bool {
        CyclicDevice::env(&mut self.drive, now, env)
    }

    fn clone_box(&self) -> Box<dyn CyclicDevice<'s> + 's> {
        Box::new(self.clone())
    }
}

impl Variant<'_> {
    /// The input while no output has taken effect yet: the drive as it stands.
    fn idle(&mut self, now: Micros) -> Result<Vec<u8>, String> {
        CyclicDevice::advance(&mut self.drive, now);
        let rules = self.drive.rules().clone();
        let order = self.drive.byte_order();
        self.drive
            .input()
            .to_bytes(&rules, order)
            .map_err(|e| e.to_string())
    }
}

/// Whether ISDU `index` is the device's own value (spec `per_device`).
fn per_device(index: u16) -> bool {
    spec()
        .family(FamilyId::Psx3xx)
        .parameters
        .iter()
        .any(|p| p.per_device && p.number == u32::from(index))
}

/// Every PSx3xx legal variant with its name.
pub fn variants() -> Vec<(&'static str, Kind)> {
    vec![
        ("start latency 8 ms", Kind::StartLatency(8_000)),
        ("start latency 30 ms", Kind::StartLatency(30_000)),
        ("identification of its own", Kind::OwnValues),
    ]
}
