//! Escaping of text for XML 1.0 and HTML (attribute values and character data).

/// Replaces the five markup characters by their entities and every character XML 1.0 does
/// not allow (controls other than tab, line feed and carriage return; U+FFFE, U+FFFF) by
/// U+FFFD, so the result is always well-formed XML (XML 1.0 §2.2 `Char`).
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            '\t' | '\n' | '\r' => out.push(c),
            c if c < ' ' || c == '\u{FFFE}' || c == '\u{FFFF}' => out.push('\u{FFFD}'),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::escape;

    #[test]
    fn markup_is_escaped_and_characters_xml_forbids_are_replaced() {
        assert_eq!(
            escape("a<b>&\"'\u{1}\u{1F}\u{FFFE}\u{FFFF}"),
            "a&lt;b&gt;&amp;&quot;&apos;\u{FFFD}\u{FFFD}\u{FFFD}\u{FFFD}"
        );
    }

    #[test]
    fn whitespace_and_other_text_are_kept() {
        let s = "tab\tline\ncr\r µs → ✓ \u{7F} \u{10000}";
        assert_eq!(escape(s), s);
    }
}
