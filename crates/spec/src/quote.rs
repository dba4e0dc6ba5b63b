//! Quoting what a user typed in an error line: at most [`QUOTED`] characters of it, so a
//! 50 MB token never comes back on the terminal.

/// Most characters of an input an error quotes.
pub const QUOTED: usize = 60;

/// `"text"`, or its first [`QUOTED`] characters and its length when it is longer.
pub fn quote(text: &str) -> String {
    let n = text.chars().count();
    if n <= QUOTED {
        format!("{text:?}")
    } else {
        let head: String = text.chars().take(QUOTED).collect();
        format!("{head:?}… ({n} characters)")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_inputs_are_cut_with_their_length() {
        assert_eq!(quote("Pr33"), "\"Pr33\"");
        let long = "A".repeat(5000);
        let q = quote(&long);
        assert!(q.ends_with("… (5000 characters)"), "{q}");
        assert!(q.len() < 90, "{q}");
    }
}
