//! Running HPD cases: every step goes to the device under test and to the reference drive
//! (the oracle), and their answers are compared (differential verdict).
//!
//! The answer window of a request is the message time-out of the Pr26 code the reference is
//! using, plus its answer delay (Pr26 = 4), the line time of the longest answer and the
//! transport's slack, counted from when the request went out. A step fails on any difference:
//! other bytes, an answer where the reference is silent or silence where it answers, or an
//! answer sooner than the reference's delay allows. An answer that had not come by the end of
//! its window is waited for one late window more (the window again plus the code 4 answer
//! delay, the longest the manual names): its bytes are judged as an answer, and its time
//! against the answer time (4 table note (*), HPD-BAUD-004). A late answer is never taken for
//! the answer to the next message.
//!
//! On real time the runner tells its own delays from the device's. The runner's clock
//! measures how late it woke at the end of an answer window, and how long the parts of a
//! split message were apart when it sent them. A late answer, or silence to a split message
//! whose parts the runner sent so far apart that the transport's slack could carry the rest
//! past the time-out, is undecided: the case runs again, up to [`ATTEMPTS`] times. On the
//! last attempt a late answer fails if the runner woke on time and passes with an open
//! finding if it did not; silence to a late rest passes with an open finding. A case that
//! fails after an answer went missing (not come by the end of its late window) while the
//! runner itself woke late from a 1 ms wait is undecided too, and so is an answer to the rest
//! of a message the runner sent past the time-out: a stalled machine stalls a device process
//! on it, and a device that does not answer, or ignores the time-out, fails every attempt. A
//! missing answer while the runner was on time is the device's (a lossy line fails the case;
//! the runner's `--retries` reports it flaky). On virtual time (sim) the runner is always on
//! time and every case runs once.
//!
//! A message split by a pause within the time-out pauses half the time-out, at most the
//! time-out less the slack. The first failing step ends the judged part of a case; its
//! clean-up steps still run. On a transport that cannot reset the device, the reference is
//! brought back in line after a failure by reading the parameters the case touched from the
//! device. A case that fails after bit changes or applied inputs runs once more with each of
//! them read back ([`verify`]), to name the requirement the failure broke.

mod verify;

use super::attribute::{self, Order};
use super::motion::{self, Round, Sample};
use super::readings::{Bases, Journal, Judge};
use super::step::{Action, Compare, HpdCase, Step};
use super::HpdSuite;
use crate::case::{
    Answer, CaseInfo, CaseRun, Failure, Finding, Outcome, Record, RequirementRef, Role,
};
use crate::link::{concat, Chunk, Link, LinkError, Micros, Recovered};
use crate::suite::Session;
use drivespec_hpd::explain::explain;
use drivespec_hpd::model::{Drive, Output};
use drivespec_hpd::params::Target;
use drivespec_hpd::step::{Check, Probe, Within};
use drivespec_hpd::{Data, LineDecoder, LineEvent, Message};
use drivespec_spec::hex::to_hex;
use std::collections::BTreeMap;

/// Most bytes of one answer kept whole in the evidence; a longer one keeps its start and its
/// last 64 bytes.
const EVIDENCE_BYTES: usize = 512;

/// A session on one device under test.
pub struct HpdSession<'a, 's> {
    suite: &'a HpdSuite<'s>,
    link: Box<dyn Link>,
    oracle: Drive,
    /// Link time at which the oracle's clock was 0.
    offset: Micros,
    /// Extra time allowed for answers (µs).
    slack: Micros,
    /// The device's values the case's `save` steps read, by (serial address, length).
    saved: BTreeMap<(u8, u8), Data>,
    /// The erratum readings the device showed, and the strict ones: the reference follows
    /// them, and the adopted reading of every other erratum.
    shown: BTreeMap<String, String>,
    /// Reference drives powered up afresh, per combination of readings.
    bases: Bases,
    /// The current case as the reference was given it, to replay on other readings.
    journal: Journal,
    /// The bytes of the last answer that had not come by the end of its window.
    owed: usize,
    /// Link time the first part of a message still incomplete went out (a `send` step).
    split_from: Option<Micros>,
    /// Whether an undecided timing is decided in this attempt of the case (its last one).
    last_attempt: bool,
    /// Why this attempt of the case is undecided: the case runs again.
    undecided: Option<String>,
    /// An answer of this attempt had not come by the end of its late window, or came after
    /// it: on real time the line's state is unsure, and a failure of the attempt undecided.
    missed: bool,
    /// The runner woke later than [`RUNNER_ON_TIME_US`] from a short wait of this attempt.
    runner_late: bool,
    /// The byte orders the device's responses of this attempt showed against the
    /// reference's (right, reversed), read and save steps alike.
    orders: (bool, bool),
    /// This run reads back the case's bit changes and inputs ([`verify`]).
    verify: bool,
    /// A read-back of this run showed a bit change or the inputs not taken.
    read_back_failed: bool,
    /// The transport failed in this attempt.
    link_broke: bool,
}

/// Attempts of a case on real time while its timing stays undecided (the runner's own
/// delays, not the device's): three make a device that is late every time fail, and a
/// runner starved once by other work on the machine pass.
const ATTEMPTS: usize = 3;

/// How late the runner may wake at the end of an answer window and still count as on time
/// (µs): on a machine with a core to spare a thread wakes well within 2 ms of its deadline.
const RUNNER_ON_TIME_US: Micros = 2_000;

/// The short sleep from which the runner measures how late it wakes (µs).
const PROBE_US: Micros = 1_000;

/// The requirement that fixes when the drive answers: at once, or 25 ms later with Pr26 = 4
/// (4 table note (*)).
const ANSWER_TIME_REQUIREMENT: &str = "HPD-BAUD-004";

/// The requirement that a message is complete within the Pr26 time-out (4 table; 4.1).
const TIMEOUT_REQUIREMENT: &str = "HPD-BAUD-002";

/// The requirement that fixes the scan period but not its phase (3.8.1).
const SCAN_REQUIREMENT: &str = "HPD-PLC-004";

/// How a judged step the reference's answer does not fit may still pass: with what the
/// device showed and the answer that fits, or failing with what else was admissible.
enum Rescue {
    Passed(Option<Finding>, Vec<u8>),
    Failed(String),
}

/// What another reading makes of the case so far: (option, reading, its answer to the last
/// judged step).
type Alternative = (String, String, Vec<u8>);

/// What the timing of an exchange tells besides its bytes.
enum Timing {
    /// Nothing more: the bytes decide.
    Clean,
    /// The step passes with this finding: the timing is not the device's to answer for.
    Open(Finding),
    /// Whether the device or the runner was late is undecided: the case runs again.
    Undecided(String),
    /// The answer came after its window while the runner was on time.
    Late(String),
}

/// What a judged step leaves for its record when another reading or scan phase decides it:
/// the admissible answer that fits, the finding, or what else was admissible.
struct Other<'o> {
    answer: &'o mut Answer,
    findings: &'o mut Vec<Finding>,
    also: &'o mut String,
}

/// A judged step's (match, explanation), nothing to judge, or a transport error with the
/// reference's answer.
type StepResult = Result<Option<(bool, String)>, (LinkError, Vec<Chunk>)>;

/// What the device and the reference did in one step.
struct Observed {
    expected: Vec<Chunk>,
    got: Vec<Chunk>,
    t0: Micros,
    /// Late bytes dropped before the request.
    late: Vec<u8>,
    /// When the first byte that came after the answer window came (a late answer).
    late_at: Option<Micros>,
    /// How late the runner woke at the end of the answer window (µs).
    woke_late: Micros,
    /// For the rest of a split message: how long after the first part the runner sent it.
    split_span: Option<Micros>,
}

impl<'a, 's> HpdSession<'a, 's> {
    pub(crate) fn new(suite: &'a HpdSuite<'s>, link: Box<dyn Link>, slack: Micros) -> Self {
        let mut session = HpdSession {
            suite,
            link,
            oracle: suite.baseline.clone(),
            offset: 0,
            slack,
            saved: BTreeMap::new(),
            shown: suite.readings.strict().clone(),
            bases: Bases::default(),
            journal: Journal::default(),
            owed: 0,
            split_from: None,
            last_attempt: true,
            undecided: None,
            missed: false,
            runner_late: false,
            orders: (false, false),
            verify: false,
            read_back_failed: false,
            link_broke: false,
        };
        session.oracle = session.base();
        session
    }

    /// The reference powered up afresh, following the readings shown so far.
    fn base(&mut self) -> Drive {
        let suite = self.suite;
        if self.shown.is_empty() {
            return suite.baseline.clone();
        }
        self.bases
            .get(suite.spec(), suite.family(), &suite.config, &self.shown)
            .cloned()
            .unwrap_or_else(|| suite.baseline.clone())
    }

    fn reset_oracle(&mut self) {
        self.oracle = self.base();
        self.offset = self.link.now();
        self.owed = 0;
    }

