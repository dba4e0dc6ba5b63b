//! The PSD4xx plausibility rules on hand-made image sequences (bus description 3.6, 4.7):
//! status bit 0 far from the target during and after a run, the positioning window when par
//! 44 was not seen, a target beyond the limits without status bit 12, re-referencing by a
//! write of par 3, and what cannot be decided.
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
