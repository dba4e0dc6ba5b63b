//! What the built-in spec holds, counted per manual, so nothing silently goes missing.
//!
//! The parameter sets are written here from the manuals' tables (PSD4xx 3.3, PSx3xx 3.1,
//! HPD 3.3 and 4.2), not from the data. The other counts pin the transcription: a change
//! must be deliberate and show up in review.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_spec::{Family, FamilyId, Level, Spec, VectorKind};
use std::collections::BTreeSet;

fn ids(family: &Family) -> BTreeSet<String> {
    family.parameters.iter().map(|p| p.id.clone()).collect()
}

fn range(prefix: &str, r: std::ops::RangeInclusive<u32>) -> Vec<String> {
    r.map(|n| format!("{prefix}{n}")).collect()
}

#[derive(Debug, PartialEq)]
struct Counts {
    models: usize,
    bitfields: usize,
    bits: usize,
    rules: usize,
    must: usize,
    should: usize,
    informative: usize,
    errata: usize,
    vectors: usize,
}

fn counts(f: &Family) -> Counts {
    let level = |l: Level| f.requirements.iter().filter(|r| r.level == l).count();
    Counts {
        models: f.models.len(),
        bitfields: f.bitfields.len(),
        bits: f.bitfields.iter().map(|b| b.bits.len()).sum(),
        rules: f
            .bitfields
            .iter()
            .flat_map(|b| &b.bits)
            .map(|b| b.rules.len())
            .sum(),
        must: level(Level::Must),
        should: level(Level::Should),
        informative: level(Level::Informative),
        errata: f.errata.len(),
        vectors: f.vectors.len(),
    }
}

fn kind_count(f: &Family, kind: VectorKind) -> usize {
    f.vectors.iter().filter(|v| v.kind == kind).count()
}

#[test]
fn psd4xx_has_every_parameter_of_table_3_3() {
    let spec = Spec::builtin().unwrap();
    let mut want: Vec<String> = Vec::new();
    for r in [
        1..=14,
        32..=33,
        37..=45,
        47..=47,
        53..=53,
        56..=59,
        63..=66,
        70..=72,
        76..=76,
        80..=92,
        96..=96,
    ] {
        want.extend(range("", r));
    }
    assert_eq!(
        ids(spec.family(FamilyId::Psd4xx)),
        want.into_iter().collect::<BTreeSet<_>>()
    );
}

#[test]
fn psx3xx_has_every_isdu_entry_of_table_3_1() {
    let spec = Spec::builtin().unwrap();
    let mut want: Vec<String> = range("0.", 1..=16);
    for r in [
        2..=2,
        12..=12,
        16..=24,
        64..=72,
        77..=80,
        109..=112,
        116..=116,
        118..=119,
        123..=138,
        142..=148,
        152..=155,
        159..=166,
        171..=182,
        193..=193,
    ] {
        want.extend(range("", r));
    }
    assert_eq!(
        ids(spec.family(FamilyId::Psx3xx)),
        want.into_iter().collect::<BTreeSet<_>>()
    );
}

#[test]
fn hpd_has_every_parameter_and_bit_parameter() {
    let spec = Spec::builtin().unwrap();
    let mut want: Vec<String> = Vec::new();
    for r in [0..=39, 50..=69, 71..=89, 92..=93] {
        want.extend(range("Pr", r));
    }
    for b in [40, 41, 42, 70, 90, 91, 94, 99] {
        want.push(format!("Pb{b}"));
    }
    let hpd = spec.family(FamilyId::Hpd);
    assert_eq!(ids(hpd), want.into_iter().collect::<BTreeSet<_>>());
    // Table 4.2 gives every parameter but the constants Pr71–Pr79 a serial address (erratum 018).
    let without: Vec<&str> = hpd
        .parameters
        .iter()
        .filter(|p| p.address.is_none())
        .map(|p| p.id.as_str())
        .collect();
    assert_eq!(without, range("Pr", 71..=79));
}

#[test]
fn the_manuals_worked_examples_are_all_there() {
    let spec = Spec::builtin().unwrap();
    let hpd = spec.family(FamilyId::Hpd);
    for case in 1..=8 {
        assert!(
            hpd.vectors
                .iter()
                .any(|v| v.id == format!("serial-case-{case}")),
            "HPD 4.1 case {case}"
        );
    }
    assert_eq!(kind_count(hpd, VectorKind::HpdFrame), 17);
    assert_eq!(kind_count(hpd, VectorKind::HpdPlc), 58);
    assert_eq!(kind_count(hpd, VectorKind::HpdPlcBytes), 7);
    assert_eq!(kind_count(hpd, VectorKind::Formula), 29);
    let psd = spec.family(FamilyId::Psd4xx);
    assert_eq!(kind_count(psd, VectorKind::Pkw), 30);
    assert_eq!(kind_count(psd, VectorKind::Position), 30);
    assert_eq!(kind_count(psd, VectorKind::Sequence), 27);
    let psx = spec.family(FamilyId::Psx3xx);
    assert_eq!(kind_count(psx, VectorKind::Isdu), 49);
    assert_eq!(kind_count(psx, VectorKind::Position), 37);
    assert_eq!(kind_count(psx, VectorKind::Timestamp), 8);
    assert_eq!(kind_count(psx, VectorKind::DirectParameter), 4);
}

#[test]
fn counts_per_manual() {
    let spec = Spec::builtin().unwrap();
    let c = |id| counts(spec.family(id));
    assert_eq!(
        c(FamilyId::Hpd),
        Counts {
            models: 4,
            bitfields: 12,
            bits: 152,
            rules: 98,
            must: 260,
            should: 19,
            informative: 53,
            errata: 39,
            vectors: 111
        }
    );
    assert_eq!(
        c(FamilyId::Psd4xx),
        Counts {
            models: 11,
            bitfields: 2,
            bits: 32,
            rules: 48,
            must: 310,
            should: 18,
            informative: 29,
            errata: 41,
            vectors: 114
        }
    );
    assert_eq!(
        c(FamilyId::Psx3xx),
        Counts {
            models: 59,
            bitfields: 4,
            bits: 44,
            rules: 62,
            must: 314,
            should: 10,
            informative: 41,
            errata: 48,
            vectors: 168
        }
    );
}

#[test]
fn every_status_and_control_bit_is_described() {
    let spec = Spec::builtin().unwrap();
    for (family, words) in [
        (FamilyId::Psd4xx, ["status", "control"]),
        (FamilyId::Psx3xx, ["status", "control"]),
    ] {
        for id in words {
            let b = spec
                .family(family)
                .bitfield(id)
                .unwrap_or_else(|| panic!("{family} bitfield {id}"));
            let described: BTreeSet<u32> = b.bits.iter().map(|x| x.bit).collect();
            assert_eq!(
                described,
                (0..b.width).collect(),
                "{family} {id}: every bit named, reserved ones too"
            );
        }
    }
}
