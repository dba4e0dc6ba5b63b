//! `hpd/motion`: the motor turned through the operating modes and the speed reference, judged
//! by the envelopes the manual states (manual 3.3 Pr0–Pr15, b40.2, b40.6, b41.0–b41.3; 3.6;
//! 3.6.3 jog, test profile and wiring test; 3.6.4 positioner; appendix F).
//!
//! Each watch reads the device round after round and judges its own samples: the value a
//! mode asks for is reached, never exceeded, ramps are no steeper than their parameter and
//! take no longer than the written-down bound, positions move one way and end within the
//! servo-error window, status bits agree with the value they report on. Where the manual
//! fixes a value after the motion (a reset position, a refused write, the wiring test code)
//! the read is compared with the reference as usual.

use super::cases::{bit_value, CaseB, Gen};
use super::names;
use super::step::{Action, Compare};
use crate::case::Role;
use drivespec_hpd::memory::Slot;
use drivespec_hpd::step::{Check, Envelope, Probe, Shaft, Within};

/// Speed tolerance (rpm): the 1 rpm resolution of Pr0 and the small overshoot and ripple of a
/// real speed loop around its reference.
const SPEED_SLACK_RPM: i64 = 5;
/// A ramp may be this much steeper than its parameter (percent): the measured speed of a real
/// drive follows the ramped reference with the small lag and overshoot of its speed loop.
const RAMP_SLACK_PERCENT: i64 = 5;
/// Run-time bound: the ideal time × 1.5 + 0.5 s (a drive may ramp more gently than its
/// parameters allow, start later, and settle).
const TIME_FACTOR_PERCENT: u64 = 150;
/// The fixed part of the run-time bound (µs).
const TIME_EXTRA_US: u64 = 500_000;
/// How long a watch goes on after the motion reached its end (µs): long enough for a few
/// reads of the status bits at a steady state (more than one speed-window slot).
const HOLD_US: u64 = 150_000;
/// Time allowed on top of the speed-window slot for a status bit to follow the speed (µs):
/// the reads around the bit's read take line time.
const BIT_LAG_SLACK_US: u64 = 20_000;
/// Travel between two reads may differ from what the speed reads allow by this much
/// (percent): the speed is read a few ms after the position, on a ramp.
const TRAVEL_SLACK_PERCENT: i64 = 10;
/// ... and by this many steps on top of one slot's travel (position resolution, the loop's
/// following error).
const TRAVEL_SLACK_STEPS: i64 = 50;
/// Position steps per revolution (manual 3.6.4).
const STEPS_PER_REV: i64 = 4096;

/// The case's jog speed (rpm) and ramps (ms per 1000 rpm): slow enough to sample.
const JOG_RPM: i64 = 600;
/// Pr8 for the forward ramp (1 s per 1000 rpm).
const RAMP_UP: i64 = 1000;
/// Pr9 / Pr11 for the decelerations (0.5 s per 1000 rpm).
const RAMP_DOWN: i64 = 500;
/// Pr10 for the reverse ramp (0.8 s per 1000 rpm).
const RAMP_REVERSE: i64 = 800;
/// Pr12 for the stop function (0.7 s per 1000 rpm).
const RAMP_STOP: i64 = 700;
/// Pr13, overspeed threshold below the jog speed (rpm).
const OVERSPEED: i64 = 300;
/// Pr14 / Pr15, the absolute speed window around the jog speed (rpm).
const WINDOW: (i64, i64) = (700, 400);
/// The internal reference Pr5 (rpm) of the reference-selection case.
const INTERNAL_RPM: i64 = 250;
/// Spindle orientation speed Pr50 (rpm).
const ORIENT_RPM: i64 = 200;
/// Pr35 is in % of the drive's peak (manual 3.3): the torque a drive delivers is at most its
/// peak, 100 % either way.
const PEAK_PERCENT: f64 = 100.0;
/// The current limit Pr19 of the jog cases (% of the drive's peak, manual 3.3): below the
/// peak, and more than an unloaded shaft jogging on the ramps needs.
const CURRENT_LIMIT_PERCENT: f64 = 90.0;
/// Positioning profile: Pr51 (ms per 1000 rpm), Pr52 (rpm), revolutions.
const PROFILE: (i64, i64, i64) = (200, 600, 5);
/// Mode-8 test profile: the highest Pr51 (rpm) the case uses, one revolution a second.
const TEST_TOP_RPM: i64 = 60;
/// Mode-8 test profile: Pr52 (revolutions), even so that Pr52 / 2 is whole.
const TEST_REVS: i64 = 2;
/// Mode-8 test profile: the shortest Pr54 (tenths of a second) the case uses.
const TEST_PAUSE_TENTHS: i64 = 5;
/// Pr54 counts tenths of a second in mode 8 (manual 3.6.3).
const US_PER_TENTH: u64 = 100_000;
/// The case picks Pr51 so that the shaft turns at most this share of a revolution (1/8) in
/// the longest round of reads the line allows: a factor of four below the half revolution
/// beyond which the turns between two reads of Pr28 could not be counted.
const TURNS_PER_ROUND: i64 = 8;
/// A first stroke may differ from its Pr52 (or Pr52 / 2) revolutions by a quarter
/// revolution: the travel before the first read of the watch (at most one round, an eighth of
/// a revolution) and a real position's settling at the stroke's end (3.6.3: the profile
/// "ensures that there is no overrun"). A wrong starting point differs by at least one
/// revolution with Pr52 = 2.
const STROKE_SLACK_STEPS: i64 = STEPS_PER_REV / 4;

pub(crate) fn generate(g: &mut Gen) {
    let Some(m) = Motion::new(g) else {
        g.errors
            .push("hpd/motion: the motor's parameters are missing".to_owned());
        return;
    };
    jog(g, &m, true);
    jog(g, &m, false);
    stop_ramp(g, &m);
    reference_select(g, &m);
    positioning(g, &m, false);
    positioning(g, &m, true);
    locked_while_busy(g, &m);
    reserved_while_busy(g, &m);
    clear_increment(g, &m);
    servo_error_latch(g, &m);
    for start in names::TEST_STARTS {
        test_profile(g, &m, start);
    }
    wiring_test(g, &m);
    feed_forward_defaults(g, &m);
    resets(g, &m);
    orientation(g, &m);
}

/// The slots and reads the motion cases use.
struct Motion {
    mode: Slot,
    pb40: Slot,
    pb70: Slot,
    speed: Probe,
    reserved: Probe,
    main: Probe,
    position: Probe,
    reference: Probe,
    /// Pr28, the shaft's absolute position within one revolution.
    shaft: Probe,
    flags41: Probe,
    flags70: Probe,
    torque: Probe,
    /// Pr35's raw value at the drive's peak torque.
    peak: i64,
    /// Pr35's raw value at [`CURRENT_LIMIT_PERCENT`].
    limit: i64,
    /// Pr19's raw value at [`CURRENT_LIMIT_PERCENT`].
    limit_setting: i64,
    slots: Vec<(u8, Slot)>,
    bit_lag_us: u64,
    /// The drive's slow operating-mode slot (µs): a drive may change its speed and position
    /// in steps of one slot.
    slot_us: u64,
}

