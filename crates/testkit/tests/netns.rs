//! The namespace test bed cleans up: a pair is gone after its drop, also when the test body
//! panics, and namespaces of a run that was killed are removed by the next pair. Skips where
//! namespaces are refused.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use drivespec_testkit::netns::{remove_stale, NetnsPair};
use std::process::Command;

fn namespaces() -> String {
    let out = Command::new("ip").args(["netns", "list"]).output().unwrap();
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn listed(name: &str) -> bool {
    namespaces()
        .lines()
        .any(|l| l.split_whitespace().next() == Some(name))
}

#[test]
fn pairs_are_removed_on_drop_and_on_panic() {
    let Some(pair) = NetnsPair::create() else {
        return;
    };
    let names = [pair.a.name.clone(), pair.b.name.clone()];
    assert!(names.iter().all(|n| listed(n)), "{}", namespaces());
    let out = pair
        .a
        .command("ip")
        .args(["-o", "link", "show", &pair.a.iface])
        .output();
    let out = out.unwrap();
    assert!(
        String::from_utf8_lossy(&out.stdout).contains("UP"),
        "{out:?}"
    );
    drop(pair);
    assert!(!names.iter().any(|n| listed(n)), "{}", namespaces());

    let (tx, rx) = std::sync::mpsc::channel();
    let result = std::thread::spawn(move || {
        let pair = NetnsPair::create().unwrap();
        tx.send(pair.a.name.clone()).unwrap();
        panic!("a failing test body");
    })
    .join();
    assert!(result.is_err());
    let name = rx.recv().unwrap();
    assert!(!listed(&name), "{}", namespaces());
}

#[test]
fn leftovers_of_a_killed_run_are_removed() {
    let Some(pair) = NetnsPair::create() else {
        return;
    };
    drop(pair);
    // A pid above pid_max belongs to no process, now or later.
    let max: u64 = std::fs::read_to_string("/proc/sys/kernel/pid_max")
        .unwrap()
        .trim()
        .parse()
        .unwrap();
    let stale = format!("drivespec-{}-0-a", max + 1);
    assert!(Command::new("ip")
        .args(["netns", "add", &stale])
        .status()
        .unwrap()
        .success());
    assert!(listed(&stale));
    remove_stale();
    assert!(!listed(&stale), "{}", namespaces());
}
