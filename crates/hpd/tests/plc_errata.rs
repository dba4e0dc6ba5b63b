//! The PLC interpreter follows the erratum reading chosen for each selectable erratum
//! (HPD-ERRATUM-001, 051, 054, 059, 068), and the adopted one by default.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_hpd::memory::{Memory, ParamMap};
use drivespec_hpd::plc::{PlcRuntime, PlcState};
use drivespec_spec::{FamilyId, Readings, Spec};

struct Run {
    mem: Memory,
    map: ParamMap,
}

impl Run {
    fn word(&self, p: u8) -> i32 {
        let s = self.map.slot(p).unwrap();
        self.mem.get_signed(s.addr, s.size)
    }
    fn bit(&self, p: u8, y: u8) -> bool {
        self.mem.bit(self.map.bit(p, y).unwrap())
    }
}

/// Runs `listing` for `scans` scans with `setup` applied, under `choice` (option, reading).
fn run(
    choice: Option<(&str, &str)>,
    listing: &str,
    scans: usize,
    inputs: u16,
    setup: impl Fn(&mut Memory, &ParamMap),
) -> Run {
    let spec = Spec::builtin().unwrap();
    let mut readings = Readings::default();
    if let Some((option, reading)) = choice {
        readings
            .choose(spec.family(FamilyId::Hpd), option, reading)
            .unwrap();
    }
    let rt = PlcRuntime::from_spec(&spec, &readings).unwrap();
    let map = ParamMap::from_spec(&spec);
    let program = rt.codec().parse_listing(listing).unwrap();
    let mut mem = Memory::default();
    mem.set_bit(map.bit(99, 13).unwrap(), true);
    mem.set_bit(map.bit(91, 8).unwrap(), true);
    setup(&mut mem, &map);
    let mut state = PlcState::default();
    for _ in 0..scans {
        rt.fast_inputs(&mut mem, &program, inputs);
        rt.scan(&mut state, &mut mem, &program, inputs);
    }
    Run { mem, map }
}

fn set(mem: &mut Memory, map: &ParamMap, p: u8, v: i32) {
    let s = map.slot(p).unwrap();
    mem.set(s.addr, s.size, v as u32);
}

#[test]
fn zero_flag_follows_option_b99_3() {
    let prog = "LD 91.8\nSUB 80,80,81\nEND\n";
    let adopted = run(None, prog, 1, 0, |m, map| set(m, map, 80, 7));
    assert!(
        adopted.bit(99, 3),
        "zero result sets b99.3 (adopted reading 'zero')"
    );
    let other = run(Some(("b99-3", "nonzero")), prog, 1, 0, |m, map| {
        set(m, map, 80, 7)
    });
    assert!(!other.bit(99, 3));
}

#[test]
fn double_word_div_follows_option_div_remainder() {
    let prog = "LD 91.8\nDIV 79,77,80\nEND\n";
    let force = |m: &mut Memory, map: &ParamMap| m.set_bit(map.bit(94, 0).unwrap(), true);
    let adopted = run(None, prog, 1, 0, force);
    assert_eq!((adopted.word(80), adopted.word(81)), (4, 96));
    let other = run(Some(("div-remainder", "quotient32")), prog, 1, 0, force);
    assert_eq!((other.word(80), other.word(81)), (4, 0));
}

#[test]
fn pr69_follows_option_dword_pr69() {
    let prog = "LD 91.8\nADD 71,72,69\nEND\n";
    let adopted = run(None, prog, 1, 0, |m, map| set(m, map, 69, 5));
    assert_eq!(adopted.word(69), -1);
    let other = run(Some(("dword-pr69", "pr60-68")), prog, 1, 0, |m, map| {
        set(m, map, 69, 5)
    });
    assert_eq!(other.word(69), -1, "a word result");
    // Only a double-word result also writes the word at the next address (here Pb91, whose
    // b91.8 the harness sets): the two readings differ there.
    let next = |r: &Run| r.mem.get(r.map.slot(69).unwrap().addr.wrapping_add(2), 2);
    assert_eq!(next(&adopted), 0xFFFF);
    assert_eq!(next(&other), 0x0100, "left as it was");
}

#[test]
fn fin_disable_bits_follow_option_fin_disable() {
    let prog = "FIN 3,1\nEND\n";
    let adopted = run(None, prog, 1, 0b10, |_, _| {});
    assert!(
        adopted.bit(70, 3),
        "b94.5 = 0 enables the first FIN (adopted 'one-disables')"
    );
    let other = run(
        Some(("fin-disable", "zero-disables")),
        prog,
        1,
        0b10,
        |_, _| {},
    );
    assert!(!other.bit(70, 3));
}

#[test]
fn timer_flag_follows_option_timer_flag() {
    let prog = "END\n";
    let adopted = run(None, prog, 1, 0, |m, map| set(m, map, 92, 1));
    assert_eq!((adopted.word(92), adopted.bit(99, 0)), (0, true));
    let other = run(Some(("timer-flag", "next-update")), prog, 1, 0, |m, map| {
        set(m, map, 92, 1)
    });
    assert_eq!((other.word(92), other.bit(99, 0)), (0, false));
    let later = run(Some(("timer-flag", "next-update")), prog, 2, 0, |m, map| {
        set(m, map, 92, 1)
    });
    assert!(later.bit(99, 0));
}
