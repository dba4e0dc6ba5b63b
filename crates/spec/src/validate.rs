//! Consistency rules over a loaded spec (see `spec/SCHEMA.md`, "The loader rejects …").

use crate::error::{Problem, ProblemKind};
use crate::{Family, Level, Parameter, Spec};
use std::collections::BTreeMap;

/// Every rule violated by the spec, in family and file order.
pub(crate) fn validate(spec: &Spec) -> Vec<Problem> {
    let mut problems = Vec::new();
    for family in spec.families() {
        let mut v = Validator {
            family,
            problems: &mut problems,
        };
        v.unique_ids();
        v.parameters();
        v.addresses();
        v.models();
        v.bitfields();
        v.requirements();
        v.errata();
        v.vectors();
        v.scenarios();
    }
    problems
}

struct Validator<'a> {
    family: &'a Family,
    problems: &'a mut Vec<Problem>,
}

impl Validator<'_> {
    fn push(&mut self, file: &str, record: String, kind: ProblemKind) {
        self.problems.push(Problem::record(file, record, kind));
    }

    fn dangling(&mut self, file: &str, record: String, what: &'static str, id: &str) {
        self.push(
            file,
            record,
            ProblemKind::Dangling {
                what,
                id: id.to_owned(),
            },
        );
    }

    fn check_unique<'k>(
        &mut self,
        what: &'static str,
        items: impl Iterator<Item = (String, &'k str, String)>,
    ) {
        let mut seen: BTreeMap<String, &str> = BTreeMap::new();
        for (key, file, record) in items {
            if let Some(first) = seen.get(&key) {
                let first = (*first).to_owned();
                self.push(
                    file,
                    record,
                    ProblemKind::Duplicate {
                        what,
                        id: key,
                        first,
                    },
                );
            } else {
                seen.insert(key, file);
            }
        }
    }

    fn unique_ids(&mut self) {
        let f = self.family;
        self.check_unique(
            "parameter id",
            f.parameters
                .iter()
                .map(|p| (p.id.to_lowercase(), p.file.as_str(), rec_p(p))),
        );
        self.check_unique(
            "parameter number",
            f.parameters.iter().map(|p| {
                let key = match p.subindex {
                    Some(s) => format!("{}.{s}", p.number),
                    None => p.number.to_string(),
                };
                (key, p.file.as_str(), rec_p(p))
            }),
        );
        self.check_unique(
            "model name",
            f.models.iter().flat_map(|m| {
                let rec = format!("model {:?}", m.id);
                let mut names: Vec<String> = m.folded_names().collect();
                names.sort();
                names.dedup();
                names
                    .into_iter()
                    .map(move |n| (n, m.file.as_str(), rec.clone()))
            }),
        );
        self.check_unique(
            "bitfield id",
            f.bitfields.iter().map(|b| {
                (
                    b.id.clone(),
                    b.file.as_str(),
                    format!("bitfield {:?}", b.id),
                )
            }),
        );
        self.check_unique(
            "requirement id",
            f.requirements.iter().map(|r| {
                (
                    r.id.clone(),
                    r.file.as_str(),
                    format!("requirement {:?}", r.id),
                )
            }),
        );
        self.check_unique(
            "erratum id",
            f.errata
                .iter()
                .map(|e| (e.id.clone(), e.file.as_str(), format!("erratum {:?}", e.id))),
        );
        self.check_unique(
            "vector id",
            f.vectors
                .iter()
                .map(|v| (v.id.clone(), v.file.as_str(), format!("vector {:?}", v.id))),
        );
        self.check_unique(
            "scenario id",
            f.scenarios.iter().map(|s| {
                (
                    s.id.clone(),
                    s.file.as_str(),
                    format!("scenario {:?}", s.id),
                )
            }),
        );
    }

    fn parameters(&mut self) {
        let f = self.family;
        for p in &f.parameters {
            let rec = rec_p(p);
            let conflicts = [
                (
                    p.range_model && p.range.is_some(),
                    "a range here and range_model: the models give the range",
                ),
                (
                    p.model_max.is_some() && !p.range_model,
                    "model_max without range_model",
                ),
                (
                    p.model_default.is_some() && !p.default_model,
                    "model_default without default_model",
                ),
            ];
            for (_, message) in conflicts.iter().filter(|c| c.0) {
                let message = (*message).to_owned();
                self.push(&p.file, rec.clone(), ProblemKind::Invalid { message });
            }
            let scales = p
                .scale
                .iter()
                .chain(p.modes.iter().filter_map(|m| m.scale.as_ref()));
            for scale in scales.filter(|s| !s.is_finite() || **s == 0.0) {
                let message = format!("scale {scale} is not a finite number other than 0");
                self.push(&p.file, rec.clone(), ProblemKind::Invalid { message });
            }
            if let (Some(range), Some((lo, hi))) = (&p.range, p.data_type.bounds()) {
                for [min, max] in range.intervals() {
                    if min > max {
                        self.push(
                            &p.file,
                            rec.clone(),
                            ProblemKind::BadRange {
                                min: *min,
                                max: *max,
                                reason: "has min > max",
                            },
                        );
                    } else if *min < lo || *max > hi {
                        self.push(
                            &p.file,
                            rec.clone(),
                            ProblemKind::BadRange {
                                min: *min,
                                max: *max,
                                reason: "exceeds the data type",
                            },
                        );
                    }
                }
            }
            if p.data_type == crate::DataType::String && p.default.is_some() {
                self.push(
                    &p.file,
                    rec.clone(),
                    ProblemKind::Invalid {
                        message: "a string parameter takes default_text, not default".into(),
                    },
                );
            }
            if let Some(s) = p.size {
                if ![1, 2, 4].contains(&s) {
                    self.push(
                        &p.file,
                        rec.clone(),
                        ProblemKind::Invalid {
                            message: format!("size {s}, expected 1, 2 or 4"),
                        },
                    );
                }
            }
            if p.address.is_some() != p.size.is_some() {
                self.push(
                    &p.file,
                    rec.clone(),
                    ProblemKind::Invalid {
                        message: "address and size go together".into(),
                    },
                );
            }
            for m in &p.modes {
                if let (Some(range), Some(d)) = (&m.range, m.default) {
                    if !range.contains(d) {
                        let range = range.to_string();
                        self.push(
                            &p.file,
                            rec.clone(),
                            ProblemKind::OutOfRange {
                                what: "mode default",
                                value: d,
                                range,
                                model: None,
                            },
                        );
                    }
                }
            }
            // Defaults and enumerated values inside the range, for the parameter and each model.
            let mut contexts: Vec<Option<&crate::DeviceModel>> = vec![None];
            contexts.extend(f.models.iter().map(Some));
            for model in contexts {
                if model.is_none() && (p.range_model || p.default_model) {
                    continue;
                }
                let r = f.resolve(p, model);
                let Some(range) = r.range else { continue };
                let model_id = model.map(|m| m.id.clone());
                if let Some(d) = r.default {
                    if !range.contains(d) {
                        let kind = ProblemKind::OutOfRange {
                            what: "default",
                            value: d,
                            range: range.to_string(),
                            model: model_id.clone(),
                        };
                        self.push(&p.file, rec.clone(), kind);
                    }
                }
                if model.is_none() {
                    for v in &p.values {
                        if !range.contains(v.value) {
                            let kind = ProblemKind::OutOfRange {
                                what: "enumerated value",
                                value: v.value,
                                range: range.to_string(),
                                model: None,
                            };
                            self.push(&p.file, rec.clone(), kind);
                        }
                    }
                }
            }
        }
    }

    fn addresses(&mut self) {
        let mut spans: Vec<(u32, u32, &Parameter)> = self
            .family
            .parameters
            .iter()
            .filter_map(|p| Some((p.address?, p.address?.saturating_add(p.size?), p)))
            .collect();
        spans.sort_by_key(|(a, _, _)| *a);
        for pair in spans.windows(2) {
            if let [(_, end_a, a), (start_b, end_b, b)] = pair {
                if start_b < end_a {
                    let kind = ProblemKind::AddressOverlap {
                        address: *start_b,
                        end: *end_b,
                        other: a.id.clone(),
                    };
                    self.push(&b.file, rec_p(b), kind);
                }
            }
        }
    }

    fn models(&mut self) {
        let f = self.family;
        for m in &f.models {
            let rec = format!("model {:?}", m.id);
            for mp in &m.params {
                if f.parameters.iter().all(|p| p.id != mp.id) {
                    self.dangling(&m.file, rec.clone(), "parameter", &mp.id);
                }
            }
            for p in &f.parameters {
                let given = m.params.iter().find(|mp| mp.id == p.id);
                if p.range_model && given.and_then(|g| g.range.as_ref()).is_none() {
                    self.push(
                        &m.file,
                        rec.clone(),
                        ProblemKind::ModelValueMissing {
                            model: m.id.clone(),
                            param: p.id.clone(),
                            what: "range",
                        },
                    );
                }
                if p.default_model && given.and_then(|g| g.default).is_none() {
                    self.push(
                        &m.file,
                        rec.clone(),
                        ProblemKind::ModelValueMissing {
                            model: m.id.clone(),
                            param: p.id.clone(),
                            what: "default",
                        },
                    );
                }
            }
        }
    }

    fn bitfields(&mut self) {
        let f = self.family;
        let mut stated: Vec<(&str, Level)> = Vec::new();
        for b in &f.bitfields {
            let rec = format!("bitfield {:?}", b.id);
            if f.parameter(&b.param).is_none() {
                self.dangling(&b.file, rec.clone(), "parameter", &b.param);
            }
            if ![8, 16, 32].contains(&b.width) {
                self.push(
                    &b.file,
                    rec.clone(),
                    ProblemKind::Invalid {
                        message: format!("width {}, expected 8, 16 or 32", b.width),
                    },
                );
            }
            if let Some(circle) = b.priority_cycle() {
                let circle: Vec<String> = circle.iter().map(u32::to_string).collect();
                let message = format!(
                    "priority_over goes round in a circle (bit {}): no bit wins",
                    circle.join(" over ")
                );
                self.push(&b.file, rec.clone(), ProblemKind::Invalid { message });
            }
            let mut seen = Vec::new();
            for bit in &b.bits {
                let brec = format!("{rec} bit {}", bit.bit);
                if bit.bit >= b.width {
                    self.push(
                        &b.file,
                        brec.clone(),
                        ProblemKind::Invalid {
                            message: format!("bit {} outside width {}", bit.bit, b.width),
                        },
                    );
                }
                if seen.contains(&bit.bit) {
                    self.push(
                        &b.file,
                        brec.clone(),
                        ProblemKind::Duplicate {
                            what: "bit",
                            id: bit.bit.to_string(),
                            first: b.file.clone(),
                        },
                    );
                }
                seen.push(bit.bit);
                for rule in &bit.rules {
                    match stated.iter().find(|(id, _)| *id == rule.requirement) {
                        Some((_, level)) => {
                            if let Some(message) = restated(rule, *level) {
                                self.push(&b.file, brec.clone(), ProblemKind::Invalid { message });
                            }
                        }
                        None => stated.push((rule.requirement.as_str(), rule.level)),
                    }
                    if !is_token(&rule.trigger) {
                        self.push(
                            &b.file,
                            brec.clone(),
                            ProblemKind::BadId {
                                id: rule.trigger.clone(),
                                pattern: "a kebab-case token",
                            },
                        );
                    }
                    for other in &rule.priority_over {
                        if b.bit(*other).is_none() {
                            self.dangling(&b.file, brec.clone(), "bit", &other.to_string());
                        }
                    }
                }
            }
        }
    }

    fn requirements(&mut self) {
        let f = self.family;
        let prefix = f.id().requirement_prefix();
        for r in &f.requirements {
            let rec = format!("requirement {:?}", r.id);
            if !is_requirement_id(&r.id, prefix) {
                self.push(
                    &r.file,
                    rec.clone(),
                    ProblemKind::BadId {
                        id: r.id.clone(),
                        pattern: "^(HPD|PSD|PSX)-[A-Z0-9]+(-[A-Z0-9]+)+$ with the family's prefix",
                    },
                );
            }
            for p in &r.params {
                if f.parameter(p).is_none() {
                    self.dangling(&r.file, rec.clone(), "parameter", p);
                }
            }
            let message = match (r.observable, r.reason.as_deref().map(str::trim)) {
                (false, None | Some("")) => {
                    Some("`observable = false` needs a `reason` saying why no check can see it")
                }
                (true, Some(_)) => Some("a `reason` is given only with `observable = false`"),
                _ => None,
            };
            if let Some(message) = message {
                let message = message.to_owned();
                self.push(&r.file, rec.clone(), ProblemKind::Invalid { message });
            }
        }
    }

    fn errata(&mut self) {
        let f = self.family;
        let prefix = format!("{}-ERRATUM-", f.id().requirement_prefix());
        for e in &f.errata {
            let rec = format!("erratum {:?}", e.id);
            if !e.id.starts_with(&prefix) {
                self.push(
                    &e.file,
                    rec.clone(),
                    ProblemKind::BadId {
                        id: e.id.clone(),
                        pattern: "<PREFIX>-ERRATUM-<NNN>",
                    },
                );
            }
            if e.readings.len() < 2 {
                self.push(
                    &e.file,
                    rec.clone(),
                    ProblemKind::Invalid {
                        message: format!("{} reading(s), expected at least 2", e.readings.len()),
                    },
                );
            }
            if e.adopted_reading().is_none() {
                self.dangling(&e.file, rec.clone(), "reading", &e.adopted);
            }
            for r in &e.requirements {
                if f.requirement(r).is_none() {
                    self.dangling(&e.file, rec.clone(), "requirement", r);
                }
            }
        }
    }

    fn scenarios(&mut self) {
        let f = self.family;
        for s in &f.scenarios {
            let rec = format!("scenario {:?}", s.id);
            if s.requirements.is_empty() {
                let message = "a scenario names at least one requirement".to_owned();
                self.push(&s.file, rec.clone(), ProblemKind::Invalid { message });
            }
            for r in &s.requirements {
                if f.requirement(r).is_none() {
                    self.dangling(&s.file, rec.clone(), "requirement", r);
                }
            }
            if s.steps.is_empty() {
                let message = "a scenario needs at least one step".to_owned();
                self.push(&s.file, rec.clone(), ProblemKind::Invalid { message });
            }
        }
    }

    fn vectors(&mut self) {
        let f = self.family;
        for v in &f.vectors {
            let rec = format!("vector {:?}", v.id);
            for r in &v.requirements {
                if f.requirement(r).is_none() {
                    self.dangling(&v.file, rec.clone(), "requirement", r);
                }
            }
            if let Some(m) = &v.model {
                if f.model(m).is_none() {
                    self.dangling(&v.file, rec.clone(), "model", m);
                }
            }
            for name in vector_params(&v.body) {
                if f.parameter(&name).is_none() {
                    self.dangling(&v.file, rec.clone(), "parameter", &name);
                }
            }
            if let crate::VectorBody::Sequence(b) = &v.body {
                if !b.input.contains_key("steps") && !b.expect.contains_key("rows") {
                    let message =
                        "a sequence vector needs input `steps` or expect `rows`".to_owned();
                    self.push(&v.file, rec.clone(), ProblemKind::Invalid { message });
                }
            }
        }
    }
}

