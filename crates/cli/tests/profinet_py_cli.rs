//! An independent IO controller against `drivespec sim psd4xx --profinet IFACE` in another
//! network namespace: profinet-py (PyPI, GPL-3.0; an external test tool run as a program,
//! `tests/profinet_py_controller.py`, never vendored or linked) finds the device by DCP,
//! reads records without an AR, connects an IO AR with the slots of the generated GSDML,
//! writes and reads records and exchanges cyclic data. The images it reports decode with the
//! PSD4xx codec as bus description 3.2.2, 3.3, 3.5, 3.6 and 3.8 say. `dumpcap` records the
//! traffic on the veth; `tshark` decodes the recording without a warning or error expert
//! info (a malformed packet is an error), and `drivespec check` finds the drive from its
//! Connect and reports no violation.
//!
//! profinet-py and tshark are installed by `.ci/run`; without them the test skips with a
//! message, or fails where `DRIVESPEC_REQUIRE_PROFINET_PY` is set.
#![allow(
    clippy::expect_used,
    clippy::unwrap_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use drivespec_psd4xx::{
    Direction, ImageBuilder, Input, RecordRead, RecordValue, RecordWrite, Rules, Width,
};
use drivespec_spec::{FamilyId, Spec};
use drivespec_testkit::netns::{NetnsPair, NsChild, ADDR_A, ADDR_B};
use drivespec_testkit::{run, temp_dir};
use serde_json::{json, Value};
use std::process::Command;

const BIN: &str = env!("CARGO_BIN_EXE_drivespec");

const SCRIPT: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/tests/profinet_py_controller.py"
);

/// The variable that turns a missing profinet-py or tshark into a failure.
const REQUIRE: &str = "DRIVESPEC_REQUIRE_PROFINET_PY";

/// The NameOfStation of the simulated device.
const NAME: &str = "psd-py";

/// The value written to general purpose register 1 (par. 80, 32 bit, 3.3).
const KEPT: i64 = 0x1234_5678;
/// The value of a write with control byte 0, which the drive ignores (3.2.2).
const IGNORED: i64 = 0x0BAD_F00D;
/// The positioning window (par. 44) written by PKW (3.3 range 1 … 100).
const WINDOW: i64 = 5;

/// Frames on the veth beyond those `drivespec sim` counts (the kernel's ARP answers and
/// probes) are fewer than this: a recording this much longer holds a datagram sent after
/// the device stopped.
const MARGIN: u64 = 12;

/// Sends a UDP datagram to the discard port of the address in argv\[1\] every 20 ms.
const PUSH: &str = "import socket, sys, time\n\
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)\n\
while True:\n    s.sendto(b'end', (sys.argv[1], 9)); time.sleep(0.02)\n";

/// What is missing of profinet-py, dumpcap and tshark, if anything.
fn missing_tools() -> Option<String> {
    let works = |program: &str, args: &[&str]| {
        Command::new(program)
            .args(args)
            .output()
            .is_ok_and(|o| o.status.success())
    };
    let mut missing = Vec::new();
    if !works("python3", &["-c", "import profinet"]) {
        missing.push("profinet-py (python3 -m pip install profinet-py==0.6.6)");
    }
    if !works("tshark", &["-v"]) || !works("dumpcap", &["-v"]) {
        missing.push("tshark (apt-get install tshark)");
    }
    (!missing.is_empty()).then(|| missing.join(", "))
}

/// The bits of the named input fields (`status` only at `status_mask`): the mask a wait of
/// the controller compares.
fn input_mask(rules: &Rules, status_mask: u16) -> Vec<u8> {
    let image = |ones: bool| {
        let mut b = ImageBuilder::new(rules, Direction::In);
        for name in ["pke", "pwe"] {
            let v = if ones { 0xFFFF_FFFF } else { 0 };
            if b.set(name, v).is_err() {
                b.set(name, if ones { 0xFFFF } else { 0 }).unwrap();
            }
        }
        b.set("status", if ones { i64::from(status_mask) } else { 0 })
            .unwrap();
        b.into_bytes()
    };
    image(true)
        .iter()
        .zip(image(false))
        .map(|(a, b)| a ^ b)
        .collect()
}

