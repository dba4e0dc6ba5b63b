//! Sequences of PROFINET-layer inputs drawn from the spec and IEC 61158-6-10: DCP requests
//! with odd, truncated and unknown blocks; Connects with boundary SendClockFactor (including
//! 8–11 and 65524, which crashed devices in the field), ReductionRatio, DataHoldFactor, IOCR
//! and submodule data lengths and module idents; record Reads and Writes of every PSD4xx
//! parameter (manual 3.2.2) and of indices around them; cyclic frames with odd cycle
//! counters, data and transfer status, IOxS and lengths.
//!
//! Inputs a correct device may legally answer by no longer being reachable under its name
//! are never drawn: a DCP Set of another NameOfStation or IP suite, a FactoryReset, and
//! record writes of command parameters (parameters with enumerated command values, such as
//! par. 96 of manual 3.3, which restart the drive or delete its name).

use super::step::PnStep;
use crate::engine::{below, chance, pick, templates, weighted};
use crate::replay::{Action, Step};
use drivespec_profinet::controller::ControllerConfig;
use drivespec_profinet::dcp::{opt, DcpBlocks};
use drivespec_profinet::identity::Identity;
use drivespec_profinet::rt::{data_status, ioxs, MAX_C_SDU, MIN_C_SDU};
use drivespec_sim::rng::Rng;
use drivespec_spec::{Family, Spec};

templates! {
    /// What a step mutates.
    Identify = 3,
    Set = 1,
    Get = 1,
    Connect = 4,
    Read = 2,
    Write = 2,
    Rt = 2,
}

/// Most steps of one sequence.
const MAX_STEPS: usize = 4;

/// SendClockFactors tried: the powers of two of RT class 1, their neighbours, and the values
/// that crashed devices in the field (8–11, 65524).
const SEND_CLOCKS: [u16; 17] = [
    0, 1, 2, 4, 8, 9, 10, 11, 16, 31, 32, 33, 64, 128, 256, 65524, 65535,
];
/// ReductionRatios tried (RT class 1: powers of two to 512).
const REDUCTIONS: [u16; 9] = [0, 1, 2, 3, 7, 512, 513, 1024, 65535];
/// DataHoldFactors tried (IEC 61158-6-10: 3 to 0x1E00).
const DATA_HOLDS: [u16; 8] = [0, 1, 2, 3, 4, 0x1E00, 0x1E01, 0xFFFF];
/// Record indices tried beside the parameters: the ends of the user range, I&M0 to I&M4
/// (0xAFF0–0xAFF4) and beyond, the ends of the index space.
const INDICES: [u16; 10] = [
    0, 0x7FFF, 0x8000, 0xAFF0, 0xAFF1, 0xAFF4, 0xAFF5, 0xE000, 0xF840, 0xFFFF,
];
/// Record data lengths tried.
const DATA_LENGTHS: [usize; 10] = [0, 1, 2, 3, 4, 5, 8, 64, 255, 1000];
/// DataStatus values tried: the good ones, each bit alone, none, all.
const DATA_STATUS: [u8; 9] = [
    data_status::GOOD_RUN,
    data_status::GOOD_STOP,
    0x00,
    0x01,
    0x04,
    0x10,
    0x20,
    0x15,
    0xFF,
];
/// IOxS values tried: good, bad (by subslot, slot, device, controller), reserved bits.
const IOXS: [u8; 6] = [ioxs::GOOD, ioxs::BAD, 0x20, 0x40, 0x60, 0xFF];

/// What the generator needs: the station's name, its modules, and the record indices of the
/// spec.
#[derive(Debug, Clone)]
pub(crate) struct Generator {
    name: String,
    identity: Identity,
    good: ControllerConfig,
    /// Parameter numbers that fit a record index (manual 3.2.2).
    params: Vec<u16>,
    /// The same without command parameters.
    writable: Vec<u16>,
}

impl Generator {
    /// The generator for the station `name` with `identity`, indices from `family`.
    pub(crate) fn new(family: &Family, identity: &Identity, name: &str) -> Generator {
        let params: Vec<(u16, bool)> = family
            .parameters
            .iter()
            .filter_map(|p| {
                u16::try_from(p.number)
                    .ok()
                    .map(|n| (n, p.values.is_empty()))
            })
            .collect();
        Generator {
            name: name.to_owned(),
            identity: identity.clone(),
            good: ControllerConfig::new(identity.clone(), [0; 6], [0; 4], name),
            params: params.iter().map(|(n, _)| *n).collect(),
            writable: params.iter().filter(|(_, w)| *w).map(|(n, _)| *n).collect(),
        }
    }

