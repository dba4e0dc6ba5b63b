//! Properties of the reference model over random sequences of control words, targets,
//! parameter writes, environment changes and connection events (manual 3.6, 4.3, 4.2.1):
//! the status-bit invariants hold in every reachable state, a positioning run never leaves the
//! limits, speed never exceeds the configured maximum and speed changes never exceed the
//! ramps, and identical inputs give identical outputs.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_positioner::machine::{CoreEvent, RunKind};
use drivespec_positioner::EnvChange;
use drivespec_psd4xx::model::{Drive, DriveConfig, Event, LinkEvent};
use drivespec_psd4xx::Output;
use model_util::*;
use proptest::prelude::*;
use std::sync::OnceLock;

const MODEL: &str = "PSD401-5V";

#[derive(Debug, Clone)]
enum Op {
    Image { control: u16, target: i32 },
    Write { pnu: u16, value: i64 },
    Env(EnvChange),
    Link(LinkEvent),
}

fn control() -> impl Strategy<Value = u16> {
    prop_oneof![
        8 => prop::sample::select(vec![
            0x00u16, 0x04, 0x10, 0x14, 0x11, 0x12, 0x54, 0x44, 0x2014, 0x2000, 0x2010
        ]),
        1 => prop::sample::select(vec![0x13u16, 0x1C, 0x34, 0x8014]),
        1 => any::<u16>(),
    ]
}

fn target() -> impl Strategy<Value = i32> {
    prop_oneof![
        8 => -20_000i32..20_000,
        1 => prop::sample::select(vec![-805_200i32, 805_200, -900_000, 900_000, 0]),
    ]
}

/// Environment changes that never move the shaft by force faster than its ramps allow.
fn gentle_env() -> impl Strategy<Value = EnvChange> {
    prop_oneof![
        prop::sample::select(vec![0u16, 170, 180, 186, 240, 310])
            .prop_map(|dv| EnvChange::MotorVoltage { dv }),
        (20i16..95).prop_map(|celsius| EnvChange::Temperature { celsius }),
        (-400i64..400).prop_map(|by| EnvChange::Displace { by }),
    ]
}

/// Everything the environment can do.
fn any_env() -> impl Strategy<Value = EnvChange> {
    prop_oneof![
        4 => gentle_env(),
        1 => any::<bool>().prop_map(|on| EnvChange::Jam { on }),
        1 => (0u16..120).prop_map(|cnm| EnvChange::LoadTorque { cnm }),
        1 => (-30_000i64..30_000).prop_map(|at| EnvChange::Block { at }),
        1 => Just(EnvChange::ClearBlocks),
        1 => (-5i32..5).prop_map(|rpm| EnvChange::BackDrive { rpm }),
        1 => (1i64..20).prop_map(|by| EnvChange::MissSteps { by }),
        1 => prop::sample::select(vec![0u16, 240]).prop_map(|dv| EnvChange::ControlVoltage { dv }),
        1 => Just(EnvChange::PositionFault),
    ]
}

fn write(limits: bool) -> BoxedStrategy<Op> {
    let mut options: Vec<BoxedStrategy<(u16, i64)>> = vec![
        (1i64..=10).prop_map(|v| (44u16, v)).boxed(),
        prop_oneof![Just(0i64), 10i64..500, -500i64..-10]
            .prop_map(|v| (45u16, v))
            .boxed(),
        (0i64..=1).prop_map(|v| (47u16, v)).boxed(),
        (30i64..=90).prop_map(|v| (57u16, v)).boxed(),
        (50i64..=500).prop_map(|v| (70u16, v)).boxed(),
        prop::sample::select(vec![1i64, -1, -2, -4, -5, -6, 2])
            .prop_map(|v| (96u16, v))
            .boxed(),
        (-20_000i64..20_000).prop_map(|v| (3u16, v)).boxed(),
        (-2000i64..2000).prop_map(|v| (40u16, v)).boxed(),
    ];
    if limits {
        options.push((0i64..805_200).prop_map(|v| (42u16, v)).boxed());
        options.push((-805_200i64..0).prop_map(|v| (43u16, v)).boxed());
        options.push(
            prop::sample::select(vec![100i64, 200, 400, 800])
                .prop_map(|v| (39u16, v))
                .boxed(),
        );
        options.push((0i64..=1).prop_map(|v| (37u16, v)).boxed());
    }
    prop::strategy::Union::new(options)
        .prop_map(|(pnu, value)| Op::Write { pnu, value })
        .boxed()
}

