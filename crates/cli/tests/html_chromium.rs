//! Every HTML report the real binary writes loads in headless Chromium without a console
//! message and with the elements a reader needs: `conform` passing (plots), failing (an
//! adapter with gaps: the failure list, plots with the failing cycle marked) and stopped by
//! `--timeout`, `fuzz` with findings (the same adapter), and `check` on recordings of
//! `corpus/captures/` (violations, timelines).
//!
//! How a page is judged: `chromium --headless --dump-dom --enable-logging=stderr --v=0`
//! loads it from a file; Chromium logs every console message (a `console.*` call, an
//! uncaught exception, a resource that failed to load) on stderr as a line with `:CONSOLE`,
//! and prints the DOM it built on stdout. The reports carry no scripts, so any such line
//! fails the test, as does a DOM without the expected elements. A page with a console error
//! and an uncaught exception is loaded too, to show the detection works with the Chromium
//! at hand. The pages load in parallel (a few seconds in all).
//!
//! Chromium is Debian's `chromium` (or `chromium-browser`, `google-chrome`, or the path in
//! `DRIVESPEC_CHROMIUM`). Without it the test says so and passes, unless
//! `DRIVESPEC_REQUIRE_CHROMIUM` is set (`.ci/run` sets it and installs Chromium).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run_with, temp_dir, CI};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// Longest a page may take to load.
const LOAD_LIMIT: Duration = Duration::from_secs(60);

/// The Chromium to use, if any.
fn chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("DRIVESPEC_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    [
        "chromium",
        "chromium-browser",
        "google-chrome",
        "google-chrome-stable",
    ]
    .iter()
    .flat_map(|name| std::env::split_paths(&path).map(move |dir| dir.join(name)))
    .find(|p| p.is_file())
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs `drivespec ARGS` (CI output) and checks its exit code.
fn drivespec(args: &[&str], code: i32) {
    let (got, out, err) = run_with(BIN, args, None, CI);
    assert_eq!(got, code, "drivespec {args:?}\n{out}\n{err}");
}

/// A page, what its DOM must contain and must not contain.
struct Page {
    file: PathBuf,
    must: &'static [&'static str],
    must_not: &'static [&'static str],
}

/// Writes the reports; the pages to load.
fn reports(dir: &Path) -> Vec<Page> {
    let d = |name: &str| dir.join(name).to_str().unwrap().to_owned();
    let root = root();
    let capture = |name: &str| {
        root.join("corpus/captures")
            .join(name)
            .to_str()
            .unwrap()
            .to_owned()
    };
    drivespec(
        &[
            "conform",
            "psd4xx",
            "--case",
            "psd4xx/position/loop/*",
            "--quiet",
            "--report-dir",
            &d("pass"),
        ],
        0,
    );
    let adapter = format!(
        "exec:python3 {}",
        root.join("tests/psd4xx_adapter.py").display()
    );
    drivespec(
        &[
            "conform",
            "psd4xx",
            "--dut",
            &adapter,
            "--case",
            "psd4xx/position/*",
            "--quiet",
            "--report-dir",
            &d("fail"),
        ],
        1,
    );
    let slow = format!("exec:{BIN} sim hpd --stdio --time-limit 60");
    drivespec(
        &[
            "conform",
            "hpd",
            "--dut",
            &slow,
            "--quiet",
            "--timeout",
            "1s",
            "--report-dir",
            &d("interrupted"),
        ],
        124,
    );
    drivespec(
        &[
            "fuzz",
            "psd4xx",
            "--dut",
            &adapter,
            "--seed",
            "7",
            "--iterations",
            "10",
            "--minimize-runs",
            "1",
            "--quiet",
            "--out",
            &d("fuzz"),
        ],
        1,
    );
    drivespec(
        &[
            "check",
            &capture("psd4xx-faults.pcap.gz"),
            &capture("psx3xx-faults.jsonl"),
            "--report-dir",
            &d("check"),
        ],
        1,
    );
    vec![
        Page {
            file: dir.join("pass/conform.html"),
            must: &[
                "<section id=\"summary\">",
                "<h2 id=\"cases-psd4xx\">",
                "<svg class=\"plot\"",
                "<g class=\"axis x\"",
                "<g class=\"axis y\"",
                "<g class=\"legend\">",
                ">time (ms)</text>",
                ">position (increments)</text>",
                ">speed (rpm)</text>",
                "<h2>Requirement coverage</h2>",
            ],
            must_not: &["failure-marker", "class=\"fail-list\""],
        },
        Page {
            file: dir.join("fail/conform.html"),
            must: &[
                "<section id=\"summary\">",
                "<ol class=\"fail-list\">",
                "<details id=\"psd4xx-position-loop-up\" open=\"\">",
                "<svg class=\"plot\"",
                "<g class=\"failure-marker\">",
                ">position (increments)</text>",
            ],
            must_not: &[],
        },
        Page {
            file: dir.join("interrupted/conform.html"),
            must: &[
                "<section id=\"summary\">",
                "interrupted: the run was stopped before its end",
                "<span class=\"not-run\">not-run</span>",
            ],
            must_not: &[],
        },
        Page {
            file: dir.join("fuzz/fuzz.html"),
            must: &[
                "<section id=\"summary\">",
                "<h2>Fuzzing</h2>",
                "<ol class=\"fail-list\">",
            ],
            must_not: &[],
        },
        Page {
            file: dir.join("check/check.html"),
            must: &[
                "<table id=\"summary\">",
                "<h3 id=\"violations-0\">",
                "<svg class=\"timeline\"",
                "<g class=\"axis x\"",
                "<g class=\"legend\">",
                "Drive is running</text>",
                "<line class=\"violation\"",
            ],
            must_not: &[],
        },
    ]
}

