//! The PKW client against a scripted drive (manual 3.8): the handshake properties — repeat the
//! command until its response, then "no command" until "no response", one command at a
//! time — time-outs in cycles, and bounded queues.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_psd4xx::{
    ClientConfig, ClientError, Outcome, Phase, Pkw, PkwClient, PkwRequest, PkwResponse, PkwRules,
    Rules,
};
use drivespec_spec::psd4xx::PkwOp;
use drivespec_spec::Spec;
use proptest::prelude::*;
use std::sync::OnceLock;

fn rules() -> &'static PkwRules {
    static RULES: OnceLock<PkwRules> = OnceLock::new();
    RULES.get_or_init(|| {
        Rules::from_spec(&Spec::builtin().unwrap())
            .unwrap()
            .pkw()
            .clone()
    })
}

/// How the scripted drive behaves.
#[derive(Debug, Clone, Copy)]
enum Mode {
    /// Answers every new command after `latency` cycles (3.8).
    Conforming,
    /// Never answers anything: keeps showing its current block.
    Silent,
    /// Answers commands but ignores "no command" (keeps its last response).
    Sticky,
    /// Answers writes with a PWE off by one.
    BadEcho,
}

/// A drive's PKW side: processes a new command after `latency` cycles and keeps its response
/// until the next command (manual 3.8).
struct Drive {
    mode: Mode,
    latency: u32,
    last: PkwRequest,
    busy: Option<u32>,
    shown: PkwResponse,
    processed: Vec<PkwRequest>,
}

impl Drive {
    fn new(mode: Mode, latency: u32) -> Drive {
        let none = rules().reply_from_text("none").unwrap();
        Drive {
            mode,
            latency,
            last: rules().request_from_text("none").unwrap(),
            busy: None,
            shown: none,
            processed: Vec::new(),
        }
    }

    fn answer(&self, cmd: &PkwRequest) -> PkwResponse {
        let r = rules();
        let codes = r.response_codes();
        let info = r.command_info(cmd.ak);
        match (info.map(|i| i.op), r.expected_response(cmd)) {
            (Some(PkwOp::None), _) => rules().reply_from_text("none").unwrap(),
            (Some(op), Some(code)) => Pkw {
                ak: code,
                spm: false,
                pnu: cmd.pnu,
                ind: cmd.ind,
                pwe: match (op, self.mode) {
                    (PkwOp::Write, Mode::BadEcho) => cmd.pwe.wrapping_add(1),
                    (PkwOp::Write, _) => cmd.pwe,
                    _ => 7,
                },
            },
            _ => Pkw {
                ak: codes.cannot_execute,
                spm: false,
                pnu: cmd.pnu,
                ind: cmd.ind,
                pwe: rules().error_codes().unknown_parameter.0,
            },
        }
    }

    /// One cycle: the controller's block in, the block the controller sees next out.
    fn step(&mut self, cmd: PkwRequest) -> PkwResponse {
        if cmd != self.last {
            self.last = cmd;
            self.busy = Some(self.latency);
        }
        if let Some(left) = self.busy {
            if left == 0 {
                self.busy = None;
                let is_none = cmd.ak == rules().command_codes().no_command;
                match self.mode {
                    Mode::Silent => {}
                    Mode::Sticky if is_none => {}
                    _ => {
                        if !is_none {
                            self.processed.push(cmd);
                        }
                        self.shown = self.answer(&cmd);
                    }
                }
            } else {
                self.busy = Some(left - 1);
            }
        }
        self.shown
    }
}

/// Runs `cycles` bus cycles; returns (input given to poll, output returned) per cycle.
fn run(client: &mut PkwClient, drive: &mut Drive, cycles: usize) -> Vec<(PkwResponse, PkwRequest)> {
    let mut input = drive.shown;
    let mut trace = Vec::with_capacity(cycles);
    for _ in 0..cycles {
        let out = client.poll(&input);
        trace.push((input, out));
        input = drive.step(out);
    }
    trace
}

fn requests() -> impl Strategy<Value = Vec<PkwRequest>> {
    requests_of(1..8)
}

