//! Interval semantics of every [`Op`]: bounds that contain the scalar result
//! ([`Op::apply`]) for every choice of operands inside the operand intervals.
//!
//! Rules, in short:
//! - **NaN**: [`Interval::EVERYTHING`] doubles as "may be NaN". An operation whose
//!   scalar form turns NaN into NaN returns `EVERYTHING` for an `EVERYTHING` operand;
//!   operations that can swallow NaN (`min`, `max`, logic, `?:`) use their normal rule,
//!   which already covers what they return for NaN; comparisons return `[0, 1]`.
//!   Any operand point that could give NaN (`sqrt` below 0, `0 * inf`, ...) also
//!   gives `EVERYTHING`.
//! - **Monotone functions** map endpoints (`exp`, `log`, `atan`, `floor`, ...),
//!   decreasing ones swap them (`acos`, `erfc`); non-correctly-rounded ones are
//!   widened by two ulps (see [`crate::interval`]).
//! - **Periodic**: `sin`/`cos` find interior extrema, `tan` gives up at poles.
//! - **Comparisons and logic** return `1` or `0` when every operand point agrees,
//!   else `[0, 1]`. Truthiness of an interval: true if it excludes 0, false if it
//!   is exactly `[0, 0]`.
//! - **`?:` / `if`**: a decided condition takes its branch, otherwise the hull.
//! - Anything without a cheap exact rule is bounded loosely (`sinc` in
//!   `[-0.2173, 1]`) or gives `EVERYTHING`.

use std::f64::consts::PI;

use super::ops::{DEG2RAD, Op, RAD2DEG};
use super::scalar;
use crate::interval::{Interval, corners, widen};

/// Whether every point of `i` is truthy (`Some(true)`), none is (`Some(false)`), or
/// it depends (`None`). NaN is truthy, and only `EVERYTHING` may hold NaN, which
/// contains 0 and so is undecided.
fn truth(i: Interval) -> Option<bool> {
    if i.lo == 0.0 && i.hi == 0.0 {
        Some(false)
    } else if i.contains(0.0) {
        None
    } else {
        Some(true)
    }
}

/// `1`, `0` or `[0, 1]`.
fn decided(d: Option<bool>) -> Interval {
    match d {
        Some(true) => Interval::point(1.0),
        Some(false) => Interval::point(0.0),
        None => Interval::UNDECIDED,
    }
}

/// Three-valued `f` over truthiness.
fn logic(a: Interval, b: Interval, f: fn(bool, bool) -> bool) -> Interval {
    match (truth(a), truth(b)) {
        (Some(x), Some(y)) => decided(Some(f(x, y))),
        // Short-circuit cases where one side decides regardless of the other.
        (Some(x), None) if f(x, true) == f(x, false) => decided(Some(f(x, true))),
        (None, Some(y)) if f(true, y) == f(false, y) => decided(Some(f(true, y))),
        _ => Interval::UNDECIDED,
    }
}

/// `a < b` is decided by `a.hi < b.lo` (true) or `a.lo >= b.hi` (false).
fn less(a: Interval, b: Interval, or_equal: bool) -> Option<bool> {
    if or_equal {
        if a.hi <= b.lo {
            Some(true)
        } else if a.lo > b.hi {
            Some(false)
        } else {
            None
        }
    } else if a.hi < b.lo {
        Some(true)
    } else if a.lo >= b.hi {
        Some(false)
    } else {
        None
    }
}

fn equal_exact(a: Interval, b: Interval) -> Option<bool> {
    if a.is_point() && b.is_point() {
        Some(a.lo == b.lo)
    } else if a.hi < b.lo || b.hi < a.lo {
        Some(false)
    } else {
        None
    }
}

/// Bounds of `x ^ c` for a constant exponent.
fn pow_const(x: Interval, c: f64) -> Interval {
    let p = |v: f64| v.powf(c);
    if c == 0.0 {
        return Interval::point(1.0);
    }
    if c.is_nan() {
        return Interval::EVERYTHING;
    }
    if c.fract() == 0.0 && c.abs() < 9.0e15 {
        let odd = c % 2.0 != 0.0;
        if c > 0.0 {
            return if odd {
                x.increasing(p)
            } else {
                widen(p(x.mig()), p(x.mag())).clamp_to(0.0, f64::INFINITY)
            };
        }
        if x.contains(0.0) {
            return Interval::EVERYTHING; // pole (and ±inf at ±0)
        }
        return if odd {
            x.decreasing(p)
        } else {
            widen(p(x.mag()), p(x.mig())).clamp_to(0.0, f64::INFINITY)
        };
    }
    if x.lo < 0.0 {
        return Interval::EVERYTHING; // negative base, fractional exponent: NaN
    }
    if c > 0.0 {
        x.increasing(p)
    } else {
        x.decreasing(p)
    }
}

