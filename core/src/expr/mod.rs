//! Math-expression strings: material gradings such as `"x/15+0.5"` and the implicit
//! functions of `Function` geometry.
//!
//! The language is the subset of ExprTk that pyvcad 2.3.4 exposes, with the same
//! operators, precedence and functions (plus the constant `e`). `parser.rs` documents
//! the grammar and `functions.rs` the vocabulary.
//!
//! [`Expr::compile`] runs lexer → parser → constant folding → tape code generation
//! once; [`Expr::eval`] then runs a compact register tape per point without
//! allocating, and [`Expr::eval_interval`] runs the same tape on [`Interval`]s for
//! conservative bounds over a box.

mod affine;
mod ast;
mod batch;
mod fold;
mod functions;
mod interval_eval;
mod lexer;
mod ops;
mod parser;
mod scalar;
mod set;
mod tape;
#[cfg(test)]
mod tests;

use std::fmt;

pub(crate) use set::ExprSet;

use crate::interval::Interval;

/// The standard coordinate variables, in slot order, that `Function` and `FGrade`
/// use: Cartesian `x, y, z`; cylindrical `rho, phic` (radius, azimuth); spherical
/// `r, theta, phis` (radius, azimuth, polar angle); and `d`, a distance the caller
/// supplies (e.g. signed distance to a surface).
pub const COORD_VARS: [&str; 9] = ["x", "y", "z", "rho", "phic", "r", "theta", "phis", "d"];

/// Fills slots 3..=7 from the Cartesian coordinates in slots 0..=2:
///
/// - `rho = sqrt(x² + y²)`, `phic = atan2(y, x)`
/// - `r = sqrt(x² + y² + z²)`, `theta = atan2(y, x)`, `phis = acos(z / r)`
///
/// `phis` is NaN at the origin, as in pyvcad. Slot 8 (`d`) is left to the caller.
///
/// # Panics
/// If `slots` has fewer than 8 elements.
#[inline]
#[cfg(test)]
pub(crate) fn fill_derived_coords(slots: &mut [f64]) {
    fill_derived_coords_used(slots, u64::MAX);
}

/// [`fill_derived_coords`] for the slots whose bit is set in `used` (bit
/// `i` for slot `i`); the others are left as they are. The azimuth's
/// `atan2` and the polar angle's `acos` cost more than the rest of a graded
/// primitive's evaluation, so an expression of `rho` alone skips them.
#[inline]
pub(crate) fn fill_derived_coords_used(slots: &mut [f64], used: u64) {
    let (x, y, z) = (slots[0], slots[1], slots[2]);
    if used & (1 << 3) != 0 {
        slots[3] = (x * x + y * y).sqrt();
    }
    if used & (1 << 4 | 1 << 6) != 0 {
        let azimuth = y.atan2(x);
        slots[4] = azimuth;
        slots[6] = azimuth;
    }
    if used & (1 << 5 | 1 << 7) != 0 {
        let r = (x * x + y * y + z * z).sqrt();
        slots[5] = r;
        slots[7] = (z / r).acos();
    }
}

/// Interval counterpart of [`fill_derived_coords`]: bounds on the derived coordinates
/// over the box in slots 0..=2, computed with the same operations so that
/// [`Expr::eval_interval`] stays conservative. `phis` is `EVERYTHING` when the box
/// contains the origin (where it is NaN).
///
/// # Panics
/// If `slots` has fewer than 8 elements.
pub(crate) fn fill_derived_coord_intervals(slots: &mut [Interval]) {
    let (x, y, z) = (slots[0], slots[1], slots[2]);
    let rho2 = x.square() + y.square();
    let azimuth = ops::Op::Atan2.apply_interval(y, x, x, 0.0);
    let r = (rho2 + z.square()).sqrt();
    slots[3] = rho2.sqrt();
    slots[4] = azimuth;
    slots[5] = r;
    slots[6] = azimuth;
    // |z| <= r holds for the computed values (sqrt(fl(z²)) = |z| in IEEE arithmetic),
    // so z / r is limited to [-1, 1] before acos.
    let cos_polar = (z / r).clamp_to(-1.0, 1.0);
    slots[7] = ops::Op::Acos.apply_interval(cos_polar, x, x, 0.0);
}

/// A compile error, pointing at a character of the source.
#[derive(Debug, Clone, thiserror::Error, PartialEq)]
#[error("in expression \"{source_text}\": at character {position}: {message}")]
pub struct ExprError {
    /// The whole expression text.
    pub source_text: String,
    /// 1-based character (not byte) column of the problem; one past the end for
    /// "the expression ended" errors.
    pub position: usize,
    /// What was wrong and what was expected.
    pub message: String,
}

/// A compiled expression. Cheap to clone, `Send + Sync`, evaluates without
/// allocating.
#[derive(Clone)]
pub struct Expr {
    source: String,
    /// `None` when the expression folded to a constant.
    tape: Option<tape::Tape>,
    /// Set when the expression is affine in its variables: evaluated as a
    /// dot product instead of the tape.
    affine: Option<affine::Affine>,
    constant: Option<f64>,
    used: u64,
}

