//! Hostile inputs on the real binary: closed or full standard output, huge patterns,
//! oversized expectations, spec files that are devices or FIFOs. Each ends with its exit code
//! and one clear line, never a panic or a hang.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run, temp_dir};
use std::io::Read;
#[cfg(unix)]
use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::process::{Command, Stdio};

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// Runs `args` with stdout read for `keep` bytes and then closed; the exit code and stderr.
fn run_closing_stdout(args: &[&str], keep: usize) -> (i32, String) {
    let mut child = Command::new(BIN)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = child.stdout.take().unwrap();
    let mut buf = vec![0u8; keep];
    out.read_exact(&mut buf).unwrap();
    drop(out);
    let result = child.wait_with_output().unwrap();
    (
        result.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&result.stderr).into_owned(),
    )
}

/// Runs `args` with stdout on `/dev/full`; the exit code and stderr.
fn run_into_full_disk(args: &[&str]) -> (i32, String) {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let result = Command::new(BIN)
        .args(args)
        .stdin(Stdio::null())
        .stdout(full)
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    (
        result.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&result.stderr).into_owned(),
    )
}

#[test]
fn a_reader_that_goes_away_ends_the_command_quietly() {
    // Each prints more than a pipe holds, so it writes after the reader has gone.
    for args in [
        &["conform", "all", "--list"][..],
        &["--format", "json", "spec", "requirements", "psd4xx"][..],
    ] {
        let (code, stderr) = run_closing_stdout(args, 1);
        assert_eq!(code, 0, "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{args:?}: {stderr}");
    }
}

#[cfg(target_os = "linux")]
#[test]
fn a_full_disk_is_one_error_line_and_exit_2() {
    for args in [
        &["decode", "hpd", "7E", "80", "01", "54", "D5"][..],
        &["conform", "hpd", "--list"][..],
        &["spec", "check"][..],
    ] {
        let (code, stderr) = run_into_full_disk(args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert_eq!(
            stderr,
            "drivespec: cannot write to standard output: No space left on device (os error 28)\n",
            "{args:?}"
        );
    }
}

#[test]
fn a_huge_case_pattern_is_bad_usage_quoting_its_start() {
    let stars = "*".repeat(100_000);
    for flag in ["--case", "--skip"] {
        let (code, _, stderr) = run(BIN, &["conform", "hpd", "--list", flag, &stars]);
        assert_eq!(code, 2, "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.contains("(100000 characters)"), "{stderr}");
        assert!(stderr.len() < 200, "{stderr}");
    }
}

#[test]
fn an_oversized_expectations_reason_is_refused() {
    let dir = temp_dir("hostile", "expect");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("expect.toml");
    let reason = "x".repeat(1_000_000);
    std::fs::write(
        &file,
        format!("[[failure]]\ncase = \"hpd/frame/*\"\nreason = \"{reason}\"\n"),
    )
    .unwrap();
    let (code, _, stderr) = run(
        BIN,
        &[
            "conform",
            "hpd",
            "--list",
            "--expect",
            file.to_str().unwrap(),
        ],
    );
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 2, "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("longer than 1000 characters"), "{stderr}");
}

fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            copy_tree(&p, &to.join(e.file_name()));
        } else {
            std::fs::copy(&p, to.join(e.file_name())).unwrap();
        }
    }
}

/// A copy of the workspace's spec with `name` in the HPD folder made by `make`.
fn spec_with(name: &str, make: impl Fn(&Path)) -> std::path::PathBuf {
    let dir = temp_dir("hostile", name);
    copy_tree(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("../../spec"),
        &dir,
    );
    make(&dir.join("hpd").join(name));
    dir
}

#[cfg(unix)]
#[test]
fn spec_files_that_never_end_are_refused() {
    let zero = spec_with("zero.toml", |p| {
        std::os::unix::fs::symlink("/dev/zero", p).unwrap()
    });
    let fifo = spec_with("fifo.toml", |p| {
        assert!(Command::new("mkfifo").arg(p).status().unwrap().success())
    });
    for dir in [zero, fifo] {
        let (code, stdout, stderr) = run(BIN, &["--spec", dir.to_str().unwrap(), "spec", "check"]);
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(code, 1, "{stdout}{stderr}");
        assert!(stdout.contains("not a regular file"), "{stdout}");
    }
}

