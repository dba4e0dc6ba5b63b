//! `--dut`: where the device under test is.
//!
//! | form | meaning |
//! | --- | --- |
//! | `sim` or `sim:MODEL` | the built-in reference model (default) |
//! | `serial:/dev/ttyUSB0?baud=57600` | a serial line, 8E1 (manual 4.1) |
//! | `tcp:HOST:PORT` | a raw byte stream (ser2net, a simulator) |
//! | `exec:COMMAND ARGS` | a subprocess speaking the protocol on stdin/stdout |
//! | `profinet:IFACE/NAME` | a PSD4xx on the network: PROFINET IO device NAME reached on interface IFACE |

pub use drivespec_link::shell_quote;
use std::fmt;
use std::str::FromStr;

/// Where the device under test is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Dut {
    /// The built-in reference model, optionally for one device model.
    Sim {
        /// Device model name (`HPD5`), matched forgivingly.
        model: Option<String>,
    },
    /// A serial port.
    Serial {
        /// Port path (`/dev/ttyUSB0`, `COM3`).
        path: String,
        /// Bits per second; None: the delivery value of the baud-rate parameter.
        baud: Option<u32>,
    },
    /// A TCP byte stream.
    Tcp {
        /// `HOST:PORT`.
        addr: String,
    },
    /// A subprocess on stdin/stdout.
    Exec {
        /// Program and arguments, split like a shell does (quotes and backslashes).
        argv: Vec<String>,
    },
    /// A PROFINET IO device on a network interface (PSD4xx bus description 3).
    Profinet {
        /// The network interface (`eth0`).
        iface: String,
        /// The device's NameOfStation.
        name: String,
    },
}

impl Default for Dut {
    fn default() -> Dut {
        Dut::Sim { model: None }
    }
}

/// Why a `--dut` text is not usable.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("--dut {text:?}: {why} (forms: sim[:MODEL], serial:PATH?baud=N, tcp:HOST:PORT, exec:'COMMAND ARGS', profinet:IFACE/NAME)")]
pub struct DutError {
    /// The text given.
    pub text: String,
    /// What is wrong.
    pub why: DutProblem,
}

/// What is wrong with a `--dut` text.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum DutProblem {
    /// `serial:` without a path.
    #[error("no port path")]
    NoPortPath,
    /// `baud=` with something else than a number.
    #[error("baud is not a number")]
    BaudNotNumber,
    /// A `serial:` option other than `baud`.
    #[error("unknown option {0:?} (known: baud)")]
    UnknownOption(String),
    /// `tcp:` without `HOST:PORT`.
    #[error("expected tcp:HOST:PORT")]
    NotHostPort,
    /// `exec:` with a command line that does not split into words.
    #[error("{0}")]
    Command(#[from] SplitError),
    /// `exec:` without a command.
    #[error("no command")]
    NoCommand,
    /// `profinet:` without `IFACE/NAME`.
    #[error("expected profinet:IFACE/NAME")]
    NotIfaceName,
    /// Not `sim`, `serial`, `tcp` or `exec`.
    #[error("unknown transport")]
    UnknownTransport,
}

/// Why a command line does not split into words ([`split_command`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SplitError {
    /// A quote (`'` or `"`) without its closing one.
    #[error("unterminated {0} quote")]
    Unterminated(char),
    /// A `\` at the end.
    #[error("trailing backslash")]
    TrailingBackslash,
}

impl FromStr for Dut {
    type Err = DutError;

    fn from_str(s: &str) -> Result<Dut, DutError> {
        let text = s.trim();
        let bad = |why: DutProblem| DutError {
            text: text.to_owned(),
            why,
        };
        let (kind, rest) = text.split_once(':').unwrap_or((text, ""));
        match kind.to_ascii_lowercase().as_str() {
            "sim" => Ok(Dut::Sim {
                model: Some(rest.trim())
                    .filter(|m| !m.is_empty())
                    .map(str::to_owned),
            }),
            "serial" => {
                let (path, query) = rest.split_once('?').unwrap_or((rest, ""));
                if path.trim().is_empty() {
                    return Err(bad(DutProblem::NoPortPath));
                }
                let mut baud = None;
                for pair in query.split('&').filter(|p| !p.is_empty()) {
                    match pair.split_once('=') {
                        Some(("baud", v)) => {
                            baud = Some(
                                v.parse::<u32>()
                                    .map_err(|_| bad(DutProblem::BaudNotNumber))?,
                            )
                        }
                        _ => return Err(bad(DutProblem::UnknownOption(pair.to_owned()))),
                    }
                }
                Ok(Dut::Serial {
                    path: path.trim().to_owned(),
                    baud,
                })
            }
            "tcp" => {
                let ok = rest
                    .rsplit_once(':')
                    .is_some_and(|(h, p)| !h.is_empty() && p.parse::<u16>().is_ok());
                if !ok {
                    return Err(bad(DutProblem::NotHostPort));
                }
                Ok(Dut::Tcp {
                    addr: rest.to_owned(),
                })
            }
            "exec" => {
                let argv = split_command(rest).map_err(|e| bad(e.into()))?;
                if argv.is_empty() {
                    return Err(bad(DutProblem::NoCommand));
                }
                Ok(Dut::Exec { argv })
            }
            "profinet" => match rest.trim().split_once('/') {
                Some((iface, name)) if !iface.is_empty() && !name.is_empty() => Ok(Dut::Profinet {
                    iface: iface.to_owned(),
                    name: name.to_owned(),
                }),
                _ => Err(bad(DutProblem::NotIfaceName)),
            },
            _ => Err(bad(DutProblem::UnknownTransport)),
        }
    }
}

