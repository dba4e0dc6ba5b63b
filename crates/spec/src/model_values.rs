//! Completes each model's parameter values: the values of its `[[param_set]]`, then the ones
//! that follow from its attributes (a parameter's `model_max` and `model_default`). A value
//! written where it follows from an attribute is a problem, whether it agrees or not, so that
//! every number stands in the spec once.

use crate::error::{Problem, ProblemKind};
use crate::{DeviceModel, ModelParam, ParamSet, Parameter, Ranges};

/// The value `model_default` names for the top of the model's range.
const RANGE_MAX: &str = "max";

/// Fills in every model's parameter values; reports unknown or repeated sets and every
/// value that is missing, repeated or contradicting where an attribute gives it.
pub(crate) fn complete(
    models: &mut [DeviceModel],
    sets: &[ParamSet],
    params: &[Parameter],
    problems: &mut Vec<Problem>,
) {
    for (i, s) in sets.iter().enumerate() {
        if let Some(first) = sets.iter().take(i).find(|o| o.id == s.id) {
            problems.push(Problem::record(
                &s.file,
                format!("param_set {:?}", s.id),
                ProblemKind::Duplicate {
                    what: "param_set",
                    id: s.id.clone(),
                    first: first.file.clone(),
                },
            ));
        }
    }
    for m in models.iter_mut() {
        let rec = format!("model {:?}", m.id);
        let mut values: Vec<ModelParam> = Vec::new();
        if let Some(id) = &m.param_set {
            match sets.iter().find(|s| s.id == *id) {
                Some(s) => values.extend(s.param.iter().cloned()),
                None => problems.push(Problem::record(
                    &m.file,
                    rec.clone(),
                    ProblemKind::Dangling {
                        what: "param_set",
                        id: id.clone(),
                    },
                )),
            }
        }
        for own in std::mem::take(&mut m.params) {
            if values.iter().any(|v| v.id == own.id) {
                let message = format!(
                    "parameter {:?} is given by the model and by its param_set",
                    own.id
                );
                problems.push(Problem::record(&m.file, rec.clone(), invalid(message)));
            } else {
                values.push(own);
            }
        }
        for v in &mut values {
            if let Some(p) = params.iter().find(|p| p.id == v.id) {
                for message in derive(m, p, v) {
                    problems.push(Problem::record(&m.file, rec.clone(), invalid(message)));
                }
            }
        }
        m.params = values;
    }
}

fn invalid(message: String) -> ProblemKind {
    ProblemKind::Invalid { message }
}

/// Fills in the range and default of `v` that follow from the attributes of `m`; returns what
/// is wrong.
fn derive(m: &DeviceModel, p: &Parameter, v: &mut ModelParam) -> Vec<String> {
    let mut wrong = Vec::new();
    let attribute = |name: &str| -> Result<i64, String> {
        match m.attribute(name) {
            Some(x) if x.fract() == 0.0 && x.abs() < 9.0e15 => Ok(x as i64),
            Some(x) => Err(format!(
                "attribute {name} = {x} of the model is not a whole number (parameter {:?})",
                p.id
            )),
            None => Err(format!(
                "the model has no attribute {name}, which parameter {:?} takes its {} from",
                p.id,
                if p.model_max.as_deref() == Some(name) {
                    "maximum"
                } else {
                    "default"
                }
            )),
        }
    };
    match (&p.model_max, v.min, &v.range) {
        (Some(name), Some(min), None) => match attribute(name) {
            Ok(max) => {
                v.range = Some(Ranges::new(min, max));
                v.min = None;
            }
            Err(e) => wrong.push(e),
        },
        (Some(name), None, Some(range)) => {
            let max = range.max().unwrap_or_default();
            let says = attribute(name).map_or_else(|e| e, |a| format!("{name} = {a}"));
            wrong.push(format!(
                "range of parameter {:?} written out (maximum {max}); its maximum is the attribute {says}: give `min` only",
                p.id
            ));
        }
        (Some(_), Some(_), Some(_)) => {
            wrong.push(format!("parameter {:?} has both `min` and `range`", p.id))
        }
        (None, Some(_), _) => wrong.push(format!(
            "`min` for parameter {:?}, which takes no maximum from the model (no model_max)",
            p.id
        )),
        (Some(_), None, None) | (None, None, _) => {}
    }
    // A default taken from a range that could not be made follows from the problem above.
    let range_failed = !wrong.is_empty() && v.range.is_none();
    if let Some(source) = p
        .model_default
        .as_ref()
        .filter(|s| !(range_failed && *s == RANGE_MAX))
    {
        let derived = if source == RANGE_MAX {
            v.range.as_ref().and_then(Ranges::max).ok_or_else(|| {
                format!("parameter {:?} has no range to take its default from", p.id)
            })
        } else {
            attribute(source)
        };
        match (v.default, derived) {
            (Some(d), Ok(x)) => wrong.push(format!(
                "default {d} of parameter {:?} written out; it is {} ({x}): leave it out",
                p.id,
                if x == d {
                    "the same as"
                } else {
                    "contradicted by"
                }
                .to_owned()
                    + " "
                    + source
            )),
            (Some(_), Err(e)) | (None, Err(e)) => wrong.push(e),
            (None, Ok(x)) => v.default = Some(x),
        }
    }
    wrong
}