fn op(wild: bool) -> BoxedStrategy<Op> {
    let env = if wild {
        any_env().boxed()
    } else {
        gentle_env().boxed()
    };
    let link = prop::sample::select(vec![
        LinkEvent::Lost,
        LinkEvent::Connected,
        LinkEvent::IopsBad,
        LinkEvent::IopsGood,
    ]);
    prop_oneof![
        6 => (control(), target()).prop_map(|(control, target)| Op::Image { control, target }),
        2 => write(wild),
        2 => env.prop_map(Op::Env),
        1 => link.prop_map(Op::Link),
    ]
    .boxed()
}

/// Speeds and ramps chosen once per case, within the PSD 401/411-5V ranges of 3.4.
fn ramps() -> impl Strategy<Value = (i64, i64, i64, i64)> {
    (1i64..=800, 1i64..=800, 1i64..=5000, 1i64..=5000)
}

fn template() -> &'static Drive {
    static DRIVE: OnceLock<Drive> = OnceLock::new();
    DRIVE.get_or_init(|| Drive::new(spec(), DriveConfig::new(MODEL)).unwrap())
}

/// One sample of the observable state.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Seen {
    t: u64,
    input: Vec<u8>,
}

struct Check {
    wild: bool,
}

/// Runs `ops`, each followed by `gaps[i]` ms, checking the invariants every millisecond.
fn run(
    ops: &[Op],
    gaps: &[u64],
    (pos, man, acc, dec): (i64, i64, i64, i64),
    wild: bool,
) -> Result<Vec<Seen>, TestCaseError> {
    let mut d = template().clone();
    let mut now = 0u64;
    for (pnu, v) in [(53u16, pos), (56, man), (58, acc), (59, dec)] {
        d.write_parameter(now, pnu, v).unwrap();
    }
    let check = Check { wild };
    let rules = d.rules().clone();
    let mut out = Output::idle(&rules);
    let mut seen = Vec::new();
    let mut last_v = 0.0;
    // Whether the positioning run in progress started inside the limits and was not pushed.
    let mut run_clean = false;
    for (op, gap) in ops.iter().zip(gaps) {
        let mut forced = false;
        match op {
            Op::Image { control, target } => {
                out.control = *control;
                out.target = *target;
            }
            Op::Write { pnu, value } => {
                let _ = d.write_parameter(now, *pnu, *value);
                // A direction change flips the counting; a reset cuts the power (par. 96 = -6).
                forced = *pnu == 37 || (*pnu == 96 && *value == -6);
            }
            Op::Env(e) => {
                d.handle_env(now, *e);
                forced = !matches!(
                    e,
                    EnvChange::MotorVoltage { .. } | EnvChange::Temperature { .. }
                );
                if matches!(e, EnvChange::Displace { .. }) {
                    run_clean = false;
                }
            }
            Op::Link(l) => d.handle_link(now, *l),
        }
        if forced {
            last_v = d.core().kinematics().vel * 60.0;
        }
        for _ in 0..*gap {
            now += MS;
            d.handle_output(now, &out);
            while let Some((_, e)) = d.poll_event() {
                if let Event::Core(CoreEvent::RunStarted { kind, .. }) = e {
                    if kind != RunKind::Manual {
                        let (lo, hi) = limits(&d);
                        run_clean = (lo..=hi).contains(&d.core().actual());
                    }
                }
            }
            invariants(&d, &check, &mut last_v, run_clean)?;
            seen.push(Seen {
                t: now,
                input: d.input_image(),
            });
        }
    }
    Ok(seen)
}

fn limits(d: &Drive) -> (i64, i64) {
    let v = d.core().axis().values();
    (v.lower_limit, v.upper_limit)
}

