//! Case selection (`--case`, `--skip`, `--level`) and the expectations file (`--expect`).
//!
//! Patterns are globs over case IDs; `*` also matches `/`, so `hpd/param/*/above-max` and
//! `hpd/*` work as expected. A pattern without `*`, `?` or `[` matches the ID itself and
//! everything under it (`hpd/frame` selects `hpd/frame/...`).

use drivespec_spec::bounded::read_text_bounded;
use drivespec_spec::quote::quote;
use drivespec_spec::Level;
use globset::{Glob, GlobMatcher};
use serde::Deserialize;
use std::path::Path;

/// Why a selection or expectations file is not usable.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum SelectError {
    /// A pattern is not a glob.
    #[error("bad case pattern {}: {why}", quote(.pattern))]
    Pattern {
        /// The pattern.
        pattern: String,
        /// Why.
        why: String,
    },
    /// A `--case` or `--skip` pattern matches no case of the families run.
    #[error("--{option} {}: matches no case{}", quote(.pattern), did_you_mean(.closest))]
    NoMatch {
        /// `case` or `skip`.
        option: &'static str,
        /// The pattern.
        pattern: String,
        /// The closest case IDs and groups, best first.
        closest: Vec<String>,
    },
    /// The patterns and `--level` leave no case to run.
    #[error("the selection (--case, --skip, --level) leaves no case to run")]
    Empty,
    /// The expectations file cannot be read or parsed.
    #[error("expectations file {file}: {why}")]
    Expect {
        /// The file.
        file: String,
        /// What is wrong.
        why: String,
    },
}

/// `; did you mean A, B or C?`, or nothing without candidates.
pub fn did_you_mean(closest: &[String]) -> String {
    match closest {
        [] => String::new(),
        [one] => format!("; did you mean {one}?"),
        [init @ .., last] => format!("; did you mean {} or {last}?", init.join(", ")),
    }
}

/// Similarity (Jaro-Winkler) from which a name counts as close to what was typed.
const CLOSE: f64 = 0.75;

/// The names of `candidates` closest to `typed` (at most three, best first, each at least
/// [`CLOSE`] alike); glob characters in `typed` are ignored.
pub fn closest<'a>(typed: &str, candidates: impl IntoIterator<Item = &'a str>) -> Vec<String> {
    let typed: String = typed
        .chars()
        .filter(|c| !matches!(c, '*' | '?' | '[' | ']' | '{' | '}'))
        .collect();
    let mut scored: Vec<(f64, &str)> = candidates
        .into_iter()
        .map(|c| (strsim::jaro_winkler(&typed, c), c))
        .filter(|(score, _)| *score >= CLOSE)
        .collect();
    scored.sort_by(|a, b| b.0.total_cmp(&a.0).then_with(|| a.1.cmp(b.1)));
    let mut out: Vec<String> = Vec::new();
    for (_, c) in scored {
        if out.len() == 3 {
            break;
        }
        if !out.iter().any(|o| o == c) {
            out.push(c.to_owned());
        }
    }
    out
}

/// Longest case pattern: case IDs are well under 100 characters, and a glob's matcher grows
/// with its length.
const MAX_PATTERN: usize = 200;
/// Largest expectations file read (bytes).
const MAX_EXPECT_FILE: u64 = 1 << 20;
/// Longest reason of a known failure (it is copied into the reports of every case it matches).
const MAX_REASON: usize = 1000;

/// One case pattern.
#[derive(Debug, Clone)]
pub struct Pattern {
    text: String,
    glob: Option<GlobMatcher>,
}

impl Pattern {
    /// Parses a pattern.
    pub fn new(text: &str) -> Result<Pattern, SelectError> {
        let text = text.trim().trim_end_matches('/').to_owned();
        if text.chars().count() > MAX_PATTERN {
            return Err(SelectError::Pattern {
                pattern: text.clone(),
                why: format!("longer than {MAX_PATTERN} characters"),
            });
        }
        let glob = if text.contains(['*', '?', '[', '{']) {
            Some(
                Glob::new(&text)
                    .map_err(|e| SelectError::Pattern {
                        pattern: text.clone(),
                        why: e.kind().to_string(),
                    })?
                    .compile_matcher(),
            )
        } else {
            None
        };
        Ok(Pattern { text, glob })
    }

