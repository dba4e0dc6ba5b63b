//! The set of files a spec is loaded from: embedded at build time or read from a folder.

use crate::bounded::{read_text_bounded, ReadError};
use crate::error::{Problem, ProblemKind, SpecErrors};
use std::path::Path;

/// Largest spec file read from disk (bytes).
const MAX_FILE: u64 = 8 << 20;
/// Most files read from one spec tree.
const MAX_FILES: usize = 4096;
/// Deepest folder nesting followed.
const MAX_DEPTH: usize = 4;

mod builtin {
    include!(concat!(env!("OUT_DIR"), "/builtin.rs"));
}

/// The TOML files of a spec tree, by path relative to its root (`psd4xx/parameters.toml`).
#[derive(Debug, Clone, Default)]
pub struct SpecFiles {
    files: Vec<(String, String)>,
}

impl SpecFiles {
    /// The files embedded in this build.
    pub fn builtin() -> SpecFiles {
        let files = builtin::FILES
            .iter()
            .map(|(p, c)| ((*p).to_owned(), (*c).to_owned()))
            .collect();
        SpecFiles { files }
    }

    /// Reads every `*.toml` below `dir`, bounded in size, count and depth.
    pub fn read_dir(dir: &Path) -> Result<SpecFiles, SpecErrors> {
        let mut out = SpecFiles::default();
        let mut problems = Vec::new();
        if !dir.is_dir() {
            let kind = ProblemKind::Io {
                message: "not a directory".into(),
            };
            return Err(SpecErrors(vec![Problem::file(
                dir.display().to_string(),
                kind,
            )]));
        }
        walk(dir, dir, 0, &mut out, &mut problems);
        out.files.sort();
        if problems.is_empty() {
            Ok(out)
        } else {
            Err(SpecErrors(problems))
        }
    }

    /// Builds a set from (path, contents) pairs; used by tests and tools.
    pub fn from_pairs<I, P, C>(pairs: I) -> SpecFiles
    where
        I: IntoIterator<Item = (P, C)>,
        P: Into<String>,
        C: Into<String>,
    {
        let mut files: Vec<(String, String)> = pairs
            .into_iter()
            .map(|(p, c)| (p.into(), c.into()))
            .collect();
        files.sort();
        SpecFiles { files }
    }

    /// Replaces or adds one file.
    pub fn set(&mut self, path: &str, contents: &str) {
        match self.files.iter_mut().find(|(p, _)| p == path) {
            Some(entry) => entry.1 = contents.to_owned(),
            None => {
                self.files.push((path.to_owned(), contents.to_owned()));
                self.files.sort();
            }
        }
    }

    /// The contents of one file.
    pub fn get(&self, path: &str) -> Option<&str> {
        self.files
            .iter()
            .find(|(p, _)| p == path)
            .map(|(_, c)| c.as_str())
    }

    /// All files in path order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &str)> {
        self.files.iter().map(|(p, c)| (p.as_str(), c.as_str()))
    }
}

fn walk(root: &Path, dir: &Path, depth: usize, out: &mut SpecFiles, problems: &mut Vec<Problem>) {
    let name = dir.display().to_string();
    if depth > MAX_DEPTH {
        return;
    }
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) => {
            problems.push(Problem::file(
                name,
                ProblemKind::Io {
                    message: e.to_string(),
                },
            ));
            return;
        }
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let toml = path.extension().is_some_and(|e| e == "toml");
        let shown = path.display().to_string();
        if path.is_dir() {
            if toml {
                problems.push(Problem::file(
                    shown,
                    ProblemKind::Io {
                        message: "a folder named like a spec file".to_owned(),
                    },
                ));
            } else {
                walk(root, &path, depth + 1, out, problems);
            }
            continue;
        }
        if !toml {
            continue;
        }
        if out.files.len() >= MAX_FILES {
            problems.push(Problem::file(
                shown,
                ProblemKind::TooMany { limit: MAX_FILES },
            ));
            return;
        }
        match read_text_bounded(&path, MAX_FILE) {
            Ok(text) => {
                let rel = path.strip_prefix(root).unwrap_or(&path);
                out.files
                    .push((rel.to_string_lossy().replace('\\', "/"), text));
            }
            Err(ReadError::TooLarge { limit, .. }) => {
                problems.push(Problem::file(shown, ProblemKind::TooLarge { limit }))
            }
            Err(e) => problems.push(Problem::file(
                shown,
                ProblemKind::Io {
                    message: e.to_string(),
                },
            )),
        }
    }
}
