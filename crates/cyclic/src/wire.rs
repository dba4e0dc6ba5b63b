//! Request and reply lines of `drivespec-cyclic/1` (README "Protocol"): the
//! PSD4xx records (`READ`/`WRITE`) and the PSx3xx ISDU requests (`ISDU-READ`/`ISDU-WRITE`).
//!
//! Words are separated by single blanks; numbers are decimal (times in µs, signed values with
//! `-`); byte strings are hex without separators (upper or lower case), `-` when empty. Unknown words give a
//! [`WireError`], never a panic.

use drivespec_psd4xx::model::LinkEvent;
use drivespec_spec::hex::{parse_hex_compact, to_hex_compact};
use std::fmt;

/// Protocol version this runner speaks.
pub const VERSION: u32 = 1;

/// An environment injection (`ENV t NAME VALUE`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Env {
    /// `power-cycle 0`: control voltage off and on again.
    PowerCycle,
    /// `jam 1|0`: the shaft is blocked / free (obstruction, 4.5).
    Jam(bool),
    /// `displace N`: the shaft is turned by hand by N increments at standstill.
    Displace(i64),
    /// `motor-voltage DV`: motor supply in 0.1 V.
    MotorVoltage(u16),
    /// `miss-steps N`: the next arrival lands N increments short.
    MissSteps(i64),
    /// `temperature C`: device temperature in °C.
    Temperature(i16),
    /// `link lost|connected|iops-bad|iops-good`: the bus connection (PSD4xx 3.9; PSx3xx 5.9
    /// knows `lost` and `connected`).
    Link(LinkEvent),
    /// `control-voltage DV`: control supply in 0.1 V; 0 switches the device off.
    ControlVoltage(u16),
    /// `load-torque CNM`: extra load torque on the shaft in cNm.
    LoadTorque(u16),
    /// `back-drive RPM`: the shaft is turned externally at this speed; 0 stops it.
    BackDrive(i32),
    /// `block POS`: a hard block at this position.
    Block(i64),
    /// `clear-blocks 0`: every block removed.
    ClearBlocks,
    /// `position-fault 0`: an internal problem in the position calculation.
    PositionFault,
    /// `keys none|forward|reverse|both`: the jog key inputs (PSx3xx 5.10).
    Keys {
        /// Forward key (pin 2) pressed.
        forward: bool,
        /// Reverse key (pin 3) pressed.
        reverse: bool,
    },
}

/// A request from the runner.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Request {
    /// `HELLO drivespec-cyclic VERSION FAMILY MODEL`.
    Hello {
        /// Protocol version.
        version: u32,
        /// Device family (`psd4xx`).
        family: String,
        /// Device model the runner tests.
        model: String,
    },
    /// `RESET`: a fresh device in its delivery state, clock at 0.
    Reset,
    /// `CYCLE T HEX`: one output image at time T; answered with the input image.
    Cycle {
        /// Virtual time (µs).
        t: u64,
        /// Output image.
        image: Vec<u8>,
    },
    /// `ADVANCE T`: time passes without a bus cycle.
    Advance {
        /// Virtual time (µs).
        t: u64,
    },
    /// `READ T INDEX`: an acyclic read record.
    Read {
        /// Virtual time (µs).
        t: u64,
        /// Record index.
        index: u16,
    },
    /// `WRITE T INDEX HEX`: an acyclic write record (control byte first).
    Write {
        /// Virtual time (µs).
        t: u64,
        /// Record index.
        index: u16,
        /// Record data.
        data: Vec<u8>,
    },
    /// `ISDU-READ T INDEX SUBINDEX`: an IO-Link ISDU read (PSx3xx 3.1).
    IsduRead {
        /// Virtual time (µs).
        t: u64,
        /// ISDU index.
        index: u16,
        /// Sub-index (0: the whole index).
        subindex: u8,
    },
    /// `ISDU-WRITE T INDEX SUBINDEX HEX`: an IO-Link ISDU write (PSx3xx 3.1).
    IsduWrite {
        /// Virtual time (µs).
        t: u64,
        /// ISDU index.
        index: u16,
        /// Sub-index (0: the whole index).
        subindex: u8,
        /// Value octets, most significant first.
        data: Vec<u8>,
    },
    /// `ENV T NAME VALUE`: an environment injection.
    Env {
        /// Virtual time (µs).
        t: u64,
        /// What changes.
        env: Env,
    },
}

