//! Python's top-level names in Rhai: `root = X` and `W = 10` without `let`,
//! and functions that read them.
//!
//! Rhai needs `let` before a new name and hides the caller's variables from
//! a `fn`. Python needs neither, so before compiling, a scan of the text
//! finds every top-level name (assigned outside any `fn`, or declared with
//! `let`/`const` outside every block) and:
//! - the scope starts with each of them as a shared cell holding
//!   [`Unassigned`], so a plain assignment updates the cell;
//! - a top-level `let`/`const` is overwritten with as many spaces, so that
//!   it assigns the same cell instead of declaring a second variable (every
//!   line and column stays where it was, so errors point at the text the
//!   user wrote);
//! - a variable that a `fn` reads and does not declare itself resolves to
//!   the cell's value at the time of the read (Python's globals), through
//!   the engine's variable resolver.
//!
//! `let` inside a block (a loop body, an `if`) keeps Rhai's meaning: a name
//! local to that block.

use std::collections::HashMap;

use rhai::{Dynamic, Engine, EvalAltResult, Position, Scope};

/// The value of a top-level name before the script assigns it.
#[derive(Clone, Debug)]
pub struct Unassigned(pub String);

/// The result of the scan.
pub struct TopLevel {
    /// The script with top-level `let` and `const` blanked out.
    pub source: String,
    /// Top-level names in order of first appearance.
    pub names: Vec<String>,
}

/// Words that are never variable names.
const KEYWORDS: &[&str] = &[
    "let",
    "const",
    "fn",
    "if",
    "else",
    "for",
    "while",
    "loop",
    "do",
    "until",
    "in",
    "return",
    "throw",
    "try",
    "catch",
    "break",
    "continue",
    "switch",
    "import",
    "export",
    "as",
    "private",
    "this",
    "true",
    "false",
    "global",
    "Fn",
    "call",
    "curry",
    "print",
    "debug",
    "type_of",
    "eval",
    "is_def_fn",
    "is_def_var",
    "is_shared",
];

#[derive(Clone, Copy, PartialEq)]
enum Prev {
    /// Start of the text, or after `;`, `{` or `}`: a statement may start.
    StatementStart,
    /// `let` or `const` at the top level: the next word is a declared name.
    Declaration,
    Other,
}

/// Scan `src` (see the module comment).
pub fn scan(src: &str) -> TopLevel {
    let b = src.as_bytes();
    let mut out = b.to_vec();
    let mut names: Vec<String> = Vec::new();
    let mut add = |n: &str| {
        if !KEYWORDS.contains(&n) && !names.iter().any(|m| m == n) {
            names.push(n.to_owned());
        }
    };
    let (mut depth, mut in_fn, mut pending_fn) = (0i64, false, false);
    let mut prev = Prev::StatementStart;
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        match c {
            b' ' | b'\t' | b'\r' | b'\n' => i += 1,
            b'/' if b.get(i + 1) == Some(&b'/') => i = line_end(b, i),
            b'/' if b.get(i + 1) == Some(&b'*') => i = block_comment_end(b, i),
            b'"' | b'`' | b'\'' => {
                i = quoted_end(b, i, c);
                prev = Prev::Other;
            }
            b'{' => {
                depth += 1;
                if pending_fn && depth == 1 {
                    in_fn = true;
                    pending_fn = false;
                }
                prev = Prev::StatementStart;
                i += 1;
            }
            b'}' => {
                depth -= 1;
                if in_fn && depth <= 0 {
                    in_fn = false;
                }
                prev = Prev::StatementStart;
                i += 1;
            }
            b';' => {
                prev = Prev::StatementStart;
                i += 1;
            }
            c if c == b'_' || c.is_ascii_alphabetic() => {
                let start = i;
                while i < b.len() && (b[i] == b'_' || b[i].is_ascii_alphanumeric()) {
                    i += 1;
                }
                let word = &src[start..i];
                let top = depth == 0 && !in_fn && !pending_fn;
                prev = if in_fn || pending_fn {
                    Prev::Other
                } else if word == "fn" && depth == 0 {
                    pending_fn = true;
                    Prev::Other
                } else if top && prev == Prev::StatementStart && (word == "let" || word == "const")
                {
                    out[start..i].fill(b' ');
                    Prev::Declaration
                } else {
                    if prev == Prev::Declaration || (prev == Prev::StatementStart && assigns(b, i))
                    {
                        add(word);
                    }
                    Prev::Other
                };
            }
            _ => {
                prev = Prev::Other;
                i += 1;
            }
        }
    }
    // Only ASCII keywords were replaced by ASCII spaces: still UTF-8.
    let source = String::from_utf8(out).unwrap_or_else(|_| src.to_owned());
    TopLevel { source, names }
}

