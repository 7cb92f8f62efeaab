//! Pure text operations behind the editor (indent, dedent, auto-indent,
//! find, line lookup), in char indices as egui's cursors count them, so they
//! are tested without a UI.

use std::ops::Range;

/// Spaces one Tab inserts.
pub const INDENT: &str = "    ";

/// Byte offset of char index `ci` (clamped to the end).
pub fn char_to_byte(text: &str, ci: usize) -> usize {
    text.char_indices().nth(ci).map_or(text.len(), |(b, _)| b)
}

/// The identifier (letters, digits, `_`) around char index `at`.
pub fn word_at(text: &str, at: usize) -> String {
    let chars: Vec<char> = text.chars().collect();
    let ident = |c: &char| c.is_alphanumeric() || *c == '_';
    let at = at.min(chars.len());
    let start = chars[..at]
        .iter()
        .rposition(|c| !ident(c))
        .map_or(0, |i| i + 1);
    let end = chars[at..]
        .iter()
        .position(|c| !ident(c))
        .map_or(chars.len(), |i| at + i);
    chars[start..end].iter().collect()
}

/// Char index of byte offset `b`.
pub fn byte_to_char(text: &str, b: usize) -> usize {
    text[..b.min(text.len())].chars().count()
}

/// Char index where 1-based `line` starts (the end when past the last line),
/// plus `column - 1` chars, clamped to that line.
pub fn line_col_to_char(text: &str, line: usize, column: Option<usize>) -> usize {
    let mut ci = 0;
    for (i, l) in text.split_inclusive('\n').enumerate() {
        if i + 1 == line.max(1) {
            let len = l.trim_end_matches('\n').chars().count();
            return ci + column.unwrap_or(1).saturating_sub(1).min(len);
        }
        ci += l.chars().count();
    }
    ci
}

/// 1-based line of char index `ci`.
pub fn line_of_char(text: &str, ci: usize) -> usize {
    1 + text.chars().take(ci).filter(|c| *c == '\n').count()
}

/// An edit result: the new text and the new selection (char indices).
#[derive(Debug, PartialEq)]
pub struct Edit {
    /// Text after the edit.
    pub text: String,
    /// Selection after the edit (empty range = a cursor).
    pub selection: Range<usize>,
}

/// The char range of the whole lines that `sel` touches.
fn line_span(text: &str, sel: &Range<usize>) -> (usize, usize) {
    let chars: Vec<char> = text.chars().collect();
    let mut start = sel.start.min(chars.len());
    while start > 0 && chars[start - 1] != '\n' {
        start -= 1;
    }
    // A selection that ends at a line start does not include that line.
    let mut end = sel.end.min(chars.len());
    if end > sel.start && end > 0 && chars[end - 1] == '\n' {
        end -= 1;
    }
    while end < chars.len() && chars[end] != '\n' {
        end += 1;
    }
    (start, end)
}

/// Tab: a cursor or a selection inside one line gets 4 spaces in place of the
/// selection; a selection over several lines indents each line.
pub fn indent(text: &str, sel: Range<usize>) -> Edit {
    let multi_line = text
        .chars()
        .skip(sel.start)
        .take(sel.end - sel.start)
        .any(|c| c == '\n');
    if !multi_line {
        let (a, b) = (char_to_byte(text, sel.start), char_to_byte(text, sel.end));
        let new = format!("{}{INDENT}{}", &text[..a], &text[b..]);
        let c = sel.start + INDENT.len();
        return Edit {
            text: new,
            selection: c..c,
        };
    }
    let (ls, le) = line_span(text, &sel);
    let (a, b) = (char_to_byte(text, ls), char_to_byte(text, le));
    let lines: Vec<String> = text[a..b]
        .split('\n')
        .map(|l| {
            if l.is_empty() {
                String::new()
            } else {
                format!("{INDENT}{l}")
            }
        })
        .collect();
    let block = lines.join("\n");
    let added = block.chars().count() - text[a..b].chars().count();
    let first_added = if text[a..b].starts_with('\n') || a == b {
        0
    } else {
        INDENT.len()
    };
    Edit {
        text: format!("{}{block}{}", &text[..a], &text[b..]),
        selection: sel.start + first_added..sel.end + added,
    }
}

