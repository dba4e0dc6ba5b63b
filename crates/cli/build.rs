//! Sets `DRIVESPEC_VERSION`, the text `drivespec --version` prints: the package version and,
//! when known, the commit it was built from with the commit's date, e.g.
//! `0.1.0 (abc1234 2026-11-27)`.
//!
//! The commit comes from `DRIVESPEC_COMMIT` and `DRIVESPEC_COMMIT_DATE` when set (builds from
//! a source archive or a container without `.git`), else from `git` when it runs and the
//! sources are a checkout, else the version stands alone.

use std::path::{Path, PathBuf};
use std::process::Command;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=DRIVESPEC_COMMIT");
    println!("cargo:rerun-if-env-changed=DRIVESPEC_COMMIT_DATE");
    let version = std::env::var("CARGO_PKG_VERSION").unwrap_or_default();
    let commit = from_env().or_else(from_git);
    let text = match commit {
        Some((hash, date)) if date.is_empty() => format!("{version} ({hash})"),
        Some((hash, date)) => format!("{version} ({hash} {date})"),
        None => version,
    };
    println!("cargo:rustc-env=DRIVESPEC_VERSION={text}");
}

/// The commit named by the environment, if any.
fn from_env() -> Option<(String, String)> {
    let hash = std::env::var("DRIVESPEC_COMMIT").ok()?.trim().to_owned();
    if hash.is_empty() {
        return None;
    }
    let date = std::env::var("DRIVESPEC_COMMIT_DATE").unwrap_or_default();
    Some((hash.chars().take(12).collect(), date.trim().to_owned()))
}

/// The checked-out commit and its date; watches the files whose change means another commit.
fn from_git() -> Option<(String, String)> {
    // HEAD and the branch it points to (loose or packed); in a worktree the branch lives in
    // the common folder.
    let git_dir = PathBuf::from(git(&["rev-parse", "--git-dir"])?);
    let common = PathBuf::from(git(&["rev-parse", "--git-common-dir"])?);
    watch(&git_dir.join("HEAD"));
    if let Some(branch) = git(&["symbolic-ref", "-q", "HEAD"]) {
        watch(&common.join(branch));
    }
    watch(&common.join("packed-refs"));
    // Sources unpacked inside some other checkout are not part of it.
    git(&["ls-files", "--error-unmatch", "build.rs"])?;
    let head = git(&["log", "-1", "--format=%h %cs", "--abbrev=7"])?;
    let (hash, date) = head.split_once(' ')?;
    Some((hash.to_owned(), date.to_owned()))
}

/// Reruns this script when `path` changes (only existing files: a missing one would rerun it
/// on every build).
fn watch(path: &Path) {
    if path.is_file() {
        println!("cargo:rerun-if-changed={}", path.display());
    }
}

/// The trimmed output of a successful `git` command run in this crate's folder.
fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    if !out.status.success() {
        return None;
    }
    let text = String::from_utf8(out.stdout).ok()?.trim().to_owned();
    (!text.is_empty()).then_some(text)
}
