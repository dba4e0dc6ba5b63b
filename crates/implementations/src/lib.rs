//! Implementations of the three drive families as other teams could write them from the
//! manuals, to measure the conformance suite from both sides:
//!
//! - legal variants ([`hpd_variants`], [`psd4xx_variants`], [`psx3xx_variants`]): they
//!   differ from the reference only where the manual leaves the choice, and must pass every
//!   case;
//! - violation mutants ([`hpd_mutants`], [`psd4xx_mutants`], [`psx3xx_mutants`]): each
//!   breaks the manual in one planted way, and must fail, naming the requirement it breaks.
//!
//! - PROFINET IO devices with a planted fault ([`profinet_faults`]): the PSD4xx on the wire
//!   deviating in one way, which `drivespec fuzz --layer profinet` must find.
//!
//! [`catalogue`] names them all; [`serve`] serves one on stdin/stdout with the protocol of its
//! family (the HPD serial line, `drivespec-cyclic/1`), which the binary `drivespec-impl`
//! does, so each runs as an `exec:` device under test too. The conformance tests
//! (`crates/conform/tests/*_variants.rs`, `*_mutants.rs`) run them in-process, the fuzzer's
//! tests run the mutants, and `tests/variants_exec.rs` runs them over `exec:`.
//!
//! These are test fixtures, not a library for users (unpublished): they are built from the
//! built-in spec and end with a panic when it does not load.
//! Each `expect` says why it cannot fail: it reads names and tables of the built-in spec or
//! re-encodes messages built from frames that decoded; none depends on what a runner sends
//! them (values a runner can set, such as parameters, are converted without `expect`).
#![forbid(unsafe_code)]
#![allow(
    missing_docs,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

pub mod catalogue;
pub mod hpd_motion_mutants;
pub mod hpd_mutants;
pub mod hpd_variants;
pub mod profinet_faults;
pub mod psd4xx_mutants;
pub mod psd4xx_variants;
pub mod psx3xx_mutants;
pub mod psx3xx_variants;
pub mod serve;

use drivespec_hpd::params::Target;
use drivespec_spec::{Bitfield, FamilyId, Spec};
use std::sync::OnceLock;

/// The built-in spec, loaded once.
pub fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| {
        Spec::builtin().expect("the built-in spec loads (checked by `drivespec spec check`)")
    })
}

/// HPD parameter or bit `name` (`Pr31`, `b70.7`) of the built-in spec; callers name entries
/// of its tables, so the lookup cannot fail on the spec the fixtures are built from.
pub fn hpd_target(name: &str) -> Target<'static> {
    Target::parse(spec().family(FamilyId::Hpd), name).expect("a name of the built-in HPD tables")
}

/// The mask of bit `name` of `field`; callers name bits of the built-in spec's status and
/// control words, so the lookup cannot fail on the spec the fixtures are built from.
pub fn mask(field: Option<&Bitfield>, name: &str) -> u16 {
    field
        .and_then(|f| f.bits.iter().find(|b| b.name == name))
        .and_then(|b| 1u16.checked_shl(b.bit))
        .expect("a bit of the built-in spec's status and control words")
}

/// The mask of the PSD4xx bit `name` of `field` (`status`, `control`) in the built-in spec.
pub fn psd4xx_bit(field: &str, name: &str) -> u16 {
    mask(spec().family(FamilyId::Psd4xx).bitfield(field), name)
}
