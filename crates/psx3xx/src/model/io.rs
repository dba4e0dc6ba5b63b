//! What goes into and comes out of a PSx3xx model drive besides the process images (manual
//! 3.1, 5.9, 5.10): ISDU answers, IO-Link communication events, jog keys, the run in
//! progress and trace events.

use crate::isdu::{Response, Value};
use drivespec_positioner::{CoreEvent, Micros};
use drivespec_spec::psx3xx::RunAction;
use serde::{Deserialize, Serialize};

/// A change of the IO-Link communication (manual 5.9, 5.10 table).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LinkEvent {
    /// The master is in OPERATE again; images and ISDU requests are processed (4.1).
    Connected,
    /// The communication stops: nothing from the master arrives, the jog keys count as "bus
    /// not connected" (5.10); the time-out of 5.9 follows ISDU 118 after the last message.
    Lost,
}

/// What one LED shows (manual 2.6; spec `[[protocol.led.state]]` patterns).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum LedLight {
    /// Dark (`off`, `dark`, `dark-250ms`).
    Off,
    /// Lit (`on`).
    On,
    /// Lit 90 % of the time, dark 10 % (`on-90-percent`, the IO-Link RUN LED).
    On90Percent,
}

impl LedLight {
    /// The spec's pattern name of the light (`off`, `on`, `on-90-percent`) (manual 2.6).
    pub fn pattern(self) -> &'static str {
        match self {
            LedLight::Off => "off",
            LedLight::On => "on",
            LedLight::On90Percent => "on-90-percent",
        }
    }
}

/// The three LEDs under the sealing plug (manual 2.6, 3.3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub struct Leds {
    /// Green IO-Link RUN LED (PSX-LED-001, PSX-LED-002).
    pub green: LedLight,
    /// Orange time-stamp LED (PSX-LED-003, PSX-LED-005, PSX-LED-006).
    pub orange: LedLight,
    /// Yellow motor-voltage LED (PSX-LED-004).
    pub yellow: LedLight,
}

/// The state of the two jog key inputs (manual 2.5.3, 5.10).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize)]
pub struct JogKeys {
    /// Pin 2 (forward) connected to +24 V (status bit 3).
    pub forward: bool,
    /// Pin 3 (reverse) connected to +24 V (status bit 2).
    pub reverse: bool,
}

impl JogKeys {
    /// No key pressed (5.10).
    pub const NONE: JogKeys = JogKeys {
        forward: false,
        reverse: false,
    };
    /// The forward key pressed (5.10).
    pub const FORWARD: JogKeys = JogKeys {
        forward: true,
        reverse: false,
    };
    /// The reverse key pressed (5.10).
    pub const REVERSE: JogKeys = JogKeys {
        forward: false,
        reverse: true,
    };
    /// Both keys pressed (5.10: cancels a jog).
    pub const BOTH: JogKeys = JogKeys {
        forward: true,
        reverse: true,
    };

    /// +1 forward, −1 reverse, 0 for none or both (5.10).
    pub fn dir(self) -> i8 {
        match (self.forward, self.reverse) {
            (true, false) => 1,
            (false, true) => -1,
            _ => 0,
        }
    }
}

/// What moves the drive now, as the manual names it (chapters 4, 5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(tag = "run", rename_all = "kebab-case")]
pub enum RunState {
    /// Standstill (4.1).
    Idle,
    /// A positioning run (4.2).
    Positioning {
        /// Target in steps.
        target: i64,
    },
    /// A readjustment after manual displacement (5.4).
    Readjust {
        /// Target in steps.
        target: i64,
    },
    /// The run to the safe position after a time-out (5.9 case 3).
    SafePosition {
        /// ISDU 138.
        target: i64,
    },
    /// The run to mid-range after ISDU 193 = -1 / -2 (3.1 ISDU 193).
    Centre {
        /// The middle of the range.
        target: i64,
    },
    /// A manual run by control bits 0/1 or format 0 codes 1/2 (4.4.3, 4.5.3).
    Manual {
        /// +1 larger values, −1 smaller values.
        dir: i8,
    },
    /// A single jog step of ISDU 135 steps (5.10).
    JogStep {
        /// +1 forward, −1 reverse.
        dir: i8,
    },
    /// A continuous jog after ISDU 163 (5.10).
    JogContinuous {
        /// +1 forward, −1 reverse.
        dir: i8,
    },
    /// The initial reference loop of control bit 7 (3.5).
    ReferenceLoop,
    /// Waiting for the brake to open before a run (5.12, 5.13).
    BrakeWait,
    /// Braking to a stop after a run ended (5.1).
    Stopping,
}

