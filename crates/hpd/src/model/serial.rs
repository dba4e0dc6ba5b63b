//! The drive's side of the serial line (manual chapter 4, 4.1): decoding with the Pr26
//! time-out, addressing, answers, broadcasts and line initialisation.
//!
//! Decisions where the manual is silent, each marked DECISION below:
//! - a well-formed write to this drive is always acknowledged, even when the drive refuses
//!   the value (read-only, out of range, security, PLC running): 4.1 has no negative answer
//!   and the acknowledge confirms reception;
//! - parameter reads answer the raw bytes at PAR for LUN bytes whatever table 4.2 holds there
//!   (the serial address space is flat; bytes past 0xFF read 0);
//! - a PLC read or write reaching outside 0x00–0x7F is not a correct message (HPD-FRAME-022)
//!   and gets no answer;
//! - the answer is decided by the state when the request is received: a request that disables
//!   the line (b99.12 clears b40.14) is still acknowledged;
//! - bytes of a chunk in which a re-initialisation takes effect were decoded with the old
//!   time-out.

use super::drive::Drive;
use super::output::{LineSettings, Output};
use crate::line::{LineDecoder, LineEvent, Micros};
use crate::repr::{Data, Message};
use std::sync::Arc;

impl Drive {
    /// Bytes received from the line at `now`, in any chunking (manual 4.1). All bytes of a chunk
    /// count as received at `now`; due timers run first.
    pub fn handle_rx(&mut self, now: Micros, bytes: &[u8]) {
        self.advance(now);
        let now = self.clock;
        let mut messages = Vec::new();
        // HPD-BAUD-003, HPD-FRAME-020: a message not complete within the time-out from its
        // STX is dropped (the decoder applies the time-out of the Pr26 code in force).
        self.decoder.feed(bytes, Some(now), &mut |e| {
            if let LineEvent::Frame(f) = e {
                messages.push(f.message);
            }
        });
        // HPD-SERIAL-012: invalid bytes never reach here, so they get no answer.
        for m in messages {
            self.on_message(now, m);
        }
    }

    /// Whether the drive communicates: the line was enabled at its last initialisation and
    /// b40.14 is still 1 (HPD-BIT-40-14).
    pub(super) fn comm_active(&self) -> bool {
        self.line.is_some_and(|l| l.enabled) && self.working.bit(self.layout.named.enable)
    }

    /// Acts on one correct message received at `now`.
    fn on_message(&mut self, now: Micros, m: Message) {
        let Some(line) = self.line else { return };
        // HPD-BIT-40-14: nothing happens on the line while disabled.
        if !self.comm_active() {
            return;
        }
        let layout = Arc::clone(&self.layout);
        let answer = match m {
            // Answers of other drives (HPD-SERIAL-001: drives only answer).
            Message::Response { .. } | Message::Ack { .. } => return,
            // HPD-SERIAL-013: a broadcast is executed and never answered.
            Message::Broadcast { par, data } => {
                self.write_bytes(par, data.as_slice());
                // HPD-BIT-99-5: in IDC mode a received broadcast sets b99.5.
                if line.idc && layout.idc.receiver_sets_trigger {
                    self.working.set_bit(layout.named.idc_trigger, true);
                }
                self.service(now);
                return;
            }
            // HPD-SERIAL-003: only messages with this drive's address are acted on.
            _ if m.addr() != line.address => return,
            // HPD-SERIAL-017, HPD-FRAME-010: a read answer repeats LUN and PAR with the data.
            Message::ReadParam { addr, lun, par } => {
                let bytes: Vec<u8> = (0..usize::from(lun))
                    .map(|i| {
                        let at = usize::from(par) + i;
                        self.working.bytes().get(at).copied().unwrap_or(0)
                    })
                    .collect();
                match Data::new(&bytes) {
                    Some(data) => Message::Response { addr, par, data },
                    None => return,
                }
            }
            Message::ReadPlc { addr, lun, par } => {
                // HPD-FRAME-022, HPD-PLC-038: PAR addresses the PLC area 0x00–0x7F.
                let Some(range) = self.plc_range(par, usize::from(lun)) else {
                    return;
                };
                match self.plc.get(range).and_then(Data::new) {
                    Some(data) => Message::Response { addr, par, data },
                    None => return,
                }
            }
            // HPD-FRAME-011: writes, bit changes and PLC writes get the short acknowledge.
            // HPD-ERRATUM-069: a refused write is acknowledged, or not answered.
            Message::WriteParam { addr, par, data } => {
                if !self.write_bytes(par, data.as_slice()) && layout.options.refusal_silent {
                    return;
                }
                Message::Ack { addr }
            }
            // HPD-FRAME-017, HPD-FRAME-018: the bits where the mask is 0 take the value's bits,
            // in the byte PAR (the word's address + 1 for bits 8–15).
            Message::BitChange {
                addr,
                par,
                mask,
                value,
            } => {
                if !self.bit_change(par, mask, value) && layout.options.refusal_silent {
                    return;
                }
                Message::Ack { addr }
            }
            Message::WritePlc { addr, par, data } => {
                let Some(range) = self.plc_range(par, usize::from(data.len())) else {
                    return;
                };
                self.write_plc(range, data.as_slice());
                Message::Ack { addr }
            }
        };
        // HPD-BAUD-004: Pr26 = 4 delays every answer by 25 ms.
        let at = now.saturating_add(line.answer_delay_us);
        self.transmit(at, &answer);
        // Commands and IDC broadcasts the request triggered run after the answer is queued.
        self.service(now);
    }

