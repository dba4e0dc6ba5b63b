//! Virtual time (manual 3.8.1, appendix F): PLC scans every 6.144 ms, FIN copies every 512 µs,
//! the motor every 2.048 ms while it moves, delayed answers, and the digital inputs and outputs.
//!
//! Scans and FIN slots count from the last power-up. Events due at the same time run as:
//! delayed answers, then the FIN copy, then the scan. An input given at `now` is seen by
//! events after `now`: everything due at or before `now` runs first.

use super::drive::Drive;
use super::output::Output;
use crate::line::Micros;
use crate::plc::Operands;
use std::sync::Arc;

/// What happens at a point of virtual time, in the order of simultaneous events.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Event {
    Answer,
    Fin,
    Motor,
    Scan,
}

impl Drive {
    /// Lets virtual time pass until `now` (manual 3.8.1, appendix F): delayed answers go
    /// out, FIN copies and PLC scans run. An earlier `now` changes nothing.
    pub fn advance(&mut self, now: Micros) {
        let now = now.max(self.clock);
        while let Some((t, event)) = self.next_event() {
            if t > now {
                break;
            }
            self.clock = t;
            match event {
                Event::Answer => {
                    if let Some((at, bytes)) = self.pending.pop_front() {
                        self.outputs.push_back(Output::Transmit { at, bytes });
                    }
                }
                Event::Fin => self.fast_inputs(t),
                Event::Motor => {
                    self.motor_tick(t);
                    self.service(t);
                }
                Event::Scan => self.scan(t),
            }
        }
        self.clock = now;
    }

    /// The digital inputs change at `now`, bit i = input i (manual 3.8.1, 3.2 X3).
    pub fn set_inputs(&mut self, now: Micros, digital_inputs: u16) {
        self.advance(now);
        self.inputs = digital_inputs;
    }

    /// When the drive next needs [`Drive::advance`]: the next PLC scan, FIN copy or delayed
    /// answer (manual 3.8.1, 4).
    pub fn poll_timeout(&self) -> Option<Micros> {
        self.next_event().map(|(t, _)| t)
    }

    fn next_event(&self) -> Option<(Micros, Event)> {
        let answer = self.pending.front().map(|(t, _)| (*t, Event::Answer));
        let fin = self.next_fin().map(|t| (t, Event::Fin));
        let scan = self.next_scan.map(|t| (t, Event::Scan));
        let motor = self.next_motor().map(|t| (t, Event::Motor));
        [answer, fin, motor, scan].into_iter().flatten().min()
    }

    /// The next FIN slot after the current time, while a FIN instruction runs (HPD-PLC-030:
    /// FIN is honoured only from the start of the program).
    fn next_fin(&self) -> Option<Micros> {
        let layout = &self.layout;
        let leading_fin = self
            .program
            .as_ref()
            .and_then(|p| p.instrs.first())
            .is_some_and(|(_, i)| matches!(i.operands, Operands::Fin { .. }));
        if !leading_fin || !layout.runtime.running(&self.working) || layout.fin_us == 0 {
            return None;
        }
        let slots = self.clock.saturating_sub(self.epoch) / layout.fin_us + 1;
        self.epoch.checked_add(slots.checked_mul(layout.fin_us)?)
    }

    /// HPD-PLC-029: the FIN copies of inputs 1–3 every 512 µs.
    fn fast_inputs(&mut self, t: Micros) {
        let layout = Arc::clone(&self.layout);
        let program = self.program.as_ref().unwrap_or(&layout.empty_program);
        layout
            .runtime
            .fast_inputs(&mut self.working, program, self.inputs);
        self.service(t);
    }

    /// One PLC scan at `t` (HPD-PLC-004: every 6.144 ms).
    fn scan(&mut self, t: Micros) {
        let layout = Arc::clone(&self.layout);
        self.refresh_status();
        let program = self.program.as_ref().unwrap_or(&layout.empty_program);
        // HPD-PLC-006, HPD-BIT-90-INPUTS, HPD-IO-003: read the inputs, update the
        // timers, run the program (only with b99.13 = 1), write the outputs.
        let outputs =
            layout
                .runtime
                .scan(&mut self.plc_state, &mut self.working, program, self.inputs);
        self.next_scan = t.checked_add(layout.scan_us);
        if outputs != self.digital_outputs {
            self.digital_outputs = outputs;
            self.outputs.push_back(Output::DigitalOutputs {
                at: t,
                value: outputs,
            });
        }
        self.service(t);
    }
}