impl Expr {
    /// Compiles `source` with the given variable names; variable `i` is read from
    /// `slots[i]` at evaluation. Names (and function names) match case-insensitively.
    ///
    /// At most 64 variables. Errors carry the 1-based character position and say
    /// what was expected.
    pub fn compile(source: &str, vars: &[&str]) -> Result<Expr, ExprError> {
        let error = |position, message: String| ExprError {
            source_text: source.to_string(),
            position,
            message,
        };
        if vars.len() > 64 {
            return Err(error(
                1,
                format!("too many variables ({}, at most 64)", vars.len()),
            ));
        }
        let vars: Vec<String> = vars.iter().map(|v| v.to_lowercase()).collect();
        let (toks, end) = lexer::lex(source)?;
        let tree = fold::fold(parser::parse(source, &toks, end, &vars)?);
        if let Some(v) = tree.as_num() {
            return Ok(Expr {
                source: source.to_string(),
                tape: None,
                affine: None,
                constant: Some(v),
                used: 0,
            });
        }
        let used = tree.used_vars();
        let tape = tape::compile(&tree).map_err(|_| {
            error(
                1,
                format!(
                    "expression is too large to compile (needs more than {} registers)",
                    tape::MAX_REGS
                ),
            )
        })?;
        Ok(Expr {
            source: source.to_string(),
            tape: Some(tape),
            affine: affine::affine(&tree),
            constant: None,
            used,
        })
    }

    /// Evaluates at one point. Does not allocate.
    ///
    /// # Panics
    /// If a variable the expression uses has no slot (`slots` too short).
    #[inline]
    pub fn eval(&self, slots: &[f64]) -> f64 {
        if let Some(a) = &self.affine {
            return a.eval(slots);
        }
        match &self.tape {
            Some(t) => t.eval(slots),
            None => self.constant.unwrap_or(f64::NAN),
        }
    }

    /// True when the expression is affine in its variables (`c + Σ kᵢ·vᵢ`).
    pub fn is_affine(&self) -> bool {
        self.affine.is_some()
    }

    /// The tape's value (bypassing the affine form), for tests.
    #[cfg(test)]
    pub(crate) fn eval_tape(&self, slots: &[f64]) -> f64 {
        self.tape.as_ref().map_or(f64::NAN, |t| t.eval(slots))
    }

    /// Evaluates many points at once: point `k` has variable `i` equal to
    /// `columns[i][k]`, and its value is written to `out[k]`. Same results as calling
    /// [`Expr::eval`] per point, several times faster for cheap expressions because
    /// the tape is dispatched once per chunk of points. Does not allocate.
    ///
    /// Columns of variables the expression does not use (see [`Expr::used_vars`])
    /// may be empty.
    ///
    /// # Panics
    /// If a used variable has no column, or its column is shorter than `out`.
    pub fn eval_batch(&self, columns: &[&[f64]], out: &mut [f64]) {
        match &self.tape {
            Some(t) => t.eval_batch(columns, out),
            None => out.fill(self.constant.unwrap_or(f64::NAN)),
        }
    }

    /// Conservative interval evaluation: the result contains `eval(p)` for every `p`
    /// with `p[i] ∈ slots[i]`; it is [`Interval::EVERYTHING`] if `eval` may be NaN.
    ///
    /// # Panics
    /// If a variable the expression uses has no slot (`slots` too short).
    pub fn eval_interval(&self, slots: &[Interval]) -> Interval {
        if let Some(a) = &self.affine {
            return a.eval_interval(slots);
        }
        match &self.tape {
            Some(t) => t.eval_interval(slots),
            None => Interval::point(self.constant.unwrap_or(f64::NAN)),
        }
    }

    /// `Some(v)` when the whole expression folded to a constant.
    pub fn constant(&self) -> Option<f64> {
        self.constant
    }

    /// Bit `i` is set when variable `i` is read.
    pub fn used_vars(&self) -> u64 {
        self.used
    }

    /// The source text this was compiled from.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Number of tape instructions (0 for a constant); a rough cost per evaluation.
    pub fn tape_len(&self) -> usize {
        self.tape.as_ref().map_or(0, |t| t.instrs.len())
    }
}

impl fmt::Debug for Expr {
    /// Shows the source, and either the constant or the tape listing.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut d = f.debug_struct("Expr");
        d.field("source", &self.source);
        match (&self.tape, self.constant) {
            (Some(t), _) => {
                let listing: Vec<String> = t.instrs.iter().map(ToString::to_string).collect();
                d.field("used_vars", &format_args!("{:#b}", self.used))
                    .field("registers", &t.regs)
                    .field("tape", &listing)
                    .field("result", &format_args!("r{}", t.result));
            }
            (None, c) => {
                d.field("constant", &c);
            }
        }
        d.finish()
    }
}
