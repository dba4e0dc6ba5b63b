//! The HPD step language: what a master puts on the line, how long it listens, what it does
//! to the drive's supply and inputs, and how an answer is compared with the reference
//! model's (manual chapter 4; fuzz replay files, `crates/fuzz/README.md` "Replay files").
//!
//! A step reads and writes as one record whose key `do` names it
//! (`{"do": "exchange", "hex": "02 C6 48", "compare": "exact"}`); every step is
//! `deny_unknown_fields`, so a misspelt key is an error naming the key.

use crate::line::Micros;
use serde::{Deserialize, Serialize};

/// How an answer of the device is compared with the reference model's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Compare {
    /// Byte for byte, silence included.
    #[default]
    Exact,
    /// The same frames; data bits outside the mask (little-endian over the data bytes) are
    /// not compared (values the drive changes by itself, manual 3.3 "live").
    Mask(u32),
    /// The same frame header; the data as a value within ± the tolerance (timers counting).
    Near(i64),
    /// A value the manual does not fix (an example value, a silent point): the same frame
    /// header, the data bits under `mask` as the reference's, and the data as a value
    /// within `min..=max` (read signed when `min` is negative); the value seen is reported.
    Open {
        /// Data bits compared with the reference (little-endian over the data bytes).
        mask: u32,
        /// Lowest value allowed.
        min: i64,
        /// Highest value allowed.
        max: i64,
    },
    /// The same frame header and the data the device answered to the case's `save` of the
    /// same parameter (a read-only parameter kept its value); the reference's data is not
    /// compared.
    Unchanged,
}

/// One HPD step (key `do`). Steps without keys are written `Name {}` so that a key given
/// to them is refused too.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "do", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Step {
    /// Sends bytes and compares what the device and the reference send back within the
    /// answer window (manual 4.1: the Pr26 time-out in force, any answer delay, and slack).
    Exchange {
        /// Bytes on the line (key `hex`).
        #[serde(rename = "hex", with = "hex_text")]
        bytes: Vec<u8>,
        /// How the answers are compared.
        #[serde(default)]
        compare: Compare,
        /// Silence from the device is accepted too (a vector whose result is `acceptable`).
        #[serde(default, skip_serializing_if = "std::ops::Not::not")]
        silence_ok: bool,
    },
    /// Sends bytes without waiting (the first part of a split frame).
    Send {
        /// Bytes on the line (key `hex`).
        #[serde(rename = "hex", with = "hex_text")]
        bytes: Vec<u8>,
    },
    /// Listens for `us` µs and compares what comes (normally nothing).
    Listen {
        /// How long.
        us: Micros,
    },
    /// Listens past the message time-out in force plus slack (manual 4, Pr26).
    ListenTimeout {},
    /// Listens for half the message time-out in force.
    ListenHalfTimeout {},
    /// Switches the device and the reference off and on.
    PowerCycle {},
    /// Sets the digital inputs of the device and the reference, bit i = input i (manual
    /// 3.8.1 b90).
    Inputs {
        /// The inputs.
        value: u16,
    },
    /// Sets the transport's bit rate to the one the reference now uses (after b42.3).
    BitRate {},
    /// Reads `lun` bytes at serial address `par` from the drive at `addr` (and the
    /// reference) and keeps the device's data for a later `restore` or `unchanged` compare.
    Save {
        /// Drive address.
        addr: u8,
        /// Serial address of the parameter.
        par: u8,
        /// Its length in bytes.
        lun: u8,
    },
    /// Reads `reads` from the drive at `addr` round after round and judges the device's own
    /// samples by `checks` (manual 3.3, 3.6: motion is judged by the properties the manual
    /// states, never against the reference's trajectory). The watch ends `hold_us` after
    /// every condition of `until` first held, or after `us`.
    Watch {
        /// Drive address.
        addr: u8,
        /// The parameters read in each round, in this order.
        reads: Vec<Probe>,
        /// Longest watch (µs).
        us: Micros,
        /// Shortest time from one round's start to the next (µs).
        #[serde(default)]
        every_us: Micros,
        /// Conditions that end the watch (all of them, in one round).
        #[serde(default, skip_serializing_if = "Vec::is_empty")]
        until: Vec<Within>,
        /// How long the watch goes on after `until` held (µs).
        #[serde(default)]
        hold_us: Micros,
        /// The properties judged, each for one requirement.
        checks: Vec<Check>,
    },
    /// Writes the data the case's `save` of `par` read from the device back to the drive at
    /// `addr` and to the reference (the device's own value, manual 4.1 CMD 5); nothing when
    /// no `save` read it.
    Restore {
        /// Drive address.
        addr: u8,
        /// Serial address of the parameter.
        par: u8,
        /// Its length in bytes.
        lun: u8,
    },
}

