//! Fuzz harnesses of the `sim-run` script language: any text parses or fails with a line
//! number, and a parsed PSD4xx script short enough to play runs on the reference drive.

use crate::pd::{psd, psx, spec};
use drivespec_positioner::script::{RunOptions, Script};
use drivespec_psd4xx::model::DriveConfig;

/// Longest virtual time a fuzz input may play, µs: long enough for a run, short enough for
/// thousands of inputs a second.
const PLAY_US: u64 = 200_000;

/// Parsed lines come in file order with times that never go back.
fn lines_in_order<C>(script: &Script<C>, text: &str) {
    let lines = text.lines().count();
    let mut last = (0, 0);
    for step in &script.lines {
        assert!(
            step.line >= 1 && step.line <= lines,
            "line {} of {lines}",
            step.line
        );
        assert!(
            step.line > last.0 && step.at >= last.1,
            "step at line {} ({} µs) after line {} ({} µs)",
            step.line,
            step.at,
            last.0,
            last.1
        );
        last = (step.line, step.at);
    }
}

/// PSD4xx scripts: parse, check the order, and play the short ones on a PSD401-5V.
pub fn psd4xx(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(script) = drivespec_psd4xx::script::parse(psd(), &text) else {
        return;
    };
    lines_in_order(&script, &text);
    if script.last() <= PLAY_US {
        let opts = RunOptions {
            every_ms: 0,
            tail_limit_us: PLAY_US,
            ..RunOptions::default()
        };
        let trace =
            drivespec_psd4xx::script::run(spec(), DriveConfig::new("PSD401-5V"), &script, &opts);
        if let Ok(trace) = trace {
            assert!(trace.passed + trace.failed <= script.lines.len());
        }
    }
}

/// PSx3xx scripts: parse and check the order.
pub fn psx3xx(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    if let Ok(script) = drivespec_psx3xx::script::parse(psx(), &text) {
        lines_in_order(&script, &text);
    }
}
