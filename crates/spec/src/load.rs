//! Parsing spec files into records, remembering which file each came from.

use crate::error::{Problem, ProblemKind};
use crate::{
    hpd, psd4xx, psx3xx, Bitfield, DeviceModel, Erratum, Family, FamilyId, FamilyInfo, ParamSet,
    Parameter, Protocol, Requirement, Scenario, SpecFiles, Vector,
};
use serde::de::DeserializeOwned;

/// Top-level arrays a common file may hold.
const COMMON_KEYS: [&str; 6] = [
    "parameter",
    "model",
    "param_set",
    "bitfield",
    "requirement",
    "erratum",
];

/// Parses all three families. Records that do not parse are left out and reported; the
/// families are returned whenever their `family.toml` and `protocol.toml` parse, so that
/// validation can report the remaining problems in the same pass.
pub(crate) fn load(files: &SpecFiles) -> (Option<[Family; 3]>, Vec<Problem>) {
    let mut problems = Vec::new();
    let [h, d, x] = FamilyId::ALL.map(|id| load_family(files, id, &mut problems));
    match (h, d, x) {
        (Some(h), Some(d), Some(x)) => (Some([h, d, x]), problems),
        _ => (None, problems),
    }
}

fn load_family(files: &SpecFiles, id: FamilyId, problems: &mut Vec<Problem>) -> Option<Family> {
    let dir = format!("{}/", id.as_str());
    let family_path = format!("{dir}family.toml");
    let protocol_path = format!("{dir}protocol.toml");
    let mut info = None;
    let mut protocol = None;
    let mut parameters = Vec::new();
    let mut models = Vec::new();
    let mut param_sets = Vec::new();
    let mut bitfields = Vec::new();
    let mut requirements = Vec::new();
    let mut errata = Vec::new();
    let mut vectors = Vec::new();
    let mut scenarios = Vec::new();

    for (path, text) in files.iter().filter(|(p, _)| p.starts_with(&dir)) {
        let Some(mut table) = parse(path, text, problems) else {
            continue;
        };
        if path == family_path {
            info = single::<FamilyInfo>(path, &mut table, "family", problems);
            if let Some(i) = &info {
                if i.id != id {
                    problems.push(Problem::file(
                        path,
                        ProblemKind::Invalid {
                            message: format!(
                                "family id {:?} in folder {:?}",
                                i.id.as_str(),
                                id.as_str()
                            ),
                        },
                    ));
                }
            }
        } else if path == protocol_path {
            protocol = match id {
                FamilyId::Hpd => single::<hpd::Protocol>(path, &mut table, "protocol", problems)
                    .map(|p| Protocol::Hpd(Box::new(p))),
                FamilyId::Psd4xx => {
                    single::<psd4xx::Protocol>(path, &mut table, "protocol", problems)
                        .map(|p| Protocol::Psd4xx(Box::new(p)))
                }
                FamilyId::Psx3xx => {
                    single::<psx3xx::Protocol>(path, &mut table, "protocol", problems)
                        .map(|p| Protocol::Psx3xx(Box::new(p)))
                }
            };
        } else if path.starts_with(&format!("{dir}vectors/")) {
            records(path, &mut table, "vector", &mut vectors, problems);
        } else if path.starts_with(&format!("{dir}scenarios/")) {
            records(path, &mut table, "scenario", &mut scenarios, problems);
        } else {
            records(path, &mut table, "parameter", &mut parameters, problems);
            records(path, &mut table, "model", &mut models, problems);
            records(path, &mut table, "param_set", &mut param_sets, problems);
            records(path, &mut table, "bitfield", &mut bitfields, problems);
            records(path, &mut table, "requirement", &mut requirements, problems);
            records(path, &mut table, "erratum", &mut errata, problems);
        }
        for key in table.keys() {
            let allowed = if path.starts_with(&format!("{dir}vectors/")) {
                "vector".to_owned()
            } else if path.starts_with(&format!("{dir}scenarios/")) {
                "scenario".to_owned()
            } else if path == family_path {
                "family".to_owned()
            } else if path == protocol_path {
                "protocol".to_owned()
            } else {
                COMMON_KEYS.join(", ")
            };
            problems.push(Problem::file(
                path,
                ProblemKind::Schema {
                    message: format!("unknown top-level key `{key}`, expected one of: {allowed}"),
                },
            ));
        }
    }
    if info.is_none() && !problems.iter().any(|p| p.file == family_path) {
        problems.push(Problem::file(
            &family_path,
            ProblemKind::Missing {
                what: "file".into(),
            },
        ));
    }
    if protocol.is_none() && !problems.iter().any(|p| p.file == protocol_path) {
        problems.push(Problem::file(
            &protocol_path,
            ProblemKind::Missing {
                what: "file".into(),
            },
        ));
    }
    crate::model_values::complete(&mut models, &param_sets, &parameters, problems);
    requirements.splice(0..0, crate::bitfield::rule_requirements(&bitfields));
    Some(Family {
        info: info?,
        parameters,
        models,
        bitfields,
        requirements,
        errata,
        vectors,
        scenarios,
        protocol: protocol?,
    })
}

