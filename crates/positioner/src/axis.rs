//! Position arithmetic of the positioning core (PSD4xx manual 4.7, 4.8 and 3.3 par. 37–45;
//! PSx3xx manual 5.5–5.7): scaling, the referencing value, the upper mapping end with the
//! permissible range it implies, the end limits, the positioning window and loop length, and
//! the recalculation cascades when direction, scaling, referencing value or mapping end change.
//!
//! Every value a user sees is an integer in *user increments* (the scaled unit, shifted by the
//! referencing value). The physical truth is the shaft position in rotations ([`f64`],
//! counted toward larger values), kept by the caller; [`Axis::actual`] maps it to user
//! increments. Lengths the manuals give in rotations (margins, delivery values) are stored at
//! the standard scaling (base increments per rotation) and scaled by denominator / numerator
//! (PSD-MAP-024, PSD-MAP-028; erratum PSD-ERRATUM-007).
//!
//! Nothing here panics: arithmetic is done in `i128` and saturated to `i64`.

use serde::{Deserialize, Serialize};

/// How a value scaled by denominator / numerator is rounded (PSD4xx 4.8; PSx3xx 5.6.4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Rounding {
    /// Toward zero (the PSD4xx spec's `scale`).
    TowardZero,
    /// To the nearest integer, halves away from zero (PSx3xx 5.6.4).
    Nearest,
}

/// Which ratio scales the permissible range of the upper limit (erratum PSD-ERRATUM-007).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LimitRatio {
    /// Denominator / numerator, like every other length (adopted reading) (4.8).
    DenOverNum,
    /// Numerator / denominator for the upper limit, as printed in PSD4xx 3.3 par. 42.
    NumOverDen,
}

/// What a change of the upper mapping end does to the limits (PSD4xx 4.7 note 4,
/// erratum PSD-ERRATUM-057).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LimitsAfterMappingEnd {
    /// Limits become the full new range: end − lower offset … end − upper margin (4.7).
    FullNewRange,
    /// Limits take the delivery values regardless of the new end (4.7).
    Delivery,
}

/// Delivery values at the standard scaling, in base increments (PSD4xx 3.3, 3.4; PSx3xx 5.6.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Delivery {
    /// Upper mapping end (PSD par. 41).
    pub mapping_end: i64,
    /// Upper limit (PSD par. 42).
    pub upper_limit: i64,
    /// Lower limit (PSD par. 43).
    pub lower_limit: i64,
    /// Referencing value (PSD par. 40).
    pub reference: i64,
    /// Positioning window (PSD par. 44).
    pub window: i64,
    /// Length of loop (PSD par. 45).
    pub loop_length: i64,
    /// Numerator (PSD par. 38).
    pub numerator: i64,
    /// Denominator (PSD par. 39).
    pub denominator: i64,
    /// Direction of rotation (PSD par. 37).
    pub direction: i64,
}

/// The family's numbers for position arithmetic (PSD4xx 4.7, 4.8; PSx3xx 5.5–5.7).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AxisConfig {
    /// Increments per rotation at numerator = denominator (400) (4.8).
    pub base_increments: i64,
    /// Highest position = mapping end − this many base increments (3 rotations = 1,200) (4.7).
    pub upper_margin: i64,
    /// Lowest position = mapping end − this many base increments (PSD 1,611,600 or per model; 4.7).
    pub lower_offset: i64,
    /// Smallest and largest numerator and denominator (1 … 10,000) (4.8).
    pub factor_range: [i64; 2],
    /// Rounding of scaled values (4.8).
    pub rounding: Rounding,
    /// Delivery values at the standard scaling (4.8).
    pub delivery: Delivery,
    /// Positioning window range at the standard scaling (PSD par. 44: 1 … 100).
    pub window_range: [i64; 2],
    /// Whether the window range scales with the resolution (erratum PSD-ERRATUM-024).
    pub scale_window_range: bool,
    /// Loop length intervals at the standard scaling (PSD par. 45: −4000 … −10, 0, 10 … 4000).
    pub loop_range: Vec<[i64; 2]>,
    /// Whether the loop range scales with the resolution (erratum PSD-ERRATUM-024).
    pub scale_loop_range: bool,
    /// Ratio of the upper limit's permissible range (erratum PSD-ERRATUM-007).
    pub upper_limit_ratio: LimitRatio,
    /// Limits after a change of the mapping end (erratum PSD-ERRATUM-057).
    pub limits_after_mapping_end: LimitsAfterMappingEnd,
}

