//! PSx3xx legal variants (`drivespec_implementations::psx3xx_variants`): drives that differ from the reference
//! only where the manual allows. Each must pass every case; the cases a variant fails are
//! printed with what the suite expected and what came.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod support;

use drivespec_conform::cyclic::{LocalPeer, Server};
use drivespec_conform::psx3xx::Psx3xxSuite;
use drivespec_conform::suite::{Settings, Suite};
use drivespec_implementations::psx3xx_variants::{variants, Variant};
use drivespec_implementations::spec;
use support::legal::{describe, failures};

#[test]
fn every_psx3xx_legal_variant_passes() {
    let suite = Psx3xxSuite::new(spec(), &Settings::default()).unwrap();
    let mut problems = Vec::new();
    for (name, kind) in variants() {
        let server = Server::new(name, "psx3xx", Box::new(Variant::new(kind)));
        let mut session = suite.session(Box::new(LocalPeer::new(name, server)));
        let failed = failures(suite.cases(), &mut session);
        let ids: Vec<&str> = failed.iter().map(|(id, _)| id.as_str()).collect();
        println!("{name:<36} fails {:>3} case(s): {ids:?}", failed.len());
        problems.extend(describe(name, &failed));
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
