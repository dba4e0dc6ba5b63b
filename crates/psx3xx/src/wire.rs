//! Process images on the wire (manual 3.3.1, 3.3.2): field layouts read from the spec and a
//! checked view over image bytes.
//!
//! A [`FieldLayout`] is one field of `protocol.process_output` / `protocol.process_input`: the
//! word that holds it (offset, length, the spec's byte order) and the bits of the word it
//! occupies (the time-stamp word of format 0 holds two fields). An [`Image`] is a buffer with
//! a layout and the byte order setting, in the manner of smoltcp's `Packet<T>`:
//! [`Image::new_checked`] verifies the length once, after which field reads cannot fail.
//!
//! Byte order: the spec gives each word's order on the wire (IO-Link: most significant octet
//! first). The setting passed to a view is the order the master presents; when it differs
//! from the wire order every word is read with its bytes reversed (manual 3.3.2 note: some
//! masters swap both output and input data).
//!
//! Nothing here panics or allocates on any input.

use crate::error::{EmitError, ImageError, RulesError};
use drivespec_positioner::{ByteOrder, Field};
use drivespec_spec::psx3xx::{Direction, PdField, ProcessImage};
use drivespec_spec::DataType;

/// One field of a process image (manual 3.3): its word and the bits it occupies.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldLayout {
    name: String,
    word: Field,
    bit: u32,
    bits: u32,
    signed: bool,
    data_type: DataType,
    params: Vec<String>,
    bitfield: Option<String>,
    description: String,
    source: String,
}

/// Mask of the low `bits` bits (1..=64).
fn mask(bits: u32) -> u64 {
    u64::MAX >> (64 - bits.clamp(1, 64))
}

impl FieldLayout {
    /// Reads a field of the spec's process image `image` (manual 3.3).
    pub fn from_spec(image: &str, f: &PdField) -> Result<FieldLayout, RulesError> {
        let bad = |what: String| RulesError::Image {
            image: image.to_owned(),
            what: format!("field {}: {what}", f.name),
        };
        let offset = usize::try_from(f.offset).map_err(|_| bad("offset too large".into()))?;
        let len = usize::try_from(f.length).map_err(|_| bad("length too large".into()))?;
        let order = ByteOrder::from(f.byte_order);
        let word = Field::new(offset, len, order).map_err(|e| bad(e.to_string()))?;
        if f.bits == 0
            || f.bit
                .checked_add(f.bits)
                .is_none_or(|end| end > word.bits())
        {
            return Err(bad(format!(
                "bits {}..{} outside the {}-bit word",
                f.bit,
                f.bit.saturating_add(f.bits),
                word.bits()
            )));
        }
        Ok(FieldLayout {
            name: f.name.clone(),
            word,
            bit: f.bit,
            bits: f.bits,
            signed: f.data_type.signed(),
            data_type: f.data_type,
            params: f.params.clone(),
            bitfield: f.bitfield.clone(),
            description: f.description.clone(),
            source: f.source.clone(),
        })
    }

    /// The spec's field name (`control_word`, `target`, `stamp` …) (manual 3.3).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Offset of the word holding the field (manual 3.3).
    pub fn offset(&self) -> usize {
        self.word.offset()
    }

    /// Length in bytes of the word holding the field (manual 3.3).
    pub fn len(&self) -> usize {
        self.word.len()
    }

    /// Always false: a word has at least one byte (manual 3.3).
    pub fn is_empty(&self) -> bool {
        self.word.is_empty()
    }

    /// Offset just past the word (manual 3.3).
    pub fn end(&self) -> usize {
        self.word.end()
    }

    /// Least significant bit of the field inside its word (manual 3.3).
    pub fn bit(&self) -> u32 {
        self.bit
    }

    /// Width of the field in bits (manual 3.3).
    pub fn bits(&self) -> u32 {
        self.bits
    }

    /// Whether the field shares its word with others (the time-stamp word, manual 3.3.1).
    pub fn is_sub_word(&self) -> bool {
        self.bits < self.word.bits()
    }

    /// Whether the value is two's complement (manual 3.3).
    pub fn signed(&self) -> bool {
        self.signed
    }

    /// The spec's value type (manual 3.3).
    pub fn data_type(&self) -> DataType {
        self.data_type
    }

