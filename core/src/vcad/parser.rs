//! The `.vcad` grammar, by recursive descent:
//!
//! ```text
//! file := call EOF
//! call := NAME "(" [arg ("," arg)*] ")" ( "{" call* "}" [";"] | ";" )
//! arg  := number | STRING | "(" number ("," number)* ")" | "[" [arg ("," arg)*] "]"
//! number := ["-" | "+"] NUM
//! ```
//!
//! Every piece keeps its line and column so the translator's messages point
//! into the `.vcad` file.

use super::VcadError;
use super::lexer::{Tok, Token};

/// Deepest nesting of `{ }` bodies and `[ ]` lists taken; deeper input is
/// refused with an error instead of exhausting the stack.
const MAX_DEPTH: usize = 256;

/// A 1-based line and column in the `.vcad` text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pos {
    /// Line.
    pub line: usize,
    /// Column.
    pub column: usize,
}

/// An argument value.
#[derive(Clone, Debug, PartialEq)]
pub enum ArgKind {
    /// `2.5`, `-1`.
    Num(f64),
    /// `"red"`.
    Str(String),
    /// `(1, 2, 3)`: a point or size.
    Tuple(Vec<f64>),
    /// `["a", "b"]`.
    List(Vec<Arg>),
    /// `true` / `false` (pyvcad's reader takes none; kept so the message
    /// can name the construct).
    Bool(bool),
}

/// An argument and where it starts.
#[derive(Clone, Debug, PartialEq)]
pub struct Arg {
    /// The value.
    pub kind: ArgKind,
    /// Where it starts.
    pub pos: Pos,
}

/// `name(args) { body }` or `name(args);`.
#[derive(Clone, Debug, PartialEq)]
pub struct Call {
    /// The construct name as written.
    pub name: String,
    /// Where the name starts.
    pub pos: Pos,
    /// The arguments in order.
    pub args: Vec<Arg>,
    /// The calls inside `{ }`; `None` for a call ended by `;`.
    pub body: Option<Vec<Call>>,
}

struct Parser<'a> {
    toks: &'a [Token],
    at: usize,
    eof: Pos,
    depth: usize,
}