/// A write the arithmetic refuses (PSD4xx 3.3 ranges; PKW error 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum AxisError {
    /// The value lies outside the permissible range, which depends on the state (4.7).
    #[error("value {value} outside the permissible range {min}..={max}")]
    OutOfRange {
        /// Value written.
        value: i64,
        /// Smallest permissible value.
        min: i64,
        /// Largest permissible value.
        max: i64,
    },
    /// The value lies in none of the permissible intervals (PSD par. 45).
    #[error("value {value} outside the permissible intervals")]
    NotInIntervals {
        /// Value written.
        value: i64,
    },
}

/// The position settings in user increments (PSD4xx par. 37–45, 3.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct AxisValues {
    /// Direction of rotation (PSD par. 37): 0 or 1.
    pub direction: i64,
    /// Position scaling numerator (PSD par. 38).
    pub numerator: i64,
    /// Position scaling denominator (PSD par. 39).
    pub denominator: i64,
    /// Referencing value (PSD par. 40).
    pub reference: i64,
    /// Upper mapping end (PSD par. 41).
    pub mapping_end: i64,
    /// Upper limit (PSD par. 42).
    pub upper_limit: i64,
    /// Lower limit (PSD par. 43).
    pub lower_limit: i64,
    /// Positioning window (PSD par. 44).
    pub window: i64,
    /// Length of loop (PSD par. 45); the sign is the loop direction, 0 = no loop.
    pub loop_length: i64,
}

fn sat(v: i128) -> i64 {
    i64::try_from(v).unwrap_or(if v < 0 { i64::MIN } else { i64::MAX })
}

fn div_round(n: i128, d: i128, rounding: Rounding) -> i128 {
    if d == 0 {
        return 0;
    }
    match rounding {
        Rounding::TowardZero => n / d,
        Rounding::Nearest => {
            let q = n / d;
            let r = n % d;
            if 2 * r.abs() >= d.abs() {
                if (n < 0) != (d < 0) {
                    q - 1
                } else {
                    q + 1
                }
            } else {
                q
            }
        }
    }
}

/// The position settings and the transferred target with their cascades (PSD4xx 4.7, 4.8).
#[derive(Debug, Clone, PartialEq)]
pub struct Axis {
    config: std::sync::Arc<AxisConfig>,
    values: AxisValues,
    target: Option<i64>,
}

impl Axis {
    /// An axis in the delivery state at the standard scaling (PSD4xx 3.3, 3.4).
    pub fn new(config: std::sync::Arc<AxisConfig>) -> Axis {
        let d = config.delivery;
        Axis {
            values: AxisValues {
                direction: d.direction,
                numerator: d.numerator,
                denominator: d.denominator,
                reference: d.reference,
                mapping_end: d.mapping_end,
                upper_limit: d.upper_limit,
                lower_limit: d.lower_limit,
                window: d.window,
                loop_length: d.loop_length,
            },
            config,
            target: None,
        }
    }

    /// The family's numbers (PSD4xx 4.7).
    pub fn config(&self) -> &AxisConfig {
        &self.config
    }

    /// The settings in force (PSD4xx par. 37–45).
    pub fn values(&self) -> AxisValues {
        self.values
    }

    /// Replaces all settings at once, without cascades: loading a parameter image from EEPROM
    /// or the delivery table (PSD4xx par. 96). Factors outside their range are clamped.
    pub fn load(&mut self, mut v: AxisValues) {
        let [lo, hi] = self.config.factor_range;
        v.numerator = v.numerator.clamp(lo.max(1), hi.max(1));
        v.denominator = v.denominator.clamp(lo.max(1), hi.max(1));
        self.values = v;
    }

    /// The valid (last correctly transferred) target, None before the first transfer (PSD4xx 3.7 bit 2).
    pub fn target(&self) -> Option<i64> {
        self.target
    }

    /// Sets the valid target (PSD4xx 3.7 bit 2, PSD-CTL-2-001).
    pub fn set_target(&mut self, target: Option<i64>) {
        self.target = target;
    }

