//! Judging a watch (manual 3.3, 3.6): the device's own samples against the envelope the
//! manual states (a range reached, never left, a ramp no steeper than its parameter, a
//! direction kept, a status bit consistent with the value it reports on). The reference's
//! trajectory is never compared sample by sample: a drive may start later, ramp more gently or
//! update its status bits in its own time slot, as far as the manual lets it.
//!
//! Pure functions over the samples; nothing here reads a clock.

use crate::link::Micros;
use drivespec_hpd::step::{Envelope, Shaft, Within};

/// One read of a round as the device answered it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Sample {
    /// The value read.
    pub(crate) value: i64,
    /// When the request went out (link µs).
    pub(crate) sent: Micros,
    /// When the answer was complete (link µs).
    pub(crate) came: Micros,
}

/// The reads of one round, in the watch's order.
pub(crate) type Round = Vec<Sample>;

/// The value `w` tests in `round`: the read's value or its bit.
fn tested(w: &Within, round: &[Sample]) -> Option<i64> {
    let v = round.get(w.probe)?.value;
    Some(match w.bit {
        Some(b) => v.checked_shr(b).unwrap_or(0) & 1,
        None => v,
    })
}

/// Whether `w` holds in `round`.
pub(crate) fn holds(w: &Within, round: &[Sample]) -> bool {
    tested(w, round).is_some_and(|v| (w.min..=w.max).contains(&v))
}

/// `min..=max`, or `bit b in min..=max`.
fn show(w: &Within) -> String {
    let range = if w.min == w.max {
        format!("{}", w.min)
    } else {
        format!("{}..={}", w.min, w.max)
    };
    match w.bit {
        Some(b) => format!("bit {b} = {range}"),
        None => range,
    }
}

/// What the envelope allows, in words.
pub(crate) fn allowed(env: &Envelope) -> String {
    match env {
        Envelope::Reaches { within } => format!("the value reaches {}", show(within)),
        Envelope::Bounded { within } => format!("every value within {}", show(within)),
        Envelope::Ends { within } => format!("the last value within {}", show(within)),
        Envelope::Slope { per_s, slack, .. } => {
            format!("a change of at most {per_s} a second (+{slack}) between two reads")
        }
        Envelope::Monotonic { rising, slack, .. } => format!(
            "the value never {} by more than {slack}",
            if *rising { "falls" } else { "rises" }
        ),
        Envelope::Travel {
            steps_per_rev,
            top_rpm,
            ..
        } => format!(
            "the position moves as the speed lets it: {steps_per_rev} steps a revolution, at most {top_rpm} rpm"
        ),
        Envelope::BitFollows { bit, ranges, .. } => {
            format!("bit {bit} = 1 exactly while the value lies in {ranges:?}")
        }
        Envelope::BusyWhileMoving {
            bit, from, to, window, ..
        } => format!(
            "bit {bit} = 1 while the position moves from {from} to {to}; after it drops the position within {to} ± {window}"
        ),
        Envelope::FirstStroke {
            shaft,
            forward,
            min,
            max,
        } => format!(
            "the first stroke turns at {} speed and ends {min}..={max} steps from the start ({} steps a revolution)",
            if *forward { "positive" } else { "negative" },
            shaft.steps_per_rev
        ),
        Envelope::Pause { min_us, .. } => format!(
            "after the first stroke at least {:.1} ms at 0 rpm",
            *min_us as f64 / 1000.0
        ),
        Envelope::Reverses { .. } => {
            "after the first stroke and its pause the shaft turns the other way".to_owned()
        }
    }
}

/// Milliseconds from the watch's start.
fn ms(t: Micros, start: Micros) -> String {
    format!("{:.1} ms", t.saturating_sub(start) as f64 / 1000.0)
}