    /// Whether the reference follows the adopted reading of every erratum (the golden
    /// vectors are the manual's examples under them).
    fn adopted_only(&self) -> bool {
        let rules = &self.suite.readings;
        self.shown
            .iter()
            .all(|(o, r)| rules.erratum(o).is_some_and(|e| e.adopted == *r))
    }

    /// The readings to try for the case so far: each other reading of every erratum not
    /// shown yet, on top of those shown.
    fn candidates(&self) -> Vec<(String, String)> {
        let rules = &self.suite.readings;
        let mut out = Vec::new();
        for option in rules.options() {
            if self.shown.contains_key(option) {
                continue;
            }
            let Some(e) = rules.erratum(option) else {
                continue;
            };
            for r in e.readings.iter().filter(|r| r.id != e.adopted) {
                out.push((option.to_owned(), r.id.clone()));
            }
        }
        out
    }

    /// The case so far replayed with `option` read as `reading` on top of the readings
    /// shown: the drive and whether every judged answer of the device fits it, with its
    /// answer to the last judged step.
    fn replay_with(&mut self, option: &str, reading: &str) -> Option<(Drive, bool, Vec<u8>)> {
        let mut readings = self.shown.clone();
        readings.insert(option.to_owned(), reading.to_owned());
        self.replay_on(&readings, None)
    }

    /// The case so far replayed under `readings`, the next PLC scan moved to `scan_at` when
    /// given: the drive, whether every judged answer of the device fits, the last answer.
    fn replay_on(
        &mut self,
        readings: &BTreeMap<String, String>,
        scan_at: Option<Micros>,
    ) -> Option<(Drive, bool, Vec<u8>)> {
        let suite = self.suite;
        let base = self
            .bases
            .get(suite.spec(), suite.family(), &suite.config, readings)?;
        let (drive, answers) = self.journal.replay(base, scan_at)?;
        let fit = self
            .journal
            .answers()
            .iter()
            .zip(&answers)
            .all(|(j, exp)| fits(&suite.rules, j.judge, exp, &j.got));
        let last = answers.last().cloned().unwrap_or_default();
        Some((drive, fit, last))
    }

    /// The PLC scan phase (3.8.1) under which every answer of the device in the case so far
    /// fits, tried with a scan just after each message of the case: the reference moves its
    /// scans by that much. The answer depends on whether a scan fell between two messages,
    /// which the manual bounds (one scan) but does not fix.
    fn admit_phase(&mut self) -> Option<Vec<u8>> {
        let readings = self.shown.clone();
        for at in self.journal.phases(self.oracle.scan_period()) {
            if let Some((drive, true, last)) = self.replay_on(&readings, Some(at)) {
                self.oracle = drive;
                return Some(last);
            }
        }
        None
    }

    /// Another admissible reading under which every answer of the device in the case so far
    /// fits: the reference switches to it and the reading counts as shown. Otherwise the
    /// other readings' answers to the last judged step.
    fn admit(&mut self) -> Result<Alternative, Vec<Alternative>> {
        let mut others = Vec::new();
        for (option, reading) in self.candidates() {
            let Some((drive, fit, last)) = self.replay_with(&option, &reading) else {
                continue;
            };
            if fit {
                self.oracle = drive;
                self.shown.insert(option.clone(), reading.clone());
                return Ok((option, reading, last));
            }
            others.push((option, reading, last));
        }
        Err(others)
    }

    /// A judged step whose answer does not fit the reference's `exp`, tried on the other
    /// admissible readings, then on the other PLC scan phases.
    fn rescue(&mut self, exp: &[u8], t0: Micros, request: Option<&Message>) -> Rescue {
        match self.admit() {
            Ok((option, reading, answer)) => {
                Rescue::Passed(self.suite.readings.finding(&option, &reading), answer)
            }
            Err(others) => match self.admit_phase() {
                Some(answer) => Rescue::Passed(
                    Some(Finding::Open {
                        requirement: SCAN_REQUIREMENT.to_owned(),
                        text: "a PLC scan fell elsewhere between the messages than in the reference (the phase of the 6.144 ms scan is not fixed)".to_owned(),
                    }),
                    answer,
                ),
                None => Rescue::Failed(self.alternatives(&others, exp, t0, request)),
            },
        }
    }

    /// What the other readings in `others` expected where it differs from `exp`, as
    /// `; or A (reading R of E)` for a failure's allowed outcomes.
    fn alternatives(
        &self,
        others: &[Alternative],
        exp: &[u8],
        t0: Micros,
        request: Option<&Message>,
    ) -> String {
        let rules = &self.suite.readings;
        let mut text = String::new();
        for (option, reading, answer) in others {
            if answer.as_slice() == exp {
                continue;
            }
            let Some(e) = rules.erratum(option) else {
                continue;
            };
            let a = self.answer(
                &[Chunk {
                    at: t0,
                    bytes: answer.clone(),
                }],
                t0,
                request,
            );
            text.push_str(&format!(
                "; or {} (reading `{reading}` of {})",
                show(&a),
                e.id
            ));
        }
        text
    }

    /// After a passing case: the readings its answers tell apart. An erratum the case
    /// exercises (cites one of its requirements), or whose reading in force is not the
    /// adopted one, is replayed on its other readings; when one of them does not fit, the
    /// case showed the reading in force, which is reported.
    fn settle(&mut self, cited: &[String], findings: &mut Vec<Finding>) {
        let rules = &self.suite.readings;
        for e in rules.errata() {
            let Some(option) = e.option.as_deref() else {
                continue;
            };
            if findings
                .iter()
                .any(|f| matches!(f, Finding::Reading { erratum, .. } if *erratum == e.id))
            {
                continue;
            }
            let current = rules.in_force(&self.shown, option).to_owned();
            let exercised = e.requirements.iter().any(|r| cited.contains(r));
            if !exercised && current == e.adopted {
                continue;
            }
            let mut told = false;
            for r in e.readings.iter().filter(|r| r.id != current) {
                if let Some((_, false, _)) = self.replay_with(option, &r.id) {
                    told = true;
                    break;
                }
            }
            if told {
                self.shown.insert(option.to_owned(), current.clone());
                findings.extend(rules.finding(option, &current));
            }
        }
    }

    fn otime(&self, t: Micros) -> Micros {
        t.saturating_sub(self.offset)
    }

    /// Message time-out and answer delay in force at the reference (µs).
    fn line_times(&self) -> (Micros, Micros, u32) {
        match self.oracle.line() {
            Some(l) => (l.timeout_us, l.answer_delay_us, l.bps.max(1)),
            None => {
                let worst = self
                    .suite
                    .protocol()
                    .baud_rates
                    .iter()
                    .map(|b| u64::from(b.timeout_ms) * 1000)
                    .max()
                    .unwrap_or(512_000);
                (worst, 0, 600)
            }
        }
    }

    /// The answer window after a request.
    fn window(&self) -> Micros {
        let (timeout, delay, bps) = self.line_times();
        let bits = u64::from(self.suite.protocol().character.bits_per_char.max(1));
        let answer = (drivespec_hpd::MAX_FRAME as u64) * bits * 1_000_000 / u64::from(bps);
        timeout + delay + answer + self.slack
    }

    /// Drains the reference's line output; reference time `o_base` is link time `t_base`.
    fn oracle_output(&mut self, o_base: Micros, t_base: Micros) -> Vec<Chunk> {
        let mut out = Vec::new();
        while let Some(o) = self.oracle.poll_output() {
            if let Output::Transmit { at, bytes } = o {
                out.push(Chunk {
                    at: at.saturating_sub(o_base).saturating_add(t_base),
                    bytes,
                });
            }
        }
        out
    }

    /// The reference time for link time `t`: never behind the reference's own clock.
    fn oracle_now(&self, t: Micros) -> Micros {
        self.otime(t).max(self.oracle.now())
    }

    /// Sends `bytes` to both and collects the answers within the window, and a late answer
    /// within the late window after it.
    fn exchange(&mut self, bytes: &[u8]) -> Result<Observed, (LinkError, Vec<Chunk>)> {
        let late = self.drain_late();
        let window = self.window();
        let (_, delay, _) = self.line_times();
        let before = self.link.now();
        let o0 = self.oracle_now(before);
        self.oracle.handle_rx(o0, bytes);
        // Only as far as the answer (and its delay) needs: the reference must not run ahead
        // of the device's clock.
        self.oracle.advance(o0 + delay + 1);
        self.journal.exchange(o0, bytes, o0 + delay + 1);
        // The window counts from when the request goes out, after the reference's work.
        let t0 = self.link.now();
        let expected = self.oracle_output(o0, t0);
        let want = concat(&expected).len();
        if let Err(e) = self.link.send(bytes) {
            return Err((e, expected));
        }
        // The rest of a split message (no STX of its own): how long after its first part.
        let split_span = match self.split_from.take() {
            Some(from) if bytes.first() != Some(&self.suite.rules.stx) => {
                Some(t0.saturating_sub(from))
            }
            _ => None,
        };
        // HPD answers are self-delimiting (LUN, or the 2-byte acknowledge): no wait after the
        // last expected byte. Bytes read with the answer are judged with it; later ones are
        // reported as late bytes before the next request.
        let mut got = match self
            .link
            .recv(t0 + window, &mut |b| want > 0 && b.len() >= want)
        {
            Ok(g) => g,
            Err(e) => return Err((e, expected)),
        };
        let end = t0 + window;
        let mut woke_late = 0;
        if concat(&got).len() < want {
            woke_late = self.link.now().saturating_sub(end);
            self.probe_runner();
        }
        let have = concat(&got).len();
        if have < want {
            let until = end + self.late_window();
            match self.link.recv(until, &mut |b| have + b.len() >= want) {
                Ok(more) => got.extend(more),
                Err(e) => return Err((e, expected)),
            }
        }
        let late_at = got.iter().map(|c| c.at).find(|at| *at > end);
        if concat(&got).len() < want {
            self.missed = true;
        }
        self.owed = 0;
        Ok(Observed {
            expected,
            got,
            t0,
            late,
            late_at,
            woke_late,
            split_span,
        })
    }