impl Step {
    /// The step's name (its `do` key).
    pub fn name(&self) -> &'static str {
        match self {
            Step::Exchange { .. } => "exchange",
            Step::Send { .. } => "send",
            Step::Listen { .. } => "listen",
            Step::ListenTimeout {} => "listen-timeout",
            Step::ListenHalfTimeout {} => "listen-half-timeout",
            Step::PowerCycle {} => "power-cycle",
            Step::Inputs { .. } => "inputs",
            Step::BitRate {} => "bit-rate",
            Step::Save { .. } => "save",
            Step::Restore { .. } => "restore",
            Step::Watch { .. } => "watch",
        }
    }

    /// The bytes the step puts on the line, if any.
    pub fn bytes(&self) -> Option<&[u8]> {
        match self {
            Step::Exchange { bytes, .. } | Step::Send { bytes } => Some(bytes),
            _ => None,
        }
    }

    /// The same step with other bytes (exchanges and sends; any other step unchanged).
    pub fn with_bytes(&self, new: Vec<u8>) -> Step {
        match self {
            Step::Exchange {
                compare,
                silence_ok,
                ..
            } => Step::Exchange {
                bytes: new,
                compare: *compare,
                silence_ok: *silence_ok,
            },
            Step::Send { .. } => Step::Send { bytes: new },
            other => other.clone(),
        }
    }
}

/// One parameter read in each round of a watch (manual 4.1 CMD 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Probe {
    /// Serial address.
    pub par: u8,
    /// Length in bytes.
    pub lun: u8,
    /// Read as a two's-complement value.
    #[serde(default)]
    pub signed: bool,
}

/// A condition on one read of a round: the value (or one bit of it) within `min..=max`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Within {
    /// Index into the watch's reads.
    pub probe: usize,
    /// The bit of the value tested instead of the value.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bit: Option<u32>,
    /// Lowest value.
    pub min: i64,
    /// Highest value.
    pub max: i64,
}

/// A property of a watch's samples, judged for one requirement.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Check {
    /// The requirement the property belongs to.
    pub requirement: String,
    /// The property.
    pub envelope: Envelope,
}

