//! Everything the PSD4xx codec reads from the spec, with the settings where engineering tools
//! and readings of the manual differ (manual 3.5 notice "UseAsBits", 3.8; errata
//! PSD-ERRATUM-050, -053, -054).

use crate::error::RulesError;
use crate::pkw::PkwRules;
use crate::record::RecordRules;
use crate::value::Params;
use crate::wire::Layout;
use drivespec_positioner::ByteOrder;
use drivespec_spec::psd4xx::{IndLayout, Protocol, WordFill, WordPosition};
use drivespec_spec::{Bitfield, FamilyId, Parameter, Spec};
use serde::{Deserialize, Serialize};

/// Settings of the codec; [`Options::from_protocol`] gives the manual's (the spec's adopted
/// readings). Engineering tools differ in byte order, so it is a setting (manual 3.5 notice).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Options {
    /// Order of multi-byte values in process data, PKW and records (erratum PSD-ERRATUM-050).
    pub byte_order: ByteOrder,
    /// Control and status word use the other order in process data (3.5 notice "UseAsBits";
    /// erratum PSD-ERRATUM-061: process data only).
    pub invert_bit_words: bool,
    /// Where a 16-bit value sits in PWE (erratum PSD-ERRATUM-053).
    pub word_position: WordPosition,
    /// What the unused PWE word holds (erratum PSD-ERRATUM-053).
    pub word_fill: WordFill,
    /// How IND carries the subindex (erratum PSD-ERRATUM-054).
    pub ind_layout: IndLayout,
}

impl Options {
    /// The spec's settings: its byte order with control and status inverted (3.5 notice), its
    /// PWE word position and fill and its IND layout.
    pub fn from_protocol(p: &Protocol) -> Options {
        Options {
            byte_order: p.byte_order.into(),
            invert_bit_words: true,
            word_position: p.pkw.word_position,
            word_fill: p.pkw.word_fill,
            ind_layout: p.pkw.ind_layout,
        }
    }

    /// The spec's settings read from a whole spec (manual 3.5, 3.8).
    pub fn manual(spec: &Spec) -> Result<Options, RulesError> {
        let p = spec
            .family(FamilyId::Psd4xx)
            .psd4xx()
            .ok_or(RulesError::NoProtocol)?;
        Ok(Options::from_protocol(p))
    }
}

/// The PSD4xx codec's tables: layouts, PKW, records, control and status bits (manual 3.2,
/// 3.5–3.8), for one [`Options`] setting.
#[derive(Debug, Clone)]
pub struct Rules {
    options: Options,
    layout: Layout,
    pkw: PkwRules,
    record: RecordRules,
    control: Bitfield,
    status: Bitfield,
    params: Params,
}

impl Rules {
    /// The rules with the manual's settings (manual 3.5, 3.8).
    pub fn from_spec(spec: &Spec) -> Result<Rules, RulesError> {
        Rules::with_options(spec, Options::manual(spec)?)
    }

    /// The rules with other settings, e.g. little-endian for a tool that swaps (3.5 notice).
    pub fn with_options(spec: &Spec, options: Options) -> Result<Rules, RulesError> {
        let family = spec.family(FamilyId::Psd4xx);
        let p = family.psd4xx().ok_or(RulesError::NoProtocol)?;
        let params = Params::from_family(family);
        let bits = |id: &'static str| {
            family
                .bitfield(id)
                .cloned()
                .ok_or(RulesError::MissingBitfield { id })
        };
        Ok(Rules {
            layout: Layout::from_protocol(p, &params, &options)?,
            pkw: PkwRules::from_protocol(p, params.clone(), &options)?,
            record: RecordRules::from_protocol(p, params.clone(), &options)?,
            control: bits("control")?,
            status: bits("status")?,
            params,
            options,
        })
    }

    /// The settings in force (manual 3.5).
    pub fn options(&self) -> &Options {
        &self.options
    }

    /// Byte positions and orders of the modules (3.5).
    pub fn layout(&self) -> &Layout {
        &self.layout
    }

    /// The PKW channel (3.8).
    pub fn pkw(&self) -> &PkwRules {
        &self.pkw
    }

    /// Acyclic records (3.2.2).
    pub fn record(&self) -> &RecordRules {
        &self.record
    }

    /// The control word bits, par. 32 (3.7).
    pub fn control_bits(&self) -> &Bitfield {
        &self.control
    }

    /// The status word bits, par. 1 (3.6).
    pub fn status_bits(&self) -> &Bitfield {
        &self.status
    }

    /// The parameter table (3.3).
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The parameter with number `pnu` (3.3).
    pub fn parameter(&self, pnu: u32) -> Option<&Parameter> {
        self.params.get(pnu)
    }
}