impl RunState {
    /// The vectors' name of the state (`none`, `positioning`, `manual-forward`, …).
    pub fn name(self) -> &'static str {
        match self {
            RunState::Idle | RunState::Stopping => "none",
            RunState::Positioning { .. } | RunState::Readjust { .. } => "positioning",
            RunState::SafePosition { .. } => "safe-position",
            RunState::Centre { .. } => "centre",
            RunState::Manual { dir } if dir > 0 => "manual-forward",
            RunState::Manual { .. } => "manual-reverse",
            RunState::JogStep { .. } => "jog-step",
            RunState::JogContinuous { .. } => "jog-continuous",
            RunState::ReferenceLoop => "reference-loop",
            RunState::BrakeWait => "brake-wait",
        }
    }
}

/// The answer to one ISDU request (manual 3.1; IEC 61131-9 A.5).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct IsduAnswer {
    /// When it was answered.
    pub at: Micros,
    /// ISDU index of the request.
    pub index: u16,
    /// Sub-index of the request.
    pub subindex: u8,
    /// The response: value octets, write acknowledged, or an ErrorType.
    pub response: Response,
    /// A write acknowledged but dropped by a guard entry (3.1 ISDU 66, 109, 111, 126).
    pub suppressed: bool,
}

/// Something the model did, for traces (manual chapters 3–5).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "event", rename_all = "kebab-case")]
pub enum Event {
    /// The positioning core's events (runs, refusals, power) (chapter 4).
    Core(CoreEvent),
    /// An ISDU entry was written (3.1).
    Written {
        /// ISDU index.
        index: u16,
        /// Sub-index.
        subindex: u8,
        /// Value written.
        value: Value,
    },
    /// A write was dropped by a guard entry (3.1).
    Suppressed {
        /// ISDU index of the dropped write.
        index: u16,
        /// The guard's parameter id.
        guard: String,
    },
    /// The parameters were saved to EEPROM (ISDU 193 = 1, ISDU 2 = 161, 5.5 comment 8).
    Saved,
    /// The working parameters were loaded from the delivery table or the EEPROM image.
    Restored {
        /// From the delivery table (true) or the saved image.
        delivery: bool,
    },
    /// The device restarted (ISDU 2 = 128 or a power cycle); the format in force (3.1 ISDU 116).
    Restarted {
        /// Process-data format now active.
        format: u8,
    },
    /// A valid time stamp is pending (4.4).
    StampPending {
        /// Control code.
        code: u8,
        /// Delay in µs.
        delay_us: u32,
    },
    /// A time stamp fired its control code (4.4).
    StampFired {
        /// Control code.
        code: u8,
    },
    /// The master time-out of 5.9 struck.
    Timeout {
        /// What the drive does (5.9).
        action: RunAction,
    },
    /// The IO-Link communication changed (5.9).
    Link(LinkEvent),
    /// The jog key inputs changed (5.10).
    Keys(JogKeys),
    /// A jog began (5.10).
    Jog {
        /// +1 forward, −1 reverse.
        dir: i8,
        /// Continuous (true) or a single step.
        continuous: bool,
    },
    /// The brake opened (true) or closed (false) (5.12, 5.13).
    Brake {
        /// Open.
        open: bool,
    },
    /// The initial reference loop started (true) or ended (false) (3.5 bit 7).
    ReferenceLoop {
        /// Started.
        started: bool,
    },
}
