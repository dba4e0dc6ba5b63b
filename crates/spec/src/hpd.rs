//! Protocol tables of `spec/hpd/protocol.toml`: the HPD serial protocol (manual 2.12,
//! chapter 4), the pico-PLC (3.8, 4.1 instruction coding, appendices F and G), digital I/O
//! and the alarm codes (3.3). Codecs and device models read every constant from here.

use serde::{Deserialize, Serialize};

/// The `[protocol]` table (manual chapter 4, 3.8, appendices F and G).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Protocol {
    /// Manual chapter the tables come from.
    pub source: String,
    /// Frame layout, stuffing and checksum (4.1).
    pub frame: Frame,
    /// Character format on the line (4.1).
    pub character: CharacterFormat,
    /// The seven message types, by CMD code (4.1 table).
    pub message_types: Vec<MessageType>,
    /// Rules of the bit-change message CMD 6 (4.1).
    pub bit_change: BitChange,
    /// Pr26 codes: baud rate and time-out (chapter 4 table).
    pub baud_rates: Vec<BaudRate>,
    /// Parameters and order of serial-line set-up (4.1, 3.9).
    pub serial_setup: SerialSetup,
    /// Inter-drive communication, Pr26 = 10 (3.8.2 example 10).
    pub idc: Idc,
    /// Command bits and the parameters the drive's commands act on (3.3, 3.4).
    pub commands: Commands,
    /// Alarm codes shown in Pr23/Pr24 (3.3 table).
    pub alarms: Vec<Alarm>,
    /// The pico-PLC (3.8.1, 4.1).
    pub plc: Plc,
    /// Digital inputs and outputs and their bits (3.8.1, 3.2, appendix C).
    pub io: Io,
    /// Software time slots of the firmware (appendix F).
    pub task_slots: Vec<TaskSlot>,
    /// The default pico-PLC program, one line per instruction (appendix G).
    pub default_program: Vec<ProgramLine>,
}

impl Protocol {
    /// The message type with CMD code `cmd` (4.1 table).
    pub fn message_type(&self, cmd: u8) -> Option<&MessageType> {
        self.message_types.iter().find(|m| m.cmd == cmd)
    }

    /// The Pr26 entry for `code` (chapter 4 table).
    pub fn baud_rate(&self, code: u8) -> Option<&BaudRate> {
        self.baud_rates.iter().find(|b| b.code == code)
    }

    /// The alarm with `code` (3.3 table).
    pub fn alarm(&self, code: u8) -> Option<&Alarm> {
        self.alarms.iter().find(|a| a.code == code)
    }
}

/// One field of a serial message (4.1 "message structure").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Field {
    /// Start of message, the value `Frame::stx` (4.1).
    Stx,
    /// Command in bits 5–7 and drive address in bits 0–4 (4.1).
    CmdAddr,
    /// Number of data bytes, 1…4 (4.1).
    Lun,
    /// Parameter serial address or PLC byte address (4.1, 4.2).
    Par,
    /// LUN data bytes, least significant first (4.1 cases 2, 4).
    Data,
    /// Bit-change mask byte: 0 at the bits to change (4.1 CMD 6).
    Mask,
    /// Bit-change value byte: 1 at the bits to set (4.1 CMD 6).
    Bits,
    /// Checksum: sum modulo 256 of all fields except STX (4.1).
    Chk,
}

/// Byte order of multi-byte data (4.1 cases 2 and 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ByteOrder {
    /// Least significant byte first.
    LittleEndian,
    /// Most significant byte first.
    BigEndian,
}

