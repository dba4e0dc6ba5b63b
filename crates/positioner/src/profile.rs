//! The trapezoidal motion profile, one fixed time step at a time (PSD4xx manual 4.3; PSx3xx
//! 5.1): acceleration and deceleration limits, a maximum speed, and the "harmonious" end of a
//! run where the deceleration is reduced step by step as the target nears (PSD-VEL-005).
//!
//! Units: positions in rotations, speeds in rotations per second, rates in rotations per
//! second². The approach curve brakes at the full deceleration `d` down to a blend distance
//! `s0` and then with a deceleration falling linearly to zero: v(s) = √(2·d·s − d·s0) above
//! `s0`, v(s) = s·√(d/s0) below it (a(s) = d·s/s0 ≤ d). A creep speed of `d·dt` lets the drive
//! arrive in finite time and stop within one step. Every step changes the speed by at most
//! `accel·dt` when speeding up and `decel·dt` when slowing down (PSD-VEL-003, PSD-VEL-004).
//!
//! Pure functions of their inputs; nothing here panics or allocates.

/// Position and speed of the shaft in rotations and rotations per second (4.3).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Kinematics {
    /// Position in rotations (4.3).
    pub pos: f64,
    /// Speed in rotations per second (4.3).
    pub vel: f64,
}

/// Speed and ramp limits of one run (PSD4xx 4.3: par. 53/56, 58, 59).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ramps {
    /// Maximum speed, rotations per second (4.3).
    pub vmax: f64,
    /// Acceleration, rotations per second² (4.3).
    pub accel: f64,
    /// Deceleration, rotations per second² (4.3).
    pub decel: f64,
    /// Blend distance as a fraction of the braking distance from `vmax` (the harmonious end) (4.3).
    pub blend: f64,
}

/// The result of one step (PSD4xx 4.3).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Step {
    /// Position and speed after the step (4.3).
    pub kin: Kinematics,
    /// The goal was reached and the drive stopped on it in this step (4.3).
    pub arrived: bool,
}

/// Rotations per second of a speed in rpm (4.3).
pub fn rps(rpm: f64) -> f64 {
    rpm / 60.0
}

/// rpm of a speed in rotations per second (4.3).
pub fn rpm(rps: f64) -> f64 {
    rps * 60.0
}

/// The highest speed from which the drive can still stop on a goal `s` rotations ahead along
/// the harmonious curve (PSD-VEL-005).
pub fn approach_speed(s: f64, r: &Ramps) -> f64 {
    if s <= 0.0 || r.decel <= 0.0 {
        return 0.0;
    }
    let s0 = if r.decel > 0.0 {
        (r.blend * r.vmax * r.vmax / (2.0 * r.decel)).max(0.0)
    } else {
        0.0
    };
    if s0 <= 0.0 || s >= s0 {
        (2.0 * r.decel * s - r.decel * s0).max(0.0).sqrt()
    } else {
        s * (r.decel / s0).sqrt()
    }
}

fn toward(v: f64, target: f64, max_step: f64) -> f64 {
    if (target - v).abs() <= max_step {
        target
    } else if target > v {
        v + max_step
    } else {
        v - max_step
    }
}

/// One step of `dt` seconds toward `goal` (PSD4xx 4.1, 4.3): accelerate to at most `vmax`,
/// brake along the harmonious curve, stop on the goal. A drive moving away from the goal (a
/// reversal, 4.2.1 case 2) first brakes with the deceleration.
pub fn approach(k: Kinematics, goal: f64, r: &Ramps, dt: f64) -> Step {
    let creep = r.decel * dt;
    let s = goal - k.pos;
    if s.abs() <= f64::EPSILON * goal.abs().max(1.0) && k.vel.abs() <= creep * (1.0 + 1e-9) {
        return Step {
            kin: Kinematics {
                pos: goal,
                vel: 0.0,
            },
            arrived: true,
        };
    }
    let dir = if s > 0.0 {
        1.0
    } else if s < 0.0 {
        -1.0
    } else {
        0.0
    };
    let v = k.vel;
    let ahead = ((s - v * dt) * dir).max(0.0);
    let curve = approach_speed(ahead, r);
    let want = r.vmax.min(curve.max(creep)) * dir;
    let new_v = if v * want < 0.0 || (dir == 0.0 && v != 0.0) {
        // Moving away from the goal (or past it): brake to a stop first.
        toward(v, 0.0, r.decel * dt)
    } else if want.abs() >= v.abs() {
        toward(v, want, r.accel * dt)
    } else if curve < r.vmax {
        // Braking for the end of the run (4.3 notice: par. 59).
        toward(v, want, r.decel * dt)
    } else {
        // A lower maximum speed during the movement (4.3 notice: par. 58).
        toward(v, want, r.accel * dt)
    };
    let pos = k.pos + (v + new_v) / 2.0 * dt;
    let left = (goal - pos) * dir;
    if dir != 0.0 && left <= 0.0 && new_v.abs() <= creep * (1.0 + 1e-9) {
        // On the goal at creep speed: a stop within one step's deceleration ends the run;
        // from faster, the drive holds the goal for one step at the slower speed first, so
        // that neither the position nor the deceleration overshoots (PSD-VEL-002).
        let stops = v.abs() <= creep * (1.0 + 1e-9);
        return Step {
            kin: Kinematics {
                pos: goal,
                vel: if stops { 0.0 } else { new_v },
            },
            arrived: stops,
        };
    }
    Step {
        kin: Kinematics { pos, vel: new_v },
        arrived: false,
    }
}

/// One step of braking to a stop with `rate` (rotations per second²) (PSD4xx 4.3 stop).
pub fn brake(k: Kinematics, rate: f64, dt: f64) -> Step {
    let new_v = toward(k.vel, 0.0, rate * dt);
    Step {
        kin: Kinematics {
            pos: k.pos + (k.vel + new_v) / 2.0 * dt,
            vel: new_v,
        },
        arrived: new_v == 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramps() -> Ramps {
        Ramps {
            vmax: rps(200.0),
            accel: rps(1000.0),
            decel: rps(2000.0),
            blend: 0.5,
        }
    }

    #[test]
    fn reaches_goal_within_limits() {
        let r = ramps();
        let dt = 0.001;
        let mut k = Kinematics::default();
        let mut steps = 0;
        loop {
            let s = approach(k, 10.0, &r, dt);
            let dv = (s.kin.vel - k.vel).abs();
            assert!(dv <= r.accel.max(r.decel) * dt * (1.0 + 1e-9));
            assert!(s.kin.vel <= r.vmax * (1.0 + 1e-12));
            k = s.kin;
            steps += 1;
            if s.arrived {
                break;
            }
            assert!(steps < 100_000);
        }
        assert_eq!(k.pos, 10.0);
        // 10 rotations at 200 rpm take about 3 s plus the ramps.
        assert!((3000..4000).contains(&steps), "{steps}");
    }

    #[test]
    fn reverses_when_goal_is_behind() {
        let r = ramps();
        let mut k = Kinematics {
            pos: 0.0,
            vel: r.vmax,
        };
        let mut min_v: f64 = 0.0;
        for _ in 0..10_000 {
            let s = approach(k, -1.0, &r, 0.001);
            min_v = min_v.min(s.kin.vel);
            k = s.kin;
            if s.arrived {
                break;
            }
        }
        assert_eq!(k.pos, -1.0);
        assert!(min_v < 0.0);
    }
}