    /// Whether the pattern selects case `id`.
    pub fn matches(&self, id: &str) -> bool {
        match &self.glob {
            Some(g) => g.is_match(id),
            None => {
                id == self.text
                    || id
                        .strip_prefix(self.text.as_str())
                        .is_some_and(|rest| rest.starts_with('/'))
            }
        }
    }

    /// The pattern as given.
    pub fn as_str(&self) -> &str {
        &self.text
    }
}

/// `--level`: which levels run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LevelFilter {
    /// Only `must` cases.
    Must,
    /// `must` and `should` cases (the default).
    #[default]
    Should,
}

impl LevelFilter {
    /// Whether a case of `level` runs.
    pub fn admits(self, level: Level) -> bool {
        match self {
            LevelFilter::Must => level == Level::Must,
            LevelFilter::Should => level != Level::Informative,
        }
    }

    /// `must` or `should`.
    pub fn as_str(self) -> &'static str {
        match self {
            LevelFilter::Must => "must",
            LevelFilter::Should => "should",
        }
    }
}

/// Which cases run.
#[derive(Debug, Clone, Default)]
pub struct Selection {
    /// `--case`: run only matching cases (all when empty).
    pub include: Vec<Pattern>,
    /// `--skip`: never run matching cases.
    pub exclude: Vec<Pattern>,
    /// `--level`.
    pub level: LevelFilter,
}

impl Selection {
    /// A selection from pattern texts.
    pub fn new(
        include: &[String],
        exclude: &[String],
        level: LevelFilter,
    ) -> Result<Selection, SelectError> {
        Ok(Selection {
            include: include
                .iter()
                .map(|p| Pattern::new(p))
                .collect::<Result<_, _>>()?,
            exclude: exclude
                .iter()
                .map(|p| Pattern::new(p))
                .collect::<Result<_, _>>()?,
            level,
        })
    }

    /// Checks that every `--case` and `--skip` pattern matches one of `ids` (the cases of the
    /// families run); the error of one that does not names the closest IDs and groups.
    pub fn check_patterns(&self, ids: &[&str]) -> Result<(), SelectError> {
        let options = [("case", &self.include), ("skip", &self.exclude)];
        for (option, patterns) in options {
            for p in patterns {
                if ids.iter().any(|id| p.matches(id)) {
                    continue;
                }
                let mut names: Vec<&str> = Vec::new();
                for id in ids {
                    let ends = id.match_indices('/').map(|(i, _)| i).chain([id.len()]);
                    names.extend(ends.filter_map(|end| id.get(..end)));
                }
                names.sort_unstable();
                names.dedup();
                return Err(SelectError::NoMatch {
                    option,
                    pattern: p.as_str().to_owned(),
                    closest: closest(p.as_str(), names),
                });
            }
        }
        Ok(())
    }

    /// Whether case `id` of `level` runs.
    pub fn admits(&self, id: &str, level: Level) -> bool {
        self.level.admits(level)
            && (self.include.is_empty() || self.include.iter().any(|p| p.matches(id)))
            && !self.exclude.iter().any(|p| p.matches(id))
    }
}

/// One known failure of the expectations file.
#[derive(Debug, Clone, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct KnownFailure {
    /// Case ID or pattern.
    pub case: String,
    /// Why the failure is accepted (required, not empty).
    pub reason: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExpectFile {
    #[serde(default)]
    failure: Vec<KnownFailure>,
}

/// The expectations file: cases known to fail, each with a reason.
///
/// ```toml
/// [[failure]]
/// case = "hpd/param/*/above-max"
/// reason = "the drive clamps values outside the range instead of ignoring them"
/// ```
#[derive(Debug, Clone, Default)]
pub struct Expectations {
    /// The file it came from.
    pub file: Option<String>,
    entries: Vec<(KnownFailure, Pattern)>,
}

