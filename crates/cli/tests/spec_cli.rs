//! The `drivespec spec` commands as a user runs them: exit codes, error lines and output.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::run;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

#[test]
fn builtin_spec_checks_clean() {
    let (code, stdout, stderr) = run(BIN, &["spec", "check"]);
    assert_eq!(code, 0, "{}{}", stdout, stderr);
    assert!(stdout.ends_with("spec ok\n"), "{}", stdout);
}

#[test]
fn unknown_device_is_bad_usage() {
    let (code, _, stderr) = run(BIN, &["spec", "list", "psd5xx"]);
    assert_eq!(code, 2);
    assert_eq!(
        stderr,
        "drivespec: unknown device \"psd5xx\"; expected one of: hpd, psd4xx, psx3xx\n"
    );
}

#[test]
fn unknown_subcommand_is_bad_usage() {
    assert_eq!(run(BIN, &["spec", "lsit", "hpd"]).0, 2);
    assert_eq!(run(BIN, &[]).0, 2);
}

#[test]
fn help_exits_zero() {
    let (code, stdout, _) = run(BIN, &["--help"]);
    assert_eq!(code, 0);
    assert!(stdout.contains("spec"), "{}", stdout);
}

#[test]
fn missing_spec_folder_is_unreadable_input() {
    let (code, _, stderr) = run(BIN, &["spec", "check", "--spec", "/nonexistent/spec"]);
    assert_eq!(code, 2);
    assert_eq!(
        stderr,
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
    let (code, stdout, stderr) = run(BIN, &["spec", "check", "--spec", dir.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 1, "{}{}", stdout, stderr);
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{}", stdout);
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

    let (code, _, _) = run(
        BIN,
        &[
            "spec",
            "check",
            "--format",
            "json",
            "--spec",
            "/nonexistent",
        ],
    );
    assert_eq!(code, 2);
}

/// A misspelt key in a step of a PSD4xx scenario fails `spec check` naming file, scenario,
/// step and key.
#[test]
fn misspelt_scenario_key_fails_check_naming_file_scenario_step_and_key() {
    let dir = std::env::temp_dir().join(format!("drivespec-scenario-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let src = concat!(env!("CARGO_MANIFEST_DIR"), "/../../spec");
    copy_dir(std::path::Path::new(src), &dir);
    let path = dir.join("psd4xx/scenarios/pkw.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let from = "{ do = \"hold\", cycles = 3, text = \"hold\" }";
    assert_eq!(text.matches(from).count(), 1);
    std::fs::write(
        &path,
        text.replace(from, "{ do = \"hold\", cylces = 3, text = \"hold\" }"),
    )
    .unwrap();
    let (code, stdout, stderr) = run(BIN, &["spec", "check", "--spec", dir.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 1, "{stdout}{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 1, "{stdout}");
    assert!(
        lines[0].starts_with(
            "psd4xx/scenarios/pkw.toml: scenario \"pkw/no-command\": steps[2]: unknown field `cylces`"
        ),
        "{}",
        lines[0]
    );
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
    let (code, stdout, stderr) = run(BIN, &["spec", "check", "--spec", dir.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 1, "{stdout}{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
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

/// A misspelt key in a step of a PSx3xx scenario fails `spec check` naming file, scenario,
/// step and key.
#[test]
fn misspelt_scenario_step_key_fails_check_naming_file_scenario_step_and_key() {
    let dir = std::env::temp_dir().join(format!("drivespec-scenarios-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let src = concat!(env!("CARGO_MANIFEST_DIR"), "/../../spec");
    copy_dir(std::path::Path::new(src), &dir);
    let path = dir.join("psx3xx/scenarios/status.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let from = "{ text = \"three cycles\", do = \"hold\", cycles = 3 }";
    assert_eq!(text.matches(from).count(), 1, "{from}");
    std::fs::write(
        &path,
        text.replace(from, &from.replace("cycles = 3", "cycels = 3")),
    )
    .unwrap();
    let (code, stdout, stderr) = run(BIN, &["spec", "check", "--spec", dir.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 1, "{stdout}{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 1, "{stdout}");
    assert!(
        lines[0].starts_with(
            "psx3xx/scenarios/status.toml: scenario \"status/power-on\": steps[1]: unknown field `cycels`"
        ),
        "{}",
        lines[0]
    );
}

#[test]
fn check_json_is_machine_readable() {
    let (code, stdout, _) = run(BIN, &["spec", "check", "--format", "json"]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["ok"], true);
    assert_eq!(v["problems"].as_array().map(Vec::len), Some(0));
}

/// `spec check` on a copy of the builtin spec in which `edit` changed the family folder
/// `family`'s files.
fn check_edited(name: &str, family: &str, edit: impl Fn(&str) -> String) -> (i32, String, String) {
    let dir = std::env::temp_dir().join(format!("drivespec-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let src = concat!(env!("CARGO_MANIFEST_DIR"), "/../../spec");
    copy_dir(std::path::Path::new(src), &dir);
    let mut changed = 0;
    for entry in std::fs::read_dir(dir.join(family)).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let text = std::fs::read_to_string(&path).unwrap();
            let edited = edit(&text);
            if edited != text {
                std::fs::write(&path, edited).unwrap();
                changed += 1;
            }
        }
    }
    let r = run(BIN, &["spec", "check", "--spec", dir.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(changed, 1, "the edit {name} changed {changed} files");
    r
}

/// `text` without the `[[requirement]]` record whose id is `id`.
fn without_requirement(text: &str, id: &str) -> String {
    let line = format!("id = {id:?}\n");
    let Some(at) = text.find(&line) else {
        return text.to_owned();
    };
    let start = text[..at].rfind("[[requirement]]").unwrap();
    let end = text[at..].find("\n[[").map_or(text.len(), |e| at + e + 1);
    format!("{}{}", &text[..start], &text[end..])
}

#[test]
fn a_spec_edit_that_breaks_case_generation_fails_check() {
    // Only a PSx3xx case cites this requirement: the spec loads, the cases cannot be made.
    let (code, stdout, stderr) = check_edited("no-case-requirement", "psx3xx", |t| {
        without_requirement(t, "PSX-PAR-NOT-SAVED")
    });
    assert_eq!(code, 1, "{}{}", stdout, stderr);
    assert!(!stdout.contains("spec ok"), "{}", stdout);
    let lines: Vec<&str> = stdout.lines().collect();
    assert!(
        lines.iter().any(|l| l.starts_with(
            "psx3xx: model \"PSE312-8\": the conformance cases cannot be generated: "
        ) && l.contains("unknown requirement PSX-PAR-NOT-SAVED")),
        "{}",
        stdout
    );
    // Every problem is a PSx3xx model's cases: the simulator does not need the requirement.
    assert!(
        lines.iter().all(|l| l.starts_with("psx3xx: model ")
            && l.contains(": the conformance cases cannot be generated: ")),
        "{}",
        stdout
    );
}

#[test]
fn a_spec_edit_that_breaks_the_simulator_fails_check() {
    // The reference PSx3xx drive takes the orange LED's acknowledge time from this pattern.
    let (code, stdout, stderr) = check_edited("no-led-dark", "psx3xx", |t| {
        t.replace("pattern = \"dark-250ms\"", "pattern = \"dark\"")
    });
    assert_eq!(code, 1, "{}{}", stdout, stderr);
    assert!(
        stdout.lines().any(|l| l
            == "psx3xx: model \"PSE312-8\": the simulator cannot be built: the reference model \
                cannot be built: spec: no dark-<n>ms state of the orange LED"),
        "{}",
        stdout
    );
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
        let (code, stdout, stderr) = run(BIN, args);
        assert_eq!(code, 0, "{args:?}: {}", stderr);
        insta::assert_snapshot!(args[2..].join("_").replace(' ', "_"), stdout);
    }
}

#[test]
fn spec_show_json_is_the_record_plus_the_resolution() {
    let (code, stdout, _) = run(
        BIN,
        &[
            "spec",
            "show",
            "psd4xx",
            "63",
            "--model",
            "psd 426/436-14h",
            "--format",
            "json",
        ],
    );
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["model"], "PSD426-14H");
    assert_eq!(v["resolved"]["range"], serde_json::json!([[150, 720]]));
    assert_eq!(v["resolved"]["default"], 360);
    assert_eq!(v["parameter"]["id"], "63");
    assert_eq!(v["per_model"].as_array().map(Vec::len), Some(11));
}

#[test]
fn unknown_model_lists_the_known_ones() {
    let (code, _, stderr) = run(BIN, &["spec", "show", "psd4xx", "63", "--model", "PSD999"]);
    assert_eq!(code, 2);
    assert!(
        stderr.starts_with("drivespec: unknown psd4xx model \"PSD999\"; known models: PSD401-5V, "),
        "{}",
        stderr
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
        let (code, stdout, stderr) = run(
            BIN,
            &["spec", "list", family, "--model", query, "--format", "json"],
        );
        assert_eq!(code, 0, "{query}: {}", stderr);
        let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
        assert_eq!(v["model"], want, "{query}");
    }
}

#[test]
fn models_and_errata_listings() {
    let (code, stdout, _) = run(BIN, &["spec", "models", "psd4xx"]);
    assert_eq!(code, 0);
    insta::assert_snapshot!("models_psd4xx", stdout);
    let (code, stdout, _) = run(BIN, &["spec", "errata", "hpd"]);
    assert_eq!(code, 0);
    assert!(stdout.contains("HPD-ERRATUM-001: b99.3"), "{}", stdout);
    let (_, stdout, _) = run(
        BIN,
        &[
            "spec",
            "requirements",
            "psd4xx",
            "--level",
            "must",
            "--format",
            "json",
        ],
    );
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert!(v["requirements"]
        .as_array()
        .unwrap()
        .iter()
        .all(|r| r["level"] == "must"));
}