/// A reply from the device side.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Reply {
    /// `HELLO drivespec-cyclic VERSION NAME…`.
    Hello {
        /// Protocol version of the device side.
        version: u32,
        /// Free text naming the implementation.
        name: String,
    },
    /// `OK`.
    Ok,
    /// `IN HEX`: the input image of a cycle.
    In(Vec<u8>),
    /// `DATA HEX`: the data of a read record.
    Data(Vec<u8>),
    /// `WRITTEN`: a write record was executed.
    Written,
    /// `IGNORED`: a write record was ignored (control byte 0).
    Ignored,
    /// `REFUSED CODE`: the record was refused with this PKW error code.
    Refused(u32),
    /// `MALFORMED`: the record data has the wrong length.
    Malformed,
    /// `ISDU-ERROR NAME`: the ISDU request was refused with this IO-Link ErrorType, named as
    /// in the spec's `protocol.isdu_errors.code` table (`IDX_NOTAVAIL`), or as hex (`0x8011`)
    /// when it has no name.
    IsduError(String),
    /// `SILENT`: no answer at all (switched off).
    Silent,
    /// `UNSUPPORTED`: the adapter cannot do this injection.
    Unsupported,
    /// `ERR TEXT`: the request line was not understood.
    Err(String),
}

/// Why a line is not a valid request or reply.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{what}: {line:?}")]
pub struct WireError {
    /// The line.
    pub line: String,
    /// What is wrong.
    pub what: String,
}

fn bad(line: &str, what: &str) -> WireError {
    WireError {
        line: line.chars().take(200).collect(),
        what: what.to_owned(),
    }
}

/// A byte string as one protocol word: hex, or `-` when empty.
fn word(bytes: &[u8]) -> String {
    if bytes.is_empty() {
        "-".to_owned()
    } else {
        to_hex_compact(bytes)
    }
}

fn link_name(e: LinkEvent) -> &'static str {
    match e {
        LinkEvent::Lost => "lost",
        LinkEvent::Connected => "connected",
        LinkEvent::IopsBad => "iops-bad",
        LinkEvent::IopsGood => "iops-good",
    }
}

impl fmt::Display for Env {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Env::PowerCycle => f.write_str("power-cycle 0"),
            Env::Jam(on) => write!(f, "jam {}", u8::from(*on)),
            Env::Displace(n) => write!(f, "displace {n}"),
            Env::MotorVoltage(dv) => write!(f, "motor-voltage {dv}"),
            Env::MissSteps(n) => write!(f, "miss-steps {n}"),
            Env::Temperature(c) => write!(f, "temperature {c}"),
            Env::Link(e) => write!(f, "link {}", link_name(*e)),
            Env::ControlVoltage(dv) => write!(f, "control-voltage {dv}"),
            Env::LoadTorque(cnm) => write!(f, "load-torque {cnm}"),
            Env::BackDrive(rpm) => write!(f, "back-drive {rpm}"),
            Env::Block(at) => write!(f, "block {at}"),
            Env::ClearBlocks => f.write_str("clear-blocks 0"),
            Env::PositionFault => f.write_str("position-fault 0"),
            Env::Keys { forward, reverse } => f.write_str(match (forward, reverse) {
                (false, false) => "keys none",
                (true, false) => "keys forward",
                (false, true) => "keys reverse",
                (true, true) => "keys both",
            }),
        }
    }
}

impl fmt::Display for Request {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Request::Hello {
                version,
                family,
                model,
            } => write!(f, "HELLO drivespec-cyclic {version} {family} {model}"),
            Request::Reset => f.write_str("RESET"),
            Request::Cycle { t, image } => write!(f, "CYCLE {t} {}", word(image)),
            Request::Advance { t } => write!(f, "ADVANCE {t}"),
            Request::Read { t, index } => write!(f, "READ {t} {index}"),
            Request::Write { t, index, data } => write!(f, "WRITE {t} {index} {}", word(data)),
            Request::IsduRead { t, index, subindex } => {
                write!(f, "ISDU-READ {t} {index} {subindex}")
            }
            Request::IsduWrite {
                t,
                index,
                subindex,
                data,
            } => write!(f, "ISDU-WRITE {t} {index} {subindex} {}", word(data)),
            Request::Env { t, env } => write!(f, "ENV {t} {env}"),
        }
    }
}

