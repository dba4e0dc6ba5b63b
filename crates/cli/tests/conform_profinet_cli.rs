//! `drivespec conform psd4xx --dut profinet:IFACE/NAME` against `drivespec sim psd4xx
//! --profinet IFACE` in another network namespace: the whole suite runs over a veth pair on
//! real time: the run opens (identify, connect, PrmEnd, ApplicationReady), every case gets a
//! verdict, and the cases needing an injection are skipped with the reason. The cases that
//! failed for the transport (a Connect refused while an unreleased AR holds the device, a
//! watchdog) are printed with their count.
#![allow(
    clippy::expect_used,
    clippy::unwrap_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use drivespec_testkit::netns::{NetnsPair, NsChild};
use std::process::Stdio;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// The NameOfStation of the simulated device.
const NAME: &str = "psd-sim";

/// Failure messages that come from the transport, not from the device's behaviour.
const TRANSPORT: [&str; 3] = [
    "the exchange failed",
    "could not be reset",
    "no station named",
];

#[test]
#[ignore = "the whole PSD4xx suite on real time takes more than 15 minutes here; run with --run-ignored"]
fn conform_over_profinet_runs_every_case_on_the_simulated_device() {
    let Some(pair) = NetnsPair::create() else {
        return;
    };
    let mut sim = pair.a.command(BIN);
    sim.args(["sim", "psd4xx", "--profinet", &pair.a.iface, "--name", NAME]);
    let mut sim = NsChild::spawn_piped(sim);
    let on = sim.wait_line("profinet:");
    assert_eq!(on, format!("{}/{NAME}", pair.a.iface));
    let dir = std::env::temp_dir().join(format!("drivespec-pn-{}", std::process::id()));
    let mut conform = pair.b.command(BIN);
    conform
        .args(["conform", "psd4xx", "--dut"])
        .arg(format!("profinet:{}/{NAME}", pair.b.iface))
        .arg("--report-dir")
        .arg(&dir)
        .stdin(Stdio::null());
    let out = conform.output().expect("run conform");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let code = out.status.code();
    assert!(
        matches!(code, Some(0 | 1)),
        "exit {code:?} (2: setup error)\n{stderr}\n{stdout}"
    );
    let json = std::fs::read_to_string(dir.join("conform.json")).expect("conform.json");
    let _ = std::fs::remove_dir_all(&dir);
    let doc: serde_json::Value = serde_json::from_str(&json).unwrap();
    let cases = doc["cases"].as_array().unwrap();
    assert!(!cases.is_empty());
    let mut transport = Vec::new();
    for c in cases {
        let status = c["status"].as_str().unwrap();
        assert!(
            ["pass", "acceptable", "fail", "skipped"].contains(&status),
            "{c}"
        );
        let text = c.to_string();
        if status == "fail" && TRANSPORT.iter().any(|t| text.contains(t)) {
            transport.push(c["id"].as_str().unwrap().to_owned());
        }
        if status == "skipped" {
            let reason = c["skip_reason"].as_str().unwrap_or_default();
            assert!(reason.contains("UNSUPPORTED"), "{c}");
        }
    }
    println!(
        "{} case(s) of {} failed for the transport: {transport:?}",
        transport.len(),
        cases.len()
    );
    assert!(
        transport.len() < cases.len(),
        "every case failed for the transport: {transport:?}"
    );
    drop(sim);
}
