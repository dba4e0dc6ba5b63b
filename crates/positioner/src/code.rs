//! Open enums over wire codes, rustls style (PSD4xx manual 3.8 command, response and error
//! codes; PSx3xx manual 3.1 ISDU codes).
//!
//! A wire code is a newtype over its raw integer ([`open_enum!`](crate::open_enum!)), so every value decodes,
//! including ones no table lists, and re-encodes to the same bytes. What a code *means*
//! comes only from the spec: a [`CodeTable`] maps codes to the spec's kebab-case names and
//! labels, and the macro's companion struct looks the codes the codec needs up by those
//! names (the names are the contract with `spec/`, the numbers are never typed twice).
//! [`CodeTable::named`] gives a value whose `Display` is the spec name, or hex for codes the
//! table does not list.
//!
//! ```
//! use drivespec_positioner::{open_enum, CodeEntry, CodeTable};
//!
//! open_enum! {
//!     /// A response code.
//!     pub struct Answer(u8);
//!     /// The answers the codec needs, looked up by spec name.
//!     pub struct Answers {
//!         /// `no-response`.
//!         none = "no-response",
//!         /// `cannot-execute`.
//!         failed = "cannot-execute",
//!     }
//! }
//!
//! let table = CodeTable::new("response", [
//!     CodeEntry::new(Answer(0), "no-response", "No response", "3.8"),
//!     CodeEntry::new(Answer(7), "cannot-execute", "Command cannot be executed", "3.8"),
//! ]).unwrap();
//! let known = Answers::from_table(&table).unwrap();
//! assert_eq!(known.failed, Answer(7));
//! assert_eq!(table.named(Answer(7)).to_string(), "cannot-execute");
//! assert_eq!(table.named(Answer(9)).to_string(), "0x09");
//! ```

use serde::ser::SerializeStruct;
use serde::Serialize;
use std::fmt;

/// A wire code newtype made by [`open_enum!`](crate::open_enum!) (PSD4xx 3.8).
pub trait WireCode: Copy + Eq + Ord + std::hash::Hash + fmt::Debug {
    /// Bits of the raw integer type (for hex formatting).
    const BITS: u32;

    /// The raw code, widened.
    fn to_u64(self) -> u64;
}

/// Writes `value` as `0x` and two hex digits per byte of a `bits`-wide code (PSD4xx 3.8).
pub fn fmt_hex(value: u64, bits: u32, f: &mut fmt::Formatter<'_>) -> fmt::Result {
    let digits = usize::try_from(bits.div_ceil(4)).unwrap_or(16);
    write!(f, "0x{value:0digits$X}")
}

/// One row of a spec code table: code, kebab-case name, label and manual section (PSD4xx 3.8).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CodeEntry<C> {
    /// The wire code.
    pub code: C,
    /// The spec's kebab-case key (`read`, `cannot-execute`, `out-of-range`).
    pub name: String,
    /// The manual's designation or meaning, one line.
    pub label: String,
    /// Manual section.
    pub source: String,
}

impl<C> CodeEntry<C> {
    /// A row from its parts (PSD4xx 3.8).
    pub fn new(
        code: C,
        name: impl Into<String>,
        label: impl Into<String>,
        source: impl Into<String>,
    ) -> CodeEntry<C> {
        CodeEntry {
            code,
            name: name.into(),
            label: label.into(),
            source: source.into(),
        }
    }
}

/// A spec table is unusable as a code table, or lacks a code the codec needs (PSD4xx 3.8).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CodeTableError {
    /// Two rows with the same code.
    #[error("{table} table: code {code} listed twice")]
    DuplicateCode {
        /// Table name.
        table: String,
        /// The code.
        code: u64,
    },
    /// Two rows with the same name.
    #[error("{table} table: name {name:?} listed twice")]
    DuplicateName {
        /// Table name.
        table: String,
        /// The name.
        name: String,
    },
    /// A name the codec looks up is missing.
    #[error("{table} table: no code named {name:?}")]
    Missing {
        /// Table name.
        table: String,
        /// The name looked for.
        name: String,
    },
}

/// The codes of one spec table with their names (PSD4xx 3.8 command/response/error tables).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CodeTable<C> {
    table: String,
    entries: Vec<CodeEntry<C>>,
}

