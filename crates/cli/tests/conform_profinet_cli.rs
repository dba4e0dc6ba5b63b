//! `drivespec conform psd4xx --dut profinet:IFACE/NAME` against `drivespec sim psd4xx
//! --profinet IFACE` in another network namespace: every case of the suite runs over a veth
//! pair on real time and passes; only the injections a network cannot make (turning the
//! shaft, the motor supply, the link) are skipped, with the reason.
//!
//! The cases are dealt round-robin to [`SHARDS`] pairs of namespaces, each with its own
//! simulated device and controller, which run at the same time.
#![allow(
    clippy::expect_used,
    clippy::unwrap_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use drivespec_testkit::netns::{NetnsPair, NsChild};
use std::process::{Child, Stdio};

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// The NameOfStation of the simulated devices.
const NAME: &str = "psd-sim";

/// Device/controller pairs the suite is spread over. A choice: the suite is some 410 s of
/// cases on real time, plus the restarts before each; each pair's two processes use about a
/// fifth of a core at the 1 ms send clock, so six fit on two cores and take some three
/// minutes.
const SHARDS: usize = 6;

/// Every case the suite selects, in its order.
fn cases() -> Vec<String> {
    let out = std::process::Command::new(BIN)
        .args(["conform", "psd4xx", "--list"])
        .output()
        .expect("list the cases");
    assert!(out.status.success(), "{out:?}");
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .filter(|id| id.starts_with("psd4xx/"))
        .map(str::to_owned)
        .collect()
}

/// One pair of namespaces with its device and the controller's run.
struct Shard {
    _pair: NetnsPair,
    sim: NsChild,
    conform: Child,
    dir: std::path::PathBuf,
}

#[test]
fn conform_over_profinet_passes_every_case_on_the_simulated_device() {
    let all = cases();
    assert!(all.len() > 100, "{all:?}");
    let mut shards = Vec::new();
    for k in 0..SHARDS {
        let Some(pair) = NetnsPair::create() else {
            return;
        };
        let mut sim = pair.a.command(BIN);
        sim.args(["sim", "psd4xx", "--profinet", &pair.a.iface, "--name", NAME]);
        // stderr inherited: the device logs every AR there, which a pipe nobody reads
        // would hold up after some 64 KiB.
        let mut sim = NsChild::spawn(sim);
        let on = sim.wait_line("profinet:");
        assert_eq!(on, format!("{}/{NAME}", pair.a.iface));
        let dir = std::env::temp_dir().join(format!("drivespec-pn-{}-{k}", std::process::id()));
        let mut conform = pair.b.command(BIN);
        conform
            .args(["conform", "psd4xx", "--quiet", "--dut"])
            .arg(format!("profinet:{}/{NAME}", pair.b.iface))
            .arg("--report-dir")
            .arg(&dir);
        for id in all.iter().skip(k).step_by(SHARDS) {
            conform.args(["--case", id]);
        }
        // Files, not pipes: a shard waited for later must not block on a full pipe.
        std::fs::create_dir_all(&dir).unwrap();
        let log = |name: &str| Stdio::from(std::fs::File::create(dir.join(name)).unwrap());
        let conform = conform
            .stdin(Stdio::null())
            .stdout(log("stdout"))
            .stderr(log("stderr"))
            .spawn()
            .expect("run conform");
        shards.push(Shard {
            _pair: pair,
            sim,
            conform,
            dir,
        });
    }
    // A case id also selects the cases under it: a case may run in two shards.
    let mut seen = std::collections::BTreeSet::new();
    let mut failed = Vec::new();
    for s in shards {
        let mut conform = s.conform;
        let code = conform.wait().expect("wait for conform").code();
        let read = |name: &str| std::fs::read_to_string(s.dir.join(name)).unwrap_or_default();
        let (stdout, stderr) = (read("stdout"), read("stderr"));
        assert!(
            matches!(code, Some(0 | 1)),
            "exit {code:?} (2: setup error)\n{stderr}\n{stdout}"
        );
        let json = std::fs::read_to_string(s.dir.join("conform.json")).expect("conform.json");
        let _ = std::fs::remove_dir_all(&s.dir);
        let doc: serde_json::Value = serde_json::from_str(&json).unwrap();
        for c in doc["cases"].as_array().unwrap() {
            seen.insert(c["id"].as_str().unwrap().to_owned());
            match c["status"].as_str().unwrap() {
                "pass" | "acceptable" => {}
                "skipped" => {
                    let reason = c["skip_reason"].as_str().unwrap_or_default();
                    assert!(reason.contains("UNSUPPORTED"), "{c}");
                }
                _ => failed.push(format!("{}: {}", c["id"], c["failure"]["message"])),
            }
        }
        println!("{}", stdout.lines().last().unwrap_or_default());
        drop(s.sim);
    }
    assert!(
        failed.is_empty(),
        "{} case(s) failed over PROFINET:\n{}",
        failed.len(),
        failed.join("\n")
    );
    assert_eq!(seen, all.into_iter().collect(), "every case got a verdict");
}