#[test]
fn a_folder_named_like_a_spec_file_is_refused() {
    let dir = spec_with("extra.toml", |p| std::fs::create_dir(p).unwrap());
    let (code, stdout, stderr) = run(BIN, &["--spec", dir.to_str().unwrap(), "spec", "check"]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 1, "{stdout}{stderr}");
    assert!(
        stdout.contains("a folder named like a spec file"),
        "{stdout}"
    );
}

#[test]
fn a_bad_value_says_what_is_wrong_in_one_line() {
    for (args, want) in [
        (
            &["encode", "hpd", "bit", "--addr", "0", "b99.14=2"][..],
            "drivespec: value \"2\": a bit is 0 or 1\n",
        ),
        (
            &["encode", "hpd", "write", "--addr", "0", "Pr33=1e308"][..],
            "drivespec: value \"1e308\": too large for any parameter\n",
        ),
    ] {
        let (code, _, stderr) = run(BIN, args);
        assert_eq!(code, 2, "{args:?}: {stderr}");
        assert_eq!(stderr, want, "{args:?}");
    }
}

#[test]
fn a_huge_token_is_quoted_by_its_start_only() {
    let dir = temp_dir("hostile", "token");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("program.txt");
    std::fs::write(&file, "A".repeat(1_000_000)).unwrap();
    let (code, _, stderr) = run(BIN, &["plc", "hpd", "asm", file.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 2, "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.contains("(1000000 characters)"), "{stderr}");
    assert!(stderr.len() < 200, "{stderr}");
}

#[test]
fn spec_scales_that_are_not_finite_or_zero_are_refused() {
    for bad in ["nan", "inf", "0.0"] {
        let dir = spec_with(&format!("scale-{bad}"), |_| {});
        let file = dir.join("hpd/parameters.toml");
        let text = std::fs::read_to_string(&file).unwrap();
        std::fs::write(
            &file,
            text.replacen("scale = 0.1", &format!("scale = {bad}"), 1),
        )
        .unwrap();
        let (code, stdout, stderr) = run(BIN, &["--spec", dir.to_str().unwrap(), "spec", "check"]);
        let _ = std::fs::remove_dir_all(&dir);
        assert_eq!(code, 1, "{bad}: {stdout}{stderr}");
        assert!(
            stdout.contains("is not a finite number other than 0"),
            "{bad}: {stdout}"
        );
    }
}

#[test]
fn spec_empty_ranges_and_circular_priorities_are_refused() {
    let edits: [(&str, &str, &str, &str, &str); 2] = [
        (
            "empty-range",
            "hpd/parameters.toml",
            "range = [[-10000, 10000]]",
            "range = []",
            "a range needs at least one [min, max] interval",
        ),
        (
            "priority-circle",
            "psd4xx/bits.toml",
            "priority_over = [10]",
            "priority_over = [0]",
            "priority_over goes round in a circle (bit 0 over 0)",
        ),
    ];
    for (name, file, from, to, says) in edits {
        let dir = spec_with(name, |_| {});
        let path = dir.join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains(from), "{name}");
        std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
        let (code, stdout, stderr) = run(BIN, &["--spec", dir.to_str().unwrap(), "spec", "check"]);
        let _ = std::fs::remove_dir_all(&dir);
        assert!(code == 1 || code == 2, "{name}: {code} {stdout}{stderr}");
        assert!(
            stdout.contains(says) || stderr.contains(says),
            "{name}: {stdout}{stderr}"
        );
    }
}

#[cfg(unix)]
#[test]
fn report_paths_follow_symlinks_and_never_replace_a_device() {
    let dir = temp_dir("hostile", "reports");
    std::fs::create_dir_all(&dir).unwrap();
    let real = dir.join("real.json");
    let link = dir.join("link.json");
    std::fs::write(&real, "old").unwrap();
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let case = [
        "conform",
        "hpd",
        "--case",
        "hpd/frame/read-parameter",
        "--quiet",
    ];
    let with = |extra: &[&str]| {
        let mut args: Vec<&str> = case.to_vec();
        args.extend_from_slice(extra);
        run(BIN, &args)
    };
    let d = dir.to_str().unwrap();
    let (code, _, stderr) = with(&["--report-dir", d, "--json", link.to_str().unwrap()]);
    assert_eq!(code, 0, "{stderr}");
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert!(std::fs::read_to_string(&real)
        .unwrap()
        .contains("drivespec-conform/1"));
    if Path::new("/dev/full").exists() {
        let (code, _, stderr) = with(&["--report-dir", d, "--json", "/dev/full"]);
        assert_eq!(code, 2, "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(std::fs::metadata("/dev/full")
            .unwrap()
            .file_type()
            .is_char_device());
    }
    let names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(names.is_empty(), "temporary files left: {names:?}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_unwritable_report_folder_is_refused_before_the_run() {
    let (code, stdout, stderr) = run(
        BIN,
        &[
            "conform",
            "all",
            "--quiet",
            "--report-dir",
            "/proc/drivespec/none",
        ],
    );
    assert_eq!(code, 2, "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.starts_with("drivespec: cannot write /proc/drivespec/none/"),
        "{stderr}"
    );
    assert!(!stdout.contains("passed"), "the run went ahead: {stdout}");
}

/// Runs `args` under a Python wrapper that reports the peak resident memory of the run (KB).
fn run_measured(args: &[&str]) -> (i32, String, u64) {
    const WRAP: &str = "import resource, subprocess, sys\n\
        r = subprocess.run(sys.argv[1:], stdout=subprocess.PIPE)\n\
        sys.stdout.buffer.write(r.stdout)\n\
        print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, file=sys.stderr)\n\
        sys.exit(r.returncode)\n";
    let mut all = vec!["-c", WRAP, BIN];
    all.extend_from_slice(args);
    let out = Command::new("python3").args(&all).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let kb = stderr
        .lines()
        .last()
        .and_then(|l| l.trim().parse().ok())
        .unwrap_or(u64::MAX);
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        kb,
    )
}

#[cfg(unix)]
#[test]
fn a_device_flooding_the_line_fails_with_bounded_evidence_and_memory() {
    let (code, stdout, kb, json) = conform_through("flooding_hpd_relay.py", "hpd", "hpd/frame/*");
    assert_eq!(code, 1, "{stdout}");
    assert!(kb < 200_000, "peak memory {kb} KB");
    assert!(
        json.len() < 20_000_000,
        "JSON report of {} bytes",
        json.len()
    );
    assert!(
        json.contains("bytes)"),
        "no shortened evidence in the report"
    );
}

#[cfg(unix)]
#[test]
fn a_reply_line_without_end_is_cut_at_the_line_limit() {
    let (code, stdout, kb, json) =
        conform_through("endless_line_relay.py", "psd4xx", "psd4xx/pkw/read/1");
    assert_eq!(code, 1, "{stdout}");
    assert!(kb < 200_000, "peak memory {kb} KB");
    assert!(json.contains("no line end within 4096 bytes"), "{json}");
}

/// `conform FAMILY --case CASE` against the simulator behind the hostile relay `script`
/// (in `tests/`), measured: exit code, stdout, peak memory (KB) and the JSON report.
fn conform_through(script: &str, family: &str, case: &str) -> (i32, String, u64, String) {
    let relay = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join(script);
    let dut = format!(
        "exec:python3 {} {BIN} sim {family} --stdio",
        relay.display()
    );
    let dir = temp_dir("hostile", script);
    let (code, stdout, kb) = run_measured(&[
        "conform",
        family,
        "--quiet",
        "--dut",
        &dut,
        "--case",
        case,
        "--report-dir",
        dir.to_str().unwrap(),
    ]);
    let json = std::fs::read_to_string(dir.join("conform.json")).unwrap_or_default();
    let _ = std::fs::remove_dir_all(&dir);
    (code, stdout, kb, json)
}

#[test]
fn a_capture_full_of_one_fault_lists_a_bounded_number() {
    let dir = temp_dir("hostile", "zeros");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("zeros.pcap");
    // pcap header (Ethernet), then 500,000 empty records.
    let mut bytes = Vec::new();
    for v in [0xa1b2_c3d4u32, 0x0004_0002, 0, 0, 65535, 1] {
        bytes.extend_from_slice(&v.to_le_bytes());
    }
    bytes.resize(bytes.len() + 500_000 * 16, 0);
    std::fs::write(&file, &bytes).unwrap();
    let (code, stdout, kb) = run_measured(&["check", file.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 1, "{stdout}");
    assert!(kb < 200_000, "peak memory {kb} KB");
    assert!(
        stdout.contains("… and 499900 more of PN-FRAME-001"),
        "{stdout}"
    );
    assert!(stdout.len() < 100_000, "{} bytes of output", stdout.len());
}

#[cfg(unix)]
#[test]
fn a_recording_through_a_pipe_or_fifo_gets_the_verdict_of_the_file() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../corpus/captures/hpd-faults.txt");
    let (code, stdout, _) = run(BIN, &["check", file.to_str().unwrap()]);
    assert_eq!(code, 1, "{stdout}");
    let text = std::fs::read_to_string(&file).unwrap();
    let (piped, piped_out, stderr) =
        drivespec_testkit::run_with(BIN, &["check", "-"], Some(&text), &[]);
    assert_eq!(piped, 1, "{piped_out}{stderr}");
    let tail = |s: &str| s.lines().skip(1).collect::<Vec<_>>().join("\n");
    assert_eq!(tail(&piped_out), tail(&stdout));
    let dir = temp_dir("hostile", "fifo");
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("capture.txt");
    assert!(Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .unwrap()
        .success());
    let writer = {
        let (fifo, text) = (fifo.clone(), text.clone());
        std::thread::spawn(move || std::fs::write(fifo, text))
    };
    let (code, fifo_out, stderr) = run(BIN, &["check", fifo.to_str().unwrap()]);
    writer.join().unwrap().unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 1, "{fifo_out}{stderr}");
    assert_eq!(tail(&fifo_out), tail(&stdout));
}