impl Motion {
    fn new(g: &Gen) -> Option<Motion> {
        let probe = |id: &str, size: Option<u8>| -> Option<Probe> {
            let p = g.param(id)?;
            let s = g.slot(p)?;
            Some(Probe {
                par: s.addr,
                lun: size.unwrap_or(s.size),
                signed: p.data_type.signed() || size == Some(4),
            })
        };
        let slots = [
            5, 7, 8, 9, 10, 11, 12, 13, 14, 15, 19, 28, 50, 51, 52, 53, 54, 56, 57, 64, 66,
        ]
        .iter()
        .map(|n| Some((*n, g.slot_of(&format!("Pr{n}"))?)))
        .collect::<Option<Vec<_>>>()?;
        let lag = g
            .protocol
            .task_slots
            .iter()
            .find(|s| s.tasks.iter().any(|t| t == names::TASK_SPEED_WINDOWS))?;
        let slot = g
            .protocol
            .task_slots
            .iter()
            .find(|s| s.tasks.iter().any(|t| t == names::TASK_SLOW_MODE))?;
        Some(Motion {
            mode: g.slot_of(names::OPERATING_MODE)?,
            pb40: g.slot_of("Pb40")?,
            pb70: g.slot_of("Pb70")?,
            speed: probe("Pr0", None)?,
            reserved: probe("Pr6", None)?,
            main: probe("Pr7", None)?,
            position: probe("Pr62", Some(4))?,
            reference: probe("Pr60", Some(4))?,
            shaft: probe("Pr28", None)?,
            flags41: probe("Pb41", None)?,
            flags70: probe("Pb70", None)?,
            torque: probe(names::TORQUE_MONITOR, None)?,
            peak: percent_raw(PEAK_PERCENT, g.param(names::TORQUE_MONITOR)?.scale?),
            limit: percent_raw(
                CURRENT_LIMIT_PERCENT,
                g.param(names::TORQUE_MONITOR)?.scale?,
            ),
            limit_setting: percent_raw(CURRENT_LIMIT_PERCENT, g.param(names::PEAK_CURRENT)?.scale?),
            slots,
            bit_lag_us: u64::from(lag.period_us) + BIT_LAG_SLACK_US,
            slot_us: u64::from(slot.period_us),
        })
    }

    /// The slack of a speed change of at most `per_s` a second: one slot's change at that
    /// rate, plus the speed resolution.
    fn slope_slack(&self, per_s: i64) -> i64 {
        let slot = i64::try_from(self.slot_us).unwrap_or(i64::MAX);
        per_s.saturating_mul(slot).div_euclid(1_000_000) + 1 + SPEED_SLACK_RPM
    }

    /// The slack of a travel at up to `rpm`: one slot's travel, plus the position resolution.
    fn travel_slack(&self, rpm: i64) -> i64 {
        let slot = i64::try_from(self.slot_us).unwrap_or(i64::MAX);
        rpm.saturating_mul(STEPS_PER_REV)
            .saturating_mul(slot)
            .div_euclid(60_000_000)
            + 1
            + TRAVEL_SLACK_STEPS
    }

    fn pr(&self, n: u8) -> Slot {
        self.slots
            .iter()
            .find(|(k, _)| *k == n)
            .map_or(Slot { addr: 0, size: 0 }, |(_, s)| *s)
    }
}

/// The raw value of `percent` in steps of `scale` %.
fn percent_raw(percent: f64, scale: f64) -> i64 {
    let steps = (percent / scale).round();
    if steps.is_finite() && steps.abs() < 1e15 {
        steps as i64
    } else {
        0
    }
}

fn within(probe: usize, min: i64, max: i64) -> Within {
    Within {
        probe,
        bit: None,
        min,
        max,
    }
}

fn bit_is(probe: usize, bit: u32, value: i64) -> Within {
    Within {
        probe,
        bit: Some(bit),
        min: value,
        max: value,
    }
}

fn check(requirement: &str, envelope: Envelope) -> Check {
    Check {
        requirement: requirement.to_owned(),
        envelope,
    }
}

/// The largest speed change a second a ramp parameter allows (manual 3.3: 1000 rpm in
/// `raw` ms), with the slack.
fn ramp_per_s(raw: i64) -> i64 {
    1_000_000 / raw.max(1) * (100 + RAMP_SLACK_PERCENT) / 100
}

/// The run-time bound of a change of `rpm` on a ramp of `raw` ms per 1000 rpm (µs).
fn time_bound(rpm: i64, raw: i64) -> u64 {
    let ideal = u64::try_from(rpm.abs() * raw).unwrap_or(0);
    ideal * TIME_FACTOR_PERCENT / 100 + TIME_EXTRA_US
}

/// Adds a watch step.
#[allow(clippy::too_many_arguments)]
fn watch(
    g: &Gen,
    cb: &mut CaseB,
    role: Role,
    text: &str,
    reads: Vec<Probe>,
    us: u64,
    until: Vec<Within>,
    checks: Vec<Check>,
) {
    let reqs: Vec<String> = checks.iter().map(|c| c.requirement.clone()).collect();
    let mut unique: Vec<&str> = Vec::new();
    for r in &reqs {
        if !unique.contains(&r.as_str()) {
            unique.push(r);
        }
    }
    cb.action(
        role,
        Action::Watch {
            addr: g.addr,
            reads,
            us,
            every_us: 0,
            until,
            hold_us: HOLD_US,
            checks,
        },
        text,
        &unique,
    );
}

/// The b41 checks on rounds whose read 0 is Pr0 and read 1 is Pb41 (manual 3.3 b41.0–b41.3,
/// with the absolute window b40.7 = 1 and the case's Pr13, Pr14, Pr15).
fn speed_bits(m: &Motion) -> Vec<Check> {
    let lag_us = m.bit_lag_us;
    let follows = |bit: u32, ranges: Vec<(i64, i64)>| Envelope::BitFollows {
        flags: 1,
        bit,
        probe: 0,
        ranges,
        lag_us,
    };
    vec![
        check(
            "HPD-BIT-41-0",
            follows(
                0,
                vec![(OVERSPEED + 1, i64::MAX), (i64::MIN, -OVERSPEED - 1)],
            ),
        ),
        check(
            "HPD-BIT-41-1",
            follows(1, vec![(WINDOW.1 + 1, WINDOW.0 - 1)]),
        ),
        check("HPD-BIT-41-2", follows(2, vec![(0, 0)])),
        check("HPD-BIT-41-3", follows(3, vec![(1, i64::MAX)])),
    ]
}

/// Setup shared by the motion cases: PLC stopped (the default program drives b40.4–b40.6,
/// b40.12 and Pr5), the operating mode, and the parameters given.
fn setup(g: &mut Gen, cb: &mut CaseB, m: &Motion, mode: i64, values: &[(Slot, i64, &str)]) {
    g.stop_plc(cb);
    g.write(cb, Role::Setup, m.mode, mode, "Pr31");
    for (slot, v, what) in values {
        g.write(cb, Role::Setup, *slot, *v, what);
    }
}