impl fmt::Display for Reply {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reply::Hello { version, name } => write!(f, "HELLO drivespec-cyclic {version} {name}"),
            Reply::Ok => f.write_str("OK"),
            Reply::In(b) => write!(f, "IN {}", word(b)),
            Reply::Data(b) => write!(f, "DATA {}", word(b)),
            Reply::Written => f.write_str("WRITTEN"),
            Reply::Ignored => f.write_str("IGNORED"),
            Reply::Refused(c) => write!(f, "REFUSED {c}"),
            Reply::Malformed => f.write_str("MALFORMED"),
            Reply::IsduError(name) => write!(f, "ISDU-ERROR {name}"),
            Reply::Silent => f.write_str("SILENT"),
            Reply::Unsupported => f.write_str("UNSUPPORTED"),
            Reply::Err(t) => write!(f, "ERR {t}"),
        }
    }
}

fn num<T: std::str::FromStr>(line: &str, w: Option<&str>, what: &str) -> Result<T, WireError> {
    w.and_then(|s| s.parse().ok())
        .ok_or_else(|| bad(line, &format!("expected {what}")))
}

fn bytes(line: &str, w: Option<&str>) -> Result<Vec<u8>, WireError> {
    match w {
        Some("-") => Some(Vec::new()),
        other => other.and_then(parse_hex_compact),
    }
    .ok_or_else(|| bad(line, "expected hex bytes"))
}

fn end(line: &str, mut words: std::str::SplitWhitespace<'_>) -> Result<(), WireError> {
    match words.next() {
        None => Ok(()),
        Some(_) => Err(bad(line, "trailing words")),
    }
}

impl Request {
    /// The virtual time the request carries; None for `HELLO` and `RESET`.
    pub fn time(&self) -> Option<u64> {
        match self {
            Request::Hello { .. } | Request::Reset => None,
            Request::Cycle { t, .. }
            | Request::Advance { t }
            | Request::Read { t, .. }
            | Request::Write { t, .. }
            | Request::IsduRead { t, .. }
            | Request::IsduWrite { t, .. }
            | Request::Env { t, .. } => Some(*t),
        }
    }