    /// The generator of the PSD4xx family of `spec`.
    pub(crate) fn of_spec(spec: &Spec, identity: &Identity, name: &str) -> Generator {
        Generator::new(
            spec.family(drivespec_spec::FamilyId::Psd4xx),
            identity,
            name,
        )
    }

    /// The next sequence: 1 to [`MAX_STEPS`] inputs, drawn from `rng` only.
    pub(crate) fn sequence(&self, rng: &mut Rng) -> Vec<Step> {
        let n = 1 + below(rng, MAX_STEPS);
        (0..n).map(|_| self.step(rng)).collect()
    }

    fn step(&self, rng: &mut Rng) -> Step {
        let t = weighted(rng, TEMPLATES, |_| true, Template::Identify);
        let (class, text, step) = match t {
            Template::Identify => self.identify(rng),
            Template::Set => self.set(rng),
            Template::Get => get(rng),
            Template::Connect => self.connect(rng),
            Template::Read => self.read(rng),
            Template::Write => self.write(rng),
            Template::Rt => rt(rng),
        };
        Step {
            action: Action::Profinet(step),
            class: class.to_owned(),
            text,
            requirements: Vec::new(),
        }
    }

    fn identify(&self, rng: &mut Rng) -> (&'static str, String, PnStep) {
        let name = self.name.as_bytes();
        let mut b = DcpBlocks::new();
        let (class, text) = match below(rng, 10) {
            0 => {
                b.plain(opt::ALL, &[]);
                ("dcp-identify-all", "Identify all".to_owned())
            }
            1 => {
                b.plain(opt::NAME_OF_STATION, name);
                (
                    "dcp-identify-name",
                    "Identify by the station's name".to_owned(),
                )
            }
            2 => {
                let mut other = name.to_vec();
                other.extend_from_slice(b"-x");
                b.plain(opt::NAME_OF_STATION, &other);
                ("dcp-identify-name", "Identify by another name".to_owned())
            }
            3 => {
                // A NameOfStation block whose length runs past the PDU.
                let mut raw = vec![opt::NAME_OF_STATION.0, opt::NAME_OF_STATION.1];
                let claimed = u16::try_from(name.len() + 1 + below(rng, 64)).unwrap_or(0xFFFF);
                raw.extend_from_slice(&claimed.to_be_bytes());
                raw.extend_from_slice(name);
                return (
                    "dcp-identify-malformed",
                    format!("Identify, a block claiming {claimed} bytes past the PDU"),
                    PnStep::DcpIdentify { blocks: raw },
                );
            }
            4 => {
                return (
                    "dcp-identify-empty",
                    "Identify without blocks".to_owned(),
                    empty_identify(),
                )
            }
            5 => {
                b.plain(opt::ALL, &[]);
                let mut raw = b.into_bytes();
                raw.push(0);
                return (
                    "dcp-identify-malformed",
                    "Identify all and a stray byte".to_owned(),
                    PnStep::DcpIdentify { blocks: raw },
                );
            }
            6 => {
                b.plain(opt::DEVICE_ID, &[0x01, 0x02, 0x03]);
                (
                    "dcp-identify-odd",
                    "Identify by a 3-byte DeviceID".to_owned(),
                )
            }
            7 => {
                let len = 1 + below(rng, 16);
                let raw: Vec<u8> = (0..len).map(|_| rng.byte()).collect();
                return (
                    "dcp-identify-random",
                    format!("Identify with {len} random bytes as blocks"),
                    PnStep::DcpIdentify { blocks: raw },
                );
            }
            8 => {
                let k = 2 + below(rng, 60);
                for _ in 0..k {
                    b.plain(opt::ALL, &[]);
                }
                (
                    "dcp-identify-many",
                    format!("Identify with {k} all-selectors"),
                )
            }
            _ => {
                b.plain(opt::ALIAS_NAME, name);
                (
                    "dcp-identify-alias",
                    "Identify by an alias of the name".to_owned(),
                )
            }
        };
        (
            class,
            text,
            PnStep::DcpIdentify {
                blocks: b.into_bytes(),
            },
        )
    }