/// Clean-up shared by the motion cases: Pb70 and Pb40 back (b40.2 = 0 ends the mode's
/// request), a wait for standstill, then the parameters and the mode.
fn cleanup(g: &mut Gen, cb: &mut CaseB, m: &Motion, values: &[(Slot, i64, &str)]) {
    g.restore(cb, m.pb70, "Pb70");
    g.restore(cb, m.pb40, "Pb40");
    watch(
        g,
        cb,
        Role::Cleanup,
        "wait for standstill",
        vec![m.speed],
        2_000_000,
        vec![within(0, 0, 0)],
        Vec::new(),
    );
    for (slot, _, what) in values.iter().rev() {
        g.restore(cb, *slot, what);
    }
    g.restore(cb, m.mode, "Pr31");
    g.restore_pb99(cb);
}

/// Pb40 with b40.2 (and b40.7 when `absolute`) set on top of its start value, written whole.
fn pb40_with(g: &Gen, m: &Motion, bits: &[&str]) -> i64 {
    let mut v = g.base(m.pb40);
    for b in bits {
        if let Some(r) = g.bit_ref(b) {
            v |= bit_value(m.pb40, r.at);
        }
    }
    i64::from(v)
}

/// HPD-MODE-8-001: jog with b70.1 (forward) or b70.2 (reverse) at Pr50, on the Pr8..Pr11
/// ramps, then back to standstill; HPD-PAR-048: Pr35 within ± the peak while it turns;
/// HPD-PAR-033: and within ± the current limit Pr19.
fn jog(g: &mut Gen, m: &Motion, forward: bool) {
    let (name, jog_bit, up, down) = if forward {
        ("forward", "b70.1", m.pr(8), m.pr(9))
    } else {
        ("reverse", "b70.2", m.pr(10), m.pr(11))
    };
    let (up_raw, down_raw) = if forward {
        (RAMP_UP, RAMP_DOWN)
    } else {
        (RAMP_REVERSE, RAMP_DOWN)
    };
    let target = if forward { JOG_RPM } else { -JOG_RPM };
    let Some(bit) = g.bit_ref(jog_bit) else {
        return;
    };
    let mut cb = CaseB::new(
        format!("hpd/motion/mode-8/jog-{name}"),
        format!(
            "mode 8 with b40.2 = 1: {jog_bit} turns the shaft {name} at Pr50 = {JOG_RPM} rpm on the ramps, and back to 0 rpm when cleared; b41.0–b41.3 follow the speed; Pr35 stays within the drive's peak and the current limit Pr19 = {CURRENT_LIMIT_PERCENT} % while it turns"
        ),
        &[],
    );
    let values = [
        (m.pr(50), JOG_RPM, "Pr50"),
        (up, up_raw, if forward { "Pr8" } else { "Pr10" }),
        (down, down_raw, if forward { "Pr9" } else { "Pr11" }),
        (m.pr(13), OVERSPEED, "Pr13"),
        (m.pr(14), WINDOW.0, "Pr14"),
        (m.pr(15), WINDOW.1, "Pr15"),
        (m.pr(19), m.limit_setting, "Pr19"),
    ];
    setup(g, &mut cb, m, 8, &values);
    let pb40 = pb40_with(g, m, &[names::RESERVED_REFERENCE, names::ABSOLUTE_WINDOW]);
    g.write(
        &mut cb,
        Role::Setup,
        m.pb40,
        pb40,
        "Pb40 (b40.2 = 1, b40.7 = 1)",
    );
    g.bit(&mut cb, Role::Check, &bit, true);
    let (lo, hi) = (target.min(0), target.max(0));
    let reads = vec![m.speed, m.flags41, m.reserved];
    let ramp_req = "HPD-PAR-026";
    let mut checks = vec![
        check(
            "HPD-MODE-8-001",
            Envelope::Bounded {
                within: within(0, lo - SPEED_SLACK_RPM, hi + SPEED_SLACK_RPM),
            },
        ),
        check(
            ramp_req,
            Envelope::Slope {
                probe: 0,
                per_s: ramp_per_s(up_raw),
                slack: m.slope_slack(ramp_per_s(up_raw)),
            },
        ),
        // The watch lasts the written-down bound: reaching the speed in it is the ramp time.
        check(
            "HPD-FORMULA-016",
            Envelope::Reaches {
                within: within(0, target - SPEED_SLACK_RPM, target + SPEED_SLACK_RPM),
            },
        ),
        check(
            "HPD-MODE-8-001",
            Envelope::Reaches {
                within: within(0, target - SPEED_SLACK_RPM, target + SPEED_SLACK_RPM),
            },
        ),
        check(
            "HPD-MODE-001",
            Envelope::Reaches {
                within: within(2, target, target),
            },
        ),
    ];
    checks.extend(speed_bits(m));
    watch(
        g,
        &mut cb,
        Role::Check,
        &format!("watch Pr0, Pb41 and Pr6 until Pr0 = {target} rpm"),
        reads.clone(),
        time_bound(target, up_raw) + HOLD_US,
        vec![within(
            0,
            target - SPEED_SLACK_RPM,
            target + SPEED_SLACK_RPM,
        )],
        checks,
    );
    watch(
        g,
        &mut cb,
        Role::Check,
        &format!("watch Pr0 and Pr35 while the shaft turns at {target} rpm"),
        vec![m.speed, m.torque],
        HOLD_US,
        Vec::new(),
        vec![
            check(
                "HPD-PAR-048",
                Envelope::Bounded {
                    within: within(1, -m.peak, m.peak),
                },
            ),
            check(
                "HPD-PAR-033",
                Envelope::Bounded {
                    within: within(1, -m.limit, m.limit),
                },
            ),
        ],
    );
    g.bit(&mut cb, Role::Check, &bit, false);
    let mut checks = vec![
        check(
            "HPD-MODE-8-001",
            Envelope::Bounded {
                within: within(0, lo - SPEED_SLACK_RPM, hi + SPEED_SLACK_RPM),
            },
        ),
        check(
            ramp_req,
            Envelope::Slope {
                probe: 0,
                per_s: ramp_per_s(down_raw),
                slack: m.slope_slack(ramp_per_s(down_raw)),
            },
        ),
        check(
            ramp_req,
            Envelope::Reaches {
                within: within(0, 0, 0),
            },
        ),
    ];
    checks.extend(speed_bits(m));
    watch(
        g,
        &mut cb,
        Role::Check,
        "watch Pr0 and Pb41 until the shaft stands still",
        reads,
        time_bound(target, down_raw) + HOLD_US,
        vec![within(0, 0, 0)],
        checks,
    );
    cleanup(g, &mut cb, m, &values);
    g.push(cb);
}

