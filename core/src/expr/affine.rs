//! Affine expressions `c + Σ kᵢ·vᵢ` (gradings such as `x/15 + 0.5` are
//! mostly affine): recognised after folding and evaluated as a short dot
//! product instead of running the tape, which matters when a grading is
//! evaluated for every voxel of a slice stack.

use super::ast::Node;
use super::ops::Op;
use crate::interval::Interval;

/// `c + Σ k·slots[i]` for `(i, k)` in `terms`.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Affine {
    pub c: f64,
    pub terms: Box<[(u8, f64)]>,
}

impl Affine {
    /// Value at `slots`.
    #[inline]
    pub(crate) fn eval(&self, slots: &[f64]) -> f64 {
        let mut v = self.c;
        for (i, k) in self.terms.iter() {
            v += k * slots[*i as usize];
        }
        v
    }

    /// Bounds over `slots`, with the same operations in the same order as
    /// [`Affine::eval`] on the corner that makes each term smallest or
    /// largest: rounding is monotone, so every point value lies within.
    #[inline]
    pub(crate) fn eval_interval(&self, slots: &[Interval]) -> Interval {
        let (mut lo, mut hi) = (self.c, self.c);
        for (i, k) in self.terms.iter() {
            let s = slots[*i as usize];
            let (a, b) = if *k >= 0.0 {
                (s.lo, s.hi)
            } else {
                (s.hi, s.lo)
            };
            lo += k * a;
            hi += k * b;
        }
        Interval::new(lo, hi)
    }
}

/// The affine form of `n`, if it has one (built from numbers, variables,
/// `+ - neg`, and `* /` by constants).
pub(crate) fn affine(n: &Node) -> Option<Affine> {
    let (c, terms) = form(n)?;
    Some(Affine {
        c,
        terms: terms.into_boxed_slice(),
    })
}

type Form = (f64, Vec<(u8, f64)>);

fn form(n: &Node) -> Option<Form> {
    match n {
        Node::Num(v) => Some((*v, Vec::new())),
        Node::Var(i) => Some((0.0, vec![(*i, 1.0)])),
        Node::Apply { op, args, .. } => match (op, args.as_slice()) {
            (Op::Neg, [a]) => Some(scale(form(a)?, -1.0)),
            (Op::Add, [a, b]) => Some(add(form(a)?, form(b)?, 1.0)),
            (Op::Sub, [a, b]) => Some(add(form(a)?, form(b)?, -1.0)),
            (Op::Mul, [a, b]) => {
                let (fa, fb) = (form(a)?, form(b)?);
                if fa.1.is_empty() {
                    Some(scale(fb, fa.0))
                } else if fb.1.is_empty() {
                    Some(scale(fa, fb.0))
                } else {
                    None
                }
            }
            (Op::Div, [a, b]) => {
                let fb = form(b)?;
                if fb.1.is_empty() && fb.0 != 0.0 && fb.0.is_finite() {
                    Some(scale_div(form(a)?, fb.0))
                } else {
                    None
                }
            }
            _ => None,
        },
    }
}

fn scale((c, mut t): Form, k: f64) -> Form {
    for term in &mut t {
        term.1 *= k;
    }
    (c * k, t)
}

/// Division keeps `x / 15` as a division of each coefficient, so `x/15`
/// evaluates as `x * (1/15)` only through the coefficient, exact to one ulp.
fn scale_div((c, mut t): Form, k: f64) -> Form {
    for term in &mut t {
        term.1 /= k;
    }
    (c / k, t)
}

fn add((ca, mut ta): Form, (cb, tb): Form, sign: f64) -> Form {
    for (i, k) in tb {
        match ta.iter_mut().find(|t| t.0 == i) {
            Some(t) => t.1 += sign * k,
            None => ta.push((i, sign * k)),
        }
    }
    (ca + sign * cb, ta)
}

#[cfg(test)]
mod tests {
    use crate::expr::Expr;

    #[test]
    fn affine_gradings_agree_with_the_tape() {
        let vars = ["x", "y", "z"];
        for src in [
            "x/15+0.5",
            "-x/15+0.5",
            "1 - (2*x - y/4) + 3",
            "0.5*(x+y) - z*2",
            "x",
        ] {
            let e = Expr::compile(src, &vars).unwrap();
            assert!(e.is_affine(), "{src}");
            for p in [[1.0, 2.0, 3.0], [-7.5, 0.25, 1e3], [0.0, 0.0, 0.0]] {
                let a = e.eval(&p);
                let t = e.eval_tape(&p);
                assert!(
                    (a - t).abs() <= 1e-12 * (1.0 + t.abs()),
                    "{src} at {p:?}: {a} vs {t}"
                );
            }
        }
        for src in ["x*y", "sin(x)", "x/y", "clamp(0, x, 1)"] {
            assert!(!Expr::compile(src, &vars).unwrap().is_affine(), "{src}");
        }
    }
}
