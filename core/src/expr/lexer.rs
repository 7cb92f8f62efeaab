//! Splits source text into tokens, each tagged with its 1-based character column so
//! error messages can point at it.
//!
//! Word operators (`and`, `or`, `not`, ...) are recognised here, case-insensitively,
//! so the parser never mistakes them for variables. Symbol aliases: `&`/`&&` for
//! `and`, `|`/`||` for `or`, `=` for `==`, `<>` for `!=`.

use super::ExprError;
use super::ops::Op;

/// What a token is.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Tok {
    /// A numeric literal (finite).
    Num(f64),
    /// An identifier, lower-cased (variable, constant or function name).
    Ident(String),
    /// `+`
    Plus,
    /// `-`
    Minus,
    /// `*`
    Star,
    /// `/`
    Slash,
    /// `%`
    Percent,
    /// `^`
    Caret,
    /// `(`
    LParen,
    /// `)`
    RParen,
    /// `,`
    Comma,
    /// `?`
    Question,
    /// `:`
    Colon,
    /// A comparison or logical binary operator, as the operation it
    /// applies: `==` or `=`, `!=` or `<>`, `<`, `<=`, `>`, `>=`; `and`,
    /// `&`, `&&`; `or`, `|`, `||`; `nand`, `nor`, `xor`, `xnor`.
    Binary(Op),
    /// `not`
    Not,
}

/// A token with its position.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Token {
    /// The token.
    pub tok: Tok,
    /// 1-based character column of its first character.
    pub pos: usize,
    /// The source text it was read from (for messages).
    pub text: String,
}

/// Tokenises `src`. Returns the tokens and the column one past the last character
/// (where "unexpected end" errors point).
pub(crate) fn lex(src: &str) -> Result<(Vec<Token>, usize), ExprError> {
    let chars: Vec<char> = src.chars().collect();
    let err = |pos: usize, message: String| ExprError {
        source_text: src.to_string(),
        position: pos,
        message,
    };
    let mut toks = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let start = i;
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        let tok = if c.is_ascii_digit()
            || (c == '.' && chars.get(i + 1).is_some_and(char::is_ascii_digit))
        {
            i = scan_number(&chars, i);
            let text: String = chars[start..i].iter().collect();
            let v: f64 = text
                .parse()
                .map_err(|_| err(start + 1, format!("malformed number '{text}'")))?;
            if !v.is_finite() {
                return Err(err(
                    start + 1,
                    format!(
                        "number '{text}' is too large (overflows to infinity); use 'inf' for infinity"
                    ),
                ));
            }
            Tok::Num(v)
        } else if c.is_alphabetic() || c == '_' {
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            let word: String = chars[start..i].iter().collect::<String>().to_lowercase();
            match word.as_str() {
                "and" => Tok::Binary(Op::And),
                "or" => Tok::Binary(Op::Or),
                "nand" => Tok::Binary(Op::Nand),
                "nor" => Tok::Binary(Op::Nor),
                "xor" => Tok::Binary(Op::Xor),
                "xnor" => Tok::Binary(Op::Xnor),
                "not" => Tok::Not,
                _ => Tok::Ident(word),
            }
        } else {
            let next = chars.get(i + 1).copied();
            let (tok, len) = match (c, next) {
                ('=', Some('=')) => (Tok::Binary(Op::Eq), 2),
                ('!', Some('=')) => (Tok::Binary(Op::Ne), 2),
                ('<', Some('>')) => (Tok::Binary(Op::Ne), 2),
                ('<', Some('=')) => (Tok::Binary(Op::Le), 2),
                ('>', Some('=')) => (Tok::Binary(Op::Ge), 2),
                ('&', Some('&')) => (Tok::Binary(Op::And), 2),
                ('|', Some('|')) => (Tok::Binary(Op::Or), 2),
                ('=', _) => (Tok::Binary(Op::Eq), 1),
                ('<', _) => (Tok::Binary(Op::Lt), 1),
                ('>', _) => (Tok::Binary(Op::Gt), 1),
                ('&', _) => (Tok::Binary(Op::And), 1),
                ('|', _) => (Tok::Binary(Op::Or), 1),
                ('+', _) => (Tok::Plus, 1),
                ('-', _) => (Tok::Minus, 1),
                ('*', _) => (Tok::Star, 1),
                ('/', _) => (Tok::Slash, 1),
                ('%', _) => (Tok::Percent, 1),
                ('^', _) => (Tok::Caret, 1),
                ('(', _) => (Tok::LParen, 1),
                (')', _) => (Tok::RParen, 1),
                (',', _) => (Tok::Comma, 1),
                ('?', _) => (Tok::Question, 1),
                (':', _) => (Tok::Colon, 1),
                ('!', _) => {
                    return Err(err(
                        start + 1,
                        "unexpected character '!'; write 'not x' for logical negation".into(),
                    ));
                }
                _ => {
                    return Err(err(start + 1, format!("unexpected character '{c}'")));
                }
            };
            i += len;
            tok
        };
        toks.push(Token {
            tok,
            pos: start + 1,
            text: chars[start..i].iter().collect(),
        });
    }
    Ok((toks, chars.len() + 1))
}

