//! Decoding a half-duplex HPD line (manual 4.1): requests and answers interleaved, with
//! optional timestamps, resynchronising on STX and applying the message time-out.
//!
//! Memory is bounded: at most one unfinished message (≤ `MAX_FRAME` bytes) is carried from
//! one chunk to the next; every other byte is decoded in place. Nothing here allocates per
//! byte or per frame.

use crate::error::FrameError;
use crate::repr::{Message, MAX_FRAME};
use crate::rules::FrameRules;
use crate::wire::{decode, next_start, AckEnd, Status};

/// Time on the line in microseconds (any epoch).
pub type Micros = u64;

/// Something found on the line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineEvent {
    /// A complete, valid message.
    Frame(FrameEvent),
    /// Bytes that are not (part of) a valid message, and why.
    Discarded(Discard),
}

/// A message and where it was on the line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FrameEvent {
    /// Offset of its STX in the stream.
    pub offset: u64,
    /// Line bytes it occupied.
    pub len: usize,
    /// Time its first byte arrived, when known.
    pub time: Option<Micros>,
    /// The message.
    pub message: Message,
}

/// Bytes dropped by the decoder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Discard {
    /// Offset of the first byte dropped.
    pub offset: u64,
    /// Bytes dropped.
    pub len: usize,
    /// Time the first byte arrived, when known.
    pub time: Option<Micros>,
    /// Why.
    pub reason: DiscardReason,
}

/// Why bytes were dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DiscardReason {
    /// They do not form a valid message.
    Invalid(FrameError),
    /// The message was not complete within the time-out from its STX (manual 4.1).
    Timeout {
        /// Time allowed.
        timeout: Micros,
        /// Time that had passed when the next bytes came.
        elapsed: Micros,
    },
    /// The stream ended inside a message.
    Truncated,
}

impl std::fmt::Display for DiscardReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DiscardReason::Invalid(e) => write!(f, "{e}"),
            DiscardReason::Timeout { timeout, elapsed } => {
                write!(
                    f,
                    "not complete within the time-out of {timeout} µs ({elapsed} µs passed)"
                )
            }
            DiscardReason::Truncated => f.write_str("the stream ends inside a message"),
        }
    }
}

/// Streaming decoder of a whole line.
#[derive(Debug, Clone)]
pub struct LineDecoder {
    rules: FrameRules,
    timeout: Option<Micros>,
    /// The unfinished message carried over from the last chunk.
    carry: Buf<MAX_FRAME>,
    carry_time: Option<Micros>,
    /// Stream offset of the carry's first byte (or of the next byte when it is empty).
    offset: u64,
}

impl LineDecoder {
    /// A decoder without time-out (times unknown, or not to be checked).
    pub fn new(rules: FrameRules) -> LineDecoder {
        LineDecoder {
            rules,
            timeout: None,
            carry: Buf::default(),
            carry_time: None,
            offset: 0,
        }
    }

    /// Applies a message time-out (manual 4.1, Pr26 table) to timestamped input.
    pub fn with_timeout(mut self, timeout: Micros) -> LineDecoder {
        self.timeout = Some(timeout);
        self
    }

    /// Stream offset of the next byte to be fed.
    pub fn position(&self) -> u64 {
        self.offset + self.carry.len as u64
    }

    /// Decodes `chunk`, which arrived at `time`, and reports what it completes to `sink`.
    pub fn feed(&mut self, chunk: &[u8], time: Option<Micros>, sink: &mut impl FnMut(LineEvent)) {
        self.expire(time, sink);
        let mut rest = chunk;
        // Finish the message carried over from the last chunk, a few bytes at a time.
        while self.carry.len > 0 && !rest.is_empty() {
            let carried = self.carry.len;
            let take = (MAX_FRAME - carried).min(rest.len());
            let (head, tail) = rest.split_at(take);
            let mut window: Buf<{ 2 * MAX_FRAME }> = Buf::default();
            window.extend(self.carry.bytes());
            window.extend(head);
            match self.step(window.bytes(), self.carry_time, sink) {
                Step::Used(n) if n >= carried => {
                    // The carried message is done; go on in the chunk itself.
                    self.carry.clear();
                    self.offset += n as u64;
                    rest = rest.get(n - carried..).unwrap_or(&[]);
                }
                Step::Used(n) => {
                    // The start of the carry was dropped; keep the remainder.
                    self.carry.drop_front(n);
                    self.offset += n as u64;
                }
                Step::Incomplete => {
                    self.carry.extend(head);
                    rest = tail;
                }
            }
        }
        self.run(rest, time, sink);
    }

