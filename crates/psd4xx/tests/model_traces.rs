//! Full traces of three manual procedures on the reference model, as readable snapshots:
//! time, actual position, speed, status word and the bits set, one line per status change and
//! one every 250 ms, followed by the model's events (manual 4.2.1 case 2, 4.5, 4.6).
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod model_util;

use drivespec_positioner::EnvChange;
use model_util::*;
use std::fmt::Write as _;

fn finish(s: &mut Sim, title: &str) -> String {
    let mut out = format!("{title}\n\n{}", render(&s.trace, 250));
    out.push_str("\nevents:\n");
    for e in s.events() {
        let _ = writeln!(out, "  {}", serde_json::to_string(&e).unwrap());
    }
    out
}

/// 4.2.1 case 2: from 8,000 to 4,000 with the reference loop (overshoot to 3,750).
#[test]
fn trace_loop_case_2() {
    let mut s = Sim::new("PSD401-5V");
    s.record = true;
    s.send(0x14, 8000);
    s.wait_idle();
    s.step(100);
    s.send(0x14, 4000);
    s.wait_idle();
    s.step(100);
    insta::assert_snapshot!(
        "trace_loop_case_2",
        finish(
            &mut s,
            "PSD 401/411-5V: 0x14 to 8000, then 0x14 to 4000 (4.2.1 case 2)"
        )
    );
}

/// 4.5: an obstruction stops the run; the same target needs the release edge.
#[test]
fn trace_obstruction() {
    let mut s = Sim::new("PSD401-5V");
    s.record = true;
    s.send(0x14, 8000);
    s.step(1000);
    s.env(EnvChange::Jam { on: true });
    s.wait_idle();
    s.env(EnvChange::Jam { on: false });
    s.step(250);
    s.send(0x04, 8000);
    s.step(10);
    s.send(0x14, 8000);
    s.wait_idle();
    s.step(100);
    insta::assert_snapshot!(
        "trace_obstruction",
        finish(
            &mut s,
            "PSD 401/411-5V: 0x14 to 8000, jammed at 1 s, freed; 0x04 then 0x14 restarts (4.5)"
        )
    );
}

/// 4.6: readjustment after the shaft is turned against the loop at standstill.
#[test]
fn trace_readjustment() {
    let mut s = Sim::new("PSD426");
    s.write(47, 1);
    s.record = true;
    s.send(0x14, 2000);
    s.wait_idle();
    s.step(300);
    s.env(EnvChange::Displace { by: -150 });
    s.wait_idle();
    s.step(300);
    insta::assert_snapshot!(
        "trace_readjustment",
        finish(
            &mut s,
            "PSD 426/436-14H, par. 47 = 1: 0x14 to 2000, turned back by 150 at standstill (4.6)"
        )
    );
}