/// HPD-PAR-027: the stop function b40.6 ramps down on Pr12.
fn stop_ramp(g: &mut Gen, m: &Motion) {
    let (Some(jog_bit), Some(stop)) = (g.bit_ref("b70.1"), g.bit_ref(names::STOP)) else {
        return;
    };
    let mut cb = CaseB::new(
        "hpd/motion/stop-ramp",
        format!(
            "jogging at {JOG_RPM} rpm, b40.6 = 1 stops the motor no faster than Pr12 = {RAMP_STOP} ms per 1000 rpm allows, within the written-down time"
        ),
        &[],
    );
    let values = [
        (m.pr(50), JOG_RPM, "Pr50"),
        (m.pr(8), RAMP_UP, "Pr8"),
        (m.pr(12), RAMP_STOP, "Pr12"),
    ];
    setup(g, &mut cb, m, 8, &values);
    let pb40 = pb40_with(g, m, &[names::RESERVED_REFERENCE]);
    g.write(&mut cb, Role::Setup, m.pb40, pb40, "Pb40 (b40.2 = 1)");
    g.bit(&mut cb, Role::Setup, &jog_bit, true);
    watch(
        g,
        &mut cb,
        Role::Setup,
        "wait until the jog speed is reached",
        vec![m.speed],
        time_bound(JOG_RPM, RAMP_UP),
        vec![within(
            0,
            JOG_RPM - SPEED_SLACK_RPM,
            JOG_RPM + SPEED_SLACK_RPM,
        )],
        vec![check(
            "HPD-FORMULA-016",
            Envelope::Reaches {
                within: within(0, JOG_RPM - SPEED_SLACK_RPM, JOG_RPM + SPEED_SLACK_RPM),
            },
        )],
    );
    g.bit(&mut cb, Role::Check, &stop, true);
    watch(
        g,
        &mut cb,
        Role::Check,
        "watch Pr0 until the shaft stands still",
        vec![m.speed],
        time_bound(JOG_RPM, RAMP_STOP),
        vec![within(0, 0, 0)],
        vec![
            check(
                "HPD-PAR-027",
                Envelope::Slope {
                    probe: 0,
                    per_s: ramp_per_s(RAMP_STOP),
                    slack: m.slope_slack(ramp_per_s(RAMP_STOP)),
                },
            ),
            check(
                "HPD-PAR-027",
                Envelope::Reaches {
                    within: within(0, 0, 0),
                },
            ),
        ],
    );
    cleanup(g, &mut cb, m, &values);
    g.push(cb);
}

/// HPD-MODE-002, HPD-FORMULA-007: with b40.2 = 0 the speed loop follows Pr7 (= Pr5 with
/// b40.12 = 1, b40.13 = 0), not the mode's jog request; with b40.2 = 1 it follows the mode.
fn reference_select(g: &mut Gen, m: &Motion) {
    let Some(jog_bit) = g.bit_ref("b70.1") else {
        return;
    };
    let mut cb = CaseB::new(
        "hpd/motion/reference-select",
        format!(
            "jog b70.1 at {JOG_RPM} rpm with b40.2 = 0 and Pr7 = Pr5 = {INTERNAL_RPM} rpm: the motor follows Pr7; b40.2 = 1 switches it to the mode's request"
        ),
        &[],
    );
    let values = [
        (m.pr(50), JOG_RPM, "Pr50"),
        (m.pr(5), INTERNAL_RPM, "Pr5"),
        (m.pr(8), RAMP_UP, "Pr8"),
        (m.pr(9), RAMP_DOWN, "Pr9"),
    ];
    setup(g, &mut cb, m, 8, &values);
    let digital = pb40_with(g, m, &[names::DIGITAL_REFERENCE]);
    g.write(&mut cb, Role::Setup, m.pb40, digital, "Pb40 (b40.12 = 1)");
    g.read(&mut cb, Role::Check, m.pr(7), Compare::Exact, "Pr7");
    if let Some(step) = cb.steps.last_mut() {
        step.requirements.insert(0, "HPD-FORMULA-007".to_owned());
    }
    g.bit(&mut cb, Role::Setup, &jog_bit, true);
    let speed = within(
        0,
        INTERNAL_RPM - SPEED_SLACK_RPM,
        INTERNAL_RPM + SPEED_SLACK_RPM,
    );
    watch(
        g,
        &mut cb,
        Role::Check,
        &format!("watch Pr0 until it reaches Pr7 = {INTERNAL_RPM} rpm"),
        vec![m.speed, m.main],
        time_bound(INTERNAL_RPM, RAMP_UP) + HOLD_US,
        vec![speed],
        vec![
            check(
                "HPD-MODE-002",
                Envelope::Bounded {
                    within: within(0, -SPEED_SLACK_RPM, INTERNAL_RPM + SPEED_SLACK_RPM),
                },
            ),
            check("HPD-FORMULA-016", Envelope::Reaches { within: speed }),
            check("HPD-MODE-002", Envelope::Reaches { within: speed }),
            check(
                "HPD-FORMULA-007",
                Envelope::Bounded {
                    within: within(1, INTERNAL_RPM, INTERNAL_RPM),
                },
            ),
        ],
    );
    let both = pb40_with(g, m, &[names::DIGITAL_REFERENCE, names::RESERVED_REFERENCE]);
    g.write(
        &mut cb,
        Role::Check,
        m.pb40,
        both,
        "Pb40 (b40.2 = 1, b40.12 = 1)",
    );
    watch(
        g,
        &mut cb,
        Role::Check,
        &format!("watch Pr0 until it reaches Pr50 = {JOG_RPM} rpm"),
        vec![m.speed],
        time_bound(JOG_RPM, RAMP_UP) + HOLD_US,
        vec![within(
            0,
            JOG_RPM - SPEED_SLACK_RPM,
            JOG_RPM + SPEED_SLACK_RPM,
        )],
        vec![
            check(
                "HPD-FORMULA-016",
                Envelope::Reaches {
                    within: within(0, JOG_RPM - SPEED_SLACK_RPM, JOG_RPM + SPEED_SLACK_RPM),
                },
            ),
            check(
                "HPD-MODE-002",
                Envelope::Reaches {
                    within: within(0, JOG_RPM - SPEED_SLACK_RPM, JOG_RPM + SPEED_SLACK_RPM),
                },
            ),
        ],
    );
    cleanup(g, &mut cb, m, &values);
    g.push(cb);
}

/// Sets command bit `name` with a bit change, cleared first: a drive whose command bits stay
/// 1 until the master clears them (the `latched` reading of HPD-ERRATUM-012) sees a rise.
fn command(g: &mut Gen, cb: &mut CaseB, role: Role, name: &str) {
    if let Some(b) = g.bit_ref(name) {
        g.bit(cb, Role::Setup, &b, false);
        g.bit(cb, role, &b, true);
    }
}

