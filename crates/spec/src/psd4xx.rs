//! Protocol tables of `spec/psd4xx/protocol.toml` (PSD4xx PROFINET bus description,
//! chapters 2, 3.1, 3.2, 3.5, 3.8, 3.9 and 4).
//!
//! Everything a PSD4xx codec or reference model needs beyond the parameter table lives
//! here: the process-data modules, the PKW channel, acyclic records, output behaviour,
//! LEDs, device naming and the numeric constants of the positioning functions. Parameters
//! are referred to by their spec id (`"44"`), never by a second hand-typed table.

use serde::{Deserialize, Serialize};

/// The `[protocol]` table (whole bus description, chapters 2–4).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Protocol {
    /// Manual chapters the tables come from.
    pub source: String,
    /// Byte order of multi-byte values on the wire (3.5; not stated, PROFINET order assumed,
    /// see erratum PSD-ERRATUM-050). A setting: fields marked `inverted` use the other order.
    pub byte_order: ByteOrder,
    /// Cyclic process data: output and input modules (3.2.1, 3.5).
    pub process_data: ProcessData,
    /// The PKW parameter channel inside the process data (3.8).
    pub pkw: Pkw,
    /// Acyclic record read and write (3.2.2).
    pub record: RecordAccess,
    /// What happens to the controller's outputs (control word, target) in special states (3.9).
    #[serde(rename = "output_behaviour")]
    pub output_behaviour: Vec<OutputBehaviour>,
    /// Status LEDs and the meaning of their patterns (3.1).
    #[serde(rename = "led")]
    pub leds: Vec<Led>,
    /// How the PROFINET device name is built (2.1).
    pub device_name: DeviceName,
    /// PROFINET identity: vendor and device ID, slots and idents, I&M0 (2.1, 3.2.1).
    pub profinet: PnIdentity,
    /// Generating the delivery state with the address switches (2.3).
    pub delivery_switch: DeliverySwitch,
    /// Numeric constants of the positioning functions (chapter 4).
    pub positioning: Positioning,
    /// Back-driving ("run in reverse") limits per model (4.11).
    pub reverse: Reverse,
}

/// Order of the bytes of a multi-byte value (3.5 notice "UseAsBits").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ByteOrder {
    /// Most significant byte first (PROFINET/Motorola order).
    BigEndian,
    /// Least significant byte first.
    LittleEndian,
}

impl ByteOrder {
    /// The other order (3.5: control and status word are inverted).
    pub fn flipped(self) -> ByteOrder {
        match self {
            ByteOrder::BigEndian => ByteOrder::LittleEndian,
            ByteOrder::LittleEndian => ByteOrder::BigEndian,
        }
    }
}

/// Cyclic process data of the IO device (3.2.1, 3.5).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessData {
    /// Manual section.
    pub source: String,
    /// Only PROFINET RT is supported although the GSD file lists IRT (3.2 notice).
    pub rt_only: bool,
    /// The module assignment is fixed and cannot be modified (3.5.1/3.5.2 notice).
    pub fixed_assignment: bool,
    /// Output module: controller → drive, 14 bytes (3.5.1).
    pub output: Module,
    /// Input module: drive → controller, 16 bytes (3.5.2).
    pub input: Module,
}

/// One process-data module as a list of fields (3.5.1, 3.5.2).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Module {
    /// Manual section.
    pub source: String,
    /// Total length in bytes.
    pub length: usize,
    /// Fields in offset order.
    #[serde(rename = "field")]
    pub fields: Vec<Field>,
}

impl Module {
    /// A field by its `name` (`"control"`, `"pwe"` …).
    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.name == name)
    }
}

/// One field of a module or of the PKW block (3.5, 3.8 "PKW format").
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Field {
    /// Short kebab-case key (`pke`, `ind`, `pwe`, `control`, `target`, `status`, `speed`, `actual`).
    pub name: String,
    /// The manual's designation.
    pub label: String,
    /// Offset of the first byte in the module.
    pub offset: usize,
    /// Length in bytes.
    pub length: usize,
    /// The corresponding parameter id (3.5 "Corresponding parameter number").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub param: Option<String>,
    /// Two's complement value.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub signed: bool,
    /// Byte order is the opposite of the protocol's `byte_order` (3.5 notice "UseAsBits").
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub inverted: bool,
    /// Manual section.
    pub source: String,
}

impl Field {
    /// The byte order of this field given the protocol's order (3.5 notice).
    pub fn byte_order(&self, protocol: ByteOrder) -> ByteOrder {
        if self.inverted {
            protocol.flipped()
        } else {
            protocol
        }
    }

    /// The byte range of the field in its module.
    pub fn span(&self) -> std::ops::Range<usize> {
        self.offset..self.offset.saturating_add(self.length)
    }
}