/// Parse a whole file: exactly one top-level call.
pub fn parse(toks: &[Token], eof: Pos) -> Result<Call, VcadError> {
    let mut p = Parser {
        toks,
        at: 0,
        eof,
        depth: 0,
    };
    if toks.is_empty() {
        return Err(VcadError::at(
            eof.line,
            eof.column,
            "the file holds no design: write one `union(){ ... }` around the parts".into(),
        ));
    }
    let root = p.call()?;
    if let Some(t) = p.toks.get(p.at) {
        return Err(VcadError::at(
            t.line,
            t.column,
            format!(
                "{} after the end of the top-level `{}(){{...}}`: a .vcad file holds one top-level union; move this inside it",
                t.tok.describe(),
                root.name
            ),
        ));
    }
    Ok(root)
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Token> {
        self.toks.get(self.at)
    }

    fn pos_here(&self) -> Pos {
        self.peek().map_or(self.eof, |t| Pos {
            line: t.line,
            column: t.column,
        })
    }

    fn found(&self) -> String {
        self.peek()
            .map_or_else(|| "the end of the file".to_owned(), |t| t.tok.describe())
    }

    fn error<T>(&self, message: String) -> Result<T, VcadError> {
        let p = self.pos_here();
        Err(VcadError::at(p.line, p.column, message))
    }

    fn is_punct(&self, c: char) -> bool {
        matches!(self.peek(), Some(Token { tok: Tok::Punct(p), .. }) if *p == c)
    }

    fn expect(&mut self, c: char, context: &str) -> Result<(), VcadError> {
        if self.is_punct(c) {
            self.at += 1;
            Ok(())
        } else {
            self.error(format!("expected `{c}` {context}, found {}", self.found()))
        }
    }

    fn enter(&mut self) -> Result<(), VcadError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return self.error(format!(
                "nested more than {MAX_DEPTH} levels deep: flatten the design"
            ));
        }
        Ok(())
    }

    fn call(&mut self) -> Result<Call, VcadError> {
        let pos = self.pos_here();
        let name = match self.peek() {
            Some(Token {
                tok: Tok::Ident(s), ..
            }) => s.clone(),
            _ => {
                return self.error(format!(
                    "expected a construct such as `sphere(1, \"red\");` or `union(){{ ... }}`, found {}",
                    self.found()
                ));
            }
        };
        self.at += 1;
        self.expect('(', &format!("after `{name}`"))?;
        let args = self.args(')', &format!("`{name}(`"))?;
        let body = if self.is_punct('{') {
            self.at += 1;
            self.enter()?;
            let mut body = Vec::new();
            while !self.is_punct('}') {
                if self.peek().is_none() {
                    return Err(VcadError::at(
                        pos.line,
                        pos.column,
                        format!("the `{{` of `{name}` is never closed: end its body with `}}`"),
                    ));
                }
                body.push(self.call()?);
            }
            self.at += 1;
            self.depth -= 1;
            if self.is_punct(';') {
                self.at += 1;
            }
            Some(body)
        } else if self.is_punct(';') {
            self.at += 1;
            None
        } else {
            return self.error(format!(
                "expected `;` to end `{name}(...)` or `{{` to open its body, found {}",
                self.found()
            ));
        };
        Ok(Call {
            name,
            pos,
            args,
            body,
        })
    }

    /// Comma-separated arguments up to `close`, which is consumed.
    fn args(&mut self, close: char, what: &str) -> Result<Vec<Arg>, VcadError> {
        let mut out = Vec::new();
        if self.is_punct(close) {
            self.at += 1;
            return Ok(out);
        }
        loop {
            out.push(self.arg()?);
            if self.is_punct(',') {
                self.at += 1;
            } else if self.is_punct(close) {
                self.at += 1;
                return Ok(out);
            } else {
                return self.error(format!(
                    "expected `,` or `{close}` in the arguments of {what}, found {}",
                    self.found()
                ));
            }
        }
    }

    fn arg(&mut self) -> Result<Arg, VcadError> {
        let pos = self.pos_here();
        let kind = match self.peek().map(|t| &t.tok) {
            Some(Tok::Str(s)) => {
                let s = s.clone();
                self.at += 1;
                ArgKind::Str(s)
            }
            Some(Tok::Punct('(')) => {
                self.at += 1;
                let mut v = vec![self.number()?];
                while self.is_punct(',') {
                    self.at += 1;
                    v.push(self.number()?);
                }
                self.expect(')', "to close the `(` of a point")?;
                ArgKind::Tuple(v)
            }
            Some(Tok::Punct('[')) => {
                self.at += 1;
                self.enter()?;
                let items = self.args(']', "a `[ ]` list")?;
                self.depth -= 1;
                ArgKind::List(items)
            }
            Some(Tok::Ident(s)) if s == "true" || s == "false" => {
                let b = s == "true";
                self.at += 1;
                ArgKind::Bool(b)
            }
            _ => ArgKind::Num(self.number()?),
        };
        Ok(Arg { kind, pos })
    }

    fn number(&mut self) -> Result<f64, VcadError> {
        let sign = if self.is_punct('-') {
            self.at += 1;
            -1.0
        } else {
            if self.is_punct('+') {
                self.at += 1;
            }
            1.0
        };
        match self.peek().map(|t| &t.tok) {
            Some(Tok::Num(v)) => {
                let v = *v;
                self.at += 1;
                Ok(sign * v)
            }
            Some(Tok::Ident(s)) => self.error(format!(
                "`{s}` where a number belongs: .vcad has no variables; write the value (or put an expression inside a \"string\" where the construct takes one)"
            )),
            _ => self.error(format!("expected a number, found {}", self.found())),
        }
    }
}
