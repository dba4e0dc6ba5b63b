//! Frames sent with `drivespec-wire` in one network namespace arrive in the other over a veth
//! pair: all of them, in order. The one-way latency and the arrival jitter are printed, not
//! asserted (speed is measured, never a verdict).
#![allow(
    clippy::expect_used,
    clippy::unwrap_used,
    clippy::panic,
    clippy::indexing_slicing
)]

use drivespec_testkit::netns::{self, NetnsPair};
use drivespec_wire::{Filter, OpenOptions, RawSocket, WireError};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

const TEST: &str = "thousand_frames_cross_the_veth_pair_in_order";

/// IEEE 802 local experimental EtherType 1: these test frames are no protocol's.
const EXPERIMENTAL: u16 = 0x88B5;

const FRAMES: u32 = 1000;

/// The send period: the 1 ms send clock PROFINET RT class 1 uses by default.
const PERIOD: Duration = Duration::from_millis(1);

fn nanos(t: SystemTime) -> u64 {
    t.duration_since(UNIX_EPOCH).unwrap().as_nanos() as u64
}

fn open(iface: &str) -> RawSocket {
    let filter = Filter::ether_types(&[EXPERIMENTAL]);
    RawSocket::open(
        iface,
        OpenOptions {
            filter,
            ..OpenOptions::default()
        },
    )
    .expect("open")
}

fn mac_hex(mac: [u8; 6]) -> String {
    mac.iter().map(|b| format!("{b:02x}")).collect()
}

/// Sends FRAMES frames, one per PERIOD: sequence number and send time in the payload.
fn send(iface: &str, dst: &str) {
    let mut sock = open(iface);
    let dst: Vec<u8> = (0..6)
        .map(|i| u8::from_str_radix(&dst[2 * i..2 * i + 2], 16).unwrap())
        .collect();
    let src = sock.interface().mac.unwrap();
    let start = Instant::now();
    for seq in 0..FRAMES {
        let due = start + PERIOD * seq;
        if let Some(wait) = due.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
        let mut f = [dst.as_slice(), &src].concat();
        f.extend_from_slice(&EXPERIMENTAL.to_be_bytes());
        f.extend_from_slice(&seq.to_be_bytes());
        f.extend_from_slice(&nanos(SystemTime::now()).to_be_bytes());
        f.resize(60, 0);
        sock.send(&f).expect("send");
    }
}

/// Receives until FRAMES frames or 5 s of silence; prints the sequence numbers' order and the
/// latency figures.
fn receive(iface: &str) {
    let mut sock = open(iface);
    println!("ready: {}", mac_hex(sock.interface().mac.unwrap()));
    let mut seqs = Vec::new();
    let mut lat = Vec::new();
    let mut arrivals = Vec::new();
    while seqs.len() < FRAMES as usize {
        let Some(r) = sock.recv(Duration::from_secs(5)).expect("receive") else {
            break;
        };
        let seq = u32::from_be_bytes(r.frame[14..18].try_into().unwrap());
        let sent = u64::from_be_bytes(r.frame[18..26].try_into().unwrap());
        seqs.push(seq);
        lat.push(nanos(r.at).saturating_sub(sent) as f64 / 1000.0);
        arrivals.push(r.instant);
    }
    let in_order = seqs.iter().enumerate().all(|(i, s)| *s == i as u32);
    let gaps: Vec<f64> = arrivals
        .windows(2)
        .map(|w| (w[1] - w[0]).as_secs_f64() * 1e6 - PERIOD.as_secs_f64() * 1e6)
        .collect();
    println!(
        "result: {} {in_order} latency(us) {} arrival-jitter(us) {}",
        seqs.len(),
        stats(&mut lat),
        stats(&mut gaps.iter().map(|g| g.abs()).collect::<Vec<_>>())
    );
}

/// Mean, p50, p99 and max of `v`.
fn stats(v: &mut [f64]) -> String {
    if v.is_empty() {
        return "none".into();
    }
    v.sort_by(f64::total_cmp);
    let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    format!(
        "mean {mean:.1} p50 {:.1} p99 {:.1} max {:.1}",
        at(0.5),
        at(0.99),
        at(1.0)
    )
}

#[test]
fn thousand_frames_cross_the_veth_pair_in_order() {
    if let Some(role) = netns::role() {
        let iface = std::env::var("DRIVESPEC_IFACE").unwrap();
        match role.as_str() {
            "send" => send(&iface, &std::env::var("DRIVESPEC_DST").unwrap()),
            _ => receive(&iface),
        }
        return;
    }
    let Some(pair) = NetnsPair::create() else {
        return;
    };
    let mut rx = pair
        .b
        .spawn_test(TEST, "recv", &[("DRIVESPEC_IFACE", &pair.b.iface)]);
    let dst = rx.wait_line("ready: ");
    let tx = pair.a.spawn_test(
        TEST,
        "send",
        &[("DRIVESPEC_IFACE", &pair.a.iface), ("DRIVESPEC_DST", &dst)],
    );
    let (code, _, _) = tx.finish();
    assert_eq!(code, 0, "the sender failed");
    let result = rx.wait_line("result: ");
    println!("veth one-way, {FRAMES} frames at 1 ms: {result}");
    let mut words = result.split_whitespace();
    assert_eq!(words.next(), Some("1000"), "frames lost: {result}");
    assert_eq!(words.next(), Some("true"), "order not kept: {result}");
}

#[test]
fn unknown_interfaces_are_named() {
    match RawSocket::open("no-such-if0", OpenOptions::default()) {
        Err(WireError::NoSuchInterface { name, present }) => {
            assert_eq!(name, "no-such-if0");
            assert!(present.contains("lo"), "{present}");
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn frames_outside_ethernet_lengths_are_refused() {
    // Needs a raw socket: as root, or skipped with a message.
    let mut sock = match RawSocket::open("lo", OpenOptions::default()) {
        Ok(s) => s,
        Err(e @ WireError::PermissionDenied { .. }) => {
            assert!(
                e.to_string().contains("cap_net_raw,cap_net_admin+ep"),
                "{e}"
            );
            println!("skipping: {e}");
            return;
        }
        Err(e) => panic!("{e}"),
    };
    for len in [13, 1519] {
        match sock.send(&vec![0; len]) {
            Err(WireError::FrameLength { len: l, .. }) => assert_eq!(l, len),
            other => panic!("{len}: {other:?}"),
        }
    }
}