/// HPD-MODE-9-001, HPD-MODE-9-002, HPD-MODE-POSITION, HPD-MODE-9-PROFILE-BUSY,
/// HPD-MODE-9-006: a profile of Pr64:65 steps from position 0, forward or in reverse
/// (b70.4), then reset type 1.
fn positioning(g: &mut Gen, m: &Motion, reverse: bool) {
    let (accel, top, revs) = PROFILE;
    let steps = revs * STEPS_PER_REV;
    let to = if reverse { -steps } else { steps };
    let name = if reverse { "reverse" } else { "forward" };
    let mut cb = CaseB::new(
        format!("hpd/motion/mode-9/profile-{name}"),
        format!(
            "mode 9: b70.8 runs {steps} steps {name} at Pr52 = {top} rpm with Pr51 = {accel} ms per 1000 rpm; the position moves one way and ends within Pr56 of the target; b70.7 is 1 while it moves; reset type 1 then zeroes both positions"
        ),
        &[],
    );
    let window = 100;
    let values = [
        (m.pr(51), accel, "Pr51"),
        (m.pr(52), top, "Pr52"),
        (m.pr(56), window, "Pr56"),
    ];
    setup(g, &mut cb, m, 9, &values);
    let increment = Slot {
        addr: m.pr(64).addr,
        size: 4,
    };
    g.write(&mut cb, Role::Setup, increment, steps, "Pr64:65");
    let pb40 = pb40_with(g, m, &[names::RESERVED_REFERENCE]);
    g.write(&mut cb, Role::Setup, m.pb40, pb40, "Pb40 (b40.2 = 1)");
    command(g, &mut cb, Role::Setup, "b70.10");
    if reverse {
        command(g, &mut cb, Role::Setup, "b70.4");
    }
    command(g, &mut cb, Role::Check, "b70.8");
    // Ideal trapezoid: the time to cruise the distance plus one ramp.
    let ideal_us =
        u64::try_from(steps * 60_000_000 / STEPS_PER_REV / top + top * accel).unwrap_or(0);
    let us = ideal_us * TIME_FACTOR_PERCENT / 100 + TIME_EXTRA_US + HOLD_US;
    let speed_lo = if reverse {
        -top - SPEED_SLACK_RPM
    } else {
        -SPEED_SLACK_RPM
    };
    let speed_hi = if reverse {
        SPEED_SLACK_RPM
    } else {
        top + SPEED_SLACK_RPM
    };
    watch(
        g,
        &mut cb,
        Role::Check,
        &format!("watch Pr62:63, Pb70, Pr0 and Pr60:61 until b70.7 = 0 at {to}"),
        vec![m.position, m.flags70, m.speed, m.reference],
        us,
        vec![bit_is(1, 7, 0), within(0, to - window, to + window)],
        vec![
            check(
                "HPD-MODE-9-002",
                Envelope::Monotonic {
                    probe: 0,
                    rising: !reverse,
                    slack: 0,
                },
            ),
            check(
                "HPD-MODE-9-001",
                Envelope::Bounded {
                    within: within(2, speed_lo, speed_hi),
                },
            ),
            check(
                "HPD-MODE-9-001",
                Envelope::Slope {
                    probe: 2,
                    per_s: ramp_per_s(accel),
                    slack: m.slope_slack(ramp_per_s(accel)),
                },
            ),
            check(
                "HPD-FORMULA-017",
                Envelope::Travel {
                    position: 0,
                    speed: 2,
                    steps_per_rev: STEPS_PER_REV,
                    top_rpm: top + SPEED_SLACK_RPM,
                    slack: TRAVEL_SLACK_PERCENT,
                    slack_steps: m.travel_slack(top + SPEED_SLACK_RPM),
                },
            ),
            // The unit table of section 3: Pr0 in rpm and Pr62:63 in 4096 steps a
            // revolution, judged together by how far the position moves at the speed read.
            check(
                "HPD-PAR-002",
                Envelope::Travel {
                    position: 0,
                    speed: 2,
                    steps_per_rev: STEPS_PER_REV,
                    top_rpm: top + SPEED_SLACK_RPM,
                    slack: TRAVEL_SLACK_PERCENT,
                    slack_steps: m.travel_slack(top + SPEED_SLACK_RPM),
                },
            ),
            check(
                "HPD-MODE-9-001",
                Envelope::Ends {
                    within: within(0, to - window, to + window),
                },
            ),
            check(
                "HPD-MODE-POSITION",
                Envelope::Ends {
                    within: within(3, to - window, to + window),
                },
            ),
            check(
                "HPD-MODE-9-PROFILE-BUSY",
                Envelope::BusyWhileMoving {
                    flags: 1,
                    bit: 7,
                    probe: 0,
                    from: 0,
                    to,
                    rpm: top + SPEED_SLACK_RPM,
                    window,
                },
            ),
        ],
    );
    command(g, &mut cb, Role::Check, "b70.10");
    for (probe, what) in [(m.position, "Pr62:63"), (m.reference, "Pr60:61")] {
        let slot = Slot {
            addr: probe.par,
            size: 4,
        };
        g.read(&mut cb, Role::Check, slot, Compare::Exact, what);
        if let Some(step) = cb.steps.last_mut() {
            step.requirements.insert(0, "HPD-MODE-9-006".to_owned());
        }
    }
    g.restore(&mut cb, increment, "Pr64:65");
    cleanup(g, &mut cb, m, &values);
    g.push(cb);
}

/// HPD-PAR-059: while a profile executes (b70.7 = 1) a write of Pr52 is not taken.
fn locked_while_busy(g: &mut Gen, m: &Motion) {
    let (accel, top, _) = PROFILE;
    let steps = 6 * STEPS_PER_REV;
    let slow = top / 2;
    let mut cb = CaseB::new(
        "hpd/motion/mode-9/locked-while-busy",
        format!(
            "mode 9: while a profile of {steps} steps at {slow} rpm executes, a write of Pr52 is not taken (only Pr64:65 may change)"
        ),
        &[],
    );
    let values = [(m.pr(51), accel, "Pr51"), (m.pr(52), slow, "Pr52")];
    setup(g, &mut cb, m, 9, &values);
    let increment = Slot {
        addr: m.pr(64).addr,
        size: 4,
    };
    g.write(&mut cb, Role::Setup, increment, steps, "Pr64:65");
    let pb40 = pb40_with(g, m, &[names::RESERVED_REFERENCE]);
    g.write(&mut cb, Role::Setup, m.pb40, pb40, "Pb40 (b40.2 = 1)");
    command(g, &mut cb, Role::Setup, "b70.10");
    command(g, &mut cb, Role::Setup, "b70.8");
    watch(
        g,
        &mut cb,
        Role::Setup,
        "wait until b70.7 = 1",
        vec![m.flags70],
        TIME_EXTRA_US,
        vec![bit_is(0, 7, 1)],
        vec![check(
            "HPD-MODE-9-PROFILE-BUSY",
            Envelope::Reaches {
                within: bit_is(0, 7, 1),
            },
        )],
    );
    if let Some(step) = cb.steps.last_mut() {
        if let Action::Watch { hold_us, .. } = &mut step.action {
            *hold_us = 0;
        }
    }
    g.write(
        &mut cb,
        Role::Check,
        m.pr(52),
        top,
        "Pr52 (while the profile runs)",
    );
    g.read(&mut cb, Role::Check, m.pr(52), Compare::Exact, "Pr52");
    if let Some(step) = cb.steps.last_mut() {
        step.requirements.insert(0, "HPD-PAR-059".to_owned());
    }
    let ideal_us = u64::try_from(steps * 60_000_000 / STEPS_PER_REV / slow).unwrap_or(0);
    watch(
        g,
        &mut cb,
        Role::Cleanup,
        "wait for the end of the profile",
        vec![m.flags70],
        ideal_us * TIME_FACTOR_PERCENT / 100 + TIME_EXTRA_US,
        vec![bit_is(0, 7, 0)],
        Vec::new(),
    );
    command(g, &mut cb, Role::Cleanup, "b70.10");
    g.restore(&mut cb, increment, "Pr64:65");
    cleanup(g, &mut cb, m, &values);
    g.push(cb);
}

