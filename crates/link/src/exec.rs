//! `exec:COMMAND ARGS`: a subprocess that speaks the protocol on stdin (requests) and stdout
//! (answers), byte for byte as on the line. Its stderr is kept (the last few KiB) for the
//! evidence when it dies.
//!
//! The process is started directly (no shell). A reader thread and a writer thread move the
//! bytes, so a process that stops reading or writing never blocks the runner; a process that
//! exits is reported as a closed connection with its status and stderr, and `recover` starts
//! it again. Dropping the link kills the process.

use super::{Caps, Chunk, Link, LinkError, Micros, Recovered, WallClock};
use std::io::{Read, Write};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::time::Duration;

/// Most stderr bytes kept for the evidence.
const STDERR_KEEP: usize = 4096;
/// Output chunks (of up to 512 bytes each) read ahead of the session.
const CHUNKS_QUEUED: usize = 256;
/// How long a process that closed its output is given to exit, and its stderr to reach its
/// end, before the evidence is taken (a process holding stderr open is not waited for longer).
const EXIT_GRACE: Duration = Duration::from_millis(500);
/// Steps in which an exit within [`EXIT_GRACE`] is looked for.
const EXIT_POLL: Duration = Duration::from_millis(10);

/// A running subprocess and the threads that move its bytes.
struct Proc {
    child: Child,
    to_child: Sender<Vec<u8>>,
    from_child: Receiver<(Micros, Vec<u8>)>,
    stderr: Arc<Mutex<Vec<u8>>>,
    /// Disconnected once the stderr reader has read to the end.
    stderr_done: Receiver<()>,
}

/// A subprocess speaking the protocol on stdin/stdout.
pub struct ExecLink {
    argv: Vec<String>,
    proc: Option<Proc>,
    clock: WallClock,
    starts: u32,
    /// Nothing came from the process since it started: the first wait gets a start-up grace.
    fresh: bool,
}

/// Extra wait for the first answer of a just-started process (interpreters take a while).
const START_GRACE_US: Micros = 1_000_000;

impl ExecLink {
    /// Starts `argv[0]` with the other words as arguments.
    pub fn spawn(argv: &[String]) -> Result<ExecLink, LinkError> {
        let clock = WallClock::start();
        let proc = start(argv, clock)?;
        Ok(ExecLink {
            argv: argv.to_vec(),
            proc: Some(proc),
            clock,
            starts: 1,
            fresh: true,
        })
    }

    /// How many times the process was started (1 + restarts).
    pub fn starts(&self) -> u32 {
        self.starts
    }

    /// The process ended: its exit status and the tail of its stderr, for the evidence.
    fn ended(&mut self) -> LinkError {
        let detail = match self.proc.take() {
            Some(mut p) => {
                let mut exited = p.child.try_wait();
                let mut waited = Duration::ZERO;
                while matches!(exited, Ok(None)) && waited < EXIT_GRACE {
                    std::thread::sleep(EXIT_POLL);
                    waited += EXIT_POLL;
                    exited = p.child.try_wait();
                }
                let status = match exited {
                    Ok(Some(s)) => format!("; the process exited ({s})"),
                    _ => {
                        let _ = p.child.kill();
                        let _ = p.child.wait();
                        "; the process closed its output and was killed".to_owned()
                    }
                };
                // The reader may not have taken the last lines the process wrote before it
                // ended (Err: it has read to the end, or the grace is over).
                let _ = p.stderr_done.recv_timeout(EXIT_GRACE);
                let tail = p
                    .stderr
                    .lock()
                    .map(|e| String::from_utf8_lossy(&e).trim().to_owned())
                    .unwrap_or_default();
                if tail.is_empty() {
                    status
                } else {
                    format!("{status}; stderr: {tail}")
                }
            }
            None => String::new(),
        };
        LinkError::Closed { detail }
    }
}

impl Drop for ExecLink {
    fn drop(&mut self) {
        if let Some(mut p) = self.proc.take() {
            let _ = p.child.kill();
            let _ = p.child.wait();
        }
    }
}