/// Frame layout, stuffing and checksum (4.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Frame {
    /// Manual section.
    pub source: String,
    /// STX, the start-of-message byte (4.1: $7E).
    pub stx: u8,
    /// A field byte after STX equal to this value is followed by `stuff_byte` (4.1).
    pub stuff_after: u8,
    /// The byte inserted after `stuff_after` (4.1: $00).
    pub stuff_byte: u8,
    /// Stuffing also applies to the checksum byte (4.1 case 1).
    pub stuff_checksum: bool,
    /// Stuffing bytes are not counted in LUN (4.1 LUN; see erratum on LUN).
    pub lun_excludes_stuffing: bool,
    /// Checksum modulus (4.1: 256).
    pub checksum_modulus: u16,
    /// The checksum covers all fields except STX (4.1).
    pub checksum_excludes_stx: bool,
    /// Bit position of CMD in the CMD+ADDR byte (4.1: bits 5–7).
    pub cmd_shift: u8,
    /// Mask of CMD in the CMD+ADDR byte (4.1: 0xE0).
    pub cmd_mask: u8,
    /// Mask of ADDR in the CMD+ADDR byte (4.1: bits 0–4).
    pub addr_mask: u8,
    /// Inclusive drive address range (4.1: 0…31).
    pub addr_range: [u8; 2],
    /// Inclusive LUN range (4.1: 1…4).
    pub lun_range: [u8; 2],
    /// CMD+ADDR is never zero (4.1).
    pub cmd_addr_nonzero: bool,
    /// Byte order of multi-byte values (4.1 cases 2, 4).
    pub byte_order: ByteOrder,
    /// Field order of a full message (4.1).
    pub fields: Vec<Field>,
    /// Field order of the short acknowledge `[STX][001+ADDR]` (4.1 CMD 1).
    pub ack_fields: Vec<Field>,
    /// CMD code of drive answers (4.1: 1).
    pub answer_cmd: u8,
    /// CMD code of the broadcast write (4.1: 7).
    pub broadcast_cmd: u8,
    /// ADDR required with the broadcast CMD (4.1: 0).
    pub broadcast_addr: u8,
    /// Most drives on one line (chapter 4: 32).
    pub max_drives: u8,
}

impl Frame {
    /// The CMD+ADDR byte for `cmd` and `addr` (4.1).
    pub fn cmd_addr(&self, cmd: u8, addr: u8) -> u8 {
        ((cmd << self.cmd_shift) & self.cmd_mask) | (addr & self.addr_mask)
    }

    /// Splits a CMD+ADDR byte into (cmd, addr) (4.1).
    pub fn split_cmd_addr(&self, byte: u8) -> (u8, u8) {
        (
            (byte & self.cmd_mask) >> self.cmd_shift,
            byte & self.addr_mask,
        )
    }
}

/// Parity of the character format (4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Parity {
    /// Even parity.
    Even,
    /// Odd parity.
    Odd,
    /// No parity bit.
    None,
}

/// Asynchronous character format (4.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CharacterFormat {
    /// Manual section.
    pub source: String,
    /// Start bits (4.1: 1).
    pub start_bits: u8,
    /// Data bits (4.1: 8).
    pub data_bits: u8,
    /// Parity (4.1: even).
    pub parity: Parity,
    /// Stop bits (4.1: 1).
    pub stop_bits: u8,
    /// Bits on the line per byte (4.1: 11).
    pub bits_per_char: u8,
}

/// Who sends a message type (4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Sender {
    /// The master (PC, PLC, keypad module).
    Master,
    /// A drive, only after being asked.
    Drive,
}

/// What a message addresses (4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Area {
    /// Parameters by serial address (4.2).
    Parameter,
    /// PLC program bytes 0x00…0x7F (4.1).
    Plc,
    /// Whatever the request addressed (answers).
    Any,
}

/// What the drive sends back (4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Answer {
    /// No answer (drive answers; broadcasts; any erroneous message).
    None,
    /// CMD 1 with LUN, PAR, data and checksum.
    Data,
    /// Short acknowledge `[STX][001+ADDR]`.
    Ack,
}

/// One message type of the 4.1 table.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MessageType {
    /// CMD code, bits 5–7 of CMD+ADDR.
    pub cmd: u8,
    /// Kebab-case name (`read-parameter`, …).
    pub name: String,
    /// Who sends it.
    pub sender: Sender,
    /// What it addresses.
    pub area: Area,
    /// The drive's answer to a correct message.
    pub answer: Answer,
    /// Field order.
    pub fields: Vec<Field>,
    /// LUN fixed by the type (bit change: 2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lun: Option<u8>,
    /// ADDR fixed by the type (broadcast: 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub addr: Option<u8>,
    /// Manual section.
    pub source: String,
    /// One line.
    pub description: String,
}

impl MessageType {
    /// Whether the drive answers a correct message of this type (4.1 notes).
    pub fn answered(&self) -> bool {
        self.answer != Answer::None
    }
}

/// Rules of the bit-change message (4.1 CMD 6).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BitChange {
    /// Manual section.
    pub source: String,
    /// CMD code (6).
    pub cmd: u8,
    /// LUN is always this (2: mask and value byte).
    pub lun: u8,
    /// Mask byte value at a bit to change (0); all other mask bits are 1.
    pub mask_change_value: u8,
    /// Value byte: 1 at bits to set, 0 elsewhere.
    pub bits_set_value: u8,
    /// Bits of a word parameter reached at PAR = address (0…7).
    pub low_bits: [u8; 2],
    /// Bits of a word parameter reached at PAR = address + `high_byte_offset` (8…15).
    pub high_bits: [u8; 2],
    /// PAR offset for bits 8…15 (1).
    pub high_byte_offset: u8,
}

