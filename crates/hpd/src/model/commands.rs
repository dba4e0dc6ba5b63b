//! Command bits (manual 3.4): alarm reset, defaults, saves, line re-initialisation, and the
//! drive-maintained status the model keeps (b41.4).
//!
//! Commands run as soon as their bit is seen at 1, whoever set it (serial line, PLC program,
//! [`Drive::set_value`]). DECISION: a refused command is dropped: under the `self-clear`
//! reading its bit is cleared like an executed one, so it does not run later when the
//! condition comes true.

use super::drive::{masked_copy, Drive};
use super::layout::CommandKind;
use crate::line::Micros;
use crate::memory::Memory;
use std::sync::Arc;

impl Drive {
    /// Runs the commands whose bits were set, IDC broadcasts and status upkeep at `now`.
    pub(super) fn service(&mut self, now: Micros) {
        let layout = Arc::clone(&self.layout);
        let self_clear = layout.options.self_clear;
        for (i, cmd) in layout.commands.iter().enumerate() {
            let applies = cmd.modes.is_empty() || cmd.modes.contains(&self.mode());
            let on = applies && self.working.bit(cmd.bit);
            let seen = self.command_seen.get(i).copied().unwrap_or(false);
            // Latched reading: a command runs on the 0 → 1 change of its bit only.
            if on && !seen {
                self.execute(cmd.kind);
            }
            let still = applies && self.working.bit(cmd.bit);
            // HPD-CMD-SELF-CLEAR: the drive clears a command bit once it has been taken
            // (erratum option `command-self-clear`, HPD-ERRATUM-012).
            if still && self_clear {
                self.working.set_bit(cmd.bit, false);
            }
            if let Some(s) = self.command_seen.get_mut(i) {
                *s = still && !self_clear;
            }
        }
        self.service_idc(now);
        self.refresh_status();
        self.wake_motor();
    }

    /// Executes one command unless its conditions forbid it (manual 3.4).
    fn execute(&mut self, kind: CommandKind) {
        let layout = Arc::clone(&self.layout);
        let n = &layout.named;
        // HPD-CMD-001: commands are accepted only with b99.7 = 0 (HPD-ERRATUM-011 reading).
        if self.secured() {
            return;
        }
        let alarm = layout.alarm(self.alarms().active);
        let checksum_reset = alarm.is_some_and(|a| a.reset_refused);
        let checksum_save = alarm.is_some_and(|a| a.save_refused);
        match kind {
            CommandKind::Reinit => {
                // HPD-CMD-002: b42.3 needs b99.6 = 1.
                if self.working.bit(n.extended_menu) {
                    // HPD-BIT-42-3, HPD-PAR-038: Pr26 and Pr27 take effect.
                    self.init_line();
                }
            }
            CommandKind::AlarmReset => {
                // HPD-CMD-006: refused while a checksum alarm is active.
                if checksum_reset {
                    return;
                }
                // HPD-CMD-005, HPD-ALARM-003: clears Pr23 and Pr24. DECISION: the model's
                // alarms do not persist, so none comes back.
                self.set_alarms(0, 0);
            }
            CommandKind::ModeDefaults => {
                // HPD-CMD-007: executed only with b40.2 = 0.
                if self.working.bit(n.reserved_reference) {
                    return;
                }
                self.mode_defaults();
            }
            CommandKind::Defaults => {
                // HPD-CMD-009: executed only with the PLC stopped (b99.13 = 0).
                if layout.runtime.running(&self.working) {
                    return;
                }
                // HPD-CMD-010: a checksum alarm is cleared so that it can be reset.
                if checksum_reset {
                    self.set_alarms(0, 0);
                }
                self.defaults();
            }
            CommandKind::SavePlc => {
                // HPD-CMD-015: b99.14 ignores checksum alarms unless the `both` reading of
                // HPD-ERRATUM-013 is chosen.
                if layout.options.plc_save_checked && checksum_save {
                    return;
                }
                // HPD-CMD-011: the PLC program is stored.
                self.saved_plc.clone_from(&self.plc);
            }
            CommandKind::SaveParams => {
                // HPD-CMD-013: refused while a checksum alarm is active.
                if checksum_save {
                    return;
                }
                // HPD-CMD-012: all parameters are stored.
                self.save_parameters();
            }
            CommandKind::Position(kind) => self.position_command(kind),
            // Commands that need what the model has not (analogue input, current sensors):
            // taken without effect.
            CommandKind::Other => {}
        }
    }

    /// b99.12 (HPD-CMD-008, HPD-PLC-002): every writable parameter to its delivery value, the
    /// operating-mode values cancelled, and the appendix G program loaded.
    fn defaults(&mut self) {
        let layout = Arc::clone(&self.layout);
        let mode = self.mode();
        for (index, p) in layout.params.iter().enumerate() {
            if !p.writable {
                continue;
            }
            // DECISION: "cancels the values used by the operating modes" clears the
            // mode-dependent parameters that have no delivery value of their own; parameters
            // without a delivery value (Pr1, timers) keep theirs.
            let value = match p.default {
                Some(d) => d as u32,
                None if !p.modes.is_empty() => 0,
                None => continue,
            };
            let value = if p.is_bits {
                let (readonly, _) = layout.fixed_bits(index, mode);
                let old = self.working.get(p.slot.addr, p.slot.size);
                (value & !readonly) | (old & readonly)
            } else {
                value
            };
            // HPD-BIT-40-14-DEFAULT: this includes b40.14 = 0, Pr26 and Pr27.
            self.working.set(p.slot.addr, p.slot.size, value);
        }
        self.plc.clone_from(&layout.default_program);
        self.recache_program();
    }

    /// b99.11 (HPD-CMD-007, HPD-MODE-005): the parameters with a default in the operating
    /// mode of Pr31 take it; the others keep their values.
    fn mode_defaults(&mut self) {
        let layout = Arc::clone(&self.layout);
        let mode = self.mode();
        for p in layout.params.iter().filter(|p| p.writable) {
            if let Some(d) = p.mode(mode).and_then(|m| m.default) {
                self.working.set(p.slot.addr, p.slot.size, d as u32);
            }
        }
    }

    /// b99.15 (HPD-CMD-012, HPD-PAR-018): the saved parameters to the save image; command
    /// bits, power-up bits and drive-owned bits are not stored.
    pub(super) fn save_parameters(&mut self) {
        let mut saved = Memory::default();
        masked_copy(
            &mut saved,
            &self.working,
            &Memory::default(),
            &self.layout.saved_mask,
        );
        self.saved = saved;
    }

    /// Status the model keeps: HPD-BIT-41-4, drive healthy while no alarm is active (the DC
    /// bus is taken as ready); HPD-BIT-41-5, the hardware enable input as last read;
    /// HPD-BIT-41-12, the drive enabled by the hardware enable and b40.9 with no alarm.
    pub(super) fn refresh_status(&mut self) {
        let named = &self.layout.named;
        let healthy = self.alarms().active == 0;
        let hardware = self.inputs & named.enable_input != 0;
        let enabled = hardware && healthy && self.working.bit(named.software_enable);
        for (b, value) in [
            (named.healthy, healthy),
            (named.hardware_enable, hardware),
            (named.drive_enabled, enabled),
        ] {
            if let Some(b) = b {
                self.working.set_bit(b, value);
            }
        }
        self.refresh_motor_status();
    }
}
