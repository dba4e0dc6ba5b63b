//! The erratum readings a device may follow (spec `[[erratum]]` records with an `option`):
//! the readings still admissible on one device, the reference drive of each reading, and the
//! case so far replayed on another reading to see whether the device's answers fit it.
//!
//! A device follows one reading of each erratum throughout, so what one case shows holds for
//! the next ones on the same device. Errata are independent: the readings already shown are
//! combined, and each other reading of an erratum not yet shown is tried on top of them, one
//! erratum at a time. Nothing is replayed while the device matches the reference, except at the
//! end of a case that exercises an erratum (cites one of its requirements) or depends on a
//! reading other than the adopted one, to say which reading the answers showed.

use super::step::Compare;
use crate::link::Micros;
use crate::suite::SetupError;
use drivespec_hpd::model::{Drive, DriveConfig, Output};
use drivespec_spec::{Erratum, Family, Readings, Spec};
use std::collections::BTreeMap;

/// The erratum options of a family and the readings the user made strict.
#[derive(Debug, Clone)]
pub(crate) struct ReadingRules<'s> {
    errata: Vec<&'s Erratum>,
    /// Option → the one admissible reading (`--reading OPTION=READING`).
    strict: BTreeMap<String, String>,
}

impl<'s> ReadingRules<'s> {
    /// The family's selectable errata, with `strict` checked against them; an option no
    /// family of `spec` has, or a reading its erratum lacks, is a usage error.
    pub(crate) fn new(
        spec: &'s Spec,
        family: &'s Family,
        strict: &[(String, String)],
    ) -> Result<ReadingRules<'s>, SetupError> {
        let errata: Vec<&Erratum> = family
            .errata
            .iter()
            .filter(|e| e.option.is_some() && e.readings.len() > 1)
            .collect();
        let mut chosen = BTreeMap::new();
        for (option, reading) in strict {
            let mut check = Readings::default();
            match check.choose(family, option, reading) {
                Ok(()) => {
                    chosen.insert(option.clone(), reading.clone());
                }
                Err(e) => {
                    let elsewhere = spec.families().iter().any(|f| {
                        f.info.id != family.info.id
                            && f.errata.iter().any(|x| x.option.as_deref() == Some(option))
                    });
                    let unknown_option =
                        matches!(e, drivespec_spec::ReadingError::UnknownOption { .. });
                    if !(elsewhere && unknown_option) {
                        return Err(SetupError::Usage(format!("--reading: {e}")));
                    }
                }
            }
        }
        Ok(ReadingRules {
            errata,
            strict: chosen,
        })
    }

    /// The erratum with `option`.
    pub(crate) fn erratum(&self, option: &str) -> Option<&'s Erratum> {
        self.errata
            .iter()
            .copied()
            .find(|e| e.option.as_deref() == Some(option))
    }

    /// The selectable errata, in spec order.
    pub(crate) fn errata(&self) -> impl Iterator<Item = &'s Erratum> + '_ {
        self.errata.iter().copied()
    }

    /// The options, in spec order.
    pub(crate) fn options(&self) -> impl Iterator<Item = &'s str> + '_ {
        self.errata.iter().filter_map(|e| e.option.as_deref())
    }

    /// The readings made strict.
    pub(crate) fn strict(&self) -> &BTreeMap<String, String> {
        &self.strict
    }

    /// The reading in force for `option` under `shown`: the shown one, else the adopted one.
    pub(crate) fn in_force<'a>(
        &'a self,
        shown: &'a BTreeMap<String, String>,
        option: &str,
    ) -> &'a str {
        shown
            .get(option)
            .map(String::as_str)
            .or_else(|| self.erratum(option).map(|e| e.adopted.as_str()))
            .unwrap_or_default()
    }

    /// A finding for reading `reading` of the erratum with `option`.
    pub(crate) fn finding(&self, option: &str, reading: &str) -> Option<crate::case::Finding> {
        let e = self.erratum(option)?;
        let r = e.readings.iter().find(|r| r.id == reading)?;
        Some(crate::case::Finding::Reading {
            erratum: e.id.clone(),
            reading: r.id.clone(),
            text: r.text.clone(),
        })
    }
}

/// Reference drives powered up afresh, one per combination of readings, built on first use.
#[derive(Debug, Default)]
pub(crate) struct Bases {
    built: Vec<(BTreeMap<String, String>, Drive)>,
}

impl Bases {
    /// The drive of `config` following `readings` (the adopted reading for every other
    /// option), built once; None when the spec cannot build it.
    pub(crate) fn get(
        &mut self,
        spec: &Spec,
        family: &Family,
        config: &DriveConfig,
        readings: &BTreeMap<String, String>,
    ) -> Option<&Drive> {
        let at = match self.built.iter().position(|(r, _)| r == readings) {
            Some(at) => at,
            None => {
                let mut chosen = Readings::default();
                for (option, reading) in readings {
                    chosen.choose(family, option, reading).ok()?;
                }
                let drive = Drive::new(spec, config.clone().with_readings(chosen)).ok()?;
                self.built.push((readings.clone(), drive));
                self.built.len() - 1
            }
        };
        self.built.get(at).map(|(_, d)| d)
    }
}

/// How a judged step's answer is compared.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Judge {
    /// The answer to a request, under the step's comparison.
    Answer {
        /// Data comparison.
        compare: Compare,
        /// Silence also passes.
        silence_ok: bool,
    },
    /// What came while listening: byte for byte.
    Listen,
}

