//! Names of PNIOStatus fields and alarm types (IEC 61158-6-10 PNIOStatus coding, AlarmType),
//! read from `pnio-names.toml`, so a refusal or an abort reads in words.

use drivespec_capture::pnio::PnioStatus;
use std::collections::HashMap;

const NAMES: &str = include_str!("../pnio-names.toml");

/// The names file (`crates/check/pnio-names.toml`) does not parse; the message names the
/// record and the reason.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("PNIO names (crates/check/pnio-names.toml): {0}")]
pub struct NamesError(String);

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Named {
    value: u16,
    name: String,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct Named2 {
    code1: u8,
    value: u8,
    name: String,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct NamesFile {
    error_code: Vec<Named>,
    error_decode: Vec<Named>,
    error_code1_pniorw: Vec<Named>,
    error_code1_pnio: Vec<Named>,
    error_code2_pnio: Vec<Named2>,
    alarm_type: Vec<Named>,
}

/// The named values of PNIOStatus and AlarmType.
#[derive(Debug, Clone, Default)]
pub struct PnioNames {
    code: HashMap<u16, String>,
    decode: HashMap<u16, String>,
    code1_rw: HashMap<u16, String>,
    code1_pnio: HashMap<u16, String>,
    code2_pnio: HashMap<(u8, u8), String>,
    alarm: HashMap<u16, String>,
}

fn table(list: Vec<Named>) -> HashMap<u16, String> {
    list.into_iter().map(|n| (n.value, n.name)).collect()
}

/// `value (name)`, or the value alone when it has no name.
fn named(value: u8, name: Option<&String>) -> String {
    match name {
        Some(n) => format!("{value:#04x} ({n})"),
        None => format!("{value:#04x}"),
    }
}

impl PnioNames {
    /// The names file, read once per process (every checker of a run shares it).
    pub fn shared() -> Result<&'static PnioNames, NamesError> {
        static NAMES: std::sync::OnceLock<Result<PnioNames, NamesError>> =
            std::sync::OnceLock::new();
        NAMES
            .get_or_init(PnioNames::load)
            .as_ref()
            .map_err(Clone::clone)
    }

    /// Reads the names file.
    fn load() -> Result<PnioNames, NamesError> {
        let f: NamesFile = toml::from_str(NAMES).map_err(|e| NamesError(e.to_string()))?;
        Ok(PnioNames {
            code: table(f.error_code),
            decode: table(f.error_decode),
            code1_rw: table(f.error_code1_pniorw),
            code1_pnio: table(f.error_code1_pnio),
            code2_pnio: f
                .error_code2_pnio
                .into_iter()
                .map(|n| ((n.code1, n.value), n.name))
                .collect(),
            alarm: table(f.alarm_type),
        })
    }

    /// A PNIOStatus in words: `ErrorCode 0xdf (IODWriteRes), ErrorDecode 0x81 (PNIO),
    /// ErrorCode1 0x40 (CMRPC), ErrorCode2 0x05 (AR UUID unknown)`.
    pub fn status(&self, s: PnioStatus) -> String {
        let code1 = match s.decode {
            0x80 => self.code1_rw.get(&u16::from(s.code1)),
            0x81 => self.code1_pnio.get(&u16::from(s.code1)),
            _ => None,
        };
        let code2 = match s.decode {
            0x81 => self.code2_pnio.get(&(s.code1, s.code2)),
            _ => None,
        };
        format!(
            "ErrorCode {}, ErrorDecode {}, ErrorCode1 {}, ErrorCode2 {}",
            named(s.code, self.code.get(&u16::from(s.code))),
            named(s.decode, self.decode.get(&u16::from(s.decode))),
            named(s.code1, code1),
            named(s.code2, code2),
        )
    }

    /// The name of an AlarmType, or its number.
    pub fn alarm_type(&self, t: u16) -> String {
        match self.alarm.get(&t) {
            Some(n) => format!("{n} ({t:#06x})"),
            None => format!("{t:#06x}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_a_write_refused_for_an_unknown_ar() {
        let names = PnioNames::load().unwrap_or_default();
        let s = PnioStatus {
            code: 0xDF,
            decode: 0x81,
            code1: 0x40,
            code2: 0x05,
        };
        assert_eq!(
            names.status(s),
            "ErrorCode 0xdf (IODWriteRes), ErrorDecode 0x81 (PNIO), ErrorCode1 0x40 (CMRPC), ErrorCode2 0x05 (AR UUID unknown)"
        );
        assert_eq!(names.alarm_type(3), "Pull (0x0003)");
        assert_eq!(names.alarm_type(0x7f), "0x007f");
    }
}