    /// Measures how late the runner's own thread wakes from a short sleep (its scheduling
    /// delay now, on the monotonic clock, apart from the transport); bytes that come
    /// meanwhile wait in the transport.
    fn probe_runner(&mut self) {
        if self.link.caps().virtual_time {
            return;
        }
        let start = std::time::Instant::now();
        std::thread::sleep(std::time::Duration::from_micros(PROBE_US));
        let slept = u64::try_from(start.elapsed().as_micros()).unwrap_or(Micros::MAX);
        if slept.saturating_sub(PROBE_US) > RUNNER_ON_TIME_US {
            self.runner_late = true;
        }
    }

    /// How long an answer not come by the end of its window is still waited for: the window
    /// again plus the longest answer delay the manual names (25 ms, Pr26 = 4), so a drive
    /// that delays every answer like code 4 is seen answering late, not silent.
    fn late_window(&self) -> Micros {
        let longest = self
            .suite
            .protocol()
            .baud_rates
            .iter()
            .filter_map(|b| b.answer_delay_ms)
            .max()
            .unwrap_or(0);
        self.window() + u64::from(longest) * 1000
    }

    /// Bytes that came after the last answer window (a late answer, already judged where
    /// it belonged): dropped so they are not taken for the next answer. The drive answers
    /// only when asked, one answer per message (4.1), so an answer still owed is waited for,
    /// up to one more answer window, before the next message goes out; then the line is
    /// swept.
    fn drain_late(&mut self) -> Vec<u8> {
        let owed = std::mem::take(&mut self.owed);
        if self.link.caps().virtual_time {
            return Vec::new();
        }
        let mut late = Vec::new();
        if owed > 0 {
            let until = self.link.now() + self.window();
            if let Ok(c) = self.link.recv(until, &mut |b| b.len() >= owed) {
                late = concat(&c);
            }
        }
        let now = self.link.now();
        if let Ok(c) = self.link.recv(now + 1, &mut |_| false) {
            late.extend(concat(&c));
        }
        if !late.is_empty() {
            self.missed = true;
        }
        late
    }

    /// What the timing of exchange `obs` tells: `fits` whether its bytes fit the
    /// reference's, `ref_silent` whether the reference was silent, `text` the step's.
    fn timing(&self, obs: &Observed, fits: bool, ref_silent: bool, text: &str) -> Timing {
        if !fits && obs.got.is_empty() && !ref_silent {
            let (timeout, _, _) = self.line_times();
            return match obs.split_span {
                Some(span) if span.saturating_add(self.slack) >= timeout => {
                    let reason = format!(
                        "the rest of the message went out {:.1} ms after its first part; with the transport's slack ({:.1} ms) it may have reached the device after the {:.1} ms time-out",
                        ms(span),
                        ms(self.slack),
                        ms(timeout)
                    );
                    if self.last_attempt {
                        Timing::Open(Finding::Open {
                            requirement: TIMEOUT_REQUIREMENT.to_owned(),
                            text: format!("{text}: {reason}; the device dropped it, which this transport cannot tell from a device fault"),
                        })
                    } else {
                        Timing::Undecided(reason)
                    }
                }
                _ => Timing::Clean,
            };
        }
        if let (false, false, true, Some(span)) =
            (fits, obs.got.is_empty(), ref_silent, obs.split_span)
        {
            let (timeout, _, _) = self.line_times();
            if span >= timeout && !self.link.caps().virtual_time && !self.last_attempt {
                return Timing::Undecided(format!(
                    "the rest of the message went out {:.1} ms after its first part, past the {:.1} ms time-out; a device process stalled between them reads both within it",
                    ms(span),
                    ms(timeout)
                ));
            }
        }
        let Some(at) = obs.late_at.filter(|_| fits) else {
            return Timing::Clean;
        };
        let after = at.saturating_sub(obs.t0);
        let window = self.window();
        let reason = format!(
            "the answer came {:.1} ms after the request, after its window of {:.1} ms (time-out, answer delay, line time of the longest answer and {:.1} ms slack)",
            ms(after),
            ms(window),
            ms(self.slack)
        );
        let on_time = self.link.caps().virtual_time || obs.woke_late <= RUNNER_ON_TIME_US;
        if !self.last_attempt {
            Timing::Undecided(reason)
        } else if on_time {
            Timing::Late(reason)
        } else {
            Timing::Open(Finding::Open {
                requirement: ANSWER_TIME_REQUIREMENT.to_owned(),
                text: format!(
                    "{text}: {reason}; the runner itself woke {:.1} ms late at the end of the window: not judged",
                    ms(obs.woke_late)
                ),
            })
        }
    }

    /// Listens for `us` on both.
    /// An answer still owed to the last message is waited for first (and reported as late).
    fn listen(&mut self, us: Micros) -> Result<Observed, (LinkError, Vec<Chunk>)> {
        let late = if self.owed > 0 {
            self.drain_late()
        } else {
            Vec::new()
        };
        let t0 = self.link.now();
        let o0 = self.oracle_now(t0);
        self.oracle.advance(o0 + us);
        self.journal.listen(o0 + us);
        let expected = self.oracle_output(o0, t0);
        match self.link.recv(t0 + us, &mut |_| false) {
            Ok(got) => {
                let want = concat(&expected).len();
                self.owed = want.saturating_sub(concat(&got).len());
                Ok(Observed {
                    expected,
                    got,
                    t0,
                    late,
                    late_at: None,
                    woke_late: 0,
                    split_span: None,
                })
            }
            Err(e) => Err((e, expected)),
        }
    }

    /// Records the device's answer to a judged step and, when the reference's does not fit
    /// (`fit`), tries the other readings and scan phases; whether the step passes.
    fn judged(
        &mut self,
        judge: Judge,
        fit: bool,
        obs: &Observed,
        request: Option<&Message>,
        other: &mut Other<'_>,
    ) -> bool {
        let got = concat(&obs.got);
        self.journal.judged(judge, &got);
        if fit {
            return true;
        }
        match self.rescue(&concat(&obs.expected), obs.t0, request) {
            Rescue::Passed(finding, answer) => {
                other.findings.extend(finding);
                let at = obs.expected.first().map_or(obs.t0, |c| c.at);
                let alt = [Chunk { at, bytes: answer }];
                *other.answer = self.answer(&alt, obs.t0, request);
                true
            }
            Rescue::Failed(text) => {
                *other.also = text;
                false
            }
        }
    }

    /// Reads the touched parameters from the device into the reference (after a failure on
    /// a transport that cannot reset the device).
    fn resync(&mut self, case: &HpdCase) {
        let family = self.suite.family();
        let addr = self.suite.settings.address;
        for slot in &case.touched {
            let Some(p) = family.parameter_at_address(u32::from(slot.addr)) else {
                continue;
            };
            let msg = Message::ReadParam {
                addr,
                lun: slot.size,
                par: slot.addr,
            };
            let Ok(bytes) = msg.to_bytes(&self.suite.rules) else {
                continue;
            };
            let _ = self.drain_late();
            let window = self.window();
            let t0 = self.link.now();
            if self.link.send(&bytes).is_err() {
                return;
            }
            let Ok(got) = self.link.recv(t0 + window, &mut |b| b.len() >= 5) else {
                return;
            };
            self.owed = 5usize.saturating_sub(concat(&got).len());
            let got = concat(&got);
            if let Ok(Message::Response { par, data, .. }) =
                drivespec_hpd::parse(&self.suite.rules, &got)
            {
                if par == slot.addr && data.len() == slot.size {
                    let target = Target::Param(p);
                    let t = self.link.now();
                    let now = self.oracle_now(t);
                    let _ = self.oracle.set_value(now, &target, target.value(&data));
                    let _ = self.oracle_output(now, t);
                }
            }
        }
    }

