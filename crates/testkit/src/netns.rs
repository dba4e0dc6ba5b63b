//! A test bed of two network namespaces joined by a veth pair (`ip netns`, `ip link`), for
//! tests that send real frames between two processes on one machine.
//!
//! Names are unique per process and pair (`drivespec-<pid>-<n>-a|b`, interfaces
//! `ds<pid>-<n>a|b`, at most 15 characters), so tests may run in parallel. Dropping a
//! [`NetnsPair`] kills the processes started in it and deletes both namespaces (which removes
//! the veth pair), also when the test panics; namespaces left by a killed run (their pid no
//! longer running) are deleted when the next pair is made. Where the kernel or the user
//! refuses namespaces (not root, no CAP_NET_ADMIN), [`NetnsPair::create`] prints why and
//! returns `None`, unless `DRIVESPEC_REQUIRE_NETNS` is set, where it panics instead.
//!
//! Code inside a namespace runs in a child process: a program through [`Netns::command`], or
//! the calling test itself through [`Netns::spawn_test`] with a role that [`role`] returns in
//! the child.

use std::io::{BufRead, BufReader, Read};
use std::net::Ipv4Addr;
use std::process::{Child, ChildStderr, ChildStdout, Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};

/// Prefix of every namespace this module makes.
const PREFIX: &str = "drivespec-";

/// The environment variable that tells a test started by [`Netns::spawn_test`] its role.
const ROLE_VAR: &str = "DRIVESPEC_NETNS_ROLE";

/// The environment variable that turns a refusal of namespaces into a test failure.
const REQUIRE_VAR: &str = "DRIVESPEC_REQUIRE_NETNS";

/// The address of the veth end in namespace `a`.
pub const ADDR_A: Ipv4Addr = Ipv4Addr::new(10, 88, 92, 1);

/// The address of the veth end in namespace `b`.
pub const ADDR_B: Ipv4Addr = Ipv4Addr::new(10, 88, 92, 2);

/// Turns IPv6 off in a namespace (where the kernel has it), so that no router solicitation
/// or listener report joins the frames a test sends.
const IPV6_OFF: &str = "[ ! -d /proc/sys/net/ipv6 ] || for c in all default; do \
    echo 1 > /proc/sys/net/ipv6/conf/$c/disable_ipv6; done";

static NEXT: AtomicU32 = AtomicU32::new(0);

/// The role given by [`Netns::spawn_test`], in the child it started; `None` in a test run
/// directly.
pub fn role() -> Option<String> {
    std::env::var(ROLE_VAR).ok()
}

/// One network namespace of a [`NetnsPair`].
#[derive(Debug)]
pub struct Netns {
    /// Its name for `ip netns`.
    pub name: String,
    /// Its end of the veth pair.
    pub iface: String,
    /// The IPv4 address of that end (prefix /24).
    pub addr: Ipv4Addr,
}

impl Netns {
    /// `program` to be run inside this namespace (`ip netns exec NAME program`).
    pub fn command(&self, program: &str) -> Command {
        let mut c = Command::new("ip");
        c.args(["netns", "exec", &self.name, program]);
        c
    }

    /// Starts the test `test` of the running test binary inside this namespace, alone and
    /// with its output shown, with [`role`] returning `role` and the variables of `env` set;
    /// stdout is piped.
    pub fn spawn_test(&self, test: &str, role: &str, env: &[(&str, &str)]) -> NsChild {
        let exe = std::env::current_exe().expect("the test binary's path");
        let mut c = self.command(&exe.display().to_string());
        c.args([test, "--exact", "--nocapture", "--test-threads=1"])
            .env(ROLE_VAR, role)
            .envs(env.iter().copied());
        NsChild::spawn(c)
    }

    fn ip(&self, args: &[&str]) {
        let mut c = self.command("ip");
        c.args(args);
        check(c);
    }
}

/// A process started in a namespace, killed when dropped; stdout (and stderr, if piped) is
/// read by line.
#[derive(Debug)]
pub struct NsChild {
    child: Child,
    stdout: BufReader<ChildStdout>,
    stderr: Option<BufReader<ChildStderr>>,
}

/// How a process ended: its exit code (-1 when killed by a signal), the rest of its stdout
/// and of its stderr (empty when inherited).
pub type Ended = (i32, String, String);

impl NsChild {
    /// Starts `c` with stdout piped and stderr inherited.
    pub fn spawn(c: Command) -> Self {
        Self::start(c, false)
    }

    /// Starts `c` with stdout and stderr piped.
    pub fn spawn_piped(c: Command) -> Self {
        Self::start(c, true)
    }

    fn start(mut c: Command, pipe_stderr: bool) -> Self {
        let mut child = c
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(if pipe_stderr {
                Stdio::piped()
            } else {
                Stdio::inherit()
            })
            .spawn()
            .expect("start a process in the namespace");
        let stdout = BufReader::new(child.stdout.take().expect("piped stdout"));
        let stderr = child.stderr.take().map(BufReader::new);
        Self {
            child,
            stdout,
            stderr,
        }
    }

    /// The process id.
    pub fn id(&self) -> u32 {
        self.child.id()
    }

    /// Reads stdout until a line containing `marker` (libtest may print its own words before
    /// it on the same line), and returns the rest of that line; panics when stdout ends first.
    pub fn wait_line(&mut self, marker: &str) -> String {
        until(&mut self.stdout, marker, "stdout")
    }

    /// As [`NsChild::wait_line`], on stderr (started with [`NsChild::spawn_piped`]).
    pub fn wait_err_line(&mut self, marker: &str) -> String {
        let err = self.stderr.as_mut().expect("stderr is piped");
        until(err, marker, "stderr")
    }