/// Scans a number starting at `i`: digits, optional `.digits`, optional exponent.
/// An `e`/`E` only starts an exponent when digits follow (optionally signed), so `2e`
/// lexes as `2` then the constant `e` (implicit multiplication makes it `2*e`).
fn scan_number(chars: &[char], mut i: usize) -> usize {
    let digits = |mut i: usize| {
        while i < chars.len() && chars[i].is_ascii_digit() {
            i += 1;
        }
        i
    };
    i = digits(i);
    if chars.get(i) == Some(&'.') {
        i = digits(i + 1);
    }
    if matches!(chars.get(i), Some('e' | 'E')) {
        let mut j = i + 1;
        if matches!(chars.get(j), Some('+' | '-')) {
            j += 1;
        }
        if chars.get(j).is_some_and(char::is_ascii_digit) {
            i = digits(j);
        }
    }
    i
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(s: &str) -> Vec<Tok> {
        lex(s).unwrap().0.into_iter().map(|t| t.tok).collect()
    }

    #[test]
    fn numbers() {
        assert_eq!(
            toks("1 1.5 .5 1.5E2 1e-3 5."),
            [1.0, 1.5, 0.5, 150.0, 1e-3, 5.0].map(Tok::Num)
        );
        assert_eq!(toks("1.e5 1E+2"), [Tok::Num(1e5), Tok::Num(100.0)]);
        assert_eq!(toks("2e"), [Tok::Num(2.0), Tok::Ident("e".into())]);
        assert_eq!(
            toks("2e+x"),
            [
                Tok::Num(2.0),
                Tok::Ident("e".into()),
                Tok::Plus,
                Tok::Ident("x".into())
            ]
        );
        let e = lex("x + 1e309").unwrap_err();
        assert_eq!(e.position, 5);
        assert!(e.message.contains("too large"), "{}", e.message);
    }

    #[test]
    fn operators_and_positions() {
        assert_eq!(
            toks("a<=b<>c AND d && e | f = g"),
            [
                Tok::Ident("a".into()),
                Tok::Binary(Op::Le),
                Tok::Ident("b".into()),
                Tok::Binary(Op::Ne),
                Tok::Ident("c".into()),
                Tok::Binary(Op::And),
                Tok::Ident("d".into()),
                Tok::Binary(Op::And),
                Tok::Ident("e".into()),
                Tok::Binary(Op::Or),
                Tok::Ident("f".into()),
                Tok::Binary(Op::Eq),
                Tok::Ident("g".into()),
            ]
        );
        let (t, end) = lex("ü + X").unwrap();
        assert_eq!(t[2].pos, 5);
        assert_eq!(t[2].tok, Tok::Ident("x".into()));
        assert_eq!(t[2].text, "X");
        assert_eq!(end, 6);
        assert_eq!(lex("x # 1").unwrap_err().position, 3);
        assert!(lex("!x").unwrap_err().message.contains("not x"));
    }
}
