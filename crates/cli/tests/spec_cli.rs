//! The `drivespec spec` commands as a user runs them: exit codes, error lines and output.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use std::process::Command;

struct Run {
    code: i32,
    stdout: String,
    stderr: String,
}

fn drivespec(args: &[&str]) -> Run {
    let out = Command::new(env!("CARGO_BIN_EXE_drivespec"))
        .args(args)
        .output()
        .expect("run drivespec");
    Run {
        code: out.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

#[test]
fn builtin_spec_checks_clean() {
    let r = drivespec(&["spec", "check"]);
    assert_eq!(r.code, 0, "{}{}", r.stdout, r.stderr);
    assert!(r.stdout.ends_with("spec ok\n"), "{}", r.stdout);
}

#[test]
fn unknown_device_is_bad_usage() {
    let r = drivespec(&["spec", "list", "psd5xx"]);
    assert_eq!(r.code, 2);
    assert_eq!(
        r.stderr,
        "drivespec: unknown device \"psd5xx\"; expected one of: hpd, psd4xx, psx3xx\n"
    );
}

#[test]
fn unknown_subcommand_is_bad_usage() {
    assert_eq!(drivespec(&["spec", "lsit", "hpd"]).code, 2);
    assert_eq!(drivespec(&[]).code, 2);
}

#[test]
fn help_exits_zero() {
    let r = drivespec(&["--help"]);
    assert_eq!(r.code, 0);
    assert!(r.stdout.contains("spec"), "{}", r.stdout);
}

#[test]
fn missing_spec_folder_is_unreadable_input() {
    let r = drivespec(&["spec", "check", "--spec", "/nonexistent/spec"]);
    assert_eq!(r.code, 2);
    assert_eq!(
        r.stderr,
        "drivespec: cannot read spec folder /nonexistent/spec: not a directory\n"
    );
}

#[test]
fn broken_spec_folder_fails_check_with_one_line_per_problem() {
    let dir = std::env::temp_dir().join(format!("drivespec-broken-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let src = concat!(env!("CARGO_MANIFEST_DIR"), "/../../spec");
    copy_dir(std::path::Path::new(src), &dir);
    std::fs::write(
        dir.join("psd4xx/zz-broken.toml"),
        "[[requirement]]\nid = \"PSD-X\"\nlevel = \"must\"\ntext = \"t\"\nsource = \"1\"\n\n[[requirement]]\nid = \"PSD-FIXTURE-1\"\nlevel = \"maybe\"\ntext = \"t\"\nsource = \"1\"\n",
    )
    .unwrap();
    let r = drivespec(&["spec", "check", "--spec", dir.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(r.code, 1, "{}{}", r.stdout, r.stderr);
    let lines: Vec<&str> = r.stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{}", r.stdout);
    assert!(
        lines[0].starts_with(
            "psd4xx/zz-broken.toml: requirement \"PSD-FIXTURE-1\": unknown variant `maybe`"
        ),
        "{}",
        lines[0]
    );
    assert!(
        lines[1].starts_with(
            "psd4xx/zz-broken.toml: requirement \"PSD-X\": identifier \"PSD-X\" does not match"
        ),
        "{}",
        lines[1]
    );

    let json = drivespec(&[
        "spec",
        "check",
        "--format",
        "json",
        "--spec",
        "/nonexistent",
    ]);
    assert_eq!(json.code, 2);
}

/// A misspelt key in a step of a `sequence` vector fails `spec check` naming file, record,
/// step and key, in each cyclic family.
#[test]
fn misspelt_step_key_fails_check_naming_file_record_and_key() {
    let dir = std::env::temp_dir().join(format!("drivespec-steps-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let src = concat!(env!("CARGO_MANIFEST_DIR"), "/../../spec");
    copy_dir(std::path::Path::new(src), &dir);
    let edit = |file: &str, from: &str, to: &str| {
        let path = dir.join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert_eq!(text.matches(from).count(), 1, "{from}");
        std::fs::write(&path, text.replace(from, to)).unwrap();
    };
    edit(
        "psd4xx/vectors/process.toml",
        "target_offset = 100",
        "target_ofset = 100",
    );
    edit(
        "psx3xx/vectors/process.toml",
        "index = 112, value = 70000 }, expect = { run = \"positioning\", target = 70000, stop = false",
        "index = 112, value = 70000 }, expect = { run = \"positioning\", target = 70000, stopp = false",
    );
    let r = drivespec(&["spec", "check", "--spec", dir.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(r.code, 1, "{}{}", r.stdout, r.stderr);
    let lines: Vec<&str> = r.stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{}", r.stdout);
    assert!(
        lines[0].starts_with(
            "psd4xx/vectors/process.toml: vector \"seq-loop-case-3-short\": input.steps[3]: unknown field `target_ofset`"
        ),
        "{}",
        lines[0]
    );
    assert!(
        lines[1].starts_with(
            "psx3xx/vectors/process.toml: vector \"seq-ts-new-target-during-run\": input.steps[2]: unknown field `stopp`"
        ),
        "{}",
        lines[1]
    );
}

#[test]
fn check_json_is_machine_readable() {
    let r = drivespec(&["spec", "check", "--format", "json"]);
    assert_eq!(r.code, 0);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    assert_eq!(v["ok"], true);
    assert_eq!(v["problems"].as_array().map(Vec::len), Some(0));
}

fn copy_dir(from: &std::path::Path, to: &std::path::Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let entry = entry.unwrap();
        let target = to.join(entry.file_name());
        if entry.path().is_dir() {
            copy_dir(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), target).unwrap();
        }
    }
}

/// `spec show` for a few parameters per device, as people read them.
#[test]
fn spec_show_snapshots() {
    let cases: [&[&str]; 9] = [
        &["spec", "show", "psd4xx", "63", "--model", "PSD426"],
        &["spec", "show", "psd4xx", "63"],
        &["spec", "show", "psd4xx", "1"],
        &["spec", "show", "psd4xx", "96"],
        &["spec", "show", "hpd", "Pr64"],
        &["spec", "show", "hpd", "Pr33"],
        &["spec", "show", "hpd", "Pb99"],
        &["spec", "show", "psx3xx", "193"],
        &["spec", "show", "psx3xx", "64"],
    ];
    for args in cases {
        let r = drivespec(args);
        assert_eq!(r.code, 0, "{args:?}: {}", r.stderr);
        insta::assert_snapshot!(args[2..].join("_").replace(' ', "_"), r.stdout);
    }
}

#[test]
fn spec_show_json_is_the_record_plus_the_resolution() {
    let r = drivespec(&[
        "spec",
        "show",
        "psd4xx",
        "63",
        "--model",
        "psd 426/436-14h",
        "--format",
        "json",
    ]);
    assert_eq!(r.code, 0);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    assert_eq!(v["model"], "PSD426-14H");
    assert_eq!(v["resolved"]["range"], serde_json::json!([[150, 720]]));
    assert_eq!(v["resolved"]["default"], 360);
    assert_eq!(v["parameter"]["id"], "63");
    assert_eq!(v["per_model"].as_array().map(Vec::len), Some(11));
}

#[test]
fn unknown_model_lists_the_known_ones() {
    let r = drivespec(&["spec", "show", "psd4xx", "63", "--model", "PSD999"]);
    assert_eq!(r.code, 2);
    assert!(
        r.stderr
            .starts_with("drivespec: unknown psd4xx model \"PSD999\"; known models: PSD401-5V, "),
        "{}",
        r.stderr
    );
}

#[test]
fn models_match_forgivingly() {
    for (family, query, want) in [
        ("psd4xx", "PSD426", "PSD426-14H"),
        ("psd4xx", "psd 426/436-14h", "PSD426-14H"),
        ("psx3xx", "PSE335-14", "PSE335-14"),
        ("psx3xx", "pse 335-14", "PSE335-14"),
    ] {
        let r = drivespec(&["spec", "list", family, "--model", query, "--format", "json"]);
        assert_eq!(r.code, 0, "{query}: {}", r.stderr);
        let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
        assert_eq!(v["model"], want, "{query}");
    }
}

#[test]
fn models_and_errata_listings() {
    let r = drivespec(&["spec", "models", "psd4xx"]);
    assert_eq!(r.code, 0);
    insta::assert_snapshot!("models_psd4xx", r.stdout);
    let r = drivespec(&["spec", "errata", "hpd"]);
    assert_eq!(r.code, 0);
    assert!(r.stdout.contains("HPD-ERRATUM-001: b99.3"), "{}", r.stdout);
    let r = drivespec(&[
        "spec",
        "requirements",
        "psd4xx",
        "--level",
        "must",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    assert!(v["requirements"]
        .as_array()
        .unwrap()
        .iter()
        .all(|r| r["level"] == "must"));
}
