//! The progress bar of a run on a terminal (`indicatif`, drawn on stderr at most 20 times a
//! second): how far the run is, its rate, the time spent and the time left. Lines printed
//! while it is drawn go above it ([`Bar::suspend`]). Without a terminal nothing is drawn.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use std::borrow::Cow;
use std::time::Duration;

/// A progress bar on stderr.
#[derive(Debug)]
pub struct Bar(ProgressBar);

impl Bar {
    /// A bar over `len` `unit`s (`cases`, `sequences`): done of total, the rate per second,
    /// the time spent, the time left, then the message ([`Bar::set`]).
    pub fn count(len: u64, unit: &str) -> Bar {
        Bar::with(
            len,
            &format!(
                "[{{bar:30}}] {{pos}}/{{len}} {unit}, {{rate}}, {{elapsed}} spent, {{eta}} left  {{wide_msg}}"
            ),
        )
    }

    /// A bar that fills with the time spent of `budget` (ms are its units): the time spent,
    /// the time left, then the message (the caller's counts and rate).
    pub fn time(budget: Duration) -> Bar {
        Bar::with(
            u64::try_from(budget.as_millis()).unwrap_or(u64::MAX),
            "[{bar:30}] {elapsed} spent, {eta} left  {wide_msg}",
        )
    }

    fn with(len: u64, template: &str) -> Bar {
        let style = ProgressStyle::with_template(template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .with_key("rate", |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = write!(w, "{:.1}/s", s.per_sec());
            })
            .progress_chars("#>-");
        let bar = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::stderr());
        bar.set_style(style);
        Bar(bar)
    }

    /// Moves the bar to `pos` with `message` after it.
    pub fn set(&self, pos: u64, message: impl Into<Cow<'static, str>>) {
        self.0.set_position(pos);
        self.0.set_message(message);
    }

    /// Moves the bar to `pos`, keeping its message.
    pub fn reach(&self, pos: u64) {
        self.0.set_position(pos);
    }

    /// Runs `f` (which prints lines) with the bar cleared, then draws the bar again below.
    pub fn suspend<R>(&self, f: impl FnOnce() -> R) -> R {
        self.0.suspend(f)
    }

    /// Leaves the bar drawn as it is and moves below it.
    pub fn finish(&self) {
        self.0.abandon();
    }
}

#[cfg(test)]
mod tests {
    use super::Bar;
    use std::time::Duration;

    #[test]
    fn bars_count_and_fill_with_time() {
        let b = Bar::count(10, "cases");
        b.set(3, "psd4xx/position/loop/up");
        assert_eq!(b.0.position(), 3);
        assert_eq!(b.0.length(), Some(10));
        assert_eq!(b.0.message(), "psd4xx/position/loop/up");
        b.reach(10);
        assert_eq!(b.0.position(), 10);
        let printed = b.suspend(|| 7);
        assert_eq!(printed, 7);
        b.finish();
        assert!(b.0.is_finished());
        let t = Bar::time(Duration::from_secs(90));
        assert_eq!(t.0.length(), Some(90_000));
    }
}