    /// Increments per rotation = base × denominator / numerator (PSD-MAP-024, 4.8).
    pub fn increments_per_rotation(&self) -> f64 {
        increments_per_rotation(
            self.config.base_increments,
            self.values.numerator,
            self.values.denominator,
        )
    }

    /// A length in base increments expressed at the current scaling (PSD-MAP-028, erratum
    /// PSD-ERRATUM-007: × denominator / numerator).
    pub fn scale(&self, base: i64) -> i64 {
        scale(
            base,
            self.values.numerator,
            self.values.denominator,
            self.config.rounding,
        )
    }

    /// The upper margin at the current scaling (3 rotations; PSD-MAP-008).
    pub fn upper_margin(&self) -> i64 {
        self.scale(self.config.upper_margin)
    }

    /// The lower offset at the current scaling (4,029 rotations on ungeared PSD4xx; PSD-MAP-009).
    pub fn lower_offset(&self) -> i64 {
        self.scale(self.config.lower_offset)
    }

    /// Lowest and highest reachable position for the mapping end in force (PSD-MAP-008,
    /// PSD-MAP-009): end − lower offset … end − upper margin.
    pub fn position_range(&self) -> (i64, i64) {
        let end = i128::from(self.values.mapping_end);
        (
            sat(end - i128::from(self.lower_offset())),
            sat(end - i128::from(self.upper_margin())),
        )
    }

    /// Permissible mapping ends for an actual position (PSD-MAP-007): actual + upper margin …
    /// actual + lower offset.
    pub fn mapping_end_window(&self, actual: i64) -> (i64, i64) {
        let a = i128::from(actual);
        (
            sat(a + i128::from(self.upper_margin())),
            sat(a + i128::from(self.lower_offset())),
        )
    }

    /// Permissible values of the upper limit (PSD-MAP-028; erratum PSD-ERRATUM-007).
    pub fn upper_limit_window(&self) -> (i64, i64) {
        match self.config.upper_limit_ratio {
            LimitRatio::DenOverNum => self.position_range(),
            LimitRatio::NumOverDen => {
                let s = |b: i64| {
                    scale(
                        b,
                        self.values.denominator,
                        self.values.numerator,
                        self.config.rounding,
                    )
                };
                let end = i128::from(self.values.mapping_end);
                (
                    sat(end - i128::from(s(self.config.lower_offset))),
                    sat(end - i128::from(s(self.config.upper_margin))),
                )
            }
        }
    }

    /// Permissible values of the lower limit (PSD-MAP-028).
    pub fn lower_limit_window(&self) -> (i64, i64) {
        self.position_range()
    }

    /// The positioning window's permissible range at the current scaling (PSD-PAR-44-003).
    pub fn window_range(&self) -> (i64, i64) {
        let [lo, hi] = self.config.window_range;
        if self.config.scale_window_range {
            (self.scale(lo).max(1), self.scale(hi).max(1))
        } else {
            (lo, hi)
        }
    }

    /// The loop length's permissible intervals at the current scaling (PSD-PAR-45-003).
    pub fn loop_intervals(&self) -> Vec<[i64; 2]> {
        self.config
            .loop_range
            .iter()
            .map(|&[lo, hi]| {
                if self.config.scale_loop_range && !(lo == 0 && hi == 0) {
                    let keep = |v: i64| {
                        let s = self.scale(v);
                        if s == 0 {
                            v.signum()
                        } else {
                            s
                        }
                    };
                    [keep(lo), keep(hi)]
                } else {
                    [lo, hi]
                }
            })
            .collect()
    }

    /// User increments of a shaft position in rotations: round(rot × increments per rotation)
    /// + referencing value (PSD-MAP-019, PSD-MAP-024).
    pub fn actual(&self, rot: f64) -> i64 {
        let raw = (rot * self.increments_per_rotation()).round();
        let raw = if raw.is_finite() { raw as i64 } else { 0 };
        raw.saturating_add(self.values.reference)
    }

    /// The shaft position in rotations of a user position (inverse of [`Axis::actual`]) (4.7).
    pub fn to_rot(&self, user: i64) -> f64 {
        let ipr = self.increments_per_rotation();
        if ipr == 0.0 {
            return 0.0;
        }
        (user as f64 - self.values.reference as f64) / ipr
    }