impl<C: WireCode> CodeTable<C> {
    /// A table from spec rows; duplicate codes or names are rejected (PSD4xx 3.8).
    pub fn new(
        table: impl Into<String>,
        entries: impl IntoIterator<Item = CodeEntry<C>>,
    ) -> Result<CodeTable<C>, CodeTableError> {
        let table = table.into();
        let mut out: Vec<CodeEntry<C>> = Vec::new();
        for e in entries {
            if out.iter().any(|o| o.code == e.code) {
                return Err(CodeTableError::DuplicateCode {
                    table,
                    code: e.code.to_u64(),
                });
            }
            if out.iter().any(|o| o.name == e.name) {
                return Err(CodeTableError::DuplicateName {
                    table,
                    name: e.name,
                });
            }
            out.push(e);
        }
        Ok(CodeTable {
            table,
            entries: out,
        })
    }

    /// The table's name (for errors) (PSD4xx 3.8).
    pub fn table(&self) -> &str {
        &self.table
    }

    /// The rows in spec order (PSD4xx 3.8).
    pub fn entries(&self) -> &[CodeEntry<C>] {
        &self.entries
    }

    /// The row of a code, None for codes the spec does not list (PSD4xx 3.8).
    pub fn entry(&self, code: C) -> Option<&CodeEntry<C>> {
        self.entries.iter().find(|e| e.code == code)
    }

    /// The spec name of a code (PSD4xx 3.8).
    pub fn name(&self, code: C) -> Option<&str> {
        self.entry(code).map(|e| e.name.as_str())
    }

    /// The code with a spec name (case-insensitive) (PSD4xx 3.8).
    pub fn code(&self, name: &str) -> Option<C> {
        self.entries
            .iter()
            .find(|e| e.name.eq_ignore_ascii_case(name))
            .map(|e| e.code)
    }

    /// The code with a spec name, or `Missing` (PSD4xx 3.8).
    pub fn require(&self, name: &str) -> Result<C, CodeTableError> {
        self.code(name).ok_or_else(|| CodeTableError::Missing {
            table: self.table.clone(),
            name: name.to_owned(),
        })
    }

    /// Whether the spec lists the code (PSD4xx 3.8).
    pub fn contains(&self, code: C) -> bool {
        self.entry(code).is_some()
    }

    /// The code with its row, for display and JSON (PSD4xx 3.8).
    pub fn named(&self, code: C) -> Named<'_, C> {
        Named {
            code,
            entry: self.entry(code),
        }
    }
}

/// A code with its spec row if any: `Display` gives the spec name, or hex for an unknown code
/// (PSD4xx 3.8); JSON is `{"code", "name"?, "label"?}`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Named<'t, C> {
    code: C,
    entry: Option<&'t CodeEntry<C>>,
}

impl<'t, C: WireCode> Named<'t, C> {
    /// The code (PSD4xx 3.8).
    pub fn code(&self) -> C {
        self.code
    }

    /// The spec row, None for an unknown code (PSD4xx 3.8).
    pub fn entry(&self) -> Option<&'t CodeEntry<C>> {
        self.entry
    }

    /// Whether the spec lists the code (PSD4xx 3.8).
    pub fn is_known(&self) -> bool {
        self.entry.is_some()
    }

    /// The spec name, None for an unknown code (PSD4xx 3.8).
    pub fn name(&self) -> Option<&'t str> {
        self.entry.map(|e| e.name.as_str())
    }

    /// The label, None for an unknown code (PSD4xx 3.8).
    pub fn label(&self) -> Option<&'t str> {
        self.entry.map(|e| e.label.as_str())
    }
}

impl<C: WireCode> fmt::Display for Named<'_, C> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.entry {
            Some(e) => f.write_str(&e.name),
            None => fmt_hex(self.code.to_u64(), C::BITS, f),
        }
    }
}

impl<C: WireCode> Serialize for Named<'_, C> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let n = if self.entry.is_some() { 3 } else { 1 };
        let mut st = s.serialize_struct("Named", n)?;
        st.serialize_field("code", &self.code.to_u64())?;
        if let Some(e) = self.entry {
            st.serialize_field("name", &e.name)?;
            st.serialize_field("label", &e.label)?;
        } else {
            st.skip_field("name")?;
            st.skip_field("label")?;
        }
        st.end()
    }
}

