//! Typed process data (manual 3.5): the output module (PKW command, control word, target
//! value) and the input module (PKW response, status word, speed, actual position), and a
//! builder of images from named fields.
//!
//! `parse` accepts exactly one module ([`DecodeError::Truncated`] with `need`/`have` for
//! fewer bytes, [`DecodeError::TrailingData`] for more) and never panics; `emit` writes what
//! `parse` reads, so `parse(emit(x)) == x` and `emit(parse(b)) == b` for every image `b`.

use crate::error::{BuildError, DecodeError, EmitError};
use crate::pkw::{PkwRequest, PkwResponse};
use crate::rules::Rules;
use crate::wire::{InputImage, ModuleLayout, OutputImage, PkwFields};
use crate::Pkw;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Direction of an image (manual 3.5, "from the perspective of the IO controller").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Direction {
    /// Output module: controller → drive (3.5.1).
    Out,
    /// Input module: drive → controller (3.5.2).
    In,
}

impl Direction {
    /// `out` or `in`, as in the spec's vectors and on the command line (manual 3.5).
    pub fn as_str(self) -> &'static str {
        match self {
            Direction::Out => "out",
            Direction::In => "in",
        }
    }

    /// The module layout of this direction (3.5).
    pub fn module(self, rules: &Rules) -> &ModuleLayout {
        match self {
            Direction::Out => &rules.layout().output.module,
            Direction::In => &rules.layout().input.module,
        }
    }

    fn pkw_fields(self, rules: &Rules) -> &PkwFields {
        match self {
            Direction::Out => &rules.layout().output.pkw,
            Direction::In => &rules.layout().input.pkw,
        }
    }
}

impl fmt::Display for Direction {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Direction::Out => "output",
            Direction::In => "input",
        })
    }
}

/// The output module, controller → drive (manual 3.5.1).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Output {
    /// PKW command (bytes 0–7).
    pub pkw: PkwRequest,
    /// Control word, par. 32 (bytes 8–9, 3.7).
    pub control: u16,
    /// Target value, par. 33 (bytes 10–13).
    pub target: i32,
}

/// The input module, drive → controller (manual 3.5.2).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct Input {
    /// PKW response (bytes 0–7).
    pub pkw: PkwResponse,
    /// Status word, par. 1 (bytes 8–9, 3.6).
    pub status: u16,
    /// Current speed in rpm, par. 2 (bytes 10–11).
    pub speed: i16,
    /// Actual position, par. 3 (bytes 12–15).
    pub actual: i32,
}

fn buffer(out: &mut [u8], need: usize) -> Result<&mut [u8], EmitError> {
    let have = out.len();
    out.get_mut(..need).ok_or(EmitError::Buffer { need, have })
}

impl Output {
    /// "No command", control word 0, target 0 (manual 3.8, 3.9 zero outputs).
    pub fn idle(rules: &Rules) -> Output {
        Output {
            pkw: Pkw {
                ak: rules.pkw().command_codes().no_command,
                ..Pkw::default()
            },
            control: 0,
            target: 0,
        }
    }

    /// Parses exactly one output module (3.5.1).
    pub fn parse(rules: &Rules, bytes: &[u8]) -> Result<Output, DecodeError> {
        let layout = &rules.layout().output;
        let view = OutputImage::new_checked(layout, bytes)?;
        Ok(Output {
            pkw: Pkw::read_from(rules.pkw(), &layout.pkw, bytes),
            control: view.control(),
            target: view.target(),
        })
    }

    /// Number of bytes `emit` writes (14) (manual 3.5).
    pub fn buffer_len(rules: &Rules) -> usize {
        rules.layout().output.module.length
    }

    /// Writes the module; returns the bytes written (3.5.1).
    pub fn emit(&self, rules: &Rules, out: &mut [u8]) -> Result<usize, EmitError> {
        let layout = &rules.layout().output;
        let need = Output::buffer_len(rules);
        let out = buffer(out, need)?;
        self.pkw.write_to(rules.pkw(), &layout.pkw, out)?;
        let mut view = OutputImage::new_unchecked(layout, out);
        view.set_control(self.control);
        view.set_target(self.target);
        Ok(need)
    }

    /// The module as bytes (3.5.1).
    pub fn to_bytes(&self, rules: &Rules) -> Result<Vec<u8>, EmitError> {
        let mut out = vec![0; Output::buffer_len(rules)];
        self.emit(rules, &mut out)?;
        Ok(out)
    }
}

impl Input {
    /// "No response", status 0, speed 0, actual 0 (manual 3.8).
    pub fn idle(rules: &Rules) -> Input {
        Input {
            pkw: Pkw {
                ak: rules.pkw().response_codes().no_response,
                ..Pkw::default()
            },
            status: 0,
            speed: 0,
            actual: 0,
        }
    }