/// Judges `env` on `rounds`: what the device showed, or why it breaks the envelope.
pub(crate) fn judge(env: &Envelope, rounds: &[Round]) -> Result<String, String> {
    let start = rounds.first().and_then(|r| r.first()).map_or(0, |s| s.sent);
    let values = |probe: usize| -> Vec<Sample> {
        rounds
            .iter()
            .filter_map(|r| r.get(probe).copied())
            .collect()
    };
    match env {
        Envelope::Reaches { within } => match rounds.iter().find(|r| holds(within, r)) {
            Some(r) => Ok(format!(
                "reached {} after {}",
                show(within),
                ms(r.first().map_or(start, |s| s.came), start)
            )),
            None => Err(format!(
                "never reached {} in {} round(s); last value {}",
                show(within),
                rounds.len(),
                rounds
                    .last()
                    .and_then(|r| tested(within, r))
                    .map_or("none".to_owned(), |v| v.to_string())
            )),
        },
        Envelope::Bounded { within } => {
            for r in rounds {
                if !holds(within, r) {
                    let s = r.get(within.probe).copied();
                    return Err(format!(
                        "{} at {}, outside {}",
                        tested(within, r).map_or("no value".to_owned(), |v| v.to_string()),
                        ms(s.map_or(start, |s| s.came), start),
                        show(within)
                    ));
                }
            }
            Ok(format!("{} value(s) within {}", rounds.len(), show(within)))
        }
        Envelope::Ends { within } => match rounds.last() {
            Some(r) if holds(within, r) => Ok(format!(
                "ended at {}",
                tested(within, r).unwrap_or_default()
            )),
            Some(r) => Err(format!(
                "ended at {}, outside {}",
                tested(within, r).map_or("no value".to_owned(), |v| v.to_string()),
                show(within)
            )),
            None => Err("no round was read".to_owned()),
        },
        Envelope::Slope {
            probe,
            per_s,
            slack,
        } => {
            let v = values(*probe);
            let mut steepest = 0.0f64;
            for w in v.windows(2) {
                let [a, b] = w else { continue };
                let dt = b.came.saturating_sub(a.sent);
                let change = (b.value - a.value).abs();
                let limit = (*per_s as f64 * dt as f64 / 1e6) + *slack as f64;
                if change as f64 > limit {
                    return Err(format!(
                        "changed by {change} from {} at {} to {} at {} (at most {limit:.0} allowed in {dt} µs)",
                        a.value,
                        ms(a.sent, start),
                        b.value,
                        ms(b.came, start)
                    ));
                }
                if dt > 0 {
                    steepest = steepest.max(change as f64 * 1e6 / dt as f64);
                }
            }
            Ok(format!("steepest change {steepest:.0} a second"))
        }
        Envelope::Monotonic {
            probe,
            rising,
            slack,
        } => {
            let v = values(*probe);
            let mut extreme: Option<i64> = None;
            for s in &v {
                if let Some(e) = extreme {
                    let back = if *rising { e - s.value } else { s.value - e };
                    if back > *slack {
                        return Err(format!(
                            "went back from {e} to {} at {}",
                            s.value,
                            ms(s.came, start)
                        ));
                    }
                }
                extreme = Some(match (extreme, rising) {
                    (Some(e), true) => e.max(s.value),
                    (Some(e), false) => e.min(s.value),
                    (None, _) => s.value,
                });
            }
            Ok(format!("{} value(s) in one direction", v.len()))
        }
        Envelope::Travel {
            position,
            speed,
            steps_per_rev,
            top_rpm,
            slack,
            slack_steps,
        } => {
            let steps = |rpm: f64, us: Micros| rpm * *steps_per_rev as f64 * us as f64 / 60e6;
            let mut judged = 0usize;
            for w in rounds.windows(2) {
                let [a, b] = w else { continue };
                let (Some(pa), Some(pb), Some(va), Some(vb)) = (
                    a.get(*position),
                    b.get(*position),
                    a.get(*speed),
                    b.get(*speed),
                ) else {
                    continue;
                };
                let moved = (pb.value - pa.value).abs() as f64;
                let outer = steps(*top_rpm as f64, pb.came.saturating_sub(pa.sent));
                let low = va.value.abs().min(vb.value.abs()) as f64;
                // The speed reads lie after the position reads of their rounds.
                let inner = steps(low, pb.sent.saturating_sub(va.came));
                let most = outer * (100 + slack) as f64 / 100.0 + *slack_steps as f64;
                let least = inner * (100 - slack) as f64 / 100.0 - *slack_steps as f64;
                if moved > most || moved < least {
                    return Err(format!(
                        "the position moved {moved:.0} steps from {} at {} to {} at {}, with the speed at {} and {} rpm: {least:.0}..={most:.0} steps expected",
                        pa.value,
                        ms(pa.sent, start),
                        pb.value,
                        ms(pb.came, start),
                        va.value,
                        vb.value
                    ));
                }
                judged += 1;
            }
            Ok(format!(
                "{judged} step(s) of the position consistent with the speed"
            ))
        }
        Envelope::BitFollows {
            flags,
            bit,
            probe,
            ranges,
            lag_us,
        } => bit_follows(rounds, *flags, *bit, *probe, ranges, *lag_us, start),
        Envelope::FirstStroke {
            shaft,
            forward,
            min,
            max,
        } => first_stroke(shaft, *forward, (*min, *max), rounds, start),
        Envelope::Pause { shaft, min_us } => pause(shaft, *min_us, rounds, start),
        Envelope::Reverses { shaft } => reverses(shaft, rounds, start),
        Envelope::BusyWhileMoving {
            flags,
            bit,
            probe,
            from,
            to,
            rpm,
            window,
        } => {
            let travel = |dt: Micros| (*rpm as f64 * 4096.0 * dt as f64 / 60e6).ceil() as i64 + 1;
            let ahead = (to - from).signum();
            let mut dropped = false;
            let mut busy_seen = false;
            for r in rounds {
                let (Some(p), Some(f)) = (r.get(*probe), r.get(*flags)) else {
                    continue;
                };
                let b = f.value.checked_shr(*bit).unwrap_or(0) & 1;
                if dropped && (p.value - to).abs() > *window {
                    return Err(format!(
                        "bit {bit} dropped but the position {} at {} is not within {to} ± {window}",
                        p.value,
                        ms(p.came, start)
                    ));
                }
                let under_way = (p.value - from) * ahead > 0
                    && (to - p.value) * ahead > travel(f.came.saturating_sub(p.sent));
                if under_way && b == 0 {
                    return Err(format!(
                        "bit {bit} = 0 at {} while the position {} was still on its way from {from} to {to}",
                        ms(f.came, start),
                        p.value
                    ));
                }
                busy_seen |= b == 1;
                dropped |= busy_seen && b == 0;
            }
            Ok(format!(
                "bit {bit} {} the motion",
                if busy_seen {
                    "set during"
                } else {
                    "never read during"
                }
            ))
        }
    }
}