/// Declares an open enum over a wire code and the struct of codes looked up by spec name
/// (PSD4xx 3.8; rustls `msgs/macros.rs` pattern with the numbers taken from the spec).
///
/// The first struct becomes a `Copy` newtype over the raw integer with `From` both ways,
/// `Display` as hex (use [`CodeTable::named`] for the spec name), serde as the bare number and
/// [`WireCode`]. The second struct gets one public field per line, filled by
/// `from_table(&CodeTable)` from the row with that spec name, and a `NAMES` constant.
#[macro_export]
macro_rules! open_enum {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident($raw:ty);
        $(#[$kmeta:meta])*
        $kvis:vis struct $known:ident {
            $( $(#[$fmeta:meta])* $field:ident = $spec:literal ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
        $vis struct $name(pub $raw);

        impl $crate::code::WireCode for $name {
            const BITS: u32 = <$raw>::BITS;
            fn to_u64(self) -> u64 {
                u64::from(self.0)
            }
        }

        impl ::core::convert::From<$raw> for $name {
            fn from(raw: $raw) -> $name {
                $name(raw)
            }
        }

        impl ::core::convert::From<$name> for $raw {
            fn from(code: $name) -> $raw {
                code.0
            }
        }

        impl ::core::fmt::Display for $name {
            fn fmt(&self, f: &mut ::core::fmt::Formatter<'_>) -> ::core::fmt::Result {
                $crate::code::fmt_hex(u64::from(self.0), <$raw>::BITS, f)
            }
        }

        impl $crate::__serde::Serialize for $name {
            fn serialize<S: $crate::__serde::Serializer>(
                &self,
                s: S,
            ) -> ::core::result::Result<S::Ok, S::Error> {
                $crate::__serde::Serialize::serialize(&self.0, s)
            }
        }

        impl<'de> $crate::__serde::Deserialize<'de> for $name {
            fn deserialize<D: $crate::__serde::Deserializer<'de>>(
                d: D,
            ) -> ::core::result::Result<$name, D::Error> {
                <$raw as $crate::__serde::Deserialize<'de>>::deserialize(d).map($name)
            }
        }

        $(#[$kmeta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        $kvis struct $known {
            $( $(#[$fmeta])* pub $field: $name, )*
        }

        impl $known {
            /// The spec names looked up, in declaration order (PSD4xx 3.8).
            pub const NAMES: &'static [&'static str] = &[$($spec),*];

            /// Looks every code up in the spec table by its name (PSD4xx 3.8).
            pub fn from_table(
                table: &$crate::code::CodeTable<$name>,
            ) -> ::core::result::Result<$known, $crate::code::CodeTableError> {
                Ok($known {
                    $( $field: table.require($spec)?, )*
                })
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    crate::open_enum! {
        /// Test code.
        pub struct Code(u16);
        /// Test names.
        pub struct Known {
            /// a
            alpha = "alpha",
            /// b
            beta = "beta",
        }
    }

    fn table() -> Result<CodeTable<Code>, CodeTableError> {
        CodeTable::new(
            "test",
            [
                CodeEntry::new(Code(1), "alpha", "Alpha", "1"),
                CodeEntry::new(Code(0x102), "beta", "Beta", "2"),
            ],
        )
    }

    #[test]
    fn lookups() -> Result<(), CodeTableError> {
        let t = table()?;
        let k = Known::from_table(&t)?;
        assert_eq!((k.alpha, k.beta), (Code(1), Code(0x102)));
        assert_eq!(Known::NAMES, &["alpha", "beta"]);
        assert_eq!(t.code("BETA"), Some(Code(0x102)));
        assert_eq!(t.named(Code(1)).to_string(), "alpha");
        assert_eq!(t.named(Code(7)).to_string(), "0x0007");
        assert_eq!(Code(7).to_string(), "0x0007");
        assert!(!t.named(Code(7)).is_known());
        assert_eq!(u16::from(Code::from(9)), 9);
        Ok(())
    }

    #[test]
    fn duplicates_and_missing() {
        let dup = CodeTable::new(
            "t",
            [
                CodeEntry::new(Code(1), "a", "", ""),
                CodeEntry::new(Code(1), "b", "", ""),
            ],
        );
        assert_eq!(
            dup,
            Err(CodeTableError::DuplicateCode {
                table: "t".into(),
                code: 1
            })
        );
        let dup = CodeTable::new(
            "t",
            [
                CodeEntry::new(Code(1), "a", "", ""),
                CodeEntry::new(Code(2), "a", "", ""),
            ],
        );
        assert!(matches!(dup, Err(CodeTableError::DuplicateName { .. })));
        let t = CodeTable::new("t", [CodeEntry::new(Code(1), "alpha", "", "")]);
        assert_eq!(
            t.and_then(|t| Known::from_table(&t)),
            Err(CodeTableError::Missing {
                table: "t".into(),
                name: "beta".into()
            })
        );
    }

    #[test]
    fn json() -> Result<(), Box<dyn std::error::Error>> {
        let t = table()?;
        assert_eq!(
            serde_json::to_string(&t.named(Code(1)))?,
            r#"{"code":1,"name":"alpha","label":"Alpha"}"#
        );
        assert_eq!(serde_json::to_string(&t.named(Code(5)))?, r#"{"code":5}"#);
        assert_eq!(serde_json::to_string(&Code(5))?, "5");
        assert_eq!(serde_json::from_str::<Code>("513")?, Code(513));
        Ok(())
    }
}
