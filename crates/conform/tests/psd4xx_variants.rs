//! PSD4xx legal variants (`drivespec_implementations::psd4xx_variants`): drives that differ from the reference
//! only where the manual allows must pass every case. The cases each variant fails are printed.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod support;

use drivespec_conform::cyclic::{LocalPeer, Server};
use drivespec_conform::psd4xx::Psd4xxSuite;
use drivespec_conform::suite::{Settings, Suite};
use drivespec_implementations::psd4xx_variants::{variants, Variant};
use drivespec_implementations::spec;
use support::legal::{describe, failures};

#[test]
fn every_psd4xx_legal_variant_passes() {
    let suite = Psd4xxSuite::new(spec(), &Settings::default()).unwrap();
    let mut problems = Vec::new();
    for (name, kind) in variants() {
        let server = Server::new(name, "psd4xx", Box::new(Variant::new(kind)));
        let mut session = suite.session(Box::new(LocalPeer::new(name, server)));
        let failed = failures(suite.cases(), &mut session);
        let ids: Vec<&str> = failed.iter().map(|(id, _)| id.as_str()).collect();
        println!("{name:<36} fails {:>3} case(s): {ids:?}", failed.len());
        problems.extend(describe(name, &failed));
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
