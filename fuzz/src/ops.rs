//! What the model harnesses of the two cyclic families read from an op's argument bytes: words
//! and environment changes.

use drivespec_positioner::EnvChange;

/// The little-endian word at byte `i` of an op's argument, 0 past its end.
pub(crate) fn word(b: &[u8], i: usize) -> u16 {
    u16::from_le_bytes([
        b.get(i).copied().unwrap_or(0),
        b.get(i + 1).copied().unwrap_or(0),
    ])
}

/// An environment change chosen and sized by an op's argument: byte 0 picks the kind, the
/// word after it the value, kept in the ranges a drive meets (manual PSD4xx 3.3, 4.5, 4.6, 4.10).
pub(crate) fn env_change(arg: &[u8]) -> EnvChange {
    let k = arg.first().copied().unwrap_or(0);
    let w = word(arg, 1);
    let s = w as i16;
    match k % 12 {
        0 => EnvChange::MotorVoltage { dv: w % 400 },
        1 => EnvChange::ControlVoltage { dv: w % 2 * 240 },
        2 => EnvChange::Temperature { celsius: s % 120 },
        3 => EnvChange::LoadTorque { cnm: w % 200 },
        4 => EnvChange::Jam { on: w & 1 == 1 },
        5 => EnvChange::Block {
            at: i64::from(s) * 16,
        },
        6 => EnvChange::ClearBlocks,
        7 => EnvChange::Displace {
            by: i64::from(s) * 4,
        },
        8 => EnvChange::BackDrive {
            rpm: i32::from(s % 50),
        },
        9 => EnvChange::MissSteps {
            by: i64::from(w % 64),
        },
        10 => EnvChange::PositionFault,
        _ => EnvChange::MotorVoltage { dv: 240 },
    }
}
