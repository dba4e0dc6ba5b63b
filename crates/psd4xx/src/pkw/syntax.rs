//! The `--pkw` mini-syntax of requests and replies (manual 3.8), documented on
//! [`RequestError`]: parsing into typed [`Request`]s and [`Reply`]s and formatting back.
//! Parsing never panics and allocates only for error messages.

use super::{ErrorCode, PkwRequest, PkwResponse, PkwRules, Reply, Request};
use crate::error::RequestError;
use drivespec_spec::psd4xx::{PkwOp, PkwValue};

impl PkwRules {
    /// Parses the request mini-syntax (see [`RequestError`]) into a typed request (3.8).
    pub fn parse_request(&self, text: &str) -> Result<Request, RequestError> {
        let t = Text::split(text)?;
        let verb = t.verb.to_ascii_lowercase();
        let generic = match verb.as_str() {
            "none" => Some(None),
            "read" => Some(Some(PkwOp::Read)),
            "write" => Some(Some(PkwOp::Write)),
            "count" => Some(Some(PkwOp::Count)),
            _ => None,
        };
        let (op, forced) = match generic {
            Some(Some(op)) => (op, None),
            Some(None) => (PkwOp::None, None),
            None => {
                let code = self
                    .commands
                    .code(&verb)
                    .ok_or_else(|| RequestError::UnknownVerb {
                        verb: t.verb.to_owned(),
                        expected: self.verbs(&["none", "read", "write", "count"], true),
                    })?;
                let info = self
                    .command_info(code)
                    .ok_or(RequestError::NoCode { what: verb.clone() })?;
                (info.op, Some(info))
            }
        };
        if op == PkwOp::None {
            t.expect_end()?;
            return Ok(Request::None);
        }
        let target = t.target()?;
        let pnu = self.pnu_arg(&target)?;
        let index = target.index.map(|i| self.index_arg(i)).transpose()?;
        if let Some(info) = forced {
            match (info.array && op != PkwOp::Count, index.is_some()) {
                (true, false) => return Err(RequestError::MissingIndex { verb }),
                (false, true) => return Err(RequestError::UnexpectedIndex { verb }),
                _ => {}
            }
        }
        if op == PkwOp::Count && index.is_some() {
            return Err(RequestError::UnexpectedIndex { verb });
        }
        if op != PkwOp::Write {
            if target.value.is_some() {
                return Err(RequestError::UnexpectedValue { verb });
            }
            return Ok(match op {
                PkwOp::Count => Request::Count { pnu },
                _ => Request::Read { pnu, index },
            });
        }
        let text_value = target
            .value
            .ok_or(RequestError::MissingValue { verb: verb.clone() })?;
        let width = match forced.and_then(|i| i.value).and_then(Self::kind_width) {
            Some((w, _)) => w,
            None => match index {
                Some(_) => self.element_width(pnu),
                None => self.width(pnu),
            }
            .ok_or(RequestError::UnknownWidth { pnu })?,
        };
        let value = number("value", text_value)?;
        self.pwe_for(pnu, value, width)?;
        Ok(Request::Write {
            pnu,
            index,
            width,
            value,
        })
    }

    /// Parses the request mini-syntax straight into a block (3.8).
    pub fn request_from_text(&self, text: &str) -> Result<PkwRequest, RequestError> {
        self.encode_request(&self.parse_request(text)?)
    }

    /// The request in the mini-syntax; the command's spec name is the verb when the width
    /// differs from the parameter's (3.8).
    pub fn format_request(&self, r: &Request) -> String {
        match *r {
            Request::None => "none".to_owned(),
            Request::Read { pnu, index } => format!("read:{pnu}{}", idx(index)),
            Request::Count { pnu } => format!("count:{pnu}"),
            Request::Write {
                pnu,
                index,
                width,
                value,
            } => {
                let natural = match index {
                    Some(_) => self.element_width(pnu),
                    None => self.width(pnu),
                };
                let verb = if natural == Some(width) {
                    None
                } else {
                    self.find_command(
                        PkwOp::Write,
                        index.is_some(),
                        Some(Self::value_kind(width, index.is_some())),
                    )
                    .and_then(|c| self.commands.name(c))
                };
                format!("{}:{pnu}{}={value}", verb.unwrap_or("write"), idx(index))
            }
        }
    }

