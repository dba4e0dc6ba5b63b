//! Status flags placed by the spec's bit rules (PSD4xx manual 3.6): each flag's bit is the
//! bit whose rules name its requirement, and bit 0 has priority over bit 10
//! (PSD-STS-0-PRIO, PSD-STS-14-MAP).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod common;

use common::*;
use drivespec_positioner::status::BitMapError;
use drivespec_positioner::{BitMap, Flag, Flags};
use drivespec_spec::FamilyId;

#[test]
fn psd_bit_numbers_and_priority() {
    let cfg = psd_core();
    let b = &cfg.bits;
    let want = [
        (Flag::Reached, 0),
        (Flag::Toggle, 2),
        (Flag::MotorOk, 4),
        (Flag::Aborted, 5),
        (Flag::Running, 6),
        (Flag::OverTemp, 7),
        (Flag::AgainstLoop, 8),
        (Flag::Error, 9),
        (Flag::Obstruction, 10),
        (Flag::ManualRotation, 11),
        (Flag::BadTarget, 12),
        (Flag::VoltageMissing, 13),
        (Flag::UpperLimit, 14),
        (Flag::LowerLimit, 15),
    ];
    for (f, n) in want {
        assert_eq!(b.bit(f), Some(n), "{f}");
    }
    assert_eq!(b.priorities(), &[(Flag::Reached, Flag::Obstruction)]);
    let mut flags = Flags::default();
    flags.put(Flag::Reached, true);
    flags.put(Flag::MotorOk, true);
    assert_eq!(b.word(flags), 0x0011);
    assert_eq!(b.flags(0x0011), flags);
    assert_eq!(
        flags.iter().collect::<Vec<_>>(),
        [Flag::Reached, Flag::MotorOk]
    );
}

#[test]
fn unknown_requirement_and_shared_bit() {
    let bf = spec().family(FamilyId::Psd4xx).bitfield("status").unwrap();
    assert!(matches!(
        BitMap::from_bitfield(bf, &[(Flag::Reached, "PSD-FIXTURE-STS-0")]),
        Err(BitMapError::NoRule { .. })
    ));
    assert!(matches!(
        BitMap::from_bitfield(
            bf,
            &[
                (Flag::Reached, "PSD-STS-0-SET-1"),
                (Flag::Error, "PSD-STS-0-SET-2")
            ]
        ),
        Err(BitMapError::Shared { bit: 0, .. })
    ));
}
