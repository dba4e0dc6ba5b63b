//! Fuzz harness of the PSD4xx reference drive model (manual 3.2–3.9, chapter 4): arbitrary
//! output images, records, parameter writes, environment and connection events and time steps.

use crate::ops::{env_change, word};
use drivespec_psd4xx::model::{Drive, DriveConfig, LinkEvent, RecordRequest};
use drivespec_psd4xx::{Input, Output, Rules};
use drivespec_spec::Spec;
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().expect("the built-in spec loads"))
}

/// A drive in the delivery state, built once and cloned per input.
fn template() -> &'static Drive {
    static DRIVE: OnceLock<Drive> = OnceLock::new();
    DRIVE.get_or_init(|| Drive::new(spec(), DriveConfig::new("PSD401-5V")).expect("model drive"))
}

/// Checks what must hold in every state (manual 3.6) and that the image codes cleanly (3.5.2).
fn check(d: &Drive, rules: &Rules) {
    let core = d.core();
    let image = d.input_image();
    let input = Input::parse(rules, &image).expect("the drive's input image parses");
    assert_eq!(
        input
            .to_bytes(rules)
            .expect("the drive's input image re-encodes"),
        image,
        "input image round trip"
    );
    if !core.powered() {
        return;
    }
    let status = input.status;
    assert_eq!(status & 0b1010, 0, "reserved status bits stay 0");
    assert_eq!(
        status >> 6 & 1 == 1,
        core.kinematics().vel != 0.0,
        "bit 6 means the shaft rotates"
    );
    assert_eq!(
        status >> 2 & 1 == 1,
        d.outputs_in_force().control & 0x2000 != 0,
        "bit 2 echoes control bit 13"
    );
    assert!(
        !(status & 1 == 1 && status >> 10 & 1 == 1),
        "bit 0 has priority over bit 10"
    );
    assert!(core.kinematics().pos.is_finite() && core.kinematics().vel.is_finite());
}

/// The model never panics on any sequence of inputs, its outputs come in time order, and the
/// status invariants of 3.6 hold after every step.
///
/// Each op byte: high nibble = kind, low nibble = argument length; then the argument. Kinds
/// 0–5 patch the output image in force (PKW, control word, target), 6 reads and 7 writes a
/// record, 8 changes the environment, 9 the connection, 10 cycles the power, 11 writes a
/// parameter directly. After each op the clock advances by up to about 2 s.
pub fn model(data: &[u8]) {
    let mut d = template().clone();
    let rules = d.rules().clone();
    let mut image = Output::idle(&rules)
        .to_bytes(&rules)
        .expect("the idle image encodes");
    let mut now = 0u64;
    let mut rest = data;
    let (mut last_input, mut last_record) = (0, 0);
    while let Some((&op, tail)) = rest.split_first() {
        let n = usize::from(op & 0x0F).min(tail.len());
        let (arg, next) = tail.split_at(n);
        rest = next;
        match op >> 4 {
            0..=5 => {
                let at = usize::from(arg.first().copied().unwrap_or(0)) % image.len();
                for (slot, b) in image.iter_mut().skip(at).zip(arg.iter().skip(1)) {
                    *slot = *b;
                }
                d.handle_image(now, &image).expect("a 14-byte image parses");
            }
            6 => d.handle_record(
                now,
                RecordRequest::Read {
                    index: word(arg, 0),
                },
            ),
            7 => d.handle_record(
                now,
                RecordRequest::Write {
                    index: word(arg, 0),
                    data: arg.get(2..).unwrap_or(&[]).to_vec(),
                },
            ),
            8 => d.handle_env(now, env_change(arg)),
            9 => d.handle_link(
                now,
                match arg.first().copied().unwrap_or(0) % 4 {
                    0 => LinkEvent::Lost,
                    1 => LinkEvent::Connected,
                    2 => LinkEvent::IopsBad,
                    _ => LinkEvent::IopsGood,
                },
            ),
            10 => d.power_cycle(now),
            11 => {
                let value =
                    i64::from(word(arg, 2) as i16) * i64::from(arg.get(4).copied().unwrap_or(1));
                let _ = d.write_parameter(now, word(arg, 0) % 128, value);
            }
            _ => {}
        }
        check(&d, &rules);
        let step = u64::from(arg.last().copied().unwrap_or(op)) * 8000;
        now += step;
        d.advance(now);
        check(&d, &rules);
        while let Some((at, input)) = d.poll_input() {
            assert!(at >= last_input, "input images come in time order");
            last_input = at;
            assert!(input.to_bytes(&rules).is_ok());
        }
        while let Some(r) = d.poll_record() {
            assert!(r.at >= last_record, "record answers come in time order");
            last_record = r.at;
        }
        while d.poll_event().is_some() {}
        assert!(d.now() >= now);
    }
}