fn parse(path: &str, text: &str, problems: &mut Vec<Problem>) -> Option<toml::Table> {
    match text.parse::<toml::Table>() {
        Ok(t) => Some(t),
        Err(e) => {
            let (line, column) = e.span().map(|s| line_col(text, s.start)).unwrap_or((0, 0));
            let message = e.message().to_owned();
            problems.push(Problem::file(
                path,
                ProblemKind::Syntax {
                    line,
                    column,
                    message,
                },
            ));
            None
        }
    }
}

/// 1-based line and column of a byte offset.
fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = text.get(..offset).unwrap_or(text);
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// Deserialises the table under `key` (removing it from `table`).
fn single<T: DeserializeOwned>(
    path: &str,
    table: &mut toml::Table,
    key: &str,
    problems: &mut Vec<Problem>,
) -> Option<T> {
    let Some(value) = table.remove(key) else {
        problems.push(Problem::file(
            path,
            ProblemKind::Missing {
                what: format!("table [{key}]"),
            },
        ));
        return None;
    };
    match value.try_into::<T>() {
        Ok(v) => Some(v),
        Err(e) => {
            problems.push(Problem::record(
                path,
                format!("[{key}]"),
                ProblemKind::Schema {
                    message: e.message().to_owned(),
                },
            ));
            None
        }
    }
}

/// A record type that remembers its file.
pub(crate) trait Record: DeserializeOwned {
    fn set_file(&mut self, file: &str);
}

macro_rules! record {
    ($($t:ty),*) => {$(
        impl Record for $t {
            fn set_file(&mut self, file: &str) {
                self.file = file.to_owned();
            }
        }
    )*};
}
record!(
    Parameter,
    DeviceModel,
    ParamSet,
    Bitfield,
    Requirement,
    Erratum,
    Vector,
    Scenario
);

/// Deserialises every element of the array `key` (removing it from `table`).
fn records<T: Record>(
    path: &str,
    table: &mut toml::Table,
    key: &str,
    out: &mut Vec<T>,
    problems: &mut Vec<Problem>,
) {
    let Some(value) = table.remove(key) else {
        return;
    };
    let toml::Value::Array(items) = value else {
        problems.push(Problem::file(
            path,
            ProblemKind::Schema {
                message: format!("`{key}` must be an array of tables ([[{key}]])"),
            },
        ));
        return;
    };
    for (i, item) in items.into_iter().enumerate() {
        let label = label(key, i, &item);
        match item.try_into::<T>() {
            Ok(mut r) => {
                r.set_file(path);
                out.push(r);
            }
            Err(e) => problems.push(Problem::record(
                path,
                label,
                ProblemKind::Schema {
                    message: e.message().to_owned(),
                },
            )),
        }
    }
}

/// `parameter "44"`, or `parameter #3` when the record has no id.
pub(crate) fn label(key: &str, index: usize, item: &toml::Value) -> String {
    match item.get("id") {
        Some(toml::Value::String(id)) => format!("{key} {id:?}"),
        _ => format!("{key} #{}", index + 1),
    }
}
