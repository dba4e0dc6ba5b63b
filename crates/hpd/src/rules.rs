//! The framing constants of manual 4.1, read from the spec's HPD protocol table.

/// The seven message types of manual 4.1, in CMD order of the manual's table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum MessageKind {
    /// CMD 1: drive response (data or short acknowledge).
    Response,
    /// CMD 2: read PLC instruction.
    ReadPlc,
    /// CMD 3: write PLC instruction.
    WritePlc,
    /// CMD 4: read parameter.
    ReadParam,
    /// CMD 5: write parameter.
    WriteParam,
    /// CMD 6: bit change.
    BitChange,
    /// CMD 7: broadcast to all drives.
    Broadcast,
}

impl MessageKind {
    /// All kinds.
    pub const ALL: [MessageKind; 7] = [
        MessageKind::Response,
        MessageKind::ReadPlc,
        MessageKind::WritePlc,
        MessageKind::ReadParam,
        MessageKind::WriteParam,
        MessageKind::BitChange,
        MessageKind::Broadcast,
    ];

    /// The name of the message type in the spec's table.
    pub fn spec_name(self) -> &'static str {
        match self {
            MessageKind::Response => "drive-response",
            MessageKind::ReadPlc => "read-plc",
            MessageKind::WritePlc => "write-plc",
            MessageKind::ReadParam => "read-parameter",
            MessageKind::WriteParam => "write-parameter",
            MessageKind::BitChange => "bit-change",
            MessageKind::Broadcast => "broadcast",
        }
    }

    fn index(self) -> usize {
        self as usize
    }
}

/// The spec's HPD tables lack something the codec needs.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum RulesError {
    /// The spec has no HPD protocol table.
    #[error("the spec has no HPD protocol table")]
    NoProtocol,
    /// A message type is missing from `protocol.message_types`.
    #[error("message type {name:?} missing from the spec's HPD message types")]
    MissingMessageType {
        /// The name looked for.
        name: &'static str,
    },
    /// A value in the frame table is unusable.
    #[error("frame table: {what}")]
    Frame {
        /// What is wrong.
        what: &'static str,
    },
}

/// Framing constants (manual 4.1): STX, stuffing, field ranges and CMD codes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FrameRules {
    /// Start of message.
    pub stx: u8,
    /// Byte sent after any field equal to STX.
    pub stuff: u8,
    /// Largest drive address.
    pub addr_max: u8,
    /// Bits of CMD+ADDR holding the address (the rest hold CMD).
    pub addr_bits: u32,
    /// Smallest LUN.
    pub lun_min: u8,
    /// Largest LUN.
    pub lun_max: u8,
    /// LUN of a bit-change message (mask + value).
    pub bit_change_lun: u8,
    /// CMD code of each message kind, indexed by `MessageKind as usize`.
    codes: [u8; 7],
    /// Message kind of each CMD code (CMD has at most 8 values: 3 bits).
    kinds: [Option<MessageKind>; 8],
    /// Mask of ADDR in CMD+ADDR.
    addr_mask: u8,
}

impl FrameRules {
    /// Reads the rules from the spec's HPD protocol table (manual 4.1).
    pub fn from_spec(spec: &drivespec_spec::Spec) -> Result<FrameRules, RulesError> {
        let protocol = spec
            .family(drivespec_spec::FamilyId::Hpd)
            .hpd()
            .ok_or(RulesError::NoProtocol)?;
        FrameRules::from_protocol(protocol)
    }

    /// Reads the rules from an HPD protocol table (manual 4.1).
    pub fn from_protocol(p: &drivespec_spec::hpd::Protocol) -> Result<FrameRules, RulesError> {
        let f = &p.frame;
        let mut codes = [0u8; 7];
        for (slot, kind) in codes.iter_mut().zip(MessageKind::ALL) {
            let name = kind.spec_name();
            let t = p.message_types.iter().find(|m| m.name == name);
            *slot = t.ok_or(RulesError::MissingMessageType { name })?.cmd;
        }
        let addr_bits = f.addr_mask.count_ones();
        if u32::from(f.addr_mask) != (1u32 << addr_bits) - 1 || u32::from(f.cmd_shift) != addr_bits
        {
            return Err(RulesError::Frame {
                what: "ADDR must fill the low bits below CMD",
            });
        }
        if f.stuff_after != f.stx {
            return Err(RulesError::Frame {
                what: "stuffing must follow the STX value",
            });
        }
        let [lun_min, lun_max] = f.lun_range;
        if lun_min == 0 || lun_max > 4 || lun_min > lun_max {
            return Err(RulesError::Frame {
                what: "LUN range must lie in 1..=4",
            });
        }
        Ok(FrameRules::new(
            f.stx,
            f.stuff_byte,
            addr_bits,
            f.addr_range[1],
            lun_min,
            lun_max,
            p.bit_change.lun,
            codes,
        ))
    }

    /// Builds the rules; `codes` gives the CMD code of each kind in `MessageKind::ALL` order.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        stx: u8,
        stuff: u8,
        addr_bits: u32,
        addr_max: u8,
        lun_min: u8,
        lun_max: u8,
        bit_change_lun: u8,
        codes: [u8; 7],
    ) -> FrameRules {
        let mut kinds = [None; 8];
        for kind in MessageKind::ALL {
            if let Some(slot) = codes
                .get(kind.index())
                .and_then(|c| kinds.get_mut(usize::from(*c)))
            {
                *slot = Some(kind);
            }
        }
        FrameRules {
            stx,
            stuff,
            addr_max,
            addr_bits,
            lun_min,
            lun_max,
            bit_change_lun,
            codes,
            kinds,
            addr_mask: u8::try_from((1u32 << addr_bits.min(8)) - 1).unwrap_or(u8::MAX),
        }
    }

    /// CMD code of a message kind.
    pub fn code(&self, kind: MessageKind) -> u8 {
        self.codes.get(kind.index()).copied().unwrap_or(0)
    }

    /// The message kind of a CMD code.
    pub fn kind(&self, cmd: u8) -> Option<MessageKind> {
        self.kinds.get(usize::from(cmd)).copied().flatten()
    }

    /// Splits CMD+ADDR into (CMD, ADDR).
    pub fn split(&self, cmd_addr: u8) -> (u8, u8) {
        (
            cmd_addr.checked_shr(self.addr_bits).unwrap_or(0),
            cmd_addr & self.addr_mask,
        )
    }

    /// Joins CMD and ADDR into one byte.
    pub fn join(&self, cmd: u8, addr: u8) -> u8 {
        cmd.checked_shl(self.addr_bits).unwrap_or(0) | (addr & self.addr_mask)
    }
}