    /// Parses one request line (without its `\n`).
    pub fn parse(line: &str) -> Result<Request, WireError> {
        let mut w = line.split_whitespace();
        let verb = w.next().unwrap_or("");
        let r = match verb {
            "HELLO" => {
                if w.next() != Some("drivespec-cyclic") {
                    return Err(bad(
                        line,
                        "expected HELLO drivespec-cyclic VERSION FAMILY MODEL",
                    ));
                }
                let version = num(line, w.next(), "version")?;
                let family = w.next().unwrap_or("").to_owned();
                let model = w.next().unwrap_or("").to_owned();
                Request::Hello {
                    version,
                    family,
                    model,
                }
            }
            "RESET" => Request::Reset,
            "CYCLE" => Request::Cycle {
                t: num(line, w.next(), "time")?,
                image: bytes(line, w.next())?,
            },
            "ADVANCE" => Request::Advance {
                t: num(line, w.next(), "time")?,
            },
            "READ" => Request::Read {
                t: num(line, w.next(), "time")?,
                index: num(line, w.next(), "index")?,
            },
            "WRITE" => Request::Write {
                t: num(line, w.next(), "time")?,
                index: num(line, w.next(), "index")?,
                data: bytes(line, w.next())?,
            },
            "ISDU-READ" => Request::IsduRead {
                t: num(line, w.next(), "time")?,
                index: num(line, w.next(), "index")?,
                subindex: num(line, w.next(), "sub-index")?,
            },
            "ISDU-WRITE" => Request::IsduWrite {
                t: num(line, w.next(), "time")?,
                index: num(line, w.next(), "index")?,
                subindex: num(line, w.next(), "sub-index")?,
                data: bytes(line, w.next())?,
            },
            "ENV" => {
                let t = num(line, w.next(), "time")?;
                let name = w.next().unwrap_or("");
                let value = w.next();
                let env = match name {
                    "power-cycle" => Env::PowerCycle,
                    "jam" => Env::Jam(num::<u8>(line, value, "0 or 1")? != 0),
                    "displace" => Env::Displace(num(line, value, "increments")?),
                    "motor-voltage" => Env::MotorVoltage(num(line, value, "0.1 V")?),
                    "miss-steps" => Env::MissSteps(num(line, value, "increments")?),
                    "temperature" => Env::Temperature(num(line, value, "°C")?),
                    "link" => Env::Link(match value {
                        Some("lost") => LinkEvent::Lost,
                        Some("connected") => LinkEvent::Connected,
                        Some("iops-bad") => LinkEvent::IopsBad,
                        Some("iops-good") => LinkEvent::IopsGood,
                        _ => return Err(bad(line, "expected lost|connected|iops-bad|iops-good")),
                    }),
                    "control-voltage" => Env::ControlVoltage(num(line, value, "0.1 V")?),
                    "load-torque" => Env::LoadTorque(num(line, value, "cNm")?),
                    "back-drive" => Env::BackDrive(num(line, value, "rpm")?),
                    "block" => Env::Block(num(line, value, "position")?),
                    "clear-blocks" => Env::ClearBlocks,
                    "position-fault" => Env::PositionFault,
                    "keys" => {
                        let (forward, reverse) = match value {
                            Some("none") => (false, false),
                            Some("forward") => (true, false),
                            Some("reverse") => (false, true),
                            Some("both") => (true, true),
                            _ => return Err(bad(line, "expected none|forward|reverse|both")),
                        };
                        Env::Keys { forward, reverse }
                    }
                    _ => return Err(bad(line, "unknown environment name")),
                };
                Request::Env { t, env }
            }
            _ => return Err(bad(line, "unknown request")),
        };
        end(line, w)?;
        Ok(r)
    }
}

