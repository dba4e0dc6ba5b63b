//! Bounded timelines of positioning drives for the HTML report: position, speed, target,
//! status and control words over time, and the violations marked.
//!
//! Memory is bounded whatever the capture length: when [`MAX_SAMPLES`] samples are held,
//! every second one is dropped and only every second new sample is kept from then on
//! (the stride doubles), so the plot covers the whole capture at an even resolution. A
//! sample is taken only when a value changes (or the stride says so). Nothing here panics.

use serde::Serialize;

/// Most samples kept per drive.
pub const MAX_SAMPLES: usize = 4000;

/// Most violation marks kept per drive.
pub const MAX_MARKS: usize = 500;

/// One point of a drive's timeline.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Sample {
    /// Time in µs.
    pub time: u64,
    /// Actual position (raw).
    pub actual: i64,
    /// Speed (rpm).
    pub speed: i64,
    /// Target value in force (raw), when known.
    pub target: Option<i64>,
    /// Status word.
    pub status: u16,
    /// Control word in force.
    pub control: u16,
}

/// A violation drawn on the timeline.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Mark {
    /// Time in µs.
    pub time: u64,
    /// Requirement ID.
    pub requirement: String,
}

/// The timeline of one drive (bounded, see the module docs).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Timeline {
    /// The drive's label (the violations' subject).
    pub label: String,
    /// Names of the status bits 0–15 (from the spec), for the legend.
    pub status_names: Vec<String>,
    /// The samples, in time order.
    pub samples: Vec<Sample>,
    /// Violations at their times.
    pub marks: Vec<Mark>,
    /// Marks not kept beyond [`MAX_MARKS`].
    pub marks_dropped: u64,
    stride: u64,
    seen: u64,
}

impl Timeline {
    /// An empty timeline.
    pub fn new(label: &str, status_names: Vec<String>) -> Timeline {
        Timeline {
            label: label.to_owned(),
            status_names,
            samples: Vec::new(),
            marks: Vec::new(),
            marks_dropped: 0,
            stride: 1,
            seen: 0,
        }
    }

    /// Offers a sample; kept when something changed or the stride says so.
    pub fn push(&mut self, s: Sample) {
        self.seen += 1;
        let changed = self.samples.last().is_none_or(|l| {
            l.actual != s.actual
                || l.speed != s.speed
                || l.status != s.status
                || l.control != s.control
                || l.target != s.target
        });
        if !changed && self.seen % self.stride.saturating_mul(64) != 0 {
            return;
        }
        if self.stride > 1 && self.seen % self.stride != 0 && !changed {
            return;
        }
        self.samples.push(s);
        if self.samples.len() >= MAX_SAMPLES {
            let mut i = 0usize;
            self.samples.retain(|_| {
                i += 1;
                i % 2 == 0
            });
            self.stride = self.stride.saturating_mul(2);
        }
    }

    /// Marks a violation at `time`.
    pub fn mark(&mut self, time: u64, requirement: &str) {
        if self.marks.len() < MAX_MARKS {
            self.marks.push(Mark {
                time,
                requirement: requirement.to_owned(),
            });
        } else {
            self.marks_dropped += 1;
        }
    }
}