/// HPD-MODE-9-008: Pr66:67 is reserved while a profile is generated (manual 3.6.4: "cannot
/// be used during profile generation"). The manual does not say what a write of it then
/// does: its answer (acknowledge or silence) and the value read back are each accepted and
/// reported. 3.6.4 allows no change of a running profile but of Pr64:65: the write, made at
/// the cruise speed, leaves the shaft at that speed, and the profile ends at its target
/// (HPD-MODE-9-001).
fn reserved_while_busy(g: &mut Gen, m: &Motion) {
    let (accel, top, _) = PROFILE;
    let steps = 6 * STEPS_PER_REV;
    let slow = top / 2;
    let window = 100;
    let mut cb = CaseB::new(
        "hpd/motion/mode-9/reserved-while-busy",
        format!(
            "mode 9: a write of Pr66:67 while a profile of {steps} steps at {slow} rpm executes may be taken, refused or ignored; the profile still ends within Pr56 of its target"
        ),
        &[],
    );
    let values = [
        (m.pr(51), accel, "Pr51"),
        (m.pr(52), slow, "Pr52"),
        (m.pr(56), window, "Pr56"),
    ];
    setup(g, &mut cb, m, 9, &values);
    let increment = Slot {
        addr: m.pr(64).addr,
        size: 4,
    };
    let reserved = Slot {
        addr: m.pr(66).addr,
        size: 4,
    };
    g.write(&mut cb, Role::Setup, increment, steps, "Pr64:65");
    let pb40 = pb40_with(g, m, &[names::RESERVED_REFERENCE]);
    g.write(&mut cb, Role::Setup, m.pb40, pb40, "Pb40 (b40.2 = 1)");
    command(g, &mut cb, Role::Setup, "b70.10");
    command(g, &mut cb, Role::Setup, "b70.8");
    let cruise = within(0, slow - SPEED_SLACK_RPM, slow + SPEED_SLACK_RPM);
    watch(
        g,
        &mut cb,
        Role::Setup,
        &format!("wait until Pr0 = {slow} rpm"),
        vec![m.speed],
        time_bound(slow, accel),
        vec![cruise],
        Vec::new(),
    );
    if let Some(step) = cb.steps.last_mut() {
        if let Action::Watch { hold_us, .. } = &mut step.action {
            *hold_us = 0;
        }
    }
    g.write(
        &mut cb,
        Role::Check,
        reserved,
        steps,
        "Pr66:67 (while the profile runs)",
    );
    if let Some(step) = cb.steps.last_mut() {
        step.requirements.insert(0, "HPD-MODE-9-008".to_owned());
        if let Action::Exchange { silence_ok, .. } = &mut step.action {
            *silence_ok = true;
        }
    }
    g.read_open(
        &mut cb,
        reserved,
        (0, i64::from(i32::MIN), i64::from(i32::MAX)),
        "HPD-MODE-9-008",
        "Pr66:67",
    );
    watch(
        g,
        &mut cb,
        Role::Check,
        &format!("watch Pr0 at {slow} rpm after the write"),
        vec![m.speed],
        HOLD_US,
        Vec::new(),
        vec![check(
            "HPD-MODE-9-008",
            Envelope::Bounded { within: cruise },
        )],
    );
    let ideal_us = u64::try_from(steps * 60_000_000 / STEPS_PER_REV / slow).unwrap_or(0);
    watch(
        g,
        &mut cb,
        Role::Check,
        &format!("watch Pr62:63 and Pb70 until b70.7 = 0 at {steps}"),
        vec![m.position, m.flags70],
        ideal_us * TIME_FACTOR_PERCENT / 100 + TIME_EXTRA_US,
        vec![bit_is(1, 7, 0), within(0, steps - window, steps + window)],
        vec![check(
            "HPD-MODE-9-001",
            Envelope::Ends {
                within: within(0, steps - window, steps + window),
            },
        )],
    );
    command(g, &mut cb, Role::Cleanup, "b70.10");
    g.restore(&mut cb, reserved, "Pr66:67");
    g.restore(&mut cb, increment, "Pr64:65");
    cleanup(g, &mut cb, m, &values);
    g.push(cb);
}

/// HPD-MODE-9-005: b70.2 clears Pr64:65 in mode 9.
fn clear_increment(g: &mut Gen, m: &Motion) {
    let mut cb = CaseB::new(
        "hpd/motion/mode-9/b70.2-clears-increment",
        "mode 9: b70.2 clears the incremental position Pr64:65",
        &[],
    );
    setup(g, &mut cb, m, 9, &[]);
    let increment = Slot {
        addr: m.pr(64).addr,
        size: 4,
    };
    g.write(&mut cb, Role::Setup, increment, 12_345, "Pr64:65");
    command(g, &mut cb, Role::Check, "b70.2");
    g.read(&mut cb, Role::Check, increment, Compare::Exact, "Pr64:65");
    if let Some(step) = cb.steps.last_mut() {
        step.requirements.insert(0, "HPD-MODE-9-005".to_owned());
    }
    g.restore(&mut cb, increment, "Pr64:65");
    g.restore(&mut cb, m.pb70, "Pb70");
    g.restore(&mut cb, m.mode, "Pr31");
    g.restore_pb99(&mut cb);
    g.push(cb);
}

/// HPD-MODE-SERVO-ERROR-LATCH: in mode 9 b70.5, once 1, stays 1 until the user resets it
/// (manual 3.6.4: "If b70.5 is utilised it must be reset by the user"). Set over the line at
/// standstill, it is still 1 after two periods of the slowest task slot (appendix F), however
/// the position error then compares with Pr56.
fn servo_error_latch(g: &mut Gen, m: &Motion) {
    let Some(servo) = g.bit_ref("b70.5") else {
        return;
    };
    let wait = 2 * g
        .protocol
        .task_slots
        .iter()
        .map(|s| u64::from(s.period_us))
        .max()
        .unwrap_or(m.slot_us);
    let mut cb = CaseB::new(
        "hpd/motion/mode-9/servo-error-latched",
        "mode 9: b70.5 set over the line stays 1 until the user clears it",
        &[],
    );
    setup(g, &mut cb, m, 9, &[]);
    g.bit(&mut cb, Role::Setup, &servo, true);
    cb.action(
        Role::Setup,
        Action::Listen { us: wait },
        "listen for two periods of the slowest task slot",
        &[],
    );
    let cmp = Compare::Mask(bit_value(m.pb70, servo.at));
    g.read(&mut cb, Role::Check, m.pb70, cmp, "Pb70");
    if let Some(step) = cb.steps.last_mut() {
        step.requirements
            .insert(0, "HPD-MODE-SERVO-ERROR-LATCH".to_owned());
    }
    g.restore(&mut cb, m.pb70, "Pb70");
    g.restore(&mut cb, m.mode, "Pr31");
    g.restore_pb99(&mut cb);
    g.push(cb);
}

/// The longest a round of `reads` reads of one word may take on the line the device was
/// commissioned with (µs): the request and the longest answer at its bit rate, the answer
/// delay and the message time-out of the answer window (manual 4 table, 4.1).
fn round_us(g: &Gen, reads: u64) -> Option<u64> {
    let line = g.baseline.line()?;
    let bits = u64::from(g.protocol.character.bits_per_char.max(1));
    let frame = (drivespec_hpd::MAX_FRAME as u64) * bits * 1_000_000 / u64::from(line.bps.max(1));
    Some(reads * (2 * frame + line.answer_delay_us + line.timeout_us))
}