/// Parameters a vector names: the HPD `param` of a request, the keys of `params` (`Pr64`),
/// of `bits` (`b99.14` names Pb99/Pr99) and of `dwords` (`Pr64:65` names Pr64 and Pr65), and
/// the parameter ids keying `state` and `saved`.
fn vector_params(body: &crate::VectorBody) -> Vec<String> {
    use crate::VectorBody as B;
    let keys = |m: &Option<BTreeMap<String, i64>>| -> Vec<String> {
        m.iter().flat_map(|m| m.keys().cloned()).collect()
    };
    let bits = |m: &Option<BTreeMap<String, i64>>| -> Vec<String> {
        keys(m)
            .iter()
            .filter_map(|k| {
                k.strip_prefix('b')?
                    .split_once('.')
                    .map(|(n, _)| n.to_owned())
            })
            .collect()
    };
    match body {
        B::HpdFrame(b) => b.input.param.iter().cloned().collect(),
        B::HpdPlc(b) => {
            let dwords = b.expect.dwords.iter().flat_map(|m| m.keys()).flat_map(|k| {
                let (lo, hi) = k.split_once(':').unwrap_or((k, ""));
                let prefix: String = lo.chars().take_while(|c| c.is_ascii_alphabetic()).collect();
                [
                    Some(lo.to_owned()),
                    (!hi.is_empty()).then(|| format!("{prefix}{hi}")),
                ]
            });
            [
                keys(&b.input.params),
                keys(&b.expect.params),
                bits(&b.input.bits),
                bits(&b.expect.bits),
            ]
            .concat()
            .into_iter()
            .chain(dwords.flatten())
            .collect()
        }
        B::Pkw(b) => [state_keys(&b.input.state), keys(&b.expect.state)].concat(),
        B::Record(b) => [state_keys(&b.input.state), keys(&b.expect.state)].concat(),
        B::Isdu(b) => [
            keys(&b.input.state),
            keys(&b.expect.state),
            keys(&b.expect.saved),
        ]
        .concat(),
        _ => Vec::new(),
    }
}

