//! The model drive: its state, construction, power-up and read-only views (manual chapter 4,
//! 3.2–3.4, 3.8.1).

use super::config::{DriveConfig, Start};
use super::error::ModelError;
use super::layout::Layout;
use super::motor::Motor;
use super::output::{Alarms, LineSettings, Output};
use crate::line::{LineDecoder, Micros};
use crate::memory::{Memory, ParamMap};
use crate::plc::{PlcState, Program};
use drivespec_spec::Spec;
use std::collections::VecDeque;
use std::sync::Arc;

/// A reference HPD drive on virtual time (manual chapter 4, 3.3–3.4, 3.6, 3.8, appendix G).
///
/// Drive it with [`Drive::handle_rx`], [`Drive::set_inputs`] and [`Drive::advance`]; drain
/// [`Drive::poll_output`] and wake up at [`Drive::poll_timeout`]. Time never goes backwards:
/// an earlier `now` is taken as the current time.
#[derive(Debug, Clone)]
pub struct Drive {
    pub(super) layout: Arc<Layout>,
    /// Working parameter values by serial address.
    pub(super) working: Memory,
    /// The parameter save image (EEPROM), written only by b99.15.
    pub(super) saved: Memory,
    /// Working PLC area.
    pub(super) plc: Vec<u8>,
    /// The PLC save image, written only by b99.14.
    pub(super) saved_plc: Vec<u8>,
    /// The program decoded from `plc` (None: no END in the area).
    pub(super) program: Option<Program>,
    pub(super) plc_state: PlcState,
    pub(super) decoder: LineDecoder,
    /// The line as last initialised; None when Pr26 or Pr27 were unusable then.
    pub(super) line: Option<LineSettings>,
    /// Current virtual time.
    pub(super) clock: Micros,
    /// Time of the last power-up: PLC scans and FIN slots count from here.
    pub(super) epoch: Micros,
    pub(super) next_scan: Option<Micros>,
    /// Answers waiting for their send time (Pr26 = 4).
    pub(super) pending: VecDeque<(Micros, Vec<u8>)>,
    pub(super) outputs: VecDeque<Output>,
    /// Physical digital inputs, bit i = input i.
    pub(super) inputs: u16,
    /// Digital outputs as last written by a scan.
    pub(super) digital_outputs: u16,
    /// Last seen state of each command bit (for the `latched` reading of HPD-ERRATUM-012).
    pub(super) command_seen: Vec<bool>,
    /// The motor beyond what the parameters hold (manual 3.3, 3.6).
    pub(super) motor: Motor,
}

impl Drive {
    /// This drive's state (values, program, line, clock) under the erratum readings `other`
    /// was built with (spec `[[erratum]]` options): what the same history would be on a drive
    /// following those readings as long as they did not tell apart so far.
    pub fn under_readings_of(&self, other: &Drive) -> Drive {
        let mut d = self.clone();
        d.layout = Arc::clone(&other.layout);
        d.command_seen.resize(d.layout.commands.len(), false);
        d
    }

    /// The next PLC scan moved to `at` (not before the current time nor a period after it),
    /// the scan grid and the FIN slots with it: the same drive with its scans at another
    /// phase against the line (3.8.1 fixes the 6.144 ms period, not when a scan falls
    /// between two messages).
    pub fn move_next_scan(&mut self, at: Micros) {
        let Some(next) = self.next_scan else { return };
        let at = at.clamp(self.clock, self.clock.saturating_add(self.layout.scan_us));
        self.epoch = if at >= next {
            self.epoch.saturating_add(at - next)
        } else {
            self.epoch.saturating_sub(next - at)
        };
        self.next_scan = Some(at);
    }

    /// The PLC scan period (3.8.1, µs).
    pub fn scan_period(&self) -> Micros {
        self.layout.scan_us
    }

    /// When the next PLC scan runs (3.8.1); None before the first power-up.
    pub fn next_scan(&self) -> Option<Micros> {
        self.next_scan
    }

    /// Builds a drive powered up at time 0 in the configured state (manual 4.1, 3.2).
    pub fn new(spec: &Spec, config: DriveConfig) -> Result<Drive, ModelError> {
        let layout = Arc::new(Layout::new(spec, &config.readings, config.motion)?);
        let mut saved = Memory::default();
        masked_copy(
            &mut saved,
            &layout.factory,
            &Memory::default(),
            &layout.saved_mask,
        );
        let mut drive = Drive {
            working: layout.factory.clone(),
            saved,
            plc: layout.default_program.clone(),
            saved_plc: layout.default_program.clone(),
            program: None,
            plc_state: PlcState::default(),
            decoder: LineDecoder::new(layout.rules.clone()),
            line: None,
            clock: 0,
            epoch: 0,
            next_scan: None,
            pending: VecDeque::new(),
            outputs: VecDeque::new(),
            inputs: 0,
            digital_outputs: 0,
            command_seen: vec![false; layout.commands.len()],
            motor: Motor::default(),
            layout,
        };
        if let Start::Commissioned { baud_code, address } = config.start {
            drive.commission(baud_code, address)?;
        }
        drive.power_up(0);
        Ok(drive)
    }