    /// Bytes in words: the frames in them, explained.
    fn words(&self, bytes: &[u8], request: Option<&Message>) -> String {
        if bytes.is_empty() {
            return "silence".to_owned();
        }
        let suite = self.suite;
        let mut parts = Vec::new();
        let mut dec = LineDecoder::new(suite.rules.clone());
        let mut sink = |e: LineEvent| match e {
            LineEvent::Frame(f) => {
                let x = explain(
                    suite.family(),
                    &suite.rules,
                    Some(&suite.codec),
                    &f.message,
                    request,
                );
                parts.push(x.summary);
            }
            LineEvent::Discarded(d) => {
                parts.push(format!(
                    "{} byte(s) that are not a message ({})",
                    d.len, d.reason
                ));
            }
        };
        dec.feed(bytes, None, &mut sink);
        dec.finish(&mut sink);
        parts.join("; ")
    }

    /// The evidence of what came: all of it up to [`EVIDENCE_BYTES`], else its start and end
    /// with the count (a device flooding the line).
    fn answer(&self, chunks: &[Chunk], t0: Micros, request: Option<&Message>) -> Answer {
        let bytes = concat(chunks);
        if bytes.is_empty() {
            return Answer::silence();
        }
        let n = bytes.len();
        let (hex, text) = match (
            bytes.get(..EVIDENCE_BYTES),
            bytes.get(n.saturating_sub(64)..),
        ) {
            (Some(head), Some(tail)) if n > EVIDENCE_BYTES => (
                format!("{} … {} ({n} bytes)", to_hex(head), to_hex(tail)),
                format!(
                    "{}; and {} more byte(s)",
                    self.words(head, request),
                    n - EVIDENCE_BYTES
                ),
            ),
            _ => (to_hex(&bytes), self.words(&bytes, request)),
        };
        Answer {
            hex,
            text,
            delay_us: chunks.first().map(|c| c.at.saturating_sub(t0)),
        }
    }

    /// Requirements the reference's answer `expected` shows (manual 4.1): the answer form,
    /// its checksum, byte order and stuffing.
    fn answer_reqs(&self, expected: &[u8]) -> Vec<String> {
        let rules = &self.suite.rules;
        let mut out: Vec<&str> = Vec::new();
        let mut dec = LineDecoder::new(rules.clone());
        let mut sink = |e: LineEvent| {
            if let LineEvent::Frame(f) = e {
                match f.message {
                    Message::Ack { .. } => out.push("HPD-FRAME-011"),
                    Message::Response { data, .. } => {
                        out.extend(["HPD-FRAME-010", "HPD-FRAME-009", "HPD-SERIAL-017"]);
                        if data.len() > 1 {
                            out.push("HPD-SERIAL-016");
                        }
                    }
                    _ => {}
                }
            }
        };
        dec.feed(expected, None, &mut sink);
        dec.finish(&mut sink);
        if expected
            .windows(2)
            .skip(1)
            .any(|w| w == [rules.stx, rules.stuff])
        {
            out.push("HPD-FRAME-003");
        }
        out.into_iter().map(str::to_owned).collect()
    }

    /// The requirements a judged step checks: its own, the case's for a check step (the
    /// behaviour under test), and those the reference's answer `expected` shows.
    fn step_checks(&self, case_reqs: &[String], step: &Step, expected: &[u8]) -> Vec<String> {
        let mut ids = step.requirements.clone();
        let case = if step.role == Role::Check {
            case_reqs
        } else {
            &[]
        };
        for r in case.iter().cloned().chain(self.answer_reqs(expected)) {
            if !ids.contains(&r) {
                ids.push(r);
            }
        }
        ids
    }

    /// The requirement a failing exchange breaks, by what differs between the reference's
    /// answer `expected` and the device's `got` (manual 4.1): the checksum or stuffing of an
    /// answer that does not decode; the answering address, LUN and PAR, or byte order of a
    /// response (reversed data, unless the device answered in the right order before in the
    /// case); the form of an acknowledge; an answer to a broadcast. A response of the right
    /// form with another value keeps every rule of the message form: it breaks the rule of
    /// the bits it differs in when their rules name one requirement
    /// ([`attribute::bit_requirement`]), else the behaviour the step or case checks, its
    /// first requirement outside [`FORM`]. None when the bytes tell nothing (silence, or an
    /// answer where the reference is silent).
    fn broken(
        &self,
        expected: &[u8],
        got: &[u8],
        own: &[String],
        case: &[String],
    ) -> Option<String> {
        let rules = &self.suite.rules;
        if let Some(rule) = frame_rule_broken(rules, got) {
            return Some(rule.to_owned());
        }
        if got.is_empty() {
            return None;
        }
        if unstuffed(rules, got) {
            return Some("HPD-FRAME-003".to_owned());
        }
        let exp = drivespec_hpd::parse(rules, expected).ok();
        let dev = drivespec_hpd::parse(rules, got).ok();
        let rule = match (exp, dev) {
            (
                Some(Message::Response {
                    addr: a,
                    par: p,
                    data: d,
                }),
                Some(Message::Response {
                    addr: b,
                    par: q,
                    data: x,
                }),
            ) => {
                if a != b {
                    "HPD-FRAME-010"
                } else if p != q || d.len() != x.len() {
                    "HPD-SERIAL-017"
                } else if d.len() > 1
                    && !self.orders.0
                    && x.as_slice().iter().rev().eq(d.as_slice())
                {
                    BYTE_ORDER
                } else if let Some(r) =
                    attribute::bit_requirement(self.suite.family(), self.mode(), p, &d, &x)
                {
                    return Some(r);
                } else {
                    return own
                        .iter()
                        .chain(case)
                        .find(|r| !FORM.contains(&r.as_str()))
                        .cloned();
                }
            }
            (Some(Message::Ack { .. }), _) => "HPD-FRAME-011",
            (Some(Message::Response { .. }), _) => "HPD-FRAME-010",
            (None, _) if expected.is_empty() => {
                let broadcast = own.iter().any(|r| r == BROADCAST_SILENT);
                return broadcast.then(|| BROADCAST_SILENT.to_owned());
            }
            _ => return None,
        };
        Some(rule.to_owned())
    }

    /// The requirements a failing step cites, the broken one first ([`HpdSession::broken`]),
    /// then the step's own, those the reference's answer `expected` shows, and the case's.
    fn requirement_refs(
        &self,
        case_reqs: &[String],
        step: Option<&Step>,
        expected: &[u8],
        got: &[u8],
    ) -> Vec<RequirementRef> {
        let family = self.suite.family();
        let own = step.map(|s| s.requirements.clone()).unwrap_or_default();
        let mut ids: Vec<String> = self
            .broken(expected, got, &own, case_reqs)
            .into_iter()
            .collect();
        for r in own {
            if !ids.contains(&r) {
                ids.push(r);
            }
        }
        for r in self
            .answer_reqs(expected)
            .into_iter()
            .chain(case_reqs.iter().cloned())
        {
            if !ids.contains(&r) {
                ids.push(r);
            }
        }
        ids.into_iter()
            .filter_map(|id| RequirementRef::of(family, &id))
            .collect()
    }

    /// The operating mode the reference is in (manual 3.6, Pr31).
    fn mode(&self) -> Option<u32> {
        let family = self.suite.family();
        let p = family.parameter(&self.suite.protocol().commands.mode_param)?;
        let addr = u8::try_from(p.address?).ok()?;
        let size = u8::try_from(p.size?).ok()?;
        Some(self.oracle.memory().get(addr, size))
    }

    /// Notes the byte order the response of `rec` showed against the reference's.
    fn note_order(&mut self, rec: &Record) {
        let bytes = |a: Option<&Answer>| {
            a.and_then(|a| drivespec_spec::hex::parse_hex(&a.hex).ok())
                .unwrap_or_default()
        };
        let exp = bytes(rec.expected.as_ref());
        let got = bytes(rec.got.as_ref());
        match attribute::byte_order(&self.suite.rules, &exp, &got) {
            Some(Order::Right) => self.orders.0 = true,
            Some(Order::Reversed) => self.orders.1 = true,
            None => {}
        }
    }

    /// Puts the byte-order rule first in a failure led by a behaviour (a rule outside the
    /// message form and the answer time) when the device answered the reference's data
    /// reversed before in the case and never in the right order: the values it was given
    /// back, or read, are byte-swapped, and the behaviour fails on them.
    fn lead_by_byte_order(&self, requirements: &mut Vec<RequirementRef>) {
        let led_by_behaviour = requirements.first().is_some_and(|r| {
            !FORM.contains(&r.id.as_str())
                && r.id != ANSWER_TIME_REQUIREMENT
                && r.id != TIMEOUT_REQUIREMENT
        });
        if !(led_by_behaviour && self.orders.1 && !self.orders.0) {
            return;
        }
        if let Some(r) = RequirementRef::of(self.suite.family(), BYTE_ORDER) {
            requirements.retain(|x| x.id != r.id);
            requirements.insert(0, r);
        }
    }
}

