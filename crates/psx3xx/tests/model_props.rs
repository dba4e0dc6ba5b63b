//! Property tests of the PSx3xx reference model over random command, parameter and
//! environment sequences (manual chapters 3–5): status-bit invariants hold in every reachable
//! state, a positioning run never leaves [lower limit, upper limit], speed and acceleration
//! stay within their limits, and identical inputs give identical outputs.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing
)]

mod model_util;

use drivespec_positioner::{EnvChange, Micros};
use drivespec_psx3xx::isdu::Value;
use drivespec_psx3xx::model::{Drive, DriveConfig, JogKeys, LedLight, LinkEvent, RunState};
use drivespec_psx3xx::{Output, Stamp, TsCode};
use model_util::*;
use proptest::prelude::*;

#[derive(Debug, Clone)]
enum Op {
    Image {
        word: u16,
        target: i32,
        speed: i16,
        stamp: u16,
        code: u8,
    },
    Write {
        index: u16,
        value: i64,
    },
    Env(EnvChange),
    Keys(u8),
    Link(bool),
    Wait(u16),
    PowerCycle,
}

/// Control words from the bits of 3.5, mostly meaningful ones.
fn word() -> impl Strategy<Value = u16> {
    prop_oneof![
        Just(0x0000u16),
        Just(0x0004),
        Just(0x0010),
        Just(0x0011),
        Just(0x0012),
        Just(0x0014),
        Just(0x0054),
        Just(0x0414),
        Just(0x0454),
        Just(0x0094),
        Just(0x1014),
        Just(0x4014),
        Just(0x0020),
        Just(0x0028),
        Just(0x0100),
        Just(0x0200),
        any::<u16>(),
    ]
}

fn writes(position: bool) -> BoxedStrategy<Op> {
    let mut choices: Vec<(u16, std::ops::RangeInclusive<i64>)> = vec![
        (131, 1..=100),
        (132, 0..=400),
        (133, 20..=1000),
        (134, 0..=1),
        (135, 1..=100),
        (137, 1..=2),
        (138, 1200..=101_200),
        (118, 0..=500),
        (142, 10..=300),
        (143, 10..=300),
        (144, 10..=300),
        (145, 10..=300),
        (146, 30..=90),
        (147, 50..=700),
        (148, 50..=700),
        (163, 20..=400),
        (110, 0..=0x1FFF),
        (112, 0..=110_000),
        (66, 0..=1),
        (193, -2..=3),
    ];
    if position {
        choices.extend([
            (123, 0..=1),
            (124, 1..=800),
            (125, 1..=800),
            (127, -5000..=5000),
            (128, 50_000..=160_000),
            (129, 40_000..=101_200),
            (130, 1200..=60_000),
            (67, 0..=100_000),
        ]);
    }
    proptest::sample::select(choices)
        .prop_flat_map(|(index, range)| range.prop_map(move |value| Op::Write { index, value }))
        .boxed()
}

fn env(external: bool) -> BoxedStrategy<EnvChange> {
    let mut s = vec![
        (200u16..320)
            .prop_map(|dv| EnvChange::MotorVoltage { dv })
            .boxed(),
        (20i16..90)
            .prop_map(|celsius| EnvChange::Temperature { celsius })
            .boxed(),
    ];
    if external {
        s.push(
            (0u16..200)
                .prop_map(|cnm| EnvChange::LoadTorque { cnm })
                .boxed(),
        );
        s.push(any::<bool>().prop_map(|on| EnvChange::Jam { on }).boxed());
        s.push(
            (-400i64..400)
                .prop_map(|by| EnvChange::Displace { by })
                .boxed(),
        );
        s.push(
            (-20i32..20)
                .prop_map(|rpm| EnvChange::BackDrive { rpm })
                .boxed(),
        );
        s.push(Just(EnvChange::ClearBlocks).boxed());
        s.push(
            (1200i64..101_200)
                .prop_map(|at| EnvChange::Block { at })
                .boxed(),
        );
        s.push(
            (0i64..20)
                .prop_map(|by| EnvChange::MissSteps { by })
                .boxed(),
        );
        s.push(Just(EnvChange::PositionFault).boxed());
        s.push(
            prop_oneof![Just(0u16), Just(240)]
                .prop_map(|dv| EnvChange::ControlVoltage { dv })
                .boxed(),
        );
    }
    proptest::strategy::Union::new(s).boxed()
}