    /// Parses the reply mini-syntax (see [`RequestError`]) into a typed reply (3.8).
    pub fn parse_reply(&self, text: &str) -> Result<Reply, RequestError> {
        let t = Text::split(text)?;
        let verb = t.verb.to_ascii_lowercase();
        let kind = match verb.as_str() {
            "none" => Some(PkwValue::None),
            "value" => None,
            "count" => Some(PkwValue::Count),
            "error" => Some(PkwValue::Error),
            _ => {
                let code = self
                    .responses
                    .code(&verb)
                    .ok_or_else(|| RequestError::UnknownVerb {
                        verb: t.verb.to_owned(),
                        expected: self.verbs(&["none", "value", "count", "error"], false),
                    })?;
                Some(
                    self.response_kind(code)
                        .ok_or(RequestError::NoCode { what: verb.clone() })?,
                )
            }
        };
        if kind == Some(PkwValue::None) {
            t.expect_end()?;
            return Ok(Reply::None);
        }
        let target = t.target()?;
        let pnu = self.pnu_arg(&target)?;
        let index = target.index.map(|i| self.index_arg(i)).transpose()?;
        let text_value = target
            .value
            .ok_or(RequestError::MissingValue { verb: verb.clone() })?;
        match kind {
            Some(PkwValue::Count) => {
                if index.is_some() {
                    return Err(RequestError::UnexpectedIndex { verb });
                }
                let n = number("value", text_value)?;
                let count = u32::try_from(n).map_err(|_| RequestError::ValueRange {
                    value: n,
                    min: 0,
                    max: i64::from(u32::MAX),
                })?;
                Ok(Reply::Count { pnu, count })
            }
            Some(PkwValue::Error) => {
                let error = match self.errors.code(text_value) {
                    Some(code) => code,
                    None if text_value.starts_with(|c: char| c.is_ascii_digit()) => {
                        let n = number("error code", text_value)?;
                        ErrorCode(u32::try_from(n).map_err(|_| RequestError::ValueRange {
                            value: n,
                            min: 0,
                            max: i64::from(u32::MAX),
                        })?)
                    }
                    None => {
                        return Err(RequestError::UnknownError {
                            name: text_value.to_owned(),
                        })
                    }
                };
                Ok(Reply::Error {
                    pnu,
                    index: index.unwrap_or(0),
                    error,
                })
            }
            forced => {
                let width = match forced.and_then(Self::kind_width) {
                    Some((w, array)) => {
                        match (array, index.is_some()) {
                            (true, false) => return Err(RequestError::MissingIndex { verb }),
                            (false, true) => return Err(RequestError::UnexpectedIndex { verb }),
                            _ => {}
                        }
                        w
                    }
                    None => match index {
                        Some(_) => self.element_width(pnu),
                        None => self.width(pnu),
                    }
                    .ok_or(RequestError::UnknownWidth { pnu })?,
                };
                let value = number("value", text_value)?;
                self.pwe_for(pnu, value, width)?;
                Ok(Reply::Value {
                    pnu,
                    index,
                    width,
                    value,
                })
            }
        }
    }

    /// Parses the reply mini-syntax straight into a block (3.8).
    pub fn reply_from_text(&self, text: &str) -> Result<PkwResponse, RequestError> {
        self.encode_reply(&self.parse_reply(text)?)
    }

    /// The reply in the mini-syntax (3.8).
    pub fn format_reply(&self, r: &Reply) -> String {
        match *r {
            Reply::None => "none".to_owned(),
            Reply::Count { pnu, count } => format!("count:{pnu}={count}"),
            Reply::Error { pnu, index, error } => {
                let i = if index == 0 { None } else { Some(index) };
                match self.errors.name(error) {
                    Some(name) => format!("error:{pnu}{}={name}", idx(i)),
                    None => format!("error:{pnu}{}={}", idx(i), error.0),
                }
            }
            Reply::Value {
                pnu,
                index,
                width,
                value,
            } => {
                let natural = match index {
                    Some(_) => self.element_width(pnu),
                    None => self.width(pnu),
                };
                let verb = if natural == Some(width) {
                    None
                } else {
                    self.find_response(Self::value_kind(width, index.is_some()))
                        .and_then(|c| self.responses.name(c))
                };
                format!("{}:{pnu}{}={value}", verb.unwrap_or("value"), idx(index))
            }
        }
    }