impl fmt::Display for Dut {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Dut::Sim { model: None } => f.write_str("sim"),
            Dut::Sim { model: Some(m) } => write!(f, "sim:{m}"),
            Dut::Serial { path, baud: None } => write!(f, "serial:{path}"),
            Dut::Serial {
                path,
                baud: Some(b),
            } => write!(f, "serial:{path}?baud={b}"),
            Dut::Tcp { addr } => write!(f, "tcp:{addr}"),
            Dut::Exec { argv } => {
                let words: Vec<String> = argv.iter().map(|w| shell_quote(w)).collect();
                write!(f, "exec:{}", words.join(" "))
            }
            Dut::Profinet { iface, name } => write!(f, "profinet:{iface}/{name}"),
        }
    }
}

/// Splits a command line into words: blanks separate, `'…'` and `"…"` quote, `\` escapes.
pub fn split_command(s: &str) -> Result<Vec<String>, SplitError> {
    let mut words = Vec::new();
    let mut cur = String::new();
    let mut in_word = false;
    let mut chars = s.chars();
    while let Some(c) = chars.next() {
        match c {
            '\'' => {
                in_word = true;
                loop {
                    match chars.next() {
                        Some('\'') => break,
                        Some(c) => cur.push(c),
                        None => return Err(SplitError::Unterminated('\'')),
                    }
                }
            }
            '"' => {
                in_word = true;
                loop {
                    match chars.next() {
                        Some('"') => break,
                        Some('\\') => match chars.next() {
                            Some(c) => cur.push(c),
                            None => return Err(SplitError::TrailingBackslash),
                        },
                        Some(c) => cur.push(c),
                        None => return Err(SplitError::Unterminated('"')),
                    }
                }
            }
            '\\' => {
                in_word = true;
                match chars.next() {
                    Some(c) => cur.push(c),
                    None => return Err(SplitError::TrailingBackslash),
                }
            }
            c if c.is_whitespace() => {
                if in_word {
                    words.push(std::mem::take(&mut cur));
                    in_word = false;
                }
            }
            c => {
                in_word = true;
                cur.push(c);
            }
        }
    }
    if in_word {
        words.push(cur);
    }
    Ok(words)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_every_form() {
        assert_eq!("sim".parse::<Dut>().unwrap(), Dut::Sim { model: None });
        assert_eq!(
            "sim:HPD5".parse::<Dut>().unwrap(),
            Dut::Sim {
                model: Some("HPD5".into())
            }
        );
        assert_eq!(
            "serial:/dev/ttyUSB0?baud=57600".parse::<Dut>().unwrap(),
            Dut::Serial {
                path: "/dev/ttyUSB0".into(),
                baud: Some(57600)
            }
        );
        assert_eq!(
            "tcp:127.0.0.1:5000".parse::<Dut>().unwrap(),
            Dut::Tcp {
                addr: "127.0.0.1:5000".into()
            }
        );
        assert_eq!(
            "exec:python3 'my adapter.py' --x".parse::<Dut>().unwrap(),
            Dut::Exec {
                argv: vec!["python3".into(), "my adapter.py".into(), "--x".into()]
            }
        );
        for (bad, why) in [
            ("tcp:host", DutProblem::NotHostPort),
            ("serial:", DutProblem::NoPortPath),
            ("serial:/dev/x?baud=fast", DutProblem::BaudNotNumber),
            (
                "serial:/dev/x?speed=1",
                DutProblem::UnknownOption("speed=1".into()),
            ),
            ("exec:", DutProblem::NoCommand),
            ("exec:'x", SplitError::Unterminated('\'').into()),
            ("exec:\"x", SplitError::Unterminated('"').into()),
            ("exec:x\\", SplitError::TrailingBackslash.into()),
            ("usb:1", DutProblem::UnknownTransport),
            ("profinet:eth0", DutProblem::NotIfaceName),
            ("profinet:/psd", DutProblem::NotIfaceName),
            ("profinet:eth0/", DutProblem::NotIfaceName),
        ] {
            assert_eq!(bad.parse::<Dut>().map_err(|e| e.why), Err(why), "{bad}");
        }
        assert_eq!(
            "profinet:veth0/psd-sim".parse::<Dut>().unwrap(),
            Dut::Profinet {
                iface: "veth0".into(),
                name: "psd-sim".into()
            }
        );
        let e = "exec:'x".parse::<Dut>().unwrap_err().to_string();
        assert!(
            e.starts_with("--dut \"exec:'x\": unterminated ' quote ("),
            "{e}"
        );
    }

    #[test]
    fn display_round_trips() {
        for s in [
            "sim",
            "sim:HPD5",
            "serial:/dev/ttyS0?baud=9600",
            "tcp:127.0.0.1:9",
            "exec:python3 'a b.py'",
            "profinet:eth1/psd-4",
        ] {
            let d: Dut = s.parse().unwrap();
            assert_eq!(d.to_string().parse::<Dut>().unwrap(), d);
        }
    }
}
