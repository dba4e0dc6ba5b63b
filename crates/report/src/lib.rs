//! Report formats shared by `drivespec conform`, `drivespec fuzz` and `drivespec check`:
//! XML 1.0 escaping ([`escape`]), JUnit XML ([`junit`]), pretty JSON ([`json`]), pieces of
//! self-contained HTML pages ([`html`]), inline SVG ([`svg`], [`plot`]) and atomic report
//! files ([`write_atomic`]). Nothing here panics; every writer returns its text.

#![forbid(unsafe_code)]

mod escape;
mod file;
pub mod html;
pub mod junit;
pub mod plot;
pub mod svg;

pub use escape::escape;
pub use file::{check_writable, write_atomic, write_set, WriteError};

/// `value` as pretty-printed JSON; a serialisation error becomes `{"error": "…"}`.
pub fn json<T: serde::Serialize + ?Sized>(value: &T) -> String {
    serde_json::to_string_pretty(value)
        .unwrap_or_else(|e| format!("{{\"error\": {:?}}}", e.to_string()))
}