/// The rules of a read and of an answer's form (manual 4.1), which a response with the right
/// address, LUN, PAR, byte order, checksum and stuffing keeps whatever value it carries. The
/// rules of what a write means (CMD 3, 5, 6, 7) are not among them: a write the drive
/// misreads shows in the values read after it.
const FORM: &[&str] = &[
    "HPD-FRAME-001",
    "HPD-FRAME-002",
    "HPD-FRAME-003",
    "HPD-FRAME-004",
    "HPD-FRAME-006",
    "HPD-FRAME-008",
    "HPD-FRAME-009",
    "HPD-FRAME-010",
    "HPD-FRAME-011",
    "HPD-FRAME-012",
    "HPD-FRAME-014",
    "HPD-FRAME-022",
    "HPD-SERIAL-001",
    "HPD-SERIAL-015",
    "HPD-SERIAL-016",
    "HPD-SERIAL-017",
];

/// The rule that multi-byte data travel least significant byte first (4.1 cases 2 and 4).
const BYTE_ORDER: &str = "HPD-SERIAL-016";

/// The rule that no drive answers a broadcast (4.1 notes; CMD 7).
const BROADCAST_SILENT: &str = "HPD-SERIAL-013";

/// The frame rule (manual 4.1) bytes `got` break when they start a message that does not
/// decode: its checksum or its stuffing.
fn frame_rule_broken(rules: &drivespec_hpd::FrameRules, got: &[u8]) -> Option<&'static str> {
    let from = got.iter().position(|b| *b == rules.stx)?;
    match drivespec_hpd::parse(rules, got.get(from..)?) {
        Err(drivespec_hpd::FrameError::Checksum { .. }) => Some("HPD-FRAME-009"),
        Err(drivespec_hpd::FrameError::Stuffing { .. }) => Some("HPD-FRAME-003"),
        _ => None,
    }
}

/// Whether `got` lacks the $00 the manual puts after a $7E inside a message (4.1 STX): it
/// does not decode, and decodes with the $00 put back.
fn unstuffed(rules: &drivespec_hpd::FrameRules, got: &[u8]) -> bool {
    let from = got.iter().position(|b| *b == rules.stx).unwrap_or(0);
    let Some(body) = got.get(from..) else {
        return false;
    };
    if drivespec_hpd::parse(rules, body).is_ok() {
        return false;
    }
    let mut stuffed = Vec::with_capacity(body.len() * 2);
    for (i, b) in body.iter().enumerate() {
        stuffed.push(*b);
        if i > 0 && *b == rules.stx {
            stuffed.push(rules.stuff);
        }
    }
    stuffed.len() > body.len() && drivespec_hpd::parse(rules, &stuffed).is_ok()
}

/// Whether the device's bytes `got` fit the reference's `exp` as `judge` compares them.
fn fits(rules: &drivespec_hpd::FrameRules, judge: Judge, exp: &[u8], got: &[u8]) -> bool {
    match judge {
        Judge::Answer {
            compare,
            silence_ok,
        } => matches(rules, compare, exp, got) || (silence_ok && got.is_empty()),
        Judge::Listen => exp == got,
    }
}

/// Whether the device's bytes match the reference's under `compare`.
fn matches(rules: &drivespec_hpd::FrameRules, compare: Compare, exp: &[u8], got: &[u8]) -> bool {
    if exp == got {
        return true;
    }
    let (Compare::Mask(_) | Compare::Near(_) | Compare::Open { .. }) = compare else {
        return false;
    };
    let (Ok(a), Ok(b)) = (
        drivespec_hpd::parse(rules, exp),
        drivespec_hpd::parse(rules, got),
    ) else {
        return false;
    };
    match (a, b) {
        (
            Message::Response {
                addr: aa,
                par: ap,
                data: ad,
            },
            Message::Response {
                addr: ba,
                par: bp,
                data: bd,
            },
        ) if aa == ba && ap == bp && ad.len() == bd.len() => match compare {
            Compare::Mask(m) => ad.unsigned() & m == bd.unsigned() & m,
            Compare::Near(tolerance) => {
                (i64::from(ad.unsigned()) - i64::from(bd.unsigned())).abs() <= tolerance
            }
            Compare::Open { mask, min, max } => {
                ad.unsigned() & mask == bd.unsigned() & mask
                    && (min..=max).contains(&value_of(&bd, min < 0))
            }
            Compare::Exact | Compare::Unchanged => false,
        },
        _ => false,
    }
}

impl Session for HpdSession<'_, '_> {
    fn describe(&self) -> String {
        self.link.describe()
    }

    fn run(&mut self, index: usize) -> CaseRun {
        let suite = self.suite;
        let (Some(info), Some(case)) = (suite.infos.get(index), suite.cases.get(index)) else {
            return CaseRun {
                findings: Vec::new(),
                checked: Vec::new(),
                outcome: Outcome::Skip {
                    reason: format!("no case {index}"),
                },
                evidence: Vec::new(),
                elapsed_us: 0,
            };
        };
        self.run_case(info, case, true)
    }
}

impl HpdSession<'_, '_> {
    /// Restarts or reconnects the device; a fresh device also gets a fresh reference.
    pub fn recover(&mut self) -> Result<Recovered, LinkError> {
        let r = self.link.recover()?;
        if r == Recovered::Fresh {
            self.reset_oracle();
        }
        Ok(r)
    }

    /// The reference powered up afresh now (after a restarted process first answered: its
    /// power-up is closer to then than to the restart).
    pub fn restart_reference(&mut self) {
        self.reset_oracle();
    }

    /// Sends `bytes` (a read) to the device alone and waits for a whole answer (manual 4.1),
    /// unjudged: a just-started process is then talking (its start-up grace is over). True
    /// when bytes came.
    pub fn wake(&mut self, bytes: &[u8]) -> bool {
        let _ = self.drain_late();
        let window = self.window();
        let t0 = self.link.now();
        if self.link.send(bytes).is_err() {
            return false;
        }
        let rules = &self.suite.rules;
        let mut whole = |b: &[u8]| {
            let from = b.iter().position(|x| *x == rules.stx).unwrap_or(b.len());
            matches!(
                drivespec_hpd::decode(
                    rules,
                    b.get(from..).unwrap_or(&[]),
                    drivespec_hpd::AckEnd::NextByte
                ),
                Ok(drivespec_hpd::Status::Complete(_))
            )
        };
        self.link
            .recv(t0 + window, &mut whole)
            .is_ok_and(|c| !c.is_empty())
    }

    /// Resets the device and the reference to the start state, when the transport can.
    pub fn reset(&mut self) -> Result<bool, LinkError> {
        let done = self.link.reset()?;
        if done {
            self.reset_oracle();
        }
        Ok(done)
    }

    /// A `save` step: reads the parameter from the device and the reference and keeps the
    /// device's data; judged as a read whose value the manual does not fix.
    fn save(&mut self, addr: u8, par: u8, lun: u8, rec: &mut Record) -> StepResult {
        let msg = Message::ReadParam { addr, lun, par };
        let Ok(bytes) = msg.to_bytes(&self.suite.rules) else {
            rec.note = Some("nothing saved: not a read message".to_owned());
            return Ok(None);
        };
        rec.sent = Some(to_hex(&bytes));
        rec.sent_text = Some(self.words(&bytes, None));
        let obs = self.exchange(&bytes)?;
        let got = concat(&obs.got);
        let ea = self.answer(&obs.expected, obs.t0, Some(&msg));
        let ga = self.answer(&obs.got, obs.t0, Some(&msg));
        let all = Compare::Open {
            mask: 0,
            min: 0,
            max: i64::from(u32::MAX),
        };
        let ok = matches(&self.suite.rules, all, &concat(&obs.expected), &got);
        if let (true, Some((_, data))) = (ok, response(&self.suite.rules, &got)) {
            self.saved.insert((par, lun), data);
        }
        let why = format!(
            "expected a response of {lun} byte(s) at {par:#04x} like {}, got {}",
            show(&ea),
            show(&ga)
        );
        rec.note = Some("the device's value is kept to be written back".to_owned());
        rec.expected = Some(ea);
        rec.got = Some(ga);
        Ok(Some((ok, why)))
    }

    /// Whether `got` is a response carrying the data a `save` of the same parameter read.
    fn unchanged(&self, got: &[u8]) -> bool {
        response(&self.suite.rules, got).is_some_and(|(par, data)| {
            self.saved
                .get(&(par, data.len()))
                .is_some_and(|kept| *kept == data)
        })
    }