/// One thing the reference was given in the current case, on the reference's clock.
#[derive(Debug, Clone)]
enum Entry {
    /// A request at `at`; its answer is what the reference sends until `until`.
    Exchange {
        at: Micros,
        bytes: Vec<u8>,
        until: Micros,
    },
    /// Listening from the reference's current time until `until`.
    Listen { until: Micros },
    /// Bytes sent without a judged answer.
    Send { at: Micros, bytes: Vec<u8> },
    /// Digital inputs applied.
    Inputs { at: Micros, value: u16 },
    /// Switched off and on.
    PowerCycle { at: Micros },
}

/// A judged answer of the device: the entry it answered, how it is judged, what came.
#[derive(Debug, Clone)]
pub(crate) struct Judged {
    entry: usize,
    /// How it is judged.
    pub(crate) judge: Judge,
    /// The device's bytes.
    pub(crate) got: Vec<u8>,
}

/// What the reference was given in the current case, from its state at the case's start.
#[derive(Debug, Clone, Default)]
pub(crate) struct Journal {
    start: Option<Drive>,
    entries: Vec<Entry>,
    judged: Vec<Judged>,
}

impl Journal {
    /// Starts a case on the reference in state `start`.
    pub(crate) fn begin(&mut self, start: &Drive) {
        self.start = Some(start.clone());
        self.entries.clear();
        self.judged.clear();
    }

    /// A request at `at` answered until `until`.
    pub(crate) fn exchange(&mut self, at: Micros, bytes: &[u8], until: Micros) {
        self.entries.push(Entry::Exchange {
            at,
            bytes: bytes.to_vec(),
            until,
        });
    }

    /// Listening until `until`.
    pub(crate) fn listen(&mut self, until: Micros) {
        self.entries.push(Entry::Listen { until });
    }

    /// Bytes sent at `at`, not judged.
    pub(crate) fn send(&mut self, at: Micros, bytes: &[u8]) {
        self.entries.push(Entry::Send {
            at,
            bytes: bytes.to_vec(),
        });
    }

    /// Inputs applied at `at`.
    pub(crate) fn inputs(&mut self, at: Micros, value: u16) {
        self.entries.push(Entry::Inputs { at, value });
    }

    /// A power cycle at `at`.
    pub(crate) fn power_cycle(&mut self, at: Micros) {
        self.entries.push(Entry::PowerCycle { at });
    }

    /// The device's answer `got` to the last exchange or listen, judged by `judge`.
    pub(crate) fn judged(&mut self, judge: Judge, got: &[u8]) {
        if let Some(entry) = self.entries.len().checked_sub(1) {
            self.judged.push(Judged {
                entry,
                judge,
                got: got.to_vec(),
            });
        }
    }

    /// The times for the reference's next scan (within one `period` of the case's start)
    /// that put a scan at the case's start, before its first message, or just after each
    /// time the case gave it something: one of each order of scans and messages the case can
    /// see (3.8.1: when a scan falls between two messages is not fixed).
    pub(crate) fn phases(&self, period: Micros) -> Vec<Micros> {
        let Some(start) = self.start.as_ref() else {
            return Vec::new();
        };
        let (Some(next), true) = (start.next_scan(), period > 0) else {
            return Vec::new();
        };
        let now = start.now();
        let first_at = |t: Micros| now + t.saturating_sub(now) % period;
        let mut out: Vec<Micros> = vec![now];
        for e in &self.entries {
            let times = match e {
                Entry::Exchange { at, until, .. } => [Some(*at), Some(*until)],
                Entry::Listen { until } => [Some(*until), None],
                Entry::Send { at, .. } | Entry::Inputs { at, .. } | Entry::PowerCycle { at } => {
                    [Some(*at), None]
                }
            };
            for t in times.into_iter().flatten() {
                let at = first_at(t + 1);
                if !out.contains(&at) {
                    out.push(at);
                }
            }
        }
        out.retain(|t| *t != next);
        out
    }

    /// The judged answers so far.
    pub(crate) fn answers(&self) -> &[Judged] {
        &self.judged
    }

    /// The case so far on a drive following `readings_of`'s readings from the case's start
    /// state, its next PLC scan moved to `scan_at` when given: that drive now and its answer
    /// to each judged step. None without a start.
    pub(crate) fn replay(
        &self,
        readings_of: &Drive,
        scan_at: Option<Micros>,
    ) -> Option<(Drive, Vec<Vec<u8>>)> {
        let mut d = self.start.as_ref()?.under_readings_of(readings_of);
        if let Some(at) = scan_at {
            d.move_next_scan(at);
        }
        let mut answers: Vec<Vec<u8>> = Vec::with_capacity(self.judged.len());
        let mut out: Vec<Vec<u8>> = Vec::with_capacity(self.entries.len());
        for e in &self.entries {
            match e {
                Entry::Exchange { at, bytes, until } => {
                    let at = (*at).max(d.now());
                    d.handle_rx(at, bytes);
                    d.advance(*until);
                }
                Entry::Listen { until } => d.advance(*until),
                Entry::Send { at, bytes } => d.handle_rx((*at).max(d.now()), bytes),
                Entry::Inputs { at, value } => d.set_inputs((*at).max(d.now()), *value),
                Entry::PowerCycle { at } => d.power_cycle((*at).max(d.now())),
            }
            out.push(transmitted(&mut d));
        }
        for j in &self.judged {
            answers.push(out.get(j.entry).cloned().unwrap_or_default());
        }
        Some((d, answers))
    }
}

/// The bytes `d` transmitted since last drained.
fn transmitted(d: &mut Drive) -> Vec<u8> {
    let mut bytes = Vec::new();
    while let Some(o) = d.poll_output() {
        if let Output::Transmit { bytes: b, .. } = o {
            bytes.extend_from_slice(&b);
        }
    }
    bytes
}