/// Shift+Tab: remove up to 4 leading spaces (or one tab) from each line the
/// selection touches.
pub fn dedent(text: &str, sel: Range<usize>) -> Edit {
    let (ls, le) = line_span(text, &sel);
    let (a, b) = (char_to_byte(text, ls), char_to_byte(text, le));
    let mut removed_total = 0;
    let mut removed_first = 0;
    let lines: Vec<&str> = text[a..b]
        .split('\n')
        .enumerate()
        .map(|(i, l)| {
            let n = if l.starts_with('\t') {
                1
            } else {
                l.chars()
                    .take(INDENT.len())
                    .take_while(|c| *c == ' ')
                    .count()
            };
            removed_total += n;
            if i == 0 {
                removed_first = n;
            }
            &l[n..]
        })
        .collect();
    let start = sel.start.saturating_sub(removed_first).max(ls);
    let end = sel.end.saturating_sub(removed_total).max(start);
    Edit {
        text: format!("{}{}{}", &text[..a], lines.join("\n"), &text[b..]),
        selection: start..end,
    }
}

/// Enter: a new line with the current line's indentation, one level more
/// after an opening bracket.
pub fn newline_with_indent(text: &str, sel: Range<usize>) -> Edit {
    let (a, b) = (char_to_byte(text, sel.start), char_to_byte(text, sel.end));
    let line_start = text[..a].rfind('\n').map_or(0, |i| i + 1);
    let line = &text[line_start..a];
    let mut indent: String = line
        .chars()
        .take_while(|c| *c == ' ' || *c == '\t')
        .collect();
    if line.trim_end().ends_with(['{', '(', '[']) {
        indent.push_str(INDENT);
    }
    let insert = format!("\n{indent}");
    let c = sel.start + insert.chars().count();
    Edit {
        text: format!("{}{insert}{}", &text[..a], &text[b..]),
        selection: c..c,
    }
}

/// Every occurrence of `query` (ASCII case-insensitive), as byte ranges.
pub fn find_all(text: &str, query: &str) -> Vec<Range<usize>> {
    if query.is_empty() {
        return Vec::new();
    }
    let hay = text.to_ascii_lowercase();
    let needle = query.to_ascii_lowercase();
    hay.match_indices(&needle)
        .map(|(i, m)| i..i + m.len())
        .collect()
}

/// The match to go to from byte offset `from`: the first starting at or after
/// it (wrapping), or the last before it when `backwards`.
pub fn next_match(matches: &[Range<usize>], from: usize, backwards: bool) -> Option<usize> {
    if matches.is_empty() {
        return None;
    }
    if backwards {
        Some(
            matches
                .iter()
                .rposition(|m| m.start < from)
                .unwrap_or(matches.len() - 1),
        )
    } else {
        Some(matches.iter().position(|m| m.start >= from).unwrap_or(0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_and_column_to_char() {
        let t = "ab\ncdé\n\nx";
        assert_eq!(line_col_to_char(t, 1, None), 0);
        assert_eq!(line_col_to_char(t, 2, Some(3)), 5);
        assert_eq!(line_col_to_char(t, 2, Some(99)), 6);
        assert_eq!(line_col_to_char(t, 4, None), 8);
        assert_eq!(line_col_to_char(t, 9, None), 9);
        assert_eq!(line_of_char(t, 5), 2);
        assert_eq!(char_to_byte(t, 6), 7);
        assert_eq!(byte_to_char(t, 7), 6);
    }

    #[test]
    fn tab_inserts_four_spaces_at_the_cursor() {
        let e = indent("ab", 1..1);
        assert_eq!(e.text, "a    b");
        assert_eq!(e.selection, 5..5);
        // A selection inside a line is replaced.
        assert_eq!(indent("abcd", 1..3).text, "a    d");
    }

    #[test]
    fn tab_over_lines_indents_each_and_shift_tab_undoes_it() {
        let t = "a\nb\n\nc";
        let e = indent(t, 0..6);
        assert_eq!(e.text, "    a\n    b\n\n    c");
        assert_eq!(e.selection, 4..18);
        let d = dedent(&e.text, e.selection.clone());
        assert_eq!(d.text, t);
        assert_eq!(d.selection, 0..6);
        assert_eq!(dedent("  x", 3..3).text, "x");
        assert_eq!(dedent("\tx", 1..1).text, "x");
    }

    #[test]
    fn enter_keeps_indentation() {
        let e = newline_with_indent("    let a = [", 13..13);
        assert_eq!(e.text, "    let a = [\n        ");
        assert_eq!(e.selection, 22..22);
        assert_eq!(newline_with_indent("  x", 3..3).text, "  x\n  ");
    }

    #[test]
    fn find_wraps_both_ways() {
        let m = find_all("Foo foo FOO", "foo");
        assert_eq!(m, vec![0..3, 4..7, 8..11]);
        assert_eq!(next_match(&m, 1, false), Some(1));
        assert_eq!(next_match(&m, 9, false), Some(0));
        assert_eq!(next_match(&m, 4, true), Some(0));
        assert_eq!(next_match(&m, 0, true), Some(2));
        assert!(find_all("abc", "").is_empty());
    }
}