/// The rounds that read both the position and the speed of `shaft`: the travel from the
/// first of them (steps, the revolutions counted between rounds) and the speed's sample. Rounds
/// so far apart that the shaft may have turned half a revolution at `top_rpm` cannot be counted.
fn shaft_rounds(
    shaft: &Shaft,
    rounds: &[Round],
    start: Micros,
) -> Result<Vec<(i64, Sample)>, String> {
    let rev = shaft.steps_per_rev.max(2);
    let half = rev / 2;
    let mut seen = Vec::new();
    let mut last: Option<(Sample, i64)> = None;
    for r in rounds {
        let (Some(p), Some(v)) = (r.get(shaft.position), r.get(shaft.speed)) else {
            continue;
        };
        let travel = match last {
            None => 0,
            Some((a, before)) => {
                let dt = p.came.saturating_sub(a.sent);
                let most = shaft.top_rpm.abs() as f64 * rev as f64 * dt as f64 / 60e6;
                if most >= half as f64 {
                    return Err(format!(
                        "the position was read at {} and {}: at up to {} rpm the shaft may turn half a revolution in between, so its revolutions cannot be counted",
                        ms(a.sent, start),
                        ms(p.came, start),
                        shaft.top_rpm
                    ));
                }
                let step = (p.value - a.value).rem_euclid(rev);
                before + if step >= half { step - rev } else { step }
            }
        };
        last = Some((*p, travel));
        seen.push((travel, *v));
    }
    Ok(seen)
}

/// Where the first stroke of a back-and-forth motion lies among the rounds of
/// [`shaft_rounds`].
struct Strokes {
    /// Sign of the first speed read that is not 0.
    dir: i64,
    /// Index of that read.
    from: usize,
    /// Index of the first read after it at 0 rpm or in the other direction.
    end: Option<usize>,
    /// Index of the first read from `end` on that is not 0 rpm.
    resume: Option<usize>,
}

fn strokes(seen: &[(i64, Sample)]) -> Option<Strokes> {
    let from = seen.iter().position(|(_, v)| v.value != 0)?;
    let dir = seen.get(from)?.1.value.signum();
    let end =
        (from + 1..seen.len()).find(|i| seen.get(*i).is_some_and(|(_, v)| v.value.signum() != dir));
    let resume =
        end.and_then(|e| (e..seen.len()).find(|i| seen.get(*i).is_some_and(|(_, v)| v.value != 0)));
    Some(Strokes {
        dir,
        from,
        end,
        resume,
    })
}

