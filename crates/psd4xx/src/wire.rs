//! Wire views of the PSD4xx process data (manual 3.5): the 14-byte output module, the 16-byte
//! input module and the 8-byte PKW block (3.8 "PKW format"), with field offsets, lengths and
//! byte orders read from the spec's module layouts and the byte-order setting.
//!
//! No-panic rules (smoltcp `wire` style): a view made with `new_checked` has exactly the
//! module's length, and every field lies inside it (checked when the [`Layout`] is built), so
//! its accessors cannot fail. A view made with `new_unchecked` over a shorter buffer reads 0
//! and ignores writes for fields beyond the end; it never panics. Nothing here allocates
//! except [`Layout`] construction.

use crate::error::{DecodeError, RulesError};
use crate::rules::Options;
use crate::value::Params;
use drivespec_positioner::{ByteOrder, Field};
use drivespec_spec::psd4xx;
use serde::Serialize;

/// One field of a module as the spec names it, with its resolved byte order (manual 3.5).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct LayoutField {
    /// Spec key (`pke`, `ind`, `pwe`, `control`, `target`, `status`, `speed`, `actual`).
    pub name: String,
    /// The manual's designation.
    pub label: String,
    /// Offset, length and byte order.
    pub field: Field,
    /// The corresponding parameter id (3.5 "Corresponding parameter number").
    pub param: Option<String>,
    /// Two's complement value.
    pub signed: bool,
    /// The byte order is the opposite of the others (3.5 notice "UseAsBits").
    pub inverted: bool,
    /// Manual section.
    pub source: String,
}

/// A module's length and fields in offset order (manual 3.5.1, 3.5.2, 3.8).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModuleLayout {
    /// Module length in bytes.
    pub length: usize,
    /// Fields in offset order.
    pub fields: Vec<LayoutField>,
}

impl ModuleLayout {
    /// A field by spec name (manual 3.5).
    pub fn field(&self, name: &str) -> Option<&LayoutField> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// Checks that `have` bytes are exactly one module (manual 3.5).
    pub fn check_len(&self, have: usize) -> Result<(), DecodeError> {
        if have < self.length {
            Err(DecodeError::Truncated {
                need: self.length,
                have,
            })
        } else if have > self.length {
            Err(DecodeError::TrailingData {
                expected: self.length,
                have,
            })
        } else {
            Ok(())
        }
    }
}

/// The PKW fields PKE, IND, PWE inside a module or block (manual 3.8 "PKW format").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PkwFields {
    /// Parameter ID: AK, SPM, PNU (2 bytes).
    pub pke: Field,
    /// Subindex (2 bytes).
    pub ind: Field,
    /// Parameter value (4 bytes).
    pub pwe: Field,
}

/// The output module: controller → drive (manual 3.5.1).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputLayout {
    /// Length and all fields (manual 3.5).
    pub module: ModuleLayout,
    /// PKW command.
    pub pkw: PkwFields,
    /// Control word, par. 32 (inverted order, 3.5 notice).
    pub control: Field,
    /// Target value, par. 33.
    pub target: Field,
}

/// The input module: drive → controller (manual 3.5.2).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputLayout {
    /// Length and all fields (manual 3.5).
    pub module: ModuleLayout,
    /// PKW response.
    pub pkw: PkwFields,
    /// Status word, par. 1 (inverted order, 3.5 notice).
    pub status: Field,
    /// Current speed in rpm, par. 2.
    pub speed: Field,
    /// Actual position, par. 3.
    pub actual: Field,
}

/// The standalone 8-byte PKW block (manual 3.8 "PKW format").
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PkwLayout {
    /// Length and all fields (manual 3.5).
    pub module: ModuleLayout,
    /// PKE, IND, PWE.
    pub pkw: PkwFields,
}

impl PkwLayout {
    /// Reads the PKW block layout of the spec (manual 3.8 "PKW format").
    pub fn from_protocol(
        p: &psd4xx::Protocol,
        params: &Params,
        options: &Options,
    ) -> Result<PkwLayout, RulesError> {
        let block = module_of("pkw", &p.pkw.fields, p.pkw.length, params, options)?;
        Ok(PkwLayout {
            pkw: pkw_fields("pkw", &block)?,
            module: block,
        })
    }
}

/// Byte positions and orders of everything cyclic (manual 3.5, 3.8), for one byte-order setting.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Layout {
    /// Output module (3.5.1).
    pub output: OutputLayout,
    /// Input module (3.5.2).
    pub input: InputLayout,
    /// PKW block (3.8).
    pub pkw: PkwLayout,
    /// Byte order of the values that are not inverted.
    pub byte_order: ByteOrder,
    /// Whether control and status use the other order (3.5 notice).
    pub invert_bit_words: bool,
}