/// Bounds of `a ^ b`.
fn pow(a: Interval, b: Interval) -> Interval {
    if b.is_point() {
        return pow_const(a, b.lo);
    }
    // Non-negative base: monotone in each argument separately, so corners bound it.
    // At a zero base a negative exponent can give -inf (`pow(-0, -1)`): give up.
    if a.lo < 0.0 || (a.lo == 0.0 && b.lo < 0.0) {
        return Interval::EVERYTHING;
    }
    let k = corners(a, b, f64::powf);
    widen(k.lo, k.hi).clamp_to(0.0, f64::INFINITY)
}

/// Bounds of `atan2(y, x)`: the angle is continuous except across the cut along the
/// negative x-axis, and over a box that neither touches the cut nor contains the
/// origin its extremes are at corners.
fn atan2(y: Interval, x: Interval) -> Interval {
    if y.contains(0.0) && x.lo <= 0.0 {
        return widen(-PI, PI);
    }
    let k = corners(y, x, f64::atan2);
    widen(k.lo, k.hi)
}

/// Bounds of `fmod(a, b)`: the result has the sign of `a` and is smaller in magnitude
/// than both `|a|` and `|b|`; `fmod(x, y) = x` when `|x| < |y|`. fmod is exact.
fn fmod(a: Interval, b: Interval) -> Interval {
    if b.contains(0.0) || !a.lo.is_finite() || !a.hi.is_finite() {
        return Interval::EVERYTHING;
    }
    if a.mag() < b.mig() {
        return a;
    }
    let m = b.mag();
    let lo = if a.lo < 0.0 { -m.min(-a.lo) } else { 0.0 };
    let hi = if a.hi > 0.0 { m.min(a.hi) } else { 0.0 };
    Interval::new(lo, hi)
}

/// Bounds of `roundn(x, n)`: monotone in `x` for each digit count, so the hull over
/// the (at most 17) digit counts `n` can take.
fn roundn(x: Interval, n: Interval) -> Interval {
    let k0 = n.lo.floor().clamp(0.0, 16.0);
    let k1 = n.hi.floor().clamp(0.0, 16.0);
    let mut out: Option<Interval> = None;
    let mut k = k0;
    while k <= k1 {
        let i = Interval::new(scalar::roundn(x.lo, k), scalar::roundn(x.hi, k));
        out = Some(out.map_or(i, |o| o.union(i)));
        k += 1.0;
    }
    out.unwrap_or(Interval::EVERYTHING)
}

/// Bounds of `root(x, n)` for a constant `n > 0`: `x^(1/n)` is increasing on
/// `x >= 0`, and the odd-integer root is increasing on all reals.
fn root(x: Interval, n: Interval) -> Interval {
    if !n.is_point() || n.lo <= 0.0 {
        return Interval::EVERYTHING;
    }
    let n = n.lo;
    let odd_integer = n == n.trunc() && n % 2.0 != 0.0;
    if x.lo >= 0.0 || odd_integer {
        x.increasing(|v| scalar::root(v, n))
    } else {
        Interval::EVERYTHING
    }
}

/// Bounds of `sinc(x)`: always within `[-0.2173, 1]` (the global minimum is
/// `-0.21723…` near `x = 4.493`), and `|sinc(x)| <= 1/|x|`.
fn sinc(x: Interval) -> Interval {
    if !x.lo.is_finite() || !x.hi.is_finite() {
        return Interval::EVERYTHING; // sin(inf) is NaN
    }
    let (mut lo, mut hi) = (-0.2173f64, 1.0f64.next_up());
    let m = x.mig();
    if m > 0.0 {
        let bound = (1.0 / m).next_up();
        lo = lo.max(-bound);
        hi = hi.min(bound);
    }
    Interval::new(lo, hi)
}

/// Bounds of `frac(x) = x - trunc(x)`: exact within one integer cell, else the range
/// the sign of `x` allows.
fn frac(x: Interval) -> Interval {
    if !x.lo.is_finite() || !x.hi.is_finite() {
        return Interval::EVERYTHING; // frac(inf) = inf - inf
    }
    if x.lo.trunc() == x.hi.trunc() {
        Interval::new(x.lo - x.lo.trunc(), x.hi - x.hi.trunc())
    } else if x.lo >= 0.0 {
        Interval::new(0.0, 1.0)
    } else if x.hi <= 0.0 {
        Interval::new(-1.0, 0.0)
    } else {
        Interval::new(-1.0, 1.0)
    }
}

/// Bounds of `cosh(x)`: even, increasing in `|x|`, at least 1.
fn cosh(x: Interval) -> Interval {
    widen(x.mig().cosh(), x.mag().cosh()).clamp_to(1.0, f64::INFINITY)
}