/// Whether the text after a word at `i` is a plain `=` (not `==` or `=>`).
fn assigns(b: &[u8], mut i: usize) -> bool {
    while i < b.len() && matches!(b[i], b' ' | b'\t') {
        i += 1;
    }
    b.get(i) == Some(&b'=') && !matches!(b.get(i + 1), Some(b'=') | Some(b'>'))
}

fn line_end(b: &[u8], i: usize) -> usize {
    b[i..]
        .iter()
        .position(|&c| c == b'\n')
        .map_or(b.len(), |n| i + n)
}

/// The end of a (nested, as in Rhai) block comment starting at `i`.
fn block_comment_end(b: &[u8], mut i: usize) -> usize {
    let mut level = 0usize;
    while i < b.len() {
        if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            level += 1;
            i += 2;
        } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
            level -= 1;
            i += 2;
            if level == 0 {
                return i;
            }
        } else {
            i += 1;
        }
    }
    i
}

/// The end of a string, back-tick string or character literal at `i`.
fn quoted_end(b: &[u8], mut i: usize, quote: u8) -> usize {
    i += 1;
    while i < b.len() {
        match b[i] {
            b'\\' => i += 2,
            c if c == quote => return i + 1,
            _ => i += 1,
        }
    }
    i
}

/// The shared cells of the top-level names, by name.
pub type Cells = HashMap<String, Dynamic>;

/// Push a shared cell for each name onto `scope`; the same cells, by name.
pub fn seed(scope: &mut Scope, names: &[String]) -> Cells {
    names
        .iter()
        .map(|n| {
            let cell = Dynamic::from(Unassigned(n.clone())).into_shared();
            scope.push_dynamic(n.as_str(), cell.clone());
            (n.clone(), cell)
        })
        .collect()
}

/// Let functions read the top-level names: a variable a function neither
/// takes nor declares resolves to the top-level cell's current value (read
/// only, as the engine makes every resolved value).
pub fn resolve_in_functions(engine: &mut Engine, cells: Cells) {
    // `print(W)` before `W = ...` shows that, not a Rust type name.
    for name in ["to_string", "to_debug"] {
        engine.register_fn(name, |u: &mut Unassigned| {
            format!("<{}: no value yet>", u.0)
        });
    }
    #[allow(deprecated)] // `on_var` is marked volatile, not deprecated.
    engine.on_var(move |name, index, ctx| {
        // At the top level the scope holds the cells; an index is a local
        // the parser already placed.
        if ctx.call_level() == 0 || index > 0 || ctx.scope().contains(name) {
            return Ok(None);
        }
        let Some(cell) = cells.get(name) else {
            return Ok(None);
        };
        let value = cell.flatten_clone();
        if value.is::<Unassigned>() {
            return Err(Box::new(EvalAltResult::ErrorRuntime(
                format!(
                    "`{name}` is read inside a function before the top level assigns it: \
                     assign `{name}` above the line that calls the function"
                )
                .into(),
                Position::NONE,
            )));
        }
        Ok(Some(value))
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn top_level_let_is_blanked_and_names_found() {
        let t = scan(
            "let a = 1;\nroot = a;\nfor i in 0..3 { let b = i; c = b; }\nfn f(x) { let d = x; e = 2; }\nconst K = 2;",
        );
        assert_eq!(t.names, ["a", "root", "c", "K"]);
        assert_eq!(
            t.source,
            "    a = 1;\nroot = a;\nfor i in 0..3 { let b = i; c = b; }\nfn f(x) { let d = x; e = 2; }\n      K = 2;"
        );
    }

    #[test]
    fn strings_comments_and_comparisons_are_not_assignments() {
        let t = scan(
            "// x = 1\n/* y = /* nested */ 2 */ let s = \"z = 3; let q = 1\";\nif s == `w = ${s}` { }\nlet m = #{ a: 1 };\nm.a = 2;\nlet c = 'x';",
        );
        assert_eq!(t.names, ["s", "m", "c"]);
        assert!(t.source.contains("\"z = 3; let q = 1\""));
    }

    #[test]
    fn unterminated_text_does_not_panic() {
        for s in ["\"abc", "/* x", "`a ${", "let", "fn f(", "}}}} a = 1", "'"] {
            let _ = scan(s);
        }
    }
}
