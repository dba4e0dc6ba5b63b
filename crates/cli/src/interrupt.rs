//! SIGINT, SIGTERM and `--timeout`: a stop flag that `conform`, `fuzz` and `check` poll
//! between exchanges, cases or records, and the exit code that says what stopped them
//! (130 SIGINT, 143 SIGTERM, 124 time limit, as shells and `timeout(1)` do). A second signal
//! ends the process at once with the same code.

use anyhow::{Context as _, Result};
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::flag;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::Duration;

/// Exit code of a run stopped by its `--timeout`.
const TIMEOUT_EXIT: u8 = 124;

/// What stopped a run: the value of [`Interrupt::cause`] (0: nothing yet).
const BY_TIMEOUT: usize = usize::MAX;

/// The stop flag of a command, set by SIGINT, SIGTERM or the time limit.
pub struct Interrupt {
    stop: Arc<AtomicBool>,
    cause: Arc<AtomicUsize>,
}

impl Interrupt {
    /// Installs the signal handlers and, with `timeout`, a timer that stops the run.
    pub fn install(timeout: Option<Duration>) -> Result<Interrupt> {
        let stop = Arc::new(AtomicBool::new(false));
        let cause = Arc::new(AtomicUsize::new(0));
        for (signal, code) in [(SIGINT, 130), (SIGTERM, 143)] {
            // The shutdown goes first: it fires only when an earlier signal set the flag.
            flag::register_conditional_shutdown(signal, code, Arc::clone(&stop))
                .and_then(|_| flag::register_usize(signal, Arc::clone(&cause), signal as usize))
                .and_then(|_| flag::register(signal, Arc::clone(&stop)))
                .context("installing the signal handlers")?;
        }
        if let Some(limit) = timeout {
            let (stop, cause) = (Arc::clone(&stop), Arc::clone(&cause));
            std::thread::spawn(move || {
                std::thread::sleep(limit);
                let _ = cause.compare_exchange(0, BY_TIMEOUT, Ordering::SeqCst, Ordering::SeqCst);
                stop.store(true, Ordering::SeqCst);
            });
        }
        Ok(Interrupt { stop, cause })
    }

    /// The flag the libraries poll.
    pub fn flag(&self) -> Arc<AtomicBool> {
        Arc::clone(&self.stop)
    }

    /// Whether the run was asked to stop.
    pub fn stopped(&self) -> bool {
        self.stop.load(Ordering::SeqCst)
    }

    /// What stopped the run, in words (`SIGINT`, `SIGTERM`, `the --timeout limit`).
    pub fn cause(&self) -> Option<&'static str> {
        match self.cause.load(Ordering::SeqCst) {
            0 => None,
            BY_TIMEOUT => Some("the --timeout limit"),
            s if s == SIGTERM as usize => Some("SIGTERM"),
            _ => Some("SIGINT"),
        }
    }

    /// The exit code of a stopped run (None: not stopped).
    pub fn exit_code(&self) -> Option<u8> {
        if !self.stopped() {
            return None;
        }
        Some(match self.cause.load(Ordering::SeqCst) {
            BY_TIMEOUT => TIMEOUT_EXIT,
            s if s == SIGTERM as usize => 143,
            _ => 130,
        })
    }
}

/// `90s`, `10m`, `2h`, `500ms`, or seconds.
pub fn parse_duration(text: &str) -> Result<Duration, String> {
    let t = text.trim();
    let split = t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let n: u64 = num
        .parse()
        .map_err(|_| format!("{text:?}: expected a number with s, m, h or ms"))?;
    let secs = |k: u64| Duration::from_secs(n.saturating_mul(k));
    match unit.trim() {
        "" | "s" => Ok(secs(1)),
        "m" | "min" => Ok(secs(60)),
        "h" => Ok(secs(3600)),
        "ms" => Ok(Duration::from_millis(n)),
        other => Err(format!("unknown unit {other:?} (s, m, h, ms)")),
    }
}