/// "positive" or "negative".
fn sense(dir: i64) -> &'static str {
    if dir > 0 {
        "positive"
    } else {
        "negative"
    }
}

/// The shaft's rounds and its first stroke, or why there is none.
fn first_of(
    shaft: &Shaft,
    rounds: &[Round],
    start: Micros,
) -> Result<(Vec<(i64, Sample)>, Strokes), String> {
    let seen = shaft_rounds(shaft, rounds, start)?;
    match strokes(&seen) {
        Some(s) => Ok((seen, s)),
        None => Err(format!(
            "the speed read 0 rpm in all {} round(s): the shaft never turned",
            seen.len()
        )),
    }
}

/// [`Envelope::FirstStroke`].
fn first_stroke(
    shaft: &Shaft,
    forward: bool,
    (min, max): (i64, i64),
    rounds: &[Round],
    start: Micros,
) -> Result<String, String> {
    let (seen, s) = first_of(shaft, rounds, start)?;
    let want = if forward { 1 } else { -1 };
    let first = seen.get(s.from).map_or(0, |(_, v)| v.value);
    let at = seen.get(s.from).map_or(start, |(_, v)| v.came);
    if s.dir != want {
        return Err(format!(
            "the first speed read that is not 0 rpm, {first} rpm at {}, is {}; the first stroke turns at {} speed",
            ms(at, start),
            sense(s.dir),
            sense(want)
        ));
    }
    let upto = s.end.map_or(seen.len(), |e| e + 1);
    let far = seen
        .iter()
        .take(upto)
        .map(|(t, _)| t.abs())
        .max()
        .unwrap_or(0);
    let revs = far as f64 / shaft.steps_per_rev.max(1) as f64;
    match s.end.and_then(|e| seen.get(e)) {
        Some((_, v)) if (min..=max).contains(&far) => Ok(format!(
            "turned at {} speed from {}, {far} steps ({revs:.2} revolutions) up to {}",
            sense(s.dir),
            ms(at, start),
            ms(v.came, start)
        )),
        Some((_, v)) => Err(format!(
            "the first stroke turned {far} steps ({revs:.2} revolutions) up to {}, outside {min}..={max}",
            ms(v.came, start)
        )),
        None if far <= max => Ok(format!(
            "turned at {} speed from {}, {far} steps ({revs:.2} revolutions) by the end of the watch, still turning",
            sense(s.dir),
            ms(at, start)
        )),
        None => Err(format!(
            "the first stroke turned {far} steps ({revs:.2} revolutions) and had not stopped, beyond {max}"
        )),
    }
}

/// [`Envelope::Pause`].
fn pause(shaft: &Shaft, min_us: Micros, rounds: &[Round], start: Micros) -> Result<String, String> {
    let (seen, s) = first_of(shaft, rounds, start)?;
    let speed = |i: usize| seen.get(i).map(|(_, v)| *v);
    let Some((end, last)) = s
        .end
        .and_then(|e| Some((speed(e)?, speed(e.checked_sub(1)?)?)))
    else {
        return Err("the first stroke never ended at 0 rpm".to_owned());
    };
    match s.resume.and_then(speed) {
        None => Ok(format!(
            "at 0 rpm from {} to the end of the watch",
            ms(end.sent, start)
        )),
        Some(next) => {
            let longest = next.came.saturating_sub(last.sent);
            if longest >= min_us {
                Ok(format!(
                    "at 0 rpm from {} to {}",
                    ms(end.sent, start),
                    ms(next.came, start)
                ))
            } else {
                Err(format!(
                    "at 0 rpm for at most {:.1} ms (between the reads of {} rpm at {} and {} rpm at {}), at least {:.1} ms required",
                    longest as f64 / 1000.0,
                    last.value,
                    ms(last.sent, start),
                    next.value,
                    ms(next.came, start),
                    min_us as f64 / 1000.0
                ))
            }
        }
    }
}

