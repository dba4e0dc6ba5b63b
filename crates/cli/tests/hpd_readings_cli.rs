//! `drivespec conform --reading OPTION=READING`: one erratum made strict, and the usage
//! errors that name the valid options and readings.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run, temp_dir};

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

fn conform(name: &str, extra: &[&str]) -> (i32, String, String) {
    let dir = temp_dir("readings", name);
    let d = dir.display().to_string();
    let mut args = vec!["conform", "hpd", "--quiet", "--report-dir", d.as_str()];
    args.extend_from_slice(extra);
    let out = run(BIN, &args);
    let _ = std::fs::remove_dir_all(&dir);
    out
}

#[test]
fn an_unknown_reading_is_a_usage_error_naming_the_readings() {
    let (code, _, err) = conform("unknown-reading", &["--reading", "b99-3=sometimes"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("readings: zero, nonzero"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    let (code, _, err) = conform("unknown-option", &["--reading", "b99-9=zero"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("options: b99-3,"), "{err}");
    let (code, _, err) = conform("no-equals", &["--reading", "b99-3"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("OPTION=READING"), "{err}");
}

/// The reference acknowledges a refused write: it passes by default (reporting the reading)
/// and fails when only silence is admissible.
#[test]
fn a_strict_reading_admits_only_that_reading() {
    let case = ["--case", "hpd/param/Pr25/write-refused"];
    let (code, out, err) = conform("default", &case);
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        out.contains("follows reading `acknowledged` of HPD-ERRATUM-069"),
        "{out}"
    );
    let mut strict = case.to_vec();
    strict.extend(["--reading", "refused-write=silent"]);
    let (code, out, err) = conform("strict", &strict);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.contains("1 failed"), "{out}");
}