/// The PKW parameter channel (3.8).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pkw {
    /// Manual section.
    pub source: String,
    /// Length of the PKW block in bytes (8).
    pub length: usize,
    /// PKE, IND and PWE with offsets inside the PKW block (3.8 "PKW format").
    #[serde(rename = "field")]
    pub fields: Vec<Field>,
    /// Bit fields of the PKE word: AK, SPM, PNU (3.8 "Parameter code (PKE) format").
    #[serde(rename = "pke_bits")]
    pub pke_bits: Vec<BitRange>,
    /// Where a 16-bit value sits inside the 32-bit PWE (erratum PSD-ERRATUM-053).
    pub word_position: WordPosition,
    /// What the unused high word of PWE holds for 16-bit values (erratum PSD-ERRATUM-053).
    pub word_fill: WordFill,
    /// How the array subindex is carried in the 16-bit IND (erratum PSD-ERRATUM-054).
    pub ind_layout: IndLayout,
    /// Number of commands the drive processes at a time (3.8: one).
    pub concurrent_commands: u32,
    /// Command codes, controller → drive (3.8 "Command code").
    #[serde(rename = "command")]
    pub commands: Vec<PkwCommand>,
    /// Response codes, drive → controller (3.8 "Response code").
    #[serde(rename = "response")]
    pub responses: Vec<PkwResponse>,
    /// Error codes carried in PWE with response 7 (3.8 "Error code").
    #[serde(rename = "error")]
    pub errors: Vec<PkwError>,
    /// A successfully processed write answers like a read of the same parameter (3.8).
    pub echo: EchoRule,
    /// String parameters read in 4-byte segments through IND (3.3 par. 13).
    #[serde(rename = "string_access")]
    pub string_access: Vec<StringAccess>,
}

impl Pkw {
    /// A field (`pke`, `ind`, `pwe`) by name.
    pub fn field(&self, name: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// A PKE bit range (`ak`, `spm`, `pnu`) by name.
    pub fn pke_bit(&self, name: &str) -> Option<&BitRange> {
        self.pke_bits.iter().find(|b| b.name == name)
    }

    /// A command by code.
    pub fn command(&self, code: u8) -> Option<&PkwCommand> {
        self.commands.iter().find(|c| c.code == code)
    }

    /// A response by code.
    pub fn response(&self, code: u8) -> Option<&PkwResponse> {
        self.responses.iter().find(|r| r.code == code)
    }

    /// The response code whose value kind is `value` (e.g. the error response 7).
    pub fn response_with(&self, value: PkwValue) -> Option<&PkwResponse> {
        self.responses.iter().find(|r| r.value == value)
    }

    /// An error by code.
    pub fn error(&self, code: u16) -> Option<&PkwError> {
        self.errors.iter().find(|e| e.code == code)
    }

    /// An error by its kebab-case name.
    pub fn error_named(&self, name: &str) -> Option<&PkwError> {
        self.errors.iter().find(|e| e.name == name)
    }
}

/// A run of bits inside a word (3.8 PKE table).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BitRange {
    /// Kebab-case key (`ak`, `spm`, `pnu`).
    pub name: String,
    /// The manual's designation.
    pub label: String,
    /// Lowest bit number.
    pub lsb: u32,
    /// Number of bits.
    pub width: u32,
    /// Whether the drive implements the function (SPM: no).
    pub implemented: bool,
    /// Manual section.
    pub source: String,
}

impl BitRange {
    /// The value of this range in `word`.
    pub fn get(&self, word: u32) -> u32 {
        word.checked_shr(self.lsb).unwrap_or(0) & self.value_mask()
    }

    /// `word` with this range replaced by `value` (extra high bits of `value` are dropped).
    pub fn put(&self, word: u32, value: u32) -> u32 {
        let mask = self.value_mask().checked_shl(self.lsb).unwrap_or(0);
        (word & !mask)
            | ((value & self.value_mask())
                .checked_shl(self.lsb)
                .unwrap_or(0))
    }

    /// Mask of `width` low bits.
    pub fn value_mask(&self) -> u32 {
        1u32.checked_shl(self.width)
            .map_or(u32::MAX, |v| v.wrapping_sub(1))
    }
}

/// Where a 16-bit value sits in the 32-bit PWE (erratum PSD-ERRATUM-053).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WordPosition {
    /// Bits 0–15 of PWE (bytes 6–7 in big-endian order; PROFIdrive "PWE2").
    Low,
    /// Bits 16–31 of PWE.
    High,
}

/// Content of the unused PWE word when a 16-bit value is carried (erratum PSD-ERRATUM-053).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WordFill {
    /// The other word is 0.
    Zero,
    /// The other word repeats the sign of a signed value (0xFFFF for negatives).
    SignExtend,
}

/// Layout of the 16-bit IND word (erratum PSD-ERRATUM-054).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum IndLayout {
    /// IND is the subindex as a whole 16-bit number.
    Word,
    /// Subindex in the high byte (bits 8–15), low byte 0 (PROFIdrive cyclic PKW).
    HighByte,
    /// Subindex in the low byte (bits 0–7), high byte 0.
    LowByte,
}