/// A cyclic step of the plan: the output image with `control` and the PKW request `pkw`,
/// until the input's PKW block is `reply` and its status has `status` at `toggle`.
fn step(rules: &Rules, control: u16, pkw: &str, reply: &str, toggle: u16, status: u16) -> Value {
    let mut out = ImageBuilder::new(rules, Direction::Out);
    out.set("control", i64::from(control))
        .unwrap()
        .pkw(pkw)
        .unwrap();
    let mut want = ImageBuilder::new(rules, Direction::In);
    want.set("status", i64::from(status))
        .unwrap()
        .pkw(reply)
        .unwrap();
    let mask = input_mask(rules, toggle);
    let want: Vec<u8> = want.bytes().iter().zip(&mask).map(|(w, m)| w & m).collect();
    json!({"output": hex(out.bytes()), "until": [hex(&mask), hex(&want)]})
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

fn unhex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

/// The data of a record answer; panics with the refusal.
fn data(v: &Value, what: &str) -> Vec<u8> {
    let d = v["data"]
        .as_str()
        .unwrap_or_else(|| panic!("{what}: refused: {v}"));
    unhex(d)
}

/// The frames `drivespec sim` received and sent, from its last line
/// (`… N frame(s) received, M sent; …`).
fn frames(sim_log: &str) -> u64 {
    let line = sim_log
        .lines()
        .find(|l| l.contains("frame(s) received"))
        .unwrap_or_else(|| panic!("no frame counts: {sim_log}"));
    let (_, rest) = line.rsplit_once(": ").unwrap();
    let received: u64 = rest.split(' ').next().unwrap().parse().unwrap();
    let (_, sent) = rest.split_once("received, ").unwrap();
    let sent: u64 = sent.split(' ').next().unwrap().parse().unwrap();
    received + sent
}

/// The bit of the bitfield `id` named `name` (3.6, 3.7).
fn bit(spec: &Spec, id: &str, name: &str) -> u16 {
    let f = spec.family(FamilyId::Psd4xx).bitfield(id).unwrap();
    let b = f.bits.iter().find(|b| b.name == name).unwrap();
    1 << b.bit
}

#[test]
fn profinet_py_exchanges_records_and_cyclic_data_with_the_simulated_device() {
    if let Some(missing) = missing_tools() {
        let msg = format!("not installed: {missing}");
        assert!(std::env::var_os(REQUIRE).is_none(), "{msg}");
        println!("skipping: {msg}");
        return;
    }
    let spec = Spec::builtin().unwrap();
    let family = spec.family(FamilyId::Psd4xx);
    let pn = &family.psd4xx().unwrap().profinet;
    let rules = Rules::from_spec(&spec).unwrap();
    let records = rules.record();
    let Some(pair) = NetnsPair::create() else {
        return;
    };
    let dir = temp_dir("profinet-py", "wire");
    std::fs::create_dir_all(&dir).unwrap();
    let gsdml = dir.join("psd4xx.xml");
    let (code, _, err) = run(
        BIN,
        &["spec", "gsdml", "psd4xx", "--out", gsdml.to_str().unwrap()],
    );
    assert_eq!(code, 0, "{err}");
    // The recording runs from before the device starts to after it stops.
    let pcap = dir.join("profinet-py.pcapng");
    let mut dumpcap = pair.b.command("dumpcap");
    // At most 60 s: a recorder that never counts the frames ends, and the test with it.
    dumpcap
        .args(["-i", &pair.b.iface, "-a", "duration:60", "-w"])
        .arg(&pcap);
    let mut dumpcap = NsChild::spawn_piped(dumpcap);
    dumpcap.wait_err_line("Capturing on");
    let mut sim = pair.a.command(BIN);
    sim.args(["sim", "psd4xx", "--profinet", &pair.a.iface, "--name", NAME])
        .args(["--time-limit", "60"]);
    let mut sim = NsChild::spawn_piped(sim);
    assert_eq!(
        sim.wait_line("profinet:"),
        format!("{}/{NAME}", pair.a.iface)
    );

    // The plan: records 3.2.2 (index = parameter number, a control byte before the value),
    // then the PKW channel and the toggle bit in the cyclic images (3.5, 3.6, 3.8).
    let (o, i) = (&pn.output, &pn.input);
    let write = |control: u8, value: i64| {
        let w = RecordWrite {
            index: 80,
            control,
            width: Width::Dword,
            value,
        };
        json!({"write": [o.slot, o.subslot, 80, hex(&w.to_bytes(records).unwrap())]})
    };
    let read = |index: u16| json!({"read": [o.slot, o.subslot, index]});
    let toggle_in = bit(&spec, "status", "Toggle bit");
    let toggle_out = bit(&spec, "control", "Toggle bit");
    let plan = json!({
        "implicit": [[o.slot, o.subslot, 44], [0, 1, 0xAFF0]],
        "output": [o.slot, o.subslot],
        "input": [i.slot, i.subslot],
        "actions": [
            write(1, KEPT),
            read(80),
            write(records.control_ignore(), IGNORED),
            read(80),
            step(&rules, toggle_out, "read:80", &format!("value:80={KEPT}"), toggle_in, toggle_in),
            step(&rules, 0, "none", "none", toggle_in, 0),
            step(&rules, 0, &format!("write:44={WINDOW}"), &format!("value:44={WINDOW}"), 0, 0),
            read(44),
        ],
    });
    let mut py = pair.b.command("python3");
    py.arg(SCRIPT)
        .args([&pair.b.iface, NAME])
        .arg(&gsdml)
        .arg(plan.to_string());
    let (code, out, err) = NsChild::spawn_piped(py).finish();
    let sim_log = sim.interrupt().2;
    assert_eq!(code, 0, "profinet-py:\n{err}\nsim:\n{sim_log}");
    // The recorder gets frames from the kernel in blocks and writes its count only when
    // frames arrive, so datagrams sent after the device stopped (and the ICMP answers to
    // them) push the last frames of the exchange into the recording: once the count is
    // MARGIN past the frames the device sent and received, a datagram after them is in.
    let on_wire = frames(&sim_log) + MARGIN;
    let mut push = pair.a.command("python3");
    push.args(["-c", PUSH, &ADDR_B.to_string()]);
    let push = NsChild::spawn(push);
    dumpcap.wait_err_piece(|p| {
        p.trim()
            .strip_prefix("Packets: ")
            .and_then(|n| n.trim().parse::<u64>().ok())
            .is_some_and(|n| n >= on_wire)
    });
    drop(push);
    let capture_log = dumpcap.interrupt();
    let got: Value = serde_json::from_str(&out).unwrap();

    // DCP (IEC 61158-6-10 Identify): the identity of [protocol.profinet], the interface's IP.
    let me = json!({"name": NAME, "vendor_id": pn.vendor_id, "device_id": pn.device_id});
    assert!(got["scan"].as_array().unwrap().contains(&me), "{got}");
    assert_eq!(got["found"]["name"], NAME);
    assert_eq!(got["found"]["ip"], ADDR_A.to_string());
    // Read Implicit: par. 44 is 2 on delivery (3.3), in 2 bytes (3.2.2); I&M0 names the vendor.
    let delivery = family.parameter("44").unwrap().default.unwrap();
    let window = RecordRead::parse(records, 44, &data(&got["implicit"][0], "read 44")).unwrap();
    assert_eq!(
        window.value,
        RecordValue::Number {
            width: Width::Word,
            value: delivery
        }
    );
    let im0 = data(&got["implicit"][1], "I&M0");
    assert_eq!(im0.get(..2), Some(&[0x00, 0x20][..]), "I&M0 block type");
    assert_eq!(
        im0.get(6..8),
        Some(&pn.vendor_id.to_be_bytes()[..]),
        "I&M0 VendorID"
    );

    // In the IO AR: a write with control byte 1 is kept, one with 0 ignored (3.2.2).
    let a = got["actions"].as_array().unwrap();
    let value =
        |v: &Value, index: u16, what: &str| match RecordRead::parse(records, index, &data(v, what))
            .unwrap()
            .value
        {
            RecordValue::Number { value, .. } => value,
            other => panic!("{what}: {other:?}"),
        };
    data(&a[0], "write 80");
    assert_eq!(value(&a[1], 80, "read 80"), KEPT);
    data(&a[2], "write 80 with control byte 0");
    assert_eq!(
        value(&a[3], 80, "read 80 after the ignored write"),
        KEPT,
        "a write with control byte 0 is ignored (3.2.2)"
    );

    // Cyclic: PKW read of par. 80 answers 2 (double word) with the value (3.8); the toggle
    // bit of the control word shows in status bit 2 (3.6); "no command" gets "no response".
    let input = |k: usize| {
        let step = &a[k];
        assert_eq!(step["met"], true, "step {k}: {step}");
        let bytes = unhex(step["input"].as_str().unwrap());
        (Input::parse(&rules, &bytes).unwrap(), step)
    };
    let expect = |reply: &str| {
        let mut b = ImageBuilder::new(&rules, Direction::In);
        b.pkw(reply).unwrap();
        Input::parse(&rules, b.bytes()).unwrap().pkw
    };
    let (read80, s) = input(4);
    assert_eq!(read80.pkw, expect(&format!("value:80={KEPT}")), "{s}");
    assert_eq!(read80.pkw.ak, rules.pkw().response_codes().value_dword);
    assert_ne!(
        read80.status & toggle_in,
        0,
        "toggle bit echoed: {read80:?}"
    );
    let (idle, s) = input(5);
    assert_eq!(idle.pkw.ak, rules.pkw().response_codes().no_response, "{s}");
    assert_eq!(idle.status & toggle_in, 0, "toggle bit cleared: {idle:?}");
    let (wrote, s) = input(6);
    assert_eq!(wrote.pkw, expect(&format!("value:44={WINDOW}")), "{s}");
    assert_eq!(wrote.pkw.ak, rules.pkw().response_codes().value_word);
    assert_eq!(s["iops_good"], true, "{s}");
    // The PKW write is the parameter the record reads (3.2.2: the same parameter number).
    assert_eq!(value(&a[7], 44, "read 44 after the PKW write"), WINDOW);

    // The recording: tshark finds no malformed packet and no warning or error.
    let expert = Command::new("tshark")
        .arg("-r")
        .arg(&pcap)
        .args(["-q", "-z", "expert,warn"])
        .output()
        .expect("run tshark");
    let expert_out = String::from_utf8_lossy(&expert.stdout);
    assert!(
        expert.status.success(),
        "{}",
        String::from_utf8_lossy(&expert.stderr)
    );
    println!("tshark -z expert,warn:{expert_out}");
    if expert_out.contains("Errors (") || expert_out.contains("Warns (") {
        let listing = Command::new("tshark")
            .arg("-r")
            .arg(&pcap)
            .output()
            .unwrap();
        panic!(
            "{expert_out}\n{}\ndumpcap: {}",
            String::from_utf8_lossy(&listing.stdout),
            capture_log.2
        );
    }
    // drivespec check: the drive found from the Connect, no violation.
    let (code, report, err) = run(BIN, &["check", pcap.to_str().unwrap(), "--report", "json"]);
    assert_eq!(code, 0, "{err}{report}");
    let doc: Value = serde_json::from_str(&report).unwrap();
    let r = &doc["reports"][0];
    let drives = r["drives"].as_array().unwrap();
    assert_eq!(drives.len(), 1, "{report}");
    assert_eq!(drives[0]["family"], "psd4xx");
    assert_eq!(drives[0]["found_by"], "connect");
    assert_eq!(drives[0]["details"]["slot"], o.slot);
    assert_eq!(r["violation_count"], 0, "{}", r["violations"]);
    std::fs::remove_dir_all(&dir).unwrap();
    drop(pair);
}
