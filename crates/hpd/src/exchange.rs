//! Pairing requests with the drive's answers on a line (manual 4.1: the drive answers only
//! correct messages addressed to it; broadcasts are never answered).

use crate::line::FrameEvent;
use crate::repr::Message;
use crate::rules::{MessageKind, RulesError};
use drivespec_spec::hpd::Answer;

/// What a request led to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Exchange {
    /// The addressed drive answered with the expected kind of answer.
    Answered {
        /// The request.
        request: FrameEvent,
        /// The answer.
        answer: FrameEvent,
    },
    /// No answer came before the next request or the end of the line.
    Unanswered {
        /// The request.
        request: FrameEvent,
    },
    /// A broadcast, which no drive answers.
    Broadcast {
        /// The request.
        request: FrameEvent,
    },
    /// An answer that does not fit the request before it.
    Unexpected {
        /// The answer.
        answer: FrameEvent,
        /// The request it follows, if any.
        request: Option<FrameEvent>,
        /// What is wrong.
        reason: Mismatch,
    },
}

/// Why an answer does not fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mismatch {
    /// No request was waiting.
    NoRequest,
    /// The request was a broadcast.
    ToBroadcast,
    /// Another drive answered.
    WrongDrive {
        /// Drive addressed.
        expected: u8,
        /// Drive that answered.
        found: u8,
    },
    /// An acknowledge where data was due, or data where an acknowledge was due.
    WrongKind {
        /// What the message type asks for.
        expected: Answer,
        /// What came.
        found: Answer,
    },
}

/// Pairs frames into exchanges.
#[derive(Debug, Clone)]
pub struct Pairer {
    answers: [Answer; 7],
    pending: Option<FrameEvent>,
}

impl Pairer {
    /// Reads the answer expected for each message type from the spec (manual 4.1 table).
    pub fn from_spec(spec: &drivespec_spec::Spec) -> Result<Pairer, RulesError> {
        let p = spec
            .family(drivespec_spec::FamilyId::Hpd)
            .hpd()
            .ok_or(RulesError::NoProtocol)?;
        let mut answers = [Answer::None; 7];
        for (slot, kind) in answers.iter_mut().zip(MessageKind::ALL) {
            let name = kind.spec_name();
            *slot = p
                .message_types
                .iter()
                .find(|m| m.name == name)
                .ok_or(RulesError::MissingMessageType { name })?
                .answer;
        }
        Ok(Pairer {
            answers,
            pending: None,
        })
    }

    /// The answer a correct request of `kind` gets.
    pub fn expected_answer(&self, kind: MessageKind) -> Answer {
        MessageKind::ALL
            .iter()
            .position(|k| *k == kind)
            .and_then(|i| self.answers.get(i))
            .copied()
            .unwrap_or(Answer::None)
    }

    /// Takes the next frame on the line.
    pub fn push(&mut self, frame: FrameEvent, sink: &mut impl FnMut(Exchange)) {
        if frame.message.is_request() {
            self.flush(sink);
            if self.expected_answer(frame.message.kind()) == Answer::None {
                sink(Exchange::Broadcast { request: frame });
            } else {
                self.pending = Some(frame);
            }
            return;
        }
        let found = match frame.message {
            Message::Ack { .. } => Answer::Ack,
            _ => Answer::Data,
        };
        let request = self.pending.take();
        let reason = match request {
            None => Mismatch::NoRequest,
            Some(r) if self.expected_answer(r.message.kind()) == Answer::None => {
                Mismatch::ToBroadcast
            }
            Some(r) if r.message.addr() != frame.message.addr() => Mismatch::WrongDrive {
                expected: r.message.addr(),
                found: frame.message.addr(),
            },
            Some(r) if self.expected_answer(r.message.kind()) != found => Mismatch::WrongKind {
                expected: self.expected_answer(r.message.kind()),
                found,
            },
            Some(r) => {
                sink(Exchange::Answered {
                    request: r,
                    answer: frame,
                });
                return;
            }
        };
        sink(Exchange::Unexpected {
            answer: frame,
            request,
            reason,
        });
    }

    /// Ends the line: a request still waiting is unanswered.
    pub fn flush(&mut self, sink: &mut impl FnMut(Exchange)) {
        if let Some(request) = self.pending.take() {
            sink(Exchange::Unanswered { request });
        }
    }
}