fn ops(external: bool, position: bool) -> impl Strategy<Value = Vec<Op>> {
    let op = prop_oneof![
        4 => (word(), 1200i32..101_200, -20i16..200, any::<u16>(), 0u8..4).prop_map(
            |(word, target, speed, stamp, code)| Op::Image { word, target, speed, stamp, code }
        ),
        2 => writes(position),
        1 => env(external).prop_map(Op::Env),
        1 => (0u8..4).prop_map(Op::Keys),
        1 => any::<bool>().prop_map(Op::Link),
        3 => (1u16..3000).prop_map(Op::Wait),
        1 => if external { Just(Op::PowerCycle) } else { Just(Op::Wait(8)) },
    ];
    proptest::collection::vec(op, 1..30)
}

fn image(d: &Drive, op: &Op) -> Option<Output> {
    let Op::Image {
        word,
        target,
        speed,
        stamp,
        code,
    } = *op
    else {
        return None;
    };
    Some(match d.active_format() {
        0 => Output::TimeStamp {
            control: TsCode(code),
            stamp: Stamp(stamp % 0x4000),
        },
        1 => Output::ControlTarget {
            control_word: word,
            target,
        },
        _ => Output::SpeedControlTarget {
            target_speed: speed,
            control_word: word,
            target,
        },
    })
}

/// Applies one op and then lets time pass in 1 ms steps, calling `each` after every step.
fn apply(d: &mut Drive, now: &mut Micros, op: &Op, each: &mut dyn FnMut(&Drive)) {
    match op {
        Op::Image { .. } => {
            if let Some(out) = image(d, op) {
                let _ = d.handle_output(*now, &out);
            }
        }
        Op::Write { index, value } => {
            let _ = d.write(*now, *index, 0, &Value::Int(*value));
        }
        Op::Env(c) => d.handle_env(*now, *c),
        Op::Keys(k) => d.handle_keys(
            *now,
            [
                JogKeys::NONE,
                JogKeys::FORWARD,
                JogKeys::REVERSE,
                JogKeys::BOTH,
            ][usize::from(*k)],
        ),
        Op::Link(up) => d.handle_link(
            *now,
            if *up {
                LinkEvent::Connected
            } else {
                LinkEvent::Lost
            },
        ),
        Op::Wait(_) => {}
        Op::PowerCycle => d.power_cycle(*now),
    }
    each(d);
    let wait = match op {
        Op::Wait(ms) => u64::from(*ms),
        _ => 8,
    };
    for _ in 0..wait {
        *now += MS;
        d.advance(*now);
        each(d);
    }
    while d.poll_input().is_some() {}
    while d.poll_isdu().is_some() {}
}

fn drive(format: u8, brake: bool) -> (Drive<'static>, Micros) {
    let mut cfg = DriveConfig::new(if brake { "PSE322-14" } else { "PSE312-8" });
    if brake {
        cfg = cfg.with_brake(drivespec_psx3xx::model::BrakeKind::Snap);
    }
    let mut d = Drive::new(spec(), cfg).unwrap();
    let _ = d.write(0, 116, 0, &Value::Int(i64::from(format)));
    let _ = d.write(0, 193, 0, &Value::Int(1));
    let _ = d.write(0, 2, 0, &Value::Int(128));
    assert_eq!(d.active_format(), format);
    (d, 0)
}

/// What holds in every state (manual 3.4).
fn status_invariants(d: &Drive) {
    if !d.core().powered() {
        assert_eq!(d.status_word(), 0);
        return;
    }
    let s = d.status_word();
    // PSX-STS-6-SET-1 / PSX-STS-6-RESET-1.
    assert_eq!(
        bit(s, 6),
        d.core().kinematics().vel != 0.0,
        "bit 6, status {s:#06x}"
    );
    // PSX-STS-2-SET-1, PSX-STS-2-RESET-1, PSX-STS-3-SET-1, PSX-STS-3-RESET-1: the key pins.
    assert_eq!(bit(s, 3), d.keys().forward);
    assert_eq!(bit(s, 2), d.keys().reverse);
    // PSX-STS-0-SET-1, PSX-STS-0-RESET-1: bit 0 at standstill only within the window of the valid target.
    if bit(s, 0) && d.run_state() == RunState::Idle {
        let target = d.core().axis().target().expect("bit 0 without a target");
        let window = d.core().axis().values().window;
        assert!(
            (d.core().actual() - target).abs() <= window,
            "bit 0 at {} for target {target}",
            d.core().actual()
        );
    }
    let k = d.core().kinematics();
    assert!(k.pos.is_finite() && k.vel.is_finite());
    let image = d.input_image();
    assert_eq!(image.len(), 8);
    // PSX-LED-001, PSX-LED-002, PSX-LED-003, PSX-LED-004.
    let leds = d.leds();
    assert_eq!(leds.green == LedLight::On90Percent, d.link_up());
    assert_eq!(
        leds.yellow == LedLight::On,
        d.core().environment().motor_dv > 0
    );
    if d.active_format() != 0 {
        assert_eq!(leds.orange, LedLight::Off);
    }
}