    /// A user-increment length in rotations (PSD-MAP-024).
    pub fn length_to_rot(&self, increments: i64) -> f64 {
        let ipr = self.increments_per_rotation();
        if ipr == 0.0 {
            return 0.0;
        }
        increments as f64 / ipr
    }

    fn delivery_scaled(&self) -> (i64, i64, i64) {
        let d = self.config.delivery;
        (
            self.scale(d.mapping_end),
            self.scale(d.upper_limit),
            self.scale(d.lower_limit),
        )
    }

    /// Writes the direction of rotation (PSD par. 37). PSD-MAP-012: referencing value, mapping
    /// end and both limits return to the delivery state (scaled to the current resolution).
    /// The shaft position counts the other way: returns the new position in rotations, wrapped
    /// into the new measuring range when it falls outside.
    pub fn set_direction(&mut self, direction: i64, rot: f64) -> Result<f64, AxisError> {
        if !(0..=1).contains(&direction) {
            return Err(AxisError::OutOfRange {
                value: direction,
                min: 0,
                max: 1,
            });
        }
        if direction == self.values.direction {
            return Ok(rot);
        }
        self.values.direction = direction;
        // PSD-MAP-012: reference, mapping end and limits to the delivery state.
        let (end, upper, lower) = self.delivery_scaled();
        self.values.reference = self.config.delivery.reference;
        self.values.mapping_end = end;
        self.values.upper_limit = upper;
        self.values.lower_limit = lower;
        let mut flipped = -rot;
        let span = self.length_to_rot(self.lower_offset().saturating_sub(self.upper_margin()));
        let (lo, hi) = self.position_range();
        let (lo, hi) = (self.to_rot(lo), self.to_rot(hi));
        if span > 0.0 {
            while flipped > hi {
                flipped -= span;
            }
            while flipped < lo {
                flipped += span;
            }
        }
        Ok(flipped)
    }

    /// Writes numerator and denominator together (PSD par. 38/39). PSD-MAP-014: target,
    /// reference, mapping end, limits, window and loop length are recalculated to keep their
    /// physical meaning (the actual value follows from the shaft position).
    pub fn set_scaling(&mut self, numerator: i64, denominator: i64) -> Result<(), AxisError> {
        let [lo, hi] = self.config.factor_range;
        for v in [numerator, denominator] {
            if !(lo..=hi).contains(&v) || v == 0 {
                return Err(AxisError::OutOfRange {
                    value: v,
                    min: lo,
                    max: hi,
                });
            }
        }
        let (n0, d0) = (self.values.numerator, self.values.denominator);
        let r = self.config.rounding;
        let f = |v: i64| rescale(v, n0, d0, numerator, denominator, r);
        let v = &mut self.values;
        v.reference = f(v.reference);
        v.mapping_end = f(v.mapping_end);
        v.upper_limit = f(v.upper_limit);
        v.lower_limit = f(v.lower_limit);
        v.window = f(v.window).max(1);
        v.loop_length = f(v.loop_length);
        v.numerator = numerator;
        v.denominator = denominator;
        self.target = self.target.map(f);
        Ok(())
    }

    /// Writes the referencing value (PSD par. 40). PSD-MAP-015: target, mapping end and limits
    /// shift with it (the actual value shifts by itself).
    pub fn set_reference(&mut self, reference: i64) {
        let delta = i128::from(reference) - i128::from(self.values.reference);
        let shift = |v: i64| sat(i128::from(v) + delta);
        let v = &mut self.values;
        v.mapping_end = shift(v.mapping_end);
        v.upper_limit = shift(v.upper_limit);
        v.lower_limit = shift(v.lower_limit);
        v.reference = reference;
        self.target = self.target.map(shift);
    }

    /// Writes the actual value (PSD par. 3): the referencing value becomes the difference to
    /// the physical position (PSD-MAP-021, PSD-MAP-022), with the cascade of
    /// [`Axis::set_reference`].
    pub fn set_actual(&mut self, value: i64, rot: f64) {
        let physical = i128::from(self.actual(rot)) - i128::from(self.values.reference);
        self.set_reference(sat(i128::from(value) - physical));
    }