impl Expectations {
    /// Reads and checks a file.
    pub fn load(path: &Path) -> Result<Expectations, SelectError> {
        let file = path.display().to_string();
        let text = read_text_bounded(path, MAX_EXPECT_FILE).map_err(|e| SelectError::Expect {
            file: file.clone(),
            why: e.to_string(),
        })?;
        Expectations::parse(&text, &file)
    }

    /// Parses expectations text; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Expectations, SelectError> {
        let bad = |why: String| SelectError::Expect {
            file: file.to_owned(),
            why,
        };
        let parsed: ExpectFile = toml::from_str(text).map_err(|e| bad(e.message().to_owned()))?;
        let mut entries = Vec::new();
        for (i, f) in parsed.failure.into_iter().enumerate() {
            if f.reason.trim().is_empty() {
                return Err(bad(format!(
                    "failure {} ({}): the reason is empty",
                    i + 1,
                    quote(&f.case)
                )));
            }
            if f.reason.chars().count() > MAX_REASON {
                return Err(bad(format!(
                    "failure {} ({}): the reason is longer than {MAX_REASON} characters",
                    i + 1,
                    quote(&f.case)
                )));
            }
            let p = Pattern::new(&f.case).map_err(|e| bad(format!("failure {}: {e}", i + 1)))?;
            entries.push((f, p));
        }
        Ok(Expectations {
            file: Some(file.to_owned()),
            entries,
        })
    }

    /// The known failure covering case `id`, if any.
    pub fn known(&self, id: &str) -> Option<&KnownFailure> {
        self.entries
            .iter()
            .find(|(_, p)| p.matches(id))
            .map(|(f, _)| f)
    }

    /// Entries that match none of `ids`.
    pub fn stale<'a>(&'a self, ids: &[&str]) -> Vec<&'a KnownFailure> {
        self.entries
            .iter()
            .filter(|(_, p)| !ids.iter().any(|id| p.matches(id)))
            .map(|(f, _)| f)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patterns_match_ids_prefixes_and_globs() {
        let p = Pattern::new("hpd/frame").unwrap();
        assert!(p.matches("hpd/frame"));
        assert!(p.matches("hpd/frame/read-lun-1"));
        assert!(!p.matches("hpd/frames"));
        let g = Pattern::new("hpd/param/*/above-max").unwrap();
        assert!(g.matches("hpd/param/Pr33/above-max"));
        assert!(g.matches("hpd/param/Pr50/mode-12/above-max"));
        assert!(!g.matches("hpd/param/Pr33/max"));
        assert!(Pattern::new("hpd/[").is_err());
    }

    #[test]
    fn selection_and_levels() {
        let s = Selection::new(
            &["hpd/frame".into()],
            &["hpd/frame/foreign-*".into()],
            LevelFilter::Must,
        )
        .unwrap();
        assert!(s.admits("hpd/frame/read-lun-1", Level::Must));
        assert!(!s.admits("hpd/frame/read-lun-1", Level::Should));
        assert!(!s.admits("hpd/frame/foreign-address/3", Level::Must));
        assert!(!s.admits("hpd/param/Pr33/read", Level::Must));
    }

    #[test]
    fn expectations_need_reasons() {
        let e = Expectations::parse(
            "[[failure]]\ncase = \"hpd/param/*\"\nreason = \"clamps\"\n",
            "x.toml",
        )
        .unwrap();
        assert_eq!(e.known("hpd/param/Pr33/max").unwrap().reason, "clamps");
        assert!(e.known("hpd/frame/x").is_none());
        assert_eq!(e.stale(&["hpd/frame/x"]).len(), 1);
        assert!(Expectations::parse("[[failure]]\ncase = \"a\"\nreason = \" \"\n", "x").is_err());
        assert!(Expectations::parse("[[failure]]\ncase = \"a\"\n", "x").is_err());
        assert!(Expectations::parse(
            "[[failure]]\ncase = \"a\"\nreason = \"r\"\nextra = 1\n",
            "x"
        )
        .is_err());
    }
}