    /// Reads stderr (started with [`NsChild::spawn_piped`]) until `done` holds for a piece
    /// of it, and returns that piece; pieces end at a newline or a carriage return (the
    /// progress counts of `dumpcap`). Panics when stderr ends first.
    pub fn wait_err_piece(&mut self, mut done: impl FnMut(&str) -> bool) -> String {
        let err = self.stderr.as_mut().expect("stderr is piped");
        let mut piece = Vec::new();
        loop {
            let mut byte = [0u8; 1];
            let n = err.read(&mut byte).expect("read stderr");
            assert!(
                n > 0,
                "the process ended before the awaited output on stderr"
            );
            if byte[0] == b'\n' || byte[0] == b'\r' {
                let text = String::from_utf8_lossy(&piece).into_owned();
                if done(&text) {
                    return text;
                }
                piece.clear();
            } else {
                piece.push(byte[0]);
            }
        }
    }

    /// Sends SIGINT (`kill -INT`), so that the process ends the way Ctrl-C ends it (a
    /// recorder flushes its file), and waits for it to end.
    pub fn interrupt(self) -> Ended {
        let pid = self.child.id().to_string();
        let sent = Command::new("kill")
            .args(["-INT", &pid])
            .status()
            .expect("run kill");
        assert!(sent.success(), "kill -INT {pid}");
        self.finish()
    }

    /// Waits for the process to end.
    pub fn finish(mut self) -> Ended {
        let mut out = String::new();
        let _ = self.stdout.read_to_string(&mut out);
        let mut err = String::new();
        if let Some(e) = self.stderr.as_mut() {
            let _ = e.read_to_string(&mut err);
        }
        let code = self.child.wait().expect("wait for the process").code();
        (code.unwrap_or(-1), out, err)
    }
}

fn until(r: &mut impl BufRead, marker: &str, what: &str) -> String {
    let mut line = String::new();
    loop {
        line.clear();
        let n = r.read_line(&mut line).expect("read the output");
        assert!(
            n > 0,
            "the process ended before printing `{marker}` on {what}"
        );
        if let Some((_, rest)) = line.trim_end().split_once(marker) {
            return rest.to_owned();
        }
    }
}

impl Drop for NsChild {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Two namespaces `a` and `b` joined by a veth pair with addresses [`ADDR_A`] and [`ADDR_B`],
/// links up and IPv6 off (no router solicitations on the wire); deleted when dropped.
#[derive(Debug)]
pub struct NetnsPair {
    /// The first namespace.
    pub a: Netns,
    /// The second namespace.
    pub b: Netns,
}

impl NetnsPair {
    /// Makes a pair, or prints why it cannot and returns `None` (panics instead when
    /// `DRIVESPEC_REQUIRE_NETNS` is set).
    pub fn create() -> Option<Self> {
        remove_stale();
        let pid = std::process::id();
        let n = NEXT.fetch_add(1, Ordering::Relaxed);
        let ns = |side: &str, addr| Netns {
            name: format!("{PREFIX}{pid}-{n}-{side}"),
            iface: format!("ds{pid}-{n}{side}"),
            addr,
        };
        let (a, b) = (ns("a", ADDR_A), ns("b", ADDR_B));
        if let Err(why) = add_namespace(&a.name) {
            let msg = format!("skipping: network namespaces are refused here ({why})");
            assert!(std::env::var_os(REQUIRE_VAR).is_none(), "{msg}");
            println!("{msg}");
            return None;
        }
        // Made from here on: dropped (and deleted) on any failure below.
        let pair = Self { a, b };
        add_namespace(&pair.b.name).expect("add the second namespace");
        let mut link = Command::new("ip");
        link.args(["link", "add", &pair.a.iface, "netns", &pair.a.name])
            .args(["type", "veth", "peer", "name", &pair.b.iface])
            .args(["netns", &pair.b.name]);
        check(link);
        for ns in [&pair.a, &pair.b] {
            let mut off = ns.command("sh");
            off.args(["-c", IPV6_OFF]);
            check(off);
            ns.ip(&["addr", "add", &format!("{}/24", ns.addr), "dev", &ns.iface]);
            ns.ip(&["link", "set", &ns.iface, "up"]);
            ns.ip(&["link", "set", "lo", "up"]);
        }
        Some(pair)
    }
}

impl Drop for NetnsPair {
    fn drop(&mut self) {
        for ns in [&self.a, &self.b] {
            let _ = Command::new("ip")
                .args(["netns", "del", &ns.name])
                .stderr(Stdio::null())
                .status();
        }
    }
}

fn add_namespace(name: &str) -> Result<(), String> {
    let out = Command::new("ip")
        .args(["netns", "add", name])
        .output()
        .map_err(|e| format!("cannot run `ip`: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(String::from_utf8_lossy(&out.stderr).trim().to_owned())
    }
}

fn check(mut c: Command) {
    let out = c.output().expect("run ip");
    assert!(
        out.status.success(),
        "{c:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Deletes the namespaces of this module whose process is no longer running.
pub fn remove_stale() {
    let Ok(out) = Command::new("ip").args(["netns", "list"]).output() else {
        return;
    };
    for line in String::from_utf8_lossy(&out.stdout).lines() {
        let Some(name) = line.split_whitespace().next() else {
            continue;
        };
        let Some(pid) = name
            .strip_prefix(PREFIX)
            .and_then(|rest| rest.split('-').next())
        else {
            continue;
        };
        if !std::path::Path::new("/proc").join(pid).exists() {
            let _ = Command::new("ip")
                .args(["netns", "del", name])
                .stderr(Stdio::null())
                .status();
        }
    }
}