impl BitChange {
    /// (PAR, mask, value) to set bit `bit` of the parameter at `address` to `value` (4.1).
    pub fn encode(&self, address: u8, bit: u8, value: bool) -> Option<(u8, u8, u8)> {
        let (par, pos) = if (self.low_bits[0]..=self.low_bits[1]).contains(&bit) {
            (address, bit.checked_sub(self.low_bits[0])?)
        } else if (self.high_bits[0]..=self.high_bits[1]).contains(&bit) {
            (
                address.checked_add(self.high_byte_offset)?,
                bit.checked_sub(self.high_bits[0])?,
            )
        } else {
            return None;
        };
        let one = 1u8.checked_shl(u32::from(pos))?;
        let mask = if self.mask_change_value == 0 {
            !one
        } else {
            one
        };
        let bits = if value == (self.bits_set_value == 1) {
            one
        } else {
            0
        };
        Some((par, mask, bits))
    }
}

/// Kind of a Pr26 code (chapter 4 table notes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BaudMode {
    /// Plain master–slave operation.
    Standard,
    /// Answers delayed by `answer_delay_ms` for PLC masters (code 4).
    Delayed,
    /// Inter-drive communication (code 10, example 10).
    Idc,
}

/// One Pr26 code (chapter 4 table).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaudRate {
    /// Pr26 value.
    pub code: u8,
    /// Bits per second.
    pub bps: u32,
    /// Time from STX within which a message must be complete (ms).
    pub timeout_ms: u32,
    /// Kind of operation.
    pub mode: BaudMode,
    /// Delay before the drive answers (ms), code 4 only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub answer_delay_ms: Option<u32>,
    /// Manual section.
    pub source: String,
    /// One line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

/// A parameter or bit set to a value (3.9, 4.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Assignment {
    /// Parameter id (`Pr26`) or bit (`b40.14`).
    pub target: String,
    /// Raw value (a command bit: 1).
    pub value: i64,
}

/// Serial-line set-up (4.1 "serial line initialisation", 3.4 b42.3, 3.9).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SerialSetup {
    /// Manual section.
    pub source: String,
    /// Baud-rate code parameter (Pr26).
    pub baud_param: String,
    /// Serial address parameter (Pr27).
    pub address_param: String,
    /// Serial communication enable bit (b40.14, default 0 = disabled).
    pub enable_bit: String,
    /// Re-initialise command after a Pr26 change (b42.3).
    pub reinit_bit: String,
    /// Save command (b99.15).
    pub save_bit: String,
    /// The set-up steps in the required order (4.1).
    pub steps: Vec<Assignment>,
    /// Settings for the Pcbrush PC program (3.9).
    pub pcbrush: Vec<Assignment>,
}

/// Command bits and the parameters the drive's commands act on (3.3, 3.4).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Commands {
    /// Manual section.
    pub source: String,
    /// Alarm reset command (3.4 b99.10).
    pub alarm_reset_bit: String,
    /// Operating-mode defaults command (3.4 b99.11).
    pub mode_defaults_bit: String,
    /// Must be 0 for the operating-mode defaults command (3.4: b40.2 = 0).
    pub mode_defaults_requires_clear: String,
    /// Security: locks parameter changes (3.3 b99.7).
    pub security_bit: String,
    /// Extended menu, needed by the re-initialisation command (3.3 b99.6, 3.4 b42.3).
    pub extended_menu_bit: String,
    /// Active alarm code (3.3 Pr23).
    pub alarm_param: String,
    /// Last alarm code (3.3 Pr24).
    pub last_alarm_param: String,
    /// Operating mode (3.3 Pr31, 3.6).
    pub mode_param: String,
}

/// Inter-drive communication, Pr26 = 10 (3.8.2 example 10).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Idc {
    /// Manual section.
    pub source: String,
    /// Pr26 code that enables it (10).
    pub baud_code: u8,
    /// Bit that starts one broadcast (b99.5).
    pub trigger_bit: String,
    /// Parameter holding the serial address (PAR) written in the other drives (Pr80).
    pub address_param: String,
    /// Parameter whose value is broadcast (Pr81).
    pub value_param: String,
    /// CMD code used (7, broadcast).
    pub cmd: u8,
    /// Data bytes sent (2, one word).
    pub lun: u8,
    /// A drive in IDC mode receiving a broadcast sets `trigger_bit` itself.
    pub receiver_sets_trigger: bool,
}

