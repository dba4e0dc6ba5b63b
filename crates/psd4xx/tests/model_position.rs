//! Every `position` vector of `spec/psd4xx/vectors/position.toml` (manual 4.7, 4.8, 3.4) comes
//! out exactly on the reference model: the drive is placed at the vector's position, its
//! parameters are written through the model's own parameter path (par. 38, 39, 40, 41, 3) and
//! the expected numbers are read back or computed by the model's position arithmetic. The
//! increments-per-rotation `formula` vectors are checked the same way.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_positioner::axis::spindle_factors;
use drivespec_psd4xx::model::DriveConfig;
use drivespec_spec::{IntOrText, Number, Vector, VectorKind, VectorResult};
use model_util::*;

const DEFAULT_MODEL: &str = "PSD401-5V";

/// Computes every expected key of a position vector; returns (key, expected, computed).
fn evaluate(v: &Vector) -> Vec<(String, f64, f64)> {
    let input = &v.position().unwrap().input;
    let model = v.model.as_deref().unwrap_or(DEFAULT_MODEL);
    let pos = input.position.or(input.actual).unwrap_or(0);
    let mut s = Sim::with(DriveConfig::new(model).with_start_position(pos));
    // 4.8 table: the factors of a spindle pitch and resolution.
    let spindle = match (input.pitch_um, input.resolution_um) {
        (Some(p), Some(r)) => spindle_factors(400, p, r),
        _ => None,
    };
    let num = input.numerator.or(spindle.map(|f| f.0));
    let den = input.denominator.or(spindle.map(|f| f.1));
    if let (Some(n), Some(d)) = (num, den) {
        // 4.7 note 7: scaling first. PSD-MAP-014 recalculates the delivery values.
        s.write(38, n);
        s.write(39, d);
    }
    if let Some(r) = input.reference.filter(|r| *r != 0) {
        s.write(40, r);
    }
    let mut accepted = true;
    if let Some(IntOrText::Text(dir)) = &input.direction {
        // PSD-MAP-007: the window of par. 41 around the actual position.
        let (lo, hi) = s.drive.core().axis().mapping_end_window(s.actual());
        s.write(41, if dir == "up" { hi } else { lo });
    } else if let Some(end) = input.mapping_end {
        if end != s.par(41) {
            accepted = s.try_write(41, end).is_ok();
        }
    }
    if let Some(w) = input.write_actual {
        s.write(3, w);
    }
    let axis = s.drive.core().axis().clone();
    let ipr = axis.increments_per_rotation();
    let actual = s.actual() as f64;
    let (lo, hi) = axis.position_range();
    let (end_min, end_max) = axis.mapping_end_window(s.actual());
    let mut out = Vec::new();
    let (_, expect) = v.body.tables();
    for (key, value) in &expect {
        let want = value
            .as_integer()
            .map(|i| i as f64)
            .or_else(|| value.as_float())
            .or_else(|| value.as_bool().map(|b| f64::from(u8::from(b))))
            .unwrap();
        let got = match key.as_str() {
            "upper_position" => hi as f64,
            "lower_position" => lo as f64,
            "range_rotations" => hi as f64 / ipr,
            "mapping_end_rotations" => s.par(41) as f64 / ipr,
            "travel_up" => hi as f64 - actual,
            "travel_down" => actual - lo as f64,
            "travel_up_rotations" => (hi as f64 - actual) / ipr,
            "travel_down_rotations" => (actual - lo as f64) / ipr,
            "mapping_end" | "delivery_mapping_end" => s.par(41) as f64,
            "mapping_end_rotations_above_actual" => (s.par(41) as f64 - actual) / ipr,
            "mapping_end_min" => end_min as f64,
            "mapping_end_max" => end_max as f64,
            "accepted" => f64::from(u8::from(accepted)),
            "upper_limit" => s.par(42) as f64,
            "lower_limit" => s.par(43) as f64,
            "increments_per_rotation" => ipr,
            "upper_margin" => axis.upper_margin() as f64,
            "lower_offset" => axis.lower_offset() as f64,
            "reference" => s.par(40) as f64,
            "actual" => s.par(3) as f64,
            "numerator" => s.par(38) as f64,
            "denominator" => s.par(39) as f64,
            other => panic!("{}: unknown expect key {other}", v.id),
        };
        out.push((key.clone(), want, got));
    }
    out
}

#[test]
fn every_position_vector_comes_out_exactly() {
    let list: Vec<&Vector> = family()
        .vectors
        .iter()
        .filter(|v| v.kind == VectorKind::Position)
        .collect();
    assert!(list.len() >= 20, "{} position vectors", list.len());
    for v in list {
        let results = evaluate(v);
        let holds = |(_, want, got): &(String, f64, f64)| (want - got).abs() < 1e-9;
        let must_hold = v.result == VectorResult::Valid
            || v.position().is_some_and(|b| b.expect.accepted.is_some());
        if must_hold {
            for r in &results {
                assert!(
                    holds(r),
                    "{}: {} expected {}, model gives {}",
                    v.id,
                    r.0,
                    r.1,
                    r.2
                );
            }
        } else {
            // An invalid vector records a printed number that is wrong (e.g. PSD-ERRATUM-059):
            // the model must not reproduce it.
            assert!(
                !results.iter().all(holds),
                "{}: the model reproduces an invalid vector",
                v.id
            );
        }
    }
}

#[test]
fn increments_per_rotation_formula_vectors() {
    for (v, b) in family()
        .vectors
        .iter()
        .filter_map(|v| Some((v, v.formula()?)))
        .filter(|(_, b)| b.input.formula == "increments-per-rotation")
    {
        let n = b.input.numerator.unwrap();
        let d = b.input.denominator.unwrap();
        let mut s = Sim::new(DEFAULT_MODEL);
        s.write(38, n);
        s.write(39, d);
        let ipr = s.drive.core().axis().increments_per_rotation();
        let want = b.expect.increments_per_rotation.unwrap().as_f64();
        let tol = b.expect.tolerance.map_or(1e-9, Number::as_f64);
        assert!((ipr - want).abs() <= tol, "{}: {ipr} vs {want}", v.id);
    }
}