/// What a PKW command does (3.8 "Command code").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PkwOp {
    /// No command (AK 0): the drive answers "no response".
    None,
    /// Read a value.
    Read,
    /// Write a value.
    Write,
    /// Read the number of array elements.
    Count,
}

/// What the PWE of a response holds (3.8 "Response code").
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum PkwValue {
    /// Nothing (response 0).
    None,
    /// A 16-bit value.
    Word,
    /// A 32-bit value.
    Dword,
    /// A 16-bit array element (IND = subindex).
    ArrayWord,
    /// A 32-bit array element (IND = subindex).
    ArrayDword,
    /// The number of array elements.
    Count,
    /// An error code (table [`PkwError`]).
    Error,
}

/// One PKW command code (3.8 "Command code").
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PkwCommand {
    /// AK value.
    pub code: u8,
    /// Kebab-case key (`read`, `write-word` …).
    pub name: String,
    /// The manual's designation.
    pub label: String,
    /// What it does.
    pub op: PkwOp,
    /// Value kind a write carries (`word`, `dword`, `array-word`, `array-dword`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<PkwValue>,
    /// Whether IND selects an array element.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub array: bool,
    /// Response codes on success.
    pub positive: Vec<u8>,
    /// Response codes on failure.
    pub negative: Vec<u8>,
    /// The requirement the code of the drive's answer states.
    pub requirement: String,
    /// Manual section (and erratum where the table was reconstructed).
    pub source: String,
}

/// One PKW response code (3.8 "Response code").
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PkwResponse {
    /// AK value.
    pub code: u8,
    /// Kebab-case key.
    pub name: String,
    /// The manual's designation.
    pub label: String,
    /// What PWE holds.
    pub value: PkwValue,
    /// Manual section.
    pub source: String,
}

/// One error code of response 7 (3.8 "Error code").
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PkwError {
    /// Value in PWE.
    pub code: u16,
    /// Kebab-case key (`unknown-parameter`, `read-only` …).
    pub name: String,
    /// The meaning, in our words.
    pub meaning: String,
    /// The requirement that a situation gives this error.
    pub requirement: String,
    /// Manual section.
    pub source: String,
}

/// The echo rule of successful writes (3.8, last paragraph).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EchoRule {
    /// Manual section.
    pub source: String,
    /// Command codes the rule applies to (2, 3, 7, 8).
    pub commands: Vec<u8>,
    /// The response code is the one a read of the parameter would give (1, 2, 4 or 5 by type).
    pub response_as_read: bool,
    /// Fields copied unchanged from the command (`pnu`, `ind`, `pwe`).
    pub copied: Vec<String>,
    /// The requirement that the copied fields equal the command's.
    pub requirement: String,
}

/// A string parameter read through PKW in fixed segments (3.3 par. 13).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StringAccess {
    /// Parameter id.
    pub param: String,
    /// Number of segments (IND 0 … segments − 1).
    pub segments: u16,
    /// Bytes per segment (the PWE width).
    pub segment_bytes: usize,
    /// Command used to read a segment.
    pub command: u8,
    /// Response carrying a segment.
    pub response: u8,
    /// The first character of a segment is the most significant PWE byte (3.3 par. 13 example).
    pub first_char_most_significant: bool,
    /// The string ends with a 0 byte.
    pub null_terminated: bool,
    /// Read record returns the whole string at once (3.3 par. 13).
    pub record_whole: bool,
    /// Manual section.
    pub source: String,
}

/// Acyclic read and write requests (3.2.2).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordAccess {
    /// Manual section.
    pub source: String,
    /// Record index = parameter number (same as the PNU).
    pub index_is_parameter_number: bool,
    /// Every parameter can be accessed by record.
    pub all_parameters: bool,
    /// A write starts with one control byte before the value.
    pub control_byte_length: usize,
    /// Control byte value that makes the drive ignore the write (0); any other value executes it.
    pub control_byte_ignore: u8,
    /// Data lengths by value width.
    #[serde(rename = "length")]
    pub lengths: Vec<RecordLength>,
}

impl RecordAccess {
    /// Lengths for a value of `bits` bits (16 or 32).
    pub fn length_for(&self, bits: u32) -> Option<&RecordLength> {
        self.lengths.iter().find(|l| l.bits == bits)
    }
}

/// Record data lengths for one value width (3.2.2 notices).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecordLength {
    /// Width of the parameter value in bits.
    pub bits: u32,
    /// Bytes returned by a read.
    pub read: usize,
    /// Bytes of a write request (control byte + value).
    pub write: usize,
    /// The requirement stating the read length.
    pub read_requirement: String,
}

/// What the drive does with the controller's outputs in one situation (3.9).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputBehaviour {
    /// Kebab-case key: `iops-bad`, `connection-interrupted`, `power-on`.
    pub situation: String,
    /// The situation in our words.
    pub label: String,
    /// What happens to the outputs.
    pub action: OutputAction,
    /// Manual section.
    pub source: String,
}