/// One alarm code (3.3 table, 3.4 b99.10/b99.15).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Alarm {
    /// Value of Pr23 / Pr24.
    pub code: u8,
    /// Kebab-case name.
    pub name: String,
    /// One line.
    pub meaning: String,
    /// Saving parameters (b99.15) is refused while it is active.
    pub save_refused: bool,
    /// The alarm reset command (b99.10) is refused while it is active.
    pub reset_refused: bool,
    /// Manual section.
    pub source: String,
}

/// One step of a PLC scan, in order (3.8.1 operational description).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ScanStep {
    /// Copy the digital inputs into b90.0…7.
    ReadInputs,
    /// Update Pr92/Pr93 and b99.0/b99.1.
    UpdateTimers,
    /// Run the user program once.
    RunProgram,
    /// Copy b91.0…6 to the digital outputs.
    WriteOutputs,
}

/// Bit layout of PLC instructions (4.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Encoding {
    /// Manual section.
    pub source: String,
    /// Mask of the instruction code in byte 0 (b0…b3).
    pub code_mask: u8,
    /// Shift of `y` in byte 0 for bit instructions (b4…b7).
    pub y_shift: u8,
    /// Mask of `y` in byte 0 (after shifting back: 0x0F).
    pub y_mask: u8,
    /// Byte holding Pa of a bit instruction (1).
    pub bit_param_byte: u8,
    /// Bytes holding Pa, Pb, Pc of an arithmetic instruction (1, 2, 3).
    pub arith_param_bytes: [u8; 3],
    /// Byte holding y of a FIN instruction (1).
    pub fin_y_byte: u8,
    /// Operand bytes hold parameter numbers (90 = 0x5A), not serial addresses.
    pub operand_is_parameter_number: bool,
    /// Value written into bits and bytes the manual leaves unused.
    pub unused_fill: u8,
}

/// Operand form of an instruction (3.8.1, 4.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OperandForm {
    /// `Pa.y`: y in the high nibble of byte 0, Pa in byte 1.
    Bit,
    /// `Pa,Pb,Pc` in bytes 1, 2, 3.
    Arith,
    /// `y,n`: n (0…3) in b4 (parameter select) and b5 (invert) of byte 0, y in byte 1.
    Fin,
    /// No operand (END; byte 1 unused).
    None,
}

/// What an instruction does (3.8.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Operation {
    /// Stack = bit (inverted when `invert`).
    Load,
    /// Bit = stack (inverted when `invert`).
    Out,
    /// Stack = stack AND bit (inverted bit when `invert`).
    And,
    /// Stack = stack OR bit (inverted bit when `invert`).
    Or,
    /// Bit = 1 when stack is 1.
    Set,
    /// Bit = 0 when stack is 1.
    Reset,
    /// Pc = Pa + Pb when stack is 1.
    Add,
    /// Pc = Pa − Pb when stack is 1.
    Sub,
    /// Pc = Pa · Pb when stack is 1.
    Mul,
    /// Pc = Pa / Pb when stack is 1.
    Div,
    /// Fast copy of a digital input into Pb40 or Pb70 every 512 µs.
    FastInput,
    /// Program end.
    End,
}

/// One PLC instruction (3.8.1 list, 4.1 coding table).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Instruction {
    /// Mnemonic (`LD`, `ORN`, …).
    pub mnemonic: String,
    /// Other spellings found in the manual (`RST` for RES).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub aliases: Vec<String>,
    /// Code in b0…b3 of byte 0.
    pub code: u8,
    /// Length in bytes (2 or 4).
    pub length: u8,
    /// Operand form.
    pub operands: OperandForm,
    /// Effect.
    pub operation: Operation,
    /// Uses the inverted operand bit (LDN, OUTN, ANDN, ORN).
    pub invert: bool,
    /// Executes only when the stack bit is 1 (SET, RES, ADD…DIV).
    pub needs_stack: bool,
    /// Manual section.
    pub source: String,
    /// One line.
    pub description: String,
}

/// One FIN slot (3.8.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FinSlot {
    /// Position among the first instructions (1…3).
    pub index: u8,
    /// Program byte address of that instruction (0, 2, 4).
    pub address: u8,
    /// Digital input copied (1…3).
    pub input: u8,
    /// Bit that disables this FIN when 1 (b94.5…b94.7).
    pub disable_bit: String,
}

