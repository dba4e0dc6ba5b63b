//! Byte-order detection from input sequences (manual 3.3.2 note) and the guard entries
//! (manual 3.1 ISDU 66, 109, 111, 126; PSX-ERRATUM-004).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_psx3xx::{
    detect_order, ByteOrder, EvidenceKind, GuardReading, Guards, Input, Rules, WriteFate,
};
use drivespec_spec::{Readings, Spec};
use proptest::prelude::*;
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

fn rules() -> &'static Rules<'static> {
    static RULES: OnceLock<Rules<'static>> = OnceLock::new();
    RULES.get_or_init(|| Rules::from_spec(spec()).unwrap())
}

const MOTOR: u16 = 1 << 4;
const RUNNING: u16 = 1 << 6;

fn encode(seq: &[Input], order: ByteOrder) -> Vec<Vec<u8>> {
    seq.iter()
        .map(|i| i.to_bytes(rules(), order).unwrap())
        .collect()
}

#[test]
fn the_manuals_motor_voltage_trick() {
    // Standstill at 51200, the motor voltage switched on and off.
    let seq: Vec<Input> = (0..6)
        .map(|i| Input {
            status: 0x0001 | if i % 2 == 0 { MOTOR } else { 0 },
            rpm: 0,
            actual: 51200,
        })
        .collect();
    for order in ByteOrder::ALL {
        let d = detect_order(rules(), &encode(&seq, order));
        assert_eq!(d.order, Some(order), "{d}");
        assert!(d.confidence > 0.95, "{d}");
        assert_eq!(d.evidence[0].kind, EvidenceKind::MotorPowerToggle, "{d}");
        assert_eq!(d.evidence[0].count, 5);
    }
}

#[test]
fn no_evidence_no_verdict() {
    let same = Input {
        status: 0x0101,
        rpm: 0,
        actual: 0x0100_0001,
    };
    let d = detect_order(rules(), &encode(&[same, same, same], ByteOrder::BigEndian));
    assert_eq!(d.order, None, "{d}");
    assert!((d.confidence - 0.5).abs() < 1e-9);
    let d = detect_order(rules(), &[vec![0u8; 3], vec![0u8; 9]]);
    assert_eq!((d.images, d.skipped, d.order), (0, 2, None));
}

/// A plausible run in the true order: small position steps, speed and running bit agreeing,
/// motor power mostly present.
fn run() -> impl Strategy<Value = Vec<Input>> {
    (
        1200i32..101_200,
        prop::collection::vec((-400i32..400, any::<bool>(), any::<u16>()), 3..12),
    )
        .prop_map(|(start, steps)| {
            let mut pos = start;
            let mut out = vec![Input {
                status: MOTOR,
                rpm: 0,
                actual: pos,
            }];
            for (i, (step, motor, noise)) in steps.into_iter().enumerate() {
                // Always move once, so there is something to see.
                let step = if i == 0 && step == 0 { 37 } else { step };
                pos += step;
                let rpm = i16::try_from(step / 8).unwrap();
                let mut status = noise & 0b1010_0000_1000_0010; // bits 1, 7, 13, 15
                if motor || rpm != 0 {
                    status |= MOTOR;
                }
                if rpm != 0 {
                    status |= RUNNING;
                }
                out.push(Input {
                    status,
                    rpm,
                    actual: pos,
                });
            }
            out
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(500))]

    #[test]
    fn detection_finds_the_order_of_generated_runs(seq in run()) {
        for order in ByteOrder::ALL {
            let d = detect_order(rules(), &encode(&seq, order));
            prop_assert_eq!(d.order, Some(order), "{}", d);
            prop_assert!(d.confidence > 0.6, "{}", d);
            prop_assert_eq!(d.images, seq.len());
        }
    }
}

#[test]
fn guards_come_from_the_spec() {
    let g = Guards::from_rules(rules(), &Readings::default()).unwrap();
    let pairs: Vec<(&str, &str)> = g
        .guards()
        .iter()
        .map(|g| (g.guard.as_str(), g.guarded.as_str()))
        .collect();
    assert_eq!(
        pairs,
        [("66", "67"), ("109", "110"), ("111", "112"), ("126", "127")]
    );
    assert_eq!(
        g.reading(),
        GuardReading::OneShot,
        "PSX-ERRATUM-004 adopted"
    );
}

#[test]
fn one_shot_guard_suppresses_only_the_next_write() {
    let mut g = Guards::from_rules(rules(), &Readings::default()).unwrap();
    assert_eq!(
        g.on_write("67", Some(0)),
        WriteFate::Execute,
        "delivery 0 does not arm"
    );
    assert_eq!(g.on_write("66", Some(0)), WriteFate::Execute);
    assert_eq!(
        g.on_write("67", Some(0)),
        WriteFate::Suppressed { guard: "66".into() }
    );
    assert_eq!(g.on_write("67", Some(0)), WriteFate::Execute);
    // Another write between guard and entry ends the suppression.
    g.on_write("66", Some(0));
    assert_eq!(g.on_write("131", Some(3)), WriteFate::Execute);
    assert_eq!(g.on_write("67", Some(0)), WriteFate::Execute);
    // 1 allows; the other guards guard their own entries only.
    g.on_write("66", Some(1));
    assert_eq!(g.on_write("67", Some(0)), WriteFate::Execute);
    g.on_write("109", Some(0));
    assert_eq!(g.on_write("112", Some(0)), WriteFate::Execute);
    g.on_write("111", Some(0));
    assert_eq!(
        g.on_write("112", Some(60000)),
        WriteFate::Suppressed {
            guard: "111".into()
        },
        "PSX-ERRATUM-003: 111 guards the target"
    );
    g.on_write("126", Some(0));
    assert!(g.is_armed("127"));
    assert_eq!(
        g.on_write("127", Some(1000)),
        WriteFate::Suppressed {
            guard: "126".into()
        }
    );
}

#[test]
fn other_guard_readings() {
    let family = spec().family(drivespec_spec::FamilyId::Psx3xx);
    let mut readings = Readings::default();
    readings
        .choose(family, drivespec_psx3xx::guard::OPTION, "next-target-write")
        .unwrap();
    let mut g = Guards::from_rules(rules(), &readings).unwrap();
    assert_eq!(g.reading(), GuardReading::NextTargetWrite);
    g.on_write("66", Some(0));
    g.on_write("131", Some(3));
    assert_eq!(
        g.on_write("67", Some(0)),
        WriteFate::Suppressed { guard: "66".into() }
    );
    assert_eq!(g.on_write("67", Some(0)), WriteFate::Execute);
    g.on_write("66", Some(0));
    g.on_write("66", Some(1));
    assert_eq!(g.on_write("67", Some(0)), WriteFate::Execute);

    let mut p = Guards::with_reading(rules(), GuardReading::Persistent).unwrap();
    assert!(p.is_armed("110"), "the delivery value 0 suppresses");
    assert!(matches!(
        p.on_write("110", Some(0x10)),
        WriteFate::Suppressed { .. }
    ));
    assert!(matches!(
        p.on_write("110", Some(0x10)),
        WriteFate::Suppressed { .. }
    ));
    p.on_write("109", Some(1));
    assert_eq!(p.on_write("110", Some(0x10)), WriteFate::Execute);
    p.reset();
    assert!(p.is_armed("110"));
}