#[cfg(unix)]
#[test]
fn inputs_that_never_end_stop_at_their_limit() {
    for args in [
        &["decode", "hpd", "--stream", "/dev/zero"][..],
        &["decode", "psx3xx", "--detect-order", "/dev/zero", "--in"][..],
        &["plc", "hpd", "asm", "/dev/zero"][..],
        &[
            "sim-run",
            "psd4xx",
            "--model",
            "PSD426",
            "--script",
            "/dev/zero",
        ][..],
    ] {
        let (code, stdout, kb) = run_measured(args);
        assert_eq!(code, 2, "{args:?}: {stdout}");
        assert!(kb < 200_000, "{args:?}: peak memory {kb} KB");
    }
}

#[test]
fn a_script_time_past_the_longest_run_is_refused_naming_the_line() {
    let script = "0 ms: control 0x14 target 2000\n1000000000 s: end\n";
    let (code, _, stderr) = drivespec_testkit::run_with(
        BIN,
        &["sim-run", "psd4xx", "--model", "PSD426", "--script", "-"],
        Some(script),
        &[],
    );
    assert_eq!(code, 2, "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("line 2: time 1000000000000000 µs is past the longest script, 3600 s"),
        "{stderr}"
    );
}

#[cfg(unix)]
#[test]
fn a_device_that_never_answers_stops_the_run_as_a_set_up_error() {
    let dir = temp_dir("hostile", "mute");
    let (code, _, stderr) = run(
        BIN,
        &[
            "conform",
            "hpd",
            "--quiet",
            "--dut",
            "exec:sleep 600",
            "--report-dir",
            dir.to_str().unwrap(),
        ],
    );
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 2, "{stderr}");
    // `--quiet` keeps the failures: each of the ten says what was expected and that silence
    // came; the last line is the set-up error.
    assert_eq!(stderr.matches("got:     silence").count(), 10, "{stderr}");
    assert!(
        stderr.ends_with("\ndrivespec: the device under test answered nothing in the first 10 cases (exec:sleep 600): check --dut, the bit rate and --address\n"),
        "{stderr}"
    );
}

