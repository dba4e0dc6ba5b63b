//! Running the `drivespec` binary in the command-line tests: a run's exit code and output, a
//! `drivespec sim` process that is killed when dropped, per-process temporary folders,
//! the checks of a `drivespec fuzz` run that finds nothing, and two network namespaces joined
//! by a veth pair ([`netns`]).
//!
//! The binary's path comes from the test crate (`env!("CARGO_BIN_EXE_drivespec")`). Test
//! code: a failure to start, feed or wait for the binary panics with the reason, which is how
//! a test reports it; no input path of the product runs through this crate.
#![forbid(unsafe_code)]
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

pub mod netns;

use std::io::{BufRead, BufReader, Read, Write};
use std::path::PathBuf;
use std::process::{Child, ChildStdout, Command, Stdio};

/// The environment variable that turns off progress output (`CI=true`).
pub const CI: &[(&str, &str)] = &[("CI", "true")];

/// Runs `bin` with `args` and no input; returns the exit code (-1 when killed by a signal),
/// stdout and stderr.
pub fn run(bin: &str, args: &[&str]) -> (i32, String, String) {
    run_with(bin, args, None, &[])
}

/// Runs `bin` with `args`, `stdin` piped in (none: stdin is empty) and the variables of `env`
/// set; returns the exit code (-1 when killed by a signal), stdout and stderr.
pub fn run_with(
    bin: &str,
    args: &[&str],
    stdin: Option<&str>,
    env: &[(&str, &str)],
) -> (i32, String, String) {
    let mut child = Command::new(bin)
        .args(args)
        .envs(env.iter().copied())
        .stdin(if stdin.is_some() {
            Stdio::piped()
        } else {
            Stdio::null()
        })
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run drivespec");
    let writer = match (stdin, child.stdin.take()) {
        (Some(text), Some(mut input)) => {
            let text = text.to_owned();
            Some(std::thread::spawn(move || {
                input.write_all(text.as_bytes()).expect("write stdin")
            }))
        }
        _ => None,
    };
    let out = child.wait_with_output().expect("wait for drivespec");
    if let Some(w) = writer {
        w.join().expect("stdin writer");
    }
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A folder `drivespec-<kind>-<name>-<pid>` in the system's temporary folder, removed first
/// if a former run left it.
pub fn temp_dir(kind: &str, name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("drivespec-{kind}-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

/// A `drivespec sim` process (time limit 60 s), killed when dropped.
#[derive(Debug)]
pub struct Sim {
    child: Child,
    stdout: BufReader<ChildStdout>,
}

impl Sim {
    /// Starts `bin sim ARGS --time-limit 60` with stdout and stderr piped.
    pub fn start(bin: &str, args: &[&str]) -> Sim {
        let mut child = Command::new(bin)
            .arg("sim")
            .args(args)
            .args(["--time-limit", "60"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("start drivespec sim");
        let stdout = BufReader::new(child.stdout.take().expect("piped stdout"));
        Sim { child, stdout }
    }

    /// The one line the server prints on stdout: the pty path or the TCP address.
    pub fn first_line(&mut self) -> String {
        let mut line = String::new();
        self.stdout
            .read_line(&mut line)
            .expect("read the first line");
        line.trim().to_owned()
    }

    /// Stops the server and returns its stderr.
    pub fn stop(mut self) -> String {
        let _ = self.child.kill();
        let mut err = String::new();
        if let Some(mut e) = self.child.stderr.take() {
            let _ = e.read_to_string(&mut err);
        }
        let _ = self.child.wait();
        err
    }
}

impl Drop for Sim {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Runs `bin fuzz FAMILY [ARGS] --iterations N --seed 3` against the built-in model and checks
/// a clean run: exit 0, N sequences and no finding, the simulated `model` named, progress on
/// stderr, `fuzz.json`, `fuzz.junit.xml` and `fuzz.html` written, and `class` among the
/// classes of the JSON report.
pub fn fuzz_finds_nothing(
    bin: &str,
    family: &str,
    args: &[&str],
    model: &str,
    iterations: u32,
    class: &str,
) {
    let out = temp_dir(&format!("fuzz-{family}-cli"), "sim");
    let dir = out.display().to_string();
    let n = iterations.to_string();
    let mut argv = vec!["fuzz", family];
    argv.extend_from_slice(args);
    argv.extend_from_slice(&["--iterations", &n, "--seed", "3", "--out", &dir]);
    let (code, stdout, stderr) = run(bin, &argv);
    assert_eq!(code, 0, "{stdout}{stderr}");
    assert!(
        stdout.contains(&format!("{n} sequence(s)")) && stdout.contains("0 finding(s)"),
        "{stdout}"
    );
    assert!(stdout.contains(&format!("sim:{model}")), "{stdout}");
    assert!(
        stderr.contains(&format!("fuzz {family}: {n}/{n} sequences")),
        "{stderr}"
    );
    for f in ["fuzz.json", "fuzz.junit.xml", "fuzz.html"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    let json = std::fs::read_to_string(out.join("fuzz.json")).expect("read fuzz.json");
    assert!(json.contains(&format!("\"{class}\"")), "{json}");
    std::fs::remove_dir_all(&out).expect("remove the output folder");
}
