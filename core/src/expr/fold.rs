//! Constant folding and exact algebraic simplification of the syntax tree.
//!
//! Any subtree without variables becomes a single constant, computed with
//! [`Op::apply`] — the same code the tape runs — so folding never changes a result.
//! The rewrites below are applied only where IEEE 754 makes them bit-exact for every
//! input (NaN, infinities and signed zeros included):
//!
//! | rewrite                    | why it is exact                                      |
//! |----------------------------|------------------------------------------------------|
//! | `x * 1`, `1 * x` → `x`     | multiplication by one is exact                       |
//! | `x / 1` → `x`              | division by one is exact                             |
//! | `x - 0`, `x + (-0)` → `x`  | `x + (-0) = x` for every `x`, including `-0`; not    |
//! |                            | `x - (-0)`, which turns `-0` into `+0`               |
//! | `x * -1` → `-x`            | exact, sign flip                                     |
//! | `x ^ 1` → `x`              | `pow(x, 1) = x` for every `x`                        |
//! | `--x` → `x`                | negation is exact                                    |
//! | `a + -b` → `a - b`         | IEEE defines `a - b` as `a + (-b)`                   |
//! | `a - -b` → `a + b`         | same                                                 |
//! | `-a + b` → `b - a`         | addition commutes exactly                            |
//! | `-a * c` → `a * (-c)`      | rounding is sign-symmetric                           |
//! | `c ? a : b` (constant `c`) | picks the branch                                     |
//!
//! `x + 0` is *not* rewritten (`-0 + 0 = +0`), nor `x * 0` (NaN, infinities, sign).
//!
//! One deliberate non-bit-exact rewrite: `x ^ 2` becomes `x * x` (`Square`). `pow`
//! is within 1 ulp of the exact square and `x * x` is correctly rounded, so they can
//! differ by 1 ulp in rare cases; the square is much faster and gives tighter
//! interval bounds.

use super::ast::Node;
use super::ops::{Op, truthy};

/// Folds constants and applies the exact rewrites, bottom-up.
pub(crate) fn fold(node: Node) -> Node {
    let Node::Apply { op, args, .. } = node else {
        return node;
    };
    let args: Vec<Node> = args.into_iter().map(fold).collect();
    if args.iter().all(|a| matches!(a, Node::Num(_))) {
        let v = |i: usize| args.get(i).and_then(Node::as_num).unwrap_or(0.0);
        return Node::Num(op.apply(v(0), v(1), v(2), 0.0));
    }
    simplify(op, args)
}

/// Applies one exact rewrite at the root of `op(args)` if one matches (children are
/// already simplified), re-simplifying the result.
fn simplify(op: Op, mut args: Vec<Node>) -> Node {
    let num = |n: &Node, v: f64| n.as_num().is_some_and(|c| c.to_bits() == v.to_bits());
    match (op, args.as_slice()) {
        (Op::Mul, [x, one]) | (Op::Mul, [one, x]) if num(one, 1.0) => x.clone(),
        (Op::Div, [x, one]) if num(one, 1.0) => x.clone(),
        (Op::Pow, [x, one]) if num(one, 1.0) => x.clone(),
        (Op::Sub, [x, zero]) if num(zero, 0.0) => x.clone(),
        (Op::Add, [x, z]) | (Op::Add, [z, x]) if num(z, -0.0) => x.clone(),
        (Op::Mul, [x, m]) | (Op::Mul, [m, x]) if num(m, -1.0) => simplify(Op::Neg, vec![x.clone()]),
        (Op::Pow, [x, two]) if num(two, 2.0) => Node::unary(Op::Square, x.clone()),
        (
            Op::Neg,
            [
                Node::Apply {
                    op: Op::Neg,
                    args: inner,
                    ..
                },
            ],
        ) => inner[0].clone(),
        (
            Op::Add,
            [
                a,
                Node::Apply {
                    op: Op::Neg,
                    args: b,
                    ..
                },
            ],
        ) => simplify(Op::Sub, vec![a.clone(), b[0].clone()]),
        (
            Op::Add,
            [
                Node::Apply {
                    op: Op::Neg,
                    args: a,
                    ..
                },
                b,
            ],
        ) => simplify(Op::Sub, vec![b.clone(), a[0].clone()]),
        (
            Op::Sub,
            [
                a,
                Node::Apply {
                    op: Op::Neg,
                    args: b,
                    ..
                },
            ],
        ) => simplify(Op::Add, vec![a.clone(), b[0].clone()]),
        (
            Op::Mul,
            [
                Node::Apply {
                    op: Op::Neg,
                    args: a,
                    ..
                },
                Node::Num(c),
            ],
        )
        | (
            Op::Mul,
            [
                Node::Num(c),
                Node::Apply {
                    op: Op::Neg,
                    args: a,
                    ..
                },
            ],
        ) => simplify(Op::Mul, vec![a[0].clone(), Node::Num(-c)]),
        (Op::Select, [Node::Num(c), _, _]) => {
            let keep = if truthy(*c) { 1 } else { 2 };
            args.swap_remove(keep)
        }
        _ => Node::apply(op, args),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn x() -> Node {
        Node::Var(0)
    }

    #[test]
    fn folds_constants() {
        let n = Node::binary(Op::Mul, Node::Num(2.0), Node::Num(std::f64::consts::PI));
        assert_eq!(fold(n), Node::Num(std::f64::consts::TAU));
        let n = Node::binary(Op::Add, x(), Node::unary(Op::Neg, Node::Num(1.0)));
        assert_eq!(fold(n), Node::binary(Op::Add, x(), Node::Num(-1.0)));
    }

    #[test]
    fn exact_rewrites() {
        let cases = [
            (Node::binary(Op::Mul, Node::Num(1.0), x()), x()),
            (Node::binary(Op::Div, x(), Node::Num(1.0)), x()),
            (Node::binary(Op::Sub, x(), Node::Num(0.0)), x()),
            (Node::binary(Op::Pow, x(), Node::Num(1.0)), x()),
            (
                Node::binary(Op::Pow, x(), Node::Num(2.0)),
                Node::unary(Op::Square, x()),
            ),
            (Node::unary(Op::Neg, Node::unary(Op::Neg, x())), x()),
            (
                Node::binary(Op::Mul, x(), Node::Num(-1.0)),
                Node::unary(Op::Neg, x()),
            ),
            (
                Node::binary(Op::Add, Node::unary(Op::Neg, x()), Node::Var(1)),
                Node::binary(Op::Sub, Node::Var(1), x()),
            ),
            (
                Node::binary(Op::Mul, Node::unary(Op::Neg, x()), Node::Num(3.0)),
                Node::binary(Op::Mul, x(), Node::Num(-3.0)),
            ),
            (
                Node::apply(Op::Select, vec![Node::Num(0.0), Node::Var(1), x()]),
                x(),
            ),
        ];
        for (input, want) in cases {
            assert_eq!(fold(input.clone()), want, "{input:?}");
        }
        // Not exact, so not rewritten.
        let keep = Node::binary(Op::Add, x(), Node::Num(0.0));
        assert_eq!(fold(keep.clone()), keep);
        let keep = Node::binary(Op::Mul, x(), Node::Num(0.0));
        assert_eq!(fold(keep.clone()), keep);
    }
}