/// A Chromium run: the process, and the files its stdout and stderr go to (a pipe would
/// fill with the DOM before the process ends).
struct Load {
    child: Child,
    out: PathBuf,
    err: PathBuf,
}

/// Starts Chromium on `file` with its own profile and output files named by `tag` in `dir`.
fn load(chromium: &Path, file: &Path, dir: &Path, tag: &str) -> Load {
    let out = dir.join(format!("{tag}.dom"));
    let err = dir.join(format!("{tag}.log"));
    let child = Command::new(chromium)
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--disable-extensions",
            "--enable-logging=stderr",
            "--v=0",
            "--dump-dom",
        ])
        .arg(format!(
            "--user-data-dir={}",
            dir.join(format!("{tag}.profile")).display()
        ))
        .arg(format!("file://{}", file.display()))
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out).unwrap())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .expect("start chromium");
    Load { child, out, err }
}

/// Waits for a Chromium run (killed past [`LOAD_LIMIT`]); the DOM it printed and its console
/// lines, or why it gave none.
fn finish(mut run: Load, start: Instant) -> Result<(String, Vec<String>), String> {
    let status = loop {
        if let Some(status) = run.child.try_wait().unwrap() {
            break status;
        }
        if start.elapsed() > LOAD_LIMIT {
            let _ = run.child.kill();
            let _ = run.child.wait();
            return Err(format!("no answer within {LOAD_LIMIT:?}"));
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let stderr = std::fs::read_to_string(&run.err).unwrap_or_default();
    if !status.success() {
        return Err(format!("exit {:?}: {stderr}", status.code()));
    }
    let console = stderr
        .lines()
        .filter(|l| l.contains(":CONSOLE"))
        .map(str::to_owned)
        .collect();
    let dom = std::fs::read_to_string(&run.out).map_err(|e| e.to_string())?;
    Ok((dom, console))
}

#[test]
fn every_html_report_loads_in_headless_chromium_without_console_errors() {
    let Some(chromium) = chromium() else {
        let required = std::env::var_os("DRIVESPEC_REQUIRE_CHROMIUM").is_some();
        assert!(
            !required,
            "DRIVESPEC_REQUIRE_CHROMIUM is set but no Chromium was found (apt-get install chromium)"
        );
        eprintln!(
            "skipped: no Chromium on PATH (apt-get install chromium, or set DRIVESPEC_CHROMIUM); the HTML reports were not loaded in a browser"
        );
        return;
    };
    let dir = temp_dir("html", "chromium");
    let mut pages = reports(&dir);
    let broken = dir.join("broken.html");
    std::fs::write(
        &broken,
        "<!DOCTYPE html><html><body><p id=\"x\">x</p><script>console.error(\"broken on purpose\");missing();</script></body></html>",
    )
    .unwrap();
    pages.push(Page {
        file: broken,
        must: &["<p id=\"x\">"],
        must_not: &[],
    });
    let start = Instant::now();
    let runs: Vec<Load> = pages
        .iter()
        .enumerate()
        .map(|(i, p)| load(&chromium, &p.file, &dir, &format!("page-{i}")))
        .collect();
    let results: Vec<Result<(String, Vec<String>), String>> =
        runs.into_iter().map(|r| finish(r, start)).collect();
    let mut problems = Vec::new();
    for (page, result) in pages.iter().zip(&results) {
        let name = page.file.strip_prefix(&dir).unwrap().display().to_string();
        let (dom, console) = match result {
            Ok(r) => r,
            Err(why) => {
                problems.push(format!("{name}: Chromium failed: {why}"));
                continue;
            }
        };
        if name == "broken.html" {
            // The detection itself: both messages must be seen.
            let seen = console.iter().any(|l| l.contains("broken on purpose"))
                && console.iter().any(|l| l.contains("missing is not defined"));
            if !seen {
                problems.push(format!(
                    "{name}: the console errors of the test page were not seen: {console:?}"
                ));
            }
            continue;
        }
        for line in console {
            problems.push(format!("{name}: console: {line}"));
        }
        if !dom.trim_end().ends_with("</html>") {
            problems.push(format!("{name}: the DOM is not a whole page"));
        }
        for m in page.must {
            if !dom.contains(m) {
                problems.push(format!("{name}: the page has no {m}"));
            }
        }
        for m in page.must_not {
            if dom.contains(m) {
                problems.push(format!("{name}: the page has {m}"));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    let _ = std::fs::remove_dir_all(&dir);
}