/// Substitute value of the outputs (3.9).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum OutputAction {
    /// Outputs keep the last valid value.
    LastValue,
    /// Outputs are set to 0.
    Zero,
}

/// One LED (or LED pair) and its states (3.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Led {
    /// Kebab-case key (`v-motor`, `port`, `bf`, `sf`).
    pub id: String,
    /// The manual's designation.
    pub label: String,
    /// Number on the device drawing (3.1 table).
    pub position: u32,
    /// States and their meaning.
    #[serde(rename = "state")]
    pub states: Vec<LedState>,
    /// Manual section.
    pub source: String,
}

/// One documented LED state (3.1 "Meaning of the LEDs").
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LedState {
    /// Kebab-case key.
    pub name: String,
    /// What the state means.
    pub meaning: String,
    /// The pattern of each colour.
    #[serde(rename = "signal")]
    pub signals: Vec<LedSignal>,
}

/// The pattern of one LED colour (3.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LedSignal {
    /// `yellow`, `green` or `red`.
    pub colour: String,
    /// Off, on or flashing.
    pub pattern: LedPattern,
    /// Flash frequency.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hz: Option<f64>,
    /// How long the pattern lasts, when limited.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration_s: Option<f64>,
}

/// LED pattern (3.1).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum LedPattern {
    /// Dark.
    Off,
    /// Lit.
    On,
    /// Flashing (or flickering) at `hz`.
    Flashing,
}

/// The PROFINET identity of the device: what DCP answers, what a Connect expects and what
/// the GSDML declares (manual 2.1, 3.2.1; the numbers are drivespec's own, see `source`).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PnIdentity {
    /// Where the numbers come from.
    pub source: String,
    /// VendorID (DCP DeviceID block, I&M0, GSDML `VendorID`).
    pub vendor_id: u16,
    /// DeviceID (DCP DeviceID block, GSDML `DeviceID`).
    pub device_id: u16,
    /// Vendor name (GSDML `VendorName`, DCP DeviceVendor).
    pub vendor_name: String,
    /// DCP DeviceRole (bit 0: IO device).
    pub device_role: u8,
    /// Instance in the PNIO object UUID (IEC 61158-6-10 "Object UUID").
    pub instance: u16,
    /// The device access point (slot 0 with its interface and port submodules).
    pub dap: PnDap,
    /// The 14-byte output module (3.2.1, 3.5.1).
    pub output: PnModule,
    /// The 16-byte input module (3.2.1, 3.5.2).
    pub input: PnModule,
    /// I&M0 record contents (IEC 61158-6-10 "I&M0").
    pub im0: PnIm0,
}

/// The device access point (IEC 61158-6-10: slot 0, subslot 1 and the interface and port
/// subslots 0x8000, 0x8001 …).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PnDap {
    /// Slot of the DAP.
    pub slot: u16,
    /// ModuleIdentNumber of the DAP.
    pub module_ident: u32,
    /// The DAP's submodules, none with IO data.
    pub submodule: Vec<PnSubmodule>,
}

/// One submodule without IO data (DAP, interface or port).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PnSubmodule {
    /// SubslotNumber.
    pub subslot: u16,
    /// SubmoduleIdentNumber.
    pub ident: u32,
    /// What it is (GSDML name).
    pub name: String,
}

/// A module with one IO submodule (3.2.1).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PnModule {
    /// SlotNumber.
    pub slot: u16,
    /// SubslotNumber of its submodule.
    pub subslot: u16,
    /// ModuleIdentNumber.
    pub module_ident: u32,
    /// SubmoduleIdentNumber.
    pub submodule_ident: u32,
    /// Name (GSDML).
    pub name: String,
}

/// I&M0 fields (IEC 61158-6-10 "I&M0"; order id and serial number come from the model).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PnIm0 {
    /// IM_Hardware_Revision.
    pub hardware_revision: u16,
    /// IM_Software_Revision prefix (`V` released, `R`, `P`, `U`, `T`).
    pub software_prefix: char,
    /// IM_Software_Revision: functional enhancement, bug fix, internal change.
    pub software_revision: [u8; 3],
    /// IM_Revision_Counter.
    pub revision_counter: u16,
    /// IM_Profile_ID (0: no profile).
    pub profile_id: u16,
    /// IM_Profile_Specific_Type.
    pub profile_specific_type: u16,
    /// IM_Version: major, minor.
    pub version: [u8; 2],
    /// IM_Supported (bit list of I&M1–15).
    pub supported: u16,
}