/// Bounds of `clamp(lo, x, hi)`: `min(max(x, lo), hi)` when the bounds are ordered
/// for every point, else the result is one of the three arguments.
fn clamp(lo: Interval, x: Interval, hi: Interval) -> Interval {
    if lo.hi <= hi.lo {
        x.max(lo).min(hi)
    } else {
        lo.union(x).union(hi)
    }
}

/// Bounds of `iclamp(lo, x, hi)`: `x` when `x` is outside `(lo, hi)` at every point,
/// otherwise one of the three arguments.
fn iclamp(lo: Interval, x: Interval, hi: Interval) -> Interval {
    if x.hi <= lo.lo || x.lo >= hi.hi {
        x
    } else {
        lo.union(x).union(hi)
    }
}

fn in_range(lo: Interval, x: Interval, hi: Interval) -> Option<bool> {
    if lo.hi <= x.lo && x.hi <= hi.lo {
        Some(true)
    } else if x.hi < lo.lo || x.lo > hi.hi {
        Some(false)
    } else {
        None
    }
}

/// Domain check: `EVERYTHING` (NaN possible) unless `lo <= x.lo && x.hi <= hi`.
fn within(x: Interval, lo: f64, hi: f64, f: impl FnOnce(Interval) -> Interval) -> Interval {
    if x.lo < lo || x.hi > hi {
        Interval::EVERYTHING
    } else {
        f(x)
    }
}

