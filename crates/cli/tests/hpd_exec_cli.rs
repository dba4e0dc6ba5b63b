//! The reference drive as an `exec:` device under test behind a pass-through relay
//! (`hpd_stdio_relay.py` in front of `drivespec sim hpd --stdio`), and on a pseudo-terminal
//! (`drivespec sim hpd --pty` as `serial:`): the cases whose answers depend on when a PLC scan
//! (6.144 ms, 3.8.1) falls between two messages, and the bit-rate changes, pass five runs in a
//! row, each run judged once. The whole suite over `exec:` is the same code path; these groups
//! are the ones real time moves.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_testkit::{run, temp_dir, Sim};

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

/// The cases real time moves: PLC programs and vectors, the outputs the default program
/// copies (Pb91), the motor (judged by envelopes, sampled as fast as the line allows), every
/// Pr26 code (a message split within the time-out pauses at most the time-out less the
/// transport's slack); after a plain read, so the drive has run its first scans before the
/// first of them (a Pb91 read right after start-up sees none yet).
const TIMED: [&str; 5] = [
    "hpd/frame/read-parameter",
    "hpd/plc/*",
    "hpd/bit/b91.*",
    "hpd/baud/*",
    "hpd/motion/*",
];

/// The answer slack (`--slack-ms`): a relay process on a machine that also builds must not
/// turn a starved process into a verdict.
const SLACK_MS: &str = "60";

/// `drivespec conform hpd` on `dut` with the timed cases: exit code and stdout.
fn conform(dut: &str, name: &str) -> (i32, String) {
    let dir = temp_dir("hpd-exec", name);
    let mut args = vec![
        "conform".to_owned(),
        "hpd".to_owned(),
        "--dut".to_owned(),
        dut.to_owned(),
        "--quiet".to_owned(),
        "--slack-ms".to_owned(),
        SLACK_MS.to_owned(),
        "--report-dir".to_owned(),
        dir.display().to_string(),
    ];
    for c in TIMED {
        args.push("--case".to_owned());
        args.push(c.to_owned());
    }
    let argv: Vec<&str> = args.iter().map(String::as_str).collect();
    let (code, out, _) = run(BIN, &argv);
    let _ = std::fs::remove_dir_all(&dir);
    (code, out)
}

#[test]
fn the_reference_behind_a_relay_passes_five_runs_in_a_row() {
    let relay = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/hpd_stdio_relay.py");
    let dut = format!("exec:python3 {relay} {BIN} sim hpd --stdio --time-limit 120");
    for n in 1..=5 {
        let (code, out) = conform(&dut, &format!("relay-{n}"));
        assert_eq!(code, 0, "run {n}:\n{out}");
        assert!(out.contains(" 0 failed"), "run {n}:\n{out}");
    }
}

#[test]
fn the_reference_on_a_pty_passes_five_runs_in_a_row() {
    for n in 1..=5 {
        let mut sim = Sim::start(BIN, &["hpd", "--pty"]);
        let path = sim.first_line();
        let (code, out) = conform(&format!("serial:{path}"), &format!("pty-{n}"));
        sim.stop();
        assert_eq!(code, 0, "run {n}:\n{out}");
        assert!(out.contains(" 0 failed"), "run {n}:\n{out}");
    }
}