/// How the PROFINET device name is formed (2.1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeviceName {
    /// Manual section.
    pub source: String,
    /// Name prefix (`psd-`).
    pub prefix: String,
    /// Parameter holding the address switch setting.
    pub switch_param: String,
    /// Digits after the prefix for an address-switch address.
    pub switch_digits: usize,
    /// Parameter holding the EEPROM address.
    pub eeprom_param: String,
    /// Digits after the prefix for an EEPROM address.
    pub eeprom_digits: usize,
    /// Addresses are zero-padded to the digit count (erratum PSD-ERRATUM-060).
    pub zero_padded: bool,
    /// The switches are read only when the drive powers up.
    pub switch_read_at_power_on: bool,
    /// Delivery state: switch setting, EEPROM address and device name.
    pub delivery_switch_setting: u16,
    /// Delivery EEPROM address.
    pub delivery_eeprom_address: u16,
    /// Delivery device name (empty).
    pub delivery_name: String,
    /// The DCP "blinking service" (flash) is supported for identification.
    pub dcp_flash: bool,
}

/// Delivery state without a controller, by address switches (2.3).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeliverySwitch {
    /// Manual section.
    pub source: String,
    /// Switch setting at power-on that arms the function (98).
    pub arm_setting: u16,
    /// Setting that confirms it inside the window (99).
    pub confirm_setting: u16,
    /// Length of the window after power-on.
    pub window_s: f64,
    /// LED that flashes during the window.
    pub led: String,
    /// Its flash frequency.
    pub led_hz: f64,
    /// Setting that completes the procedure (0).
    pub finish_setting: u16,
    /// The window ends at once when communication is established.
    pub ends_on_communication: bool,
    /// Par. 96 value whose action is performed (-5: delivery state, save, move to mid-range).
    pub action_value: i64,
}

/// Numeric constants of chapter 4.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Positioning {
    /// Manual section.
    pub source: String,
    /// Position scaling (4.8).
    pub scaling: Scaling,
    /// Absolute encoder range and mapping end (4.7).
    pub mapping: Mapping,
    /// Parameter changes that reset or recalculate others (4.7 notes 3–6).
    #[serde(rename = "side_effect")]
    pub side_effects: Vec<SideEffect>,
    /// Recommended write order, one group per step (4.7 note 7).
    pub write_order: Vec<Vec<String>>,
    /// Saving parameters (4.7 note 8).
    pub save: Save,
    /// Reference loop and positioning accuracy (4.1, 4.2).
    #[serde(rename = "loop")]
    pub reference_loop: ReferenceLoop,
    /// Velocity and ramps (4.3).
    pub velocity: Velocity,
    /// Torque limits (4.4).
    pub torque: Torque,
    /// Motor supply voltage limits (3.3 par. 90, 3.6 bits 4 and 13, 4.6).
    pub motor_voltage: MotorVoltage,
    /// Device temperature limit (3.6 bit 7).
    pub temperature: Temperature,
    /// Obstruction detection (4.5, 4.10).
    pub obstruction: Obstruction,
    /// Readjustment after manual turning (4.6).
    pub adjustment: Adjustment,
    /// Recommended settings for a reference run to a block (4.10).
    pub reference_run: ReferenceRun,
    /// Run abort when the controller fails (4.9).
    pub master_failure: MasterFailure,
}

/// Position scaling (4.8).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scaling {
    /// Manual section.
    pub source: String,
    /// Numerator parameter (38).
    pub numerator_param: String,
    /// Denominator parameter (39).
    pub denominator_param: String,
    /// Increments per rotation at numerator = denominator (400).
    pub base_increments_per_rotation: i64,
    /// Delivery numerator.
    pub default_numerator: i64,
    /// Delivery denominator.
    pub default_denominator: i64,
    /// Smallest factor.
    pub factor_min: i64,
    /// Largest factor.
    pub factor_max: i64,
    /// Spindle pitch at the delivery scaling, in µm (4 mm).
    pub default_pitch_um: i64,
    /// Resolution at the delivery scaling, in µm (0.01 mm).
    pub default_resolution_um: i64,
}

impl Scaling {
    /// Increments per rotation = base × denominator / numerator (4.8 formula).
    pub fn increments_per_rotation(&self, numerator: i64, denominator: i64) -> Option<f64> {
        if numerator == 0 {
            return None;
        }
        Some(self.base_increments_per_rotation as f64 * denominator as f64 / numerator as f64)
    }

    /// A length given in delivery-scaling increments, expressed in the scaled unit
    /// (value × denominator / numerator, rounded toward zero).
    pub fn scale(&self, value: i64, numerator: i64, denominator: i64) -> Option<i64> {
        let v = i128::from(value).checked_mul(i128::from(denominator))?;
        let v = v.checked_div(i128::from(numerator))?;
        i64::try_from(v).ok()
    }
}

