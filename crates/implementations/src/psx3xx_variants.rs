//! PSx3xx legal variants: the reference drive changed only where the manual leaves the
//! choice to the implementation (chapter 5 fixes no reaction time; 3.1 gives identification
//! values as examples and lets a save take up to 2000 ms), as a second team's drive would
//! behave.

use crate::{mask, spec};
use drivespec_cyclic::{CyclicDevice, Env, Reply};
use drivespec_positioner::Micros;
use drivespec_psx3xx::isdu::Request;
use drivespec_psx3xx::model::{BrakeKind, Drive};
use drivespec_psx3xx::Output;
use drivespec_sim::reference::ReferenceError;
use drivespec_spec::FamilyId;
use std::collections::VecDeque;

/// A freedom the manual leaves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// A new process output takes effect this many µs later.
    StartLatency(Micros),
    /// Identification values (spec `per_device`) of its own.
    OwnValues,
    /// A save to EEPROM takes this many µs; ISDU 193 reads 1 until it is finished (3.1: "≠ 0
    /// → Save is still running").
    SaveTime(Micros),
    /// Status bit 11 set whenever the shaft is turned at standstill by more than the
    /// positioning window, also after a run stopped by withdrawing the release (3.4 bit 11
    /// names no completed run), until the next run.
    DisplacedAfterAbort,
}

/// The reference drive with the freedom `kind` taken.
#[derive(Clone)]
pub struct Variant<'s> {
    drive: Drive<'s>,
    kind: Kind,
    /// The output image in force and the images still to take effect (due, image).
    applied: Option<Vec<u8>>,
    pending: VecDeque<(Micros, Vec<u8>)>,
    /// When the save in progress is finished.
    saving_until: Option<Micros>,
    /// The shaft was turned beyond the window after an aborted run (bit 11 shown).
    displaced: bool,
}

impl Variant<'static> {
    /// The variant `kind`.
    pub fn new(kind: Kind) -> Variant<'static> {
        // The default model without brake, which the built-in spec always builds.
        let reference = drivespec_sim::reference::psx3xx(spec(), None, None)
            .expect("a model and brake the built-in spec offers");
        Variant::on(kind, reference.drive)
    }

    /// The variant `kind` built on `model` with its brake option (manual 5.11–5.13); an
    /// unknown model or a brake the model cannot have is the reference's error.
    pub fn with_brake(
        kind: Kind,
        model: &str,
        brake: BrakeKind,
    ) -> Result<Variant<'static>, ReferenceError> {
        let reference = drivespec_sim::reference::psx3xx(spec(), Some(model), Some(brake))?;
        Ok(Variant::on(kind, reference.drive))
    }

    fn on(kind: Kind, drive: Drive<'static>) -> Variant<'static> {
        Variant {
            drive,
            kind,
            applied: None,
            pending: VecDeque::new(),
            saving_until: None,
            displaced: false,
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
        let mut input = last.unwrap_or_else(|| self.drive.input());
        if self.displaced {
            if input.status & status_bit(&self.drive, RUNNING) != 0 {
                self.displaced = false;
            } else {
                input.status |= status_bit(&self.drive, DISPLACED);
            }
        }
        input.to_bytes(&rules, order).map_err(|e| e.to_string())
    }

    fn advance(&mut self, now: Micros) {
        CyclicDevice::advance(&mut self.drive, now);
    }

    fn isdu(&mut self, now: Micros, req: Request) -> Reply {
        let (index, _) = req.address();
        let read = matches!(req, Request::Read { .. });
        if let Kind::SaveTime(us) = self.kind {
            let saving = self.saving_until.is_some_and(|end| now < end);
            if read && saving && index == DELIVERY_STATE {
                return Reply::Data(vec![0, 1]);
            }
            let save = self.saves(&req);
            let reply = CyclicDevice::isdu(&mut self.drive, now, req);
            if save && reply == Reply::Ok {
                self.saving_until = Some(now.saturating_add(us));
            }
            return reply;
        }
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
        if matches!(env, Env::PowerCycle) {
            self.saving_until = None;
            self.displaced = false;
        }
        if let (Kind::DisplacedAfterAbort, Env::Displace(n)) = (self.kind, env) {
            let status = self.drive.status_word();
            let window = match self.drive.value(WINDOW) {
                drivespec_psx3xx::isdu::Value::Int(w) => w,
                _ => 0,
            };
            let standing = status & status_bit(&self.drive, RUNNING) == 0;
            let aborted = status & status_bit(&self.drive, ABORTED) != 0;
            self.displaced |= standing && aborted && n.abs() > window;
        }
        CyclicDevice::env(&mut self.drive, now, env)
    }

    fn clone_box(&self) -> Box<dyn CyclicDevice<'s> + 's> {
        Box::new(self.clone())
    }
}

/// ISDU 193: delivery state and save command (3.1).
const DELIVERY_STATE: u16 = 193;
/// ISDU 131: the positioning window (3.1).
const WINDOW: &str = "131";
/// Status bits by their names in the spec (3.4).
const RUNNING: &str = "Drive is running";
const ABORTED: &str = "Positioning run aborted";
const DISPLACED: &str = "Manual displacement";

/// The mask of the status bit `name` (3.4).
fn status_bit(drive: &Drive<'_>, name: &str) -> u16 {
    mask(drive.rules().status_bits(), name)
}

impl Variant<'_> {
    /// Whether `req` writes a command that saves to EEPROM (3.1 ISDU 2 = 161, ISDU 193).
    fn saves(&self, req: &Request) -> bool {
        let Request::Write { index, data, .. } = req else {
            return false;
        };
        // Command values are signed (3.1: ISDU 193 -2…3, ±15 bit).
        let signed = match data.as_slice() {
            [a, b] => i64::from(i16::from_be_bytes([*a, *b])),
            other => other.iter().fold(0i64, |a, b| (a << 8) | i64::from(*b)),
        };
        self.drive
            .rules()
            .protocol()
            .commands
            .commands
            .iter()
            .any(|c| c.save && c.param == index.to_string() && c.value == signed)
    }

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
        ("start latency 1 ms", Kind::StartLatency(1_000)),
        ("start latency 3 ms", Kind::StartLatency(3_000)),
        ("start latency 8 ms", Kind::StartLatency(8_000)),
        ("start latency 30 ms", Kind::StartLatency(30_000)),
        ("identification of its own", Kind::OwnValues),
        ("a save takes 1.5 s", Kind::SaveTime(1_500_000)),
        (
            "bit 11 also after an aborted run",
            Kind::DisplacedAfterAbort,
        ),
    ]
}