impl Layout {
    /// Reads the layouts from the spec's protocol table (manual 3.5, 3.8) with the byte order
    /// of `options`.
    pub fn from_protocol(
        p: &psd4xx::Protocol,
        params: &Params,
        options: &Options,
    ) -> Result<Layout, RulesError> {
        let out = module("output", &p.process_data.output, params, options)?;
        let inp = module("input", &p.process_data.input, params, options)?;
        Ok(Layout {
            output: OutputLayout {
                pkw: pkw_fields("output", &out)?,
                control: need(&out, "output", "control", 2)?,
                target: need(&out, "output", "target", 4)?,
                module: out,
            },
            input: InputLayout {
                pkw: pkw_fields("input", &inp)?,
                status: need(&inp, "input", "status", 2)?,
                speed: need(&inp, "input", "speed", 2)?,
                actual: need(&inp, "input", "actual", 4)?,
                module: inp,
            },
            pkw: PkwLayout::from_protocol(p, params, options)?,
            byte_order: options.byte_order,
            invert_bit_words: options.invert_bit_words,
        })
    }
}

fn module(
    table: &'static str,
    m: &psd4xx::Module,
    params: &Params,
    options: &Options,
) -> Result<ModuleLayout, RulesError> {
    module_of(table, &m.fields, m.length, params, options)
}

fn module_of(
    table: &'static str,
    spec_fields: &[psd4xx::Field],
    length: usize,
    params: &Params,
    options: &Options,
) -> Result<ModuleLayout, RulesError> {
    let mut fields: Vec<LayoutField> = Vec::with_capacity(spec_fields.len());
    for f in spec_fields {
        let inverted = options.invert_bit_words && f.inverted;
        let order = options.byte_order.inverted_if(inverted);
        let field = Field::new(f.offset, f.length, order).map_err(|error| RulesError::Field {
            table,
            name: f.name.clone(),
            error,
        })?;
        if field.end() > length {
            return Err(RulesError::FieldBounds {
                table,
                name: f.name.clone(),
                end: field.end(),
                length,
            });
        }
        if let Some(other) = fields
            .iter()
            .find(|o| o.field.offset() < field.end() && field.offset() < o.field.end())
        {
            return Err(RulesError::Overlap {
                table,
                a: other.name.clone(),
                b: f.name.clone(),
            });
        }
        let param = f
            .param
            .as_deref()
            .and_then(|id| params.iter().find(|p| p.id == id));
        if let Some(width) = param.and_then(|p| p.data_type.width()) {
            let expected = usize::try_from(width).unwrap_or(0);
            if expected != f.length {
                return Err(RulesError::FieldWidth {
                    table,
                    name: f.name.clone(),
                    expected,
                    found: f.length,
                });
            }
        }
        fields.push(LayoutField {
            name: f.name.clone(),
            label: f.label.clone(),
            field,
            param: f.param.clone(),
            signed: f.signed,
            inverted,
            source: f.source.clone(),
        });
    }
    fields.sort_by_key(|f| f.field.offset());
    Ok(ModuleLayout { length, fields })
}

fn need(
    m: &ModuleLayout,
    table: &'static str,
    name: &'static str,
    len: usize,
) -> Result<Field, RulesError> {
    let f = m
        .field(name)
        .ok_or(RulesError::MissingField { table, name })?;
    if f.field.len() != len {
        return Err(RulesError::FieldWidth {
            table,
            name: name.to_owned(),
            expected: len,
            found: f.field.len(),
        });
    }
    Ok(f.field)
}

fn pkw_fields(table: &'static str, m: &ModuleLayout) -> Result<PkwFields, RulesError> {
    Ok(PkwFields {
        pke: need(m, table, "pke", 2)?,
        ind: need(m, table, "ind", 2)?,
        pwe: need(m, table, "pwe", 4)?,
    })
}

fn get(f: Field, b: &[u8]) -> u64 {
    f.read_unsigned(b).unwrap_or(0)
}

fn get_signed(f: Field, b: &[u8]) -> i64 {
    f.read_signed(b).unwrap_or(0)
}

/// Writes a value that fits the field by construction; a short unchecked buffer ignores it.
fn put(f: Field, b: &mut [u8], v: u64) {
    let _ = f.write_unsigned(b, v & f.max_unsigned());
}

macro_rules! pkw_accessors {
    () => {
        /// PKE: AK, SPM and PNU as one word (3.8 PKE format).
        pub fn pke(&self) -> u16 {
            get(self.layout.pkw.pke, self.buffer.as_ref()) as u16
        }

        /// IND: the subindex word (3.8).
        pub fn ind(&self) -> u16 {
            get(self.layout.pkw.ind, self.buffer.as_ref()) as u16
        }

        /// PWE: the parameter value (3.8).
        pub fn pwe(&self) -> u32 {
            get(self.layout.pkw.pwe, self.buffer.as_ref()) as u32
        }
    };
}

