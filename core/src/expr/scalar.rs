//! The scalar definitions of ExprTk's functions that are not plain `f64`
//! methods, shared by constant folding, the tape and interval evaluation.

/// The ExprTk `epsilon` constant, also the tolerance of `equal`.
pub(crate) const EPSILON: f64 = 1e-10;

/// `sgn(x)`: `1` if `x > 0`, `-1` if `x < 0`, else `0` (also for NaN, as ExprTk).
#[inline(always)]
pub(crate) fn sgn(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// `sinc(x) = sin(x) / x`, and `1` where `|x| < f64::EPSILON` (the removable
/// singularity; ExprTk uses the same threshold). NaN stays NaN.
#[inline(always)]
pub(crate) fn sinc(x: f64) -> f64 {
    if x.abs() < f64::EPSILON {
        1.0
    } else {
        x.sin() / x
    }
}

/// Standard normal CDF `Φ(x) = ½·erfc(-x/√2)`. Equal to ExprTk's
/// `½·(1 + erf(x/√2))` mathematically, but accurate in the lower tail too.
#[inline(always)]
pub(crate) fn ncdf(x: f64) -> f64 {
    0.5 * libm::erfc(-x * std::f64::consts::FRAC_1_SQRT_2)
}

/// `root(x, n) = x^(1/n)`; for `x < 0` the real root `-|x|^(1/n)` when `n` is an odd
/// integer, NaN otherwise (ExprTk's rule).
#[inline(always)]
pub(crate) fn root(x: f64, n: f64) -> f64 {
    if x < 0.0 {
        if n == n.trunc() && n % 2.0 != 0.0 {
            -(-x).powf(1.0 / n)
        } else {
            f64::NAN
        }
    } else {
        x.powf(1.0 / n)
    }
}

/// `10^k` for `k` in `0..=16`, the digit counts `roundn` accepts.
const POW10: [f64; 17] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
];

/// The scale `10^floor(n)` of `roundn`, with `floor(n)` clamped to `0..=16` (NaN → 0).
#[inline(always)]
pub(crate) fn roundn_scale(n: f64) -> f64 {
    POW10[n.floor().clamp(0.0, 16.0) as usize]
}

/// `roundn(x, n) = round(x · 10^d) / 10^d` with `d = floor(n)` clamped to `0..=16`;
/// halves round away from zero (ExprTk's rule).
#[inline(always)]
pub(crate) fn roundn(x: f64, n: f64) -> f64 {
    let p = roundn_scale(n);
    (x * p).round() / p
}

/// `equal(a, b)`: true when `a == b` exactly (so `equal(inf, inf)` holds), or when
/// `|a - b| <= 1e-10 · max(1, |a|, |b|)`: absolute tolerance `1e-10` near zero,
/// relative tolerance `1e-10` for large values. This is ExprTk's rule.
#[inline(always)]
pub(crate) fn equal(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= EPSILON * 1f64.max(a.abs()).max(b.abs())
}

/// `clamp(lo, x, hi)`: `lo` if `x < lo`, else `hi` if `x > hi`, else `x` (ExprTk's
/// order of tests, so NaN passes through and `lo` wins when `lo > hi`).
#[inline(always)]
pub(crate) fn clamp(lo: f64, x: f64, hi: f64) -> f64 {
    if x < lo {
        lo
    } else if x > hi {
        hi
    } else {
        x
    }
}

/// `iclamp(lo, x, hi)`, the inverse clamp: `x` when `x <= lo` or `x >= hi`; inside
/// the open range, the nearer of `lo` and `hi` (ties go to `hi`). ExprTk's rule.
#[inline(always)]
pub(crate) fn iclamp(lo: f64, x: f64, hi: f64) -> f64 {
    if x <= lo || x >= hi {
        x
    } else if x - lo < hi - x {
        lo
    } else {
        hi
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn helpers() {
        assert_eq!(sgn(-3.0), -1.0);
        assert_eq!(sgn(0.0), 0.0);
        assert_eq!(sgn(f64::NAN), 0.0);
        assert_eq!(sinc(0.0), 1.0);
        assert!((sinc(1.0) - 1f64.sin()).abs() < 1e-15);
        assert_eq!(ncdf(0.0), 0.5);
        assert!((ncdf(1.0) - 0.841_344_746_068_542_9).abs() < 1e-15);
        assert_eq!(root(27.0, 3.0), 3.0);
        assert_eq!(root(-27.0, 3.0), -3.0);
        assert!(root(-16.0, 4.0).is_nan());
        assert_eq!(roundn(1.23456, 2.0), 1.23);
        assert_eq!(roundn(-1.235, 2.0), -1.24);
        assert_eq!(roundn(2.5, -3.0), 3.0);
        assert!(equal(1.0, 1.0 + 1e-12));
        assert!(!equal(1.0, 1.0 + 1e-9));
        assert!(equal(1e20, 1e20 * (1.0 + 1e-12)));
        assert!(equal(f64::INFINITY, f64::INFINITY));
        assert_eq!(clamp(0.0, 2.0, 1.0), 1.0);
        assert_eq!(clamp(0.0, -2.0, 1.0), 0.0);
        assert!(clamp(0.0, f64::NAN, 1.0).is_nan());
        assert_eq!(iclamp(0.0, 0.3, 1.0), 0.0);
        assert_eq!(iclamp(0.0, 0.5, 1.0), 1.0);
        assert_eq!(iclamp(0.0, 0.7, 1.0), 1.0);
        assert_eq!(iclamp(0.0, 1.5, 1.0), 1.5);
    }
}