    /// The word's byte order on the wire, as the spec gives it (manual 3.3).
    pub fn wire_order(&self) -> ByteOrder {
        self.word.order()
    }

    /// Corresponding ISDU parameter ids, the main one first (manual 3.3 tables).
    pub fn params(&self) -> &[String] {
        &self.params
    }

    /// Id of the bitfield describing the field's bits (`status`, `control`) (manual 3.3).
    pub fn bitfield(&self) -> Option<&str> {
        self.bitfield.as_deref()
    }

    /// The spec's one-line description (manual 3.3).
    pub fn description(&self) -> &str {
        &self.description
    }

    /// Manual section (manual 3.3).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Smallest value the field holds (manual 3.3).
    pub fn min(&self) -> i64 {
        if self.signed {
            i64::MIN >> (64 - self.bits.clamp(1, 64))
        } else {
            0
        }
    }

    /// Largest value the field holds (manual 3.3).
    pub fn max(&self) -> i64 {
        if self.signed {
            (mask(self.bits) >> 1) as i64
        } else {
            i64::try_from(mask(self.bits)).unwrap_or(i64::MAX)
        }
    }

    /// The word with the order the master presents (`order`) given the wire order `wire`.
    fn word(&self, order: ByteOrder, wire: ByteOrder) -> Field {
        self.word
            .with_order(self.word.order().inverted_if(order != wire))
    }

    /// The raw word holding the field (manual 3.3).
    pub fn read_word(&self, buf: &[u8], order: ByteOrder, wire: ByteOrder) -> Option<u64> {
        self.word(order, wire).read_unsigned(buf).ok()
    }

    /// The field's value in `buf`; None when `buf` is too short (manual 3.3).
    pub fn read(&self, buf: &[u8], order: ByteOrder, wire: ByteOrder) -> Option<i64> {
        let raw = self.read_word(buf, order, wire)?;
        let v = raw.checked_shr(self.bit).unwrap_or(0) & mask(self.bits);
        Some(if self.signed {
            let shift = 64 - self.bits.clamp(1, 64);
            ((v << shift) as i64) >> shift
        } else {
            i64::try_from(v).unwrap_or(i64::MAX)
        })
    }

    /// Writes the field's value into `buf`, keeping the other bits of its word (manual 3.3).
    pub fn write(
        &self,
        buf: &mut [u8],
        order: ByteOrder,
        wire: ByteOrder,
        value: i64,
    ) -> Result<(), EmitError> {
        if !(self.min()..=self.max()).contains(&value) {
            return Err(EmitError::Range {
                field: self.name.clone(),
                value,
                min: self.min(),
                max: self.max(),
            });
        }
        let word = self.word(order, wire);
        let have = buf.len();
        let old = word.read_unsigned(buf).map_err(|_| EmitError::Buffer {
            need: word.end(),
            have,
        })?;
        let m = mask(self.bits).checked_shl(self.bit).unwrap_or(0);
        let v = (value as u64 & mask(self.bits))
            .checked_shl(self.bit)
            .unwrap_or(0);
        word.write_unsigned(buf, (old & !m) | v)
            .map_err(|_| EmitError::Buffer {
                need: word.end(),
                have,
            })
    }
}

/// A process image of the spec (manual 3.3.1 output formats, 3.3.2 input).
#[derive(Debug, Clone, PartialEq)]
pub struct ImageLayout {
    direction: Direction,
    format: Option<u8>,
    name: String,
    length: usize,
    fields: Vec<FieldLayout>,
    wire: ByteOrder,
    source: String,
}

impl ImageLayout {
    /// Reads a spec process image; every field must lie inside the image (manual 3.3).
    pub fn from_spec(p: &ProcessImage, wire: ByteOrder) -> Result<ImageLayout, RulesError> {
        let length = usize::try_from(p.length).map_err(|_| RulesError::Image {
            image: p.name.clone(),
            what: "length too large".into(),
        })?;
        let mut fields = Vec::with_capacity(p.fields.len());
        for f in &p.fields {
            let layout = FieldLayout::from_spec(&p.name, f)?;
            if layout.end() > length {
                return Err(RulesError::Image {
                    image: p.name.clone(),
                    what: format!("field {} ends at byte {} of {length}", f.name, layout.end()),
                });
            }
            if fields.iter().any(|o: &FieldLayout| o.name == f.name) {
                return Err(RulesError::Image {
                    image: p.name.clone(),
                    what: format!("field {} listed twice", f.name),
                });
            }
            fields.push(layout);
        }
        Ok(ImageLayout {
            direction: p.direction,
            format: p.format,
            name: p.name.clone(),
            length,
            fields,
            wire,
            source: p.source.clone(),
        })
    }