    /// Parses exactly one input module (3.5.2).
    pub fn parse(rules: &Rules, bytes: &[u8]) -> Result<Input, DecodeError> {
        let layout = &rules.layout().input;
        let view = InputImage::new_checked(layout, bytes)?;
        Ok(Input {
            pkw: Pkw::read_from(rules.pkw(), &layout.pkw, bytes),
            status: view.status(),
            speed: view.speed(),
            actual: view.actual(),
        })
    }

    /// Number of bytes `emit` writes (16) (manual 3.5).
    pub fn buffer_len(rules: &Rules) -> usize {
        rules.layout().input.module.length
    }

    /// Writes the module; returns the bytes written (3.5.2).
    pub fn emit(&self, rules: &Rules, out: &mut [u8]) -> Result<usize, EmitError> {
        let layout = &rules.layout().input;
        let need = Input::buffer_len(rules);
        let out = buffer(out, need)?;
        self.pkw.write_to(rules.pkw(), &layout.pkw, out)?;
        let mut view = InputImage::new_unchecked(layout, out);
        view.set_status(self.status);
        view.set_speed(self.speed);
        view.set_actual(self.actual);
        Ok(need)
    }

    /// The module as bytes (3.5.2).
    pub fn to_bytes(&self, rules: &Rules) -> Result<Vec<u8>, EmitError> {
        let mut out = vec![0; Input::buffer_len(rules)];
        self.emit(rules, &mut out)?;
        Ok(out)
    }
}

/// Builds an image from named fields (manual 3.5): the spec's field names (`pke`, `ind`,
/// `pwe`, `control`, `target`, `status`, `speed`, `actual`) and a PKW text in the mini-syntax
/// (`read:44`, `write:44=5`; replies `value:44=2`, `error:44=out-of-range` for input images).
///
/// It starts from the idle image ("no command" / "no response", everything else 0).
#[derive(Debug, Clone)]
pub struct ImageBuilder<'r> {
    rules: &'r Rules,
    direction: Direction,
    bytes: Vec<u8>,
}

impl<'r> ImageBuilder<'r> {
    /// An idle image of one direction (3.5).
    pub fn new(rules: &'r Rules, direction: Direction) -> ImageBuilder<'r> {
        let bytes = match direction {
            Direction::Out => Output::idle(rules).to_bytes(rules),
            Direction::In => Input::idle(rules).to_bytes(rules),
        }
        .unwrap_or_else(|_| vec![0; direction.module(rules).length]);
        ImageBuilder {
            rules,
            direction,
            bytes,
        }
    }

    /// Sets a field by its spec name to a raw value (two's complement for signed fields) (manual 3.5).
    pub fn set(&mut self, name: &str, value: i64) -> Result<&mut Self, BuildError> {
        let module = self.direction.module(self.rules);
        let Some(f) = module.field(name) else {
            return Err(BuildError::UnknownField {
                direction: self.direction,
                name: name.to_owned(),
                known: module
                    .fields
                    .iter()
                    .map(|f| f.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        };
        let written = if f.signed {
            f.field.write_signed(&mut self.bytes, value)
        } else {
            match u64::try_from(value) {
                Ok(v) => f.field.write_unsigned(&mut self.bytes, v),
                Err(_) => Err(drivespec_positioner::FieldError::Range {
                    value: i128::from(value),
                    min: 0,
                    max: i128::from(f.field.max_unsigned()),
                }),
            }
        };
        written.map_err(|error| BuildError::Field {
            name: name.to_owned(),
            error,
        })?;
        Ok(self)
    }

    /// Sets the PKW block from the mini-syntax: a request for output images, a reply for
    /// input images (3.8).
    pub fn pkw(&mut self, text: &str) -> Result<&mut Self, BuildError> {
        match self.direction {
            Direction::Out => {
                let pkw = self.rules.pkw().request_from_text(text)?;
                self.pkw_request(&pkw)
            }
            Direction::In => {
                let pkw = self.rules.pkw().reply_from_text(text)?;
                self.pkw_response(&pkw)
            }
        }
    }

    /// Sets the PKW block to a request block (3.8).
    pub fn pkw_request(&mut self, pkw: &PkwRequest) -> Result<&mut Self, BuildError> {
        let fields = self.direction.pkw_fields(self.rules);
        pkw.write_to(self.rules.pkw(), fields, &mut self.bytes)?;
        Ok(self)
    }

    /// Sets the PKW block to a response block (3.8).
    pub fn pkw_response(&mut self, pkw: &PkwResponse) -> Result<&mut Self, BuildError> {
        let fields = self.direction.pkw_fields(self.rules);
        pkw.write_to(self.rules.pkw(), fields, &mut self.bytes)?;
        Ok(self)
    }

    /// The image so far (manual 3.5).
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// The finished image (manual 3.5).
    pub fn into_bytes(self) -> Vec<u8> {
        self.bytes
    }
}
