//! The reference drive of a PSD4xx or PSx3xx model as the device starts, built from the spec
//! and the family's model crate alone, and the cyclic server on it: what `drivespec sim`
//! serves and what a conformance suite's cases expect at their start.

use drivespec_cyclic::{CyclicDevice, Server};
pub use drivespec_psx3xx::model::BrakeKind;
use drivespec_spec::{DeviceModel, Family, FamilyId, Spec};

/// The PSD4xx model taken when none is named: an ungeared PSD 401 (the model the spec's
/// vectors assume).
pub const PSD4XX_DEFAULT_MODEL: &str = "PSD401-5V";

/// The PSx3xx model taken when none is named: the PSE 312-8 the spec's vectors assume
/// (`spec/psx3xx/vectors/isdu.toml`).
pub const PSX3XX_DEFAULT_MODEL: &str = "PSE312-8";

/// The model attribute holding the ISDU 79 model code (PSx3xx manual 3.1 ISDU 79).
const MODEL_CODE: &str = "device_model_code";

/// The ISDU 79 code the reference reports for the gearbox types whose code the manual does
/// not document (PSX-ERRATUM-016, reading "list-incomplete"): a device reporting its own code
/// differs in the cases that read ISDU 79 or the device ID, which then belong in its
/// expectations file.
pub const UNDOCUMENTED_CODE: u16 = 0;

/// Why a reference drive cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ReferenceError {
    /// The model named is none of the family's.
    #[error("unknown {family} model {query:?}; known: {}", known.join(", "))]
    UnknownModel {
        /// The family as the manuals write it (`PSD4xx`).
        family: &'static str,
        /// The model asked for.
        query: String,
        /// The family's model IDs.
        known: Vec<String>,
    },
    /// The PSx3xx model cannot have the brake option asked for (PSx3xx manual 5.11–5.13,
    /// spec `[[protocol.brake]] models`).
    #[error("PSx3xx model {model} cannot have a {brake} brake; the {brake} brake is for {} (manual {section})", models.join(", "))]
    NoSuchBrake {
        /// The model.
        model: String,
        /// The brake kind asked for.
        brake: &'static str,
        /// The model patterns that may have it.
        models: Vec<String>,
        /// The manual sections of the option.
        section: String,
    },
    /// The PSD4xx drive model cannot be built from the spec.
    #[error(transparent)]
    Psd4xx(#[from] drivespec_psd4xx::model::ModelError),
    /// The PSx3xx drive model cannot be built from the spec.
    #[error(transparent)]
    Psx3xx(#[from] drivespec_psx3xx::model::ModelError),
}

/// A family's reference drive for one model, in its start state.
#[derive(Debug, Clone)]
pub struct Reference<'s, D> {
    /// The model in the spec.
    pub model: &'s DeviceModel,
    /// The drive as the device starts.
    pub drive: D,
}

impl<'s, D: CyclicDevice<'s> + Clone + 's> Reference<'_, D> {
    /// A cyclic server on a copy of the drive (its state now is what `RESET` restores),
    /// greeting as `drivespec reference MODEL`.
    pub fn server(&self, family: FamilyId) -> Server<'s> {
        Server::new(
            &format!("drivespec reference {}", self.model.id),
            family.as_str(),
            Box::new(self.drive.clone()),
        )
    }
}

/// The family's model matching `query` (forgivingly), `default` when none is given.
fn model<'s>(
    family: &'s Family,
    name: &'static str,
    query: Option<&str>,
    default: &str,
) -> Result<&'s DeviceModel, ReferenceError> {
    let query = query.unwrap_or(default);
    family
        .model(query)
        .ok_or_else(|| ReferenceError::UnknownModel {
            family: name,
            query: query.to_owned(),
            known: family.models.iter().map(|m| m.id.clone()).collect(),
        })
}

/// The PSD4xx reference drive of `model` (default [`PSD4XX_DEFAULT_MODEL`]).
pub fn psd4xx<'s>(
    spec: &'s Spec,
    model: Option<&str>,
) -> Result<Reference<'s, drivespec_psd4xx::model::Drive>, ReferenceError> {
    use drivespec_psd4xx::model::{Drive, DriveConfig};
    let family = spec.family(FamilyId::Psd4xx);
    let model = self::model(family, "PSD4xx", model, PSD4XX_DEFAULT_MODEL)?;
    let drive = Drive::new(spec, DriveConfig::new(&model.id))?;
    Ok(Reference { model, drive })
}

/// The PSx3xx reference drive of `model` (default [`PSX3XX_DEFAULT_MODEL`]) with the brake
/// option `brake` (manual 5.11–5.13; a model the spec's `[[protocol.brake]]` does not offer it
/// for is an error); a gearbox type without a documented ISDU 79 code reports
/// [`UNDOCUMENTED_CODE`].
pub fn psx3xx<'s>(
    spec: &'s Spec,
    model: Option<&str>,
    brake: Option<BrakeKind>,
) -> Result<Reference<'s, drivespec_psx3xx::model::Drive<'s>>, ReferenceError> {
    use drivespec_psx3xx::model::{Drive, DriveConfig, ModelError};
    let family = spec.family(FamilyId::Psx3xx);
    let model = self::model(family, "PSx3xx", model, PSX3XX_DEFAULT_MODEL)?;
    let mut config = DriveConfig::new(&model.id);
    if model.attribute(MODEL_CODE).is_none() {
        // PSX-ERRATUM-016: the ISDU 79 code of this gearbox type is undocumented.
        config.model_code = Some(UNDOCUMENTED_CODE);
    }
    config.brake = brake;
    let drive = Drive::new(spec, config).map_err(|e| match e {
        ModelError::NoSuchBrake { model, brake } => {
            let option = family
                .psx3xx()
                .and_then(|p| p.brakes.iter().find(|b| b.kind == brake));
            ReferenceError::NoSuchBrake {
                model,
                brake,
                models: option.map(|b| b.models.clone()).unwrap_or_default(),
                section: option.map(|b| b.source.clone()).unwrap_or_default(),
            }
        }
        other => other.into(),
    })?;
    Ok(Reference { model, drive })
}