    /// `out` (master to device) or `in` (manual 3.3).
    pub fn direction(&self) -> Direction {
        self.direction
    }

    /// ISDU 116 format of an output image (manual 3.3).
    pub fn format(&self) -> Option<u8> {
        self.format
    }

    /// The spec's image name (`time-stamp`, `six-byte`, `eight-byte`, `input`) (manual 3.3).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Image length in bytes (manual 3.3).
    pub fn length(&self) -> usize {
        self.length
    }

    /// The fields in spec order (manual 3.3).
    pub fn fields(&self) -> &[FieldLayout] {
        &self.fields
    }

    /// A field by spec name (manual 3.3).
    pub fn field(&self, name: &str) -> Option<&FieldLayout> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// The wire byte order (manual 3.3.2; IO-Link octet order).
    pub fn wire_order(&self) -> ByteOrder {
        self.wire
    }

    /// Manual section (manual 3.3).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The field names, comma separated (for messages) (manual 3.3).
    pub fn field_names(&self) -> String {
        let names: Vec<&str> = self.fields.iter().map(|f| f.name()).collect();
        names.join(", ")
    }
}

/// A buffer viewed as a process image (manual 3.3), smoltcp `Packet` style.
#[derive(Debug, Clone)]
pub struct Image<'l, T: AsRef<[u8]>> {
    buffer: T,
    layout: &'l ImageLayout,
    order: ByteOrder,
}

impl<'l, T: AsRef<[u8]>> Image<'l, T> {
    /// A view without a length check; reads of fields past the end give None (manual 3.3).
    pub fn new_unchecked(buffer: T, layout: &'l ImageLayout, order: ByteOrder) -> Image<'l, T> {
        Image {
            buffer,
            layout,
            order,
        }
    }

    /// A view of a buffer at least as long as the image (manual 3.3).
    pub fn new_checked(
        buffer: T,
        layout: &'l ImageLayout,
        order: ByteOrder,
    ) -> Result<Image<'l, T>, ImageError> {
        let image = Image::new_unchecked(buffer, layout, order);
        image.check_len()?;
        Ok(image)
    }

    /// `Truncated` when the buffer is shorter than the image (manual 3.3).
    pub fn check_len(&self) -> Result<(), ImageError> {
        let have = self.buffer.as_ref().len();
        if have < self.layout.length {
            return Err(ImageError::Truncated {
                need: self.layout.length,
                have,
            });
        }
        Ok(())
    }

    /// The image layout (manual 3.3).
    pub fn layout(&self) -> &'l ImageLayout {
        self.layout
    }

    /// The byte order setting of the view (manual 3.3).
    pub fn order(&self) -> ByteOrder {
        self.order
    }

    /// The image's bytes (the buffer cut to the image length when longer) (manual 3.3).
    pub fn bytes(&self) -> &[u8] {
        let b = self.buffer.as_ref();
        b.get(..self.layout.length).unwrap_or(b)
    }

    /// The underlying buffer (manual 3.3).
    pub fn into_inner(self) -> T {
        self.buffer
    }

    /// A field's value by spec name; None for an unknown name or a short buffer (manual 3.3).
    pub fn get(&self, name: &str) -> Option<i64> {
        self.layout
            .field(name)?
            .read(self.buffer.as_ref(), self.order, self.layout.wire)
    }

    /// The raw word holding a field; None for an unknown name or a short buffer (manual 3.3).
    pub fn word(&self, name: &str) -> Option<u64> {
        self.layout
            .field(name)?
            .read_word(self.buffer.as_ref(), self.order, self.layout.wire)
    }
}

impl<T: AsRef<[u8]> + AsMut<[u8]>> Image<'_, T> {
    /// Writes a field by spec name (manual 3.3).
    pub fn set(&mut self, name: &str, value: i64) -> Result<(), EmitError> {
        let field = self.layout.field(name).ok_or_else(|| EmitError::NoField {
            field: name.to_owned(),
        })?;
        field.write(self.buffer.as_mut(), self.order, self.layout.wire, value)
    }
}