    fn verbs(&self, generic: &[&str], commands: bool) -> String {
        let mut all: Vec<&str> = generic.to_vec();
        if commands {
            all.extend(self.commands.entries().iter().map(|e| e.name.as_str()));
        } else {
            all.extend(self.responses.entries().iter().map(|e| e.name.as_str()));
        }
        all.join(", ")
    }

    fn pnu_arg(&self, t: &Target<'_>) -> Result<u16, RequestError> {
        let n = number("PNU", t.pnu)?;
        u16::try_from(n)
            .ok()
            .filter(|p| *p <= self.pnu_max())
            .ok_or(RequestError::PnuRange {
                pnu: n,
                max: u64::from(self.pnu_max()),
            })
    }

    fn index_arg(&self, text: &str) -> Result<u16, RequestError> {
        let n = number("index", text)?;
        u16::try_from(n)
            .ok()
            .filter(|i| *i <= self.index_max())
            .ok_or(RequestError::IndexRange {
                index: n,
                max: u64::from(self.index_max()),
            })
    }
}

fn idx(index: Option<u16>) -> String {
    index.map(|i| format!("[{i}]")).unwrap_or_default()
}

/// Parses a number as the mini-syntax writes it: decimal with an optional sign, or `0x` hex
/// (`0x14`, `-250`, `12_000`); for command-line values next to `--pkw` (manual 3.8).
pub fn parse_number(text: &str) -> Result<i64, RequestError> {
    number("number", text)
}

/// A decimal (optionally signed) or `0x` hexadecimal number.
pub(crate) fn number(what: &'static str, text: &str) -> Result<i64, RequestError> {
    drivespec_spec::hex::parse_int(text).map_err(|_| RequestError::Number {
        what,
        found: text.to_owned(),
    })
}

/// A mini-syntax text split at the verb.
struct Text<'a> {
    whole: &'a str,
    verb: &'a str,
    rest: Option<(usize, &'a str)>,
}

/// `pnu[index]=value` after the verb.
struct Target<'a> {
    pnu: &'a str,
    index: Option<&'a str>,
    value: Option<&'a str>,
}

impl<'a> Text<'a> {
    fn split(text: &'a str) -> Result<Text<'a>, RequestError> {
        let whole = text.trim();
        if whole.is_empty() {
            return Err(RequestError::Empty);
        }
        Ok(match whole.split_once(':') {
            Some((verb, rest)) => Text {
                whole,
                verb: verb.trim(),
                rest: Some((verb.len() + 1, rest)),
            },
            None => Text {
                whole,
                verb: whole,
                rest: None,
            },
        })
    }

    fn syntax(&self, offset: usize, expected: &'static str) -> RequestError {
        RequestError::Syntax {
            text: self.whole.to_owned(),
            offset,
            expected,
        }
    }

    fn expect_end(&self) -> Result<(), RequestError> {
        match self.rest {
            None => Ok(()),
            Some((at, _)) => Err(self.syntax(at.saturating_sub(1), "end of text")),
        }
    }

    fn target(&self) -> Result<Target<'a>, RequestError> {
        let Some((at, rest)) = self.rest else {
            return Err(self.syntax(self.whole.len(), "`:` and a parameter number"));
        };
        let (head, value) = match rest.split_once('=') {
            Some((h, v)) => (h, Some(v.trim())),
            None => (rest, None),
        };
        let (pnu, index) = match head.split_once('[') {
            Some((p, tail)) => {
                let close = tail.find(']').ok_or_else(|| {
                    self.syntax(at + p.len() + 1 + tail.len(), "`]` after the index")
                })?;
                let after = tail.get(close + 1..).unwrap_or("");
                if !after.trim().is_empty() {
                    return Err(self.syntax(at + p.len() + close + 2, "`=` or end of text"));
                }
                (p, Some(tail.get(..close).unwrap_or("").trim()))
            }
            None => (head, None),
        };
        let pnu = pnu.trim();
        if pnu.is_empty() {
            return Err(self.syntax(at, "a parameter number"));
        }
        if value == Some("") {
            return Err(self.syntax(self.whole.len(), "a value after `=`"));
        }
        Ok(Target { pnu, index, value })
    }
}
