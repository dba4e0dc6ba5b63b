//! Pieces of self-contained HTML pages (no scripts, no external resources).

/// An element ID for `text` (a case or finding ID): ASCII letters and digits kept, every
/// other character `-`.
pub fn anchor(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::anchor;

    #[test]
    fn anchors_keep_letters_and_digits() {
        assert_eq!(anchor("hpd/fuzz/finding-1 ä"), "hpd-fuzz-finding-1--");
    }
}