/// Absolute encoder range and the upper mapping end (4.7, 3.3 par. 41–43).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mapping {
    /// Manual section.
    pub source: String,
    /// Upper mapping end parameter (41).
    pub param: String,
    /// Upper limit parameter (42).
    pub upper_limit_param: String,
    /// Lower limit parameter (43).
    pub lower_limit_param: String,
    /// Referencing value parameter (40).
    pub reference_param: String,
    /// Actual value parameter (3); writing it sets the referencing value.
    pub actual_param: String,
    /// Rotations the absolute encoder covers (4,026).
    pub encoder_rotations: i64,
    /// Highest position = mapping end − this many rotations (3).
    pub upper_margin_rotations: i64,
    /// Lowest position = mapping end − this many rotations (4,029).
    pub lower_offset_rotations: i64,
    /// Upper margin in delivery-scaling increments (1,200).
    pub upper_margin: i64,
    /// Lower offset in delivery-scaling increments (1,611,600) for models without auxiliary gearbox.
    pub lower_offset: i64,
    /// Usable span in delivery-scaling increments (1,610,400).
    pub span: i64,
    /// Delivery upper mapping end (806,400 = +2,016 rotations) for models without gearbox.
    pub default_mapping_end: i64,
    /// Delivery upper limit (805,200).
    pub default_upper_limit: i64,
    /// Delivery lower limit (-805,200).
    pub default_lower_limit: i64,
    /// Delivery positioning range ± rotations (2,013).
    pub default_range_rotations: i64,
    /// Delivery actual position (0).
    pub default_position: i64,
    /// Geared models: lower offset = model default of par. 41 − model default of par. 43
    /// (3.3 par. 42/43 "reduced in accordance with the gear ratio", 3.4 table).
    pub lower_offset_from_model_defaults: bool,
    /// Changing par. 41 resets the limits to the full new range, not to the absolute delivery
    /// numbers (erratum PSD-ERRATUM-057).
    pub limits_follow_mapping_end: bool,
}

impl Mapping {
    /// Highest and lowest reachable positions for a mapping end (delivery scaling, no gearbox).
    pub fn position_range(&self, mapping_end: i64) -> (i64, i64) {
        (
            mapping_end.saturating_sub(self.lower_offset),
            mapping_end.saturating_sub(self.upper_margin),
        )
    }

    /// Permissible values of par. 41 for an actual position (delivery scaling, no gearbox).
    pub fn mapping_end_window(&self, actual: i64) -> (i64, i64) {
        (
            actual.saturating_add(self.upper_margin),
            actual.saturating_add(self.lower_offset),
        )
    }
}

/// A parameter write that changes other values (4.7 notes 3–6).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SideEffect {
    /// Parameters whose change triggers the effect.
    pub changed: Vec<String>,
    /// What happens to `affected`.
    pub effect: SideEffectKind,
    /// Parameter ids affected (3 = actual value, 33 = target value).
    pub affected: Vec<String>,
    /// Manual section.
    pub source: String,
}

/// Kind of side effect (4.7 notes).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SideEffectKind {
    /// Set to the delivery state.
    Reset,
    /// Recalculated to keep the same physical meaning.
    Recalculate,
}

/// Saving parameters to EEPROM (4.7 note 8).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Save {
    /// Parameter (96).
    pub param: String,
    /// Value to write (1).
    pub value: i64,
    /// Longest duration of a save.
    pub max_ms: u32,
    /// Manual section.
    pub source: String,
}

/// Direction of motion along the position axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Direction {
    /// Toward larger position values.
    Increasing,
    /// Toward smaller position values.
    Decreasing,
}

/// Reference loop and positioning accuracy (4.1, 4.2.1, 4.2.2, 3.3 par. 44/45).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceLoop {
    /// Manual section.
    pub source: String,
    /// Loop length parameter (45); 0 disables the loop, the sign selects the direction.
    pub length_param: String,
    /// Positioning window parameter (44).
    pub window_param: String,
    /// Control bit that disables the loop for a run (bit 6).
    pub no_loop_control_bit: u32,
    /// Delivery loop length (250 increments = 5/8 rotation).
    pub default_length: i64,
    /// The 5/8-rotation overshoot of 4.2.1 as a fraction of a rotation: [5, 8].
    pub default_length_rotations: [i64; 2],
    /// The overshoot equals |par. 45|, not a fixed 5/8 rotation (erratum PSD-ERRATUM-055).
    pub overshoot_is_loop_length: bool,
    /// Final approach direction for a positive loop length (erratum PSD-ERRATUM-056).
    pub positive_approach: Direction,
    /// With lash present (status bit 8), the final approach covers at least |loop| and the
    /// drive backs off by at most |loop| first (4.2.1 case 3, erratum PSD-ERRATUM-055).
    pub min_final_approach_is_loop_length: bool,
    /// Positioning attempts in all: the first run plus one automatic second positioning (4.2.1).
    pub attempts: u32,
    /// Status bit set when the second attempt also ends outside the window (bit 10).
    pub attempts_exhausted_status_bit: u32,
}

impl ReferenceLoop {
    /// Final approach direction for a loop length (None when the loop is off).
    pub fn approach(&self, loop_length: i64) -> Option<Direction> {
        let flip = |d: Direction| match d {
            Direction::Increasing => Direction::Decreasing,
            Direction::Decreasing => Direction::Increasing,
        };
        match loop_length.signum() {
            1 => Some(self.positive_approach),
            -1 => Some(flip(self.positive_approach)),
            _ => None,
        }
    }
}