/// FIN fast-input rules (3.8.1, 4.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FastInputs {
    /// Manual section.
    pub source: String,
    /// Copy period (µs).
    pub period_us: u32,
    /// Most FIN instructions honoured (3).
    pub max_count: u8,
    /// Highest program byte address of an honoured FIN (5).
    pub last_address: u8,
    /// Bit of byte 0 selecting the target parameter (b4).
    pub select_bit: u8,
    /// Bit of byte 0 inverting the input (b5).
    pub invert_bit: u8,
    /// Target parameters by select value (0 → Pb40, 1 → Pb70).
    pub targets: Vec<String>,
    /// The three slots.
    pub slots: Vec<FinSlot>,
    /// A FIN after address `last_address` or after any other instruction is a NOP.
    pub late_is_nop: bool,
}

/// One PLC timer (3.8.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Timer {
    /// 1 or 2.
    pub index: u8,
    /// Counter parameter, in scans (Pr92, Pr93).
    pub param: String,
    /// Status bit: 1 when the counter is 0 (b99.0, b99.1).
    pub status_bit: String,
    /// Decrement per scan while non-zero.
    pub decrement: u8,
    /// Time base of one count (µs): the scan time.
    pub base_us: u32,
    /// Manual section.
    pub source: String,
}

/// How the high word of a double-word operand is found (3.8.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum HighWord {
    /// The word at the next serial address (4.2 table).
    NextAddress,
}

/// Arithmetic rules of ADD/SUB/MUL/DIV (3.8.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Arithmetic {
    /// Manual section.
    pub source: String,
    /// Executed only when the stack bit is 1.
    pub requires_stack: bool,
    /// Operands are signed 16-bit words unless double word applies.
    pub word_signed: bool,
    /// Bit forcing the next executed operation to double word (b94.0).
    pub dword_force_bit: String,
    /// `dword_force_bit` is reset by the drive after that operation.
    pub dword_force_auto_reset: bool,
    /// Operands always treated as double words (Pr60…Pr69).
    pub dword_params: Vec<String>,
    /// Where the high word of a double word is.
    pub high_word: HighWord,
    /// Double-word DIV: quotient in the low word, remainder in the high word.
    pub div_remainder_in_high_word: bool,
    /// Set to 1 when the result is negative, else 0 (b99.2).
    pub negative_bit: String,
    /// Zero/non-zero flag of the result (b99.3).
    pub zero_bit: String,
    /// Erratum option deciding whether `zero_bit` = 1 means zero or non-zero.
    pub zero_bit_option: String,
    /// Byte parameters that must not be arithmetic operands.
    pub forbidden_params: Vec<String>,
    /// A result written to a constant (Pr71…Pr79) only sets the flags.
    pub constant_result_discarded: bool,
    /// Runs of parameters with successive serial addresses ([first, last]).
    pub successive: Vec<[String; 2]>,
}

/// One PLC constant (3.8.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Constant {
    /// Parameter id (Pr71…Pr79).
    pub param: String,
    /// Its fixed value (double word).
    pub value: i64,
}

/// Text form of PLC listings (3.8.1, appendix G).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ListingSyntax {
    /// Manual section.
    pub source: String,
    /// Between Pa and y (`90.1`).
    pub bit_separator: String,
    /// Between arithmetic and FIN operands in the canonical form (`92,78,92`).
    pub operand_separator: String,
    /// Separators a reader must also accept between arithmetic operands.
    pub accepted_separators: Vec<String>,
    /// Parameter numbers may carry leading zeros (`05`).
    pub leading_zeros: bool,
}

/// The pico-PLC (3.8.1, 4.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plc {
    /// Manual section.
    pub source: String,
    /// Program area size in bytes (128).
    pub area_bytes: u16,
    /// First program byte address (0x00).
    pub first_address: u8,
    /// Last program byte address (0x7F).
    pub last_address: u8,
    /// Most instructions, END included (64; arithmetic counts as two).
    pub max_instructions: u8,
    /// Stack depth in bits (1).
    pub stack_depth: u8,
    /// Scan period (µs): 6144.
    pub scan_us: u32,
    /// Order of the steps of one scan.
    pub scan_order: Vec<ScanStep>,
    /// PLC run bit: 1 runs, 0 stops and allows editing (b99.13).
    pub run_bit: String,
    /// Save-program command (b99.14).
    pub save_bit: String,
    /// Default-values command that also loads appendix G (b99.12).
    pub default_bit: String,
    /// Bit layout.
    pub encoding: Encoding,
    /// Listing text form.
    pub listing: ListingSyntax,
    /// The 16 instructions.
    pub instructions: Vec<Instruction>,
    /// FIN rules.
    pub fast_inputs: FastInputs,
    /// The two timers.
    pub timers: Vec<Timer>,
    /// Arithmetic rules.
    pub arithmetic: Arithmetic,
    /// Constants Pr71…Pr79.
    pub constants: Vec<Constant>,
    /// Free saved words for the user (Pr80…Pr89).
    pub free_words: Vec<String>,
}

