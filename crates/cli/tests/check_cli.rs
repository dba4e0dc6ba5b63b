//! `drivespec check` as users run it on the recordings under `corpus/captures/`: exit codes,
//! detection, the report formats, `--max-violations`, a truncated file,
//! folders checked in parallel and NDJSON.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run_with, temp_dir, CI};
use std::path::PathBuf;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

fn capture(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../corpus/captures")
        .join(name)
        .display()
        .to_string()
}

#[test]
fn clean_recordings_of_every_family_exit_0_and_say_what_was_detected() {
    for (file, family, detected) in [
        ("hpd-clean.socat", "[hpd]", "socat"),
        ("psd4xx-clean.pcap.gz", "[psd4xx]", "gzip-compressed pcap"),
        ("psx3xx-clean.csv", "[psx3xx]", "IO-Link CSV"),
    ] {
        let (code, out, err) = run_with(BIN, &["check", &capture(file)], None, CI);
        assert_eq!(code, 0, "{file}: {out}{err}");
        assert!(out.contains(family), "{out}");
        assert!(out.contains(detected), "{out}");
        assert!(out.contains("result: PASS"), "{out}");
    }
}

#[test]
fn violations_exit_1_with_requirement_place_and_evidence() {
    let (code, out, _) = run_with(
        BIN,
        &["check", "--baud", "8", &capture("hpd-faults.txt")],
        None,
        CI,
    );
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("HPD-SERIAL-012"), "{out}");
    assert!(out.contains("line "), "{out}");
    assert!(out.contains("bytes: 7E"), "{out}");
    assert!(out.contains("result: FAIL"), "{out}");
}

#[test]
fn json_report_follows_the_schema_and_counts_beyond_the_listing_cap() {
    let (code, out, _) = run_with(
        BIN,
        &[
            "check",
            "--report",
            "json",
            "--max-violations",
            "1",
            &capture("psd4xx-faults.pcap.gz"),
        ],
        None,
        CI,
    );
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["schema"], "drivespec-check/1");
    let r = &v["reports"][0];
    assert_eq!(r["family"], "psd4xx");
    assert_eq!(r["violations"].as_array().unwrap().len(), 1);
    assert_eq!(r["violation_count"], 5);
    assert_eq!(r["drives"][0]["found_by"], "connect");
    let first = &r["violations"][0];
    for key in [
        "requirement",
        "level",
        "text",
        "source",
        "subject",
        "where",
        "message",
        "evidence",
    ] {
        assert!(first.get(key).is_some(), "{key} missing: {first}");
    }
    assert!(first["where"]["frame"].is_u64());
    assert_eq!(r["requirements"]["PSD-PKW-034"]["violations"], 1);
}

#[test]
fn the_global_json_format_selects_the_json_report() {
    let (code, out, _) = run_with(
        BIN,
        &["--format", "json", "check", &capture("psx3xx-clean.jsonl")],
        None,
        CI,
    );
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["reports"][0]["family"], "psx3xx");
}