fn invariants(
    d: &Drive,
    c: &Check,
    last_v: &mut f64,
    run_clean: bool,
) -> Result<(), TestCaseError> {
    let core = d.core();
    if !core.powered() {
        return Ok(());
    }
    let status = d.input().status;
    let bit = |n: u32| status >> n & 1 == 1;
    let ctx = || format!("status {status:#06x} at {} ms", d.now() / MS);
    // PSD-STS-1-RSV, PSD-STS-3-RSV: reserved bits stay 0.
    prop_assert_eq!(status & 0b1010, 0, "{}", ctx());
    // PSD-STS-6-SET-1 / PSD-STS-6-RESET-1.
    let v = core.kinematics().vel * 60.0;
    prop_assert_eq!(bit(6), v != 0.0, "{}", ctx());
    // PSD-CTL-13-001: the toggle echo of the outputs in force.
    prop_assert_eq!(
        bit(2),
        d.outputs_in_force().control & 0x2000 != 0,
        "{}",
        ctx()
    );
    // PSD-STS-0-PRIO (exclusive reading).
    prop_assert!(!(bit(0) && bit(10)), "{}", ctx());
    // PSD-STS-4-SET-1 / PSD-STS-4-RESET-1 against the measured voltage.
    let u = core.motor_voltage();
    let limit = d.parameter(90).unwrap();
    if u > limit && u < 300 {
        prop_assert!(bit(4), "{}", ctx());
    } else if u < limit || u > 300 {
        prop_assert!(!bit(4), "{}", ctx());
    }
    // PSD-STS-7-SET-1.
    if i64::from(core.environment().celsius) > d.parameter(91).unwrap() {
        prop_assert!(bit(7), "{}", ctx());
    }
    // Bit 0 never stands for a position outside the window at standstill (PSD-PAR-44-001).
    if bit(0) && core.run_kind().is_none() {
        let t = core.axis().target().unwrap();
        let w = core.axis().values().window;
        prop_assert!(core.actual().abs_diff(t) <= w.unsigned_abs(), "{}", ctx());
    }
    // PSD-STS-9-NORUN: no run starts while the error bit is set (a run ending is allowed).
    if bit(9) {
        prop_assert!(
            !matches!(
                core.run_kind(),
                Some(RunKind::Positioning | RunKind::Manual)
            ) || core.kinematics().vel.abs() <= last_v.abs() / 60.0 + 1e-9,
            "{}",
            ctx()
        );
    }
    if !c.wild {
        // The ramps in force (par. 96 may restore other values at standstill).
        let par = |n: u16| d.parameter(n).unwrap() as f64;
        let max_rpm = par(53).max(par(56));
        let accel = par(58);
        let max_decel = core.config().max_deceleration.max(par(59));
        // PSD-VEL-001, PSD-VEL-002: never faster than par. 53 / 56.
        prop_assert!(v.abs() <= max_rpm + 1e-6, "{v} rpm; {}", ctx());
        // PSD-VEL-003, PSD-VEL-004: speed changes within the ramps (1 ms per sample).
        let dv = v - *last_v;
        let up = v.abs() > last_v.abs() && v * *last_v >= 0.0;
        let allowed = if up { accel } else { max_decel.max(accel) } / 1000.0;
        prop_assert!(
            dv.abs() <= allowed * (1.0 + 1e-9) + 1e-9,
            "dv {dv}; {}",
            ctx()
        );
        // A positioning run never leaves [lower limit, upper limit] (4.2.1 notice).
        if run_clean
            && matches!(
                core.run_kind(),
                Some(RunKind::Positioning | RunKind::Readjust | RunKind::Centre)
            )
        {
            let (lo, hi) = limits(d);
            prop_assert!((lo..=hi).contains(&core.actual()), "{}", ctx());
        }
    }
    *last_v = v;
    Ok(())
}

fn case(wild: bool) -> impl Strategy<Value = (Vec<Op>, Vec<u64>, (i64, i64, i64, i64))> {
    (1usize..24).prop_flat_map(move |n| {
        (
            prop::collection::vec(op(wild), n),
            prop::collection::vec(prop_oneof![3 => 1u64..50, 1 => 50u64..1500], n),
            ramps(),
        )
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    /// Gentle environment: every invariant, including speed, ramps and limits.
    #[test]
    fn invariants_hold((ops, gaps, r) in case(false)) {
        run(&ops, &gaps, r, false)?;
    }

    /// Anything goes (jams, blocks, loads, power cuts, faults, limit and scaling writes):
    /// the status-bit invariants still hold and nothing panics.
    #[test]
    fn invariants_hold_in_a_wild_environment((ops, gaps, r) in case(true)) {
        run(&ops, &gaps, r, true)?;
    }

    /// Identical inputs give identical outputs (style rule 11).
    #[test]
    fn deterministic((ops, gaps, r) in case(true)) {
        let a = run(&ops, &gaps, r, true)?;
        let b = run(&ops, &gaps, r, true)?;
        prop_assert_eq!(a, b);
    }
}
