//! `sim-run` scripts on the PSD4xx reference drive: the family's commands parse with errors
//! naming the line, runs are deterministic, `end` and the tail limit stop a run, and the
//! trace holds the PKW, record and direct-write answers.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_positioner::script::{Action, Line, LineError, PlayError, RunOptions, Script, What};
use drivespec_psd4xx::model::{DriveConfig, LinkEvent};
use drivespec_psd4xx::script::{parse, run, run_text, RunError};
use drivespec_psd4xx::step::Step;
use drivespec_psd4xx::Rules;
use drivespec_spec::Spec;

fn spec() -> Spec {
    Spec::builtin().unwrap()
}

fn opts() -> RunOptions {
    RunOptions {
        every_ms: 0,
        ..RunOptions::default()
    }
}

#[test]
fn family_commands_parse() {
    let spec = spec();
    let rules = Rules::from_spec(&spec).unwrap();
    let s = parse(
        &rules,
        "0 ms: control 0x14 target -250\n1 ms: target 7\n2 ms: record write 44 01 00 05\n\
         3 ms: record read 13\n4 ms: par 96 = -1\n5 ms: link iops-bad\n6 ms: power-cycle\n\
         7 ms: pkw read:44\n",
    )
    .unwrap();
    let cmds: Vec<Step> = s
        .lines
        .iter()
        .map(|st| match &st.action {
            Action::Step(c) => c.clone(),
            other => panic!("{other:?}"),
        })
        .collect();
    assert_eq!(
        cmds[0],
        Step::Process {
            control: Some(0x14),
            target: Some(-250)
        }
    );
    assert_eq!(
        cmds[1],
        Step::Process {
            control: None,
            target: Some(7)
        }
    );
    assert_eq!(
        cmds[2],
        Step::RecordWrite {
            index: 44,
            hex: vec![1, 0, 5]
        }
    );
    assert_eq!(cmds[3], Step::RecordRead { index: 13 });
    assert_eq!(cmds[4], Step::Par { pnu: 96, value: -1 });
    assert_eq!(
        cmds[5],
        Step::Link {
            event: LinkEvent::IopsBad
        }
    );
    assert_eq!(cmds[6], Step::PowerCycle);
    assert!(matches!(cmds[7], Step::Pkw { pkw } if pkw.ak == 1 && pkw.pnu == 44));
}

#[test]
fn a_step_that_waits_on_the_drive_is_refused_before_the_run() {
    let spec = spec();
    let rules = Rules::from_spec(&spec).unwrap();
    let mut script = parse(
        &rules,
        "0 ms: control 0x14 target 800
",
    )
    .unwrap();
    for (step, name) in [
        (Step::Hold { cycles: 3 }, "hold"),
        (
            Step::Until {
                running: false,
                max: 10,
            },
            "until",
        ),
        (Step::Advance { us: 5 }, "advance"),
        (
            Step::Env {
                env: "jam 1".to_owned(),
            },
            "env",
        ),
    ] {
        script.lines.push(Line {
            line: 2,
            at: 1_000,
            text: name.to_owned(),
            action: Action::Step(step),
        });
        let e = run(&spec, DriveConfig::new("PSD426"), &script, &opts()).unwrap_err();
        assert_eq!(
            e,
            RunError::Play(PlayError::Unplayable {
                line: 2,
                step: name
            })
        );
        script.lines.pop();
    }
    let empty: Script<Step> = Script { lines: Vec::new() };
    assert!(run(&spec, DriveConfig::new("PSD426"), &empty, &opts()).is_ok());
}

#[test]
fn family_errors_name_the_line() {
    let spec = spec();
    let rules = Rules::from_spec(&spec).unwrap();
    let cases: [(&str, usize); 6] = [
        ("0 ms: control 0x10000\n", 1),
        ("0 ms: control 0x14\n1 ms: control 0x14 speed 5\n", 2),
        ("\n\n0 ms: pkw frobnicate:44\n", 3),
        ("0 ms: record erase 44\n", 1),
        ("0 ms: link down\n", 1),
        ("0 ms: par 44 5\n", 1),
    ];
    for (text, line) in cases {
        let e = parse(&rules, text).unwrap_err();
        assert_eq!(e.line, line, "{text}: {e}");
        assert!(e.to_string().starts_with(&format!("line {line}: ")), "{e}");
    }
    let e = parse(&rules, "0 ms: pkw write:44\n").unwrap_err();
    assert!(matches!(e.error, LineError::Family { .. }), "{e}");
}

#[test]
fn runs_are_deterministic_and_answer_every_channel() {
    let spec = spec();
    let text = "0 ms: pkw read:44\n5 ms: control 0x14 target 800\n10 ms: record read 44\n\
                20 ms: par 44 = 70000\n30 ms: record write 44 00 00 09\n5 s: expect position = 795..805\n";
    let a = run_text(&spec, DriveConfig::new("PSD426"), text, &opts()).unwrap();
    let b = run_text(&spec, DriveConfig::new("PSD426"), text, &opts()).unwrap();
    assert_eq!(a, b);
    assert_eq!((a.passed, a.failed), (1, 0));
    let answers: Vec<(&str, &str)> = a
        .entries
        .iter()
        .filter_map(|e| match &e.what {
            What::Answer {
                channel, answer, ..
            } => Some((channel.as_str(), answer.as_str())),
            _ => None,
        })
        .collect();
    assert!(
        answers
            .iter()
            .any(|(c, a)| *c == "pkw" && a.starts_with("value:44=")),
        "{answers:?}"
    );
    assert!(
        answers.contains(&("record 44", "data 00 02")),
        "{answers:?}"
    );
    assert!(
        answers
            .iter()
            .any(|(c, a)| *c == "par" && a.starts_with("error:44=")),
        "{answers:?}"
    );
    assert!(answers.contains(&("record 44", "ignored")), "{answers:?}");
}

#[test]
fn end_and_tail_limit_stop_the_run() {
    let spec = spec();
    let t = run_text(
        &spec,
        DriveConfig::new("PSD426"),
        "0 ms: control 0x14 target 8000\n500 ms: end\n",
        &opts(),
    )
    .unwrap();
    assert_eq!(t.entries.last().unwrap().t_us, 500_000);
    let short = RunOptions {
        tail_limit_us: 50_000,
        ..opts()
    };
    let t = run_text(
        &spec,
        DriveConfig::new("PSD426"),
        "0 ms: env back-drive 10\n",
        &short,
    )
    .unwrap();
    assert_eq!(t.entries.last().unwrap().what, What::TailLimit);
    let e = run_text(&spec, DriveConfig::new("PSD999"), "0 ms: end\n", &opts()).unwrap_err();
    assert!(matches!(e, RunError::Model(_)), "{e}");
}