    /// Writes the upper mapping end (PSD par. 41), permitted between actual + upper margin and
    /// actual + lower offset (PSD-MAP-007). PSD-MAP-013: the limits follow (erratum
    /// PSD-ERRATUM-057).
    pub fn set_mapping_end(&mut self, end: i64, actual: i64) -> Result<(), AxisError> {
        let (min, max) = self.mapping_end_window(actual);
        if !(min..=max).contains(&end) {
            return Err(AxisError::OutOfRange {
                value: end,
                min,
                max,
            });
        }
        self.values.mapping_end = end;
        match self.config.limits_after_mapping_end {
            LimitsAfterMappingEnd::FullNewRange => {
                let (lo, hi) = self.position_range();
                self.values.lower_limit = lo;
                self.values.upper_limit = hi;
            }
            LimitsAfterMappingEnd::Delivery => {
                let (_, upper, lower) = self.delivery_scaled();
                self.values.upper_limit = upper;
                self.values.lower_limit = lower;
            }
        }
        Ok(())
    }

    /// Writes the upper limit (PSD par. 42) within its permissible range (PSD-MAP-028).
    pub fn set_upper_limit(&mut self, v: i64) -> Result<(), AxisError> {
        let (min, max) = self.upper_limit_window();
        if !(min..=max).contains(&v) {
            return Err(AxisError::OutOfRange { value: v, min, max });
        }
        self.values.upper_limit = v;
        Ok(())
    }

    /// Writes the lower limit (PSD par. 43) within its permissible range (PSD-MAP-028).
    pub fn set_lower_limit(&mut self, v: i64) -> Result<(), AxisError> {
        let (min, max) = self.lower_limit_window();
        if !(min..=max).contains(&v) {
            return Err(AxisError::OutOfRange { value: v, min, max });
        }
        self.values.lower_limit = v;
        Ok(())
    }

    /// Writes the positioning window (PSD par. 44) within its scaled range (PSD-PAR-44-003).
    pub fn set_window(&mut self, v: i64) -> Result<(), AxisError> {
        let (min, max) = self.window_range();
        if !(min..=max).contains(&v) {
            return Err(AxisError::OutOfRange { value: v, min, max });
        }
        self.values.window = v;
        Ok(())
    }

    /// Writes the length of loop (PSD par. 45) within its scaled intervals (PSD-PAR-45-003).
    pub fn set_loop_length(&mut self, v: i64) -> Result<(), AxisError> {
        if !self
            .loop_intervals()
            .iter()
            .any(|[lo, hi]| (*lo..=*hi).contains(&v))
        {
            return Err(AxisError::NotInIntervals { value: v });
        }
        self.values.loop_length = v;
        Ok(())
    }
}

/// Increments per rotation = base × denominator / numerator (PSD-MAP-024, 4.8).
pub fn increments_per_rotation(base: i64, numerator: i64, denominator: i64) -> f64 {
    if numerator == 0 {
        return 0.0;
    }
    base as f64 * denominator as f64 / numerator as f64
}

/// A base-increment length at a scaling: value × denominator / numerator (PSD-MAP-028).
pub fn scale(value: i64, numerator: i64, denominator: i64, rounding: Rounding) -> i64 {
    sat(div_round(
        i128::from(value) * i128::from(denominator),
        i128::from(numerator),
        rounding,
    ))
}

/// A user value at scaling (n0, d0) expressed at scaling (n1, d1) (PSD-MAP-014).
pub fn rescale(value: i64, n0: i64, d0: i64, n1: i64, d1: i64, rounding: Rounding) -> i64 {
    sat(div_round(
        i128::from(value) * i128::from(d1) * i128::from(n0),
        i128::from(n1) * i128::from(d0),
        rounding,
    ))
}

/// Numerator and denominator for a spindle pitch and resolution (PSD4xx 4.8 table): numerator
/// = base, denominator = pitch / resolution; None when the resolution does not divide the pitch.
pub fn spindle_factors(base: i64, pitch_um: i64, resolution_um: i64) -> Option<(i64, i64)> {
    if resolution_um <= 0 || pitch_um <= 0 || pitch_um % resolution_um != 0 {
        return None;
    }
    Some((base, pitch_um / resolution_um))
}
