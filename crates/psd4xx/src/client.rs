//! A sans-IO PKW client: the controller's side of the handshake of manual 3.8.
//!
//! The controller repeats a command every cycle until the drive shows the matching response,
//! then sends "no command" until the drive shows "no response", and only then the next
//! command (one command at a time). [`PkwClient::poll`] is called once per bus cycle with the
//! PKW block of the latest input image and returns the block for the next output image.
//! Results are collected with [`PkwClient::next_completion`].
//!
//! Time is counted in cycles (calls to `poll`): a request that sees no matching response
//! within `timeout_cycles` completes with [`Outcome::TimedOut`]. Waiting for "no response"
//! is bounded the same way: when the drive keeps an old response for `timeout_cycles`, the
//! next queued request completes with `TimedOut` in phase [`Phase::AwaitNoResponse`] without
//! being sent. The client never panics and holds at most `capacity` requests and results.

use crate::error::ClientError;
use crate::pkw::{ErrorCode, PkwRequest, PkwResponse, PkwRules, Reply, Verdict};
use crate::Pkw;
use serde::Serialize;
use std::collections::VecDeque;

/// Settings of the client (manual 3.8 gives no time-out; these are ours).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct ClientConfig {
    /// Cycles to wait for a matching response (and for "no response") before giving up.
    pub timeout_cycles: u32,
    /// Largest number of queued requests plus uncollected results.
    pub capacity: usize,
}

impl Default for ClientConfig {
    /// 100 cycles, 16 requests.
    fn default() -> ClientConfig {
        ClientConfig {
            timeout_cycles: 100,
            capacity: 16,
        }
    }
}

/// Number of a submitted request, in submission order (from 0) (manual 3.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct RequestId(pub u64);

/// Where the handshake waits (manual 3.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Phase {
    /// The command is sent; waiting for its response.
    AwaitResponse,
    /// "No command" is sent; waiting for "no response".
    AwaitNoResponse,
}

/// How a request ended (manual 3.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "outcome", rename_all = "kebab-case")]
pub enum Outcome {
    /// A positive response (for writes: with PNU, IND and PWE echoed, 3.8 last paragraph).
    Done {
        /// The response.
        response: PkwResponse,
    },
    /// The drive cannot execute the command: response 7 with an error code.
    Refused {
        /// The response.
        response: PkwResponse,
        /// The error code in PWE.
        error: ErrorCode,
    },
    /// A positive answer to a write that does not echo PNU, IND and PWE.
    EchoMismatch {
        /// The response.
        response: PkwResponse,
    },
    /// A matching response whose code the command does not allow, or an unknown command
    /// answered by anything but "no response".
    Unexpected {
        /// The response.
        response: PkwResponse,
    },
    /// No matching response (or no "no response") within the time-out.
    TimedOut {
        /// Where the handshake waited.
        phase: Phase,
    },
}

/// A finished request (manual 3.8).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Completion {
    /// Its number.
    pub id: RequestId,
    /// The command sent.
    pub request: PkwRequest,
    /// How it ended.
    pub outcome: Outcome,
    /// Cycles from sending the command to the end.
    pub cycles: u32,
}