#[test]
fn junit_and_html_reports_and_the_report_dir() {
    let (code, out, _) = run_with(
        BIN,
        &[
            "check",
            "--report",
            "junit",
            &capture("psx3xx-faults.jsonl"),
        ],
        None,
        CI,
    );
    assert_eq!(code, 1);
    assert!(out.starts_with("<?xml"), "{out}");
    assert!(out.contains("name=\"PSX-GUARD-126-SUPPRESS\""), "{out}");
    assert!(out.contains("<failure"), "{out}");
    let dir = std::env::temp_dir().join(format!("drivespec-check-cli-{}", std::process::id()));
    let (code, out, _) = run_with(
        BIN,
        &[
            "check",
            "--report",
            "html",
            "--report-dir",
            dir.to_str().unwrap(),
            &capture("psd4xx-clean.pcap.gz"),
        ],
        None,
        CI,
    );
    assert_eq!(code, 0);
    assert!(
        out.contains("<svg"),
        "the HTML report plots the drive's timeline"
    );
    for f in ["check.txt", "check.json", "check.xml", "check.html"] {
        assert!(dir.join(f).is_file(), "{f}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_truncated_capture_is_reported_up_to_the_error_and_exits_2() {
    let (code, out, err) = run_with(
        BIN,
        &["check", &capture("psd4xx-truncated.pcap.gz")],
        None,
        CI,
    );
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("truncated record at byte"), "{err}");
    assert!(
        out.contains("PSD-PKW-034"),
        "what came before the error is checked: {out}"
    );
}

#[test]
fn options_that_do_not_fit_the_recording_are_bad_usage() {
    let (code, _, err) = run_with(
        BIN,
        &["check", "--device", "psx3xx", &capture("hpd-clean.txt")],
        None,
        CI,
    );
    assert_eq!(code, 2);
    assert!(err.contains("--device psx3xx"), "{err}");
    let (code, _, err) = run_with(
        BIN,
        &["check", "--baud", "12345", &capture("hpd-clean.txt")],
        None,
        CI,
    );
    assert_eq!(code, 2);
    assert!(err.contains("--baud"), "{err}");
    let (code, _, _) = run_with(BIN, &["check", "/nonexistent/file.pcap"], None, CI);
    assert_eq!(code, 2);
    let (code, _, _) = run_with(BIN, &["check"], None, CI);
    assert_eq!(code, 2);
}

#[test]
fn frame_id_and_offset_locate_the_drive_without_a_connect() {
    let (code, out, _) = run_with(
        BIN,
        &[
            "check",
            "--frame-id",
            "0x8001,0x8000",
            "--offset",
            "0",
            &capture("psd4xx-search.pcap.gz"),
        ],
        None,
        CI,
    );
    assert_eq!(code, 1);
    assert!(out.contains("found by options"), "{out}");
    assert!(out.contains("PSD-STS-5-SET-1"), "{out}");
}

#[test]
fn a_required_family_whose_checks_did_not_run_fails() {
    let file = capture("psd4xx-clean.pcap.gz");
    let base = ["check", "--module-ident", "0x1234", "--no-search"];
    let (code, out, _) = run_with(BIN, &[&base[..], &[&file]].concat(), None, CI);
    assert_eq!(code, 0, "{out}");
    assert!(
        out.contains("result: PASS — PROFINET: pass; PSD4xx: no drive found"),
        "{out}"
    );
    for extra in [["--require", "psd4xx"], ["--device", "psd4xx"]] {
        let args = [&base[..], &extra[..], &[&file]].concat();
        let (code, out, _) = run_with(BIN, &args, None, CI);
        assert_eq!(code, 1, "{extra:?}: {out}");
        assert!(
            out.contains(
                "result: FAIL — PROFINET: pass; PSD4xx: no drive found (required: psd4xx)"
            ),
            "{out}"
        );
    }
}

/// A folder of three recordings (one in a subfolder) and a file that is not a recording.
fn recordings_folder(name: &str) -> PathBuf {
    let dir = temp_dir("check", name);
    std::fs::create_dir_all(dir.join("line")).unwrap();
    for (from, to) in [
        ("psd4xx-faults.pcap.gz", "b-plc.pcap.gz"),
        ("psx3xx-faults.jsonl", "a-master.jsonl"),
        ("hpd-faults.txt", "line/c-hpd.txt"),
    ] {
        std::fs::copy(capture(from), dir.join(to)).unwrap();
    }
    std::fs::write(dir.join("README.md"), "not a recording").unwrap();
    dir
}

#[test]
fn a_folder_gives_the_same_merged_report_with_one_or_two_jobs() {
    let dir = recordings_folder("jobs");
    let d = dir.display().to_string();
    let (code1, one, err1) = run_with(BIN, &["check", "-j1", "--report", "json", &d], None, CI);
    let (code2, two, err2) = run_with(BIN, &["check", "-j", "2", "--report", "json", &d], None, CI);
    assert_eq!((code1, code2), (1, 1), "{err1}{err2}");
    assert_eq!(one, two, "the report does not depend on the number of jobs");
    let v: serde_json::Value = serde_json::from_str(&one).unwrap();
    let files: Vec<&str> = v["reports"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["file"].as_str().unwrap())
        .collect();
    assert_eq!(files.len(), 3, "{files:?}");
    for (file, ending) in files
        .iter()
        .zip(["a-master.jsonl", "b-plc.pcap.gz", "c-hpd.txt"])
    {
        assert!(file.ends_with(ending), "sorted by path: {files:?}");
    }
    let families: Vec<&str> = v["reports"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["family"].as_str().unwrap())
        .collect();
    assert_eq!(families, ["psx3xx", "psd4xx", "hpd"]);
    assert_eq!(v["failed"], 3);
    let (code, text, _) = run_with(BIN, &["check", "-j2", &d], None, CI);
    assert_eq!(code, 1);
    assert!(
        text.ends_with("3 files: 3 failed, 0 unreadable\n"),
        "{text}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_unreadable_file_among_good_ones_exits_2_names_it_and_reports_the_others() {
    let dir = temp_dir("check", "unreadable");
    std::fs::create_dir_all(&dir).unwrap();
    let missing = dir.join("missing.pcap").display().to_string();
    let good = [capture("hpd-clean.socat"), capture("psx3xx-clean.csv")];
    let (code, out, err) = run_with(
        BIN,
        &[
            "check", "-j2", "--report", "json", &good[0], &missing, &good[1],
        ],
        None,
        CI,
    );
    assert_eq!(code, 2, "{out}{err}");
    assert!(err.contains("missing.pcap"), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let reports = v["reports"].as_array().unwrap();
    assert_eq!(reports.len(), 2, "{out}");
    assert!(reports.iter().all(|r| r["verdict"] == "pass"), "{out}");
    let (code, out, _) = run_with(
        BIN,
        &["check", "--report", "ndjson", &good[0], &missing],
        None,
        CI,
    );
    assert_eq!(code, 2);
    assert!(
        out.lines()
            .any(|l| l.contains("\"unreadable\"") && l.contains("missing.pcap")),
        "{out}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn ndjson_writes_one_finding_per_line_with_the_schema_and_a_summary_last() {
    let dir = recordings_folder("ndjson");
    let d = dir.display().to_string();
    let (code, out, err) = run_with(BIN, &["check", "--report", "ndjson", &d], None, CI);
    assert_eq!(code, 1, "{err}");
    let lines: Vec<serde_json::Value> = out
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect();
    assert!(lines
        .iter()
        .all(|l| l["schema"] == "drivespec-check-finding/1"));
    let (_, json, _) = run_with(BIN, &["check", "--report", "json", &d], None, CI);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let listed: usize = v["reports"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["violations"].as_array().unwrap().len())
        .sum();
    let findings: Vec<&serde_json::Value> =
        lines.iter().filter(|l| l["kind"] == "finding").collect();
    assert!(listed > 0);
    assert_eq!(findings.len(), listed);
    let first = findings[0];
    for key in [
        "file",
        "requirement",
        "level",
        "message",
        "evidence",
        "event",
    ] {
        assert!(first.get(key).is_some(), "{key} missing: {first}");
    }
    assert!(lines
        .iter()
        .any(|l| l["frame"].is_u64() && l["time"].is_u64()));
    let summary = lines.last().unwrap();
    assert_eq!(summary["kind"], "summary");
    assert_eq!(summary["files"], 3);
    assert_eq!(summary["findings"], listed);
    assert_eq!(summary["violation_count"], v["violation_count"]);
    assert_eq!(lines.len(), listed + 1);
    let _ = std::fs::remove_dir_all(&dir);
}