/// Between `len.start` and `len.end - 1` commands.
fn requests_of(len: std::ops::Range<usize>) -> impl Strategy<Value = Vec<PkwRequest>> {
    let text = prop_oneof![
        prop::sample::select(vec![1u16, 2, 3, 13, 20, 42, 44, 96, 2047])
            .prop_map(|p| format!("read:{p}")),
        (0u16..5).prop_map(|i| format!("read:13[{i}]")),
        (1i64..=100).prop_map(|v| format!("write:44={v}")),
        (-1000i64..1000).prop_map(|v| format!("write:3={v}")),
        Just("count:13".to_owned()),
    ];
    prop::collection::vec(text, len).prop_map(|v| {
        v.iter()
            .map(|t| rules().request_from_text(t).unwrap())
            .collect()
    })
}

fn is_none(b: &PkwRequest) -> bool {
    b.ak == rules().command_codes().no_command
}

/// The handshake rules of 3.8, checked on a trace.
fn check_handshake(trace: &[(PkwResponse, PkwRequest)]) {
    let no_response = rules().response_codes().no_response;
    for (k, w) in trace.windows(2).enumerate() {
        let (_, prev) = w[0];
        let (input, out) = w[1];
        if !is_none(&out) && out != prev {
            // A command starts only after "no command" was sent and "no response" is seen.
            assert!(
                is_none(&prev),
                "cycle {}: command changed without no-command",
                k + 1
            );
            assert_eq!(
                input.ak,
                no_response,
                "cycle {}: started before no response",
                k + 1
            );
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn conforming_drive_answers_everything_in_order(reqs in requests(), latency in 0u32..6, slack in 1u32..10) {
        let timeout = latency + 1 + slack;
        let mut client = PkwClient::new(rules().clone(), ClientConfig { timeout_cycles: timeout, capacity: 16 });
        let mut drive = Drive::new(Mode::Conforming, latency);
        let ids: Vec<_> = reqs.iter().map(|r| client.submit(*r).unwrap()).collect();
        let trace = run(&mut client, &mut drive, reqs.len() * (2 * latency as usize + 6) + 4);
        check_handshake(&trace);
        prop_assert!(client.is_idle());
        let done: Vec<_> = std::iter::from_fn(|| client.next_completion()).collect();
        prop_assert_eq!(done.len(), reqs.len());
        for ((c, id), req) in done.iter().zip(&ids).zip(&reqs) {
            prop_assert_eq!(c.id, *id);
            prop_assert_eq!(c.request, *req);
            prop_assert!(c.cycles <= latency + 2, "answered within the latency: {:?}", c);
            match c.outcome {
                Outcome::Done { response } => {
                    prop_assert_eq!(response.pnu, req.pnu);
                    prop_assert_eq!(Some(response.ak), rules().expected_response(req));
                }
                Outcome::Refused { error, .. } => {
                    prop_assert!(rules().expected_response(req).is_none());
                    prop_assert_eq!(error, rules().error_codes().unknown_parameter);
                }
                other => prop_assert!(false, "{:?}", other),
            }
        }
        // The drive saw each command exactly once, in order (one at a time, 3.8).
        prop_assert_eq!(&drive.processed, &reqs);
    }

    #[test]
    fn silent_drive_times_out_each_request(reqs in requests(), timeout in 1u32..12) {
        let mut client = PkwClient::new(rules().clone(), ClientConfig { timeout_cycles: timeout, capacity: 16 });
        let mut drive = Drive::new(Mode::Silent, 0);
        for r in &reqs {
            client.submit(*r).unwrap();
        }
        let trace = run(&mut client, &mut drive, reqs.len() * (timeout as usize + 2) + 2);
        check_handshake(&trace);
        let done: Vec<_> = std::iter::from_fn(|| client.next_completion()).collect();
        prop_assert_eq!(done.len(), reqs.len());
        for c in done {
            prop_assert_eq!(c.outcome, Outcome::TimedOut { phase: Phase::AwaitResponse });
            prop_assert_eq!(c.cycles, timeout);
        }
        // Each command was repeated for `timeout` cycles.
        let sent = trace.iter().filter(|(_, o)| !is_none(o)).count();
        prop_assert_eq!(sent, reqs.len() * timeout as usize);
    }

    #[test]
    fn sticky_drive_blocks_the_next_command(reqs in requests_of(2..8), latency in 0u32..4, timeout in 6u32..12) {
        let mut client = PkwClient::new(rules().clone(), ClientConfig { timeout_cycles: timeout, capacity: 16 });
        let mut drive = Drive::new(Mode::Sticky, latency);
        for r in &reqs {
            client.submit(*r).unwrap();
        }
        let trace = run(&mut client, &mut drive, reqs.len() * (timeout as usize + latency as usize + 2) + 4);
        check_handshake(&trace);
        let done: Vec<_> = std::iter::from_fn(|| client.next_completion()).collect();
        prop_assert_eq!(done.len(), reqs.len());
        let first_answered = matches!(done[0].outcome, Outcome::Done { .. } | Outcome::Refused { .. });
        prop_assert!(first_answered, "{:?}", done[0]);
        for c in &done[1..] {
            prop_assert_eq!(c.outcome, Outcome::TimedOut { phase: Phase::AwaitNoResponse });
        }
        // Only the first command ever went out.
        prop_assert_eq!(drive.processed.len(), 1);
    }

    #[test]
    fn any_input_never_breaks_the_client(inputs in prop::collection::vec((0u8..=15, 0u16..=2047, any::<u16>(), any::<u32>()), 0..200), reqs in requests(), timeout in 1u32..8) {
        let mut client = PkwClient::new(rules().clone(), ClientConfig { timeout_cycles: timeout, capacity: 8 });
        let mut submitted = 0;
        for r in &reqs {
            if client.submit(*r).is_ok() {
                submitted += 1;
            }
        }
        let mut completed = 0;
        let mut prev = client.output();
        for (ak, pnu, ind, pwe) in inputs {
            let input = Pkw { ak: drivespec_psd4xx::ResponseCode(ak), spm: false, pnu, ind, pwe };
            let out = client.poll(&input);
            if !is_none(&out) && out != prev {
                prop_assert!(is_none(&prev));
                prop_assert_eq!(input.ak, rules().response_codes().no_response);
            }
            prev = out;
            while client.next_completion().is_some() {
                completed += 1;
            }
        }
        prop_assert_eq!(completed + client.pending(), submitted);
    }
}

#[test]
fn writes_must_be_echoed() {
    let mut client = PkwClient::new(rules().clone(), ClientConfig::default());
    let mut drive = Drive::new(Mode::BadEcho, 1);
    let w = rules().request_from_text("write:44=10").unwrap();
    let r = rules().request_from_text("read:44").unwrap();
    client.submit(w).unwrap();
    client.submit(r).unwrap();
    run(&mut client, &mut drive, 20);
    let first = client.next_completion().unwrap();
    assert!(
        matches!(first.outcome, Outcome::EchoMismatch { response } if response.pwe == 11),
        "{first:?}"
    );
    let second = client.next_completion().unwrap();
    assert!(matches!(second.outcome, Outcome::Done { .. }), "{second:?}");
    let reply = second.reply(rules()).unwrap();
    assert_eq!(rules().format_reply(&reply), "value:44=7");
}

#[test]
fn queue_is_bounded() {
    let mut client = PkwClient::new(
        rules().clone(),
        ClientConfig {
            timeout_cycles: 5,
            capacity: 2,
        },
    );
    let r = rules().request_from_text("read:44").unwrap();
    let none = rules().request_from_text("none").unwrap();
    assert_eq!(client.submit(none), Err(ClientError::NotACommand));
    client.submit(r).unwrap();
    client.submit(r).unwrap();
    assert_eq!(client.submit(r), Err(ClientError::Full { capacity: 2 }));
    // Finished but uncollected results still count.
    let mut drive = Drive::new(Mode::Conforming, 0);
    run(&mut client, &mut drive, 10);
    assert!(client.is_idle());
    assert_eq!(client.submit(r), Err(ClientError::Full { capacity: 2 }));
    assert!(client.next_completion().is_some());
    assert!(client.submit(r).is_ok());
}

#[test]
fn starts_with_no_command_until_no_response() {
    let mut client = PkwClient::new(rules().clone(), ClientConfig::default());
    let r = rules().request_from_text("read:44").unwrap();
    client.submit(r).unwrap();
    // The drive still shows an old answer: the client first clears it (3.8).
    let old = rules().reply_from_text("value:42=5").unwrap();
    assert!(is_none(&client.poll(&old)));
    assert_eq!(client.phase(), Some(Phase::AwaitNoResponse));
    let none = rules().reply_from_text("none").unwrap();
    assert_eq!(client.poll(&none), r);
    assert_eq!(client.phase(), Some(Phase::AwaitResponse));
    // A response for another parameter is not the answer; the command is repeated.
    assert_eq!(client.poll(&old), r);
    let answer = rules().reply_from_text("value:44=2").unwrap();
    assert!(is_none(&client.poll(&answer)));
    let c = client.next_completion().unwrap();
    assert_eq!(c.outcome, Outcome::Done { response: answer });
    assert_eq!(c.cycles, 2);
}