    /// Runs `case` (described by `info`) as [`Session::run`] runs a suite case, judged step
    /// by step against the reference; `from_start`: reset first on transports that can. On
    /// real time a case whose timing is undecided runs again, up to [`ATTEMPTS`] times; the
    /// last attempt's record notes why the ones before it did not count.
    pub fn run_case(&mut self, info: &CaseInfo, case: &HpdCase, from_start: bool) -> CaseRun {
        let attempts = if self.link.caps().virtual_time {
            1
        } else {
            ATTEMPTS
        };
        let mut why: Vec<String> = Vec::new();
        let mut attempt = 1;
        loop {
            self.last_attempt = attempt >= attempts;
            self.undecided = None;
            self.missed = false;
            self.runner_late = false;
            let run = self.attempt(info, case, from_start);
            if self.missed
                && self.runner_late
                && matches!(run.outcome, Outcome::Fail(_))
                && self.undecided.is_none()
            {
                self.undecided = Some(
                    "an answer did not come within its late window while the runner itself woke late: the machine stalled".to_owned(),
                );
            }
            match self.undecided.take() {
                Some(reason) if !self.last_attempt => {
                    why.push(format!("attempt {attempt}: {reason}"));
                    attempt += 1;
                    // Answers still on their way are not taken for the next attempt's.
                    let settle = self.link.now() + self.late_window();
                    let _ = self.link.recv(settle, &mut |_| false);
                    self.owed = 0;
                }
                _ => {
                    self.last_attempt = true;
                    let mut run = self.verified(info, case, run);
                    if let (false, Some(first)) = (why.is_empty(), run.evidence.first_mut()) {
                        let note = format!("undecided timing, not counted: {}", why.join("; "));
                        first.note = Some(match first.note.take() {
                            Some(n) => format!("{note}; {n}"),
                            None => note,
                        });
                    }
                    return run;
                }
            }
        }
    }