    /// Decodes the bytes of one chunk in place; an unfinished tail goes to the carry.
    fn run(&mut self, mut bytes: &[u8], time: Option<Micros>, sink: &mut impl FnMut(LineEvent)) {
        while !bytes.is_empty() {
            match self.step(bytes, time, sink) {
                Step::Used(n) => {
                    self.offset += n as u64;
                    bytes = bytes.get(n..).unwrap_or(&[]);
                }
                Step::Incomplete => {
                    self.carry.clear();
                    self.carry.extend(bytes);
                    self.carry_time = time;
                    return;
                }
            }
        }
    }

    /// Decodes one message or one discard at the start of `bytes` (whose first byte is at
    /// `self.offset`).
    fn step(&self, bytes: &[u8], time: Option<Micros>, sink: &mut impl FnMut(LineEvent)) -> Step {
        match decode(&self.rules, bytes, AckEnd::NextByte) {
            Ok(Status::Complete(d)) => {
                sink(LineEvent::Frame(FrameEvent {
                    offset: self.offset,
                    len: d.len,
                    time,
                    message: d.message,
                }));
                Step::Used(d.len)
            }
            Ok(Status::Incomplete { .. }) => Step::Incomplete,
            Err(e) => {
                let reason = DiscardReason::Invalid(e.error);
                sink(LineEvent::Discarded(Discard {
                    offset: self.offset,
                    len: e.skip,
                    time,
                    reason,
                }));
                Step::Used(e.skip)
            }
        }
    }

    /// Drops a carried message whose time-out has passed by `now`.
    fn expire(&mut self, now: Option<Micros>, sink: &mut impl FnMut(LineEvent)) {
        let (Some(timeout), Some(now), Some(start)) = (self.timeout, now, self.carry_time) else {
            return;
        };
        if self.carry.len == 0 || now.saturating_sub(start) <= timeout {
            return;
        }
        // A lone [STX][001+ADDR] followed by silence is a complete acknowledge.
        if let Ok(Status::Complete(d)) = decode(&self.rules, self.carry.bytes(), AckEnd::Immediate)
        {
            if d.len == self.carry.len {
                sink(LineEvent::Frame(FrameEvent {
                    offset: self.offset,
                    len: d.len,
                    time: Some(start),
                    message: d.message,
                }));
                self.offset += d.len as u64;
                self.carry.clear();
                return;
            }
        }
        let reason = DiscardReason::Timeout {
            timeout,
            elapsed: now.saturating_sub(start),
        };
        sink(LineEvent::Discarded(Discard {
            offset: self.offset,
            len: self.carry.len,
            time: Some(start),
            reason,
        }));
        self.offset += self.carry.len as u64;
        self.carry.clear();
    }

    /// Ends the stream: a carried acknowledge is complete, anything else is truncated.
    pub fn finish(&mut self, sink: &mut impl FnMut(LineEvent)) {
        while self.carry.len > 0 {
            let bytes = self.carry.bytes();
            let time = self.carry_time;
            let offset = self.offset;
            let used = match decode(&self.rules, bytes, AckEnd::Immediate) {
                Ok(Status::Complete(d)) => {
                    sink(LineEvent::Frame(FrameEvent {
                        offset,
                        len: d.len,
                        time,
                        message: d.message,
                    }));
                    d.len
                }
                Ok(Status::Incomplete { .. }) => {
                    // Drop up to the next byte that could start a message, and go on.
                    let n = next_start(&self.rules, bytes, 1);
                    sink(LineEvent::Discarded(Discard {
                        offset,
                        len: n,
                        time,
                        reason: DiscardReason::Truncated,
                    }));
                    n
                }
                Err(e) => {
                    let reason = DiscardReason::Invalid(e.error);
                    sink(LineEvent::Discarded(Discard {
                        offset,
                        len: e.skip,
                        time,
                        reason,
                    }));
                    e.skip
                }
            };
            let used = used.clamp(1, self.carry.len);
            self.carry.drop_front(used);
            self.offset += used as u64;
        }
    }
}

enum Step {
    /// Bytes used by a frame or a discard.
    Used(usize),
    /// The bytes are the beginning of a message.
    Incomplete,
}

/// A fixed-capacity byte buffer; bytes beyond the capacity are not stored.
#[derive(Debug, Clone, Copy)]
struct Buf<const N: usize> {
    bytes: [u8; N],
    len: usize,
}

impl<const N: usize> Default for Buf<N> {
    fn default() -> Self {
        Buf {
            bytes: [0; N],
            len: 0,
        }
    }
}

impl<const N: usize> Buf<N> {
    fn bytes(&self) -> &[u8] {
        self.bytes.get(..self.len).unwrap_or(&[])
    }

    fn extend(&mut self, more: &[u8]) {
        for (slot, b) in self.bytes.iter_mut().skip(self.len).zip(more) {
            *slot = *b;
            self.len += 1;
        }
    }

    fn drop_front(&mut self, n: usize) {
        let n = n.min(self.len);
        self.bytes.copy_within(n..self.len, 0);
        self.len -= n;
    }

    fn clear(&mut self) {
        self.len = 0;
    }
}