/// What the manual lets a watched value do (manual 3.3 ramps and windows, 3.6 modes).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "is", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Envelope {
    /// The value comes into `min..=max` in some round.
    Reaches {
        /// The read and the range.
        within: Within,
    },
    /// Every value lies in `min..=max`.
    Bounded {
        /// The read and the range.
        within: Within,
    },
    /// The value of the last round lies in `min..=max`.
    Ends {
        /// The read and the range.
        within: Within,
    },
    /// From one round to the next the value changes by at most `per_s` a second of the time
    /// between the first read's request and the second read's answer, plus `slack`.
    Slope {
        /// Index into the watch's reads.
        probe: usize,
        /// Largest change a second.
        per_s: i64,
        /// Change allowed on top (resolution, one slot of the drive).
        slack: i64,
    },
    /// The value never moves against the direction by more than `slack`.
    Monotonic {
        /// Index into the watch's reads.
        probe: usize,
        /// Rising (true) or falling.
        rising: bool,
        /// Backwards motion allowed (resolution).
        slack: i64,
    },
    /// Between two rounds the position read `position` moves as far as the speed read
    /// `speed` (rpm) lets it in the time between: no farther than `top_rpm` and no less than
    /// the lower of the two speeds allow, at `steps_per_rev` steps a revolution, ± `slack`
    /// percent and `slack_steps` (a speed that rises and falls once between two reads is
    /// nowhere below the lower of them).
    Travel {
        /// Index of the position's read.
        position: usize,
        /// Index of the speed's read.
        speed: usize,
        /// Position steps per revolution.
        steps_per_rev: i64,
        /// The highest speed of the motion (rpm).
        top_rpm: i64,
        /// Relative slack (percent).
        slack: i64,
        /// Absolute slack (steps).
        slack_steps: i64,
    },
    /// Bit `bit` of read `flags` is 1 while read `probe` lies in one of `ranges` and 0 while
    /// it lies in none; judged where every read of `probe` from `lag_us` before the bit's
    /// read to the first one after it agrees (the drive updates the bit in its own time slot).
    BitFollows {
        /// Index of the bit parameter's read.
        flags: usize,
        /// The bit.
        bit: u32,
        /// Index of the value's read.
        probe: usize,
        /// Where the bit is 1.
        ranges: Vec<(i64, i64)>,
        /// How long the bit may lag behind the value (µs).
        lag_us: Micros,
    },
    /// Bit `bit` of read `flags` is 1 while position read `probe` shows a motion from `from`
    /// to `to` still under way (farther from `to` than `rpm` can cover before the bit's
    /// read), and once it has read 0 after a 1 the position lies within `window` of `to`.
    BusyWhileMoving {
        /// Index of the bit parameter's read.
        flags: usize,
        /// The bit.
        bit: u32,
        /// Index of the position's read.
        probe: usize,
        /// Position at the start.
        from: i64,
        /// Position at the end.
        to: i64,
        /// The highest speed of the motion (rpm).
        rpm: i64,
        /// Position error allowed at the end (steps).
        window: i64,
    },
    /// The first stroke of a back-and-forth motion (manual 3.6.3 test profile): the first
    /// speed read that is not 0 has the sign `forward` asks for, and the farthest the shaft
    /// gets from where the first round saw it, up to its first read at 0 rpm or in the other
    /// direction, lies within `min..=max` steps. A stroke still under way at the end of the
    /// watch is judged only for its direction and for not having gone beyond `max`.
    FirstStroke {
        /// The reads that show the shaft.
        shaft: Shaft,
        /// The first stroke turns at positive speed.
        forward: bool,
        /// Shortest stroke (steps).
        min: i64,
        /// Longest stroke (steps).
        max: i64,
    },
    /// After the first stroke (as [`Envelope::FirstStroke`] finds it) the shaft stands at 0
    /// rpm for at least `min_us` before it turns again, judged on the longest standstill the
    /// reads around it allow.
    Pause {
        /// The reads that show the shaft.
        shaft: Shaft,
        /// Shortest standstill (µs).
        min_us: Micros,
    },
    /// After the first stroke and its standstill the shaft turns again, against the first
    /// stroke's direction.
    Reverses {
        /// The reads that show the shaft.
        shaft: Shaft,
    },
}

/// A shaft seen through an absolute position within one revolution and a speed (manual 3.3
/// Pr28 and Pr0): the revolutions are counted between two rounds, which takes the rounds
/// close enough that at `top_rpm` the shaft turns less than half a revolution between them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Shaft {
    /// Index of the position's read (0..`steps_per_rev`).
    pub position: usize,
    /// Index of the speed's read (rpm).
    pub speed: usize,
    /// Position steps per revolution.
    pub steps_per_rev: i64,
    /// The highest speed of the motion (rpm).
    pub top_rpm: i64,
}

/// Bytes as spaced hex text (`7E 80 01`); any form `drivespec_spec::hex::parse_hex` reads.
mod hex_text {
    use drivespec_spec::hex::{parse_hex, to_hex};
    use serde::{Deserialize, Deserializer, Serializer};

