//! The part of `drivespec spec check` that builds what the spec feeds: every conformance
//! suite's cases (each family, each model) and every family's simulator (each model), so an
//! edit that loads but breaks them fails the check with the family, the model and the reason.

use drivespec_conform::suite::{suite, Settings};
use drivespec_sim::{device, with_cyclic_server, DeviceOptions};
use drivespec_spec::{FamilyId, Spec};
use std::fmt;
use std::sync::Arc;

/// What could not be built from the spec.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// The conformance suite's cases.
    Cases,
    /// The simulator (`drivespec sim`) on the reference model.
    Simulator,
}

impl Part {
    fn as_str(self) -> &'static str {
        match self {
            Part::Cases => "the conformance cases cannot be generated",
            Part::Simulator => "the simulator cannot be built",
        }
    }
}

/// One family and model whose cases or simulator the spec cannot build.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BuildProblem {
    /// The family.
    pub family: FamilyId,
    /// The device model (its record in the family's model table).
    pub model: String,
    /// What failed.
    pub part: Part,
    /// Why.
    pub reason: String,
}

impl BuildProblem {
    /// The family's folder in the spec tree.
    pub fn file(&self) -> &'static str {
        self.family.as_str()
    }

    /// The record, as the loader names model records.
    pub fn record(&self) -> String {
        format!("model {:?}", self.model)
    }

    /// What is wrong.
    pub fn message(&self) -> String {
        format!("{}: {}", self.part.as_str(), self.reason)
    }
}

impl fmt::Display for BuildProblem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}: {}", self.file(), self.record(), self.message())
    }
}

/// Builds every suite and simulator of every model from `spec`; what failed, in family and
/// model order.
pub fn problems(spec: &Arc<Spec>) -> Vec<BuildProblem> {
    let mut out = Vec::new();
    for family in spec.families() {
        let id = family.id();
        for model in &family.models {
            let problem = |part, reason: String| BuildProblem {
                family: id,
                model: model.id.clone(),
                part,
                reason,
            };
            let settings = Settings {
                model: Some(model.id.clone()),
                ..Settings::default()
            };
            if let Err(e) = suite(spec, id, &settings) {
                out.push(problem(Part::Cases, e.to_string()));
            }
            let served = match id {
                FamilyId::Hpd => {
                    let opts = DeviceOptions {
                        model: Some(model.id.clone()),
                        ..DeviceOptions::default()
                    };
                    device(Arc::clone(spec), id, &opts).map(drop)
                }
                FamilyId::Psd4xx | FamilyId::Psx3xx => {
                    with_cyclic_server(spec, id, Some(&model.id), None, |_, _| ())
                }
            };
            if let Err(e) = served {
                out.push(problem(Part::Simulator, e.to_string()));
            }
        }
    }
    out
}
