//! Every requirement and erratum ID named in the code exists in the spec, so a renamed or
//! merged ID cannot leave a check pointing at nothing.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

use drivespec_spec::{FamilyId, Spec};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        let name = e.file_name();
        if p.is_dir() && name != "target" && name != "corpus" {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// An ID named in code: exact (`HPD-FRAME-004`) or a glob over IDs (`PSD-STS-0-*`).
#[derive(Debug, PartialEq)]
enum Named {
    Id(String),
    Prefix(String),
}

/// IDs such as `HPD-FRAME-004` or `PSD-ERRATUM-059`, and globs such as `PSD-STS-0-*`, in a text.
fn ids(text: &str) -> Vec<Named> {
    let mut found = Vec::new();
    let bytes = text.as_bytes();
    for prefix in ["HPD-", "PSD-", "PSX-"] {
        let mut from = 0;
        while let Some(i) = text[from..].find(prefix) {
            let start = from + i;
            let boundary = start == 0
                || !(bytes[start - 1].is_ascii_alphanumeric() || bytes[start - 1] == b'-');
            let end = text[start..]
                .find(|c: char| !(c.is_ascii_uppercase() || c.is_ascii_digit() || c == '-'))
                .map_or(text.len(), |e| start + e);
            let id = text[start..end].trim_end_matches('-');
            // `-FIXTURE-` IDs are deliberately absent: tests use them to build broken specs.
            let glob = text[end..].starts_with('*');
            if boundary && id.split('-').count() >= 3 && !id.contains("-FIXTURE-") {
                found.push(if glob {
                    Named::Prefix(format!("{id}-"))
                } else {
                    Named::Id(id.to_owned())
                });
            }
            from = end.max(start + 1);
        }
    }
    found
}

#[test]
fn ids_named_in_code_exist() {
    let spec = Spec::builtin().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut files = Vec::new();
    for dir in ["crates", "fuzz", "tests"] {
        rust_files(&root.join(dir), &mut files);
    }
    // The spec crate's own sources and tests use made-up IDs to show the format.
    files.retain(|f| !f.starts_with(root.join("crates/spec")));
    let mut missing = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for named in ids(&text) {
            let (Named::Id(id) | Named::Prefix(id)) = &named;
            let family = match &id[..3] {
                "HPD" => FamilyId::Hpd,
                "PSD" => FamilyId::Psd4xx,
                _ => FamilyId::Psx3xx,
            };
            let fam = spec.family(family);
            let mut all = fam
                .requirements
                .iter()
                .map(|r| r.id.as_str())
                .chain(fam.errata.iter().map(|e| e.id.as_str()));
            let known = match &named {
                Named::Id(id) => all.any(|known| known == id),
                Named::Prefix(prefix) => all.any(|known| known.starts_with(prefix.as_str())),
            };
            if !known {
                let shown = match &named {
                    Named::Id(id) => id.clone(),
                    Named::Prefix(prefix) => format!("{prefix}* (matches nothing)"),
                };
                missing.push(format!(
                    "{}: {shown}",
                    f.strip_prefix(&root).unwrap_or(f).display()
                ));
            }
        }
    }
    missing.sort();
    missing.dedup();
    assert!(
        missing.is_empty(),
        "IDs named in code but absent from spec/:\n{}",
        missing.join("\n")
    );
}

#[test]
fn id_scanner_finds_ids_and_nothing_else() {
    assert_eq!(
        ids("see HPD-FRAME-004, and PSD-STS-10-RESET."),
        [
            Named::Id("HPD-FRAME-004".into()),
            Named::Id("PSD-STS-10-RESET".into())
        ]
    );
    assert_eq!(
        ids(r#"breaks: &["PSD-STS-0-*", "PSD-POS-*"]"#),
        [Named::Prefix("PSD-STS-0-".into())]
    );
    assert_eq!(ids("XHPD-FRAME-004 HPD-X"), Vec::<Named>::new());
}
