//! `sim-run` scripts on the PSx3xx reference drive: the family's commands parse into the
//! family's steps with errors naming the line, and runs are deterministic.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_positioner::script::{Action, LineError, RunOptions, What};
use drivespec_psx3xx::model::{DriveConfig, LinkEvent};
use drivespec_psx3xx::script::{parse, run_text};
use drivespec_psx3xx::step::Step;
use drivespec_psx3xx::Rules;
use drivespec_spec::{FamilyId, Spec};

#[test]
fn family_commands_parse_and_errors_name_the_line() {
    let spec = Spec::builtin().unwrap();
    let rules = Rules::from_family(spec.family(FamilyId::Psx3xx)).unwrap();
    let s = parse(
        &rules,
        "0 ms: control 0x14 target 60000 speed 50\n1 ms: isdu read 64\n2 ms: stamp 3 100\n\
         3 ms: keys both\n4 ms: link lost\n5 ms: power-cycle\n",
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
            target: Some(60000),
            speed: Some(50)
        }
    );
    assert_eq!(
        cmds[1],
        Step::IsduRead {
            index: 64,
            subindex: 0
        }
    );
    assert_eq!(
        cmds[2],
        Step::Stamp {
            code: 3,
            stamp: 100
        }
    );
    assert_eq!(
        cmds[3],
        Step::Keys {
            forward: true,
            reverse: true
        }
    );
    assert_eq!(
        cmds[4],
        Step::Link {
            event: LinkEvent::Lost
        }
    );
    assert_eq!(cmds[5], Step::PowerCycle);

    for (text, line) in [
        ("0 ms: keys sideways\n", 1),
        ("0 ms: control 0x14\n1 ms: control 0x14 torque 5\n", 2),
        ("\n0 ms: isdu erase 64\n", 2),
        ("0 ms: stamp 3\n", 1),
    ] {
        let e = parse(&rules, text).unwrap_err();
        assert_eq!(e.line, line, "{text}: {e}");
    }
    let e = parse(&rules, "0 ms: isdu write 60000 = 1\n").unwrap_err();
    assert!(matches!(e.error, LineError::Family { .. }), "{e}");
}

#[test]
fn runs_are_deterministic() {
    let spec = Spec::builtin().unwrap();
    let text = "0 ms: control 0x14 target 52000\n100 ms: isdu read 64\n";
    let opts = RunOptions::default();
    let a = run_text(&spec, DriveConfig::new("PSE335-14"), text, &opts).unwrap();
    let b = run_text(&spec, DriveConfig::new("PSE335-14"), text, &opts).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.family, "psx3xx");
    assert!(a.entries.len() > 4);
}

#[test]
fn leds_command_records_the_three_leds() {
    let spec = Spec::builtin().unwrap();
    let text = "0 ms: leds\n10 ms: link lost\n20 ms: env motor-voltage 0\n30 ms: leds\n";
    let trace = run_text(
        &spec,
        DriveConfig::new("PSE312-8"),
        text,
        &RunOptions::default(),
    )
    .unwrap();
    let shown: Vec<String> = trace
        .entries
        .iter()
        .filter_map(|e| match &e.what {
            What::Answer {
                channel, answer, ..
            } if channel == "leds" => Some(answer.clone()),
            _ => None,
        })
        .collect();
    // PSX-LED-001, PSX-LED-002, PSX-LED-003, PSX-LED-004 as the spec names the patterns.
    assert_eq!(
        shown,
        [
            "green on-90-percent, orange off, yellow on",
            "green off, orange off, yellow off"
        ]
    );
    for pattern in ["on-90-percent", "off", "on"] {
        assert!(
            spec.family(FamilyId::Psx3xx)
                .psx3xx()
                .unwrap()
                .leds
                .iter()
                .any(|l| l.states.iter().any(|s| s.pattern == pattern)),
            "{pattern} is a spec pattern"
        );
    }
}
