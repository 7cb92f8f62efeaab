//! Several expressions evaluated together. An FGrade's expressions are
//! usually a fraction and its complement (`clamp(0, rho/15, 1)` and
//! `1 - clamp(0, rho/15, 1)`, the paper's listings), which share all their
//! work: the expressions that run on tapes are fused into one tape
//! ([`tape::fuse`]) whose shared instructions run once. The values are bit
//! for bit those of [`Expr::eval`]: affine and constant members keep their
//! own evaluation, and fused results are the same operations on the same
//! operands.

use std::sync::Arc;

use super::Expr;
use super::tape::{self, MultiTape};

/// Most expressions fused into one tape: the usual few materials (a small
/// scratch array per evaluation; zeroing a large one per voxel would cost
/// more than fusing saves).
const MAX_FUSED: usize = 4;

/// Expressions evaluated as a set (see the module doc).
#[derive(Clone, Debug)]
pub struct ExprSet {
    exprs: Vec<Arc<Expr>>,
    /// The fused tape of the members that run on tapes, and their indices;
    /// `None` when fusing shares nothing.
    fused: Option<(MultiTape, Vec<usize>)>,
}

impl ExprSet {
    /// The set of `exprs`, fused where that shares instructions.
    pub fn new(exprs: Vec<Arc<Expr>>) -> ExprSet {
        let on_tape: Vec<usize> = (0..exprs.len())
            .filter(|&i| exprs[i].affine.is_none() && exprs[i].tape.is_some())
            .collect();
        let tapes: Vec<&tape::Tape> = on_tape
            .iter()
            .filter_map(|&i| exprs[i].tape.as_ref())
            .collect();
        let separate: usize = tapes.iter().map(|t| t.instrs.len()).sum();
        let fused = if (2..=MAX_FUSED).contains(&tapes.len()) {
            tape::fuse(&tapes)
                .ok()
                .filter(|m| m.len() < separate)
                .map(|m| (m, on_tape))
        } else {
            None
        };
        ExprSet { exprs, fused }
    }

    /// The expressions, in order.
    pub fn exprs(&self) -> &[Arc<Expr>] {
        &self.exprs
    }

    /// True when some members run as one fused tape.
    pub fn is_fused(&self) -> bool {
        self.fused.is_some()
    }

    /// The value of every expression at `slots` into `out` (one per
    /// expression), each exactly what [`Expr::eval`] gives.
    #[inline]
    pub fn eval_into(&self, slots: &[f64], out: &mut [f64]) {
        let Some((tape, members)) = &self.fused else {
            for (o, e) in out.iter_mut().zip(&self.exprs) {
                *o = e.eval(slots);
            }
            return;
        };
        let mut vals = [0.0; MAX_FUSED];
        tape.eval_into(slots, &mut vals[..members.len()]);
        let mut k = 0;
        for (i, (o, e)) in out.iter_mut().zip(&self.exprs).enumerate() {
            *o = if members.get(k) == Some(&i) {
                k += 1;
                vals[k - 1]
            } else {
                e.eval(slots)
            };
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::expr::COORD_VARS;

    fn set(sources: &[&str]) -> ExprSet {
        ExprSet::new(
            sources
                .iter()
                .map(|s| Arc::new(Expr::compile(s, &COORD_VARS).expect("compiles")))
                .collect(),
        )
    }

    #[test]
    fn fused_values_are_each_expressions_own() {
        let cases: [&[&str]; 4] = [
            &["clamp(0, rho/15, 1)", "1 - clamp(0, rho/15, 1)"],
            &[
                "clamp(0, (floor((x + 10)/5) + 0.5)/4, 1)",
                "1 - clamp(0, (floor((x + 10)/5) + 0.5)/4, 1)",
            ],
            // Affine and constant members keep their own evaluation.
            &[
                "x/15 + 0.5",
                "sin(x) * y",
                "0.25",
                "min(y, x) + sin(x)",
                "max(x, -0.0)",
            ],
            &["min(x, y) * 2", "min(y, x) * 3", "z"],
        ];
        let mut rng = crate::xorshift::XorShift::new(0x5EED_1234_ABCD_0001);
        for sources in cases {
            let s = set(sources);
            let mut out = vec![0.0; sources.len()];
            for n in 0..5_000 {
                let mut slots = [0.0; COORD_VARS.len()];
                for v in &mut slots[..3] {
                    // Zeros of both signs, and values across a wide range.
                    *v = match n % 7 {
                        0 => 0.0,
                        1 => -0.0,
                        _ => (rng.next_f64() - 0.5) * 40.0,
                    };
                }
                crate::expr::fill_derived_coords(&mut slots);
                s.eval_into(&slots, &mut out);
                for (o, e) in out.iter().zip(s.exprs()) {
                    assert_eq!(
                        o.to_bits(),
                        e.eval(&slots).to_bits(),
                        "{} at {slots:?}",
                        e.source()
                    );
                }
            }
        }
    }

    #[test]
    fn complements_share_their_work() {
        let s = set(&["clamp(0, rho/15, 1)", "1 - clamp(0, rho/15, 1)"]);
        let (tape, _) = s.fused.as_ref().expect("fused");
        let separate: usize = s.exprs().iter().map(|e| e.tape_len()).sum();
        // The second expression adds only its `1 - ...`.
        assert_eq!(tape.len(), s.exprs()[0].tape_len() + 1, "{separate}");
        // Nothing shared: not fused.
        assert!(!set(&["sin(x)", "cos(y)"]).is_fused());
        assert!(!set(&["x/15 + 0.5", "-x/15 + 0.5"]).is_fused());
    }
}