/// HPD-MODE-8-005, HPD-MODE-8-006: in mode 8, b70.0 = 1 with b40.2 = 1 runs the test profile
/// from the starting point Pr53 = `start`. Mode 8 has no position register (Pr60:63 are
/// reserved), so the shaft is followed through Pr28, its revolutions counted between rounds,
/// and through Pr0. Judged: the speed never above Pr51; the first stroke's direction and
/// length (Pr52, Pr52 / 2 or Pr52 revolutions at negative speed); a pause of Pr54 at 0 rpm;
/// the next stroke the other way. The manual gives the profile no ramps and does not say how
/// soon after b70.0 it starts: any ramp and start are accepted. Pr50 = 2 × Pr51 shows a
/// profile run at the jog speed.
fn test_profile(g: &mut Gen, m: &Motion, start: i64) {
    let (Some(run), Some(round)) = (g.bit_ref("b70.0"), round_us(g, 2)) else {
        return;
    };
    let per_round =
        i64::try_from(60_000_000 / (round.max(1) * TURNS_PER_ROUND as u64)).unwrap_or(i64::MAX);
    let rpm = TEST_TOP_RPM.min(per_round - SPEED_SLACK_RPM).max(1);
    let tenths = TEST_PAUSE_TENTHS
        .max(i64::try_from((4 * round).div_ceil(US_PER_TENTH)).unwrap_or(TEST_PAUSE_TENTHS));
    let pause_us = u64::try_from(tenths).unwrap_or(0) * US_PER_TENTH;
    let (forward, revs_x2, words) = match names::TEST_STARTS.iter().position(|s| *s == start) {
        Some(1) => (true, TEST_REVS, "Pr52 / 2 revolutions at positive speed"),
        Some(2) => (false, 2 * TEST_REVS, "Pr52 revolutions at negative speed"),
        _ => (true, 2 * TEST_REVS, "Pr52 revolutions at positive speed"),
    };
    let stroke = revs_x2 * STEPS_PER_REV / 2;
    let mut cb = CaseB::new(
        format!("hpd/motion/mode-8/profile-start-{start}"),
        format!(
            "mode 8 with b40.2 = 1 and Pr53 = {start}: b70.0 = 1 runs the test profile at no more than Pr51 = {rpm} rpm, first {words} (Pr52 = {TEST_REVS}), then a pause of Pr54 = {tenths} tenths of a second at 0 rpm, then the other way"
        ),
        &[],
    );
    let values = [
        (m.pr(50), 2 * rpm, "Pr50"),
        (m.pr(51), rpm, "Pr51"),
        (m.pr(52), TEST_REVS, "Pr52"),
        (m.pr(53), start, "Pr53"),
        (m.pr(54), tenths, "Pr54"),
        (m.pr(8), RAMP_UP, "Pr8"),
        (m.pr(9), RAMP_DOWN, "Pr9"),
        (m.pr(10), RAMP_REVERSE, "Pr10"),
        (m.pr(11), RAMP_DOWN, "Pr11"),
    ];
    setup(g, &mut cb, m, 8, &values);
    let pb40 = pb40_with(g, m, &[names::RESERVED_REFERENCE]);
    g.write(&mut cb, Role::Setup, m.pb40, pb40, "Pb40 (b40.2 = 1)");
    g.bit(&mut cb, Role::Check, &run, true);
    let shaft = Shaft {
        position: 0,
        speed: 1,
        steps_per_rev: STEPS_PER_REV,
        top_rpm: rpm + SPEED_SLACK_RPM,
    };
    let half = (rpm / 2).max(1);
    let back = if forward {
        within(1, i64::MIN, -half)
    } else {
        within(1, half, i64::MAX)
    };
    let first_us = u64::try_from(revs_x2 * 30_000_000 / rpm).unwrap_or(0);
    let ramps_us = u64::try_from(3 * rpm * RAMP_REVERSE.max(RAMP_UP)).unwrap_or(0);
    watch(
        g,
        &mut cb,
        Role::Check,
        "watch Pr28 and Pr0 through the first stroke and the pause until the shaft turns back",
        vec![m.shaft, m.speed],
        (first_us + pause_us) * TIME_FACTOR_PERCENT / 100 + TIME_EXTRA_US + ramps_us + HOLD_US,
        vec![back],
        vec![
            check(
                "HPD-MODE-8-005",
                Envelope::Bounded {
                    within: within(1, -rpm - SPEED_SLACK_RPM, rpm + SPEED_SLACK_RPM),
                },
            ),
            check(
                "HPD-MODE-8-006",
                Envelope::FirstStroke {
                    shaft,
                    forward,
                    min: stroke - STROKE_SLACK_STEPS,
                    max: stroke + STROKE_SLACK_STEPS,
                },
            ),
            // Less one round of reads: the speed read of a real loop settles at 0 rpm a little
            // after its profile's reference does.
            check(
                "HPD-MODE-8-005",
                Envelope::Pause {
                    shaft,
                    min_us: pause_us.saturating_sub(round),
                },
            ),
            check("HPD-MODE-8-005", Envelope::Reverses { shaft }),
        ],
    );
    cleanup(g, &mut cb, m, &values);
    g.push(cb);
}

/// HPD-MODE-8-004: with b40.9 = 1 the wiring test ends with code 1 in Pr56 (Pr57 = 0).
fn wiring_test(g: &mut Gen, m: &Motion) {
    let mut cb = CaseB::new(
        "hpd/motion/mode-8/wiring-test-enabled",
        "mode 8 with b40.9 = 1: the wiring test b70.3 ends, and Pr56 shows code 1 after Pr57 = 0",
        &[],
    );
    let values = [(m.pr(57), 0, "Pr57"), (m.pr(56), 0, "Pr56")];
    setup(g, &mut cb, m, 8, &values);
    let pb40 = pb40_with(g, m, &[names::SOFTWARE_ENABLE]);
    g.write(&mut cb, Role::Setup, m.pb40, pb40, "Pb40 (b40.9 = 1)");
    command(g, &mut cb, Role::Check, "b70.3");
    watch(
        g,
        &mut cb,
        Role::Check,
        "watch Pb70 until the test has ended (b70.3 = 0)",
        vec![m.flags70],
        TIME_EXTRA_US * 4,
        vec![bit_is(0, 3, 0)],
        vec![check(
            "HPD-MODE-8-003",
            Envelope::Reaches {
                within: bit_is(0, 3, 0),
            },
        )],
    );
    g.write(&mut cb, Role::Check, m.pr(57), 0, "Pr57");
    g.read(&mut cb, Role::Check, m.pr(56), Compare::Exact, "Pr56");
    if let Some(step) = cb.steps.last_mut() {
        step.requirements.insert(0, "HPD-MODE-8-004".to_owned());
    }
    g.restore(&mut cb, m.pb70, "Pb70");
    g.restore(&mut cb, m.pb40, "Pb40");
    for (slot, _, what) in values.iter().rev() {
        g.restore(&mut cb, *slot, what);
    }
    g.restore(&mut cb, m.mode, "Pr31");
    g.restore_pb99(&mut cb);
    g.push(cb);
}

