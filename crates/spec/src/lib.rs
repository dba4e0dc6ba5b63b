//! The machine-readable spec of the three manuals drivespec tests against.
//!
//! `spec/` (see `spec/SCHEMA.md`) is embedded at build time; [`Spec::load_dir`] reads another
//! tree so users can add device models without recompiling. Loading validates the whole
//! tree and reports every problem with its file and record. Nothing here panics on any
//! input; memory grows with the size of the files read.

mod bitfield;
pub mod bounded;
mod device_model;
mod erratum;
mod error;
mod family;
mod files;
pub mod gsdml;
pub mod hex;
mod load;
mod model_values;
mod parameter;
pub mod quote;
mod range;
mod requirement;
mod scenario;
mod validate;
mod vector;

pub mod hpd;
pub mod psd4xx;
pub mod psx3xx;

pub use bitfield::{BitRule, Bitfield, BitfieldBit, BitfieldValue, RuleAction};
pub use device_model::{DeviceModel, ModelParam, ParamSet};
pub use erratum::{Erratum, Reading, ReadingError, Readings};
pub use error::{Problem, ProblemKind, SpecErrors};
pub use family::{Family, FamilyId, FamilyInfo, Protocol};
pub use files::SpecFiles;
pub use parameter::{Access, DataType, EnumValue, ModeMeaning, Parameter, Resolved};
pub use range::Ranges;
pub use requirement::{Level, Requirement};
pub use scenario::{check_scenarios, Scenario, ScenarioError, TypedScenario};
pub use vector::{
    Body, BodyError, DirectParameterExpect, DirectParameterInput, FormulaExpect, FormulaInput,
    HpdFrameExpect, HpdFrameInput, HpdPlcBytesExpect, HpdPlcBytesInput, HpdPlcExpect, HpdPlcInput,
    IntOrText, IsduExpect, IsduInput, Number, OneOrMany, PkwExpect, PkwInput, PositionExpect,
    PositionInput, ProcessImageExpect, ProcessImageInput, RecordExpect, RecordInput,
    TimestampExpect, TimestampInput, Vector, VectorBody, VectorKind, VectorResult,
};

use std::path::Path;

/// The whole spec: one [`Family`] per manual.
#[derive(Debug)]
pub struct Spec {
    hpd: Family,
    psd4xx: Family,
    psx3xx: Family,
}

impl Spec {
    /// The spec embedded in this build (the workspace's `spec/` folder).
    pub fn builtin() -> Result<Spec, SpecErrors> {
        Spec::from_files(&SpecFiles::builtin())
    }

    /// Loads and validates a spec tree from a directory laid out like `spec/`.
    pub fn load_dir(dir: &Path) -> Result<Spec, SpecErrors> {
        let files = SpecFiles::read_dir(dir)?;
        Spec::from_files(&files)
    }

    /// Loads and validates a spec from a set of files (paths relative to the spec root).
    pub fn from_files(files: &SpecFiles) -> Result<Spec, SpecErrors> {
        let (families, mut problems) = load::load(files);
        let Some([hpd, psd4xx, psx3xx]) = families else {
            return Err(SpecErrors(problems));
        };
        let spec = Spec {
            hpd,
            psd4xx,
            psx3xx,
        };
        problems.extend(validate::validate(&spec));
        if problems.is_empty() {
            Ok(spec)
        } else {
            Err(SpecErrors(problems))
        }
    }

    /// The family of one manual.
    pub fn family(&self, id: FamilyId) -> &Family {
        match id {
            FamilyId::Hpd => &self.hpd,
            FamilyId::Psd4xx => &self.psd4xx,
            FamilyId::Psx3xx => &self.psx3xx,
        }
    }

    /// All families, in the order hpd, psd4xx, psx3xx.
    pub fn families(&self) -> [&Family; 3] {
        [&self.hpd, &self.psd4xx, &self.psx3xx]
    }
}