/// The drive with the readings other than the adopted ones where a reading changes what a
/// run does or shows (PSX-ERRATUM-011, PSX-ERRATUM-051, PSX-ERRATUM-056).
fn drive_other_readings(format: u8) -> (Drive<'static>, Micros) {
    let cfg = DriveConfig::new("PSE312-8").with_readings(readings(&[
        ("psx-signed-measurements", "unsigned"),
        ("psx-ts-bit-layout", "high-bits"),
        ("psx-ref-sign", "physical-minus-written"),
    ]));
    let mut d = Drive::new(spec(), cfg).unwrap();
    let _ = d.write(0, 116, 0, &Value::Int(i64::from(format)));
    let _ = d.write(0, 193, 0, &Value::Int(1));
    let _ = d.write(0, 2, 0, &Value::Int(128));
    assert_eq!(d.active_format(), format);
    (d, 0)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// Status invariants hold in every reachable state, with every kind of input.
    #[test]
    fn status_bits_hold_in_every_state(format in 0u8..3, brake in any::<bool>(), ops in ops(true, true)) {
        let (mut d, mut now) = drive(format, brake);
        for op in &ops {
            apply(&mut d, &mut now, op, &mut |d| status_invariants(d));
        }
    }

    /// A positioning run never leaves [lower limit, upper limit] (PSX-MAP-001, PSX-RUN-008),
    /// and speed and acceleration stay within their limits (PSX-VEL-001 … PSX-VEL-003).
    #[test]
    fn runs_stay_within_limits_speed_and_acceleration(format in 0u8..3, ops in ops(false, false)) {
        let (mut d, mut now) = drive(format, false);
        let max_decel = 700.0_f64.max(d.core().config().max_deceleration);
        let mut last_v = d.core().kinematics().vel;
        // A lowered cap takes effect with the deceleration, so the bound is the largest cap seen.
        let mut cap_seen = 0;
        for op in &ops {
            apply(&mut d, &mut now, op, &mut |d| {
                let v = d.core().kinematics().vel;
                let a = (v - last_v).abs() * 60.0 / 0.001;
                assert!(a <= max_decel * (1.0 + 1e-6) + 1e-6, "{a} rpm/s");
                last_v = v;
                let limits = d.core().axis().values();
                if matches!(d.run_state(), RunState::Positioning { .. } | RunState::SafePosition { .. } | RunState::Centre { .. }) {
                    let x = d.core().actual();
                    assert!(
                        x >= limits.lower_limit - 1 && x <= limits.upper_limit + 1,
                        "{x} outside {}..{}", limits.lower_limit, limits.upper_limit
                    );
                }
                let caps = [143u16, 144].map(|i| match d.read(i, 0) { Ok(Value::Int(v)) => v, _ => 0 });
                cap_seen = cap_seen.max(caps[0].max(caps[1]));
                let rpm = d.core().speed_rpm().abs();
                assert!(rpm <= cap_seen + 1, "{rpm} rpm above the caps {caps:?}");
            });
        }
    }

    /// Under the other readings the invariants hold too, ISDU 65 and the input's speed are
    /// never negative (PSX-ISDU-65-UNIT) and ISDU 127 is the negated referencing value of
    /// the core (PSX-POS-009).
    #[test]
    fn other_readings_keep_the_invariants(format in 0u8..3, ops in ops(true, true)) {
        let (mut d, mut now) = drive_other_readings(format);
        for op in &ops {
            apply(&mut d, &mut now, op, &mut |d| {
                status_invariants(d);
                if d.core().powered() {
                    assert!(d.input().rpm >= 0);
                    assert_eq!(d.value("65"), Value::Int(i64::from(d.input().rpm)));
                    let reference = d.core().get(drivespec_positioner::machine::Setting::Reference);
                    let shown = reference
                        .saturating_neg()
                        .clamp(i64::from(i32::MIN), i64::from(i32::MAX));
                    assert_eq!(d.value("127"), Value::Int(shown));
                }
            });
        }
    }

    /// Identical inputs give identical outputs (style rule 11).
    #[test]
    fn the_model_is_deterministic(format in 0u8..3, brake in any::<bool>(), ops in ops(true, true)) {
        let trace = |ops: &[Op]| {
            let (mut d, mut now) = drive(format, brake);
            let mut out: Vec<(u16, i64, i64)> = Vec::new();
            for op in ops {
                apply(&mut d, &mut now, op, &mut |d| {
                    out.push((d.status_word(), d.core().actual(), d.core().speed_rpm()));
                });
            }
            let mut events = 0;
            while d.poll_event().is_some() {
                events += 1;
            }
            (out, events)
        };
        prop_assert_eq!(trace(&ops), trace(&ops));
    }
}