/// [`Envelope::Reverses`].
fn reverses(shaft: &Shaft, rounds: &[Round], start: Micros) -> Result<String, String> {
    let (seen, s) = first_of(shaft, rounds, start)?;
    if s.end.is_none() {
        return Err("the first stroke never ended".to_owned());
    }
    match s.resume.and_then(|r| seen.get(r)) {
        None => Err("the shaft did not turn again after its first stroke".to_owned()),
        Some((_, v)) if v.value.signum() == -s.dir => Ok(format!(
            "turned again at {} speed from {}",
            sense(-s.dir),
            ms(v.came, start)
        )),
        Some((_, v)) => Err(format!(
            "turned again at {} rpm at {}, in the first stroke's direction",
            v.value,
            ms(v.came, start)
        )),
    }
}

/// [`Envelope::BitFollows`]: each read of the bit judged where the value's reads around it
/// agree.
fn bit_follows(
    rounds: &[Round],
    flags: usize,
    bit: u32,
    probe: usize,
    ranges: &[(i64, i64)],
    lag_us: Micros,
    start: Micros,
) -> Result<String, String> {
    let inside = |v: i64| ranges.iter().any(|(lo, hi)| (*lo..=*hi).contains(&v));
    let values: Vec<Sample> = rounds
        .iter()
        .filter_map(|r| r.get(probe).copied())
        .collect();
    let (mut judged, mut ones) = (0usize, 0usize);
    for r in rounds {
        let Some(f) = r.get(flags) else { continue };
        let before = values.iter().rev().find(|s| s.came <= f.sent);
        let after = values.iter().find(|s| s.sent >= f.came);
        let (Some(before), Some(after)) = (before, after) else {
            continue;
        };
        let around: Vec<&Sample> = values
            .iter()
            .filter(|s| s.came + lag_us >= f.sent && s.sent <= f.came)
            .chain([before, after])
            .collect();
        let first = inside(before.value);
        if around.iter().any(|s| inside(s.value) != first) {
            continue;
        }
        judged += 1;
        let b = f.value.checked_shr(bit).unwrap_or(0) & 1;
        if (b == 1) != first {
            return Err(format!(
                "bit {bit} = {b} at {} while the value read around it was {} (and {}), {} {ranges:?}",
                ms(f.came, start),
                before.value,
                after.value,
                if first { "inside" } else { "outside" }
            ));
        }
        ones += usize::from(first);
    }
    Ok(format!(
        "{judged} read(s) of bit {bit} judged ({ones} with the value inside)"
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rounds(values: &[(i64, i64)]) -> Vec<Round> {
        values
            .iter()
            .enumerate()
            .map(|(i, (a, b))| {
                let t = 10_000 * i as u64;
                vec![
                    Sample {
                        value: *a,
                        sent: t,
                        came: t + 2_000,
                    },
                    Sample {
                        value: *b,
                        sent: t + 2_000,
                        came: t + 4_000,
                    },
                ]
            })
            .collect()
    }

    #[test]
    fn a_ramp_steeper_than_allowed_fails_and_a_gentle_one_passes() {
        let steep = rounds(&[(0, 0), (100, 0), (200, 0)]);
        let slope = Envelope::Slope {
            probe: 0,
            per_s: 1000,
            slack: 2,
        };
        assert!(judge(&slope, &steep).is_err());
        let gentle = rounds(&[(0, 0), (10, 0), (20, 0)]);
        assert!(judge(&slope, &gentle).is_ok());
    }

    #[test]
    fn a_bit_is_judged_only_where_the_values_around_it_agree() {
        let env = Envelope::BitFollows {
            flags: 1,
            bit: 2,
            probe: 0,
            ranges: vec![(0, 0)],
            lag_us: 0,
        };
        // Standstill with the bit set, then moving with the bit clear: passes.
        let good = rounds(&[(0, 4), (0, 4), (50, 0), (60, 0)]);
        assert!(judge(&env, &good).is_ok());
        // The bit stays set while the speed is well away from 0.
        let bad = rounds(&[(0, 4), (50, 4), (60, 4), (70, 4)]);
        assert!(judge(&env, &bad).is_err());
        // At the change, either value passes.
        let edge = rounds(&[(0, 4), (0, 0), (50, 0), (60, 0)]);
        assert!(judge(&env, &edge).is_ok());
    }

    #[test]
    fn a_busy_bit_low_during_the_motion_fails() {
        let env = Envelope::BusyWhileMoving {
            flags: 1,
            bit: 7,
            probe: 0,
            from: 0,
            to: 40_960,
            rpm: 600,
            window: 100,
        };
        let good = rounds(&[
            (0, 0),
            (1_000, 128),
            (20_000, 128),
            (40_960, 0),
            (40_960, 0),
        ]);
        assert!(judge(&env, &good).is_ok());
        let bad = rounds(&[(0, 0), (1_000, 0), (20_000, 0), (40_960, 0)]);
        assert!(judge(&env, &bad).is_err());
        let early = rounds(&[(0, 0), (1_000, 128), (20_000, 0), (30_000, 0)]);
        assert!(judge(&env, &early).is_err());
    }

    /// Rounds of (Pr28, Pr0) 10 ms apart from `legs` of (steps a round, rpm, rounds).
    fn shaft_legs(legs: &[(i64, i64, usize)]) -> Vec<Round> {
        let mut at = 1_000;
        let mut values = Vec::new();
        for (step, rpm, n) in legs {
            for _ in 0..*n {
                at += step;
                values.push((at.rem_euclid(4096), *rpm));
            }
        }
        rounds(&values)
    }

    const SHAFT: Shaft = Shaft {
        position: 0,
        speed: 1,
        steps_per_rev: 4096,
        top_rpm: 200,
    };

    #[test]
    fn a_test_profile_is_judged_by_its_strokes_counted_through_the_revolutions() {
        // 82 rounds of 100 steps (8200 steps, two revolutions), 60 rounds (600 ms) at rest,
        // then back.
        let good = shaft_legs(&[(0, 0, 3), (100, 146, 82), (0, 0, 60), (-100, -146, 20)]);
        let stroke = |forward| Envelope::FirstStroke {
            shaft: SHAFT,
            forward,
            min: 8192 - 1024,
            max: 8192 + 1024,
        };
        let pause = Envelope::Pause {
            shaft: SHAFT,
            min_us: 500_000,
        };
        let back = Envelope::Reverses { shaft: SHAFT };
        assert!(judge(&stroke(true), &good).is_ok());
        assert!(judge(&pause, &good).is_ok());
        assert!(judge(&back, &good).is_ok());
        // The wrong direction, one revolution only, or still turning beyond the stroke.
        assert!(judge(&stroke(false), &good).is_err());
        let short = shaft_legs(&[(100, 146, 41), (0, 0, 60), (-100, -146, 20)]);
        assert!(judge(&stroke(true), &short).is_err());
        let over = shaft_legs(&[(100, 146, 120)]);
        assert!(judge(&stroke(true), &over).is_err());
        let under_way = shaft_legs(&[(100, 146, 50)]);
        assert!(judge(&stroke(true), &under_way).is_ok());
        // Straight back without the pause, or on again in the first direction.
        let no_pause = shaft_legs(&[(100, 146, 82), (0, 0, 2), (-100, -146, 20)]);
        assert!(judge(&stroke(true), &no_pause).is_ok());
        assert!(judge(&pause, &no_pause).is_err());
        let again = shaft_legs(&[(100, 146, 82), (0, 0, 60), (100, 146, 20)]);
        assert!(judge(&back, &again).is_err());
        let never = shaft_legs(&[(100, 146, 82), (0, 0, 60)]);
        assert!(judge(&pause, &never).is_ok());
        assert!(judge(&back, &never).is_err());
    }

    #[test]
    fn revolutions_between_reads_too_far_apart_are_not_counted() {
        let fast = Shaft {
            top_rpm: 3_000,
            ..SHAFT
        };
        let r = shaft_legs(&[(100, 146, 82), (0, 0, 60), (-100, -146, 20)]);
        let why = judge(
            &Envelope::FirstStroke {
                shaft: fast,
                forward: true,
                min: 0,
                max: 10_000,
            },
            &r,
        )
        .unwrap_err();
        assert!(why.contains("cannot be counted"), "{why}");
    }

    #[test]
    fn direction_and_ranges() {
        let r = rounds(&[(0, 0), (5, 0), (3, 0), (9, 0)]);
        let up = Envelope::Monotonic {
            probe: 0,
            rising: true,
            slack: 1,
        };
        assert!(judge(&up, &r).is_err());
        let w = Within {
            probe: 0,
            bit: None,
            min: 8,
            max: 10,
        };
        assert!(judge(&Envelope::Reaches { within: w }, &r).is_ok());
        assert!(judge(&Envelope::Ends { within: w }, &r).is_ok());
        assert!(judge(&Envelope::Bounded { within: w }, &r).is_err());
    }
}