/// The parameter ids keying a `state` table.
fn state_keys(state: &Option<BTreeMap<String, crate::IntOrText>>) -> Vec<String> {
    state.iter().flat_map(|m| m.keys().cloned()).collect()
}

fn rec_p(p: &Parameter) -> String {
    format!("parameter {:?}", p.id)
}

/// `abc-def-1`.
fn is_token(s: &str) -> bool {
    !s.is_empty()
        && !s.starts_with('-')
        && !s.ends_with('-')
        && s.chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
}

/// `^(HPD|PSD|PSX)-[A-Z0-9]+(-[A-Z0-9]+)+$` with the family's prefix.
fn is_requirement_id(id: &str, prefix: &str) -> bool {
    let mut parts = id.split('-');
    parts.next() == Some(prefix)
        && id.split('-').count() >= 3
        && parts.all(|p| {
            !p.is_empty()
                && p.chars()
                    .all(|c| c.is_ascii_uppercase() || c.is_ascii_digit())
        })
}

/// What a rule naming a requirement that an earlier rule created must not say: another
/// level, or the requirement's statement, source, parameters or note.
fn restated(rule: &crate::BitRule, level: Level) -> Option<String> {
    let id = &rule.requirement;
    if rule.level != level {
        return Some(format!(
            "level {} for requirement {id:?}, which an earlier rule gives level {}",
            rule.level.as_str(),
            level.as_str()
        ));
    }
    let keys = [
        ("statement", rule.statement.is_some()),
        ("source", rule.source.is_some()),
        ("params", !rule.params.is_empty()),
        ("note", rule.note.is_some()),
        ("reason", rule.reason.is_some()),
    ];
    keys.iter().find(|(_, set)| *set).map(|(key, _)| {
        format!("`{key}` for requirement {id:?}, which an earlier rule already states")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requirement_ids() {
        assert!(is_requirement_id("PSD-STS-10-RESET", "PSD"));
        assert!(is_requirement_id("HPD-FRAME-004", "HPD"));
        assert!(!is_requirement_id("HPD-FRAME", "HPD"));
        assert!(!is_requirement_id("PSD-FRAME-004", "HPD"));
        assert!(!is_requirement_id("HPD-frame-004", "HPD"));
        assert!(!is_requirement_id("HPD--004", "HPD"));
    }
}