    /// One attempt of [`HpdSession::run_case`].
    fn attempt(&mut self, info: &CaseInfo, case: &HpdCase, from_start: bool) -> CaseRun {
        let suite = self.suite;
        let caps = self.link.caps();
        if case.needs_power_cycle && !caps.power_cycle {
            return CaseRun {
                findings: Vec::new(),
                checked: Vec::new(),
                outcome: Outcome::Skip {
                    reason: "needs the device switched off and on, which this transport cannot do (only sim can)".to_owned(),
                },
                evidence: Vec::new(),
                elapsed_us: 0,
            };
        }
        let applies_inputs = case
            .steps
            .iter()
            .any(|s| matches!(s.action, Action::Inputs { .. }));
        if applies_inputs && !caps.inputs {
            return CaseRun {
                findings: Vec::new(),
                checked: Vec::new(),
                outcome: Outcome::Skip {
                    reason: "needs the device's digital inputs driven, which this transport cannot do (only sim can)".to_owned(),
                },
                evidence: Vec::new(),
                elapsed_us: 0,
            };
        }
        let start = self.link.now();
        if caps.reset && from_start {
            match self.link.reset() {
                Ok(true) => self.reset_oracle(),
                Ok(false) => {}
                Err(e) => {
                    return CaseRun {
                        findings: Vec::new(),
                        checked: Vec::new(),
                        outcome: Outcome::Fail(Failure {
                            step: None,
                            message: format!("transport: {e}"),
                            expected: "a device in its start state".to_owned(),
                            got: e.to_string(),
                            requirements: Vec::new(),
                        }),
                        evidence: Vec::new(),
                        elapsed_us: 0,
                    }
                }
            }
        }
        self.saved.clear();
        self.split_from = None;
        self.orders = (false, false);
        self.link_broke = false;
        // What a failure may cite: the case's own requirements first, as declared.
        let mut order: Vec<String> = case.checks.clone();
        for r in &info.requirements {
            if !order.contains(r) {
                order.push(r.clone());
            }
        }
        self.journal.begin(&self.oracle);
        let mut findings: Vec<Finding> = Vec::new();
        let mut cited: Vec<String> = info.requirements.clone();
        let mut evidence: Vec<Record> = Vec::new();
        let mut failure: Option<Failure> = None;
        let mut checked: Vec<String> = Vec::new();
        let mut broken = false;
        let mut last_request: Option<Message> = None;
        for (i, step) in case.steps.iter().enumerate() {
            let judged = step.role != Role::Cleanup;
            if judged && failure.is_some() {
                continue;
            }
            if broken {
                break;
            }
            let at_us = self.link.now();
            let mut rec = Record {
                step: i,
                role: step.role,
                action: step.text.clone(),
                at_us,
                sent: None,
                sent_text: None,
                expected: None,
                got: None,
                ok: None,
                note: None,
            };
            // What the other admissible readings expected of a failing step.
            let mut also = String::new();
            // The requirement a failing watch broke.
            let mut broke: Option<String> = None;
            let result: StepResult = match &step.action {
                Action::Exchange {
                    bytes,
                    compare,
                    silence_ok,
                } => {
                    let golden = &step.golden;
                    let request = drivespec_hpd::parse(&suite.rules, bytes).ok();
                    rec.sent = Some(to_hex(bytes));
                    rec.sent_text = Some(self.words(bytes, None));
                    last_request = request;
                    match self.exchange(bytes) {
                        Ok(obs) => {
                            let exp = concat(&obs.expected);
                            let got = concat(&obs.got);
                            let mut ea = self.answer(&obs.expected, obs.t0, request.as_ref());
                            let ga = self.answer(&obs.got, obs.t0, request.as_ref());
                            let judge = Judge::Answer {
                                compare: *compare,
                                silence_ok: *silence_ok,
                            };
                            let mut ok = match compare {
                                Compare::Unchanged => self.unchanged(&got),
                                _ => fits(&suite.rules, judge, &exp, &got),
                            };
                            if judged {
                                let mut other = Other {
                                    answer: &mut ea,
                                    findings: &mut findings,
                                    also: &mut also,
                                };
                                ok = self.judged(judge, ok, &obs, request.as_ref(), &mut other);
                            }
                            let mut why = format!("expected {}, got {}", show(&ea), show(&ga));
                            if let (true, Some(ed), Some(gd)) =
                                (ok && !got.is_empty(), ea.delay_us, ga.delay_us)
                            {
                                // A delayed answer (Pr26 = 4) must not come early.
                                if ed >= 5_000 && gd + ed / 5 < ed {
                                    ok = false;
                                    broke = Some(ANSWER_TIME_REQUIREMENT.to_owned());
                                    why = format!("the answer came after {gd} µs; the reference answers after {ed} µs (answer delay)");
                                }
                            }
                            if judged {
                                match self.timing(&obs, ok, exp.is_empty(), &step.text) {
                                    Timing::Clean => {}
                                    Timing::Open(f) => {
                                        ok = true;
                                        findings.push(f);
                                    }
                                    Timing::Undecided(reason) => {
                                        ok = false;
                                        why = format!("undecided, the case runs again: {reason}");
                                        self.undecided = Some(reason);
                                    }
                                    Timing::Late(text) => {
                                        ok = false;
                                        broke = Some(ANSWER_TIME_REQUIREMENT.to_owned());
                                        why = text;
                                    }
                                }
                            }
                            if let Some(g) = golden.as_ref().filter(|_| self.adopted_only()) {
                                if g != &exp {
                                    ok = false;
                                    why = format!(
                                        "the reference model disagrees with the golden vector: vector {}, model {}",
                                        if g.is_empty() { "silence".to_owned() } else { to_hex(g) },
                                        show(&ea)
                                    );
                                }
                            }
                            rec.note = match compare {
                                Compare::Exact => None,
                                Compare::Mask(m) => Some(format!("data compared under mask {m:#06x} (bits the drive sets itself are not compared)")),
                                Compare::Near(tolerance) => Some(format!("data compared within ±{tolerance}")),
                                Compare::Open { mask, min, max } => Some(format!("the manual does not fix the value: {min}..={max} accepted, bits {mask:#06x} compared")),
                                Compare::Unchanged => Some("data compared with the value read before the write".to_owned()),
                            };
                            if let (true, Compare::Open { .. }, Some(requirement)) =
                                (ok && judged, compare, step.requirements.first())
                            {
                                findings.push(Finding::Open {
                                    requirement: requirement.clone(),
                                    text: format!(
                                        "{}: the device: {}; the reference: {}",
                                        step.text, ga.text, ea.text
                                    ),
                                });
                            }
                            if *silence_ok {
                                rec.note = Some(
                                    "silence is also accepted (vector result: acceptable)"
                                        .to_owned(),
                                );
                            }
                            if !obs.late.is_empty() {
                                let n = late_note(&obs.late);
                                rec.note = Some(match rec.note.take() {
                                    Some(x) => format!("{x}; {n}"),
                                    None => n,
                                });
                            }
                            rec.expected = Some(ea);
                            rec.got = Some(ga);
                            Ok(Some((ok, why)))
                        }
                        Err(e) => Err(e),
                    }
                }
                Action::Send { bytes } => {
                    rec.sent = Some(to_hex(bytes));
                    let late = self.drain_late();
                    if !late.is_empty() {
                        rec.note = Some(late_note(&late));
                    }
                    let t = self.link.now();
                    let o = self.oracle_now(t);
                    self.oracle.handle_rx(o, bytes);
                    self.journal.send(o, bytes);
                    let sent = self.link.now();
                    if self.split_from.is_none() || bytes.first() == Some(&suite.rules.stx) {
                        self.split_from = Some(sent);
                    }
                    match self.link.send(bytes) {
                        Ok(()) => Ok(None),
                        Err(e) => Err((e, Vec::new())),
                    }
                }
                Action::Listen { .. } | Action::ListenTimeout {} | Action::ListenHalfTimeout {} => {
                    let (timeout, _, _) = self.line_times();
                    let us = match step.action {
                        Action::Listen { us } => us,
                        Action::ListenTimeout {} => timeout + self.slack.max(1_000),
                        // A pause that, with the transport's slack, could carry the rest of
                        // the message past the time-out is shortened, to none at the least.
                        _ => (timeout / 2).min(timeout.saturating_sub(self.slack)),
                    };
                    rec.note = Some(format!("listened {us} µs"));
                    match self.listen(us) {
                        Ok(obs) => {
                            if !obs.late.is_empty() {
                                rec.note = Some(format!(
                                    "{}; {}",
                                    late_note(&obs.late),
                                    rec.note.take().unwrap_or_default()
                                ));
                            }
                            let mut ea = self.answer(&obs.expected, obs.t0, last_request.as_ref());
                            let ga = self.answer(&obs.got, obs.t0, last_request.as_ref());
                            let exp = concat(&obs.expected);
                            let got = concat(&obs.got);
                            let mut ok = fits(&suite.rules, Judge::Listen, &exp, &got);
                            if judged {
                                let mut other = Other {
                                    answer: &mut ea,
                                    findings: &mut findings,
                                    also: &mut also,
                                };
                                ok = self.judged(
                                    Judge::Listen,
                                    ok,
                                    &obs,
                                    last_request.as_ref(),
                                    &mut other,
                                );
                            }
                            let why = format!(
                                "expected {} while listening, got {}",
                                show(&ea),
                                show(&ga)
                            );
                            rec.expected = Some(ea);
                            rec.got = Some(ga);
                            Ok(Some((ok, why)))
                        }
                        Err(e) => Err(e),
                    }
                }
                Action::PowerCycle {} => match self.link.power_cycle() {
                    Ok(_) => {
                        let t = self.link.now();
                        let o = self.oracle_now(t);
                        self.oracle.power_cycle(o);
                        self.journal.power_cycle(o);
                        let _ = self.oracle_output(o, t);
                        Ok(None)
                    }
                    Err(e) => Err((e, Vec::new())),
                },
                Action::BitRate {} => {
                    let bps = self.oracle.line().map_or(0, |l| l.bps);
                    rec.note = Some(format!("{bps} b/s"));
                    match self.link.set_bit_rate(bps) {
                        Ok(()) => Ok(None),
                        Err(e) => Err((e, Vec::new())),
                    }
                }
                Action::Save { addr, par, lun } => self.save(*addr, *par, *lun, &mut rec),
                Action::Watch {
                    addr,
                    reads,
                    us,
                    every_us,
                    until,
                    hold_us,
                    checks,
                } => {
                    let watch = Watch {
                        addr: *addr,
                        reads,
                        us: *us,
                        every_us: *every_us,
                        until,
                        hold_us: *hold_us,
                    };
                    match self.watch(&watch, &mut rec) {
                        Ok((_, Some(rule))) => {
                            broke = Some(rule.to_owned());
                            let why = rec.note.clone().unwrap_or_default();
                            Ok(Some((false, why)))
                        }
                        Ok((rounds, None)) => Ok(Some(
                            self.judge_watch(&watch, checks, &rounds, &mut rec, &mut broke),
                        )),
                        Err(e) => Err(e),
                    }
                }
                Action::Restore { addr, par, lun } => {
                    match self.saved.get(&(*par, *lun)).cloned() {
                        Some(data) => {
                            let msg = Message::WriteParam {
                                addr: *addr,
                                par: *par,
                                data,
                            };
                            match msg.to_bytes(&suite.rules) {
                                Ok(bytes) => {
                                    rec.sent = Some(to_hex(&bytes));
                                    rec.sent_text = Some(self.words(&bytes, None));
                                    match self.exchange(&bytes) {
                                        Ok(obs) => {
                                            let ea = self.answer(&obs.expected, obs.t0, None);
                                            let ga = self.answer(&obs.got, obs.t0, None);
                                            let ok = ea.hex == ga.hex;
                                            let why = format!(
                                                "expected {}, got {}",
                                                show(&ea),
                                                show(&ga)
                                            );
                                            rec.expected = Some(ea);
                                            rec.got = Some(ga);
                                            Ok(Some((ok, why)))
                                        }
                                        Err(e) => Err(e),
                                    }
                                }
                                Err(e) => {
                                    rec.note = Some(format!("nothing restored: {e}"));
                                    Ok(None)
                                }
                            }
                        }
                        None => {
                            rec.note = Some("nothing restored: no value was saved".to_owned());
                            Ok(None)
                        }
                    }
                }
                Action::Inputs { value } => match self.link.set_inputs(*value) {
                    Ok(taken) => {
                        let t = self.link.now();
                        let o = self.oracle_now(t);
                        self.oracle.set_inputs(o, *value);
                        self.journal.inputs(o, *value);
                        if !taken {
                            rec.note = Some(
                                "this transport cannot set digital inputs; only the reference took them"
                                    .to_owned(),
                            );
                        }
                        Ok(None)
                    }
                    Err(e) => Err((e, Vec::new())),
                },
            };
            match result {
                Ok(Some((ok, why))) => {
                    if judged {
                        rec.ok = Some(ok);
                        let exp_bytes = rec
                            .expected
                            .as_ref()
                            .and_then(|a| drivespec_spec::hex::parse_hex(&a.hex).ok())
                            .unwrap_or_default();
                        for id in self.step_checks(&info.requirements, step, &exp_bytes) {
                            if !checked.contains(&id) {
                                checked.push(id);
                            }
                        }
                        if !ok {
                            let mut requirements = self.requirement_refs(
                                &order,
                                Some(step),
                                &exp_bytes,
                                &rec.got.as_ref().map_or_else(Vec::new, |a| {
                                    drivespec_spec::hex::parse_hex(&a.hex).unwrap_or_default()
                                }),
                            );
                            if let Some(r) = broke
                                .as_deref()
                                .and_then(|id| RequirementRef::of(suite.family(), id))
                            {
                                requirements.retain(|x| x.id != r.id);
                                requirements.insert(0, r);
                            }
                            self.lead_by_byte_order(&mut requirements);
                            failure = Some(Failure {
                                step: Some(evidence.len()),
                                message: format!("step {i} ({}): {why}", step.text),
                                expected: format!(
                                    "{}{also}",
                                    rec.expected.as_ref().map(show).unwrap_or_default()
                                ),
                                got: rec.got.as_ref().map(show).unwrap_or_default(),
                                requirements,
                            });
                        }
                    } else {
                        rec.note = Some(match &rec.note {
                            Some(n) => format!("{n}; clean-up, not judged"),
                            None => "clean-up, not judged".to_owned(),
                        });
                    }
                }
                Ok(None) => {}
                Err((e, expected)) => {
                    let ea = self.answer(&expected, at_us, last_request.as_ref());
                    rec.expected = Some(ea.clone());
                    rec.ok = Some(false);
                    rec.note = Some(format!("transport: {e}"));
                    if failure.is_none() {
                        failure = Some(Failure {
                            step: Some(evidence.len()),
                            message: format!("step {i} ({}): transport: {e}", step.text),
                            expected: show(&ea),
                            got: e.to_string(),
                            requirements: self.requirement_refs(
                                &order,
                                Some(step),
                                &concat(&expected),
                                &[],
                            ),
                        });
                    }
                    broken = true;
                    self.link_broke = true;
                    match self.link.recover() {
                        Ok(Recovered::Fresh) => self.reset_oracle(),
                        Ok(Recovered::Same) => {}
                        Err(e2) => {
                            rec.note = Some(format!("transport: {e}; restart failed: {e2}"));
                        }
                    }
                }
            }
            self.note_order(&rec);
            evidence.push(rec);
            if judged && failure.is_none() && !broken {
                failure = self.read_back(i, step, &mut evidence);
            }
        }
        if failure.is_some() && !broken && !caps.reset {
            self.resync(case);
        }
        if failure.is_none() {
            for s in &case.steps {
                for r in &s.requirements {
                    if !cited.contains(r) {
                        cited.push(r.clone());
                    }
                }
            }
            self.settle(&cited, &mut findings);
        }
        let elapsed_us = self.link.now().saturating_sub(start);
        if failure.is_some() {
            findings.clear();
        }
        CaseRun {
            findings,
            checked,
            outcome: match failure {
                Some(f) => Outcome::Fail(f),
                None => Outcome::Pass,
            },
            evidence,
            elapsed_us,
        }
    }
}

/// The rounds of a watch, with the frame rule a read without a response broke (which ends
/// the watch), or a transport error.
type WatchResult = Result<(Vec<Round>, Option<&'static str>), (LinkError, Vec<Chunk>)>;

/// The rule a read without a response breaks when its bytes break no frame rule (manual 4.1:
/// a read is answered with the parameter's value).
const NO_RESPONSE: &str = "HPD-FRAME-010";

/// A watch step's reads and when it ends (manual 3.3, 3.6).
struct Watch<'w> {
    addr: u8,
    reads: &'w [Probe],
    us: Micros,
    every_us: Micros,
    until: &'w [Within],
    hold_us: Micros,
}