    pub(super) fn serialize<S: Serializer>(bytes: &[u8], s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&to_hex(bytes))
    }

    pub(super) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<u8>, D::Error> {
        let text = String::deserialize(d)?;
        parse_hex(&text).map_err(|e| serde::de::Error::custom(format!("hex: {e}")))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)]
    use super::*;

    fn read(text: &str) -> Result<Step, toml::de::Error> {
        toml::from_str(text)
    }

    #[test]
    fn steps_read_with_their_keys() {
        assert_eq!(
            read("do = \"exchange\"\nhex = \"02 C6 48\"\ncompare = { mask = 65280 }").unwrap(),
            Step::Exchange {
                bytes: vec![0x02, 0xC6, 0x48],
                compare: Compare::Mask(0xFF00),
                silence_ok: false,
            }
        );
        assert_eq!(
            read("do = \"exchange\"\nhex = \"02C648\"\nsilence_ok = true").unwrap(),
            Step::Exchange {
                bytes: vec![0x02, 0xC6, 0x48],
                compare: Compare::Exact,
                silence_ok: true,
            }
        );
        assert_eq!(
            read("do = \"listen\"\nus = 6144").unwrap(),
            Step::Listen { us: 6144 }
        );
        assert_eq!(
            read("do = \"listen-half-timeout\"").unwrap(),
            Step::ListenHalfTimeout {}
        );
        assert_eq!(
            read("do = \"inputs\"\nvalue = 5").unwrap(),
            Step::Inputs { value: 5 }
        );
    }

    #[test]
    fn misspelt_keys_missing_keys_and_bad_hex_are_refused() {
        let e = read("do = \"listen\"\nuss = 5").unwrap_err().to_string();
        assert!(e.contains("uss"), "{e}");
        let e = read("do = \"exchange\"\nhex = \"02\"\ncompre = \"exact\"")
            .unwrap_err()
            .to_string();
        assert!(e.contains("compre"), "{e}");
        let e = read("do = \"send\"").unwrap_err().to_string();
        assert!(e.contains("hex"), "{e}");
        let e = read("do = \"send\"\nhex = \"0G\"").unwrap_err().to_string();
        assert!(e.contains("hex:"), "{e}");
        let e = read("do = \"power-cycle\"\nus = 5")
            .unwrap_err()
            .to_string();
        assert!(e.contains("us"), "{e}");
        let e = read("do = \"nap\"").unwrap_err().to_string();
        assert!(e.contains("nap"), "{e}");
    }

    #[test]
    fn names_bytes_and_round_trip() {
        let steps = [
            Step::Exchange {
                bytes: vec![0x7E, 0x80],
                compare: Compare::Near(3),
                silence_ok: true,
            },
            Step::Send { bytes: vec![1] },
            Step::Listen { us: 7 },
            Step::ListenTimeout {},
            Step::ListenHalfTimeout {},
            Step::PowerCycle {},
            Step::Inputs { value: 0xFFFF },
            Step::BitRate {},
            Step::Save {
                addr: 0,
                par: 0x46,
                lun: 2,
            },
            Step::Restore {
                addr: 1,
                par: 0x46,
                lun: 2,
            },
            Step::Exchange {
                bytes: vec![0x7E],
                compare: Compare::Open {
                    mask: 0xFF00,
                    min: -20,
                    max: 20,
                },
                silence_ok: false,
            },
            Step::Exchange {
                bytes: vec![0x7E],
                compare: Compare::Unchanged,
                silence_ok: false,
            },
        ];
        for s in &steps {
            let text = toml::to_string(s).unwrap();
            assert!(text.contains(&format!("do = \"{}\"", s.name())), "{text}");
            assert_eq!(&read(&text).unwrap(), s, "{text}");
        }
        assert_eq!(
            steps[0].with_bytes(vec![2]),
            Step::Exchange {
                bytes: vec![2],
                compare: Compare::Near(3),
                silence_ok: true,
            }
        );
        assert_eq!(steps[1].with_bytes(vec![2]).bytes(), Some(&[2u8][..]));
        assert_eq!(steps[2].with_bytes(vec![2]), steps[2]);
        assert_eq!(steps[2].bytes(), None);
    }
}