fn start(argv: &[String], clock: WallClock) -> Result<Proc, LinkError> {
    let (program, args) = argv.split_first().ok_or_else(|| LinkError::Open {
        what: "exec:".to_owned(),
        reason: "no command".to_owned(),
    })?;
    let mut child = Command::new(program)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| LinkError::Open {
            what: format!("exec:{}", argv.join(" ")),
            reason: e.to_string(),
        })?;
    let (stdin, stdout, stderr) =
        match (child.stdin.take(), child.stdout.take(), child.stderr.take()) {
            (Some(i), Some(o), Some(e)) => (i, o, e),
            _ => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(LinkError::Open {
                    what: format!("exec:{}", argv.join(" ")),
                    reason: "no pipes to the process".to_owned(),
                });
            }
        };
    let (to_child, rx) = mpsc::channel::<Vec<u8>>();
    std::thread::spawn(move || writer(stdin, rx));
    // Bounded: a process that floods its output blocks on the pipe instead of filling memory.
    let (tx, from_child) = mpsc::sync_channel(CHUNKS_QUEUED);
    std::thread::spawn(move || {
        let mut stdout = stdout;
        let mut buf = [0u8; 512];
        loop {
            match stdout.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(n) => {
                    let bytes = buf.get(..n).unwrap_or(&[]).to_vec();
                    if tx.send((clock.now(), bytes)).is_err() {
                        break;
                    }
                }
            }
        }
    });
    let keep = Arc::new(Mutex::new(Vec::new()));
    let sink = Arc::clone(&keep);
    let (done, stderr_done) = mpsc::channel::<()>();
    std::thread::spawn(move || {
        let _done = done;
        let mut stderr = stderr;
        let mut buf = [0u8; 512];
        while let Ok(n) = stderr.read(&mut buf) {
            if n == 0 {
                break;
            }
            if let Ok(mut k) = sink.lock() {
                k.extend_from_slice(buf.get(..n).unwrap_or(&[]));
                let extra = k.len().saturating_sub(STDERR_KEEP);
                k.drain(..extra);
            }
        }
    });
    Ok(Proc {
        child,
        to_child,
        from_child,
        stderr: keep,
        stderr_done,
    })
}

fn writer(mut stdin: ChildStdin, rx: Receiver<Vec<u8>>) {
    while let Ok(bytes) = rx.recv() {
        if stdin
            .write_all(&bytes)
            .and_then(|()| stdin.flush())
            .is_err()
        {
            break;
        }
    }
}

impl Link for ExecLink {
    fn describe(&self) -> String {
        let words: Vec<String> = self.argv.iter().map(|w| crate::shell_quote(w)).collect();
        format!("exec:{}", words.join(" "))
    }

    fn caps(&self) -> Caps {
        Caps::default()
    }

    fn now(&mut self) -> Micros {
        self.clock.now()
    }

    fn send(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        let alive = match self.proc.as_mut() {
            Some(p) => matches!(p.child.try_wait(), Ok(None)),
            None => false,
        };
        let sent = alive
            && self
                .proc
                .as_ref()
                .is_some_and(|p| p.to_child.send(bytes.to_vec()).is_ok());
        if sent {
            Ok(())
        } else {
            Err(self.ended())
        }
    }

    fn recv(
        &mut self,
        deadline: Micros,
        enough: &mut dyn FnMut(&[u8]) -> bool,
    ) -> Result<Vec<Chunk>, LinkError> {
        let clock = self.clock;
        let mut chunks = Vec::new();
        let mut all = Vec::new();
        let deadline = if self.fresh {
            deadline.saturating_add(START_GRACE_US)
        } else {
            deadline
        };
        while let Some(left) = clock.until(deadline) {
            let got = match self.proc.as_ref() {
                Some(p) => p
                    .from_child
                    .recv_timeout(left.max(Duration::from_micros(50))),
                None => Err(RecvTimeoutError::Disconnected),
            };
            match got {
                Ok((at, bytes)) => {
                    self.fresh = false;
                    all.extend_from_slice(&bytes);
                    chunks.push(Chunk { at, bytes });
                    if all.len() >= crate::MAX_RECV || enough(&all) {
                        break;
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => {
                    // Give what came before the end; the next call reports the exit.
                    if chunks.is_empty() {
                        return Err(self.ended());
                    }
                    break;
                }
            }
        }
        Ok(chunks)
    }

    fn recover(&mut self) -> Result<Recovered, LinkError> {
        if let Some(mut p) = self.proc.take() {
            let _ = p.child.kill();
            let _ = p.child.wait();
        }
        self.proc = Some(start(&self.argv, self.clock)?);
        self.starts = self.starts.saturating_add(1);
        self.fresh = true;
        Ok(Recovered::Fresh)
    }
}
