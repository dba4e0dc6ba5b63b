//! PSx3xx legal variants (`drivespec_implementations::psx3xx_variants`): drives that differ from the reference
//! only where the manual allows. Each must pass every case, also built with a snap brake and
//! run by a suite that declares it (`--brake snap`); the cases a variant fails are
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

#[test]
fn every_psx3xx_legal_variant_with_a_snap_brake_passes() {
    use drivespec_implementations::psx3xx_mutants::SNAP_BRAKE_MODEL;
    use drivespec_sim::reference::BrakeKind;
    let settings = Settings {
        model: Some(SNAP_BRAKE_MODEL.to_owned()),
        brake: Some(BrakeKind::Snap),
        ..Settings::default()
    };
    let suite = Psx3xxSuite::new(spec(), &settings).unwrap();
    let mut problems = Vec::new();
    for (name, kind) in variants() {
        let server = Server::new(
            name,
            "psx3xx",
            Box::new(Variant::with_brake(kind, SNAP_BRAKE_MODEL, BrakeKind::Snap).unwrap()),
        );
        let mut session = suite.session(Box::new(LocalPeer::new(name, server)));
        let failed = failures(suite.cases(), &mut session);
        let ids: Vec<&str> = failed.iter().map(|(id, _)| id.as_str()).collect();
        println!(
            "{name:<36} with a snap brake fails {:>3} case(s): {ids:?}",
            failed.len()
        );
        problems.extend(describe(name, &failed));
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn bit_11_after_an_aborted_run_is_reported_as_the_open_point() {
    use drivespec_conform::case::{Finding, Outcome};
    use drivespec_conform::suite::Session;
    use drivespec_implementations::psx3xx_variants::Kind;
    let suite = Psx3xxSuite::new(spec(), &Settings::default()).unwrap();
    let index = suite
        .cases()
        .iter()
        .position(|c| c.id == "psx3xx/position/readjust-after-abort")
        .unwrap();
    let bits = |kind: Option<Kind>| {
        let server = match kind {
            Some(k) => Server::new("variant", "psx3xx", Box::new(Variant::new(k))),
            None => suite.server(),
        };
        let mut session = suite.session(Box::new(LocalPeer::new("dut", server)));
        let run = session.run(index);
        assert_eq!(run.outcome, Outcome::Pass);
        match run.findings.as_slice() {
            [Finding::Open { requirement, text }] => {
                assert_eq!(requirement, "PSX-STS-11-SET-1");
                text.clone()
            }
            other => panic!("{other:?}"),
        }
    };
    assert!(bits(None).ends_with("at 0x0000"));
    assert!(bits(Some(Kind::DisplacedAfterAbort)).ends_with("at 0x0800"));
}