impl Completion {
    /// The typed reply of a `Done` or `Refused` outcome (3.8).
    pub fn reply(&self, rules: &PkwRules) -> Option<Reply> {
        match self.outcome {
            Outcome::Done { response } | Outcome::Refused { response, .. } => {
                rules.reply(&response)
            }
            _ => None,
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    /// Sending "no command" until "no response" is seen.
    Clearing { cycles: u32 },
    /// Ready: "no response" seen, nothing in flight.
    Idle,
    /// Sending a command until its response is seen.
    Active {
        id: RequestId,
        request: PkwRequest,
        cycles: u32,
    },
}

/// The controller side of the PKW handshake (manual 3.8), driven one bus cycle at a time.
#[derive(Debug, Clone)]
pub struct PkwClient {
    rules: PkwRules,
    config: ClientConfig,
    state: State,
    queue: VecDeque<(RequestId, PkwRequest)>,
    done: VecDeque<Completion>,
    next_id: u64,
}

impl PkwClient {
    /// A client that first waits for "no response" (the drive's state is unknown) (manual 3.8).
    pub fn new(rules: PkwRules, config: ClientConfig) -> PkwClient {
        PkwClient {
            rules,
            config,
            state: State::Clearing { cycles: 0 },
            queue: VecDeque::new(),
            done: VecDeque::new(),
            next_id: 0,
        }
    }

    /// Queues a command (3.8: one at a time; they are sent in order).
    pub fn submit(&mut self, request: PkwRequest) -> Result<RequestId, ClientError> {
        if request.ak == self.rules.command_codes().no_command {
            return Err(ClientError::NotACommand);
        }
        let in_flight = usize::from(matches!(self.state, State::Active { .. }));
        if self.queue.len() + self.done.len() + in_flight >= self.config.capacity {
            return Err(ClientError::Full {
                capacity: self.config.capacity,
            });
        }
        let id = RequestId(self.next_id);
        self.next_id += 1;
        self.queue.push_back((id, request));
        Ok(id)
    }

    /// One bus cycle: takes the PKW block of the latest input and returns the block to send (manual 3.8).
    pub fn poll(&mut self, input: &PkwResponse) -> PkwRequest {
        let timeout = self.config.timeout_cycles;
        match self.state {
            State::Idle => {}
            State::Clearing { cycles } => {
                if input.ak == self.rules.response_codes().no_response {
                    self.state = State::Idle;
                } else if cycles.saturating_add(1) >= timeout {
                    if let Some((id, request)) = self.queue.pop_front() {
                        self.finish(
                            id,
                            request,
                            Outcome::TimedOut {
                                phase: Phase::AwaitNoResponse,
                            },
                            0,
                        );
                    }
                    self.state = State::Clearing { cycles: 0 };
                } else {
                    self.state = State::Clearing {
                        cycles: cycles.saturating_add(1),
                    };
                }
            }
            State::Active {
                id,
                request,
                cycles,
            } => {
                let cycles = cycles.saturating_add(1);
                if self.rules.answers(&request, input) {
                    let outcome = self.outcome(&request, input);
                    self.finish(id, request, outcome, cycles);
                    self.state = State::Clearing { cycles: 0 };
                } else if cycles >= timeout {
                    let outcome = Outcome::TimedOut {
                        phase: Phase::AwaitResponse,
                    };
                    self.finish(id, request, outcome, cycles);
                    self.state = State::Clearing { cycles: 0 };
                } else {
                    self.state = State::Active {
                        id,
                        request,
                        cycles,
                    };
                }
            }
        }
        if self.state == State::Idle {
            if let Some((id, request)) = self.queue.pop_front() {
                self.state = State::Active {
                    id,
                    request,
                    cycles: 0,
                };
            }
        }
        self.output()
    }

    /// The block the client sends now: the active command, or "no command" (3.8).
    pub fn output(&self) -> PkwRequest {
        match self.state {
            State::Active { request, .. } => request,
            _ => Pkw {
                ak: self.rules.command_codes().no_command,
                ..Pkw::default()
            },
        }
    }

    /// The next finished request, oldest first (manual 3.8).
    pub fn next_completion(&mut self) -> Option<Completion> {
        self.done.pop_front()
    }

    /// Requests queued or in flight (manual 3.8).
    pub fn pending(&self) -> usize {
        self.queue.len() + usize::from(matches!(self.state, State::Active { .. }))
    }

    /// Whether nothing is queued or in flight (manual 3.8).
    pub fn is_idle(&self) -> bool {
        self.pending() == 0
    }

    /// Where the handshake waits now, None when idle (3.8).
    pub fn phase(&self) -> Option<Phase> {
        match self.state {
            State::Idle => None,
            State::Clearing { .. } => Some(Phase::AwaitNoResponse),
            State::Active { .. } => Some(Phase::AwaitResponse),
        }
    }

    /// The PKW rules in use (manual 3.8).
    pub fn rules(&self) -> &PkwRules {
        &self.rules
    }

    fn outcome(&self, request: &PkwRequest, response: &PkwResponse) -> Outcome {
        let response = *response;
        match self.rules.verdict(request.ak, response.ak) {
            Verdict::Negative => Outcome::Refused {
                response,
                error: ErrorCode(response.pwe),
            },
            Verdict::Positive => match self.rules.echo_holds(request, &response) {
                Some(false) => Outcome::EchoMismatch { response },
                _ => Outcome::Done { response },
            },
            Verdict::NotAllowed | Verdict::UnknownCommand => Outcome::Unexpected { response },
        }
    }

    fn finish(&mut self, id: RequestId, request: PkwRequest, outcome: Outcome, cycles: u32) {
        self.done.push_back(Completion {
            id,
            request,
            outcome,
            cycles,
        });
    }
}