/// HPD-MODE-9-007, HPD-MODE-10-008: b99.11 gives b70.6 its mode default: 0 in modes 9 and
/// 11, 1 in mode 10.
fn feed_forward_defaults(g: &mut Gen, m: &Motion) {
    let Some(ff) = g.bit_ref("b70.6") else {
        return;
    };
    for (mode, requirement, default) in [
        (9, "HPD-MODE-9-007", false),
        (11, "HPD-MODE-9-007", false),
        (10, "HPD-MODE-10-008", true),
    ] {
        let mut cb = CaseB::new(
            format!("hpd/motion/mode-{mode}/feed-forward-default"),
            format!(
                "mode {mode}: after b70.6 = {} the mode defaults (b99.11) give b70.6 = {}",
                u8::from(!default),
                u8::from(default)
            ),
            &[],
        );
        setup(g, &mut cb, m, mode, &[]);
        g.bit(&mut cb, Role::Setup, &ff, !default);
        command(g, &mut cb, Role::Setup, names::MODE_DEFAULTS);
        g.read(
            &mut cb,
            Role::Check,
            m.pb70,
            Compare::Mask(bit_value(m.pb70, ff.at)),
            "Pb70 (b70.6)",
        );
        if let Some(step) = cb.steps.last_mut() {
            step.requirements.insert(0, requirement.to_owned());
        }
        g.restore(&mut cb, m.pb70, "Pb70");
        g.restore(&mut cb, m.mode, "Pr31");
        g.restore_pb99(&mut cb);
        g.push(cb);
    }
}

/// HPD-MODE-11-004, HPD-MODE-10-007: the reset types act on the positions written by the
/// master (mode 11: type 3 then type 1; mode 10: type 1 refused while the axis is locked).
fn resets(g: &mut Gen, m: &Motion) {
    let position = Slot {
        addr: m.position.par,
        size: 4,
    };
    let reference = Slot {
        addr: m.reference.par,
        size: 4,
    };
    let (motor_at, reference_at) = (5_000, 7_000);
    let read = |g: &mut Gen, cb: &mut CaseB, slot: Slot, what: &str, req: &str| {
        g.read(cb, Role::Check, slot, Compare::Exact, what);
        if let Some(step) = cb.steps.last_mut() {
            step.requirements.insert(0, req.to_owned());
        }
    };
    let mut cb = CaseB::new(
        "hpd/motion/mode-11/resets",
        format!(
            "mode 11 with Pr62:63 = {motor_at} and Pr60:61 = {reference_at}: reset type 3 (b70.12) sets the reference to the motor position, reset type 1 (b70.10) zeroes both"
        ),
        &[],
    );
    setup(g, &mut cb, m, 11, &[]);
    g.write(&mut cb, Role::Setup, position, motor_at, "Pr62:63");
    g.write(&mut cb, Role::Setup, reference, reference_at, "Pr60:61");
    command(g, &mut cb, Role::Check, "b70.12");
    read(g, &mut cb, reference, "Pr60:61", "HPD-MODE-11-004");
    command(g, &mut cb, Role::Check, "b70.10");
    read(g, &mut cb, position, "Pr62:63", "HPD-MODE-11-004");
    read(g, &mut cb, reference, "Pr60:61", "HPD-MODE-11-004");
    g.restore(&mut cb, m.pb70, "Pb70");
    g.restore(&mut cb, m.mode, "Pr31");
    g.restore_pb99(&mut cb);
    g.push(cb);

    let Some(lock) = g.bit_ref("b70.8") else {
        return;
    };
    let mut cb = CaseB::new(
        "hpd/motion/mode-10/reset-only-released",
        format!(
            "mode 10 with Pr62:63 = {motor_at}: reset type 1 (b70.10) is not executed while the axis is locked (b70.8 = 1), and is once it is released"
        ),
        &[],
    );
    setup(g, &mut cb, m, 10, &[]);
    g.write(&mut cb, Role::Setup, position, motor_at, "Pr62:63");
    g.bit(&mut cb, Role::Setup, &lock, true);
    command(g, &mut cb, Role::Check, "b70.10");
    read(g, &mut cb, position, "Pr62:63", "HPD-MODE-10-007");
    g.bit(&mut cb, Role::Setup, &lock, false);
    command(g, &mut cb, Role::Check, "b70.10");
    read(g, &mut cb, position, "Pr62:63", "HPD-MODE-10-007");
    g.restore(&mut cb, m.pb70, "Pb70");
    g.restore(&mut cb, m.mode, "Pr31");
    g.restore_pb99(&mut cb);
    g.push(cb);
}

/// HPD-MODE-12-001, HPD-MODE-12-SERVO-ERROR: with b40.2 = 1 mode 12 turns at no more than
/// Pr50 and stops with the shaft (Pr28) within Pr56 of Pr54; b70.5 is then 0.
fn orientation(g: &mut Gen, m: &Motion) {
    let Some(shaft) = g.slot_of("Pr28") else {
        return;
    };
    let (top, ramp, at, window) = (ORIENT_RPM, RAMP_DOWN, STEPS_PER_REV / 2, 100);
    let mut cb = CaseB::new(
        "hpd/motion/mode-12/orientation",
        format!(
            "mode 12: b40.2 = 1 turns the spindle up to Pr50 = {top} rpm, never faster, and stops it with Pr28 within Pr56 = {window} of Pr54 = {at}; b70.5 is 0 with the loop closed there"
        ),
        &[],
    );
    let values = [
        (m.pr(50), top, "Pr50"),
        (m.pr(52), ramp, "Pr52"),
        (m.pr(54), at, "Pr54"),
        (m.pr(56), window, "Pr56"),
    ];
    setup(g, &mut cb, m, 12, &values);
    let pb40 = pb40_with(g, m, &[names::RESERVED_REFERENCE]);
    g.write(&mut cb, Role::Check, m.pb40, pb40, "Pb40 (b40.2 = 1)");
    let probe = Probe {
        par: shaft.addr,
        lun: shaft.size,
        signed: false,
    };
    // At most two revolutions at Pr50 plus the ramps.
    let ideal_us = u64::try_from(2 * 60_000_000 / top + top * ramp).unwrap_or(0);
    let speed = within(0, top - SPEED_SLACK_RPM, top + SPEED_SLACK_RPM);
    watch(
        g,
        &mut cb,
        Role::Check,
        &format!("watch Pr0 until it reaches Pr50 = {top} rpm"),
        vec![m.speed],
        time_bound(top, ramp),
        vec![speed],
        vec![check(
            "HPD-MODE-12-001",
            Envelope::Reaches { within: speed },
        )],
    );
    if let Some(step) = cb.steps.last_mut() {
        if let Action::Watch { hold_us, .. } = &mut step.action {
            *hold_us = 0;
        }
    }
    watch(
        g,
        &mut cb,
        Role::Check,
        &format!("watch Pr0, Pr28 and Pb70 until the spindle stands at {at}"),
        vec![m.speed, probe, m.flags70],
        ideal_us * TIME_FACTOR_PERCENT / 100 + TIME_EXTRA_US + HOLD_US,
        vec![
            within(0, 0, 0),
            within(1, at - window, at + window),
            bit_is(2, 5, 0),
        ],
        vec![
            check(
                "HPD-MODE-12-001",
                Envelope::Bounded {
                    within: within(0, -SPEED_SLACK_RPM, top + SPEED_SLACK_RPM),
                },
            ),
            check(
                "HPD-MODE-12-001",
                Envelope::Ends {
                    within: within(1, at - window, at + window),
                },
            ),
            check(
                "HPD-MODE-12-001",
                Envelope::Ends {
                    within: within(0, 0, 0),
                },
            ),
            check(
                "HPD-MODE-12-SERVO-ERROR",
                Envelope::Ends {
                    within: bit_is(2, 5, 0),
                },
            ),
        ],
    );
    cleanup(g, &mut cb, m, &values);
    g.push(cb);
}