    fn set(&self, rng: &mut Rng) -> (&'static str, String, PnStep) {
        let mut b = DcpBlocks::new();
        let (class, text) = match below(rng, 6) {
            0 => {
                let qualifier = u16::from(chance(rng, 50));
                b.with_info(opt::NAME_OF_STATION, qualifier, self.name.as_bytes());
                ("dcp-set-same-name", "Set the station's own name".to_owned())
            }
            1 => {
                b.with_info(opt::CONTROL_SIGNAL, 0, &[0x01, 0x00]);
                ("dcp-set-signal", "Set Signal (flash the LED)".to_owned())
            }
            2 => {
                // An IP suite too short to be one: no device can take it.
                let len = below(rng, 12);
                let data: Vec<u8> = (0..len).map(|_| rng.byte()).collect();
                b.with_info(opt::IP_PARAMETER, 1, &data);
                (
                    "dcp-set-short-ip",
                    format!("Set an IP suite of {len} bytes"),
                )
            }
            3 => {
                let option = (
                    0x07 + u8::try_from(below(rng, 0x70)).unwrap_or(0),
                    rng.byte(),
                );
                b.with_info(option, 0, &[rng.byte(), rng.byte()]);
                (
                    "dcp-set-unknown",
                    format!("Set of unknown option {:?}", option),
                )
            }
            4 => {
                b.with_info(opt::CONTROL_START, 0, &[]);
                b.with_info(opt::NAME_OF_STATION, 0, self.name.as_bytes());
                b.with_info(opt::CONTROL_STOP, 0, &[]);
                (
                    "dcp-set-transaction",
                    "Start, the own name, Stop".to_owned(),
                )
            }
            _ => {
                let mut raw = vec![opt::NAME_OF_STATION.0, opt::NAME_OF_STATION.1, 0xFF, 0xFF];
                raw.extend_from_slice(&[0, 0]);
                return (
                    "dcp-set-malformed",
                    "Set with a block claiming 65535 bytes".to_owned(),
                    PnStep::DcpSet { blocks: raw },
                );
            }
        };
        (
            class,
            text,
            PnStep::DcpSet {
                blocks: b.into_bytes(),
            },
        )
    }

    fn connect(&self, rng: &mut Rng) -> (&'static str, String, PnStep) {
        let id = &self.identity;
        let g = &self.good;
        let (mut scf, mut rr, mut dhf, mut dl) = (
            g.send_clock_factor,
            g.reduction_ratio,
            g.data_hold_factor,
            g.data_length,
        );
        let (mut il, mut ol) = (id.input.length, id.output.length);
        let (mut mi, mut si) = (id.output.module_ident, id.output.submodule_ident);
        let mut changed = Vec::new();
        for _ in 0..1 + below(rng, 2) {
            match below(rng, 7) {
                0 => {
                    scf = *pick(rng, &SEND_CLOCKS).unwrap_or(&scf);
                    changed.push(format!("SendClockFactor {scf}"));
                }
                1 => {
                    rr = *pick(rng, &REDUCTIONS).unwrap_or(&rr);
                    changed.push(format!("ReductionRatio {rr}"));
                }
                2 => {
                    dhf = *pick(rng, &DATA_HOLDS).unwrap_or(&dhf);
                    changed.push(format!("DataHoldFactor {dhf}"));
                }
                3 => {
                    let min = u16::try_from(MIN_C_SDU).unwrap_or(40);
                    let max = u16::try_from(MAX_C_SDU).unwrap_or(1440);
                    let lengths = [0, 1, min - 1, min, min + 1, max, max + 1, 0xFFFF];
                    dl = *pick(rng, &lengths).unwrap_or(&dl);
                    changed.push(format!("IOCR DataLength {dl}"));
                }
                4 => {
                    il = boundary(rng, il);
                    changed.push(format!("input length {il}"));
                }
                5 => {
                    ol = boundary(rng, ol);
                    changed.push(format!("output length {ol}"));
                }
                _ => {
                    let idents = [mi ^ 1, 0, u32::MAX, id.input.module_ident];
                    if chance(rng, 50) {
                        mi = *pick(rng, &idents).unwrap_or(&mi);
                        changed.push(format!("module ident {mi:#x}"));
                    } else {
                        let subs = [si ^ 1, 0, u32::MAX, id.input.submodule_ident];
                        si = *pick(rng, &subs).unwrap_or(&si);
                        changed.push(format!("submodule ident {si:#x}"));
                    }
                }
            }
        }
        (
            "connect",
            format!("Connect with {}", changed.join(", ")),
            PnStep::Connect {
                send_clock_factor: scf,
                reduction_ratio: rr,
                data_hold_factor: dhf,
                data_length: dl,
                input_length: il,
                output_length: ol,
                module_ident: mi,
                submodule_ident: si,
            },
        )
    }