macro_rules! pkw_setters {
    () => {
        /// Writes PKE (3.8).
        pub fn set_pke(&mut self, v: u16) {
            put(self.layout.pkw.pke, self.buffer.as_mut(), u64::from(v));
        }

        /// Writes IND (3.8).
        pub fn set_ind(&mut self, v: u16) {
            put(self.layout.pkw.ind, self.buffer.as_mut(), u64::from(v));
        }

        /// Writes PWE (3.8).
        pub fn set_pwe(&mut self, v: u32) {
            put(self.layout.pkw.pwe, self.buffer.as_mut(), u64::from(v));
        }
    };
}

macro_rules! view_common {
    ($layout:ty) => {
        /// A view without a length check; see the module docs for what short buffers do (manual 3.5).
        pub fn new_unchecked(layout: &'l $layout, buffer: T) -> Self {
            Self { layout, buffer }
        }

        /// A view of exactly one module (`Truncated` / `TrailingData` otherwise) (manual 3.5).
        pub fn new_checked(layout: &'l $layout, buffer: T) -> Result<Self, DecodeError> {
            let view = Self::new_unchecked(layout, buffer);
            view.check_len()?;
            Ok(view)
        }

        /// Checks that the buffer is exactly one module long (manual 3.5).
        pub fn check_len(&self) -> Result<(), DecodeError> {
            self.layout.module.check_len(self.buffer.as_ref().len())
        }

        /// The buffer (manual 3.5).
        pub fn into_inner(self) -> T {
            self.buffer
        }

        /// The bytes (manual 3.5).
        pub fn as_bytes(&self) -> &[u8] {
            self.buffer.as_ref()
        }
    };
}

/// A view of the 14-byte output module (manual 3.5.1).
#[derive(Debug, Clone)]
pub struct OutputImage<'l, T> {
    layout: &'l OutputLayout,
    buffer: T,
}

impl<'l, T: AsRef<[u8]>> OutputImage<'l, T> {
    view_common!(OutputLayout);
    pkw_accessors!();

    /// Control word, par. 32 (3.5.1, 3.7).
    pub fn control(&self) -> u16 {
        get(self.layout.control, self.buffer.as_ref()) as u16
    }

    /// Target value, par. 33 (3.5.1).
    pub fn target(&self) -> i32 {
        get_signed(self.layout.target, self.buffer.as_ref()) as i32
    }
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> OutputImage<'_, T> {
    pkw_setters!();

    /// Writes the control word (3.5.1).
    pub fn set_control(&mut self, v: u16) {
        put(self.layout.control, self.buffer.as_mut(), u64::from(v));
    }

    /// Writes the target value (3.5.1).
    pub fn set_target(&mut self, v: i32) {
        put(
            self.layout.target,
            self.buffer.as_mut(),
            u64::from(v as u32),
        );
    }
}

/// A view of the 16-byte input module (manual 3.5.2).
#[derive(Debug, Clone)]
pub struct InputImage<'l, T> {
    layout: &'l InputLayout,
    buffer: T,
}

impl<'l, T: AsRef<[u8]>> InputImage<'l, T> {
    view_common!(InputLayout);
    pkw_accessors!();

    /// Status word, par. 1 (3.5.2, 3.6).
    pub fn status(&self) -> u16 {
        get(self.layout.status, self.buffer.as_ref()) as u16
    }

    /// Current speed in rpm, par. 2 (3.5.2).
    pub fn speed(&self) -> i16 {
        get_signed(self.layout.speed, self.buffer.as_ref()) as i16
    }

    /// Actual position, par. 3 (3.5.2).
    pub fn actual(&self) -> i32 {
        get_signed(self.layout.actual, self.buffer.as_ref()) as i32
    }
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> InputImage<'_, T> {
    pkw_setters!();

    /// Writes the status word (3.5.2).
    pub fn set_status(&mut self, v: u16) {
        put(self.layout.status, self.buffer.as_mut(), u64::from(v));
    }

    /// Writes the current speed (3.5.2).
    pub fn set_speed(&mut self, v: i16) {
        put(self.layout.speed, self.buffer.as_mut(), u64::from(v as u16));
    }

    /// Writes the actual position (3.5.2).
    pub fn set_actual(&mut self, v: i32) {
        put(
            self.layout.actual,
            self.buffer.as_mut(),
            u64::from(v as u32),
        );
    }
}

/// A view of the 8-byte PKW block on its own (manual 3.8 "PKW format").
#[derive(Debug, Clone)]
pub struct PkwBlock<'l, T> {
    layout: &'l PkwLayout,
    buffer: T,
}

impl<'l, T: AsRef<[u8]>> PkwBlock<'l, T> {
    view_common!(PkwLayout);
    pkw_accessors!();
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> PkwBlock<'_, T> {
    pkw_setters!();
}