impl HpdSession<'_, '_> {
    /// Reads the watch's parameters from the device round after round until its end; the
    /// reference only goes along in time, then runs on until the same `until` holds for it
    /// (its motion ended too) so that the steps after the watch find it in the same state.
    fn watch(&mut self, w: &Watch<'_>, rec: &mut Record) -> WatchResult {
        let rules = self.suite.rules.clone();
        let requests: Vec<(Probe, Vec<u8>)> = w
            .reads
            .iter()
            .filter_map(|p| {
                let msg = Message::ReadParam {
                    addr: w.addr,
                    lun: p.lun,
                    par: p.par,
                };
                msg.to_bytes(&rules).ok().map(|b| (*p, b))
            })
            .collect();
        let start = self.link.now();
        let deadline = start.saturating_add(w.us);
        let mut rounds: Vec<Round> = Vec::new();
        let mut held: Option<Micros> = None;
        loop {
            let r0 = self.link.now();
            if r0 >= deadline || held.is_some_and(|h| r0 >= h.saturating_add(w.hold_us)) {
                break;
            }
            let mut round = Round::new();
            for (probe, bytes) in &requests {
                let _ = self.drain_late();
                let window = self.window();
                let sent = self.link.now();
                self.link.send(bytes).map_err(|e| (e, Vec::new()))?;
                let mut whole = |b: &[u8]| {
                    let from = b.iter().position(|x| *x == rules.stx).unwrap_or(b.len());
                    matches!(
                        drivespec_hpd::decode(
                            &rules,
                            b.get(from..).unwrap_or(&[]),
                            drivespec_hpd::AckEnd::NextByte
                        ),
                        Ok(drivespec_hpd::Status::Complete(_))
                    )
                };
                let end = sent.saturating_add(window);
                let mut got = self
                    .link
                    .recv(end, &mut whole)
                    .map_err(|e| (e, Vec::new()))?;
                let mut woke_late = 0;
                let have = concat(&got);
                if !whole(&have) {
                    woke_late = self.link.now().saturating_sub(end);
                    let more = self
                        .link
                        .recv(end.saturating_add(self.late_window()), &mut |b| {
                            let mut all = have.clone();
                            all.extend_from_slice(b);
                            whole(&all)
                        })
                        .map_err(|e| (e, Vec::new()))?;
                    got.extend(more);
                }
                let late = got
                    .iter()
                    .map(|c| c.at)
                    .find(|at| *at > end)
                    .map(|at| (at, woke_late));
                let came = got.last().map_or_else(|| self.link.now(), |c| c.at);
                match response(&rules, &concat(&got)) {
                    Some((par, data)) if par == probe.par && data.len() == probe.lun => {
                        if let Some((at, woke_late)) = late {
                            let on_time =
                                self.link.caps().virtual_time || woke_late <= RUNNER_ON_TIME_US;
                            if on_time || !self.last_attempt {
                                let reason = format!(
                                    "the answer to the read of {} byte(s) at {:#04x} came {:.1} ms after the request, after its window of {:.1} ms",
                                    probe.lun,
                                    probe.par,
                                    ms(at.saturating_sub(sent)),
                                    ms(window)
                                );
                                if !self.last_attempt {
                                    self.undecided = Some(reason.clone());
                                }
                                rec.got = Some(self.answer(&got, sent, None));
                                rec.note = Some(reason);
                                rounds.push(round);
                                return Ok((rounds, Some(ANSWER_TIME_REQUIREMENT)));
                            }
                        }
                        round.push(Sample {
                            value: value_of(&data, probe.signed),
                            sent,
                            came,
                        });
                    }
                    _ => {
                        let bytes = concat(&got);
                        let raw = self.oracle.memory().get(probe.par, probe.lun);
                        let expected = Data::from_value(i64::from(raw), probe.lun)
                            .and_then(|data| {
                                Message::Response {
                                    addr: w.addr,
                                    par: probe.par,
                                    data,
                                }
                                .to_bytes(&rules)
                                .ok()
                            })
                            .unwrap_or_default();
                        rec.expected = Some(self.answer(
                            &[Chunk {
                                at: sent,
                                bytes: expected,
                            }],
                            sent,
                            None,
                        ));
                        rec.got = Some(self.answer(&got, sent, None));
                        let broken = if unstuffed(&rules, &bytes) {
                            "HPD-FRAME-003"
                        } else {
                            frame_rule_broken(&rules, &bytes).unwrap_or(NO_RESPONSE)
                        };
                        rec.note = Some(format!(
                            "no response to the read of {} byte(s) at {:#04x}: {}",
                            probe.lun,
                            probe.par,
                            if got.is_empty() {
                                "silence".to_owned()
                            } else {
                                to_hex(&concat(&got))
                            }
                        ));
                        rounds.push(round);
                        return Ok((rounds, Some(broken)));
                    }
                }
            }
            let t = self.link.now();
            let o = self.oracle_now(t);
            self.oracle.advance(o);
            let _ = self.oracle_output(o, t);
            if held.is_none()
                && !w.until.is_empty()
                && w.until.iter().all(|c| motion::holds(c, &round))
            {
                held = Some(self.link.now());
            }
            rounds.push(round);
            let next = r0.saturating_add(w.every_us);
            if next > self.link.now() {
                let _ = self.link.recv(next, &mut |_| false);
            }
        }
        let t = self.link.now();
        let mut o = self.oracle_now(t);
        let bound = o.saturating_add(w.us);
        while !w.until.is_empty() && o < bound && !self.oracle_holds(w) {
            o = o.saturating_add(self.oracle.scan_period());
            self.oracle.advance(o);
        }
        let _ = self.oracle_output(o, t);
        self.journal.listen(o);
        Ok((rounds, None))
    }

    /// Whether the watch's `until` holds for the reference's values now.
    fn oracle_holds(&self, w: &Watch<'_>) -> bool {
        let mem = self.oracle.memory();
        let round: Round = w
            .reads
            .iter()
            .map(|p| {
                let raw = mem.get(p.par, p.lun);
                let data = Data::from_value(i64::from(raw), p.lun);
                Sample {
                    value: data.map_or(0, |d| value_of(&d, p.signed)),
                    sent: 0,
                    came: 0,
                }
            })
            .collect();
        w.until.iter().all(|c| motion::holds(c, &round))
    }

    /// Judges a watch's rounds by its checks: whether all hold and why not; `broke` names the
    /// requirement of the first check that failed.
    fn judge_watch(
        &self,
        w: &Watch<'_>,
        checks: &[Check],
        rounds: &[Round],
        rec: &mut Record,
        broke: &mut Option<String>,
    ) -> (bool, String) {
        let first = rounds.first().and_then(|r| r.first()).map_or(0, |s| s.sent);
        let last = rounds
            .last()
            .and_then(|r| r.last())
            .map_or(first, |s| s.came);
        let mut seen = Vec::new();
        let mut allowed = Vec::new();
        for c in checks {
            allowed.push(format!(
                "{}: {}",
                c.requirement,
                motion::allowed(&c.envelope)
            ));
            match motion::judge(&c.envelope, rounds) {
                Ok(text) => seen.push(format!("{}: {text}", c.requirement)),
                Err(why) => {
                    *broke = Some(c.requirement.clone());
                    rec.expected = Some(text_answer(allowed.join("; ")));
                    rec.got = Some(text_answer(why.clone()));
                    return (false, format!("{}: {why}", c.requirement));
                }
            }
        }
        rec.note = Some(format!(
            "{} round(s) of {} read(s) over {:.1} ms",
            rounds.len(),
            w.reads.len(),
            last.saturating_sub(first) as f64 / 1000.0
        ));
        rec.expected = Some(text_answer(allowed.join("; ")));
        rec.got = Some(text_answer(seen.join("; ")));
        (true, String::new())
    }
}

/// µs as ms.
fn ms(us: Micros) -> f64 {
    us as f64 / 1000.0
}

/// An answer record that is a judgement in words, not bytes.
fn text_answer(text: String) -> Answer {
    Answer {
        hex: String::new(),
        text,
        delay_us: None,
    }
}

/// The note on late bytes dropped before a request.
fn late_note(late: &[u8]) -> String {
    format!(
        "{} late byte(s) dropped before the request: {}",
        late.len(),
        to_hex(late)
    )
}

fn show(a: &Answer) -> String {
    if a.is_silence() {
        a.text.clone()
    } else {
        format!("{} ({})", a.hex, a.text)
    }
}

/// The data as a number: signed over its length when `signed`.
fn value_of(data: &Data, signed: bool) -> i64 {
    if !signed {
        return i64::from(data.unsigned());
    }
    let shift = 32 - 8 * u32::from(data.len().clamp(1, 4));
    i64::from((data.signed() << shift) >> shift)
}

/// The response `bytes` hold, if they are one.
fn response(rules: &drivespec_hpd::FrameRules, bytes: &[u8]) -> Option<(u8, Data)> {
    match drivespec_hpd::parse(rules, bytes) {
        Ok(Message::Response { par, data, .. }) => Some((par, data)),
        _ => None,
    }
}
