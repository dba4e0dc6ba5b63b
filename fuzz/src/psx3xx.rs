//! Fuzz harness of the PSx3xx reference drive model (manual chapters 3–5): arbitrary process
//! images in the active format, ISDU requests, IO-Link events, jog keys, environment changes,
//! power cycles and time steps.

use crate::ops::{env_change, word};
use drivespec_psx3xx::isdu::{Request, Value};
use drivespec_psx3xx::model::LedLight;
use drivespec_psx3xx::model::{Drive, DriveConfig, JogKeys, LinkEvent};
use drivespec_psx3xx::{Input, Output};
use drivespec_spec::{FamilyId, Readings, Spec};
use std::sync::OnceLock;

fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().expect("the built-in spec loads"))
}

/// Erratum readings other than the adopted ones, for the drives built with `other` set
/// (PSX-ERRATUM-011, PSX-ERRATUM-051, PSX-ERRATUM-056, PSX-ERRATUM-064).
const OTHER_READINGS: &[(&str, &str)] = &[
    ("psx-signed-measurements", "unsigned"),
    ("psx-ts-bit-layout", "high-bits"),
    ("psx-ref-sign", "physical-minus-written"),
    ("psx-ts-reference", "inactive-marker"),
];

/// Drives in the delivery state, one per process-data format, brake option and reading set
/// (adopted or [`OTHER_READINGS`]), built once and cloned per input.
fn template(format: u8, brake: bool, other: bool) -> &'static Drive<'static> {
    static DRIVES: OnceLock<Vec<Drive<'static>>> = OnceLock::new();
    let drives = DRIVES.get_or_init(|| {
        let mut out = Vec::new();
        for (brake, other) in [(false, false), (true, false), (false, true), (true, true)] {
            for f in 0..3u8 {
                let mut cfg = DriveConfig::new(if brake { "PSE322-14" } else { "PSE312-8" });
                if brake {
                    cfg = cfg.with_brake(drivespec_psx3xx::model::BrakeKind::Snap);
                }
                if other {
                    let mut readings = Readings::default();
                    for (option, reading) in OTHER_READINGS {
                        readings
                            .choose(spec().family(FamilyId::Psx3xx), option, reading)
                            .expect("a reading of the spec");
                    }
                    cfg = cfg.with_readings(readings);
                }
                let mut d = Drive::new(spec(), cfg).expect("model drive");
                let _ = d.write(0, 116, 0, &Value::Int(i64::from(f)));
                let _ = d.write(0, 193, 0, &Value::Int(1));
                let _ = d.write(0, 2, 0, &Value::Int(128));
                assert_eq!(d.active_format(), f);
                while d.poll_event().is_some() {}
                while d.poll_isdu().is_some() {}
                out.push(d);
            }
        }
        out
    });
    let set = usize::from(brake) + if other { 2 } else { 0 };
    &drives[usize::from(format % 3) + 3 * set]
}

/// What must hold in every state (manual 3.3.2, 3.4).
fn check(d: &Drive) {
    let rules = d.rules();
    let image = d.input_image();
    let input = Input::parse(rules, d.byte_order(), &image).expect("the input image parses");
    assert_eq!(
        input
            .to_bytes(rules, d.byte_order())
            .expect("the drive's input image re-encodes"),
        image,
        "input image round trip"
    );
    let core = d.core();
    if !core.powered() {
        assert_eq!(input.status, 0, "a drive that is off sends zeros");
        return;
    }
    let status = input.status;
    assert_eq!(
        status >> 6 & 1 == 1,
        core.kinematics().vel != 0.0,
        "bit 6 means the shaft rotates"
    );
    assert_eq!(
        status >> 3 & 1 == 1,
        d.keys().forward,
        "bit 3 is the forward key"
    );
    assert_eq!(
        status >> 2 & 1 == 1,
        d.keys().reverse,
        "bit 2 is the reverse key"
    );
    assert!(core.kinematics().pos.is_finite() && core.kinematics().vel.is_finite());
    let leds = d.leds();
    assert_eq!(
        leds.green == LedLight::On90Percent,
        d.link_up(),
        "the green LED shows the communication (PSX-LED-001, PSX-LED-002)"
    );
    assert_eq!(
        leds.yellow == LedLight::On,
        core.environment().motor_dv > 0,
        "the yellow LED shows the motor voltage (PSX-LED-004)"
    );
    if d.active_format() != d.rules().timestamp().format {
        assert_eq!(leds.orange, LedLight::Off, "PSX-LED-003");
    }
    assert_eq!(
        d.value("65"),
        Value::Int(i64::from(d.input().rpm)),
        "ISDU 65 is the input's speed under every reading (PSX-ERRATUM-011)"
    );
}

