//! The PLC examples of manual 3.8.1 / 3.8.2 / 4.1 / appendix G from `spec/hpd/vectors/plc.toml`,
//! run on the PLC codec and interpreter.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_hpd::memory::{Memory, ParamMap};
use drivespec_hpd::plc::{PlcCodec, PlcRuntime, PlcState};
use drivespec_spec::hex::parse_hex;
use drivespec_spec::{FamilyId, Readings, Spec, VectorKind};
use std::collections::BTreeMap;

fn lines(v: &[String]) -> String {
    v.iter().map(|l| format!("{l}\n")).collect()
}

fn table(v: &Option<BTreeMap<String, i64>>) -> Vec<(String, i64)> {
    v.iter()
        .flat_map(|t| t.iter().map(|(k, v)| (k.clone(), *v)))
        .collect()
}

#[test]
fn listings_encode_to_the_manual_bytes_and_back() {
    let spec = Spec::builtin().unwrap();
    let codec = PlcCodec::from_spec(&spec).unwrap();
    let vectors: Vec<_> = spec
        .family(FamilyId::Hpd)
        .vectors
        .iter()
        .filter(|v| v.kind == VectorKind::HpdPlcBytes)
        .collect();
    assert!(vectors.len() >= 2, "cases 7 and 8 of 4.1 at least");
    for v in vectors {
        let body = v.hpd_plc_bytes().unwrap();
        let program = codec
            .parse_listing(&lines(&body.input.listing))
            .unwrap_or_else(|e| panic!("{}: {e}", v.id));
        let bytes = codec.encode_program(&program).unwrap();
        let want = parse_hex(body.expect.bytes.as_deref().unwrap()).unwrap();
        assert_eq!(bytes, want, "{}", v.id);
        // Back from bytes: the same instructions, listed the same way.
        let mut at = 0;
        for (_, instr) in &program.instrs {
            let (back, len) = codec.decode(&bytes[at..], at).unwrap();
            assert_eq!(&back, instr, "{}", v.id);
            at += len;
        }
    }
}

#[test]
fn appendix_g_round_trips_through_bytes() {
    let spec = Spec::builtin().unwrap();
    let codec = PlcCodec::from_spec(&spec).unwrap();
    let g = &spec.family(FamilyId::Hpd).hpd().unwrap().default_program;
    let listing: String = g.iter().map(|l| format!("{}\n", l.listing)).collect();
    let program = codec.parse_listing(&listing).unwrap();
    for ((addr, instr), line) in program.instrs.iter().zip(g) {
        assert_eq!(*addr, usize::from(line.address), "{}", line.listing);
        assert_eq!(codec.format(instr), line.listing);
    }
    let bytes = codec.encode_program(&program).unwrap();
    let back = codec.decode_program(&bytes).unwrap();
    assert_eq!(back, program);
    assert_eq!(codec.check(&program), vec![]);
}

#[test]
fn arithmetic_logic_and_timer_examples_give_the_manual_results() {
    let spec = Spec::builtin().unwrap();
    let family = spec.family(FamilyId::Hpd);
    let runtime = PlcRuntime::from_spec(&spec, &Readings::default()).unwrap();
    let map = ParamMap::from_spec(&spec);
    let codec = runtime.codec();
    let run_bit = ParamMap::parse_bit(&family.hpd().unwrap().plc.run_bit).unwrap();
    let vectors: Vec<_> = family
        .vectors
        .iter()
        .filter(|v| v.kind == VectorKind::HpdPlc)
        .collect();
    assert!(
        vectors.len() >= 5,
        "ADD, ADD with and without b94.0, DIV, timer at least"
    );
    for v in vectors {
        let body = v.hpd_plc().unwrap();
        let mut mem = Memory::default();
        let b = map.bit(run_bit.0, run_bit.1).unwrap();
        mem.set_bit(b, true);
        let mut inputs = 0u16;
        for (name, value) in table(&body.input.params) {
            let slot = map
                .slot(ParamMap::parse_param(&name).unwrap())
                .unwrap_or_else(|| panic!("{}: {name} has no slot", v.id));
            mem.set(slot.addr, slot.size, value as u32);
        }
        for (name, value) in table(&body.input.bits) {
            let (n, y) = ParamMap::parse_bit(&name).unwrap();
            mem.set_bit(map.bit(n, y).unwrap(), value == 1);
            if name.starts_with("b90.") && y < 8 && value == 1 {
                inputs |= 1 << y;
            }
        }
        let program = codec
            .parse_listing(&lines(&body.input.program))
            .unwrap_or_else(|e| panic!("{}: {e}", v.id));
        let scans = body.input.scans.unwrap_or(1);
        let mut state = PlcState::default();
        // One scan period holds scan_us / fin_period_us FIN copy slots (3.8.1).
        let fin_per_scan = runtime.scan_us() / runtime.fin_period_us();
        for _ in 0..scans {
            for _ in 0..fin_per_scan {
                runtime.fast_inputs(&mut mem, &program, inputs);
            }
            runtime.scan(&mut state, &mut mem, &program, inputs);
        }
        for (name, want) in table(&body.expect.params) {
            let slot = map.slot(ParamMap::parse_param(&name).unwrap()).unwrap();
            assert_eq!(
                i64::from(mem.get_signed(slot.addr, slot.size)),
                want,
                "{}: {name}",
                v.id
            );
        }
        for (name, want) in table(&body.expect.bits) {
            let (n, y) = ParamMap::parse_bit(&name).unwrap();
            assert_eq!(
                mem.bit(map.bit(n, y).unwrap()),
                want == 1,
                "{}: {name}",
                v.id
            );
        }
        for (name, want) in table(&body.expect.dwords) {
            let (lo, _) = name.split_once(':').unwrap();
            let slot = map.slot(ParamMap::parse_param(lo).unwrap()).unwrap();
            assert_eq!(
                i64::from(mem.get_signed(slot.addr, 4)),
                want,
                "{}: {name}",
                v.id
            );
        }
        if let Some(ms) = body.expect.elapsed_ms {
            let elapsed = scans as f64 * f64::from(runtime.scan_us()) / 1000.0;
            assert!(
                (elapsed - ms).abs() < 0.5,
                "{}: {elapsed} ms vs {ms} ms",
                v.id
            );
        }
    }
}