    /// Applies the set-up steps of manual 4.1 (`protocol.serial_setup.steps`) with the given
    /// code and address, and saves the parameters; the power-up that follows initialises the
    /// line (HPD-SERIAL-009).
    fn commission(&mut self, baud_code: Option<u8>, address: u8) -> Result<(), ModelError> {
        let layout = Arc::clone(&self.layout);
        let named = &layout.named;
        let code = baud_code.unwrap_or(self.working.get(named.baud.addr, named.baud.size) as u8);
        if layout.baud(code).is_none() {
            return Err(ModelError::BaudCode { code });
        }
        if address > layout.rules.addr_max {
            return Err(ModelError::Address {
                addr: address,
                max: layout.rules.addr_max,
            });
        }
        let setup = &layout.setup;
        for step in &setup.steps {
            let unknown = || ModelError::Spec {
                what: format!("serial set-up step {} has no serial address", step.target),
            };
            if step.target.contains('.') {
                let bit = ParamMap::parse_bit(&step.target)
                    .and_then(|(n, y)| layout.map.bit(n, y))
                    .ok_or_else(unknown)?;
                // Power-up initialises the line and the image is saved below.
                if bit != setup.reinit && bit != setup.save {
                    self.working.set_bit(bit, step.value != 0);
                }
                continue;
            }
            let slot = ParamMap::parse_param(&step.target)
                .and_then(|n| layout.map.slot(n))
                .ok_or_else(unknown)?;
            let value = if step.target == setup.baud_param {
                i64::from(code)
            } else if step.target == setup.address_param {
                i64::from(address)
            } else {
                step.value
            };
            self.working.set(slot.addr, slot.size, value as u32);
        }
        self.save_parameters();
        Ok(())
    }

    /// Power-up at `now` (manual 3.4, 3.8.1): the saved image is loaded, everything else takes
    /// its delivery value, the line is initialised and the PLC starts scanning.
    pub(super) fn power_up(&mut self, now: Micros) {
        let layout = Arc::clone(&self.layout);
        self.clock = self.clock.max(now);
        self.epoch = self.clock;
        // HPD-PAR-018: only what b99.15 and b99.14 stored survives power-down.
        let mut working = Memory::default();
        masked_copy(
            &mut working,
            &self.saved,
            &layout.factory,
            &layout.saved_mask,
        );
        // HPD-BIT-94-POWER-ON, HPD-BIT-91-POWER-ON: these bits are 0 at power-up.
        for b in &layout.power_on_reset {
            working.set_bit(*b, false);
        }
        self.working = working;
        self.plc.clone_from(&self.saved_plc);
        self.recache_program();
        self.plc_state = PlcState::default();
        self.pending.clear();
        self.command_seen.iter_mut().for_each(|s| *s = false);
        self.reset_motor();
        // HPD-PLC-004: scans every 6.144 ms from power-up.
        self.next_scan = self.epoch.checked_add(layout.scan_us);
        if self.digital_outputs != 0 {
            self.digital_outputs = 0;
            self.outputs.push_back(Output::DigitalOutputs {
                at: self.clock,
                value: 0,
            });
        }
        // HPD-BIT-42-3: the serial line is also initialised at every power-up.
        self.init_line();
        self.service(self.clock);
    }

    /// Switches the drive off and on again at `now` (manual 3.2, 3.4): working values are lost,
    /// the saved image and saved PLC program are loaded (HPD-PAR-018).
    pub fn power_cycle(&mut self, now: Micros) {
        self.advance(now);
        self.power_up(now);
    }

    /// Decodes the program from the PLC area again (manual 3.8.1, 4.1).
    pub(super) fn recache_program(&mut self) {
        self.program = self.layout.runtime.codec().decode_program(&self.plc).ok();
    }

    /// The next output, in the order the drive produced them (manual 4.1, 3.8.1).
    pub fn poll_output(&mut self) -> Option<Output> {
        self.outputs.pop_front()
    }

    /// Current virtual time in µs, the clock of time-outs (manual 4.1) and scans (3.8.1).
    pub fn now(&self) -> Micros {
        self.clock
    }

    /// Working parameter memory by serial address (manual 4.2).
    pub fn memory(&self) -> &Memory {
        &self.working
    }

    /// The parameter save image (EEPROM) written by b99.15 (manual 3.4); bytes of parameters
    /// that are not saved read 0.
    pub fn saved_memory(&self) -> &Memory {
        &self.saved
    }

    /// Working PLC area, addresses 0x00–0x7F (manual 4.1).
    pub fn plc_area(&self) -> &[u8] {
        &self.plc
    }

    /// The PLC program save image written by b99.14 (manual 3.4).
    pub fn saved_plc_area(&self) -> &[u8] {
        &self.saved_plc
    }

    /// The program the PLC runs, None when the area holds no END (manual 3.8.1, 4.1).
    pub fn program(&self) -> Option<&Program> {
        self.program.as_ref()
    }

    /// Pr23 and Pr24 (manual 3.3).
    pub fn alarms(&self) -> Alarms {
        let n = &self.layout.named;
        Alarms {
            active: self.working.get(n.alarm.addr, n.alarm.size) as u8,
            last: self.working.get(n.last_alarm.addr, n.last_alarm.size) as u8,
        }
    }

    /// The serial line as last initialised, with whether it communicates now (manual 4.1);
    /// None when Pr26 or Pr27 held unusable values at the last initialisation.
    pub fn line(&self) -> Option<LineSettings> {
        self.line.map(|l| LineSettings {
            active: self.comm_active(),
            ..l
        })
    }

    /// Physical digital inputs as last set, bit i = input i (manual 3.8.1).
    pub fn digital_inputs(&self) -> u16 {
        self.inputs
    }

    /// Digital outputs as last written by a PLC scan, bit j = output j (manual 3.8.1).
    pub fn digital_outputs(&self) -> u16 {
        self.digital_outputs
    }
}

/// `dst = (src & mask) | (rest & !mask)`, byte by byte.
pub(super) fn masked_copy(dst: &mut Memory, src: &Memory, rest: &Memory, mask: &[u8; 256]) {
    for (addr, m) in (0..=u8::MAX).zip(mask.iter()) {
        let v = (src.get(addr, 1) as u8 & m) | (rest.get(addr, 1) as u8 & !m);
        dst.set(addr, 1, u32::from(v));
    }
}