impl Op {
    /// Interval counterpart of [`Op::apply`]: contains `apply(a, b, c, imm)` for every
    /// `a ∈ a`, `b ∈ b`, `c ∈ c` (only the first `arity()` operands are read).
    pub(crate) fn apply_interval(
        self,
        a: Interval,
        b: Interval,
        c: Interval,
        imm: f64,
    ) -> Interval {
        use Op::*;
        let n = self.arity();
        if (n >= 1 && a.is_everything())
            || (n >= 2 && b.is_everything())
            || (n >= 3 && c.is_everything())
        {
            match self {
                Min | Max | MinC | MaxC | Sgn | Not | And | Or | Xor | Nand | Nor | Xnor
                | Select => {}
                Eq | Ne | Lt | Le | Gt | Ge | Equal | InRange => return Interval::UNDECIDED,
                _ => return Interval::EVERYTHING,
            }
        }
        let inf = f64::INFINITY;
        match self {
            Var => Interval::EVERYTHING, // loaded by the evaluator
            Const => Interval::point(imm),
            AddC => a + imm,
            SubCR => imm - a,
            MulC => a * imm,
            DivRC => a / imm,
            DivCR => imm / a,
            MinC => a.min(Interval::point(imm)),
            MaxC => a.max(Interval::point(imm)),
            PowC => pow_const(a, imm),
            ClampLoC => a.max(Interval::point(imm)),
            ClampHiC => a.min(Interval::point(imm)),
            Neg => -a,
            Not => decided(truth(a).map(|t| !t)),
            Abs => a.abs(),
            Square => a.square(),
            Sqrt => a.sqrt(),
            Ceil => Interval::new(a.lo.ceil(), a.hi.ceil()),
            Floor => Interval::new(a.lo.floor(), a.hi.floor()),
            Round => Interval::new(a.lo.round(), a.hi.round()),
            Trunc => Interval::new(a.lo.trunc(), a.hi.trunc()),
            Frac => frac(a),
            Sgn => Interval::new(scalar::sgn(a.lo), scalar::sgn(a.hi)),
            Exp => a.exp(),
            Expm1 => a.increasing(f64::exp_m1).clamp_to(-1.0, inf),
            Ln => a.ln(),
            Log10 => within(a, 0.0, inf, |a| a.increasing(f64::log10)),
            Log2 => within(a, 0.0, inf, |a| a.increasing(f64::log2)),
            Log1p => within(a, -1.0, inf, |a| a.increasing(f64::ln_1p)),
            Sin => a.sin(),
            Cos => a.cos(),
            Tan => a.tan(),
            Asin => within(a, -1.0, 1.0, |a| a.increasing(f64::asin)),
            Acos => within(a, -1.0, 1.0, |a| a.decreasing(f64::acos)),
            Atan => a.increasing(f64::atan),
            Sinh => a.increasing(f64::sinh),
            Cosh => cosh(a),
            Tanh => a.increasing(f64::tanh).clamp_to(-1.0, 1.0),
            Asinh => a.increasing(f64::asinh),
            Acosh => within(a, 1.0, inf, |a| a.increasing(f64::acosh)),
            Atanh => within(a, -1.0, 1.0, |a| a.increasing(f64::atanh)),
            Sec => 1.0 / a.cos(),
            Csc => 1.0 / a.sin(),
            Cot => 1.0 / a.tan(),
            Sinc => sinc(a),
            Deg2Rad => a * DEG2RAD,
            Rad2Deg => a * RAD2DEG,
            Erf => a.increasing(libm::erf).clamp_to(-1.0, 1.0),
            Erfc => a.decreasing(libm::erfc).clamp_to(0.0, 2.0),
            Ncdf => a.increasing(scalar::ncdf).clamp_to(0.0, 1.0),
            Add => a + b,
            Sub => a - b,
            Mul => a * b,
            Div => a / b,
            Mod => fmod(a, b),
            Pow => pow(a, b),
            Min => a.min(b),
            Max => a.max(b),
            Atan2 => atan2(a, b),
            Hypot => widen(a.mig().hypot(b.mig()), a.mag().hypot(b.mag())).clamp_to(0.0, inf),
            Root => root(a, b),
            Logn => a.ln() / b.ln(),
            Roundn => roundn(a, b),
            Equal => {
                if a.is_point() && b.is_point() {
                    Interval::point(self.apply(a.lo, b.lo, 0.0, 0.0))
                } else {
                    Interval::UNDECIDED
                }
            }
            Eq => decided(equal_exact(a, b)),
            Ne => decided(equal_exact(a, b).map(|e| !e)),
            Lt => decided(less(a, b, false)),
            Le => decided(less(a, b, true)),
            Gt => decided(less(b, a, false)),
            Ge => decided(less(b, a, true)),
            And => logic(a, b, |x, y| x & y),
            Or => logic(a, b, |x, y| x | y),
            Xor => logic(a, b, |x, y| x ^ y),
            Nand => logic(a, b, |x, y| !(x & y)),
            Nor => logic(a, b, |x, y| !(x | y)),
            Xnor => logic(a, b, |x, y| x == y),
            Select => match truth(a) {
                Some(true) => b,
                Some(false) => c,
                None => b.union(c),
            },
            Clamp => clamp(a, b, c),
            IClamp => iclamp(a, b, c),
            InRange => decided(in_range(a, b, c)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interval::test_rng::IntervalRng;

    /// fidget-style exhaustive check: for every op, random operand intervals, random
    /// points inside them; the scalar result must lie in the interval result (or the
    /// interval must be `EVERYTHING` when the scalar is NaN).
    #[test]
    fn every_op_is_conservative() {
        let mut rng = IntervalRng::new(0x2545_F491_4F6C_DD1D);
        for &op in Op::ALL {
            if op == Op::Var {
                continue;
            }
            for round in 0..3000 {
                let (a, b, c) = (rng.interval(), rng.interval(), rng.interval());
                let imm = if round % 3 == 0 {
                    rng.pick(&[0.0, 1.0, 2.0, 3.0, -1.0, -2.0, 0.5, f64::INFINITY])
                } else {
                    rng.value()
                };
                let out = op.apply_interval(a, b, c, imm);
                assert!(out.lo <= out.hi, "{op:?}: {out:?}");
                for _ in 0..6 {
                    let (x, y, z) = (rng.sample(a), rng.sample(b), rng.sample(c));
                    let v = op.apply(x, y, z, imm);
                    let ok = if v.is_nan() {
                        out.is_everything()
                    } else {
                        out.contains(v)
                    };
                    assert!(
                        ok,
                        "{op:?}({x}, {y}, {z}; imm {imm}) = {v} not in {out:?}\n  operands {a:?} {b:?} {c:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn tight_where_it_matters() {
        let i = |lo, hi| Interval::new(lo, hi);
        assert_eq!(
            Op::Lt.apply_interval(i(0.0, 1.0), i(2.0, 3.0), i(0.0, 0.0), 0.0),
            i(1.0, 1.0)
        );
        assert_eq!(
            Op::Lt.apply_interval(i(0.0, 2.5), i(2.0, 3.0), i(0.0, 0.0), 0.0),
            Interval::UNDECIDED
        );
        let sel = Op::Select.apply_interval(i(1.0, 2.0), i(5.0, 6.0), i(-9.0, 9.0), 0.0);
        assert_eq!(sel, i(5.0, 6.0));
        let cl = Op::Clamp.apply_interval(i(0.0, 0.0), i(-5.0, 0.5), i(1.0, 1.0), 0.0);
        assert_eq!(cl, i(0.0, 0.5));
        let p = Op::PowC.apply_interval(i(-2.0, 1.0), i(0.0, 0.0), i(0.0, 0.0), 2.0);
        assert!(p.lo == 0.0 && p.hi >= 4.0 && p.hi < 4.0 + 1e-12);
        assert_eq!(
            Op::Sqrt.apply_interval(i(-1.0, 4.0), i(0.0, 0.0), i(0.0, 0.0), 0.0),
            Interval::EVERYTHING
        );
        assert_eq!(
            Op::And.apply_interval(i(0.0, 0.0), Interval::EVERYTHING, i(0.0, 0.0), 0.0),
            i(0.0, 0.0)
        );
    }
}
