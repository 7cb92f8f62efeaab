//! Overlap resolvers: how a Union or Intersection combines the values of
//! children that all contain a point (pyvcad 3's conflict resolvers). N
//! children reduce pairwise from the left, as pyvcad 3 does, so `average`
//! of three is `((a + b)/2 + c)/2`.

use std::sync::Arc;

use crate::expr::Expr;
use crate::interval::Interval;

/// A per-attribute overlap policy.
#[derive(Clone, Debug)]
pub enum Resolver {
    /// The first child containing the point (the default).
    First,
    /// `(a + b) / 2`.
    Average,
    /// `min(a, b)` per component.
    Min,
    /// `max(a, b)` per component.
    Max,
    /// `a + b`.
    Sum,
    /// A math string of `a` (the values so far) and `b` (the next child's).
    Custom(Arc<Expr>),
}

impl Resolver {
    /// `"first"`, `"average"`, `"min"`, `"max"`, `"sum"`, or a math string
    /// of `a` and `b`.
    pub(crate) fn parse(text: &str) -> Result<Resolver, String> {
        Ok(match text.trim().to_ascii_lowercase().as_str() {
            "first" => Resolver::First,
            "average" => Resolver::Average,
            "min" => Resolver::Min,
            "max" => Resolver::Max,
            "sum" => Resolver::Sum,
            _ => {
                let e = Expr::compile(text, &["a", "b"]).map_err(|e| {
                    format!(
                        "{e}; a resolver is \"first\", \"average\", \"min\", \"max\", \"sum\" or a math string of a and b such as \"a*0.5+b*0.5\""
                    )
                })?;
                Resolver::Custom(Arc::new(e))
            }
        })
    }

    /// The name a script writes.
    pub fn describe(&self) -> String {
        match self {
            Resolver::First => "first".into(),
            Resolver::Average => "average".into(),
            Resolver::Min => "min".into(),
            Resolver::Max => "max".into(),
            Resolver::Sum => "sum".into(),
            Resolver::Custom(e) => format!("\"{}\"", e.source()),
        }
    }

    /// `acc = acc ⊕ next`, per component.
    #[inline]
    pub(crate) fn fold(&self, acc: &mut [f64], next: &[f64]) {
        for (a, b) in acc.iter_mut().zip(next) {
            *a = match self {
                Resolver::First => *a,
                Resolver::Average => 0.5 * (*a + *b),
                Resolver::Min => a.min(*b),
                Resolver::Max => a.max(*b),
                Resolver::Sum => *a + *b,
                Resolver::Custom(e) => e.eval(&[*a, *b]),
            };
        }
    }

    /// Bounds of `a ⊕ b` for `a` in `x` and `b` in `y`.
    pub(crate) fn fold_interval(&self, x: Interval, y: Interval) -> Interval {
        match self {
            Resolver::First => x,
            Resolver::Average => Interval::new(0.5 * (x.lo + y.lo), 0.5 * (x.hi + y.hi)),
            Resolver::Min => x.min(y),
            Resolver::Max => x.max(y),
            Resolver::Sum => Interval::new(x.lo + y.lo, x.hi + y.hi),
            Resolver::Custom(e) => e.eval_interval(&[x, y]),
        }
    }
}
