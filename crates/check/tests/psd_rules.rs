//! The PSD4xx plausibility rules on hand-made image sequences (bus description 3.6, 4.7):
//! status bit 0 far from the target during and after a run, the positioning window when par
//! 44 was not seen, a target beyond the limits without status bit 12, re-referencing by a
//! write of par 3, speeds and position jumps beyond the fastest model (4.3, 3.4), and what
//! cannot be decided.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_check::psd4xx::{PsdDrive, PsdOptions};
use drivespec_check::report::{Catalog, Recorder};
use drivespec_check::{Report, Where};
use drivespec_psd4xx::{Input, Output, RecordRead, RecordValue, RecordWrite, Rules, Width};
use drivespec_spec::{FamilyId, Spec};
use std::sync::Arc;

const RUNNING: u16 = 1 << 6;
const REACHED: u16 = 1;
const BAD_TARGET: u16 = 1 << 12;

/// A drive under test, fed image by image, one output and one input per 1 ms cycle.
struct Bench<'s> {
    rules: Arc<Rules>,
    drive: PsdDrive<'s>,
    rec: Recorder,
    frame: u64,
}

impl<'s> Bench<'s> {
    fn new(spec: &'s Spec) -> Bench<'s> {
        let rules = Arc::new(Rules::from_spec(spec).unwrap());
        let family = spec.family(FamilyId::Psd4xx);
        let drive = PsdDrive::new(
            "drive",
            family,
            rules.clone(),
            None,
            None,
            PsdOptions::default(),
        );
        let rec = Recorder::new(Arc::new(Catalog::new(spec).unwrap()), "psd4xx", None);
        Bench {
            rules,
            drive,
            rec,
            frame: 0,
        }
    }

    fn at(&mut self) -> Where {
        self.frame += 1;
        Where {
            event: self.frame,
            frame: Some(self.frame),
            time: Some(1_000_000 + self.frame * 500),
            ..Where::default()
        }
    }

    /// `n` cycles of `control` and `target` out, `status`, `actual` and `speed` in.
    fn cycles(&mut self, n: u32, control: u16, target: i32, status: u16, actual: i32, speed: i16) {
        for _ in 0..n {
            let out = Output {
                control,
                target,
                ..Output::default()
            }
            .to_bytes(&self.rules)
            .unwrap();
            let at = self.at();
            self.drive.output(&mut self.rec, at, &out);
            let inp = Input {
                status,
                actual,
                speed,
                ..Input::default()
            }
            .to_bytes(&self.rules)
            .unwrap();
            let at = self.at();
            self.drive.input(&mut self.rec, at, &inp);
        }
    }

    /// The drive reports par `index` = `value` (a record read).
    fn read(&mut self, index: u16, width: Width, value: i64) {
        let data = RecordRead {
            index,
            value: RecordValue::Number { width, value },
        }
        .to_bytes(self.rules.record())
        .unwrap();
        let at = self.at();
        self.drive.record_read(&mut self.rec, at, index, &data);
    }

    /// The controller writes par `index` = `value` and the drive accepts it.
    fn write(&mut self, index: u16, width: Width, value: i64) {
        let data = RecordWrite {
            index,
            control: 1,
            width,
            value,
        }
        .to_bytes(self.rules.record())
        .unwrap();
        let at = self.at();
        self.drive.record_write(&mut self.rec, at, index, &data);
        self.drive.record_written(&mut self.rec, at, index, true);
    }

    fn report(self) -> Report {
        self.rec.finish()
    }
}

fn count(r: &Report, id: &str) -> u64 {
    r.requirements.get(id).map_or(0, |t| t.violations)
}

#[test]
fn bit_0_during_a_run_far_from_the_target_is_a_violation() {
    let spec = Spec::builtin().unwrap();
    let mut b = Bench::new(&spec);
    b.read(44, Width::Word, 5);
    b.cycles(30, 0x14, 10_000, RUNNING, 1000, 100);
    // Bit 0 set while running, 1934 increments from the target.
    b.cycles(5, 0x14, 10_000, RUNNING | REACHED, 8066, 100);
    let r = b.report();
    assert_eq!(count(&r, "PSD-PAR-44-001"), 1, "{:#?}", r.violations);
    assert!(r.violations[0].message.contains("during a run"));
}

#[test]
fn without_par_44_the_largest_window_of_the_manual_applies() {
    let spec = Spec::builtin().unwrap();
    let mut b = Bench::new(&spec);
    b.cycles(30, 0x14, 10_000, RUNNING, 1000, 100);
    // 60 increments off: inside the largest window (100), no violation.
    b.cycles(30, 0x14, 10_000, REACHED, 9940, 0);
    // 500 increments off: beyond any window par 44 can hold.
    b.cycles(30, 0x14, 10_000, 0, 9940, 0);
    b.cycles(5, 0x14, 10_000, REACHED, 9500, 0);
    let r = b.report();
    assert_eq!(count(&r, "PSD-PAR-44-001"), 1, "{:#?}", r.violations);
    assert!(r.violations[0].message.contains("par 44 not seen"));
}

#[test]
fn bit_0_without_a_transferred_target_is_inconclusive() {
    let spec = Spec::builtin().unwrap();
    let mut b = Bench::new(&spec);
    b.cycles(30, 0x10, 0, REACHED, 9500, 0);
    let r = b.report();
    assert_eq!(r.violation_count, 0, "{:#?}", r.violations);
    assert_eq!(r.inconclusive_count, 1);
    assert_eq!(r.inconclusive[0].requirement, "PSD-PAR-44-001");
}

#[test]
fn writing_par_3_moves_the_target_with_the_position() {
    let spec = Spec::builtin().unwrap();
    let mut b = Bench::new(&spec);
    b.read(44, Width::Word, 5);
    b.cycles(30, 0x14, 10_000, RUNNING, 1000, 100);
    b.cycles(30, 0x14, 10_000, REACHED, 10_000, 0);
    // Re-reference: the position 10000 becomes 50000; the target moves along (4.7).
    b.write(3, Width::Dword, 50_000);
    b.cycles(50, 0x14, 10_000, REACHED, 50_000, 0);
    let r = b.report();
    assert_eq!(count(&r, "PSD-PAR-44-001"), 0, "{:#?}", r.violations);
}

#[test]
fn a_target_beyond_the_limit_needs_bit_12() {
    let spec = Spec::builtin().unwrap();
    let mut b = Bench::new(&spec);
    b.read(42, Width::Dword, 100_000);
    b.read(43, Width::Dword, -100_000);
    b.read(44, Width::Word, 5);
    // Beyond the upper limit, and the drive runs without bit 12.
    b.cycles(30, 0x14, 200_000, RUNNING, 1000, 100);
    b.cycles(5, 0x00, 200_000, 0, 1000, 0);
    // Beyond the lower limit, refused with bit 12: conforming.
    b.cycles(30, 0x14, -200_000, BAD_TARGET, 1000, 0);
    let r = b.report();
    assert_eq!(count(&r, "PSD-STS-12-SET-1"), 1, "{:#?}", r.violations);
    assert!(r.violations[0].message.contains("running"));
}

#[test]
fn a_target_without_known_limits_is_inconclusive() {
    let spec = Spec::builtin().unwrap();
    let mut b = Bench::new(&spec);
    b.cycles(30, 0x14, 200_000, RUNNING, 1000, 100);
    let r = b.report();
    assert_eq!(r.violation_count, 0, "{:#?}", r.violations);
    assert!(r
        .inconclusive
        .iter()
        .any(|i| i.requirement == "PSD-STS-12-SET-1"));
}

/// The delivery scaling (par 38 = par 39 = 400: 400 increments per rotation), as read.
fn delivery_scaling(b: &mut Bench<'_>) {
    b.read(38, Width::Word, 400);
    b.read(39, Width::Word, 400);
}

#[test]
fn a_position_jump_faster_than_any_model_is_a_violation() {
    let spec = Spec::builtin().unwrap();
    let mut b = Bench::new(&spec);
    delivery_scaling(&mut b);
    // 1000 rpm (the fastest model) is about 6.7 increments per ms: 30 per ms is allowed
    // with the slack (+10 %, 4 ms), 30,000 is not.
    b.cycles(10, 0x10, 40_000, RUNNING, 1000, 1000);
    b.cycles(1, 0x10, 40_000, RUNNING, 1030, 1000);
    b.cycles(1, 0x10, 40_000, RUNNING, 31_030, 1000);
    b.cycles(10, 0x10, 40_000, RUNNING, 31_037, 1000);
    let jump_frame = 2 + 2 * 12;
    let r = b.report();
    assert_eq!(count(&r, "PSD-VEL-002"), 1, "{:#?}", r.violations);
    assert_eq!(r.violations[0].at.frame, Some(jump_frame));
    assert!(r.violations[0].message.contains("30000 increments"));
    assert_eq!(r.inconclusive_count, 0, "{:#?}", r.inconclusive);
}

#[test]
fn a_position_wrapping_round_the_32_bit_value_moves_the_short_way() {
    let spec = Spec::builtin().unwrap();
    let mut b = Bench::new(&spec);
    delivery_scaling(&mut b);
    b.cycles(3, 0x10, 0, RUNNING, i32::MAX - 2, 300);
    b.cycles(3, 0x10, 0, RUNNING, i32::MIN + 2, 300);
    let r = b.report();
    assert_eq!(r.violation_count, 0, "{:#?}", r.violations);
}

#[test]
fn writing_par_3_excuses_the_jump_of_the_actual_value() {
    let spec = Spec::builtin().unwrap();
    let mut b = Bench::new(&spec);
    delivery_scaling(&mut b);
    b.cycles(10, 0x00, 0, 0, 10_000, 0);
    b.write(3, Width::Dword, 50_000);
    b.cycles(10, 0x00, 0, 0, 50_000, 0);
    let r = b.report();
    assert_eq!(r.violation_count, 0, "{:#?}", r.violations);
}

#[test]
fn a_speed_above_the_fastest_model_is_a_violation_once_per_stretch() {
    let spec = Spec::builtin().unwrap();
    let mut b = Bench::new(&spec);
    // Model unknown: 1000 rpm (PSD 422/432-8V, 3.4 par 53) + 10 % is the limit.
    b.cycles(10, 0x10, 0, RUNNING, 0, 1100);
    b.cycles(10, 0x10, 0, RUNNING, 0, 1200);
    b.cycles(10, 0x10, 0, RUNNING, 0, 900);
    // A manual run (control bits 0 and 4) too fast: par 56's requirement.
    b.cycles(10, 0x11, 0, RUNNING, 0, -1500);
    let r = b.report();
    assert_eq!(count(&r, "PSD-VEL-002"), 1, "{:#?}", r.violations);
    assert_eq!(count(&r, "PSD-VEL-001"), 1, "{:#?}", r.violations);
    assert_eq!(r.violations[0].at.frame, Some(22));
    // Without the scaling, the position change cannot be judged: said once.
    assert_eq!(r.inconclusive_count, 0);
    let mut b = Bench::new(&spec);
    b.cycles(5, 0x10, 0, RUNNING, 0, 100);
    b.cycles(5, 0x10, 0, RUNNING, 90_000, 100);
    let r = b.report();
    assert_eq!(r.violation_count, 0, "{:#?}", r.violations);
    assert!(r
        .inconclusive
        .iter()
        .any(|i| i.requirement == "PSD-VEL-002"));
}

/// With the model unknown, a write some model of the family accepts is no violation, even
/// where the reference model standing in for the drive (the family's first) refuses it.
#[test]
fn an_accepted_write_in_another_models_range_is_no_violation() {
    let spec = Spec::builtin().unwrap();
    let rules = Arc::new(Rules::from_spec(&spec).unwrap());
    let family = spec.family(FamilyId::Psd4xx);
    let oracle = drivespec_psd4xx::model::Drive::new(
        &spec,
        drivespec_psd4xx::model::DriveConfig::new(&family.models[0].id),
    )
    .unwrap();
    let drive = PsdDrive::new(
        "drive",
        family,
        rules.clone(),
        None,
        Some(oracle),
        PsdOptions::default(),
    );
    let rec = Recorder::new(Arc::new(Catalog::new(&spec).unwrap()), "psd4xx", None);
    let mut b = Bench {
        rules,
        drive,
        rec,
        frame: 0,
    };
    b.cycles(2, 0x00, 0, 0, 0, 0);
    // 900 rpm: beyond the first model's par 53 (1..800), inside PSD 422/432-8V's (1..1000).
    b.write(53, Width::Word, 900);
    // 5000 rpm: no model has it.
    b.write(53, Width::Word, 5000);
    let r = b.report();
    assert_eq!(count(&r, "PSD-PKW-025"), 1, "{:#?}", r.violations);
    assert!(r.violations[0].message.contains("5000"));
}
