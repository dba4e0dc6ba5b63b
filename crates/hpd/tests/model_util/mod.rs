//! Helpers shared by the drive model tests: the spec, request builders and output draining.
#![allow(dead_code)]

use drivespec_hpd::model::{Drive, DriveConfig, Output};
use drivespec_hpd::params::Target;
use drivespec_hpd::{parse, Data, FrameRules, Message, Micros};
use drivespec_spec::hpd::Protocol;
use drivespec_spec::{Family, FamilyId, Readings, Spec};
use std::sync::OnceLock;

pub fn spec() -> &'static Spec {
    static SPEC: OnceLock<Spec> = OnceLock::new();
    SPEC.get_or_init(|| Spec::builtin().unwrap())
}

pub fn family() -> &'static Family {
    spec().family(FamilyId::Hpd)
}

pub fn protocol() -> &'static Protocol {
    family().hpd().unwrap()
}

pub fn rules() -> FrameRules {
    FrameRules::from_spec(spec()).unwrap()
}

/// A parameter, double word or bit by name (`Pr31`, `Pr64:65`, `b99.14`).
pub fn target(name: &str) -> Target<'static> {
    Target::parse(family(), name).unwrap()
}

/// (serial address, length) of a parameter.
pub fn slot(name: &str) -> (u8, u8) {
    target(name).address().unwrap()
}

/// A commissioned drive at `addr` with the default Pr26 code.
pub fn drive(addr: u8) -> Drive {
    Drive::new(spec(), DriveConfig::commissioned(addr)).unwrap()
}

/// A commissioned drive at `addr` with erratum option `option` read as `reading`.
pub fn drive_with(addr: u8, option: &str, reading: &str) -> Drive {
    let mut readings = Readings::default();
    readings.choose(family(), option, reading).unwrap();
    Drive::new(
        spec(),
        DriveConfig::commissioned(addr).with_readings(readings),
    )
    .unwrap()
}

pub fn bytes(msg: &Message) -> Vec<u8> {
    msg.to_bytes(&rules()).unwrap()
}

pub fn drain(d: &mut Drive) -> Vec<Output> {
    std::iter::from_fn(|| d.poll_output()).collect()
}

/// The bytes of every transmission among `outputs`.
pub fn transmits(outputs: &[Output]) -> Vec<Vec<u8>> {
    outputs
        .iter()
        .filter_map(|o| match o {
            Output::Transmit { bytes, .. } => Some(bytes.clone()),
            Output::DigitalOutputs { .. } => None,
        })
        .collect()
}

/// Sends `msg` at `now` and returns what the drive sent back at once, decoded.
pub fn exchange(d: &mut Drive, now: Micros, msg: &Message) -> Vec<Message> {
    d.handle_rx(now, &bytes(msg));
    transmits(&drain(d))
        .iter()
        .map(|b| parse(&rules(), b).unwrap())
        .collect()
}

/// A read request for `name` to drive `addr`.
pub fn read(addr: u8, name: &str) -> Message {
    target(name).read(addr).unwrap()
}

/// A raw write of `value` into `name`, whatever its range (manual 4.1 CMD 5).
pub fn write(addr: u8, name: &str, value: i64) -> Message {
    let (par, lun) = slot(name);
    Message::WriteParam {
        addr,
        par,
        data: Data::from_value(value, lun).unwrap(),
    }
}

/// A bit change setting bit `name` (`b99.15`) to `on` (manual 4.1 CMD 6).
pub fn bit(addr: u8, name: &str, on: bool) -> Message {
    target(name)
        .write(family(), addr, if on { "1" } else { "0" })
        .unwrap()
}

/// The working value of `name`.
pub fn value(d: &Drive, name: &str) -> i64 {
    d.value(&target(name)).unwrap()
}

/// Sets `name` directly (keypad or measurement) at `now`.
pub fn set(d: &mut Drive, now: Micros, name: &str, v: i64) {
    d.set_value(now, &target(name), v).unwrap();
}

/// The short acknowledge of drive `addr`.
pub fn ack(addr: u8) -> Message {
    Message::Ack { addr }
}

/// PLC scan period and FIN period from the spec (µs).
pub fn scan_us() -> Micros {
    Micros::from(protocol().plc.scan_us)
}

pub fn fin_us() -> Micros {
    Micros::from(protocol().plc.fast_inputs.period_us)
}

/// The PLC area bytes of a listing.
pub fn program_bytes(lines: &[&str]) -> Vec<u8> {
    let runtime = drivespec_hpd::plc::PlcCodec::from_spec(spec()).unwrap();
    let program = runtime.parse_listing(&lines.join("\n")).unwrap();
    runtime.encode_program(&program).unwrap()
}

/// Writes `code` into the PLC area from address 0 of drive `addr`, two bytes per message,
/// with the PLC stopped, then starts it again.
pub fn load_program(d: &mut Drive, now: Micros, addr: u8, code: &[u8]) {
    assert_eq!(exchange(d, now, &bit(addr, "b99.13", false)), [ack(addr)]);
    for (i, chunk) in code.chunks(2).enumerate() {
        let msg = Message::WritePlc {
            addr,
            par: u8::try_from(2 * i).unwrap(),
            data: Data::new(chunk).unwrap(),
        };
        assert_eq!(exchange(d, now, &msg), [ack(addr)]);
    }
    assert_eq!(exchange(d, now, &bit(addr, "b99.13", true)), [ack(addr)]);
}
