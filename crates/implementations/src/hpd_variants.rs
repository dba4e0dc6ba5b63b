//! HPD legal variants: drives that differ from the reference only where the manual allows,
//! as a second team reading the same manual could have built them.
//!
//! - the other reading of every erratum with an option (spec `[[erratum]]`, e.g. the 3.8.1
//!   prose "b99.3 = 0 if the result is zero", or no answer to a refused write, 4.1);
//! - a PLC whose 6.144 ms scan (3.8.1) runs at another phase from power-up;
//! - answers sent later than the reference sends them, within the time-out (4.1);
//! - a motor that starts later after a command and ramps more gently than its parameters
//!   allow (3.3: the ramps are limits; 3.6.4: the profile start is "not generated on a
//!   constant time base").

use crate::spec;
use drivespec_hpd::model::{Drive, DriveConfig, MotionStyle, Output};
use drivespec_link::Micros;
use drivespec_sim::SimDevice;
use drivespec_spec::{FamilyId, Readings};

/// How a variant differs from the reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Reading `.1` of the erratum with option `.0`.
    Reading(&'static str, &'static str),
    /// The scan grid shifted by this many µs: the drive's clock started that much earlier.
    ScanPhase(Micros),
    /// Every answer sent this many µs later.
    AnswerDelay(Micros),
    /// Motion starting this many µs after its command, on this share of the steepest ramps
    /// (percent).
    Motion(Micros, u32),
}

/// A legal variant.
#[derive(Clone)]
pub struct Variant {
    inner: Drive,
    kind: Kind,
}

impl Variant {
    /// The variant `kind`, commissioned at address 0 (manual 4.1).
    pub fn new(kind: Kind) -> Variant {
        let mut readings = Readings::default();
        if let Kind::Reading(option, reading) = kind {
            readings
                .choose(spec().family(FamilyId::Hpd), option, reading)
                .expect("an option and reading of the built-in errata");
        }
        let mut config = DriveConfig::commissioned(0).with_readings(readings);
        if let Kind::Motion(start_latency_us, ramp_percent) = kind {
            config = config.with_motion(MotionStyle {
                start_latency_us,
                ramp_percent,
            });
        }
        let mut inner =
            Drive::new(spec(), config).expect("the built-in spec builds the reference drive");
        if let Kind::ScanPhase(shift) = kind {
            inner.advance(shift);
        }
        Variant { inner, kind }
    }

    /// The drive's own clock for link time `now`.
    fn clock(&self, now: Micros) -> Micros {
        match self.kind {
            Kind::ScanPhase(shift) => now + shift,
            _ => now,
        }
    }
}

impl SimDevice for Variant {
    fn handle_rx(&mut self, now: Micros, bytes: &[u8]) {
        let t = self.clock(now);
        self.inner.handle_rx(t, bytes);
    }
    fn advance(&mut self, now: Micros) {
        let t = self.clock(now);
        self.inner.advance(t);
    }
    fn poll_output(&mut self) -> Option<Output> {
        match self.inner.poll_output()? {
            Output::Transmit { at, bytes } => Some(Output::Transmit {
                at: match self.kind {
                    Kind::ScanPhase(shift) => at.saturating_sub(shift),
                    Kind::AnswerDelay(d) => at + d,
                    Kind::Reading(..) | Kind::Motion(..) => at,
                },
                bytes,
            }),
            o => Some(o),
        }
    }
    fn power_cycle(&mut self, now: Micros) {
        let t = self.clock(now);
        self.inner.power_cycle(t);
    }
    fn clone_box(&self) -> Box<dyn SimDevice> {
        Box::new(self.clone())
    }
    fn set_inputs(&mut self, now: Micros, inputs: u16) -> bool {
        let t = self.clock(now);
        self.inner.set_inputs(t, inputs);
        true
    }
}

/// Every variant, with a name: the other reading of each erratum with an option, scan
/// phases across one scan, answer delays within the time-out.
pub fn variants() -> Vec<(String, Kind)> {
    let mut out = Vec::new();
    for e in &spec().family(FamilyId::Hpd).errata {
        let Some(option) = e.option.as_deref() else {
            continue;
        };
        for r in e.readings.iter().filter(|r| r.id != e.adopted) {
            let option: &'static str = Box::leak(option.to_owned().into_boxed_str());
            let reading: &'static str = Box::leak(r.id.clone().into_boxed_str());
            out.push((
                format!("{} reading {reading}", e.id),
                Kind::Reading(option, reading),
            ));
        }
    }
    for shift in [1_000, 3_072, 5_000, 6_000] {
        out.push((format!("scan phase +{shift} µs"), Kind::ScanPhase(shift)));
    }
    for delay in [500, 2_000] {
        out.push((
            format!("answers {delay} µs later"),
            Kind::AnswerDelay(delay),
        ));
    }
    for (latency, percent) in [(10_000, 80), (30_000, 100), (3_000, 60)] {
        out.push((
            format!("motion {latency} µs late on {percent} % of the ramps"),
            Kind::Motion(latency, percent),
        ));
    }
    out
}
