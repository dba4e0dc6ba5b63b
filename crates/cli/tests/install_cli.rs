//! What an installation ships beside the binary: shell completions, man pages, and
//! `--version` naming the commit.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run, temp_dir};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// Subcommands every completion script and the main man page must offer.
const SUBCOMMANDS: &[&str] = &[
    "conform",
    "fuzz",
    "check",
    "sim-run",
    "decode",
    "completions",
];

fn completions(shell: &str) -> String {
    let (code, stdout, stderr) = run(BIN, &["completions", shell]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.is_empty(), "{stderr}");
    for sub in SUBCOMMANDS {
        assert!(stdout.contains(sub), "{shell} completions lack {sub}");
    }
    stdout
}

#[test]
fn bash_completions_are_a_valid_script() {
    let script = completions("bash");
    assert!(script.contains("complete -F _drivespec"), "{script}");
    assert!(script.contains("--dut"), "conform's options are completed");
    let dir = temp_dir("install", "bash");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("drivespec.bash");
    std::fs::write(&path, &script).unwrap();
    let check = Command::new("bash").arg("-n").arg(&path).output().unwrap();
    assert!(
        check.status.success(),
        "{}",
        String::from_utf8_lossy(&check.stderr)
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn zsh_and_fish_completions_name_the_subcommands() {
    assert!(completions("zsh").starts_with("#compdef drivespec\n"));
    assert!(completions("fish").contains("complete -c drivespec "));
}

#[test]
fn unknown_shell_is_bad_usage() {
    let (code, stdout, stderr) = run(BIN, &["completions", "tcsh"]);
    assert_eq!(code, 2, "{stdout}");
    assert!(
        stderr.contains("bash"),
        "the error lists the shells: {stderr}"
    );
}

#[test]
fn man_page_is_roff_with_name_and_subcommands() {
    let (code, page, stderr) = run(BIN, &["man"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(page.contains("\n.TH drivespec 1 "), "{page}");
    let name = page.split_once("\n.SH NAME\n").expect("NAME section").1;
    assert!(
        name.starts_with("drivespec \\- Conformance test suite"),
        "{name}"
    );
    for sub in SUBCOMMANDS {
        let reference = format!("drivespec\\-{}(1)", sub.replace('-', "\\-"));
        assert!(page.contains(&reference), "{reference}");
    }
}

#[test]
fn man_out_writes_one_page_per_subcommand() {
    let dir = temp_dir("install", "man");
    let (code, stdout, stderr) = run(BIN, &["man", "--out", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    let listed: Vec<&str> = stdout.lines().collect();
    for page in [
        "drivespec.1",
        "drivespec-conform.1",
        "drivespec-decode-hpd.1",
    ] {
        let path = dir.join(page);
        assert!(listed.contains(&path.to_str().unwrap()), "{stdout}");
        assert!(std::fs::read_to_string(&path).unwrap().contains(".SH NAME"));
    }
    let conform = std::fs::read_to_string(dir.join("drivespec-conform.1")).unwrap();
    assert!(conform.contains("\\-\\-expect"), "{conform}");
    assert!(!dir.join("drivespec-help.1").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

/// The commit text the build script derives: from `DRIVESPEC_COMMIT` (and its date) when
/// set, else from `git` when the sources are a checkout.
fn expected_commit() -> Option<String> {
    if let Some(hash) = option_env!("DRIVESPEC_COMMIT").filter(|h| !h.trim().is_empty()) {
        let hash: String = hash.trim().chars().take(12).collect();
        return Some(match option_env!("DRIVESPEC_COMMIT_DATE").map(str::trim) {
            Some(date) if !date.is_empty() => format!("{hash} {date}"),
            _ => hash,
        });
    }
    let git = |args: &[&str]| {
        let out = Command::new("git")
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .ok()?;
        out.status
            .success()
            .then(|| String::from_utf8_lossy(&out.stdout).trim().to_owned())
    };
    git(&["ls-files", "--error-unmatch", "build.rs"])?;
    git(&["log", "-1", "--format=%h %cs", "--abbrev=7"])
}

#[test]
fn version_names_the_commit() {
    let (code, stdout, stderr) = run(BIN, &["--version"]);
    assert_eq!(code, 0, "{stderr}");
    let expected = match expected_commit() {
        Some(commit) => format!("drivespec {} ({commit})\n", env!("CARGO_PKG_VERSION")),
        None => format!("drivespec {}\n", env!("CARGO_PKG_VERSION")),
    };
    assert_eq!(stdout, expected);
}
