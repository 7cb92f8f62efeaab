//! Recursive-descent parser from tokens to a [`Node`] tree (precedence climbing
//! for the binary levels).
//!
//! Grammar, from lowest to highest precedence (pyvcad 2.3.4's ExprTk subset):
//!
//! ```text
//! ternary  := or ( '?' ternary ':' ternary )?          right-associative
//! or       := and ( ('or' | 'nor' | 'xor' | 'xnor') and )*
//! and      := not ( ('and' | 'nand') not )*
//! not      := 'not' not | cmp
//! cmp      := add ( ('==' | '=' | '!=' | '<>' | '<' | '<=' | '>' | '>=') add )*
//! add      := mul ( ('+' | '-') mul )*
//! mul      := unary ( ('*' | '/' | '%') unary | <implicit '*'> unary )*
//! unary    := ('-' | '+') unary | power
//! power    := primary ( '^' unary )?                   right-associative
//! primary  := number | constant | variable | function '(' args ')' | '(' ternary ')'
//! ```
//!
//! So `2^3^2 = 2^9`, `-2^2 = -(2^2)`, `2^-1 = 0.5`, `1 < 2 == 1` is `(1 < 2) == 1`.
//! Implicit multiplication, as ExprTk: a number literal directly followed by a name
//! or `(` multiplies (`2x`, `2 pi`, `3(x+1)`, `2sin(x)`), at the precedence of `*`, so
//! `1/2x = (1/2)*x` and `2x^2 = 2*(x^2)`.

use super::ExprError;
use super::ast::{MAX_DEPTH, MAX_NESTING, Node};
use super::functions::{self, FnKind};
use super::lexer::{Tok, Token};
use super::ops::Op;

type PResult<T> = Result<T, ExprError>;

/// Parses a token stream into a tree. `vars` are the lower-cased variable names, in
/// slot order; `end` is the column one past the last character.
pub(crate) fn parse(src: &str, toks: &[Token], end: usize, vars: &[String]) -> PResult<Node> {
    let mut p = Parser {
        src,
        toks,
        i: 0,
        end,
        vars,
        depth: 0,
    };
    if toks.is_empty() {
        return Err(p.error(1, "the expression is empty".into()));
    }
    let node = p.ternary()?;
    if let Some(t) = p.peek() {
        return Err(p.error(
            t.pos,
            format!(
                "unexpected '{}'; expected an operator or end of expression",
                t.text
            ),
        ));
    }
    Ok(node)
}

/// Binding level of prefix `not`: between `and` and the comparisons.
const NOT_LEVEL: u8 = 3;
/// Binding level of `*`, `/`, `%` and implicit multiplication.
const MUL_LEVEL: u8 = 6;

/// The operation and binding level (higher binds tighter) of a binary operator.
fn binary_op(tok: &Tok) -> Option<(Op, u8)> {
    Some(match tok {
        Tok::Binary(op) => (*op, binary_level(*op)),
        Tok::Plus => (Op::Add, 5),
        Tok::Minus => (Op::Sub, 5),
        Tok::Star => (Op::Mul, MUL_LEVEL),
        Tok::Slash => (Op::Div, MUL_LEVEL),
        Tok::Percent => (Op::Mod, MUL_LEVEL),
        _ => return None,
    })
}

/// The binding level of a comparison or logical operator: `or`-like 1,
/// `and`-like 2, comparisons 4 (tighter than `not`, looser than `+`).
fn binary_level(op: Op) -> u8 {
    match op {
        Op::Or | Op::Nor | Op::Xor | Op::Xnor => 1,
        Op::And | Op::Nand => 2,
        _ => 4,
    }
}

struct Parser<'a> {
    src: &'a str,
    toks: &'a [Token],
    i: usize,
    end: usize,
    vars: &'a [String],
    /// Current recursion depth of the nesting rules (parentheses, calls, prefix ops).
    depth: u32,
}

