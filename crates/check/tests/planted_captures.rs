//! PSD4xx recordings written by an independent generator (`tests/planted_psd4xx.py`: scapy
//! and the bus description, no code of this project) with planted violations at known
//! frames (`corpus/planted/*.truth.json`). Checked through the same path as `drivespec
//! check`, every plant is found with its requirement at its frame (100 % recall) and
//! nothing else is reported (no false alarm); a recording without plants passes, one with
//! only should-level plants passes with warnings.
//!
//! The second test runs the generator again (when python3 with scapy is installed; with
//! `DRIVESPEC_REQUIRE_SCAPY` set a missing scapy fails instead of skipping) and compares
//! its output with the committed files byte for byte.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_check::run::{check_path, RunOptions};
use drivespec_check::{Report, Verdict};
use drivespec_spec::Spec;
use flate2::read::GzDecoder;
use serde::Deserialize;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::Command;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Truth {
    schema: String,
    capture: String,
    description: String,
    #[allow(dead_code)]
    generator: String,
    /// The scapy version that wrote it.
    scapy: String,
    #[allow(dead_code)]
    seed: u64,
    frames: u64,
    connect: bool,
    plants: Vec<Plant>,
    #[allow(dead_code)]
    probes: Vec<Probe>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Plant {
    requirement: String,
    level: String,
    /// `violation` (a listed violation) or `allowed` (an allowed state, e.g. an alarm).
    kind: String,
    what: String,
    frame: u64,
    time_us: u64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Probe {
    #[allow(dead_code)]
    what: String,
}

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../corpus/planted")
}

fn truths(dir: &Path) -> Vec<(PathBuf, Truth)> {
    let mut out: Vec<(PathBuf, Truth)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".truth.json"))
        .map(|p| {
            let t: Truth = serde_json::from_str(&std::fs::read_to_string(&p).unwrap())
                .unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (p, t)
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

fn gunzip(path: &Path) -> Vec<u8> {
    let mut out = Vec::new();
    GzDecoder::new(std::fs::File::open(path).unwrap())
        .read_to_end(&mut out)
        .unwrap();
    out
}

/// Plants not found at their frame, and findings no plant explains.
fn score(t: &Truth, r: &Report) -> (Vec<String>, Vec<String>) {
    let mut missed = Vec::new();
    for p in &t.plants {
        let found = match p.kind.as_str() {
            "violation" => r.violations.iter().any(|v| {
                v.requirement == p.requirement
                    && v.level == p.level
                    && v.at.frame == Some(p.frame)
                    && v.at.time == Some(p.time_us)
            }),
            "allowed" => r.allowed.iter().any(|a| {
                a.requirement == p.requirement
                    && a.start.frame == Some(p.frame)
                    && a.start.time == Some(p.time_us)
            }),
            k => panic!("{}: unknown kind {k}", t.capture),
        };
        if !found {
            missed.push(format!(
                "{} frame {}: {} ({})",
                p.requirement, p.frame, p.what, p.kind
            ));
        }
    }
    let false_alarms = r
        .violations
        .iter()
        .filter(|v| {
            !t.plants.iter().any(|p| {
                p.kind == "violation"
                    && p.requirement == v.requirement
                    && v.at.frame == Some(p.frame)
            })
        })
        .map(|v| format!("{} at {}: {}", v.requirement, v.at, v.message))
        .collect();
    (missed, false_alarms)
}

#[test]
fn every_plant_is_found_at_its_frame_and_nothing_else() {
    let spec = Spec::builtin().unwrap();
    let all = truths(&dir());
    assert!(all.len() >= 6, "{} truth files", all.len());
    let (mut plants, mut found, mut false_alarms) = (0usize, 0usize, Vec::new());
    let mut problems = Vec::new();
    for (_, t) in &all {
        assert_eq!(t.schema, "drivespec-planted/1");
        let path = dir().join(&t.capture);
        let r = check_path(&spec, &path, &RunOptions::default(), &mut |_| {}).unwrap();
        assert!(
            r.frames.values().sum::<u64>() > t.frames / 2,
            "{}",
            t.capture
        );
        assert_eq!(
            r.drives.len(),
            1,
            "{}: {:?} {:?}",
            t.capture,
            r.drives,
            r.notes
        );
        let want = if t.connect { "connect" } else { "search" };
        assert_eq!(r.drives[0].found_by, want, "{}", t.capture);
        assert!(
            r.scopes.iter().all(|s| s.ran),
            "{}: {:?}",
            t.capture,
            r.scopes
        );
        assert_eq!(
            r.violation_count,
            r.violations.len() as u64,
            "{}: every violation is listed",
            t.capture
        );
        let (missed, false_here) = score(t, &r);
        plants += t.plants.len();
        found += t.plants.len() - missed.len();
        if !missed.is_empty() {
            problems.push(format!("{} missed:\n  {}", t.capture, missed.join("\n  ")));
        }
        if !false_here.is_empty() {
            problems.push(format!(
                "{} false alarms:\n  {}",
                t.capture,
                false_here.join("\n  ")
            ));
        }
        false_alarms.extend(false_here);
        // No plant: PASS (exit 0); only should-level plants: PASS with warnings (exit 0).
        let want = if t.plants.iter().any(|p| p.level == "must") {
            Verdict::Fail
        } else if t.plants.iter().any(|p| p.kind == "violation") {
            Verdict::Warn
        } else {
            Verdict::Pass
        };
        assert_eq!(r.verdict, want, "{}: {}", t.capture, t.description);
    }
    eprintln!(
        "planted recordings: {} files, {found} of {plants} plants found at their frame, {} false alarm(s)",
        all.len(),
        false_alarms.len()
    );
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    assert!(plants >= 25, "{plants} plants");
}

/// The generator reads nothing of this project: it imports the standard library and
/// scapy only.
#[test]
fn the_generator_imports_only_the_standard_library_and_scapy() {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/planted_psd4xx.py");
    let text = std::fs::read_to_string(script).unwrap();
    let allowed = [
        "decimal", "gzip", "json", "os", "random", "struct", "sys", "uuid", "scapy",
    ];
    let mut imports = 0;
    for line in text.lines().map(str::trim_start) {
        let module = if let Some(rest) = line.strip_prefix("import ") {
            rest
        } else if let Some(rest) = line.strip_prefix("from ") {
            rest.split(" import").next().unwrap_or(rest)
        } else {
            continue;
        };
        let top = module.split(['.', ' ', ',']).next().unwrap_or(module);
        assert!(allowed.contains(&top), "the generator imports {module}");
        imports += 1;
    }
    assert!(imports > 5);
    assert!(!text.contains("sys.path"), "the generator changes sys.path");
    for code in ["crates/", "spec/psd4xx", "target/"] {
        assert!(!text.contains(code), "the generator names {code}");
    }
}

#[test]
fn the_generator_reproduces_the_committed_recordings() {
    let committed = truths(&dir());
    let want = committed[0].1.scapy.clone();
    let have = Command::new("python3")
        .args(["-c", "import scapy; print(scapy.__version__)"])
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_owned());
    if have.as_deref() != Some(want.as_str()) {
        let why = match have {
            Some(v) => format!("python3 has scapy {v}, the recordings were written with {want}"),
            None => "python3 with scapy is not available".to_owned(),
        };
        assert!(
            std::env::var_os("DRIVESPEC_REQUIRE_SCAPY").is_none(),
            "DRIVESPEC_REQUIRE_SCAPY is set, but {why} (pip install scapy=={want})"
        );
        eprintln!("skipped: {why} (pip install scapy=={want})");
        return;
    }
    let out = std::env::temp_dir().join(format!("drivespec-planted-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/planted_psd4xx.py");
    let run = Command::new("python3")
        .arg(&script)
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let fresh = truths(&out);
    let names = |v: &[(PathBuf, Truth)]| -> Vec<String> {
        v.iter().map(|(_, t)| t.capture.clone()).collect()
    };
    assert_eq!(names(&committed), names(&fresh));
    for ((cp, ct), (fp, _)) in committed.iter().zip(&fresh) {
        assert_eq!(
            std::fs::read(cp).unwrap(),
            std::fs::read(fp).unwrap(),
            "{} differs from the generator's",
            cp.display()
        );
        let capture = gunzip(&dir().join(&ct.capture));
        assert_eq!(
            capture,
            gunzip(&out.join(&ct.capture)),
            "{} differs from the generator's",
            ct.capture
        );
        assert!(capture.len() as u64 > ct.frames * 60);
    }
    let _ = std::fs::remove_dir_all(&out);
}