#[test]
fn an_empty_recording_is_nothing_to_check() {
    let dir = temp_dir("hostile", "empty");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("empty.pcap");
    std::fs::write(&file, b"").unwrap();
    let (code, stdout, stderr) = run(BIN, &["check", file.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 2, "{stdout}{stderr}");
    assert!(
        stderr.ends_with("empty.pcap: empty: nothing to check\n"),
        "{stderr}"
    );
    assert!(!stdout.contains("PASS"), "{stdout}");
}

#[test]
fn a_byte_order_mark_is_read_past_and_unknown_text_is_not_taken_for_hpd_bytes() {
    let dir = temp_dir("hostile", "text-kinds");
    std::fs::create_dir_all(&dir).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../corpus/captures");
    let plain = root.join("psx3xx-faults.jsonl");
    let mut marked = vec![0xef, 0xbb, 0xbf];
    marked.extend(std::fs::read(&plain).unwrap());
    let bom = dir.join("bom.jsonl");
    std::fs::write(&bom, marked).unwrap();
    let violations = |path: &Path| {
        let (code, out, err) = run(BIN, &["--format", "json", "check", path.to_str().unwrap()]);
        assert_eq!(code, 1, "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        v["violation_count"].as_u64().unwrap()
    };
    assert_eq!(violations(&bom), violations(&plain));

    for (name, bytes) in [
        ("notes.txt", b"hello, this is no recording\n".to_vec()),
        (
            "utf16.csv",
            vec![0xff, 0xfe, b't', 0, b'i', 0, b'm', 0, b'e', 0],
        ),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let (code, _, err) = run(BIN, &["check", path.to_str().unwrap()]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(
            err.contains("cannot tell what this recording is"),
            "{name}: {err}"
        );
        assert_eq!(err.lines().count(), 1, "{name}: {err}");
    }
    std::fs::remove_dir_all(dir).unwrap();
}

/// A recording from `corpus/captures`.
fn corpus(name: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../corpus/captures")
        .join(name)
}

#[test]
fn gzip_with_trailing_garbage_is_checked_up_to_the_garbage_and_says_where_it_starts() {
    let dir = temp_dir("hostile", "gzip-tail");
    std::fs::create_dir_all(&dir).unwrap();
    let gz = std::fs::read(corpus("psd4xx-faults.pcap.gz")).unwrap();
    let file = dir.join("tail.pcap.gz");
    let mut bytes = gz.clone();
    bytes.extend_from_slice(b"trailing garbage");
    std::fs::write(&file, &bytes).unwrap();
    let (clean_code, clean, _) = run(
        BIN,
        &["check", corpus("psd4xx-faults.pcap.gz").to_str().unwrap()],
    );
    let (code, out, err) = run(BIN, &["check", file.to_str().unwrap()]);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(clean_code, 1, "{clean}");
    assert_eq!(code, 2, "{out}{err}");
    let said = format!(
        "the 1 gzip member(s) before compressed byte {} were read; the bytes from there on are not gzip",
        gz.len()
    );
    assert!(err.contains(&said), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    // Every violation of the readable part is still listed.
    let listed = |text: &str| {
        text.lines()
            .filter(|l| l.contains("PSD-") || l.contains("PN-"))
            .count()
    };
    assert_eq!(listed(&out), listed(&clean), "{out}");
}

#[test]
fn a_log_of_mostly_unreadable_lines_is_not_judged() {
    let dir = temp_dir("hostile", "unreadable-lines");
    std::fs::create_dir_all(&dir).unwrap();
    let log = std::fs::read_to_string(corpus("hpd-clean.txt")).unwrap();
    let lines = log.lines().count();
    let with = |junk: usize| {
        let mut text = log.clone();
        for i in 0..junk {
            text.push_str(&format!("not a serial line {i}\n"));
        }
        let file = dir.join(format!("junk-{junk}.txt"));
        std::fs::write(&file, text).unwrap();
        run(BIN, &["check", "--format", "text", file.to_str().unwrap()])
    };
    // A few unreadable lines: judged, and the share is said.
    let (code, out, err) = with(3);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("3 of "), "{out}");
    assert!(
        out.contains("line(s)") && out.contains("were unreadable and skipped"),
        "{out}"
    );
    // More unreadable lines than readable ones: not a pass.
    let (code, out, err) = with(lines * 2);
    let _ = std::fs::remove_dir_all(&dir);
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("more than half: not judged"), "{err}");
}