/// How a stop (release withdrawn) brakes (4.3, erratum PSD-ERRATUM-058).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum StopRamp {
    /// With the deceleration of par. 59.
    Parameter,
    /// With the maximum possible deceleration, ignoring par. 59.
    Maximum,
}

/// Velocity and ramps (4.3).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Velocity {
    /// Manual section.
    pub source: String,
    /// Maximum speed of positioning runs (53).
    pub positioning_param: String,
    /// Maximum speed of manual runs (56).
    pub manual_param: String,
    /// Maximum acceleration, also used for speed changes during a run (58).
    pub acceleration_param: String,
    /// Maximum deceleration (59).
    pub deceleration_param: String,
    /// Braking when the release is withdrawn (adopted reading).
    pub stop_ramp: StopRamp,
    /// Braking at an end position (limit) reached during a run.
    pub limit_ramp: StopRamp,
    /// Above this speed the stepper motor may resonate or lock (4.4 notice).
    pub resonance_rpm: i64,
}

/// Torque limits (4.4).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Torque {
    /// Manual section.
    pub source: String,
    /// Maximum start-up torque (63).
    pub startup_param: String,
    /// Maximum operating torque (64).
    pub operating_param: String,
    /// Duration of the start-up phase (71).
    pub startup_time_param: String,
    /// Holding torque at the end of a run (65).
    pub end_holding_param: String,
    /// Duration of the end-of-run holding torque (72).
    pub end_holding_time_param: String,
    /// Holding torque at standstill (66).
    pub holding_param: String,
}

/// Motor supply voltage limits, raw in 0.1 V (3.3 par. 90, 3.6 bits 4/13).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorVoltage {
    /// Manual section.
    pub source: String,
    /// Lower limit parameter (90), also the minimum to start a run.
    pub limit_param: String,
    /// Measurement filter parameter (76).
    pub filter_param: String,
    /// Fixed upper limit (300 = 30 V).
    pub upper_limit: i64,
    /// Lowest voltage tolerated during a run (175 = 17.5 V).
    pub run_minimum: i64,
    /// Raw unit (0.1 V).
    pub scale: f64,
}

/// Device temperature limit (3.6 bit 7).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Temperature {
    /// Manual section.
    pub source: String,
    /// Limit parameter (91), °C.
    pub limit_param: String,
    /// Measured temperature parameter (8), °C.
    pub measured_param: String,
    /// Bit 7 resets this many °C below the limit (5).
    pub hysteresis_c: i64,
}

/// Obstruction detection (4.5, 4.10).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Obstruction {
    /// Manual section.
    pub source: String,
    /// Speed limit in % of the target speed (57).
    pub speed_limit_param: String,
    /// Time below the speed limit before the run aborts, ms (70).
    pub time_param: String,
    /// Holding torque applied after the abort (66).
    pub holding_param: String,
    /// Status bit set (10).
    pub status_bit: u32,
    /// Torque for intentional runs to a block: below this % of the nominal rated torque.
    pub block_run_max_torque_percent: i64,
    /// A new run to the same target needs a release 0→1 edge with bit 2 set (4.5 exception).
    pub same_target_needs_release_edge: bool,
}

/// Readjustment after manual turning (4.6).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Adjustment {
    /// Manual section.
    pub source: String,
    /// Readjustment parameter (47): 0 off, 1 on.
    pub enable_param: String,
    /// Control bit that must be set (release, bit 4).
    pub release_bit: u32,
    /// Status bit set on manual rotation (11).
    pub manual_rotation_bit: u32,
    /// Status bit that must be 1 (motor voltage, bit 4) when the window is left.
    pub voltage_bit: u32,
    /// Status bits set when the window is left without motor voltage (10 and 13).
    pub no_voltage_bits: Vec<u32>,
    /// Adjusts in both directions when the loop is off (par. 45 = 0).
    pub both_directions_without_loop: bool,
}

/// Recommended settings for a reference run to a block (4.10).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ReferenceRun {
    /// Manual section.
    pub source: String,
    /// Settings before the run.
    #[serde(rename = "setting")]
    pub settings: Vec<RecommendedSetting>,
    /// The run is a manual run (control bit 0 or 1).
    pub manual_run: bool,
}

/// One recommended setting (4.10 step 1).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RecommendedSetting {
    /// Step label (`1a` …).
    pub step: String,
    /// Parameters set.
    pub params: Vec<String>,
    /// Raw value, when fixed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub value: Option<i64>,
    /// Percent of the parameter's maximum, when relative.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub percent_of_max: Option<i64>,
    /// One line.
    pub note: String,
}