    /// A (slot, subslot): the output, input or DAP submodule, or one that does not exist.
    fn subslot(&self, rng: &mut Rng) -> (u16, u16) {
        let id = &self.identity;
        let dap = id
            .dap_submodules
            .first()
            .map_or((id.dap_slot, 1), |(s, _)| (id.dap_slot, *s));
        let all = [
            (id.output.slot, id.output.subslot),
            (id.output.slot, id.output.subslot),
            (id.input.slot, id.input.subslot),
            dap,
            (0x7FFF, 1),
            (id.output.slot, 0x9999),
        ];
        *pick(rng, &all).unwrap_or(&all[0])
    }

    fn index(&self, rng: &mut Rng, from: &[u16]) -> u16 {
        match below(rng, 4) {
            0 => *pick(rng, &INDICES).unwrap_or(&0),
            1 => u16::try_from(rng.range(0, 0xFFFF)).unwrap_or(0),
            _ => *pick(rng, from).unwrap_or(&0),
        }
    }

    fn read(&self, rng: &mut Rng) -> (&'static str, String, PnStep) {
        let (slot, subslot) = self.subslot(rng);
        let index = self.index(rng, &self.params);
        (
            "record-read",
            format!("Read index {index:#06x} of {slot}/{subslot:#x}"),
            PnStep::RecordRead {
                slot,
                subslot,
                index,
            },
        )
    }

    fn write(&self, rng: &mut Rng) -> (&'static str, String, PnStep) {
        let (slot, subslot) = self.subslot(rng);
        let mut index = self.index(rng, &self.writable);
        if self.params.contains(&index) && !self.writable.contains(&index) {
            index = self.writable.first().copied().unwrap_or(0);
        }
        let len = *pick(rng, &DATA_LENGTHS).unwrap_or(&3);
        let data: Vec<u8> = (0..len).map(|_| rng.byte()).collect();
        (
            "record-write",
            format!("Write {len} byte(s) to index {index:#06x} of {slot}/{subslot:#x}"),
            PnStep::RecordWrite {
                slot,
                subslot,
                index,
                data,
            },
        )
    }
}

/// An Identify request with no blocks.
fn empty_identify() -> PnStep {
    PnStep::DcpIdentify { blocks: Vec::new() }
}

/// A length around `good`: 0, one less, one more, 255 or 65535.
fn boundary(rng: &mut Rng, good: u16) -> u16 {
    let all = [
        0,
        good.saturating_sub(1),
        good.saturating_add(1),
        255,
        0xFFFF,
    ];
    *pick(rng, &all).unwrap_or(&good)
}

fn get(rng: &mut Rng) -> (&'static str, String, PnStep) {
    let pairs: Vec<u8> = match below(rng, 4) {
        0 => vec![2, 2, 1, 2, 2, 3],
        1 => vec![2, 2, 1],
        2 => (0..64).flat_map(|_| [2u8, 2]).collect(),
        _ => (0..2 * (1 + below(rng, 8))).map(|_| rng.byte()).collect(),
    };
    (
        "dcp-get",
        format!("Get with {} byte(s) of option pairs", pairs.len()),
        PnStep::DcpGet { blocks: pairs },
    )
}

fn rt(rng: &mut Rng) -> (&'static str, String, PnStep) {
    let counters = [0, 1, 0x7FFF, 0xFFFF, rng.byte().into()];
    let cycle_counter = *pick(rng, &counters).unwrap_or(&0);
    let data_status = *pick(rng, &DATA_STATUS).unwrap_or(&0);
    let transfer_status = if chance(rng, 75) { 0 } else { rng.byte() };
    let ioxs = *pick(rng, &IOXS).unwrap_or(&0);
    let min = u16::try_from(MIN_C_SDU).unwrap_or(40);
    let max = u16::try_from(MAX_C_SDU).unwrap_or(1440);
    let lengths = [0, 1, min - 1, min, min + 1, 64, max];
    let length = *pick(rng, &lengths).unwrap_or(&min);
    (
        "rt",
        format!(
            "cyclic frame: counter {cycle_counter}, DataStatus {data_status:#04x}, \
             TransferStatus {transfer_status:#04x}, IOxS {ioxs:#04x}, C_SDU {length} bytes"
        ),
        PnStep::Rt {
            cycle_counter,
            data_status,
            transfer_status,
            ioxs,
            length,
        },
    )
}