    /// The PLC area indices of `len` bytes from PAR, None when they reach outside the area.
    fn plc_range(&self, par: u8, len: usize) -> Option<std::ops::Range<usize>> {
        let start = usize::from(par.checked_sub(self.layout.plc_first)?);
        let end = start.checked_add(len)?;
        (end <= self.layout.plc_len).then_some(start..end)
    }

    /// Sends `message` at `at`: queued when `at` lies in the future (manual 4.1).
    pub(super) fn transmit(&mut self, at: Micros, message: &Message) {
        let Ok(bytes) = message.to_bytes(&self.layout.rules) else {
            return;
        };
        if at <= self.clock {
            self.outputs.push_back(Output::Transmit { at, bytes });
        } else {
            let pos = self.pending.partition_point(|(t, _)| *t <= at);
            self.pending.insert(pos, (at, bytes));
        }
    }

    /// Initialises the serial line from Pr26, Pr27 and b40.14 (HPD-BIT-42-3, HPD-PAR-038): the new code's time-out and answer delay, the new address, and whether
    /// the line is enabled, all take effect now; a half-received message is dropped.
    pub(super) fn init_line(&mut self) {
        let layout = Arc::clone(&self.layout);
        let n = &layout.named;
        let code = self.working.get(n.baud.addr, n.baud.size);
        let address = self.working.get(n.address.addr, n.address.size);
        let settings = u8::try_from(code).ok().and_then(|code| {
            let baud = layout.baud(code)?;
            let address = u8::try_from(address)
                .ok()
                .filter(|a| *a <= layout.rules.addr_max)?;
            Some(LineSettings {
                active: false,
                enabled: self.working.bit(n.enable),
                baud_code: code,
                bps: baud.bps,
                timeout_us: Micros::from(baud.timeout_ms).saturating_mul(1000),
                answer_delay_us: Micros::from(baud.answer_delay_ms.unwrap_or(0))
                    .saturating_mul(1000),
                address,
                // HPD-BAUD-005, HPD-BIT-99-5: Pr26 = 10 is inter-drive communication.
                idc: code == layout.idc.baud_code,
            })
        });
        let decoder = LineDecoder::new(layout.rules.clone());
        self.decoder = match settings {
            Some(s) => decoder.with_timeout(s.timeout_us),
            None => decoder,
        };
        // DECISION: with an unusable Pr26 or Pr27 the line stays silent until initialised
        // again with usable values.
        self.line = settings;
    }

    /// Sends the IDC broadcast of Pr81 to the serial address in Pr80 when b99.5 = 1 in IDC
    /// mode, and clears b99.5 (HPD-BIT-99-5).
    ///
    /// DECISION: b99.5 is cleared once the broadcast is sent, so that one received broadcast
    /// gives one answer broadcast (3.8.2 example 10 describes a ping-pong between two drives);
    /// a Pr80 outside 0..=255 sends nothing.
    pub(super) fn service_idc(&mut self, now: Micros) {
        let layout = Arc::clone(&self.layout);
        let n = &layout.named;
        let idc = self.line.is_some_and(|l| l.idc);
        if !idc || !self.comm_active() || !self.working.bit(n.idc_trigger) {
            return;
        }
        self.working.set_bit(n.idc_trigger, false);
        let target = self
            .working
            .get_signed(n.idc_target.addr, n.idc_target.size);
        let value = self.working.get(n.idc_value.addr, n.idc_value.size);
        let (Ok(par), Some(data)) = (
            u8::try_from(target),
            Data::from_value(i64::from(value), layout.idc.lun),
        ) else {
            return;
        };
        self.transmit(now, &Message::Broadcast { par, data });
    }
}