/// Run abort when the controller fails (4.9, 3.9).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MasterFailure {
    /// Manual section.
    pub source: String,
    /// A communication time-out aborts a run.
    pub abort_on_timeout: bool,
    /// The run continues at once when the restored process data are valid.
    pub resume_on_valid_data: bool,
    /// The manual gives no time-out value; the PROFINET watchdog applies.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub timeout_ms: Option<u32>,
}

/// Back-driving limits (4.11).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reverse {
    /// Manual section.
    pub source: String,
    /// Above the permissible speed the drive survives at most this long (1–2 s).
    pub max_duration_s: [f64; 2],
    /// Name of the model attribute holding the permissible reverse speed in rpm (4.11 table,
    /// kept once in `models.toml`).
    pub speed_attribute: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Deserialize)]
    struct File {
        protocol: Protocol,
    }

    fn protocol() -> Result<Protocol, String> {
        let text = include_str!("../../../spec/psd4xx/protocol.toml");
        toml::from_str::<File>(text)
            .map(|f| f.protocol)
            .map_err(|e| e.to_string())
    }

    fn contiguous(fields: &[Field], length: usize) -> bool {
        let mut next = 0;
        for f in fields {
            if f.offset != next {
                return false;
            }
            next = f.offset + f.length;
        }
        next == length
    }

    #[test]
    fn layouts_are_contiguous() -> Result<(), String> {
        let p = protocol()?;
        assert!(contiguous(
            &p.process_data.output.fields,
            p.process_data.output.length
        ));
        assert!(contiguous(
            &p.process_data.input.fields,
            p.process_data.input.length
        ));
        assert!(contiguous(&p.pkw.fields, p.pkw.length));
        assert_eq!(
            (
                p.process_data.output.length,
                p.process_data.input.length,
                p.pkw.length
            ),
            (14, 16, 8)
        );
        let control = p.process_data.output.field("control").ok_or("control")?;
        assert_eq!(control.byte_order(p.byte_order), ByteOrder::LittleEndian);
        Ok(())
    }

    #[test]
    fn pke_bits() -> Result<(), String> {
        let p = protocol()?;
        let ak = p.pkw.pke_bit("ak").ok_or("ak")?;
        let pnu = p.pkw.pke_bit("pnu").ok_or("pnu")?;
        let spm = p.pkw.pke_bit("spm").ok_or("spm")?;
        assert_eq!(
            (ak.get(0x102C), pnu.get(0x102C), spm.get(0x102C)),
            (1, 44, 0)
        );
        assert_eq!(pnu.put(ak.put(0, 7), 44), 0x702C);
        let total: u32 = p.pkw.pke_bits.iter().map(|b| b.width).sum();
        assert_eq!(total, 16);
        Ok(())
    }

    #[test]
    fn pkw_tables_agree() -> Result<(), String> {
        let p = protocol()?;
        for c in &p.pkw.commands {
            for r in c.positive.iter().chain(&c.negative) {
                assert!(
                    p.pkw.response(*r).is_some(),
                    "command {} names response {r}",
                    c.code
                );
            }
        }
        for code in &p.pkw.echo.commands {
            assert_eq!(p.pkw.command(*code).map(|c| c.op), Some(PkwOp::Write));
        }
        assert_eq!(
            p.pkw.response_with(PkwValue::Error).map(|r| r.code),
            Some(7)
        );
        assert_eq!(p.pkw.error_named("out-of-range").map(|e| e.code), Some(2));
        for l in &p.record.lengths {
            assert_eq!(l.write, l.read + p.record.control_byte_length);
            assert_eq!(l.read * 8, l.bits as usize);
        }
        Ok(())
    }

    #[test]
    fn mapping_constants_agree() -> Result<(), String> {
        let p = protocol()?;
        let m = &p.positioning.mapping;
        let base = p.positioning.scaling.base_increments_per_rotation;
        assert_eq!(m.upper_margin, m.upper_margin_rotations * base);
        assert_eq!(m.lower_offset, m.lower_offset_rotations * base);
        assert_eq!(m.span, m.encoder_rotations * base);
        assert_eq!(m.span, m.lower_offset - m.upper_margin);
        assert_eq!(
            m.position_range(m.default_mapping_end),
            (m.default_lower_limit, m.default_upper_limit)
        );
        assert_eq!(m.default_upper_limit, m.default_range_rotations * base);
        assert_eq!(m.mapping_end_window(0), (1200, 1_611_600));
        let s = &p.positioning.scaling;
        assert_eq!(s.increments_per_rotation(400, 100), Some(100.0));
        assert_eq!(s.scale(m.lower_offset, 400, 100), Some(402_900));
        let l = &p.positioning.reference_loop;
        assert_eq!(
            l.default_length * l.default_length_rotations[1],
            base * l.default_length_rotations[0]
        );
        assert_eq!(l.approach(250), Some(Direction::Increasing));
        assert_eq!(l.approach(-250), Some(Direction::Decreasing));
        assert_eq!(l.approach(0), None);
        Ok(())
    }
}
