//! `drivespec fuzz psd4xx --layer profinet` as users run it: against `drivespec sim psd4xx
//! --profinet` in another network namespace it finds nothing (exit 0); a station nobody
//! answers for is a setup error (exit 2); a device with a planted fault (it restarts after a
//! malformed DCP Identify, served from `drivespec-implementations` in the other namespace)
//! is found (exit 1), minimised to that Identify, and its replay file reproduces it. In
//! memory (`--dut sim`) it needs no namespace.
#![allow(
    clippy::expect_used,
    clippy::unwrap_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use drivespec_testkit::netns::{self, NetnsPair, NsChild};
use std::path::Path;
use std::process::Stdio;
use std::time::Duration;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");
/// The test that serves the faulty device in the other namespace.
const TEST: &str = "a_planted_fault_is_found_minimised_and_replayed";
/// The NameOfStation of the devices.
const NAME: &str = "psd-fuzzed";
/// The seed of the fault run, and the sequence in which its first malformed Identify comes
/// (the generator draws from the seed only, the same in memory and on the wire).
const FAULT_SEED: &str = "0";
const FAULT_SEQUENCES: &str = "27";

/// Runs `drivespec` in `ns` (or here) with `args`: exit code, stdout, stderr.
fn run(ns: Option<&netns::Netns>, args: &[&str]) -> (i32, String, String) {
    let mut c = match ns {
        Some(n) => n.command(BIN),
        None => std::process::Command::new(BIN),
    };
    let out = c
        .args(args)
        .stdin(Stdio::null())
        .output()
        .expect("run drivespec");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn out_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!(
        "drivespec-pnfuzz-cli-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn fuzzing_the_device_in_memory_finds_nothing() {
    let dir = out_dir("memory");
    let (code, out, err) = run(
        None,
        &[
            "fuzz",
            "psd4xx",
            "--layer",
            "profinet",
            "--dut",
            "sim",
            "--iterations",
            "20",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{err}{out}");
    assert!(out.contains("20 sequence(s)"), "{out}");
    assert!(out.contains("PROFINET layer"), "{out}");
    let (code, _, err) = run(
        None,
        &[
            "fuzz",
            "hpd",
            "--layer",
            "profinet",
            "--iterations",
            "1",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--layer profinet is for psd4xx"), "{err}");
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn fuzzing_the_simulated_device_on_a_veth_pair_finds_nothing() {
    let Some(pair) = NetnsPair::create() else {
        return;
    };
    let mut sim = pair.a.command(BIN);
    sim.args(["sim", "psd4xx", "--profinet", &pair.a.iface, "--name", NAME]);
    let mut sim = NsChild::spawn_piped(sim);
    sim.wait_line("profinet:");
    let dir = out_dir("sim");
    let dut = format!("profinet:{}/{NAME}", pair.b.iface);
    let (code, out, err) = run(
        Some(&pair.b),
        &[
            "fuzz",
            "psd4xx",
            "--layer",
            "profinet",
            "--dut",
            &dut,
            "--iterations",
            "12",
            "--seed",
            "3",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{err}{out}");
    assert!(
        out.contains("12 sequence(s)") && out.contains("0 finding(s)"),
        "{out}"
    );
    // No station of that name: a setup error, within the probe's deadlines.
    let nobody = format!("profinet:{}/nobody", pair.b.iface);
    let (code, _, err) = run(
        Some(&pair.b),
        &[
            "fuzz",
            "psd4xx",
            "--layer",
            "profinet",
            "--dut",
            &nobody,
            "--iterations",
            "1",
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("no station named \"nobody\""), "{err}");
    let _ = std::fs::remove_dir_all(dir);
    drop(sim);
}

/// The faulty device, served in the namespace the test started it in.
fn serve_faulty() {
    let iface = std::env::var("DRIVESPEC_IFACE").unwrap();
    drivespec_implementations::profinet_faults::serve_profinet(
        &iface,
        NAME,
        "restart-on-malformed-identify",
        Duration::from_secs(55),
    )
    .unwrap();
}

#[test]
fn a_planted_fault_is_found_minimised_and_replayed() {
    if netns::role().is_some() {
        serve_faulty();
        return;
    }
    let Some(pair) = NetnsPair::create() else {
        return;
    };
    let mut device = pair
        .a
        .spawn_test(TEST, "faulty", &[("DRIVESPEC_IFACE", &pair.a.iface)]);
    device.wait_line("profinet:");
    let dir = out_dir("fault");
    let dut = format!("profinet:{}/{NAME}", pair.b.iface);
    let (code, out, err) = run(
        Some(&pair.b),
        &[
            "fuzz",
            "psd4xx",
            "--layer",
            "profinet",
            "--dut",
            &dut,
            "--iterations",
            FAULT_SEQUENCES,
            "--seed",
            FAULT_SEED,
            "--quiet",
            "--out",
            dir.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 1, "{err}{out}");
    assert!(
        out.contains("hang/profinet-probe/dcp-identify in 1 step(s)"),
        "{out}"
    );
    let file = dir.join("finding-1.json");
    let text = std::fs::read_to_string(&file).unwrap();
    let replay: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(replay["layer"], "profinet", "{text}");
    assert_eq!(replay["steps"][0]["do"], "dcp-identify", "{text}");
    assert_eq!(replay["finding"]["reproduced"], true, "{text}");
    // The replay command of the report names the layer; the file alone is enough to replay
    // it (its layer is the default).
    let report = std::fs::read_to_string(dir.join("fuzz.json")).unwrap();
    assert!(
        report.contains("fuzz psd4xx --layer profinet --dut"),
        "{report}"
    );
    let (code, out, err) = run(
        Some(&pair.b),
        &[
            "fuzz",
            "psd4xx",
            "--dut",
            &dut,
            "--replay",
            file.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 1, "{err}{out}");
    assert!(
        out.contains("fails at step 0: hang/profinet-probe/dcp-identify"),
        "{out}"
    );
    let _ = std::fs::remove_dir_all(Path::new(&dir));
    drop(device);
}
