//! Fuzz harnesses of case selection: `--case`/`--skip` patterns and expectations files.

use drivespec_conform::select::{Expectations, Pattern};

/// Case IDs of the three suites' shapes that patterns are tried on.
const IDS: &[&str] = &[
    "hpd/frame/read-parameter",
    "hpd/param/Pr7/above-max",
    "psd4xx/pkw/par-44/write",
    "psx3xx/isdu/142/range",
    "psx3xx/sequence/seq-loop-case-3-short",
];

/// A pattern parses or fails cleanly; a pattern without glob characters selects itself and
/// every case under it.
pub fn pattern(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(p) = Pattern::new(&text) else {
        return;
    };
    for id in IDS {
        let _ = p.matches(id);
    }
    let plain = p.as_str();
    if !plain.is_empty() && !plain.contains(['*', '?', '[', '{']) {
        assert!(p.matches(plain), "{plain:?} does not select itself");
        assert!(
            p.matches(&format!("{plain}/x")),
            "{plain:?} does not select a case under it"
        );
    }
}

/// An expectations file parses or fails cleanly; no accepted entry has an empty reason.
pub fn expectations(data: &[u8]) {
    let text = String::from_utf8_lossy(data);
    let Ok(e) = Expectations::parse(&text, "fuzz.toml") else {
        return;
    };
    for id in IDS {
        if let Some(known) = e.known(id) {
            assert!(!known.reason.trim().is_empty(), "empty reason accepted");
        }
    }
    let _ = e.stale(IDS);
}