/// The model never panics on any sequence of inputs, its outputs come in time order, and the
/// invariants of 3.3.2 and 3.4 hold after every step.
///
/// Byte 0 picks the format (0–2), the brake option (bit 2) and the erratum readings (bit 3:
/// [`OTHER_READINGS`]). Then each op byte: high nibble
/// = kind, low nibble = argument length; then the argument. Kinds 0–3 patch the output image
/// in force and send it, 4 reads and 5 writes an ISDU entry, 6 changes the environment, 7 the
/// jog keys, 8 the IO-Link communication, 9 cycles the power, 10 writes a number to an entry.
/// After each op the clock advances by up to about 2 s.
pub fn model(data: &[u8]) {
    let Some((&first, mut rest)) = data.split_first() else {
        return;
    };
    let mut d = template(first % 3, first & 4 != 0, first & 8 != 0).clone();
    let mut image: Vec<u8> = Vec::new();
    let mut now = 0u64;
    let (mut last_input, mut last_isdu) = (0, 0);
    while let Some((&op, tail)) = rest.split_first() {
        let n = usize::from(op & 0x0F).min(tail.len());
        let (arg, next) = tail.split_at(n);
        rest = next;
        let rules = d.rules().clone();
        let len = rules
            .output(d.active_format())
            .map_or(0, |o| o.layout.length());
        if image.len() != len {
            image = vec![0; len];
            if let Ok(out) = Output::parse(&rules, d.active_format(), d.byte_order(), &image) {
                image = out
                    .to_bytes(&rules, d.byte_order())
                    .expect("a built output image encodes");
            }
        }
        match op >> 4 {
            0..=3 if !image.is_empty() => {
                let at = usize::from(arg.first().copied().unwrap_or(0)) % image.len();
                for (slot, b) in image.iter_mut().skip(at).zip(arg.iter().skip(1)) {
                    *slot = *b;
                }
                d.handle_image(now, &image)
                    .expect("an image of the active format parses");
            }
            4 => d.handle_isdu(
                now,
                Request::Read {
                    index: word(arg, 0) % 256,
                    subindex: arg.get(2).copied().unwrap_or(0) % 20,
                },
            ),
            5 => d.handle_isdu(
                now,
                Request::Write {
                    index: word(arg, 0) % 256,
                    subindex: arg.get(2).copied().unwrap_or(0) % 20,
                    data: arg.get(3..).unwrap_or(&[]).to_vec(),
                },
            ),
            6 => d.handle_env(now, env_change(arg)),
            7 => d.handle_keys(
                now,
                JogKeys {
                    forward: arg.first().copied().unwrap_or(0) & 1 == 1,
                    reverse: arg.first().copied().unwrap_or(0) & 2 == 2,
                },
            ),
            8 => d.handle_link(
                now,
                if arg.first().copied().unwrap_or(0) & 1 == 1 {
                    LinkEvent::Connected
                } else {
                    LinkEvent::Lost
                },
            ),
            9 => d.power_cycle(now),
            10 => {
                let value =
                    i64::from(word(arg, 2) as i16) * i64::from(arg.get(4).copied().unwrap_or(1));
                let _ = d.write(now, word(arg, 0) % 256, 0, &Value::Int(value));
            }
            _ => {}
        }
        check(&d);
        let step = u64::from(arg.last().copied().unwrap_or(op)) * 8000;
        now += step;
        d.advance(now);
        check(&d);
        while let Some((at, input)) = d.poll_input() {
            assert!(at >= last_input, "input images come in time order");
            last_input = at;
            assert!(input.to_bytes(&rules, d.byte_order()).is_ok());
        }
        while let Some(a) = d.poll_isdu() {
            assert!(a.at >= last_isdu, "ISDU answers come in time order");
            last_isdu = a.at;
        }
        while d.poll_event().is_some() {}
        assert!(d.now() >= now);
    }
}
