//! Names that other programs read back: CSV columns used as expression
//! variables, `.inp` set names, slice-stack folder names. Each has its own
//! rules for what to keep; all replace the rest the same way.

/// `name` with every character that `keep` rejects replaced by `_`.
pub fn underscore_other(name: &str, keep: impl Fn(char) -> bool) -> String {
    name.chars()
        .map(|c| if keep(c) { c } else { '_' })
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn replaces_only_rejected_characters() {
        let s = super::underscore_other("Vero Cyan-2.x", |c| c.is_ascii_alphanumeric());
        assert_eq!(s, "Vero_Cyan_2_x");
    }
}