impl Plc {
    /// The instruction with code `code` (4.1 table).
    pub fn instruction(&self, code: u8) -> Option<&Instruction> {
        self.instructions.iter().find(|i| i.code == code)
    }

    /// The instruction with mnemonic or alias `name`, case-insensitive (3.8.1).
    pub fn by_mnemonic(&self, name: &str) -> Option<&Instruction> {
        self.instructions.iter().find(|i| {
            i.mnemonic.eq_ignore_ascii_case(name)
                || i.aliases.iter().any(|a| a.eq_ignore_ascii_case(name))
        })
    }

    /// The value of constant `param` (3.8.1).
    pub fn constant(&self, param: &str) -> Option<i64> {
        self.constants
            .iter()
            .find(|c| c.param == param)
            .map(|c| c.value)
    }
}

/// One digital input or output (3.2 terminal tables, 3.8.1, appendix C).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IoPoint {
    /// Input or output number.
    pub index: u8,
    /// Its bit (`b90.1`, `b91.6`).
    pub bit: String,
    /// Terminal(s) (`X3-12`, `X2-17/18`).
    pub terminal: String,
    /// Electrical kind (`24V`, `pnp`, `relay`).
    pub kind: String,
    /// Function under the default program or hardware (appendix G, 3.2).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub function: Option<String>,
    /// Manual section.
    pub source: String,
}

/// A run of bits reserved for the PLC (3.8.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UserBits {
    /// Parameter (Pb90, Pb91).
    pub param: String,
    /// First bit.
    pub first_bit: u8,
    /// Last bit.
    pub last_bit: u8,
    /// Kept by the save command.
    pub saved: bool,
    /// Value after power-up when not saved.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub power_up: Option<u8>,
    /// Manual section.
    pub source: String,
}

/// Digital I/O (3.8.1, 3.2, 4.2, appendix C).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Io {
    /// Manual section.
    pub source: String,
    /// Parameter holding the inputs (Pb90).
    pub input_param: String,
    /// Parameter holding the outputs (Pb91).
    pub output_param: String,
    /// Index of the hardware enable input (3.8.1 "b90.0 = drive enable", 3.2 X3-11).
    pub enable_input: u8,
    /// The software enable bit: with it 0 the drive cannot be started (3.3 b40.9).
    pub software_enable_bit: String,
    /// The digital inputs, b90.0…7.
    pub inputs: Vec<IoPoint>,
    /// The digital outputs, b91.0…6.
    pub outputs: Vec<IoPoint>,
    /// Bits free for the PLC.
    pub user_bits: Vec<UserBits>,
}

/// One firmware time slot (appendix F).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TaskSlot {
    /// Period (µs).
    pub period_us: u32,
    /// Tasks run in it.
    pub tasks: Vec<String>,
    /// Manual section.
    pub source: String,
}

/// One line of the default PLC program (appendix G).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProgramLine {
    /// Program byte address.
    pub address: u8,
    /// Canonical listing line (`LD 90.1`, `ADD 92,78,92`).
    pub listing: String,
    /// What the block does (first line of a block only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub comment: Option<String>,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bc() -> BitChange {
        BitChange {
            source: String::new(),
            cmd: 6,
            lun: 2,
            mask_change_value: 0,
            bits_set_value: 1,
            low_bits: [0, 7],
            high_bits: [8, 15],
            high_byte_offset: 1,
        }
    }

    #[test]
    fn bit_change_cases_5_and_6() {
        assert_eq!(bc().encode(0x92, 14, true), Some((0x93, 0xBF, 0x40)));
        assert_eq!(bc().encode(0x5C, 9, false), Some((0x5D, 0xFD, 0x00)));
        assert_eq!(bc().encode(0x5C, 16, false), None);
    }
}