impl Reply {
    /// Parses one reply line (without its `\n`).
    pub fn parse(line: &str) -> Result<Reply, WireError> {
        let mut w = line.split_whitespace();
        let verb = w.next().unwrap_or("");
        let r = match verb {
            "HELLO" => {
                if w.next() != Some("drivespec-cyclic") {
                    return Err(bad(line, "expected HELLO drivespec-cyclic VERSION NAME"));
                }
                let version = num(line, w.next(), "version")?;
                let name: Vec<&str> = w.by_ref().collect();
                Reply::Hello {
                    version,
                    name: name.join(" "),
                }
            }
            "OK" => Reply::Ok,
            "IN" => Reply::In(bytes(line, w.next())?),
            "DATA" => Reply::Data(bytes(line, w.next())?),
            "WRITTEN" => Reply::Written,
            "IGNORED" => Reply::Ignored,
            "REFUSED" => Reply::Refused(num(line, w.next(), "error code")?),
            "MALFORMED" => Reply::Malformed,
            "ISDU-ERROR" => match w.next() {
                Some(name) if name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') => {
                    Reply::IsduError(name.to_owned())
                }
                _ => return Err(bad(line, "expected an ErrorType name or hex")),
            },
            "SILENT" => Reply::Silent,
            "UNSUPPORTED" => Reply::Unsupported,
            "ERR" => {
                let text: Vec<&str> = w.by_ref().collect();
                Reply::Err(text.join(" "))
            }
            _ => return Err(bad(line, "unknown reply")),
        };
        end(line, w)?;
        Ok(r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::strategy::Strategy;

    #[test]
    fn requests_and_replies_round_trip() {
        let reqs = [
            Request::Hello {
                version: 1,
                family: "psd4xx".into(),
                model: "PSD401-5V".into(),
            },
            Request::Reset,
            Request::Cycle {
                t: 10_000,
                image: vec![0x10, 0xFF],
            },
            Request::Advance { t: 5 },
            Request::Read { t: 1, index: 44 },
            Request::Write {
                t: 1,
                index: 44,
                data: vec![1, 0, 3],
            },
            Request::Env {
                t: 2,
                env: Env::Displace(-40),
            },
            Request::Env {
                t: 2,
                env: Env::Link(LinkEvent::IopsBad),
            },
            Request::IsduRead {
                t: 8000,
                index: 0,
                subindex: 10,
            },
            Request::IsduWrite {
                t: 16_000,
                index: 193,
                subindex: 0,
                data: vec![0xFF, 0xFE],
            },
            Request::Env {
                t: 3,
                env: Env::Keys {
                    forward: true,
                    reverse: false,
                },
            },
            Request::Env {
                t: 3,
                env: Env::ControlVoltage(0),
            },
            Request::Env {
                t: 3,
                env: Env::BackDrive(-12),
            },
            Request::Env {
                t: 3,
                env: Env::ClearBlocks,
            },
        ];
        for r in reqs {
            assert_eq!(Request::parse(&r.to_string()), Ok(r));
        }
        let replies = [
            Reply::Hello {
                version: 1,
                name: "my sim 2".into(),
            },
            Reply::In(vec![1, 2]),
            Reply::Refused(17),
            Reply::Err("what".into()),
            Reply::Silent,
            Reply::IsduError("IDX_NOTAVAIL".into()),
            Reply::IsduError("0x8011".into()),
            Reply::Data(Vec::new()),
        ];
        for r in replies {
            assert_eq!(Reply::parse(&r.to_string()), Ok(r));
        }
        // Arbitrary lines never panic (a deterministic generator over the protocol's words).
        let words = [
            "HELLO",
            "drivespec-cyclic",
            "CYCLE",
            "IN",
            "ENV",
            "jam",
            "link",
            "-1",
            "99999999999999999999",
            "0A",
            "zz",
            "",
            "READ",
            "WRITE",
            "REFUSED",
            "é",
        ];
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..5000 {
            let mut line = String::new();
            for _ in 0..(x % 6) {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                line.push_str(words[(x % words.len() as u64) as usize]);
                line.push(' ');
            }
            x = x.wrapping_add(1);
            let _ = (Request::parse(&line), Reply::parse(&line));
        }
        for bad in [
            "",
            "CYCLE x 00",
            "CYCLE 1 0",
            "READ 1",
            "ENV 1 warp 9",
            "OK extra",
            "ISDU-READ 1 2",
            "ISDU-READ 1 2 256",
            "ISDU-WRITE 1 2 0",
            "ENV 1 keys sideways",
            "ISDU-ERROR",
            "ISDU-ERROR A-B",
        ] {
            assert!(
                Request::parse(bad).is_err() || Reply::parse(bad).is_err(),
                "{bad}"
            );
        }
    }

    proptest::proptest! {
        /// No line, however garbled, makes either parser panic; what parses prints back to
        /// the same request or reply.
        #[test]
        fn arbitrary_lines_never_panic(line in "\\PC{0,80}") {
            if let Ok(r) = Request::parse(&line) {
                proptest::prop_assert_eq!(Request::parse(&r.to_string()), Ok(r));
            }
            if let Ok(r) = Reply::parse(&line) {
                proptest::prop_assert_eq!(Reply::parse(&r.to_string()), Ok(r));
            }
        }

        /// Lines built from the protocol's own words, numbers and hex never panic either.
        #[test]
        fn protocol_words_never_panic(words in proptest::collection::vec(
            proptest::prop_oneof![
                proptest::sample::select(vec![
                    "HELLO", "drivespec-cyclic", "RESET", "CYCLE", "ADVANCE", "READ", "WRITE",
                    "ISDU-READ", "ISDU-WRITE", "ENV", "keys", "link", "both", "lost",
                    "power-cycle", "IN", "DATA", "ISDU-ERROR", "REFUSED", "SILENT", "OK",
                ]).prop_map(str::to_owned),
                proptest::num::i64::ANY.prop_map(|n| n.to_string()),
                "[0-9A-Fa-f]{0,9}",
            ],
            0..7,
        )) {
            let line = words.join(" ");
            let _ = (Request::parse(&line), Reply::parse(&line));
        }
    }
}