impl Parser<'_> {
    fn error(&self, position: usize, message: String) -> ExprError {
        ExprError {
            source_text: self.src.to_string(),
            position,
            message,
        }
    }

    fn peek(&self) -> Option<&Token> {
        self.toks.get(self.i)
    }

    fn peek_tok(&self) -> Option<&Tok> {
        self.peek().map(|t| &t.tok)
    }

    /// Consumes the next token if it is `tok`.
    fn eat(&mut self, tok: &Tok) -> bool {
        if self.peek_tok() == Some(tok) {
            self.i += 1;
            true
        } else {
            false
        }
    }

    /// Position of the next token, or the end column.
    fn here(&self) -> usize {
        self.peek().map_or(self.end, |t| t.pos)
    }

    /// Runs `f` one nesting level deeper, refusing input nested beyond
    /// [`MAX_NESTING`] before the recursion can exhaust the stack.
    fn nested<T>(&mut self, f: impl FnOnce(&mut Self) -> PResult<T>) -> PResult<T> {
        if self.depth >= MAX_NESTING {
            return Err(self.error(
                self.here(),
                format!("expression is nested too deeply (more than {MAX_NESTING} levels)"),
            ));
        }
        self.depth += 1;
        let r = f(self);
        self.depth -= 1;
        r
    }

    /// Builds `op(args)`, refusing trees deeper than [`MAX_DEPTH`] (long operator
    /// chains like `1+1+...+1` grow the tree without recursing in the parser).
    fn node(&self, pos: usize, op: Op, args: Vec<Node>) -> PResult<Node> {
        let n = Node::apply(op, args);
        if n.depth() > MAX_DEPTH {
            return Err(self.error(
                pos,
                format!("expression is nested too deeply (more than {MAX_DEPTH} levels)"),
            ));
        }
        Ok(n)
    }

    fn ternary(&mut self) -> PResult<Node> {
        self.nested(|p| {
            let cond = p.binary(0)?;
            let Some(q) = p.peek().filter(|t| t.tok == Tok::Question).map(|t| t.pos) else {
                return Ok(cond);
            };
            p.i += 1;
            let then = p.ternary()?;
            if !p.eat(&Tok::Colon) {
                let msg = format!("expected ':' to complete the '?' at character {q}");
                return Err(p.error_found(msg));
            }
            let otherwise = p.ternary()?;
            p.node(q, Op::Select, vec![cond, then, otherwise])
        })
    }

    /// An "expected X" error at the next token (naming it) or at the end.
    fn error_found(&self, expected: String) -> ExprError {
        match self.peek() {
            Some(t) => self.error(t.pos, format!("{expected}, found '{}'", t.text)),
            None => self.error(self.end, format!("{expected}, but the expression ended")),
        }
    }

    /// Precedence climbing over the binary levels and prefix `not`: parses operators
    /// binding at least as tightly as `min` (see [`binary_op`]), left-associatively.
    /// One function for all levels keeps the recursion per nesting level shallow.
    fn binary(&mut self, min: u8) -> PResult<Node> {
        let mut lhs = match self.peek() {
            Some(t) if t.tok == Tok::Not && min <= NOT_LEVEL => {
                let pos = t.pos;
                self.i += 1;
                let x = self.nested(|p| p.binary(NOT_LEVEL))?;
                self.node(pos, Op::Not, vec![x])?
            }
            _ => self.unary()?,
        };
        while let Some(t) = self.peek() {
            let pos = t.pos;
            let (op, level, implicit) = match binary_op(&t.tok) {
                Some((op, level)) => (op, level, false),
                None if matches!(t.tok, Tok::Ident(_) | Tok::LParen) && self.follows_number() => {
                    (Op::Mul, MUL_LEVEL, true)
                }
                None => break,
            };
            if level < min {
                break;
            }
            if !implicit {
                self.i += 1;
            }
            let rhs = self.binary(level + 1)?;
            lhs = self.node(pos, op, vec![lhs, rhs])?;
        }
        Ok(lhs)
    }

    /// Whether the previous token was a number literal (implicit multiplication).
    fn follows_number(&self) -> bool {
        self.i > 0 && matches!(self.toks[self.i - 1].tok, Tok::Num(_))
    }

    fn unary(&mut self) -> PResult<Node> {
        match self.peek().map(|t| (&t.tok, t.pos)) {
            Some((Tok::Minus, pos)) => {
                self.i += 1;
                let x = self.nested(Self::unary)?;
                self.node(pos, Op::Neg, vec![x])
            }
            Some((Tok::Plus, _)) => {
                self.i += 1;
                self.nested(Self::unary)
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> PResult<Node> {
        let base = self.primary()?;
        if let Some(t) = self.peek().filter(|t| t.tok == Tok::Caret) {
            let pos = t.pos;
            self.i += 1;
            let exponent = self.nested(Self::unary)?;
            return self.node(pos, Op::Pow, vec![base, exponent]);
        }
        Ok(base)
    }

    fn primary(&mut self) -> PResult<Node> {
        let Some(t) = self.peek() else {
            let after = self
                .toks
                .last()
                .map_or(String::new(), |t| format!(" after '{}'", t.text));
            return Err(self.error(
                self.end,
                format!(
                    "expected a number, variable, function or '('{after}, but the expression ended"
                ),
            ));
        };
        let pos = t.pos;
        match &t.tok {
            Tok::Num(v) => {
                let v = *v;
                self.i += 1;
                Ok(Node::Num(v))
            }
            Tok::LParen => {
                self.i += 1;
                let inner = self.ternary()?;
                if !self.eat(&Tok::RParen) {
                    let msg = format!("expected ')' to close '(' at character {pos}");
                    return Err(self.error_found(msg));
                }
                Ok(inner)
            }
            Tok::Ident(name) => {
                let text = t.text.clone();
                let name = name.clone();
                self.i += 1;
                if self.peek_tok() == Some(&Tok::LParen) {
                    self.call(&name, &text, pos)
                } else {
                    self.name(&name, &text, pos)
                }
            }
            _ => Err(self.error(
                pos,
                format!(
                    "expected a number, variable, function or '(', found '{}'",
                    t.text
                ),
            )),
        }
    }

    /// A name not followed by `(`: constant, variable, or a misused function.
    fn name(&self, name: &str, text: &str, pos: usize) -> PResult<Node> {
        if let Some(v) = functions::constant(name) {
            return Ok(Node::Num(v));
        }
        if let Some(i) = self.vars.iter().position(|v| v == name) {
            return Ok(Node::Var(i as u8));
        }
        if let Some(f) = functions::function(name) {
            let example = if f.params.is_empty() {
                "a, b"
            } else {
                f.params
            };
            return Err(self.error(
                pos,
                format!(
                    "function '{text}' must be called with arguments, e.g. {}({example})",
                    f.name
                ),
            ));
        }
        Err(self.error(
            pos,
            functions::unknown_variable_message(name, text, self.vars),
        ))
    }

    /// `name(args...)`; the `(` is the next token.
    fn call(&mut self, name: &str, text: &str, pos: usize) -> PResult<Node> {
        let Some(f) = functions::function(name) else {
            let msg = if functions::constant(name).is_some() || self.vars.iter().any(|v| v == name)
            {
                format!("'{text}' is not a function; write '{text}*(...)' to multiply")
            } else {
                functions::unknown_function_message(name, text)
            };
            return Err(self.error(pos, msg));
        };
        let open = self.here();
        self.i += 1; // '('
        let mut args = Vec::new();
        if !self.eat(&Tok::RParen) {
            loop {
                args.push(self.ternary()?);
                if self.eat(&Tok::RParen) {
                    break;
                }
                if !self.eat(&Tok::Comma) {
                    let msg = format!(
                        "expected ',' or ')' in the call to '{text}' opened at character {open}"
                    );
                    return Err(self.error_found(msg));
                }
            }
        }
        let n = args.len();
        match (f.arity(), f.kind) {
            (Some(want), FnKind::Fixed(op)) => {
                if n != want {
                    let s = if want == 1 { "" } else { "s" };
                    return Err(self.error(
                        pos,
                        format!(
                            "function '{}' expects {want} argument{s} ({}), got {n}",
                            f.name, f.params
                        ),
                    ));
                }
                self.node(pos, op, args)
            }
            (_, kind) => {
                // A fold, or `avg` (a sum over the count, as ExprTk has it).
                let (op, fold) = match kind {
                    FnKind::Fold(op) => (op, true),
                    _ => (Op::Add, false),
                };
                let mut it = args.into_iter();
                let Some(mut acc) = it.next() else {
                    return Err(self.error(
                        pos,
                        format!("function '{}' expects at least 1 argument, got 0", f.name),
                    ));
                };
                for a in it {
                    acc = self.node(pos, op, vec![acc, a])?;
                }
                if fold {
                    Ok(acc)
                } else {
                    self.node(pos, Op::Div, vec![acc, Node::Num(n as f64)])
                }
            }
        }
    }
}
