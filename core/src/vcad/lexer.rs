//! Tokens of the legacy `.vcad` text language, each with its 1-based line
//! and column (columns count characters, as editors show them).

use super::VcadError;

/// What a token is.
#[derive(Clone, Debug, PartialEq)]
pub enum Tok {
    /// A construct name (`union`, `sphere`, ...), as written.
    Ident(String),
    /// A number literal, with any leading `-` or `+` folded in by the parser.
    Num(f64),
    /// A double-quoted string (material name, expression, path).
    Str(String),
    /// One of `( ) { } [ ] , ; - +`.
    Punct(char),
}

/// A token and where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    /// The token.
    pub tok: Tok,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
}

impl Tok {
    /// The token as the error messages quote it.
    pub fn describe(&self) -> String {
        match self {
            Tok::Ident(s) => format!("`{s}`"),
            Tok::Num(v) => format!("the number {v}"),
            Tok::Str(s) => format!("the string \"{s}\""),
            Tok::Punct(c) => format!("`{c}`"),
        }
    }
}

struct Cursor<'a> {
    chars: std::iter::Peekable<std::str::Chars<'a>>,
    line: usize,
    column: usize,
}

impl Cursor<'_> {
    fn peek(&mut self) -> Option<char> {
        self.chars.peek().copied()
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.chars.next()?;
        if c == '\n' {
            self.line += 1;
            self.column = 1;
        } else {
            self.column += 1;
        }
        Some(c)
    }
}

/// Split `src` into tokens; comments (`//` to the end of the line and
/// `/* ... */`) and white space are dropped.
pub fn tokenize(src: &str) -> Result<Vec<Token>, VcadError> {
    let mut cur = Cursor {
        chars: src.chars().peekable(),
        line: 1,
        column: 1,
    };
    let mut out = Vec::new();
    while let Some(c) = cur.peek() {
        let (line, column) = (cur.line, cur.column);
        let err = |message: String| VcadError::at(line, column, message);
        if c.is_whitespace() {
            cur.bump();
        } else if c == '/' {
            cur.bump();
            match cur.peek() {
                Some('/') => {
                    while cur.peek().is_some_and(|c| c != '\n') {
                        cur.bump();
                    }
                }
                Some('*') => {
                    cur.bump();
                    let mut prev = ' ';
                    loop {
                        match cur.bump() {
                            Some('/') if prev == '*' => break,
                            Some(c) => prev = c,
                            None => {
                                return Err(err(
                                    "this `/*` comment is never closed: end it with `*/`".into(),
                                ));
                            }
                        }
                    }
                }
                _ => {
                    return Err(err(
                        "`/` outside a string: .vcad has no arithmetic; write the value as a number, or an expression inside a string (\"x/2\")".into(),
                    ));
                }
            }
        } else if c == '"' {
            cur.bump();
            let mut s = String::new();
            loop {
                match cur.bump() {
                    Some('"') => break,
                    Some('\n') | None => {
                        return Err(err(
                            "this string is never closed: end it with `\"` on the same line".into(),
                        ));
                    }
                    Some(c) => s.push(c),
                }
            }
            out.push(Token {
                tok: Tok::Str(s),
                line,
                column,
            });
        } else if c.is_ascii_digit() || c == '.' {
            let text = number_text(&mut cur);
            let v: f64 = text.parse().map_err(|_| {
                err(format!(
                    "`{text}` is not a number (write digits with one `.` and an optional exponent, as in 1.5e-3)"
                ))
            })?;
            if !v.is_finite() {
                return Err(err(format!("`{text}` is too large for a number")));
            }
            out.push(Token {
                tok: Tok::Num(v),
                line,
                column,
            });
        } else if c.is_alphabetic() || c == '_' {
            let mut s = String::new();
            while let Some(c) = cur.peek().filter(|c| c.is_alphanumeric() || *c == '_') {
                s.push(c);
                cur.bump();
            }
            out.push(Token {
                tok: Tok::Ident(s),
                line,
                column,
            });
        } else if "(){}[],;-+".contains(c) {
            cur.bump();
            out.push(Token {
                tok: Tok::Punct(c),
                line,
                column,
            });
        } else {
            return Err(err(format!(
                "unexpected character `{c}`: .vcad takes construct names, numbers, \"strings\", ( ) {{ }} [ ] , ; and comments"
            )));
        }
    }
    Ok(out)
}

/// The characters of a number literal: digits, one `.`, an exponent.
fn number_text(cur: &mut Cursor<'_>) -> String {
    let mut s = String::new();
    while let Some(c) = cur.peek() {
        let exp_sign = (c == '-' || c == '+') && s.ends_with(['e', 'E']);
        if c.is_ascii_digit() || c == '.' || c == 'e' || c == 'E' || exp_sign {
            s.push(c);
            cur.bump();
        } else {
            break;
        }
    }
    s
}
